//! The interface every backend implements (CPU here; OpenGL in `kantele-gl`; CUDA later): load a
//! [`Scene`] once, render frames of it, read the pictures back.
//!
//! Loading (uploading meshes and textures, building mip levels) is outside a frame; a frame is
//! clear + every draw + waiting for the image to be complete, as the timing rules require.

use std::ops::Range;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use glam::{Mat4, Vec3};

use crate::error::RenderError;
use crate::multisample::SampleCount;
use crate::scene::Scene;
use crate::stats::FrameStats;

/// What a frame writes into the colour buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Pass {
    /// The shaded picture (linear RGBA).
    #[default]
    Color,
    /// World-space unit normals (after two-sided flipping) in RGB, alpha 1; background is the
    /// clear value 0.
    Normals,
    /// Exact integer ids stored in float channels: R = instance id (the draw's `node_index +
    /// 1`), G = triangle id (triangle index within its mesh + 1), B = primitive id (draw index
    /// + 1: in glTF terms a mesh primitive placed by a node); background 0.
    Ids,
}

/// Camera, light and size of one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameView {
    /// Target width in pixels.
    pub width: u32,
    /// Target height in pixels.
    pub height: u32,
    /// World → eye.
    pub view: Mat4,
    /// Eye → clip (OpenGL conventions).
    pub projection: Mat4,
    /// Unit vector towards the light, world space.
    pub to_light: Vec3,
    /// Light colour × intensity.
    pub light_color: Vec3,
    /// What to render.
    pub pass: Pass,
}

impl FrameView {
    /// The view the scene itself asks for: its camera, light and resolution.
    pub fn of_scene(scene: &Scene) -> Self {
        let (width, height) = scene.resolution;
        Self::with_camera(scene, &scene.camera, width, height)
    }

    /// The scene seen through `camera` at `width × height`.
    pub fn with_camera(
        scene: &Scene,
        camera: &crate::scene::Camera,
        width: u32,
        height: u32,
    ) -> Self {
        let aspect = width as f32 / height.max(1) as f32;
        Self::with_matrices(scene, camera.view, camera.projection(aspect), width, height)
    }

    /// The scene seen through explicit `view` (world → eye, OpenGL) and `projection` matrices
    /// at `width × height`, lit by the scene's light (a headlight follows `view`). This is the
    /// constructor camera modules such as `kantele_output::pose` build frames with.
    pub fn with_matrices(
        scene: &Scene,
        view: Mat4,
        projection: Mat4,
        width: u32,
        height: u32,
    ) -> Self {
        let (to_light, light_color) = scene.light.resolve(&view);
        Self {
            width,
            height,
            view,
            projection,
            to_light,
            light_color,
            pass: Pass::Color,
        }
    }
}

/// A finished frame read back from a backend.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major linear RGBA, row 0 = top row.
    pub color: Vec<[f32; 4]>,
    /// Row-major window depth in [0, 1] (1 = background), row 0 = top row.
    pub depth: Vec<f32>,
}

impl FrameImage {
    /// The colour buffer as 8-bit RGBA, RGB encoded to sRGB when `srgb` is set.
    pub fn to_rgba8(&self, srgb: bool) -> Vec<u8> {
        self.color
            .iter()
            .flat_map(|c| crate::color::encode_rgba8(*c, srgb))
            .collect()
    }
}

/// A renderer of [`Scene`]s.
pub trait Backend {
    /// Short name: `cpu`, `gl`, `cuda`.
    fn name(&self) -> &str;
    /// What actually renders: e.g. `kantele cpu (bisector, 2 threads)` or the GL_RENDERER string.
    fn renderer(&self) -> String;
    /// Threads the backend renders with (1 for a GPU driver).
    fn threads(&self) -> usize;
    /// The instruction set of the backend's per-pixel path (`"avx512"`, `"avx2"`, `"scalar"`, …), or `"-"`
    /// where the question does not apply (a GPU driver).
    fn isa(&self) -> String {
        "-".to_string()
    }
    /// How colour frames are stored: `"f32"` (linear floats, the default), `"srgb8"` (8-bit
    /// sRGB, blending in linear space) or `"rgba8"` (8-bit linear).
    fn target(&self) -> String {
        "f32".to_string()
    }
    /// Restricts the following frames to the pixel rows `rows` of their view (a render
    /// region; `None`: whole frames again). The viewport stays the whole view's, so a band is
    /// bit-identical to the same rows of the whole frame; [`Backend::read_frame`] returns only
    /// those rows (`height` = rows in the band). Backends that cannot render regions refuse
    /// with [`RenderError::Unsupported`]; the default refuses every region.
    fn set_render_region(&mut self, rows: Option<Range<u32>>) -> Result<(), RenderError> {
        match rows {
            None => Ok(()),
            Some(_) => Err(RenderError::Unsupported {
                backend: self.name().to_string(),
                message: "cannot render a region (band) of a frame".into(),
            }),
        }
    }
    /// A flag that cancels the frame in flight while it is `true`: [`Backend::render`] then
    /// returns [`RenderError::Cancelled`] soon after it is set. The default ignores the flag
    /// (frames of such a backend always finish).
    fn set_cancel_flag(&mut self, flag: Option<Arc<AtomicBool>>) {
        let _ = flag;
    }
    /// Takes the scene and uploads what it needs. Not part of a frame.
    fn load(&mut self, scene: Arc<Scene>) -> Result<(), RenderError>;
    /// Renders one complete frame of the loaded scene and waits until it is finished.
    fn render(&mut self, view: &FrameView) -> Result<FrameStats, RenderError>;
    /// Reads back the last frame.
    fn read_frame(&mut self) -> Result<FrameImage, RenderError>;
    /// Sets the samples per pixel of later [`Pass::Color`] frames (multisample antialiasing,
    /// see [`crate::multisample`]); the normal and id passes are always rendered at 1×, and
    /// the depth read back is the per-pixel (pixel-centre) depth. A backend without
    /// multisampling (or without this count) returns [`RenderError::Unsupported`] and keeps
    /// its previous count.
    fn set_samples(&mut self, samples: SampleCount) -> Result<(), RenderError> {
        if samples.is_multisampled() {
            return Err(RenderError::Unsupported {
                backend: self.name().to_string(),
                message: format!("{samples}x multisampling is not implemented"),
            });
        }
        Ok(())
    }
    /// Samples per pixel of [`Pass::Color`] frames.
    fn samples(&self) -> SampleCount {
        SampleCount::X1
    }
}
