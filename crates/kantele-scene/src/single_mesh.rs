//! The scene of a file that holds one mesh and nothing else (PLY, STL): no materials, cameras or
//! lights of its own. It gets one light grey, double-sided material (scans and CAD exports have
//! no reliable winding), the headlight, a framing camera and Lambert shading unless the options
//! choose otherwise, as OBJ files do.

use std::path::Path;

use glam::{Mat4, Vec3, Vec4};
use kantele_rules::scene::{Draw, Light, Material, Mesh, Scene, Shading};

use crate::budget::Budget;
use crate::mesh_util::framing_camera;
use crate::read_policy::read_scene_file;
use crate::{LoadError, LoadOptions, LoadedScene, SceneInfo};

/// Linear base colour of the material of a mesh without vertex colours: a light grey (sRGB
/// 218) on which the shading shows.
pub(crate) const LIGHT_GREY: f32 = 0.7;

/// The material of a single-mesh file: light grey, or white when the mesh has vertex colours
/// (they multiply the base colour and are shown as they are); double-sided; for PBR shading a
/// fully rough dielectric.
pub(crate) fn single_mesh_material(vertex_colors: bool) -> Material {
    let base = if vertex_colors { 1.0 } else { LIGHT_GREY };
    Material {
        name: String::new(),
        base_color_factor: Vec4::new(base, base, base, 1.0),
        double_sided: true,
        metallic: 0.0,
        roughness: 1.0,
        ..Material::default()
    }
}

/// Face normals of a de-indexed triangle list (`positions` three corners a triangle): every
/// corner gets `normalize((b − a) × (c − a))` of its triangle, +Z for degenerate or non-finite
/// ones, as [`Mesh::flat_shaded`] computes them.
pub(crate) fn face_normals(positions: &[Vec3]) -> Vec<Vec3> {
    let mut normals = Vec::with_capacity(positions.len());
    for corners in positions.chunks_exact(3) {
        let [a, b, c] = [corners[0], corners[1], corners[2]];
        let normal = (b - a).cross(c - a).try_normalize().unwrap_or(Vec3::Z);
        normals.extend([normal; 3]);
    }
    normals
}

/// The scene of `mesh`, the only mesh of the file at `path` (its `material` is set here):
/// drawn once at the origin, framed by a made-up camera, lit by the headlight. A mesh without
/// primitives draws nothing (with a warning).
/// Loads a file holding one mesh (PLY, STL): reads it under the read policy and the budget,
/// hands its bytes, its name and the budget to `read_mesh` (whose error becomes a one-line
/// error naming the file), and makes the scene of [`single_mesh_scene`].
pub(crate) fn load_single_mesh(
    path: &Path,
    options: &LoadOptions,
    read_mesh: impl FnOnce(Vec<u8>, String, &mut Budget, &mut SceneInfo) -> Result<Mesh, String>,
) -> Result<LoadedScene, LoadError> {
    let (bytes, mut budget) = read_scene_file(path, options.max_memory)?;
    let mut info = SceneInfo {
        source: path.display().to_string(),
        node_count: 1,
        ..SceneInfo::default()
    };
    let mesh = read_mesh(bytes, mesh_name(path), &mut budget, &mut info)
        .map_err(|e| LoadError::invalid(path, e))?;
    single_mesh_scene(path, mesh, info, options, budget)
}

pub(crate) fn single_mesh_scene(
    path: &Path,
    mut mesh: Mesh,
    mut info: SceneInfo,
    options: &LoadOptions,
    mut budget: Budget,
) -> Result<LoadedScene, LoadError> {
    let mut scene = Scene {
        light: Light::Headlight,
        resolution: (800, 600),
        ..Scene::default()
    };
    scene
        .materials
        .push(single_mesh_material(mesh.colors.is_some()));
    if mesh.positions.iter().any(|p| !p.is_finite()) {
        info.warn(format!(
            "{}: some positions are infinite or NaN; primitives using them are not drawn",
            mesh.name
        ));
    }
    if mesh.indices.is_empty() {
        info.warn("the file has no faces or points: nothing is drawn");
    } else {
        mesh.material = 0;
        let node_name = mesh.name.clone();
        scene.meshes.push(mesh);
        scene.draws.push(Draw {
            mesh: 0,
            model: Mat4::IDENTITY,
            node_name,
            node_index: 0,
        });
    }
    scene.camera = framing_camera(&scene);
    scene
        .validate()
        .map_err(|e| LoadError::invalid(path, e.to_string()))?;
    crate::shading::apply(
        &mut scene,
        &mut info,
        options,
        Shading::Lambert,
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

/// The name of a file's mesh: its file name without the extension.
pub(crate) fn mesh_name(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;
    use kantele_rules::scene::Topology;

    #[test]
    fn face_normals_match_flat_shading() {
        let positions = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::ZERO,
            Vec3::Y,
            Vec3::X,
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::NAN,
            Vec3::X,
            Vec3::Y,
        ];
        let mesh = Mesh {
            positions: positions.clone(),
            indices: (0..positions.len() as u32).collect(),
            topology: Topology::Triangles,
            ..Mesh::default()
        };
        let flat = mesh.flat_shaded();
        assert_eq!(Some(face_normals(&positions)), flat.normals);
        assert_eq!(face_normals(&positions)[3], -Vec3::Z);
    }

    #[test]
    fn the_material_is_grey_or_white_and_double_sided() {
        let grey = single_mesh_material(false);
        assert!(grey.double_sided);
        assert_eq!(grey.base_color_factor, Vec4::new(0.7, 0.7, 0.7, 1.0));
        assert_eq!(single_mesh_material(true).base_color_factor, Vec4::ONE);
    }
}
