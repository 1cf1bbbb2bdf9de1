//! PLY and STL files: every encoding of the same mesh loads to the same mesh, faces of any size
//! are triangulated, point clouds stay points, and the real-world samples of
//! `$KANTELE_SHARED/realworld/ply-stl` load with the counts their headers declare.

use std::path::{Path, PathBuf};

use crate::common::ply_stl::*;
use crate::common::*;
use glam::{Vec2, Vec3, Vec4};
use kantele_rules::color::srgb_to_linear;
use kantele_rules::scene::{Light, Mesh, Shading, Topology};
use kantele_scene::{load_scene, LoadedScene};

fn load(path: &Path) -> LoadedScene {
    load_scene(path).unwrap_or_else(|e| panic!("{} should load: {e}", path.display()))
}

/// Writes `bytes` as `name` in a fresh folder and loads it.
fn write_and_load(name: &str, bytes: &[u8]) -> LoadedScene {
    let path = temp_dir("ply-stl").join(name);
    std::fs::write(&path, bytes).unwrap();
    load(&path)
}

/// The only mesh of a PLY or STL scene, after checking what every such scene has: one draw,
/// one light grey (white with vertex colours) double-sided material, Lambert and the headlight.
fn only_mesh(loaded: &LoadedScene) -> &Mesh {
    let scene = &loaded.scene;
    assert_eq!(scene.meshes.len(), 1);
    assert_eq!(scene.draws.len(), 1);
    assert_eq!(scene.materials.len(), 1);
    let mesh = &scene.meshes[0];
    let material = &scene.materials[mesh.material];
    assert!(material.double_sided, "scans have no reliable winding");
    let base = if mesh.colors.is_some() { 1.0 } else { 0.7 };
    assert_eq!(material.base_color_factor, Vec4::new(base, base, base, 1.0));
    assert_eq!(scene.shading, Shading::Lambert);
    assert_eq!(scene.light, Light::Headlight);
    assert!(!loaded.info.camera_from_file);
    mesh
}

/// Bounding box of a mesh's positions.
fn bounds(mesh: &Mesh) -> (Vec3, Vec3) {
    mesh.bounds().expect("finite positions")
}

fn assert_close(a: Vec3, b: Vec3, eps: f32, what: &str) {
    assert!(a.abs_diff_eq(b, eps), "{what}: {a} vs {b}");
}

#[test]
fn every_ply_encoding_loads_to_the_same_mesh() {
    let source = quad_and_pentagon();
    let loaded: Vec<LoadedScene> = PlyFormat::ALL
        .iter()
        .map(|&format| write_and_load(&format!("{}.ply", format.name()), &source.to_ply(format)))
        .collect();
    for (format, loaded) in PlyFormat::ALL.iter().zip(&loaded) {
        let mesh = only_mesh(loaded);
        assert_eq!(mesh.topology, Topology::Triangles, "{format:?}");
        // A quad and a pentagon: 2 + 3 triangles over the file's 9 vertices (smooth normals
        // from the file keep them shared).
        assert_eq!(mesh.triangle_count(), 5, "{format:?}");
        assert_eq!(mesh.positions.len(), 9, "{format:?}");
        assert_eq!(mesh.positions[7], Vec3::new(2.5, 1.5, 1.0));
        assert!(mesh.normals.as_ref().unwrap().iter().all(|n| *n == Vec3::Z));
        // v is flipped: (0, 0) is the image's top-left.
        let uv = mesh.texcoords.as_ref().expect("texcoords");
        assert_eq!(uv[2], Vec2::new(1.0 / 3.0, 0.5));
        assert_eq!(uv[7], Vec2::new(2.5 / 3.0, 1.0 - 0.75));
        // Colours are sRGB bytes, decoded to linear; alpha is linear.
        let colors = mesh.colors.as_ref().expect("colours");
        let half = srgb_to_linear(128.0 / 255.0);
        assert_eq!(colors[0], Vec4::new(1.0, half, 0.0, 1.0));
        assert_eq!(colors[8].w, 247.0 / 255.0);
        // The unknown `edge` element is skipped and reported; `confidence` is not read.
        assert!(
            loaded
                .info
                .ignored
                .iter()
                .any(|i| i == "PLY element 'edge'"),
            "{:?}",
            loaded.info.ignored
        );
    }
    let ascii = &loaded[0].scene.meshes[0];
    for other in &loaded[1..] {
        let other = &other.scene.meshes[0];
        assert_eq!(other.positions, ascii.positions);
        assert_eq!(other.normals, ascii.normals);
        assert_eq!(other.texcoords, ascii.texcoords);
        assert_eq!(other.colors, ascii.colors);
        assert_eq!(other.indices, ascii.indices);
    }
}

/// Area of a mesh's triangles projected on the xy plane (counter-clockwise positive).
fn xy_area(mesh: &Mesh) -> f32 {
    let p = |i: u32| mesh.positions[i as usize];
    mesh.indices
        .chunks_exact(3)
        .map(|t| (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0])).z * 0.5)
        .sum()
}

#[test]
fn ply_faces_of_any_size_are_triangulated() {
    let house = quad_and_pentagon();
    // One face at a time, in each encoding: quad 2 triangles, pentagon 3, an L-shaped
    // (concave) hexagon 4 covering its area of 3, not the 3.5 a fan from its first corner would.
    let hexagon = vec![
        [2.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [1.0, 2.0, 0.0],
        [0.0, 2.0, 0.0],
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
    ];
    let cases = [
        (house.positions.clone(), vec![0, 1, 2, 3], 2, 1.0),
        (house.positions.clone(), vec![4, 5, 6, 7, 8], 3, 1.25),
        (hexagon, vec![0, 1, 2, 3, 4, 5], 4, 3.0),
    ];
    for (positions, face, triangles, area) in cases {
        let mesh = PlyMesh {
            positions,
            faces: Some(vec![face.clone()]),
            ..PlyMesh::default()
        };
        for format in PlyFormat::ALL {
            let loaded = write_and_load("face.ply", &mesh.to_ply(format));
            let mesh = only_mesh(&loaded);
            assert_eq!(mesh.triangle_count(), triangles, "{face:?} {format:?}");
            assert!(
                (xy_area(mesh) - area).abs() < 1e-5,
                "{face:?}: area {}",
                xy_area(mesh)
            );
        }
    }
    // Faces of one or two corners are not drawn.
    let mesh = PlyMesh {
        positions: house.positions.clone(),
        faces: Some(vec![vec![0], vec![0, 1], vec![0, 1, 2]]),
        ..PlyMesh::default()
    };
    let loaded = write_and_load("small-faces.ply", &mesh.to_ply(PlyFormat::Ascii));
    assert_eq!(only_mesh(&loaded).triangle_count(), 1);
}

#[test]
fn ply_without_normals_is_flat_shaded_grey() {
    let mut source = quad_and_pentagon();
    source.normals = None;
    source.colors = None;
    let loaded = write_and_load("flat.ply", &source.to_ply(PlyFormat::BinaryLittleEndian));
    let mesh = only_mesh(&loaded);
    // De-indexed: one vertex per corner, each with its triangle's normal.
    assert_eq!(mesh.positions.len(), 15);
    assert_eq!(mesh.indices, (0..15).collect::<Vec<u32>>());
    assert!(mesh.normals.as_ref().unwrap().iter().all(|n| *n == Vec3::Z));
    assert_eq!(mesh.texcoords.as_ref().map(Vec::len), Some(15));
    assert!(mesh.colors.is_none());
    assert!(loaded.info.warnings.iter().all(|w| !w.contains("NaN")));
}

#[test]
fn ply_point_clouds_are_points() {
    let mut source = quad_and_pentagon();
    source.edge_element = false;
    for faces in [None, Some(Vec::new())] {
        source.faces = faces.clone();
        for format in PlyFormat::ALL {
            let loaded = write_and_load("cloud.ply", &source.to_ply(format));
            let mesh = only_mesh(&loaded);
            assert_eq!(mesh.topology, Topology::Points, "{faces:?} {format:?}");
            assert_eq!(mesh.indices, (0..9).collect::<Vec<u32>>());
            assert_eq!(mesh.primitive_count(), 9);
            assert_eq!(loaded.scene.triangle_count(), 0);
            // The file's normals light the points.
            assert_eq!(mesh.normals.as_ref().map(Vec::len), Some(9));
        }
    }
}

/// Outward normal of a tetrahedron face with centroid `c` (the tetrahedron's centroid is
/// (0.25, 0.25, 0.25)).
fn points_outwards(normal: Vec3, face_centroid: Vec3) -> bool {
    normal.dot(face_centroid - Vec3::splat(0.25)) > 0.0
}

#[test]
fn every_stl_encoding_loads_to_the_same_mesh() {
    let triangles = tetrahedron();
    let files: Vec<(&str, Vec<u8>)> = vec![
        (
            "ascii.stl",
            stl_ascii(&triangles, "solid tetrahedron", "\n"),
        ),
        // A bare `solid`, Windows line ends, an upper-case extension.
        ("bare.STL", stl_ascii(&triangles, "solid", "\r\n")),
        // A name that is not UTF-8.
        ("latin1.stl", stl_ascii(&triangles, "solid T\u{e4}il", "\n")),
        // Binary whose header starts with `solid`, as some CAD exporters write it.
        (
            "solid-header.stl",
            stl_binary(&triangles, b"solid exported", [0.0; 3]),
        ),
        ("binary.stl", stl_binary(&triangles, b"binary", [0.0; 3])),
    ];
    let mut first: Option<Mesh> = None;
    for (name, mut bytes) in files {
        if name == "latin1.stl" {
            // "Täil" in Latin-1.
            let at = bytes.iter().position(|&b| b == 0xc3).unwrap();
            bytes.splice(at..at + 2, [0xe4]);
        }
        let loaded = write_and_load(name, &bytes);
        let mesh = only_mesh(&loaded).clone();
        assert_eq!(mesh.triangle_count(), 4, "{name}");
        assert_eq!(mesh.positions.len(), 12, "{name}");
        assert!(mesh.texcoords.is_none() && mesh.colors.is_none());
        // Flat normals from the winding (the files' facet normals are zero).
        let normals = mesh.normals.as_ref().expect("normals");
        for (k, corners) in mesh.positions.chunks_exact(3).enumerate() {
            let centroid = (corners[0] + corners[1] + corners[2]) / 3.0;
            let n = normals[3 * k];
            assert!((n.length() - 1.0).abs() < 1e-6, "{name}: {n}");
            assert!(points_outwards(n, centroid), "{name}: face {k}: {n}");
            assert!(normals[3 * k + 1] == n && normals[3 * k + 2] == n);
        }
        assert!(
            loaded.info.warnings.is_empty(),
            "{name}: {:?}",
            loaded.info.warnings
        );
        match &first {
            None => first = Some(mesh),
            Some(first) => {
                assert_eq!(mesh.positions, first.positions, "{name}");
                assert_eq!(mesh.normals, first.normals, "{name}");
                assert_eq!(mesh.indices, first.indices, "{name}");
            }
        }
    }
}

#[test]
fn a_binary_stl_that_starts_like_text_is_binary() {
    // Ten triangles: the count's first byte is a line break (0x0a), so the 80-byte header
    // "solid …" is a valid first line of text; only the size (84 + 50 × 10) tells binary.
    let triangles: Vec<Triangle> = (0..10)
        .map(|k| tetrahedron()[k % 4].map(|[x, y, z]| [x + k as f32, y, z]))
        .collect();
    let bytes = stl_binary(&triangles, b"solid part exported as binary", [0.0; 3]);
    assert_eq!(bytes[80], b'\n');
    let loaded = write_and_load("text-like.stl", &bytes);
    let mesh = only_mesh(&loaded);
    assert_eq!(mesh.triangle_count(), 10);
    assert_eq!(mesh.positions[27], Vec3::new(9.0, 0.0, 0.0));
}

#[test]
fn stl_normals_come_from_the_winding_not_the_file() {
    // The file's facet normals point inwards; the loaded ones follow the winding (outwards).
    let triangles = tetrahedron();
    let loaded = write_and_load(
        "inward.stl",
        &stl_binary(&triangles, b"inward normals", [0.0, 0.0, -1.0]),
    );
    let mesh = only_mesh(&loaded);
    // Face 0 lies in the z = 0 plane, wound to face −z (outwards).
    assert_eq!(mesh.normals.as_ref().unwrap()[0], -Vec3::Z);
    assert_eq!(
        mesh.normals.as_ref().unwrap()[9],
        Vec3::splat(1.0 / 3f32.sqrt())
    );
}

#[test]
fn several_stl_solids_are_one_mesh() {
    let triangles = tetrahedron();
    let mut text = stl_ascii(&triangles[..2], "solid one", "\n");
    text.extend(b"\n");
    text.extend(stl_ascii(&triangles[2..], "solid two", "\n"));
    let loaded = write_and_load("two.stl", &text);
    assert_eq!(only_mesh(&loaded).triangle_count(), 4);
    assert!(
        loaded.info.warnings.iter().any(|w| w.contains("2 solids")),
        "{:?}",
        loaded.info.warnings
    );
}

#[test]
fn degenerate_and_nan_stl_triangles_load() {
    let mut triangles = tetrahedron();
    triangles.push([[1.0, 1.0, 1.0]; 3]);
    triangles.push([[f32::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    triangles.push([[f32::INFINITY, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    let loaded = write_and_load("odd.stl", &stl_binary(&triangles, b"odd", [0.0; 3]));
    let mesh = only_mesh(&loaded);
    assert_eq!(mesh.triangle_count(), 7);
    assert!(mesh.normals.as_ref().unwrap().iter().all(|n| n.is_finite()));
    assert_eq!(mesh.normals.as_ref().unwrap()[12], Vec3::Z);
    assert!(
        loaded
            .info
            .warnings
            .iter()
            .any(|w| w.contains("infinite or NaN")),
        "{:?}",
        loaded.info.warnings
    );
    // The camera frames the finite part.
    let (center, radius) = loaded.scene.bounding_sphere().expect("finite bounds");
    assert!(center.is_finite() && radius < 2.0, "{center} {radius}");
}

/// `$KANTELE_SHARED/realworld/ply-stl`, when present (see `corpus.rs`).
fn realworld_ply_stl() -> Option<PathBuf> {
    Some(kantele_testkit::shared_dir("realworld")?.join("ply-stl"))
}

#[test]
fn realworld_ply_files() {
    let Some(dir) = realworld_ply_stl() else {
        return;
    };
    // bunny.ply: ASCII, "element vertex 8171", "element face 16301" (all triangles); no
    // normals, so flat shaded: three vertices per triangle. confidence and intensity are
    // skipped.
    let loaded = load(&dir.join("bunny.ply"));
    let mesh = only_mesh(&loaded);
    assert_eq!(mesh.topology, Topology::Triangles);
    assert_eq!(mesh.triangle_count(), 16301);
    assert_eq!(mesh.positions.len(), 3 * 16301);
    assert!(mesh.texcoords.is_none() && mesh.colors.is_none());
    let (lo, hi) = bounds(mesh);
    assert_close(
        lo,
        Vec3::new(-0.094_571_6, 0.033_389_1, -0.061_873_6),
        1e-6,
        "min",
    );
    assert_close(
        hi,
        Vec3::new(0.060_934_6, 0.186_643, 0.058_689_5),
        1e-6,
        "max",
    );
    assert!(
        loaded.info.warnings.is_empty(),
        "{:?}",
        loaded.info.warnings
    );

    // cube_blender_uv.ply: ASCII from Blender, 24 vertices with normals and s/t, 6 quads.
    let loaded = load(&dir.join("cube_blender_uv.ply"));
    let mesh = only_mesh(&loaded);
    assert_eq!(mesh.triangle_count(), 12);
    assert_eq!(mesh.positions.len(), 24);
    assert_eq!(mesh.normals.as_ref().map(Vec::len), Some(24));
    let uv = mesh
        .texcoords
        .as_ref()
        .expect("the cube has texture coordinates");
    // Vertex 0: s 0.625, t 0.5; vertex 2: s 0.875, t 0.75 (t flipped to v).
    assert_eq!(uv[0], Vec2::new(0.625, 0.5));
    assert_eq!(uv[2], Vec2::new(0.875, 0.25));
    assert_eq!(bounds(mesh), (Vec3::splat(-0.5), Vec3::splat(0.5)));
    // Every triangle's winding agrees with the file's normals (counter-clockwise outwards).
    let normals = mesh.normals.as_ref().unwrap();
    for t in mesh.indices.chunks_exact(3) {
        let p = |k: usize| mesh.positions[t[k] as usize];
        let winding = (p(1) - p(0)).cross(p(2) - p(0));
        assert!(winding.dot(normals[t[0] as usize]) > 0.0);
    }

    // ply_points_bin.ply: binary little-endian, 8 vertices with normals, "element face 0".
    let loaded = load(&dir.join("ply_points_bin.ply"));
    let mesh = only_mesh(&loaded);
    assert_eq!(mesh.topology, Topology::Points);
    assert_eq!(mesh.indices, (0..8).collect::<Vec<u32>>());
    assert_eq!(mesh.normals.as_ref().map(Vec::len), Some(8));
    assert_eq!(bounds(mesh), (Vec3::splat(-1.0), Vec3::splat(1.0)));
}

#[test]
fn realworld_stl_files() {
    let Some(dir) = realworld_ply_stl() else {
        return;
    };
    // All three are binary; the triangle count is the header's (bytes 80..84), and the size is
    // 84 + 50 × that. Boxes computed independently from the raw floats.
    let files = [
        (
            "20mm-xyz-cube.stl",
            260,
            Vec3::new(-47.9519, -4.908, -30.9815),
            Vec3::new(-27.9519, 15.092, -10.9815),
        ),
        (
            "cylinder.stl",
            416,
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 8.0),
        ),
        (
            "featuretype.STL",
            3476,
            Vec3::new(-2.5, -1.25, 0.0),
            Vec3::new(2.5, 1.25, 1.375),
        ),
    ];
    for (name, triangles, lo, hi) in files {
        let path = dir.join(name);
        let bytes = std::fs::read(&path).unwrap();
        let declared = u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as usize;
        assert_eq!(declared, triangles, "{name}");
        assert_eq!(bytes.len(), 84 + 50 * declared, "{name}");
        let loaded = load(&path);
        let mesh = only_mesh(&loaded);
        assert_eq!(mesh.triangle_count(), triangles, "{name}");
        assert_eq!(mesh.positions.len(), 3 * triangles, "{name}");
        let (min, max) = bounds(mesh);
        assert_close(min, lo, 1e-3, name);
        assert_close(max, hi, 1e-3, name);
        assert!(
            loaded.info.warnings.is_empty(),
            "{name}: {:?}",
            loaded.info.warnings
        );
    }
    // The calibration cube is 20 mm on every side.
    let cube = load(&dir.join("20mm-xyz-cube.stl"));
    let (min, max) = bounds(&cube.scene.meshes[0]);
    assert_close(max - min, Vec3::splat(20.0), 1e-3, "cube size");
}
