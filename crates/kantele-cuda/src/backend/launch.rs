//! The frame's launch sequence: the frame's uniforms, one kernel launch with its arguments,
//! the tiled frame queued step by step, the stage events, the status read-back, and the
//! thesis' baselines.

use std::mem::size_of;

use cudarc::driver::{CudaSlice, LaunchConfig, PushKernelArg};
use kantele_rules::backend::{FrameView, Pass};
use kantele_rules::geometry::clip::GuardBand;
use kantele_rules::setup::{PixelRect, TriangleSetup};
use kantele_rules::RenderError;

use super::device::{FrameBuffers, SceneBuffers};
use super::{failed, CudaBackend};
use crate::plan::{
    baseline_grid, ocmt_batches, tiled_frame, CudaStrategy, Kernel, Needs, Stage, Step,
    BASELINE_BLOCK,
};
use crate::records::{pass_code, view_projection, FrameUniforms, SlotInfo};

/// The status words of a frame (see `StatusWord` in common.cuh).
pub(super) mod status {
    pub const CLIP_REQUESTED: usize = 0;
    pub const BIN_TOTAL: usize = 1;
    pub const TRIANGLES_IN: usize = 2;
    pub const INVALID: usize = 3;
    pub const REJECTED: usize = 4;
    pub const CLIPPED: usize = 5;
    pub const CULLED: usize = 6;
    pub const DEGENERATE: usize = 7;
    pub const BINNED: usize = 8;
    pub const COVERED: usize = 9;
    pub const SHADED: usize = 10;
    pub const DISCARDED: usize = 11;
}

impl CudaBackend {
    pub(super) fn uniforms(
        &self,
        view: &FrameView,
        frame: &FrameBuffers,
        scene: &SceneBuffers,
    ) -> FrameUniforms {
        let guard = GuardBand::new(view.width, view.height);
        let clear = match view.pass {
            Pass::Color => scene.clear_color,
            Pass::Normals | Pass::Ids => [0.0; 4],
        };
        let shape = frame.shape;
        FrameUniforms {
            view_projection: view_projection(&view.projection, &view.view),
            to_light: view.to_light.to_array(),
            light_color: view.light_color.to_array(),
            ambient: scene.ambient,
            half_width: view.width as f32 * 0.5,
            half_height: view.height as f32 * 0.5,
            guard_kx: guard.k_x,
            guard_ky: guard.k_y,
            clear_color: clear,
            width: view.width,
            height: view.height,
            tiles_x: shape.tiles_x(),
            tiles_y: shape.tiles_y(),
            pass: pass_code(view.pass),
            draw_count: shape.draws,
            shaded_count: shape.shaded,
            slot_count: shape.slots,
            clip_capacity: frame.capacities.clip,
            bin_capacity: frame.capacities.bins,
            chunk_count: shape.chunks(),
        }
    }

    /// Queues one kernel of the tiled frame.
    pub(super) fn launch_step(
        &self,
        kernel: Kernel,
        blocks: u32,
        threads: u32,
        u: &FrameUniforms,
        scene: &SceneBuffers,
        frame: &FrameBuffers,
    ) -> Result<(), RenderError> {
        let cfg = LaunchConfig {
            grid_dim: (blocks, 1, 1),
            block_dim: (threads, 1, 1),
            shared_mem_bytes: 0,
        };
        let a = |b: &CudaSlice<_>| self.addr(b);
        let issue = self.addr(&scene.issue);
        let (draws, vertices, indices) = (
            self.addr(&scene.draws),
            self.addr(&scene.vertices),
            self.addr(&scene.indices),
        );
        let (mvp, pos, vary) = (a(&frame.mvp), a(&frame.pos_clip), a(&frame.varyings));
        let (setups, attrs, slots) = (
            self.addr(&frame.setups),
            a(&frame.setup_attrs),
            self.addr(&frame.slots),
        );
        let (counts, offsets, tile_start, bins, status) = (
            self.addr(&frame.counts),
            self.addr(&frame.offsets),
            self.addr(&frame.tile_start),
            self.addr(&frame.bins),
            self.addr(&frame.status),
        );
        let (color, depth) = (a(&frame.color), a(&frame.depth));
        let view = self.scene_view(scene);
        let name = match kernel {
            Kernel::DrawMatrices => "kantele_draw_matrices",
            Kernel::Vertex => "kantele_vertex",
            Kernel::Primitive => "kantele_primitive",
            Kernel::BinCount => "kantele_bin_count",
            Kernel::ScanBlocks(_) => "kantele_scan_blocks",
            Kernel::ScanAdd(_) => "kantele_scan_add",
            Kernel::BinFill => "kantele_bin_fill",
            Kernel::BinRanges => "kantele_bin_ranges",
            Kernel::Raster => "kantele_raster",
            Kernel::Resolve => "kantele_resolve_rgba8",
        };
        let func = self.functions.get(name)?;
        let mut args = self.stream.launch_builder(func);
        // Scan levels: level 0 scans `counts` into `offsets`; level k scans the sums of level
        // k − 1 in place. Adds go back down.
        let levels = crate::plan::scan_levels(frame.shape.matrix_cells());
        let level_io = |level: usize| -> (u64, u64, u32, u64) {
            let n = levels[level] as u32;
            let sums = if level + 1 < levels.len() {
                self.addr(&frame.scan_sums[level])
            } else {
                0
            };
            if level == 0 {
                (counts, offsets, n, sums)
            } else {
                let data = self.addr(&frame.scan_sums[level - 1]);
                (data, data, n, sums)
            }
        };
        let scan_in;
        let scan_out;
        let scan_n;
        let scan_sums;
        let rgba8 = frame.rgba8.as_ref().map_or(0, |b| self.addr(b));
        match kernel {
            Kernel::DrawMatrices => {
                args.arg(u).arg(&draws).arg(&mvp);
            }
            Kernel::Vertex => {
                args.arg(u)
                    .arg(&draws)
                    .arg(&mvp)
                    .arg(&vertices)
                    .arg(&pos)
                    .arg(&vary);
            }
            Kernel::Primitive => {
                args.arg(u)
                    .arg(&draws)
                    .arg(&issue)
                    .arg(&indices)
                    .arg(&pos)
                    .arg(&vary)
                    .arg(&setups)
                    .arg(&attrs)
                    .arg(&slots)
                    .arg(&status);
            }
            Kernel::BinCount => {
                args.arg(u)
                    .arg(&setups)
                    .arg(&slots)
                    .arg(&counts)
                    .arg(&status);
            }
            Kernel::BinFill => {
                args.arg(u)
                    .arg(&setups)
                    .arg(&slots)
                    .arg(&offsets)
                    .arg(&bins);
            }
            Kernel::ScanBlocks(level) => {
                (scan_in, scan_out, scan_n, scan_sums) = level_io(level);
                args.arg(&scan_in)
                    .arg(&scan_out)
                    .arg(&scan_n)
                    .arg(&scan_sums);
            }
            Kernel::ScanAdd(level) => {
                let (_, out, n, _) = level_io(level);
                (scan_out, scan_n) = (out, n);
                scan_sums = self.addr(&frame.scan_sums[level]);
                args.arg(&scan_out).arg(&scan_n).arg(&scan_sums);
            }
            Kernel::BinRanges => {
                args.arg(u).arg(&offsets).arg(&status).arg(&tile_start);
            }
            Kernel::Raster => {
                args.arg(u)
                    .arg(&view)
                    .arg(&setups)
                    .arg(&attrs)
                    .arg(&tile_start)
                    .arg(&bins)
                    .arg(&status)
                    .arg(&color)
                    .arg(&depth);
            }
            Kernel::Resolve => {
                args.arg(u).arg(&color).arg(&rgba8);
            }
        }
        // SAFETY: the arguments above follow each kernel's C signature in order and type
        // (FrameUniforms and SceneView by value with the checked layout, u32 counts, device
        // addresses as u64). Every address is of a buffer in `scene` or `frame`, sized by
        // `prepare_frame` for this frame's shape and capacities, and the kernels bound every
        // index by those sizes (slot, vertex, tile counts and capacities in `u`).
        unsafe { args.launch(cfg) }.map_err(|e| failed(name, e))?;
        Ok(())
    }

    /// Queues the whole tiled frame.
    pub(super) fn queue_tiled(
        &self,
        u: &FrameUniforms,
        scene: &SceneBuffers,
        frame: &FrameBuffers,
    ) -> Result<(), RenderError> {
        for step in tiled_frame(&frame.shape, self.resolve_rgba8) {
            match step {
                Step::ZeroStatus => self.zero(&frame.status)?,
                Step::ZeroCounts => self.zero(&frame.counts)?,
                Step::Launch {
                    kernel,
                    blocks,
                    threads,
                } => self.launch_step(kernel, blocks, threads, u, scene, frame)?,
                Step::Mark(stage) => self.mark(stage)?,
            }
        }
        Ok(())
    }

    pub(super) fn mark(&self, stage: Stage) -> Result<(), RenderError> {
        let index = match stage {
            Stage::Geometry => 1,
            Stage::Binning => 2,
            Stage::Raster => 3,
        };
        self.events[index]
            .record(&self.stream)
            .map_err(|e| failed("event", e))
    }

    pub(super) fn read_needs(
        &self,
        frame: &FrameBuffers,
    ) -> Result<(Vec<u64>, Needs), RenderError> {
        let words = self
            .stream
            .clone_dtoh(&frame.status)
            .map_err(|e| failed("reading the frame status", e))?;
        let needs = Needs {
            clip: words[status::CLIP_REQUESTED],
            bins: words[status::BIN_TOTAL],
        };
        Ok((words, needs))
    }

    /// Runs the thesis' baselines after the geometry stages: reads the setups back, then one
    /// launch per triangle (ocot) or per batch (ocmt).
    pub(super) fn run_baseline(&mut self, u: &FrameUniforms) -> Result<(), RenderError> {
        let (Some(scene), Some(frame)) = (self.scene.as_ref(), self.frame.as_ref()) else {
            return Err(failed("frame", "no scene loaded"));
        };
        let slots = self
            .stream
            .clone_dtoh(&frame.slots)
            .map_err(|e| failed("reading triangle slots", e))?;
        let mut ordered = Vec::new();
        for pair in slots.chunks_exact(2).take(frame.shape.slots as usize) {
            let info = SlotInfo {
                first: pair[0],
                count: pair[1],
            };
            ordered.extend(info.first..info.first + info.count);
        }
        let view = self.scene_view(scene);
        let (setups, attrs) = (self.addr(&frame.setups), self.addr(&frame.setup_attrs));
        let (color, depth) = (self.addr(&frame.color), self.addr(&frame.depth));
        let (gx, gy) = baseline_grid(u.width, u.height);
        let block = (BASELINE_BLOCK, BASELINE_BLOCK, 1);
        let clear = self.functions.get("kantele_clear")?;
        let mut args = self.stream.launch_builder(clear);
        args.arg(u).arg(&color).arg(&depth);
        // SAFETY: `kantele_clear(FrameUniforms, float4* color, float* depth)`; both buffers
        // hold width × height pixels and the kernel bounds x, y by them.
        unsafe {
            args.launch(LaunchConfig {
                grid_dim: (gx, gy, 1),
                block_dim: block,
                shared_mem_bytes: 0,
            })
        }
        .map_err(|e| failed("kantele_clear", e))?;
        match self.strategy {
            CudaStrategy::Ocot => {
                let bytes = self
                    .stream
                    .clone_dtoh(&frame.setups)
                    .map_err(|e| failed("reading setups", e))?;
                let func = self.functions.get("kantele_ocot_triangle")?;
                for &r in &ordered {
                    let bbox = bbox_of(&bytes, r as usize);
                    let (bx, by) = baseline_grid(bbox.width() as u32, bbox.height() as u32);
                    if bx == 0 || by == 0 {
                        continue;
                    }
                    let mut args = self.stream.launch_builder(func);
                    args.arg(u)
                        .arg(&view)
                        .arg(&setups)
                        .arg(&attrs)
                        .arg(&r)
                        .arg(&color)
                        .arg(&depth);
                    // SAFETY: `kantele_ocot_triangle(FrameUniforms, SceneView, const
                    // TriangleSetup*, const float*, u32 ref, float4*, float*)`; `r` is a setup
                    // written this frame and the grid covers its in-target bounding box.
                    unsafe {
                        args.launch(LaunchConfig {
                            grid_dim: (bx, by, 1),
                            block_dim: block,
                            shared_mem_bytes: 0,
                        })
                    }
                    .map_err(|e| failed("kantele_ocot_triangle", e))?;
                }
            }
            _ => {
                let refs = self.upload(&ordered, 0u32, "ordered triangles")?;
                let refs_addr = self.addr(&refs);
                let func = self.functions.get("kantele_ocmt_batch")?;
                for (first, count) in ocmt_batches(ordered.len() as u32) {
                    let mut args = self.stream.launch_builder(func);
                    args.arg(u)
                        .arg(&view)
                        .arg(&setups)
                        .arg(&attrs)
                        .arg(&refs_addr)
                        .arg(&first)
                        .arg(&count)
                        .arg(&color)
                        .arg(&depth);
                    // SAFETY: `kantele_ocmt_batch(FrameUniforms, SceneView, const
                    // TriangleSetup*, const float*, const u32* refs, u32 first, u32 count,
                    // float4*, float*)`; `refs[first..first + count]` exist and name setups
                    // written this frame.
                    unsafe {
                        args.launch(LaunchConfig {
                            grid_dim: (gx, gy, 1),
                            block_dim: block,
                            shared_mem_bytes: 0,
                        })
                    }
                    .map_err(|e| failed("kantele_ocmt_batch", e))?;
                }
                // Keep the uploaded list alive until the launches are done.
                if let Some(frame) = self.frame.as_mut() {
                    frame.ordered = refs;
                }
            }
        }
        Ok(())
    }
}

/// The bounding box of setup `index` in a read-back setup array.
fn bbox_of(bytes: &[u8], index: usize) -> PixelRect {
    let base = index * size_of::<TriangleSetup>() + std::mem::offset_of!(TriangleSetup, bbox);
    let int = |k: usize| {
        bytes
            .get(base + 4 * k..base + 4 * k + 4)
            .and_then(|b| b.try_into().ok())
            .map_or(0, i32::from_ne_bytes)
    };
    PixelRect {
        x0: int(0),
        y0: int(1),
        x1: int(2),
        y1: int(3),
    }
}
