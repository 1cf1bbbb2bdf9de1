//! Built-in demo scenes, generated in code (no asset files).

mod cube;
mod ground;
mod pbr;
mod pixel_edges;
mod teapot;
mod teapot_data;

use glam::Vec4;
use kantele_rules::scene::Scene;

use crate::{LoadedScene, SceneInfo};

/// Names and descriptions of the built-in scenes.
pub const SCENES: &[(&str, &str)] = &[
    (
        "cube",
        "the thesis' textured cube: 256x256 checker, trilinear + REPEAT, unlit, top face at a grazing angle",
    ),
    (
        "teapot",
        "the Utah teapot tessellated from Newell's 32 Bezier patches, Lambert, directional light",
    ),
    (
        "ground",
        "a huge checker ground plane reaching behind the camera, a cube and a triangle standing on it",
    ),
    (
        "pixel-edges",
        "quads whose edges run exactly through pixel centres: only the fill rule decides their edge pixels",
    ),
    (
        "pbr-spheres",
        "PBR: 5x5 spheres over metallic (up) and roughness (right) in the built-in studio with a key light",
    ),
    (
        "pbr-lights",
        "PBR: a normal-mapped floor, a gold and a plastic sphere under a point and a spot light with ranges",
    ),
    (
        "pbr-glass",
        "PBR: clear and frosted glass panes, a clear and a tinted glass volume over a checker (transmission)",
    ),
    (
        "pbr-sheen",
        "PBR: velvet spheres over sheen colour and roughness, on a woven cloth floor (sheen)",
    ),
];

/// Background of the built-in scenes: a dark grey-blue (linear).
pub const CLEAR_COLOR: Vec4 = Vec4::new(0.035, 0.045, 0.07, 1.0);

/// Builds the built-in scene `name`, if there is one.
pub fn build(name: &str) -> Option<LoadedScene> {
    let (scene, info) = match name {
        "cube" => cube::scene(),
        "teapot" => teapot::scene(),
        "ground" => ground::scene(),
        "pixel-edges" => pixel_edges::scene(),
        "pbr-spheres" => pbr::spheres(),
        "pbr-lights" => pbr::lights(),
        "pbr-glass" => pbr::glass(),
        "pbr-sheen" => pbr::sheen(),
        _ => return None,
    };
    Some(finish(name, scene, info))
}

fn finish(name: &str, scene: Scene, mut info: SceneInfo) -> LoadedScene {
    info.source = format!("builtin:{name}");
    info.node_count = scene.draws.len() + info.cameras.len() + info.lights.len();
    LoadedScene {
        scene,
        info,
        animation: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_listed_builtin_builds_and_validates() {
        for (name, description) in SCENES {
            assert!(!description.is_empty());
            let loaded = build(name).unwrap_or_else(|| panic!("builtin {name} missing"));
            assert_eq!(loaded.info.source, format!("builtin:{name}"));
            assert!(loaded.scene.triangle_count() > 0, "{name} has no triangles");
            loaded
                .scene
                .validate()
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(loaded.info.camera_from_file);
            if loaded.scene.shading == kantele_rules::scene::Shading::Lambert {
                assert_eq!(loaded.scene.clear_color, CLEAR_COLOR);
            }
            for mesh in &loaded.scene.meshes {
                assert!(
                    mesh.normals.is_some(),
                    "{name}: mesh {} lacks normals",
                    mesh.name
                );
            }
        }
        assert!(build("nope").is_none());
    }
}
