//! Per-stage counters and timings of one frame.

use std::time::Duration;

/// What each stage of a frame did. Counters are exact; times are wall-clock per stage.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameStats {
    /// Draw calls executed.
    pub draws: u64,
    /// Triangles submitted (index count / 3 over all draws).
    pub triangles_in: u64,
    /// Triangles dropped because a vertex was NaN or infinite.
    pub triangles_invalid: u64,
    /// Triangles wholly outside one clip plane (trivial reject).
    pub triangles_rejected: u64,
    /// Triangles that crossed the near plane or the guard band and went through the clipper.
    pub triangles_clipped: u64,
    /// Triangles removed by face culling.
    pub triangles_culled: u64,
    /// Triangles (after clipping) with zero area in fixed point, or covering no pixel centre box.
    pub triangles_degenerate: u64,
    /// Triangles handed to binning (after clipping, culling, degenerate removal).
    pub triangles_binned: u64,
    /// Triangle references written to tile bins (a triangle counts once per tile it touches).
    pub bin_entries: u64,
    /// Triangle–tile pairs skipped because the triangle lay behind everything already in the
    /// tile (LESS / LEQUAL depth test); their pixels are not counted below.
    pub tiles_depth_rejected: u64,
    /// Covered 8 × 8 blocks skipped because every depth stored in the block lay in front of the
    /// triangle (the block level of the depth hierarchy); their pixels are not counted below.
    pub blocks_depth_rejected: u64,
    /// Pixels covered by triangles (coverage before depth test), outside rejected tiles.
    pub fragments_covered: u64,
    /// Fragments that reached the fragment shader (after the early depth test).
    pub fragments_shaded: u64,
    /// Fragments the shader discarded.
    pub fragments_discarded: u64,
    /// Time in vertex shading, primitive assembly, clipping, culling and setup.
    pub geometry_time: Duration,
    /// Time sorting triangles into tile bins.
    pub binning_time: Duration,
    /// Time rasterizing, shading and merging on all tiles (wall clock).
    pub raster_time: Duration,
    /// Whole frame, wall clock.
    pub total_time: Duration,
}
