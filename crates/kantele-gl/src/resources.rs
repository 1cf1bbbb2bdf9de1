//! Scene data in GL objects: one vertex array + vertex buffer + index buffer per mesh, one RGBA8 /
//! SRGB8_ALPHA8 texture with its complete mip chain per texture, one sampler object per texture
//! binding of a material, for a PBR scene the split-sum table, (with a sheen) the sheen's
//! albedo table and (with an environment) its pre-filtered levels as float textures; and a
//! frame's transmission backdrop, uploaded with the rules' own mip chain.

use glow::HasContext;
use kantele_rules::scene::{Material, Mesh, Scene, Shading, TextureBinding};
use kantele_rules::shade::environment::{
    brdf_table, Environment, BRDF_TABLE_SIZE, SPECULAR_LEVELS,
};
use kantele_rules::shade::sheen::sheen_table;
use kantele_rules::shade::texture::{ColorSpace, Filter, MinFilter, Sampler, Texture, Wrap};
use kantele_rules::shade::transmission::Backdrop;
use kantele_rules::vertex::{PbrVertex, StandardVertex};

use crate::pbr::PBR_TEXTURES;

/// Floats per vertex: position 3, normal 3, texcoord 2, colour 4.
pub(crate) const VERTEX_FLOATS: usize = 12;
/// Floats per vertex of a PBR scene: [`VERTEX_FLOATS`], then the second texcoord 2 and the
/// tangent 4.
pub(crate) const PBR_VERTEX_FLOATS: usize = VERTEX_FLOATS + 6;

/// A mesh on the GPU.
pub(crate) struct GpuMesh {
    pub(crate) vertex_array: glow::VertexArray,
    pub(crate) vertex_buffer: glow::Buffer,
    pub(crate) index_buffer: glow::Buffer,
    /// Indices to draw (3 per triangle).
    pub(crate) index_count: i32,
}

/// Everything uploaded for one scene.
#[derive(Default)]
pub(crate) struct GpuScene {
    pub(crate) meshes: Vec<GpuMesh>,
    pub(crate) textures: Vec<glow::Texture>,
    /// Per material: the sampler object of its base colour texture, if it has one.
    pub(crate) samplers: Vec<Option<glow::Sampler>>,
    /// Per material: the sampler object of its emissive texture, if it has one.
    pub(crate) emissive_samplers: Vec<Option<glow::Sampler>>,
    /// Per material: the sampler objects of its PBR textures ([`Material::pbr_textures`]),
    /// where it has them.
    pub(crate) pbr_samplers: Vec<[Option<glow::Sampler>; PBR_TEXTURES.len()]>,
    /// The environment of a PBR scene, if it has one.
    pub(crate) environment: Option<GpuEnvironment>,
    /// The split-sum table of a PBR scene ([`upload_brdf_table`]): image-based light and
    /// transmission read it.
    pub(crate) brdf: Option<glow::Texture>,
    /// The sheen's albedo table ([`upload_sheen_table`]), for a PBR scene with a sheen.
    pub(crate) sheen_albedo: Option<glow::Texture>,
}

/// An environment on the GPU, read by the PBR program with `texelFetch` only: the
/// pre-filtered levels of [`Environment::levels`] stacked in one `GL_RGB32F` atlas (level 0 at
/// row 0, each level `(size + 2)²` texels with its border, at column 0).
pub(crate) struct GpuEnvironment {
    pub(crate) atlas: glow::Texture,
    /// The atlas row where each level starts.
    pub(crate) rows: [i32; SPECULAR_LEVELS],
    /// Each level's size without its border.
    pub(crate) sizes: [i32; SPECULAR_LEVELS],
}

/// Interleaved vertices (position, normal, texcoord, colour: [`VERTEX_FLOATS`] floats) and u32
/// indices of a mesh, prepared exactly as the CPU backend prepares it
/// ([`StandardVertex::from_mesh`]: attribute defaults, flat normals for meshes without any).
pub(crate) fn interleave(mesh: &Mesh) -> (Vec<f32>, Vec<u32>) {
    let (vertices, indices) = StandardVertex::from_mesh(mesh);
    let floats = vertices.iter().flat_map(standard_floats).collect();
    (floats, indices)
}

/// Interleaved vertices of a PBR scene's mesh ([`PBR_VERTEX_FLOATS`] floats: those of
/// [`interleave`], then the second texcoord and the tangent) and u32 indices, as the CPU
/// backend prepares them ([`PbrVertex::from_mesh`]).
pub(crate) fn interleave_pbr(mesh: &Mesh) -> (Vec<f32>, Vec<u32>) {
    let (vertices, indices) = PbrVertex::from_mesh(mesh);
    let floats = vertices
        .iter()
        .flat_map(|v| {
            let (t1, t) = (v.texcoord1, v.tangent);
            let mut floats = [0.0; PBR_VERTEX_FLOATS];
            floats[..VERTEX_FLOATS].copy_from_slice(&standard_floats(&v.standard));
            floats[VERTEX_FLOATS..].copy_from_slice(&[t1.x, t1.y, t.x, t.y, t.z, t.w]);
            floats
        })
        .collect();
    (floats, indices)
}

fn standard_floats(v: &StandardVertex) -> [f32; VERTEX_FLOATS] {
    let (p, n, t, c) = (v.position, v.normal, v.texcoord, v.color);
    [p.x, p.y, p.z, n.x, n.y, n.z, t.x, t.y, c.x, c.y, c.z, c.w]
}

fn f32_bytes(values: impl IntoIterator<Item = f32>) -> Vec<u8> {
    values.into_iter().flat_map(f32::to_ne_bytes).collect()
}

fn u32_bytes(values: &[u32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_ne_bytes()).collect()
}

/// Uploads one mesh, in the vertex layout of `shading`.
///
/// # Safety
/// `gl` must be current on this thread.
pub(crate) unsafe fn upload_mesh(
    gl: &glow::Context,
    mesh: &Mesh,
    shading: Shading,
) -> Result<GpuMesh, String> {
    // (location, floats, offset in floats) of each attribute.
    let standard = [(0u32, 3i32, 0i32), (1, 3, 3), (2, 2, 6), (3, 4, 8)];
    let (vertices, indices, floats, extra) = match shading {
        Shading::Lambert => {
            let (v, i) = interleave(mesh);
            (v, i, VERTEX_FLOATS, &[][..])
        }
        Shading::Pbr => {
            let (v, i) = interleave_pbr(mesh);
            (
                v,
                i,
                PBR_VERTEX_FLOATS,
                &[(4u32, 2i32, 12i32), (5, 4, 14)][..],
            )
        }
    };
    let stride = (floats * 4) as i32;
    // SAFETY: the context is current (caller's contract); every handle used is created here, and
    // the byte slices outlive the calls that copy them.
    unsafe {
        let vertex_array = gl.create_vertex_array()?;
        let vertex_buffer = gl.create_buffer()?;
        let index_buffer = gl.create_buffer()?;
        gl.bind_vertex_array(Some(vertex_array));
        gl.bind_buffer(glow::ARRAY_BUFFER, Some(vertex_buffer));
        gl.buffer_data_u8_slice(glow::ARRAY_BUFFER, &f32_bytes(vertices), glow::STATIC_DRAW);
        gl.bind_buffer(glow::ELEMENT_ARRAY_BUFFER, Some(index_buffer));
        gl.buffer_data_u8_slice(
            glow::ELEMENT_ARRAY_BUFFER,
            &u32_bytes(&indices),
            glow::STATIC_DRAW,
        );
        for &(location, size, offset) in standard.iter().chain(extra) {
            gl.enable_vertex_attrib_array(location);
            gl.vertex_attrib_pointer_f32(location, size, glow::FLOAT, false, stride, offset * 4);
        }
        gl.bind_vertex_array(None);
        gl.bind_buffer(glow::ARRAY_BUFFER, None);
        Ok(GpuMesh {
            vertex_array,
            vertex_buffer,
            index_buffer,
            index_count: i32::try_from(indices.len())
                .map_err(|_| format!("{} indices are too many for GL", indices.len()))?,
        })
    }
}

/// Uploads a texture with every level of its mip chain as its 8-bit texels (GL_SRGB8_ALPHA8 for
/// an sRGB texture, GL_RGBA8 otherwise, so GL decodes them as Kantele does), rows in memory order: the
/// first row of a kantele level (the image's top row, addressed by v = 0 as in glTF) becomes GL's
/// t = 0 row, so no flip is needed anywhere.
///
/// # Safety
/// `gl` must be current on this thread.
pub(crate) unsafe fn upload_texture(
    gl: &glow::Context,
    texture: &Texture,
) -> Result<glow::Texture, String> {
    let levels = texture.levels();
    // SAFETY: the context is current (caller's contract); the texture is created here; each
    // level's byte slice holds exactly width × height RGBA8 texels as declared.
    unsafe {
        let max_size = gl.get_parameter_i32(glow::MAX_TEXTURE_SIZE);
        if texture.width() as i64 > max_size as i64 || texture.height() as i64 > max_size as i64 {
            return Err(format!(
                "texture {}x{} exceeds GL_MAX_TEXTURE_SIZE {max_size}",
                texture.width(),
                texture.height()
            ));
        }
        let handle = gl.create_texture()?;
        gl.bind_texture(glow::TEXTURE_2D, Some(handle));
        gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, 4);
        gl.pixel_store_i32(glow::UNPACK_ROW_LENGTH, 0);
        let internal_format = match texture.source_color_space() {
            ColorSpace::Srgb => glow::SRGB8_ALPHA8,
            ColorSpace::Linear => glow::RGBA8,
        };
        let level_count = levels.len();
        for (level, mip) in levels.enumerate() {
            let bytes: Vec<u8> = mip.texels.iter().flat_map(|t| t.to_le_bytes()).collect();
            gl.tex_image_2d(
                glow::TEXTURE_2D,
                level as i32,
                internal_format as i32,
                mip.width as i32,
                mip.height as i32,
                0,
                glow::RGBA,
                glow::UNSIGNED_BYTE,
                glow::PixelUnpackData::Slice(Some(&bytes)),
            );
        }
        gl.tex_parameter_i32(glow::TEXTURE_2D, glow::TEXTURE_BASE_LEVEL, 0);
        gl.tex_parameter_i32(
            glow::TEXTURE_2D,
            glow::TEXTURE_MAX_LEVEL,
            level_count as i32 - 1,
        );
        gl.bind_texture(glow::TEXTURE_2D, None);
        Ok(handle)
    }
}

/// The level atlas of an environment: `(width, height, RGB f32 texels row by row, first row of
/// each level, size of each level)`; an error when the levels are not the rules' six bordered
/// squares.
#[allow(clippy::type_complexity)]
pub(crate) fn environment_atlas(
    environment: &Environment,
) -> Result<
    (
        usize,
        usize,
        Vec<f32>,
        [i32; SPECULAR_LEVELS],
        [i32; SPECULAR_LEVELS],
    ),
    String,
> {
    let levels = &environment.levels;
    if levels.len() != SPECULAR_LEVELS {
        return Err(format!(
            "{} pre-filtered levels, expected {SPECULAR_LEVELS}",
            levels.len()
        ));
    }
    let mut rows = [0i32; SPECULAR_LEVELS];
    let mut sizes = [0i32; SPECULAR_LEVELS];
    let (mut width, mut height) = (0usize, 0usize);
    for (k, level) in levels.iter().enumerate() {
        let stride = level.stride() as usize;
        if level.size == 0 || level.size > 1 << 14 || level.texels.len() != stride * stride {
            return Err(format!(
                "level {k}: {} texels for size {}",
                level.texels.len(),
                level.size
            ));
        }
        rows[k] = height as i32;
        sizes[k] = level.size as i32;
        width = width.max(stride);
        height += stride;
    }
    let mut texels = vec![0.0f32; width * height * 3];
    for (k, level) in levels.iter().enumerate() {
        let stride = level.stride() as usize;
        for (y, row) in level.texels.chunks_exact(stride).enumerate() {
            let start = (rows[k] as usize + y) * width * 3;
            for (x, texel) in row.iter().enumerate() {
                texels[start + 3 * x..start + 3 * x + 3].copy_from_slice(texel);
            }
        }
    }
    Ok((width, height, texels, rows, sizes))
}

/// A float texture of one level read by `texelFetch` (nearest filters, no mip levels).
///
/// # Safety
/// `gl` must be current on this thread; `texels` holds `width × height` texels of `format`.
unsafe fn upload_float_texture(
    gl: &glow::Context,
    internal_format: u32,
    format: u32,
    (width, height): (usize, usize),
    texels: &[f32],
) -> Result<glow::Texture, String> {
    // SAFETY: the context is current (caller's contract); the texture is created here; rows of
    // f32 texels are 4-byte aligned, so UNPACK_ALIGNMENT 4 adds no padding.
    unsafe {
        let max_size = gl.get_parameter_i32(glow::MAX_TEXTURE_SIZE);
        if width as i64 > max_size as i64 || height as i64 > max_size as i64 {
            return Err(format!(
                "{width}x{height} exceeds GL_MAX_TEXTURE_SIZE {max_size}"
            ));
        }
        let handle = gl.create_texture()?;
        gl.bind_texture(glow::TEXTURE_2D, Some(handle));
        gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, 4);
        gl.pixel_store_i32(glow::UNPACK_ROW_LENGTH, 0);
        gl.tex_image_2d(
            glow::TEXTURE_2D,
            0,
            internal_format as i32,
            width as i32,
            height as i32,
            0,
            format,
            glow::FLOAT,
            glow::PixelUnpackData::Slice(Some(&f32_bytes(texels.iter().copied()))),
        );
        for (parameter, value) in [
            (glow::TEXTURE_MIN_FILTER, glow::NEAREST),
            (glow::TEXTURE_MAG_FILTER, glow::NEAREST),
            (glow::TEXTURE_WRAP_S, glow::CLAMP_TO_EDGE),
            (glow::TEXTURE_WRAP_T, glow::CLAMP_TO_EDGE),
        ] {
            gl.tex_parameter_i32(glow::TEXTURE_2D, parameter, value as i32);
        }
        gl.tex_parameter_i32(glow::TEXTURE_2D, glow::TEXTURE_BASE_LEVEL, 0);
        gl.tex_parameter_i32(glow::TEXTURE_2D, glow::TEXTURE_MAX_LEVEL, 0);
        gl.bind_texture(glow::TEXTURE_2D, None);
        Ok(handle)
    }
}

/// Uploads an environment's levels.
///
/// # Safety
/// `gl` must be current on this thread.
pub(crate) unsafe fn upload_environment(
    gl: &glow::Context,
    environment: &Environment,
) -> Result<GpuEnvironment, String> {
    let (width, height, texels, rows, sizes) = environment_atlas(environment)?;
    // SAFETY: forwarded caller's contract; the slice holds the declared texel count.
    unsafe {
        let atlas = upload_float_texture(gl, glow::RGB32F, glow::RGB, (width, height), &texels)?;
        Ok(GpuEnvironment { atlas, rows, sizes })
    }
}

/// Uploads the split-sum table of [`brdf_table`] as a `BRDF_TABLE_SIZE²` `GL_RG32F` texture
/// (x: `NdotV`, y: roughness), read by `texelFetch` only.
///
/// # Safety
/// `gl` must be current on this thread.
pub(crate) unsafe fn upload_brdf_table(gl: &glow::Context) -> Result<glow::Texture, String> {
    let table: Vec<f32> = brdf_table().iter().flatten().copied().collect();
    let size = (BRDF_TABLE_SIZE, BRDF_TABLE_SIZE);
    // SAFETY: forwarded caller's contract; the table holds BRDF_TABLE_SIZE² RG texels.
    unsafe { upload_float_texture(gl, glow::RG32F, glow::RG, size, &table) }
}

/// Uploads the sheen's albedo table of [`sheen_table`] as a `BRDF_TABLE_SIZE²` `GL_R32F`
/// texture (x: `NdotV`, y: roughness, as the split-sum table), read by `texelFetch` only.
///
/// # Safety
/// `gl` must be current on this thread.
pub(crate) unsafe fn upload_sheen_table(gl: &glow::Context) -> Result<glow::Texture, String> {
    let size = (BRDF_TABLE_SIZE, BRDF_TABLE_SIZE);
    // SAFETY: forwarded caller's contract; the table holds BRDF_TABLE_SIZE² R texels.
    unsafe { upload_float_texture(gl, glow::R32F, glow::RED, size, sheen_table()) }
}

/// A frame's backdrop on the GPU: every level of the rules' chain ([`Backdrop::level`]) in one
/// `GL_RGB32F` texture with explicit levels, rows in memory order (the backdrop's top row is
/// GL's `t = 0` row, where the rules' `v = 0` points), sampled trilinearly
/// (`GL_LINEAR_MIPMAP_LINEAR`, `GL_LINEAR`) and clamped to the edge, as
/// [`Backdrop::sample_lanes`] reads it.
pub(crate) struct GpuBackdrop {
    pub(crate) texture: glow::Texture,
    /// The chain the texture holds (the rules read the same one).
    pub(crate) backdrop: std::sync::Arc<Backdrop>,
}

/// Uploads `backdrop`'s levels.
///
/// # Safety
/// `gl` must be current on this thread.
pub(crate) unsafe fn upload_backdrop(
    gl: &glow::Context,
    backdrop: std::sync::Arc<Backdrop>,
) -> Result<GpuBackdrop, String> {
    let levels: Vec<(u32, u32, Vec<[f32; 3]>)> = (0..backdrop.level_count())
        .map_while(|k| backdrop.level(k))
        .collect();
    let count = levels.len();
    // SAFETY: the context is current (caller's contract); the texture is created here; each
    // level's byte slice holds exactly width × height RGB f32 texels as declared, and rows of
    // f32 texels are 4-byte aligned, so UNPACK_ALIGNMENT 4 adds no padding.
    unsafe {
        let max_size = gl.get_parameter_i32(glow::MAX_TEXTURE_SIZE);
        let (width, height, _) = &levels[0];
        if *width as i64 > max_size as i64 || *height as i64 > max_size as i64 {
            return Err(format!(
                "backdrop {width}x{height} exceeds GL_MAX_TEXTURE_SIZE {max_size}"
            ));
        }
        let texture = gl.create_texture()?;
        gl.bind_texture(glow::TEXTURE_2D, Some(texture));
        gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, 4);
        gl.pixel_store_i32(glow::UNPACK_ROW_LENGTH, 0);
        for (k, (width, height, texels)) in levels.iter().enumerate() {
            gl.tex_image_2d(
                glow::TEXTURE_2D,
                k as i32,
                glow::RGB32F as i32,
                *width as i32,
                *height as i32,
                0,
                glow::RGB,
                glow::FLOAT,
                glow::PixelUnpackData::Slice(Some(&f32_bytes(texels.iter().flatten().copied()))),
            );
        }
        for (parameter, value) in [
            (glow::TEXTURE_MIN_FILTER, glow::LINEAR_MIPMAP_LINEAR as i32),
            (glow::TEXTURE_MAG_FILTER, glow::LINEAR as i32),
            (glow::TEXTURE_WRAP_S, glow::CLAMP_TO_EDGE as i32),
            (glow::TEXTURE_WRAP_T, glow::CLAMP_TO_EDGE as i32),
            (glow::TEXTURE_BASE_LEVEL, 0),
            (glow::TEXTURE_MAX_LEVEL, count as i32 - 1),
        ] {
            gl.tex_parameter_i32(glow::TEXTURE_2D, parameter, value);
        }
        gl.bind_texture(glow::TEXTURE_2D, None);
        Ok(GpuBackdrop { texture, backdrop })
    }
}

fn wrap(w: Wrap) -> i32 {
    (match w {
        Wrap::Repeat => glow::REPEAT,
        Wrap::ClampToEdge => glow::CLAMP_TO_EDGE,
        Wrap::MirroredRepeat => glow::MIRRORED_REPEAT,
    }) as i32
}

fn mag_filter(f: Filter) -> i32 {
    (match f {
        Filter::Nearest => glow::NEAREST,
        Filter::Linear => glow::LINEAR,
    }) as i32
}

fn min_filter(f: MinFilter) -> i32 {
    (match f {
        MinFilter::Nearest => glow::NEAREST,
        MinFilter::Linear => glow::LINEAR,
        MinFilter::NearestMipmapNearest => glow::NEAREST_MIPMAP_NEAREST,
        MinFilter::LinearMipmapNearest => glow::LINEAR_MIPMAP_NEAREST,
        MinFilter::NearestMipmapLinear => glow::NEAREST_MIPMAP_LINEAR,
        MinFilter::LinearMipmapLinear => glow::LINEAR_MIPMAP_LINEAR,
    }) as i32
}

/// A sampler object for a glTF sampler (no anisotropy, no LOD bias: GL's defaults).
///
/// # Safety
/// `gl` must be current on this thread.
pub(crate) unsafe fn create_sampler(
    gl: &glow::Context,
    sampler: &Sampler,
) -> Result<glow::Sampler, String> {
    // SAFETY: the context is current (caller's contract); the sampler is created here.
    unsafe {
        let handle = gl.create_sampler()?;
        gl.sampler_parameter_i32(handle, glow::TEXTURE_WRAP_S, wrap(sampler.wrap_s));
        gl.sampler_parameter_i32(handle, glow::TEXTURE_WRAP_T, wrap(sampler.wrap_t));
        gl.sampler_parameter_i32(
            handle,
            glow::TEXTURE_MAG_FILTER,
            mag_filter(sampler.mag_filter),
        );
        gl.sampler_parameter_i32(
            handle,
            glow::TEXTURE_MIN_FILTER,
            min_filter(sampler.min_filter),
        );
        Ok(handle)
    }
}

impl GpuScene {
    /// Uploads every mesh, texture and sampler of `scene`. On failure whatever was created is
    /// deleted again.
    ///
    /// # Safety
    /// `gl` must be current on this thread.
    pub(crate) unsafe fn upload(gl: &glow::Context, scene: &Scene) -> Result<Self, String> {
        let mut gpu = GpuScene::default();
        let result = (|| {
            for (i, mesh) in scene.meshes.iter().enumerate() {
                // SAFETY: forwarded caller's contract.
                let m = unsafe { upload_mesh(gl, mesh, scene.shading) }
                    .map_err(|e| format!("mesh {i}: {e}"))?;
                gpu.meshes.push(m);
            }
            for (i, texture) in scene.textures.iter().enumerate() {
                // SAFETY: forwarded caller's contract.
                let t = unsafe { upload_texture(gl, texture) }
                    .map_err(|e| format!("texture {i}: {e}"))?;
                gpu.textures.push(t);
            }
            for material in &scene.materials {
                let sampler = match material_binding(material) {
                    // SAFETY: forwarded caller's contract.
                    Some(s) => Some(unsafe { create_sampler(gl, &s) }?),
                    None => None,
                };
                gpu.samplers.push(sampler);
                let emissive = match material.emissive_texture.map(|b| b.sampler) {
                    // SAFETY: forwarded caller's contract.
                    Some(s) => Some(unsafe { create_sampler(gl, &s) }?),
                    None => None,
                };
                gpu.emissive_samplers.push(emissive);
                let mut pbr = [None; PBR_TEXTURES.len()];
                let textures: [Option<TextureBinding>; PBR_TEXTURES.len()] =
                    material.pbr_textures();
                for (slot, binding) in pbr.iter_mut().zip(textures) {
                    if let Some(b) = binding {
                        // SAFETY: forwarded caller's contract.
                        *slot = Some(unsafe { create_sampler(gl, &b.sampler) }?);
                    }
                }
                gpu.pbr_samplers.push(pbr);
            }
            if scene.shading == Shading::Pbr {
                // SAFETY: forwarded caller's contract.
                let brdf = unsafe { upload_brdf_table(gl) }
                    .map_err(|e| format!("split-sum table: {e}"))?;
                gpu.brdf = Some(brdf);
            }
            if scene.shading == Shading::Pbr && scene.materials.iter().any(Material::has_sheen) {
                // SAFETY: forwarded caller's contract.
                let table = unsafe { upload_sheen_table(gl) }
                    .map_err(|e| format!("sheen albedo table: {e}"))?;
                gpu.sheen_albedo = Some(table);
            }
            if let (Shading::Pbr, Some(light)) = (scene.shading, &scene.environment) {
                // SAFETY: forwarded caller's contract.
                let e = unsafe { upload_environment(gl, &light.environment) }
                    .map_err(|e| format!("environment: {e}"))?;
                gpu.environment = Some(e);
            }
            Ok(())
        })();
        match result {
            Ok(()) => Ok(gpu),
            Err(e) => {
                // SAFETY: forwarded caller's contract; the objects are ours.
                unsafe { gpu.delete(gl) };
                Err(e)
            }
        }
    }

    /// Deletes every GL object.
    ///
    /// # Safety
    /// `gl` must be current on this thread and the objects must belong to it.
    pub(crate) unsafe fn delete(&mut self, gl: &glow::Context) {
        // SAFETY: the caller guarantees a current context owning these objects; each is deleted
        // once because the vectors are drained.
        unsafe {
            for m in self.meshes.drain(..) {
                gl.delete_vertex_array(m.vertex_array);
                gl.delete_buffer(m.vertex_buffer);
                gl.delete_buffer(m.index_buffer);
            }
            for t in self.textures.drain(..) {
                gl.delete_texture(t);
            }
            for s in self.samplers.drain(..).flatten() {
                gl.delete_sampler(s);
            }
            for s in self.emissive_samplers.drain(..).flatten() {
                gl.delete_sampler(s);
            }
            for s in self.pbr_samplers.drain(..).flatten().flatten() {
                gl.delete_sampler(s);
            }
            if let Some(e) = self.environment.take() {
                gl.delete_texture(e.atlas);
            }
            if let Some(t) = self.brdf.take() {
                gl.delete_texture(t);
            }
            if let Some(t) = self.sheen_albedo.take() {
                gl.delete_texture(t);
            }
        }
    }
}

fn material_binding(material: &Material) -> Option<Sampler> {
    material.base_color_texture.map(|b| b.sampler)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn interleave_fills_defaults() {
        let mesh = Mesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            normals: Some(vec![Vec3::Z; 3]),
            indices: vec![0, 1, 2],
            ..Mesh::default()
        };
        let (v, i) = interleave(&mesh);
        assert_eq!(i, vec![0, 1, 2]);
        assert_eq!(v.len(), 3 * VERTEX_FLOATS);
        assert_eq!(
            &v[VERTEX_FLOATS..2 * VERTEX_FLOATS],
            &[1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0]
        );
    }

    #[test]
    fn interleave_pbr_appends_the_second_texcoord_and_the_tangent() {
        let mesh = Mesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            normals: Some(vec![Vec3::Z; 3]),
            texcoords1: Some(vec![glam::Vec2::new(0.25, 0.5); 3]),
            tangents: Some(vec![glam::Vec4::new(1.0, 0.0, 0.0, -1.0); 3]),
            indices: vec![0, 1, 2],
            ..Mesh::default()
        };
        let (v, i) = interleave_pbr(&mesh);
        let (standard, _) = interleave(&mesh);
        assert_eq!(i, vec![0, 1, 2]);
        assert_eq!(v.len(), 3 * PBR_VERTEX_FLOATS);
        let second = &v[PBR_VERTEX_FLOATS..2 * PBR_VERTEX_FLOATS];
        assert_eq!(
            &second[..VERTEX_FLOATS],
            &standard[VERTEX_FLOATS..2 * VERTEX_FLOATS]
        );
        assert_eq!(&second[VERTEX_FLOATS..], &[0.25, 0.5, 1.0, 0.0, 0.0, -1.0]);
    }

    #[test]
    fn environment_atlas_stacks_the_levels_with_their_borders() {
        let environment = Environment::studio();
        let (width, height, texels, rows, sizes) = environment_atlas(&environment).expect("atlas");
        let strides: Vec<usize> = environment
            .levels
            .iter()
            .map(|l| l.stride() as usize)
            .collect();
        assert_eq!(width, strides.iter().copied().max().unwrap());
        assert_eq!(height, strides.iter().sum::<usize>());
        assert_eq!(texels.len(), width * height * 3);
        for (k, level) in environment.levels.iter().enumerate() {
            assert_eq!(sizes[k] as u32, level.size);
            let stride = strides[k];
            for (x, y) in [(0, 0), (stride - 1, 0), (3, stride - 1), (stride / 2, 1)] {
                let at = ((rows[k] as usize + y) * width + x) * 3;
                assert_eq!(
                    texels[at..at + 3],
                    level.texels[y * stride + x],
                    "level {k} ({x}, {y})"
                );
            }
        }
        let mut broken = (*environment).clone();
        broken.levels.pop();
        assert!(environment_atlas(&broken).is_err());
    }

    #[test]
    fn interleave_flat_normals_split_vertices() {
        // Two triangles sharing an edge, one facing +Z, one facing −Z.
        let mesh = Mesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)],
            indices: vec![0, 1, 2, 1, 2, 3],
            ..Mesh::default()
        };
        let (v, i) = interleave(&mesh);
        assert_eq!(i, (0..6).collect::<Vec<u32>>());
        let normal = |k: usize| Vec3::from_slice(&v[k * VERTEX_FLOATS + 3..k * VERTEX_FLOATS + 6]);
        for k in 0..3 {
            assert_eq!(normal(k), Vec3::Z);
            assert_eq!(normal(k + 3), -Vec3::Z);
        }
        assert_eq!(Vec3::from_slice(&v[4 * VERTEX_FLOATS..]), Vec3::Y);
    }
}
