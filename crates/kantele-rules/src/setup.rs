//! Triangle setup: viewport transform, snapping to the sub-pixel grid, orientation and face
//! culling, integer edge functions with the top-left fill rule folded in as a bias, and the
//! data the fragment stage needs for perspective-correct interpolation.
//!
//! Takes three clip-space positions (already clipped to the near plane and guard band) and
//! hands a [`TriangleSetup`] to binning and traversal. The record is plain old data
//! (`#[repr(C)]`, no pointers) so a GPU backend can consume the same layout.

use glam::Vec4;

use crate::fixed::{pixel_center, snap, SUBPIXEL_ONE};
pub use crate::state::{CullMode, FrontFace};

/// A half-open rectangle of pixels `[x0, x1) × [y0, y1)`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct PixelRect {
    /// First column.
    pub x0: i32,
    /// First row.
    pub y0: i32,
    /// One past the last column.
    pub x1: i32,
    /// One past the last row.
    pub y1: i32,
}

impl PixelRect {
    /// Whether the rectangle holds no pixel.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.x0 >= self.x1 || self.y0 >= self.y1
    }

    /// The overlap of two rectangles (possibly empty).
    #[inline]
    pub fn intersect(&self, other: &PixelRect) -> PixelRect {
        PixelRect {
            x0: self.x0.max(other.x0),
            y0: self.y0.max(other.y0),
            x1: self.x1.min(other.x1),
            y1: self.y1.min(other.y1),
        }
    }

    /// Width in pixels (0 when empty).
    #[inline]
    pub fn width(&self) -> i32 {
        (self.x1 - self.x0).max(0)
    }

    /// Height in pixels (0 when empty).
    #[inline]
    pub fn height(&self) -> i32 {
        (self.y1 - self.y0).max(0)
    }
}

/// An integer edge function `E(x, y) = a·x + b·y + c` over sub-pixel coordinates, positive
/// inside the triangle. `bias` is 0 for top and left edges and −1 otherwise, so that a sample is
/// covered exactly when `E + bias ≥ 0` (the top-left rule without a per-pixel branch).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct EdgeFunction {
    /// Coefficient of x (= y_from − y_to), sub-pixel units.
    pub a: i64,
    /// Coefficient of y (= x_to − x_from), sub-pixel units.
    pub b: i64,
    /// Constant term, sub-pixel units squared.
    pub c: i64,
    /// Fill-rule bias: 0 or −1.
    pub bias: i64,
}

impl EdgeFunction {
    /// The edge from `p` to `q` (sub-pixel coordinates), inside to its right in image
    /// coordinates (y down), for triangles with positive [`TriangleSetup::area2`].
    fn new(p: (i64, i64), q: (i64, i64)) -> Self {
        let a = p.1 - q.1;
        let b = q.0 - p.0;
        let c = -(a * p.0 + b * p.1);
        // With y down and positive area, a top edge runs exactly horizontally to the right
        // (a == 0, b > 0) and a left edge runs upwards (a > 0).
        let top_left = a > 0 || (a == 0 && b > 0);
        #[cfg(feature = "fault-injection")]
        let top_left = top_left != crate::fault::active(crate::fault::Fault::FillRule);
        Self {
            a,
            b,
            c,
            bias: if top_left { 0 } else { -1 },
        }
    }

    /// The unbiased value at the centre of pixel `(x, y)`.
    #[inline]
    pub fn at_pixel(&self, x: i32, y: i32) -> i64 {
        self.a * pixel_center(x as i64) + self.b * pixel_center(y as i64) + self.c
    }

    /// The biased value at the centre of pixel `(x, y)`: covered when `≥ 0`.
    #[inline]
    pub fn biased_at_pixel(&self, x: i32, y: i32) -> i64 {
        self.at_pixel(x, y) + self.bias
    }

    /// Change of the value per pixel step in x.
    #[inline]
    pub fn step_x(&self) -> i64 {
        self.a * SUBPIXEL_ONE
    }

    /// Change of the value per pixel step in y.
    #[inline]
    pub fn step_y(&self) -> i64 {
        self.b * SUBPIXEL_ONE
    }
}

/// Everything traversal and fragment processing need about one triangle.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct TriangleSetup {
    /// Edge functions; edge `i` is opposite vertex `i`, so `λ_i = E_i / area2`.
    pub edges: [EdgeFunction; 3],
    /// Twice the signed area in sub-pixel units squared (> 0 after orientation).
    pub area2: i64,
    /// Pixels whose centres (on a multisampled target: whose samples) may be covered, clamped
    /// to the target.
    pub bbox: PixelRect,
    /// Snapped vertex positions (sub-pixel units), after orientation.
    pub pos_subpixel: [[i64; 2]; 3],
    /// Window depth `(z/w + 1) / 2` of each vertex.
    pub depth: [f32; 3],
    /// Smallest and largest vertex depth: interpolated depth is clamped to this range (the
    /// exact value always lies in it; `f32` barycentrics of slivers can stray a little).
    pub depth_range: [f32; 2],
    /// `1 / w_clip` of each vertex.
    pub inv_w: [f32; 3],
    /// `(a_i, b_i) / area2` for edges 1 and 2: `λ_i` at a sample `d` sub-pixel units from
    /// vertex 0 is `g_i · d` (edges 1 and 2 pass through vertex 0, so there is no constant).
    pub bary_gradient: [[f32; 2]; 2],
    /// Index of the draw in the frame.
    pub draw: u32,
    /// Index of the source triangle within its draw.
    pub primitive_id: u32,
    /// Bit set of [`TriangleSetup::FRONT_FACING`] and [`TriangleSetup::SWAPPED`] (a `u32`, not
    /// `bool`s, so a GPU reads the same bytes; other bits are 0).
    pub flags: u32,
    /// Always 0: makes the record's end explicit (no compiler padding; the size is a multiple
    /// of 8 for the `i64` fields).
    pub reserved: u32,
}

/// The record's size and field offsets, fixed: the CUDA backend's kernels mirror them
/// (`kantele-cuda/kernels/common.cuh`, checked again on the device at start-up).
const _: () = {
    use std::mem::{offset_of, size_of};
    type T = TriangleSetup;
    assert!(size_of::<EdgeFunction>() == 32);
    assert!(size_of::<PixelRect>() == 16);
    assert!(offset_of!(T, edges) == 0);
    assert!(offset_of!(T, area2) == 96);
    assert!(offset_of!(T, bbox) == 104);
    assert!(offset_of!(T, pos_subpixel) == 120);
    assert!(offset_of!(T, depth) == 168);
    assert!(offset_of!(T, depth_range) == 180);
    assert!(offset_of!(T, inv_w) == 188);
    assert!(offset_of!(T, bary_gradient) == 200);
    assert!(offset_of!(T, draw) == 216);
    assert!(offset_of!(T, primitive_id) == 220);
    assert!(offset_of!(T, flags) == 224);
    assert!(offset_of!(T, reserved) == 228);
    assert!(size_of::<T>() == 232);
};

/// Why setup produced no triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SetupReject {
    /// Removed by face culling.
    Culled,
    /// Zero area after snapping, no pixel centre inside its box on the target, or (1×) none
    /// of the few centres in a small box covered.
    Degenerate,
}

/// Maps clip space to window coordinates for a `width × height` target (row 0 at the top).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Viewport {
    half_width: f32,
    half_height: f32,
    /// Target width in pixels.
    pub width: u32,
    /// Target height in pixels.
    pub height: u32,
    /// How far (sub-pixel units) the samples of a multisampled target lie from their pixel
    /// centre at most: a triangle's pixel box reaches that much further (0 at 1×).
    sample_reach: i64,
}

impl Viewport {
    /// The viewport covering a whole `width × height` target.
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            half_width: width as f32 * 0.5,
            half_height: height as f32 * 0.5,
            width,
            height,
            sample_reach: 0,
        }
    }

    /// The same viewport for a target with `samples` samples per pixel: triangles' pixel boxes
    /// then hold every pixel one of whose samples they may cover, and a triangle that covers a
    /// sample but no pixel centre is kept.
    pub fn with_samples(self, samples: crate::multisample::SampleCount) -> Self {
        Self {
            sample_reach: samples.reach_subpixel(),
            ..self
        }
    }

    /// Window coordinates `(x, y, depth)` and `1/w` of a clip-space position with `w > 0`.
    /// `x = x_ndc·W/2 + W/2` and `y = −y_ndc·H/2 + H/2` (the image's top row is NDC y = +1).
    #[inline]
    pub fn to_window(&self, pos_clip: Vec4) -> ([f32; 3], f32) {
        let inv_w = 1.0 / pos_clip.w;
        let x_ndc = pos_clip.x * inv_w;
        let y_ndc = pos_clip.y * inv_w;
        let z_ndc = pos_clip.z * inv_w;
        (
            [
                x_ndc * self.half_width + self.half_width,
                -y_ndc * self.half_height + self.half_height,
                z_ndc * 0.5 + 0.5,
            ],
            inv_w,
        )
    }

    /// The whole target as a pixel rectangle.
    #[inline]
    pub fn rect(&self) -> PixelRect {
        PixelRect {
            x0: 0,
            y0: 0,
            x1: self.width as i32,
            y1: self.height as i32,
        }
    }
}

/// One vertex in window space, as setup reads it: snapped sub-pixel position, window depth and
/// `1 / w_clip`. Computed once per vertex ([`Viewport::window_vertex`]) and shared by every
/// triangle that uses the vertex.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct WindowVertex {
    /// Snapped position in sub-pixel units ([`snap`]: within ±`SUBPIXEL_LIMIT`).
    pub pos: [i32; 2],
    /// Window depth `(z/w + 1) / 2`.
    pub depth: f32,
    /// `1 / w_clip`.
    pub inv_w: f32,
}

impl Viewport {
    /// The window-space vertex of a clip-space position (meaningful for `w > 0` inside the
    /// guard band; any input gives a defined value).
    #[inline]
    pub fn window_vertex(&self, pos_clip: Vec4) -> WindowVertex {
        let (window, inv_w) = self.to_window(pos_clip);
        WindowVertex::snapped(window, inv_w)
    }
}

impl WindowVertex {
    /// The vertex at window coordinates `(x, y, depth)` with `1/w = inv_w`, its position snapped
    /// to the sub-pixel grid (points and lines are expanded into triangles in window space,
    /// `geometry::wide`).
    #[inline]
    pub fn snapped(window: [f32; 3], inv_w: f32) -> Self {
        // `snap` clamps to ±SUBPIXEL_LIMIT = ±2^24: the value fits an `i32`.
        WindowVertex {
            pos: [snap(window[0]) as i32, snap(window[1]) as i32],
            depth: window[2],
            inv_w,
        }
    }
}

/// Sets up one triangle from clip-space positions (each with `w > 0`, inside the guard band).
pub fn setup_triangle(
    viewport: &Viewport,
    pos_clip: [Vec4; 3],
    cull: CullMode,
    front_face: FrontFace,
) -> Result<TriangleSetup, SetupReject> {
    let window = [
        viewport.window_vertex(pos_clip[0]),
        viewport.window_vertex(pos_clip[1]),
        viewport.window_vertex(pos_clip[2]),
    ];
    setup_window_triangle(viewport, window, cull, front_face)
}

/// Whether the three edges of a triangle cover the centre of pixel `(x, y)` (top-left rule
/// included): [`TriangleSetup::covers`], before the record exists.
#[inline]
fn edges_cover(edges: &[EdgeFunction; 3], x: i32, y: i32) -> bool {
    edges.iter().all(|e| e.biased_at_pixel(x, y) >= 0)
}

/// Pixel centres in a triangle's box, at most, for which setup tests each centre's coverage and
/// drops a triangle that covers none (see [`setup_window_triangle`]; the CUDA kernels' setup
/// applies the same rule).
pub const SMALL_BOX_PIXELS: i64 = 4;

/// Sets up one triangle from its window-space vertices ([`Viewport::window_vertex`] of positions
/// with `w > 0` inside the guard band): the same record as [`setup_triangle`].
///
/// Always inlined: the primitive stage calls it once per triangle, and as a call it returned
/// the record (over 200 bytes) through memory, to be copied again into the batch.
#[inline(always)]
pub fn setup_window_triangle(
    viewport: &Viewport,
    window: [WindowVertex; 3],
    cull: CullMode,
    front_face: FrontFace,
) -> Result<TriangleSetup, SetupReject> {
    let [v0, mut v1, mut v2] = window;
    let area = |v0: &WindowVertex, v1: &WindowVertex, v2: &WindowVertex| {
        let p0 = [v0.pos[0] as i64, v0.pos[1] as i64];
        (v1.pos[0] as i64 - p0[0]) * (v2.pos[1] as i64 - p0[1])
            - (v2.pos[0] as i64 - p0[0]) * (v1.pos[1] as i64 - p0[1])
    };
    let mut area2 = area(&v0, &v1, &v2);
    if area2 == 0 {
        return Err(SetupReject::Degenerate);
    }
    // Window y points down, so a counter-clockwise triangle in NDC has negative area here.
    let ccw = area2 < 0;
    let front_facing = match front_face {
        FrontFace::Ccw => ccw,
        FrontFace::Cw => !ccw,
    };
    match (cull, front_facing) {
        (CullMode::Back, false) | (CullMode::Front, true) => return Err(SetupReject::Culled),
        _ => {}
    }
    let swapped = area2 < 0;
    if swapped {
        std::mem::swap(&mut v1, &mut v2);
        area2 = -area2;
    }
    let v = [v0, v1, v2];
    let pos: [[i64; 2]; 3] = v.map(|v| [v.pos[0] as i64, v.pos[1] as i64]);
    let p = |i: usize| (pos[i][0], pos[i][1]);
    let edges = [
        EdgeFunction::new(p(1), p(2)),
        EdgeFunction::new(p(2), p(0)),
        EdgeFunction::new(p(0), p(1)),
    ];
    // Pixel x is a candidate when its centre x·256 + 128 lies within [min, max] (widened by
    // the sample reach of a multisampled target); an arithmetic shift is the floor division
    // by 256.
    let reach = viewport.sample_reach;
    let min_x = pos[0][0].min(pos[1][0]).min(pos[2][0]) - reach;
    let max_x = pos[0][0].max(pos[1][0]).max(pos[2][0]) + reach;
    let min_y = pos[0][1].min(pos[1][1]).min(pos[2][1]) - reach;
    let max_y = pos[0][1].max(pos[1][1]).max(pos[2][1]) + reach;
    let half = crate::fixed::SUBPIXEL_HALF;
    let bits = crate::fixed::SUBPIXEL_BITS;
    let first = |min: i64| (min - half + SUBPIXEL_ONE - 1) >> bits;
    let last = |max: i64| (max - half) >> bits;
    let bbox = PixelRect {
        x0: first(min_x) as i32,
        y0: first(min_y) as i32,
        x1: last(max_x) as i32 + 1,
        y1: last(max_y) as i32 + 1,
    }
    .intersect(&viewport.rect());
    if bbox.is_empty() {
        return Err(SetupReject::Degenerate);
    }
    // A triangle whose box holds only a few pixel centres, none of them covered, draws nothing
    // (1×; under multisampling the box reaches further than the centres). A far mesh has many
    // such triangles; dropped here, each costs no setup record, no bin entry and no raster
    // call. The test is the rasterizer's own (`TriangleSetup::covers`).
    if reach == 0 && i64::from(bbox.width()) * i64::from(bbox.height()) <= SMALL_BOX_PIXELS {
        let covered =
            (bbox.y0..bbox.y1).any(|y| (bbox.x0..bbox.x1).any(|x| edges_cover(&edges, x, y)));
        if !covered {
            return Err(SetupReject::Degenerate);
        }
    }
    let depth = [v0.depth, v1.depth, v2.depth];
    let area_f = area2 as f32;
    Ok(TriangleSetup {
        edges,
        area2,
        bbox,
        pos_subpixel: pos,
        depth_range: [
            depth[0].min(depth[1]).min(depth[2]),
            depth[0].max(depth[1]).max(depth[2]),
        ],
        depth,
        inv_w: [v0.inv_w, v1.inv_w, v2.inv_w],
        bary_gradient: [
            [edges[1].a as f32 / area_f, edges[1].b as f32 / area_f],
            [edges[2].a as f32 / area_f, edges[2].b as f32 / area_f],
        ],
        draw: 0,
        primitive_id: 0,
        flags: (front_facing as u32 * TriangleSetup::FRONT_FACING)
            | (swapped as u32 * TriangleSetup::SWAPPED),
        reserved: 0,
    })
}

impl TriangleSetup {
    /// [`TriangleSetup::flags`] bit: the triangle is front-facing.
    pub const FRONT_FACING: u32 = 1;
    /// [`TriangleSetup::flags`] bit: vertices 1 and 2 were swapped to make the area positive
    /// (varyings follow).
    pub const SWAPPED: u32 = 2;

    /// Whether the triangle is front-facing.
    #[inline]
    pub fn front_facing(&self) -> bool {
        self.flags & Self::FRONT_FACING != 0
    }

    /// Whether vertices 1 and 2 were swapped to make the area positive (varyings follow).
    #[inline]
    pub fn swapped(&self) -> bool {
        self.flags & Self::SWAPPED != 0
    }

    /// Whether the centre of pixel `(x, y)` is covered (top-left rule included).
    #[inline]
    pub fn covers(&self, x: i32, y: i32) -> bool {
        edges_cover(&self.edges, x, y)
    }

    /// Screen-space barycentric weights `λ_i = E_i / area2` at the centre of pixel `(x, y)`,
    /// evaluated from scratch in a fixed order of `f32` operations (no accumulated stepping, no
    /// fused multiply-add), so every traversal and every backend gets the same bits:
    /// `d = centre − vertex 0` (exact), `λ1 = g1·d`, `λ2 = g2·d`, `λ0 = 1 − λ1 − λ2`.
    #[inline]
    pub fn barycentrics(&self, x: i32, y: i32) -> [f32; 3] {
        let dx = (pixel_center(x as i64) - self.pos_subpixel[0][0]) as f32;
        let dy = (pixel_center(y as i64) - self.pos_subpixel[0][1]) as f32;
        let g = &self.bary_gradient;
        let l1 = g[0][0] * dx + g[0][1] * dy;
        let l2 = g[1][0] * dx + g[1][1] * dy;
        [1.0 - l1 - l2, l1, l2]
    }

    /// Window depth at the given barycentrics (affine in screen space), clamped to the
    /// vertices' depth range.
    #[inline]
    pub fn depth_at(&self, bary: &[f32; 3]) -> f32 {
        let z = bary[0] * self.depth[0] + bary[1] * self.depth[1] + bary[2] * self.depth[2];
        z.max(self.depth_range[0]).min(self.depth_range[1])
    }

    /// Per-pixel derivatives of the screen-space barycentrics: `(dλ/dx, dλ/dy)`, those of the
    /// values [`TriangleSetup::barycentrics`] computes (`λ0 = 1 − λ1 − λ2`).
    #[inline]
    pub fn barycentric_gradients(&self) -> ([f32; 3], [f32; 3]) {
        let one = SUBPIXEL_ONE as f32; // one pixel in sub-pixel units
        let g = &self.bary_gradient;
        let (dx1, dx2) = (g[0][0] * one, g[1][0] * one);
        let (dy1, dy2) = (g[0][1] * one, g[1][1] * one);
        ([-(dx1 + dx2), dx1, dx2], [-(dy1 + dy2), dy1, dy2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ndc(x: f32, y: f32) -> Vec4 {
        Vec4::new(x, y, 0.0, 1.0)
    }

    #[test]
    fn ccw_triangle_is_front_facing_and_cw_is_culled() {
        let vp = Viewport::new(16, 16);
        let ccw = [ndc(-0.5, -0.5), ndc(0.5, -0.5), ndc(0.0, 0.5)];
        let t = setup_triangle(&vp, ccw, CullMode::Back, FrontFace::Ccw).expect("front face");
        assert!(t.front_facing());
        // Counter-clockwise in NDC is clockwise with window y down: set up swapped.
        assert!(t.swapped());
        assert!(t.area2 > 0);
        let cw = [ccw[0], ccw[2], ccw[1]];
        assert_eq!(
            setup_triangle(&vp, cw, CullMode::Back, FrontFace::Ccw),
            Err(SetupReject::Culled)
        );
        let back = setup_triangle(&vp, cw, CullMode::None, FrontFace::Ccw).expect("not culled");
        assert!(!back.front_facing());
        assert!(!back.swapped());
        assert_eq!(back.flags, 0);
        assert_eq!(
            setup_triangle(&vp, ccw, CullMode::Front, FrontFace::Ccw),
            Err(SetupReject::Culled)
        );
    }

    #[test]
    fn barycentrics_sum_to_one_and_are_one_at_vertices() {
        let vp = Viewport::new(64, 64);
        let t = setup_triangle(
            &vp,
            [ndc(-1.0, -1.0), ndc(1.0, -1.0), ndc(-1.0, 1.0)],
            CullMode::None,
            FrontFace::Ccw,
        )
        .expect("valid");
        let b = t.barycentrics(10, 20);
        assert!((b.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        for (i, v) in t.pos_subpixel.iter().enumerate() {
            let e = t.edges[i];
            let value = e.a * v[0] + e.b * v[1] + e.c;
            assert_eq!(value, t.area2);
        }
    }

    #[test]
    fn zero_area_is_degenerate() {
        let vp = Viewport::new(16, 16);
        let line = [ndc(-0.5, -0.5), ndc(0.0, 0.0), ndc(0.5, 0.5)];
        assert_eq!(
            setup_triangle(&vp, line, CullMode::None, FrontFace::Ccw),
            Err(SetupReject::Degenerate)
        );
    }

    /// Setup drops a small triangle exactly when it covers no pixel centre: checked against the
    /// same triangle set up for a 4× target, whose box reaches further so nothing is dropped,
    /// over every small triangle with vertices on a quarter-pixel grid near a few centres.
    #[test]
    fn small_triangles_are_dropped_exactly_when_they_cover_no_centre() {
        let one = Viewport::new(8, 8);
        let four = one.with_samples(crate::multisample::SampleCount::X4);
        let vertex = |k: u32| -> WindowVertex {
            // 0..=8 quarter pixels from (2.25, 2.25) in x and y.
            let (x, y) = (2.25 + 0.25 * (k % 9) as f32, 2.25 + 0.25 * (k / 9) as f32);
            WindowVertex::snapped([x, y, 0.5], 1.0)
        };
        let (mut dropped, mut kept_small) = (0, 0);
        for a in 0..81 {
            for b in 0..81 {
                for c in (0..81).step_by(7) {
                    let window = [vertex(a), vertex(b), vertex(c)];
                    let reference =
                        setup_window_triangle(&four, window, CullMode::None, FrontFace::Ccw);
                    let result =
                        setup_window_triangle(&one, window, CullMode::None, FrontFace::Ccw);
                    let Ok(reference) = reference else {
                        assert_eq!(result, reference, "{a} {b} {c}");
                        continue;
                    };
                    let covered = (reference.bbox.y0..reference.bbox.y1)
                        .flat_map(|y| (reference.bbox.x0..reference.bbox.x1).map(move |x| (x, y)))
                        .filter(|&(x, y)| reference.covers(x, y))
                        .count();
                    match result {
                        Ok(t) => {
                            let area = i64::from(t.bbox.width() * t.bbox.height());
                            assert!(covered > 0 || area > SMALL_BOX_PIXELS);
                            let with_reach = TriangleSetup {
                                bbox: reference.bbox,
                                ..t
                            };
                            assert_eq!(with_reach, reference, "{a} {b} {c}");
                            kept_small += (area <= SMALL_BOX_PIXELS) as u32;
                        }
                        Err(reject) => {
                            assert_eq!(reject, SetupReject::Degenerate, "{a} {b} {c}");
                            assert_eq!(covered, 0, "{a} {b} {c}: dropped, covers {covered}");
                            dropped += 1;
                        }
                    }
                }
            }
        }
        // Both outcomes occur.
        assert!(
            dropped > 100 && kept_small > 100,
            "{dropped} dropped, {kept_small} kept"
        );
    }

    #[test]
    fn top_left_rule_on_a_pixel_aligned_square() {
        // Square [2, 6) × [2, 6) in pixels, split along the diagonal: the pixel centres on the
        // right and bottom boundaries are not covered, those on the left and top are.
        let vp = Viewport::new(8, 8);
        let to_ndc = |x: f32, y: f32| ndc(x / 4.0 - 1.0, 1.0 - y / 4.0);
        let a = to_ndc(2.5, 2.5);
        let b = to_ndc(6.5, 2.5);
        let c = to_ndc(6.5, 6.5);
        let d = to_ndc(2.5, 6.5);
        let t1 = setup_triangle(&vp, [a, d, c], CullMode::None, FrontFace::Ccw).expect("t1");
        let t2 = setup_triangle(&vp, [a, c, b], CullMode::None, FrontFace::Ccw).expect("t2");
        for y in 0..8 {
            for x in 0..8 {
                let n = t1.covers(x, y) as u32 + t2.covers(x, y) as u32;
                let inside = (2..6).contains(&x) && (2..6).contains(&y);
                assert_eq!(n, inside as u32, "pixel ({x}, {y})");
            }
        }
    }
}
