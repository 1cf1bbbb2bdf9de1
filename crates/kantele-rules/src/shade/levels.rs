//! Where each level of a texture's mip chain lies: a [`LevelTable`] of offsets and sizes, and
//! the same values as [`LaneTable`]s, the form the lane-wide sampler looks them up in.

use kantele_lanes::{F32x8, I32x8, Lanes, Mask8, TexelGather};

use crate::state::MAX_TEXTURE_SIZE;

/// Where each mip level lies in the texel storage, one entry per level (level 0 first), and
/// the same as [`LaneTable`]s for the lane-wide sampler.
#[derive(Clone, Debug)]
pub(super) struct LevelTable {
    /// Index of each level's first texel.
    pub(super) offsets: Vec<u32>,
    /// Width of each level in texels.
    pub(super) widths: Vec<u32>,
    /// Height of each level in texels.
    pub(super) heights: Vec<u32>,
    /// The offsets as a [`LaneTable`].
    pub(super) lane_offsets: LaneTable,
    /// The widths and heights as [`LaneTable`]s.
    pub(super) lane_sizes: [LaneTable; 2],
}

impl LevelTable {
    /// The table of a chain whose levels, stored one after another, have `sizes` (width,
    /// height), level 0 first (at most 16 levels, at most 16384² · 4/3 texels in all).
    pub(super) fn new(sizes: &[(u32, u32)]) -> Self {
        let mut offsets = Vec::with_capacity(sizes.len());
        let mut offset = 0u32;
        for &(w, h) in sizes {
            offsets.push(offset);
            offset += w * h;
        }
        let (widths, heights): (Vec<u32>, Vec<u32>) = sizes.iter().copied().unzip();
        Self {
            lane_offsets: lane_table(&offsets),
            lane_sizes: [lane_table(&widths), lane_table(&heights)],
            offsets,
            widths,
            heights,
        }
    }
}

/// The per-level values of a mip chain (at most 16 levels: [`MAX_TEXTURE_SIZE`] has 15) in the
/// form the lane-wide sampler looks them up, two 8-lane permutes: the values of levels
/// `0..16`, the last level's repeated past the last level.
pub(super) type LaneTable = [i32; 16];

const _: () = assert!(
    MAX_TEXTURE_SIZE.ilog2() < 16,
    "a mip chain must fit a LaneTable"
);

/// `values` (one per level, at most 16, each below 2³¹: offsets of at most 16384² · 4/3
/// texels, sizes of at most 16384) as a [`LaneTable`].
/// A `const fn`, so that fixed chains (the environment's specular levels) have their tables as
/// constants.
pub(super) const fn lane_table(values: &[u32]) -> LaneTable {
    let mut table = [0; 16];
    let mut k = 0;
    while k < 16 {
        let value = if k < values.len() {
            values[k]
        } else if values.is_empty() {
            0
        } else {
            values[values.len() - 1]
        };
        table[k] = if value > i32::MAX as u32 {
            i32::MAX
        } else {
            value as i32
        };
        k += 1;
    }
    table
}

/// Lane `k`: `table[index[k] mod 16]`, without a branch or a memory access per lane (two
/// permutes of eight entries and a select; the values move as bits).
#[inline(always)]
pub(super) fn lookup16<L: Lanes>(table: &LaneTable, index: L::I32) -> L::I32 {
    let lanes = index.lanes();
    let low = L::F32::from_bits(lanes.load_i32(&table[..8])).permute(index);
    let high = L::F32::from_bits(lanes.load_i32(&table[8..])).permute(index);
    let in_high = (index & lanes.splat_i32(8)).simd_eq(lanes.splat_i32(8));
    in_high.select_f32(high, low).to_bits()
}

/// The bilinear blend of RGB texels stored four words apart (RGB and a 0, as `f32` bits), per
/// lane: `top` and `bottom` are the word indices of the left texels of the footprint's two rows,
/// each row's right texel the next in memory; `fx`, `fy` the weights of the right and bottom
/// texels. Each row's two texels are read together ([`TexelGather::gather_u32_quad`]).
#[inline(always)]
pub(super) fn bilinear_rgb<L: Lanes>(
    lanes: L,
    table: &[u32],
    top: L::I32,
    bottom: L::I32,
    fx: L::F32,
    fy: L::F32,
) -> [L::F32; 3] {
    let right = lanes.splat_i32(4);
    let [top_left, top_right, bottom_left, bottom_right] = [
        top.gather_u32_quad(table),
        (top + right).gather_u32_quad(table),
        bottom.gather_u32_quad(table),
        (bottom + right).gather_u32_quad(table),
    ];
    let mut out = [lanes.splat_f32(0.0); 3];
    for (c, o) in out.iter_mut().enumerate() {
        let t = [
            L::F32::from_bits(top_left[c]),
            L::F32::from_bits(top_right[c]),
            L::F32::from_bits(bottom_left[c]),
            L::F32::from_bits(bottom_right[c]),
        ];
        let top = t[0] + (t[1] - t[0]) * fx;
        let bottom = t[2] + (t[3] - t[2]) * fx;
        *o = top + (bottom - top) * fy;
    }
    out
}
