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
    /// Colour channels of written fragments that were NaN (from the fragment shader, or from
    /// blending infinities) and were written as 0 instead.
    pub nan_color_channels: u64,
    /// The picture came out empty (no pixel covered) although triangles were submitted that
    /// were neither invalid nor wholly outside the view volume: a warning worth printing
    /// (everything culled, degenerate, clipped away or rejected by depth is legal, but rarely
    /// meant). See [`FrameStats::empty_picture_warning`].
    pub empty_picture: bool,
    /// Why the frame stopped before drawing everything, if it did (its budget ran out or the
    /// caller cancelled it; the picture is then partly drawn).
    pub stopped: Option<FrameStop>,
    /// Time in vertex shading, primitive assembly, clipping, culling and setup.
    pub geometry_time: Duration,
    /// Time sorting triangles into tile bins.
    pub binning_time: Duration,
    /// Time rasterizing, shading and merging on all tiles (wall clock).
    pub raster_time: Duration,
    /// Whole frame, wall clock.
    pub total_time: Duration,
}

/// Why a frame stopped before drawing everything.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameStop {
    /// The caller raised the renderer's cancellation flag.
    Cancelled,
    /// The frame's time budget ran out.
    TimedOut {
        /// The budget it had.
        budget: Duration,
    },
}

impl FrameStats {
    /// Whether the picture came out empty although the frame had geometry inside the view
    /// volume; the one-line warning to print then (`None` when the picture is not empty, or
    /// when it is empty for an obvious reason: no triangles, all invalid or outside).
    pub fn empty_picture_warning(&self) -> Option<String> {
        self.empty_picture.then(|| {
            format!(
                "the picture is empty although {} of {} triangles lie inside the view volume \
                 ({} culled, {} degenerate or smaller than a pixel, {} hidden by depth)",
                self.triangles_in - self.triangles_invalid - self.triangles_rejected,
                self.triangles_in,
                self.triangles_culled,
                self.triangles_degenerate,
                self.tiles_depth_rejected + self.blocks_depth_rejected,
            )
        })
    }

    /// Whether the counters describe a picture that is empty although triangles inside the
    /// view volume were submitted (sets [`FrameStats::empty_picture`]).
    pub fn is_unexpectedly_empty(&self) -> bool {
        self.stopped.is_none()
            && self.fragments_covered == 0
            && self.triangles_in > self.triangles_invalid + self.triangles_rejected
    }
}
