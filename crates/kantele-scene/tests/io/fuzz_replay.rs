//! The fuzz targets on stable: every committed corpus file under `fuzz/corpus/<target>/`, then
//! deterministic pseudo-random mutations of them, through the same bodies `cargo fuzz` runs
//! (`kantele::fuzz_targets`, `kantele_testkit::fuzz_targets`, `kantele_scene::fuzz_ktx2`,
//! `kantele_scene::fuzz_dds`). A defect panics, failing the test.
//!
//! The seed files are generated, not hand-edited: `cargo test -p kantele-scene --test io
//! -- --ignored write_seed_corpus` writes them (inputs the fuzzer found stay as they are).

use std::path::{Path, PathBuf};

use serde_json::json;

/// Mutated inputs per target.
const MUTATIONS: usize = 1500;

fn corpus_dir(target: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz/corpus")
        .join(target)
}

/// The corpus files of a target, sorted by name.
fn corpus(target: &str) -> Vec<(PathBuf, Vec<u8>)> {
    let dir = corpus_dir(target);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("corpus entry").path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    files
        .into_iter()
        .map(|p| {
            let bytes = std::fs::read(&p).expect("read corpus file");
            (p, bytes)
        })
        .collect()
}

/// xorshift64*: the same mutations on every run.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Bytes a mutation likes to write: boundaries of integer types, JSON and OBJ syntax.
const INTERESTING: &[&[u8]] = &[
    b"0",
    b"-1",
    b"4294967295",
    b"2147483648",
    b"65535",
    b"1e38",
    b"-1e-38",
    b"nan",
    b"\xff\xff\xff\xff",
    b"\x00\x00\x00\x80",
    b"\x00\x00\xc0\x7f",
    b"[]",
    b"{}",
    b"null",
    b"\"",
    b"/",
    b"\n",
];

/// One to four random edits of `input`: bit flips, overwritten or inserted interesting bytes,
/// deletions, duplicated ranges, and splices from `other`.
fn mutate(rng: &mut Rng, input: &[u8], other: &[u8]) -> Vec<u8> {
    let mut out = input.to_vec();
    for _ in 0..1 + rng.below(4) {
        let at = rng.below(out.len() + 1);
        match rng.below(6) {
            0 if !out.is_empty() => {
                let i = at.min(out.len() - 1);
                out[i] ^= 1 << rng.below(8);
            }
            1 => {
                let piece = INTERESTING[rng.below(INTERESTING.len())];
                let end = (at + piece.len()).min(out.len());
                out.splice(at..end, piece.iter().copied());
            }
            2 => {
                let piece = INTERESTING[rng.below(INTERESTING.len())];
                out.splice(at..at, piece.iter().copied());
            }
            3 => {
                let end = (at + 1 + rng.below(16)).min(out.len());
                out.drain(at.min(end)..end);
            }
            4 => {
                let end = (at + 1 + rng.below(64)).min(out.len());
                let piece = out[at.min(end)..end].to_vec();
                out.splice(at..at, piece);
            }
            _ => {
                let from = rng.below(other.len() + 1);
                let end = (from + 1 + rng.below(64)).min(other.len());
                out.splice(at..at, other[from.min(end)..end].iter().copied());
            }
        }
    }
    out
}

/// Runs `body` on every corpus file of `target` and on [`MUTATIONS`] mutations of them; a
/// panic names the input that caused it.
fn replay(target: &str, seed: u64, body: fn(&[u8])) {
    let files = corpus(target);
    assert!(!files.is_empty(), "no corpus for {target}");
    for (path, bytes) in &files {
        run_one(body, bytes, &format!("{}", path.display()));
    }
    let mut rng = Rng(seed);
    for k in 0..MUTATIONS {
        let (path, input) = &files[rng.below(files.len())];
        let other = &files[rng.below(files.len())].1;
        let mutated = mutate(&mut rng, input, other);
        run_one(
            body,
            &mutated,
            &format!("mutation {k} of {}", path.display()),
        );
    }
}

fn run_one(body: fn(&[u8]), input: &[u8], name: &str) {
    if std::panic::catch_unwind(|| body(input)).is_err() {
        let saved = std::env::temp_dir().join(format!(
            "kantele-fuzz-failure-{}-{}",
            std::process::id(),
            name.replace(['/', ' '], "_")
        ));
        let _ = std::fs::write(&saved, input);
        panic!("{name} failed; input saved to {}", saved.display());
    }
}

#[test]
fn gltf_corpus_and_mutations() {
    replay(
        "gltf",
        0x9e37_79b9_7f4a_7c15,
        kantele_testkit::fuzz_targets::gltf,
    );
}

#[test]
fn obj_corpus_and_mutations() {
    replay(
        "obj",
        0xd1b5_4a32_d192_ed03,
        kantele_testkit::fuzz_targets::obj,
    );
}

#[test]
fn ply_corpus_and_mutations() {
    replay(
        "ply",
        0x2545_f491_4f6c_dd1d,
        kantele_testkit::fuzz_targets::ply,
    );
}

#[test]
fn stl_corpus_and_mutations() {
    replay(
        "stl",
        0xbf58_476d_1ce4_e5b9,
        kantele_testkit::fuzz_targets::stl,
    );
}

#[test]
fn ktx2_corpus_and_mutations() {
    replay("ktx2", 0x6a09_e667_f3bc_c908, kantele_scene::fuzz_ktx2);
}

#[test]
fn dds_corpus_and_mutations() {
    replay("dds", 0x3c6e_f372_fe94_f82b, kantele_scene::fuzz_dds);
}

#[test]
fn draco_corpus_and_mutations() {
    replay(
        "draco",
        0x2f6b_9c1e_83d4_a507,
        kantele_testkit::fuzz_targets::draco,
    );
}

#[test]
fn raster_corpus_and_mutations() {
    replay(
        "raster",
        0x8cb9_2ba7_2f3d_8dd7,
        kantele::fuzz_targets::raster,
    );
}

#[test]
fn clip_corpus_and_mutations() {
    replay("clip", 0x5851_f42d_4c95_7f2d, kantele::fuzz_targets::clip);
}

/// Writes the generated seed files (small: a few KB in all).
#[test]
#[ignore = "writes fuzz/corpus; run by hand when the seeds change"]
fn write_seed_corpus() {
    let gltf = corpus_dir("gltf");
    std::fs::create_dir_all(&gltf).expect("corpus dir");
    let quad = crate::common::textured_quad();
    quad.write_glb(&gltf.join("seed-textured-quad.glb"));
    quad.write_gltf_embedded(&gltf.join("seed-textured-quad.gltf"));
    cube_gltf().write_glb(&gltf.join("seed-builtin-cube.glb"));
    std::fs::write(gltf.join("seed-sparse-strip.gltf"), sparse_strip()).expect("write");
    std::fs::write(
        gltf.join("seed-skin-animation.gltf"),
        crate::animation::fuzz_seed(),
    )
    .expect("write");

    let obj = corpus_dir("obj");
    std::fs::create_dir_all(&obj).expect("corpus dir");
    std::fs::write(obj.join("seed-builtin-cube.obj"), cube_obj()).expect("write");
    std::fs::write(obj.join("seed-polygons.obj"), polygons_obj()).expect("write");

    // ply: the quad and pentagon in each encoding, and a point cloud; stl: a tetrahedron as
    // ASCII and as binary with a `solid` header.
    let ply = corpus_dir("ply");
    std::fs::create_dir_all(&ply).expect("corpus dir");
    for (name, bytes) in crate::common::ply_stl::ply_fuzz_seeds() {
        std::fs::write(ply.join(name), bytes).expect("write");
    }
    let stl = corpus_dir("stl");
    std::fs::create_dir_all(&stl).expect("corpus dir");
    for (name, bytes) in crate::common::ply_stl::stl_fuzz_seeds() {
        std::fs::write(stl.join(name), bytes).expect("write");
    }

    // ktx2: the KTX2 test images (ETC1S with mip levels, ETC1S with alpha, UASTC with
    // Zstandard; tests/data/ktx2/README.md).
    let ktx2 = corpus_dir("ktx2");
    std::fs::create_dir_all(&ktx2).expect("corpus dir");
    let images = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/ktx2");
    for name in [
        "quadrants-etc1s.ktx2",
        "quadrants-etc1s-alpha.ktx2",
        "quadrants-uastc-zstd.ktx2",
    ] {
        std::fs::copy(images.join(name), ktx2.join(format!("seed-{name}"))).expect("copy");
    }

    // dds: the DDS test images (tests/data/dds/README.md; written by the kantele-scene unit
    // test `write_seed_files`).
    let dds = corpus_dir("dds");
    std::fs::create_dir_all(&dds).expect("corpus dir");
    let images = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/dds");
    let mut names: Vec<_> = std::fs::read_dir(&images)
        .expect("tests/data/dds")
        .map(|e| e.expect("entry").file_name())
        .filter(|n| n.to_string_lossy().ends_with(".dds"))
        .collect();
    names.sort();
    for name in names {
        let seed = format!("seed-{}", name.to_string_lossy());
        std::fs::copy(images.join(&name), dds.join(seed)).expect("copy");
    }

    // raster: width/height exponents, mode, strategy, then six little-endian u32 coordinates.
    let raster = corpus_dir("raster");
    std::fs::create_dir_all(&raster).expect("corpus dir");
    for (name, head, coords) in [
        (
            "seed-near-target",
            [2u8, 2, 0, 4],
            [100u32, 9000, 70000, 120, 3000, 50000],
        ),
        ("seed-lattice", [3, 1, 1, 2], [7, 40, 61, 3, 150, 99]),
        (
            "seed-guard-band",
            [5, 5, 2, 0],
            [1 << 31, 12345, 77, 1 << 30, 999_999, 4],
        ),
        ("seed-collinear", [0, 4, 3, 1], [10, 5000, 20000, 7, 300, 0]),
    ] {
        let mut bytes = head.to_vec();
        bytes.extend(coords.iter().flat_map(|c| c.to_le_bytes()));
        std::fs::write(raster.join(name), bytes).expect("write");
    }

    // clip: width, height, perspective flag, strategy, then tagged floats (see
    // `kantele::fuzz_targets::clip`): tag % 4 == 1 is a raw f32 bit pattern.
    let clip = corpus_dir("clip");
    std::fs::create_dir_all(&clip).expect("corpus dir");
    let raw = |values: &[f32]| -> Vec<u8> {
        values
            .iter()
            .flat_map(|v| std::iter::once(1u8).chain(v.to_le_bytes()))
            .collect()
    };
    // A 1e6 ground plane triangle seen from 2 units above, near 0.1, far 1e7, fov byte 100.
    let mut ground = vec![63, 47, 1, 4];
    ground.extend(raw(&[0.1, 1e7]));
    ground.push(100);
    ground.extend(raw(&[-1e6, -2.0, 1e6, 1e6, -2.0, 1e6, 0.0, -2.0, -1e6]));
    std::fs::write(clip.join("seed-ground-plane"), ground).expect("write");
    // Behind the eye, crossing w = 0, one NaN (tag 0 = NaN).
    let mut crossing = vec![31, 31, 0, 1];
    crossing.extend(raw(&[0.5, 0.5, 0.0, -1.0, -0.5, 0.3, 0.2, 2.0]));
    crossing.extend(raw(&[0.0, 0.9, 1e-30]));
    crossing.push(0);
    std::fs::write(clip.join("seed-crossing-w0"), crossing).expect("write");
}

/// The built-in cube (positions, normals, indices) as a glTF document.
fn cube_gltf() -> crate::common::Gltf {
    let loaded = kantele_scene::builtin_scene("cube").expect("built-in cube");
    let mesh = &loaded.scene.meshes[0];
    let mut g = crate::common::Gltf::new();
    let positions: Vec<[f32; 3]> = mesh.positions.iter().map(|p| p.to_array()).collect();
    let position = g.vec3(&positions);
    let mut attributes = json!({"POSITION": position});
    if let Some(normals) = &mesh.normals {
        let normals: Vec<[f32; 3]> = normals.iter().map(|n| n.to_array()).collect();
        attributes["NORMAL"] = json!(g.vec3(&normals));
    }
    let indices: Vec<u16> = mesh.indices.iter().map(|&i| i as u16).collect();
    let indices = g.indices_u16(&indices);
    let material =
        g.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.3, 0.2, 1.0]}}));
    let m = g.mesh(
        "cube",
        vec![json!({"attributes": attributes, "indices": indices, "material": material})],
    );
    let node =
        g.node(json!({"mesh": m, "rotation": [0.2, 0.3, 0.0, 0.933], "scale": [1.0, 2.0, 1.0]}));
    g.root(node);
    g
}

/// A triangle strip whose positions come from a sparse accessor over a zero base, with a
/// camera and a light: the rarely used parts of the JSON in a few hundred bytes.
fn sparse_strip() -> String {
    let positions: [f32; 12] = [
        -1.0, -1.0, 0.0, 1.0, -1.0, 0.0, -1.0, 1.0, 0.0, 1.0, 1.0, 0.0,
    ];
    let indices: [u32; 4] = [0, 1, 2, 3];
    let mut bin: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
    bin.extend(positions.iter().flat_map(|f| f.to_le_bytes()));
    let document = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "directional", "intensity": 2.0}]}},
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": [
            {"mesh": 0},
            {"camera": 0, "translation": [0.0, 0.0, 4.0]},
            {"extensions": {"KHR_lights_punctual": {"light": 0}}, "rotation": [0.0, 0.383, 0.0, 0.924]},
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1, "zfar": 100.0}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "mode": 5}]}],
        "accessors": [{
            "componentType": 5126, "type": "VEC3", "count": 4,
            "min": [-1.0, -1.0, 0.0], "max": [1.0, 1.0, 0.0],
            "sparse": {
                "count": 4,
                "indices": {"bufferView": 0, "componentType": 5125},
                "values": {"bufferView": 1},
            },
        }],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 16},
            {"buffer": 0, "byteOffset": 16, "byteLength": 48},
        ],
        "buffers": [{
            "byteLength": bin.len(),
            "uri": format!("data:application/octet-stream;base64,{}", crate::common::base64(&bin)),
        }],
    });
    serde_json::to_string(&document).expect("json")
}

/// The built-in cube as OBJ text with a material library after the separator.
fn cube_obj() -> Vec<u8> {
    let loaded = kantele_scene::builtin_scene("cube").expect("built-in cube");
    let mesh = &loaded.scene.meshes[0];
    let mut text = String::from("mtllib scene.mtl\no cube\nusemtl red\n");
    for p in &mesh.positions {
        text += &format!("v {} {} {}\n", p.x, p.y, p.z);
    }
    for tri in mesh.indices.chunks(3) {
        text += &format!("f {} {} {}\n", tri[0] + 1, tri[1] + 1, tri[2] + 1);
    }
    let mut bytes = text.into_bytes();
    bytes.extend_from_slice(kantele_testkit::fuzz_targets::MTL_SEPARATOR);
    bytes.extend_from_slice(b"newmtl red\nKd 0.8 0.2 0.1\nKa 0.1 0.1 0.1\nd 0.9\nillum 2\n");
    bytes
}

/// Quads and a concave polygon with texture coordinates, normals, negative indices, groups
/// and a texture map that does not exist.
fn polygons_obj() -> Vec<u8> {
    let mut bytes = b"mtllib scene.mtl
g quad
v -1 -1 0
v 1 -1 0
v 1 1 0
v -1 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
usemtl textured
f 1/1/1 2/2/1 3/3/1 4/4/1
g concave
v 0 0 1
v 2 0 1
v 2 2 1
v 1 0.5 1
v 0 2 1
f -5 -4 -3 -2 -1
l 1 2
p 3
"
    .to_vec();
    bytes.extend_from_slice(kantele_testkit::fuzz_targets::MTL_SEPARATOR);
    bytes.extend_from_slice(b"newmtl textured\nKd 1 1 1\nmap_Kd missing.png\n");
    bytes
}
