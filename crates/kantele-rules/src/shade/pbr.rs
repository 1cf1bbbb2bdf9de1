//! glTF 2.0's physically based shading, written once for every backend: the metallic-roughness
//! BRDF of the specification's Appendix B (GGX distribution, Smith height-correlated
//! visibility, Schlick Fresnel, the metal / dielectric mix), with the dielectric reflectance of
//! `KHR_materials_ior` and `KHR_materials_specular`, the coat of `KHR_materials_clearcoat`,
//! the sheen of `KHR_materials_sheen` ([`super::sheen`]) and the transmission of
//! `KHR_materials_transmission` and `KHR_materials_volume` ([`super::transmission`]); the
//! `KHR_lights_punctual` falloff, image-based light through an [`EnvironmentLight`], exposure
//! and tone mapping.
//!
//! The functions are generic over [`Lanes`]: the CPU backend runs them on eight pixels at once,
//! and on one pixel through the same code (a scalar [`Lanes`] with the value in every lane), so
//! there is one sequence of operations per rule. The OpenGL shader (`kantele-gl`) follows the
//! same formulas; `f64` versions for tests live in the tests below.

use glam::Vec3;
use kantele_lanes::{F32x8, Lanes, Mask8};

use super::environment::{brdf_ab_lanes, EnvironmentLight};
use super::sheen::{charlie_d, charlie_v, SheenLayer, SheenTerms};
use super::transmission::{attenuate, transmitted_light, TransmissionLayer, TransmissionView};
use crate::scene::{LightKind, PunctualLight};

/// Reflectance at normal incidence of every dielectric (glTF: IOR 1.5).
pub const DIELECTRIC_F0: f32 = 0.04;

/// The smallest perceptual roughness the punctual lights see: below it a highlight is narrower
/// than a pixel and `D` overflows (as Filament's `MIN_PERCEPTUAL_ROUGHNESS`). Image-based light
/// uses the material's own roughness.
pub const MIN_PUNCTUAL_ROUGHNESS: f32 = 0.045;

/// `1 / π`, as `f32`.
const INV_PI: f32 = std::f32::consts::FRAC_1_PI;

/// How the linear colour is mapped to the displayable range after exposure.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Tonemap {
    /// Colours are written as they are (values above 1 clip when quantised).
    None,
    /// Khronos PBR Neutral: colours below 0.76 keep their hue and value, brighter ones are
    /// compressed towards white (the choice for product pictures).
    #[default]
    PbrNeutral,
    /// The ACES filmic curve as fitted by Krzysztof Narkowicz, per channel.
    Aces,
}

impl Tonemap {
    /// The command-line name: `none`, `pbr-neutral`, `aces`.
    pub fn name(self) -> &'static str {
        match self {
            Tonemap::None => "none",
            Tonemap::PbrNeutral => "pbr-neutral",
            Tonemap::Aces => "aces",
        }
    }

    /// The tone map named `name` (see [`Tonemap::name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        [Tonemap::None, Tonemap::PbrNeutral, Tonemap::Aces]
            .into_iter()
            .find(|t| t.name() == name)
    }
}

/// A punctual light as a frame sees it: world space, with the constants of its falloff.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameLight {
    /// Colour × intensity.
    pub color: Vec3,
    /// Directional lights: the unit vector towards the light. Spot lights: the unit vector
    /// along which the light shines (the node's −Z). Point lights: unused.
    pub direction: Vec3,
    /// Point and spot lights: the position.
    pub position: Vec3,
    /// `true` for a directional light (no position, no falloff).
    pub directional: bool,
    /// `1 / range²`, 0 without a range.
    pub inverse_range_squared: f32,
    /// Spot cone: `scale = 1 / max(0.001, cos inner − cos outer)`; 0 for point lights.
    pub cone_scale: f32,
    /// Spot cone: `offset = −cos outer × scale`; 1 for point lights (no cone).
    pub cone_offset: f32,
}

impl FrameLight {
    /// The frame's form of a scene light (already in world space).
    pub fn new(light: &PunctualLight) -> Self {
        let mut out = Self {
            color: light.color,
            direction: light.direction.normalize_or_zero(),
            position: light.position,
            directional: false,
            inverse_range_squared: match light.range {
                Some(r) if r.is_finite() && r > 0.0 => 1.0 / (r * r),
                _ => 0.0,
            },
            cone_scale: 0.0,
            cone_offset: 1.0,
        };
        match light.kind {
            LightKind::Directional => {
                // Stored as the direction towards the light.
                out.direction = -out.direction;
                out.directional = true;
            }
            LightKind::Point => {}
            LightKind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => {
                let (cos_inner, cos_outer) = (inner_cone_angle.cos(), outer_cone_angle.cos());
                out.cone_scale = 1.0 / (cos_inner - cos_outer).max(0.001);
                out.cone_offset = -cos_outer * out.cone_scale;
            }
        }
        out
    }

    /// A directional light of colour `color` shining from `to_light` (the headlight, or the
    /// Lambert scene's light).
    pub fn directional(to_light: Vec3, color: Vec3) -> Self {
        Self {
            color,
            direction: to_light.normalize_or_zero(),
            position: Vec3::ZERO,
            directional: true,
            inverse_range_squared: 0.0,
            cone_scale: 0.0,
            cone_offset: 1.0,
        }
    }
}

/// Everything of a surface point the shading reads, per lane (world space).
#[derive(Clone, Copy, Debug)]
pub struct Surface<L: Lanes> {
    /// Base colour (linear RGB).
    pub base: [L::F32; 3],
    /// Metalness in [0, 1].
    pub metallic: L::F32,
    /// Perceptual roughness in [0, 1].
    pub roughness: L::F32,
    /// Ambient occlusion in [0, 1], applied to image-based light only.
    pub occlusion: L::F32,
    /// Shading normal (unit).
    pub normal: [L::F32; 3],
    /// The surface point.
    pub position: [L::F32; 3],
    /// Reflectance at normal incidence of the dielectric part, in [0, 1]
    /// ([`DIELECTRIC_F0`] without `KHR_materials_ior` and `KHR_materials_specular`).
    pub dielectric_f0: [L::F32; 3],
    /// Weight of the dielectric part's specular reflection (`KHR_materials_specular`; 1
    /// without it).
    pub specular_weight: L::F32,
    /// The clear coat, where the material has one.
    pub clearcoat: Option<ClearcoatLayer<L>>,
    /// The sheen, where the material has one.
    pub sheen: Option<SheenLayer<L>>,
    /// The transmission, where the material has one and the frame a backdrop
    /// ([`PbrLighting::transmission`]).
    pub transmission: Option<TransmissionLayer<L>>,
}

/// `KHR_materials_clearcoat`'s layer over a surface point, per lane: a dielectric (F0 =
/// [`DIELECTRIC_F0`]) GGX lobe of its own roughness and normal, weighted by `factor`, which
/// takes `factor × F_coat(N_coat·V)` of the light away from what lies under it (emission
/// included).
#[derive(Clone, Copy, Debug)]
pub struct ClearcoatLayer<L: Lanes> {
    /// `clearcoatFactor` × texture, in [0, 1].
    pub factor: L::F32,
    /// Perceptual roughness in [0, 1].
    pub roughness: L::F32,
    /// The coat's shading normal (unit).
    pub normal: [L::F32; 3],
}

/// What lights a frame's PBR draws: the punctual lights, the environment and the eye.
#[derive(Clone, Debug)]
pub struct PbrLighting {
    /// Punctual lights (directional, point, spot).
    pub lights: Vec<FrameLight>,
    /// Image-based light, if any.
    pub environment: Option<EnvironmentLight>,
    /// The eye, world space (the view vector points from the surface towards it).
    pub eye: Vec3,
    /// `2^EV` applied before the tone map.
    pub exposure: f32,
    /// The tone map.
    pub tonemap: Tonemap,
    /// What transmissive surfaces see through: set by a backend once it has drawn the frame's
    /// backdrop ([`super::transmission`]); `None` from [`PbrLighting::for_frame`].
    pub transmission: Option<TransmissionView>,
}

/// The most punctual lights a PBR frame shades with (the OpenGL shader's array size); loaders
/// keep the first ones and warn about the rest.
pub const MAX_LIGHTS: usize = 8;

impl PbrLighting {
    /// The lighting of one frame of `scene` seen as `view`: the scene's punctual lights (at
    /// most [`MAX_LIGHTS`]), its environment, and — when it has neither — the view's resolved
    /// light (the headlight) as one directional light.
    pub fn for_frame(scene: &crate::scene::Scene, view: &crate::backend::FrameView) -> Self {
        let mut lights: Vec<FrameLight> = scene
            .lights
            .iter()
            .take(MAX_LIGHTS)
            .map(FrameLight::new)
            .collect();
        if lights.is_empty() && scene.environment.is_none() {
            lights.push(FrameLight::directional(view.to_light, view.light_color));
        }
        Self {
            lights,
            environment: scene.environment.clone(),
            eye: view.view.inverse().transform_point3(Vec3::ZERO),
            exposure: exposure_scale(scene.exposure),
            tonemap: scene.tonemap,
            transmission: None,
        }
    }
}

/// `2^ev`, the colour scale of an exposure of `ev` stops (1 for non-finite `ev`).
pub fn exposure_scale(ev: f32) -> f32 {
    if ev.is_finite() {
        ev.clamp(-64.0, 64.0).exp2()
    } else {
        1.0
    }
}

#[inline(always)]
fn dot3<L: Lanes>(a: &[L::F32; 3], b: &[L::F32; 3]) -> L::F32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `v / |v|`, zero where `|v|` is zero or not finite.
#[inline(always)]
pub fn normalize3<L: Lanes>(lanes: L, v: [L::F32; 3]) -> [L::F32; 3] {
    let length2 = dot3::<L>(&v, &v);
    let rcp = lanes.splat_f32(1.0) / length2.sqrt();
    let usable = rcp
        .abs()
        .simd_lt(lanes.splat_f32(f32::INFINITY))
        .and(rcp.simd_gt(lanes.splat_f32(0.0)));
    let zero = lanes.splat_f32(0.0);
    [
        usable.select_f32(v[0] * rcp, zero),
        usable.select_f32(v[1] * rcp, zero),
        usable.select_f32(v[2] * rcp, zero),
    ]
}

#[inline(always)]
fn clamp01<L: Lanes>(lanes: L, x: L::F32) -> L::F32 {
    x.max(lanes.splat_f32(0.0)).min(lanes.splat_f32(1.0))
}

/// The reflectance of a surface point: Schlick's `F0` and `F90` of the metal / dielectric
/// mix, and the diffuse colour.
#[derive(Clone, Copy)]
struct Reflectance<L: Lanes> {
    c_diff: [L::F32; 3],
    f0: [L::F32; 3],
    f90: L::F32,
}

/// The material's diffuse colour and reflectance: `c_diff = base × (1 − metallic)`,
/// `F0 = w F0d + (base − w F0d) × metallic`, `F90 = w + (1 − w) × metallic`, where `F0d` is
/// the dielectric reflectance and `w` the specular weight: the metal's Fresnel (`F0 = base`,
/// `F90 = 1`) mixed with the dielectric's scaled by `w` (Schlick's form is affine in `F0` and
/// `F90`). Without the extensions (`F0d = 0.04`, `w = 1`) this is Appendix B's
/// `F0 = 0.04 + (base − 0.04) × metallic`, `F90 = 1`, to the bit.
#[inline(always)]
fn reflectance<L: Lanes>(lanes: L, s: &Surface<L>) -> Reflectance<L> {
    let one = lanes.splat_f32(1.0);
    let dielectric = one - s.metallic;
    let c_diff = [
        s.base[0] * dielectric,
        s.base[1] * dielectric,
        s.base[2] * dielectric,
    ];
    let w = s.specular_weight;
    let d = &s.dielectric_f0;
    let weighted = [d[0] * w, d[1] * w, d[2] * w];
    let f0 = [
        weighted[0] + (s.base[0] - weighted[0]) * s.metallic,
        weighted[1] + (s.base[1] - weighted[1]) * s.metallic,
        weighted[2] + (s.base[2] - weighted[2]) * s.metallic,
    ];
    Reflectance {
        c_diff,
        f0,
        f90: w + (one - w) * s.metallic,
    }
}

/// `D × V`: the GGX distribution times the Smith height-correlated visibility, for
/// `alpha = roughness²` (Appendix B):
/// `D = α² / (π (NdotH² (α² − 1) + 1)²)`,
/// `V = 0.5 / (NdotL √(NdotV² (1 − α²) + α²) + NdotV √(NdotL² (1 − α²) + α²))` (0 where the
/// denominator is 0).
#[inline(always)]
pub fn ggx_d_times_v<L: Lanes>(
    lanes: L,
    alpha: L::F32,
    n_dot_l: L::F32,
    n_dot_v: L::F32,
    n_dot_h: L::F32,
) -> L::F32 {
    let one = lanes.splat_f32(1.0);
    let zero = lanes.splat_f32(0.0);
    let a2 = alpha * alpha;
    let f = n_dot_h * n_dot_h * (a2 - one) + one;
    let d = a2 / (lanes.splat_f32(std::f32::consts::PI) * f * f);
    let ggx_v = n_dot_l * (n_dot_v * n_dot_v * (one - a2) + a2).sqrt();
    let ggx_l = n_dot_v * (n_dot_l * n_dot_l * (one - a2) + a2).sqrt();
    let denominator = ggx_v + ggx_l;
    let positive = denominator.simd_gt(zero);
    let v = positive.select_f32(lanes.splat_f32(0.5) / denominator, zero);
    d * v
}

/// Schlick's Fresnel: `F0 + (F90 − F0) (1 − VdotH)⁵`.
#[inline(always)]
pub fn schlick<L: Lanes>(lanes: L, f0: &[L::F32; 3], f90: L::F32, v_dot_h: L::F32) -> [L::F32; 3] {
    let m5 = schlick_weight(lanes, v_dot_h);
    [
        f0[0] + (f90 - f0[0]) * m5,
        f0[1] + (f90 - f0[1]) * m5,
        f0[2] + (f90 - f0[2]) * m5,
    ]
}

/// `(1 − VdotH)⁵`, Schlick's weight.
#[inline(always)]
fn schlick_weight<L: Lanes>(lanes: L, v_dot_h: L::F32) -> L::F32 {
    let m = lanes.splat_f32(1.0) - v_dot_h;
    let m2 = m * m;
    m2 * m2 * m
}

/// The clear coat's Fresnel: Schlick's with `F0 = 0.04`, `F90 = 1`.
#[inline(always)]
fn coat_fresnel<L: Lanes>(lanes: L, v_dot_h: L::F32) -> L::F32 {
    let f0 = lanes.splat_f32(DIELECTRIC_F0);
    f0 + (lanes.splat_f32(1.0) - f0) * schlick_weight(lanes, v_dot_h)
}

/// Radiance arriving from `light` at the surface point and the unit vector towards it:
/// directional lights arrive unattenuated; point and spot lights fall off as `1 / d²`, times
/// `clamp(1 − (d / range)⁴, 0, 1)` with a range, and spot lights by the cone,
/// `clamp(cos θ × scale + offset, 0, 1)²` (`KHR_lights_punctual`).
#[inline(always)]
pub fn light_arrival<L: Lanes>(
    lanes: L,
    light: &FrameLight,
    position: &[L::F32; 3],
) -> ([L::F32; 3], L::F32) {
    let one = lanes.splat_f32(1.0);
    if light.directional {
        let l = [
            lanes.splat_f32(light.direction.x),
            lanes.splat_f32(light.direction.y),
            lanes.splat_f32(light.direction.z),
        ];
        return (l, one);
    }
    let d = [
        lanes.splat_f32(light.position.x) - position[0],
        lanes.splat_f32(light.position.y) - position[1],
        lanes.splat_f32(light.position.z) - position[2],
    ];
    let distance2 = dot3::<L>(&d, &d);
    let l = normalize3(lanes, d);
    let mut attenuation = one / distance2;
    if light.inverse_range_squared > 0.0 {
        let ratio2 = distance2 * lanes.splat_f32(light.inverse_range_squared);
        attenuation = attenuation * clamp01(lanes, one - ratio2 * ratio2);
    }
    if light.cone_scale > 0.0 {
        let cos_angle = -(l[0] * lanes.splat_f32(light.direction.x)
            + l[1] * lanes.splat_f32(light.direction.y)
            + l[2] * lanes.splat_f32(light.direction.z));
        let cone = clamp01(
            lanes,
            cos_angle * lanes.splat_f32(light.cone_scale) + lanes.splat_f32(light.cone_offset),
        );
        attenuation = attenuation * cone * cone;
    }
    // A surface at the light's position receives nothing (not infinity).
    let finite = attenuation.abs().simd_lt(lanes.splat_f32(f32::INFINITY));
    (l, finite.select_f32(attenuation, lanes.splat_f32(0.0)))
}

/// What one light or the environment gives a surface point, by layer: the base, the clear
/// coat's lobe (not yet weighted by the coat factor) and the sheen's lobe (0 without them).
#[derive(Clone, Copy)]
struct Layers<L: Lanes> {
    base: [L::F32; 3],
    coat: [L::F32; 3],
    sheen: [L::F32; 3],
}

impl<L: Lanes> Layers<L> {
    #[inline(always)]
    fn zero(lanes: L) -> Self {
        let zero = [lanes.splat_f32(0.0); 3];
        Self {
            base: zero,
            coat: zero,
            sheen: zero,
        }
    }

    #[inline(always)]
    fn add(&mut self, other: &Self) {
        for k in 0..3 {
            self.base[k] = self.base[k] + other.base[k];
            self.coat[k] = self.coat[k] + other.coat[k];
            self.sheen[k] = self.sheen[k] + other.sheen[k];
        }
    }
}

/// Outgoing radiance of one surface point towards `view` (unit, towards the eye) lit by one
/// punctual light: `radiance × NdotL × ((1 − F) c_diff / π + F D V)` (Appendix B); with a
/// clear coat, the coat's lobe `radiance × NdotL_coat × F_coat D V` (its roughness and normal);
/// with a sheen, its lobe `radiance × NdotL × sheenColor × D_charlie × V_charlie`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn punctual<L: Lanes>(
    lanes: L,
    light: &FrameLight,
    s: &Surface<L>,
    view: &[L::F32; 3],
    r: &Reflectance<L>,
    alpha: L::F32,
    path: &[L::F32; 3],
    sheen: Option<&SheenTerms<L>>,
) -> Layers<L> {
    let (l, attenuation) = light_arrival(lanes, light, &s.position);
    let h = normalize3(lanes, [view[0] + l[0], view[1] + l[1], view[2] + l[2]]);
    let n_dot_l = clamp01(lanes, dot3::<L>(&s.normal, &l));
    let n_dot_v = clamp01(lanes, dot3::<L>(&s.normal, view));
    let n_dot_h = clamp01(lanes, dot3::<L>(&s.normal, &h));
    let v_dot_h = clamp01(lanes, dot3::<L>(view, &h));
    let f = schlick(lanes, &r.f0, r.f90, v_dot_h);
    let dv = ggx_d_times_v(lanes, alpha, n_dot_l, n_dot_v, n_dot_h);
    let one = lanes.splat_f32(1.0);
    let inv_pi = lanes.splat_f32(INV_PI);
    let scale = attenuation * n_dot_l;
    let mut out = [lanes.splat_f32(0.0); 3];
    let color = light.color.to_array();
    if let Some(layer) = &s.transmission {
        // Transmission takes its part of the diffuse light, and adds the light from behind.
        let through = punctual_transmission(lanes, light, s, layer, view, r, alpha, path);
        let kept = one - layer.factor;
        for c in 0..3 {
            let brdf = (one - f[c]) * r.c_diff[c] * inv_pi * kept + f[c] * dv;
            out[c] = lanes.splat_f32(color[c]) * scale * brdf + through[c];
        }
    } else {
        for c in 0..3 {
            let brdf = (one - f[c]) * r.c_diff[c] * inv_pi + f[c] * dv;
            out[c] = lanes.splat_f32(color[c]) * scale * brdf;
        }
    }
    let mut coat = [lanes.splat_f32(0.0); 3];
    if let Some(layer) = &s.clearcoat {
        let n = &layer.normal;
        let n_dot_l = clamp01(lanes, dot3::<L>(n, &l));
        let n_dot_v = clamp01(lanes, dot3::<L>(n, view));
        let n_dot_h = clamp01(lanes, dot3::<L>(n, &h));
        let clamped = layer.roughness.max(lanes.splat_f32(MIN_PUNCTUAL_ROUGHNESS));
        let dv = ggx_d_times_v(lanes, clamped * clamped, n_dot_l, n_dot_v, n_dot_h);
        let lobe = attenuation * n_dot_l * coat_fresnel(lanes, v_dot_h) * dv;
        for c in 0..3 {
            coat[c] = lanes.splat_f32(color[c]) * lobe;
        }
    }
    let mut sheen_out = [lanes.splat_f32(0.0); 3];
    if let (Some(layer), Some(terms)) = (&s.sheen, sheen) {
        let d = charlie_d(lanes, terms.alpha, terms.exponent, n_dot_h);
        let lobe = scale * d * charlie_v(lanes, terms, n_dot_l, n_dot_v);
        for c in 0..3 {
            sheen_out[c] = lanes.splat_f32(color[c]) * lobe * layer.color[c];
        }
    }
    Layers {
        base: out,
        coat,
        sheen: sheen_out,
    }
}

/// The light of one punctual light that a transmissive surface point lets through towards
/// `view`: the GGX lobe around the light's direction mirrored in the surface's plane
/// (`radiance × NdotL_mirrored × (1 − F) × c_diff × D V`, at `α × clamp(2 ior − 2, 0, 1)`, no
/// narrower than the punctual lights' floor), × the transmission factor, with the light's
/// falloff taken where the refracted view ray leaves the volume and dimmed along that path.
/// The glTF sample viewer's lobe, with the cosine factor that the rendering equation gives
/// every lobe.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn punctual_transmission<L: Lanes>(
    lanes: L,
    light: &FrameLight,
    s: &Surface<L>,
    layer: &TransmissionLayer<L>,
    view: &[L::F32; 3],
    r: &Reflectance<L>,
    alpha: L::F32,
    path: &[L::F32; 3],
) -> [L::F32; 3] {
    let one = lanes.splat_f32(1.0);
    let n = &s.normal;
    let exit = [
        s.position[0] + path[0],
        s.position[1] + path[1],
        s.position[2] + path[2],
    ];
    let (l, attenuation) = light_arrival(lanes, light, &exit);
    // The light's direction mirrored in the surface's plane: L − 2 (N·L) N.
    let n_dot_l = dot3::<L>(n, &l);
    let twice = n_dot_l + n_dot_l;
    let mirrored = normalize3(
        lanes,
        [
            l[0] - twice * n[0],
            l[1] - twice * n[1],
            l[2] - twice * n[2],
        ],
    );
    let h = normalize3(
        lanes,
        [
            view[0] + mirrored[0],
            view[1] + mirrored[1],
            view[2] + mirrored[2],
        ],
    );
    let n_dot_m = clamp01(lanes, dot3::<L>(n, &mirrored));
    let n_dot_v = clamp01(lanes, dot3::<L>(n, view));
    let n_dot_h = clamp01(lanes, dot3::<L>(n, &h));
    let v_dot_h = clamp01(lanes, dot3::<L>(view, &h));
    let floor = MIN_PUNCTUAL_ROUGHNESS * MIN_PUNCTUAL_ROUGHNESS;
    let ior_scale = (2.0 * layer.volume.ior - 2.0).clamp(0.0, 1.0);
    let alpha_t = (alpha * lanes.splat_f32(ior_scale)).max(lanes.splat_f32(floor));
    let dv = ggx_d_times_v(lanes, alpha_t, n_dot_m, n_dot_v, n_dot_h);
    let f = schlick(lanes, &r.f0, r.f90, v_dot_h);
    let weight = attenuation * n_dot_m * dv * layer.factor;
    let color = light.color.to_array();
    let mut out = [lanes.splat_f32(0.0); 3];
    for c in 0..3 {
        out[c] = lanes.splat_f32(color[c]) * weight * (one - f[c]) * r.c_diff[c];
    }
    attenuate(lanes, &layer.volume, path, out)
}

/// The linear colour of a lit surface point emitting `emissive`, before exposure and tone
/// mapping: every punctual light by Appendix B (`punctual`), plus image-based light (diffuse
/// irradiance × `c_diff × (1 − FssEss)` and the pre-filtered specular radiance ×
/// `FssEss = F0 A + F90 B`, both × occlusion), where `A`, `B` are the split-sum terms of the
/// environment's BRDF table; plus the emission. With a clear coat of weight `k` (`KHR_materials_clearcoat`)
/// that sum is scaled by `1 − k F_coat(N_coat·V)` and the coat's own lobe, × `k`, is added.
/// With transmission of weight `t` (a [`TransmissionLayer`] and a frame's
/// [`TransmissionView`]), `t` of the diffuse light (image-based and punctual) is replaced by
/// light from behind: the backdrop's ([`transmitted_light`]) × `c_diff × (1 − FssEss)`, and
/// each punctual light's transmitted lobe. With a sheen ([`super::sheen`]) all of that but the
/// emission is scaled by `1 − max(sheenColor) E(NdotV)` and the sheen's lobes added, under the
/// coat.
#[inline(always)]
pub fn shade<L: Lanes>(
    lanes: L,
    lighting: &PbrLighting,
    s: &Surface<L>,
    emissive: &[L::F32; 3],
) -> [L::F32; 3] {
    let view = normalize3(
        lanes,
        [
            lanes.splat_f32(lighting.eye.x) - s.position[0],
            lanes.splat_f32(lighting.eye.y) - s.position[1],
            lanes.splat_f32(lighting.eye.z) - s.position[2],
        ],
    );
    let r = reflectance(lanes, s);
    let clamped = s.roughness.max(lanes.splat_f32(MIN_PUNCTUAL_ROUGHNESS));
    let alpha = clamped * clamped;
    let mut sum = Layers::zero(lanes);
    let zero = lanes.splat_f32(0.0);
    let path = match &s.transmission {
        Some(layer) => super::transmission::refraction_path(lanes, layer, &s.normal, &view),
        None => [zero; 3],
    };
    // A `match`, not `Option::map`: a closure's body may be compiled out of line, without the
    // kernel's instruction set.
    #[allow(clippy::manual_map)]
    let sheen = match &s.sheen {
        Some(layer) => Some(layer.terms(lanes, clamp01(lanes, dot3::<L>(&s.normal, &view)))),
        None => None,
    };
    for light in &lighting.lights {
        sum.add(&punctual(
            lanes,
            light,
            s,
            &view,
            &r,
            alpha,
            &path,
            sheen.as_ref(),
        ));
    }
    if let Some(environment) = &lighting.environment {
        sum.add(&image_based(
            lanes,
            environment,
            s,
            &view,
            &r,
            sheen.as_ref(),
        ));
    }
    let Layers {
        base: mut color,
        coat: coat_color,
        sheen: sheen_color,
    } = sum;
    if let (Some(layer), Some(through)) = (&s.transmission, &lighting.transmission) {
        // The backdrop replaces the part `factor` of the dielectric's diffuse light (the
        // image-based part was scaled down in `image_based`), with the same room left by the
        // specular reflection.
        let light = transmitted_light(
            lanes,
            through,
            layer,
            &s.position,
            &s.normal,
            &view,
            s.roughness,
        );
        let n_dot_v = clamp01(lanes, dot3::<L>(&s.normal, &view));
        let [a, b] = brdf_ab_lanes(lanes, n_dot_v, s.roughness);
        let one = lanes.splat_f32(1.0);
        for k in 0..3 {
            let fss_ess = r.f0[k] * a + r.f90 * b;
            color[k] = color[k] + layer.factor * r.c_diff[k] * (one - fss_ess) * light[k];
        }
    }
    if let Some(terms) = &sheen {
        for k in 0..3 {
            color[k] = color[k] * terms.base_scale + sheen_color[k];
        }
    }
    for k in 0..3 {
        color[k] = color[k] + emissive[k];
    }
    if let Some(layer) = &s.clearcoat {
        let n_dot_v = clamp01(lanes, dot3::<L>(&layer.normal, &view));
        let under = lanes.splat_f32(1.0) - layer.factor * coat_fresnel(lanes, n_dot_v);
        for k in 0..3 {
            color[k] = color[k] * under + layer.factor * coat_color[k];
        }
    }
    color
}

/// The image-based part of [`shade`]: the light under the coat, the coat's lobe (not yet
/// weighted by the coat factor; 0 without a coat) and the sheen's (0 without a sheen).
#[inline(always)]
fn image_based<L: Lanes>(
    lanes: L,
    environment: &EnvironmentLight,
    s: &Surface<L>,
    view: &[L::F32; 3],
    r: &Reflectance<L>,
    sheen: Option<&SheenTerms<L>>,
) -> Layers<L> {
    let one = lanes.splat_f32(1.0);
    let zero = lanes.splat_f32(0.0);
    let coat = s.clearcoat.as_ref();
    // The specular lookups of the base, the coat and the sheen, from one call site: each call
    // site of the lookups is compiled into every kernel. The base and the coat also read the
    // split-sum table.
    let mut lobes = [(s.normal, s.roughness); 3];
    let mut count = 1;
    if let Some(layer) = coat {
        lobes[count] = (layer.normal, layer.roughness);
        count += 1;
    }
    let split_sums = count;
    if let Some(layer) = &s.sheen {
        lobes[count] = (s.normal, layer.roughness);
        count += 1;
    }
    let mut reads = [([zero; 3], zero, zero); 3];
    for (k, ((n, roughness), read)) in lobes[..count].iter().zip(&mut reads).enumerate() {
        let n_dot_v_raw = dot3::<L>(n, view);
        // R = 2 (N·V) N − V.
        let two_n_dot_v = n_dot_v_raw + n_dot_v_raw;
        let reflected = [
            two_n_dot_v * n[0] - view[0],
            two_n_dot_v * n[1] - view[1],
            two_n_dot_v * n[2] - view[2],
        ];
        read.0 = environment.specular_lanes(lanes, &reflected, *roughness);
        if k < split_sums {
            let n_dot_v = clamp01(lanes, n_dot_v_raw);
            [read.1, read.2] = environment.brdf_lanes(lanes, n_dot_v, *roughness);
        }
    }
    let irradiance = environment.irradiance_lanes(lanes, &s.normal);
    let intensity = lanes.splat_f32(environment.intensity);
    let weight = s.occlusion * intensity;
    let (specular, a, b) = reads[0];
    let mut out = [zero; 3];
    let kept = match &s.transmission {
        Some(layer) => one - layer.factor,
        None => one,
    };
    for c in 0..3 {
        let fss_ess = r.f0[c] * a + r.f90 * b;
        let diffuse = irradiance[c] * r.c_diff[c] * (one - fss_ess) * kept;
        out[c] = (diffuse + specular[c] * fss_ess) * weight;
    }
    let mut coat_out = [zero; 3];
    if coat.is_some() {
        let (specular, a, b) = reads[1];
        let fss_ess = lanes.splat_f32(DIELECTRIC_F0) * a + b;
        for c in 0..3 {
            coat_out[c] = specular[c] * fss_ess * weight;
        }
    }
    let mut sheen_out = [zero; 3];
    if let (Some(layer), Some(terms)) = (&s.sheen, sheen) {
        let (specular, _, _) = reads[split_sums];
        let scale = terms.albedo * weight;
        for c in 0..3 {
            sheen_out[c] = specular[c] * layer.color[c] * scale;
        }
    }
    Layers {
        base: out,
        coat: coat_out,
        sheen: sheen_out,
    }
}

/// Exposure (`× scale`) and the tone map, per lane.
#[inline(always)]
pub fn tonemap<L: Lanes>(
    lanes: L,
    tonemap: Tonemap,
    exposure: f32,
    rgb: [L::F32; 3],
) -> [L::F32; 3] {
    let e = lanes.splat_f32(exposure);
    let rgb = [rgb[0] * e, rgb[1] * e, rgb[2] * e];
    match tonemap {
        Tonemap::None => rgb,
        Tonemap::PbrNeutral => pbr_neutral(lanes, rgb),
        Tonemap::Aces => [
            aces(lanes, rgb[0]),
            aces(lanes, rgb[1]),
            aces(lanes, rgb[2]),
        ],
    }
}

/// The ACES filmic curve as fitted by Krzysztof Narkowicz, per lane: `x (2.51 x + 0.03) /
/// (x (2.43 x + 0.59) + 0.14)` of `max(x, 0)`, clamped to [0, 1]. A function, not a closure:
/// LLVM may compile a closure's body out of line, without the kernel's instruction set.
#[inline(always)]
fn aces<L: Lanes>(lanes: L, x: L::F32) -> L::F32 {
    let x = x.max(lanes.splat_f32(0.0));
    let num = x * (lanes.splat_f32(2.51) * x + lanes.splat_f32(0.03));
    let den = x * (lanes.splat_f32(2.43) * x + lanes.splat_f32(0.59)) + lanes.splat_f32(0.14);
    clamp01(lanes, num / den)
}

/// Khronos PBR Neutral: peak values from here on are compressed towards white.
pub const PBR_NEUTRAL_START_COMPRESSION: f32 = 0.8 - 0.04;
/// Khronos PBR Neutral: how far compressed colours move towards white.
pub const PBR_NEUTRAL_DESATURATION: f32 = 0.15;

/// Khronos PBR Neutral (the reference GLSL, operation for operation).
#[inline(always)]
fn pbr_neutral<L: Lanes>(lanes: L, rgb: [L::F32; 3]) -> [L::F32; 3] {
    const START_COMPRESSION: f32 = PBR_NEUTRAL_START_COMPRESSION;
    const DESATURATION: f32 = PBR_NEUTRAL_DESATURATION;
    let one = lanes.splat_f32(1.0);
    let x = rgb[0].min(rgb[1].min(rgb[2]));
    let small = x - lanes.splat_f32(6.25) * x * x;
    let offset = x
        .simd_lt(lanes.splat_f32(0.08))
        .select_f32(small, lanes.splat_f32(0.04));
    let c = [rgb[0] - offset, rgb[1] - offset, rgb[2] - offset];
    let peak = c[0].max(c[1].max(c[2]));
    let d = 1.0 - START_COMPRESSION;
    let new_peak = one - lanes.splat_f32(d * d) / (peak + lanes.splat_f32(d - START_COMPRESSION));
    let ratio = new_peak / peak;
    let g = one - one / (lanes.splat_f32(DESATURATION) * (peak - new_peak) + one);
    let compress = peak.simd_ge(lanes.splat_f32(START_COMPRESSION));
    let mut out = c;
    for k in 0..3 {
        let scaled = c[k] * ratio;
        let mixed = scaled + (new_peak - scaled) * g;
        out[k] = compress.select_f32(mixed, c[k]);
    }
    out
}

#[cfg(test)]
#[path = "pbr_tests.rs"]
mod tests;
