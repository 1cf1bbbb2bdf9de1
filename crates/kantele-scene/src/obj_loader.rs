//! Wavefront OBJ with MTL materials.

use std::cell::RefCell;
use std::collections::HashMap;
use std::path::Path;

use glam::{Mat4, Vec2, Vec3, Vec4};
use kantele_rules::scene::{Draw, Light, Mesh, Scene, Topology};

use crate::ear_clip::triangulate_faces;
use crate::mesh_util::{first_index_out_of_range, flat_normals, framing_camera};
use crate::mtl_libraries::{MtlLibraries, MAX_LINE_WARNINGS};
use crate::obj_material::{default_material, Converter};
use crate::obj_text::{patch_obj, text, UNNAMED_MATERIAL};
use crate::obj_textures::ObjTextures;
use crate::obj_wide::{read_lines_points, vertex_color, ObjWide};
use crate::read_policy::{read_scene_file, ReadPolicy};
use crate::{LoadError, LoadOptions, LoadedScene, SceneInfo};

/// Bytes of memory charged per byte of OBJ text before parsing: the parser's vertices (with
/// one vertex per distinct corner), indices and the flat-shaded copy stay within this.
const OBJ_BYTES_PER_TEXT_BYTE: u64 = 32;

/// Loads an `.obj` file and the materials of its `.mtl` libraries.
pub fn load(path: &Path, options: &LoadOptions) -> Result<LoadedScene, LoadError> {
    let (bytes, mut budget) = read_scene_file(path, options.max_memory)?;
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
    // The MTL loader runs inside tobj (a `Fn`): what it changes goes through cells.
    let budget = RefCell::new(budget);
    let libraries = RefCell::new(MtlLibraries::new(&directory, &policy));
    let load_mtl = |name: &Path| -> tobj::MTLLoadResult {
        libraries
            .borrow_mut()
            .load(&name.to_string_lossy(), &mut budget.borrow_mut())
    };
    let tobj_options = tobj::LoadOptions {
        triangulate: false,
        single_index: true,
        ..Default::default()
    };
    let (models, _) = tobj::load_obj_buf(
        &mut std::io::Cursor::new(patched.text.as_bytes()),
        &tobj_options,
        load_mtl,
    )
    .map_err(|e| LoadError::invalid(path, format!("not a valid OBJ file: {e}")))?;
    drop(patched);
    let mut budget = budget.into_inner();
    let libraries = libraries.into_inner();
    if let Some(e) = &libraries.fatal {
        return Err(LoadError::invalid(path, e));
    }
    if let Some(e) = libraries.first_missing.as_ref().filter(|_| options.strict) {
        return Err(LoadError::invalid(path, e));
    }
    let mut info = SceneInfo {
        source: path.display().to_string(),
        node_count: models.len(),
        ..SceneInfo::default()
    };
    for w in &libraries.warnings {
        info.warn(w.as_str());
    }
    for i in &libraries.ignored {
        info.ignore(i.as_str());
    }
    let mut scene = Scene {
        light: Light::Headlight,
        resolution: (800, 600),
        ..Scene::default()
    };
    let mut textures = ObjTextures::new(&policy, options);
    // Per material: the texture-coordinate scale and offset of its textures.
    let mut material_uv: Vec<Option<(Vec2, Vec2)>> = Vec::new();
    for (m, folder) in &libraries.materials {
        let converted = Converter {
            textures: &mut textures,
            scene: &mut scene,
            info: &mut info,
            budget: &mut budget,
        }
        .convert(m, folder)
        .map_err(|e| LoadError::invalid(path, e))?;
        scene.materials.push(converted.material);
        material_uv.push(converted.uv);
    }
    textures.finish(&mut info);
    let material_names: Vec<String> = libraries
        .materials
        .iter()
        .map(|(m, _)| {
            if m.name.is_empty() {
                UNNAMED_MATERIAL.to_string()
            } else {
                m.name.clone()
            }
        })
        .collect();
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
        // The material's `-s` / `-o`; then OBJ's v, which runs upwards, turned to glTF's (and
        // Kantele's), which runs downwards from the image's top row.
        let (scale, offset) = m
            .material_id
            .and_then(|id| material_uv.get(id).copied().flatten())
            .unwrap_or((Vec2::ONE, Vec2::ZERO));
        let texcoords = (m.texcoords.len() == 2 * n).then(|| {
            m.texcoords
                .chunks_exact(2)
                .map(|t| {
                    let uv = Vec2::new(t[0], t[1]) * scale + offset;
                    Vec2::new(uv.x, 1.0 - uv.y)
                })
                .collect::<Vec<_>>()
        });
        let colors = (m.vertex_color.len() == 3 * n).then(|| {
            m.vertex_color
                .chunks_exact(3)
                .map(|c| vertex_color([c[0], c[1], c[2]]))
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
            texcoords1: None,
            tangents: None,
        };
        if mesh.normals.is_none() {
            // De-indexed: one vertex (position, normal, texcoord, colour) per corner.
            budget
                .charge(mesh.indices.len() as u64, 48, &what)
                .map_err(|e| LoadError::invalid(path, e))?;
            flat_normals(&mut mesh);
        }
        let pbr = options.shading == Some(kantele_rules::scene::Shading::Pbr);
        if pbr && scene.materials[mesh.material].normal_texture.is_some() {
            // MikkTSpace tangents for the normal map (the MTL's maps read the one set); only
            // PBR shading reads them.
            crate::tangents::generate(&mut mesh, 0, &mut budget, &what)
                .map_err(|e| LoadError::invalid(path, e))?;
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
        add_lines_points(
            &mut scene,
            &mut info,
            wide,
            &material_names,
            &mut default_index,
        );
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
    Ok(LoadedScene {
        scene,
        info,
        animation: None,
    })
}

/// Adds a mesh and a draw for each group of `l` / `p` statements (or of the vertices of a file
/// of vertices alone), with only the positions (and colours) it uses; its material is the
/// `usemtl` in force (by name, the last of that name as in `tobj`), else the default one.
fn add_lines_points(
    scene: &mut Scene,
    info: &mut SceneInfo,
    wide: ObjWide,
    material_names: &[String],
    default_index: &mut Option<usize>,
) {
    let skipped = wide.warnings.len();
    for w in wide.warnings.into_iter().take(MAX_LINE_WARNINGS) {
        info.warn(w);
    }
    if skipped > MAX_LINE_WARNINGS {
        info.warn(format!(
            "{} more l / p statements with a bad vertex reference are skipped",
            skipped - MAX_LINE_WARNINGS
        ));
    }
    for (k, group) in wide.groups.into_iter().enumerate() {
        let named = group.material.as_ref().and_then(|name| {
            material_names
                .iter()
                .rposition(|m| m == name)
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
