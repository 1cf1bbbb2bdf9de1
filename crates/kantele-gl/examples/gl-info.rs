//! Prints what the GL backend runs on, then times frames of a synthetic scene (a lit grid of
//! triangles filling a 1280 × 720 image) with the float and the 8-bit target.
//!
//! `cargo run -p kantele-gl --release --example gl-info [-- TRIANGLES]`

use std::sync::Arc;
use std::time::Duration;

use glam::{Mat4, Vec3, Vec4};
use kantele::backend::{Backend, FrameView, Pass};
use kantele::scene::{Draw, Material, Mesh, Scene};
use kantele_gl::GlBackend;

fn grid(triangles: usize) -> Mesh {
    let cells = ((triangles / 2) as f64).sqrt().ceil().max(1.0) as u32;
    let n = cells + 1;
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let x = i as f32 / cells as f32 * 2.0 - 1.0;
            let y = j as f32 / cells as f32 * 2.0 - 1.0;
            positions.push(Vec3::new(x, y, 0.1 * (x * 7.0).sin() * (y * 5.0).cos()));
            normals.push(Vec3::new(0.3 * x, 0.2 * y, 1.0).normalize());
        }
    }
    let mut indices = Vec::new();
    for j in 0..cells {
        for i in 0..cells {
            let a = j * n + i;
            indices.extend_from_slice(&[a, a + 1, a + n + 1, a, a + n + 1, a + n]);
        }
    }
    Mesh {
        name: "grid".into(),
        positions,
        normals: Some(normals),
        indices,
        ..Mesh::default()
    }
}

fn main() {
    let triangles: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(1_000_000);
    let mut gl = match GlBackend::new() {
        Ok(gl) => gl,
        Err(e) => {
            eprintln!("no GL: {e}");
            std::process::exit(1);
        }
    };
    println!("renderer: {}", gl.renderer());
    println!("version:  {}", gl.gl_version());
    println!("platform: {}", gl.platform());

    let scene = Scene {
        meshes: vec![grid(triangles)],
        materials: vec![Material {
            base_color_factor: Vec4::new(0.8, 0.5, 0.3, 1.0),
            ..Material::default()
        }],
        draws: vec![Draw {
            mesh: 0,
            model: Mat4::IDENTITY,
            node_name: "grid".into(),
            node_index: 0,
        }],
        ..Scene::default()
    };
    let triangles = scene.triangle_count();
    gl.load(Arc::new(scene)).expect("load");
    let view = FrameView {
        width: 1280,
        height: 720,
        view: Mat4::IDENTITY,
        projection: Mat4::IDENTITY,
        to_light: Vec3::new(0.3, 0.4, 1.0).normalize(),
        light_color: Vec3::ONE,
        pass: Pass::Color,
    };
    for fast in [false, true] {
        gl.set_fast_target(fast);
        for _ in 0..3 {
            gl.render(&view).expect("warm-up frame");
        }
        let mut times: Vec<Duration> = (0..20)
            .map(|_| gl.render(&view).expect("frame").total_time)
            .collect();
        times.sort();
        println!(
            "{} target: {triangles} triangles at 1280x720, median frame {:.2} ms",
            if fast { "RGBA8  " } else { "RGBA32F" },
            times[times.len() / 2].as_secs_f64() * 1e3
        );
    }
}
