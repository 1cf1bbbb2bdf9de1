//! GLSL 3.30 core sources: Kantele's shading rules (`docs/rendering-rules.md`, "Shading: the
//! Lambert model") written as one vertex and one fragment shader.

/// Vertex attribute locations (interleaved buffer, see [`crate::resources`]).
pub(crate) const VERTEX: &str = r#"#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_texcoord;
layout(location = 3) in vec4 a_color;

// y-flipped projection × view × model (window row 0 = image row 0).
uniform mat4 u_model_view_projection;
// Inverse transpose of the model matrix's upper 3 × 3.
uniform mat3 u_normal_matrix;

out vec3 v_normal;
out vec2 v_texcoord;
out vec4 v_color;

void main() {
    gl_Position = u_model_view_projection * vec4(a_position, 1.0);
    v_normal = u_normal_matrix * a_normal;
    v_texcoord = a_texcoord;
    v_color = a_color;
}
"#;

/// Pass numbers of `u_pass`.
pub(crate) const PASS_COLOR: i32 = 0;
/// World normals.
pub(crate) const PASS_NORMALS: i32 = 1;
/// Integer ids in float channels.
pub(crate) const PASS_IDS: i32 = 2;

/// Alpha modes of `u_alpha_mode`.
pub(crate) const ALPHA_OPAQUE: i32 = 0;
/// Discard below the cutoff.
pub(crate) const ALPHA_MASK: i32 = 1;
/// Blended.
pub(crate) const ALPHA_BLEND: i32 = 2;

pub(crate) const FRAGMENT: &str = r#"#version 330 core
in vec3 v_normal;
in vec2 v_texcoord;
in vec4 v_color;

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
uniform vec3 u_to_light;       // unit, world space
uniform vec3 u_light_color;    // colour × intensity
uniform float u_ambient;
uniform int u_pass;            // 0 colour, 1 normals, 2 ids
uniform vec2 u_ids;            // node index + 1, draw index + 1

layout(location = 0) out vec4 o_color;

void main() {
    // Texels are kantele's 8-bit mip chain (SRGB8_ALPHA8 or RGBA8), decoded to linear by GL.
    vec4 base = u_base_color_factor * v_color;
    if (u_has_texture) {
        base *= texture(u_base_color_texture, v_texcoord);
    }
    if (u_alpha_mode == 1 && base.a < u_alpha_cutoff) {
        discard;
    }
    vec3 n = normalize(v_normal);
    // The projection is y-flipped and glFrontFace is GL_CW, so gl_FrontFacing keeps its meaning:
    // true for triangles counter-clockwise in (unflipped) NDC.
    if (u_double_sided && !gl_FrontFacing) {
        n = -n;
    }
    if (u_pass == 1) {
        o_color = vec4(n, 1.0);
        return;
    }
    if (u_pass == 2) {
        o_color = vec4(u_ids.x, float(gl_PrimitiveID + 1), u_ids.y, 1.0);
        return;
    }
    vec3 rgb = base.rgb;
    if (!u_unlit) {
        rgb = base.rgb * (u_ambient + (1.0 - u_ambient) * max(0.0, dot(n, u_to_light)) * u_light_color);
    }
    vec3 emissive = u_emissive;
    if (u_has_emissive_texture) {
        emissive *= texture(u_emissive_texture, v_texcoord).rgb;
    }
    rgb += emissive;
    float a = u_alpha_mode == 2 ? base.a : 1.0;
    o_color = vec4(rgb, a);
}
"#;
