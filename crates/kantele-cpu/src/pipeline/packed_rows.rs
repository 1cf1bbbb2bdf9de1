//! Packed rows: the fragments of a sparsely covered 8 × 8 block shaded eight at a time,
//! whatever their rows.
//!
//! The per-pixel kernel shades a row of eight pixels per call of the fragment program. Where
//! small triangles cover a block, most rows hold a few fragments (3.8 of 8 lanes on the spot
//! scene, 1.7 on the bunny) and every row still pays for the whole program. For a program that
//! shades each lane from its own values alone ([`LaneProgram::PACKED_ROWS`]), the kernel
//! instead packs the fragments of all rows of such a block next to each other
//! ([`PackedRows::pack`]: their barycentrics and depths, moved to the front of the lanes by
//! [`F32x8::permute`]), shades them in groups of eight, and unpacks each row's results back to
//! its pixels ([`PackedRows::unpack`]) before the rest of the row's path (blending, stores).
//! Every lane goes through the same operations as in its own row, so the picture is the same,
//! bit for bit.
//!
//! [`LaneProgram::PACKED_ROWS`]: super::shader::LaneProgram::PACKED_ROWS

use kantele_lanes::{F32x8, Lanes, Mask8, MaskOf};

/// For each row mask (bit `k`: lane `k` holds a fragment), the lanes that move to the front,
/// in order: entry `j` is the lane of the `j`-th set bit (0 past the last one).
static PACK_LANES: [[i32; 8]; 256] = pack_lanes();

/// For each row mask, where each of its lanes is found among the packed ones: entry `k` is the
/// number of set bits below bit `k` (0 for lanes that are not set).
static UNPACK_LANES: [[i32; 8]; 256] = unpack_lanes();

const fn pack_lanes() -> [[i32; 8]; 256] {
    let mut table = [[0; 8]; 256];
    let mut bits = 0;
    while bits < 256 {
        let (mut lane, mut next) = (0, 0);
        while lane < 8 {
            if bits & (1 << lane) != 0 {
                table[bits][next] = lane;
                next += 1;
            }
            lane += 1;
        }
        bits += 1;
    }
    table
}

const fn unpack_lanes() -> [[i32; 8]; 256] {
    let mut table = [[0; 8]; 256];
    let mut bits = 0;
    while bits < 256 {
        let (mut lane, mut below) = (0, 0);
        while lane < 8 {
            if bits & (1 << lane) != 0 {
                table[bits][lane] = below;
                below += 1;
            }
            lane += 1;
        }
        bits += 1;
    }
    table
}

/// Whether a block with coverage `mask` (bit `8·row + lane`) is shaded packed: when its covered
/// pixels fill fewer groups of eight than it has covered rows, so that packing saves at least
/// one call of the fragment program.
#[inline(always)]
pub(super) fn packing_saves_a_row(mask: u64) -> bool {
    let groups = mask.count_ones().div_ceil(8);
    let mut rows = 0;
    for row in 0..8 {
        rows += u32::from((mask >> (8 * row)) as u8 != 0);
    }
    groups < rows
}

/// The packed values of one block: up to 64 fragments, stored in order of their rows and
/// lanes. Written eight lanes at a time, so a store at fragment `n` also writes the seven
/// entries after it (at most entry 63: a block's rows before its last hold at most 56).
pub(super) struct PackedRows {
    /// Barycentrics λ1 and λ2 of each fragment (λ0 is `1 − λ1 − λ2`, recomputed alike).
    l1: [f32; 64],
    l2: [f32; 64],
    /// Window depth of each fragment.
    depth: [f32; 64],
    /// The fragment program's colour of each fragment.
    color: [[f32; 64]; 4],
    /// 1 where the program kept the fragment, 0 where it discarded it.
    keep: [f32; 64],
}

impl PackedRows {
    /// Empty storage (every value 0).
    pub(super) fn new() -> Self {
        Self {
            l1: [0.0; 64],
            l2: [0.0; 64],
            depth: [0.0; 64],
            color: [[0.0; 64]; 4],
            keep: [0.0; 64],
        }
    }

    /// Appends the lanes of one row set in `bits` after the first `at` fragments (`at ≤ 56`).
    #[inline(always)]
    pub(super) fn pack<L: Lanes>(
        &mut self,
        lanes: L,
        at: usize,
        bits: u8,
        [_, l1, l2]: [L::F32; 3],
        depth: L::F32,
    ) {
        let order = lanes.load_i32(&PACK_LANES[usize::from(bits)]);
        l1.permute(order).store(&mut self.l1[at..]);
        l2.permute(order).store(&mut self.l2[at..]);
        depth.permute(order).store(&mut self.depth[at..]);
    }

    /// The barycentrics and depths of fragments `at..at + 8` (`at ≤ 56`).
    #[inline(always)]
    pub(super) fn group<L: Lanes>(
        &self,
        lanes: L,
        at: usize,
        one: L::F32,
    ) -> ([L::F32; 3], L::F32) {
        let l1 = lanes.load_f32(&self.l1[at..]);
        let l2 = lanes.load_f32(&self.l2[at..]);
        ([one - l1 - l2, l1, l2], lanes.load_f32(&self.depth[at..]))
    }

    /// Stores the program's results for fragments `at..at + 8` (`at ≤ 56`).
    #[inline(always)]
    pub(super) fn store_shaded<L: Lanes>(
        &mut self,
        at: usize,
        color: [L::F32; 4],
        keep: MaskOf<L>,
        [zero, one]: [L::F32; 2],
    ) {
        for (channel, out) in color.iter().zip(&mut self.color) {
            channel.store(&mut out[at..]);
        }
        keep.select_f32(one, zero).store(&mut self.keep[at..]);
    }

    /// The colours and kept lanes of one row whose fragments are those set in `bits`, packed
    /// from fragment `at` on (`at ≤ 56`): each lane's own results back in its place (lanes not
    /// set in `bits` are unspecified and not kept).
    #[inline(always)]
    pub(super) fn unpack<L: Lanes>(
        &self,
        lanes: L,
        at: usize,
        bits: u8,
        zero: L::F32,
    ) -> ([L::F32; 4], MaskOf<L>) {
        let order = lanes.load_i32(&UNPACK_LANES[usize::from(bits)]);
        let mut color = [zero; 4];
        for (channel, packed) in color.iter_mut().zip(&self.color) {
            *channel = lanes.load_f32(&packed[at..]).permute(order);
        }
        let keep = lanes
            .load_f32(&self.keep[at..])
            .permute(order)
            .simd_gt(zero);
        (color, keep.and(lanes.mask_from_bits(bits)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kantele_lanes::{dispatch, I32x8, Isa, LaneKernel};

    #[test]
    fn the_tables_move_each_set_lane_to_its_rank_and_back() {
        for bits in 0..256usize {
            let set: Vec<i32> = (0..8).filter(|k| bits & (1 << k) != 0).collect();
            assert_eq!(&PACK_LANES[bits][..set.len()], &set[..], "{bits:08b}");
            for (rank, &lane) in set.iter().enumerate() {
                assert_eq!(UNPACK_LANES[bits][lane as usize], rank as i32, "{bits:08b}");
            }
        }
    }

    /// Packs rows, "shades" each packed lane (a value of its own: `2·l1 + depth`, discarding
    /// some), unpacks: every row gets its own lanes' results.
    struct RoundTrip(Vec<(u8, [f32; 8], [f32; 8])>);

    impl LaneKernel for RoundTrip {
        type Output = Vec<([u32; 8], u8)>;
        #[inline(always)]
        fn run<L: Lanes>(self, lanes: L) -> Self::Output {
            let (zero, one) = (lanes.splat_f32(0.0), lanes.splat_f32(1.0));
            let mut packed = PackedRows::new();
            let mut at = 0;
            for (bits, l1, depth) in &self.0 {
                let l1 = lanes.f32_from_array(*l1);
                packed.pack(
                    lanes,
                    at,
                    *bits,
                    [zero, l1, zero],
                    lanes.f32_from_array(*depth),
                );
                at += bits.count_ones() as usize;
            }
            for group in (0..at).step_by(8) {
                let ([_, l1, _], depth) = packed.group(lanes, group, one);
                let value = l1 + l1 + depth;
                let keep = value.simd_lt(lanes.splat_f32(100.0));
                packed.store_shaded::<L>(group, [value, depth, l1, one], keep, [zero, one]);
            }
            let mut out = Vec::new();
            let mut at = 0;
            for (bits, _, _) in &self.0 {
                let (color, keep) = packed.unpack(lanes, at, *bits, zero);
                at += bits.count_ones() as usize;
                out.push((color[0].to_bits().to_array().map(|v| v as u32), keep.bits()));
            }
            out
        }
    }

    #[test]
    fn every_row_gets_its_own_lanes_back_on_every_instruction_set() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for _ in 0..500 {
            let rows: Vec<(u8, [f32; 8], [f32; 8])> = (0..8)
                .map(|_| {
                    let bits = (next() as u8) & (next() as u8);
                    let l1 = std::array::from_fn(|_| (next() % 64) as f32);
                    let depth = std::array::from_fn(|_| (next() % 64) as f32 / 8.0);
                    (bits, l1, depth)
                })
                .collect();
            let expected: Vec<([u32; 8], u8)> = rows
                .iter()
                .map(|(bits, l1, depth)| {
                    let value: [f32; 8] = std::array::from_fn(|k| l1[k] + l1[k] + depth[k]);
                    let keep = (0..8)
                        .filter(|&k| bits & (1 << k) != 0 && value[k] < 100.0)
                        .fold(0u8, |acc, k| acc | 1 << k);
                    (value.map(f32::to_bits), keep)
                })
                .collect();
            for isa in Isa::supported() {
                let got = dispatch(isa, RoundTrip(rows.clone()));
                for ((row, (bits, _, _)), (got, want)) in
                    rows.iter().enumerate().zip(got.iter().zip(&expected))
                {
                    assert_eq!(got.1, want.1, "{isa} row {row}: kept lanes");
                    for k in (0..8).filter(|k| bits & (1 << k) != 0) {
                        assert_eq!(got.0[k], want.0[k], "{isa} row {row} lane {k}");
                    }
                }
            }
        }
    }

    #[test]
    fn packing_is_chosen_where_it_saves_a_call() {
        assert!(!packing_saves_a_row(0));
        assert!(!packing_saves_a_row(u64::MAX));
        assert!(!packing_saves_a_row(0xff));
        // One row of three pixels, and two such rows: one group instead of two rows.
        assert!(!packing_saves_a_row(0x0700));
        assert!(packing_saves_a_row(0x0707));
        // Two full rows and one pixel: three rows and three groups.
        assert!(!packing_saves_a_row(0x01_ffff));
        // A small triangle: rows of 1, 3, 5 and 2 pixels (11: two groups, four rows).
        assert!(packing_saves_a_row(0x0300_1f07_0100_0000));
    }
}
