//! Per-sample coverage of a triangle in one tile, for multisampled targets.
//!
//! A sample at offset `(dx, dy)` (exact sub-pixel units) from its pixel centre is covered when
//! `E(centre) + a·dx + b·dy + bias ≥ 0` for all three edges: the edge functions with their
//! constant moved by `a·dx + b·dy`, an exact integer. Each sample's coverage is therefore that of
//! the triangle with shifted edges, found by [`rasterize_blocks`] with any strategy (so every
//! strategy gives the same sample coverage, as it does pixel coverage). Plane 0 is the pixel
//! centre itself — the coverage of a 1× frame, which keeps the per-pixel depth exact — and
//! plane `1 + s` is sample `s`.

use super::{rasterize_blocks, BlockCoverage, Strategy};
use kantele_lanes::Isa;
use kantele_rules::fixed::{BLOCK_LOG2, TILE_SIZE};
use kantele_rules::multisample::{SampleCount, MAX_SAMPLES};
use kantele_rules::setup::{PixelRect, TriangleSetup};

/// 8 × 8 blocks per tile.
const BLOCKS: usize = ((TILE_SIZE >> BLOCK_LOG2) * (TILE_SIZE >> BLOCK_LOG2)) as usize;

/// Coverage planes: the pixel centre, then each sample.
pub const MAX_COVERAGE_PLANES: usize = MAX_SAMPLES + 1;

/// A triangle's coverage in one tile, per coverage plane (pixel centre, then each sample), as
/// 8 × 8 block masks (bit `8·r + c` = pixel `(x + c, y + r)` of the block). Reused from
/// triangle to triangle; no allocation once grown.
#[derive(Clone, Debug)]
pub struct SampleCoverage {
    /// `masks[plane][block]`, blocks row-major within the tile.
    masks: [[u64; BLOCKS]; MAX_COVERAGE_PLANES],
    /// Union of every plane's mask per block: the pixels with anything covered.
    union: [u64; BLOCKS],
    /// Blocks with a non-zero union, ascending.
    blocks: Vec<u8>,
    /// The tile's first pixel.
    origin: (i32, i32),
    /// Coverage planes of the last triangle (samples + 1).
    planes: usize,
    scratch: BlockCoverage,
}

impl Default for SampleCoverage {
    fn default() -> Self {
        Self {
            masks: [[0; BLOCKS]; MAX_COVERAGE_PLANES],
            union: [0; BLOCKS],
            blocks: Vec::with_capacity(BLOCKS),
            origin: (0, 0),
            planes: 0,
            scratch: BlockCoverage::default(),
        }
    }
}

/// One covered block of a [`SampleCoverage`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SampleBlock {
    /// Column of the block's first pixel (a multiple of 8).
    pub x: i32,
    /// Row of the block's first pixel (a multiple of 8).
    pub y: i32,
    /// Index of the block within its tile (row-major).
    pub index: usize,
    /// Pixels with at least one plane covered.
    pub union: u64,
}

impl SampleCoverage {
    /// Whether nothing is covered.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.blocks.is_empty()
    }

    /// Number of coverage planes (samples + 1).
    #[inline]
    pub fn planes(&self) -> usize {
        self.planes
    }

    /// The covered blocks, ascending in the tile.
    #[inline]
    pub fn blocks(&self) -> impl Iterator<Item = SampleBlock> + '_ {
        let per_row = (TILE_SIZE >> BLOCK_LOG2) as i32;
        self.blocks.iter().map(move |&b| {
            let b = b as usize;
            SampleBlock {
                x: self.origin.0 + ((b as i32 % per_row) << BLOCK_LOG2),
                y: self.origin.1 + ((b as i32 / per_row) << BLOCK_LOG2),
                index: b,
                union: self.union[b],
            }
        })
    }

    /// The mask of plane `plane` (0: pixel centres, `1 + s`: sample `s`) in block `block`.
    #[inline(always)]
    pub fn mask(&self, plane: usize, block: usize) -> u64 {
        self.masks[plane][block]
    }

    /// Number of covered samples (pixel-centre plane not counted).
    pub fn sample_count(&self) -> u64 {
        self.blocks
            .iter()
            .map(|&b| {
                (1..self.planes)
                    .map(|p| self.masks[p][b as usize].count_ones() as u64)
                    .sum::<u64>()
            })
            .sum()
    }

    fn clear(&mut self) {
        for &b in &self.blocks {
            let b = b as usize;
            self.union[b] = 0;
            for plane in &mut self.masks[..self.planes] {
                plane[b] = 0;
            }
        }
        self.blocks.clear();
    }
}

/// Finds the pixel-centre and per-sample coverage of `rect` (which lies in one 64 × 64 tile),
/// replacing what `out` held.
pub fn rasterize_samples(
    tri: &TriangleSetup,
    rect: PixelRect,
    strategy: Strategy,
    samples: SampleCount,
    isa: Isa,
    out: &mut SampleCoverage,
) {
    out.clear();
    out.planes = samples.count() + 1;
    let tile = TILE_SIZE as i32;
    out.origin = (rect.x0 & !(tile - 1), rect.y0 & !(tile - 1));
    let offsets = samples.offsets_subpixel();
    for plane in 0..out.planes {
        let shifted = if plane == 0 {
            *tri
        } else {
            let [dx, dy] = offsets[plane - 1];
            let mut t = *tri;
            for e in &mut t.edges {
                e.c += e.a * dx + e.b * dy;
            }
            t
        };
        rasterize_blocks(&shifted, rect, strategy, isa, &mut out.scratch);
        for block in out.scratch.blocks() {
            let index = crate::rop::TileBuffer::block_index(block.x, block.y);
            if out.union[index] == 0 {
                out.blocks.push(index as u8);
            }
            out.union[index] |= block.mask;
            out.masks[plane][index] = block.mask;
        }
    }
    out.blocks.sort_unstable();
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec4;
    use kantele_rules::fixed::pixel_center;
    use kantele_rules::setup::{setup_triangle, CullMode, FrontFace, Viewport};

    /// Reference: whether the sample at `offset` of pixel `(x, y)` is covered, from scratch.
    fn covered(tri: &TriangleSetup, x: i32, y: i32, offset: [i64; 2]) -> bool {
        tri.edges.iter().all(|e| {
            e.a * (pixel_center(x as i64) + offset[0])
                + e.b * (pixel_center(y as i64) + offset[1])
                + e.c
                + e.bias
                >= 0
        })
    }

    #[test]
    fn every_strategy_finds_exactly_the_covered_samples() {
        let mut seed = 777u64;
        let mut rand = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % 10_000) as f32 / 10_000.0 * 2.4 - 1.2
        };
        let mut coverage = SampleCoverage::default();
        let mut checked = 0;
        for samples in [SampleCount::X4, SampleCount::X8] {
            let vp = Viewport::new(100, 70).with_samples(samples);
            let offsets = samples.offsets_subpixel();
            for _ in 0..120 {
                let p = [
                    Vec4::new(rand(), rand(), 0.0, 1.0),
                    Vec4::new(rand() * 0.1, rand() * 0.1, 0.0, 1.0),
                    Vec4::new(rand(), rand(), 0.0, 1.0),
                ];
                let Ok(tri) = setup_triangle(&vp, p, CullMode::None, FrontFace::Ccw) else {
                    continue;
                };
                for (tx, ty) in [(0, 0), (64, 0), (0, 64), (64, 64)] {
                    let rect = PixelRect {
                        x0: tx,
                        y0: ty,
                        x1: (tx + 64).min(100),
                        y1: (ty + 64).min(70),
                    };
                    let levels = [Isa::Scalar, Isa::best()];
                    for (strategy, isa) in Strategy::ALL
                        .into_iter()
                        .flat_map(|s| levels.map(|isa| (s, isa)))
                    {
                        rasterize_samples(&tri, rect, strategy, samples, isa, &mut coverage);
                        let mut found = [0u64; MAX_COVERAGE_PLANES];
                        let mut planes = vec![[0u64; 64]; coverage.planes()];
                        for b in coverage.blocks() {
                            for (p, plane) in planes.iter_mut().enumerate() {
                                plane[b.index] = coverage.mask(p, b.index);
                                found[p] += plane[b.index].count_ones() as u64;
                            }
                        }
                        for y in rect.y0..rect.y1 {
                            for x in rect.x0..rect.x1 {
                                let block = crate::rop::TileBuffer::block_index(x, y);
                                let bit = ((y & 7) << 3) | (x & 7);
                                for (p, plane) in planes.iter().enumerate() {
                                    let offset = if p == 0 { [0, 0] } else { offsets[p - 1] };
                                    assert_eq!(
                                        plane[block] >> bit & 1 == 1,
                                        covered(&tri, x, y, offset),
                                        "{strategy} {isa} plane {p} pixel ({x}, {y})"
                                    );
                                }
                            }
                        }
                        assert_eq!(
                            coverage.sample_count(),
                            found[1..coverage.planes()].iter().sum::<u64>()
                        );
                    }
                }
                checked += 1;
            }
        }
        assert!(checked > 150, "{checked}");
    }

    #[test]
    fn a_sliver_between_pixel_centres_still_covers_samples() {
        // A thin triangle over x ∈ [10.3, 10.45]: no pixel centre (x.5) inside, but the 4×
        // sample at 6/16 = 0.375 is.
        let vp = Viewport::new(32, 32);
        let to_ndc = |x: f32, y: f32| Vec4::new(x / 16.0 - 1.0, 1.0 - y / 16.0, 0.0, 1.0);
        let p = [to_ndc(10.3, 2.0), to_ndc(10.45, 2.0), to_ndc(10.3, 20.0)];
        assert!(setup_triangle(&vp, p, CullMode::None, FrontFace::Ccw).is_err());
        let tri = setup_triangle(
            &vp.with_samples(SampleCount::X4),
            p,
            CullMode::None,
            FrontFace::Ccw,
        )
        .expect("kept on a multisampled target");
        let mut coverage = SampleCoverage::default();
        let rect = PixelRect {
            x0: 0,
            y0: 0,
            x1: 32,
            y1: 32,
        };
        rasterize_samples(
            &tri,
            rect,
            Strategy::Bisector,
            SampleCount::X4,
            Isa::best(),
            &mut coverage,
        );
        assert!(coverage.sample_count() > 0);
        assert!(coverage.blocks().all(|b| coverage.mask(0, b.index) == 0));
    }
}
