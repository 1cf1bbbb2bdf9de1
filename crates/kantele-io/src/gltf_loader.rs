//! glTF 2.0 (`.gltf` with external or embedded data, `.glb`) by the reference-scene rules.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::{Mode, Semantic};
use kantele::scene::{AlphaMode, Camera, Draw, Light, Material, Mesh, Scene, TextureBinding};
use kantele::shade::texture::{Filter, MinFilter, Sampler, Texture, Wrap};

use crate::mesh_util::{
    fan_to_list, first_index_out_of_range, flat_normals, framing_camera, strip_to_list,
};
use crate::texture_util::decode_srgb;
use crate::{LoadError, LoadedScene, SceneInfo};

/// Extensions whose content the loader uses.
const SUPPORTED_EXTENSIONS: &[&str] = &["KHR_lights_punctual", "KHR_materials_unlit"];

/// Extensions that change how geometry or images are stored: without them the file cannot be
/// read at all, so requiring one is an error.
const UNREADABLE_EXTENSIONS: &[&str] = &[
    "KHR_draco_mesh_compression",
    "KHR_mesh_quantization",
    "EXT_meshopt_compression",
    "KHR_texture_basisu",
    "EXT_texture_webp",
    "EXT_texture_avif",
    "MSFT_texture_dds",
];

/// Default image size when the scene's extras give none.
const DEFAULT_RESOLUTION: (u32, u32) = (800, 600);

/// Loads a `.gltf` or `.glb` file.
pub fn load(path: &Path) -> Result<LoadedScene, LoadError> {
    let bytes = std::fs::read(path).map_err(|source| LoadError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    if bytes.is_empty() {
        return Err(LoadError::invalid(path, "the file is empty"));
    }
    let mut info = SceneInfo {
        source: path.display().to_string(),
        ..SceneInfo::default()
    };
    let gltf::Gltf { document, blob } = gltf::Gltf::from_slice_without_validation(&bytes)
        .map_err(|e| LoadError::invalid(path, format!("not a valid glTF file: {e}")))?;
    let document = check_extensions(path, document, &mut info)?;
    let buffers = load_buffers(path, &document, blob)?;
    Loader {
        path,
        document: &document,
        buffers: &buffers,
        scene: Scene::default(),
        info,
        image_textures: HashMap::new(),
        primitive_meshes: HashMap::new(),
        default_material: None,
    }
    .run()
}

/// Records the extensions, rejects required ones that cannot be read, and validates the document
/// (without the unsupported required extensions, which are tried anyway with a warning).
fn check_extensions(
    path: &Path,
    document: gltf::Document,
    info: &mut SceneInfo,
) -> Result<gltf::Document, LoadError> {
    info.extensions_used = document.extensions_used().map(String::from).collect();
    for ext in document.extensions_required() {
        if UNREADABLE_EXTENSIONS.contains(&ext) {
            return Err(LoadError::invalid(
                path,
                format!("the file requires extension {ext}, which this loader cannot read"),
            ));
        }
        if !SUPPORTED_EXTENSIONS.contains(&ext) {
            info.warn(format!(
                "the file requires unsupported extension {ext}; loading it anyway, the picture may be wrong"
            ));
        }
    }
    for ext in &info.extensions_used.clone() {
        if !SUPPORTED_EXTENSIONS.contains(&ext.as_str()) {
            info.warn(format!("extension {ext} is not supported and is ignored"));
        }
    }
    let mut json = document.into_json();
    json.extensions_required
        .retain(|e| SUPPORTED_EXTENSIONS.contains(&e.as_str()));
    validate(path, json, info)
}

/// Validates the document. Missing `min` / `max` on POSITION accessors (required by the spec,
/// often left out by hand-written files, and unused here) only give a warning.
fn validate(
    path: &Path,
    json: gltf::json::Root,
    info: &mut SceneInfo,
) -> Result<gltf::Document, LoadError> {
    match gltf::Document::from_json(json.clone()) {
        Ok(document) => Ok(document),
        Err(gltf::Error::Validation(errors)) => {
            let harmless = |(p, e): &(gltf::json::Path, gltf::json::validation::Error)| {
                matches!(e, gltf::json::validation::Error::Missing)
                    && (p.0.ends_with("[\"POSITION\"].min") || p.0.ends_with("[\"POSITION\"].max"))
            };
            if errors.iter().all(harmless) {
                info.warn("POSITION accessors lack the min / max the glTF spec requires");
                Ok(gltf::Document::from_json_without_validation(json))
            } else {
                let list: Vec<String> = errors
                    .iter()
                    .filter(|e| !harmless(e))
                    .map(|(p, e)| format!("{p}: {e}"))
                    .collect();
                Err(LoadError::invalid(
                    path,
                    format!("invalid glTF: {}", list.join("; ")),
                ))
            }
        }
        Err(e) => Err(LoadError::invalid(path, e.to_string())),
    }
}

/// Reads every buffer: the GLB binary chunk, external files or data URIs.
fn load_buffers(
    path: &Path,
    document: &gltf::Document,
    mut blob: Option<Vec<u8>>,
) -> Result<Vec<Vec<u8>>, LoadError> {
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        let what = format!("buffer {}", buffer.index());
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => blob.take().ok_or_else(|| {
                LoadError::invalid(
                    path,
                    format!("{what} refers to the binary chunk, which the file lacks"),
                )
            })?,
            gltf::buffer::Source::Uri(uri) => read_uri(path, uri, &what)?,
        };
        if data.len() < buffer.length() {
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

/// Reads the data an URI refers to: a `data:` URI, or a file relative to the glTF file.
fn read_uri(path: &Path, uri: &str, what: &str) -> Result<Vec<u8>, LoadError> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((_, payload)) = rest.split_once(";base64,") else {
            return Err(LoadError::invalid(
                path,
                format!("{what}: only base64 data URIs are supported"),
            ));
        };
        return decode_base64(payload).ok_or_else(|| {
            LoadError::invalid(path, format!("{what}: the data URI is not valid base64"))
        });
    }
    let file: PathBuf = if let Some(rest) = uri.strip_prefix("file://") {
        PathBuf::from(percent_decode(rest))
    } else if uri.contains(':') && !looks_like_windows_path(uri) {
        return Err(LoadError::invalid(
            path,
            format!("{what}: unsupported URI '{uri}' (only relative files and data URIs)"),
        ));
    } else {
        path.parent()
            .unwrap_or(Path::new(""))
            .join(percent_decode(uri))
    };
    std::fs::read(&file).map_err(|e| {
        LoadError::invalid(
            path,
            format!("{what}: cannot read file {}: {e}", file.display()),
        )
    })
}

fn looks_like_windows_path(uri: &str) -> bool {
    let b = uri.as_bytes();
    b.len() > 2 && b[0].is_ascii_alphabetic() && b[1] == b':' && (b[2] == b'/' || b[2] == b'\\')
}

/// Decodes `%XX` escapes (URIs in glTF are percent-encoded); malformed escapes stay as they are.
fn percent_decode(s: &str) -> String {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            let hex = std::str::from_utf8(&bytes[i + 1..i + 3])
                .ok()
                .and_then(|h| u8::from_str_radix(h, 16).ok());
            if let Some(byte) = hex {
                out.push(byte);
                i += 3;
                continue;
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Standard base64 (RFC 4648, padding optional, whitespace ignored); `None` on a bad character.
fn decode_base64(s: &str) -> Option<Vec<u8>> {
    fn value(c: u8) -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            _ => return None,
        } as u32)
    }
    let mut out = Vec::with_capacity(s.len() / 4 * 3);
    let mut acc = 0u32;
    let mut bits = 0;
    for c in s.bytes() {
        if c == b'=' {
            break;
        }
        if c.is_ascii_whitespace() {
            continue;
        }
        acc = (acc << 6) | value(c)?;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Some(out)
}

/// Converts a glTF document to a [`Scene`].
struct Loader<'a> {
    path: &'a Path,
    document: &'a gltf::Document,
    buffers: &'a [Vec<u8>],
    scene: Scene,
    info: SceneInfo,
    /// glTF image index → index into `scene.textures`.
    image_textures: HashMap<usize, usize>,
    /// (glTF mesh, primitive) → index into `scene.meshes` (`None`: not drawable, skipped).
    primitive_meshes: HashMap<(usize, usize), Option<usize>>,
    /// Index of the appended default material, once one was needed.
    default_material: Option<usize>,
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
            self.info
                .warn("skins are not supported; meshes are drawn in their bind pose");
        }
        if document.animations().len() > 0 {
            self.info
                .warn("animations are not supported and are ignored");
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
            if camera.is_none() {
                camera = self.camera(&node, world);
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
                    _ => self
                        .info
                        .warn("point and spot lights are not supported and are ignored"),
                }
            }
            if let Some(mesh) = node.mesh() {
                if node.skin().is_some() || mesh.weights().is_some() {
                    self.info
                        .warn("skinning and morph targets are not supported; drawn without them");
                }
                for primitive in mesh.primitives() {
                    let key = (mesh.index(), primitive.index());
                    let mesh_index = match self.primitive_meshes.get(&key) {
                        Some(&m) => m,
                        None => {
                            let m = self.primitive(&mesh, &primitive)?;
                            self.primitive_meshes.insert(key, m);
                            m
                        }
                    };
                    if let Some(mesh_index) = mesh_index {
                        self.scene.draws.push(Draw {
                            mesh: mesh_index,
                            model: world,
                            node_name: node.name().unwrap_or_default().to_string(),
                            node_index: index,
                        });
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

    /// The camera of a node, if it has a usable perspective one.
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
                    aspect_ratio: p.aspect_ratio(),
                    znear: p.znear(),
                    zfar: p.zfar(),
                })
            }
            gltf::camera::Projection::Orthographic(_) => {
                self.info.warn(format!(
                    "orthographic camera '{name}' is not supported; ignored"
                ));
                None
            }
        }
    }

    fn material(&mut self, material: &gltf::Material) -> Result<Material, LoadError> {
        let pbr = material.pbr_metallic_roughness();
        let base_color_texture = match pbr.base_color_texture() {
            Some(info) => self.texture_binding(&info)?,
            None => None,
        };
        let alpha_mode = match material.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => AlphaMode::Mask {
                cutoff: material.alpha_cutoff().unwrap_or(0.5),
            },
            gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        };
        Ok(Material {
            name: material.name().unwrap_or_default().to_string(),
            base_color_factor: Vec4::from(pbr.base_color_factor()),
            base_color_texture,
            double_sided: material.double_sided(),
            alpha_mode,
            unlit: material.unlit(),
        })
    }

    fn texture_binding(
        &mut self,
        info: &gltf::texture::Info,
    ) -> Result<Option<TextureBinding>, LoadError> {
        let texture = info.texture();
        if info.tex_coord() != 0 {
            self.info.warn(format!(
                "texture {} uses TEXCOORD_{}; only TEXCOORD_0 is supported, so it is left out",
                texture.index(),
                info.tex_coord()
            ));
            return Ok(None);
        }
        let image = texture.source();
        let texture_index = match self.image_textures.get(&image.index()) {
            Some(&t) => t,
            None => {
                let decoded = self.image(&image)?;
                self.scene.textures.push(Arc::new(decoded));
                let t = self.scene.textures.len() - 1;
                self.image_textures.insert(image.index(), t);
                t
            }
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

    /// Decodes one glTF image as an sRGB texture.
    fn image(&mut self, image: &gltf::Image) -> Result<Texture, LoadError> {
        let mut what = format!("image {}", image.index());
        if let Some(name) = image.name() {
            what = format!("{what} ('{name}')");
        }
        let (bytes, mime_type) = match image.source() {
            gltf::image::Source::View { view, mime_type } => {
                let data = self
                    .buffers
                    .get(view.buffer().index())
                    .and_then(|b| b.get(view.offset()..view.offset().checked_add(view.length())?))
                    .ok_or_else(|| {
                        self.invalid(format!("{what}: its buffer view lies outside the buffer"))
                    })?;
                (data.to_vec(), Some(mime_type))
            }
            gltf::image::Source::Uri { uri, mime_type } => {
                if !uri.starts_with("data:") {
                    what = format!("{what} from '{uri}'");
                }
                (read_uri(self.path, uri, &what)?, mime_type)
            }
        };
        decode_srgb(&bytes, mime_type).map_err(|e| self.invalid(format!("{what}: {e}")))
    }

    fn default_material(&mut self) -> usize {
        *self.default_material.get_or_insert_with(|| {
            self.scene.materials.push(Material::default());
            self.scene.materials.len() - 1
        })
    }

    /// Converts one primitive to a scene mesh; `None` when it is not drawn (points, lines).
    fn primitive(
        &mut self,
        mesh: &gltf::Mesh,
        primitive: &gltf::Primitive,
    ) -> Result<Option<usize>, LoadError> {
        let mesh_name = named(mesh.name(), "mesh", mesh.index());
        let what = format!("mesh '{mesh_name}' primitive {}", primitive.index());
        let mode = primitive.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            self.info.warn(format!(
                "{what}: mode {mode:?} is not drawn (only triangles are)"
            ));
            return Ok(None);
        }
        if primitive.morph_targets().len() > 0 {
            self.info
                .warn("skinning and morph targets are not supported; drawn without them");
        }

        let accessor_error = |semantic: &str, index: usize| {
            format!("{what}: {semantic} accessor {index} cannot be read (it lies outside its buffer or has no data)")
        };
        let check = |semantic: &str,
                     accessor: &gltf::Accessor,
                     types: &[DataType],
                     dims: &[Dimensions],
                     normalized_ints: bool|
         -> Result<(), LoadError> {
            let ty = accessor.data_type();
            let ok_type = types.contains(&ty)
                && dims.contains(&accessor.dimensions())
                && (!normalized_ints || ty == DataType::F32 || accessor.normalized());
            if !ok_type {
                return Err(self.invalid(format!(
                    "{what}: {semantic} accessor {} has type {:?} {:?}{}, which glTF does not allow",
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

        let Some(position_accessor) = primitive.get(&Semantic::Positions) else {
            return Err(self.invalid(format!("{what} has no POSITION attribute")));
        };
        check(
            "POSITION",
            &position_accessor,
            &[DataType::F32],
            &[Dimensions::Vec3],
            false,
        )?;
        let normal_accessor = primitive.get(&Semantic::Normals);
        if let Some(a) = &normal_accessor {
            check("NORMAL", a, &[DataType::F32], &[Dimensions::Vec3], false)?;
        }
        let texcoord_accessor = primitive.get(&Semantic::TexCoords(0));
        if let Some(a) = &texcoord_accessor {
            check(
                "TEXCOORD_0",
                a,
                &[DataType::F32, DataType::U8, DataType::U16],
                &[Dimensions::Vec2],
                true,
            )?;
        }
        let color_accessor = primitive.get(&Semantic::Colors(0));
        if let Some(a) = &color_accessor {
            check(
                "COLOR_0",
                a,
                &[DataType::F32, DataType::U8, DataType::U16],
                &[Dimensions::Vec3, Dimensions::Vec4],
                true,
            )?;
        }
        let index_accessor = primitive.indices();
        if let Some(a) = &index_accessor {
            check(
                "index",
                a,
                &[DataType::U8, DataType::U16, DataType::U32],
                &[Dimensions::Scalar],
                false,
            )?;
        }

        let buffers = self.buffers;
        let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
        let positions: Vec<Vec3> = reader
            .read_positions()
            .ok_or_else(|| self.invalid(accessor_error("POSITION", position_accessor.index())))?
            .map(Vec3::from)
            .collect();
        let n = positions.len();
        let count_error = |semantic: &str, len: usize| {
            self.invalid(format!(
                "{what}: {semantic} has {len} elements but POSITION has {n}"
            ))
        };
        if n != position_accessor.count() {
            return Err(self.invalid(accessor_error("POSITION", position_accessor.index())));
        }
        let normals = match &normal_accessor {
            Some(a) => {
                let normals: Vec<Vec3> = reader
                    .read_normals()
                    .ok_or_else(|| self.invalid(accessor_error("NORMAL", a.index())))?
                    .map(Vec3::from)
                    .collect();
                if normals.len() != n {
                    return Err(count_error("NORMAL", normals.len()));
                }
                Some(normals)
            }
            None => None,
        };
        let texcoords = match &texcoord_accessor {
            Some(a) => {
                let texcoords: Vec<Vec2> = reader
                    .read_tex_coords(0)
                    .ok_or_else(|| self.invalid(accessor_error("TEXCOORD_0", a.index())))?
                    .into_f32()
                    .map(Vec2::from)
                    .collect();
                if texcoords.len() != n {
                    return Err(count_error("TEXCOORD_0", texcoords.len()));
                }
                Some(texcoords)
            }
            None => None,
        };
        let colors = match &color_accessor {
            Some(a) => {
                let colors: Vec<Vec4> = reader
                    .read_colors(0)
                    .ok_or_else(|| self.invalid(accessor_error("COLOR_0", a.index())))?
                    .into_rgba_f32()
                    .map(Vec4::from)
                    .collect();
                if colors.len() != n {
                    return Err(count_error("COLOR_0", colors.len()));
                }
                Some(colors)
            }
            None => None,
        };
        let vertex_indices: Vec<u32> = match &index_accessor {
            Some(a) => {
                let indices: Vec<u32> = reader
                    .read_indices()
                    .ok_or_else(|| self.invalid(accessor_error("index", a.index())))?
                    .into_u32()
                    .collect();
                if indices.len() != a.count() {
                    return Err(self.invalid(accessor_error("index", a.index())));
                }
                indices
            }
            None => {
                let n = u32::try_from(n).map_err(|_| {
                    self.invalid(format!("{what}: too many vertices for 32-bit indices"))
                })?;
                (0..n).collect()
            }
        };
        let indices = match mode {
            Mode::TriangleStrip => strip_to_list(&vertex_indices),
            Mode::TriangleFan => fan_to_list(&vertex_indices),
            _ => {
                if vertex_indices.len() % 3 != 0 {
                    return Err(self.invalid(format!(
                        "{what}: {} indices do not make whole triangles",
                        vertex_indices.len()
                    )));
                }
                vertex_indices
            }
        };
        if let Some((position, index)) = first_index_out_of_range(&indices, n) {
            return Err(self.invalid(format!(
                "{what}: index {index} at position {position} is out of range for {n} vertices"
            )));
        }
        let material = match primitive.material().index() {
            Some(m) => m,
            None => self.default_material(),
        };
        let mut converted = Mesh {
            name: mesh_name,
            positions,
            normals,
            texcoords,
            colors,
            indices,
            material,
        };
        if converted.normals.is_none() {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round_trip() {
        assert_eq!(decode_base64("aGVsbG8=").unwrap(), b"hello");
        assert_eq!(decode_base64("aGVsbG8").unwrap(), b"hello");
        assert_eq!(decode_base64("AAECAwQF").unwrap(), vec![0, 1, 2, 3, 4, 5]);
        assert_eq!(decode_base64("").unwrap(), Vec::<u8>::new());
        assert!(decode_base64("a*b").is_none());
    }

    #[test]
    fn percent_decoding() {
        assert_eq!(percent_decode("my%20file.png"), "my file.png");
        assert_eq!(percent_decode("100%"), "100%");
        assert_eq!(percent_decode("%zz%4"), "%zz%4");
        assert_eq!(percent_decode("%C3%A4.bin"), "ä.bin");
    }
}
