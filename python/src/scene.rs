//! `kantele.Scene`: a loaded or numpy-built scene, rendered into numpy arrays.

use std::path::PathBuf;
use std::sync::{Arc, Mutex, PoisonError};

use kantele::backend::Backend;
use kantele::cpu::{CpuBackend, CpuOptions};
use kantele::error::RenderError;
use kantele::multisample::SampleCount;
use kantele::rop::TargetFormat;
use kantele::scene::{Scene, Shading};
use kantele::shade::pbr::Tonemap;
use kantele::state::CullMode;
use kantele_scene::{AnimationPlayer, EnvironmentChoice, IndexOrName, LoadOptions};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::arrays::view_dict;
use crate::camera::{self, pose_error, PyCamera};
use crate::errors::{load_error, render_error, value_error};
use crate::mesh_arrays::{scene_from_arrays, MeshArrays};
use crate::render::{render_views, OutputKind, RenderedView};
use kantele_output::pose::CameraPose;

/// A CPU backend with this scene loaded, kept between calls.
struct CachedCpu {
    threads: Option<usize>,
    backend: CpuBackend,
}

/// A scene ready to render: meshes, materials, textures, camera and light.
#[pyclass(name = "Scene", module = "kantele", frozen)]
pub struct PyScene {
    scene: Arc<Scene>,
    source: String,
    warnings: Vec<String>,
    cpu: Mutex<Option<CachedCpu>>,
    /// The animation the scene was loaded with, to pose it at other times (`at_time`).
    animation: Option<AnimationPlayer>,
}

impl PyScene {
    /// Wraps a validated scene.
    pub fn new(scene: Scene, source: String, warnings: Vec<String>) -> PyResult<Self> {
        scene
            .validate()
            .map_err(|e| value_error(format!("{source}: {e}")))?;
        Ok(Self {
            scene: Arc::new(scene),
            source,
            warnings,
            cpu: Mutex::new(None),
            animation: None,
        })
    }

    /// Loads a scene file (glTF, OBJ, PLY or STL) under `options` with the GIL released.
    pub fn load_path(py: Python<'_>, path: PathBuf, options: LoadOptions) -> PyResult<Self> {
        let loaded = py
            .detach(|| kantele_scene::load_scene_with(&path, &options))
            .map_err(load_error)?;
        let mut scene = Self::new(loaded.scene, loaded.info.source, loaded.info.warnings)?;
        scene.animation = loaded.animation;
        Ok(scene)
    }
}

/// A scene or animation named in Python: an `int` index or a `str` name.
#[derive(FromPyObject)]
pub enum NameOrIndex {
    /// By position in the file.
    Index(usize),
    /// By name.
    Name(String),
}

impl From<NameOrIndex> for IndexOrName {
    fn from(choice: NameOrIndex) -> Self {
        match choice {
            NameOrIndex::Index(i) => IndexOrName::Index(i),
            NameOrIndex::Name(n) => IndexOrName::Name(n),
        }
    }
}

/// `options` with `load`'s choice arguments: which scene, material variant and animation pose
/// of the file, and the culling override (see `Scene.load`).
pub fn choice_options(
    options: LoadOptions,
    scene: Option<NameOrIndex>,
    variant: Option<String>,
    animation: Option<NameOrIndex>,
    time: f32,
    cull: Option<&str>,
) -> PyResult<LoadOptions> {
    if !time.is_finite() {
        return Err(value_error("time must be a finite number of seconds"));
    }
    let cull = match cull {
        None => None,
        Some("back") => Some(CullMode::Back),
        Some("front") => Some(CullMode::Front),
        Some("none") => Some(CullMode::None),
        Some(other) => {
            return Err(value_error(format!(
                "unknown cull '{other}' (choose from: back, front, none)"
            )))
        }
    };
    Ok(LoadOptions {
        scene: scene.map(IndexOrName::from),
        variant,
        animation: animation.map(IndexOrName::from),
        time,
        cull,
        ..options
    })
}

/// The load options of `load`'s shading arguments (see `Scene.load`).
pub fn shading_options(
    shading: &str,
    environment: Option<PathBuf>,
    environment_intensity: f32,
    environment_rotation: f32,
    exposure: f32,
    tonemap: &str,
) -> PyResult<LoadOptions> {
    let shading = match shading {
        "auto" => None,
        "lambert" => Some(Shading::Lambert),
        "pbr" => Some(Shading::Pbr),
        _ => {
            return Err(value_error(format!(
                "unknown shading '{shading}' (choose from: auto, lambert, pbr)"
            )))
        }
    };
    let environment = match environment {
        None => EnvironmentChoice::Default,
        Some(p) if p.as_os_str() == "studio" => EnvironmentChoice::Studio,
        Some(p) if p.as_os_str() == "none" => EnvironmentChoice::None,
        Some(p) => EnvironmentChoice::File(p),
    };
    let tonemap = Tonemap::from_name(tonemap).ok_or_else(|| {
        value_error(format!(
            "unknown tonemap '{tonemap}' (choose from: none, pbr-neutral, aces)"
        ))
    })?;
    let finite = |name: &str, v: f32| {
        if v.is_finite() {
            Ok(v)
        } else {
            Err(value_error(format!("{name} must be a finite number")))
        }
    };
    if !(environment_intensity.is_finite() && environment_intensity >= 0.0) {
        return Err(value_error(
            "environment_intensity must be a finite number >= 0",
        ));
    }
    Ok(LoadOptions {
        shading,
        environment,
        environment_intensity,
        environment_rotation_degrees: finite("environment_rotation", environment_rotation)?,
        exposure: finite("exposure", exposure)?,
        tonemap,
        ..LoadOptions::default()
    })
}

/// Which backend renders, parsed from the `backend` argument.
#[derive(Clone, Copy, PartialEq, Eq)]
enum BackendKind {
    Cpu,
    Gl,
}

fn parse_backend(name: &str) -> PyResult<BackendKind> {
    match name {
        "cpu" => Ok(BackendKind::Cpu),
        "gl" => Ok(BackendKind::Gl),
        _ => Err(value_error(format!(
            "unknown backend '{name}' (choose from: cpu, gl)"
        ))),
    }
}

fn parse_outputs(outputs: &Bound<'_, PyAny>) -> PyResult<Vec<OutputKind>> {
    if outputs.is_instance_of::<pyo3::types::PyString>() {
        return Err(value_error(
            "outputs must be a sequence of names, e.g. (\"color\",), not a string",
        ));
    }
    let mut kinds = Vec::new();
    for item in outputs.try_iter()? {
        let name: String = item?.extract()?;
        let kind = OutputKind::parse(&name).map_err(value_error)?;
        if !kinds.contains(&kind) {
            kinds.push(kind);
        }
    }
    if kinds.is_empty() {
        return Err(value_error("outputs is empty: ask for at least one output"));
    }
    Ok(kinds)
}

fn parse_size(size: Option<(i64, i64)>, default: (u32, u32), source: &str) -> PyResult<(u32, u32)> {
    let max = kantele::MAX_TARGET_SIZE as i64;
    let (w, h) = match size {
        Some(s) => s,
        None => (default.0 as i64, default.1 as i64),
    };
    if !(1..=max).contains(&w) || !(1..=max).contains(&h) {
        let whose = if size.is_some() {
            "size".to_string()
        } else {
            format!("{source}: the scene's resolution")
        };
        return Err(value_error(format!(
            "{whose} {w}x{h} is outside 1..={max} on a side"
        )));
    }
    Ok((w as u32, h as u32))
}

/// Samples per pixel of colour frames: 1, 4 or 8 (what `--msaa` accepts).
fn parse_msaa(msaa: i64) -> PyResult<SampleCount> {
    u32::try_from(msaa)
        .map_err(|_| format!("unsupported sample count {msaa} (expected 1, 4 or 8)"))
        .and_then(SampleCount::from_count)
        .map_err(|e| value_error(format!("msaa: {e}")))
}

/// The colour target: `"f32"` or `"srgb8"`, the latter for the CPU backend only.
fn parse_target(target: &str, backend: BackendKind) -> PyResult<TargetFormat> {
    let format: TargetFormat = target
        .parse()
        .map_err(|e: String| value_error(format!("target: {e}")))?;
    if format != TargetFormat::LinearF32 && backend != BackendKind::Cpu {
        return Err(value_error(format!(
            "target='{target}' is a CPU backend option (the GL backend renders into f32)"
        )));
    }
    Ok(format)
}

fn parse_threads(threads: Option<i64>) -> PyResult<Option<usize>> {
    match threads {
        None => Ok(None),
        Some(t) if (1..=1024).contains(&t) => Ok(Some(t as usize)),
        Some(t) => Err(value_error(format!("threads {t} is outside 1..=1024"))),
    }
}

/// How `render` and `render_many` render, parsed once from their keyword arguments.
struct RenderSettings {
    outputs: Vec<OutputKind>,
    backend: BackendKind,
    threads: Option<usize>,
    samples: SampleCount,
    target: TargetFormat,
}

impl RenderSettings {
    /// The settings from the Python arguments (`outputs=None`: every output), checked in the
    /// order they are declared.
    fn parse(
        outputs: Option<&Bound<'_, PyAny>>,
        backend: &str,
        threads: Option<i64>,
        msaa: i64,
        target: &str,
    ) -> PyResult<Self> {
        let outputs = match outputs {
            Some(o) => parse_outputs(o)?,
            None => vec![
                OutputKind::Color,
                OutputKind::Depth,
                OutputKind::Normals,
                OutputKind::Ids,
            ],
        };
        let backend = parse_backend(backend)?;
        Ok(Self {
            outputs,
            backend,
            threads: parse_threads(threads)?,
            samples: parse_msaa(msaa)?,
            target: parse_target(target, backend)?,
        })
    }
}

impl PyScene {
    /// Renders the scene through `views` with the GIL released.
    fn render_frames(
        &self,
        py: Python<'_>,
        views: Vec<CameraPose>,
        settings: &RenderSettings,
    ) -> PyResult<Vec<RenderedView>> {
        let RenderSettings {
            ref outputs,
            backend,
            threads,
            samples,
            target,
        } = *settings;
        let scene = &self.scene;
        let cpu = &self.cpu;
        let result = py.detach(|| -> Result<Vec<RenderedView>, RenderError> {
            match backend {
                BackendKind::Cpu => {
                    // Concurrent renders of one scene take turns on its backend.
                    let mut cached = cpu.lock().unwrap_or_else(PoisonError::into_inner);
                    if cached.as_ref().is_none_or(|c| c.threads != threads) {
                        *cached = None;
                        let mut backend = CpuBackend::new(CpuOptions {
                            threads,
                            ..CpuOptions::default()
                        })?;
                        backend.load(scene.clone())?;
                        *cached = Some(CachedCpu { threads, backend });
                    }
                    let cached = cached.as_mut().expect("a backend was made above");
                    cached.backend.set_samples(samples)?;
                    cached.backend.set_target(target);
                    render_views(&mut cached.backend, scene, &views, outputs)
                }
                BackendKind::Gl => {
                    // The GL backend lives and dies on this thread (it is !Send).
                    let mut gl = kantele_gl::GlBackend::new()?;
                    gl.set_samples(samples)?;
                    gl.load(scene.clone())?;
                    render_views(&mut gl, scene, &views, outputs)
                }
            }
        });
        result.map_err(|e| render_error(prefix(&self.source, e)))
    }

    /// The scene's own camera, not tied to a size.
    fn scene_camera(&self) -> PyResult<PyCamera> {
        let (w, h) = parse_size(None, self.scene.resolution, &self.source)?;
        let pose = CameraPose::from_scene_camera(&self.scene.camera, w, h)
            .map_err(|e| value_error(format!("{}: camera: {e}", self.source)))?;
        Ok(PyCamera::new(pose, false))
    }

    /// The pose of each camera (`None`: the scene's) at its image size: `size`, else the
    /// camera's own size, else the scene's resolution.
    fn views(
        &self,
        cameras: &[Option<PyCamera>],
        size: Option<(i64, i64)>,
    ) -> PyResult<Vec<CameraPose>> {
        let explicit = match size {
            Some(_) => Some(parse_size(size, (0, 0), &self.source)?),
            None => None,
        };
        let mut poses = Vec::with_capacity(cameras.len());
        let mut scene_camera = None;
        for c in cameras {
            let camera = match c {
                Some(c) => c,
                None => scene_camera.get_or_insert(self.scene_camera()?),
            };
            let (w, h) = match (explicit, camera.size()) {
                (Some(s), _) | (None, Some(s)) => s,
                (None, None) => parse_size(None, self.scene.resolution, &self.source)?,
            };
            poses.push(camera.pose_at(w, h).map_err(pose_error)?);
        }
        Ok(poses)
    }
}

/// The error with the scene's source in front, as the CLI names the file.
fn prefix(source: &str, error: RenderError) -> RenderError {
    match error {
        RenderError::InvalidScene(m) => RenderError::InvalidScene(format!("{source}: {m}")),
        other => other,
    }
}

#[pymethods]
impl PyScene {
    /// Loads a glTF 2.0 (`.gltf`, `.glb`), OBJ, PLY or STL file. Raises `OSError` when the file
    /// cannot be read and `ValueError` when it is malformed. `shading`: `auto` (glTF reference
    /// scenes and OBJ, PLY and STL files Lambert, other glTF files PBR), `lambert` or `pbr`;
    /// for PBR, `environment` (`studio`, `none` or an .hdr / .exr file; default: the studio
    /// when the file has no lights), `environment_intensity`, `environment_rotation` (degrees
    /// about +Y), `exposure` (stops) and `tonemap` (`none`, `pbr-neutral`, `aces`), as the
    /// `kantele` command's options of the same names.
    ///
    /// Of a glTF file, `scene` (index or name) picks the scene to draw, `variant` a material
    /// variant (`KHR_materials_variants`), and `animation` (index or name) with `time`
    /// (seconds) the pose; `cull` (`back`, `front` or `none`) overrides every material's face
    /// culling. `at_time` poses a scene loaded with an animation at other times.
    #[staticmethod]
    #[pyo3(signature = (path, shading = "auto", environment = None, environment_intensity = 1.0, environment_rotation = 0.0, exposure = 0.0, tonemap = "pbr-neutral", *, scene = None, variant = None, animation = None, time = 0.0, cull = None))]
    #[allow(clippy::too_many_arguments)]
    fn load(
        py: Python<'_>,
        path: PathBuf,
        shading: &str,
        environment: Option<PathBuf>,
        environment_intensity: f32,
        environment_rotation: f32,
        exposure: f32,
        tonemap: &str,
        scene: Option<NameOrIndex>,
        variant: Option<String>,
        animation: Option<NameOrIndex>,
        time: f32,
        cull: Option<&str>,
    ) -> PyResult<Self> {
        let options = shading_options(
            shading,
            environment,
            environment_intensity,
            environment_rotation,
            exposure,
            tonemap,
        )?;
        let options = choice_options(options, scene, variant, animation, time, cull)?;
        Self::load_path(py, path, options)
    }

    /// This scene posed at `time` seconds of the animation it was loaded with (`load`'s
    /// `animation`): a new `Scene`, as loading at that time would give, without reading the
    /// file again. Raises `ValueError` for a scene loaded without an animation.
    fn at_time(&self, py: Python<'_>, time: f32) -> PyResult<Self> {
        let Some(player) = &self.animation else {
            return Err(value_error(format!(
                "{}: loaded without an animation (pass animation= to load)",
                self.source
            )));
        };
        let mut scene = Scene::clone(&self.scene);
        py.detach(|| player.pose(&mut scene, time))
            .map_err(|e| value_error(format!("{}: {e}", self.source)))?;
        let mut posed = Self::new(scene, self.source.clone(), self.warnings.clone())?;
        posed.animation = Some(player.clone());
        Ok(posed)
    }

    /// The animation this scene was loaded with, as `(index, name, (first, last))` (the key
    /// times its channels span, seconds), or `None`.
    #[getter]
    fn animation(&self) -> Option<(usize, String, (f32, f32))> {
        self.animation
            .as_ref()
            .map(|p| (p.index(), p.name().to_string(), p.time_range()))
    }

    /// A scene of one mesh from numpy arrays: `vertices` (N, 3) floats, `faces` (M, 3)
    /// integers (counter-clockwise = front), optional `normals` (N, 3) (flat shading without),
    /// `colors` (N, 3 or 4: `uint8` sRGB or float linear), `uvs` (N, 2), (0, 0) = the
    /// texture's top-left corner, and `texture` (H, W, 3 or 4: `uint8` sRGB or float linear).
    /// The camera frames the mesh, as for files without one; `resolution` is 800×600.
    #[staticmethod]
    #[pyo3(signature = (vertices, faces, normals = None, colors = None, uvs = None, texture = None, double_sided = false))]
    #[allow(clippy::too_many_arguments)]
    fn from_arrays<'py>(
        vertices: Bound<'py, PyAny>,
        faces: Bound<'py, PyAny>,
        normals: Option<Bound<'py, PyAny>>,
        colors: Option<Bound<'py, PyAny>>,
        uvs: Option<Bound<'py, PyAny>>,
        texture: Option<Bound<'py, PyAny>>,
        double_sided: bool,
    ) -> PyResult<Self> {
        let arrays = MeshArrays {
            vertices,
            faces,
            normals,
            colors,
            uvs,
            texture,
        };
        let scene = scene_from_arrays(&arrays, double_sided)?;
        Self::new(scene, "arrays".into(), Vec::new())
    }

    /// A built-in scene by name: `cube`, `teapot`, `ground` or `pixel-edges`.
    #[staticmethod]
    fn builtin(name: &str) -> PyResult<Self> {
        let loaded = kantele_scene::builtin_scene(name).map_err(load_error)?;
        Self::new(loaded.scene, loaded.info.source, loaded.info.warnings)
    }

    /// Where the scene came from (a path, `builtin:NAME` or `arrays`).
    #[getter]
    fn source(&self) -> &str {
        &self.source
    }

    /// Problems the loader noticed that did not stop loading.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    /// Triangles drawn per frame.
    #[getter]
    fn triangle_count(&self) -> usize {
        self.scene.triangle_count()
    }

    /// The image size `(width, height)` the scene asks for (used when `size` is `None`).
    #[getter]
    fn resolution(&self) -> (u32, u32) {
        self.scene.resolution
    }

    /// The scene's own camera: the file's, or one framing everything drawn (not tied to an
    /// image size: it renders at the `size` asked for, else the scene's resolution).
    #[getter]
    fn camera(&self) -> PyResult<PyCamera> {
        self.scene_camera()
    }

    /// `views` cameras circling the scene at `elevation` degrees above its centre, each
    /// framing all of it for images of `size` (default: the scene's resolution) with a vertical
    /// field of view of `yfov_deg`: the cameras of `kantele render --orbit VIEWS` (whose
    /// defaults these are; written as literals so that `help()` shows them).
    #[pyo3(signature = (views, size = None, elevation = 20.0, yfov_deg = 45.0))]
    fn orbit_cameras(
        &self,
        views: u32,
        size: Option<(i64, i64)>,
        elevation: f32,
        yfov_deg: f32,
    ) -> PyResult<Vec<PyCamera>> {
        let (w, h) = parse_size(size, self.scene.resolution, &self.source)?;
        let poses = camera::orbit(&self.scene, views, w, h, elevation, yfov_deg)
            .map_err(|e| value_error(format!("{}: {}", self.source, e.0)))?;
        Ok(poses.into_iter().map(|p| PyCamera::new(p, true)).collect())
    }

    /// A camera framing everything the scene draws, seen from `direction` (a vector from the
    /// scene towards the camera), for images of `size` (default: the scene's resolution).
    #[pyo3(
        signature = (direction = [0.4, 0.5, 1.0], size = None, yfov_deg = 45.0),
        text_signature = "($self, direction=(0.4, 0.5, 1.0), size=None, yfov_deg=45.0)"
    )]
    fn framing_camera(
        &self,
        direction: [f32; 3],
        size: Option<(i64, i64)>,
        yfov_deg: f32,
    ) -> PyResult<PyCamera> {
        let (w, h) = parse_size(size, self.scene.resolution, &self.source)?;
        let pose = camera::framing(&self.scene, direction.into(), w, h, yfov_deg)
            .map_err(|e| value_error(format!("{}: {}", self.source, e.0)))?;
        Ok(PyCamera::new(pose, true))
    }

    /// World-space bounding sphere `((x, y, z), radius)` of everything drawn, or `None`.
    #[getter]
    fn bounding_sphere(&self) -> Option<((f32, f32, f32), f32)> {
        self.scene
            .bounding_sphere()
            .map(|(c, r)| ((c.x, c.y, c.z), r))
    }

    /// One dict per primitive (a glTF mesh primitive placed by a node: one draw), indexed by
    /// primitive id − 1: `id`, `node_index`, `node_name`, `mesh_index`, `mesh_name` (the
    /// meaning of the `ids` output's primitive channel).
    #[getter]
    fn primitives<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let list = PyList::empty(py);
        for (i, d) in self.scene.draws.iter().enumerate() {
            let dict = PyDict::new(py);
            dict.set_item("id", i + 1)?;
            dict.set_item("node_index", d.node_index)?;
            dict.set_item("node_name", &d.node_name)?;
            dict.set_item("mesh_index", d.mesh)?;
            let mesh_name = self
                .scene
                .meshes
                .get(d.mesh)
                .map_or("", |m| m.name.as_str());
            dict.set_item("mesh_name", mesh_name)?;
            list.append(dict)?;
        }
        Ok(list)
    }

    /// The old name of [`primitives`](Self::primitives), kept for a while: warns with a
    /// `DeprecationWarning`.
    #[getter]
    fn draws<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let category = py.get_type::<pyo3::exceptions::PyDeprecationWarning>();
        PyErr::warn(
            py,
            category.as_any(),
            c"Scene.draws is renamed Scene.primitives (glTF: a mesh primitive placed by a node)",
            1,
        )?;
        self.primitives(py)
    }

    /// Renders one view and returns a dict of numpy arrays, one per name in `outputs`:
    ///
    /// - `color`: `uint8` (H, W, 4), sRGB-encoded RGB and alpha, row 0 at the top (the CLI's PNG);
    /// - `color_linear`: `float32` (H, W, 4) linear RGBA;
    /// - `depth`: `float32` (H, W), distance along the camera's view axis (OpenCV z), `inf` where
    ///   nothing was drawn;
    /// - `normals`: `float32` (H, W, 3) world-space unit normals, 0 where nothing was drawn;
    /// - `ids`: `uint32` (H, W, 3): instance (node index + 1), triangle (index in its primitive
    ///   + 1) and primitive (index into `Scene.primitives` + 1) ids, 0 = background; the
    ///   channel names are `kantele.ID_CHANNELS`.
    ///
    /// `camera=None` uses the scene's camera, `size=None` the scene's resolution. `msaa` is the
    /// samples per pixel of the colour outputs (1, 4 or 8, as `kantele render --msaa`; the GL
    /// backend offers what its driver does, llvmpipe 4): edges are antialiased, while depth,
    /// normals and ids stay per pixel, equal to a 1× render's. `target` is the CPU backend's
    /// colour target, `"f32"` or `"srgb8"` (as `kantele render --target`: 8-bit sRGB tiles, a
    /// quarter of the colour memory, the same 8-bit colour). The GIL is released while
    /// rendering.
    #[pyo3(signature = (camera = None, size = None, outputs = None, backend = "cpu", threads = None, msaa = 1, target = "f32"))]
    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        camera: Option<PyCamera>,
        size: Option<(i64, i64)>,
        outputs: Option<Bound<'py, PyAny>>,
        backend: &str,
        threads: Option<i64>,
        msaa: i64,
        target: &str,
    ) -> PyResult<Bound<'py, PyDict>> {
        let settings = RenderSettings::parse(outputs.as_ref(), backend, threads, msaa, target)?;
        let views = self.views(&[camera], size)?;
        let mut all = self.render_frames(py, views, &settings)?;
        view_dict(py, all.remove(0))
    }

    /// Renders every camera of `cameras` (a `None` entry is the scene's camera) and returns a
    /// list of dicts as [`render`] does. The scene is prepared once; the GIL is released for
    /// the whole batch.
    #[pyo3(signature = (cameras, size = None, outputs = None, backend = "cpu", threads = None, msaa = 1, target = "f32"))]
    #[allow(clippy::too_many_arguments)]
    fn render_many<'py>(
        &self,
        py: Python<'py>,
        cameras: Vec<Option<PyCamera>>,
        size: Option<(i64, i64)>,
        outputs: Option<Bound<'py, PyAny>>,
        backend: &str,
        threads: Option<i64>,
        msaa: i64,
        target: &str,
    ) -> PyResult<Bound<'py, PyList>> {
        let settings = RenderSettings::parse(outputs.as_ref(), backend, threads, msaa, target)?;
        let views = self.views(&cameras, size)?;
        let all = self.render_frames(py, views, &settings)?;
        let list = PyList::empty(py);
        for view in all {
            list.append(view_dict(py, view)?)?;
        }
        Ok(list)
    }

    fn __repr__(&self) -> String {
        format!(
            "Scene(source={:?}, triangles={}, draws={}, resolution={}x{})",
            self.source,
            self.scene.triangle_count(),
            self.scene.draws.len(),
            self.scene.resolution.0,
            self.scene.resolution.1
        )
    }
}
