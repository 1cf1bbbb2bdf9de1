//! Clipping in homogeneous clip space (before the divide by w).
//!
//! Only the planes that matter for correctness and safety are clipped: the near plane
//! `z ≥ −w`, a tiny positive `w` (so no division by `w ≤ 0` can happen even with unusual
//! projection matrices) and the guard band `|x|, |y| ≤ k·w`. The far plane and the sides inside
//! the guard band are left to the rasterizer (scissoring to the target and discarding depth
//! outside [0, 1]), which gives the same pictures with far fewer clipped triangles.
//!
//! # Precision at any scale
//!
//! - The `w` plane is relative: `w ≥ max(W_MIN, W_RELATIVE_EPSILON · w_max)`, where `w_max` is
//!   the largest `w` of the polygon after near clipping. A model of size 1e-9 (whose `w` is
//!   about 1e-9 everywhere) is therefore kept, as OpenGL keeps it, and the plane still cuts
//!   triangles that reach behind the eye at a `w` far below anything a sane near plane
//!   produces. [`W_MIN`] keeps `1/w` (and the sum of three of them) finite in `f32`.
//! - Intersections are computed in `f64` from the exact `f32` inputs: plane distances, the
//!   parameter `t` and the interpolated positions and varyings. A 1e6 ground plane cut at a
//!   near plane of 0.1 loses 24 bits to cancellation; `f32` had none to spare (its near edge
//!   moved by tens of pixels), `f64` keeps 29. Triangles reaching |x/w| ≈ 1e12 keep about 13
//!   bits after the guard-band cut, i.e. a hundredth of a pixel on ordinary targets.
//! - A clipped polygon is rounded back to `f32` only at the end; a vertex that would then have
//!   `w ≤ 0` or a non-finite coordinate drops the whole polygon (it cannot happen with the
//!   planes above, but the contract is *never* `w ≤ 0`).
//!
//! Triangles that need no clipping ([`ClipTest::Accept`]) never come here, so ordinary
//! geometry is set up from its unmodified vertex positions.

use glam::{DVec4, Vec3A, Vec4};

use crate::MAX_VARYINGS;

/// A vertex in clip space with its varyings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipVertex {
    /// Clip-space position.
    pub pos_clip: Vec4,
    /// Varyings; only the first `n` (the draw's varying count) are meaningful.
    pub varyings: [f32; MAX_VARYINGS],
}

/// A plane `dot(plane, pos_clip) ≥ 0` in clip space.
pub type ClipPlane = Vec4;

/// The near plane `z + w ≥ 0`.
pub const NEAR_PLANE: ClipPlane = Vec4::new(0.0, 0.0, 1.0, 1.0);

/// Smallest `w` a vertex handed to setup may have: `1/w` stays finite in `f32` (below
/// 2.2e37), and so does the sum of three such values in perspective-correct interpolation.
pub const W_MIN: f32 = 4.0 * f32::MIN_POSITIVE;

/// The smallest `w` of a vertex accepted without clipping: the old name of [`W_MIN`], kept for
/// mirrors of these rules (the CUDA kernels' `KANTELE_W_EPSILON`). The clip plane itself is
/// relative now (see the module docs).
pub const W_EPSILON: f32 = W_MIN;

/// The `w` plane of a polygon lies at `W_RELATIVE_EPSILON · w_max` (or [`W_MIN`] if larger),
/// `w_max` being the polygon's largest `w`: scale-free, and 2^-40 below anything a near plane
/// at a sane near/far ratio cuts.
pub const W_RELATIVE_EPSILON: f64 = 1.0 / (1u64 << 40) as f64;

/// Most vertices a triangle can have after clipping against all planes (3 + one per plane).
pub const MAX_CLIPPED_VERTICES: usize = 3 + 6;

/// Outcome codes of the trivial reject / accept test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClipTest {
    /// Wholly outside one frustum plane: draw nothing.
    Reject,
    /// Needs no clipping: inside the near plane, `w ≥ W_MIN`, and inside the guard band.
    Accept,
    /// Crosses the near plane or the guard band: clip.
    Clip,
}

/// The guard band for a target: clip-space planes `k_x·w ± x ≥ 0`, `k_y·w ± y ≥ 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GuardBand {
    /// `k_x` such that `x_ndc = ±k_x` is `GUARD_BAND_PIXELS` outside the target.
    pub k_x: f32,
    /// Same for y.
    pub k_y: f32,
}

impl GuardBand {
    /// The guard band for a `width × height` target.
    pub fn new(width: u32, height: u32) -> Self {
        let g = crate::fixed::GUARD_BAND_PIXELS;
        Self {
            k_x: 1.0 + 2.0 * g / width as f32,
            k_y: 1.0 + 2.0 * g / height as f32,
        }
    }

    fn planes(&self) -> [DVec4; 4] {
        let (k_x, k_y) = (self.k_x as f64, self.k_y as f64);
        [
            DVec4::new(-1.0, 0.0, 0.0, k_x),
            DVec4::new(1.0, 0.0, 0.0, k_x),
            DVec4::new(0.0, -1.0, 0.0, k_y),
            DVec4::new(0.0, 1.0, 0.0, k_y),
        ]
    }
}

/// Classifies a triangle: reject when all three vertices are outside one of the six view-volume
/// planes, accept when no clipping plane is crossed, clip otherwise.
pub fn classify(p: [Vec4; 3], guard: &GuardBand) -> ClipTest {
    classify_codes(p.map(|v| ClipCode::of(v, guard)))
}

/// What [`classify`] needs to know about one vertex, computed once per vertex and combined per
/// triangle with [`classify_codes`]: bits 0–5 the view-volume planes the vertex is strictly
/// outside of (an outcode: x > w, x < −w, y > w, y < −w, z > w, z < −w; a NaN sets none),
/// [`ClipCode::INSIDE`] when it needs no clipping, [`ClipCode::FINITE`] when every coordinate
/// is finite.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct ClipCode(pub u8);

impl ClipCode {
    /// Bits of the six view-volume planes.
    pub const OUTSIDE: u8 = 0x3f;
    /// Inside the near plane, `w ≥ W_MIN` and inside the guard band.
    pub const INSIDE: u8 = 0x40;
    /// All four coordinates finite.
    pub const FINITE: u8 = 0x80;

    /// The code of clip-space position `v`.
    #[inline]
    pub fn of(v: Vec4, guard: &GuardBand) -> Self {
        // Two lane-wise comparisons give the outcode.
        let xyz = Vec3A::new(v.x, v.y, v.z);
        let w = Vec3A::splat(v.w);
        let outside = xyz.cmpgt(w).bitmask() | xyz.cmplt(-w).bitmask() << 3;
        // |x| ≤ k_x·w, |y| ≤ k_y·w, −z ≤ w (z ≥ −w) and W_MIN ≤ w, all four at once.
        let inside = Vec4::new(v.x.abs(), v.y.abs(), -v.z, W_MIN)
            .cmple(Vec4::new(guard.k_x * v.w, guard.k_y * v.w, v.w, v.w))
            .all();
        Self(
            outside as u8
                | if inside { Self::INSIDE } else { 0 }
                | if v.is_finite() { Self::FINITE } else { 0 },
        )
    }

    /// Whether all of the triangle's coordinates are finite.
    #[inline]
    pub fn all_finite(codes: [ClipCode; 3]) -> bool {
        codes[0].0 & codes[1].0 & codes[2].0 & Self::FINITE != 0
    }
}

/// [`classify`] from the vertices' [`ClipCode`]s: rejected when all three are outside one plane,
/// accepted when all three are inside.
#[inline]
pub fn classify_codes(codes: [ClipCode; 3]) -> ClipTest {
    let all = codes[0].0 & codes[1].0 & codes[2].0;
    if all & ClipCode::OUTSIDE != 0 {
        ClipTest::Reject
    } else if all & ClipCode::INSIDE != 0 {
        ClipTest::Accept
    } else {
        ClipTest::Clip
    }
}

/// A convex polygon of clip vertices, at most [`MAX_CLIPPED_VERTICES`]. Positions are kept in
/// `f64` while clipping and rounded to `f32` once, at the end.
#[derive(Clone, Debug)]
pub struct ClipPolygon {
    vertices: [ClipVertex; MAX_CLIPPED_VERTICES],
    positions: [DVec4; MAX_CLIPPED_VERTICES],
    len: usize,
}

impl ClipPolygon {
    /// The triangle `a, b, c`.
    #[inline]
    pub fn triangle(a: ClipVertex, b: ClipVertex, c: ClipVertex) -> Self {
        let mut vertices = [a; MAX_CLIPPED_VERTICES];
        vertices[1] = b;
        vertices[2] = c;
        let mut positions = [DVec4::ZERO; MAX_CLIPPED_VERTICES];
        for (p, v) in positions.iter_mut().zip(&vertices[..3]) {
            *p = v.pos_clip.as_dvec4();
        }
        Self {
            vertices,
            positions,
            len: 3,
        }
    }

    /// The vertices, in order (same winding as the input triangle).
    #[inline]
    pub fn vertices(&self) -> &[ClipVertex] {
        &self.vertices[..self.len]
    }

    /// Clips against the near plane, the relative `w` plane and the guard band, interpolating
    /// the first `varying_count` varyings linearly in clip space. The result may be empty
    /// (fewer than 3 vertices); every vertex left has a finite position with `w ≥ W_MIN`.
    pub fn clip(&mut self, guard: &GuardBand, varying_count: usize) {
        let n = varying_count.min(MAX_VARYINGS);
        self.clip_plane(DVec4::new(0.0, 0.0, 1.0, 1.0), 0.0, n);
        let w_max = self.positions[..self.len]
            .iter()
            .map(|p| p.w)
            .fold(0.0f64, f64::max);
        let w_floor = (W_RELATIVE_EPSILON * w_max).max(W_MIN as f64);
        self.clip_plane(DVec4::new(0.0, 0.0, 0.0, 1.0), w_floor, n);
        for plane in guard.planes() {
            self.clip_plane(plane, 0.0, n);
        }
        if self.len < 3 {
            self.len = 0;
            return;
        }
        for (v, p) in self.vertices[..self.len]
            .iter_mut()
            .zip(&self.positions[..self.len])
        {
            v.pos_clip = p.as_vec4();
            if !v.pos_clip.is_finite() || v.pos_clip.w < W_MIN {
                self.len = 0;
                return;
            }
        }
    }

    /// Sutherland–Hodgman against the plane `dot(plane, p) ≥ offset`, in `f64`.
    fn clip_plane(&mut self, plane: DVec4, offset: f64, n: usize) {
        if self.len < 3 {
            self.len = 0;
            return;
        }
        let distance = |p: DVec4| plane.dot(p) - offset;
        let count = self.len;
        if self.positions[..count].iter().all(|&p| distance(p) >= 0.0) {
            return;
        }
        let (src, src_pos) = (self.vertices, self.positions);
        let mut out = 0;
        for i in 0..count {
            let j = (i + 1) % count;
            let (da, db) = (distance(src_pos[i]), distance(src_pos[j]));
            if da >= 0.0 {
                self.vertices[out] = src[i];
                self.positions[out] = src_pos[i];
                out += 1;
            }
            if (da >= 0.0) != (db >= 0.0) {
                // Interpolate from the inside vertex towards the outside one, so the same edge
                // gives the same point whichever triangle it belongs to.
                let (inner, outer, d_in, d_out) = if da >= 0.0 {
                    (i, j, da, db)
                } else {
                    (j, i, db, da)
                };
                let t = d_in / (d_in - d_out);
                let (p_in, p_out) = (src_pos[inner], src_pos[outer]);
                let mut v = src[inner];
                let (a, b) = (&src[inner].varyings, &src[outer].varyings);
                for k in 0..n {
                    let (a, b) = (a[k] as f64, b[k] as f64);
                    v.varyings[k] = (a + (b - a) * t) as f32;
                }
                if out < MAX_CLIPPED_VERTICES {
                    self.vertices[out] = v;
                    self.positions[out] = p_in + (p_out - p_in) * t;
                    out += 1;
                }
            }
        }
        self.len = out;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vertex(x: f32, y: f32, z: f32, w: f32, attr: f32) -> ClipVertex {
        let mut varyings = [0.0; MAX_VARYINGS];
        varyings[0] = attr;
        ClipVertex {
            pos_clip: Vec4::new(x, y, z, w),
            varyings,
        }
    }

    #[test]
    fn triangle_behind_the_eye_is_rejected_and_inside_is_accepted() {
        let guard = GuardBand::new(100, 100);
        let behind = [
            Vec4::new(0.0, 0.0, -2.0, 1.0),
            Vec4::new(1.0, 0.0, -2.0, 1.0),
            Vec4::new(0.0, 1.0, -2.0, 1.0),
        ];
        assert_eq!(classify(behind, &guard), ClipTest::Reject);
        let inside = [
            Vec4::new(0.0, 0.0, 0.0, 1.0),
            Vec4::new(0.5, 0.0, 0.0, 1.0),
            Vec4::new(0.0, 0.5, 0.0, 1.0),
        ];
        assert_eq!(classify(inside, &guard), ClipTest::Accept);
    }

    /// The rules of [`classify`] written plane by plane.
    fn classify_by_planes(p: [Vec4; 3], guard: &GuardBand) -> ClipTest {
        let planes: [fn(Vec4) -> bool; 6] = [
            |v| v.x > v.w,
            |v| v.x < -v.w,
            |v| v.y > v.w,
            |v| v.y < -v.w,
            |v| v.z > v.w,
            |v| v.z < -v.w,
        ];
        if planes.iter().any(|out| p.iter().all(|&v| out(v))) {
            return ClipTest::Reject;
        }
        let inside = |v: &Vec4| {
            v.z >= -v.w
                && v.w >= W_MIN
                && v.x.abs() <= guard.k_x * v.w
                && v.y.abs() <= guard.k_y * v.w
        };
        if p.iter().all(inside) {
            ClipTest::Accept
        } else {
            ClipTest::Clip
        }
    }

    #[test]
    fn outcodes_classify_as_the_planes_do() {
        let guard = GuardBand::new(64, 48);
        // Coordinates on, inside and outside every plane, the guard band and W_MIN, and NaN.
        let values = [
            0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            2.0,
            -2.0,
            600.0,
            -600.0,
            1e-6,
            f32::NAN,
            f32::INFINITY,
        ];
        let ws = [1.0, 2.0, 1e-6, 0.0, -1.0, f32::NAN];
        let mut state = 0x9e37_79b9u32;
        let mut pick = |n: usize| {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state as usize % n
        };
        let mut seen = [0usize; 3];
        for _ in 0..20_000 {
            let p: [Vec4; 3] = std::array::from_fn(|_| {
                let w = ws[pick(ws.len())];
                let mut c = || values[pick(values.len())] * if pick(2) == 0 { 1.0 } else { w };
                Vec4::new(c(), c(), c(), w)
            });
            let expected = classify_by_planes(p, &guard);
            assert_eq!(classify(p, &guard), expected, "{p:?}");
            seen[expected as usize] += 1;
        }
        assert!(seen.iter().all(|&n| n > 100), "{seen:?}");
    }

    #[test]
    fn near_clip_cuts_a_crossing_triangle_into_a_quad_with_interpolated_varyings() {
        let guard = GuardBand::new(100, 100);
        // One vertex behind the near plane (z < -w).
        let a = vertex(0.0, 0.0, -3.0, 1.0, 0.0);
        let b = vertex(0.5, 0.0, 0.0, 1.0, 1.0);
        let c = vertex(0.0, 0.5, 0.0, 1.0, 1.0);
        let mut poly = ClipPolygon::triangle(a, b, c);
        poly.clip(&guard, 1);
        assert_eq!(poly.vertices().len(), 4);
        for v in poly.vertices() {
            assert!(v.pos_clip.z >= -v.pos_clip.w - 1e-6);
        }
        // The new vertices sit at z = -w: a→b is cut at t = 2/3, so the varying is 2/3.
        let cut: Vec<f32> = poly
            .vertices()
            .iter()
            .filter(|v| (v.pos_clip.z + v.pos_clip.w).abs() < 1e-6)
            .map(|v| v.varyings[0])
            .collect();
        assert_eq!(cut.len(), 2);
        for value in cut {
            assert!((value - 2.0 / 3.0).abs() < 1e-6);
        }
    }

    #[test]
    fn guard_band_and_negative_w_leave_only_safe_vertices() {
        let guard = GuardBand::new(64, 64);
        let a = vertex(1e9, 0.0, 0.0, 1.0, 0.0);
        let b = vertex(0.0, 0.0, 0.0, -1.0, 0.0);
        let c = vertex(0.0, 0.5, 0.0, 1.0, 0.0);
        let mut poly = ClipPolygon::triangle(a, b, c);
        poly.clip(&guard, 0);
        // Intersections are computed in f64 and rounded to f32 once: at most an f32 rounding
        // step outside a plane.
        for v in poly.vertices() {
            assert!(v.pos_clip.w >= W_MIN);
            assert!(v.pos_clip.x.abs() <= guard.k_x * v.pos_clip.w * (1.0 + 1e-6));
            assert!(v.pos_clip.y.abs() <= guard.k_y * v.pos_clip.w * (1.0 + 1e-6));
        }
    }
}
