//! glTF 2.0 (`.gltf` with external or embedded data, `.glb`) by the reference-scene rules.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use glam::{Mat3, Mat4, Quat, Vec2, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::{Mode, Semantic};
use kantele::scene::{
    AlphaMode, Camera, Draw, Light, Material, Mesh, NamedCamera, Scene, TextureBinding, Topology,
};
use kantele::shade::texture::{Filter, MinFilter, Sampler, Texture, Wrap};

use crate::accessor::{read_f32, read_u32, BufferData};
use crate::budget::Budget;
use crate::gltf_patch::{patch, split_glb, Patched};
use crate::mesh_util::{
    fan_to_list, first_index_out_of_range, flat_normals, framing_camera, line_strip_to_list,
    strip_to_list,
};
use crate::read_policy::{read_regular_file, ReadPolicy};
use crate::texture_util::{decode_srgb_within, image_size, placeholder, ImageError};
use crate::uri::read_uri;
use crate::{LoadError, LoadOptions, LoadedScene, SceneInfo};

/// Extensions whose content the loader uses.
pub(crate) const SUPPORTED_EXTENSIONS: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_unlit",
    "KHR_mesh_quantization",
    "KHR_texture_transform",
    "KHR_materials_emissive_strength",
    "EXT_mesh_gpu_instancing",
    "EXT_texture_webp",
    "EXT_meshopt_compression",
];

/// Extensions that change how geometry or images are stored and that this loader cannot decode:
/// requiring one is an error (using one without requiring it is refused where it is used).
const UNREADABLE_EXTENSIONS: &[&str] = &[
    "KHR_draco_mesh_compression",
    "KHR_texture_basisu",
    "EXT_texture_avif",
    "MSFT_texture_dds",
];

/// Default image size when the scene's extras give none.
const DEFAULT_RESOLUTION: (u32, u32) = (800, 600);

/// Loads a `.gltf` or `.glb` file under `options`.
pub fn load(path: &Path, options: &LoadOptions) -> Result<LoadedScene, LoadError> {
    std::fs::metadata(path).map_err(|source| LoadError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let invalid = |m: String| LoadError::invalid(path, m);
    let mut budget = Budget::new(options.max_memory);
    let bytes = read_regular_file(path, &mut budget).map_err(invalid)?;
    if bytes.is_empty() {
        return Err(LoadError::invalid(path, "the file is empty"));
    }
    let mut info = SceneInfo {
        source: path.display().to_string(),
        ..SceneInfo::default()
    };
    let (json, blob) = split_glb(&bytes).map_err(invalid)?;
    drop(bytes);
    // A parsed JSON tree takes several times its text.
    budget
        .charge(json.len() as u64, 16, "parsing the glTF JSON")
        .map_err(invalid)?;
    let mut value: serde_json::Value = serde_json::from_slice(&json)
        .map_err(|e| invalid(format!("not a valid glTF file: {e}")))?;
    drop(json);
    let patched = patch(&mut value).map_err(invalid)?;
    for w in &patched.warnings {
        info.warn(w.clone());
    }
    if patched.animations > 0 {
        info.ignore("animations");
    }
    let root: gltf::json::Root = serde_json::from_value(value)
        .map_err(|e| invalid(format!("not a valid glTF file: {e}")))?;
    let document = check_extensions(path, root, &mut info)?;
    let policy = ReadPolicy::new(path, &options.allow_read);
    let buffers = load_buffers(path, &document, blob, &policy, &mut budget)?;
    let decoded_views = crate::meshopt_views::decode_views(&document, &buffers, &mut budget)
        .map_err(|e| LoadError::invalid(path, e))?;
    Loader {
        path,
        document: &document,
        buffers: &buffers,
        decoded_views: &decoded_views,
        options,
        policy: &policy,
        budget,
        patched,
        scene: Scene::default(),
        info,
        image_textures: HashMap::new(),
        encoded_images: HashMap::new(),
        primitive_meshes: HashMap::new(),
        default_material: None,
        material_uv: Vec::new(),
    }
    .run()
}

/// Records the extensions and validates the document. What cannot be decoded at all was
/// refused while patching; other unsupported extensions give a warning (and the picture may
/// lack what they add).
fn check_extensions(
    path: &Path,
    mut json: gltf::json::Root,
    info: &mut SceneInfo,
) -> Result<gltf::Document, LoadError> {
    info.extensions_used = json.extensions_used.clone();
    for ext in &json.extensions_required {
        if UNREADABLE_EXTENSIONS.contains(&ext.as_str()) {
            return Err(LoadError::invalid(
                path,
                format!("the file requires extension {ext}, which this loader cannot decode"),
            ));
        }
        if !SUPPORTED_EXTENSIONS.contains(&ext.as_str()) {
            info.warn(format!(
                "the file requires unsupported extension {ext}; loading it anyway, the picture may be wrong"
            ));
        }
    }
    for ext in &json.extensions_used {
        if !SUPPORTED_EXTENSIONS.contains(&ext.as_str()) {
            info.ignore(ext.clone());
        }
    }
    // Handled above: the crate's own list of supported extensions must not reject the file.
    json.extensions_required.clear();
    validate(path, json, info)
}

/// Validates the document. Errors that the glTF spec allows or that this loader handles
/// itself are let through: missing `min` / `max` on POSITION accessors (a warning), accessors
/// without a buffer view (zero-filled) and textures without a source (drawn untextured).
fn validate(
    path: &Path,
    json: gltf::json::Root,
    info: &mut SceneInfo,
) -> Result<gltf::Document, LoadError> {
    use gltf::json::validation::{Error, Validate};
    let mut errors = Vec::new();
    json.validate(&json, gltf::json::Path::new, &mut |p, e| {
        errors.push((p(), e))
    });
    let mut min_max_missing = false;
    let fatal: Vec<String> = errors
        .iter()
        .filter(|(p, e)| {
            let p = p.as_str();
            let missing = matches!(e, Error::Missing);
            if missing && (p.ends_with("[\"POSITION\"].min") || p.ends_with("[\"POSITION\"].max")) {
                min_max_missing = true;
                return false;
            }
            let handled = missing
                && ((p.starts_with("accessors[") && p.ends_with("].bufferView"))
                    || (p.starts_with("textures[") && p.ends_with("].source")));
            !handled
        })
        .map(|(p, e)| format!("{p}: {e}"))
        .collect();
    if !fatal.is_empty() {
        return Err(LoadError::invalid(
            path,
            format!("invalid glTF: {}", fatal.join("; ")),
        ));
    }
    if min_max_missing {
        info.warn("POSITION accessors lack the min / max the glTF spec requires");
    }
    Ok(gltf::Document::from_json_without_validation(json))
}

/// Reads every buffer: the GLB binary chunk, external files or data URIs. Fallback buffers of
/// `EXT_meshopt_compression` that have no data stay empty.
fn load_buffers(
    path: &Path,
    document: &gltf::Document,
    mut blob: Option<Vec<u8>>,
    policy: &ReadPolicy,
    budget: &mut Budget,
) -> Result<Vec<Vec<u8>>, LoadError> {
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        let what = format!("buffer {}", buffer.index());
        let fallback = buffer
            .extension_value("EXT_meshopt_compression")
            .and_then(|v| v.get("fallback"))
            .and_then(serde_json::Value::as_bool)
            == Some(true);
        let data = match buffer.source() {
            gltf::buffer::Source::Bin if fallback => Vec::new(),
            gltf::buffer::Source::Bin => blob.take().ok_or_else(|| {
                LoadError::invalid(
                    path,
                    format!("{what} refers to the binary chunk, which the file lacks"),
                )
            })?,
            gltf::buffer::Source::Uri(uri) => read_uri(path, uri, policy, budget)
                .map_err(|e| LoadError::invalid(path, format!("{what}: {e}")))?,
        };
        if data.len() < buffer.length() && !fallback {
            return Err(LoadError::invalid(
                path,
                format!(
                    "{what} holds {} bytes but declares {} (truncated file?)",
                    data.len(),
                    buffer.length()
                ),
            ));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

/// Converts a glTF document to a [`Scene`].
struct Loader<'a> {
    path: &'a Path,
    document: &'a gltf::Document,
    buffers: &'a [Vec<u8>],
    /// `EXT_meshopt_compression` buffer views, decoded.
    decoded_views: &'a HashMap<usize, Vec<u8>>,
    options: &'a LoadOptions,
    policy: &'a ReadPolicy,
    budget: Budget,
    /// What patching the JSON found (the image each texture shows).
    patched: Patched,
    scene: Scene,
    info: SceneInfo,
    /// glTF image index → index into `scene.textures` (`None`: it could not be loaded).
    image_textures: HashMap<usize, Option<usize>>,
    /// Encoded image bytes → index into `scene.textures`: identical sources decode once.
    encoded_images: HashMap<Vec<u8>, usize>,
    /// (glTF mesh, primitive, morph weights' bits) → index into `scene.meshes` (`None`: not
    /// drawable, skipped).
    primitive_meshes: HashMap<(usize, usize, Vec<u32>), Option<usize>>,
    /// Index of the appended default material, once one was needed.
    default_material: Option<usize>,
    /// Per file material: the texture coordinates its textures read.
    material_uv: Vec<Option<UvMap>>,
}

/// Which texture coordinates a material's textures read: a `TEXCOORD_n` set and a
/// `KHR_texture_transform` (applied to the mesh's coordinates at load).
#[derive(Clone, Copy, Debug, PartialEq)]
struct UvMap {
    set: u32,
    transform: Mat3,
}

impl UvMap {
    fn of(info: &gltf::texture::Info) -> Self {
        let mut set = info.tex_coord();
        let mut transform = Mat3::IDENTITY;
        if let Some(t) = info.extension_value("KHR_texture_transform") {
            let pair = |key: &str, default: Vec2| {
                t.get(key)
                    .and_then(|v| v.as_array())
                    .and_then(|a| {
                        Some(Vec2::new(
                            a.first()?.as_f64()? as f32,
                            a.get(1)?.as_f64()? as f32,
                        ))
                    })
                    .unwrap_or(default)
            };
            let offset = pair("offset", Vec2::ZERO);
            let scale = pair("scale", Vec2::ONE);
            let rotation = t.get("rotation").and_then(|v| v.as_f64()).unwrap_or(0.0) as f32;
            // uv' = T × R × S × uv. R's columns are (cos, −sin) and (sin, cos): the direction
            // in which the sample models (TextureTransformTest, TextureTransformMultiTest) and
            // the common viewers rotate; checked by the corpus test.
            let (sin, cos) = rotation.sin_cos();
            let translation = Mat3::from_cols(Vec3::X, Vec3::Y, offset.extend(1.0));
            let rotation =
                Mat3::from_cols(Vec3::new(cos, -sin, 0.0), Vec3::new(sin, cos, 0.0), Vec3::Z);
            let scale = Mat3::from_diagonal(scale.extend(1.0));
            transform = translation * rotation * scale;
            if let Some(s) = t.get("texCoord").and_then(|v| v.as_u64()) {
                set = s as u32;
            }
            if !transform.is_finite() {
                transform = Mat3::IDENTITY;
            }
        }
        Self { set, transform }
    }
}

impl Loader<'_> {
    fn invalid(&self, message: impl Into<String>) -> LoadError {
        LoadError::invalid(self.path, message)
    }

    fn run(mut self) -> Result<LoadedScene, LoadError> {
        let document = self.document;
        self.info.node_count = document.nodes().len();
        self.info.cameras = document
            .cameras()
            .map(|c| named(c.name(), "camera", c.index()))
            .collect();
        self.info.lights = document
            .lights()
            .map(|lights| {
                lights
                    .map(|l| named(l.name(), "light", l.index()))
                    .collect()
            })
            .unwrap_or_default();
        for material in document.materials() {
            let converted = self.material(&material)?;
            self.scene.materials.push(converted);
        }
        if document.skins().len() > 0 {
            self.info.ignore("skins (meshes drawn in their bind pose)");
        }

        let Some(gltf_scene) = document
            .default_scene()
            .or_else(|| document.scenes().next())
        else {
            self.info.warn("the file has no scene: nothing is drawn");
            self.scene.camera = framing_camera(&self.scene);
            return Ok(LoadedScene {
                scene: self.scene,
                info: self.info,
            });
        };
        self.extras(&gltf_scene);

        let mut camera = None;
        let mut light = None;
        let mut visited = vec![false; document.nodes().len()];
        // Depth first, each node before its children, in file order.
        let mut stack: Vec<(gltf::Node, Mat4)> =
            gltf_scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
        stack.reverse();
        while let Some((node, parent)) = stack.pop() {
            let index = node.index();
            if std::mem::replace(&mut visited[index], true) {
                self.info.warn(format!(
                    "node {index} is reached more than once (the node hierarchy is not a tree); drawn once"
                ));
                continue;
            }
            let local = Mat4::from_cols_array_2d(&node.transform().matrix());
            let world = parent * local;
            if let Some(c) = self.camera(&node, world) {
                let name = node
                    .camera()
                    .map(|c| named(c.name(), "camera", c.index()))
                    .unwrap_or_default();
                self.scene
                    .file_cameras
                    .push(NamedCamera { name, camera: c });
                if camera.is_none() {
                    camera = Some(c);
                }
            }
            if let Some(l) = node.light() {
                match l.kind() {
                    gltf::khr_lights_punctual::Kind::Directional => {
                        if light.is_none() {
                            light = Some(Light::Directional {
                                to_light: world.transform_vector3(Vec3::Z).normalize_or_zero(),
                                color: Vec3::from(l.color()) * l.intensity(),
                            });
                        }
                    }
                    _ => self.info.ignore("point and spot lights"),
                }
            }
            if let Some(mesh) = node.mesh() {
                if node.skin().is_some() {
                    self.info.ignore("skins (meshes drawn in their bind pose)");
                }
                // Default morph weights: the node's, else the mesh's (the rest pose).
                let weights: Vec<f32> = node
                    .weights()
                    .or(mesh.weights())
                    .map(<[f32]>::to_vec)
                    .unwrap_or_default();
                let instances = self.instances(&node, world)?;
                for primitive in mesh.primitives() {
                    let key = (
                        mesh.index(),
                        primitive.index(),
                        weights.iter().map(|w| w.to_bits()).collect::<Vec<u32>>(),
                    );
                    let mesh_index = match self.primitive_meshes.get(&key) {
                        Some(&m) => m,
                        None => {
                            let m = self.primitive(&mesh, &primitive, &weights)?;
                            self.primitive_meshes.insert(key, m);
                            m
                        }
                    };
                    if let Some(mesh_index) = mesh_index {
                        self.budget
                            .charge(instances.len() as u64, 128, "the draws of a node")
                            .map_err(|e| self.invalid(e))?;
                        for &model in &instances {
                            self.scene.draws.push(Draw {
                                mesh: mesh_index,
                                model,
                                node_name: node.name().unwrap_or_default().to_string(),
                                node_index: index,
                            });
                        }
                    }
                }
            }
            let children: Vec<_> = node.children().collect();
            for child in children.into_iter().rev() {
                stack.push((child, world));
            }
        }

        self.scene.light = light.unwrap_or(Light::Headlight);
        match camera {
            Some(camera) => {
                self.scene.camera = camera;
                self.info.camera_from_file = true;
            }
            None => {
                self.scene.camera = framing_camera(&self.scene);
                self.info.camera_from_file = false;
            }
        }
        self.scene
            .validate()
            .map_err(|e| self.invalid(e.to_string()))?;
        Ok(LoadedScene {
            scene: self.scene,
            info: self.info,
        })
    }

    /// The model matrices a node's mesh is drawn with: its world matrix, or one per instance of
    /// `EXT_mesh_gpu_instancing` (world × the instance's TRS).
    fn instances(&mut self, node: &gltf::Node, world: Mat4) -> Result<Vec<Mat4>, LoadError> {
        let Some(ext) = node.extension_value("EXT_mesh_gpu_instancing") else {
            return Ok(vec![world]);
        };
        let what = format!("node {} (EXT_mesh_gpu_instancing)", node.index());
        let attributes = ext.get("attributes").and_then(|a| a.as_object());
        let data = BufferData {
            buffers: self.buffers,
            decoded_views: self.decoded_views,
        };
        let mut read = |name: &str, components: usize| -> Result<Option<Vec<f32>>, LoadError> {
            let Some(index) = attributes
                .and_then(|a| a.get(name))
                .and_then(|v| v.as_u64())
            else {
                return Ok(None);
            };
            let accessor = self
                .document
                .accessors()
                .nth(index as usize)
                .ok_or_else(|| {
                    LoadError::invalid(self.path, format!("{what}: no accessor {index}"))
                })?;
            if accessor.dimensions().multiplicity() != components {
                return Err(LoadError::invalid(
                    self.path,
                    format!("{what}: {name} accessor {index} has the wrong type"),
                ));
            }
            let label = format!("{what}: {name} accessor {index}");
            read_f32(&data, &accessor, &mut self.budget, &label)
                .map(Some)
                .map_err(|e| LoadError::invalid(self.path, e))
        };
        let translation = read("TRANSLATION", 3)?;
        let rotation = read("ROTATION", 4)?;
        let scale = read("SCALE", 3)?;
        let counts = [
            translation.as_ref().map(|t| t.len() / 3),
            rotation.as_ref().map(|r| r.len() / 4),
            scale.as_ref().map(|s| s.len() / 3),
        ];
        let mut known = counts.iter().flatten();
        let Some(&count) = known.next() else {
            return Ok(vec![world]);
        };
        if known.any(|&c| c != count) {
            return Err(self.invalid(format!(
                "{what}: the instance attributes have different counts"
            )));
        }
        let mut models =
            crate::budget::vec_with_capacity(count, &what).map_err(|e| self.invalid(e))?;
        for i in 0..count {
            let t = translation
                .as_ref()
                .map_or(Vec3::ZERO, |t| Vec3::from_slice(&t[3 * i..]));
            let r = rotation.as_ref().map_or(Quat::IDENTITY, |r| {
                let q = Vec4::from_slice(&r[4 * i..]);
                q.try_normalize().map_or(Quat::IDENTITY, Quat::from_vec4)
            });
            let s = scale
                .as_ref()
                .map_or(Vec3::ONE, |s| Vec3::from_slice(&s[3 * i..]));
            models.push(world * Mat4::from_scale_rotation_translation(s, r, t));
        }
        Ok(models)
    }

    /// Reads `resolution`, `clear_color` and `ambient` from the scene's extras.
    fn extras(&mut self, gltf_scene: &gltf::Scene) {
        self.scene.resolution = DEFAULT_RESOLUTION;
        self.scene.clear_color = Vec4::new(0.0, 0.0, 0.0, 1.0);
        self.scene.ambient = 0.1;
        let Some(raw) = gltf_scene.extras() else {
            return;
        };
        let value: serde_json::Value = match serde_json::from_str(raw.get()) {
            Ok(v) => v,
            Err(e) => {
                self.info
                    .warn(format!("scene extras are not valid JSON ({e}); ignored"));
                return;
            }
        };
        let numbers = |v: &serde_json::Value| -> Option<Vec<f64>> {
            v.as_array()?
                .iter()
                .map(serde_json::Value::as_f64)
                .collect()
        };
        if let Some(v) = value.get("resolution") {
            let max = kantele::MAX_TARGET_SIZE as f64;
            match numbers(v).as_deref() {
                Some(&[w, h])
                    if w >= 1.0 && h >= 1.0 && w <= max && h <= max && w.fract() == 0.0 && h.fract() == 0.0 =>
                {
                    self.scene.resolution = (w as u32, h as u32);
                }
                _ => self.info.warn(format!(
                    "scene extras: resolution {v} is not [width, height] in 1..={max}; using 800x600"
                )),
            }
        }
        if let Some(v) = value.get("clear_color") {
            match numbers(v).as_deref() {
                Some(&[r, g, b, a]) if [r, g, b, a].iter().all(|c| c.is_finite()) => {
                    self.scene.clear_color = Vec4::new(r as f32, g as f32, b as f32, a as f32);
                }
                Some(&[r, g, b]) if [r, g, b].iter().all(|c| c.is_finite()) => {
                    self.scene.clear_color = Vec4::new(r as f32, g as f32, b as f32, 1.0);
                }
                _ => self.info.warn(format!(
                    "scene extras: clear_color {v} is not [r, g, b, a]; using black"
                )),
            }
        }
        if let Some(v) = value.get("ambient") {
            match v.as_f64() {
                Some(a) if a.is_finite() => self.scene.ambient = a as f32,
                _ => self.info.warn(format!(
                    "scene extras: ambient {v} is not a number; using 0.1"
                )),
            }
        }
    }

    /// The camera of a node, if it has a usable (perspective or orthographic) one.
    fn camera(&mut self, node: &gltf::Node, world: Mat4) -> Option<Camera> {
        let camera = node.camera()?;
        let name = named(camera.name(), "camera", camera.index());
        match camera.projection() {
            gltf::camera::Projection::Perspective(p) => {
                let ok = p.yfov().is_finite()
                    && p.yfov() > 0.0
                    && p.yfov() < std::f32::consts::PI
                    && p.znear().is_finite()
                    && p.znear() > 0.0
                    && p.zfar().is_none_or(|f| f.is_finite() && f > p.znear())
                    && p.aspect_ratio().is_none_or(|a| a.is_finite() && a > 0.0);
                let view = world.inverse();
                if !ok || !view.is_finite() {
                    self.info.warn(format!(
                        "camera '{name}' has invalid parameters or placement; ignored"
                    ));
                    return None;
                }
                Some(Camera {
                    view,
                    yfov: p.yfov(),
                    ymag: None,
                    aspect_ratio: p.aspect_ratio(),
                    znear: p.znear(),
                    zfar: p.zfar(),
                })
            }
            gltf::camera::Projection::Orthographic(o) => {
                // Pixels stay square: `ymag` is kept and the image's aspect decides the width;
                // `xmag / ymag` is the aspect an image takes when no size is given.
                let (xmag, ymag) = (o.xmag().abs(), o.ymag().abs());
                let ok = xmag.is_finite()
                    && xmag > 0.0
                    && ymag.is_finite()
                    && ymag > 0.0
                    && o.znear().is_finite()
                    && o.znear() >= 0.0
                    && o.zfar().is_finite()
                    && o.zfar() > o.znear();
                let view = world.inverse();
                if !ok || !view.is_finite() {
                    self.info.warn(format!(
                        "camera '{name}' has invalid parameters or placement; ignored"
                    ));
                    return None;
                }
                Some(Camera {
                    view,
                    yfov: std::f32::consts::FRAC_PI_4,
                    ymag: Some(ymag),
                    aspect_ratio: Some(xmag / ymag),
                    // glTF allows znear = 0 for orthographic cameras; the pipeline's depth
                    // range needs a positive one.
                    znear: o.znear().max(o.zfar() * 1e-6),
                    zfar: Some(o.zfar()),
                })
            }
        }
    }

    /// Converts a material; also records which texture coordinates its textures read
    /// (`self.material_uv`), which the loader bakes into the meshes that use it.
    fn material(&mut self, material: &gltf::Material) -> Result<Material, LoadError> {
        let name = named(material.name(), "material", material.index().unwrap_or(0));
        let pbr = material.pbr_metallic_roughness();
        let (base_color_texture, base_uv) = match pbr.base_color_texture() {
            Some(info) => (self.texture_binding(&info)?, Some(UvMap::of(&info))),
            None => (None, None),
        };
        let strength = material
            .extension_value("KHR_materials_emissive_strength")
            .and_then(|v| v.get("emissiveStrength"))
            .and_then(serde_json::Value::as_f64)
            .filter(|s| s.is_finite() && *s >= 0.0)
            .unwrap_or(1.0) as f32;
        let mut emissive = Vec3::from(material.emissive_factor()) * strength;
        if !emissive.is_finite() {
            emissive = Vec3::ZERO;
        }
        let (mut emissive_texture, emissive_uv) = match material.emissive_texture() {
            Some(info) => (self.texture_binding(&info)?, Some(UvMap::of(&info))),
            None => (None, None),
        };
        let mut uv = base_color_texture.and(base_uv);
        if emissive_texture.is_some() {
            match uv {
                None => uv = emissive_uv,
                Some(base) if Some(base) != emissive_uv => {
                    self.info.warn(format!(
                        "material '{name}': the emissive texture reads other texture coordinates than the base colour texture; its emission is left out"
                    ));
                    emissive_texture = None;
                    emissive = Vec3::ZERO;
                }
                Some(_) => {}
            }
        }
        self.material_uv.push(uv);
        let alpha_mode = match material.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => AlphaMode::Mask {
                cutoff: material.alpha_cutoff().unwrap_or(0.5),
            },
            gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        };
        if material.unlit() {
            // KHR_materials_unlit: every property but the base colour is a fallback for viewers
            // without the extension; the unlit shading adds emission, so drop it here.
            emissive = Vec3::ZERO;
            emissive_texture = None;
        }
        Ok(Material {
            name: material.name().unwrap_or_default().to_string(),
            base_color_factor: Vec4::from(pbr.base_color_factor()),
            base_color_texture,
            double_sided: material.double_sided(),
            alpha_mode,
            unlit: material.unlit(),
            emissive,
            emissive_texture,
        })
    }

    fn texture_binding(
        &mut self,
        info: &gltf::texture::Info,
    ) -> Result<Option<TextureBinding>, LoadError> {
        let texture = info.texture();
        let Some(image_index) = self
            .patched
            .texture_images
            .get(texture.index())
            .copied()
            .flatten()
        else {
            return Ok(None);
        };
        let texture_index = match self.image_textures.get(&image_index) {
            Some(&t) => t,
            None => {
                let t = self.image(image_index)?;
                self.image_textures.insert(image_index, t);
                t
            }
        };
        let Some(texture_index) = texture_index else {
            return Ok(None);
        };
        let s = texture.sampler();
        let wrap = |mode| match mode {
            gltf::texture::WrappingMode::ClampToEdge => Wrap::ClampToEdge,
            gltf::texture::WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
            gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
        };
        let sampler = Sampler {
            wrap_s: wrap(s.wrap_s()),
            wrap_t: wrap(s.wrap_t()),
            mag_filter: match s.mag_filter() {
                Some(gltf::texture::MagFilter::Nearest) => Filter::Nearest,
                Some(gltf::texture::MagFilter::Linear) | None => Filter::Linear,
            },
            min_filter: match s.min_filter() {
                Some(gltf::texture::MinFilter::Nearest) => MinFilter::Nearest,
                Some(gltf::texture::MinFilter::Linear) => MinFilter::Linear,
                Some(gltf::texture::MinFilter::NearestMipmapNearest) => {
                    MinFilter::NearestMipmapNearest
                }
                Some(gltf::texture::MinFilter::LinearMipmapNearest) => {
                    MinFilter::LinearMipmapNearest
                }
                Some(gltf::texture::MinFilter::NearestMipmapLinear) => {
                    MinFilter::NearestMipmapLinear
                }
                Some(gltf::texture::MinFilter::LinearMipmapLinear) | None => {
                    MinFilter::LinearMipmapLinear
                }
            },
        };
        Ok(Some(TextureBinding {
            texture: texture_index,
            sampler,
        }))
    }

    /// Loads one glTF image as an sRGB texture into the scene (once per distinct encoded
    /// image); `None` when it is missing or cannot be decoded and the load is not strict (a
    /// warning says so). Budget overruns are always errors.
    fn image(&mut self, index: usize) -> Result<Option<usize>, LoadError> {
        let Some(image) = self.document.images().nth(index) else {
            return Ok(None);
        };
        let mut what = format!("image {index}");
        if let Some(name) = image.name() {
            what = format!("{what} ('{name}')");
        }
        let loaded = match image.source() {
            gltf::image::Source::View { view, mime_type } => {
                let data = BufferData {
                    buffers: self.buffers,
                    decoded_views: self.decoded_views,
                };
                data.view(&view)
                    .map(|b| (b.to_vec(), Some(mime_type.to_string())))
            }
            gltf::image::Source::Uri { uri, mime_type } => {
                if !uri.starts_with("data:") {
                    what = format!("{what} from '{uri}'");
                }
                read_uri(self.path, uri, self.policy, &mut self.budget)
                    .map(|b| (b, mime_type.map(str::to_string)))
            }
        };
        let (bytes, mime_type) = match loaded {
            Ok(loaded) => loaded,
            Err(e) if e.contains("memory budget") => {
                return Err(self.invalid(format!("{what}: {e}")))
            }
            Err(e) => return self.texture_problem(format!("{what}: {e}")),
        };
        if let Some(&t) = self.encoded_images.get(&bytes) {
            return Ok(Some(t));
        }
        let size = match image_size(&bytes, mime_type.as_deref()) {
            Ok(size) => size,
            Err(ImageError::Budget(e) | ImageError::Decode(e)) => {
                return self.texture_problem(format!("{what}: {e}"))
            }
        };
        if !self.options.decode_textures {
            // Describing the scene: the header's size is reported, nothing is decoded.
            return Ok(Some(self.push_texture(placeholder(), bytes, size)));
        }
        match decode_srgb_within(&bytes, mime_type.as_deref(), &mut self.budget) {
            Ok(texture) => Ok(Some(self.push_texture(texture, bytes, size))),
            Err(ImageError::Budget(e)) => Err(self.invalid(format!("{what}: {e}"))),
            Err(ImageError::Decode(e)) => self.texture_problem(format!("{what}: {e}")),
        }
    }

    fn push_texture(&mut self, texture: Texture, encoded: Vec<u8>, size: (u32, u32)) -> usize {
        self.scene.textures.push(Arc::new(texture));
        self.info.texture_sizes.push(size);
        let t = self.scene.textures.len() - 1;
        self.encoded_images.insert(encoded, t);
        t
    }

    /// A texture that cannot be loaded: an error when strict, otherwise a warning and no
    /// texture.
    fn texture_problem(&mut self, message: String) -> Result<Option<usize>, LoadError> {
        if self.options.strict {
            return Err(self.invalid(message));
        }
        self.info.warn(format!(
            "{message}; drawn untextured (--strict makes this an error)"
        ));
        Ok(None)
    }

    fn default_material(&mut self) -> usize {
        *self.default_material.get_or_insert_with(|| {
            self.scene.materials.push(Material::default());
            self.scene.materials.len() - 1
        })
    }

    /// Converts one primitive (triangles, lines or points) to a scene mesh.
    fn primitive(
        &mut self,
        mesh: &gltf::Mesh,
        primitive: &gltf::Primitive,
        weights: &[f32],
    ) -> Result<Option<usize>, LoadError> {
        let mesh_name = named(mesh.name(), "mesh", mesh.index());
        let what = format!("mesh '{mesh_name}' primitive {}", primitive.index());
        let mode = primitive.mode();
        let material = match primitive.material().index() {
            Some(m) => m,
            None => self.default_material(),
        };
        let uv = self.material_uv.get(material).copied().flatten();
        let uv_set = uv.map_or(0, |u| u.set);

        let check = |semantic: &str,
                     accessor: &gltf::Accessor,
                     allowed: &[(DataType, bool)],
                     dims: &[Dimensions]|
         -> Result<(), LoadError> {
            let ty = accessor.data_type();
            let normalized = accessor.normalized() && ty != DataType::F32;
            let ok_type =
                allowed.contains(&(ty, normalized)) && dims.contains(&accessor.dimensions());
            if !ok_type {
                return Err(self.invalid(format!(
                    "{what}: {semantic} accessor {} has type {:?} {:?}{}, which glTF (with KHR_mesh_quantization) does not allow",
                    accessor.index(),
                    ty,
                    accessor.dimensions(),
                    if accessor.normalized() { " (normalized)" } else { "" }
                )));
            }
            if accessor.count() == 0 {
                return Err(self.invalid(format!(
                    "{what}: {semantic} accessor {} is empty",
                    accessor.index()
                )));
            }
            Ok(())
        };
        use DataType::{F32, I16, I8, U16, U32, U8};
        // Types of glTF 2.0 plus KHR_mesh_quantization, as (component type, normalized).
        let any_int = [
            (F32, false),
            (I8, false),
            (I8, true),
            (U8, false),
            (U8, true),
            (I16, false),
            (I16, true),
            (U16, false),
            (U16, true),
        ];
        let normal_types = [(F32, false), (I8, true), (I16, true)];
        let color_types = [(F32, false), (U8, true), (U16, true)];
        let index_types = [(U8, false), (U16, false), (U32, false)];

        let Some(position_accessor) = primitive.get(&Semantic::Positions) else {
            return Err(self.invalid(format!("{what} has no POSITION attribute")));
        };
        check(
            "POSITION",
            &position_accessor,
            &any_int,
            &[Dimensions::Vec3],
        )?;
        let normal_accessor = primitive.get(&Semantic::Normals);
        if let Some(a) = &normal_accessor {
            check("NORMAL", a, &normal_types, &[Dimensions::Vec3])?;
        }
        let texcoord_name = format!("TEXCOORD_{uv_set}");
        let texcoord_accessor = primitive.get(&Semantic::TexCoords(uv_set));
        if let Some(a) = &texcoord_accessor {
            check(&texcoord_name, a, &any_int, &[Dimensions::Vec2])?;
        }
        let color_accessor = primitive.get(&Semantic::Colors(0));
        if let Some(a) = &color_accessor {
            check(
                "COLOR_0",
                a,
                &color_types,
                &[Dimensions::Vec3, Dimensions::Vec4],
            )?;
        }
        let index_accessor = primitive.indices();
        if let Some(a) = &index_accessor {
            check("index", a, &index_types, &[Dimensions::Scalar])?;
        }

        let data = BufferData {
            buffers: self.buffers,
            decoded_views: self.decoded_views,
        };
        let n = position_accessor.count();
        let mut read = |semantic: &str, accessor: &gltf::Accessor| {
            let label = format!("{what}: {semantic} accessor {}", accessor.index());
            read_f32(&data, accessor, &mut self.budget, &label)
        };
        let positions: Vec<Vec3> = read("POSITION", &position_accessor)
            .map_err(|e| LoadError::invalid(self.path, e))?
            .chunks_exact(3)
            .map(Vec3::from_slice)
            .collect();
        let count_error = |semantic: &str, len: usize| {
            LoadError::invalid(
                self.path,
                format!("{what}: {semantic} has {len} elements but POSITION has {n}"),
            )
        };
        let normals = match &normal_accessor {
            Some(a) if a.count() != n => return Err(count_error("NORMAL", a.count())),
            Some(a) => Some(
                read("NORMAL", a)
                    .map_err(|e| LoadError::invalid(self.path, e))?
                    .chunks_exact(3)
                    .map(Vec3::from_slice)
                    .collect::<Vec<_>>(),
            ),
            None => None,
        };
        let texcoords = match &texcoord_accessor {
            Some(a) if a.count() != n => return Err(count_error(&texcoord_name, a.count())),
            Some(a) => {
                let transform = uv.map_or(Mat3::IDENTITY, |u| u.transform);
                Some(
                    read(&texcoord_name, a)
                        .map_err(|e| LoadError::invalid(self.path, e))?
                        .chunks_exact(2)
                        .map(|t| transform.transform_point2(Vec2::from_slice(t)))
                        .collect::<Vec<_>>(),
                )
            }
            None => None,
        };
        let (mut positions, mut normals) = (positions, normals);
        for (target, &weight) in primitive.morph_targets().zip(weights) {
            if weight == 0.0 || !weight.is_finite() {
                continue;
            }
            let mut apply = |accessor: Option<gltf::Accessor>,
                             values: &mut [Vec3],
                             semantic: &str|
             -> Result<(), LoadError> {
                let Some(a) = accessor else { return Ok(()) };
                if a.count() != n || a.dimensions() != Dimensions::Vec3 {
                    return Err(count_error(semantic, a.count()));
                }
                let deltas = read(semantic, &a).map_err(|e| LoadError::invalid(self.path, e))?;
                for (v, d) in values.iter_mut().zip(deltas.chunks_exact(3)) {
                    *v += weight * Vec3::from_slice(d);
                }
                Ok(())
            };
            apply(target.positions(), &mut positions, "morph target POSITION")?;
            if let Some(normals) = normals.as_mut() {
                apply(target.normals(), normals, "morph target NORMAL")?;
            }
        }
        let colors = match &color_accessor {
            Some(a) if a.count() != n => return Err(count_error("COLOR_0", a.count())),
            Some(a) => {
                let flat = read("COLOR_0", a).map_err(|e| LoadError::invalid(self.path, e))?;
                Some(if a.dimensions() == Dimensions::Vec3 {
                    flat.chunks_exact(3)
                        .map(|c| Vec4::new(c[0], c[1], c[2], 1.0))
                        .collect::<Vec<_>>()
                } else {
                    flat.chunks_exact(4).map(Vec4::from_slice).collect()
                })
            }
            None => None,
        };
        let vertex_indices: Vec<u32> = match &index_accessor {
            Some(a) => {
                let label = format!("{what}: index accessor {}", a.index());
                read_u32(&data, a, &mut self.budget, &label)
                    .map_err(|e| LoadError::invalid(self.path, e))?
            }
            None => {
                let n = u32::try_from(n).map_err(|_| {
                    self.invalid(format!("{what}: too many vertices for 32-bit indices"))
                })?;
                self.budget
                    .charge(n as u64, 4, &what)
                    .map_err(|e| LoadError::invalid(self.path, e))?;
                (0..n).collect()
            }
        };
        if positions.iter().any(|p| !p.is_finite()) {
            self.info.warn(format!(
                "{what}: some positions are infinite or NaN; triangles using them are not drawn"
            ));
        }
        let (indices, topology) = match mode {
            Mode::TriangleStrip => (strip_to_list(&vertex_indices), Topology::Triangles),
            Mode::TriangleFan => (fan_to_list(&vertex_indices), Topology::Triangles),
            Mode::LineStrip => (line_strip_to_list(&vertex_indices, false), Topology::Lines),
            Mode::LineLoop => (line_strip_to_list(&vertex_indices, true), Topology::Lines),
            Mode::Points => (vertex_indices, Topology::Points),
            Mode::Lines | Mode::Triangles => {
                let topology = if mode == Mode::Lines {
                    Topology::Lines
                } else {
                    Topology::Triangles
                };
                let per = topology.vertices_per_primitive();
                if vertex_indices.len() % per != 0 {
                    return Err(self.invalid(format!(
                        "{what}: {} indices do not make whole {}",
                        vertex_indices.len(),
                        topology.name()
                    )));
                }
                (vertex_indices, topology)
            }
        };
        if let Some((position, index)) = first_index_out_of_range(&indices, n) {
            return Err(self.invalid(format!(
                "{what}: index {index} at position {position} is out of range for {n} vertices"
            )));
        }
        let mut converted = Mesh {
            name: mesh_name,
            positions,
            normals,
            texcoords,
            colors,
            indices,
            topology,
            material,
        };
        if converted.normals.is_none() && topology == Topology::Triangles {
            // De-indexed: one vertex (position, normal, texcoord, colour) per corner.
            self.budget
                .charge(converted.indices.len() as u64, 48, &what)
                .map_err(|e| self.invalid(e))?;
            flat_normals(&mut converted);
        }
        self.scene.meshes.push(converted);
        Ok(Some(self.scene.meshes.len() - 1))
    }
}

/// A name for reports: the file's name, or `KIND INDEX`.
fn named(name: Option<&str>, kind: &str, index: usize) -> String {
    match name {
        Some(n) if !n.is_empty() => n.to_string(),
        _ => format!("{kind} {index}"),
    }
}
