//! Wavefront OBJ with MTL materials.

use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3, Vec4};
use kantele_rules::scene::{
    AlphaMode, Draw, Light, Material, Mesh, Scene, TextureBinding, Topology,
};
use kantele_rules::shade::texture::Texture;

use crate::budget::Budget;
use crate::ear_clip::triangulate_faces;
use crate::mesh_util::{first_index_out_of_range, flat_normals, framing_camera};
use crate::obj_text::{patch_mtl, patch_obj, text, texture_file_name, UNNAMED_MATERIAL};
use crate::obj_wide::{read_lines_points, ObjWide};
use crate::read_policy::{read_regular_file, ReadPolicy};
use crate::texture_util::{
    decode_srgb_within, image_size, placeholder, trilinear_repeat, ImageError,
};
use crate::{LoadError, LoadOptions, LoadedScene, SceneInfo};

/// Bytes of memory charged per byte of OBJ text before parsing: the parser's vertices (with
/// one vertex per distinct corner), indices and the flat-shaded copy stay within this.
const OBJ_BYTES_PER_TEXT_BYTE: u64 = 32;

/// Loads an `.obj` file and the materials of its `.mtl` libraries.
pub fn load(path: &Path, options: &LoadOptions) -> Result<LoadedScene, LoadError> {
    std::fs::metadata(path).map_err(|source| LoadError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let mut budget = Budget::new(options.max_memory);
    let bytes = read_regular_file(path, &mut budget).map_err(|e| LoadError::invalid(path, e))?;
    budget
        .charge(
            bytes.len() as u64,
            OBJ_BYTES_PER_TEXT_BYTE,
            "parsing the OBJ text",
        )
        .map_err(|e| LoadError::invalid(path, e))?;
    let source = text(&bytes);
    drop(bytes);
    let patched = patch_obj(&source);
    // A file of vertices alone is drawn as points.
    let vertices_only = patched.faces == 0 && patched.lines == 0 && patched.points == 0;
    let wide = (patched.lines + patched.points > 0 || (vertices_only && patched.vertices > 0))
        .then(|| read_lines_points(&source, vertices_only));
    drop(source);
    let policy = ReadPolicy::new(path, &options.allow_read);
    let directory = path.parent().unwrap_or(Path::new("")).to_path_buf();
    // The MTL loader runs inside tobj (a `Fn`): what it needs to change goes through cells.
    let budget = RefCell::new(budget);
    let material_dirs: RefCell<Vec<PathBuf>> = RefCell::new(Vec::new());
    let mtl_warnings: RefCell<Vec<String>> = RefCell::new(Vec::new());
    let load_mtl = |name: &Path| -> tobj::MTLLoadResult {
        let file = directory.join(name.to_string_lossy().replace('\\', "/"));
        let bytes = policy.read(&file, &mut budget.borrow_mut()).map_err(|e| {
            mtl_warnings
                .borrow_mut()
                .push(format!("material library {}: {e}", name.display()));
            tobj::LoadError::OpenFileFailed
        })?;
        let (mtl, warnings) = patch_mtl(&text(&bytes));
        for w in warnings {
            mtl_warnings
                .borrow_mut()
                .push(format!("material library {}: {w}", name.display()));
        }
        let result = tobj::load_mtl_buf(&mut std::io::Cursor::new(mtl.as_bytes()));
        if let Ok((materials, _)) = &result {
            let dir = file.parent().unwrap_or(Path::new("")).to_path_buf();
            material_dirs
                .borrow_mut()
                .extend(std::iter::repeat_n(dir, materials.len()));
        }
        result
    };
    let tobj_options = tobj::LoadOptions {
        triangulate: false,
        single_index: true,
        ..Default::default()
    };
    let (models, materials) = tobj::load_obj_buf(
        &mut std::io::Cursor::new(patched.text.as_bytes()),
        &tobj_options,
        load_mtl,
    )
    .map_err(|e| LoadError::invalid(path, format!("not a valid OBJ file: {e}")))?;
    let mut budget = budget.into_inner();
    let material_dirs = material_dirs.into_inner();
    let mut info = SceneInfo {
        source: path.display().to_string(),
        node_count: models.len(),
        ..SceneInfo::default()
    };
    for w in mtl_warnings.into_inner() {
        info.warn(w);
    }
    let mut scene = Scene {
        light: Light::Headlight,
        resolution: (800, 600),
        ..Scene::default()
    };
    let materials = match materials {
        Ok(m) => m,
        Err(e) => {
            info.warn(format!(
                "the material library could not be read ({e}); using the default material"
            ));
            Vec::new()
        }
    };
    let mut texture_files: HashMap<PathBuf, Option<usize>> = HashMap::new();
    for (material_index, m) in materials.iter().enumerate() {
        let base_color_texture = match m.diffuse_texture.as_deref().map(texture_file_name) {
            Some(name) if !name.is_empty() => {
                // Relative to the folder of the MTL file that names it.
                let folder = material_dirs.get(material_index).unwrap_or(&directory);
                let file = folder.join(name.replace('\\', "/"));
                let texture = match texture_files.get(&file) {
                    Some(&t) => t,
                    None => {
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
                        texture_files.insert(file.clone(), t);
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
        let name = if m.name == UNNAMED_MATERIAL {
            String::new()
        } else {
            m.name.clone()
        };
        scene.materials.push(Material {
            name,
            base_color_factor: Vec4::new(diffuse[0], diffuse[1], diffuse[2], alpha),
            base_color_texture,
            // OBJ states no winding: faces show from both sides.
            double_sided: true,
            alpha_mode,
            unlit: false,
            // For PBR shading: a dielectric whose roughness follows the specular exponent
            // (`Ns`, Blender's conversion `√(2 / (Ns + 2))`), fully rough without one.
            metallic: 0.0,
            roughness: m
                .shininess
                .filter(|s| s.is_finite() && *s >= 0.0)
                .map_or(1.0, |s| (2.0 / (s + 2.0)).sqrt()),
            ..Material::default()
        });
    }
    let mut default_index = None;

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
        if let Some((position, index)) = first_index_out_of_range(&m.indices, n) {
            return Err(LoadError::invalid(
                path,
                format!(
                    "{what}: index {index} at position {position} is out of range for {n} vertices"
                ),
            ));
        }
        let indices = triangulate_faces(&m.indices, &m.face_arities, &positions, &mut budget)
            .map_err(|e| LoadError::invalid(path, format!("{what}: {e}")))?;
        if indices.is_empty() {
            continue;
        }
        if positions.iter().any(|p| !p.is_finite()) {
            info.warn(format!(
                "{what}: some positions are infinite or NaN; faces using them are not drawn"
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
                *default_index.get_or_insert_with(|| {
                    scene.materials.push(default_material());
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
            indices,
            topology: Topology::Triangles,
            material,
        };
        if mesh.normals.is_none() {
            // De-indexed: one vertex (position, normal, texcoord, colour) per corner.
            budget
                .charge(mesh.indices.len() as u64, 48, &what)
                .map_err(|e| LoadError::invalid(path, e))?;
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
    if let Some(wide) = wide {
        add_lines_points(&mut scene, &mut info, wide, &materials, &mut default_index);
    }
    if scene.draws.is_empty() {
        info.warn("the file has no faces, lines or points: nothing is drawn");
    }
    scene.camera = framing_camera(&scene);
    scene
        .validate()
        .map_err(|e| LoadError::invalid(path, e.to_string()))?;
    crate::shading::apply(
        &mut scene,
        &mut info,
        options,
        kantele_rules::scene::Shading::Lambert,
        false,
        &mut budget,
    )
    .map_err(|e| LoadError::invalid(path, e))?;
    Ok(LoadedScene { scene, info })
}

/// The material of faces without one: white, dielectric, fully rough and, as every OBJ
/// material, double-sided.
fn default_material() -> Material {
    Material {
        double_sided: true,
        metallic: 0.0,
        ..Material::default()
    }
}

/// Adds a mesh and a draw for each group of `l` / `p` statements (or of the vertices of a file
/// of vertices alone), with only the positions (and colours) it uses; its material is the
/// `usemtl` in force (by name, the last of that name as in `tobj`), else the default one.
fn add_lines_points(
    scene: &mut Scene,
    info: &mut SceneInfo,
    wide: ObjWide,
    materials: &[tobj::Material],
    default_index: &mut Option<usize>,
) {
    for w in wide.warnings {
        info.warn(w);
    }
    for (k, group) in wide.groups.into_iter().enumerate() {
        let named = group.material.as_ref().and_then(|name| {
            materials
                .iter()
                .rposition(|m| &m.name == name)
                .filter(|&i| i < scene.materials.len())
        });
        let material = named.unwrap_or_else(|| {
            *default_index.get_or_insert_with(|| {
                scene.materials.push(default_material());
                scene.materials.len() - 1
            })
        });
        let mut remap: HashMap<u32, u32> = HashMap::new();
        let mut used = Vec::new();
        let indices = group
            .indices
            .iter()
            .map(|&i| {
                *remap.entry(i).or_insert_with(|| {
                    used.push(i as usize);
                    used.len() as u32 - 1
                })
            })
            .collect();
        let positions = used.iter().map(|&i| wide.positions[i]).collect();
        let colors: Option<Vec<Vec4>> = wide.colors.as_ref().map(|colors| {
            used.iter()
                .map(|&i| colors.get(i).copied().unwrap_or(Vec4::ONE))
                .collect()
        });
        let name = format!("{} {k}", group.topology.name());
        scene.meshes.push(Mesh {
            name: name.clone(),
            positions,
            colors,
            indices,
            topology: group.topology,
            material,
            ..Mesh::default()
        });
        scene.draws.push(Draw {
            mesh: scene.meshes.len() - 1,
            model: Mat4::IDENTITY,
            node_name: name,
            node_index: info.node_count + k,
        });
    }
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
