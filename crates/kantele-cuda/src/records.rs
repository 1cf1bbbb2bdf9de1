//! The plain records the kernels read, laid out as `#[repr(C)]` structs that mirror the structs
//! of `kernels/common.cuh` (their sizes and field offsets are passed to NVRTC as defines and
//! checked there with `static_assert`), and their construction from a [`Scene`].

use glam::Mat4;
use kantele_rules::backend::Pass;
use kantele_rules::camera::normal_matrix;
use kantele_rules::scene::{AlphaMode, Scene};
use kantele_rules::setup::FrontFace;
use kantele_rules::shade::texture::{Filter, MinFilter, Sampler, Wrap};
use kantele_rules::vertex::StandardVertex;

/// `DrawRecord::flags`: the material is unlit (`KHR_materials_unlit`).
pub const DRAW_UNLIT: u32 = 1 << 0;
/// `DrawRecord::flags`: double-sided (no culling; back faces flip the normal).
pub const DRAW_DOUBLE_SIDED: u32 = 1 << 1;
/// `DrawRecord::flags`: alpha mode MASK.
pub const DRAW_ALPHA_MASK: u32 = 1 << 2;
/// `DrawRecord::flags`: alpha mode BLEND (alpha blending, no depth writes).
pub const DRAW_ALPHA_BLEND: u32 = 1 << 3;
/// `DrawRecord::flags`: the base colour is multiplied by a texture.
pub const DRAW_TEXTURED: u32 = 1 << 4;
/// `DrawRecord::flags`: clockwise in NDC is front (the model matrix mirrors).
pub const DRAW_FRONT_CW: u32 = 1 << 5;
/// `DrawRecord::flags`: the emission is multiplied by an emissive texture.
pub const DRAW_EMISSIVE_TEXTURED: u32 = 1 << 6;
/// `DrawRecord::flags`: the mesh has vertex colours (`COLOR_0`). With a texture, it decides
/// how the normal is interpolated (`material_normal` in `kernels/common.cuh`).
pub const DRAW_VERTEX_COLORS: u32 = 1 << 7;

/// Kernel code of a [`Wrap`] mode.
pub fn wrap_code(w: Wrap) -> u32 {
    match w {
        Wrap::Repeat => 0,
        Wrap::ClampToEdge => 1,
        Wrap::MirroredRepeat => 2,
    }
}

/// Kernel code of a magnification [`Filter`].
pub fn filter_code(f: Filter) -> u32 {
    match f {
        Filter::Nearest => 0,
        Filter::Linear => 1,
    }
}

/// Kernel code of a [`MinFilter`].
pub fn min_filter_code(f: MinFilter) -> u32 {
    match f {
        MinFilter::Nearest => 0,
        MinFilter::Linear => 1,
        MinFilter::NearestMipmapNearest => 2,
        MinFilter::LinearMipmapNearest => 3,
        MinFilter::NearestMipmapLinear => 4,
        MinFilter::LinearMipmapLinear => 5,
    }
}

/// Kernel code of a [`Pass`].
pub fn pass_code(p: Pass) -> u32 {
    match p {
        Pass::Color => 0,
        Pass::Normals => 1,
        Pass::Ids => 2,
    }
}

/// A texture binding's sampler as kernel codes (`SamplerCodes` in `common.cuh`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SamplerCodes {
    /// Wrap mode in s ([`wrap_code`]).
    pub wrap_s: u32,
    /// Wrap mode in t ([`wrap_code`]).
    pub wrap_t: u32,
    /// Magnification filter ([`filter_code`]).
    pub mag_filter: u32,
    /// Minification filter ([`min_filter_code`]).
    pub min_filter: u32,
}

impl SamplerCodes {
    /// The codes of `sampler`.
    pub fn new(sampler: &Sampler) -> Self {
        Self {
            wrap_s: wrap_code(sampler.wrap_s),
            wrap_t: wrap_code(sampler.wrap_t),
            mag_filter: filter_code(sampler.mag_filter),
            min_filter: min_filter_code(sampler.min_filter),
        }
    }
}

/// One scene draw as the kernels see it (`DrawRecord` in `common.cuh`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DrawRecord {
    /// Model matrix, column-major.
    pub model: [f32; 16],
    /// Normal matrix (`kantele_rules::camera::normal_matrix`), column-major.
    pub normal_matrix: [f32; 9],
    /// The material's base colour factor.
    pub base_color_factor: [f32; 4],
    /// The material's linear emission, added after lighting.
    pub emissive: [f32; 3],
    /// MASK cutoff.
    pub alpha_cutoff: f32,
    /// `DRAW_*` flags.
    pub flags: u32,
    /// Base colour texture index when `DRAW_TEXTURED`.
    pub texture: u32,
    /// Its sampler.
    pub sampler: SamplerCodes,
    /// Emissive texture index when `DRAW_EMISSIVE_TEXTURED`.
    pub emissive_texture: u32,
    /// Its sampler.
    pub emissive_sampler: SamplerCodes,
    /// Node index + 1 (the ids pass' red channel).
    pub node_id: u32,
    /// Draw index + 1 (the ids pass' blue channel).
    pub draw_id: u32,
    /// First vertex of the mesh in the scene's vertex array.
    pub vertex_base: u32,
    /// The mesh's vertex count.
    pub vertex_count: u32,
    /// First index of the mesh in the scene's index array.
    pub index_base: u32,
    /// The mesh's triangle count.
    pub triangle_count: u32,
    /// First slot of this draw among the frame's shaded vertices.
    pub shaded_base: u32,
}

/// One draw of a frame in issue order (`DrawIssue` in `common.cuh`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DrawIssue {
    /// Scene draw index.
    pub draw: u32,
    /// Its first triangle slot this frame.
    pub slot_base: u32,
}

/// The frame's draws in `order` (`Scene::draw_order`) with their slot bases: each draw's
/// triangles follow the previous draw's, so triangle slots are in submission order.
pub fn draw_issue(draws: &[DrawRecord], order: &[usize]) -> Vec<DrawIssue> {
    let mut base = 0u32;
    order
        .iter()
        .filter_map(|&d| draws.get(d).map(|r| (d, r)))
        .map(|(d, record)| {
            let issue = DrawIssue {
                draw: d as u32,
                slot_base: base,
            };
            base = base.saturating_add(record.triangle_count);
            issue
        })
        .collect()
}

/// A texture's place in the level table (`TextureRecord` in `common.cuh`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TextureRecord {
    /// Index of level 0 in the level table.
    pub first_level: u32,
    /// Levels in the chain (down to 1 × 1).
    pub level_count: u32,
    /// Level 0 width.
    pub width: u32,
    /// Level 0 height.
    pub height: u32,
}

/// One mip level's place in the texel array (`LevelRecord` in `common.cuh`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LevelRecord {
    /// First texel (RGBA f32) of the level.
    pub offset: u64,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
}

/// Everything a frame's launches need by value (`FrameUniforms` in `common.cuh`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameUniforms {
    /// `projection * view`, column-major.
    pub view_projection: [f32; 16],
    /// Unit vector towards the light (world space).
    pub to_light: [f32; 3],
    /// Light colour.
    pub light_color: [f32; 3],
    /// Scene ambient term.
    pub ambient: f32,
    /// `Viewport::new(width, height)`'s half width (`width as f32 * 0.5`).
    pub half_width: f32,
    /// Half height.
    pub half_height: f32,
    /// `GuardBand::new(width, height).k_x`.
    pub guard_kx: f32,
    /// `GuardBand::new(width, height).k_y`.
    pub guard_ky: f32,
    /// Clear colour (linear RGBA).
    pub clear_color: [f32; 4],
    /// Target width.
    pub width: u32,
    /// Target height.
    pub height: u32,
    /// Tiles per row.
    pub tiles_x: u32,
    /// Tile rows.
    pub tiles_y: u32,
    /// [`pass_code`].
    pub pass: u32,
    /// Scene draws.
    pub draw_count: u32,
    /// Vertices shaded per frame (over all draws).
    pub shaded_count: u32,
    /// Triangle slots per frame (over all draws).
    pub slot_count: u32,
    /// Setups available for clipped fans.
    pub clip_capacity: u32,
    /// Entries available in the bins.
    pub bin_capacity: u32,
    /// Binning chunks.
    pub chunk_count: u32,
}

/// Where a triangle slot's setups are (`SlotInfo` in `common.cuh`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SlotInfo {
    /// Index of the first setup.
    pub first: u32,
    /// Setups (0 = nothing drawn, 1 = whole triangle, up to 7 for a clipped fan).
    pub count: u32,
}

/// Device pointers of the scene data the fragment stage reads (`SceneView` in `common.cuh`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SceneView {
    /// `DrawRecord` array.
    pub draws: u64,
    /// `TextureRecord` array.
    pub textures: u64,
    /// `LevelRecord` array.
    pub levels: u64,
    /// RGBA f32 texels of every level of every texture.
    pub texels: u64,
}

// SAFETY: plain `#[repr(C)]` data without pointers into host memory or padding-dependent
// invariants; the kernels read the same layout (checked by `static_assert` in common.cuh).
unsafe impl cudarc::driver::DeviceRepr for FrameUniforms {}
// SAFETY: as above; the fields are device addresses, passed by value.
unsafe impl cudarc::driver::DeviceRepr for SceneView {}
// SAFETY: plain `#[repr(C)]` data, copied to the device as is and read there with the layout of
// common.cuh (sizes `static_assert`ed, offsets compared at start-up by the layout probe).
unsafe impl cudarc::driver::DeviceRepr for DrawRecord {}
// SAFETY: as for `DrawRecord`.
unsafe impl cudarc::driver::DeviceRepr for TextureRecord {}
// SAFETY: as for `DrawRecord`.
unsafe impl cudarc::driver::DeviceRepr for LevelRecord {}
// SAFETY: as for `DrawRecord`.
unsafe impl cudarc::driver::DeviceRepr for SlotInfo {}
// SAFETY: as for `DrawRecord`.
unsafe impl cudarc::driver::DeviceRepr for DrawIssue {}

/// The scene flattened for upload: every array the kernels read, built once at `load`.
#[derive(Clone, Debug, Default)]
pub struct SceneArrays {
    /// Vertices of all meshes, mesh after mesh.
    pub vertices: Vec<StandardVertex>,
    /// Indices of all meshes (relative to their mesh), mesh after mesh.
    pub indices: Vec<u32>,
    /// One record per draw, in scene order.
    pub draws: Vec<DrawRecord>,
    /// One record per texture.
    pub textures: Vec<TextureRecord>,
    /// Every mip level of every texture.
    pub levels: Vec<LevelRecord>,
    /// Texels of every level, RGBA f32.
    pub texels: Vec<[f32; 4]>,
    /// Vertices shaded per frame (Σ over draws of their mesh's vertex count).
    pub shaded_count: u32,
    /// Triangle slots per frame.
    pub slot_count: u32,
}

/// Why a scene cannot be drawn by the CUDA backend.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum SceneLimit {
    /// A per-frame count exceeds what the kernels index with 32 bits.
    #[error("{what} ({count}) exceeds the CUDA backend's limit of {limit}")]
    TooLarge {
        /// What overflowed.
        what: &'static str,
        /// How many there are.
        count: u64,
        /// The most allowed.
        limit: u64,
    },
}

/// The most triangle slots, shaded vertices or indices one frame may have: slot indices,
/// setups (slots plus clipped fans) and bin references are `u32` in the kernels.
pub const MAX_FRAME_ELEMENTS: u64 = 1 << 30;

fn checked(what: &'static str, count: u64) -> Result<u32, SceneLimit> {
    if count > MAX_FRAME_ELEMENTS {
        return Err(SceneLimit::TooLarge {
            what,
            count,
            limit: MAX_FRAME_ELEMENTS,
        });
    }
    Ok(count as u32)
}

impl SceneArrays {
    /// Flattens a validated scene (`Scene::validate` has checked every index).
    pub fn new(scene: &Scene) -> Result<Self, SceneLimit> {
        let mut out = SceneArrays::default();
        let mut mesh_bases = Vec::with_capacity(scene.meshes.len());
        for mesh in &scene.meshes {
            let (vertices, indices) = StandardVertex::from_mesh(mesh);
            let vertex_base = checked("scene vertices", out.vertices.len() as u64)?;
            let index_base = checked("scene indices", out.indices.len() as u64)?;
            mesh_bases.push((
                vertex_base,
                vertices.len() as u32,
                index_base,
                // Lines and points are not drawn by this backend (yet): no triangles.
                mesh.triangle_count() as u32,
            ));
            out.vertices.extend_from_slice(&vertices);
            out.indices.extend_from_slice(&indices);
            checked("scene vertices", out.vertices.len() as u64)?;
            checked("scene indices", out.indices.len() as u64)?;
        }
        for texture in &scene.textures {
            out.textures.push(TextureRecord {
                first_level: out.levels.len() as u32,
                level_count: texture.level_count() as u32,
                width: texture.width(),
                height: texture.height(),
            });
            for level in texture.levels() {
                out.levels.push(LevelRecord {
                    offset: out.texels.len() as u64,
                    width: level.width,
                    height: level.height,
                });
                // The GPU filters linear f32 texels: the 8-bit levels decoded once, at upload.
                for y in 0..level.height {
                    for x in 0..level.width {
                        out.texels.push(level.texel(x, y).to_array());
                    }
                }
            }
        }
        let (mut shaded, mut slots) = (0u64, 0u64);
        for (i, draw) in scene.draws.iter().enumerate() {
            let material = &scene.materials[scene.meshes[draw.mesh].material];
            let (vertex_base, vertex_count, index_base, triangle_count) = mesh_bases[draw.mesh];
            let mut flags = 0;
            if material.unlit {
                flags |= DRAW_UNLIT;
            }
            if material.double_sided {
                flags |= DRAW_DOUBLE_SIDED;
            }
            let mut alpha_cutoff = 0.0;
            match material.alpha_mode {
                AlphaMode::Opaque => {}
                AlphaMode::Mask { cutoff } => {
                    flags |= DRAW_ALPHA_MASK;
                    alpha_cutoff = cutoff;
                }
                AlphaMode::Blend => flags |= DRAW_ALPHA_BLEND,
            }
            if draw.front_face() == FrontFace::Cw {
                flags |= DRAW_FRONT_CW;
            }
            if scene.meshes[draw.mesh].colors.is_some() {
                flags |= DRAW_VERTEX_COLORS;
            }
            let mut record = DrawRecord {
                model: draw.model.to_cols_array(),
                normal_matrix: normal_matrix(&draw.model).to_cols_array(),
                base_color_factor: material.base_color_factor.to_array(),
                alpha_cutoff,
                flags,
                node_id: draw.node_index as u32 + 1,
                draw_id: i as u32 + 1,
                vertex_base,
                vertex_count,
                index_base,
                triangle_count,
                shaded_base: checked("shaded vertices per frame", shaded)?,
                emissive: material.emissive.to_array(),
                ..DrawRecord::default()
            };
            if let Some(binding) = material.base_color_texture {
                record.flags |= DRAW_TEXTURED;
                record.texture = binding.texture as u32;
                record.sampler = SamplerCodes::new(&binding.sampler);
            }
            if let Some(binding) = material.emissive_texture {
                record.flags |= DRAW_EMISSIVE_TEXTURED;
                record.emissive_texture = binding.texture as u32;
                record.emissive_sampler = SamplerCodes::new(&binding.sampler);
            }
            shaded += vertex_count as u64;
            slots += triangle_count as u64;
            out.draws.push(record);
        }
        out.shaded_count = checked("shaded vertices per frame", shaded)?;
        out.slot_count = checked("triangles per frame", slots)?;
        Ok(out)
    }
}

/// `projection * view` as a column array (the kernels multiply it by each model matrix).
pub fn view_projection(projection: &Mat4, view: &Mat4) -> [f32; 16] {
    (*projection * *view).to_cols_array()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec3, Vec4};
    use kantele_rules::scene::{Draw, Material, Mesh, TextureBinding};
    use kantele_rules::shade::texture::{Sampler, Texture};
    use std::sync::Arc;

    fn triangle_mesh(material: usize) -> Mesh {
        Mesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            indices: vec![0, 1, 2],
            material,
            ..Mesh::default()
        }
    }

    #[test]
    fn draws_index_their_meshes_and_frame_slots_in_order() {
        let texture = Texture::from_rgba_f32(4, 2, vec![Vec4::ONE; 8]).expect("texture");
        let scene = Scene {
            meshes: vec![
                triangle_mesh(0),
                Mesh {
                    positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::ONE],
                    normals: Some(vec![Vec3::Z; 4]),
                    colors: Some(vec![Vec4::ONE; 4]),
                    indices: vec![0, 1, 2, 2, 1, 3],
                    material: 1,
                    ..Mesh::default()
                },
            ],
            materials: vec![
                Material::default(),
                Material {
                    double_sided: true,
                    alpha_mode: AlphaMode::Mask { cutoff: 0.25 },
                    base_color_texture: Some(TextureBinding {
                        texture: 0,
                        sampler: Sampler {
                            wrap_s: Wrap::MirroredRepeat,
                            min_filter: MinFilter::NearestMipmapLinear,
                            ..Sampler::default()
                        },
                        texcoord: 0,
                    }),
                    ..Material::default()
                },
            ],
            textures: vec![Arc::new(texture)],
            draws: vec![
                Draw {
                    mesh: 1,
                    model: Mat4::IDENTITY,
                    node_name: String::new(),
                    node_index: 4,
                },
                Draw {
                    mesh: 0,
                    model: Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)),
                    node_name: String::new(),
                    node_index: 7,
                },
                Draw {
                    mesh: 1,
                    model: Mat4::IDENTITY,
                    node_name: String::new(),
                    node_index: 9,
                },
            ],
            ..Scene::default()
        };
        let a = SceneArrays::new(&scene).expect("arrays");
        // Mesh 0 has no normals: flat shading un-indexes it (still 3 vertices).
        assert_eq!(a.vertices.len(), 3 + 4);
        assert_eq!(a.indices.len(), 3 + 6);
        let bases: Vec<(u32, u32, u32, u32)> = a
            .draws
            .iter()
            .map(|d| (d.vertex_base, d.index_base, d.shaded_base, d.triangle_count))
            .collect();
        assert_eq!(bases, vec![(3, 3, 0, 2), (0, 0, 4, 1), (3, 3, 7, 2)]);
        // Issued in another order, slots follow that order.
        let issue = draw_issue(&a.draws, &[2, 0, 1]);
        let issue: Vec<(u32, u32)> = issue.iter().map(|i| (i.draw, i.slot_base)).collect();
        assert_eq!(issue, vec![(2, 0), (0, 2), (1, 4)]);
        assert_eq!((a.shaded_count, a.slot_count), (11, 5));
        let d0 = a.draws[0];
        assert_eq!(
            d0.flags,
            DRAW_DOUBLE_SIDED | DRAW_ALPHA_MASK | DRAW_TEXTURED | DRAW_VERTEX_COLORS
        );
        assert_eq!(
            (d0.alpha_cutoff, d0.sampler.wrap_s, d0.sampler.min_filter),
            (0.25, 2, 4)
        );
        assert_eq!((d0.node_id, d0.draw_id), (5, 1));
        assert_eq!(a.draws[1].flags, DRAW_FRONT_CW, "the mirrored draw");
        assert_eq!((a.draws[2].node_id, a.draws[2].draw_id), (10, 3));
        // 4 × 2 → 2 × 1 → 1 × 1, texels laid out level after level.
        assert_eq!(a.textures[0].level_count, 3);
        let levels: Vec<(u64, u32, u32)> = a
            .levels
            .iter()
            .map(|l| (l.offset, l.width, l.height))
            .collect();
        assert_eq!(levels, vec![(0, 4, 2), (8, 2, 1), (10, 1, 1)]);
        assert_eq!(a.texels.len(), 11);
    }

    #[test]
    fn codes_are_distinct() {
        let mins = [
            MinFilter::Nearest,
            MinFilter::Linear,
            MinFilter::NearestMipmapNearest,
            MinFilter::LinearMipmapNearest,
            MinFilter::NearestMipmapLinear,
            MinFilter::LinearMipmapLinear,
        ];
        let mut codes: Vec<u32> = mins.iter().map(|m| min_filter_code(*m)).collect();
        codes.dedup();
        assert_eq!(codes.len(), 6);
        let wraps = [Wrap::Repeat, Wrap::ClampToEdge, Wrap::MirroredRepeat].map(wrap_code);
        assert_eq!(wraps, [0, 1, 2]);
    }
}
