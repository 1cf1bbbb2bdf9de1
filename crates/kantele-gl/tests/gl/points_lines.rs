//! Points and lines drawn by Kantele and by OpenGL (`GL_POINTS`, `GL_LINES`, size and width 1):
//! points must cover the same pixels exactly; lines the same pixels except for a few at their
//! ends (llvmpipe's diamond-exit arithmetic is in float, Kantele's moved ends are exact; every
//! differing pixel must lie within 1.5 pixels of an end, and at most one per four segments),
//! with the same colours where both draw (interpolated along the line). Skips (with a message) where
//! EGL/OpenGL is unavailable.

use std::sync::Arc;

use glam::{Mat4, Vec3, Vec4};
use kantele::backend::{Backend, FrameImage, FrameView};
use kantele::cpu::{CpuBackend, CpuOptions};
use kantele::scene::{Draw, Material, Mesh, Scene, Topology};

use crate::common::{gl_or_skip, render};

const W: u32 = 160;
const H: u32 = 120;

/// A small deterministic generator (xorshift), so failures reproduce.
struct Random(u64);

impl Random {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// One mesh of `topology` with positions given in NDC (drawn with identity matrices), coloured
/// by vertex (unlit: no normals).
fn scene(topology: Topology, positions: Vec<Vec3>, colors: Vec<Vec4>) -> Scene {
    let n = positions.len() as u32;
    Scene {
        meshes: vec![Mesh {
            positions,
            colors: Some(colors),
            indices: (0..n).collect(),
            topology,
            ..Mesh::default()
        }],
        materials: vec![Material::default()],
        draws: vec![Draw {
            mesh: 0,
            model: Mat4::IDENTITY,
            node_name: "wide".into(),
            node_index: 0,
        }],
        resolution: (W, H),
        ..Scene::default()
    }
}

fn render_both(scene: Scene) -> Option<(FrameImage, FrameImage)> {
    let mut gl = gl_or_skip()?;
    let scene = Arc::new(scene);
    let view = FrameView::with_matrices(&scene, Mat4::IDENTITY, Mat4::IDENTITY, W, H);
    let mut cpu = CpuBackend::new(CpuOptions::default()).expect("cpu");
    cpu.load(scene.clone()).expect("cpu load");
    gl.load(scene).expect("gl load");
    Some((render(&mut cpu, &view), render(&mut gl, &view)))
}

fn drawn(image: &FrameImage) -> Vec<bool> {
    image.depth.iter().map(|&d| d < 1.0).collect()
}

#[test]
fn points_cover_the_same_pixels_as_opengl() {
    let mut random = Random(0x9e37_79b9_7f4a_7c15);
    let count = 300;
    let positions: Vec<Vec3> = (0..count)
        .map(|_| Vec3::new(random.next() * 2.0 - 1.0, random.next() * 2.0 - 1.0, 0.0))
        .collect();
    let colors = (0..count)
        .map(|i| Vec4::new(i as f32 / count as f32, 0.5, 1.0, 1.0))
        .collect();
    let Some((cpu, gl)) = render_both(scene(Topology::Points, positions, colors)) else {
        return;
    };
    let (a, b) = (drawn(&cpu), drawn(&gl));
    let cpu_count = a.iter().filter(|&&d| d).count();
    assert!(cpu_count > 250, "{cpu_count} point pixels");
    let differ = a.iter().zip(&b).filter(|(x, y)| x != y).count();
    eprintln!("points: {cpu_count} pixels, {differ} differ from OpenGL");
    assert_eq!(differ, 0, "point coverage differs from OpenGL");
}

#[test]
fn lines_cover_the_same_pixels_as_opengl_but_for_their_ends() {
    let mut random = Random(0x2545_f491_4f6c_dd1d);
    let lines = 60;
    let mut positions = Vec::new();
    let mut colors = Vec::new();
    for _ in 0..lines {
        for end in 0..2 {
            positions.push(Vec3::new(
                random.next() * 2.2 - 1.1,
                random.next() * 2.2 - 1.1,
                0.0,
            ));
            colors.push(Vec4::new(end as f32, 1.0 - end as f32, 0.5, 1.0));
        }
    }
    // Axis-aligned ones through pixel centres and along pixel edges too.
    for (a, b) in [
        ((-0.8, 0.1), (0.7, 0.1)),
        ((0.3, -0.9), (0.3, 0.9)),
        ((-0.5, -0.5), (0.5, 0.5)),
        ((-0.4, 0.6), (0.6, -0.4)),
    ] {
        positions.push(Vec3::new(a.0, a.1, 0.0));
        positions.push(Vec3::new(b.0, b.1, 0.0));
        colors.push(Vec4::new(1.0, 0.0, 0.5, 1.0));
        colors.push(Vec4::new(0.0, 1.0, 0.5, 1.0));
    }
    let segments = positions.len() / 2;
    // Window positions of the ends (pixel units, y down).
    let ends: Vec<(f32, f32)> = positions
        .iter()
        .map(|p| ((p.x + 1.0) * 0.5 * W as f32, (1.0 - p.y) * 0.5 * H as f32))
        .collect();
    let Some((cpu, gl)) = render_both(scene(Topology::Lines, positions, colors)) else {
        return;
    };
    let (a, b) = (drawn(&cpu), drawn(&gl));
    let cpu_count = a.iter().filter(|&&d| d).count();
    let gl_count = b.iter().filter(|&&d| d).count();
    let differing: Vec<usize> = (0..a.len()).filter(|&i| a[i] != b[i]).collect();
    let differ = differing.len();
    // Every differing pixel lies at an end of a segment (its centre within 1.5 pixels of one).
    for &i in &differing {
        let (x, y) = ((i as u32 % W) as f32 + 0.5, (i as u32 / W) as f32 + 0.5);
        assert!(
            ends.iter()
                .any(|e| (e.0 - x).abs() <= 1.5 && (e.1 - y).abs() <= 1.5),
            "pixel ({x}, {y}) differs from OpenGL away from any end (cpu {}, gl {})",
            a[i],
            b[i]
        );
    }
    // Colours where both drew: the same interpolation along the line (8-bit steps).
    let mut worst = 0.0f32;
    for i in 0..a.len() {
        if a[i] && b[i] {
            let d = (Vec4::from_array(cpu.color[i]) - Vec4::from_array(gl.color[i]))
                .abs()
                .max_element();
            worst = worst.max(d);
        }
    }
    eprintln!(
        "lines: {segments} segments, cpu {cpu_count} px, gl {gl_count} px, {differ} differ, \
         worst colour difference {worst:.4}"
    );
    assert!(cpu_count > 3000, "{cpu_count} line pixels");
    // A few end pixels (measured: 1 of about 4400 with llvmpipe).
    assert!(
        differ <= segments / 4,
        "{differ} pixels differ for {segments} segments"
    );
    assert!(worst < 0.05, "colour along the lines differs by {worst}");
}
