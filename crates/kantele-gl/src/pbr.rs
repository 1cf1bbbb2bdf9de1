//! The PBR program: glTF metallic-roughness shading (`kantele_rules::shade::pbr`) written in
//! GLSL 3.30 operation for operation — the same formulas, the same order, the same clamps —
//! its uniform locations, and the per-frame and per-draw uniforms it reads. The Lambert program
//! of [`crate::shaders`] is untouched; a frame uses this one when its scene's
//! [`Shading`](kantele_rules::scene::Shading) is `Pbr`.
//!
//! The environment ([`EnvironmentLight`]) is read with the arithmetic of
//! `kantele_rules::shade::environment`: nine SH coefficients for irradiance, and the six
//! pre-filtered octahedral levels and the split-sum table read by `texelFetch` with the bilinear
//! weights computed in the shader as the CPU computes them (never GL's filtering). The levels
//! share one `GL_RGB32F` atlas, stacked from level 0 at row 0 (see
//! [`crate::resources::GpuEnvironment`]).
//!
//! Transmission (`kantele_rules::shade::transmission`) follows the rules the same way: the
//! refracted path, the exit point's place in the backdrop, Beer's law, the punctual lights'
//! transmitted lobe and the backdrop term of `pbr::shade`. Its per-draw constants (the rules'
//! `Volume`: `1 / ior`, the model's scale, the Beer coefficients, the level-of-detail scale)
//! come from the host; the backdrop is read with `textureLod` on the rules' own mip chain
//! ([`crate::resources::GpuBackdrop`]), trilinear as `Backdrop::sample_lanes`. A draw without
//! transmission (`u_transmissive` false) takes none of these branches.
//!
//! Sheen (`kantele_rules::shade::sheen`) likewise: the Charlie distribution and visibility
//! with the rules' fit of `Λ` (GLSL's `log2` and `exp2` in place of the rules' lane
//! polynomials, with the same clamps), the lobe's albedo read from the rules' own table (a
//! `GL_R32F` texture, by `texelFetch` and the split-sum table's bilinear arithmetic), the base
//! scaled by `1 − max(sheenColor) E(NdotV)` and the image-based sheen read along the reflected
//! view at the sheen's roughness. A draw without a sheen (`u_sheen` false) takes none of these
//! branches.

use glam::{Mat4, Vec3};
use glow::HasContext;
use kantele_rules::shade::environment::{
    EnvironmentLight, BRDF_TABLE_SIZE, SH_Y0, SH_Y1, SH_Y2, SH_Y20, SH_Y22, SPECULAR_LEVELS,
};
use kantele_rules::shade::pbr::{
    FrameLight, PbrLighting, Tonemap, DIELECTRIC_F0, MAX_LIGHTS, MIN_PUNCTUAL_ROUGHNESS,
    PBR_NEUTRAL_DESATURATION, PBR_NEUTRAL_START_COMPRESSION,
};
use kantele_rules::shade::sheen::LAMBDA_FIT;

use crate::program::{uniforms, Uniforms};
use crate::resources::{GpuBackdrop, GpuEnvironment};

/// The program's material textures besides the base colour and emissive ones, in the order of
/// [`Material::pbr_textures`](kantele_rules::scene::Material::pbr_textures): the names of
/// their `u_has_*` flag and sampler uniforms. Texture `k` is on unit [`FIRST_PBR_UNIT`] + `k`.
pub(crate) const PBR_TEXTURES: [(&str, &str); 12] = [
    (
        "u_has_metallic_roughness_texture",
        "u_metallic_roughness_texture",
    ),
    ("u_has_normal_texture", "u_normal_texture"),
    ("u_has_occlusion_texture", "u_occlusion_texture"),
    ("u_has_specular_texture", "u_specular_texture"),
    ("u_has_specular_color_texture", "u_specular_color_texture"),
    ("u_has_clearcoat_texture", "u_clearcoat_texture"),
    (
        "u_has_clearcoat_roughness_texture",
        "u_clearcoat_roughness_texture",
    ),
    (
        "u_has_clearcoat_normal_texture",
        "u_clearcoat_normal_texture",
    ),
    ("u_has_transmission_texture", "u_transmission_texture"),
    ("u_has_thickness_texture", "u_thickness_texture"),
    ("u_has_sheen_color_texture", "u_sheen_color_texture"),
    ("u_has_sheen_roughness_texture", "u_sheen_roughness_texture"),
];
/// Texture unit of the first of [`PBR_TEXTURES`] (0 and 1 are the base colour and emissive).
pub(crate) const FIRST_PBR_UNIT: u32 = 2;
/// The material textures: the base colour, the emissive and [`PBR_TEXTURES`] (the length of
/// `u_texcoord_set`).
pub(crate) const TEXTURE_SLOTS: usize = 2 + PBR_TEXTURES.len();
/// Texture unit of the environment's level atlas.
pub(crate) const UNIT_ENVIRONMENT: u32 = FIRST_PBR_UNIT + PBR_TEXTURES.len() as u32;
/// Texture unit of the split-sum table.
pub(crate) const UNIT_BRDF: u32 = UNIT_ENVIRONMENT + 1;
/// Texture unit of the frame's backdrop (transmission).
pub(crate) const UNIT_BACKDROP: u32 = UNIT_BRDF + 1;
/// Texture unit of the sheen's albedo table.
pub(crate) const UNIT_SHEEN_ALBEDO: u32 = UNIT_BACKDROP + 1;
/// The samplers the fragment shader reads, one per unit from 0 to [`UNIT_SHEEN_ALBEDO`]: 18,
/// more than the 16 OpenGL 3.3 guarantees (`GL_MAX_TEXTURE_IMAGE_UNITS`; llvmpipe and NVIDIA
/// offer 32). [`check_texture_units`] refuses a context with fewer.
pub(crate) const FRAGMENT_SAMPLERS: u32 = UNIT_SHEEN_ALBEDO + 1;

/// An error naming the shortfall when a context's fragment stage has fewer texture units
/// (`available`, its `GL_MAX_TEXTURE_IMAGE_UNITS`) than the PBR program's
/// [`FRAGMENT_SAMPLERS`].
pub(crate) fn check_texture_units(available: i32) -> Result<(), String> {
    if i64::from(available) < i64::from(FRAGMENT_SAMPLERS) {
        return Err(format!(
            "the PBR fragment shader reads {FRAGMENT_SAMPLERS} textures, the driver offers \
             {available} fragment texture units (GL_MAX_TEXTURE_IMAGE_UNITS)"
        ));
    }
    Ok(())
}

/// The vertex shader: the Lambert program's, plus the world position, the second texture
/// coordinate set and the world tangent (PbrShader's vertex stage) for the fragment shader.
pub(crate) const VERTEX: &str = r#"#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_texcoord;
layout(location = 3) in vec4 a_color;
layout(location = 4) in vec2 a_texcoord1;
layout(location = 5) in vec4 a_tangent;

// y-flipped projection × view × model (window row 0 = image row 0).
uniform mat4 u_model_view_projection;
// Inverse transpose of the model matrix's upper 3 × 3.
uniform mat3 u_normal_matrix;
// The draw's model matrix (world position).
uniform mat4 u_model;
// -1 where the model matrix mirrors (the tangent's bitangent sign flips), else 1.
uniform float u_tangent_sign;

out vec3 v_normal;
out vec2 v_texcoord;
out vec4 v_color;
out vec3 v_position;
out vec2 v_texcoord1;
out vec4 v_tangent;

void main() {
    gl_Position = u_model_view_projection * vec4(a_position, 1.0);
    v_normal = u_normal_matrix * a_normal;
    v_texcoord = a_texcoord;
    v_color = a_color;
    v_position = (u_model * vec4(a_position, 1.0)).xyz;
    v_texcoord1 = a_texcoord1;
    v_tangent = vec4(mat3(u_model) * a_tangent.xyz, a_tangent.w * u_tangent_sign);
}
"#;

/// The fragment shader after its constants (see [`fragment_source`]).
const FRAGMENT_BODY: &str = r#"
in vec3 v_normal;
in vec2 v_texcoord;
in vec4 v_color;
in vec3 v_position;
in vec2 v_texcoord1;
in vec4 v_tangent;

// The texture coordinate set (0 or 1) each texture reads, in the CPU shader's slot order:
// base colour, emissive, metallic-roughness, normal, occlusion, specular, specular colour,
// clear coat, clear-coat roughness, clear-coat normal, transmission, thickness, sheen colour,
// sheen roughness.
uniform int u_texcoord_set[TEXTURE_SLOTS];
// The set whose derivatives orient the tangent frame without mesh tangents.
uniform int u_frame_set;
// The mesh has tangents (else the derivative frame).
uniform bool u_has_tangents;


uniform vec4 u_base_color_factor;
uniform bool u_has_texture;
uniform sampler2D u_base_color_texture;
uniform vec3 u_emissive;        // linear emitted colour, added after lighting
uniform bool u_has_emissive_texture;
uniform sampler2D u_emissive_texture;
uniform bool u_unlit;
uniform int u_alpha_mode;      // 0 opaque, 1 mask, 2 blend
uniform float u_alpha_cutoff;
uniform bool u_double_sided;
uniform int u_pass;            // 0 colour, 1 normals, 2 ids
uniform vec2 u_ids;            // node index + 1, draw index + 1

uniform float u_metallic;
uniform float u_roughness;
uniform bool u_has_metallic_roughness_texture;
uniform sampler2D u_metallic_roughness_texture;
uniform bool u_has_normal_texture;
uniform sampler2D u_normal_texture;
uniform float u_normal_scale;
uniform bool u_has_occlusion_texture;
uniform sampler2D u_occlusion_texture;
uniform float u_occlusion_strength;
// KHR_materials_ior and KHR_materials_specular.
uniform vec3 u_dielectric_f0;
uniform float u_specular_weight;
uniform bool u_has_specular_texture;
uniform sampler2D u_specular_texture;
uniform bool u_has_specular_color_texture;
uniform sampler2D u_specular_color_texture;
// KHR_materials_clearcoat (u_clearcoat 0: no coat).
uniform float u_clearcoat;
uniform bool u_has_clearcoat_texture;
uniform sampler2D u_clearcoat_texture;
uniform float u_clearcoat_roughness;
uniform bool u_has_clearcoat_roughness_texture;
uniform sampler2D u_clearcoat_roughness_texture;
uniform bool u_has_clearcoat_normal_texture;
uniform sampler2D u_clearcoat_normal_texture;
uniform float u_clearcoat_normal_scale;
// KHR_materials_transmission and KHR_materials_volume (u_transmissive false: no transmission,
// or no backdrop in this frame).
uniform bool u_transmissive;
uniform float u_transmission;
uniform bool u_has_transmission_texture;
uniform sampler2D u_transmission_texture;
uniform float u_thickness;
uniform bool u_has_thickness_texture;
uniform sampler2D u_thickness_texture;
// transmission::Volume, computed on the host: 1 / ior, clamp(2 ior - 2, 0, 1), the model's
// scale per axis, Beer's law in base 2 per channel, the level of detail per unit of roughness.
uniform float u_eta;
uniform float u_ior_scale;
uniform vec3 u_volume_scale;
uniform vec3 u_attenuation;
uniform float u_lod_scale;
// transmission::TransmissionView: the backdrop's chain (RGB32F, row 0 at the top is t = 0,
// trilinear, clamped to the edge), its last level, and the frame's view-projection (unflipped).
uniform sampler2D u_backdrop;
uniform float u_backdrop_last_level;
uniform mat4 u_backdrop_view_projection;
// KHR_materials_sheen (u_sheen false: no sheen).
uniform bool u_sheen;
uniform vec3 u_sheen_color;
uniform bool u_has_sheen_color_texture;
uniform sampler2D u_sheen_color_texture;
uniform float u_sheen_roughness;
uniform bool u_has_sheen_roughness_texture;
uniform sampler2D u_sheen_roughness_texture;

// PbrLighting: the eye, the punctual lights (FrameLight, as u_punctual_*: u_light_color is
// the Lambert program's), exposure scale and tone map.
uniform vec3 u_eye;
uniform int u_punctual_count;
uniform vec3 u_punctual_color[MAX_LIGHTS];
uniform vec3 u_punctual_direction[MAX_LIGHTS];
uniform vec3 u_punctual_position[MAX_LIGHTS];
uniform bool u_punctual_directional[MAX_LIGHTS];
uniform float u_punctual_inverse_range_squared[MAX_LIGHTS];
uniform float u_punctual_cone_scale[MAX_LIGHTS];
uniform float u_punctual_cone_offset[MAX_LIGHTS];
uniform float u_exposure;
uniform int u_tonemap;         // 0 none, 1 PBR Neutral, 2 ACES

// EnvironmentLight.
uniform bool u_has_environment;
uniform float u_environment_intensity;
uniform vec2 u_environment_rotation;  // (sin, cos) of lookup_rotation()
uniform vec3 u_irradiance_sh[9];
uniform sampler2D u_environment;      // the levels, stacked (RGB32F, texelFetch only)
uniform int u_level_row[LEVELS];      // first atlas row of each level
uniform int u_level_size[LEVELS];     // each level's size without its border
uniform sampler2D u_brdf;             // split-sum (A, B), RG32F, texelFetch only
uniform sampler2D u_sheen_albedo;     // sheen::sheen_table, R32F, texelFetch only

layout(location = 0) out vec4 o_color;

bool is_finite(float x) {
    return !isnan(x) && !isinf(x);
}

float clamp01(float x) {
    return min(max(x, 0.0), 1.0);
}

float dot3(vec3 a, vec3 b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}

// pbr::normalize3: v / |v|, zero where |v| is zero or not finite.
vec3 normalize3(vec3 v) {
    float length2 = dot3(v, v);
    float rcp = 1.0 / sqrt(length2);
    bool usable = length2 > 0.0 && rcp > 0.0 && !isinf(rcp);
    return usable ? v * rcp : vec3(0.0);
}

// pbr::ggx_d_times_v.
float ggx_d_times_v(float alpha, float n_dot_l, float n_dot_v, float n_dot_h) {
    float a2 = alpha * alpha;
    float f = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
    float d = a2 / (PI * f * f);
    float ggx_v = n_dot_l * sqrt(n_dot_v * n_dot_v * (1.0 - a2) + a2);
    float ggx_l = n_dot_v * sqrt(n_dot_l * n_dot_l * (1.0 - a2) + a2);
    float denominator = ggx_v + ggx_l;
    float v = denominator > 0.0 ? 0.5 / denominator : 0.0;
    return d * v;
}

// pbr::schlick_weight.
float schlick_weight(float v_dot_h) {
    float m = 1.0 - v_dot_h;
    float m2 = m * m;
    return m2 * m2 * m;
}

// pbr::schlick.
vec3 schlick(vec3 f0, float f90, float v_dot_h) {
    return f0 + (f90 - f0) * schlick_weight(v_dot_h);
}

// pbr::coat_fresnel.
float coat_fresnel(float v_dot_h) {
    return DIELECTRIC_F0 + (1.0 - DIELECTRIC_F0) * schlick_weight(v_dot_h);
}

// pbr::Surface (less what the fragment shader reads directly) and pbr::Reflectance.
struct Surface {
    vec3 n;
    float roughness;
    float occlusion;
    vec3 position;
    vec3 c_diff;
    vec3 f0;
    float f90;
    bool coat;
    float coat_factor;
    float coat_roughness;
    vec3 coat_n;
    bool transmission;
    float transmission_factor;
    float thickness;
    bool sheen;
    vec3 sheen_color;
    float sheen_roughness;
};

// sheen::SheenTerms: what the sheen needs once per point.
struct SheenTerms {
    float alpha;
    float exponent;
    float albedo;
    float base_scale;
    float fit[5];
    float twice_at_half;
    float lambda_view;
};

// sheen::lambda_exponent: the fit's exponent a / (1 + b x^c) + d x + e for x in [0, 1]
// (x^c = 2^(c log2 x), x no smaller than the least normal float).
float lambda_exponent(float fit[5], float x) {
    x = max(x, FLT_MIN_NORMAL);
    float power = exp2(clamp(fit[2] * log2(x), -126.0, 0.0));
    return fit[0] / (1.0 + fit[1] * power) + fit[3] * x + fit[4];
}

// sheen::sheen_lambda: exp(L(cos)) below 1/2, exp(2 L(1/2) - L(1 - cos)) from there, with
// twice_at_half = 2 L(1/2); one evaluation of L.
float sheen_lambda(float fit[5], float twice_at_half, float cos_theta) {
    bool below_half = cos_theta < 0.5;
    float l = lambda_exponent(fit, below_half ? cos_theta : 1.0 - cos_theta);
    float exponent = below_half ? l : twice_at_half - l;
    return exp2(clamp(exponent * LOG2_E, -126.0, 127.0));
}

// sheen::charlie_v: 1 / ((1 + Lambda(NdotV) + Lambda(NdotL)) 4 NdotV NdotL), at most 1.
float charlie_v(SheenTerms t, float n_dot_l, float n_dot_v) {
    float lambda_light = sheen_lambda(t.fit, t.twice_at_half, n_dot_l);
    float denominator = (1.0 + t.lambda_view + lambda_light) * 4.0 * n_dot_v * n_dot_l;
    // 1 / 0 is infinite, and clamps to 1.
    return denominator > 0.0 ? min(1.0 / denominator, 1.0) : 1.0;
}

// sheen::charlie_d: (2 + 1/alpha) (1 - NdotH^2)^exponent / (2 pi).
float charlie_d(float alpha, float exponent, float n_dot_h) {
    float sin2 = max(1.0 - n_dot_h * n_dot_h, FLT_MIN_NORMAL);
    float power = exp2(clamp(exponent * log2(sin2), -126.0, 0.0));
    return (2.0 + 1.0 / alpha) * power * HALF_INV_PI;
}

// pbr::light_arrival: the unit vector towards light i and the attenuation.
void light_arrival(int i, vec3 position, out vec3 l, out float attenuation) {
    if (u_punctual_directional[i]) {
        l = u_punctual_direction[i];
        attenuation = 1.0;
        return;
    }
    vec3 d = u_punctual_position[i] - position;
    float distance2 = dot3(d, d);
    l = normalize3(d);
    float a = 1.0 / distance2;
    if (u_punctual_inverse_range_squared[i] > 0.0) {
        float ratio2 = distance2 * u_punctual_inverse_range_squared[i];
        a = a * clamp01(1.0 - ratio2 * ratio2);
    }
    if (u_punctual_cone_scale[i] > 0.0) {
        vec3 axis = u_punctual_direction[i];
        float cos_angle = -(l.x * axis.x + l.y * axis.y + l.z * axis.z);
        float cone = clamp01(cos_angle * u_punctual_cone_scale[i] + u_punctual_cone_offset[i]);
        a = a * cone * cone;
    }
    // A surface at the light's position receives nothing (not infinity).
    attenuation = is_finite(a) ? a : 0.0;
}

// transmission::attenuate: `light` after travelling along `path` inside the volume.
vec3 attenuate(vec3 light, vec3 path) {
    if (u_attenuation == vec3(0.0)) {
        return light;
    }
    float distance = sqrt(dot3(path, path));
    vec3 out_ = light;
    for (int c = 0; c < 3; c++) {
        if (u_attenuation[c] > 0.0) {
            out_[c] = light[c] * exp2(clamp(-(u_attenuation[c] * distance), -126.0, 0.0));
        }
    }
    return out_;
}

// pbr::punctual_transmission: the light of light i that the surface lets through towards
// `view`, its falloff taken where the refracted view ray leaves the volume (`path`).
vec3 punctual_transmission(int i, Surface s, vec3 view, float alpha, vec3 path) {
    vec3 n = s.n;
    vec3 exit_ = s.position + path;
    vec3 l;
    float attenuation;
    light_arrival(i, exit_, l, attenuation);
    // The light's direction mirrored in the surface's plane: L - 2 (N.L) N.
    float n_dot_l = dot3(n, l);
    float twice = n_dot_l + n_dot_l;
    vec3 mirrored = normalize3(l - twice * n);
    vec3 h = normalize3(view + mirrored);
    float n_dot_m = clamp01(dot3(n, mirrored));
    float n_dot_v = clamp01(dot3(n, view));
    float n_dot_h = clamp01(dot3(n, h));
    float v_dot_h = clamp01(dot3(view, h));
    float alpha_t = max(alpha * u_ior_scale, TRANSMISSION_ALPHA_FLOOR);
    float dv = ggx_d_times_v(alpha_t, n_dot_m, n_dot_v, n_dot_h);
    vec3 f = schlick(s.f0, s.f90, v_dot_h);
    float weight = attenuation * n_dot_m * dv * s.transmission_factor;
    vec3 through = u_punctual_color[i] * weight * (1.0 - f) * s.c_diff;
    return attenuate(through, path);
}

// pbr::punctual: light i on the surface, on its coat (into `coat`) and on its sheen (into
// `sheen_out`, with the point's terms `sheen`); `path` is the refracted path through a
// transmissive surface's volume.
vec3 punctual(
    int i, Surface s, vec3 view, float alpha, vec3 path, SheenTerms sheen, out vec3 coat,
    out vec3 sheen_out
) {
    vec3 l;
    float attenuation;
    light_arrival(i, s.position, l, attenuation);
    vec3 n = s.n;
    vec3 h = normalize3(view + l);
    float n_dot_l = clamp01(dot3(n, l));
    float n_dot_v = clamp01(dot3(n, view));
    float n_dot_h = clamp01(dot3(n, h));
    float v_dot_h = clamp01(dot3(view, h));
    vec3 f = schlick(s.f0, s.f90, v_dot_h);
    float dv = ggx_d_times_v(alpha, n_dot_l, n_dot_v, n_dot_h);
    float scale = attenuation * n_dot_l;
    vec3 brdf;
    vec3 through = vec3(0.0);
    if (s.transmission) {
        // Transmission takes its part of the diffuse light, and adds the light from behind.
        through = punctual_transmission(i, s, view, alpha, path);
        float kept = 1.0 - s.transmission_factor;
        brdf = (1.0 - f) * s.c_diff * INV_PI * kept + f * dv;
    } else {
        brdf = (1.0 - f) * s.c_diff * INV_PI + f * dv;
    }
    coat = vec3(0.0);
    if (s.coat) {
        vec3 nc = s.coat_n;
        float c_n_dot_l = clamp01(dot3(nc, l));
        float c_n_dot_v = clamp01(dot3(nc, view));
        float c_n_dot_h = clamp01(dot3(nc, h));
        float clamped = max(s.coat_roughness, MIN_PUNCTUAL_ROUGHNESS);
        float c_dv = ggx_d_times_v(clamped * clamped, c_n_dot_l, c_n_dot_v, c_n_dot_h);
        float lobe = attenuation * c_n_dot_l * coat_fresnel(v_dot_h) * c_dv;
        coat = u_punctual_color[i] * lobe;
    }
    sheen_out = vec3(0.0);
    if (s.sheen) {
        float d = charlie_d(sheen.alpha, sheen.exponent, n_dot_h);
        float lobe = scale * d * charlie_v(sheen, n_dot_l, n_dot_v);
        sheen_out = u_punctual_color[i] * lobe * s.sheen_color;
    }
    if (s.transmission) {
        return u_punctual_color[i] * scale * brdf + through;
    }
    return u_punctual_color[i] * scale * brdf;
}

// EnvironmentLight::irradiance_lanes: irradiance / pi at the unit normal n.
vec3 irradiance(vec3 n) {
    float s = u_environment_rotation.x;
    float c = u_environment_rotation.y;
    float x = c * n.x + s * n.z;
    float y = n.y;
    float z = c * n.z - s * n.x;
    float basis[9] = float[9](
        SH_Y0,
        SH_Y1 * y,
        SH_Y1 * z,
        SH_Y1 * x,
        SH_Y2 * x * y,
        SH_Y2 * y * z,
        SH_Y20 * (3.0 * z * z - 1.0),
        SH_Y2 * x * z,
        SH_Y22 * (x * x - y * y)
    );
    vec3 sum = vec3(0.0);
    for (int i = 0; i < 9; i++) {
        sum = sum + u_irradiance_sh[i] * basis[i];
    }
    return max(sum, vec3(0.0));
}

float sign_of(float v) {
    return v >= 0.0 ? 1.0 : -1.0;
}

// environment::octahedral_encode.
vec2 octahedral_encode(vec3 d) {
    float sum = abs(d.x) + abs(d.y) + abs(d.z);
    vec2 p = sum > 0.0 ? vec2(d.x / sum, d.y / sum) : vec2(0.0);
    if (d.z < 0.0) {
        p = vec2((1.0 - abs(p.y)) * sign_of(p.x), (1.0 - abs(p.x)) * sign_of(p.y));
    }
    return p * 0.5 + 0.5;
}

vec3 level_texel(int level, int x, int y) {
    return texelFetch(u_environment, ivec2(x, u_level_row[level] + y), 0).rgb;
}

// OctahedralLevel::sample: bilinear inside level `level` at unit direction d.
vec3 level_sample(int level, vec3 d) {
    vec2 uv = octahedral_encode(d);
    float size = float(u_level_size[level]);
    // Texel centre i sits at (i + 0.5) / size; the border shifts indices by one.
    float x = clamp(uv.x * size + 0.5, 0.0, size + 1.0);
    float y = clamp(uv.y * size + 0.5, 0.0, size + 1.0);
    float x0f = floor(x);
    float y0f = floor(y);
    float fx = x - x0f;
    float fy = y - y0f;
    int stride = u_level_size[level] + 2;
    int x0 = int(x0f);
    int y0 = int(y0f);
    int x1 = min(x0 + 1, stride - 1);
    int y1 = min(y0 + 1, stride - 1);
    vec3 t00 = level_texel(level, x0, y0);
    vec3 t10 = level_texel(level, x1, y0);
    vec3 t01 = level_texel(level, x0, y1);
    vec3 t11 = level_texel(level, x1, y1);
    vec3 top = t00 + (t10 - t00) * fx;
    vec3 bottom = t01 + (t11 - t01) * fx;
    return top + (bottom - top) * fy;
}

// EnvironmentLight::specular: pre-filtered radiance along r (need not be unit).
vec3 specular(vec3 r, float roughness) {
    float s = u_environment_rotation.x;
    float c = u_environment_rotation.y;
    vec3 d = normalize3(vec3(c * r.x + s * r.z, r.y, -s * r.x + c * r.z));
    float last = float(LEVELS - 1);
    float lod = is_finite(roughness) ? clamp(roughness * last, 0.0, last) : last;
    float level = floor(lod);
    float t = lod - level;
    int k = int(level);
    vec3 lo = level_sample(k, d);
    if (t == 0.0) {
        return lo;
    }
    vec3 hi = level_sample(min(k + 1, LEVELS - 1), d);
    return lo + (hi - lo) * t;
}

float brdf_coordinate(float v) {
    float n = float(BRDF_TABLE_SIZE);
    v = is_finite(v) ? v : 1.0;
    return clamp(v * n - 0.5, 0.0, n - 1.0);
}

// environment::pair_table_lanes: two values read bilinearly from `table`, BRDF_TABLE_SIZE²
// cells (x: NdotV, y: roughness), clamped to its cell centres.
vec2 pair_table(sampler2D table, float n_dot_v, float roughness) {
    float x = brdf_coordinate(n_dot_v);
    float y = brdf_coordinate(roughness);
    float x0f = floor(x);
    float y0f = floor(y);
    float fx = x - x0f;
    float fy = y - y0f;
    int x0 = int(x0f);
    int y0 = int(y0f);
    int x1 = min(x0 + 1, BRDF_TABLE_SIZE - 1);
    int y1 = min(y0 + 1, BRDF_TABLE_SIZE - 1);
    vec2 t00 = texelFetch(table, ivec2(x0, y0), 0).rg;
    vec2 t10 = texelFetch(table, ivec2(x1, y0), 0).rg;
    vec2 t01 = texelFetch(table, ivec2(x0, y1), 0).rg;
    vec2 t11 = texelFetch(table, ivec2(x1, y1), 0).rg;
    vec2 top = t00 + (t10 - t00) * fx;
    vec2 bottom = t01 + (t11 - t01) * fx;
    return top + (bottom - top) * fy;
}

// environment::brdf_ab: (A, B) read bilinearly from the split-sum table.
vec2 brdf_ab(float n_dot_v, float roughness) {
    return pair_table(u_brdf, n_dot_v, roughness);
}

// sheen::sheen_albedo_lanes: E(NdotV, roughness) read bilinearly from the sheen's table.
float sheen_albedo(float n_dot_v, float roughness) {
    return pair_table(u_sheen_albedo, n_dot_v, roughness).x;
}

// sheen::SheenLayer::terms at n_dot_v (clamped to [0, 1]).
SheenTerms sheen_terms(Surface s, float n_dot_v) {
    float roughness = min(max(s.sheen_roughness, MIN_PUNCTUAL_ROUGHNESS), 1.0);
    SheenTerms t;
    t.alpha = roughness * roughness;
    t.albedo = sheen_albedo(n_dot_v, roughness);
    float brightest = max(max(s.sheen_color.r, s.sheen_color.g), s.sheen_color.b);
    // sheen::lambda_fit: each coefficient mixed by (1 - alpha)^2.
    float one_minus = 1.0 - t.alpha;
    float mixing = one_minus * one_minus;
    for (int k = 0; k < 5; k++) {
        t.fit[k] = LAMBDA_AT_ONE[k] + (LAMBDA_AT_ZERO[k] - LAMBDA_AT_ONE[k]) * mixing;
    }
    t.exponent = 0.5 / t.alpha;
    t.base_scale = max(1.0 - brightest * t.albedo, 0.0);
    float at_half = lambda_exponent(t.fit, 0.5);
    t.twice_at_half = at_half + at_half;
    t.lambda_view = sheen_lambda(t.fit, t.twice_at_half, n_dot_v);
    return t;
}

// Terms of a point without a sheen (never read).
SheenTerms no_sheen() {
    SheenTerms t;
    t.alpha = 1.0;
    t.exponent = 0.5;
    t.albedo = 0.0;
    t.base_scale = 1.0;
    for (int k = 0; k < 5; k++) {
        t.fit[k] = 0.0;
    }
    t.twice_at_half = 0.0;
    t.lambda_view = 0.0;
    return t;
}

// pbr::image_based, one lobe: the pre-filtered radiance along the reflection about n and the
// split-sum terms (A, B).
void environment_lobe(vec3 n, vec3 view, float roughness, out vec3 radiance, out vec2 ab) {
    float n_dot_v_raw = dot3(n, view);
    float n_dot_v = clamp01(n_dot_v_raw);
    // R = 2 (N.V) N - V.
    float two_n_dot_v = n_dot_v_raw + n_dot_v_raw;
    vec3 reflected = two_n_dot_v * n - view;
    radiance = specular(reflected, roughness);
    ab = brdf_ab(n_dot_v, roughness);
}

// pbr::image_based: the light under the coat, the coat's (into `coat`) and the sheen's (into
// `sheen_out`, with the point's terms `sheen`).
vec3 image_based(Surface s, vec3 view, SheenTerms sheen, out vec3 coat, out vec3 sheen_out) {
    vec3 specular_;
    vec2 ab;
    environment_lobe(s.n, view, s.roughness, specular_, ab);
    vec3 irradiance_ = irradiance(s.n);
    float weight = s.occlusion * u_environment_intensity;
    vec3 fss_ess = s.f0 * ab.x + s.f90 * ab.y;
    vec3 diffuse = irradiance_ * s.c_diff * (1.0 - fss_ess);
    if (s.transmission) {
        diffuse = diffuse * (1.0 - s.transmission_factor);
    }
    coat = vec3(0.0);
    if (s.coat) {
        vec3 coat_specular;
        vec2 coat_ab;
        environment_lobe(s.coat_n, view, s.coat_roughness, coat_specular, coat_ab);
        float coat_fss_ess = DIELECTRIC_F0 * coat_ab.x + coat_ab.y;
        coat = coat_specular * coat_fss_ess * weight;
    }
    sheen_out = vec3(0.0);
    if (s.sheen) {
        // The pre-filtered radiance along R = 2 (N.V) N - V at the sheen's roughness.
        float n_dot_v_raw = dot3(s.n, view);
        float two_n_dot_v = n_dot_v_raw + n_dot_v_raw;
        vec3 sheen_specular = specular(two_n_dot_v * s.n - view, s.sheen_roughness);
        float scale = sheen.albedo * weight;
        sheen_out = sheen_specular * s.sheen_color * scale;
    }
    return (diffuse + specular_ * fss_ess) * weight;
}

// transmission::refraction_path: the view ray refracted at n by 1 / ior (GLSL's refract of
// -view; total internal reflection gives no path), normalised, times the thickness and the
// draw's scale per axis. Zero for a thin wall.
vec3 refraction_path(Surface s, vec3 view) {
    vec3 n = s.n;
    float eta = u_eta;
    // i = -view; k = 1 - eta^2 (1 - (n.i)^2); t = eta i - (eta (n.i) + sqrt(k)) n.
    float n_dot_i = -dot3(n, view);
    float k = 1.0 - eta * eta * (1.0 - n_dot_i * n_dot_i);
    float along_n = eta * n_dot_i + sqrt(max(k, 0.0));
    vec3 t = normalize3(-(eta * view) - along_n * n);
    vec3 length_ = s.thickness * u_volume_scale;
    return k >= 0.0 ? t * length_ : vec3(0.0);
}

// transmission::backdrop_uv: where world point p lies in the backdrop, (u, v) from 0 to 1 left
// to right and top to bottom (the texture's s and t: its row 0 is the top).
vec2 backdrop_uv(vec3 p) {
    mat4 m = u_backdrop_view_projection;
    float x = m[0][0] * p.x + m[1][0] * p.y + m[2][0] * p.z + m[3][0];
    float y = m[0][1] * p.x + m[1][1] * p.y + m[2][1] * p.z + m[3][1];
    float w = m[0][3] * p.x + m[1][3] * p.y + m[2][3] * p.z + m[3][3];
    w = max(w, 1e-6);
    return vec2(0.5 + 0.5 * (x / w), 0.5 - 0.5 * (y / w));
}

// transmission::transmitted_light: the backdrop where the refracted view ray leaves the
// volume, blurred for the roughness, dimmed along the path.
vec3 transmitted_light(Surface s, vec3 path) {
    vec2 uv = backdrop_uv(s.position + path);
    float lod = s.roughness * u_lod_scale;
    lod = is_finite(lod) ? clamp(lod, 0.0, u_backdrop_last_level) : 0.0;
    vec3 light = textureLod(u_backdrop, uv, lod).rgb;
    return attenuate(light, path);
}

// pbr::shade: the linear colour before exposure and tone mapping, emission, sheen and coat
// included.
vec3 shade(Surface s, vec3 emissive) {
    vec3 view = normalize3(u_eye - s.position);
    float clamped = max(s.roughness, MIN_PUNCTUAL_ROUGHNESS);
    float alpha = clamped * clamped;
    vec3 color = vec3(0.0);
    vec3 coat_color = vec3(0.0);
    vec3 sheen_color = vec3(0.0);
    vec3 path = s.transmission ? refraction_path(s, view) : vec3(0.0);
    SheenTerms sheen = no_sheen();
    if (s.sheen) {
        sheen = sheen_terms(s, clamp01(dot3(s.n, view)));
    }
    for (int i = 0; i < u_punctual_count; i++) {
        vec3 coat;
        vec3 sheen_light;
        color = color + punctual(i, s, view, alpha, path, sheen, coat, sheen_light);
        coat_color = coat_color + coat;
        sheen_color = sheen_color + sheen_light;
    }
    if (u_has_environment) {
        vec3 coat;
        vec3 sheen_light;
        color = color + image_based(s, view, sheen, coat, sheen_light);
        coat_color = coat_color + coat;
        sheen_color = sheen_color + sheen_light;
    }
    if (s.transmission) {
        // The backdrop replaces the part `transmission_factor` of the dielectric's diffuse
        // light, with the same room left by the specular reflection.
        vec3 light = transmitted_light(s, path);
        float n_dot_v = clamp01(dot3(s.n, view));
        vec2 ab = brdf_ab(n_dot_v, s.roughness);
        vec3 fss_ess = s.f0 * ab.x + s.f90 * ab.y;
        color = color + s.transmission_factor * s.c_diff * (1.0 - fss_ess) * light;
    }
    if (s.sheen) {
        // The layer keeps 1 - max(sheenColor) E(NdotV) of the base, and adds its own lobes.
        color = color * sheen.base_scale + sheen_color;
    }
    color = color + emissive;
    if (s.coat) {
        float under = 1.0 - s.coat_factor * coat_fresnel(clamp01(dot3(s.coat_n, view)));
        color = color * under + s.coat_factor * coat_color;
    }
    return color;
}

// The texture coordinates of the texture in slot k (u_texcoord_set).
vec2 uv(int k) {
    return u_texcoord_set[k] == 1 ? v_texcoord1 : v_texcoord;
}

// The tangent frame (t, b) around ng from t_ (orthonormal_frame): t = normalize(t_ - ng (ng.t_)),
// b = ng x t, negated where flip.
void orthonormal_frame(vec3 ng, vec3 t_, bool flip, out vec3 t, out vec3 b) {
    t = normalize3(t_ - ng * dot3(ng, t_));
    b = cross(ng, t);
    if (flip) {
        b = -b;
    }
}

// The normal texture's texel bent into the tangent frame (t, b) around ng (PbrShader's bend).
vec3 bend(vec3 t, vec3 b, vec3 ng, vec4 texel, float scale) {
    vec3 m = texel.rgb * 2.0 - 1.0;
    m.x = m.x * scale;
    m.y = m.y * scale;
    vec3 bent = normalize3(t * m.x + b * m.y + ng * m.z);
    return bent != vec3(0.0) ? bent : ng;
}

// pbr::pbr_neutral (Khronos PBR Neutral).
vec3 pbr_neutral(vec3 rgb) {
    float x = min(rgb.r, min(rgb.g, rgb.b));
    float toe = x - 6.25 * x * x;
    float toe_offset = x < 0.08 ? toe : 0.04;
    vec3 c = rgb - toe_offset;
    float peak = max(c.r, max(c.g, c.b));
    float d = 1.0 - START_COMPRESSION;
    float new_peak = 1.0 - (d * d) / (peak + (d - START_COMPRESSION));
    float ratio = new_peak / peak;
    float g = 1.0 - 1.0 / (DESATURATION * (peak - new_peak) + 1.0);
    vec3 scaled = c * ratio;
    vec3 mixed = scaled + (new_peak - scaled) * g;
    return peak >= START_COMPRESSION ? mixed : c;
}

float aces(float x) {
    x = max(x, 0.0);
    float num = x * (2.51 * x + 0.03);
    float den = x * (2.43 * x + 0.59) + 0.14;
    return clamp01(num / den);
}

// pbr::tonemap: exposure, then the tone map.
vec3 tonemap(vec3 rgb) {
    rgb = rgb * u_exposure;
    if (u_tonemap == 1) {
        return pbr_neutral(rgb);
    }
    if (u_tonemap == 2) {
        return vec3(aces(rgb.r), aces(rgb.g), aces(rgb.b));
    }
    return rgb;
}

void main() {
    // Every texture and derivative is read here, in uniform control flow, before any discard.
    // Texels are kantele's 8-bit mip chains (SRGB8_ALPHA8 or RGBA8), decoded to linear by GL.
    vec4 base = u_base_color_factor * v_color;
    if (u_has_texture) {
        base *= texture(u_base_color_texture, uv(0));
    }
    vec4 metallic_roughness = vec4(1.0);
    if (u_has_metallic_roughness_texture) {
        metallic_roughness = texture(u_metallic_roughness_texture, uv(2));
    }
    vec4 occlusion_texel = vec4(1.0);
    if (u_has_occlusion_texture) {
        occlusion_texel = texture(u_occlusion_texture, uv(4));
    }
    vec4 normal_texel = vec4(0.5, 0.5, 1.0, 1.0);
    if (u_has_normal_texture) {
        normal_texel = texture(u_normal_texture, uv(3));
    }
    vec3 emissive = u_emissive;
    if (u_has_emissive_texture) {
        emissive *= texture(u_emissive_texture, uv(1)).rgb;
    }
    vec4 specular_texel = vec4(1.0);
    if (u_has_specular_texture) {
        specular_texel = texture(u_specular_texture, uv(5));
    }
    vec4 specular_color_texel = vec4(1.0);
    if (u_has_specular_color_texture) {
        specular_color_texel = texture(u_specular_color_texture, uv(6));
    }
    vec4 clearcoat_texel = vec4(1.0);
    if (u_has_clearcoat_texture) {
        clearcoat_texel = texture(u_clearcoat_texture, uv(7));
    }
    vec4 clearcoat_roughness_texel = vec4(1.0);
    if (u_has_clearcoat_roughness_texture) {
        clearcoat_roughness_texel = texture(u_clearcoat_roughness_texture, uv(8));
    }
    vec4 clearcoat_normal_texel = vec4(0.5, 0.5, 1.0, 1.0);
    if (u_has_clearcoat_normal_texture) {
        clearcoat_normal_texel = texture(u_clearcoat_normal_texture, uv(9));
    }
    vec4 transmission_texel = vec4(1.0);
    if (u_has_transmission_texture) {
        transmission_texel = texture(u_transmission_texture, uv(10));
    }
    vec4 thickness_texel = vec4(1.0);
    if (u_has_thickness_texture) {
        thickness_texel = texture(u_thickness_texture, uv(11));
    }
    vec4 sheen_color_texel = vec4(1.0);
    if (u_has_sheen_color_texture) {
        sheen_color_texel = texture(u_sheen_color_texture, uv(12));
    }
    vec4 sheen_roughness_texel = vec4(1.0);
    if (u_has_sheen_roughness_texture) {
        sheen_roughness_texel = texture(u_sheen_roughness_texture, uv(13));
    }
    // The projection is y-flipped (window row 0 = image row 0), so dFdy is the derivative
    // towards increasing image row, as the CPU's.
    vec3 dp_dx = dFdx(v_position);
    vec3 dp_dy = dFdy(v_position);
    vec2 frame_uv = u_frame_set == 1 ? v_texcoord1 : v_texcoord;
    vec2 duv_dx = dFdx(frame_uv);
    vec2 duv_dy = dFdy(frame_uv);

    if (u_alpha_mode == 1 && base.a < u_alpha_cutoff) {
        discard;
    }

    float metallic = u_metallic;
    float roughness = u_roughness;
    if (u_has_metallic_roughness_texture) {
        metallic = u_metallic * metallic_roughness.b;
        roughness = u_roughness * metallic_roughness.g;
    }
    metallic = clamp(metallic, 0.0, 1.0);
    roughness = clamp(roughness, 0.0, 1.0);
    float occlusion = 1.0;
    if (u_has_occlusion_texture) {
        occlusion = 1.0 + u_occlusion_strength * (occlusion_texel.r - 1.0);
    }

    vec3 ng = normalize3(v_normal);
    vec3 n = ng;
    bool coat = u_clearcoat > 0.0;
    vec3 coat_n = ng;
    if (u_has_normal_texture || (coat && u_has_clearcoat_normal_texture)) {
        vec3 t;
        vec3 b;
        if (u_has_tangents) {
            // The mesh's tangent, its bitangent sign in w.
            orthonormal_frame(ng, v_tangent.xyz, v_tangent.w < 0.0, t, b);
        } else {
            // The tangent from the screen-space derivatives of position and texture
            // coordinate.
            float du_dx = duv_dx.x;
            float dv_dx = duv_dx.y;
            float du_dy = duv_dy.x;
            float dv_dy = duv_dy.y;
            float det = du_dx * dv_dy - du_dy * dv_dx;
            vec3 t_ = (dv_dy * dp_dx - dv_dx * dp_dy) / det;
            // Mirrored texture coordinates (the mapping turns the other way on screen than on
            // a face seen from its front) flip the bitangent.
            orthonormal_frame(ng, t_, (det < 0.0) != !gl_FrontFacing, t, b);
        }
        // A degenerate frame (t zero or not finite) keeps the geometric normal.
        if (t != vec3(0.0)) {
            if (u_has_normal_texture) {
                n = bend(t, b, ng, normal_texel, u_normal_scale);
            }
            if (coat && u_has_clearcoat_normal_texture) {
                coat_n = bend(t, b, ng, clearcoat_normal_texel, u_clearcoat_normal_scale);
            }
        }
    }
    // The projection is y-flipped and glFrontFace is GL_CW, so gl_FrontFacing keeps its meaning:
    // true for triangles counter-clockwise in (unflipped) NDC.
    if (u_double_sided && !gl_FrontFacing) {
        n = -n;
        coat_n = -coat_n;
    }
    if (u_pass == 1) {
        o_color = vec4(n, 1.0);
        return;
    }
    if (u_pass == 2) {
        o_color = vec4(u_ids.x, float(gl_PrimitiveID + 1), u_ids.y, 1.0);
        return;
    }
    vec3 rgb;
    if (u_unlit) {
        rgb = base.rgb + emissive;
    } else {
        Surface s;
        s.n = n;
        s.roughness = roughness;
        s.occlusion = occlusion;
        s.position = v_position;
        // pbr::reflectance, with KHR_materials_ior and KHR_materials_specular.
        vec3 dielectric_f0 = u_dielectric_f0;
        if (u_has_specular_color_texture) {
            dielectric_f0 = dielectric_f0 * specular_color_texel.rgb;
        }
        dielectric_f0 = min(dielectric_f0, vec3(1.0));
        float w = u_specular_weight;
        if (u_has_specular_texture) {
            w = w * specular_texel.a;
        }
        w = clamp01(w);
        s.c_diff = base.rgb * (1.0 - metallic);
        vec3 weighted = dielectric_f0 * w;
        s.f0 = weighted + (base.rgb - weighted) * metallic;
        s.f90 = w + (1.0 - w) * metallic;
        s.coat = coat;
        float coat_factor = u_clearcoat;
        if (u_has_clearcoat_texture) {
            coat_factor = coat_factor * clearcoat_texel.r;
        }
        float coat_roughness = u_clearcoat_roughness;
        if (u_has_clearcoat_roughness_texture) {
            coat_roughness = coat_roughness * clearcoat_roughness_texel.g;
        }
        s.coat_factor = clamp01(coat_factor);
        s.coat_roughness = clamp01(coat_roughness);
        s.coat_n = coat_n;
        s.transmission = u_transmissive;
        float transmission = u_transmission;
        if (u_has_transmission_texture) {
            transmission = transmission * transmission_texel.r;
        }
        float thickness = u_thickness;
        if (u_has_thickness_texture) {
            thickness = thickness * thickness_texel.g;
        }
        s.transmission_factor = clamp01(transmission);
        s.thickness = max(thickness, 0.0);
        // KHR_materials_sheen: the colour times the sRGB texture's RGB, the roughness times
        // the linear texture's alpha, both clamped to [0, 1].
        s.sheen = u_sheen;
        vec3 sheen_color = u_sheen_color;
        if (u_has_sheen_color_texture) {
            sheen_color = sheen_color * sheen_color_texel.rgb;
        }
        float sheen_roughness = u_sheen_roughness;
        if (u_has_sheen_roughness_texture) {
            sheen_roughness = sheen_roughness * sheen_roughness_texel.a;
        }
        s.sheen_color = vec3(
            clamp01(sheen_color.r),
            clamp01(sheen_color.g),
            clamp01(sheen_color.b)
        );
        s.sheen_roughness = clamp01(sheen_roughness);
        rgb = shade(s, emissive);
    }
    rgb = tonemap(rgb);
    float a = u_alpha_mode == 2 ? base.a : 1.0;
    o_color = vec4(rgb, a);
}
"#;

/// The fragment shader: the rules' constants (formatted from `kantele_rules`, so each is written
/// once), then the shading.
pub(crate) fn fragment_source() -> String {
    // Debug formatting of an f32 is the shortest decimal that reads back as the same f32.
    let float = |name: &str, value: f32| format!("const float {name} = {value:?};\n");
    let int = |name: &str, value: usize| format!("const int {name} = {value};\n");
    let mut source = String::from("#version 330 core\n");
    source += &int("MAX_LIGHTS", MAX_LIGHTS);
    source += &int("LEVELS", SPECULAR_LEVELS);
    source += &int("BRDF_TABLE_SIZE", BRDF_TABLE_SIZE);
    source += &int("TEXTURE_SLOTS", TEXTURE_SLOTS);
    source += &float("PI", std::f32::consts::PI);
    source += &float("INV_PI", std::f32::consts::FRAC_1_PI);
    source += &float("DIELECTRIC_F0", DIELECTRIC_F0);
    source += &float("MIN_PUNCTUAL_ROUGHNESS", MIN_PUNCTUAL_ROUGHNESS);
    // The transmitted lobe's narrowest alpha (pbr::punctual_transmission).
    source += &float(
        "TRANSMISSION_ALPHA_FLOOR",
        MIN_PUNCTUAL_ROUGHNESS * MIN_PUNCTUAL_ROUGHNESS,
    );
    source += &float("START_COMPRESSION", PBR_NEUTRAL_START_COMPRESSION);
    source += &float("DESATURATION", PBR_NEUTRAL_DESATURATION);
    // Spherical harmonics of bands 0–2.
    source += &float("SH_Y0", SH_Y0);
    source += &float("SH_Y1", SH_Y1);
    source += &float("SH_Y2", SH_Y2);
    source += &float("SH_Y20", SH_Y20);
    source += &float("SH_Y22", SH_Y22);
    // The sheen (sheen.rs): the least normal float, log2(e), 1 / (2 pi) and the fit of Lambda.
    source += &float("FLT_MIN_NORMAL", f32::MIN_POSITIVE);
    source += &float("LOG2_E", std::f32::consts::LOG2_E);
    source += &float("HALF_INV_PI", 0.5 / std::f32::consts::PI);
    let floats = |name: &str, values: [f32; 5]| {
        let values: Vec<String> = values.iter().map(|v| format!("{v:?}")).collect();
        format!("const float {name}[5] = float[5]({});\n", values.join(", "))
    };
    source += &floats("LAMBDA_AT_ONE", LAMBDA_FIT.map(|[at_one, _]| at_one));
    source += &floats("LAMBDA_AT_ZERO", LAMBDA_FIT.map(|[_, at_zero]| at_zero));
    source += FRAGMENT_BODY;
    source
}

/// `u_tonemap`'s value for a tone map.
fn tonemap_index(tonemap: Tonemap) -> i32 {
    match tonemap {
        Tonemap::None => 0,
        Tonemap::PbrNeutral => 1,
        Tonemap::Aces => 2,
    }
}

/// Uniform locations of the PBR program.
pub(crate) struct PbrUniforms {
    /// The uniforms it shares with the Lambert program (the Lambert light and ambient are
    /// `None`).
    pub(crate) common: Uniforms,
    pub(crate) model: Option<glow::UniformLocation>,
    pub(crate) metallic: Option<glow::UniformLocation>,
    pub(crate) roughness: Option<glow::UniformLocation>,
    /// The `u_has_*` flag and the sampler of each of [`PBR_TEXTURES`].
    pub(crate) textures: [[Option<glow::UniformLocation>; 2]; PBR_TEXTURES.len()],
    pub(crate) normal_scale: Option<glow::UniformLocation>,
    pub(crate) occlusion_strength: Option<glow::UniformLocation>,
    pub(crate) dielectric_f0: Option<glow::UniformLocation>,
    pub(crate) specular_weight: Option<glow::UniformLocation>,
    pub(crate) clearcoat: Option<glow::UniformLocation>,
    pub(crate) clearcoat_roughness: Option<glow::UniformLocation>,
    pub(crate) clearcoat_normal_scale: Option<glow::UniformLocation>,
    pub(crate) transmissive: Option<glow::UniformLocation>,
    pub(crate) transmission: Option<glow::UniformLocation>,
    pub(crate) thickness: Option<glow::UniformLocation>,
    pub(crate) eta: Option<glow::UniformLocation>,
    pub(crate) ior_scale: Option<glow::UniformLocation>,
    pub(crate) volume_scale: Option<glow::UniformLocation>,
    pub(crate) attenuation: Option<glow::UniformLocation>,
    pub(crate) lod_scale: Option<glow::UniformLocation>,
    pub(crate) backdrop: Option<glow::UniformLocation>,
    pub(crate) backdrop_last_level: Option<glow::UniformLocation>,
    pub(crate) backdrop_view_projection: Option<glow::UniformLocation>,
    pub(crate) sheen: Option<glow::UniformLocation>,
    pub(crate) sheen_color: Option<glow::UniformLocation>,
    pub(crate) sheen_roughness: Option<glow::UniformLocation>,
    pub(crate) tangent_sign: Option<glow::UniformLocation>,
    pub(crate) texcoord_sets: Option<glow::UniformLocation>,
    pub(crate) frame_set: Option<glow::UniformLocation>,
    pub(crate) has_tangents: Option<glow::UniformLocation>,
    pub(crate) eye: Option<glow::UniformLocation>,
    pub(crate) light_count: Option<glow::UniformLocation>,
    pub(crate) light_color: Option<glow::UniformLocation>,
    pub(crate) light_direction: Option<glow::UniformLocation>,
    pub(crate) light_position: Option<glow::UniformLocation>,
    pub(crate) light_directional: Option<glow::UniformLocation>,
    pub(crate) light_inverse_range_squared: Option<glow::UniformLocation>,
    pub(crate) light_cone_scale: Option<glow::UniformLocation>,
    pub(crate) light_cone_offset: Option<glow::UniformLocation>,
    pub(crate) exposure: Option<glow::UniformLocation>,
    pub(crate) tonemap: Option<glow::UniformLocation>,
    pub(crate) has_environment: Option<glow::UniformLocation>,
    pub(crate) environment_intensity: Option<glow::UniformLocation>,
    pub(crate) environment_rotation: Option<glow::UniformLocation>,
    pub(crate) irradiance_sh: Option<glow::UniformLocation>,
    pub(crate) environment: Option<glow::UniformLocation>,
    pub(crate) level_row: Option<glow::UniformLocation>,
    pub(crate) level_size: Option<glow::UniformLocation>,
    pub(crate) brdf: Option<glow::UniformLocation>,
    pub(crate) sheen_albedo: Option<glow::UniformLocation>,
}

/// Looks up every uniform of the PBR program.
///
/// # Safety
/// `gl` must be current on this thread and `program` the linked PBR program of it.
pub(crate) unsafe fn pbr_uniforms(gl: &glow::Context, program: glow::Program) -> PbrUniforms {
    // SAFETY: caller's contract.
    let at = |name: &str| unsafe { gl.get_uniform_location(program, name) };
    PbrUniforms {
        // The Lambert light and ambient are not the PBR program's (its lights are named
        // u_punctual_*): none, whatever the program declares.
        common: Uniforms {
            to_light: None,
            light_color: None,
            ambient: None,
            // SAFETY: caller's contract.
            ..unsafe { uniforms(gl, program) }
        },
        model: at("u_model"),
        metallic: at("u_metallic"),
        roughness: at("u_roughness"),
        textures: PBR_TEXTURES.map(|(has, sampler)| [at(has), at(sampler)]),
        normal_scale: at("u_normal_scale"),
        occlusion_strength: at("u_occlusion_strength"),
        dielectric_f0: at("u_dielectric_f0"),
        specular_weight: at("u_specular_weight"),
        clearcoat: at("u_clearcoat"),
        clearcoat_roughness: at("u_clearcoat_roughness"),
        clearcoat_normal_scale: at("u_clearcoat_normal_scale"),
        transmissive: at("u_transmissive"),
        transmission: at("u_transmission"),
        thickness: at("u_thickness"),
        eta: at("u_eta"),
        ior_scale: at("u_ior_scale"),
        volume_scale: at("u_volume_scale"),
        attenuation: at("u_attenuation"),
        lod_scale: at("u_lod_scale"),
        backdrop: at("u_backdrop"),
        backdrop_last_level: at("u_backdrop_last_level"),
        backdrop_view_projection: at("u_backdrop_view_projection"),
        sheen: at("u_sheen"),
        sheen_color: at("u_sheen_color"),
        sheen_roughness: at("u_sheen_roughness"),
        tangent_sign: at("u_tangent_sign"),
        texcoord_sets: at("u_texcoord_set"),
        frame_set: at("u_frame_set"),
        has_tangents: at("u_has_tangents"),
        eye: at("u_eye"),
        light_count: at("u_punctual_count"),
        light_color: at("u_punctual_color"),
        light_direction: at("u_punctual_direction"),
        light_position: at("u_punctual_position"),
        light_directional: at("u_punctual_directional"),
        light_inverse_range_squared: at("u_punctual_inverse_range_squared"),
        light_cone_scale: at("u_punctual_cone_scale"),
        light_cone_offset: at("u_punctual_cone_offset"),
        exposure: at("u_exposure"),
        tonemap: at("u_tonemap"),
        has_environment: at("u_has_environment"),
        environment_intensity: at("u_environment_intensity"),
        environment_rotation: at("u_environment_rotation"),
        irradiance_sh: at("u_irradiance_sh"),
        environment: at("u_environment"),
        level_row: at("u_level_row"),
        level_size: at("u_level_size"),
        brdf: at("u_brdf"),
        sheen_albedo: at("u_sheen_albedo"),
    }
}

/// The punctual lights as the shader's uniform arrays, [`MAX_LIGHTS`] long (unused entries
/// zero).
struct LightArrays {
    count: i32,
    color: Vec<f32>,
    direction: Vec<f32>,
    position: Vec<f32>,
    directional: Vec<i32>,
    inverse_range_squared: Vec<f32>,
    cone_scale: Vec<f32>,
    cone_offset: Vec<f32>,
}

impl LightArrays {
    fn new(lights: &[FrameLight]) -> Self {
        let lights = &lights[..lights.len().min(MAX_LIGHTS)];
        let vec3s = |f: &dyn Fn(&FrameLight) -> Vec3| {
            let mut v: Vec<f32> = lights.iter().flat_map(|l| f(l).to_array()).collect();
            v.resize(3 * MAX_LIGHTS, 0.0);
            v
        };
        let floats = |f: &dyn Fn(&FrameLight) -> f32| {
            let mut v: Vec<f32> = lights.iter().map(f).collect();
            v.resize(MAX_LIGHTS, 0.0);
            v
        };
        let mut directional: Vec<i32> = lights.iter().map(|l| l.directional as i32).collect();
        directional.resize(MAX_LIGHTS, 0);
        Self {
            count: lights.len() as i32,
            color: vec3s(&|l| l.color),
            direction: vec3s(&|l| l.direction),
            position: vec3s(&|l| l.position),
            directional,
            inverse_range_squared: floats(&|l| l.inverse_range_squared),
            cone_scale: floats(&|l| l.cone_scale),
            cone_offset: floats(&|l| l.cone_offset),
        }
    }
}

/// The rules' lookup tables on the GPU ([`crate::resources::GpuScene`]'s), read by
/// `texelFetch`.
#[derive(Clone, Copy)]
pub(crate) struct LookupTables {
    /// The split-sum table.
    pub(crate) brdf: Option<glow::Texture>,
    /// The sheen's albedo table.
    pub(crate) sheen_albedo: Option<glow::Texture>,
}

/// Sets the frame's uniforms of the PBR program (in use): texture units, the eye, the lights,
/// exposure and tone map, the environment, whose atlas it binds to [`UNIT_ENVIRONMENT`], the
/// split-sum table (`tables.brdf`, on [`UNIT_BRDF`]), the sheen's albedo table
/// (`tables.sheen_albedo`, on [`UNIT_SHEEN_ALBEDO`]), and the backdrop of a frame with
/// transmission (on [`UNIT_BACKDROP`], with `lighting.transmission`'s view-projection), leaving
/// unit 0 active.
///
/// # Safety
/// `gl` must be current on this thread with the PBR program in use; `environment`, the tables
/// and `backdrop` must be its objects.
pub(crate) unsafe fn set_frame_uniforms(
    gl: &glow::Context,
    u: &PbrUniforms,
    lighting: &PbrLighting,
    environment: Option<&GpuEnvironment>,
    tables: LookupTables,
    backdrop: Option<&GpuBackdrop>,
) {
    let lights = LightArrays::new(&lighting.lights);
    let unit = |unit: u32| unit as i32;
    // SAFETY: caller's contract; every slice has the length of its uniform array.
    unsafe {
        for (k, [_, sampler]) in u.textures.iter().enumerate() {
            gl.uniform_1_i32(sampler.as_ref(), unit(FIRST_PBR_UNIT + k as u32));
        }
        gl.uniform_1_i32(u.environment.as_ref(), unit(UNIT_ENVIRONMENT));
        gl.uniform_1_i32(u.brdf.as_ref(), unit(UNIT_BRDF));
        gl.uniform_1_i32(u.backdrop.as_ref(), unit(UNIT_BACKDROP));
        gl.uniform_1_i32(u.sheen_albedo.as_ref(), unit(UNIT_SHEEN_ALBEDO));
        gl.uniform_3_f32_slice(u.eye.as_ref(), &lighting.eye.to_array());
        gl.uniform_1_i32(u.light_count.as_ref(), lights.count);
        gl.uniform_3_f32_slice(u.light_color.as_ref(), &lights.color);
        gl.uniform_3_f32_slice(u.light_direction.as_ref(), &lights.direction);
        gl.uniform_3_f32_slice(u.light_position.as_ref(), &lights.position);
        gl.uniform_1_i32_slice(u.light_directional.as_ref(), &lights.directional);
        gl.uniform_1_f32_slice(
            u.light_inverse_range_squared.as_ref(),
            &lights.inverse_range_squared,
        );
        gl.uniform_1_f32_slice(u.light_cone_scale.as_ref(), &lights.cone_scale);
        gl.uniform_1_f32_slice(u.light_cone_offset.as_ref(), &lights.cone_offset);
        gl.uniform_1_f32(u.exposure.as_ref(), lighting.exposure);
        gl.uniform_1_i32(u.tonemap.as_ref(), tonemap_index(lighting.tonemap));
        let light_and_maps = lighting.environment.as_ref().zip(environment);
        gl.uniform_1_i32(u.has_environment.as_ref(), light_and_maps.is_some() as i32);
        gl.active_texture(glow::TEXTURE0 + UNIT_ENVIRONMENT);
        gl.bind_sampler(UNIT_ENVIRONMENT, None);
        gl.bind_texture(glow::TEXTURE_2D, environment.map(|e| e.atlas));
        gl.active_texture(glow::TEXTURE0 + UNIT_BRDF);
        gl.bind_sampler(UNIT_BRDF, None);
        gl.bind_texture(glow::TEXTURE_2D, tables.brdf);
        gl.active_texture(glow::TEXTURE0 + UNIT_SHEEN_ALBEDO);
        gl.bind_sampler(UNIT_SHEEN_ALBEDO, None);
        gl.bind_texture(glow::TEXTURE_2D, tables.sheen_albedo);
        gl.active_texture(glow::TEXTURE0 + UNIT_BACKDROP);
        gl.bind_sampler(UNIT_BACKDROP, None);
        gl.bind_texture(glow::TEXTURE_2D, backdrop.map(|b| b.texture));
        gl.active_texture(glow::TEXTURE0);
        let view_projection = lighting
            .transmission
            .as_ref()
            .map_or(Mat4::IDENTITY, |t| t.view_projection);
        gl.uniform_matrix_4_f32_slice(
            u.backdrop_view_projection.as_ref(),
            false,
            &view_projection.to_cols_array(),
        );
        let last_level = backdrop.map_or(0, |b| b.backdrop.level_count() - 1);
        gl.uniform_1_f32(u.backdrop_last_level.as_ref(), last_level as f32);
        if let Some((light, maps)) = light_and_maps {
            set_environment_uniforms(gl, u, light, maps);
        }
    }
}

/// The environment's uniforms: intensity, lookup rotation, SH coefficients, level layout.
///
/// # Safety
/// As [`set_frame_uniforms`].
unsafe fn set_environment_uniforms(
    gl: &glow::Context,
    u: &PbrUniforms,
    light: &EnvironmentLight,
    maps: &GpuEnvironment,
) {
    let (sin, cos) = light.lookup_rotation();
    let sh: Vec<f32> = light
        .environment
        .irradiance_sh
        .iter()
        .flat_map(|c| c.to_array())
        .collect();
    // SAFETY: caller's contract; the slices have their uniform arrays' lengths.
    unsafe {
        gl.uniform_1_f32(u.environment_intensity.as_ref(), light.intensity);
        gl.uniform_2_f32(u.environment_rotation.as_ref(), sin, cos);
        gl.uniform_3_f32_slice(u.irradiance_sh.as_ref(), &sh);
        gl.uniform_1_i32_slice(u.level_row.as_ref(), &maps.rows);
        gl.uniform_1_i32_slice(u.level_size.as_ref(), &maps.sizes);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fragment shader declares one sampler per unit up to [`UNIT_SHEEN_ALBEDO`].
    #[test]
    fn the_fragment_shader_reads_one_sampler_per_unit() {
        let source = fragment_source();
        let samplers = source.matches("uniform sampler2D ").count();
        assert_eq!(samplers as u32, FRAGMENT_SAMPLERS);
        assert_eq!(FRAGMENT_SAMPLERS, 18);
        assert_eq!(
            source.matches("uniform sampler2D u_has").count(),
            0,
            "flags are bools"
        );
        for (has, sampler) in PBR_TEXTURES {
            assert!(source.contains(&format!("uniform bool {has};")), "{has}");
            assert!(
                source.contains(&format!("uniform sampler2D {sampler};")),
                "{sampler}"
            );
        }
    }

    /// A context with fewer fragment texture units than the program's samplers is refused
    /// with one line; OpenGL 3.3's guaranteed 16 is too few, llvmpipe's 32 enough.
    #[test]
    fn too_few_texture_units_are_refused() {
        for units in [0, 16, 17] {
            let error = check_texture_units(units).expect_err("too few");
            assert!(!error.contains('\n'), "{error}");
            assert!(error.contains("GL_MAX_TEXTURE_IMAGE_UNITS"), "{error}");
            assert!(error.contains(&format!("offers {units} ")), "{error}");
        }
        assert!(check_texture_units(18).is_ok());
        assert!(check_texture_units(32).is_ok());
    }

    /// The fit of `Λ` reaches the shader as the rules hold it.
    #[test]
    fn the_lambda_fit_is_the_rules() {
        let source = fragment_source();
        let at_one: Vec<String> = LAMBDA_FIT.iter().map(|[v, _]| format!("{v:?}")).collect();
        let at_zero: Vec<String> = LAMBDA_FIT.iter().map(|[_, v]| format!("{v:?}")).collect();
        assert!(source.contains(&format!(
            "LAMBDA_AT_ONE[5] = float[5]({});",
            at_one.join(", ")
        )));
        assert!(source.contains(&format!(
            "LAMBDA_AT_ZERO[5] = float[5]({});",
            at_zero.join(", ")
        )));
    }
}
