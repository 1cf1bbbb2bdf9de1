//! Host-side planning, kept apart from the driver calls so it can be tested on any machine: the
//! tile grid and binning chunks of a frame, the buffer capacities and how they grow after an
//! overflow, the levels of the device-wide scan, and the fixed sequence of launches of a frame.

use kantele_rules::fixed::TILE_SIZE;

use crate::defines::BIN_CHUNK;
use crate::records::MAX_FRAME_ELEMENTS;

/// Threads per block of the one-thread-per-item kernels.
pub const THREADS: u32 = 256;
/// Threads per block of the scan kernels (one element each).
pub const SCAN_THREADS: u32 = 1024;
/// Threads per block of the raster kernel (one 4 × 4 quad of a 64 × 64 tile each).
pub const RASTER_THREADS: u32 = 256;
/// Side of the baselines' square thread blocks (the thesis' 16 × 16 virtual blocks).
pub const BASELINE_BLOCK: u32 = 16;
/// Triangles per launch of the "one call, many triangles" baseline.
pub const OCMT_BATCH: u32 = 1024;

/// What one frame works on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameShape {
    /// Target width in pixels.
    pub width: u32,
    /// Target height in pixels.
    pub height: u32,
    /// Scene draws.
    pub draws: u32,
    /// Vertices shaded per frame.
    pub shaded: u32,
    /// Triangle slots per frame.
    pub slots: u32,
}

impl FrameShape {
    /// Tiles per row.
    pub fn tiles_x(&self) -> u32 {
        self.width.div_ceil(TILE_SIZE)
    }

    /// Tile rows.
    pub fn tiles_y(&self) -> u32 {
        self.height.div_ceil(TILE_SIZE)
    }

    /// Tiles in the target.
    pub fn tiles(&self) -> u32 {
        self.tiles_x() * self.tiles_y()
    }

    /// Binning chunks (one warp each).
    pub fn chunks(&self) -> u32 {
        self.slots.div_ceil(BIN_CHUNK)
    }

    /// Cells of the binning count matrix (tiles × chunks).
    pub fn matrix_cells(&self) -> u64 {
        self.tiles() as u64 * self.chunks() as u64
    }
}

/// Sizes of the buffers whose need is only known on the device.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Capacities {
    /// Setups for the fans of clipped triangles.
    pub clip: u32,
    /// Entries of all tile bins together.
    pub bins: u32,
}

/// The device's report at the end of a frame: what the frame needed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Needs {
    /// Setups of clipped fans requested.
    pub clip: u64,
    /// Bin entries requested.
    pub bins: u64,
}

/// The most setups (slots plus clipped fans) or bin entries a frame may hold: indices into them
/// are `u32` in the kernels.
pub const MAX_CAPACITY: u64 = MAX_FRAME_ELEMENTS * 2;

impl Capacities {
    /// A first guess: few clipped triangles, about two tiles per triangle.
    pub fn initial(shape: &FrameShape) -> Self {
        Self {
            clip: (shape.slots / 8).max(1024),
            bins: shape
                .slots
                .saturating_mul(2)
                .saturating_add(shape.tiles())
                .max(4096),
        }
    }

    /// Whether a frame that needed `needs` fit.
    pub fn fits(&self, needs: &Needs) -> bool {
        needs.clip <= self.clip as u64 && needs.bins <= self.bins as u64
    }

    /// Capacities for redoing a frame that needed `needs`: each overflowed buffer grows to
    /// 1.5 × its need (so a camera moving a little does not overflow again next frame). An
    /// error when a need exceeds what the kernels can index.
    pub fn grown(&self, needs: &Needs, slots: u32) -> Result<Self, String> {
        let grow = |current: u32, need: u64, limit: u64, what: &str| -> Result<u32, String> {
            if need <= current as u64 {
                return Ok(current);
            }
            if need > limit {
                return Err(format!(
                    "a frame needs {need} {what}, more than the CUDA backend's limit of {limit}"
                ));
            }
            Ok((need + need / 2).min(limit) as u32)
        };
        Ok(Self {
            clip: grow(
                self.clip,
                needs.clip,
                MAX_CAPACITY - slots as u64,
                "clipped triangles",
            )?,
            bins: grow(self.bins, needs.bins, MAX_CAPACITY, "bin entries")?,
        })
    }
}

/// Element counts of each level of the exclusive scan of `n` elements: level 0 is the input,
/// each next level holds the block sums of the one before, down to a single block.
pub fn scan_levels(n: u64) -> Vec<u64> {
    let mut levels = Vec::new();
    let mut count = n;
    while count > 0 {
        levels.push(count);
        if count <= SCAN_THREADS as u64 {
            break;
        }
        count = count.div_ceil(SCAN_THREADS as u64);
    }
    levels
}

/// A kernel of the pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kernel {
    /// `kantele_draw_matrices` (vertex.cu).
    DrawMatrices,
    /// `kantele_vertex` (vertex.cu).
    Vertex,
    /// `kantele_primitive` (primitive.cu).
    Primitive,
    /// `kantele_bin_count` (binning.cu).
    BinCount,
    /// `kantele_scan_blocks` on scan level `usize` (binning.cu).
    ScanBlocks(usize),
    /// `kantele_scan_add` onto scan level `usize` (binning.cu).
    ScanAdd(usize),
    /// `kantele_bin_fill` (binning.cu).
    BinFill,
    /// `kantele_bin_ranges` (binning.cu).
    BinRanges,
    /// `kantele_raster` (raster.cu).
    Raster,
    /// `kantele_resolve_rgba8` (resolve.cu).
    Resolve,
}

/// One step of a frame, in stream order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// Zero the status words.
    ZeroStatus,
    /// Zero the binning count matrix.
    ZeroCounts,
    /// Launch a kernel on a 1-D grid of `blocks` × `threads`.
    Launch {
        /// Which kernel.
        kernel: Kernel,
        /// Blocks in the grid (never 0: launches with no work are left out).
        blocks: u32,
        /// Threads per block.
        threads: u32,
    },
    /// Record the event that ends a stage (for per-stage GPU times).
    Mark(Stage),
}

/// The stages timed with events.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Vertex and primitive stages.
    Geometry,
    /// Binning.
    Binning,
    /// Fine raster (and the resolve when asked for).
    Raster,
}

fn launch(kernel: Kernel, items: u64, threads: u32) -> Option<Step> {
    let blocks = items.div_ceil(threads as u64);
    (blocks > 0).then_some(Step::Launch {
        kernel,
        blocks: blocks.min(u32::MAX as u64) as u32,
        threads,
    })
}

/// The launches of one tiled frame: the same for every frame of a scene at one size. No step
/// needs a value from the host, so the whole frame is queued at once and read back at the end.
pub fn tiled_frame(shape: &FrameShape, resolve_rgba8: bool) -> Vec<Step> {
    let mut steps = vec![Step::ZeroStatus, Step::ZeroCounts];
    steps.extend(launch(Kernel::DrawMatrices, shape.draws as u64, THREADS));
    steps.extend(launch(Kernel::Vertex, shape.shaded as u64, THREADS));
    steps.extend(launch(Kernel::Primitive, shape.slots as u64, THREADS));
    steps.push(Step::Mark(Stage::Geometry));
    // One warp (32 threads) per chunk.
    let warp_threads = shape.chunks() as u64 * 32;
    steps.extend(launch(Kernel::BinCount, warp_threads, THREADS));
    let levels = scan_levels(shape.matrix_cells());
    for (level, &n) in levels.iter().enumerate() {
        steps.extend(launch(Kernel::ScanBlocks(level), n, SCAN_THREADS));
    }
    for level in (0..levels.len().saturating_sub(1)).rev() {
        steps.extend(launch(Kernel::ScanAdd(level), levels[level], SCAN_THREADS));
    }
    // The ranges read the scanned offsets before the fill advances them as its cursors
    // (after the fill, tile t's first entry would read as tile t + 1's).
    steps.extend(launch(Kernel::BinRanges, shape.tiles() as u64 + 1, THREADS));
    steps.extend(launch(Kernel::BinFill, warp_threads, THREADS));
    steps.push(Step::Mark(Stage::Binning));
    // One block per tile.
    steps.extend(launch(
        Kernel::Raster,
        shape.tiles() as u64 * RASTER_THREADS as u64,
        RASTER_THREADS,
    ));
    if resolve_rgba8 {
        steps.extend(launch(
            Kernel::Resolve,
            shape.width as u64 * shape.height as u64,
            THREADS,
        ));
    }
    steps.push(Step::Mark(Stage::Raster));
    steps
}

/// The CUDA backend's ways of rasterizing.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum CudaStrategy {
    /// The full pipeline: binning into 64 × 64 tiles, one thread block per tile.
    #[default]
    Tiled,
    /// The thesis' "one call, one triangle": a launch per triangle over its bounding box.
    Ocot,
    /// The thesis' "one call, many triangles": a launch per batch over 16 × 16 blocks.
    Ocmt,
}

impl CudaStrategy {
    /// Every strategy.
    pub const ALL: [CudaStrategy; 3] =
        [CudaStrategy::Tiled, CudaStrategy::Ocot, CudaStrategy::Ocmt];

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            CudaStrategy::Tiled => "tiled",
            CudaStrategy::Ocot => "ocot",
            CudaStrategy::Ocmt => "ocmt",
        }
    }
}

impl std::fmt::Display for CudaStrategy {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for CudaStrategy {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| format!("unknown CUDA strategy '{s}' (expected tiled, ocot or ocmt)"))
    }
}

/// Grid (x, y) of 16 × 16 blocks covering `width × height` pixels.
pub fn baseline_grid(width: u32, height: u32) -> (u32, u32) {
    (
        width.div_ceil(BASELINE_BLOCK),
        height.div_ceil(BASELINE_BLOCK),
    )
}

/// The "one call, many triangles" batches of `triangles` ordered setups: `(first, count)`.
pub fn ocmt_batches(triangles: u32) -> Vec<(u32, u32)> {
    (0..triangles.div_ceil(OCMT_BATCH))
        .map(|b| {
            let first = b * OCMT_BATCH;
            (first, OCMT_BATCH.min(triangles - first))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shape(width: u32, height: u32, slots: u32) -> FrameShape {
        FrameShape {
            width,
            height,
            draws: 3,
            shaded: slots * 2,
            slots,
        }
    }

    #[test]
    fn tiles_and_chunks_round_up() {
        let s = shape(1920, 1080, 268_000);
        assert_eq!((s.tiles_x(), s.tiles_y(), s.tiles()), (30, 17, 510));
        assert_eq!(s.chunks(), 268_000u32.div_ceil(BIN_CHUNK));
        assert_eq!(shape(64, 64, 0).tiles(), 1);
        assert_eq!(shape(65, 1, 0).tiles(), 2);
        assert_eq!(shape(65, 1, 0).chunks(), 0);
    }

    #[test]
    fn scan_levels_reduce_to_one_block() {
        assert!(scan_levels(0).is_empty());
        assert_eq!(scan_levels(1), vec![1]);
        assert_eq!(scan_levels(1024), vec![1024]);
        assert_eq!(scan_levels(1025), vec![1025, 2]);
        assert_eq!(scan_levels(510 * 1047), vec![533_970, 522]);
        assert_eq!(scan_levels(1 << 21), vec![1 << 21, 2048, 2]);
        for n in [1u64, 5000, 3_000_000] {
            let levels = scan_levels(n);
            assert!(*levels.last().expect("a level") <= SCAN_THREADS as u64);
        }
    }

    #[test]
    fn capacities_grow_past_the_need_and_stop_at_the_limit() {
        let s = shape(800, 600, 10_000);
        let c = Capacities::initial(&s);
        assert!(c.fits(&Needs {
            clip: 10,
            bins: 100
        }));
        let needs = Needs {
            clip: c.clip as u64 + 1,
            bins: 10,
        };
        assert!(!c.fits(&needs));
        let g = c.grown(&needs, s.slots).expect("grows");
        assert!(g.fits(&needs));
        assert_eq!(g.bins, c.bins, "only the overflowed buffer grows");
        assert_eq!(g.clip as u64, needs.clip + needs.clip / 2);
        let huge = Needs {
            clip: 0,
            bins: MAX_CAPACITY + 1,
        };
        let err = c.grown(&huge, s.slots).expect_err("too large");
        assert!(err.contains("bin entries"), "{err}");
    }

    #[test]
    fn a_frame_is_a_fixed_sequence_covering_all_work() {
        let s = shape(1920, 1080, 100_000);
        let steps = tiled_frame(&s, false);
        assert_eq!(steps, tiled_frame(&s, false), "deterministic");
        let blocks = |k: Kernel| {
            steps.iter().find_map(|st| match st {
                Step::Launch {
                    kernel,
                    blocks,
                    threads,
                } if *kernel == k => Some((*blocks, *threads)),
                _ => None,
            })
        };
        let (b, t) = blocks(Kernel::Primitive).expect("primitive");
        assert!(b * t >= s.slots && (b - 1) * t < s.slots);
        let (b, t) = blocks(Kernel::BinCount).expect("bin count");
        assert!(b * (t / 32) >= s.chunks());
        assert_eq!(blocks(Kernel::Raster), Some((s.tiles(), RASTER_THREADS)));
        let (b, t) = blocks(Kernel::BinRanges).expect("ranges");
        assert!(b * t > s.tiles());
        assert_eq!(blocks(Kernel::Resolve), None);
        assert!(tiled_frame(&s, true).iter().any(|st| matches!(
            st,
            Step::Launch {
                kernel: Kernel::Resolve,
                ..
            }
        )));
        // Stage order: geometry, then the scans up and down, then fill, ranges, raster.
        let order: Vec<Kernel> = steps
            .iter()
            .filter_map(|st| match st {
                Step::Launch { kernel, .. } => Some(*kernel),
                _ => None,
            })
            .collect();
        assert_eq!(
            order,
            vec![
                Kernel::DrawMatrices,
                Kernel::Vertex,
                Kernel::Primitive,
                Kernel::BinCount,
                Kernel::ScanBlocks(0),
                Kernel::ScanBlocks(1),
                Kernel::ScanAdd(0),
                Kernel::BinRanges,
                Kernel::BinFill,
                Kernel::Raster,
            ]
        );
    }

    #[test]
    fn an_empty_scene_still_clears_every_tile() {
        let s = FrameShape {
            width: 100,
            height: 70,
            draws: 0,
            shaded: 0,
            slots: 0,
        };
        let steps = tiled_frame(&s, false);
        let kernels: Vec<Kernel> = steps
            .iter()
            .filter_map(|st| match st {
                Step::Launch { kernel, .. } => Some(*kernel),
                _ => None,
            })
            .collect();
        assert_eq!(kernels, vec![Kernel::BinRanges, Kernel::Raster]);
    }

    #[test]
    fn strategies_parse_and_batches_cover_every_triangle() {
        for k in CudaStrategy::ALL {
            assert_eq!(k.name().parse::<CudaStrategy>(), Ok(k));
        }
        assert!("bisector".parse::<CudaStrategy>().is_err());
        assert!(ocmt_batches(0).is_empty());
        let b = ocmt_batches(2 * OCMT_BATCH + 5);
        assert_eq!(b.len(), 3);
        assert_eq!(b[2], (2 * OCMT_BATCH, 5));
        assert_eq!(b.iter().map(|x| x.1).sum::<u32>(), 2 * OCMT_BATCH + 5);
        assert_eq!(baseline_grid(17, 16), (2, 1));
    }
}
