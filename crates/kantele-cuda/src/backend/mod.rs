//! [`CudaBackend`]: the driver calls. Start-up (driver, device, NVRTC, modules, layout probe),
//! scene upload at `load`, the frame's launches at `render`, and the read-back. The device
//! buffers and their helpers are in [`device`], the launch sequence of a frame in [`launch`].
//!
//! `unsafe` here is confined to kernel launches (`LaunchArgs::launch`) and one context setting;
//! each launch passes arguments in the order and types of the kernel's C signature, and every
//! buffer it names is owned by this struct and outlives the launch (the stream is synchronised
//! before any buffer is dropped or replaced).

mod device;
mod launch;

use std::collections::HashMap;
use std::sync::Arc;
use std::time::{Duration, Instant};

use cudarc::driver::{
    sys, CudaContext, CudaEvent, CudaFunction, CudaStream, LaunchConfig, PushKernelArg,
};
use cudarc::nvrtc::Ptx;
use kantele_rules::backend::{Backend, FrameImage, FrameView};
use kantele_rules::scene::Scene;
use kantele_rules::stats::FrameStats;
use kantele_rules::RenderError;

use self::device::{FrameBuffers, SceneBuffers};
use self::launch::status;
use crate::kernels::{cache_dir, compile_all};
use crate::nvrtc::Nvrtc;
use crate::plan::{tiled_frame, Capacities, CudaStrategy, FrameShape, Kernel, Stage, Step};
use crate::records::{draw_issue, DrawIssue, SceneArrays};

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

/// Every kernel entry point by name.
struct Functions(HashMap<&'static str, CudaFunction>);

impl Functions {
    fn get(&self, name: &str) -> Result<&CudaFunction, RenderError> {
        self.0
            .get(name)
            .ok_or_else(|| failed("missing kernel", name))
    }
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
        if scene.shading == kantele_rules::scene::Shading::Pbr {
            return Err(unsupported(
                "PBR shading is not implemented in the CUDA kernels yet; draw the file with --shading lambert, or with the cpu or gl backend".to_string(),
            ));
        }
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
            || view.width > kantele_rules::MAX_TARGET_SIZE
            || view.height > kantele_rules::MAX_TARGET_SIZE
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
