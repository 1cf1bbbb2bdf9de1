//! A diagnostic scene whose every edge runs exactly through pixel centres, so the fill rule
//! alone decides the edge pixels: a renderer with the wrong tie rule disagrees with OpenGL on
//! about a tenth of the picture (used to prove that `kantele compare` catches such a bug).

use glam::{Mat4, Vec3, Vec4};
use kantele_rules::scene::{Camera, Draw, Light, Material, Mesh, Scene};

use super::CLEAR_COLOR;
use crate::SceneInfo;

/// Image size in pixels.
const WIDTH: u32 = 128;
const HEIGHT: u32 = 96;
/// Quads per row and column, their side and spacing in pixels.
const COLUMNS: u32 = 6;
const ROWS: u32 = 4;
const SIDE: f32 = 15.0;
const PITCH: u32 = 20;

/// World position (on the plane z = −1) of the image point `(x, y)` in pixels, for a camera at
/// the origin looking down −Z with tan(yfov / 2) = 0.5. Rounding errors are far below the
/// 1/256-pixel snapping grid, so vertices snap exactly onto pixel centres.
fn on_plane(x: f32, y: f32) -> Vec3 {
    let aspect = WIDTH as f32 / HEIGHT as f32;
    let x_ndc = x / WIDTH as f32 * 2.0 - 1.0;
    let y_ndc = 1.0 - y / HEIGHT as f32 * 2.0;
    Vec3::new(x_ndc * 0.5 * aspect, y_ndc * 0.5, -1.0)
}

pub fn scene() -> (Scene, SceneInfo) {
    let mut positions = Vec::new();
    let mut colors = Vec::new();
    let mut indices = Vec::new();
    for row in 0..ROWS {
        for column in 0..COLUMNS {
            // Corners on pixel centres (k + 0.5).
            let x0 = 4.5 + (column * PITCH) as f32;
            let y0 = 8.5 + (row * PITCH) as f32;
            let first = positions.len() as u32;
            // Counter-clockwise on screen with y up: top-left, bottom-left, bottom-right, top-right.
            positions.extend([
                on_plane(x0, y0),
                on_plane(x0, y0 + SIDE),
                on_plane(x0 + SIDE, y0 + SIDE),
                on_plane(x0 + SIDE, y0),
            ]);
            let shade = (row * COLUMNS + column) as f32 / (ROWS * COLUMNS) as f32;
            colors.extend([Vec4::new(0.2 + 0.8 * shade, 0.6, 1.0 - 0.8 * shade, 1.0); 4]);
            indices.extend([first, first + 1, first + 2, first, first + 2, first + 3]);
        }
    }
    let mesh = Mesh {
        name: "pixel-edge quads".into(),
        normals: Some(vec![Vec3::Z; positions.len()]),
        positions,
        texcoords: None,
        colors: Some(colors),
        indices,
        material: 0,
        topology: kantele_rules::scene::Topology::Triangles,
        texcoords1: None,
        tangents: None,
    };
    let scene = Scene {
        file_cameras: Vec::new(),
        meshes: vec![mesh],
        materials: vec![Material {
            name: "unlit vertex colour".into(),
            unlit: true,
            ..Material::default()
        }],
        textures: Vec::new(),
        draws: vec![Draw {
            mesh: 0,
            model: Mat4::IDENTITY,
            node_name: "quads".into(),
            node_index: 0,
        }],
        camera: Camera {
            view: Mat4::IDENTITY,
            yfov: 2.0 * 0.5f32.atan(),
            ymag: None,
            aspect_ratio: Some(WIDTH as f32 / HEIGHT as f32),
            znear: 0.1,
            zfar: Some(10.0),
        },
        light: Light::Headlight,
        ambient: 0.1,
        clear_color: CLEAR_COLOR,
        resolution: (WIDTH, HEIGHT),
        ..Scene::default()
    };
    let info = SceneInfo {
        cameras: vec!["pixel-centre camera".into()],
        camera_from_file: true,
        ..SceneInfo::default()
    };
    (scene, info)
}
