//! Wavefront OBJ with MTL materials.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3, Vec4};
use kantele::scene::{AlphaMode, Draw, Light, Material, Mesh, Scene, TextureBinding};
use kantele::shade::texture::Texture;

use crate::budget::Budget;
use crate::mesh_util::{first_index_out_of_range, flat_normals, framing_camera};
use crate::read_policy::ReadPolicy;
use crate::texture_util::{
    decode_srgb_within, image_size, placeholder, trilinear_repeat, ImageError,
};
use crate::{LoadError, LoadOptions, LoadedScene, SceneInfo};

/// Loads an `.obj` file and the materials of its `.mtl` libraries.
pub fn load(path: &Path, options: &LoadOptions) -> Result<LoadedScene, LoadError> {
    // tobj reports a missing file only as "open file failed": look first, for a proper message.
    std::fs::metadata(path).map_err(|source| LoadError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let tobj_options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, materials) = tobj::load_obj(path, &tobj_options)
        .map_err(|e| LoadError::invalid(path, format!("not a valid OBJ file: {e}")))?;
    let mut info = SceneInfo {
        source: path.display().to_string(),
        node_count: models.len(),
        ..SceneInfo::default()
    };
    let mut scene = Scene {
        light: Light::Headlight,
        resolution: (800, 600),
        ..Scene::default()
    };
    let directory = path.parent().unwrap_or(Path::new(""));
    let materials = match materials {
        Ok(m) => m,
        Err(e) => {
            info.warn(format!(
                "the material library could not be read ({e}); using the default material"
            ));
            Vec::new()
        }
    };
    let policy = ReadPolicy::new(path, &options.allow_read);
    let mut budget = Budget::new(options.max_memory);
    let mut texture_files: HashMap<String, Option<usize>> = HashMap::new();
    for m in &materials {
        let base_color_texture = match m.diffuse_texture.as_deref().map(str::trim) {
            Some(name) if !name.is_empty() => {
                let texture = match texture_files.get(name) {
                    Some(&t) => t,
                    None => {
                        let file = directory.join(name.replace('\\', "/"));
                        let what = format!("material '{}': texture {}", m.name, file.display());
                        let t = match load_texture(&file, &policy, &mut budget, options) {
                            Ok(texture) => {
                                scene.textures.push(Arc::new(texture.0));
                                info.texture_sizes.push(texture.1);
                                Some(scene.textures.len() - 1)
                            }
                            Err(ImageError::Budget(e)) => {
                                return Err(LoadError::invalid(path, format!("{what}: {e}")))
                            }
                            Err(ImageError::Decode(e)) if options.strict => {
                                return Err(LoadError::invalid(path, format!("{what}: {e}")))
                            }
                            Err(ImageError::Decode(e)) => {
                                info.warn(format!(
                                    "{what}: {e}; drawn untextured (--strict makes this an error)"
                                ));
                                None
                            }
                        };
                        texture_files.insert(name.to_string(), t);
                        t
                    }
                };
                texture.map(|texture| TextureBinding {
                    texture,
                    sampler: trilinear_repeat(),
                })
            }
            _ => None,
        };
        let diffuse = m.diffuse.unwrap_or([1.0; 3]);
        let dissolve = m.dissolve.unwrap_or(1.0);
        let (alpha, alpha_mode) = if dissolve.is_finite() && dissolve < 1.0 {
            (dissolve.max(0.0), AlphaMode::Blend)
        } else {
            (1.0, AlphaMode::Opaque)
        };
        scene.materials.push(Material {
            name: m.name.clone(),
            base_color_factor: Vec4::new(diffuse[0], diffuse[1], diffuse[2], alpha),
            base_color_texture,
            double_sided: false,
            alpha_mode,
            unlit: false,
        });
    }
    let mut default_material = None;

    for (model_index, model) in models.iter().enumerate() {
        let m = &model.mesh;
        let what = format!("object '{}'", model.name);
        let positions: Vec<Vec3> = m
            .positions
            .chunks_exact(3)
            .map(|p| Vec3::new(p[0], p[1], p[2]))
            .collect();
        let n = positions.len();
        if n == 0 || m.indices.is_empty() {
            continue;
        }
        let normals = (m.normals.len() == 3 * n).then(|| {
            m.normals
                .chunks_exact(3)
                .map(|v| Vec3::new(v[0], v[1], v[2]))
                .collect::<Vec<_>>()
        });
        if normals.is_none() && !m.normals.is_empty() {
            info.warn(format!(
                "{what}: only some vertices have normals; using flat normals"
            ));
        }
        // OBJ's v runs upwards; glTF's (and Kantele's) downwards from the image's top row.
        let texcoords = (m.texcoords.len() == 2 * n).then(|| {
            m.texcoords
                .chunks_exact(2)
                .map(|t| Vec2::new(t[0], 1.0 - t[1]))
                .collect::<Vec<_>>()
        });
        let colors = (m.vertex_color.len() == 3 * n).then(|| {
            m.vertex_color
                .chunks_exact(3)
                .map(|c| Vec4::new(c[0], c[1], c[2], 1.0))
                .collect::<Vec<_>>()
        });
        if m.indices.len() % 3 != 0 {
            return Err(LoadError::invalid(
                path,
                format!("{what}: the faces do not make whole triangles"),
            ));
        }
        if let Some((position, index)) = first_index_out_of_range(&m.indices, n) {
            return Err(LoadError::invalid(
                path,
                format!(
                    "{what}: index {index} at position {position} is out of range for {n} vertices"
                ),
            ));
        }
        let material = match m.material_id {
            Some(id) if id < scene.materials.len() => id,
            other => {
                if let Some(id) = other {
                    info.warn(format!(
                        "{what}: material {id} does not exist; using the default material"
                    ));
                }
                *default_material.get_or_insert_with(|| {
                    scene.materials.push(Material::default());
                    scene.materials.len() - 1
                })
            }
        };
        let mut mesh = Mesh {
            name: model.name.clone(),
            positions,
            normals,
            texcoords,
            colors,
            indices: m.indices.clone(),
            material,
        };
        if mesh.normals.is_none() {
            flat_normals(&mut mesh);
        }
        scene.meshes.push(mesh);
        scene.draws.push(Draw {
            mesh: scene.meshes.len() - 1,
            model: Mat4::IDENTITY,
            node_name: model.name.clone(),
            node_index: model_index,
        });
    }
    if scene.draws.is_empty() {
        info.warn("the file has no faces: nothing is drawn");
    }
    scene.camera = framing_camera(&scene);
    scene
        .validate()
        .map_err(|e| LoadError::invalid(path, e.to_string()))?;
    Ok(LoadedScene { scene, info })
}

/// Reads and decodes a texture file under the read policy and budget (a placeholder when
/// textures are not decoded); with its header size.
fn load_texture(
    file: &Path,
    policy: &ReadPolicy,
    budget: &mut Budget,
    options: &LoadOptions,
) -> Result<(Texture, (u32, u32)), ImageError> {
    let bytes = policy.read(file, budget).map_err(|e| {
        if e.contains("memory budget") {
            ImageError::Budget(e)
        } else {
            ImageError::Decode(e)
        }
    })?;
    let size = image_size(&bytes, None)?;
    if !options.decode_textures {
        return Ok((placeholder(), size));
    }
    Ok((decode_srgb_within(&bytes, None, budget)?, size))
}
