//! The built-in PBR material: glTF 2.0's metallic-roughness model
//! ([`kantele_rules::shade::pbr`]) as a [`Shader`] of the CPU pipeline, for scenes drawn with
//! [`Shading::Pbr`](kantele_rules::scene::Shading::Pbr).
//!
//! Per fragment: the base colour, alpha and emission as the Lambert material reads them; metallic
//! and roughness (× the blue and green channels of their texture), occlusion, and the shading
//! normal — the interpolated world normal, bent by the normal texture in the tangent frame of
//! the mesh's tangents, or, for a mesh without tangents, in the frame derived from the
//! screen-space derivatives of the world position and the texture coordinate (as the glTF
//! sample viewer does for meshes without tangents); then
//! the dielectric reflectance and specular weight of `KHR_materials_ior` and
//! `KHR_materials_specular`, the coat of `KHR_materials_clearcoat` (its factor, roughness and
//! normal texture, bent in the same frame), the transmission and thickness of
//! `KHR_materials_transmission` and `KHR_materials_volume` (where the frame has a backdrop:
//! [`PbrLighting::transmission`]), the sheen colour and roughness of `KHR_materials_sheen`;
//! then [`pbr::shade`] with the emission, exposure and the tone map.
//!
//! Each texture reads one of the mesh's two texture coordinate sets
//! ([`TextureBinding::texcoord`](kantele_rules::scene::TextureBinding::texcoord)).
//!
//! One generic routine shades eight fragments at once ([`FragmentLanes`]) and one fragment
//! ([`Fragment`], every lane holding it), so both follow the same operations.

use glam::{Mat3, Mat4, Vec2, Vec4};

use crate::material::material_render_state;
use crate::pipeline::{
    Fragment, FragmentLanes, LaneProgram, LaneProgramJob, RenderState, ShadedLanes, Shader,
};
use kantele_lanes::{F32x8, Lanes, Mask8, Scalar};
use kantele_rules::backend::Pass;
use kantele_rules::camera::normal_matrix;
use kantele_rules::scene::{AlphaMode, Material};
use kantele_rules::shade::pbr::{self, normalize3, ClearcoatLayer, PbrLighting, Surface};
use kantele_rules::shade::sheen::SheenLayer;
use kantele_rules::shade::texture::{Sampler, Texture};
use kantele_rules::shade::transmission::{TransmissionLayer, Volume};
use kantele_rules::vertex::PbrVertex;

/// Where the PBR shader's first varyings sit; the others follow as the draw needs them
/// ([`VaryingLayout`]).
mod at {
    /// World normal, three.
    pub const NORMAL: usize = 0;
    /// World position, three.
    pub const POSITION: usize = 3;
    /// The first varying after those every draw has.
    pub const OPTIONAL: usize = 6;
}

/// Where a draw's optional varyings sit: only what it reads is interpolated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct VaryingLayout {
    /// The two texture coordinate sets (two each), where a texture reads them.
    texcoords: [Option<usize>; 2],
    /// The world tangent and bitangent sign (four), where the mesh has tangents and a normal
    /// texture is read.
    tangent: Option<usize>,
    /// The vertex colour (four), where the mesh has colours.
    color: Option<usize>,
    /// The texture coordinates (two) whose derivatives orient the tangent frame of a draw that
    /// bends normals without mesh tangents (0 where none: never read).
    frame_texcoord: usize,
    /// Varyings in all.
    count: usize,
}

impl VaryingLayout {
    /// The layout of the given varyings; `frame_set` is the texture coordinate set of the
    /// derivative tangent frame, if the draw has one.
    fn new(texcoords: [bool; 2], tangent: bool, color: bool, frame_set: Option<u32>) -> Self {
        let mut count = at::OPTIONAL;
        let mut take = |wanted: bool, size: usize| {
            wanted.then(|| {
                count += size;
                count - size
            })
        };
        let texcoords = [take(texcoords[0], 2), take(texcoords[1], 2)];
        let tangent = take(tangent, 4);
        let color = take(color, 4);
        let frame_texcoord = frame_set
            .and_then(|set| texcoords[(set as usize).min(1)])
            .unwrap_or(0);
        Self {
            texcoords,
            tangent,
            color,
            frame_texcoord,
            count,
        }
    }
}

/// A texture with the sampler it is read through and the texture coordinate set it reads.
#[derive(Clone, Copy, Debug)]
pub struct Bound<'a> {
    /// The texture.
    pub texture: &'a Texture,
    /// How it is sampled.
    pub sampler: Sampler,
    /// The mesh's texture coordinate set it reads (0 or 1).
    pub texcoord: u32,
}

/// A material texture, where the material has it.
pub type BoundTexture<'a> = Option<Bound<'a>>;

/// The textures a PBR material reads.
#[derive(Clone, Copy, Default)]
pub struct PbrTextures<'a> {
    /// sRGB base colour.
    pub base_color: BoundTexture<'a>,
    /// sRGB emission.
    pub emissive: BoundTexture<'a>,
    /// Linear: blue = metallic, green = roughness.
    pub metallic_roughness: BoundTexture<'a>,
    /// Linear tangent-space normal.
    pub normal: BoundTexture<'a>,
    /// Linear: red = occlusion.
    pub occlusion: BoundTexture<'a>,
    /// Linear: alpha = specular weight (`KHR_materials_specular`).
    pub specular: BoundTexture<'a>,
    /// sRGB: the dielectric reflectance's colour (`KHR_materials_specular`).
    pub specular_color: BoundTexture<'a>,
    /// Linear: red = clear coat weight (`KHR_materials_clearcoat`).
    pub clearcoat: BoundTexture<'a>,
    /// Linear: green = clear coat roughness.
    pub clearcoat_roughness: BoundTexture<'a>,
    /// Linear tangent-space normal of the clear coat.
    pub clearcoat_normal: BoundTexture<'a>,
    /// Linear: red = transmission (`KHR_materials_transmission`).
    pub transmission: BoundTexture<'a>,
    /// Linear: green = thickness (`KHR_materials_volume`).
    pub thickness: BoundTexture<'a>,
    /// sRGB: the sheen's colour (`KHR_materials_sheen`).
    pub sheen_color: BoundTexture<'a>,
    /// Linear: alpha = sheen roughness.
    pub sheen_roughness: BoundTexture<'a>,
}

impl<'a> PbrTextures<'a> {
    /// Every texture with its slot of [`Texels`].
    fn slots(&self) -> [(usize, BoundTexture<'a>); SLOTS] {
        [
            (BASE_COLOR, self.base_color),
            (EMISSIVE, self.emissive),
            (METALLIC_ROUGHNESS, self.metallic_roughness),
            (NORMAL, self.normal),
            (OCCLUSION, self.occlusion),
            (SPECULAR, self.specular),
            (SPECULAR_COLOR, self.specular_color),
            (CLEARCOAT, self.clearcoat),
            (CLEARCOAT_ROUGHNESS, self.clearcoat_roughness),
            (CLEARCOAT_NORMAL, self.clearcoat_normal),
            (TRANSMISSION, self.transmission),
            (THICKNESS, self.thickness),
            (SHEEN_COLOR, self.sheen_color),
            (SHEEN_ROUGHNESS, self.sheen_roughness),
        ]
    }

    /// The textures a draw of `pass` reads, with the slot of [`Texels`] each fills: all of
    /// them for colour (the clear coat's only with a coat, the sheen's only with a sheen,
    /// transmission and thickness only when the draw transmits); the base colour (for its
    /// alpha, where the material tests it) and the normal texture for normals; the base colour
    /// for ids, where alpha is tested.
    fn reads(&self, pass: Pass, alpha_tested: bool, layers: Layers) -> TextureReads<'a> {
        let mut reads = TextureReads {
            reads: [None; SLOTS],
            count: 0,
        };
        for (slot, bound) in self.slots() {
            let wanted = match slot {
                BASE_COLOR => pass == Pass::Color || alpha_tested,
                NORMAL => pass != Pass::Ids,
                CLEARCOAT | CLEARCOAT_ROUGHNESS | CLEARCOAT_NORMAL => {
                    pass == Pass::Color && layers.clearcoat
                }
                TRANSMISSION | THICKNESS => pass == Pass::Color && layers.transmits,
                SHEEN_COLOR | SHEEN_ROUGHNESS => pass == Pass::Color && layers.sheen,
                _ => pass == Pass::Color,
            };
            if let (Some(bound), true) = (bound, wanted) {
                reads.reads[reads.count] = Some((slot, bound));
                reads.count += 1;
            }
        }
        reads
    }
}

/// Slots of [`Texels`].
const BASE_COLOR: usize = 0;
const EMISSIVE: usize = 1;
const METALLIC_ROUGHNESS: usize = 2;
const NORMAL: usize = 3;
const OCCLUSION: usize = 4;
const SPECULAR: usize = 5;
const SPECULAR_COLOR: usize = 6;
const CLEARCOAT: usize = 7;
const CLEARCOAT_ROUGHNESS: usize = 8;
const CLEARCOAT_NORMAL: usize = 9;
const TRANSMISSION: usize = 10;
const THICKNESS: usize = 11;
const SHEEN_COLOR: usize = 12;
const SHEEN_ROUGHNESS: usize = 13;
const SLOTS: usize = 14;

/// The layers a draw shades besides its base.
#[derive(Clone, Copy)]
struct Layers {
    clearcoat: bool,
    transmits: bool,
    sheen: bool,
}

/// The texels of a fragment's textures, by slot (1 where a texture is not read).
type Texels<L> = [[<L as Lanes>::F32; 4]; SLOTS];

/// The textures one draw reads, in slot order: the first `count` entries.
#[derive(Clone, Copy)]
struct TextureReads<'a> {
    reads: [Option<(usize, Bound<'a>)>; SLOTS],
    count: usize,
}

impl TextureReads<'_> {
    /// Whether any texture read reads texture coordinate set `set`.
    fn reads_set(&self, set: u32) -> bool {
        self.reads[..self.count]
            .iter()
            .flatten()
            .any(|(_, bound)| bound.texcoord == set)
    }
}

/// The shader of one draw of a PBR scene.
pub struct PbrShader<'a> {
    model: Mat4,
    model_view_projection: Mat4,
    normal_matrix: Mat3,
    lighting: &'a PbrLighting,
    material: &'a Material,
    textures: PbrTextures<'a>,
    /// What the fragment program samples ([`PbrTextures::reads`]).
    reads: TextureReads<'a>,
    pass: Pass,
    /// `(instance id, draw id)` for the id pass.
    ids: (f32, f32),
    /// `model`'s upper 3 × 3 turns the other way (negative determinant): the tangents' `w`
    /// is negated, so the bitangent keeps pointing along increasing v.
    mirrored: bool,
    /// Where the varyings sit.
    layout: VaryingLayout,
    /// The volume constants of a transmissive draw in a frame with a backdrop.
    volume: Option<Volume>,
}

impl<'a> PbrShader<'a> {
    /// The shader for a draw with object → world `model`, seen through `view_projection`, lit
    /// by the frame's `lighting`. `ids` are the instance id and draw id of the id pass.
    pub fn new(
        model: Mat4,
        view_projection: Mat4,
        lighting: &'a PbrLighting,
        material: &'a Material,
        textures: PbrTextures<'a>,
        pass: Pass,
        ids: (u32, u32),
    ) -> Self {
        let alpha_tested = !matches!(material.alpha_mode, AlphaMode::Opaque);
        let volume = match &lighting.transmission {
            Some(view) if material.has_transmission() && pass == Pass::Color => Some(Volume::new(
                material.ior,
                material.attenuation_color,
                material.attenuation_distance,
                &model,
                &view.backdrop,
            )),
            _ => None,
        };
        let layers = Layers {
            clearcoat: material.has_clearcoat(),
            transmits: volume.is_some(),
            sheen: material.has_sheen(),
        };
        let reads = textures.reads(pass, alpha_tested, layers);
        let mut shader = Self {
            model,
            model_view_projection: view_projection * model,
            normal_matrix: normal_matrix(&model),
            lighting,
            material,
            textures,
            reads,
            pass,
            ids: (ids.0 as f32, ids.1 as f32),
            mirrored: Mat3::from_mat4(model).determinant() < 0.0,
            layout: VaryingLayout::new([false; 2], false, false, None),
            volume,
        };
        shader.layout = shader.layout_for(true, false);
        shader
    }

    /// What the mesh drawn has: vertex colours (glTF `COLOR_0`; the default is yes) and
    /// tangents (the default is no: the derivative tangent frame).
    pub fn with_mesh_attributes(mut self, vertex_colors: bool, tangents: bool) -> Self {
        self.layout = self.layout_for(vertex_colors, tangents);
        self
    }

    /// The varyings the draw needs with a mesh that has colours and tangents as given: the
    /// texture coordinate sets its textures read (the derivative frame reads the normal
    /// texture's), the tangents where a normal texture is bent, the colours.
    fn layout_for(&self, vertex_colors: bool, tangents: bool) -> VaryingLayout {
        let frame_set = self.frame_texture().map(|b| b.texcoord);
        let bends = frame_set.is_some();
        let derivative_set = frame_set.filter(|_| !tangents);
        let set = |s: u32| self.reads.reads_set(s) || derivative_set == Some(s);
        VaryingLayout::new(
            [set(0), set(1)],
            bends && tangents,
            vertex_colors,
            derivative_set,
        )
    }

    /// The texture whose coordinates orient the tangent frame, when the draw bends a normal:
    /// the normal texture, else the coat's.
    fn frame_texture(&self) -> Option<Bound<'_>> {
        let coat = self.material.has_clearcoat() && self.pass == Pass::Color;
        match self.pass {
            Pass::Ids => None,
            _ => self
                .textures
                .normal
                .or(self.textures.clearcoat_normal.filter(|_| coat)),
        }
    }

    /// The state the material asks for ([`material_render_state`]).
    pub fn render_state(&self) -> RenderState {
        material_render_state(self.material, self.pass)
    }

    fn varying_count(&self) -> usize {
        self.layout.count
    }

    /// The varying of texture coordinate set `set` (0 where the draw has none: never read).
    fn texcoord_varying(&self, set: u32) -> usize {
        self.layout.texcoords[(set as usize).min(1)].unwrap_or(0)
    }
}

/// What the shading routine reads of the fragments it shades: varyings, their derivatives and
/// texture samples, for eight fragments ([`FragmentLanes`]) or one ([`Fragment`] in every lane).
trait Fragments<L: Lanes> {
    fn lanes(&self) -> L;
    fn varying(&self, index: usize) -> L::F32;
    fn derivatives(&self, index: usize) -> (L::F32, L::F32);
    /// `texture` sampled at the texture coordinate in varyings `u` and `u + 1`.
    fn sample(&self, texture: &Texture, sampler: &Sampler, u: usize) -> [L::F32; 4];
    fn front_facing(&self) -> bool;
    fn primitive_id(&self) -> u32;
}

impl<L: Lanes> Fragments<L> for FragmentLanes<'_, L> {
    #[inline(always)]
    fn lanes(&self) -> L {
        self.lanes
    }
    #[inline(always)]
    fn varying(&self, index: usize) -> L::F32 {
        FragmentLanes::varying(self, index)
    }
    #[inline(always)]
    fn derivatives(&self, index: usize) -> (L::F32, L::F32) {
        FragmentLanes::derivatives(self, index)
    }
    #[inline(always)]
    fn sample(&self, texture: &Texture, sampler: &Sampler, u: usize) -> [L::F32; 4] {
        let (du_dx, du_dy) = FragmentLanes::derivatives(self, u);
        let (dv_dx, dv_dy) = FragmentLanes::derivatives(self, u + 1);
        texture.sample_grad_lanes::<L>(
            sampler,
            [
                FragmentLanes::varying(self, u),
                FragmentLanes::varying(self, u + 1),
            ],
            [du_dx, dv_dx],
            [du_dy, dv_dy],
            self.active,
        )
    }
    #[inline(always)]
    fn front_facing(&self) -> bool {
        self.front_facing
    }
    #[inline(always)]
    fn primitive_id(&self) -> u32 {
        self.primitive_id
    }
}

impl Fragments<Scalar> for Fragment<'_> {
    fn lanes(&self) -> Scalar {
        Scalar
    }
    fn varying(&self, index: usize) -> <Scalar as Lanes>::F32 {
        Scalar.splat_f32(Fragment::varying(self, index))
    }
    fn derivatives(&self, index: usize) -> (<Scalar as Lanes>::F32, <Scalar as Lanes>::F32) {
        let (dx, dy) = Fragment::derivatives(self, index);
        (Scalar.splat_f32(dx), Scalar.splat_f32(dy))
    }
    fn sample(
        &self,
        texture: &Texture,
        sampler: &Sampler,
        u: usize,
    ) -> [<Scalar as Lanes>::F32; 4] {
        let (du_dx, du_dy) = Fragment::derivatives(self, u);
        let (dv_dx, dv_dy) = Fragment::derivatives(self, u + 1);
        let t = texture.sample_grad(
            sampler,
            Vec2::new(Fragment::varying(self, u), Fragment::varying(self, u + 1)),
            Vec2::new(du_dx, dv_dx),
            Vec2::new(du_dy, dv_dy),
        );
        t.to_array().map(|c| Scalar.splat_f32(c))
    }
    fn front_facing(&self) -> bool {
        self.front_facing
    }
    fn primitive_id(&self) -> u32 {
        self.primitive_id
    }
}

impl PbrShader<'_> {
    /// The texels of every texture the draw reads ([`PbrTextures::reads`]), from one call site
    /// of the sampler in a loop: the sampler is the largest part of the program, and each of
    /// its call sites is compiled into every kernel.
    #[inline(always)]
    fn sample_textures<L: Lanes, F: Fragments<L>>(&self, f: &F) -> Texels<L> {
        let one = f.lanes().splat_f32(1.0);
        let mut texels = [[one; 4]; SLOTS];
        let reads = &self.reads;
        for (slot, bound) in reads.reads[..reads.count].iter().flatten() {
            let u = self.texcoord_varying(bound.texcoord);
            texels[*slot] = f.sample(bound.texture, &bound.sampler, u);
        }
        texels
    }

    /// The shading routine (see the module docs): colour and the lanes kept.
    #[inline(always)]
    fn shade<L: Lanes, F: Fragments<L>>(&self, f: &F) -> ([L::F32; 4], L::Mask) {
        let lanes = f.lanes();
        let all = lanes.mask_all(true);
        let one = lanes.splat_f32(1.0);
        let m = self.material;
        let needs_alpha = !matches!(m.alpha_mode, AlphaMode::Opaque);
        if self.pass == Pass::Ids && !needs_alpha {
            return (self.ids_lanes(lanes, f.primitive_id()), all);
        }
        let texels = self.sample_textures(f);
        // --- base colour and alpha ---
        // No `[T; N]::map` or other closure-taking helper on lanes here: LLVM may keep its body
        // out of line, compiled without the kernel's instruction set (see `kantele_lanes`).
        let factor = m.base_color_factor;
        let mut base = [
            lanes.splat_f32(factor.x),
            lanes.splat_f32(factor.y),
            lanes.splat_f32(factor.z),
            lanes.splat_f32(factor.w),
        ];
        if let Some(color) = self.layout.color {
            for (c, b) in base.iter_mut().enumerate() {
                *b = *b * f.varying(color + c);
            }
        }
        if self.textures.base_color.is_some() {
            for c in 0..4 {
                base[c] = base[c] * texels[BASE_COLOR][c];
            }
        }
        let (alpha, keep) = match m.alpha_mode {
            AlphaMode::Opaque => (one, all),
            AlphaMode::Mask { cutoff } => (one, base[3].simd_lt(lanes.splat_f32(cutoff)).not()),
            AlphaMode::Blend => (base[3], all),
        };
        if self.pass == Pass::Ids {
            return (self.ids_lanes(lanes, f.primitive_id()), keep);
        }
        let [normal, coat_normal] = self.normals(f, &texels);
        if self.pass == Pass::Normals {
            return ([normal[0], normal[1], normal[2], one], keep);
        }
        // --- emission ---
        let e = m.emissive;
        let mut emissive = [
            lanes.splat_f32(e.x),
            lanes.splat_f32(e.y),
            lanes.splat_f32(e.z),
        ];
        if self.textures.emissive.is_some() {
            for c in 0..3 {
                emissive[c] = emissive[c] * texels[EMISSIVE][c];
            }
        }
        let rgb = if m.unlit {
            [
                base[0] + emissive[0],
                base[1] + emissive[1],
                base[2] + emissive[2],
            ]
        } else {
            let mut metallic = lanes.splat_f32(m.metallic);
            let mut roughness = lanes.splat_f32(m.roughness);
            if self.textures.metallic_roughness.is_some() {
                let texel = texels[METALLIC_ROUGHNESS];
                metallic = metallic * texel[2];
                roughness = roughness * texel[1];
            }
            let mut occlusion = one;
            if self.textures.occlusion.is_some() {
                let texel = texels[OCCLUSION];
                occlusion = one + lanes.splat_f32(m.occlusion_strength) * (texel[0] - one);
            }
            // KHR_materials_ior and KHR_materials_specular.
            let f0 = m.dielectric_f0;
            let mut dielectric_f0 = [
                lanes.splat_f32(f0.x),
                lanes.splat_f32(f0.y),
                lanes.splat_f32(f0.z),
            ];
            if self.textures.specular_color.is_some() {
                for c in 0..3 {
                    dielectric_f0[c] = dielectric_f0[c] * texels[SPECULAR_COLOR][c];
                }
            }
            let mut specular_weight = lanes.splat_f32(m.specular_weight);
            if self.textures.specular.is_some() {
                specular_weight = specular_weight * texels[SPECULAR][3];
            }
            // KHR_materials_clearcoat.
            let clearcoat = if m.has_clearcoat() {
                let mut factor = lanes.splat_f32(m.clearcoat);
                if self.textures.clearcoat.is_some() {
                    factor = factor * texels[CLEARCOAT][0];
                }
                let mut roughness = lanes.splat_f32(m.clearcoat_roughness);
                if self.textures.clearcoat_roughness.is_some() {
                    roughness = roughness * texels[CLEARCOAT_ROUGHNESS][1];
                }
                Some(ClearcoatLayer {
                    factor: clamp01(lanes, factor),
                    roughness: clamp01(lanes, roughness),
                    normal: coat_normal,
                })
            } else {
                None
            };
            // KHR_materials_transmission and KHR_materials_volume.
            let transmission = if let Some(volume) = self.volume {
                let mut factor = lanes.splat_f32(m.transmission);
                if self.textures.transmission.is_some() {
                    factor = factor * texels[TRANSMISSION][0];
                }
                let mut thickness = lanes.splat_f32(m.thickness);
                if self.textures.thickness.is_some() {
                    thickness = thickness * texels[THICKNESS][1];
                }
                Some(TransmissionLayer {
                    factor: clamp01(lanes, factor),
                    thickness: thickness.max(lanes.splat_f32(0.0)),
                    volume,
                })
            } else {
                None
            };
            // KHR_materials_sheen.
            let sheen = if m.has_sheen() {
                let c = m.sheen_color;
                let mut color = [
                    lanes.splat_f32(c.x),
                    lanes.splat_f32(c.y),
                    lanes.splat_f32(c.z),
                ];
                if self.textures.sheen_color.is_some() {
                    for (k, channel) in color.iter_mut().enumerate() {
                        *channel = *channel * texels[SHEEN_COLOR][k];
                    }
                }
                let mut roughness = lanes.splat_f32(m.sheen_roughness);
                if self.textures.sheen_roughness.is_some() {
                    roughness = roughness * texels[SHEEN_ROUGHNESS][3];
                }
                Some(SheenLayer {
                    color: [
                        clamp01(lanes, color[0]),
                        clamp01(lanes, color[1]),
                        clamp01(lanes, color[2]),
                    ],
                    roughness: clamp01(lanes, roughness),
                })
            } else {
                None
            };
            let surface = Surface {
                base: [base[0], base[1], base[2]],
                metallic: clamp01(lanes, metallic),
                roughness: clamp01(lanes, roughness),
                occlusion,
                normal,
                position: [
                    f.varying(at::POSITION),
                    f.varying(at::POSITION + 1),
                    f.varying(at::POSITION + 2),
                ],
                dielectric_f0: [
                    dielectric_f0[0].min(one),
                    dielectric_f0[1].min(one),
                    dielectric_f0[2].min(one),
                ],
                specular_weight: clamp01(lanes, specular_weight),
                clearcoat,
                sheen,
                transmission,
            };
            pbr::shade(lanes, self.lighting, &surface, &emissive)
        };
        let [r, g, b] = pbr::tonemap(lanes, self.lighting.tonemap, self.lighting.exposure, rgb);
        ([r, g, b, alpha], keep)
    }

    /// The shading normals of the material and of its clear coat: the interpolated normal,
    /// bent by the normal texture and by the coat's normal texture (each where the material has
    /// one) in the tangent frame ([`PbrShader::tangent_frame`]), flipped on back faces of
    /// double-sided materials.
    #[inline(always)]
    fn normals<L: Lanes, F: Fragments<L>>(&self, f: &F, texels: &Texels<L>) -> [[L::F32; 3]; 2] {
        let lanes = f.lanes();
        let ng = normalize3(
            lanes,
            [
                f.varying(at::NORMAL),
                f.varying(at::NORMAL + 1),
                f.varying(at::NORMAL + 2),
            ],
        );
        let m = self.material;
        let bent = self.textures.normal.is_some();
        let coat_bent = self.textures.clearcoat_normal.is_some()
            && m.has_clearcoat()
            && self.pass == Pass::Color;
        let mut normals = [ng, ng];
        if bent || coat_bent {
            let frame = self.tangent_frame(f, ng);
            if bent {
                normals[0] = bend(lanes, &frame, ng, texels[NORMAL], m.normal_scale);
            }
            if coat_bent {
                let texel = texels[CLEARCOAT_NORMAL];
                normals[1] = bend(lanes, &frame, ng, texel, m.clearcoat_normal_scale);
            }
        }
        if m.double_sided && !f.front_facing() {
            let [n, c] = normals;
            [[-n[0], -n[1], -n[2]], [-c[0], -c[1], -c[2]]]
        } else {
            normals
        }
    }

    /// The tangent frame `[t, b]` around `ng`: of the mesh's tangents where it has them
    /// ([`PbrShader::vertex_tangent_frame`]), else from derivatives
    /// ([`PbrShader::derivative_tangent_frame`]).
    #[inline(always)]
    fn tangent_frame<L: Lanes, F: Fragments<L>>(&self, f: &F, ng: [L::F32; 3]) -> [[L::F32; 3]; 2] {
        match self.layout.tangent {
            Some(tangent) => vertex_tangent_frame(f, ng, tangent),
            None => self.derivative_tangent_frame(f, ng),
        }
    }

    /// The derivative tangent frame `[t, b]` around `ng`: `t_ = (∂v/∂y ∂p/∂x − ∂v/∂x ∂p/∂y) /
    /// det` with `det = ∂u/∂x ∂v/∂y − ∂u/∂y ∂v/∂x` (u, v: the coordinates of the
    /// [frame texture](PbrShader::frame_texture), [`VaryingLayout::frame_texcoord`]), `t = normalize(t_ − ng (ng·t_))` (0 where
    /// degenerate), `b = ±ng × t` (negative where the mapping is mirrored: `det < 0` on a front
    /// face, `det > 0` on a back face).
    #[inline(always)]
    fn derivative_tangent_frame<L: Lanes, F: Fragments<L>>(
        &self,
        f: &F,
        ng: [L::F32; 3],
    ) -> [[L::F32; 3]; 2] {
        let lanes = f.lanes();
        let u = self.layout.frame_texcoord;
        let (du_dx, du_dy) = f.derivatives(u);
        let (dv_dx, dv_dy) = f.derivatives(u + 1);
        let mut dp_dx = [lanes.splat_f32(0.0); 3];
        let mut dp_dy = dp_dx;
        for c in 0..3 {
            (dp_dx[c], dp_dy[c]) = f.derivatives(at::POSITION + c);
        }
        let det = du_dx * dv_dy - du_dy * dv_dx;
        let t_ = [
            (dv_dy * dp_dx[0] - dv_dx * dp_dy[0]) / det,
            (dv_dy * dp_dx[1] - dv_dx * dp_dy[1]) / det,
            (dv_dy * dp_dx[2] - dv_dx * dp_dy[2]) / det,
        ];
        // Mirrored texture coordinates (the mapping turns the other way on screen than on a
        // face seen from its front) flip the bitangent.
        let zero = lanes.splat_f32(0.0);
        let turned = det.simd_lt(zero);
        let mirrored = if f.front_facing() {
            turned
        } else {
            turned.not()
        };
        orthonormal_frame(lanes, ng, t_, mirrored)
    }

    #[inline(always)]
    fn ids_lanes<L: Lanes>(&self, lanes: L, primitive_id: u32) -> [L::F32; 4] {
        [
            lanes.splat_f32(self.ids.0),
            lanes.splat_f32(primitive_id as f32 + 1.0),
            lanes.splat_f32(self.ids.1),
            lanes.splat_f32(1.0),
        ]
    }
}

/// The tangent frame `[t, b]` of the mesh's interpolated tangent `t_` (world, varyings
/// `tangent..tangent + 3`) and bitangent sign `w` (varying `tangent + 3`) around `ng`:
/// `t = normalize(t_ − ng (ng·t_))` (0 where degenerate), `b = ng × t`, negated where `w < 0`.
#[inline(always)]
fn vertex_tangent_frame<L: Lanes, F: Fragments<L>>(
    f: &F,
    ng: [L::F32; 3],
    tangent: usize,
) -> [[L::F32; 3]; 2] {
    let lanes = f.lanes();
    let t_ = [
        f.varying(tangent),
        f.varying(tangent + 1),
        f.varying(tangent + 2),
    ];
    let flipped = f.varying(tangent + 3).simd_lt(lanes.splat_f32(0.0));
    orthonormal_frame(lanes, ng, t_, flipped)
}

/// `[t, b]` with `t = normalize(t_ − ng (ng·t_))` (0 where degenerate) and `b = ng × t`,
/// negated in the lanes of `flip`.
#[inline(always)]
fn orthonormal_frame<L: Lanes>(
    lanes: L,
    ng: [L::F32; 3],
    t_: [L::F32; 3],
    flip: L::Mask,
) -> [[L::F32; 3]; 2] {
    let along = ng[0] * t_[0] + ng[1] * t_[1] + ng[2] * t_[2];
    let t = normalize3(
        lanes,
        [
            t_[0] - ng[0] * along,
            t_[1] - ng[1] * along,
            t_[2] - ng[2] * along,
        ],
    );
    let b = [
        ng[1] * t[2] - ng[2] * t[1],
        ng[2] * t[0] - ng[0] * t[2],
        ng[0] * t[1] - ng[1] * t[0],
    ];
    let b = [
        flip.select_f32(-b[0], b[0]),
        flip.select_f32(-b[1], b[1]),
        flip.select_f32(-b[2], b[2]),
    ];
    [t, b]
}

/// `x` clamped to [0, 1] per lane (NaN gives 0).
#[inline(always)]
fn clamp01<L: Lanes>(lanes: L, x: L::F32) -> L::F32 {
    x.max(lanes.splat_f32(0.0)).min(lanes.splat_f32(1.0))
}

/// `ng` bent by a normal texture's `texel` in the tangent frame `[t, b]`
/// ([`PbrShader::tangent_frame`]): `n = normalize(t m.x + b m.y + ng m.z)` with `m = 2 texel −
/// 1`, `m.xy ×= scale`; `ng` where the frame or the result is degenerate.
#[inline(always)]
fn bend<L: Lanes>(
    lanes: L,
    [t, b]: &[[L::F32; 3]; 2],
    ng: [L::F32; 3],
    texel: [L::F32; 4],
    scale: f32,
) -> [L::F32; 3] {
    let one = lanes.splat_f32(1.0);
    let zero = lanes.splat_f32(0.0);
    let two = lanes.splat_f32(2.0);
    let scale = lanes.splat_f32(scale);
    let m = [
        (texel[0] * two - one) * scale,
        (texel[1] * two - one) * scale,
        texel[2] * two - one,
    ];
    let bent = normalize3(
        lanes,
        [
            t[0] * m[0] + b[0] * m[1] + ng[0] * m[2],
            t[1] * m[0] + b[1] * m[1] + ng[1] * m[2],
            t[2] * m[0] + b[2] * m[1] + ng[2] * m[2],
        ],
    );
    // normalize3 gives 0 for a degenerate frame (t) or result: keep ng there.
    let usable = (t[0]
        .simd_ne(zero)
        .or(t[1].simd_ne(zero))
        .or(t[2].simd_ne(zero)))
    .and(
        bent[0]
            .simd_ne(zero)
            .or(bent[1].simd_ne(zero))
            .or(bent[2].simd_ne(zero)),
    );
    [
        usable.select_f32(bent[0], ng[0]),
        usable.select_f32(bent[1], ng[1]),
        usable.select_f32(bent[2], ng[2]),
    ]
}

impl Shader for PbrShader<'_> {
    type Vertex = PbrVertex;

    fn varying_count(&self) -> usize {
        PbrShader::varying_count(self)
    }

    /// World normal and position; then what the layout holds: the texture coordinate sets,
    /// the world tangent (`model × xyz`, `w` negated under a mirroring `model`), the colour.
    #[inline]
    fn vertex(&self, vertex: &PbrVertex, varyings: &mut [f32]) -> Vec4 {
        let v = &vertex.standard;
        let n = self.normal_matrix * v.normal;
        varyings[at::NORMAL..at::NORMAL + 3].copy_from_slice(&n.to_array());
        let p = self.model.transform_point3(v.position);
        varyings[at::POSITION..at::POSITION + 3].copy_from_slice(&p.to_array());
        let layout = &self.layout;
        for (at, texcoord) in layout.texcoords.iter().zip([v.texcoord, vertex.texcoord1]) {
            if let Some(at) = *at {
                varyings[at..at + 2].copy_from_slice(&texcoord.to_array());
            }
        }
        if let Some(at) = layout.tangent {
            let t = self.model.transform_vector3(vertex.tangent.truncate());
            let w = if self.mirrored {
                -vertex.tangent.w
            } else {
                vertex.tangent.w
            };
            varyings[at..at + 4].copy_from_slice(&t.extend(w).to_array());
        }
        if let Some(at) = layout.color {
            varyings[at..at + 4].copy_from_slice(&v.color.to_array());
        }
        self.model_view_projection * v.position.extend(1.0)
    }

    fn fragment(&self, fragment: &Fragment<'_>) -> Option<Vec4> {
        let (color, keep) = self.shade::<Scalar, _>(fragment);
        keep.any().then(|| {
            Vec4::new(
                color[0].extract(0),
                color[1].extract(0),
                color[2].extract(0),
                color[3].extract(0),
            )
        })
    }

    #[inline(always)]
    fn fragment_lanes<L: Lanes>(&self, fragments: &FragmentLanes<'_, L>) -> ShadedLanes<L> {
        let (color, keep) = self.shade(fragments);
        ShadedLanes { color, keep }
    }

    /// Runs `job` with `fragment_lanes` as a lane program that has no kernels of its own for
    /// constant triangles (a PBR triangle reads its world position, never the same at three
    /// vertices).
    #[inline(always)]
    fn with_lane_program<J: LaneProgramJob>(&self, job: J) -> J::Output {
        job.run(&PbrProgram(self))
    }
}

/// The PBR shader's [`Shader::fragment_lanes`] as the draw's lane program, opting out of the
/// kernels for constant triangles ([`LaneProgram::CONSTANT_KERNELS`]): a PBR triangle reads
/// its world position, which is never the same at three vertices, and the program is the
/// largest the renderer compiles.
struct PbrProgram<'s, 'a>(&'s PbrShader<'a>);

impl LaneProgram for PbrProgram<'_, '_> {
    const CONSTANT_KERNELS: bool = false;

    /// Each lane is shaded from its own values: its varyings and their derivatives, its texture
    /// samples (whose results do not depend on which lanes share a call, see
    /// `sample_grad_lanes`) and its environment lookups (gathers per lane); the fragment's
    /// position on screen is never read. Most PBR models are finely tessellated (about four
    /// fragments a triangle in EnvironmentTest), where packing fills the lanes.
    const PACKED_ROWS: bool = true;

    #[inline(always)]
    fn fragment_lanes<L: Lanes>(&self, fragments: &FragmentLanes<'_, L>) -> ShadedLanes<L> {
        let (color, keep) = self.0.shade(fragments);
        ShadedLanes { color, keep }
    }
}

#[cfg(test)]
#[path = "pbr_material_tests.rs"]
mod tests;
