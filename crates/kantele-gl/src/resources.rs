//! Scene data in GL objects: one vertex array + vertex buffer + index buffer per mesh, one RGBA8 /
//! SRGB8_ALPHA8 texture with its complete mip chain per texture, one sampler object per textured material.

use glow::HasContext;
use kantele_rules::scene::{Material, Mesh, Scene};
use kantele_rules::shade::texture::{ColorSpace, Filter, MinFilter, Sampler, Texture, Wrap};
use kantele_rules::vertex::StandardVertex;

/// Floats per vertex: position 3, normal 3, texcoord 2, colour 4.
pub(crate) const VERTEX_FLOATS: usize = 12;

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
}

/// Interleaved vertices (position, normal, texcoord, colour: [`VERTEX_FLOATS`] floats) and u32
/// indices of a mesh, prepared exactly as the CPU backend prepares it
/// ([`StandardVertex::from_mesh`]: attribute defaults, flat normals for meshes without any).
pub(crate) fn interleave(mesh: &Mesh) -> (Vec<f32>, Vec<u32>) {
    let (vertices, indices) = StandardVertex::from_mesh(mesh);
    let floats = vertices
        .iter()
        .flat_map(|v| {
            let (p, n, t, c) = (v.position, v.normal, v.texcoord, v.color);
            [p.x, p.y, p.z, n.x, n.y, n.z, t.x, t.y, c.x, c.y, c.z, c.w]
        })
        .collect();
    (floats, indices)
}

fn f32_bytes(values: impl IntoIterator<Item = f32>) -> Vec<u8> {
    values.into_iter().flat_map(f32::to_ne_bytes).collect()
}

fn u32_bytes(values: &[u32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_ne_bytes()).collect()
}

/// Uploads one mesh.
///
/// # Safety
/// `gl` must be current on this thread.
pub(crate) unsafe fn upload_mesh(gl: &glow::Context, mesh: &Mesh) -> Result<GpuMesh, String> {
    let (vertices, indices) = interleave(mesh);
    let stride = (VERTEX_FLOATS * 4) as i32;
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
        for (location, size, offset) in [(0u32, 3i32, 0i32), (1, 3, 3), (2, 2, 6), (3, 4, 8)] {
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
                let m = unsafe { upload_mesh(gl, mesh) }.map_err(|e| format!("mesh {i}: {e}"))?;
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
