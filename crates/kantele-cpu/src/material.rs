//! Built-in materials: shaders implementing exactly the shading rules of the reference scenes,
//! so a loaded scene draws without user shaders.
//!
//! `base = baseColorFactor × COLOR_0 × texture(uv)`; unlit → `base + emissive`; otherwise Lambert
//! `base.rgb × (ambient + (1 − ambient) × max(0, N·L) × light) + emissive`, with `N` the interpolated
//! world normal renormalised per pixel and flipped on back faces of double-sided materials.
//! Alpha: OPAQUE → 1, MASK → discard below the cutoff, BLEND → blended by the draw's state.

use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};

pub use kantele_rules::vertex::StandardVertex;

use crate::pipeline::{
    Fragment, FragmentLanes, LaneProgram, LaneProgramJob, RenderState, ShadedLanes, Shader,
    ShaderLanes,
};
use crate::rop::BlendMode;
use kantele_lanes::{F32x8, Lanes, Mask8};
use kantele_rules::backend::Pass;
use kantele_rules::camera::normal_matrix;
use kantele_rules::scene::{AlphaMode, Material};
use kantele_rules::setup::CullMode;
use kantele_rules::shade::sample_lanes::TrilinearRepeat15;
use kantele_rules::shade::texture::{Sampler, Texture};

/// Which varyings a draw writes and interpolates: the world normal (varyings 0–2), the texture
/// coordinate (3–4) and the vertex colour (5–8), each only when the draw's fragment program
/// reads it. The places are fixed, so the fragment program's indices are constants; the count
/// ends after the last one read (places before it that are not read hold 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct VaryingLayout {
    /// Lambert shading or the normals pass.
    normal: bool,
    /// A base colour or emissive texture.
    texcoord: bool,
    /// A mesh with vertex colours.
    color: bool,
}

impl VaryingLayout {
    /// First of the normal's three varyings.
    const NORMAL: usize = 0;
    /// First of the texture coordinate's two.
    const TEXCOORD: usize = 3;
    /// First of the colour's four.
    const COLOR: usize = 5;

    /// Whether the normal is interpolated as a direction only, without the perspective
    /// division (`varying_direction`, then renormalised): where the draw reads no other
    /// varying (no texture coordinate, no vertex colour), so its rows divide once, for the
    /// normal's length, instead of twice. A draw that reads another varying divides for it
    /// anyway and takes the perspective-correct normal: three more multiplications there
    /// measured slower (see BENCHMARKS.md). The CUDA kernel's `material_normal` follows the
    /// same rule.
    fn normal_from_direction(self) -> bool {
        !self.texcoord && !self.color
    }

    /// Varyings written: up to the end of the last one read.
    fn count(self) -> usize {
        if self.color {
            Self::COLOR + 4
        } else if self.texcoord {
            Self::TEXCOORD + 2
        } else if self.normal {
            Self::NORMAL + 3
        } else {
            0
        }
    }
}

/// The fixed-function state a material asks for in `pass` (every built-in material): culling
/// unless double-sided, and for BLEND alpha blending without depth writes (no blending outside
/// the colour pass).
pub fn material_render_state(material: &Material, pass: Pass) -> RenderState {
    let blend = matches!(material.alpha_mode, AlphaMode::Blend);
    RenderState {
        cull: if material.double_sided {
            CullMode::None
        } else {
            CullMode::Back
        },
        depth_write: !blend,
        blend: if blend && pass == Pass::Color {
            BlendMode::Alpha
        } else {
            BlendMode::Replace
        },
        ..RenderState::default()
    }
}

/// Light and camera shared by every draw of a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lighting {
    /// Unit vector towards the light, world space.
    pub to_light: Vec3,
    /// Light colour × intensity.
    pub light_color: Vec3,
    /// Ambient term.
    pub ambient: f32,
}

/// The shader of one scene draw.
pub struct MaterialShader<'a> {
    model_view_projection: Mat4,
    normal_matrix: Mat3,
    lighting: Lighting,
    material: &'a Material,
    texture: Option<(&'a Texture, Sampler)>,
    pass: Pass,
    /// `(instance id, draw id)` for the id pass.
    ids: (f32, f32),
    /// Emissive texture (see [`MaterialShader::with_emissive_texture`]).
    emissive_texture: Option<(&'a Texture, Sampler)>,
    /// Which varyings the fragment program reads, decided once per draw (`color`: the mesh has
    /// vertex colours, see [`MaterialShader::with_vertex_colors`]).
    layout: VaryingLayout,
    /// The material's properties for the lane program of an untextured colour-pass draw,
    /// decided once per draw (`None` for every other draw).
    untextured_color: Option<UntexturedColor>,
}

/// What the lane program of an untextured colour-pass draw reads of its material, copied out
/// once per draw: the per-row program then branches on the alpha mode and on lit or unlit
/// only, instead of on every material property, with the same operations in the same order.
#[derive(Clone, Copy, Debug)]
struct UntexturedColor {
    unlit: bool,
    vertex_colors: bool,
    alpha_mode: AlphaMode,
    base_color_factor: [f32; 4],
    emissive: Vec3,
    double_sided: bool,
}

impl<'a> MaterialShader<'a> {
    /// The shader for a draw with object → world `model`, seen through `view_projection`.
    /// `ids` are the instance id and draw id written by the id pass (both ≥ 1).
    pub fn new(
        model: Mat4,
        view_projection: Mat4,
        lighting: Lighting,
        material: &'a Material,
        texture: Option<(&'a Texture, Sampler)>,
        pass: Pass,
        ids: (u32, u32),
    ) -> Self {
        Self {
            model_view_projection: view_projection * model,
            normal_matrix: normal_matrix(&model),
            lighting,
            material,
            texture,
            pass,
            ids: (ids.0 as f32, ids.1 as f32),
            emissive_texture: None,
            layout: VaryingLayout {
                normal: true,
                texcoord: true,
                color: true,
            },
            untextured_color: None,
        }
        .with_lane_program()
    }

    /// Decides which varyings the draw interpolates ([`VaryingLayout`]) and which lane program
    /// it runs (see [`UntexturedColor`]).
    fn with_lane_program(mut self) -> Self {
        let m = self.material;
        let lit = self.pass == Pass::Color && !m.unlit;
        self.layout = VaryingLayout {
            normal: lit || self.pass == Pass::Normals,
            texcoord: self.texture.is_some() || self.emissive_texture.is_some(),
            color: self.layout.color,
        };
        let untextured_color =
            self.pass == Pass::Color && self.texture.is_none() && self.emissive_texture.is_none();
        self.untextured_color = untextured_color.then_some(UntexturedColor {
            unlit: m.unlit,
            vertex_colors: self.layout.color,
            alpha_mode: m.alpha_mode,
            base_color_factor: m.base_color_factor.to_array(),
            emissive: m.emissive,
            double_sided: m.double_sided,
        });
        self
    }

    /// The same shader reading the material's emissive texture (emission: `material.emissive`
    /// × this texture at the base colour's texture coordinates, added after lighting).
    pub fn with_emissive_texture(mut self, texture: Option<(&'a Texture, Sampler)>) -> Self {
        self.emissive_texture = texture;
        self.with_lane_program()
    }

    /// Whether the mesh has vertex colours (glTF `COLOR_0`; the default is yes). Without them
    /// the colour is white, the base colour is `baseColorFactor` × the texture exactly, and no
    /// colour is interpolated.
    pub fn with_vertex_colors(mut self, present: bool) -> Self {
        self.layout.color = present;
        self.with_lane_program()
    }

    /// The fixed-function state the material asks for: culling unless double-sided, and for
    /// BLEND alpha blending without depth writes (no blending outside the colour pass).
    pub fn render_state(&self) -> RenderState {
        material_render_state(self.material, self.pass)
    }

    #[inline]
    fn base_color(&self, fragment: &Fragment<'_>) -> Vec4 {
        let v = fragment.varyings();
        let color = if self.layout.color {
            let c = VaryingLayout::COLOR;
            Vec4::new(v[c], v[c + 1], v[c + 2], v[c + 3])
        } else {
            Vec4::ONE
        };
        let mut base = self.material.base_color_factor * color;
        if let Some((texture, sampler)) = self.texture {
            base *= sample(fragment, self.layout, texture, &sampler);
        }
        base
    }

    #[inline]
    fn normal(&self, fragment: &Fragment<'_>) -> Vec3 {
        if !self.layout.normal {
            return Vec3::ZERO;
        }
        let at = VaryingLayout::NORMAL;
        let n = if self.layout.normal_from_direction() {
            // The direction alone: no perspective division (see `Fragment::varying_direction`).
            Vec3::new(
                fragment.varying_direction(at),
                fragment.varying_direction(at + 1),
                fragment.varying_direction(at + 2),
            )
        } else {
            let v = fragment.varyings();
            Vec3::new(v[at], v[at + 1], v[at + 2])
        }
        .normalize_or_zero();
        if self.material.double_sided && !fragment.front_facing {
            -n
        } else {
            n
        }
    }
}

impl Shader for MaterialShader<'_> {
    type Vertex = StandardVertex;

    fn varying_count(&self) -> usize {
        self.layout.count()
    }

    #[inline]
    fn vertex(&self, vertex: &StandardVertex, varyings: &mut [f32]) -> Vec4 {
        let layout = self.layout;
        let count = layout.count();
        varyings[..count].fill(0.0);
        if layout.normal {
            let at = VaryingLayout::NORMAL;
            let n = self.normal_matrix * vertex.normal;
            varyings[at..at + 3].copy_from_slice(&n.to_array());
        }
        if layout.texcoord {
            let at = VaryingLayout::TEXCOORD;
            varyings[at..at + 2].copy_from_slice(&vertex.texcoord.to_array());
        }
        if layout.color {
            let at = VaryingLayout::COLOR;
            varyings[at..at + 4].copy_from_slice(&vertex.color.to_array());
        }
        self.model_view_projection * vertex.position.extend(1.0)
    }

    #[inline]
    fn fragment(&self, fragment: &Fragment<'_>) -> Option<Vec4> {
        let needs_alpha = !matches!(self.material.alpha_mode, AlphaMode::Opaque);
        if self.pass != Pass::Color && !needs_alpha {
            return Some(self.auxiliary(fragment));
        }
        let base = self.base_color(fragment);
        let alpha = match self.material.alpha_mode {
            AlphaMode::Opaque => 1.0,
            AlphaMode::Mask { cutoff } => {
                if base.w < cutoff {
                    return None;
                }
                1.0
            }
            AlphaMode::Blend => base.w,
        };
        if self.pass != Pass::Color {
            return Some(self.auxiliary(fragment));
        }
        // --- emissive (loaders work): added after lighting, and to unlit colour ---
        let emissive = self.emissive(fragment);
        if self.material.unlit {
            return Some((base.truncate() + emissive).extend(alpha));
        }
        let l = self.lighting;
        let n_dot_l = self.normal(fragment).dot(l.to_light).max(0.0);
        let light = Vec3::splat(l.ambient) + (1.0 - l.ambient) * n_dot_l * l.light_color;
        Some((base.truncate() * light + emissive).extend(alpha))
    }

    #[inline(always)]
    fn fragment_lanes<L: Lanes>(&self, fragments: &FragmentLanes<'_, L>) -> ShadedLanes<L> {
        self.shade_lanes(fragments)
    }

    /// Opaque colour-pass draws without an emissive texture, untextured or with a base colour
    /// texture sampled with the glTF default (REPEAT, LINEAR / LINEAR_MIPMAP_LINEAR, a
    /// power-of-two sRGB texture), run a program compiled for their lighting and vertex colours
    /// (`OpaqueUntextured`, `Textured`); so do lit, alpha-masked or blended draws with such a
    /// texture and no vertex colours (foliage cards, particles, decals: `Textured` with its
    /// alpha); every other draw runs `fragment_lanes`.
    #[inline(always)]
    fn with_lane_program<J: LaneProgramJob>(&self, job: J) -> J::Output {
        if let Some(texture) = self.opaque_textured() {
            let (shader, vertex_colors) = (self, self.layout.color);
            return match (self.material.unlit, vertex_colors) {
                (true, true) => job.run(&Textured::<true, true, false> { shader, texture }),
                (true, false) => job.run(&Textured::<true, false, false> { shader, texture }),
                (false, true) => job.run(&Textured::<false, true, false> { shader, texture }),
                (false, false) => job.run(&Textured::<false, false, false> { shader, texture }),
            };
        }
        if let Some(texture) = self.alpha_textured() {
            return job.run(&Textured::<false, false, true> {
                shader: self,
                texture,
            });
        }
        let Some(program) = self.untextured_color else {
            return job.run(&ShaderLanes(self));
        };
        if !matches!(program.alpha_mode, AlphaMode::Opaque) {
            return job.run(&ShaderLanes(self));
        }
        let shader = self;
        match (program.unlit, program.vertex_colors) {
            (true, true) => job.run(&OpaqueUntextured::<true, true> { shader, program }),
            (true, false) => job.run(&OpaqueUntextured::<true, false> { shader, program }),
            (false, true) => job.run(&OpaqueUntextured::<false, true> { shader, program }),
            (false, false) => job.run(&OpaqueUntextured::<false, false> { shader, program }),
        }
    }
}

impl<'a> MaterialShader<'a> {
    /// The base colour texture of an opaque colour-pass draw without an emissive texture, when
    /// it is sampled in the [`TrilinearRepeat15`] configuration ([`Textured`] then shades
    /// the draw).
    fn opaque_textured(&self) -> Option<TrilinearRepeat15<'a>> {
        let plain = self.pass == Pass::Color
            && self.emissive_texture.is_none()
            && matches!(self.material.alpha_mode, AlphaMode::Opaque);
        let (texture, sampler) = self.texture.filter(|_| plain)?;
        texture.trilinear_repeat15(&sampler)
    }

    /// The base colour texture of a lit, alpha-masked or blended colour-pass draw without vertex
    /// colours or an emissive texture, when it is sampled in the [`TrilinearRepeat15`]
    /// configuration ([`Textured`] with its alpha then shades the draw).
    fn alpha_textured(&self) -> Option<TrilinearRepeat15<'a>> {
        let plain = self.pass == Pass::Color
            && self.emissive_texture.is_none()
            && !self.material.unlit
            && !self.layout.color
            && !matches!(self.material.alpha_mode, AlphaMode::Opaque);
        let (texture, sampler) = self.texture.filter(|_| plain)?;
        texture.trilinear_repeat15(&sampler)
    }
}

/// The lane program of a colour-pass draw whose base colour texture is sampled in the
/// [`TrilinearRepeat15`] configuration, without an emissive texture, with lighting (`UNLIT`),
/// vertex colours (`VERTEX_COLORS`) and whether the draw is opaque (`ALPHA` false) or
/// alpha-masked or blended (`ALPHA` true: alpha and the kept lanes by the alpha mode) fixed at
/// compile time: the operations of [`MaterialShader::shade_lanes`] for such a draw, in the same
/// order, with no branch on the pass, the wrap modes, the filters or the texel storage.
struct Textured<'s, 'a, const UNLIT: bool, const VERTEX_COLORS: bool, const ALPHA: bool> {
    shader: &'s MaterialShader<'a>,
    texture: TrilinearRepeat15<'a>,
}

impl<const UNLIT: bool, const VERTEX_COLORS: bool, const ALPHA: bool> LaneProgram
    for Textured<'_, '_, UNLIT, VERTEX_COLORS, ALPHA>
{
    /// A texture coordinate is rarely the same at a triangle's three vertices, and the sampler
    /// makes these the largest kernels: compiled once.
    const CONSTANT_KERNELS: bool = false;

    /// Each lane is shaded from its own values, and the sampler's results do not depend on
    /// which lanes share a call (see `sample_grad_lanes`).
    const PACKED_ROWS: bool = true;

    #[inline(always)]
    fn fragment_lanes<L: Lanes>(&self, f: &FragmentLanes<'_, L>) -> ShadedLanes<L> {
        let (shader, lanes) = (self.shader, f.lanes);
        let material = shader.material;
        let factor = material.base_color_factor.to_array();
        let mut base = factor_times_color_lanes(f, factor, VERTEX_COLORS);
        let u = VaryingLayout::TEXCOORD;
        let (du_dx, du_dy) = f.derivatives(u);
        let (dv_dx, dv_dy) = f.derivatives(u + 1);
        let texel = self.texture.sample_grad_lanes::<L>(
            [f.varying(u), f.varying(u + 1)],
            [du_dx, dv_dx],
            [du_dy, dv_dy],
            f.active,
        );
        let channels = if ALPHA { 4 } else { 3 };
        for c in 0..channels {
            base[c] = base[c] * texel[c];
        }
        let (alpha, keep) = if ALPHA {
            MaterialShader::alpha_lanes(lanes, material.alpha_mode, base[3])
        } else {
            (lanes.splat_f32(1.0), lanes.mask_all(true))
        };
        let e = material.emissive;
        let emissive = [
            lanes.splat_f32(e.x),
            lanes.splat_f32(e.y),
            lanes.splat_f32(e.z),
        ];
        let [r, g, b] = if UNLIT {
            [
                base[0] + emissive[0],
                base[1] + emissive[1],
                base[2] + emissive[2],
            ]
        } else {
            let n = shader.normal_lanes(f, material.double_sided);
            shader.lit_lanes(lanes, n, &base, emissive)
        };
        ShadedLanes {
            color: [r, g, b, alpha],
            keep,
        }
    }
}

/// The lane program of an opaque untextured colour-pass draw with lighting (`UNLIT`) and vertex
/// colours (`VERTEX_COLORS`) fixed at compile time: [`MaterialShader::shade_untextured_color_lanes`]
/// with those branches, and the alpha mode's, decided (the interpolation of an unused alpha
/// varying disappears with them).
struct OpaqueUntextured<'s, 'a, const UNLIT: bool, const VERTEX_COLORS: bool> {
    shader: &'s MaterialShader<'a>,
    program: UntexturedColor,
}

impl<const UNLIT: bool, const VERTEX_COLORS: bool> LaneProgram
    for OpaqueUntextured<'_, '_, UNLIT, VERTEX_COLORS>
{
    #[inline(always)]
    fn fragment_lanes<L: Lanes>(&self, f: &FragmentLanes<'_, L>) -> ShadedLanes<L> {
        let program = UntexturedColor {
            unlit: UNLIT,
            vertex_colors: VERTEX_COLORS,
            alpha_mode: AlphaMode::Opaque,
            ..self.program
        };
        self.shader.shade_untextured_color_lanes(f, &program)
    }
}

impl MaterialShader<'_> {
    /// Emitted colour: `material.emissive` × the emissive texture, if any (loaders work).
    #[inline]
    fn emissive(&self, fragment: &Fragment<'_>) -> Vec3 {
        let mut emissive = self.material.emissive;
        if let Some((texture, sampler)) = self.emissive_texture {
            emissive *= sample(fragment, self.layout, texture, &sampler).truncate();
        }
        emissive
    }

    /// The value of the normals or ids pass.
    #[inline]
    fn auxiliary(&self, fragment: &Fragment<'_>) -> Vec4 {
        match self.pass {
            Pass::Normals => self.normal(fragment).extend(1.0),
            _ => Vec4::new(
                self.ids.0,
                fragment.primitive_id as f32 + 1.0,
                self.ids.1,
                1.0,
            ),
        }
    }
}

/// The lane-wide fragment program: the same operations as [`Shader::fragment`] above, in the same
/// order, on eight pixels at once.
impl MaterialShader<'_> {
    #[inline(always)]
    fn shade_lanes<L: Lanes>(&self, f: &FragmentLanes<'_, L>) -> ShadedLanes<L> {
        if let Some(program) = &self.untextured_color {
            return self.shade_untextured_color_lanes(f, program);
        }
        let lanes = f.lanes;
        let all = lanes.mask_all(true);
        let needs_alpha = !matches!(self.material.alpha_mode, AlphaMode::Opaque);
        if self.pass != Pass::Color && !needs_alpha {
            return ShadedLanes {
                color: self.auxiliary_lanes(f),
                keep: all,
            };
        }
        let base = self.base_color_lanes(f);
        let (alpha, keep) = Self::alpha_lanes(lanes, self.material.alpha_mode, base[3]);
        if self.pass != Pass::Color {
            return ShadedLanes {
                color: self.auxiliary_lanes(f),
                keep,
            };
        }
        if self.material.unlit {
            let emissive = self.emissive_lanes(f);
            return ShadedLanes {
                color: [
                    base[0] + emissive[0],
                    base[1] + emissive[1],
                    base[2] + emissive[2],
                    alpha,
                ],
                keep,
            };
        }
        let n = self.normal_lanes(f, self.material.double_sided);
        let emissive = self.emissive_lanes(f);
        let [r, g, b] = self.lit_lanes(lanes, n, &base, emissive);
        ShadedLanes {
            color: [r, g, b, alpha],
            keep,
        }
    }

    /// [`MaterialShader::shade_lanes`] for an untextured colour-pass draw: the same
    /// operations in the same order, with the material's properties read from `program`.
    #[inline(always)]
    fn shade_untextured_color_lanes<L: Lanes>(
        &self,
        f: &FragmentLanes<'_, L>,
        program: &UntexturedColor,
    ) -> ShadedLanes<L> {
        let lanes = f.lanes;
        let base = factor_times_color_lanes(f, program.base_color_factor, program.vertex_colors);
        let (alpha, keep) = Self::alpha_lanes(lanes, program.alpha_mode, base[3]);
        let e = program.emissive;
        let emissive = [
            lanes.splat_f32(e.x),
            lanes.splat_f32(e.y),
            lanes.splat_f32(e.z),
        ];
        if program.unlit {
            return ShadedLanes {
                color: [
                    base[0] + emissive[0],
                    base[1] + emissive[1],
                    base[2] + emissive[2],
                    alpha,
                ],
                keep,
            };
        }
        let n = self.normal_lanes(f, program.double_sided);
        let [r, g, b] = self.lit_lanes(lanes, n, &base, emissive);
        ShadedLanes {
            color: [r, g, b, alpha],
            keep,
        }
    }

    /// Alpha and the kept lanes by the alpha mode, from the base colour's alpha.
    #[inline(always)]
    fn alpha_lanes<L: Lanes>(lanes: L, mode: AlphaMode, base_alpha: L::F32) -> (L::F32, L::Mask) {
        let all = lanes.mask_all(true);
        match mode {
            AlphaMode::Opaque => (lanes.splat_f32(1.0), all),
            AlphaMode::Mask { cutoff } => (
                lanes.splat_f32(1.0),
                base_alpha.simd_lt(lanes.splat_f32(cutoff)).not(),
            ),
            AlphaMode::Blend => (base_alpha, all),
        }
    }

    /// Lambert: `base.rgb × (ambient + (1 − ambient) × max(0, N·L) × light) + emissive`.
    #[inline(always)]
    fn lit_lanes<L: Lanes>(
        &self,
        lanes: L,
        n: [L::F32; 3],
        base: &[L::F32; 4],
        emissive: [L::F32; 3],
    ) -> [L::F32; 3] {
        let l = self.lighting;
        let n_dot_l = (n[0] * lanes.splat_f32(l.to_light.x)
            + n[1] * lanes.splat_f32(l.to_light.y)
            + n[2] * lanes.splat_f32(l.to_light.z))
        .max(lanes.splat_f32(0.0));
        let diffuse = lanes.splat_f32(1.0 - l.ambient) * n_dot_l;
        let ambient = lanes.splat_f32(l.ambient);
        let light = [
            ambient + diffuse * lanes.splat_f32(l.light_color.x),
            ambient + diffuse * lanes.splat_f32(l.light_color.y),
            ambient + diffuse * lanes.splat_f32(l.light_color.z),
        ];
        [
            base[0] * light[0] + emissive[0],
            base[1] * light[1] + emissive[1],
            base[2] * light[2] + emissive[2],
        ]
    }

    /// [`MaterialShader::emissive`] per lane, the texture sampled lane-wide.
    #[inline(always)]
    fn emissive_lanes<L: Lanes>(&self, f: &FragmentLanes<'_, L>) -> [L::F32; 3] {
        let lanes = f.lanes;
        let e = self.material.emissive;
        let mut emissive = [
            lanes.splat_f32(e.x),
            lanes.splat_f32(e.y),
            lanes.splat_f32(e.z),
        ];
        if let Some((texture, sampler)) = self.emissive_texture {
            let texel = sample_lanes(f, self.layout, texture, &sampler);
            for c in 0..3 {
                emissive[c] = emissive[c] * texel[c];
            }
        }
        emissive
    }

    /// `baseColorFactor × COLOR_0 × texture(uv)` per lane; the texture is sampled lane-wide.
    #[inline(always)]
    fn base_color_lanes<L: Lanes>(&self, f: &FragmentLanes<'_, L>) -> [L::F32; 4] {
        let factor = self.material.base_color_factor.to_array();
        let mut base = factor_times_color_lanes(f, factor, self.layout.color);
        if let Some((texture, sampler)) = self.texture {
            let texel = sample_lanes(f, self.layout, texture, &sampler);
            for c in 0..4 {
                base[c] = base[c] * texel[c];
            }
        }
        base
    }

    /// The interpolated world normal, renormalised (zero when degenerate, as
    /// `Vec3::normalize_or_zero`), flipped on back faces when `double_sided`.
    #[inline(always)]
    fn normal_lanes<L: Lanes>(&self, f: &FragmentLanes<'_, L>, double_sided: bool) -> [L::F32; 3] {
        let lanes = f.lanes;
        if !self.layout.normal {
            return [lanes.splat_f32(0.0); 3];
        }
        let at = VaryingLayout::NORMAL;
        let n = if self.layout.normal_from_direction() {
            // The direction alone: no perspective division (see
            // `FragmentLanes::varying_direction`).
            [
                f.varying_direction(at),
                f.varying_direction(at + 1),
                f.varying_direction(at + 2),
            ]
        } else {
            [f.varying(at), f.varying(at + 1), f.varying(at + 2)]
        };
        let length2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
        let rcp = lanes.splat_f32(1.0) / length2.sqrt();
        let usable = rcp
            .abs()
            .simd_lt(lanes.splat_f32(f32::INFINITY))
            .and(rcp.simd_gt(lanes.splat_f32(0.0)));
        let zero = lanes.splat_f32(0.0);
        let n = [
            usable.select_f32(n[0] * rcp, zero),
            usable.select_f32(n[1] * rcp, zero),
            usable.select_f32(n[2] * rcp, zero),
        ];
        if double_sided && !f.front_facing {
            [-n[0], -n[1], -n[2]]
        } else {
            n
        }
    }

    /// The value of the normals or ids pass, per lane.
    #[inline(always)]
    fn auxiliary_lanes<L: Lanes>(&self, f: &FragmentLanes<'_, L>) -> [L::F32; 4] {
        let lanes = f.lanes;
        match self.pass {
            Pass::Normals => {
                let n = self.normal_lanes(f, self.material.double_sided);
                [n[0], n[1], n[2], lanes.splat_f32(1.0)]
            }
            _ => [
                lanes.splat_f32(self.ids.0),
                lanes.splat_f32(f.primitive_id as f32 + 1.0),
                lanes.splat_f32(self.ids.1),
                lanes.splat_f32(1.0),
            ],
        }
    }
}

/// `factor × COLOR_0` per lane when the mesh has `vertex_colors`, else `factor` itself (as
/// `factor × 1` in [`MaterialShader::base_color`], exactly). The untextured program passes its
/// own copy of the flag: reading `self.layout` there measured 5–12% slower on the thesis quads.
#[inline(always)]
fn factor_times_color_lanes<L: Lanes>(
    f: &FragmentLanes<'_, L>,
    factor: [f32; 4],
    vertex_colors: bool,
) -> [L::F32; 4] {
    let lanes = f.lanes;
    let c = VaryingLayout::COLOR;
    if vertex_colors {
        [
            lanes.splat_f32(factor[0]) * f.varying(c),
            lanes.splat_f32(factor[1]) * f.varying(c + 1),
            lanes.splat_f32(factor[2]) * f.varying(c + 2),
            lanes.splat_f32(factor[3]) * f.varying(c + 3),
        ]
    } else {
        [
            lanes.splat_f32(factor[0]),
            lanes.splat_f32(factor[1]),
            lanes.splat_f32(factor[2]),
            lanes.splat_f32(factor[3]),
        ]
    }
}

/// A texture sampled at the material's texture coordinates ([`VaryingLayout::TEXCOORD`]; 0
/// where `layout` has none) with their analytic screen-space derivatives, lane-wide.
#[inline(always)]
fn sample_lanes<L: Lanes>(
    f: &FragmentLanes<'_, L>,
    layout: VaryingLayout,
    texture: &Texture,
    sampler: &Sampler,
) -> [L::F32; 4] {
    if !layout.texcoord {
        return [f.lanes.splat_f32(0.0); 4];
    }
    let u = VaryingLayout::TEXCOORD;
    let (du_dx, du_dy) = f.derivatives(u);
    let (dv_dx, dv_dy) = f.derivatives(u + 1);
    texture.sample_grad_lanes::<L>(
        sampler,
        [f.varying(u), f.varying(u + 1)],
        [du_dx, dv_dx],
        [du_dy, dv_dy],
        f.active,
    )
}

/// [`sample_lanes`] for one fragment.
#[inline]
fn sample(
    fragment: &Fragment<'_>,
    layout: VaryingLayout,
    texture: &Texture,
    sampler: &Sampler,
) -> Vec4 {
    if !layout.texcoord {
        return Vec4::ZERO;
    }
    let u = VaryingLayout::TEXCOORD;
    let v = fragment.varyings();
    let (du_dx, du_dy) = fragment.derivatives(u);
    let (dv_dx, dv_dy) = fragment.derivatives(u + 1);
    texture.sample_grad(
        sampler,
        Vec2::new(v[u], v[u + 1]),
        Vec2::new(du_dx, dv_dx),
        Vec2::new(du_dy, dv_dy),
    )
}

#[cfg(test)]
#[path = "material_tests.rs"]
mod tests;
