//! Scene inputs (files and built-ins), loading with file-naming errors, warnings printed once.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Result};
use kantele::scene::Shading;
use kantele::shade::pbr::Tonemap;
use kantele::state::CullMode;
use kantele_scene::{EnvironmentChoice, LoadError, LoadOptions, LoadedScene};

use crate::cli::{CullArg, LoadArgs, SceneArgs, ShadingArg, TonemapArg};

/// One scene to load.
#[derive(Clone, Debug)]
pub enum Input {
    /// A scene file, with the options it is loaded under.
    File(PathBuf, LoadOptions),
    /// A built-in scene by name, with the options it is loaded under (its culling; a scene,
    /// variant or animation choice is refused).
    Builtin(String, LoadOptions),
}

impl Input {
    /// What names outputs: the file stem or the built-in's name.
    pub fn stem(&self) -> String {
        match self {
            Input::File(p, _) => p
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "scene".into()),
            Input::Builtin(n, _) => n.clone(),
        }
    }

    /// How errors name it.
    pub fn label(&self) -> String {
        match self {
            Input::File(p, _) => p.display().to_string(),
            Input::Builtin(n, _) => format!("builtin:{n}"),
        }
    }

    /// The same input with textures left undecoded (their sizes come from the image headers):
    /// for describing a scene.
    pub fn without_texture_decoding(&self) -> Input {
        match self {
            Input::File(p, options) => Input::File(
                p.clone(),
                LoadOptions {
                    decode_textures: false,
                    ..options.clone()
                },
            ),
            other => other.clone(),
        }
    }

    /// Loads the scene; errors name the file.
    pub fn load(&self) -> Result<LoadedScene> {
        let loaded = match self {
            Input::File(p, options) => {
                kantele_scene::load_scene_with(p, options).map_err(|e| anyhow!("{e}"))?
            }
            Input::Builtin(n, options) => {
                kantele_scene::builtin_scene_with(n, options).map_err(|e| match e {
                    // Only this error leaves the scene unnamed.
                    LoadError::UnknownBuiltin(_) => anyhow!("{}: {e}", self.label()),
                    other => anyhow!("{other}"),
                })?
            }
        };
        loaded
            .scene
            .validate()
            .map_err(|e| anyhow!("{}: {e}", self.label()))?;
        Ok(loaded)
    }
}

/// A scene or animation named on the command line: digits are an index, anything else a name.
fn parse_choice<T: std::str::FromStr<Err = std::convert::Infallible>>(text: &str) -> T {
    match text.parse() {
        Ok(choice) => choice,
        Err(never) => match never {},
    }
}

/// Extensions of scene files found in folders and by patterns.
pub const SCENE_EXTENSIONS: &[&str] = &["gltf", "glb", "obj", "ply", "stl"];

fn is_scene_file(path: &Path) -> bool {
    path.is_file() && SCENE_EXTENSIONS.contains(&crate::output::extension(path).as_str())
}

/// The scene files of a folder (not its subfolders), sorted by name.
fn folder_scenes(dir: &Path) -> Result<Vec<PathBuf>> {
    let entries = std::fs::read_dir(dir)
        .map_err(|e| anyhow!("{}: cannot list the folder: {e}", dir.display()))?;
    let mut found: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| is_scene_file(p))
        .collect();
    found.sort();
    if found.is_empty() {
        bail!(
            "{}: the folder holds no scene files (.gltf, .glb, .obj, .ply, .stl)",
            dir.display()
        );
    }
    Ok(found)
}

/// The scene files matching a glob pattern, sorted.
fn pattern_scenes(pattern: &str) -> Result<Vec<PathBuf>> {
    let paths = glob::glob(pattern).map_err(|e| anyhow!("{pattern}: not a valid pattern: {e}"))?;
    let mut found: Vec<PathBuf> = paths
        .filter_map(|p| p.ok())
        .filter(|p| is_scene_file(p))
        .collect();
    found.sort();
    if found.is_empty() {
        bail!("{pattern}: no scene file (.gltf, .glb, .obj, .ply, .stl) matches");
    }
    Ok(found)
}

/// The loader's options from the command's load flags.
fn load_options(args: &LoadArgs) -> Result<LoadOptions> {
    Ok(LoadOptions {
        max_memory: args.max_memory.unwrap_or(kantele_scene::DEFAULT_MAX_MEMORY),
        allow_read: args.allow_read.clone(),
        strict: args.strict,
        shading: match args.shading {
            ShadingArg::Auto => None,
            ShadingArg::Lambert => Some(Shading::Lambert),
            ShadingArg::Pbr => Some(Shading::Pbr),
        },
        environment: match args.environment.as_deref() {
            None => EnvironmentChoice::Default,
            Some("studio") => EnvironmentChoice::Studio,
            Some("none") => EnvironmentChoice::None,
            Some(file) => {
                let path = PathBuf::from(file);
                if !path.is_file() {
                    bail!("--environment {file}: no such file (or use studio, none)");
                }
                EnvironmentChoice::File(path)
            }
        },
        environment_intensity: args.environment_intensity,
        environment_rotation_degrees: args.environment_rotation,
        exposure: args.exposure,
        tonemap: match args.tonemap {
            TonemapArg::None => Tonemap::None,
            TonemapArg::PbrNeutral => Tonemap::PbrNeutral,
            TonemapArg::Aces => Tonemap::Aces,
        },
        scene: args.choice.scene.as_deref().map(parse_choice),
        variant: args.choice.variant.clone(),
        animation: args.choice.animation.as_deref().map(parse_choice),
        time: args.choice.time.unwrap_or(0.0),
        cull: args.choice.cull.map(|c| match c {
            CullArg::Back => CullMode::Back,
            CullArg::Front => CullMode::Front,
            CullArg::None => CullMode::None,
        }),
        ..LoadOptions::default()
    })
}

/// The inputs of a command, files first: a folder stands for the scene files in it and a
/// pattern (`*`, `?`, `[...]`) for the scene files it matches. Checks that files exist and
/// built-ins are known before anything is rendered.
pub fn inputs(args: &SceneArgs) -> Result<Vec<Input>> {
    let mut out = Vec::new();
    let options = load_options(&args.load)?;
    let file = |p: PathBuf| Input::File(p, options.clone());
    for p in &args.scenes {
        match std::fs::metadata(p) {
            Ok(m) if m.is_file() => out.push(file(p.clone())),
            Ok(m) if m.is_dir() => out.extend(folder_scenes(p)?.into_iter().map(file)),
            Ok(_) => bail!("{}: not a file", p.display()),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                let text = p.to_string_lossy();
                if text.contains(['*', '?', '[']) {
                    out.extend(pattern_scenes(&text)?.into_iter().map(file));
                } else {
                    bail!("{}: no such file", p.display())
                }
            }
            Err(e) => bail!("{}: {e}", p.display()),
        }
    }
    let known = kantele_scene::builtin_scenes();
    for n in &args.builtins {
        if !known.iter().any(|(name, _)| name == n) {
            let names: Vec<&str> = known.iter().map(|(n, _)| *n).collect();
            bail!(
                "builtin:{n}: no built-in scene named '{n}' (available: {})",
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            );
        }
        out.push(Input::Builtin(n.clone(), options.clone()));
    }
    if out.is_empty() {
        bail!("no scene given: name a scene file or use --builtin NAME");
    }
    Ok(out)
}

/// Prints each loader warning once per run as `kantele: warning: ...`.
#[derive(Default)]
pub struct Warnings {
    seen: HashSet<String>,
}

impl Warnings {
    /// Prints the warnings not printed yet (through `print`, so a progress bar can step aside).
    pub fn report(&mut self, loaded: &LoadedScene, mut print: impl FnMut(&str)) {
        for w in &loaded.info.warnings {
            if self.seen.insert(w.clone()) {
                print(&format!("kantele: warning: {}: {}", loaded.info.source, w));
            }
        }
    }
}
