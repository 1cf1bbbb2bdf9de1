//! Draw jobs: each stage's work for one recorded draw ([`DrawCall`]), behind the stages' job
//! traits, so each stage's loop runs compiled for the draw's concrete shader.

use glam::Vec4;

use super::call::DrawCall;
use super::fragment::{shade_triangle, RasterCounters, RasterJob};
use super::geometry::{GeometryJob, PrimitiveBatch, ShadedVertices, TargetSpace};
use super::multisample::shade_triangle_multisampled;
use super::packed_rows::PackedRows;
use super::shader::Shader;
use crate::raster::samples::SampleCoverage;
use crate::raster::BlockCoverage;
use crate::rop::{DepthFunc, TileBuffer};
use kantele_lanes::Isa;
use kantele_rules::geometry::clip::{classify_codes, ClipCode, ClipPolygon, ClipTest, ClipVertex};
use kantele_rules::setup::{
    setup_window_triangle, SetupReject, TriangleSetup, Viewport, WindowVertex,
};
use kantele_rules::state::Topology;
use kantele_rules::MAX_VARYINGS;

/// A queued draw with its shader type erased: the geometry stage's job and the raster's job
/// of one draw, so the hot loops inside are compiled for the concrete shader.
pub(super) trait DrawJob: GeometryJob + RasterJob {}

impl<T: GeometryJob + RasterJob + ?Sized> DrawJob for T {}

impl<S: Shader> DrawCall<'_, S> {
    #[inline]
    fn triangle_vertices(&self, t: usize) -> [usize; 3] {
        [
            self.indices.get(3 * t),
            self.indices.get(3 * t + 1),
            self.indices.get(3 * t + 2),
        ]
    }

    /// Sets up one (clipped or whole) triangle and appends it with its varyings. Always inlined
    /// into [`GeometryJob::assemble`], with [`setup_window_triangle`]: as two calls per triangle,
    /// the record (over 200 bytes) went back through memory; inlined, the mesh scenes' frames
    /// are 2–23% shorter at one thread (docs/design-notes.md).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)] // the stage's inputs; bundling them would only rename them
    fn emit(
        &self,
        draw: u32,
        primitive_id: u32,
        window: [WindowVertex; 3],
        varyings: [&[f32]; 3],
        viewport: &Viewport,
        out: &mut PrimitiveBatch,
    ) {
        match setup_window_triangle(viewport, window, self.state.cull, self.state.front_face) {
            Ok(mut tri) => {
                tri.draw = draw;
                tri.primitive_id = primitive_id;
                let order = if tri.swapped() { [0, 2, 1] } else { [0, 1, 2] };
                for v in order {
                    out.attrs.extend_from_slice(varyings[v]);
                }
                out.push(tri);
            }
            Err(SetupReject::Culled) => out.counters.culled += 1,
            Err(SetupReject::Degenerate) => out.counters.degenerate += 1,
        }
    }
}

impl<S: Shader> GeometryJob for DrawCall<'_, S> {
    fn vertex_count(&self) -> usize {
        self.vertices.len()
    }

    fn varying_count(&self) -> usize {
        self.shader.varying_count()
    }

    fn primitive_count(&self) -> usize {
        self.indices.len(self.vertices.len()) / self.topology.vertices_per_primitive()
    }

    fn shade_vertices(&self, first: usize, pos: &mut [Vec4], varyings: &mut [f32]) {
        let n = self.shader.varying_count();
        for (i, p) in pos.iter_mut().enumerate() {
            let out = &mut varyings[i * n..(i + 1) * n];
            *p = self.shader.vertex(&self.vertices[first + i], out);
        }
    }

    fn sort_order(&self, shaded: &ShadedVertices) -> Option<Vec<u32>> {
        if !self.state.sort_back_to_front || self.topology != Topology::Triangles {
            return None;
        }
        let key = |t: usize| {
            let [a, b, c] = self.triangle_vertices(t);
            let w = shaded.pos_clip[a].w + shaded.pos_clip[b].w + shaded.pos_clip[c].w;
            if w.is_nan() {
                f32::NEG_INFINITY
            } else {
                w
            }
        };
        let mut order: Vec<u32> = (0..self.primitive_count() as u32).collect();
        // Farthest first; a stable sort keeps submission order among equals.
        order.sort_by(|&a, &b| key(b as usize).total_cmp(&key(a as usize)));
        Some(order)
    }

    fn assemble(
        &self,
        draw: u32,
        triangles: std::ops::Range<usize>,
        order: Option<&[u32]>,
        shaded: &ShadedVertices,
        target: &TargetSpace,
        out: &mut PrimitiveBatch,
    ) {
        if self.topology != Topology::Triangles {
            return self.assemble_points_lines(draw, triangles, shaded, target, out);
        }
        let TargetSpace { viewport, guard } = target;
        let n = self.shader.varying_count();
        for slot in triangles {
            out.counters.triangles_in += 1;
            let t = order.map_or(slot, |o| o[slot] as usize);
            let ix = self.triangle_vertices(t);
            // Per-vertex codes from the vertex stage (`ClipCode::of`), combined.
            let codes = ix.map(|i| shaded.clip_codes[i]);
            if !ClipCode::all_finite(codes) {
                out.counters.invalid += 1;
                continue;
            }
            let vary = ix.map(|i| &shaded.varyings[i * n..(i + 1) * n]);
            match classify_codes(codes) {
                ClipTest::Reject => out.counters.rejected += 1,
                ClipTest::Accept => {
                    let window = ix.map(|i| shaded.window[i]);
                    self.emit(draw, t as u32, window, vary, viewport, out)
                }
                ClipTest::Clip => {
                    out.counters.clipped += 1;
                    let pos = ix.map(|i| shaded.pos_clip[i]);
                    let vertex = |k: usize| {
                        let mut v = ClipVertex {
                            pos_clip: pos[k],
                            varyings: [0.0; MAX_VARYINGS],
                        };
                        v.varyings[..n].copy_from_slice(vary[k]);
                        v
                    };
                    let mut poly = ClipPolygon::triangle(vertex(0), vertex(1), vertex(2));
                    poly.clip(guard, n);
                    let verts = poly.vertices();
                    if verts.iter().any(|v| !v.pos_clip.is_finite()) {
                        out.counters.invalid += 1;
                        continue;
                    }
                    for k in 1..verts.len().saturating_sub(1) {
                        let (a, b, c) = (&verts[0], &verts[k], &verts[k + 1]);
                        self.emit(
                            draw,
                            t as u32,
                            [a.pos_clip, b.pos_clip, c.pos_clip].map(|p| viewport.window_vertex(p)),
                            [&a.varyings[..n], &b.varyings[..n], &c.varyings[..n]],
                            viewport,
                            out,
                        );
                    }
                }
            }
        }
    }
}

impl<S: Shader> RasterJob for DrawCall<'_, S> {
    fn rejects_by_depth_bound(&self) -> bool {
        self.state.depth_test
            && matches!(
                self.state.depth_func,
                DepthFunc::Less | DepthFunc::LessEqual
            )
    }

    fn raster(
        &self,
        tri: &TriangleSetup,
        attrs: &[f32],
        coverage: &BlockCoverage,
        packed: &mut PackedRows,
        tile: &mut TileBuffer,
        isa: Isa,
    ) -> RasterCounters {
        shade_triangle(self, tri, attrs, coverage, packed, tile, isa)
    }

    fn raster_multisampled(
        &self,
        tri: &TriangleSetup,
        attrs: &[f32],
        coverage: &SampleCoverage,
        tile: &mut TileBuffer,
        isa: Isa,
    ) -> RasterCounters {
        shade_triangle_multisampled(self, tri, attrs, coverage, tile, isa)
    }
}
