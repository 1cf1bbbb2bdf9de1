//! The Utah teapot, tessellated from Newell's Bézier patches.

use glam::{Mat4, Vec3, Vec4};
use kantele_rules::scene::{Draw, Light, Material, Mesh, Scene};

use super::teapot_data::{PATCHES, POINTS};
use super::CLEAR_COLOR;
use crate::mesh_util::framing_camera;
use crate::SceneInfo;

/// Quads per patch side.
pub const DIVISIONS: usize = 10;

/// Cubic Bernstein polynomials at `t`.
fn bernstein(t: f32) -> [f32; 4] {
    let s = 1.0 - t;
    [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t]
}

/// Their derivatives.
fn bernstein_derivative(t: f32) -> [f32; 4] {
    let s = 1.0 - t;
    [
        -3.0 * s * s,
        3.0 * s * s - 6.0 * t * s,
        6.0 * t * s - 3.0 * t * t,
        3.0 * t * t,
    ]
}

/// Classic data (z up) → y up: a rotation of −90° about x, `(x, y, z) → (x, z, −y)`.
fn y_up(p: Vec3) -> Vec3 {
    Vec3::new(p.x, p.z, -p.y)
}

/// The 16 control points of a patch, `[row along u][column along v]`, y up.
fn control_points(patch: &[u16; 16]) -> [[Vec3; 4]; 4] {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| y_up(Vec3::from(POINTS[patch[4 * i + j] as usize - 1])))
    })
}

/// Position and partial derivatives `(P, ∂P/∂u, ∂P/∂v)` of a patch at `(u, v)`.
fn evaluate(cp: &[[Vec3; 4]; 4], u: f32, v: f32) -> (Vec3, Vec3, Vec3) {
    let (bu, bv) = (bernstein(u), bernstein(v));
    let (du, dv) = (bernstein_derivative(u), bernstein_derivative(v));
    let mut p = Vec3::ZERO;
    let mut pu = Vec3::ZERO;
    let mut pv = Vec3::ZERO;
    for i in 0..4 {
        for j in 0..4 {
            p += cp[i][j] * (bu[i] * bv[j]);
            pu += cp[i][j] * (du[i] * bv[j]);
            pv += cp[i][j] * (bu[i] * dv[j]);
        }
    }
    (p, pu, pv)
}

/// The outward unit normal of a patch at `(u, v)`. With the classic data's orientation, outward
/// is `∂P/∂v × ∂P/∂u`. Where that vanishes (the poles of the lid and the bottom, where a whole row
/// of control points coincides), the normal is the limit taken by stepping towards the patch's
/// interior.
fn normal(cp: &[[Vec3; 4]; 4], u: f32, v: f32) -> Vec3 {
    let (_, pu, pv) = evaluate(cp, u, v);
    if let Some(n) = pv.cross(pu).try_normalize() {
        if pv.cross(pu).length() > 1e-6 * pu.length().max(pv.length()).max(1e-6) {
            return n;
        }
    }
    let step = 1e-3;
    let towards = |t: f32| if t < 0.5 { t + step } else { t - step };
    let (_, pu, pv) = evaluate(cp, towards(u), towards(v));
    pv.cross(pu).try_normalize().unwrap_or(Vec3::Y)
}

/// The tessellated teapot: `(DIVISIONS + 1)²` vertices per patch, two triangles per grid cell,
/// counter-clockwise from outside; triangles collapsed at the poles are left out.
pub fn teapot_mesh(material: usize) -> Mesh {
    let n = DIVISIONS;
    let mut positions = Vec::with_capacity(PATCHES.len() * (n + 1) * (n + 1));
    let mut normals = Vec::with_capacity(positions.capacity());
    let mut indices = Vec::with_capacity(PATCHES.len() * n * n * 6);
    for patch in &PATCHES {
        let cp = control_points(patch);
        let base = positions.len() as u32;
        for i in 0..=n {
            for j in 0..=n {
                let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
                positions.push(evaluate(&cp, u, v).0);
                normals.push(normal(&cp, u, v));
            }
        }
        let at = |i: usize, j: usize| base + (i * (n + 1) + j) as u32;
        for i in 0..n {
            for j in 0..n {
                let (a, b, c, d) = (at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j));
                for tri in [[a, b, c], [a, c, d]] {
                    // Rows of coinciding control points (the poles) collapse some triangles.
                    let [p, q, r] = tri.map(|k| positions[k as usize]);
                    if (q - p).cross(r - p).length_squared() > 1e-12 {
                        indices.extend(tri);
                    }
                }
            }
        }
    }
    Mesh {
        name: "teapot".into(),
        positions,
        normals: Some(normals),
        texcoords: None,
        colors: None,
        indices,
        material,
        topology: kantele_rules::scene::Topology::Triangles,
        texcoords1: None,
        tangents: None,
    }
}

pub fn scene() -> (Scene, SceneInfo) {
    let mut scene = Scene {
        meshes: vec![teapot_mesh(0)],
        materials: vec![Material {
            name: "teapot-lambert".into(),
            base_color_factor: Vec4::new(0.85, 0.55, 0.3, 1.0),
            ..Material::default()
        }],
        textures: Vec::new(),
        draws: vec![Draw {
            mesh: 0,
            model: Mat4::IDENTITY,
            node_name: "teapot".into(),
            node_index: 2,
        }],
        light: Light::Directional {
            to_light: Vec3::new(0.45, 0.8, 0.4).normalize(),
            color: Vec3::ONE,
        },
        ambient: 0.1,
        clear_color: CLEAR_COLOR,
        resolution: (1024, 768),
        ..Scene::default()
    };
    scene.camera = framing_camera(&scene);
    let info = SceneInfo {
        cameras: vec!["camera".into()],
        camera_from_file: true,
        lights: vec!["sun".into()],
        ..SceneInfo::default()
    };
    (scene, info)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn data_is_complete() {
        assert_eq!(PATCHES.len(), 32);
        assert_eq!(POINTS.len(), 306);
        assert!(PATCHES
            .iter()
            .flatten()
            .all(|&i| (1..=306).contains(&(i as usize))));
        // The teapot is symmetric about the classic xz plane.
        for p in POINTS {
            assert!(
                POINTS.contains(&[p[0], -p[1], p[2]]) || p[1] == 0.0,
                "{p:?}"
            );
        }
    }

    #[test]
    fn teapot_is_y_up_with_the_expected_size() {
        let mesh = teapot_mesh(0);
        let n = DIVISIONS;
        assert_eq!(mesh.positions.len(), 32 * (n + 1) * (n + 1));
        // Eight patches (lid top, bottom) have a pole: n triangles collapse in each.
        assert_eq!(mesh.triangle_count(), 32 * n * n * 2 - 8 * n);
        let (lo, hi) = mesh.bounds().unwrap();
        assert!(
            (lo.y - 0.0).abs() < 1e-4 && (hi.y - 3.15).abs() < 1e-4,
            "{lo} {hi}"
        );
        assert!(hi.x > 3.0 && lo.x < -2.9);
    }

    #[test]
    fn normals_are_unit_and_agree_with_the_winding() {
        let mesh = teapot_mesh(0);
        let normals = mesh.normals.as_ref().unwrap();
        assert!(normals
            .iter()
            .all(|n| n.is_finite() && (n.length() - 1.0).abs() < 1e-4));
        let mut agree = 0;
        let mut total = 0;
        for tri in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[tri[k] as usize]);
            let face = (b - a).cross(c - a);
            let vertex_normals: Vec3 = tri.iter().map(|&k| normals[k as usize]).sum();
            total += 1;
            if face.dot(vertex_normals) > 0.0 {
                agree += 1;
            }
        }
        assert!(agree as f32 > 0.99 * total as f32, "{agree} of {total}");
    }

    #[test]
    fn normals_point_outwards() {
        let mesh = teapot_mesh(0);
        let normals = mesh.normals.as_ref().unwrap();
        // Body, lid and bottom are surfaces of revolution about the y axis: outward is away from
        // the axis, and up on the lid / down on the bottom near the axis. Spout and handle are
        // tubes: at their sides (far from the z = 0 plane of symmetry) outward points along ±z.
        let per_patch = (DIVISIONS + 1) * (DIVISIONS + 1);
        let mut outward = 0;
        let mut total = 0;
        let mut stats = vec![(0, 0); 32];
        for (patch, chunk) in mesh.positions.chunks(per_patch).enumerate() {
            for (k, p) in chunk.iter().enumerate() {
                let n = normals[patch * per_patch + k];
                let radial = Vec3::new(p.x, 0.0, p.z);
                let direction = match patch {
                    // The rim is a lip around a circle of radius 1.45 at height 2.4: its inner
                    // half faces the axis.
                    0..=3 => {
                        let r = radial.length();
                        radial / r * (r - 1.45) + Vec3::Y * (p.y - 2.4)
                    }
                    12..=19 => {
                        if p.z.abs() < 0.15 {
                            continue;
                        }
                        Vec3::new(0.0, 0.0, p.z.signum())
                    }
                    // The knob is roughly a ball around (0, 2.95, 0) (its concave neck, one row
                    // per patch, is where this guess fails).
                    20..=23 => *p - Vec3::new(0.0, 2.95, 0.0),
                    28..=31 if radial.length() < 1.0 => -Vec3::Y,
                    _ => radial,
                };
                total += 1;
                stats[patch].1 += 1;
                if n.dot(direction) > 0.0 {
                    outward += 1;
                    stats[patch].0 += 1;
                }
            }
        }
        assert!(
            outward as f32 > 0.95 * total as f32,
            "{outward} of {total} outwards; per patch {stats:?}"
        );
    }

    #[test]
    fn winding_encloses_a_positive_volume() {
        // With every face counter-clockwise from outside, the signed volume is positive (the
        // surface is not quite closed where spout and handle meet the body, hence the range).
        let mesh = teapot_mesh(0);
        let origin = Vec3::new(0.0, 1.5, 0.0);
        let volume: f32 = mesh
            .indices
            .chunks_exact(3)
            .map(|t| {
                let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[t[k] as usize] - origin);
                a.dot(b.cross(c)) / 6.0
            })
            .sum();
        // The body alone is about a solid of revolution of radius ~1.8 and height ~3.
        assert!(volume > 20.0 && volume < 40.0, "volume {volume}");
    }

    #[test]
    fn pole_normals_point_along_the_axis() {
        let mesh = teapot_mesh(0);
        let normals = mesh.normals.as_ref().unwrap();
        for (p, n) in mesh.positions.iter().zip(normals) {
            if p.x.abs() < 1e-6 && p.z.abs() < 1e-6 {
                if (p.y - 3.15).abs() < 1e-4 {
                    assert!(n.dot(Vec3::Y) > 0.99, "lid pole normal {n}");
                } else if p.y.abs() < 1e-4 {
                    assert!(n.dot(-Vec3::Y) > 0.99, "bottom pole normal {n}");
                }
            }
        }
    }
}
