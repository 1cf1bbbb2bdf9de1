//! A frame of a [`Shading::Pbr`](kantele_rules::scene::Shading::Pbr) scene: the shader of
//! every draw and, when a colour frame has transmissive draws, the backdrop they see through
//! ([`kantele_rules::shade::transmission`]), drawn first into a target kept between frames.

use std::sync::Arc;

use super::{draw_scene, layout_mismatch, CpuBackend, PreparedMesh, PreparedMeshes};
use crate::pbr_material::{Bound, PbrShader, PbrTextures};
use crate::pipeline::Renderer;
use crate::rop::{Framebuffer, TargetFormat};
use kantele_rules::backend::{FrameView, Pass};
use kantele_rules::error::RenderError;
use kantele_rules::multisample::SampleCount;
use kantele_rules::scene::{Material, Scene};
use kantele_rules::shade::pbr::{PbrLighting, Tonemap};
use kantele_rules::shade::transmission::{backdrop_size, Backdrop, TransmissionView};
use kantele_rules::stats::FrameStats;
use kantele_rules::vertex::PbrVertex;

impl CpuBackend {
    /// A frame of a [`Shading::Pbr`] scene (the renderer already sized for `view`). A colour
    /// frame with transmissive draws first draws its backdrop ([`draw_backdrop`]).
    pub(super) fn render_pbr(&mut self, view: &FrameView) -> Result<FrameStats, RenderError> {
        let Some((scene, meshes)) = &self.scene else {
            return Err(RenderError::InvalidScene("no scene loaded".into()));
        };
        let PreparedMeshes::Pbr(meshes) = meshes else {
            return Err(layout_mismatch());
        };
        let mut lighting = PbrLighting::for_frame(scene, view);
        let unlit = scene.unlit_materials();
        let transmissive = transmissive_draws(scene, &unlit);
        if view.pass == Pass::Color && transmissive.iter().any(|&t| t) {
            let (width, height) = backdrop_size(view.width, view.height);
            let mut target = match self.backdrop_target.take() {
                Some(fb) if (fb.width(), fb.height()) == (width, height) => fb,
                _ => Framebuffer::band(
                    width,
                    height,
                    0..height,
                    SampleCount::X1,
                    TargetFormat::LinearF32,
                    self.renderer.threads(),
                )?,
            };
            // Draw into the backdrop's target, then give the frame its own back.
            self.renderer.swap_target(&mut target);
            let backdrop = draw_backdrop(
                &mut self.renderer,
                scene,
                &unlit,
                meshes,
                view,
                &transmissive,
            );
            self.renderer.swap_target(&mut target);
            self.backdrop_target = Some(target);
            lighting.transmission = Some(TransmissionView {
                backdrop: Arc::new(backdrop?),
                view_projection: view.projection * view.view,
            });
        }
        let shaders = pbr_shaders(scene, &unlit, view, &lighting);
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
}

/// Whether each draw of `scene` has a transmissive material (`unlit`: its unlit materials).
fn transmissive_draws(scene: &Scene, unlit: &[Material]) -> Vec<bool> {
    scene
        .draws
        .iter()
        .map(|draw| scene.draw_material(draw.mesh, unlit).has_transmission())
        .collect()
}

/// Draws the backdrop of a colour frame `view` of `scene`
/// ([`kantele_rules::shade::transmission`]) into the renderer's target (the caller's 1-sample
/// `f32` target of [`backdrop_size`], whole, whatever rows the frame itself is restricted to):
/// every draw that is neither transmissive (`transmissive`) nor blended, with the frame's
/// camera and clear colour, linear (no exposure, no tone map).
fn draw_backdrop(
    renderer: &mut Renderer,
    scene: &Scene,
    unlit: &[Material],
    meshes: &[PreparedMesh<PbrVertex>],
    view: &FrameView,
    transmissive: &[bool],
) -> Result<Backdrop, RenderError> {
    let (width, height) = (
        renderer.framebuffer().width(),
        renderer.framebuffer().height(),
    );
    let mut lighting = PbrLighting::for_frame(scene, view);
    lighting.exposure = 1.0;
    lighting.tonemap = Tonemap::None;
    let shaders = pbr_shaders(scene, unlit, view, &lighting);
    draw_scene(
        renderer,
        scene,
        meshes,
        view,
        &shaders,
        |s| s.render_state(),
        |i| !transmissive[i] && !scene.is_blended(i),
    )?;
    let color = renderer.framebuffer().try_read_color()?;
    Backdrop::new(width, height, &color).ok_or_else(|| {
        RenderError::InvalidScene(format!(
            "the backdrop of {width} x {height} pixels could not be built"
        ))
    })
}

/// The shaders of every draw of a PBR frame `view` of `scene` lit by `lighting`.
fn pbr_shaders<'a>(
    scene: &'a Scene,
    unlit: &'a [Material],
    view: &FrameView,
    lighting: &'a PbrLighting,
) -> Vec<PbrShader<'a>> {
    let view_projection = view.projection * view.view;
    let bound = |b: Option<kantele_rules::scene::TextureBinding>| {
        b.map(|b| Bound {
            texture: &scene.textures[b.texture],
            sampler: b.sampler,
            texcoord: b.texcoord,
        })
    };
    scene
        .draws
        .iter()
        .enumerate()
        .map(|(i, draw)| {
            let material = scene.draw_material(draw.mesh, unlit);
            let textures = PbrTextures {
                base_color: bound(material.base_color_texture),
                emissive: bound(material.emissive_texture),
                metallic_roughness: bound(material.metallic_roughness_texture),
                normal: bound(material.normal_texture),
                occlusion: bound(material.occlusion_texture),
                specular: bound(material.specular_texture),
                specular_color: bound(material.specular_color_texture),
                clearcoat: bound(material.clearcoat_texture),
                clearcoat_roughness: bound(material.clearcoat_roughness_texture),
                clearcoat_normal: bound(material.clearcoat_normal_texture),
                transmission: bound(material.transmission_texture),
                thickness: bound(material.thickness_texture),
                sheen_color: bound(material.sheen_color_texture),
                sheen_roughness: bound(material.sheen_roughness_texture),
            };
            PbrShader::new(
                draw.model,
                view_projection,
                lighting,
                material,
                textures,
                view.pass,
                (draw.node_index as u32 + 1, i as u32 + 1),
            )
            .with_mesh_attributes(
                scene.meshes[draw.mesh].colors.is_some(),
                scene.meshes[draw.mesh].tangents.is_some(),
            )
        })
        .collect()
}
