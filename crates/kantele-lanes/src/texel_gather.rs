//! Lane operations of the texture sampler: fetching two neighbouring
//! texels per lane at once, and decoding the red, green and blue bytes of packed texels through
//! a 256-entry table.
//!
//! [`TexelGather`] is a separate trait (every [`Lanes::I32`](super::Lanes::I32) implements it)
//! so the sampler's operations stay in one block. The readable reference is written on arrays
//! with scalar loads; the scalar, SSE2/SSE4.1 and NEON implementations use it as it is (SSE and
//! NEON have no gather instruction). AVX2 fetches pairs with two `vpgatherdq`, runs of four
//! entries with one 16-byte load per lane and a transpose, and decodes with three `vpgatherdd` (in `avx2.rs`, the block marked `TexelGather`). Every implementation
//! returns the same bits for every input: they are table reads.

use super::{I32x8, Lanes};

/// Texel fetches for the lane-wide sampler.
pub trait TexelGather: I32x8 {
    /// Two neighbouring table entries per lane: lane `k` of the first result is `table[c]` and of
    /// the second `table[c + 1]`, with `c = clamp(self[k], 0, table.len() - 2)`; all zeros when
    /// `table` has fewer than two entries. One read of 8 bytes per lane on AVX2 (`vpgatherdq`):
    /// the two texels of a bilinear footprint's row, when they are neighbours in memory.
    fn gather_u32_pair(self, table: &[u32]) -> (Self, Self);

    /// Four neighbouring table entries per lane: lane `k` of result `i` is `table[c + i]`, with
    /// `c = clamp(self[k], 0, table.len() - 4)`; all zeros when `table` has fewer than four
    /// entries. One 16-byte load per lane and a transpose on AVX2: the two texels of a bilinear
    /// footprint's row in a texture's decoded copy (two words a texel).
    fn gather_u32_quad(self, table: &[u32]) -> [Self; 4];

    /// The fixed-point bilinear filter of one mip level per lane, optionally blended with a
    /// second level (trilinear): [`filter15_reference`] with `words` a texture's decoded copy
    /// (two words per texel, `[r | g << 16, b | a << 16]`, channels in `0..=32767`). Returns the
    /// red, green, blue and alpha lanes in the same units. AVX2 filters the texels packed as
    /// 16-bit values, as they are loaded (one 16-byte load per lane and row, `vpmulhrsw`), and
    /// gives the same bits: every step is exact integer arithmetic.
    fn filter15(
        words: &[u32],
        first: Footprint15<Self>,
        second: Option<(Footprint15<Self>, Self)>,
    ) -> [Self; 4];

    /// Bytes 0, 1 and 2 of each lane (red, green and blue of a packed texel) decoded through a
    /// 256-entry table: lane `k` of result `c` is `table[(self[k] >> 8c) & 0xff]`.
    fn lookup_rgb(self, table: &[u32; 256]) -> [Self; 3];
}

/// One mip level's bilinear footprint per lane, for [`TexelGather::filter15`]: the two texels
/// of each row are neighbours in memory.
#[derive(Clone, Copy, Debug)]
pub struct Footprint15<I> {
    /// Texel index (not word index) of the top row's left texel.
    pub top: I,
    /// Texel index of the bottom row's left texel.
    pub bottom: I,
    /// Weight of the right texels, in `0..=32767` (units of 1/32768).
    pub alpha: I,
    /// Weight of the bottom row, in `0..=32767`.
    pub beta: I,
}

/// One step of the fixed-point filter: `a + (((b − a) · w + 2^14) >> 15)` per lane, for `a`
/// and `b` in `0..=32767` and `w` in `0..=32767` (units of 1/32768). The result lies between
/// `a` and `b` (`a` exactly where `w = 0`), and every intermediate fits in `i32`. It is what
/// `vpmulhrsw` computes on the difference, so the packed 16-bit AVX2 filter gives the same bits.
#[inline(always)]
pub fn lerp15<L: Lanes>(a: L::I32, b: L::I32, w: L::I32) -> L::I32 {
    let half = a.lanes().splat_i32(1 << 14);
    a + ((b - a) * w + half).shr_arith::<15>()
}

/// [`lerp15`] on four channels.
#[inline(always)]
pub fn lerp15_channels<L: Lanes>(a: [L::I32; 4], b: [L::I32; 4], w: L::I32) -> [L::I32; 4] {
    [
        lerp15::<L>(a[0], b[0], w),
        lerp15::<L>(a[1], b[1], w),
        lerp15::<L>(a[2], b[2], w),
        lerp15::<L>(a[3], b[3], w),
    ]
}

/// The channels of decoded texels, the words `rg = r | g << 16` and `ba = b | a << 16`.
#[inline(always)]
pub fn unpack_words15<L: Lanes>(rg: L::I32, ba: L::I32) -> [L::I32; 4] {
    let low = rg.lanes().splat_i32(0xffff);
    [
        rg & low,
        rg.shr_logical::<16>(),
        ba & low,
        ba.shr_logical::<16>(),
    ]
}

/// The texels at texel indices `index` and `index + 1` of a decoded copy (`words`, two per
/// texel), unpacked: [`TexelGather::gather_u32_quad`] at word `2 · index` (wrapping).
#[inline(always)]
pub fn gather_texel_pair15<L: Lanes>(words: &[u32], index: L::I32) -> ([L::I32; 4], [L::I32; 4]) {
    let [rg0, ba0, rg1, ba1] = (index + index).gather_u32_quad(words);
    (unpack_words15::<L>(rg0, ba0), unpack_words15::<L>(rg1, ba1))
}

/// The bilinear blend of a footprint's four texels `[top left, top right, bottom left, bottom
/// right]`: each row with `alpha`, then the two rows with `beta` ([`lerp15`]).
#[inline(always)]
pub fn bilinear15<L: Lanes>(texels: [[L::I32; 4]; 4], alpha: L::I32, beta: L::I32) -> [L::I32; 4] {
    let [t00, t10, t01, t11] = texels;
    let top = lerp15_channels::<L>(t00, t10, alpha);
    let bottom = lerp15_channels::<L>(t01, t11, alpha);
    lerp15_channels::<L>(top, bottom, beta)
}

/// [`TexelGather::filter15`], the reference: per level, each row's two texels blended with
/// `alpha` ([`lerp15`]), then the two rows with `beta`; then, with a second level, the two levels
/// with its weight (`0..=32767`). The word index of a texel index, `2 · index` (wrapping), is
/// clamped as [`TexelGather::gather_u32_quad`] clamps it.
#[inline(always)]
pub fn filter15_reference<L: Lanes>(
    words: &[u32],
    first: Footprint15<L::I32>,
    second: Option<(Footprint15<L::I32>, L::I32)>,
) -> [L::I32; 4] {
    let level = filter_level15_reference::<L>(words, first);
    match second {
        None => level,
        Some((footprint, weight)) => lerp15_channels::<L>(
            level,
            filter_level15_reference::<L>(words, footprint),
            weight,
        ),
    }
}

/// One level of [`filter15_reference`].
#[inline(always)]
fn filter_level15_reference<L: Lanes>(words: &[u32], f: Footprint15<L::I32>) -> [L::I32; 4] {
    let (t00, t10) = gather_texel_pair15::<L>(words, f.top);
    let (t01, t11) = gather_texel_pair15::<L>(words, f.bottom);
    bilinear15::<L>([t00, t10, t01, t11], f.alpha, f.beta)
}

/// [`TexelGather::gather_u32_pair`] (`N = 2`) and [`TexelGather::gather_u32_quad`] (`N = 4`)
/// on plain arrays, the reference: lane `k` of result `i` is `table[c + i]` with
/// `c = clamp(index[k], 0, table.len() - N)`; all zeros when `table` has fewer than `N` entries.
#[inline(always)]
fn gather_run_reference<const N: usize>(index: [i32; 8], table: &[u32]) -> [[i32; 8]; N] {
    let mut out = [[0i32; 8]; N];
    let Some(last) = table.len().checked_sub(N) else {
        return out;
    };
    for k in 0..8 {
        let c = usize::try_from(index[k]).unwrap_or(0).min(last);
        for (i, entries) in out.iter_mut().enumerate() {
            entries[k] = table[c + i] as i32;
        }
    }
    out
}

/// [`TexelGather::lookup_rgb`] on plain arrays: the reference.
#[inline(always)]
fn lookup_rgb_reference(packed: [i32; 8], table: &[u32; 256]) -> [[i32; 8]; 3] {
    let mut out = [[0i32; 8]; 3];
    for k in 0..8 {
        let [r, g, b, _] = packed[k].to_le_bytes();
        out[0][k] = table[r as usize] as i32;
        out[1][k] = table[g as usize] as i32;
        out[2][k] = table[b as usize] as i32;
    }
    out
}

/// Implements [`TexelGather`] with the array references (scalar loads).
macro_rules! texel_gather_by_reference {
    ($(#[$attr:meta])* impl $(<$param:ident: $bound:path>)? for $ty:ty) => {
        $(#[$attr])*
        impl$(<$param: $bound>)? TexelGather for $ty {
            #[inline(always)]
            fn gather_u32_pair(self, table: &[u32]) -> (Self, Self) {
                let lanes = self.lanes();
                let [first, second] = gather_run_reference::<2>(self.to_array(), table);
                (lanes.i32_from_array(first), lanes.i32_from_array(second))
            }

            #[inline(always)]
            fn gather_u32_quad(self, table: &[u32]) -> [Self; 4] {
                let lanes = self.lanes();
                let [a, b, c, d] = gather_run_reference::<4>(self.to_array(), table);
                [
                    lanes.i32_from_array(a),
                    lanes.i32_from_array(b),
                    lanes.i32_from_array(c),
                    lanes.i32_from_array(d),
                ]
            }

            #[inline(always)]
            fn filter15(
                words: &[u32],
                first: Footprint15<Self>,
                second: Option<(Footprint15<Self>, Self)>,
            ) -> [Self; 4] {
                filter15_reference::<<$ty as I32x8>::Lanes>(words, first, second)
            }

            #[inline(always)]
            fn lookup_rgb(self, table: &[u32; 256]) -> [Self; 3] {
                let lanes = self.lanes();
                let [r, g, b] = lookup_rgb_reference(self.to_array(), table);
                [
                    lanes.i32_from_array(r),
                    lanes.i32_from_array(g),
                    lanes.i32_from_array(b),
                ]
            }
        }
    };
}

texel_gather_by_reference!(impl for super::scalar::ScalarI32);
texel_gather_by_reference!(
    #[cfg(target_arch = "x86_64")]
    impl<T: super::sse2::SseLevel> for super::sse2::SseI32<T>
);
texel_gather_by_reference!(
    #[cfg(target_arch = "aarch64")]
    impl for super::neon::NeonI32
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{dispatch, Isa, LaneKernel};

    struct Pair<'a> {
        index: [i32; 8],
        table: &'a [u32],
    }

    impl LaneKernel for Pair<'_> {
        type Output = ([i32; 8], [i32; 8]);
        #[inline(always)]
        fn run<L: Lanes>(self, lanes: L) -> Self::Output {
            let (a, b) = lanes.i32_from_array(self.index).gather_u32_pair(self.table);
            (a.to_array(), b.to_array())
        }
    }

    struct Quad<'a> {
        index: [i32; 8],
        table: &'a [u32],
    }

    impl LaneKernel for Quad<'_> {
        type Output = [[i32; 8]; 4];
        #[inline(always)]
        fn run<L: Lanes>(self, lanes: L) -> Self::Output {
            let [a, b, c, d] = lanes.i32_from_array(self.index).gather_u32_quad(self.table);
            [a.to_array(), b.to_array(), c.to_array(), d.to_array()]
        }
    }

    struct Bytes<'a> {
        packed: [i32; 8],
        table: &'a [u32; 256],
    }

    impl LaneKernel for Bytes<'_> {
        type Output = [[i32; 8]; 3];
        #[inline(always)]
        fn run<L: Lanes>(self, lanes: L) -> Self::Output {
            let [r, g, b] = lanes.i32_from_array(self.packed).lookup_rgb(self.table);
            [r.to_array(), g.to_array(), b.to_array()]
        }
    }

    struct Filter<'a> {
        words: &'a [u32],
        first: [[i32; 8]; 4],
        second: Option<([[i32; 8]; 4], [i32; 8])>,
    }

    impl LaneKernel for Filter<'_> {
        type Output = [[i32; 8]; 4];
        #[inline(always)]
        fn run<L: Lanes>(self, lanes: L) -> Self::Output {
            let footprint = |[top, bottom, alpha, beta]: [[i32; 8]; 4]| Footprint15 {
                top: lanes.i32_from_array(top),
                bottom: lanes.i32_from_array(bottom),
                alpha: lanes.i32_from_array(alpha),
                beta: lanes.i32_from_array(beta),
            };
            let second = self
                .second
                .map(|(f, w)| (footprint(f), lanes.i32_from_array(w)));
            let out = L::I32::filter15(self.words, footprint(self.first), second);
            out.map(|c| c.to_array())
        }
    }

    /// `lerp15` on plain integers.
    fn lerp(a: i32, b: i32, w: i32) -> i32 {
        a + (((b - a) * w + (1 << 14)) >> 15)
    }

    /// [`TexelGather::filter15`] on plain integers, lane `k`: the bilinear blend of each
    /// footprint (indices clamped as the trait says), then the levels.
    fn filter_expected(words: &[u32], filter: &Filter<'_>, k: usize) -> [i32; 4] {
        let texel = |index: i32, right: usize, c: usize| -> i32 {
            let w = (index.wrapping_add(index) as i64).clamp(0, words.len() as i64 - 4) as usize;
            let word = words[w + 2 * right + c / 2];
            ((word >> (16 * (c % 2))) & 0xffff) as i32
        };
        let level = |[top, bottom, alpha, beta]: [[i32; 8]; 4], c: usize| -> i32 {
            let row = |index: i32| lerp(texel(index, 0, c), texel(index, 1, c), alpha[k]);
            lerp(row(top[k]), row(bottom[k]), beta[k])
        };
        std::array::from_fn(|c| match filter.second {
            None => level(filter.first, c),
            Some((second, w)) => lerp(level(filter.first, c), level(second, c), w[k]),
        })
    }

    #[test]
    fn the_fixed_point_filter_is_the_same_on_every_instruction_set() {
        let mut state = 0x2545_f491u32;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state
        };
        for len in [4usize, 6, 64, 130] {
            let words: Vec<u32> = (0..len)
                .map(|_| (next() % 32641) | (next() % 32641) << 16)
                .collect();
            for round in 0..200 {
                let texels = (len / 2) as u32;
                let mut footprint = || -> [[i32; 8]; 4] {
                    let index = |v: u32| match v % 16 {
                        0 => i32::MIN,
                        1 => -1,
                        2 => i32::MAX,
                        3 => texels as i32,
                        _ => (v % texels) as i32,
                    };
                    let weight = |v: u32| match v % 8 {
                        0 => 0,
                        1 => 32767,
                        _ => (v % 32768) as i32,
                    };
                    [
                        std::array::from_fn(|_| index(next())),
                        std::array::from_fn(|_| index(next())),
                        std::array::from_fn(|_| weight(next())),
                        std::array::from_fn(|_| weight(next())),
                    ]
                };
                let first = footprint();
                let second_footprint = footprint();
                let second = (round % 2 == 1).then(|| {
                    (
                        second_footprint,
                        std::array::from_fn(|k| (first[2][k] ^ first[3][k]) & 0x7fff),
                    )
                });
                let filter = Filter {
                    words: &words,
                    first,
                    second,
                };
                let expected: [[i32; 8]; 4] = std::array::from_fn(|c| {
                    std::array::from_fn(|k| filter_expected(&words, &filter, k)[c])
                });
                for isa in Isa::supported() {
                    let got = dispatch(
                        isa,
                        Filter {
                            words: &words,
                            first,
                            second,
                        },
                    );
                    assert_eq!(got, expected, "{isa}, {len} words, round {round}");
                }
            }
        }
    }

    /// Checks `gather` (a run of `N` neighbouring entries per lane, at every supported level)
    /// against the clamped reads it must make, over tables of `lens` entries and windows of
    /// `edges` as indices.
    fn check_runs<const N: usize>(
        edges: &[i32],
        lens: &[usize],
        gather: impl Fn(Isa, [i32; 8], &[u32]) -> [[i32; 8]; N],
    ) {
        for &len in lens {
            let table: Vec<u32> = (0..len as u32)
                .map(|i| 0x8000_0001u32.wrapping_mul(i + 1))
                .collect();
            for start in 0..edges.len() {
                let index: [i32; 8] = std::array::from_fn(|k| edges[(start + k) % edges.len()]);
                let expected: [[i32; 8]; N] = if len < N {
                    [[0; 8]; N]
                } else {
                    let c = |k: usize| (index[k].max(0) as usize).min(len - N);
                    std::array::from_fn(|i| std::array::from_fn(|k| table[c(k) + i] as i32))
                };
                for isa in Isa::supported() {
                    let got = gather(isa, index, &table);
                    assert_eq!(got, expected, "{isa}, {len} entries, {index:?}");
                }
            }
        }
    }

    #[test]
    fn pairs_are_neighbouring_entries_with_clamped_indices() {
        let edges = [i32::MIN, -1, 0, 1, 5, 6, 7, 8, 1000, i32::MAX];
        check_runs::<2>(&edges, &[0, 1, 2, 3, 8, 9], |isa, index, table| {
            let (first, second) = dispatch(isa, Pair { index, table });
            [first, second]
        });
    }

    #[test]
    fn quads_are_four_neighbouring_entries_with_clamped_indices() {
        let edges = [i32::MIN, -1, 0, 1, 3, 4, 5, 6, 7, 8, 1000, i32::MAX];
        check_runs::<4>(&edges, &[0, 1, 3, 4, 5, 8, 9, 17], |isa, index, table| {
            dispatch(isa, Quad { index, table })
        });
    }

    #[test]
    fn bytes_are_decoded_through_the_table() {
        let table: [u32; 256] = std::array::from_fn(|k| (k as u32).wrapping_mul(0x9e37_79b9));
        let mut state = 0x1234_5678u32;
        for _ in 0..64 {
            let packed: [i32; 8] = std::array::from_fn(|_| {
                state ^= state << 13;
                state ^= state >> 17;
                state ^= state << 5;
                state as i32
            });
            let expected: [[i32; 8]; 3] = std::array::from_fn(|byte| {
                std::array::from_fn(|k| table[packed[k].to_le_bytes()[byte] as usize] as i32)
            });
            for isa in Isa::supported() {
                let got = dispatch(
                    isa,
                    Bytes {
                        packed,
                        table: &table,
                    },
                );
                assert_eq!(got, expected, "{isa}");
            }
        }
    }
}
