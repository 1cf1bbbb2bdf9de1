//! Clipping of lines and points in homogeneous clip space, by the rules the triangle clipper
//! follows ([`super::clip`]): segments are cut at the near plane, at a `w` plane relative to the
//! segment's largest `w` and at the side planes `|x| ≤ k_x·w`, `|y| ≤ k_y·w` of a
//! [`GuardBand`], in `f64` from the exact `f32` inputs, and rounded to `f32` once; no vertex
//! handed on has `w ≤ 0`. The pipeline passes `k = 1`, the view volume's sides, as OpenGL
//! clips lines (a line leaving the picture then ends on its edge, as in llvmpipe). A point is kept only when it lies inside the
//! view volume (OpenGL 3.3 §2.20: a point outside it is discarded, not clipped).

use glam::{DVec4, Vec4};

use super::clip::{ClipVertex, GuardBand, W_MIN, W_RELATIVE_EPSILON};
use crate::MAX_VARYINGS;

/// Outcome of clipping a segment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SegmentClip {
    /// Wholly outside one plane of the view volume: draw nothing.
    Rejected,
    /// Inside every clipping plane: the ends as they are.
    Inside,
    /// Cut: the part inside, with interpolated varyings (both ends finite, `w ≥ W_MIN`).
    Clipped(ClipVertex, ClipVertex),
    /// Cut down to nothing (or to non-finite values by rounding).
    Empty,
}

/// Classifies and, where needed, clips the segment `a → b`, interpolating the first
/// `varying_count` varyings linearly in clip space.
pub fn clip_segment(
    a: &ClipVertex,
    b: &ClipVertex,
    guard: &GuardBand,
    varying_count: usize,
) -> SegmentClip {
    let (pa, pb) = (a.pos_clip, b.pos_clip);
    let outside = |f: &dyn Fn(Vec4) -> bool| f(pa) && f(pb);
    if outside(&|v| v.x > v.w)
        || outside(&|v| v.x < -v.w)
        || outside(&|v| v.y > v.w)
        || outside(&|v| v.y < -v.w)
        || outside(&|v| v.z > v.w)
        || outside(&|v| v.z < -v.w)
    {
        return SegmentClip::Rejected;
    }
    let inside = |v: Vec4| {
        v.z >= -v.w && v.w >= W_MIN && v.x.abs() <= guard.k_x * v.w && v.y.abs() <= guard.k_y * v.w
    };
    if inside(pa) && inside(pb) {
        return SegmentClip::Inside;
    }
    // Parameter range [t0, t1] of the part of a + (b − a)·t inside every plane, in f64.
    let (da, db) = (pa.as_dvec4(), pb.as_dvec4());
    let mut range = (0.0f64, 1.0f64);
    cut(&mut range, da, db, DVec4::new(0.0, 0.0, 1.0, 1.0), 0.0);
    // The relative w plane, from the largest w left after the near cut.
    let w_at = |t: f64| da.w + (db.w - da.w) * t;
    let w_max = w_at(range.0).max(w_at(range.1.max(range.0)));
    let w_floor = (W_RELATIVE_EPSILON * w_max).max(W_MIN as f64);
    cut(&mut range, da, db, DVec4::new(0.0, 0.0, 0.0, 1.0), w_floor);
    let (k_x, k_y) = (guard.k_x as f64, guard.k_y as f64);
    for plane in [
        DVec4::new(-1.0, 0.0, 0.0, k_x),
        DVec4::new(1.0, 0.0, 0.0, k_x),
        DVec4::new(0.0, -1.0, 0.0, k_y),
        DVec4::new(0.0, 1.0, 0.0, k_y),
    ] {
        cut(&mut range, da, db, plane, 0.0);
    }
    let (t0, t1) = range;
    if t0 >= t1 {
        return SegmentClip::Empty;
    }
    let n = varying_count.min(MAX_VARYINGS);
    let at = |t: f64| -> Option<ClipVertex> {
        let mut v = *a;
        v.pos_clip = (da + (db - da) * t).as_vec4();
        for k in 0..n {
            let (x, y) = (a.varyings[k] as f64, b.varyings[k] as f64);
            v.varyings[k] = (x + (y - x) * t) as f32;
        }
        (v.pos_clip.is_finite() && v.pos_clip.w >= W_MIN).then_some(v)
    };
    // Unclipped ends keep their exact values.
    let first = if t0 == 0.0 { Some(*a) } else { at(t0) };
    let second = if t1 == 1.0 { Some(*b) } else { at(t1) };
    match (first, second) {
        (Some(p), Some(q)) => SegmentClip::Clipped(p, q),
        _ => SegmentClip::Empty,
    }
}

/// Narrows the parameter range `(t0, t1)` of `a + (b − a)·t` to the side
/// `dot(plane, p) ≥ offset`; an empty range has `t0 ≥ t1`.
fn cut(range: &mut (f64, f64), a: DVec4, b: DVec4, plane: DVec4, offset: f64) {
    let (fa, fb) = (plane.dot(a) - offset, plane.dot(b) - offset);
    if fa < 0.0 && fb < 0.0 {
        *range = (1.0, 0.0);
    } else if fa < 0.0 {
        range.0 = range.0.max(fa / (fa - fb));
    } else if fb < 0.0 {
        range.1 = range.1.min(fa / (fa - fb));
    }
}

/// Whether a point is drawn: finite, `w ≥ W_MIN` and inside the view volume
/// `−w ≤ x, y, z ≤ w`.
#[inline]
pub fn point_inside(p: Vec4) -> bool {
    p.is_finite() && p.w >= W_MIN && p.x.abs() <= p.w && p.y.abs() <= p.w && p.z.abs() <= p.w
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
    fn segments_inside_outside_and_across_the_near_plane() {
        let guard = GuardBand::new(100, 100);
        let a = vertex(-0.5, 0.0, 0.0, 1.0, 0.0);
        let b = vertex(0.5, 0.0, 0.0, 1.0, 1.0);
        assert_eq!(clip_segment(&a, &b, &guard, 1), SegmentClip::Inside);
        let behind = vertex(0.5, 0.0, -3.0, 1.0, 1.0);
        let behind2 = vertex(-0.5, 0.0, -3.0, 1.0, 1.0);
        assert_eq!(
            clip_segment(&behind, &behind2, &guard, 1),
            SegmentClip::Rejected
        );
        // a at z = 0 (inside), behind at z = −3: the near plane z = −w is reached at t = 1/3.
        let SegmentClip::Clipped(p, q) = clip_segment(&a, &behind, &guard, 1) else {
            panic!("expected a clipped segment");
        };
        assert_eq!(p, a);
        assert!((q.pos_clip.z + q.pos_clip.w).abs() < 1e-6);
        assert!((q.varyings[0] - 1.0 / 3.0).abs() < 1e-6);
        assert!((q.pos_clip.x - (-0.5 + 1.0 / 3.0)).abs() < 1e-6);
    }

    #[test]
    fn a_segment_through_the_eye_never_hands_on_w_at_or_below_zero() {
        let guard = GuardBand::new(64, 64);
        let a = vertex(0.0, 0.0, 0.5, 1.0, 0.0);
        let b = vertex(1e9, 0.0, 0.0, -1.0, 0.0);
        match clip_segment(&a, &b, &guard, 0) {
            SegmentClip::Clipped(p, q) => {
                for v in [p, q] {
                    assert!(v.pos_clip.w >= W_MIN);
                    assert!(v.pos_clip.x.abs() <= guard.k_x * v.pos_clip.w * (1.0 + 1e-6));
                }
            }
            SegmentClip::Empty => {}
            other => panic!("unexpected {other:?}"),
        }
    }

    #[test]
    fn points_outside_the_view_volume_are_dropped() {
        assert!(point_inside(Vec4::new(0.9, -0.9, 0.5, 1.0)));
        assert!(!point_inside(Vec4::new(1.1, 0.0, 0.0, 1.0)));
        assert!(!point_inside(Vec4::new(0.0, 0.0, 0.0, -1.0)));
        assert!(!point_inside(Vec4::new(0.0, 0.0, 1.5, 1.0)));
        assert!(!point_inside(Vec4::new(f32::NAN, 0.0, 0.0, 1.0)));
    }
}
