//! Clipping in homogeneous clip space (before the divide by w).
//!
//! Only the planes that matter for correctness and safety are clipped: the near plane
//! `z ≥ −w`, a tiny positive `w` (so no division by `w ≤ 0` can happen even with unusual
//! projection matrices) and the guard band `|x|, |y| ≤ k·w`. The far plane and the sides inside
//! the guard band are left to the rasterizer (scissoring to the target and discarding depth
//! outside [0, 1]), which gives the same pictures with far fewer clipped triangles.

use glam::Vec4;

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
/// `w ≥ W_EPSILON`, written as a plane through a shifted origin (handled specially).
pub const W_EPSILON: f32 = 1e-6;

/// Most vertices a triangle can have after clipping against all planes (3 + one per plane).
pub const MAX_CLIPPED_VERTICES: usize = 3 + 6;

/// Outcome codes of the trivial reject / accept test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClipTest {
    /// Wholly outside one frustum plane: draw nothing.
    Reject,
    /// Needs no clipping: inside the near plane, positive w, and inside the guard band.
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

    fn planes(&self) -> [ClipPlane; 4] {
        [
            Vec4::new(-1.0, 0.0, 0.0, self.k_x),
            Vec4::new(1.0, 0.0, 0.0, self.k_x),
            Vec4::new(0.0, -1.0, 0.0, self.k_y),
            Vec4::new(0.0, 1.0, 0.0, self.k_y),
        ]
    }
}

/// Classifies a triangle: reject when all three vertices are outside one of the six view-volume
/// planes, accept when no clipping plane is crossed, clip otherwise.
pub fn classify(p: [Vec4; 3], guard: &GuardBand) -> ClipTest {
    let outside = |f: &dyn Fn(Vec4) -> bool| p.iter().all(|&v| f(v));
    if outside(&|v| v.x > v.w)
        || outside(&|v| v.x < -v.w)
        || outside(&|v| v.y > v.w)
        || outside(&|v| v.y < -v.w)
        || outside(&|v| v.z > v.w)
        || outside(&|v| v.z < -v.w)
    {
        return ClipTest::Reject;
    }
    let inside = |v: Vec4| {
        v.z >= -v.w
            && v.w >= W_EPSILON
            && v.x.abs() <= guard.k_x * v.w
            && v.y.abs() <= guard.k_y * v.w
    };
    if p.iter().all(|&v| inside(v)) {
        ClipTest::Accept
    } else {
        ClipTest::Clip
    }
}

/// A convex polygon of clip vertices, at most [`MAX_CLIPPED_VERTICES`].
#[derive(Clone, Debug)]
pub struct ClipPolygon {
    vertices: [ClipVertex; MAX_CLIPPED_VERTICES],
    len: usize,
}

impl ClipPolygon {
    /// The triangle `a, b, c`.
    pub fn triangle(a: ClipVertex, b: ClipVertex, c: ClipVertex) -> Self {
        let mut vertices = [a; MAX_CLIPPED_VERTICES];
        vertices[1] = b;
        vertices[2] = c;
        Self { vertices, len: 3 }
    }

    /// The vertices, in order (same winding as the input triangle).
    pub fn vertices(&self) -> &[ClipVertex] {
        &self.vertices[..self.len]
    }

    /// Clips against the near plane, `w ≥ ε` and the guard band, interpolating the first
    /// `varying_count` varyings linearly in clip space. The result may be empty (fewer than 3
    /// vertices).
    pub fn clip(&mut self, guard: &GuardBand, varying_count: usize) {
        self.clip_plane(|v| v.z + v.w, varying_count);
        self.clip_plane(|v| v.w - W_EPSILON, varying_count);
        for plane in guard.planes() {
            self.clip_plane(|v| plane.dot(v), varying_count);
        }
    }

    /// Sutherland–Hodgman against one plane given by its signed distance function (inside ≥ 0).
    fn clip_plane(&mut self, distance: impl Fn(Vec4) -> f32, n: usize) {
        if self.len < 3 {
            self.len = 0;
            return;
        }
        let src = self.vertices;
        let count = self.len;
        if src[..count].iter().all(|v| distance(v.pos_clip) >= 0.0) {
            return;
        }
        let mut out = 0;
        for i in 0..count {
            let a = &src[i];
            let b = &src[(i + 1) % count];
            let da = distance(a.pos_clip);
            let db = distance(b.pos_clip);
            if da >= 0.0 {
                self.vertices[out] = *a;
                out += 1;
            }
            if (da >= 0.0) != (db >= 0.0) {
                // Interpolate from the inside vertex towards the outside one, so the same edge
                // gives the same point whichever triangle it belongs to.
                let (inner, outer, d_in, d_out) = if da >= 0.0 {
                    (a, b, da, db)
                } else {
                    (b, a, db, da)
                };
                let t = d_in / (d_in - d_out);
                let mut v = *inner;
                v.pos_clip = inner.pos_clip + (outer.pos_clip - inner.pos_clip) * t;
                for k in 0..n {
                    v.varyings[k] = inner.varyings[k] + (outer.varyings[k] - inner.varyings[k]) * t;
                }
                if out < MAX_CLIPPED_VERTICES {
                    self.vertices[out] = v;
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
        // Intersections are computed in f32, so a vertex may end a hair outside a plane (here
        // about 1e-4 relative, a couple of pixels at w ≈ 5e-4); snapping clamps to twice the
        // guard band, which absorbs it.
        for v in poly.vertices() {
            assert!(v.pos_clip.w >= W_EPSILON * 0.99);
            assert!(v.pos_clip.x.abs() <= guard.k_x * v.pos_clip.w * 1.001);
            assert!(v.pos_clip.y.abs() <= guard.k_y * v.pos_clip.w * 1.001);
        }
    }
}
