//! The primitive stage for points and lines: assembly from the index buffer, clipping in clip
//! space ([`kantele_rules::geometry::segment`]), expansion into a window-space quad
//! ([`kantele_rules::geometry::wide`]) and set-up of its two triangles, which then take the triangle
//! path unchanged. Points and lines are never culled and always face the viewer (OpenGL 3.3
//! §3.6.1: only polygons have a back face).

use super::call::DrawCall;
use super::geometry::{PrimitiveBatch, ShadedVertices, TargetSpace};
use super::shader::Shader;
use kantele_rules::geometry::clip::{ClipVertex, GuardBand};
use kantele_rules::geometry::segment::{clip_segment, point_inside, SegmentClip};
use kantele_rules::geometry::wide::{line_quad, point_quad, WideQuad};
use kantele_rules::setup::{
    setup_window_triangle, CullMode, FrontFace, SetupReject, TriangleSetup, Viewport, WindowVertex,
};
use kantele_rules::state::Topology;
use kantele_rules::MAX_VARYINGS;

/// Lines are clipped to the view volume's sides (`|x|, |y| ≤ w`), as OpenGL clips them, rather
/// than to the triangles' guard band: where a line leaves the picture its end then lies on the
/// picture's edge in both, and the slope of the snapped segment is the same.
const VIEW_VOLUME: GuardBand = GuardBand { k_x: 1.0, k_y: 1.0 };

impl<S: Shader> DrawCall<'_, S> {
    /// Assembles, clips and sets up the points or lines `primitives` of this draw.
    pub(super) fn assemble_points_lines(
        &self,
        draw: u32,
        primitives: std::ops::Range<usize>,
        shaded: &ShadedVertices,
        target: &TargetSpace,
        out: &mut PrimitiveBatch,
    ) {
        let n = self.shader.varying_count();
        let vertex = |i: usize| {
            let mut v = ClipVertex {
                pos_clip: shaded.pos_clip[i],
                varyings: [0.0; MAX_VARYINGS],
            };
            v.varyings[..n].copy_from_slice(&shaded.varyings[i * n..(i + 1) * n]);
            v
        };
        for p in primitives {
            out.counters.triangles_in += 1;
            match self.topology {
                Topology::Points => {
                    let pos = shaded.pos_clip[self.indices.get(p)];
                    if !pos.is_finite() {
                        out.counters.invalid += 1;
                    } else if !point_inside(pos) {
                        out.counters.rejected += 1;
                    } else {
                        let v = vertex(self.indices.get(p));
                        emit_quad(draw, p as u32, [&v, &v], &target.viewport, n, out, |w| {
                            Some(point_quad(w[0]))
                        });
                    }
                }
                // Lines (triangle draws never come here).
                Topology::Lines | Topology::Triangles => {
                    let (ia, ib) = (self.indices.get(2 * p), self.indices.get(2 * p + 1));
                    let (pa, pb) = (shaded.pos_clip[ia], shaded.pos_clip[ib]);
                    if !pa.is_finite() || !pb.is_finite() {
                        out.counters.invalid += 1;
                        continue;
                    }
                    let (a, b) = (vertex(ia), vertex(ib));
                    let (a, b) = match clip_segment(&a, &b, &VIEW_VOLUME, n) {
                        SegmentClip::Rejected => {
                            out.counters.rejected += 1;
                            continue;
                        }
                        SegmentClip::Empty => {
                            out.counters.clipped += 1;
                            continue;
                        }
                        SegmentClip::Inside => (a, b),
                        SegmentClip::Clipped(a, b) => {
                            out.counters.clipped += 1;
                            (a, b)
                        }
                    };
                    emit_quad(draw, p as u32, [&a, &b], &target.viewport, n, out, |w| {
                        line_quad(w[0], w[1])
                    });
                }
            }
        }
    }
}

/// Expands one point or line (its clip-space ends, `w > 0`) with `expand` into a quad and sets
/// up its two triangles, front-facing and never culled. Each corner carries the depth, `1/w`
/// and varyings of the primitive where its end of the quad lies ([`WideQuad::t`]): depth and
/// `1/w` interpolated linearly in window space, varyings perspective-correctly.
fn emit_quad(
    draw: u32,
    primitive_id: u32,
    ends: [&ClipVertex; 2],
    viewport: &Viewport,
    varying_count: usize,
    out: &mut PrimitiveBatch,
    expand: impl Fn([[f32; 2]; 2]) -> Option<WideQuad>,
) {
    let window = ends.map(|v| viewport.to_window(v.pos_clip));
    let Some(quad) = expand(window.map(|(w, _)| [w[0], w[1]])) else {
        out.counters.degenerate += 1;
        return;
    };
    let n = varying_count;
    // Depth, 1/w and varyings at each end of the quad.
    let at = |t: f32| -> (f32, f32, [f32; MAX_VARYINGS]) {
        let (a, b) = (&window[0], &window[1]);
        let mut varyings = ends[0].varyings;
        if t == 0.0 {
            return (a.0[2], a.1, varyings);
        }
        if t == 1.0 {
            return (b.0[2], b.1, ends[1].varyings);
        }
        let depth = a.0[2] + (b.0[2] - a.0[2]) * t;
        let inv_w = a.1 + (b.1 - a.1) * t;
        if !(inv_w > 0.0 && inv_w.is_finite() && depth.is_finite()) {
            // An end moved far out along a steeply receding line: keep the nearer vertex's.
            let nearer = if t < 0.5 { 0 } else { 1 };
            return (window[nearer].0[2], window[nearer].1, ends[nearer].varyings);
        }
        for (k, v) in varyings[..n].iter_mut().enumerate() {
            let (va, vb) = (ends[0].varyings[k] * a.1, ends[1].varyings[k] * b.1);
            *v = (va + (vb - va) * t) / inv_w;
        }
        (depth, inv_w, varyings)
    };
    let quad_ends = [at(quad.t[0]), at(quad.t[1])];
    for corners in WideQuad::TRIANGLES {
        let end = |k: usize| &quad_ends[quad.ends[corners[k]]];
        let position = |k: usize| -> [f32; 3] {
            let c = quad.corners[corners[k]];
            [c[0], c[1], end(k).0]
        };
        let corner = |k: usize| WindowVertex::snapped(position(k), end(k).1);
        match setup_window_triangle(
            viewport,
            [corner(0), corner(1), corner(2)],
            CullMode::None,
            FrontFace::Ccw,
        ) {
            Ok(mut tri) => {
                tri.draw = draw;
                tri.primitive_id = primitive_id;
                tri.flags |= TriangleSetup::FRONT_FACING;
                let order = if tri.swapped() { [0, 2, 1] } else { [0, 1, 2] };
                for k in order {
                    out.attrs.extend_from_slice(&end(k).2[..n]);
                }
                out.push(tri);
            }
            Err(SetupReject::Culled) | Err(SetupReject::Degenerate) => out.counters.degenerate += 1,
        }
    }
}
