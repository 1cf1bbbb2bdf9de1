//! glTF 2.0 (`.gltf` with external or embedded data, `.glb`) by the reference-scene rules.

mod animation;
mod camera;
mod catalogue;
mod clip;
mod material;
mod material_extensions;
mod morph;
mod nodes;
mod pose;
mod primitive;
mod rig_builder;
mod skin;
mod spec_gloss;

pub use pose::{AnimationPlayer, PoseError};

use std::collections::HashMap;
use std::path::Path;

use kantele_rules::scene::Scene;
use kantele_rules::shade::texture::ColorSpace;

use crate::budget::Budget;
use crate::gltf_patch::{patch, split_glb, Patched};
use crate::read_policy::{read_scene_file, ReadPolicy};
use crate::uri::read_uri;
use crate::{LoadError, LoadOptions, LoadedScene, SceneInfo};
use material::MaterialUvMaps;

/// Extensions whose content the loader uses.
pub(crate) const SUPPORTED_EXTENSIONS: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_unlit",
    "KHR_mesh_quantization",
    "KHR_texture_transform",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_specular",
    "KHR_materials_clearcoat",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    "KHR_materials_sheen",
    "KHR_materials_pbrSpecularGlossiness",
    "EXT_mesh_gpu_instancing",
    "EXT_texture_webp",
    "EXT_meshopt_compression",
    "KHR_texture_basisu",
    "MSFT_texture_dds",
    "KHR_materials_variants",
    "KHR_draco_mesh_compression",
];

/// Extensions that change how geometry or images are stored and that this loader cannot decode:
/// requiring one is an error (using one without requiring it is refused where it is used).
const UNREADABLE_EXTENSIONS: &[&str] = &["EXT_texture_avif"];

/// Default image size when the scene's extras give none.
const DEFAULT_RESOLUTION: (u32, u32) = (800, 600);

/// Loads a `.gltf` or `.glb` file under `options`.
pub fn load(path: &Path, options: &LoadOptions) -> Result<LoadedScene, LoadError> {
    let invalid = |m: String| LoadError::invalid(path, m);
    let (bytes, mut budget) = read_scene_file(path, options.max_memory)?;
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
    // Read before patching, which drops the animations.
    let animations = catalogue::read_animations(&value, &mut budget).map_err(invalid)?;
    let patched = patch(&mut value).map_err(invalid)?;
    for w in &patched.warnings {
        info.warn(w.clone());
    }
    let root: gltf::json::Root = serde_json::from_value(value)
        .map_err(|e| invalid(format!("not a valid glTF file: {e}")))?;
    let document = check_extensions(path, root, &mut info)?;
    let policy = ReadPolicy::new(path, &options.allow_read);
    let buffers = load_buffers(path, &document, blob, &policy, &mut budget)?;
    let mut decoded_views = crate::meshopt_views::decode_views(&document, &buffers, &mut budget)
        .map_err(|e| LoadError::invalid(path, e))?;
    let draco = crate::draco_views::decode_views(&document, &buffers, &patched.draco, &mut budget)
        .map_err(|e| LoadError::invalid(path, e))?;
    decoded_views.extend(draco);
    Loader {
        path,
        document: &document,
        buffers: &buffers,
        decoded_views: &decoded_views,
        options,
        policy: &policy,
        budget,
        patched,
        animations,
        scene: Scene::default(),
        info,
        image_textures: HashMap::new(),
        encoded_images: HashMap::new(),
        spec_gloss_textures: HashMap::new(),
        primitive_meshes: HashMap::new(),
        default_material: None,
        material_uv: Vec::new(),
        material_normal_map: Vec::new(),
        reference_extras: false,
        clear_color_given: false,
        rig: None,
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
    /// `EXT_meshopt_compression` buffer views and those made for `KHR_draco_mesh_compression`
    /// accessors, decoded.
    decoded_views: &'a HashMap<usize, Vec<u8>>,
    options: &'a LoadOptions,
    policy: &'a ReadPolicy,
    budget: Budget,
    /// What patching the JSON found (the image each texture shows).
    patched: Patched,
    /// The file's animations, for [`SceneInfo::animations`] (taken when listed).
    animations: Vec<catalogue::AnimationTimes>,
    scene: Scene,
    info: SceneInfo,
    /// glTF image index → index into `scene.textures` (`None`: it could not be loaded).
    image_textures: HashMap<(usize, ColorSpace), Option<usize>>,
    /// Encoded image bytes → index into `scene.textures`: identical sources decode once.
    encoded_images: HashMap<(Vec<u8>, ColorSpace), usize>,
    /// `KHR_materials_pbrSpecularGlossiness` conversions → their base colour and
    /// metallic-roughness textures in `scene.textures` (`None`: no source could be loaded).
    spec_gloss_textures: HashMap<spec_gloss::ConversionKey, Option<(usize, usize)>>,
    /// (glTF mesh, primitive, morph weights' bits) → index into `scene.meshes` (`None`: not
    /// drawable, skipped).
    primitive_meshes: HashMap<(usize, usize, Vec<u32>), Option<usize>>,
    /// Index of the appended default material, once one was needed.
    default_material: Option<usize>,
    /// Per file material: the texture coordinates its textures read.
    material_uv: Vec<MaterialUvMaps>,
    /// Per file material: which of its maps (`material_uv`) the normal texture reads, where it
    /// bends normals: the meshes that use it get tangents for that map.
    material_normal_map: Vec<Option<usize>>,
    /// The scene's extras carry `ambient`: a reference scene (Lambert by default).
    reference_extras: bool,
    /// The scene's extras give a clear colour.
    clear_color_given: bool,
    /// What posing needs (skins, the chosen animation), when the file has either.
    rig: Option<rig_builder::RigBuilder>,
}

impl Loader<'_> {
    fn invalid(&self, message: impl Into<String>) -> LoadError {
        LoadError::invalid(self.path, message)
    }
}

/// A name for reports: the file's name, or `KIND INDEX`.
fn named(name: Option<&str>, kind: &str, index: usize) -> String {
    match name {
        Some(n) if !n.is_empty() => capped_name(n),
        _ => format!("{kind} {index}"),
    }
}

/// The most characters of a name from the file that the scene keeps ([`capped_name`]).
const MAX_NAME_CHARS: usize = 256;

/// `name` cut to [`MAX_NAME_CHARS`] characters (an ellipsis marks the cut): names are copied
/// per draw, per warning and per sidecar entry, so a file's name must not be a size it chose.
fn capped_name(name: &str) -> String {
    match name.char_indices().nth(MAX_NAME_CHARS) {
        Some((end, _)) => format!("{}…", &name[..end]),
        None => name.to_string(),
    }
}
