//! Command-line arguments (clap derive).

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};
use kantele::multisample::SampleCount;
use kantele::raster::Strategy;
use kantele::rop::TargetFormat;

/// Kantele: a software rasterizer. Render, inspect, benchmark, compare and view glTF 2.0, OBJ,
/// PLY and STL scenes by Kantele's rendering rules (`docs/rendering-rules.md`).
///
/// Errors are reported as one line `kantele: error: <file>: <problem>` on stderr with exit
/// status 2 (`compare` exits with 1 when a tolerance is broken).
#[derive(Debug, Parser)]
#[command(
    name = "kantele",
    version = concat!(env!("CARGO_PKG_VERSION"), " (", env!("KANTELE_BUILD"), ")"),
    about,
    long_about
)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Render scenes to PNG, with optional depth, normal and id images and a JSON sidecar.
    Render(RenderArgs),
    /// Describe a scene: nodes, draws, meshes, materials, textures, cameras, lights, warnings.
    Info(InfoArgs),
    /// Time frames of scenes on one or more backends (median of N frames after warm-up).
    Bench(BenchArgs),
    /// Render scenes with several backends and measure how far their pictures differ.
    Compare(CompareArgs),
    /// Open a window and look at a scene with an orbit camera (CPU backend).
    View(ViewArgs),
    /// Write a square PNG thumbnail of a scene: framed, transparent background.
    Thumbnail(ThumbnailArgs),
}

/// `kantele thumbnail IN OUT --size N`.
#[derive(Debug, Args)]
pub struct ThumbnailArgs {
    /// The scene file.
    #[arg(value_name = "IN")]
    pub input: PathBuf,
    /// The PNG to write.
    #[arg(value_name = "OUT")]
    pub output: PathBuf,
    /// Width and height in pixels.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub size: u32,
    /// How the file is read, shaded and posed.
    #[command(flatten)]
    pub load: LoadArgs,
    /// CPU backend options (a thumbnail is multisampled 4× unless --msaa says otherwise).
    #[command(flatten)]
    pub cpu: CpuArgs,
    /// The camera (default: `auto`, the model framed by its silhouette) and the background
    /// (default: transparent). A thumbnail is one picture: `--orbit` and `--views` belong to
    /// `render`.
    #[command(flatten)]
    pub camera: CameraArgs,
}

/// Which scenes to work on: files and built-in scenes.
#[derive(Debug, Args, Clone)]
pub struct SceneArgs {
    /// Scene files (.gltf, .glb, .obj, .ply, .stl), folders of them, or quoted patterns
    /// ("scans/*.glb").
    #[arg(value_name = "SCENE")]
    pub scenes: Vec<PathBuf>,
    /// A built-in scene (cube, teapot, ground, pixel-edges, pbr-spheres, pbr-lights, pbr-glass, pbr-sheen); may be repeated. Built-ins come after the files.
    #[arg(long = "builtin", value_name = "NAME")]
    pub builtins: Vec<String>,
    /// How the files are read, shaded and posed.
    #[command(flatten)]
    pub load: LoadArgs,
}

/// How scene files are read (budgets, read policy), shaded and posed: shared by every command.
#[derive(Debug, Args, Clone)]
pub struct LoadArgs {
    /// Fail on problems that are otherwise warnings (a texture file missing or undecodable).
    #[arg(long)]
    pub strict: bool,
    /// Memory a scene load may use for what the file controls (vertices, indices, texels,
    /// decoded data), e.g. 512M, 4G (default 4G); larger files are refused before allocating.
    #[arg(long, value_name = "BYTES", value_parser = parse_bytes)]
    pub max_memory: Option<u64>,
    /// Also let scenes read files under DIR (by default only the scene's own folder); may be
    /// repeated.
    #[arg(long = "allow-read", value_name = "DIR")]
    pub allow_read: Vec<PathBuf>,
    /// Shading model of scene files: `auto` lets the file decide (glTF reference scenes, whose
    /// extras carry `ambient`, and OBJ, PLY and STL files are drawn with `lambert`; every other
    /// glTF file with `pbr`, glTF's metallic-roughness model). Built-in scenes keep their own.
    #[arg(long, value_enum, default_value_t = ShadingArg::Auto)]
    pub shading: ShadingArg,
    /// Image-based light of PBR scenes: `studio` (built-in), `none`, or an equirectangular
    /// .hdr or .exr image. Default: the studio when the file has no lights, else none.
    #[arg(long, value_name = "FILE|studio|none")]
    pub environment: Option<String>,
    /// Multiplies the environment's light.
    #[arg(long, value_name = "SCALE", default_value_t = 1.0, value_parser = parse_non_negative)]
    pub environment_intensity: f32,
    /// Turns the environment about the up axis (+Y), in degrees.
    #[arg(long, value_name = "DEG", default_value_t = 0.0, allow_hyphen_values = true, value_parser = parse_finite)]
    pub environment_rotation: f32,
    /// Exposure of PBR scenes in stops (colour × 2^EV before the tone map).
    #[arg(long, value_name = "EV", default_value_t = 0.0, allow_hyphen_values = true, value_parser = parse_finite)]
    pub exposure: f32,
    /// Tone map of PBR scenes.
    #[arg(long, value_enum, default_value_t = TonemapArg::PbrNeutral)]
    pub tonemap: TonemapArg,
    /// What to draw of each file: scene, material variant, animation pose, culling.
    #[command(flatten)]
    pub choice: ChoiceArgs,
}

/// What to draw of a file: which glTF scene, material variant and animation pose, and how
/// faces are culled.
#[derive(Debug, Args, Clone, Default)]
pub struct ChoiceArgs {
    /// The glTF scene to draw, by index or name (default: the file's default scene; `kantele
    /// info` lists them).
    #[arg(long, value_name = "NAME|INDEX")]
    pub scene: Option<String>,
    /// The material variant to draw (KHR_materials_variants), by name (default: the file's own
    /// materials; `kantele info` lists them).
    #[arg(long, value_name = "NAME")]
    pub variant: Option<String>,
    /// The glTF animation to pose the scene by, by index or name (default: the rest pose, skins
    /// applied; `kantele info` lists the animations with their lengths).
    #[arg(long, value_name = "NAME|INDEX")]
    pub animation: Option<String>,
    /// The time of --animation to pose at, seconds (default 0; before the first key the
    /// first holds, after the last key the last).
    #[arg(long, value_name = "SECONDS", requires = "animation", allow_hyphen_values = true, value_parser = parse_finite)]
    pub time: Option<f32>,
    /// Face culling of every material: `back`, `front` or `none` (default: the file's: glTF
    /// materials by `doubleSided`; OBJ, PLY and STL faces are drawn from both sides).
    #[arg(long, value_enum)]
    pub cull: Option<CullArg>,
}

/// `--cull`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum CullArg {
    /// Cull back faces.
    Back,
    /// Cull front faces.
    Front,
    /// Draw both faces.
    None,
}

/// `--shading`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ShadingArg {
    /// By the file (see `--shading`).
    Auto,
    /// The reference scenes' Lambert model.
    Lambert,
    /// glTF's metallic-roughness model with punctual lights and image-based light.
    Pbr,
}

/// `--tonemap`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum TonemapArg {
    /// Colours as they are (above 1 clips).
    None,
    /// Khronos PBR Neutral (for product pictures).
    PbrNeutral,
    /// The ACES filmic curve (Narkowicz's fit).
    Aces,
}

/// Parses a finite number.
fn parse_finite(s: &str) -> Result<f32, String> {
    s.trim()
        .parse::<f32>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| format!("'{s}' is not a finite number"))
}

/// Parses `A:B`, two finite times in seconds with A ≤ B.
fn parse_time_range(s: &str) -> Result<(f32, f32), String> {
    let bad = || format!("'{s}' is not a time range A:B in seconds with A <= B (e.g. 0:2.5)");
    let (a, b) = s.split_once(':').ok_or_else(bad)?;
    let (a, b) = (
        parse_finite(a).map_err(|_| bad())?,
        parse_finite(b).map_err(|_| bad())?,
    );
    if a > b {
        return Err(bad());
    }
    Ok((a, b))
}

/// Parses a finite number ≥ 0.
fn parse_non_negative(s: &str) -> Result<f32, String> {
    parse_finite(s)
        .ok()
        .filter(|v| *v >= 0.0)
        .ok_or_else(|| format!("'{s}' is not a finite number ≥ 0"))
}

/// Parses a byte count with an optional K, M, G or T suffix (powers of 1024).
pub fn parse_bytes(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let (digits, shift) = match t.chars().last().map(|c| c.to_ascii_uppercase()) {
        Some('K') => (&t[..t.len() - 1], 10),
        Some('M') => (&t[..t.len() - 1], 20),
        Some('G') => (&t[..t.len() - 1], 30),
        Some('T') => (&t[..t.len() - 1], 40),
        _ => (t, 0),
    };
    digits
        .parse::<u64>()
        .ok()
        .and_then(|n| n.checked_mul(1u64 << shift))
        .ok_or_else(|| format!("'{s}' is not a byte count (e.g. 4G, 512M, 1000000)"))
}

/// A backend by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum BackendKind {
    /// Kantele's CPU rasterizer.
    Cpu,
    /// The OpenGL reference backend (headless EGL).
    Gl,
    /// The CUDA backend: the whole tiled pipeline on an NVIDIA GPU (cargo feature `cuda`).
    Cuda,
    /// The CUDA backend with the thesis' "one call, one triangle" scheme (a baseline).
    CudaOcot,
    /// The CUDA backend with the thesis' "one call, many triangles" scheme (a baseline).
    CudaOcmt,
}

impl BackendKind {
    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            BackendKind::Cpu => "cpu",
            BackendKind::Gl => "gl",
            BackendKind::Cuda => "cuda",
            BackendKind::CudaOcot => "cuda-ocot",
            BackendKind::CudaOcmt => "cuda-ocmt",
        }
    }
}

/// What `--depth` stores.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum DepthKind {
    /// Planar depth: distance along the view axis (−z_eye), background +inf (0 in PNG).
    #[default]
    Eye,
    /// Ray distance: from the camera centre to the surface point, background +inf (0 in PNG).
    Ray,
    /// Raw window depth in [0, 1], background 1.0.
    Window,
}

/// Unit of `--depth` values (eye and ray depth).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum DepthUnit {
    /// Scene units (metres in glTF).
    M,
    /// Millimetres: scene units × 1000 (the BOP convention for 16-bit PNG depth).
    Mm,
}

/// The frame `--normals` are expressed in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum NormalSpace {
    /// World space.
    #[default]
    World,
    /// Camera space, OpenCV axes (x right, y down, z forward).
    Camera,
}

/// The up axis of automatic framing and orbits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum UpArg {
    /// +Y up (glTF).
    #[default]
    Y,
    /// +Z up (many scans and CAD files).
    Z,
}

/// Options of the CPU backend shared by several commands.
#[derive(Debug, Args, Clone, Default)]
pub struct CpuArgs {
    /// CPU worker threads (default: every core).
    #[arg(long, value_name = "N", value_parser = parse_threads)]
    pub threads: Option<usize>,
    /// CPU triangle traversal strategy: bbox, incremental, block, adaptive, bisector.
    #[arg(long, value_name = "NAME", value_parser = parse_strategy)]
    pub strategy: Option<Strategy>,
    /// Longest a CPU frame may take, in seconds; a frame that runs longer stops cleanly with an
    /// error (a work budget for untrusted scenes).
    #[arg(long, value_name = "SECONDS", value_parser = parse_timeout)]
    pub timeout: Option<std::time::Duration>,
    /// Multisample antialiasing: samples per pixel, 1, 4 or 8 (colour only: depth, ids and
    /// normals stay per pixel); default 1, for `thumbnail` 4. Every backend draws it;
    /// llvmpipe's OpenGL offers at most 4.
    #[arg(long, value_name = "N", value_parser = parse_msaa)]
    pub msaa: Option<SampleCount>,
    /// CPU colour target: f32 (linear floats, exact) or srgb8 (8-bit sRGB, a quarter of the
    /// colour memory; the same 8-bit pictures). Normals and ids always use f32.
    #[arg(long, value_name = "FORMAT", default_value_t = TargetFormat::LinearF32, value_parser = parse_target)]
    pub target: TargetFormat,
}

impl CpuArgs {
    /// Samples per pixel: `--msaa`, else 1.
    pub fn samples(&self) -> SampleCount {
        self.msaa.unwrap_or(SampleCount::X1)
    }
}

/// Parses `--target`: f32 or srgb8.
fn parse_target(s: &str) -> Result<TargetFormat, String> {
    s.parse()
}

/// Parses `--msaa`: 1, 4 or 8.
fn parse_msaa(s: &str) -> Result<SampleCount, String> {
    s.parse()
}

/// Parses `--timeout`: positive seconds (fractions allowed).
fn parse_timeout(s: &str) -> Result<std::time::Duration, String> {
    let seconds: f64 = s
        .parse()
        .map_err(|_| format!("'{s}' is not a number of seconds"))?;
    if !(seconds > 0.0 && seconds <= 1e9) {
        return Err(format!(
            "'{s}': the timeout must be a positive number of seconds"
        ));
    }
    Ok(std::time::Duration::from_secs_f64(seconds))
}

/// `kantele render`.
#[derive(Debug, Args)]
#[command(after_long_help = RENDER_HELP)]
pub struct RenderArgs {
    /// Scenes to render.
    #[command(flatten)]
    pub input: SceneArgs,
    /// Colour output (.png: 8-bit sRGB RGBA; .exr: linear float RGBA; .npy: float32 (H, W, 4);
    /// .gif/.apng: every view as one animation; `-` writes the PNG to standard output). With several scenes or views this is a template: {stem}, {index},
    /// {frame}. A JSON sidecar OUT.json is written next to each colour image (not for `-`).
    #[arg(short, long, value_name = "OUT")]
    pub output: String,
    /// Image size WxH, overriding the scene's resolution (each side 1..=16384).
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Backend to render with.
    #[arg(long, value_enum, default_value_t = BackendKind::Cpu)]
    pub backend: BackendKind,
    /// CPU backend options.
    #[command(flatten)]
    pub cpu: CpuArgs,
    /// Memory for one image's pixels while it is rendered and written (render target, readback
    /// and file rows; about 56 bytes a pixel, 120 at --msaa 4, 200 at --msaa 8), e.g. 512M, 2G
    /// (default 1G). A bigger picture is
    /// rendered in horizontal bands of whole 64-row tiles, each streamed into its files (PNG,
    /// PFM, .npy; not .exr); the picture is bit-identical to an unbanded one.
    #[arg(long, value_name = "BYTES", value_parser = parse_bytes)]
    pub frame_memory: Option<u64>,
    /// Print one JSON line per finished image on stdout.
    #[arg(long)]
    pub json: bool,
    /// Print nothing on success: no `wrote` line per image on stderr and no count of images
    /// skipped by --skip-existing (warnings and errors still print).
    #[arg(long, short)]
    pub quiet: bool,
    /// Frames per second of an animated -o (.gif, .apng) and time steps per second of
    /// --time-range.
    #[arg(long, value_name = "N", default_value_t = 24, value_parser = clap::value_parser!(u16).range(1..=100))]
    pub fps: u16,
    /// A sequence of --animation from A to B seconds: one picture per time step, at A, A +
    /// 1/fps, A + 2/fps, … up to B (--fps sets the steps); each written to its own files (a
    /// numbered -o: {frame}) or all in one .gif/.apng. With several views (--orbit, --views)
    /// every view is drawn at every time, time by time. Each sidecar records its time.
    #[arg(long, value_name = "A:B", requires = "animation", conflicts_with = "time", value_parser = parse_time_range)]
    pub time_range: Option<(f32, f32)>,
    /// Skip images whose files all exist already (resume an interrupted batch).
    #[arg(long)]
    pub skip_existing: bool,
    /// Cameras and background.
    #[command(flatten)]
    pub camera: CameraArgs,
    /// Depth, normal and id outputs.
    #[command(flatten)]
    pub extra: ExtraOutputArgs,
}

/// Which cameras `render` uses, and the background.
#[derive(Debug, Args, Clone, Default)]
pub struct CameraArgs {
    /// The camera: `N` or `NAME` (a camera of the file), `auto` (frame the model by its silhouette,
    /// ignoring the file's cameras) or `look-at:EYE:TARGET[:UP]` (comma-separated x,y,z).
    /// Default: the file's first camera, else `auto`.
    #[arg(long, value_name = "SPEC", conflicts_with_all = ["views", "orbit"])]
    pub camera: Option<String>,
    /// Vertical field of view in degrees of `auto`, `look-at` and orbit cameras (default 45).
    #[arg(long, value_name = "DEG", value_parser = parse_fov)]
    pub fov: Option<f32>,
    /// Frame the model with an orthographic camera (the `auto` framing, from the same
    /// direction; implies `--camera auto`, which is the only camera it combines with).
    #[arg(long, conflicts_with_all = ["fov", "views", "orbit"])]
    pub ortho: bool,
    /// Render the views of a file: a sidecar written by `render` (reproduces its picture) or a
    /// list of poses (see --help).
    #[arg(long, value_name = "FILE", conflicts_with = "orbit")]
    pub views: Option<PathBuf>,
    /// Render N views on a circle around the centre of the scene's box, written as numbered images
    /// ({frame}), or as one animated image when -o is .gif or .apng.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=100000))]
    pub orbit: Option<u32>,
    /// Orbit elevation above the horizon, degrees.
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 20.0,
        allow_negative_numbers = true,
        requires = "orbit"
    )]
    pub elevation: f32,
    /// Orbit radius in scene units (default: the nearest from which the model stays inside 92%
    /// of the picture at every azimuth).
    #[arg(long, value_name = "R", requires = "orbit")]
    pub radius: Option<f32>,
    /// Up axis of `auto` framing and orbits.
    #[arg(long, value_enum, default_value_t = UpArg::Y)]
    pub up: UpArg,
    /// Background: a name (black, white, grey, ...), #rrggbb[aa], r,g,b[,a] in 0..=1 or 0..=255,
    /// or `transparent`. Default: the scene's clear colour.
    #[arg(long, value_name = "COLOR", value_parser = parse_color)]
    pub background: Option<[f32; 4]>,
}

/// Depth, normal and id outputs of `render` (file names follow the -o template rules).
#[derive(Debug, Args, Clone, Default)]
pub struct ExtraOutputArgs {
    /// Depth output: .png (16-bit gray, 0 = background, millimetres unless --depth-unit m),
    /// .exr (one float channel), .pfm or .npy (float32).
    #[arg(long, value_name = "OUT")]
    pub depth: Option<String>,
    /// What the depth image stores.
    #[arg(long, value_enum, default_value_t = DepthKind::Eye)]
    pub depth_kind: DepthKind,
    /// Unit of eye and ray depth (default: mm for .png, m otherwise).
    #[arg(long, value_enum)]
    pub depth_unit: Option<DepthUnit>,
    /// Normal output: .png (n*0.5+0.5, 8-bit, background transparent black), .exr (float RGB,
    /// background 0) or .npy (float32 HxWx3, background 0).
    #[arg(long, value_name = "OUT")]
    pub normals: Option<String>,
    /// The frame normals are expressed in.
    #[arg(long, value_enum, default_value_t = NormalSpace::World)]
    pub normals_space: NormalSpace,
    /// Id output KIND=FILE (repeatable; a bare FILE means instance=FILE). KIND: instance, mesh,
    /// material, primitive (a mesh primitive placed by a node: one draw), triangle (within its
    /// draw). One channel, 0 = background: .png (16-bit gray), .exr (u32) or .npy (uint32).
    #[arg(long = "ids", value_name = "KIND=FILE", value_parser = parse_ids)]
    pub ids: Vec<(IdKind, String)>,
}

/// What an id image holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum IdKind {
    /// The node: node index + 1.
    Instance,
    /// The scene mesh: mesh index + 1.
    Mesh,
    /// The material: material index + 1.
    Material,
    /// The draw (a mesh primitive placed by a node): draw index + 1.
    Primitive,
    /// The triangle within its draw: triangle index + 1.
    Triangle,
}

impl IdKind {
    /// Every kind, in the order of the names.
    pub const ALL: [IdKind; 5] = [
        IdKind::Instance,
        IdKind::Mesh,
        IdKind::Material,
        IdKind::Primitive,
        IdKind::Triangle,
    ];

    /// The name used on the command line and in the sidecar.
    pub fn name(self) -> &'static str {
        match self {
            IdKind::Instance => "instance",
            IdKind::Mesh => "mesh",
            IdKind::Material => "material",
            IdKind::Primitive => "primitive",
            IdKind::Triangle => "triangle",
        }
    }
}

const RENDER_HELP: &str = r#"Output templates:
  {stem}   file stem of the scene (or the built-in's name)
  {index}  number of the image among all images written by this command (0000, 0001, ...)
  {frame}  number of the orbit view (0000 without --orbit)
  Several scenes or --orbit N>1 need placeholders that make every name unique.

Cameras:
  --camera look-at:0,1,5:0,0,0[:0,1,0]   eye, target and up as x,y,z
  --views FILE   a sidecar (OUT.json, which reproduces its picture), a list of sidecars, or
                 pose records, one or a list or {"views": [...]}; one image per view ({frame}).
                 A pose record has
                   "world_to_camera": 4x4 rows with "convention": "opencv"|"opengl"
                     (or "world_to_camera_opencv" / "world_to_camera_gl" instead);
                   one projection: "fx","fy","cx","cy" (pixels; the top-left pixel's centre
                     is 0,0), or "yfov" (radians), or "yfov_deg", or orthographic "ymag";
                   optionally "width","height" (default: --size), "znear" (default 0.01,
                     as Python's Camera.from_opencv) and "zfar" (default: infinite).
  Pixels stay square: the image's aspect decides the field of view across; without --size the
  image takes the file camera's aspect ratio.

Depth (--depth), one value per pixel:
  .pfm: greyscale 'Pf' float, little-endian, rows bottom to top (as PFM requires).
  .exr: one float channel 'Y'.   .npy: float32, shape (H, W).
  .png: 16-bit gray, round(depth) in --depth-unit (mm by default), 0 = background (BOP).
  eye:    distance along the view axis (-z in eye space), background +inf.
  ray:    distance from the camera centre, background +inf.
  window: window depth in [0, 1] as the depth buffer holds it, background 1.0.

Ids (--ids KIND=FILE): one channel per file, 0 = background; PNG when every id of the scene
fits 16 bits, else .exr (u32) or .npy (uint32). The sidecar maps ids to nodes and meshes.

Output sets: every file of an image (colour, depth, normals, ids, sidecar last) is written to
temporaries and moved into place together; Ctrl-C (SIGINT/SIGTERM) drops the image in flight,
removes its temporaries and exits with status 130. Outputs that would overwrite a scene file,
its textures or each other are refused before rendering; output folders are created first.

Sidecar OUT.json: camera intrinsics (fx, fy, cx, cy in pixels with pixel centres at integer
coordinates as in OpenCV; width, height, yfov, znear, zfar = null for an infinite projection),
world-to-camera matrices (rows) in OpenGL convention (x right, y up, looking down -z) and
OpenCV convention (x right, y down, z forward), the depth convention, id maps, scene source,
backend, renderer and render time."#;

/// `kantele info`.
#[derive(Debug, Args)]
pub struct InfoArgs {
    /// The scene to describe.
    #[command(flatten)]
    pub input: SceneArgs,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// `kantele bench`.
#[derive(Debug, Args)]
#[command(after_long_help = BENCH_HELP)]
pub struct BenchArgs {
    /// Scenes to time.
    #[command(flatten)]
    pub input: SceneArgs,
    /// Backends, comma-separated (the first is the reference of the ratio column).
    #[arg(
        long = "backend",
        visible_alias = "backends",
        value_enum,
        value_delimiter = ',',
        default_value = "cpu",
        value_name = "LIST"
    )]
    pub backends: Vec<BackendKind>,
    /// Timed frames per scene and backend.
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u32).range(1..))]
    pub frames: u32,
    /// Untimed warm-up frames before them.
    #[arg(long, default_value_t = 3)]
    pub warmup: u32,
    /// Untimed warm-up time per scene and backend, in milliseconds: warm-up frames go on until
    /// both `--warmup` frames and this long have passed. The first frames of a busy spell can
    /// run slower than the rest (cold caches, worker threads waking, virtual CPUs the host has
    /// not yet spread over its cores), and a short scene's frames would all fall in it.
    #[arg(long, default_value_t = 300, value_name = "MS")]
    pub warmup_ms: u64,
    /// Image size WxH instead of the scene's resolution.
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// CPU backend options.
    #[command(flatten)]
    pub cpu: CpuArgs,
    /// One JSON object per line instead of a table; with the medians of the CPU backend's
    /// stages too (`geometry_ms`, `binning_ms`, `raster_ms`; null for backends that do not time
    /// them) and what its last frame drew (`triangles_binned`, `bin_entries`,
    /// `fragments_covered`, `fragments_shaded`; null for backends that do not count them).
    #[arg(long)]
    pub json: bool,
}

const BENCH_HELP: &str = "\
Each frame is one render() call: clear, every draw, and waiting until the image is complete
(the timing rules of docs/rendering-rules.md). Loading is not timed. The GL backend renders
into an RGBA8 target here (the fair configuration).

The ratio column (with several backends) is this backend's median time divided by the first
backend's: below 1 means faster than the first.

A backend that cannot start (e.g. no EGL) is an error when it is the only one; with several
backends it is shown as 'unavailable', a warning is printed and the others still run (exit
status 0 as long as every scene ran on at least one backend).";

/// `kantele compare`.
#[derive(Debug, Args)]
#[command(after_long_help = COMPARE_HELP)]
pub struct CompareArgs {
    /// Scenes to compare.
    #[command(flatten)]
    pub input: SceneArgs,
    /// Backends, comma-separated; every pair is compared.
    #[arg(
        long = "backends",
        visible_alias = "backend",
        value_enum,
        value_delimiter = ',',
        default_value = "cpu,gl",
        value_name = "LIST"
    )]
    pub backends: Vec<BackendKind>,
    /// Write `DIR/<stem>-<backend>.png` and `DIR/<stem>-diff.png`.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Largest share of pixels (0..1) whose coverage may differ.
    #[arg(
        long,
        default_value_t = 0.001,
        value_name = "F",
        allow_negative_numbers = true
    )]
    pub max_coverage_diff: f64,
    /// Largest mean absolute 8-bit sRGB difference over the RGB channels of all pixels.
    #[arg(
        long,
        default_value_t = 1.0,
        value_name = "F",
        allow_negative_numbers = true
    )]
    pub max_mean_diff: f64,
    /// CPU backend options.
    #[command(flatten)]
    pub cpu: CpuArgs,
    /// One JSON object per line per compared pair.
    #[arg(long)]
    pub json: bool,
}

const COMPARE_HELP: &str = "\
Metrics per pair (a, b):
  coverage: share of pixels covered (depth < 1) in exactly one of the two images
  colour:   largest and mean absolute difference of the 8-bit sRGB RGB channels, all pixels
  depth:    largest and mean absolute window-depth difference over pixels covered by both
Difference image: grey = largest channel difference x8; red = covered only in a,
green = covered only in b. With more than two backends it is named <stem>-<a>-vs-<b>-diff.png.
Exit status: 1 when a tolerance is broken (each broken one is named on stderr), 2 on errors.";

/// `kantele view`.
#[derive(Debug, Args)]
#[command(after_long_help = VIEW_HELP)]
pub struct ViewArgs {
    /// The scene to view.
    #[command(flatten)]
    pub input: SceneArgs,
    /// Backend to start with (B toggles cpu/gl when gl is available).
    #[arg(long, value_enum, default_value_t = BackendKind::Cpu)]
    pub backend: BackendKind,
    /// CPU backend options.
    #[command(flatten)]
    pub cpu: CpuArgs,
    /// Initial window size WxH.
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Spin the camera around the scene at this many degrees per second (the blog's spinning
    /// teapot); dragging still works.
    #[arg(long, value_name = "DEG_PER_S")]
    pub spin: Option<f32>,
    /// Quit after N frames (for tests).
    #[arg(long, hide = true)]
    pub frames: Option<u64>,
    /// Save the last frame as PNG when quitting (for tests).
    #[arg(long, hide = true, value_name = "PATH")]
    pub screenshot: Option<PathBuf>,
}

const VIEW_HELP: &str = "\
Controls:
  left drag   rotate around the centre of the scene's bounding sphere
  wheel       zoom
  S           next CPU traversal strategy (bbox, incremental, block, adaptive, bisector)
  B           toggle the cpu / gl backend (when the OpenGL backend can start)
  Esc, Q      quit
The window title shows the scene, frames per second and the strategy. The first frames use the
scene's own camera; dragging or zooming switches to the orbit camera.";

/// Parses `WxH` with both sides in `1..=MAX_TARGET_SIZE`.
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("size '{s}' is not WIDTHxHEIGHT (e.g. 800x600)"))?;
    let side = |v: &str| {
        v.trim()
            .parse::<u64>()
            .map_err(|_| format!("size '{s}' is not WIDTHxHEIGHT (e.g. 800x600)"))
    };
    let (w, h) = (side(w)?, side(h)?);
    let max = kantele::MAX_TARGET_SIZE as u64;
    if w == 0 || h == 0 || w > max || h > max {
        return Err(format!(
            "size {w}x{h} is out of range: each side must be 1..={max} pixels"
        ));
    }
    Ok((w as u32, h as u32))
}

/// The narrowest field of view `--fov` takes, in degrees: a camera framing the scene through
/// a narrower one stands so far away (over 10 000 times the scene's radius) that 32-bit
/// positions no longer tell its triangles apart, and the picture comes out empty.
pub const MIN_FOV_DEG: f32 = 0.01;

/// Parses a vertical field of view in degrees, in [[`MIN_FOV_DEG`], 180).
pub fn parse_fov(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(v) if (MIN_FOV_DEG..180.0).contains(&v) => Ok(v),
        _ => Err(format!(
            "field of view '{s}' must be degrees in [{MIN_FOV_DEG}, 180)"
        )),
    }
}

/// Parses `KIND=FILE` (or a bare `FILE`, meaning `instance=FILE`).
pub fn parse_ids(s: &str) -> Result<(IdKind, String), String> {
    if let Some((kind, file)) = s.split_once('=') {
        if let Some(k) = IdKind::ALL.iter().find(|k| k.name() == kind) {
            if file.is_empty() {
                return Err(format!("--ids {s}: no file after '='"));
            }
            return Ok((*k, file.to_string()));
        }
        if !kind.contains(['/', '.', '\\']) {
            return Err(format!(
                "--ids {s}: unknown id kind '{kind}' (use instance, mesh, material, primitive or triangle)"
            ));
        }
    }
    if s.is_empty() {
        return Err("--ids needs KIND=FILE".into());
    }
    Ok((IdKind::Instance, s.to_string()))
}

/// Parses a colour: a name, `#rgb`/`#rrggbb`/`#rrggbbaa`, `r,g,b[,a]` (all in 0..=1, or
/// integers up to 255), or `transparent`. The result is linear RGBA (names, hex and 0..=255
/// values are sRGB and are decoded).
pub fn parse_color(s: &str) -> Result<[f32; 4], String> {
    let bad = || {
        format!(
            "colour '{s}' is not a name (black, white, grey, red, ...), #rrggbb[aa], r,g,b[,a] or transparent"
        )
    };
    let t = s.trim().to_ascii_lowercase();
    let srgb8 = |c: [u8; 4]| {
        [
            kantele::color::srgb_to_linear(c[0] as f32 / 255.0),
            kantele::color::srgb_to_linear(c[1] as f32 / 255.0),
            kantele::color::srgb_to_linear(c[2] as f32 / 255.0),
            c[3] as f32 / 255.0,
        ]
    };
    let named: Option<[u8; 4]> = match t.as_str() {
        "transparent" | "none" => return Ok([0.0; 4]),
        "black" => Some([0, 0, 0, 255]),
        "white" => Some([255, 255, 255, 255]),
        "grey" | "gray" => Some([128, 128, 128, 255]),
        "red" => Some([255, 0, 0, 255]),
        "green" => Some([0, 255, 0, 255]),
        "blue" => Some([0, 0, 255, 255]),
        _ => None,
    };
    if let Some(c) = named {
        return Ok(srgb8(c));
    }
    if let Some(hex) = t.strip_prefix('#') {
        let digits: Vec<u8> = hex
            .chars()
            .map(|c| c.to_digit(16).map(|d| d as u8))
            .collect::<Option<_>>()
            .ok_or_else(bad)?;
        let c = match digits.len() {
            3 => [digits[0] * 17, digits[1] * 17, digits[2] * 17, 255],
            6 | 8 => {
                let byte = |i: usize| digits[2 * i] * 16 + digits[2 * i + 1];
                [
                    byte(0),
                    byte(1),
                    byte(2),
                    if digits.len() == 8 { byte(3) } else { 255 },
                ]
            }
            _ => return Err(bad()),
        };
        return Ok(srgb8(c));
    }
    let parts: Vec<f32> = t
        .split(',')
        .map(|p| {
            p.trim()
                .parse::<f32>()
                .ok()
                .filter(|v| v.is_finite() && *v >= 0.0)
        })
        .collect::<Option<_>>()
        .ok_or_else(bad)?;
    if parts.len() != 3 && parts.len() != 4 {
        return Err(bad());
    }
    if parts.iter().all(|v| *v <= 1.0) {
        let a = parts.get(3).copied().unwrap_or(1.0);
        return Ok([parts[0], parts[1], parts[2], a]);
    }
    if parts.iter().all(|v| *v <= 255.0 && v.fract() == 0.0) {
        let a = parts.get(3).copied().unwrap_or(255.0);
        return Ok(srgb8([
            parts[0] as u8,
            parts[1] as u8,
            parts[2] as u8,
            a as u8,
        ]));
    }
    Err(bad())
}

fn parse_strategy(s: &str) -> Result<Strategy, String> {
    match s {
        "ocot" | "ocmt" => Err(format!(
            "'{s}' is a CUDA scheme: use --backend cuda-{s} (--strategy picks the CPU traversal)"
        )),
        _ => s.parse(),
    }
}

fn parse_threads(s: &str) -> Result<usize, String> {
    match s.parse::<usize>() {
        Ok(n) if (1..=1024).contains(&n) => Ok(n),
        _ => Err(format!("thread count '{s}' must be a number in 1..=1024")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn clap_definition_is_consistent() {
        Cli::command().debug_assert();
    }

    #[test]
    fn sizes() {
        assert_eq!(parse_size("800x600"), Ok((800, 600)));
        assert_eq!(parse_size("16384X1"), Ok((16384, 1)));
        assert!(parse_size("0x0").is_err());
        assert!(parse_size("100000x100000")
            .unwrap_err()
            .contains("1..=16384"));
        assert!(parse_size("16385x10").is_err());
        assert!(parse_size("800").is_err());
        assert!(parse_size("ax3").is_err());
    }
}
