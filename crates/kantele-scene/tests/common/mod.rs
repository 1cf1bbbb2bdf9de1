//! Helpers for the integration tests: temporary directories, a small glTF writer and PLY and
//! STL writers.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use serde_json::{json, Value};

pub mod ply_stl;

/// A fresh, empty temporary directory for one test.
pub fn temp_dir(name: &str) -> PathBuf {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!(
        "kantele-scene-test-{}-{}-{name}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create temp dir");
    dir
}

/// The reference scenes (`$KANTELE_SHARED/scenes`), when present (a failure instead of a skip
/// when `KANTELE_REQUIRE` names `scenes`).
pub fn reference_scenes() -> Option<PathBuf> {
    kantele_testkit::shared_dir("scenes")
}

/// The reference scenes' `.glb` files, sorted (at least the 18 of
/// `docs/rendering-rules.md`), when present (see [`reference_scenes`]).
pub fn reference_scene_files() -> Option<Vec<PathBuf>> {
    let dir = reference_scenes()?;
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("read scenes")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "glb"))
        .collect();
    files.sort();
    assert!(files.len() >= 18, "{} scenes", files.len());
    Some(files)
}

/// A PNG of the given RGBA texels.
pub fn png(width: u32, height: u32, rgba: &[u8]) -> Vec<u8> {
    let image = image::RgbaImage::from_raw(width, height, rgba.to_vec()).expect("size matches");
    let mut out = std::io::Cursor::new(Vec::new());
    image
        .write_to(&mut out, image::ImageFormat::Png)
        .expect("encode png");
    out.into_inner()
}

/// A 2 × 2 test image: red, green / blue, white.
pub fn test_png() -> Vec<u8> {
    png(
        2,
        2,
        &[
            255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255,
        ],
    )
}

/// Standard base64 with padding.
pub fn base64(data: &[u8]) -> String {
    const ALPHABET: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in data.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

pub const FLOAT: u32 = 5126;
pub const UNSIGNED_BYTE: u32 = 5121;
pub const UNSIGNED_SHORT: u32 = 5123;
pub const UNSIGNED_INT: u32 = 5125;

/// Builds a glTF document with one binary buffer, written as `.glb` or `.gltf`.
pub struct Gltf {
    pub json: Value,
    pub bin: Vec<u8>,
    /// Images: (name, PNG bytes, how to store them when writing `.gltf`).
    pub images: Vec<Vec<u8>>,
}

impl Default for Gltf {
    fn default() -> Self {
        Self::new()
    }
}

impl Gltf {
    pub fn new() -> Self {
        Self {
            json: json!({
                "asset": {"version": "2.0"},
                "scene": 0,
                "scenes": [{"nodes": []}],
                "nodes": [],
                "meshes": [],
                "accessors": [],
                "bufferViews": [],
            }),
            bin: Vec::new(),
            images: Vec::new(),
        }
    }

    fn array(&mut self, key: &str) -> &mut Vec<Value> {
        if self.json.get(key).is_none() {
            self.json[key] = json!([]);
        }
        self.json[key].as_array_mut().expect("array")
    }

    fn push(&mut self, key: &str, value: Value) -> usize {
        let a = self.array(key);
        a.push(value);
        a.len() - 1
    }

    /// Appends raw bytes as a buffer view (4-byte aligned); returns its index.
    pub fn view(&mut self, bytes: &[u8]) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.push(
            "bufferViews",
            json!({"buffer": 0, "byteOffset": offset, "byteLength": bytes.len()}),
        )
    }

    /// An accessor over new data; returns its index.
    pub fn accessor(
        &mut self,
        bytes: &[u8],
        component_type: u32,
        ty: &str,
        count: usize,
        normalized: bool,
    ) -> usize {
        let view = self.view(bytes);
        let mut a = json!({"bufferView": view, "componentType": component_type, "type": ty, "count": count});
        if normalized {
            a["normalized"] = json!(true);
        }
        self.push("accessors", a)
    }

    pub fn vec3(&mut self, values: &[[f32; 3]]) -> usize {
        let bytes: Vec<u8> = values
            .iter()
            .flatten()
            .flat_map(|f| f.to_le_bytes())
            .collect();
        let idx = self.accessor(&bytes, FLOAT, "VEC3", values.len(), false);
        let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
        for v in values {
            for k in 0..3 {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
        }
        if values.iter().flatten().all(|f| f.is_finite()) {
            self.json["accessors"][idx]["min"] = json!(lo);
            self.json["accessors"][idx]["max"] = json!(hi);
        }
        idx
    }

    pub fn vec2(&mut self, values: &[[f32; 2]]) -> usize {
        let bytes: Vec<u8> = values
            .iter()
            .flatten()
            .flat_map(|f| f.to_le_bytes())
            .collect();
        self.accessor(&bytes, FLOAT, "VEC2", values.len(), false)
    }

    pub fn indices_u16(&mut self, values: &[u16]) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|i| i.to_le_bytes()).collect();
        self.accessor(&bytes, UNSIGNED_SHORT, "SCALAR", values.len(), false)
    }

    pub fn indices_u32(&mut self, values: &[u32]) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|i| i.to_le_bytes()).collect();
        self.accessor(&bytes, UNSIGNED_INT, "SCALAR", values.len(), false)
    }

    /// A mesh of the given primitives (JSON objects); returns its index.
    pub fn mesh(&mut self, name: &str, primitives: Vec<Value>) -> usize {
        self.push("meshes", json!({"name": name, "primitives": primitives}))
    }

    /// A node (JSON object); returns its index. Does not add it to the scene.
    pub fn node(&mut self, node: Value) -> usize {
        self.push("nodes", node)
    }

    /// Adds a node index to the scene's root list.
    pub fn root(&mut self, node: usize) {
        self.json["scenes"][0]["nodes"]
            .as_array_mut()
            .expect("scene nodes")
            .push(json!(node));
    }

    pub fn material(&mut self, material: Value) -> usize {
        self.push("materials", material)
    }

    pub fn sampler(&mut self, sampler: Value) -> usize {
        self.push("samplers", sampler)
    }

    pub fn texture(&mut self, texture: Value) -> usize {
        self.push("textures", texture)
    }

    pub fn camera(&mut self, camera: Value) -> usize {
        self.push("cameras", camera)
    }

    /// An image whose bytes go into the buffer (`.glb`) or a file / data URI (`.gltf`).
    pub fn image(&mut self, bytes: Vec<u8>) -> usize {
        self.images.push(bytes);
        self.push(
            "images",
            json!({"name": format!("image{}", self.images.len() - 1)}),
        )
    }

    fn finished_json(&self, buffer_uri: Option<String>) -> Value {
        let mut json = self.json.clone();
        let mut buffer = json!({"byteLength": self.bin.len()});
        if let Some(uri) = buffer_uri {
            buffer["uri"] = json!(uri);
        }
        json["buffers"] = json!([buffer]);
        json
    }

    /// Writes a `.glb`, images inside the binary chunk.
    pub fn write_glb(&self, path: &Path) {
        let mut this = Gltf {
            json: self.json.clone(),
            bin: self.bin.clone(),
            images: Vec::new(),
        };
        for (i, bytes) in self.images.iter().enumerate() {
            let view = this.view(bytes);
            this.json["images"][i]["bufferView"] = json!(view);
            this.json["images"][i]["mimeType"] = json!("image/png");
        }
        while !this.bin.len().is_multiple_of(4) {
            this.bin.push(0);
        }
        let mut json = serde_json::to_vec(&this.finished_json(None)).expect("json");
        while !json.len().is_multiple_of(4) {
            json.push(b' ');
        }
        let total = 12 + 8 + json.len() + 8 + this.bin.len();
        let mut out = Vec::with_capacity(total);
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&(total as u32).to_le_bytes());
        out.extend_from_slice(&(json.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&json);
        out.extend_from_slice(&(this.bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&this.bin);
        std::fs::write(path, out).expect("write glb");
    }

    /// Writes a `.gltf` with an external `.bin` and external `.png` images next to it.
    pub fn write_gltf_external(&self, path: &Path) {
        let dir = path.parent().expect("dir");
        let stem = path.file_stem().and_then(|s| s.to_str()).expect("stem");
        let bin_name = format!("{stem}.bin");
        std::fs::write(dir.join(&bin_name), &self.bin).expect("write bin");
        let mut json = self.finished_json(Some(bin_name));
        for (i, bytes) in self.images.iter().enumerate() {
            let name = format!("{stem}-image{i}.png");
            std::fs::write(dir.join(&name), bytes).expect("write png");
            if json["images"][i].get("uri").is_none() {
                json["images"][i]["uri"] = json!(name);
            }
        }
        std::fs::write(path, serde_json::to_vec_pretty(&json).expect("json")).expect("write");
    }

    /// Writes a self-contained `.gltf` with data URIs.
    pub fn write_gltf_embedded(&self, path: &Path) {
        let mut json = self.finished_json(Some(format!(
            "data:application/octet-stream;base64,{}",
            base64(&self.bin)
        )));
        for (i, bytes) in self.images.iter().enumerate() {
            json["images"][i]["uri"] = json!(format!("data:image/png;base64,{}", base64(bytes)));
        }
        std::fs::write(path, serde_json::to_vec(&json).expect("json")).expect("write");
    }
}

/// A textured, lit quad seen by a camera under a parent node, with a directional light:
/// the common test scene.
pub fn textured_quad() -> Gltf {
    let mut g = Gltf::new();
    let positions = g.vec3(&[
        [-1.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
    ]);
    let normals = g.vec3(&[[0.0, 0.0, 1.0]; 4]);
    let texcoords = g.vec2(&[[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]]);
    let indices = g.indices_u16(&[0, 1, 2, 0, 2, 3]);
    let image = g.image(test_png());
    let sampler =
        g.sampler(json!({"magFilter": 9728, "minFilter": 9986, "wrapS": 33071, "wrapT": 33648}));
    let texture = g.texture(json!({"source": image, "sampler": sampler}));
    let material = g.material(json!({
        "name": "quad-material",
        "pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.5, 0.25, 1.0], "baseColorTexture": {"index": texture}},
        "doubleSided": true,
        "alphaMode": "MASK",
        "alphaCutoff": 0.25,
    }));
    let mesh = g.mesh(
        "quad",
        vec![json!({
            "attributes": {"POSITION": positions, "NORMAL": normals, "TEXCOORD_0": texcoords},
            "indices": indices,
            "material": material,
        })],
    );
    let camera = g.camera(
        json!({"name": "cam", "type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}),
    );
    let camera_node =
        g.node(json!({"name": "camera", "camera": camera, "translation": [0.0, 0.0, 2.0]}));
    g.root(camera_node);
    g.json["extensionsUsed"] = json!(["KHR_lights_punctual"]);
    g.json["extensions"] = json!({"KHR_lights_punctual": {"lights": [
        {"name": "sun", "type": "directional", "color": [1.0, 0.5, 0.5], "intensity": 2.0}
    ]}});
    // Rotated −90° about x: the light node's +z axis (towards the light) becomes +y.
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let light_node = g.node(json!({"name": "sun", "rotation": [-s, 0.0, 0.0, s], "extensions": {"KHR_lights_punctual": {"light": 0}}}));
    g.root(light_node);
    let child = g.node(json!({"name": "quad", "mesh": mesh, "translation": [0.0, 0.0, -1.0]}));
    let parent = g.node(json!({"name": "parent", "translation": [0.5, 0.0, 0.0], "scale": [2.0, 2.0, 2.0], "children": [child]}));
    g.root(parent);
    g.json["scenes"][0]["extras"] =
        json!({"resolution": [320, 240], "clear_color": [0.1, 0.2, 0.3, 1.0], "ambient": 0.25});
    g
}
