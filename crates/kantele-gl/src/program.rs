//! The shader programs: compiling and linking GLSL (the Lambert program of [`crate::shaders`],
//! the PBR program of [`crate::pbr`]), and the Lambert program's uniform locations.

use glow::HasContext;

/// Uniform locations of the Lambert program (also looked up in the PBR program, which lacks
/// the light and ambient ones).
pub(crate) struct Uniforms {
    pub(crate) model_view_projection: Option<glow::UniformLocation>,
    pub(crate) normal_matrix: Option<glow::UniformLocation>,
    pub(crate) base_color_factor: Option<glow::UniformLocation>,
    pub(crate) has_texture: Option<glow::UniformLocation>,
    pub(crate) base_color_texture: Option<glow::UniformLocation>,
    pub(crate) emissive: Option<glow::UniformLocation>,
    pub(crate) has_emissive_texture: Option<glow::UniformLocation>,
    pub(crate) emissive_texture: Option<glow::UniformLocation>,
    pub(crate) unlit: Option<glow::UniformLocation>,
    pub(crate) alpha_mode: Option<glow::UniformLocation>,
    pub(crate) alpha_cutoff: Option<glow::UniformLocation>,
    pub(crate) double_sided: Option<glow::UniformLocation>,
    pub(crate) to_light: Option<glow::UniformLocation>,
    pub(crate) light_color: Option<glow::UniformLocation>,
    pub(crate) ambient: Option<glow::UniformLocation>,
    pub(crate) pass: Option<glow::UniformLocation>,
    pub(crate) ids: Option<glow::UniformLocation>,
}

/// Compiles and links a program of a vertex and a fragment shader.
///
/// # Safety
/// `gl` must be current on this thread.
pub(crate) unsafe fn build_program(
    gl: &glow::Context,
    vertex: &str,
    fragment: &str,
) -> Result<glow::Program, String> {
    // SAFETY: the context is current (caller's contract); shaders and program are created here
    // and the shaders are deleted once linked (or on failure).
    unsafe {
        let program = gl.create_program()?;
        let mut shaders = Vec::new();
        for (kind, source, what) in [
            (glow::VERTEX_SHADER, vertex, "vertex"),
            (glow::FRAGMENT_SHADER, fragment, "fragment"),
        ] {
            let shader = gl.create_shader(kind)?;
            gl.shader_source(shader, source);
            gl.compile_shader(shader);
            if !gl.get_shader_compile_status(shader) {
                let log = gl.get_shader_info_log(shader);
                gl.delete_shader(shader);
                for s in shaders {
                    gl.delete_shader(s);
                }
                gl.delete_program(program);
                return Err(format!("{what} shader does not compile: {log}"));
            }
            gl.attach_shader(program, shader);
            shaders.push(shader);
        }
        gl.link_program(program);
        let linked = gl.get_program_link_status(program);
        for s in shaders {
            gl.detach_shader(program, s);
            gl.delete_shader(s);
        }
        if !linked {
            let log = gl.get_program_info_log(program);
            gl.delete_program(program);
            return Err(format!("shader program does not link: {log}"));
        }
        Ok(program)
    }
}

/// Looks up every uniform of the program.
///
/// # Safety
/// `gl` must be current on this thread and `program` a linked program of it.
pub(crate) unsafe fn uniforms(gl: &glow::Context, program: glow::Program) -> Uniforms {
    // SAFETY: caller's contract.
    let at = |name: &str| unsafe { gl.get_uniform_location(program, name) };
    Uniforms {
        model_view_projection: at("u_model_view_projection"),
        normal_matrix: at("u_normal_matrix"),
        base_color_factor: at("u_base_color_factor"),
        has_texture: at("u_has_texture"),
        base_color_texture: at("u_base_color_texture"),
        emissive: at("u_emissive"),
        has_emissive_texture: at("u_has_emissive_texture"),
        emissive_texture: at("u_emissive_texture"),
        unlit: at("u_unlit"),
        alpha_mode: at("u_alpha_mode"),
        alpha_cutoff: at("u_alpha_cutoff"),
        double_sided: at("u_double_sided"),
        to_light: at("u_to_light"),
        light_color: at("u_light_color"),
        ambient: at("u_ambient"),
        pass: at("u_pass"),
        ids: at("u_ids"),
    }
}
