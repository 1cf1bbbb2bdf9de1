//! The CPU backend: scenes drawn through the software [`pipeline`](crate::pipeline) with the
//! built-in [`material`](crate::material) shaders, behind the [`Backend`] interface.

use std::sync::Arc;

use crate::material::{Lighting, MaterialShader, StandardVertex};
use crate::pipeline::{Indices, RenderState, Renderer, RendererOptions, Shader};
use crate::raster::Strategy;
use crate::rop::{Framebuffer, TargetFormat};
use kantele_rules::backend::{Backend, FrameImage, FrameView, Pass};
use kantele_rules::error::RenderError;
use kantele_rules::multisample::SampleCount;
use kantele_rules::scene::{Mesh, Scene, Shading, Topology};
use kantele_rules::stats::FrameStats;
use kantele_rules::vertex::PbrVertex;

mod pbr_frame;

/// Options of the CPU backend.
pub type CpuOptions = RendererOptions;

/// A mesh converted once, at load time, to the vertex layout `V` the shaders read.
struct PreparedMesh<V> {
    vertices: Vec<V>,
    indices: Vec<u32>,
    topology: Topology,
}

impl<V> PreparedMesh<V> {
    fn new(mesh: &Mesh, convert: fn(&Mesh) -> (Vec<V>, Vec<u32>)) -> Self {
        let (vertices, indices) = convert(mesh);
        Self {
            vertices,
            indices,
            topology: mesh.topology,
        }
    }
}

/// A scene's meshes in the vertex layout of its shading.
enum PreparedMeshes {
    /// Lambert scenes.
    Standard(Vec<PreparedMesh<StandardVertex>>),
    /// PBR scenes: also the second texture coordinate set and the tangents.
    Pbr(Vec<PreparedMesh<PbrVertex>>),
}

impl PreparedMeshes {
    fn new(scene: &Scene) -> Self {
        match scene.shading {
            Shading::Lambert => Self::Standard(
                scene
                    .meshes
                    .iter()
                    .map(|m| PreparedMesh::new(m, StandardVertex::from_mesh))
                    .collect(),
            ),
            Shading::Pbr => Self::Pbr(
                scene
                    .meshes
                    .iter()
                    .map(|m| PreparedMesh::new(m, PbrVertex::from_mesh))
                    .collect(),
            ),
        }
    }
}

/// The error of a frame whose scene's meshes were prepared for another shading (the scene's
/// shading is fixed when it is loaded, so this is an internal inconsistency).
fn layout_mismatch() -> RenderError {
    RenderError::InvalidScene("the scene's meshes were prepared for another shading".into())
}

/// Renders scenes with Kantele's CPU pipeline.
pub struct CpuBackend {
    renderer: Renderer,
    /// Samples per pixel of colour frames.
    samples: SampleCount,
    /// The target format of colour frames (normals and ids are always drawn into `f32`).
    target: TargetFormat,
    scene: Option<(Arc<Scene>, PreparedMeshes)>,
    /// The rows frames are restricted to (`None`: whole frames).
    region: Option<std::ops::Range<u32>>,
    /// The target of the last backdrop drawn (transmissive frames), kept for the next one.
    backdrop_target: Option<Framebuffer>,
}

impl CpuBackend {
    /// A backend with the given options.
    pub fn new(options: CpuOptions) -> Result<Self, RenderError> {
        Ok(Self {
            renderer: Renderer::new(1, 1, options)?,
            samples: options.samples,
            target: options.target,
            scene: None,
            region: None,
            backdrop_target: None,
        })
    }

    /// The traversal strategy in use.
    pub fn strategy(&self) -> Strategy {
        self.renderer.strategy()
    }

    /// Changes the traversal strategy (pictures stay identical).
    pub fn set_strategy(&mut self, strategy: Strategy) {
        self.renderer.set_strategy(strategy);
    }

    /// Changes the time budget of a frame (`None`: unlimited); a frame over it makes
    /// [`Backend::render`] return [`RenderError::TimedOut`].
    pub fn set_timeout(&mut self, timeout: Option<std::time::Duration>) {
        self.renderer.set_timeout(timeout);
    }

    /// How colour frames are stored from the next frame on (normals and ids always use `f32`).
    pub fn set_target(&mut self, target: TargetFormat) {
        self.target = target;
    }

    /// The underlying renderer (framebuffer access).
    pub fn renderer(&self) -> &Renderer {
        &self.renderer
    }
}

/// Clears (the scene's clear colour in the colour pass, 0 in the others) and draws every draw
/// `i` of `scene` for which `drawn(i)` holds, in the scene's draw order, with `shaders[i]`
/// under the state `state` gives it (front faces by the draw's model matrix).
fn draw_scene<S: Shader>(
    renderer: &mut Renderer,
    scene: &Scene,
    meshes: &[PreparedMesh<S::Vertex>],
    view: &FrameView,
    shaders: &[S],
    state: impl Fn(&S) -> RenderState,
    drawn: impl Fn(usize) -> bool,
) -> Result<FrameStats, RenderError> {
    let clear = match view.pass {
        Pass::Color => scene.clear_color,
        Pass::Normals | Pass::Ids => glam::Vec4::ZERO,
    };
    let mut frame = renderer.begin_frame(Some(clear), Some(1.0));
    for index in scene
        .draw_order(&view.view)
        .into_iter()
        .filter(|&i| drawn(i))
    {
        let (draw, shader) = (&scene.draws[index], &shaders[index]);
        let mesh = &meshes[draw.mesh];
        let state = RenderState {
            front_face: draw.front_face(),
            ..state(shader)
        };
        frame.draw_primitives(
            shader,
            &mesh.vertices,
            Indices::U32(&mesh.indices),
            mesh.topology,
            state,
        )?;
    }
    frame.try_end()
}

impl Backend for CpuBackend {
    fn name(&self) -> &str {
        "cpu"
    }

    fn renderer(&self) -> String {
        format!("kantele cpu ({})", self.renderer.strategy())
    }

    fn threads(&self) -> usize {
        self.renderer.threads()
    }

    fn isa(&self) -> String {
        self.renderer.isa().name().to_string()
    }

    fn target(&self) -> String {
        self.target.name().to_string()
    }

    /// Restricts frames to rows `rows` of their view ([`Renderer::resize_band`]): only those
    /// tiles are allocated, binned and drawn. A region past a frame's height is an error of
    /// that frame's [`Backend::render`].
    fn set_render_region(&mut self, rows: Option<std::ops::Range<u32>>) -> Result<(), RenderError> {
        if let Some(r) = &rows {
            if r.is_empty() {
                return Err(RenderError::InvalidRegion {
                    rows: (r.start, r.end),
                    height: 0,
                });
            }
        }
        self.region = rows;
        Ok(())
    }

    /// A flag that cancels the frame in flight while it is `true` (see
    /// [`Renderer::set_cancel_flag`]): [`Backend::render`] then returns
    /// [`RenderError::Cancelled`]. The time budget is [`CpuOptions::timeout`].
    fn set_cancel_flag(&mut self, flag: Option<Arc<std::sync::atomic::AtomicBool>>) {
        self.renderer.set_cancel_flag(flag);
    }

    fn load(&mut self, scene: Arc<Scene>) -> Result<(), RenderError> {
        scene.validate()?;
        let meshes = PreparedMeshes::new(&scene);
        // Decoded texels for the lane-wide sampler, now rather than in the first frame.
        for texture in &scene.textures {
            texture.prepare_lane_sampling();
        }
        self.scene = Some((scene, meshes));
        Ok(())
    }

    fn render(&mut self, view: &FrameView) -> Result<FrameStats, RenderError> {
        let Some((scene, meshes)) = &self.scene else {
            return Err(RenderError::InvalidScene("no scene loaded".into()));
        };
        // Ids and normals are never averaged nor quantised: those passes render at 1× into
        // `f32`.
        let (samples, target) = match view.pass {
            Pass::Color => (self.samples, self.target),
            Pass::Normals | Pass::Ids => (SampleCount::X1, TargetFormat::LinearF32),
        };
        if (samples, target) != (self.renderer.samples(), self.renderer.target_format()) {
            // Re-created at the new size (the 1 × 1 target first keeps the switch cheap).
            self.renderer.resize(1, 1)?;
            self.renderer.set_samples(samples)?;
            self.renderer.set_target_format(target)?;
        }
        let rows = self.region.clone().unwrap_or(0..view.height);
        self.renderer.resize_band(view.width, view.height, rows)?;
        let view_projection = view.projection * view.view;
        let lighting = Lighting {
            to_light: view.to_light,
            light_color: view.light_color,
            ambient: scene.ambient,
        };
        if scene.shading == Shading::Pbr {
            return self.render_pbr(view);
        }
        let PreparedMeshes::Standard(meshes) = meshes else {
            return Err(layout_mismatch());
        };
        let unlit = scene.unlit_materials();
        let shaders: Vec<MaterialShader<'_>> = scene
            .draws
            .iter()
            .enumerate()
            .map(|(i, draw)| {
                let material = scene.draw_material(draw.mesh, &unlit);
                let texture = material
                    .base_color_texture
                    .map(|b| (&*scene.textures[b.texture], b.sampler));
                MaterialShader::new(
                    draw.model,
                    view_projection,
                    lighting,
                    material,
                    texture,
                    view.pass,
                    (draw.node_index as u32 + 1, i as u32 + 1),
                )
                .with_emissive_texture(
                    material
                        .emissive_texture
                        .map(|b| (&*scene.textures[b.texture], b.sampler)),
                )
                .with_vertex_colors(scene.meshes[draw.mesh].colors.is_some())
            })
            .collect();
        draw_scene(
            &mut self.renderer,
            scene,
            meshes,
            view,
            &shaders,
            |s| s.render_state(),
            |_| true,
        )
    }

    fn set_samples(&mut self, samples: SampleCount) -> Result<(), RenderError> {
        self.samples = samples;
        Ok(())
    }

    fn samples(&self) -> SampleCount {
        self.samples
    }

    fn read_frame(&mut self) -> Result<FrameImage, RenderError> {
        let fb = self.renderer.framebuffer();
        Ok(FrameImage {
            width: fb.width(),
            height: fb.rows().len() as u32,
            color: fb.try_read_color()?,
            depth: fb.try_read_depth()?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Mat4, Vec3, Vec4};
    use kantele_rules::backend::FrameView;
    use kantele_rules::scene::{Draw, Material};

    /// A single-sided quad facing the camera, drawn once plainly and once through a mirroring
    /// model matrix: both must be visible (the mirror flips which winding is front).
    #[test]
    fn mirrored_draws_keep_their_front_faces() {
        let quad = Mesh {
            positions: vec![
                Vec3::new(-0.5, -0.5, 0.0),
                Vec3::new(0.5, -0.5, 0.0),
                Vec3::new(0.5, 0.5, 0.0),
                Vec3::new(-0.5, 0.5, 0.0),
            ],
            normals: Some(vec![Vec3::Z; 4]),
            indices: vec![0, 1, 2, 0, 2, 3],
            ..Mesh::default()
        };
        let covered = |model: Mat4| {
            let scene = Scene {
                meshes: vec![quad.clone()],
                materials: vec![Material::default()],
                draws: vec![Draw {
                    mesh: 0,
                    model,
                    node_name: String::new(),
                    node_index: 0,
                }],
                camera: kantele_rules::scene::Camera::framing(Vec3::ZERO, 1.0, Vec3::Z, 1.0),
                resolution: (64, 64),
                ..Scene::default()
            };
            let mut cpu = CpuBackend::new(CpuOptions::default()).expect("cpu");
            cpu.load(Arc::new(scene.clone())).expect("load");
            let stats = cpu.render(&FrameView::of_scene(&scene)).expect("render");
            (stats.fragments_shaded, stats.triangles_culled)
        };
        let plain = covered(Mat4::IDENTITY);
        let mirrored = covered(Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)));
        assert!(plain.0 > 500, "{plain:?}");
        assert_eq!(
            mirrored, plain,
            "the mirrored quad must be drawn, not culled"
        );
    }

    /// Without vertex colours the base colour is the factor exactly (no interpolated white,
    /// whose weights need not sum to exactly 1); with white vertex colours it is within rounding.
    #[test]
    fn meshes_without_vertex_colors_shade_with_the_factor_exactly() {
        let factor = Vec4::new(0.3, 0.6, 0.9, 1.0);
        let image = |colors: Option<Vec<Vec4>>| {
            let quad = Mesh {
                positions: vec![
                    Vec3::new(-0.5, -0.4, 0.0),
                    Vec3::new(0.6, -0.5, -0.3),
                    Vec3::new(0.5, 0.5, 0.2),
                    Vec3::new(-0.5, 0.45, 0.1),
                ],
                colors,
                indices: vec![0, 1, 2, 0, 2, 3],
                ..Mesh::default()
            };
            let scene = Scene {
                meshes: vec![quad],
                materials: vec![Material {
                    base_color_factor: factor,
                    unlit: true,
                    ..Material::default()
                }],
                draws: vec![Draw {
                    mesh: 0,
                    model: Mat4::IDENTITY,
                    node_name: String::new(),
                    node_index: 0,
                }],
                camera: kantele_rules::scene::Camera::framing(Vec3::ZERO, 1.0, Vec3::Z, 1.0),
                resolution: (64, 64),
                clear_color: Vec4::ZERO,
                ..Scene::default()
            };
            let mut cpu = CpuBackend::new(CpuOptions::default()).expect("cpu");
            cpu.load(Arc::new(scene.clone())).expect("load");
            cpu.render(&FrameView::of_scene(&scene)).expect("render");
            cpu.read_frame().expect("read")
        };
        let plain = image(None);
        let covered: Vec<_> = plain.color.iter().filter(|c| c[3] > 0.0).collect();
        assert!(covered.len() > 500, "{} pixels", covered.len());
        assert!(covered.iter().all(|c| **c == factor.to_array()));
        let white = image(Some(vec![Vec4::ONE; 4]));
        for (a, b) in plain.color.iter().zip(&white.color) {
            for (x, y) in a.iter().zip(b) {
                assert!((x - y).abs() <= 1e-6, "{a:?} vs {b:?}");
            }
        }
    }

    /// A red quad behind a clear, thin-walled pane: through the pane the red shows as without
    /// the pane, less the pane's reflection, where an opaque white pane hides it; a frame drawn in two bands is
    /// the whole frame's, although each band's transmission reads the whole backdrop.
    #[test]
    fn a_clear_pane_shows_what_is_behind_it() {
        let quad = |z: f32, material: usize| Mesh {
            positions: vec![
                Vec3::new(-0.5, -0.5, z),
                Vec3::new(0.5, -0.5, z),
                Vec3::new(0.5, 0.5, z),
                Vec3::new(-0.5, 0.5, z),
            ],
            normals: Some(vec![Vec3::Z; 4]),
            indices: vec![0, 1, 2, 0, 2, 3],
            material,
            ..Mesh::default()
        };
        // The pane's transmission, or no pane.
        let frame = |pane: Option<f32>, band: bool| {
            let transmission = pane.unwrap_or(0.0);
            let draws = if pane.is_some() { 2 } else { 1 };
            let scene = Scene {
                meshes: vec![quad(-0.3, 0), quad(0.0, 1)],
                materials: vec![
                    Material {
                        base_color_factor: Vec4::new(1.0, 0.0, 0.0, 1.0),
                        metallic: 0.0,
                        ..Material::default()
                    },
                    Material {
                        metallic: 0.0,
                        roughness: 0.0,
                        transmission,
                        ..Material::default()
                    },
                ],
                draws: (0..draws)
                    .map(|i| Draw {
                        mesh: i,
                        model: Mat4::from_scale(Vec3::new(2.0, 2.0, 1.0)),
                        node_name: String::new(),
                        node_index: i,
                    })
                    .collect(),
                camera: kantele_rules::scene::Camera::framing(Vec3::ZERO, 1.0, Vec3::Z, 1.0),
                resolution: (48, 48),
                shading: Shading::Pbr,
                clear_color: Vec4::ZERO,
                ..Scene::default()
            };
            let mut cpu = CpuBackend::new(CpuOptions::default()).expect("cpu");
            cpu.load(Arc::new(scene.clone())).expect("load");
            let view = FrameView::of_scene(&scene);
            if !band {
                cpu.render(&view).expect("render");
                return cpu.read_frame().expect("read").color;
            }
            let mut color = Vec::new();
            for rows in [0..20, 20..48] {
                cpu.set_render_region(Some(rows)).expect("region");
                cpu.render(&view).expect("render");
                color.extend(cpu.read_frame().expect("read").color);
            }
            color
        };
        // Off the centre, away from the headlight's highlight on the smooth pane.
        let centre = 30 * 48 + 14;
        let clear = frame(Some(1.0), false);
        let opaque = frame(Some(0.0), false);
        let bare = frame(None, false)[centre];
        assert!(
            bare[0] > 0.2 && bare[1] < 1e-3,
            "the red quad alone: {bare:?}"
        );
        let c = clear[centre];
        let kept = c[0] / bare[0];
        assert!(
            (0.85..1.0).contains(&kept) && c[1] < 1e-3,
            "through the pane: {c:?}, {kept} of the red"
        );
        let o = opaque[centre];
        assert!(
            o[1] > 0.2 && (o[0] - o[1]).abs() < 0.01,
            "opaque pane: {o:?}"
        );
        let banded = frame(Some(1.0), true);
        assert!(
            banded
                .iter()
                .zip(&clear)
                .all(|(a, b)| a.map(f32::to_bits) == b.map(f32::to_bits)),
            "two bands differ from the whole frame"
        );
    }
}
