//! Scene loading for Kantele: glTF 2.0 (`.gltf`, `.glb`) and OBJ/MTL files into a
//! [`kantele::scene::Scene`], by the rules of the reference scenes, plus built-in demo scenes.
#![warn(missing_docs)]

use std::path::{Path, PathBuf};

use kantele::scene::Scene;
use thiserror::Error;

/// A loaded scene with what a user checks before rendering it.
#[derive(Clone, Debug)]
pub struct LoadedScene {
    /// The scene, ready for any backend.
    pub scene: Scene,
    /// Facts about the source file.
    pub info: SceneInfo,
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
    pub warnings: Vec<String>,
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
    /// The file is not valid glTF / OBJ, or uses something that cannot be drawn.
    #[error("{path}: {message}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The file extension is not one we read.
    #[error("{path}: unknown scene format (expected .gltf, .glb or .obj)")]
    UnknownFormat {
        /// The file.
        path: PathBuf,
    },
    /// No built-in scene has that name.
    #[error("no built-in scene named '{0}' (try: {list})", list = builtin_names().join(", "))]
    UnknownBuiltin(String),
}

/// Loads a scene file, choosing the format by extension (`.gltf`, `.glb`, `.obj`).
pub fn load_scene(path: &Path) -> Result<LoadedScene, LoadError> {
    Err(LoadError::UnknownFormat {
        path: path.to_path_buf(),
    })
}

/// Names and one-line descriptions of the built-in scenes.
pub fn builtin_scenes() -> &'static [(&'static str, &'static str)] {
    &[]
}

fn builtin_names() -> Vec<&'static str> {
    builtin_scenes().iter().map(|(n, _)| *n).collect()
}

/// Builds a built-in scene by name.
pub fn builtin_scene(name: &str) -> Result<LoadedScene, LoadError> {
    Err(LoadError::UnknownBuiltin(name.to_string()))
}
