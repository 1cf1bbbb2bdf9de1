//! One frame's GL commands: the fixed state, the program of the scene's shading (Lambert or
//! PBR) and its frame uniforms, then per draw its culling, alpha mode, blending, uniforms,
//! textures and primitive mode, in the scene's draw order.
//!
//! A PBR colour frame with a transmissive draw is drawn twice: first its backdrop
//! (`kantele_rules::shade::transmission`: the draws that are neither transmissive nor blended,
//! linear — no tone map, exposure 1 — at `backdrop_size`, one sample, into a `GL_RGBA32F`
//! framebuffer), read back into the rules' [`Backdrop`] and uploaded with its mip chain, then
//! the frame with the backdrop bound.

use std::sync::Arc;

use glam::{Mat3, Mat4, Vec4};
use glow::HasContext;
use kantele_rules::backend::{FrameView, Pass};
use kantele_rules::camera::normal_matrix;
use kantele_rules::scene::{
    AlphaMode, Draw, Material, Mesh, Scene, Shading, TextureBinding, Topology,
};
use kantele_rules::shade::pbr::{PbrLighting, Tonemap};
use kantele_rules::shade::transmission::{backdrop_size, Backdrop, TransmissionView, Volume};
use kantele_rules::stats::FrameStats;
use kantele_rules::RenderError;

use crate::resources::{upload_backdrop, GpuBackdrop};
use crate::{backend_error, pbr};
use crate::{shaders, GlBackend};

/// What one pass of [`GlBackend::draw_pass`] draws, and where.
struct PassSetup<'a> {
    framebuffer: glow::Framebuffer,
    /// The viewport's size.
    size: (u32, u32),
    /// Clear and draw depth alone (colour writes off).
    depth_only: bool,
    /// The PBR program's lighting (`None` for Lambert scenes).
    lighting: Option<&'a PbrLighting>,
    /// The frame's backdrop, when it has transmissive draws.
    backdrop: Option<&'a GpuBackdrop>,
    /// Draw only what a backdrop shows: the draws neither transmissive nor blended.
    backdrop_pass: bool,
}

/// Whether `draw` is transmissive (its material's `transmission` is above 0).
fn transmissive(scene: &Scene, draw: &Draw) -> bool {
    scene.materials[scene.meshes[draw.mesh].material].has_transmission()
}

impl GlBackend {
    /// Clear + every draw + glFinish into `framebuffer` (the target's or its multisampled
    /// one), with the context current. `depth_only` clears and draws depth alone (colour
    /// writes off): the per-pixel depth of a multisampled frame. A PBR colour frame with a
    /// transmissive draw first draws its backdrop (see the module docs).
    pub(crate) fn draw_frame(
        &self,
        scene: &Scene,
        view: &FrameView,
        framebuffer: glow::Framebuffer,
        depth_only: bool,
        stats: &mut FrameStats,
    ) -> Result<(), RenderError> {
        let target = self.target.as_ref().expect("target was created");
        let size = (target.width, target.height);
        let pbr = scene.shading == Shading::Pbr;
        let mut lighting = pbr.then(|| PbrLighting::for_frame(scene, view));
        let with_backdrop = pbr
            && view.pass == Pass::Color
            && !depth_only
            && scene.draws.iter().any(|d| transmissive(scene, d));
        let backdrop = match (&mut lighting, with_backdrop) {
            (Some(lighting), true) => {
                let backdrop = self.draw_backdrop(scene, view, lighting)?;
                lighting.transmission = Some(TransmissionView {
                    backdrop: backdrop.backdrop.clone(),
                    view_projection: view.projection * view.view,
                });
                Some(backdrop)
            }
            _ => None,
        };
        let setup = PassSetup {
            framebuffer,
            size,
            depth_only,
            lighting: lighting.as_ref(),
            backdrop: backdrop.as_ref(),
            backdrop_pass: false,
        };
        let result = self.draw_pass(scene, view, &setup, stats);
        if let Some(backdrop) = backdrop {
            // SAFETY: `gl` is current on this thread; the texture is ours and no longer used.
            unsafe { self.gl.delete_texture(backdrop.texture) };
        }
        result
    }

    /// The backdrop of a frame of `scene` seen as `view` lit by `lighting`: its opaque draws
    /// drawn linear into a one-sample `GL_RGBA32F` framebuffer of [`backdrop_size`], read back
    /// (row 0 at the top, as the y-flipped projection draws it), turned into the rules'
    /// [`Backdrop`] and uploaded.
    fn draw_backdrop(
        &self,
        scene: &Scene,
        view: &FrameView,
        lighting: &PbrLighting,
    ) -> Result<GpuBackdrop, RenderError> {
        let (width, height) = backdrop_size(view.width, view.height);
        let linear = PbrLighting {
            tonemap: Tonemap::None,
            exposure: 1.0,
            transmission: None,
            ..lighting.clone()
        };
        let framebuffer = self.create_backdrop_target(width, height)?;
        let setup = PassSetup {
            framebuffer: framebuffer.framebuffer,
            size: (width, height),
            depth_only: false,
            lighting: Some(&linear),
            backdrop: None,
            backdrop_pass: true,
        };
        let drawn = self.draw_pass(scene, view, &setup, &mut FrameStats::default());
        let pixels = drawn.and_then(|()| self.read_color(framebuffer.framebuffer, width, height));
        self.delete_backdrop_target(framebuffer);
        let backdrop = Backdrop::new(width, height, &pixels?)
            .ok_or_else(|| backend_error(format!("backdrop {width}x{height}: no chain")))?;
        // SAFETY: `gl` is current on this thread.
        let uploaded = unsafe { upload_backdrop(&self.gl, Arc::new(backdrop)) }
            .map_err(|e| backend_error(format!("uploading the backdrop: {e}")))?;
        if let Err(e) = self.check("uploading the backdrop") {
            // SAFETY: `gl` is current on this thread; the texture is ours and unused.
            unsafe { self.gl.delete_texture(uploaded.texture) };
            return Err(e);
        }
        Ok(uploaded)
    }

    /// Clear + the draws of `setup` + glFinish, with the context current.
    fn draw_pass(
        &self,
        scene: &Scene,
        view: &FrameView,
        setup: &PassSetup,
        stats: &mut FrameStats,
    ) -> Result<(), RenderError> {
        let gl = &self.gl;
        let (framebuffer, depth_only) = (setup.framebuffer, setup.depth_only);
        // Lambert scenes: the Lambert program, its uniforms and GL calls exactly as ever.
        let pbr = scene.shading == Shading::Pbr;
        let (program, u) = if pbr {
            (self.pbr_program, &self.pbr_uniforms.common)
        } else {
            (self.program, &self.uniforms)
        };
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
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(framebuffer));
            gl.draw_buffers(&[glow::COLOR_ATTACHMENT0]);
            gl.viewport(0, 0, setup.size.0 as i32, setup.size.1 as i32);
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

            gl.use_program(Some(program));
            if let (true, Some(lighting)) = (pbr, setup.lighting) {
                pbr::set_frame_uniforms(
                    gl,
                    &self.pbr_uniforms,
                    lighting,
                    self.gpu.environment.as_ref(),
                    pbr::LookupTables {
                        brdf: self.gpu.brdf,
                        sheen_albedo: self.gpu.sheen_albedo,
                    },
                    setup.backdrop,
                );
            }
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
                if setup.backdrop_pass
                    && (material.has_transmission() || scene.is_blended(draw_index))
                {
                    continue;
                }
                stats.draws += 1;
                stats.triangles_in += mesh.primitive_count() as u64;
                if gpu_mesh.index_count == 0 {
                    continue;
                }
                // The y-flip mirrors the winding: front (CCW in NDC) is CW in GL's window; a
                // mirroring model matrix flips it once more.
                gl.front_face(match draw.front_face() {
                    kantele_rules::setup::FrontFace::Ccw => glow::CW,
                    kantele_rules::setup::FrontFace::Cw => glow::CCW,
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
                if pbr {
                    self.set_pbr_draw_uniforms(draw, material, mesh, setup.backdrop);
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

impl GlBackend {
    /// The PBR program's uniforms and textures of one draw: the model matrix and whether it
    /// mirrors, the material's metallic, roughness, normal scale and occlusion strength, its
    /// PBR textures on their units with the samplers of the mesh's material, the texture
    /// coordinate set of every texture, whether the mesh has tangents, its sheen (colour,
    /// roughness, and whether it has one), and — for a transmissive material in a frame with a
    /// `backdrop` — its transmission, thickness and the rules' [`Volume`] constants.
    ///
    /// # Safety
    /// `self.gl` must be current on this thread with the PBR program in use; `material` must be
    /// the material of `mesh` in the loaded scene (or its unlit copy), whose texture indices
    /// were validated.
    unsafe fn set_pbr_draw_uniforms(
        &self,
        draw: &Draw,
        material: &Material,
        mesh: &Mesh,
        backdrop: Option<&GpuBackdrop>,
    ) {
        let gl = &self.gl;
        let u = &self.pbr_uniforms;
        let samplers = self.gpu.pbr_samplers[mesh.material];
        let mirrored = Mat3::from_mat4(draw.model).determinant() < 0.0;
        let set = |b: Option<TextureBinding>| b.map_or(0, |b| b.texcoord as i32);
        // One texture per entry of PBR_TEXTURES (a different count does not compile).
        let textures: [Option<TextureBinding>; pbr::PBR_TEXTURES.len()] = material.pbr_textures();
        let mut sets = [0i32; pbr::TEXTURE_SLOTS];
        sets[0] = set(material.base_color_texture);
        sets[1] = set(material.emissive_texture);
        for (k, binding) in textures.into_iter().enumerate() {
            sets[2 + k] = set(binding);
        }
        let volume = backdrop.filter(|_| material.has_transmission()).map(|b| {
            Volume::new(
                material.ior,
                material.attenuation_color,
                material.attenuation_distance,
                &draw.model,
                &b.backdrop,
            )
        });
        let coat_normal = material
            .clearcoat_normal_texture
            .filter(|_| material.has_clearcoat());
        let frame_set = set(material.normal_texture.or(coat_normal));
        // SAFETY: caller's contract; the textures and samplers are ours and alive.
        unsafe {
            gl.uniform_matrix_4_f32_slice(u.model.as_ref(), false, &draw.model.to_cols_array());
            gl.uniform_1_f32(u.tangent_sign.as_ref(), if mirrored { -1.0 } else { 1.0 });
            gl.uniform_1_i32_slice(u.texcoord_sets.as_ref(), &sets);
            gl.uniform_1_i32(u.frame_set.as_ref(), frame_set);
            gl.uniform_1_i32(u.has_tangents.as_ref(), mesh.tangents.is_some() as i32);
            gl.uniform_1_f32(u.metallic.as_ref(), material.metallic);
            gl.uniform_1_f32(u.roughness.as_ref(), material.roughness);
            gl.uniform_1_f32(u.normal_scale.as_ref(), material.normal_scale);
            gl.uniform_1_f32(u.occlusion_strength.as_ref(), material.occlusion_strength);
            gl.uniform_3_f32_slice(u.dielectric_f0.as_ref(), &material.dielectric_f0.to_array());
            gl.uniform_1_f32(u.specular_weight.as_ref(), material.specular_weight);
            gl.uniform_1_f32(u.clearcoat.as_ref(), material.clearcoat);
            gl.uniform_1_f32(u.clearcoat_roughness.as_ref(), material.clearcoat_roughness);
            gl.uniform_1_f32(
                u.clearcoat_normal_scale.as_ref(),
                material.clearcoat_normal_scale,
            );
            gl.uniform_1_i32(u.transmissive.as_ref(), volume.is_some() as i32);
            if let Some(volume) = volume {
                let ior_scale = (2.0 * volume.ior - 2.0).clamp(0.0, 1.0);
                gl.uniform_1_f32(u.transmission.as_ref(), material.transmission);
                gl.uniform_1_f32(u.thickness.as_ref(), material.thickness);
                gl.uniform_1_f32(u.eta.as_ref(), 1.0 / volume.ior);
                gl.uniform_1_f32(u.ior_scale.as_ref(), ior_scale);
                gl.uniform_3_f32_slice(u.volume_scale.as_ref(), &volume.scale.to_array());
                gl.uniform_3_f32_slice(u.attenuation.as_ref(), &volume.attenuation.to_array());
                gl.uniform_1_f32(u.lod_scale.as_ref(), volume.lod_scale);
            }
            gl.uniform_1_i32(u.sheen.as_ref(), material.has_sheen() as i32);
            gl.uniform_3_f32_slice(u.sheen_color.as_ref(), &material.sheen_color.to_array());
            gl.uniform_1_f32(u.sheen_roughness.as_ref(), material.sheen_roughness);
            for (k, ((binding, sampler), [has, _])) in textures
                .into_iter()
                .zip(samplers)
                .zip(&u.textures)
                .enumerate()
            {
                let unit = pbr::FIRST_PBR_UNIT + k as u32;
                gl.active_texture(glow::TEXTURE0 + unit);
                gl.uniform_1_i32(has.as_ref(), binding.is_some() as i32);
                gl.bind_texture(
                    glow::TEXTURE_2D,
                    binding.map(|b| self.gpu.textures[b.texture]),
                );
                gl.bind_sampler(unit, binding.and(sampler));
            }
        }
    }
}
