//! Plain scene data shared by every backend: meshes, materials, textures, draws, camera and
//! light. Loaders (`kantele-scene`) fill it; backends draw it by the rules of the reference scenes
//! (see the crate docs): draws in order, Lambert or unlit shading, alpha modes.

use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3, Vec4};

use crate::camera;
use crate::error::RenderError;
use crate::setup::FrontFace;
use crate::shade::texture::{Sampler, Texture};
pub use crate::state::Topology;

/// An indexed list of triangles, lines or points ([`Mesh::topology`]) with the standard vertex
/// attributes.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Name for reports (glTF mesh name, OBJ object name); may be empty.
    pub name: String,
    /// Object-space positions.
    pub positions: Vec<Vec3>,
    /// Object-space normals, one per position; `None` means flat shading from face normals.
    pub normals: Option<Vec<Vec3>>,
    /// Texture coordinates, one per position; (0, 0) is the image's top-left. The first set
    /// of the material's textures ([`TextureBinding::texcoord`] 0): the glTF loader stores
    /// here the `TEXCOORD_n` set its first texture reads, with that texture's
    /// `KHR_texture_transform` applied.
    pub texcoords: Option<Vec<Vec2>>,
    /// A second set of texture coordinates, one per position, for the textures of the material
    /// that read other coordinates than the first set ([`TextureBinding::texcoord`] 1).
    pub texcoords1: Option<Vec<Vec2>>,
    /// Object-space tangents for normal textures, one per position: the direction of
    /// increasing u of the normal texture's coordinates in `xyz`, and in `w` (±1) the sign of
    /// the bitangent `w × (normal × tangent)`. `None`: the shading derives a tangent frame from
    /// screen-space derivatives.
    pub tangents: Option<Vec<Vec4>>,
    /// Linear vertex colours (`COLOR_0`), RGBA, one per position.
    pub colors: Option<Vec<Vec4>>,
    /// Index list: three indices per triangle, two per line, one per point.
    pub indices: Vec<u32>,
    /// What the indices describe (strips, fans and loops are unrolled by the loaders).
    pub topology: Topology,
    /// Index into [`Scene::materials`].
    pub material: usize,
}

impl Mesh {
    /// Number of triangles (0 for a mesh of lines or points).
    pub fn triangle_count(&self) -> usize {
        match self.topology {
            Topology::Triangles => self.indices.len() / 3,
            _ => 0,
        }
    }

    /// Number of primitives: triangles, lines or points.
    pub fn primitive_count(&self) -> usize {
        self.indices.len() / self.topology.vertices_per_primitive()
    }

    /// The mesh with one vertex per triangle corner and every normal set to its face normal
    /// `normalize((b − a) × (c − a))` (object space; counter-clockwise faces point outwards).
    /// Zero-area faces get +Z. Used for meshes without normals. Lines and points have no
    /// faces: they keep their vertices and get +Z normals (backends draw them unlit, as glTF
    /// asks for lines and points without normals).
    pub fn flat_shaded(&self) -> Mesh {
        if self.topology != Topology::Triangles {
            return Mesh {
                normals: Some(vec![Vec3::Z; self.positions.len()]),
                ..self.clone()
            };
        }
        let n = self.indices.len();
        let mut out = Mesh {
            name: self.name.clone(),
            positions: Vec::with_capacity(n),
            normals: Some(Vec::with_capacity(n)),
            texcoords: self.texcoords.as_ref().map(|_| Vec::with_capacity(n)),
            texcoords1: self.texcoords1.as_ref().map(|_| Vec::with_capacity(n)),
            tangents: self.tangents.as_ref().map(|_| Vec::with_capacity(n)),
            colors: self.colors.as_ref().map(|_| Vec::with_capacity(n)),
            indices: (0..n as u32).collect(),
            topology: Topology::Triangles,
            material: self.material,
        };
        let get = |i: u32| self.positions.get(i as usize).copied().unwrap_or(Vec3::NAN);
        for tri in self.indices.chunks_exact(3) {
            let [a, b, c] = [get(tri[0]), get(tri[1]), get(tri[2])];
            let normal = (b - a).cross(c - a).try_normalize().unwrap_or(Vec3::Z);
            for &i in tri {
                out.positions.push(get(i));
                if let Some(normals) = &mut out.normals {
                    normals.push(normal);
                }
                if let (Some(dst), Some(src)) = (&mut out.texcoords, &self.texcoords) {
                    dst.push(src.get(i as usize).copied().unwrap_or(Vec2::ZERO));
                }
                if let (Some(dst), Some(src)) = (&mut out.texcoords1, &self.texcoords1) {
                    dst.push(src.get(i as usize).copied().unwrap_or(Vec2::ZERO));
                }
                if let (Some(dst), Some(src)) = (&mut out.tangents, &self.tangents) {
                    dst.push(src.get(i as usize).copied().unwrap_or(Vec4::ZERO));
                }
                if let (Some(dst), Some(src)) = (&mut out.colors, &self.colors) {
                    dst.push(src.get(i as usize).copied().unwrap_or(Vec4::ONE));
                }
            }
        }
        out
    }

    /// Object-space bounding box `(min, max)` of the referenced positions, ignoring non-finite
    /// ones; `None` when there are none.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut it = self.positions.iter().filter(|p| p.is_finite());
        let first = *it.next()?;
        Some(it.fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p))))
    }
}

/// How a material treats alpha (glTF `alphaMode`).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum AlphaMode {
    /// Alpha is ignored (taken as 1).
    #[default]
    Opaque,
    /// Fragments with alpha below the cutoff are discarded; the rest are opaque.
    Mask {
        /// `alphaCutoff` (glTF default 0.5).
        cutoff: f32,
    },
    /// `dst = src.rgb × src.a + dst × (1 − src.a)`, depth tested but not written.
    Blend,
}

/// A texture reference with the sampler it is read through.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureBinding {
    /// Index into [`Scene::textures`].
    pub texture: usize,
    /// How it is sampled.
    pub sampler: Sampler,
    /// Which of the mesh's sets of texture coordinates it reads: 0 [`Mesh::texcoords`],
    /// 1 [`Mesh::texcoords1`].
    pub texcoord: u32,
}

/// A material with the shading rules of the reference scenes.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Name for reports; may be empty.
    pub name: String,
    /// Linear RGBA factor (`baseColorFactor`).
    pub base_color_factor: Vec4,
    /// sRGB base colour texture, multiplied in after decoding.
    pub base_color_texture: Option<TextureBinding>,
    /// Back faces are drawn (and lit from their side) instead of culled.
    pub double_sided: bool,
    /// Alpha handling.
    pub alpha_mode: AlphaMode,
    /// Unlit: colour = base colour + emission, no lighting (`KHR_materials_unlit`, whose
    /// materials the loader gives no emission, and lines and points without normals, which glTF
    /// draws as base + emissive).
    pub unlit: bool,
    /// Linear emitted colour (`emissiveFactor` × `KHR_materials_emissive_strength`), added after
    /// lighting.
    pub emissive: Vec3,
    /// sRGB emissive texture, multiplied into `emissive`. Lambert shading reads it, as the
    /// base colour texture, with the first texture coordinate set; PBR shading with its own
    /// ([`TextureBinding::texcoord`]).
    pub emissive_texture: Option<TextureBinding>,
    /// `metallicFactor` (PBR shading; glTF default 1).
    pub metallic: f32,
    /// `roughnessFactor`, perceptual (PBR shading; glTF default 1).
    pub roughness: f32,
    /// Linear texture whose blue channel multiplies `metallic` and green `roughness`.
    pub metallic_roughness_texture: Option<TextureBinding>,
    /// Linear tangent-space normal texture (PBR shading).
    pub normal_texture: Option<TextureBinding>,
    /// Scales the normal texture's X and Y (`normalTexture.scale`).
    pub normal_scale: f32,
    /// Linear texture whose red channel is ambient occlusion (PBR shading, image-based light).
    pub occlusion_texture: Option<TextureBinding>,
    /// `occlusion = 1 + strength × (texel − 1)` (`occlusionTexture.strength`).
    pub occlusion_strength: f32,
    /// Reflectance at normal incidence of the dielectric part, before the specular colour
    /// texture: `((ior − 1) / (ior + 1))² × specularColorFactor` (`KHR_materials_ior`,
    /// `KHR_materials_specular`; 0.04 without them). The shading clamps it to 1 after the
    /// texture.
    pub dielectric_f0: Vec3,
    /// `specularFactor`: scales the dielectric part's specular reflection, which the diffuse
    /// part then makes room for (`KHR_materials_specular`; 1 without it).
    pub specular_weight: f32,
    /// Linear texture whose alpha channel multiplies `specular_weight`.
    pub specular_texture: Option<TextureBinding>,
    /// sRGB texture whose RGB multiplies `dielectric_f0`.
    pub specular_color_texture: Option<TextureBinding>,
    /// `clearcoatFactor`: the weight of a clear coat over the material (`KHR_materials_clearcoat`;
    /// 0 without it: no coat).
    pub clearcoat: f32,
    /// Linear texture whose red channel multiplies `clearcoat`.
    pub clearcoat_texture: Option<TextureBinding>,
    /// `clearcoatRoughnessFactor`, perceptual.
    pub clearcoat_roughness: f32,
    /// Linear texture whose green channel multiplies `clearcoat_roughness`.
    pub clearcoat_roughness_texture: Option<TextureBinding>,
    /// Linear tangent-space normal texture of the coat (without one the coat follows the
    /// interpolated normal, not the base's normal texture).
    pub clearcoat_normal_texture: Option<TextureBinding>,
    /// Scales the coat normal texture's X and Y.
    pub clearcoat_normal_scale: f32,
    /// Index of refraction of the dielectric part (`KHR_materials_ior`; 1.5 without it): bends
    /// the light a volume transmits and widens rough transmission.
    pub ior: f32,
    /// `transmissionFactor`: the part of the dielectric's diffuse light replaced by light from
    /// behind the surface (`KHR_materials_transmission`; 0 without it: opaque).
    pub transmission: f32,
    /// Linear texture whose red channel multiplies `transmission`.
    pub transmission_texture: Option<TextureBinding>,
    /// `thicknessFactor`: the volume's thickness under the surface, in the mesh's units
    /// (`KHR_materials_volume`; 0: thin-walled, no refraction).
    pub thickness: f32,
    /// Linear texture whose green channel multiplies `thickness`.
    pub thickness_texture: Option<TextureBinding>,
    /// `attenuationColor`: the colour white light becomes after `attenuation_distance` inside
    /// the volume (linear RGB in [0, 1]).
    pub attenuation_color: Vec3,
    /// `attenuationDistance` in world units; infinite: no attenuation.
    pub attenuation_distance: f32,
    /// `sheenColorFactor`: the colour of a layer of fibres over the material
    /// (`KHR_materials_sheen`, linear RGB in [0, 1]; black without it: no sheen).
    pub sheen_color: Vec3,
    /// sRGB texture whose RGB multiplies `sheen_color`.
    pub sheen_color_texture: Option<TextureBinding>,
    /// `sheenRoughnessFactor`, perceptual.
    pub sheen_roughness: f32,
    /// Linear texture whose alpha channel multiplies `sheen_roughness`.
    pub sheen_roughness_texture: Option<TextureBinding>,
}

impl Default for Material {
    fn default() -> Self {
        Self {
            name: String::new(),
            base_color_factor: Vec4::ONE,
            base_color_texture: None,
            double_sided: false,
            alpha_mode: AlphaMode::Opaque,
            unlit: false,
            emissive: Vec3::ZERO,
            emissive_texture: None,
            metallic: 1.0,
            roughness: 1.0,
            metallic_roughness_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            occlusion_texture: None,
            occlusion_strength: 1.0,
            dielectric_f0: Vec3::splat(crate::shade::pbr::DIELECTRIC_F0),
            specular_weight: 1.0,
            specular_texture: None,
            specular_color_texture: None,
            clearcoat: 0.0,
            clearcoat_texture: None,
            clearcoat_roughness: 0.0,
            clearcoat_roughness_texture: None,
            clearcoat_normal_texture: None,
            clearcoat_normal_scale: 1.0,
            ior: 1.5,
            transmission: 0.0,
            transmission_texture: None,
            thickness: 0.0,
            thickness_texture: None,
            attenuation_color: Vec3::ONE,
            attenuation_distance: f32::INFINITY,
            sheen_color: Vec3::ZERO,
            sheen_color_texture: None,
            sheen_roughness: 0.0,
            sheen_roughness_texture: None,
        }
    }
}

impl Material {
    /// The material's textures that PBR shading reads besides the base colour and emissive
    /// ones: metallic-roughness, normal, occlusion, specular, specular colour, clear coat,
    /// clear-coat roughness, clear-coat normal, transmission, thickness, sheen colour and sheen
    /// roughness.
    pub fn pbr_textures(&self) -> [Option<TextureBinding>; 12] {
        [
            self.metallic_roughness_texture,
            self.normal_texture,
            self.occlusion_texture,
            self.specular_texture,
            self.specular_color_texture,
            self.clearcoat_texture,
            self.clearcoat_roughness_texture,
            self.clearcoat_normal_texture,
            self.transmission_texture,
            self.thickness_texture,
            self.sheen_color_texture,
            self.sheen_roughness_texture,
        ]
    }

    /// Whether the material has a sheen (a sheen colour above black; unlit materials have
    /// none).
    pub fn has_sheen(&self) -> bool {
        self.sheen_color.max_element() > 0.0 && !self.unlit
    }

    /// Whether the material has a clear coat (`clearcoat > 0`).
    pub fn has_clearcoat(&self) -> bool {
        self.clearcoat > 0.0
    }

    /// Whether light from behind shows through the material (`transmission > 0`; unlit
    /// materials transmit nothing).
    pub fn has_transmission(&self) -> bool {
        self.transmission > 0.0 && !self.unlit
    }
}

/// Which shading model a scene is drawn with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Shading {
    /// The reference scenes' rule: Lambert under one directional light with an ambient term
    /// (`docs/rendering-rules.md`). Chosen by the loaders for reference scenes (glTF files
    /// whose `scene.extras` carry `ambient`) and for built-in scenes.
    #[default]
    Lambert,
    /// glTF 2.0's metallic-roughness model (Appendix B) under the scene's punctual lights and
    /// environment ([`crate::shade::pbr`]).
    Pbr,
}

impl Shading {
    /// The command-line name: `lambert`, `pbr`.
    pub fn name(self) -> &'static str {
        match self {
            Shading::Lambert => "lambert",
            Shading::Pbr => "pbr",
        }
    }
}

/// What kind of `KHR_lights_punctual` light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightKind {
    /// Parallel light along [`PunctualLight::direction`].
    Directional,
    /// Light from [`PunctualLight::position`] in every direction.
    Point,
    /// A point light limited to a cone around [`PunctualLight::direction`].
    Spot {
        /// Angle from the axis where the falloff starts (radians).
        inner_cone_angle: f32,
        /// Angle from the axis where the light ends (radians).
        outer_cone_angle: f32,
    },
}

/// A punctual light placed in the world (PBR shading).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PunctualLight {
    /// Its kind.
    pub kind: LightKind,
    /// Linear colour × intensity (lux for directional lights, candela for the others).
    pub color: Vec3,
    /// World position (point and spot lights).
    pub position: Vec3,
    /// World direction the light travels (the node's −Z; directional and spot lights).
    pub direction: Vec3,
    /// Distance where the light ends (`None`: infinite).
    pub range: Option<f32>,
}

/// One draw: a mesh placed in the world by a node.
#[derive(Clone, Debug)]
pub struct Draw {
    /// Index into [`Scene::meshes`].
    pub mesh: usize,
    /// Object → world transform.
    pub model: Mat4,
    /// The node's name (for id maps); may be empty.
    pub node_name: String,
    /// The node's index in the source file (instance id − 1 in id buffers).
    pub node_index: usize,
}

impl Draw {
    /// Which winding is front for this draw: a model matrix with a negative determinant
    /// mirrors the mesh, so its counter-clockwise faces appear clockwise (glTF 2.0 §3.7.4).
    pub fn front_face(&self) -> FrontFace {
        if self.model.determinant() < 0.0 {
            FrontFace::Cw
        } else {
            FrontFace::Ccw
        }
    }
}

/// A camera of the source file with its name (the glTF camera's name, or `camera N`).
#[derive(Clone, Debug, PartialEq)]
pub struct NamedCamera {
    /// The camera's name in the file.
    pub name: String,
    /// The camera, placed by its node.
    pub camera: Camera,
}

/// A perspective or orthographic camera: placement plus glTF-style projection parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// World → eye transform (inverse of the camera node's world matrix).
    pub view: Mat4,
    /// Vertical field of view in radians (perspective cameras).
    pub yfov: f32,
    /// `Some(ymag)`: an orthographic camera whose view volume is `2·ymag` scene units high (and
    /// `2·ymag·aspect` wide; glTF's `xmag / ymag` is its `aspect_ratio`); `yfov` is then unused
    /// and `zfar` must be finite.
    pub ymag: Option<f32>,
    /// Width / height; `None` means the render target's aspect.
    pub aspect_ratio: Option<f32>,
    /// Near plane distance (> 0).
    pub znear: f32,
    /// Far plane distance; `None` is an infinite projection.
    pub zfar: Option<f32>,
}

impl Camera {
    /// The projection matrix for a target of the given aspect ratio (used when the camera has
    /// none of its own).
    pub fn projection(&self, target_aspect: f32) -> Mat4 {
        let aspect = self.aspect_ratio.unwrap_or(target_aspect);
        if let Some(ymag) = self.ymag {
            let xmag = ymag * aspect;
            let far = self.zfar.unwrap_or(self.znear + 1.0);
            return Mat4::orthographic_rh_gl(-xmag, xmag, -ymag, ymag, self.znear, far);
        }
        match self.zfar {
            Some(far) => camera::perspective(self.yfov, aspect, self.znear, far),
            None => camera::perspective_infinite(self.yfov, aspect, self.znear),
        }
    }

    /// Eye → world transform.
    pub fn world_from_eye(&self) -> Mat4 {
        self.view.inverse()
    }

    /// A camera looking at the bounding sphere `(center, radius)` from direction `from_dir`
    /// (towards the eye), framing it completely for the given aspect ratio.
    pub fn framing(center: Vec3, radius: f32, from_dir: Vec3, aspect: f32) -> Self {
        let yfov = 45f32.to_radians();
        let radius = if radius.is_finite() && radius > 0.0 {
            radius
        } else {
            1.0
        };
        let half = 0.5 * yfov.min(2.0 * (aspect.max(1e-3) * (0.5 * yfov).tan()).atan());
        let distance = radius / half.sin();
        let dir = from_dir.try_normalize().unwrap_or(Vec3::Z);
        let eye = center + dir * distance;
        let up = if dir.cross(Vec3::Y).length_squared() < 1e-6 {
            Vec3::Z
        } else {
            Vec3::Y
        };
        Self {
            view: camera::look_at(eye, center, up),
            yfov,
            ymag: None,
            aspect_ratio: None,
            znear: (distance - radius).max(distance * 1e-3) * 0.5,
            zfar: Some(distance + radius * 2.0),
        }
    }
}

/// The scene's light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// A directional light shining along the camera's view direction (`L` = camera +Z), colour 1.
    Headlight,
    /// A directional light.
    Directional {
        /// Unit vector towards the light, in world space (the light node's world +Z).
        to_light: Vec3,
        /// Colour × intensity.
        color: Vec3,
    },
}

impl Light {
    /// `(L, colour)` in world space for a camera with the given view matrix.
    pub fn resolve(&self, view: &Mat4) -> (Vec3, Vec3) {
        match *self {
            Light::Headlight => {
                let to_light = view
                    .inverse()
                    .transform_vector3(Vec3::Z)
                    .normalize_or_zero();
                (to_light, Vec3::ONE)
            }
            Light::Directional { to_light, color } => (to_light.normalize_or_zero(), color),
        }
    }
}

/// Everything needed to draw a picture by the reference-scene rules.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Meshes (glTF primitives), referenced by draws.
    pub meshes: Vec<Mesh>,
    /// Materials, referenced by meshes.
    pub materials: Vec<Material>,
    /// Decoded textures with mip chains, referenced by materials.
    pub textures: Vec<Arc<Texture>>,
    /// Draws in draw order.
    pub draws: Vec<Draw>,
    /// The scene's camera (a loader supplies a framing one when the file has none).
    pub camera: Camera,
    /// Every usable camera of the source file, in draw order, by name (the first is `camera`);
    /// empty when the file has none.
    pub file_cameras: Vec<NamedCamera>,
    /// The light.
    pub light: Light,
    /// Ambient term of the Lambert rule.
    pub ambient: f32,
    /// Linear clear colour.
    pub clear_color: Vec4,
    /// Image size `(width, height)` the scene asks for.
    pub resolution: (u32, u32),
    /// The shading model.
    pub shading: Shading,
    /// Punctual lights of PBR shading (the Lambert rule reads [`Scene::light`]). With neither
    /// lights nor an environment, PBR scenes are lit by a headlight.
    pub lights: Vec<PunctualLight>,
    /// Image-based light of PBR shading.
    pub environment: Option<crate::shade::environment::EnvironmentLight>,
    /// Exposure of PBR shading in stops (colour × 2^EV before the tone map).
    pub exposure: f32,
    /// Tone map of PBR shading.
    pub tonemap: crate::shade::pbr::Tonemap,
}

impl Default for Scene {
    fn default() -> Self {
        Self {
            meshes: Vec::new(),
            materials: Vec::new(),
            textures: Vec::new(),
            draws: Vec::new(),
            camera: Camera::framing(Vec3::ZERO, 1.0, Vec3::Z, 4.0 / 3.0),
            file_cameras: Vec::new(),
            light: Light::Headlight,
            ambient: 0.1,
            clear_color: Vec4::new(0.0, 0.0, 0.0, 1.0),
            resolution: (800, 600),
            shading: Shading::Lambert,
            lights: Vec::new(),
            environment: None,
            exposure: 0.0,
            tonemap: crate::shade::pbr::Tonemap::PbrNeutral,
        }
    }
}

impl Scene {
    /// Total triangles drawn per frame (a mesh drawn twice counts twice).
    pub fn triangle_count(&self) -> usize {
        self.draws
            .iter()
            .map(|d| self.meshes.get(d.mesh).map_or(0, Mesh::triangle_count))
            .sum()
    }

    /// The order in which draws are issued for a camera with world → eye matrix `view`: every
    /// draw whose material is not `BLEND` first, in scene order, then the `BLEND` draws back to
    /// front by the eye-space depth of their world bounding-box centre (ties, and draws without
    /// a finite box, keep scene order). The reference-scene rule; both backends use it per frame.
    pub fn draw_order(&self, view: &Mat4) -> Vec<usize> {
        let mut order: Vec<usize> = (0..self.draws.len())
            .filter(|&i| !self.is_blended(i))
            .collect();
        let mut blended: Vec<(f32, usize)> = (0..self.draws.len())
            .filter(|&i| self.is_blended(i))
            .map(|i| {
                let draw = &self.draws[i];
                let depth = self
                    .meshes
                    .get(draw.mesh)
                    .and_then(Mesh::bounds)
                    .map(|(lo, hi)| {
                        let centre = draw.model.transform_point3((lo + hi) * 0.5);
                        // Eye space looks down −z: the farthest has the most negative z.
                        view.transform_point3(centre).z
                    })
                    .filter(|z| z.is_finite())
                    .unwrap_or(f32::NEG_INFINITY);
                (depth, i)
            })
            .collect();
        // Stable: equal depths keep scene order. Farthest (most negative eye z) first.
        blended.sort_by(|a, b| a.0.total_cmp(&b.0));
        order.extend(blended.into_iter().map(|(_, i)| i));
        order
    }

    /// Whether draw `i` blends ([`AlphaMode::Blend`]; `false` for a draw or mesh that does not
    /// exist): such draws come last, back to front, in [`Scene::draw_order`].
    pub fn is_blended(&self, i: usize) -> bool {
        self.draws
            .get(i)
            .and_then(|draw| self.meshes.get(draw.mesh))
            .and_then(|m| self.materials.get(m.material))
            .is_some_and(|m| m.alpha_mode == AlphaMode::Blend)
    }

    /// Whether colour frames of the scene draw a backdrop first: PBR shading with a
    /// transmissive material ([`Material::has_transmission`]).
    pub fn has_transmission(&self) -> bool {
        self.shading == Shading::Pbr && self.materials.iter().any(Material::has_transmission)
    }

    /// Unlit copies of the materials, for lines and points without normals: glTF 2.0 §3.7.2.1
    /// says they are drawn without lighting. Index `i` is material `i` with `unlit` set.
    pub fn unlit_materials(&self) -> Vec<Material> {
        self.materials
            .iter()
            .map(|m| Material {
                unlit: true,
                ..m.clone()
            })
            .collect()
    }

    /// The material mesh `mesh` is drawn with: its own, or its unlit copy from `unlit`
    /// ([`Scene::unlit_materials`]) for lines and points without normals.
    pub fn draw_material<'s>(&'s self, mesh: usize, unlit: &'s [Material]) -> &'s Material {
        let mesh = &self.meshes[mesh];
        if mesh.topology != Topology::Triangles && mesh.normals.is_none() {
            &unlit[mesh.material]
        } else {
            &self.materials[mesh.material]
        }
    }

    /// World-space bounding sphere `(center, radius)` of everything drawn (from the boxes).
    pub fn bounding_sphere(&self) -> Option<(Vec3, f32)> {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for draw in &self.draws {
            let Some((a, b)) = self.meshes.get(draw.mesh).and_then(Mesh::bounds) else {
                continue;
            };
            for i in 0..8 {
                let corner = Vec3::new(
                    if i & 1 == 0 { a.x } else { b.x },
                    if i & 2 == 0 { a.y } else { b.y },
                    if i & 4 == 0 { a.z } else { b.z },
                );
                let p = draw.model.transform_point3(corner);
                if p.is_finite() {
                    lo = lo.min(p);
                    hi = hi.max(p);
                }
            }
        }
        if lo.x > hi.x {
            return None;
        }
        let center = (lo + hi) * 0.5;
        Some((center, (hi - lo).length() * 0.5))
    }

    /// Checks every cross reference (draw → mesh → material → texture) and every index.
    pub fn validate(&self) -> Result<(), RenderError> {
        for (i, draw) in self.draws.iter().enumerate() {
            if draw.mesh >= self.meshes.len() {
                return Err(RenderError::InvalidScene(format!(
                    "draw {i} refers to mesh {} of {}",
                    draw.mesh,
                    self.meshes.len()
                )));
            }
        }
        for (i, mesh) in self.meshes.iter().enumerate() {
            let n = mesh.positions.len();
            if mesh.material >= self.materials.len() {
                return Err(RenderError::InvalidScene(format!(
                    "mesh {i} refers to material {} of {}",
                    mesh.material,
                    self.materials.len()
                )));
            }
            let attribute_ok = |len: Option<usize>| len.is_none_or(|l| l == n);
            if !attribute_ok(mesh.normals.as_ref().map(Vec::len))
                || !attribute_ok(mesh.texcoords.as_ref().map(Vec::len))
                || !attribute_ok(mesh.texcoords1.as_ref().map(Vec::len))
                || !attribute_ok(mesh.tangents.as_ref().map(Vec::len))
                || !attribute_ok(mesh.colors.as_ref().map(Vec::len))
            {
                return Err(RenderError::InvalidScene(format!(
                    "mesh {i}: attribute count differs from its {n} positions"
                )));
            }
            match mesh.topology {
                Topology::Triangles if mesh.indices.len() % 3 != 0 => {
                    return Err(RenderError::IncompleteTriangle(mesh.indices.len()))
                }
                Topology::Lines if mesh.indices.len() % 2 != 0 => {
                    return Err(RenderError::IncompleteLine(mesh.indices.len()))
                }
                _ => {}
            }
            if let Some((position, &index)) = mesh
                .indices
                .iter()
                .enumerate()
                .find(|(_, &ix)| ix as usize >= n)
            {
                return Err(RenderError::IndexOutOfRange {
                    index,
                    position,
                    vertex_count: n,
                });
            }
        }
        for (i, material) in self.materials.iter().enumerate() {
            let textures = [material.base_color_texture, material.emissive_texture];
            for binding in textures
                .into_iter()
                .chain(material.pbr_textures())
                .flatten()
            {
                if binding.texture >= self.textures.len() {
                    return Err(RenderError::InvalidScene(format!(
                        "material {i} refers to texture {} of {}",
                        binding.texture,
                        self.textures.len()
                    )));
                }
                if binding.texcoord > 1 {
                    return Err(RenderError::InvalidScene(format!(
                        "material {i} reads texture coordinate set {} (meshes have 2)",
                        binding.texcoord
                    )));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Opaque and mask draws keep scene order; blended ones follow, farthest first, ties in
    /// scene order.
    #[test]
    fn draw_order_puts_blend_last_back_to_front() {
        let mesh = |material| Mesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            indices: vec![0, 1, 2],
            material,
            ..Mesh::default()
        };
        let draw = |mesh, z: f32| Draw {
            mesh,
            model: Mat4::from_translation(Vec3::new(0.0, 0.0, z)),
            node_name: String::new(),
            node_index: 0,
        };
        let scene = Scene {
            meshes: vec![mesh(0), mesh(1), mesh(2)],
            materials: vec![
                Material::default(),
                Material {
                    alpha_mode: AlphaMode::Blend,
                    ..Material::default()
                },
                Material {
                    alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
                    ..Material::default()
                },
            ],
            draws: vec![
                draw(1, -1.0), // blend, near
                draw(0, -3.0), // opaque
                draw(1, -5.0), // blend, far
                draw(2, -2.0), // mask
                draw(1, -1.0), // blend, near (tie with draw 0)
            ],
            ..Scene::default()
        };
        // Camera at the origin looking down −z.
        assert_eq!(scene.draw_order(&Mat4::IDENTITY), vec![1, 3, 2, 0, 4]);
        // Seen from the other side (camera at z = −10 looking towards +z) the far one flips.
        let behind = Mat4::from_rotation_y(std::f32::consts::PI)
            * Mat4::from_translation(Vec3::new(0.0, 0.0, 10.0));
        assert_eq!(scene.draw_order(&behind), vec![1, 3, 0, 4, 2]);
    }
}
