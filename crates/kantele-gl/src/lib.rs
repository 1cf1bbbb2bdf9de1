//! The OpenGL reference backend of Kantele ("the yardstick"): renders a [`Scene`] by the rules of
//! the reference scenes (`/work/shared/scenes/README.md`) with a desktop OpenGL 3.3 core context
//! created headlessly through EGL, so that Kantele's pictures and timings can be compared with a
//! real GL driver (Mesa's llvmpipe on CI, a GPU driver where there is one).
//!
//! The entry point is [`GlBackend`]: [`GlBackend::new`] creates the context (or returns an
//! error when no EGL/OpenGL is available), and the [`Backend`] trait does the rest: `load` a
//! scene once, `render` a [`kantele::backend::FrameView`], then `read_frame`. The
//! `unsafe` GL and EGL calls of the workspace live in this crate. The core `kantele` crate
//! forbids `unsafe`.
//!
//! ```no_run
//! use std::sync::Arc;
//! use kantele::backend::{Backend, FrameView};
//! use kantele::scene::Scene;
//!
//! # fn scene() -> Scene { unimplemented!() }
//! let scene = Arc::new(scene()); // e.g. from kantele-io
//! let mut gl = kantele_gl::GlBackend::new()?;
//! gl.load(scene.clone())?;
//! gl.render(&FrameView::of_scene(&scene))?;
//! let image = gl.read_frame()?; // linear RGBA + depth, row 0 = top
//! # Ok::<(), kantele::RenderError>(())
//! ```
//!
//! # How the rules map onto GL
//!
//! - **Orientation.** The projection is y-flipped (`diag(1, −1, 1, 1) · projection`), so window
//!   row 0 is image row 0 and `glReadPixels` returns the top row first without any copy-flip.
//!   The flip mirrors the winding, so `glFrontFace(GL_CW)` keeps counter-clockwise-in-NDC
//!   triangles front-facing (and `gl_FrontFacing` keeps its meaning). Rendered this way, llvmpipe
//!   and NVIDIA apply the top-left tie rule of the README in image coordinates.
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
//!   sampler object per textured material carries the glTF wrap modes and filters.
//! - **Meshes without normals** are split into one vertex triple per triangle carrying the
//!   object-space face normal (flat shading).
//! - **Alpha.** OPAQUE writes alpha 1; MASK discards fragments with alpha below the cutoff and
//!   writes alpha 1; BLEND uses `glBlendFuncSeparate(SRC_ALPHA, ONE_MINUS_SRC_ALPHA, ONE,
//!   ONE_MINUS_SRC_ALPHA)` with depth writes off, so the stored alpha is
//!   `src.a + dst.a × (1 − src.a)` (the "over" operator's coverage).
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

mod egl;
mod resources;
mod shaders;

use std::marker::PhantomData;
use std::sync::Arc;
use std::time::Instant;

use glam::{Mat3, Mat4, Vec4};
use glow::HasContext;
use kantele::backend::{Backend, FrameImage, FrameView, Pass};
use kantele::camera::normal_matrix;
use kantele::multisample::SampleCount;
use kantele::scene::{AlphaMode, Scene, Topology};
use kantele::stats::FrameStats;
use kantele::RenderError;

#[cfg(doc)]
use kantele::shade::texture::Texture;

use crate::egl::EglContext;
use crate::resources::GpuScene;

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

/// Uniform locations of the shader program.
struct Uniforms {
    model_view_projection: Option<glow::UniformLocation>,
    normal_matrix: Option<glow::UniformLocation>,
    base_color_factor: Option<glow::UniformLocation>,
    has_texture: Option<glow::UniformLocation>,
    base_color_texture: Option<glow::UniformLocation>,
    emissive: Option<glow::UniformLocation>,
    has_emissive_texture: Option<glow::UniformLocation>,
    emissive_texture: Option<glow::UniformLocation>,
    unlit: Option<glow::UniformLocation>,
    alpha_mode: Option<glow::UniformLocation>,
    alpha_cutoff: Option<glow::UniformLocation>,
    double_sided: Option<glow::UniformLocation>,
    to_light: Option<glow::UniformLocation>,
    light_color: Option<glow::UniformLocation>,
    ambient: Option<glow::UniformLocation>,
    pass: Option<glow::UniformLocation>,
    ids: Option<glow::UniformLocation>,
}

/// The render target: a framebuffer with a colour and a depth renderbuffer.
struct Target {
    framebuffer: glow::Framebuffer,
    color: glow::Renderbuffer,
    depth: glow::Renderbuffer,
    width: u32,
    height: u32,
    fast: bool,
    /// The multisampled framebuffer colour frames are drawn into before they are resolved
    /// into `framebuffer` (`None` at 1×).
    multisample: Option<MultisampleTarget>,
}

/// A multisampled framebuffer of the target's size and formats.
struct MultisampleTarget {
    framebuffer: glow::Framebuffer,
    color: glow::Renderbuffer,
    depth: glow::Renderbuffer,
    samples: SampleCount,
}

/// The OpenGL backend: a headless EGL context, the scene's meshes and textures in GL objects, and
/// an offscreen framebuffer.
///
/// Not `Send`: the GL context belongs to the creating thread (see the crate docs).
pub struct GlBackend {
    // `Drop` deletes the GL objects; then the fields drop in order, `egl` (the context) last.
    gl: glow::Context,
    program: glow::Program,
    uniforms: Uniforms,
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
    /// Creates a headless desktop OpenGL 3.3+ core context and the shader program.
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
    /// available; the message lists every attempt.
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
        let program = unsafe { build_program(&gl) }.map_err(backend_error)?;
        // SAFETY: `gl` is current; `program` is ours and linked.
        let uniforms = unsafe { uniforms(&gl, program) };
        // SAFETY: `gl` is current on this thread.
        let max_samples = unsafe { gl.get_parameter_i32(glow::MAX_SAMPLES) };
        let backend = Self {
            gl,
            program,
            uniforms,
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

    /// Creates (or re-creates) the framebuffer for the view's size, the selected format and
    /// `samples` per pixel.
    fn ensure_target(
        &mut self,
        width: u32,
        height: u32,
        samples: SampleCount,
    ) -> Result<(), RenderError> {
        if let Some(t) = &self.target {
            let target_samples = t
                .multisample
                .as_ref()
                .map_or(SampleCount::X1, |m| m.samples);
            if t.width == width
                && t.height == height
                && t.fast == self.fast_target
                && target_samples == samples
            {
                return Ok(());
            }
        }
        self.delete_target();
        let fast = self.fast_target;
        let gl = &self.gl;
        // SAFETY: `gl` is current on this thread; the objects are created here and attached
        // to the framebuffer created here.
        let target = unsafe {
            let max = gl.get_parameter_i32(glow::MAX_RENDERBUFFER_SIZE);
            let mut dims = [0i32; 2];
            gl.get_parameter_i32_slice(glow::MAX_VIEWPORT_DIMS, &mut dims);
            if width as i64 > max.min(dims[0]) as i64 || height as i64 > max.min(dims[1]) as i64 {
                return Err(unsupported(format!(
                    "target {width}x{height} exceeds the driver's limits (renderbuffer {max}, viewport {}x{})",
                    dims[0], dims[1]
                )));
            }
            let framebuffer = gl.create_framebuffer().map_err(backend_error)?;
            let color = gl.create_renderbuffer().map_err(backend_error)?;
            let depth = gl.create_renderbuffer().map_err(backend_error)?;
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(framebuffer));
            gl.bind_renderbuffer(glow::RENDERBUFFER, Some(color));
            let color_format = if fast { glow::RGBA8 } else { glow::RGBA32F };
            gl.renderbuffer_storage(
                glow::RENDERBUFFER,
                color_format,
                width as i32,
                height as i32,
            );
            gl.framebuffer_renderbuffer(
                glow::FRAMEBUFFER,
                glow::COLOR_ATTACHMENT0,
                glow::RENDERBUFFER,
                Some(color),
            );
            gl.bind_renderbuffer(glow::RENDERBUFFER, Some(depth));
            gl.renderbuffer_storage(
                glow::RENDERBUFFER,
                glow::DEPTH_COMPONENT32F,
                width as i32,
                height as i32,
            );
            gl.framebuffer_renderbuffer(
                glow::FRAMEBUFFER,
                glow::DEPTH_ATTACHMENT,
                glow::RENDERBUFFER,
                Some(depth),
            );
            gl.bind_renderbuffer(glow::RENDERBUFFER, None);
            let status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
            let mut target = Target {
                framebuffer,
                color,
                depth,
                width,
                height,
                fast,
                multisample: None,
            };
            if status != glow::FRAMEBUFFER_COMPLETE {
                self.target = Some(target);
                self.delete_target();
                return Err(backend_error(format!(
                    "framebuffer {width}x{height} incomplete (status 0x{status:04X})"
                )));
            }
            if samples.is_multisampled() {
                let ms = MultisampleTarget {
                    framebuffer: gl.create_framebuffer().map_err(backend_error)?,
                    color: gl.create_renderbuffer().map_err(backend_error)?,
                    depth: gl.create_renderbuffer().map_err(backend_error)?,
                    samples,
                };
                let n = samples.count() as i32;
                gl.bind_framebuffer(glow::FRAMEBUFFER, Some(ms.framebuffer));
                gl.bind_renderbuffer(glow::RENDERBUFFER, Some(ms.color));
                gl.renderbuffer_storage_multisample(
                    glow::RENDERBUFFER,
                    n,
                    color_format,
                    width as i32,
                    height as i32,
                );
                gl.framebuffer_renderbuffer(
                    glow::FRAMEBUFFER,
                    glow::COLOR_ATTACHMENT0,
                    glow::RENDERBUFFER,
                    Some(ms.color),
                );
                gl.bind_renderbuffer(glow::RENDERBUFFER, Some(ms.depth));
                gl.renderbuffer_storage_multisample(
                    glow::RENDERBUFFER,
                    n,
                    glow::DEPTH_COMPONENT32F,
                    width as i32,
                    height as i32,
                );
                gl.framebuffer_renderbuffer(
                    glow::FRAMEBUFFER,
                    glow::DEPTH_ATTACHMENT,
                    glow::RENDERBUFFER,
                    Some(ms.depth),
                );
                gl.bind_renderbuffer(glow::RENDERBUFFER, None);
                let status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
                target.multisample = Some(ms);
                if status != glow::FRAMEBUFFER_COMPLETE {
                    self.target = Some(target);
                    self.delete_target();
                    return Err(unsupported(format!(
                        "{samples}x multisampled framebuffer {width}x{height} incomplete \
                         (status 0x{status:04X})"
                    )));
                }
            }
            target
        };
        self.target = Some(target);
        self.last_pass = None;
        self.check("creating the framebuffer")
    }

    fn delete_target(&mut self) {
        if let Some(t) = self.target.take() {
            // SAFETY: `gl` is current on this thread and the objects are ours.
            unsafe {
                self.gl.bind_framebuffer(glow::FRAMEBUFFER, None);
                self.gl.delete_framebuffer(t.framebuffer);
                self.gl.delete_renderbuffer(t.color);
                self.gl.delete_renderbuffer(t.depth);
                if let Some(ms) = t.multisample {
                    self.gl.delete_framebuffer(ms.framebuffer);
                    self.gl.delete_renderbuffer(ms.color);
                    self.gl.delete_renderbuffer(ms.depth);
                }
            }
        }
        self.last_pass = None;
        self.multisampled_view = None;
    }

    /// Resolves the multisampled colour into the single-sample target (`glBlitFramebuffer`).
    fn resolve(&self) -> Result<(), RenderError> {
        let target = self.target.as_ref().expect("target was created");
        let Some(ms) = &target.multisample else {
            return Ok(());
        };
        let (w, h) = (target.width as i32, target.height as i32);
        // SAFETY: `gl` is current on this thread; both framebuffers are ours, complete and of
        // the same size and colour format.
        unsafe {
            let gl = &self.gl;
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(ms.framebuffer));
            gl.read_buffer(glow::COLOR_ATTACHMENT0);
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, Some(target.framebuffer));
            gl.draw_buffers(&[glow::COLOR_ATTACHMENT0]);
            gl.blit_framebuffer(
                0,
                0,
                w,
                h,
                0,
                0,
                w,
                h,
                glow::COLOR_BUFFER_BIT,
                glow::NEAREST,
            );
            gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            gl.finish();
        }
        self.check("resolving the multisampled frame")
    }

    /// Clear + every draw + glFinish into `framebuffer` (the target's or its multisampled
    /// one), with the context current. `depth_only` clears and draws depth alone (colour
    /// writes off): the per-pixel depth of a multisampled frame.
    fn draw_frame(
        &self,
        scene: &Scene,
        view: &FrameView,
        framebuffer: glow::Framebuffer,
        depth_only: bool,
        stats: &mut FrameStats,
    ) -> Result<(), RenderError> {
        let gl = &self.gl;
        let u = &self.uniforms;
        let color_pass = view.pass == Pass::Color;
        let pass = match view.pass {
            Pass::Color => shaders::PASS_COLOR,
            Pass::Normals => shaders::PASS_NORMALS,
            Pass::Ids => shaders::PASS_IDS,
        };
        let clear = if color_pass {
            scene.clear_color
        } else {
            Vec4::ZERO
        };
        // Window row 0 = image row 0: flip y after the projection (see the crate docs).
        let flip = Mat4::from_diagonal(Vec4::new(1.0, -1.0, 1.0, 1.0));
        let view_projection = flip * view.projection * view.view;
        // SAFETY: `gl` is current on this thread (caller); the program, target, meshes, textures
        // and samplers are ours and alive; every draw's mesh, material and texture index was
        // checked by `Scene::validate` in `load`, and index buffers only hold in-range indices.
        unsafe {
            let target = self.target.as_ref().expect("target was created");
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(framebuffer));
            gl.draw_buffers(&[glow::COLOR_ATTACHMENT0]);
            gl.viewport(0, 0, target.width as i32, target.height as i32);
            gl.disable(glow::SCISSOR_TEST);
            gl.disable(glow::BLEND);
            gl.enable(glow::MULTISAMPLE);
            gl.color_mask(!depth_only, !depth_only, !depth_only, !depth_only);
            gl.depth_mask(true);
            gl.clear_color(clear.x, clear.y, clear.z, clear.w);
            gl.clear_depth_f64(1.0);
            gl.clear(if depth_only {
                glow::DEPTH_BUFFER_BIT
            } else {
                glow::COLOR_BUFFER_BIT | glow::DEPTH_BUFFER_BIT
            });

            gl.enable(glow::DEPTH_TEST);
            gl.depth_func(glow::LESS);
            gl.depth_range_f64(0.0, 1.0);
            gl.front_face(glow::CW);
            gl.cull_face(glow::BACK);
            gl.blend_func_separate(
                glow::SRC_ALPHA,
                glow::ONE_MINUS_SRC_ALPHA,
                glow::ONE,
                glow::ONE_MINUS_SRC_ALPHA,
            );
            gl.blend_equation(glow::FUNC_ADD);

            gl.use_program(Some(self.program));
            gl.uniform_3_f32_slice(u.to_light.as_ref(), &view.to_light.to_array());
            gl.uniform_3_f32_slice(u.light_color.as_ref(), &view.light_color.to_array());
            gl.uniform_1_f32(u.ambient.as_ref(), scene.ambient);
            gl.uniform_1_i32(u.pass.as_ref(), pass);
            gl.uniform_1_i32(u.base_color_texture.as_ref(), 0);
            gl.uniform_1_i32(u.emissive_texture.as_ref(), 1);
            gl.active_texture(glow::TEXTURE0);

            // Points and lines are drawn with GL's initial point size and line width, 1 (never
            // changed here; PROGRAM_POINT_SIZE stays off), as the CPU pipeline draws them.
            gl.line_width(1.0);
            let unlit = scene.unlit_materials();
            for draw_index in scene.draw_order(&view.view) {
                let draw = &scene.draws[draw_index];
                let mesh = &scene.meshes[draw.mesh];
                let gpu_mesh = &self.gpu.meshes[draw.mesh];
                let material = scene.draw_material(draw.mesh, &unlit);
                stats.draws += 1;
                stats.triangles_in += mesh.primitive_count() as u64;
                if gpu_mesh.index_count == 0 {
                    continue;
                }
                // The y-flip mirrors the winding: front (CCW in NDC) is CW in GL's window; a
                // mirroring model matrix flips it once more.
                gl.front_face(match draw.front_face() {
                    kantele::setup::FrontFace::Ccw => glow::CW,
                    kantele::setup::FrontFace::Cw => glow::CCW,
                });
                if material.double_sided {
                    gl.disable(glow::CULL_FACE);
                } else {
                    gl.enable(glow::CULL_FACE);
                }
                let (alpha_mode, cutoff) = match material.alpha_mode {
                    AlphaMode::Opaque => (shaders::ALPHA_OPAQUE, 0.0),
                    AlphaMode::Mask { cutoff } => (shaders::ALPHA_MASK, cutoff),
                    AlphaMode::Blend => (shaders::ALPHA_BLEND, 0.0),
                };
                let blend = alpha_mode == shaders::ALPHA_BLEND;
                if blend && color_pass {
                    gl.enable(glow::BLEND);
                } else {
                    gl.disable(glow::BLEND);
                }
                gl.depth_mask(!blend);

                let mvp = view_projection * draw.model;
                let normal: Mat3 = normal_matrix(&draw.model);
                gl.uniform_matrix_4_f32_slice(
                    u.model_view_projection.as_ref(),
                    false,
                    &mvp.to_cols_array(),
                );
                gl.uniform_matrix_3_f32_slice(
                    u.normal_matrix.as_ref(),
                    false,
                    &normal.to_cols_array(),
                );
                gl.uniform_4_f32_slice(
                    u.base_color_factor.as_ref(),
                    &material.base_color_factor.to_array(),
                );
                gl.uniform_1_i32(u.unlit.as_ref(), material.unlit as i32);
                gl.uniform_1_i32(u.alpha_mode.as_ref(), alpha_mode);
                gl.uniform_1_f32(u.alpha_cutoff.as_ref(), cutoff);
                gl.uniform_1_i32(u.double_sided.as_ref(), material.double_sided as i32);
                gl.uniform_2_f32(
                    u.ids.as_ref(),
                    (draw.node_index + 1) as f32,
                    (draw_index + 1) as f32,
                );
                gl.uniform_3_f32_slice(u.emissive.as_ref(), &material.emissive.to_array());
                gl.active_texture(glow::TEXTURE1);
                match material.emissive_texture {
                    Some(binding) => {
                        gl.uniform_1_i32(u.has_emissive_texture.as_ref(), 1);
                        gl.bind_texture(glow::TEXTURE_2D, Some(self.gpu.textures[binding.texture]));
                        gl.bind_sampler(1, self.gpu.emissive_samplers[mesh.material]);
                    }
                    None => {
                        gl.uniform_1_i32(u.has_emissive_texture.as_ref(), 0);
                        gl.bind_texture(glow::TEXTURE_2D, None);
                        gl.bind_sampler(1, None);
                    }
                }
                gl.active_texture(glow::TEXTURE0);
                match material.base_color_texture {
                    Some(binding) => {
                        gl.uniform_1_i32(u.has_texture.as_ref(), 1);
                        gl.bind_texture(glow::TEXTURE_2D, Some(self.gpu.textures[binding.texture]));
                        gl.bind_sampler(0, self.gpu.samplers[mesh.material]);
                    }
                    None => {
                        gl.uniform_1_i32(u.has_texture.as_ref(), 0);
                        gl.bind_texture(glow::TEXTURE_2D, None);
                        gl.bind_sampler(0, None);
                    }
                }
                gl.bind_vertex_array(Some(gpu_mesh.vertex_array));
                let mode = match mesh.topology {
                    Topology::Triangles => glow::TRIANGLES,
                    Topology::Lines => glow::LINES,
                    Topology::Points => glow::POINTS,
                };
                gl.draw_elements(mode, gpu_mesh.index_count, glow::UNSIGNED_INT, 0);
            }
            gl.bind_vertex_array(None);
            gl.depth_mask(true);
            gl.color_mask(true, true, true, true);
            gl.finish();
        }
        self.check("rendering the frame")
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
        let side_ok = |s: u32| (1..=kantele::MAX_TARGET_SIZE).contains(&s);
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
        let target = self.target.as_ref().expect("checked above");
        let pixels = width as usize * height as usize;
        let mut color = vec![0u8; pixels * 16];
        let mut depth = vec![0u8; pixels * 4];
        // SAFETY: the context is current on this thread; the framebuffer is ours; the buffers
        // hold exactly width × height RGBA f32 / f32 values with PACK_ALIGNMENT 4 and no row
        // length, which is what glReadPixels writes for these formats.
        unsafe {
            let gl = &self.gl;
            gl.bind_buffer(glow::PIXEL_PACK_BUFFER, None);
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(target.framebuffer));
            gl.read_buffer(glow::COLOR_ATTACHMENT0);
            gl.pixel_store_i32(glow::PACK_ALIGNMENT, 4);
            gl.pixel_store_i32(glow::PACK_ROW_LENGTH, 0);
            gl.read_pixels(
                0,
                0,
                width as i32,
                height as i32,
                glow::RGBA,
                glow::FLOAT,
                glow::PixelPackData::Slice(Some(&mut color)),
            );
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
            color: color
                .chunks_exact(16)
                .map(|p| {
                    [
                        float(&p[0..4]),
                        float(&p[4..8]),
                        float(&p[8..12]),
                        float(&p[12..16]),
                    ]
                })
                .collect(),
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

/// Compiles and links the shader program.
///
/// # Safety
/// `gl` must be current on this thread.
unsafe fn build_program(gl: &glow::Context) -> Result<glow::Program, String> {
    // SAFETY: the context is current (caller's contract); shaders and program are created here
    // and the shaders are deleted once linked (or on failure).
    unsafe {
        let program = gl.create_program()?;
        let mut shaders = Vec::new();
        for (kind, source, what) in [
            (glow::VERTEX_SHADER, shaders::VERTEX, "vertex"),
            (glow::FRAGMENT_SHADER, shaders::FRAGMENT, "fragment"),
        ] {
            let shader = gl.create_shader(kind)?;
            gl.shader_source(shader, source);
            gl.compile_shader(shader);
            if !gl.get_shader_compile_status(shader) {
                let log = gl.get_shader_info_log(shader);
                gl.delete_shader(shader);
                for s in shaders {
                    gl.delete_shader(s);
                }
                gl.delete_program(program);
                return Err(format!("{what} shader does not compile: {log}"));
            }
            gl.attach_shader(program, shader);
            shaders.push(shader);
        }
        gl.link_program(program);
        let linked = gl.get_program_link_status(program);
        for s in shaders {
            gl.detach_shader(program, s);
            gl.delete_shader(s);
        }
        if !linked {
            let log = gl.get_program_info_log(program);
            gl.delete_program(program);
            return Err(format!("shader program does not link: {log}"));
        }
        Ok(program)
    }
}

/// Looks up every uniform of the program.
///
/// # Safety
/// `gl` must be current on this thread and `program` a linked program of it.
unsafe fn uniforms(gl: &glow::Context, program: glow::Program) -> Uniforms {
    // SAFETY: caller's contract.
    let at = |name: &str| unsafe { gl.get_uniform_location(program, name) };
    Uniforms {
        model_view_projection: at("u_model_view_projection"),
        normal_matrix: at("u_normal_matrix"),
        base_color_factor: at("u_base_color_factor"),
        has_texture: at("u_has_texture"),
        base_color_texture: at("u_base_color_texture"),
        emissive: at("u_emissive"),
        has_emissive_texture: at("u_has_emissive_texture"),
        emissive_texture: at("u_emissive_texture"),
        unlit: at("u_unlit"),
        alpha_mode: at("u_alpha_mode"),
        alpha_cutoff: at("u_alpha_cutoff"),
        double_sided: at("u_double_sided"),
        to_light: at("u_to_light"),
        light_color: at("u_light_color"),
        ambient: at("u_ambient"),
        pass: at("u_pass"),
        ids: at("u_ids"),
    }
}
