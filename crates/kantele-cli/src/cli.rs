//! Command-line arguments (clap derive).

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};
use kantele::raster::Strategy;

/// Kantele: a software rasterizer. Render, inspect, benchmark, compare and view glTF 2.0 / OBJ
/// scenes by the rules of the reference scenes (`shared/scenes/README.md`).
///
/// Errors are reported as one line `kantele: error: <file>: <problem>` on stderr with exit
/// status 2 (`compare` exits with 1 when a tolerance is broken).
#[derive(Debug, Parser)]
#[command(name = "kantele", version, about, long_about)]
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
}

/// Which scenes to work on: files and built-in scenes.
#[derive(Debug, Args, Clone)]
pub struct SceneArgs {
    /// Scene files (.gltf, .glb, .obj).
    #[arg(value_name = "SCENE")]
    pub scenes: Vec<PathBuf>,
    /// A built-in scene (cube, teapot, ground, pixel-edges); may be repeated. Built-ins come after the files.
    #[arg(long = "builtin", value_name = "NAME")]
    pub builtins: Vec<String>,
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
    /// Linear eye-space distance along the view axis (−z_eye), background +inf.
    #[default]
    Eye,
    /// Raw window depth in [0, 1], background 1.0.
    Window,
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
}

/// `kantele render`.
#[derive(Debug, Args)]
#[command(after_long_help = RENDER_HELP)]
pub struct RenderArgs {
    /// Scenes to render.
    #[command(flatten)]
    pub input: SceneArgs,
    /// Colour output (.png: 8-bit sRGB RGBA; .exr: linear float RGBA). With several scenes or
    /// --orbit this is a template: {stem}, {index}, {frame}. A JSON sidecar OUT.json is written
    /// next to each colour image.
    #[arg(short, long, value_name = "OUT")]
    pub output: String,
    /// Image size WxH, overriding the scene's resolution (each side 1..=16384).
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Depth output (.pfm or .exr, 32-bit float); same template rules as -o.
    #[arg(long, value_name = "OUT")]
    pub depth: Option<String>,
    /// What the depth image stores.
    #[arg(long, value_enum, default_value_t = DepthKind::Eye)]
    pub depth_kind: DepthKind,
    /// World-normal output: .png (n*0.5+0.5, 8-bit linear, background transparent black) or .exr
    /// (float normals, background 0).
    #[arg(long, value_name = "OUT")]
    pub normals: Option<String>,
    /// Id output: .png (16-bit RGB: R = instance id, G = primitive id, B = draw id) or .exr
    /// (float RGB holding the same exact integers). 0 = background.
    #[arg(long, value_name = "OUT")]
    pub ids: Option<String>,
    /// Backend to render with.
    #[arg(long, value_enum, default_value_t = BackendKind::Cpu)]
    pub backend: BackendKind,
    /// CPU backend options.
    #[command(flatten)]
    pub cpu: CpuArgs,
    /// Render N views on a circle around the scene's bounding sphere (20° elevation) instead
    /// of the scene's camera; written as numbered images ({frame}).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=100000))]
    pub orbit: Option<u32>,
    /// Print one JSON line per finished image on stdout.
    #[arg(long)]
    pub json: bool,
}

const RENDER_HELP: &str = "\
Output templates:
  {stem}   file stem of the scene (or the built-in's name)
  {index}  number of the image among all images written by this command (0000, 0001, ...)
  {frame}  number of the orbit view (0000 without --orbit)
  Several scenes or --orbit N>1 need placeholders that make every name unique.

Depth (--depth): 32-bit float, one value per pixel.
  .pfm: greyscale 'Pf', little-endian, rows bottom to top (as PFM requires).
  .exr: RGB float with the value in all three channels.
  eye:    distance along the view axis (-z in eye space), background +inf.
  window: window depth in [0, 1] as the depth buffer holds it, background 1.0.

Sidecar OUT.json: camera intrinsics (fx, fy, cx, cy in pixels with pixel centres at integer
coordinates as in OpenCV; width, height, yfov, znear, zfar = null for an infinite projection),
world-to-camera matrices (rows) in OpenGL convention (x right, y up, looking down -z) and
OpenCV convention (x right, y down, z forward), the depth convention, id maps, scene source,
backend, renderer and render time.";

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
    /// Image size WxH instead of the scene's resolution.
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// CPU backend options.
    #[command(flatten)]
    pub cpu: CpuArgs,
    /// One JSON object per line instead of a table.
    #[arg(long)]
    pub json: bool,
}

const BENCH_HELP: &str = "\
Each frame is one render() call: clear, every draw, and waiting until the image is complete
(the timing rules of shared/scenes/README.md). Loading is not timed. The GL backend renders
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
    /// Quit after N frames (for tests).
    /// Spin the camera around the scene at this many degrees per second (the blog's spinning
    /// teapot); dragging still works.
    #[arg(long, value_name = "DEG_PER_S")]
    pub spin: Option<f32>,

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
