//! Rendering frames of a scene into plain arrays, with no Python involved: this runs with the
//! GIL released. The conversion to numpy (without copying) is in `arrays.rs`.

use kantele::backend::{Backend, FrameImage, FrameView, Pass};
use kantele::error::RenderError;
use kantele::scene::Scene;
use kantele_output::pose::CameraPose;

/// One array `Scene.render` can return.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputKind {
    /// `uint8` H×W×4, RGB sRGB-encoded, alpha linear: the bytes of the CLI's PNG.
    Color,
    /// `float32` H×W×4 linear RGBA, as the framebuffer holds it.
    ColorLinear,
    /// `float32` H×W: distance along the camera's view axis (OpenCV `z`), background `inf`.
    Depth,
    /// `float32` H×W: distance from the camera centre to the surface, background `inf`.
    RayDepth,
    /// `float32` H×W×3 world-space unit normals, background 0.
    Normals,
    /// `uint32` H×W×3: instance (node index + 1), triangle (index in its primitive + 1),
    /// primitive (draw index + 1); 0 = background.
    Ids,
}

impl OutputKind {
    /// Every output with its Python name.
    pub const ALL: [(&'static str, OutputKind); 6] = [
        ("color", OutputKind::Color),
        ("color_linear", OutputKind::ColorLinear),
        ("depth", OutputKind::Depth),
        ("ray_depth", OutputKind::RayDepth),
        ("normals", OutputKind::Normals),
        ("ids", OutputKind::Ids),
    ];

    /// The output called `name`.
    pub fn parse(name: &str) -> Result<Self, String> {
        Self::ALL
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, k)| *k)
            .ok_or_else(|| {
                let names: Vec<&str> = Self::ALL.iter().map(|(n, _)| *n).collect();
                format!(
                    "unknown output '{name}' (choose from: {})",
                    names.join(", ")
                )
            })
    }

    /// The Python name.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, k)| *k == self)
            .map(|(n, _)| *n)
            .unwrap_or("?")
    }

    /// The pass that produces it.
    fn pass(self) -> Pass {
        match self {
            OutputKind::Color
            | OutputKind::ColorLinear
            | OutputKind::Depth
            | OutputKind::RayDepth => Pass::Color,
            OutputKind::Normals => Pass::Normals,
            OutputKind::Ids => Pass::Ids,
        }
    }
}

/// Pixel data of one output with its array shape (row 0 = top row).
#[derive(Debug)]
pub enum Pixels {
    /// 8-bit data, shape H×W×C.
    U8(Vec<u8>, [usize; 3]),
    /// Float data, shape H×W (C = 1) or H×W×C.
    F32(Vec<f32>, [usize; 3]),
    /// Integer ids, shape H×W×C.
    U32(Vec<u32>, [usize; 3]),
}

/// The outputs of one view, in the order they were asked for.
pub type RenderedView = Vec<(OutputKind, Pixels)>;

/// Renders `scene` (loaded into `backend`) through every camera and extracts `outputs`.
/// Each pass is rendered once per view, only when an output needs it.
pub fn render_views(
    backend: &mut dyn Backend,
    scene: &Scene,
    cameras: &[CameraPose],
    outputs: &[OutputKind],
) -> Result<Vec<RenderedView>, RenderError> {
    let mut result = Vec::with_capacity(cameras.len());
    for camera in cameras {
        let mut frames: Vec<(Pass, FrameImage)> = Vec::new();
        let mut rendered = Vec::with_capacity(outputs.len());
        for &kind in outputs {
            let pass = kind.pass();
            if !frames.iter().any(|(p, _)| *p == pass) {
                let frame = render_pass(backend, &camera.frame_view(scene, pass))?;
                frames.push((pass, frame));
            }
            let frame = frames
                .iter()
                .find(|(p, _)| *p == pass)
                .map(|(_, f)| f)
                .expect("the pass was rendered above");
            rendered.push((kind, extract(kind, frame, camera)?));
        }
        result.push(rendered);
    }
    Ok(result)
}

fn render_pass(backend: &mut dyn Backend, view: &FrameView) -> Result<FrameImage, RenderError> {
    backend.render(view)?;
    let frame = backend.read_frame()?;
    let n = view.width as usize * view.height as usize;
    if (frame.width, frame.height) != (view.width, view.height)
        || frame.color.len() != n
        || frame.depth.len() != n
    {
        return Err(RenderError::Backend {
            backend: backend.name().to_string(),
            message: format!(
                "returned a {}x{} frame for a {}x{} view",
                frame.width, frame.height, view.width, view.height
            ),
        });
    }
    Ok(frame)
}

fn extract(
    kind: OutputKind,
    frame: &FrameImage,
    camera: &CameraPose,
) -> Result<Pixels, RenderError> {
    let (h, w) = (frame.height as usize, frame.width as usize);
    Ok(match kind {
        OutputKind::Color => Pixels::U8(frame.to_rgba8(true), [h, w, 4]),
        OutputKind::ColorLinear => {
            Pixels::F32(frame.color.iter().flatten().copied().collect(), [h, w, 4])
        }
        OutputKind::Depth => Pixels::F32(camera.planar_depth(&frame.depth), [h, w, 1]),
        OutputKind::RayDepth => Pixels::F32(camera.ray_depth(&frame.depth), [h, w, 1]),
        OutputKind::Normals => Pixels::F32(
            frame
                .color
                .iter()
                .zip(&frame.depth)
                .flat_map(|(c, &d)| {
                    if d < 1.0 {
                        [c[0], c[1], c[2]]
                    } else {
                        [0.0; 3]
                    }
                })
                .collect(),
            [h, w, 3],
        ),
        OutputKind::Ids => {
            let mut ids = Vec::with_capacity(frame.color.len() * 3);
            for c in &frame.color {
                for &v in &c[..3] {
                    if !(v.is_finite() && v >= 0.0 && v.fract() == 0.0 && v <= 16_777_216.0) {
                        return Err(RenderError::Backend {
                            backend: "id pass".into(),
                            message: format!("holds a non-integer id {v}"),
                        });
                    }
                    ids.push(v as u32);
                }
            }
            Pixels::U32(ids, [h, w, 3])
        }
    })
}
