//! [`CudaBackend`]: the driver calls. Start-up (driver, device, NVRTC, modules, layout probe),
//! scene upload at `load`, the frame's launches at `render`, and the read-back.
//!
//! `unsafe` here is confined to kernel launches (`LaunchArgs::launch`) and one context setting;
//! each launch passes arguments in the order and types of the kernel's C signature, and every
//! buffer it names is owned by this struct and outlives the launch (the stream is synchronised
//! before any buffer is dropped or replaced).

use std::collections::HashMap;
use std::mem::size_of;
use std::sync::Arc;
use std::time::{Duration, Instant};

use cudarc::driver::{
    sys, CudaContext, CudaEvent, CudaFunction, CudaSlice, CudaStream, DevicePtr, DeviceRepr,
    LaunchConfig, PushKernelArg, ValidAsZeroBits,
};
use cudarc::nvrtc::Ptx;
use kantele::backend::{Backend, FrameImage, FrameView, Pass};
use kantele::geometry::clip::GuardBand;
use kantele::scene::Scene;
use kantele::setup::{PixelRect, TriangleSetup};
use kantele::stats::FrameStats;
use kantele::RenderError;

use crate::defines::{MATERIAL_VARYINGS, STATUS_WORDS};
use crate::kernels::{cache_dir, compile_all};
use crate::nvrtc::Nvrtc;
use crate::plan::{
    baseline_grid, ocmt_batches, tiled_frame, Capacities, CudaStrategy, FrameShape, Kernel, Needs,
    Stage, Step, BASELINE_BLOCK, SCAN_THREADS,
};
use crate::records::{
    draw_issue, pass_code, view_projection, DrawIssue, FrameUniforms, SceneArrays, SceneView,
    SlotInfo,
};

const NAME: &str = "cuda";

fn unsupported(message: impl Into<String>) -> RenderError {
    RenderError::Unsupported {
        backend: NAME.into(),
        message: message.into(),
    }
}

fn failed(what: &str, e: impl std::fmt::Display) -> RenderError {
    RenderError::Backend {
        backend: NAME.into(),
        message: format!("{what}: {e}"),
    }
}

/// Whether the CUDA driver library can be opened (no CUDA call is made).
pub fn driver_present() -> bool {
    // SAFETY: only tries `dlopen` on the driver's library names and closes what it opened.
    unsafe { cudarc::driver::sys::is_culib_present() }
}

/// The status words of a frame (see `StatusWord` in common.cuh).
mod status {
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

/// Every kernel entry point by name.
struct Functions(HashMap<&'static str, CudaFunction>);

impl Functions {
    fn get(&self, name: &str) -> Result<&CudaFunction, RenderError> {
        self.0
            .get(name)
            .ok_or_else(|| failed("missing kernel", name))
    }
}

/// The scene's data on the device, uploaded once at `load`.
struct SceneBuffers {
    scene: Arc<Scene>,
    records: Vec<crate::records::DrawRecord>,
    /// The draw order `issue` was last written for.
    issued_order: Vec<usize>,
    issue: CudaSlice<DrawIssue>,
    arrays_shape: (u32, u32, u32), // draws, shaded vertices, slots
    clear_color: [f32; 4],
    ambient: f32,
    vertices: CudaSlice<f32>,
    indices: CudaSlice<u32>,
    draws: CudaSlice<crate::records::DrawRecord>,
    textures: CudaSlice<crate::records::TextureRecord>,
    levels: CudaSlice<crate::records::LevelRecord>,
    texels: CudaSlice<f32>,
}

/// The frame's working buffers, sized for one scene and target size; kept between frames.
struct FrameBuffers {
    shape: FrameShape,
    capacities: Capacities,
    mvp: CudaSlice<f32>,
    pos_clip: CudaSlice<f32>,
    varyings: CudaSlice<f32>,
    setups: CudaSlice<u8>,
    setup_attrs: CudaSlice<f32>,
    slots: CudaSlice<u32>,
    counts: CudaSlice<u32>,
    offsets: CudaSlice<u32>,
    scan_sums: Vec<CudaSlice<u32>>,
    tile_start: CudaSlice<u32>,
    bins: CudaSlice<u32>,
    status: CudaSlice<u64>,
    color: CudaSlice<f32>,
    depth: CudaSlice<f32>,
    rgba8: Option<CudaSlice<u8>>,
    ordered: CudaSlice<u32>,
}

/// The CUDA backend. See the crate docs.
pub struct CudaBackend {
    stream: Arc<CudaStream>,
    functions: Functions,
    device: String,
    strategy: CudaStrategy,
    resolve_rgba8: bool,
    scene: Option<SceneBuffers>,
    frame: Option<FrameBuffers>,
    events: [CudaEvent; 4],
}

impl CudaBackend {
    /// Opens the CUDA driver and the first GPU, compiles the kernels (or takes them from the
    /// disk cache) and checks the record layouts. Without a driver, a device or NVRTC: a
    /// one-line error, never a panic.
    pub fn new() -> Result<Self, RenderError> {
        if !driver_present() {
            return Err(unsupported(
                "no CUDA driver found (libcuda.so could not be opened)",
            ));
        }
        // cudarc panics if a driver function is missing from an unusual libcuda; turn that
        // into an error too.
        match std::panic::catch_unwind(Self::start) {
            Ok(result) => result,
            Err(panic) => {
                let message = panic
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_else(|| "the CUDA driver library is unusable".into());
                Err(unsupported(
                    message.lines().next().unwrap_or("").to_string(),
                ))
            }
        }
    }

    fn start() -> Result<Self, RenderError> {
        let ctx = CudaContext::new(0).map_err(|e| unsupported(format!("no CUDA device: {e}")))?;
        // SAFETY: the backend uses one stream only, so cudarc's cross-stream event tracking is
        // not needed; every buffer is used on that stream in order.
        unsafe { ctx.disable_event_tracking() };
        let stream = ctx.default_stream();
        let device = ctx.name().map_err(|e| failed("device name", e))?;
        let (major, minor) = ctx
            .compute_capability()
            .map_err(|e| failed("compute capability", e))?;
        let arch = (major * 10 + minor) as u32;
        let nvrtc = Nvrtc::load().map_err(|e| unsupported(e.to_string()))?;
        let cache = cache_dir();
        let compiled = compile_all(&nvrtc, arch, cache.as_deref())
            .map_err(|e| failed("compiling kernels", e))?;
        let mut functions = HashMap::new();
        for (source, ptx) in compiled {
            let module = ctx
                .load_module(Ptx::from_src(ptx))
                .map_err(|e| failed(&format!("loading {}", source.name), e))?;
            for &entry in source.entry_points {
                let f = module
                    .load_function(entry)
                    .map_err(|e| failed(&format!("kernel {entry}"), e))?;
                functions.insert(entry, f);
            }
        }
        let event = || {
            ctx.new_event(Some(sys::CUevent_flags::CU_EVENT_DEFAULT))
                .map_err(|e| failed("event", e))
        };
        let events = [event()?, event()?, event()?, event()?];
        let backend = Self {
            stream,
            functions: Functions(functions),
            device: format!("{device} (sm_{arch})"),
            strategy: CudaStrategy::Tiled,
            resolve_rgba8: false,
            scene: None,
            frame: None,
            events,
        };
        backend.check_layout()?;
        Ok(backend)
    }

    /// The GPU's name and compute capability.
    pub fn device(&self) -> &str {
        &self.device
    }

    /// The rasterization scheme in use.
    pub fn strategy(&self) -> CudaStrategy {
        self.strategy
    }

    /// Chooses the rasterization scheme (the tiled pipeline or a thesis baseline).
    pub fn set_strategy(&mut self, strategy: CudaStrategy) {
        self.strategy = strategy;
    }

    /// With `true`, every frame also resolves to 8-bit sRGB on the device (the counterpart of
    /// the GL backend's RGBA8 target for timing); read it with [`CudaBackend::read_rgba8`].
    pub fn set_resolve_rgba8(&mut self, resolve: bool) {
        self.resolve_rgba8 = resolve;
    }

    /// The last frame as 8-bit sRGB RGBA (row 0 at the top), when resolving is on.
    pub fn read_rgba8(&mut self) -> Result<Option<Vec<u8>>, RenderError> {
        let Some(frame) = &self.frame else {
            return Ok(None);
        };
        match &frame.rgba8 {
            Some(buffer) => Ok(Some(
                self.stream
                    .clone_dtoh(buffer)
                    .map_err(|e| failed("reading the 8-bit frame", e))?,
            )),
            None => Ok(None),
        }
    }

    fn alloc<T: DeviceRepr + ValidAsZeroBits>(
        &self,
        len: usize,
        what: &str,
    ) -> Result<CudaSlice<T>, RenderError> {
        self.stream
            .alloc_zeros::<T>(len.max(1))
            .map_err(|e| failed(&format!("allocating {what} ({len} elements)"), e))
    }

    fn upload<T: DeviceRepr + Clone>(
        &self,
        data: &[T],
        filler: T,
        what: &str,
    ) -> Result<CudaSlice<T>, RenderError> {
        // Zero-length device buffers are not allowed: upload one filler element instead.
        let one = [filler];
        let data = if data.is_empty() { &one[..] } else { data };
        self.stream
            .clone_htod(data)
            .map_err(|e| failed(&format!("uploading {what}"), e))
    }

    fn addr<T>(&self, buffer: &CudaSlice<T>) -> u64 {
        let (ptr, _sync) = buffer.device_ptr(&self.stream);
        ptr
    }

    /// Runs `kantele_layout_probe` and compares the kernels' field offsets with Rust's.
    fn check_layout(&self) -> Result<(), RenderError> {
        let fields = crate::layout::fields();
        let scratch = self.alloc::<u8>(4096, "layout probe")?;
        let out = self.alloc::<u64>(fields.len() + 8, "layout probe")?;
        let base = self.addr(&scratch);
        let (t, d, f, l) = (base, base + 1024, base + 2048, base + 3072);
        let o = self.addr(&out);
        let func = self.functions.get("kantele_layout_probe")?;
        let mut args = self.stream.launch_builder(func);
        args.arg(&t).arg(&d).arg(&f).arg(&l).arg(&o);
        // SAFETY: `kantele_layout_probe(const TriangleSetup*, const DrawRecord*, const
        // FrameUniforms*, const LevelRecord*, u64* out)`: four pointers into `scratch` (only
        // their addresses are used) and `out`, which holds more than the 28 words written.
        unsafe { args.launch(LaunchConfig::for_num_elems(1)) }
            .map_err(|e| failed("layout probe", e))?;
        let offsets = self
            .stream
            .clone_dtoh(&out)
            .map_err(|e| failed("layout probe", e))?;
        crate::layout::check(&offsets).map_err(|e| failed("layout check", e))
    }

    fn uniforms(
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

    /// (Re)allocates the frame buffers when the shape or capacities changed.
    fn prepare_frame(
        &mut self,
        shape: FrameShape,
        capacities: Capacities,
    ) -> Result<(), RenderError> {
        if let Some(f) = &self.frame {
            if f.shape == shape
                && f.capacities == capacities
                && f.rgba8.is_some() == self.resolve_rgba8
            {
                return Ok(());
            }
        }
        self.stream
            .synchronize()
            .map_err(|e| failed("synchronising", e))?;
        self.frame = None;
        let setups_len = shape.slots as usize + capacities.clip as usize;
        let pixels = shape.width as usize * shape.height as usize;
        let cells = shape.matrix_cells() as usize;
        let levels = crate::plan::scan_levels(cells as u64);
        let mut scan_sums = Vec::new();
        for &n in &levels {
            scan_sums
                .push(self.alloc::<u32>(n.div_ceil(SCAN_THREADS as u64) as usize, "scan sums")?);
        }
        let frame = FrameBuffers {
            shape,
            capacities,
            mvp: self.alloc(16 * shape.draws as usize, "matrices")?,
            pos_clip: self.alloc(4 * shape.shaded as usize, "clip positions")?,
            varyings: self.alloc(MATERIAL_VARYINGS * shape.shaded as usize, "varyings")?,
            setups: self.alloc(size_of::<TriangleSetup>() * setups_len, "triangle setups")?,
            setup_attrs: self.alloc(3 * MATERIAL_VARYINGS * setups_len, "setup varyings")?,
            slots: self.alloc(2 * shape.slots as usize, "triangle slots")?,
            counts: self.alloc(cells, "bin counts")?,
            offsets: self.alloc(cells, "bin offsets")?,
            scan_sums,
            tile_start: self.alloc(shape.tiles() as usize + 1, "tile ranges")?,
            bins: self.alloc(capacities.bins as usize, "bins")?,
            status: self.alloc(STATUS_WORDS, "status")?,
            color: self.alloc(4 * pixels, "colour buffer")?,
            depth: self.alloc(pixels, "depth buffer")?,
            rgba8: if self.resolve_rgba8 {
                Some(self.alloc(4 * pixels, "8-bit colour buffer")?)
            } else {
                None
            },
            ordered: self.alloc(1, "ordered triangles")?,
        };
        self.frame = Some(frame);
        Ok(())
    }

    fn scene_view(&self, scene: &SceneBuffers) -> SceneView {
        SceneView {
            draws: self.addr(&scene.draws),
            textures: self.addr(&scene.textures),
            levels: self.addr(&scene.levels),
            texels: self.addr(&scene.texels),
        }
    }

    /// Queues one kernel of the tiled frame.
    fn launch_step(
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
    fn queue_tiled(
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

    fn zero<T: DeviceRepr + ValidAsZeroBits>(
        &self,
        buffer: &CudaSlice<T>,
    ) -> Result<(), RenderError> {
        let ptr = self.addr(buffer);
        let bytes = buffer.len() * size_of::<T>();
        // SAFETY: `ptr` is the start of `buffer`, which holds `bytes` bytes; the memset is
        // queued on the same stream as every use of the buffer.
        unsafe { cudarc::driver::result::memset_d8_async(ptr, 0, bytes, self.stream.cu_stream()) }
            .map_err(|e| failed("clearing a buffer", e))
    }

    fn mark(&self, stage: Stage) -> Result<(), RenderError> {
        let index = match stage {
            Stage::Geometry => 1,
            Stage::Binning => 2,
            Stage::Raster => 3,
        };
        self.events[index]
            .record(&self.stream)
            .map_err(|e| failed("event", e))
    }

    fn read_needs(&self, frame: &FrameBuffers) -> Result<(Vec<u64>, Needs), RenderError> {
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
    fn run_baseline(&mut self, u: &FrameUniforms) -> Result<(), RenderError> {
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

impl Backend for CudaBackend {
    fn name(&self) -> &str {
        NAME
    }

    fn renderer(&self) -> String {
        format!("kantele cuda ({}, {})", self.strategy, self.device)
    }

    fn threads(&self) -> usize {
        1
    }

    fn load(&mut self, scene: Arc<Scene>) -> Result<(), RenderError> {
        scene.validate()?;
        let arrays = SceneArrays::new(&scene).map_err(|e| unsupported(e.to_string()))?;
        self.stream
            .synchronize()
            .map_err(|e| failed("synchronising", e))?;
        self.frame = None;
        self.scene = None;
        let vertices: Vec<f32> = arrays
            .vertices
            .iter()
            .flat_map(|v| {
                let mut f = [0.0f32; 12];
                f[..3].copy_from_slice(&v.position.to_array());
                f[3..6].copy_from_slice(&v.normal.to_array());
                f[6..8].copy_from_slice(&v.texcoord.to_array());
                f[8..].copy_from_slice(&v.color.to_array());
                f
            })
            .collect();
        let texels: Vec<f32> = arrays.texels.iter().flatten().copied().collect();
        let order: Vec<usize> = (0..arrays.draws.len()).collect();
        let issue = draw_issue(&arrays.draws, &order);
        let buffers = SceneBuffers {
            scene: scene.clone(),
            records: arrays.draws.clone(),
            issued_order: order,
            issue: self.upload(&issue, DrawIssue::default(), "draw order")?,
            arrays_shape: (
                arrays.draws.len() as u32,
                arrays.shaded_count,
                arrays.slot_count,
            ),
            clear_color: scene.clear_color.to_array(),
            ambient: scene.ambient,
            vertices: self.upload(&vertices, 0.0, "vertices")?,
            indices: self.upload(&arrays.indices, 0, "indices")?,
            draws: self.upload(&arrays.draws, Default::default(), "draws")?,
            textures: self.upload(&arrays.textures, Default::default(), "textures")?,
            levels: self.upload(&arrays.levels, Default::default(), "mip levels")?,
            texels: self.upload(&texels, 0.0, "texels")?,
        };
        self.scene = Some(buffers);
        Ok(())
    }

    fn render(&mut self, view: &FrameView) -> Result<FrameStats, RenderError> {
        let wall = Instant::now();
        if view.width == 0
            || view.height == 0
            || view.width > kantele::MAX_TARGET_SIZE
            || view.height > kantele::MAX_TARGET_SIZE
        {
            return Err(RenderError::InvalidSize {
                width: view.width,
                height: view.height,
            });
        }
        let Some(scene) = self.scene.as_mut() else {
            return Err(RenderError::InvalidScene("no scene loaded".into()));
        };
        // The reference-scene rule: BLEND draws last, back to front for this camera. The order
        // (and so the slots' submission order) is uploaded only when it changes.
        let order = scene.scene.draw_order(&view.view);
        if order != scene.issued_order && !order.is_empty() {
            let issue = draw_issue(&scene.records, &order);
            self.stream
                .memcpy_htod(&issue, &mut scene.issue)
                .map_err(|e| failed("uploading the draw order", e))?;
            scene.issued_order = order;
        }
        let (draws, shaded, slots) = scene.arrays_shape;
        let shape = FrameShape {
            width: view.width,
            height: view.height,
            draws,
            shaded,
            slots,
        };
        let mut capacities = match &self.frame {
            Some(f) if f.shape == shape => f.capacities,
            _ => Capacities::initial(&shape),
        };
        // A frame that overflowed is redone with the buffers grown to what it needed. The needs
        // are exact, so this settles after at most two redos (clipped fans, then the bins their
        // growth adds); the bound only guards against a logic error.
        for _attempt in 0..4 {
            self.prepare_frame(shape, capacities)?;
            let (Some(scene), Some(frame)) = (self.scene.as_ref(), self.frame.as_ref()) else {
                return Err(failed("frame", "buffers missing"));
            };
            let u = self.uniforms(view, frame, scene);
            self.events[0]
                .record(&self.stream)
                .map_err(|e| failed("event", e))?;
            match self.strategy {
                CudaStrategy::Tiled => self.queue_tiled(&u, scene, frame)?,
                CudaStrategy::Ocot | CudaStrategy::Ocmt => {
                    self.zero(&frame.status)?;
                    for kernel in [Kernel::DrawMatrices, Kernel::Vertex, Kernel::Primitive] {
                        if let Some(Step::Launch {
                            kernel,
                            blocks,
                            threads,
                        }) = tiled_frame(&frame.shape, false)
                            .into_iter()
                            .find(|s| matches!(s, Step::Launch { kernel: k, .. } if *k == kernel))
                        {
                            self.launch_step(kernel, blocks, threads, &u, scene, frame)?;
                        }
                    }
                    self.mark(Stage::Geometry)?;
                    let (_, needs) = self.read_needs(frame)?;
                    if needs.clip <= frame.capacities.clip as u64 {
                        self.run_baseline(&u)?;
                    }
                    self.mark(Stage::Binning)?;
                    self.mark(Stage::Raster)?;
                }
            }
            let Some(frame) = self.frame.as_ref() else {
                return Err(failed("frame", "buffers missing"));
            };
            let (words, mut needs) = self.read_needs(frame)?;
            if self.strategy != CudaStrategy::Tiled {
                needs.bins = 0;
            }
            if !frame.capacities.fits(&needs) {
                capacities = frame
                    .capacities
                    .grown(&needs, shape.slots)
                    .map_err(unsupported)?;
                continue;
            }
            let ms = |a: usize, b: usize| -> Duration {
                self.events[a]
                    .elapsed_ms(&self.events[b])
                    .map(|ms| Duration::from_secs_f64(ms.max(0.0) as f64 / 1000.0))
                    .unwrap_or_default()
            };
            return Ok(FrameStats {
                draws: draws as u64,
                triangles_in: words[status::TRIANGLES_IN],
                triangles_invalid: words[status::INVALID],
                triangles_rejected: words[status::REJECTED],
                triangles_clipped: words[status::CLIPPED],
                triangles_culled: words[status::CULLED],
                triangles_degenerate: words[status::DEGENERATE],
                triangles_binned: words[status::BINNED],
                bin_entries: if self.strategy == CudaStrategy::Tiled {
                    words[status::BIN_TOTAL]
                } else {
                    0
                },
                tiles_depth_rejected: 0,
                fragments_covered: words[status::COVERED],
                fragments_shaded: words[status::SHADED],
                fragments_discarded: words[status::DISCARDED],
                geometry_time: ms(0, 1),
                binning_time: ms(1, 2),
                raster_time: ms(2, 3),
                total_time: wall.elapsed(),
                ..FrameStats::default()
            });
        }
        Err(failed(
            "frame",
            "buffers still overflow after growing (this is a bug)",
        ))
    }

    fn read_frame(&mut self) -> Result<FrameImage, RenderError> {
        let Some(frame) = &self.frame else {
            return Err(RenderError::InvalidScene("no frame rendered".into()));
        };
        let color = self
            .stream
            .clone_dtoh(&frame.color)
            .map_err(|e| failed("reading colour", e))?;
        let depth = self
            .stream
            .clone_dtoh(&frame.depth)
            .map_err(|e| failed("reading depth", e))?;
        let pixels = frame.shape.width as usize * frame.shape.height as usize;
        Ok(FrameImage {
            width: frame.shape.width,
            height: frame.shape.height,
            color: color
                .chunks_exact(4)
                .take(pixels)
                .map(|c| [c[0], c[1], c[2], c[3]])
                .collect(),
            depth: depth.into_iter().take(pixels).collect(),
        })
    }
}

impl Drop for CudaBackend {
    fn drop(&mut self) {
        // Let queued work finish before its buffers are freed.
        let _ = self.stream.synchronize();
    }
}
