//! Scene loading for Kantele: glTF 2.0 (`.gltf`, `.glb`), OBJ/MTL, PLY and STL files into a
//! [`kantele_rules::scene::Scene`], by the rules of the reference scenes, plus built-in demo scenes.
//!
//! The rules (draw order, camera, light, extras, materials) are those of
//! `docs/rendering-rules.md`; the glTF loader follows them exactly, the OBJ, PLY and STL loaders
//! and the built-in scenes fill the same structure with sensible defaults.
//!
//! # Entry points
//!
//! - [`load_scene`] loads a file, choosing the format by extension. Malformed input of any kind
//!   gives a [`LoadError`] that names the file, never a panic. [`load_scene_with`] loads under
//!   [`LoadOptions`]: a memory budget and read policy, which scene and material variant of a
//!   glTF file to draw, shading and a face-culling override.
//! - [`builtin_scenes`] lists the built-in scenes (`cube`, `teapot`, `ground`, `pixel-edges`),
//!   generated in code with no asset files, and [`builtin_scene`] builds one by name
//!   ([`builtin_scene_with`]: with the culling override).
//! - Each call returns a [`LoadedScene`]: the [`Scene`], ready for any
//!   [`Backend`](kantele_rules::backend::Backend), and a [`SceneInfo`] with facts and warnings about
//!   the source.
//! - [`mesh_util`] holds helpers shared by the loaders (flat normals, strips and fans to lists,
//!   a framing camera); [`texture_util`] the procedural textures of the built-in scenes.
//!
//! ```no_run
//! use std::sync::Arc;
//! use kantele::backend::{Backend, FrameView};
//! use kantele::cpu::{CpuBackend, CpuOptions};
//!
//! let loaded = kantele_scene::builtin_scene("cube")?;
//! let scene = Arc::new(loaded.scene);
//! let mut cpu = CpuBackend::new(CpuOptions::default())?;
//! cpu.load(scene.clone())?;
//! cpu.render(&FrameView::of_scene(&scene))?;
//! let image = cpu.read_frame()?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]
#![forbid(unsafe_code)]

use std::path::{Path, PathBuf};

use kantele_rules::scene::{Scene, Shading};
use kantele_rules::shade::pbr::Tonemap;
use kantele_rules::state::CullMode;
use thiserror::Error;

mod accessor;
mod budget;
mod builtin;
mod choices;
mod cull_override;
mod dds_image;
mod draco_stream;
mod draco_views;
mod ear_clip;
mod environment_file;
mod gltf_loader;
mod gltf_patch;
mod ktx2_image;
pub mod mesh_util;
mod meshopt_views;
mod mtl;
mod mtl_libraries;
mod mtl_texels;
mod mtl_texture;
mod obj_loader;
mod obj_material;
mod obj_text;
mod obj_textures;
mod obj_wide;
mod ply_loader;
mod quiet_panic;
mod read_policy;
mod shading;
mod single_mesh;
mod spec_gloss_texels;
mod stl_loader;
mod tangents;
pub mod texture_util;
mod uri;

pub use choices::{AnimationChoice, FileAnimation, FileScene, IndexOrName, SceneChoice};
pub use cull_override::override_culling;
pub use gltf_loader::{AnimationPlayer, PoseError};
pub use mesh_util::flat_normals;

/// Where the last panic that the loaders caught on this thread (one of a dependency's known
/// panics, turned into a [`LoadError`]) was raised: the fuzz targets in `kantele-testkit` tell
/// a dependency's panic from one in Kantele's own code by it (not a public API).
#[doc(hidden)]
pub fn last_caught_panic_file() -> Option<String> {
    quiet_panic::last_caught_file()
}

/// Body of the `ktx2` fuzz target (`fuzz/fuzz_targets/ktx2.rs`): decodes the bytes as a KTX2
/// image under a 64 MiB budget and panics on a defect (a panic in Kantele's own code, a texture
/// of another size than the header's, an error of several lines); not a public API.
#[doc(hidden)]
pub fn fuzz_ktx2(data: &[u8]) {
    ktx2_image::fuzz(data);
}

/// Body of the `dds` fuzz target (`fuzz/fuzz_targets/dds.rs`): decodes the bytes as a DDS
/// image under a 64 MiB budget and panics on a defect (a panic in Kantele's own code, a texture
/// of another size than the header's, an error of several lines); not a public API.
#[doc(hidden)]
pub fn fuzz_dds(data: &[u8]) {
    dds_image::fuzz(data);
}

/// A `.glb` whose one triangle primitive is the given `KHR_draco_mesh_compression` stream (its
/// attribute 0 as POSITION), sized from the stream's header: the `draco` fuzz target in
/// `kantele-testkit` loads it (not a public API).
#[doc(hidden)]
pub fn draco_stream_glb(stream: &[u8]) -> Vec<u8> {
    draco_views::single_stream_glb(stream)
}

/// A loaded scene with what a user checks before rendering it.
#[derive(Clone, Debug)]
pub struct LoadedScene {
    /// The scene, ready for any backend.
    pub scene: Scene,
    /// Facts about the source file.
    pub info: SceneInfo,
    /// The animation chosen with [`LoadOptions::animation`], to pose the scene at other times
    /// without reloading; `None` when none was chosen (always for formats other than glTF).
    pub animation: Option<AnimationPlayer>,
}

/// Facts about a source file, for `kantele info` and the render sidecar.
#[derive(Clone, Debug, Default)]
pub struct SceneInfo {
    /// Where it came from (file path or `builtin:NAME`).
    pub source: String,
    /// Number of nodes in the file.
    pub node_count: usize,
    /// Names of the cameras in the file (empty when a framing camera was made up).
    pub cameras: Vec<String>,
    /// Whether the scene's camera came from the file.
    pub camera_from_file: bool,
    /// Names of the lights in the file.
    pub lights: Vec<String>,
    /// Extensions the file uses.
    pub extensions_used: Vec<String>,
    /// Problems that did not stop loading (unsupported but harmless features, ...), once each.
    /// Features the file uses that are not drawn are listed together in one of them.
    pub warnings: Vec<String>,
    /// Width and height of each texture of the scene, as its image header declares them
    /// (also when textures were not decoded).
    pub texture_sizes: Vec<(u32, u32)>,
    /// Features the file uses that are ignored (extensions, unplayable animation channels,
    /// ...), once each.
    pub ignored: Vec<String>,
    /// The glTF file's scenes in file order, with the default one and the one drawn marked;
    /// empty for other formats and built-in scenes (one scene each).
    pub scenes: Vec<FileScene>,
    /// The glTF file's animations in file order, with their lengths.
    pub animations: Vec<FileAnimation>,
    /// Names of the glTF file's material variants (`KHR_materials_variants`), in file order
    /// (`variant N` for one without a name).
    pub variants: Vec<String>,
    /// Index into [`SceneInfo::variants`] of the variant drawn ([`LoadOptions::variant`]);
    /// `None`: the default materials.
    pub variant_loaded: Option<usize>,
    /// Every file the load read (canonical paths, in reading order): the scene file, its
    /// buffers and images, MTL libraries and their maps. Empty for built-in scenes.
    pub files_read: Vec<PathBuf>,
}

impl SceneInfo {
    /// Records a warning unless the same text was recorded before.
    pub(crate) fn warn(&mut self, message: impl Into<String>) {
        let message = message.into();
        if !self.warnings.contains(&message) {
            self.warnings.push(message);
        }
    }

    /// Records a feature of the file that is ignored (reported in one warning line).
    pub(crate) fn ignore(&mut self, feature: impl Into<String>) {
        let feature = feature.into();
        if !self.ignored.contains(&feature) {
            self.ignored.push(feature);
        }
    }

    /// Adds the one warning line that names every ignored feature.
    pub(crate) fn finish(&mut self) {
        if !self.ignored.is_empty() {
            let line = format!(
                "ignored (not drawn or not applied): {}",
                self.ignored.join(", ")
            );
            self.warn(line);
        }
    }
}

/// Why a scene could not be loaded. Every message names the file.
#[derive(Debug, Error)]
pub enum LoadError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file is not valid glTF / OBJ / PLY / STL, or uses something that cannot be drawn.
    #[error("{path}: {message}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The file extension is not one we read.
    #[error("{path}: unknown scene format (expected .gltf, .glb, .obj, .ply or .stl)")]
    UnknownFormat {
        /// The file.
        path: PathBuf,
    },
    /// No built-in scene has that name.
    #[error("no built-in scene named '{0}' (try: {list})", list = builtin_names().join(", "))]
    UnknownBuiltin(String),
}

impl LoadError {
    /// A [`LoadError::Invalid`] for `path`.
    pub(crate) fn invalid(path: &Path, message: impl Into<String>) -> Self {
        LoadError::Invalid {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }
}

/// A parser's message as one line for a [`LoadError`]: line breaks, tabs and other control
/// characters become spaces, runs of spaces one, and a long message is cut at 200 characters.
pub(crate) fn one_line(message: &str) -> String {
    const MAX_CHARS: usize = 200;
    let mut out = String::new();
    for (count, word) in message
        .split(|c: char| c.is_whitespace() || c.is_control())
        .filter(|w| !w.is_empty())
        .enumerate()
    {
        if count > 0 {
            out.push(' ');
        }
        out.push_str(word);
    }
    if out.chars().count() > MAX_CHARS {
        out = out.chars().take(MAX_CHARS).collect::<String>() + "…";
    }
    out
}

/// Default memory budget of a load: 4 GiB.
pub const DEFAULT_MAX_MEMORY: u64 = 4 << 30;

/// What a load may do: its memory budget, where it may read, and whether problems that can be
/// worked around (a missing texture file) are errors; what to draw of a glTF file (which scene,
/// which material variant); and how the result is shaded and culled.
///
/// A scene or variant choice applies to glTF files only: OBJ, PLY and STL files and built-in
/// scenes have one scene and no variants, and loading one with either choice is an error.
#[derive(Clone, Debug)]
pub struct LoadOptions {
    /// Bytes the load may allocate for what the file controls (vertices, indices, texels,
    /// decoded images and buffers), checked by arithmetic before each allocation; a file that
    /// needs more is refused with an error. Default [`DEFAULT_MAX_MEMORY`].
    pub max_memory: u64,
    /// Folders, besides the scene file's own folder, from which the scene may read files.
    /// Only regular files are ever read (no devices, FIFOs or folders), after resolving `..`
    /// and symbolic links.
    pub allow_read: Vec<PathBuf>,
    /// Turn recoverable problems (a texture file that is missing or cannot be decoded) into
    /// errors instead of warnings.
    pub strict: bool,
    /// Decode textures (default). Without it, each image's header is read and a placeholder of
    /// its size stands in for it: for describing a scene without paying for its pixels.
    pub decode_textures: bool,
    /// The shading model; `None` (default) lets the file decide: glTF reference scenes (whose
    /// `scene.extras` carry `ambient`), OBJ, PLY and STL files and built-in scenes are drawn with
    /// [`Shading::Lambert`], every other glTF file with [`Shading::Pbr`].
    pub shading: Option<Shading>,
    /// Image-based light of PBR scenes.
    pub environment: EnvironmentChoice,
    /// Multiplies the environment's light.
    pub environment_intensity: f32,
    /// Turns the environment about world +Y, in degrees.
    pub environment_rotation_degrees: f32,
    /// Exposure of PBR scenes in stops.
    pub exposure: f32,
    /// Tone map of PBR scenes.
    pub tonemap: Tonemap,
    /// The glTF animation to play (by index or name); `None` (default) draws the rest pose
    /// (the file's node transforms and morph weights, skins applied). An animation the file
    /// lacks is an error that lists those it has. The loaded scene's
    /// [`LoadedScene::animation`] poses it at other times.
    pub animation: Option<AnimationChoice>,
    /// The time of [`LoadOptions::animation`] to pose the scene at, in seconds (default 0);
    /// before the first key the first holds, after the last key the last. Ignored without an
    /// animation; a NaN or infinite time is an error.
    pub time: f32,
    /// Which scene of a glTF file to draw; `None` (default): the file's default scene (its
    /// `scene`, else scene 0). A choice that matches no scene is an error listing the file's
    /// scenes ([`SceneInfo::scenes`] lists them after a load).
    pub scene: Option<SceneChoice>,
    /// The material variant (`KHR_materials_variants`) to draw, by name: a primitive whose
    /// `mappings` name it is drawn with the mapped material instead of its own. `None`
    /// (default): every primitive's own material, as the extension says for no choice. A name
    /// the file does not define is an error listing its variants ([`SceneInfo::variants`]).
    pub variant: Option<String>,
    /// Face culling for every material, overriding the file's ([`override_culling`]):
    /// [`CullMode::None`] draws both faces, [`CullMode::Back`] culls back faces,
    /// [`CullMode::Front`] culls front faces (it reverses every triangle). `None` (default): the
    /// file decides (glTF `doubleSided`; OBJ, PLY and STL files are double-sided).
    pub cull: Option<CullMode>,
}

/// Which environment lights a PBR scene.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum EnvironmentChoice {
    /// The built-in studio when the file has no lights, else none.
    #[default]
    Default,
    /// The built-in neutral studio ([`kantele_rules::shade::environment::EnvironmentLight::studio`]).
    Studio,
    /// No environment: the file's lights, or a headlight when it has none.
    None,
    /// An equirectangular `.hdr` or `.exr` image (read wherever it is: the user named it).
    File(PathBuf),
}

impl Default for LoadOptions {
    fn default() -> Self {
        Self {
            max_memory: DEFAULT_MAX_MEMORY,
            allow_read: Vec::new(),
            strict: false,
            decode_textures: true,
            shading: None,
            environment: EnvironmentChoice::Default,
            environment_intensity: 1.0,
            environment_rotation_degrees: 0.0,
            exposure: 0.0,
            tonemap: Tonemap::PbrNeutral,
            animation: None,
            time: 0.0,
            scene: None,
            variant: None,
            cull: None,
        }
    }
}

/// Loads a scene file with the default [`LoadOptions`], choosing the format by extension
/// (`.gltf`, `.glb`, `.obj`, `.ply`, `.stl`; any case).
///
/// Malformed input of any kind gives an error naming the file; the loader does not panic.
pub fn load_scene(path: &Path) -> Result<LoadedScene, LoadError> {
    load_scene_with(path, &LoadOptions::default())
}

/// Loads a scene file under the given options (memory budget, read policy, strictness, scene,
/// variant, culling).
///
/// Malformed input of any kind gives an error naming the file; the loader does not panic and
/// does not allocate beyond `options.max_memory` for what the file controls.
pub fn load_scene_with(path: &Path, options: &LoadOptions) -> Result<LoadedScene, LoadError> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let loader: fn(&Path, &LoadOptions) -> Result<LoadedScene, LoadError> =
        match extension.as_deref() {
            Some("gltf") | Some("glb") => gltf_loader::load,
            Some("obj") => obj_loader::load,
            Some("ply") => ply_loader::load,
            Some("stl") => stl_loader::load,
            _ => {
                return Err(LoadError::UnknownFormat {
                    path: path.to_path_buf(),
                })
            }
        };
    if !matches!(extension.as_deref(), Some("gltf" | "glb")) {
        refuse_scene_choices(options).map_err(|e| LoadError::invalid(path, e))?;
    }
    // The parsing crates are defensive but not panic-free on every malformed input (unchecked
    // `unreachable!`s, arithmetic on counts); a panic there must become a one-line error, not a
    // crash or a backtrace on stderr.
    let (result, files_read) =
        read_policy::record_reads(|| quiet_panic::catch(|| loader(path, options)));
    match result {
        Ok(Ok(mut loaded)) => {
            if let Some(cull) = options.cull {
                override_culling(&mut loaded.scene, cull);
            }
            loaded.info.files_read = files_read;
            loaded.info.finish();
            Ok(loaded)
        }
        Ok(Err(e)) => Err(e),
        Err(what) => Err(LoadError::invalid(
            path,
            format!("malformed file (the parser failed: {what})"),
        )),
    }
}

/// Where `path` leads, whether or not a file is there yet: its canonical form when it exists,
/// else its longest existing ancestor's canonical form with the rest appended (`.` and `..`
/// resolved by name). The loaders' read policy places paths this way; the command compares its
/// outputs with the inputs by it.
pub fn resolved_path(path: &Path) -> PathBuf {
    read_policy::resolved(path)
}

/// OBJ or MTL text as the OBJ loader reads it: UTF-16 with a byte-order mark, UTF-8 (a
/// byte-order mark dropped), else Latin-1; lines ending in `\` joined with the next. For tools
/// that look into these files as the loader does (the command's guard against overwriting an
/// input).
pub fn obj_text(bytes: &[u8]) -> String {
    obj_text::text(bytes)
}

/// Names and one-line descriptions of the built-in scenes.
pub fn builtin_scenes() -> &'static [(&'static str, &'static str)] {
    builtin::SCENES
}

fn builtin_names() -> Vec<&'static str> {
    builtin_scenes().iter().map(|(n, _)| *n).collect()
}

/// Builds a built-in scene by name.
pub fn builtin_scene(name: &str) -> Result<LoadedScene, LoadError> {
    builtin::build(name).ok_or_else(|| LoadError::UnknownBuiltin(name.to_string()))
}

/// Builds a built-in scene by name with the options that apply to built-in scenes: the
/// culling override ([`LoadOptions::cull`]). A scene or variant choice is an error (a built-in
/// scene has one scene and no variants); the other options are not used.
pub fn builtin_scene_with(name: &str, options: &LoadOptions) -> Result<LoadedScene, LoadError> {
    if !builtin_names().contains(&name) {
        return Err(LoadError::UnknownBuiltin(name.to_string()));
    }
    refuse_scene_choices(options).map_err(|e| LoadError::Invalid {
        path: PathBuf::from(format!("builtin:{name}")),
        message: e,
    })?;
    let mut loaded = builtin_scene(name)?;
    if let Some(cull) = options.cull {
        override_culling(&mut loaded.scene, cull);
    }
    Ok(loaded)
}

/// The error for a scene or variant choice on a source that has one scene and no variants.
fn refuse_scene_choices(options: &LoadOptions) -> Result<(), String> {
    if let Some(choice) = &options.scene {
        return Err(format!(
            "cannot draw scene {}: only glTF files have scenes to choose from (this has one)",
            one_line(&choice.to_string())
        ));
    }
    if let Some(variant) = &options.variant {
        return Err(format!(
            "cannot draw material variant '{}': only glTF files have material variants",
            one_line(variant)
        ));
    }
    if let Some(choice) = &options.animation {
        return Err(format!(
            "cannot pose by animation {}: only glTF files have animations",
            one_line(&choice.to_string())
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parser_messages_become_one_short_line() {
        assert_eq!(
            one_line("Couldn't read element line.\n\tString: '1 2\r\n'\n\tError: x"),
            "Couldn't read element line. String: '1 2 ' Error: x"
        );
        let long = one_line(&"word ".repeat(100));
        assert_eq!(long.chars().count(), 201);
        assert!(long.ends_with('…'));
    }
}
