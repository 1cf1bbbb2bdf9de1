//! The OpenGL reference backend of Kantele ("the yardstick"): renders a [`Scene`] by Kantele's
//! rendering rules (`docs/rendering-rules.md`) with a desktop OpenGL 3.3 core context created
//! headlessly through EGL, so that Kantele's pictures and timings can be compared with a
//! real GL driver (Mesa's llvmpipe on CI, a GPU driver where there is one).
//!
//! The entry point is [`GlBackend`]: [`GlBackend::new`] creates the context (or returns an
//! error when no EGL/OpenGL is available), and the [`Backend`] trait does the rest: `load` a
//! scene once, `render` a [`kantele_rules::backend::FrameView`], then `read_frame`. The
//! `unsafe` GL and EGL calls of the workspace live in this crate. The core `kantele` crate
//! forbids `unsafe`.
//!
//! ```no_run
//! use std::sync::Arc;
//! use kantele_rules::backend::{Backend, FrameView};
//! use kantele_rules::scene::Scene;
//!
//! # fn scene() -> Scene { unimplemented!() }
//! let scene = Arc::new(scene()); // e.g. from kantele-scene
//! let mut gl = kantele_gl::GlBackend::new()?;
//! gl.load(scene.clone())?;
//! gl.render(&FrameView::of_scene(&scene))?;
//! let image = gl.read_frame()?; // linear RGBA + depth, row 0 = top
//! # Ok::<(), kantele_rules::RenderError>(())
//! ```
//!
//! # How the rules map onto GL
//!
//! - **Orientation.** The projection is y-flipped (`diag(1, −1, 1, 1) · projection`), so window
//!   row 0 is image row 0 and `glReadPixels` returns the top row first without any copy-flip.
//!   The flip mirrors the winding, so `glFrontFace(GL_CW)` keeps counter-clockwise-in-NDC
//!   triangles front-facing (and `gl_FrontFacing` keeps its meaning). Rendered this way, llvmpipe
//!   and NVIDIA apply the rules' top-left tie rule in image coordinates.
//! - **Colour target.** `GL_RGBA32F` by default: linear float values, encoded to sRGB exactly on
//!   the host when written as 8-bit. [`GlBackend::set_fast_target`] switches to `GL_RGBA8` (no
//!   sRGB encoding by the driver), the fair configuration for *timings* (8-bit stores, as a real
//!   application would use); its pictures are quantised and it only renders [`Pass::Color`].
//! - **Depth.** `GL_DEPTH_COMPONENT32F`, cleared to 1, test `GL_LESS`, default depth range, so
//!   window depth = `(z/w + 1) / 2`.
//! - **Multisampling** ([`Backend::set_samples`]): colour frames are drawn into a multisampled
//!   framebuffer (`glRenderbufferStorageMultisample`, the same colour format and
//!   `GL_DEPTH_COMPONENT32F`), resolved into the single-sample target with
//!   `glBlitFramebuffer` (GL averages the samples of a float target in linear space). The
//!   count is checked against `GL_MAX_SAMPLES` (llvmpipe: 4, so 8× is CPU-only there). The
//!   depth read back after a multisampled frame is the per-pixel depth of kantele's rule: the
//!   frame's depth drawn once more at 1× (colour writes off) when it is read back, so it equals
//!   a 1× render's; the normal and id passes are always drawn at 1×.
//! - **Textures.** Every level of kantele's mip chain ([`Texture::levels`]) is uploaded as
//!   its 8-bit texels, `GL_SRGB8_ALPHA8` for sRGB textures and `GL_RGBA8` otherwise, so both
//!   renderers decode and filter identical texels. Rows go up in memory
//!   order: the image's top row is GL's `t = 0` row, which is where glTF's `v = 0` points. One
//!   sampler object per texture binding of a material carries the glTF wrap modes and filters.
//!   The metallic-roughness, normal and occlusion textures are linear, hence `GL_RGBA8`.
//! - **Meshes without normals** are split into one vertex triple per triangle carrying the
//!   object-space face normal (flat shading).
//! - **Alpha.** OPAQUE writes alpha 1; MASK discards fragments with alpha below the cutoff and
//!   writes alpha 1; BLEND uses `glBlendFuncSeparate(SRC_ALPHA, ONE_MINUS_SRC_ALPHA, ONE,
//!   ONE_MINUS_SRC_ALPHA)` with depth writes off, so the stored alpha is
//!   `src.a + dst.a × (1 − src.a)` (the "over" operator's coverage).
//! - **PBR.** Scenes whose [`Scene::shading`] is [`Shading::Pbr`] are drawn with a second
//!   program (the Lambert one is untouched) that follows `kantele_rules::shade::pbr`
//!   operation for operation: metallic-roughness (blue, green), occlusion (red) and normal
//!   textures, up to [`MAX_LIGHTS`] punctual lights as uniform arrays, the environment, exposure
//!   and the tone map, all from [`PbrLighting::for_frame`]. The tangent of normal mapping comes
//!   from `dFdx`/`dFdy` of the world position and texture coordinate (the y-flip makes `dFdy`
//!   the derivative towards increasing image row, as the CPU's). The environment is uploaded
//!   at `load`: the SH coefficients are uniforms, the six pre-filtered octahedral levels share
//!   one `GL_RGB32F` atlas and the split-sum table is a `GL_RG32F` texture, all read with
//!   `texelFetch` and the rules' own bilinear arithmetic, never GL's filtering; the split-sum
//!   table is uploaded for every PBR scene (transmission reads it without an environment). The
//!   normal pass writes the normal-mapped normal.
//! - **Transmission** (`KHR_materials_transmission`, `KHR_materials_volume`). A PBR colour
//!   frame with a transmissive draw first draws its backdrop as the rules define it
//!   (`kantele_rules::shade::transmission`): the draws neither transmissive nor blended, no
//!   tone map, exposure 1, at `backdrop_size`, one sample, into a `GL_RGBA32F` framebuffer. It
//!   is read back into the rules' `Backdrop`, whose own box-filtered chain is uploaded level by
//!   level as a `GL_RGB32F` texture (explicit base and max levels, top row at `t = 0`), so both
//!   backends filter the same texels; the frame then reads it with `textureLod`
//!   (`GL_LINEAR_MIPMAP_LINEAR`, clamped to the edge) at the refracted exit point projected by
//!   the frame's view-projection. Each transmissive draw's `Volume` (index of refraction,
//!   scale, Beer coefficients, level-of-detail scale) is computed on the host by the rules.
//!   Other draws and frames are drawn as before.
//! - **Sheen** (`KHR_materials_sheen`) follows `kantele_rules::shade::sheen`: the Charlie lobe
//!   per light, the image-based sheen and the scale of the base under it, with the lobe's
//!   albedo table computed by the rules and uploaded at `load` (for a scene with a sheen) as a
//!   `GL_R32F` texture, read as the split-sum table is. With the sheen's two textures the PBR
//!   fragment shader reads 18 samplers, more than OpenGL 3.3 guarantees (16):
//!   [`GlBackend::new`] fails with one line where `GL_MAX_TEXTURE_IMAGE_UNITS` is smaller
//!   (llvmpipe and NVIDIA offer 32).
//! - **Passes.** [`Pass::Normals`] writes the world normal after two-sided flipping, alpha 1;
//!   [`Pass::Ids`] writes `(node_index + 1, gl_PrimitiveID + 1, draw index + 1, 1)`. Both clear to
//!   0 and never blend; MASK discards as in the colour pass and BLEND geometry is drawn without
//!   depth writes (it overwrites what lies behind it).
//!
//! # What a machine needs
//!
//! Nothing at build time (`libEGL.so.1` is opened with `dlopen`). At run time on Debian/Ubuntu:
//! `apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri` (glvnd's libEGL, Mesa's EGL vendor
//! library, and the DRI drivers with llvmpipe); neither libGL nor libGLES is used. Without them
//! [`GlBackend::new`] returns an error and the tests skip.
//!
//! # Threads
//!
//! A GL context is current on one thread at a time: [`GlBackend`] is neither `Send` nor `Sync`
//! and must be used (and dropped) on the thread that created it. Several backends may live on
//! one thread; each makes its own context current before it works.
#![warn(missing_docs)]
#![warn(unsafe_op_in_unsafe_fn)]

mod draw;
mod egl;
mod pbr;
mod program;
mod resources;
mod shaders;
mod target;

use std::marker::PhantomData;
use std::sync::Arc;
use std::time::Instant;

use glow::HasContext;
use kantele_rules::backend::{Backend, FrameImage, FrameView, Pass};
use kantele_rules::multisample::SampleCount;
use kantele_rules::scene::Scene;
use kantele_rules::stats::FrameStats;
use kantele_rules::RenderError;

#[cfg(doc)]
use kantele_rules::scene::Shading;
#[cfg(doc)]
use kantele_rules::shade::pbr::{PbrLighting, MAX_LIGHTS};
#[cfg(doc)]
use kantele_rules::shade::texture::Texture;

use crate::egl::EglContext;
use crate::pbr::{pbr_uniforms, PbrUniforms};
use crate::program::{build_program, uniforms, Uniforms};
use crate::resources::GpuScene;
use crate::target::Target;

const NAME: &str = "gl";

fn backend_error(message: impl Into<String>) -> RenderError {
    RenderError::Backend {
        backend: NAME.into(),
        message: message.into(),
    }
}

fn unsupported(message: impl Into<String>) -> RenderError {
    RenderError::Unsupported {
        backend: NAME.into(),
        message: message.into(),
    }
}

/// The OpenGL backend: a headless EGL context, the scene's meshes and textures in GL objects, and
/// an offscreen framebuffer.
///
/// Not `Send`: the GL context belongs to the creating thread (see the crate docs).
pub struct GlBackend {
    // `Drop` deletes the GL objects; then the fields drop in order, `egl` (the context) last.
    gl: glow::Context,
    /// The Lambert program (`Shading::Lambert` scenes).
    program: glow::Program,
    uniforms: Uniforms,
    /// The PBR program (`Shading::Pbr` scenes).
    pbr_program: glow::Program,
    pbr_uniforms: PbrUniforms,
    scene: Option<Arc<Scene>>,
    gpu: GpuScene,
    target: Option<Target>,
    fast_target: bool,
    /// Pass of the last frame rendered into `target` (`None`: nothing rendered yet).
    last_pass: Option<Pass>,
    /// Samples per pixel of colour frames.
    samples: SampleCount,
    /// `GL_MAX_SAMPLES` of the driver.
    max_samples: i32,
    /// The view of the last frame when it was multisampled: its per-pixel depth is drawn at
    /// read-back.
    multisampled_view: Option<FrameView>,
    renderer: String,
    version: String,
    egl: EglContext,
    /// Keeps the type `!Send` and `!Sync`: the context is current on the creating thread only.
    _not_send: PhantomData<*const ()>,
}

impl GlBackend {
    /// Creates a headless desktop OpenGL 3.3+ core context and the shader programs (Lambert and
    /// PBR).
    ///
    /// `libEGL.so.1` is loaded at run time. Displays are tried in this order: an
    /// `EGL_EXT_platform_device` hardware device (NVIDIA's EGL has no surfaceless platform),
    /// Mesa's surfaceless platform (`EGL_MESA_platform_surfaceless`: llvmpipe without a GPU), a
    /// software device, then `EGL_DEFAULT_DISPLAY`. The environment variable
    /// `KANTELE_GL_PLATFORM` = `surfaceless`, `device`, `device:N` or `default` forces one
    /// (`LIBGL_ALWAYS_SOFTWARE=1` makes Mesa use llvmpipe on any of them). The context is made
    /// current without a surface (`EGL_KHR_surfaceless_context`).
    ///
    /// Fails with [`RenderError::Backend`] (never panics) when EGL, a display or a context is not
    /// available (the message lists every attempt), or when the context's fragment stage has
    /// fewer texture units than the PBR program reads (18, `GL_MAX_TEXTURE_IMAGE_UNITS`).
    pub fn new() -> Result<Self, RenderError> {
        // EGL wrappers unwrap a few driver answers (an error code EGL does not define); a broken
        // driver must still only make `new` fail, so a panic in there is caught and reported.
        let egl = std::panic::catch_unwind(EglContext::new)
            .unwrap_or_else(|_| Err("EGL set-up panicked (broken EGL driver?)".into()))
            .map_err(backend_error)?;
        // SAFETY: the context was just made current on this thread; the loader returns EGL's
        // addresses for GL functions (null for unknown ones, which glow tolerates).
        let gl = unsafe { glow::Context::from_loader_function(|name| egl.proc_address(name)) };
        // SAFETY: `gl` is current on this thread.
        let (renderer, version) = unsafe {
            (
                gl.get_parameter_string(glow::RENDERER),
                gl.get_parameter_string(glow::VERSION),
            )
        };
        let supported = gl.version();
        if (supported.major, supported.minor) < (3, 3) || supported.is_embedded {
            return Err(backend_error(format!(
                "need desktop OpenGL 3.3 core, got \"{version}\" ({renderer})"
            )));
        }
        // SAFETY: `gl` is current on this thread.
        let program = unsafe { build_program(&gl, shaders::VERTEX, shaders::FRAGMENT) }
            .map_err(backend_error)?;
        // SAFETY: `gl` is current on this thread.
        let texture_units = unsafe { gl.get_parameter_i32(glow::MAX_TEXTURE_IMAGE_UNITS) };
        let pbr_program = pbr::check_texture_units(texture_units)
            // SAFETY: `gl` is current on this thread.
            .and_then(|()| unsafe { build_program(&gl, pbr::VERTEX, &pbr::fragment_source()) })
            .map_err(|e| backend_error(format!("PBR program: {e}")))?;
        // SAFETY: `gl` is current; the programs are ours and linked.
        let (uniforms, pbr_uniforms) =
            unsafe { (uniforms(&gl, program), pbr_uniforms(&gl, pbr_program)) };
        // SAFETY: `gl` is current on this thread.
        let max_samples = unsafe { gl.get_parameter_i32(glow::MAX_SAMPLES) };
        let backend = Self {
            gl,
            program,
            uniforms,
            pbr_program,
            pbr_uniforms,
            scene: None,
            gpu: GpuScene::default(),
            target: None,
            fast_target: false,
            last_pass: None,
            samples: SampleCount::X1,
            max_samples,
            multisampled_view: None,
            renderer,
            version,
            egl,
            _not_send: PhantomData,
        };
        backend.check("creating the context")?;
        Ok(backend)
    }

    /// Selects the colour target format: `false` (default) renders into `GL_RGBA32F`, the
    /// reference configuration for pictures; `true` renders into `GL_RGBA8`, the fair
    /// configuration for timings (what an application would draw into). Only [`Pass::Color`] can
    /// be rendered into the 8-bit target. Takes effect at the next frame.
    pub fn set_fast_target(&mut self, fast: bool) {
        self.fast_target = fast;
    }

    /// Whether the 8-bit colour target is selected (see [`GlBackend::set_fast_target`]).
    pub fn fast_target(&self) -> bool {
        self.fast_target
    }

    /// `GL_MAX_SAMPLES`: the most samples per pixel the driver offers (llvmpipe: 4).
    pub fn max_samples(&self) -> u32 {
        self.max_samples.max(1) as u32
    }

    /// The `GL_RENDERER` string, e.g. `llvmpipe (LLVM 15.0.6, 256 bits)`.
    pub fn gl_renderer(&self) -> &str {
        &self.renderer
    }

    /// The `GL_VERSION` string, e.g. `4.5 (Core Profile) Mesa 22.3.6`.
    pub fn gl_version(&self) -> &str {
        &self.version
    }

    /// How the EGL display was opened and its EGL version, e.g. `EGL surfaceless, EGL 1.5`.
    pub fn platform(&self) -> String {
        let (major, minor) = self.egl.version;
        format!("{}, EGL {major}.{minor}", self.egl.platform)
    }

    /// Makes this backend's context current on the calling thread if another one is.
    fn make_current(&self) -> Result<(), RenderError> {
        self.egl.make_current().map_err(backend_error)
    }

    /// `glGetError` after a phase: any error becomes [`RenderError::Backend`] naming the phase.
    fn check(&self, phase: &str) -> Result<(), RenderError> {
        let mut errors = Vec::new();
        // SAFETY: `gl` is current on this thread (every caller made it so). glGetError returns
        // NO_ERROR once the error flags are drained; the bound keeps a lost context from looping.
        unsafe {
            for _ in 0..16 {
                match self.gl.get_error() {
                    glow::NO_ERROR => break,
                    e => errors.push(gl_error_name(e)),
                }
            }
        }
        if errors.is_empty() {
            Ok(())
        } else {
            Err(backend_error(format!(
                "GL error while {phase}: {}",
                errors.join(", ")
            )))
        }
    }
}

impl Backend for GlBackend {
    fn name(&self) -> &str {
        NAME
    }

    /// The `GL_RENDERER` string, e.g. `llvmpipe (LLVM 15.0.6, 256 bits)`.
    fn renderer(&self) -> String {
        self.renderer.clone()
    }

    /// `GL_RGBA8` (`"rgba8"`) with [`GlBackend::set_fast_target`], else `GL_RGBA32F` (`"f32"`).
    fn target(&self) -> String {
        match self.fast_target {
            true => "rgba8",
            false => "f32",
        }
        .to_string()
    }

    /// For llvmpipe, its rasterizer threads (`LP_NUM_THREADS`, else the number of cores, as
    /// Mesa chooses them); 1 for a GPU driver.
    fn threads(&self) -> usize {
        if !self.renderer.starts_with("llvmpipe") {
            return 1;
        }
        std::env::var("LP_NUM_THREADS")
            .ok()
            .and_then(|v| v.trim().parse::<usize>().ok())
            .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
    }

    fn load(&mut self, scene: Arc<Scene>) -> Result<(), RenderError> {
        scene.validate()?;
        self.make_current()?;
        // SAFETY: the context is current on this thread; the old objects are ours.
        unsafe { self.gpu.delete(&self.gl) };
        self.scene = None;
        // SAFETY: the context is current on this thread.
        self.gpu = unsafe { GpuScene::upload(&self.gl, &scene) }
            .map_err(|e| backend_error(format!("uploading the scene: {e}")))?;
        self.check("uploading the scene")?;
        self.scene = Some(scene);
        Ok(())
    }

    fn render(&mut self, view: &FrameView) -> Result<FrameStats, RenderError> {
        let scene = self
            .scene
            .clone()
            .ok_or_else(|| backend_error("render called before load"))?;
        let (width, height) = (view.width, view.height);
        let side_ok = |s: u32| (1..=kantele_rules::MAX_TARGET_SIZE).contains(&s);
        if !side_ok(width) || !side_ok(height) {
            return Err(RenderError::InvalidSize { width, height });
        }
        if self.fast_target && view.pass != Pass::Color {
            return Err(unsupported(format!(
                "{:?} pass needs the float target (set_fast_target(false))",
                view.pass
            )));
        }
        // Ids and normals are never averaged: those passes are drawn at 1×.
        let samples = match view.pass {
            Pass::Color => self.samples,
            Pass::Normals | Pass::Ids => SampleCount::X1,
        };
        self.make_current()?;
        self.ensure_target(width, height, samples)?;
        self.last_pass = None;
        self.multisampled_view = None;
        let mut stats = FrameStats::default();
        let start = Instant::now();
        let target = self.target.as_ref().expect("target was created");
        let framebuffer = target
            .multisample
            .as_ref()
            .map_or(target.framebuffer, |ms| ms.framebuffer);
        self.draw_frame(&scene, view, framebuffer, false, &mut stats)?;
        self.resolve()?;
        stats.total_time = start.elapsed();
        self.last_pass = Some(view.pass);
        if samples.is_multisampled() {
            self.multisampled_view = Some(*view);
        }
        Ok(stats)
    }

    /// Sets the samples per pixel of colour frames; an error when the driver offers fewer
    /// (`GL_MAX_SAMPLES`; llvmpipe offers 4).
    fn set_samples(&mut self, samples: SampleCount) -> Result<(), RenderError> {
        if samples.count() as i64 > self.max_samples.max(1) as i64 {
            return Err(unsupported(format!(
                "{samples}x multisampling: the driver ({}) offers at most {} samples per pixel \
                 (GL_MAX_SAMPLES)",
                self.renderer,
                self.max_samples.max(1)
            )));
        }
        self.samples = samples;
        Ok(())
    }

    fn samples(&self) -> SampleCount {
        self.samples
    }

    fn read_frame(&mut self) -> Result<FrameImage, RenderError> {
        let target = match (&self.target, self.last_pass) {
            (Some(t), Some(_)) => t,
            _ => {
                return Err(backend_error(
                    "read_frame called before a frame was rendered",
                ))
            }
        };
        let (width, height) = (target.width, target.height);
        self.make_current()?;
        // A multisampled frame's per-pixel depth: its depth drawn again at 1×.
        if let Some(view) = self.multisampled_view.take() {
            let scene = self
                .scene
                .clone()
                .ok_or_else(|| backend_error("read_frame called before load"))?;
            let framebuffer = self.target.as_ref().expect("checked above").framebuffer;
            self.draw_frame(&scene, &view, framebuffer, true, &mut FrameStats::default())?;
        }
        let framebuffer = self.target.as_ref().expect("checked above").framebuffer;
        let color = self.read_color(framebuffer, width, height)?;
        let mut depth = vec![0u8; width as usize * height as usize * 4];
        // SAFETY: the context is current on this thread; the framebuffer is ours; the buffer
        // holds exactly width × height f32 values with PACK_ALIGNMENT 4 and no row length,
        // which is what glReadPixels writes for this format.
        unsafe {
            let gl = &self.gl;
            gl.bind_buffer(glow::PIXEL_PACK_BUFFER, None);
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(framebuffer));
            gl.pixel_store_i32(glow::PACK_ALIGNMENT, 4);
            gl.pixel_store_i32(glow::PACK_ROW_LENGTH, 0);
            gl.read_pixels(
                0,
                0,
                width as i32,
                height as i32,
                glow::DEPTH_COMPONENT,
                glow::FLOAT,
                glow::PixelPackData::Slice(Some(&mut depth)),
            );
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, None);
        }
        self.check("reading the frame back")?;
        let float = |b: &[u8]| f32::from_ne_bytes([b[0], b[1], b[2], b[3]]);
        Ok(FrameImage {
            width,
            height,
            color,
            depth: depth.chunks_exact(4).map(float).collect(),
        })
    }
}

impl Drop for GlBackend {
    fn drop(&mut self) {
        if self.make_current().is_ok() {
            // SAFETY: the context is current on this thread; the objects are ours and deleted
            // once. The context itself is destroyed afterwards by `EglContext`'s drop.
            unsafe {
                self.gpu.delete(&self.gl);
                self.delete_target();
                self.gl.use_program(None);
                self.gl.delete_program(self.program);
                self.gl.delete_program(self.pbr_program);
            }
        }
    }
}

impl std::fmt::Debug for GlBackend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GlBackend")
            .field("renderer", &self.renderer)
            .field("version", &self.version)
            .field("platform", &self.platform())
            .field("fast_target", &self.fast_target)
            .finish_non_exhaustive()
    }
}

fn gl_error_name(e: u32) -> String {
    match e {
        glow::INVALID_ENUM => "GL_INVALID_ENUM".into(),
        glow::INVALID_VALUE => "GL_INVALID_VALUE".into(),
        glow::INVALID_OPERATION => "GL_INVALID_OPERATION".into(),
        glow::INVALID_FRAMEBUFFER_OPERATION => "GL_INVALID_FRAMEBUFFER_OPERATION".into(),
        glow::OUT_OF_MEMORY => "GL_OUT_OF_MEMORY".into(),
        other => format!("0x{other:04X}"),
    }
}
