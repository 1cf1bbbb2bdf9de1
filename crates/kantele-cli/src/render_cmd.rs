//! `kantele render`: colour, depth, normal and id images with a JSON sidecar, each image's
//! files written together ([`OutputSet`]), checked before anything is rendered.

use std::io::IsTerminal;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use anyhow::{anyhow, bail, Result};
use indicatif::{ProgressBar, ProgressStyle};
use kantele::backend::{Backend, FrameImage, FrameView, Pass};
use kantele::band::{plan_bands, target_bytes_per_pixel, TARGET_BYTES_PER_PIXEL};
use kantele::multisample::SampleCount;
use kantele::scene::Scene;
use kantele::shade::transmission::backdrop_bytes;
use kantele::stats::FrameStats;
use kantele::RenderError;
use kantele_output::output::OutputSet;
use kantele_output::pose::sidecar::SidecarAnimation;
use kantele_output::pose::sidecar::{AnimationSidecar, InstanceId, PrimitiveId, SidecarCamera};
use kantele_output::pose::sidecar::{SidecarDepth, SidecarIds};
use kantele_output::pose::sidecar::{SidecarNormals, MATRIX_LAYOUT};
use kantele_output::pose::{rows, CameraPose, Sidecar};
use serde_json::json;

use crate::animation::{is_animation, Animation, ANIMATION_TYPES};
use crate::backends::make_backend;
use crate::camera_args::CameraPlan;
use crate::cli::{DepthKind, DepthUnit, NormalSpace, RenderArgs};
use crate::frame_files::{self as files, FramePaths};
use crate::frame_writer::{BandContext, Content, OutputFile};
use crate::output::{digits_for, expand_template, extension, has_placeholder, TemplateVars};
use crate::output_plan::OutputGuard;
use crate::scenes::{self, Input, Warnings};
use crate::signals::InterruptFlag;
use kantele_scene::AnimationPlayer;

/// The colour output name that means standard output.
pub const STDOUT: &str = "-";

/// What the id files hold, for the sidecar.
const ID_FILES: &str = "one channel per file (see files), 0 = background: instance = node_index + 1, mesh = mesh index + 1, material = material index + 1, primitive = a mesh primitive placed by a node (one draw; see primitive_ids), triangle = triangle index in its primitive + 1";

/// The unit of eye and ray depth: `--depth-unit`, else millimetres for PNG and metres otherwise.
fn depth_unit(args: &RenderArgs) -> DepthUnit {
    args.extra.depth_unit.unwrap_or_else(|| {
        match args.extra.depth.as_deref().map(|d| extension(Path::new(d))) {
            Some(e) if e == "png" => DepthUnit::Mm,
            _ => DepthUnit::M,
        }
    })
}

/// Checks file types and flag combinations that need no scene.
fn check_flags(args: &RenderArgs) -> Result<()> {
    if args.output == STDOUT && args.json {
        bail!("-o - and --json would both write to standard output; use one");
    }
    if is_animation(&args.output) {
        let e = &args.extra;
        if e.depth.is_some() || e.normals.is_some() || !e.ids.is_empty() {
            bail!("{}: an animation holds colour only; write depth, normals and ids with a numbered -o (.png)", args.output);
        }
    } else if args.output != STDOUT {
        let mut types = files::COLOR_TYPES.to_vec();
        types.extend_from_slice(ANIMATION_TYPES);
        files::check_type(&args.output, "-o", &types)?;
    }
    let extra = &args.extra;
    if let Some(d) = &extra.depth {
        files::check_type(d, "--depth", files::DEPTH_TYPES)?;
        if extension(Path::new(d)) == "png" && extra.depth_kind == DepthKind::Window {
            bail!("{d}: window depth in [0, 1] does not fit a 16-bit integer PNG; use .exr, .pfm or .npy");
        }
    }
    if extra.depth_unit.is_some() && extra.depth_kind == DepthKind::Window {
        bail!("--depth-unit applies to eye and ray depth, not window depth");
    }
    if let Some(n) = &extra.normals {
        files::check_type(n, "--normals", files::NORMAL_TYPES)?;
    }
    for (_, f) in &extra.ids {
        files::check_type(f, "--ids", files::ID_TYPES)?;
    }
    Ok(())
}

/// Expands every output name; refuses names shared by two files or with an input, and
/// creates the output folders.
fn plan_outputs(
    args: &RenderArgs,
    inputs: &[Input],
    views: usize,
    guard: &mut OutputGuard,
) -> Result<Vec<Vec<FramePaths>>> {
    // An animation holds every view of a scene in one file.
    let views = if is_animation(&args.output) { 1 } else { views };
    let total = inputs.len() * views;
    let extra = &args.extra;
    let templates: Vec<&String> = std::iter::once(&args.output)
        .chain(&extra.depth)
        .chain(&extra.normals)
        .chain(extra.ids.iter().map(|(_, f)| f))
        .collect();
    if args.output == STDOUT && (total > 1 || templates.len() > 1) {
        bail!("-o -: standard output takes one colour image only (no other outputs, one scene, one view)");
    }
    if total > 1 {
        for t in &templates {
            if !has_placeholder(t) {
                bail!(
                    "{t}: {total} images would be written to one file: use {{stem}}, {{index}} or {{frame}} in the name"
                );
            }
        }
    }
    let digits = digits_for(total.max(views));
    let mut plan = Vec::new();
    for (i, input) in inputs.iter().enumerate() {
        let stem = input.stem();
        let mut per_view = Vec::new();
        for frame in 0..views {
            let vars = TemplateVars {
                stem: &stem,
                index: i * views + frame,
                frame,
            };
            let expand = |t: &String| -> Result<PathBuf> {
                Ok(PathBuf::from(expand_template(t, &vars, digits)?))
            };
            let color = if args.output == STDOUT {
                None
            } else {
                Some(expand(&args.output)?)
            };
            let sidecar = color.as_ref().map(|c| {
                let mut s = c.clone().into_os_string();
                s.push(".json");
                PathBuf::from(s)
            });
            let paths = FramePaths {
                color,
                sidecar,
                depth: extra.depth.as_ref().map(expand).transpose()?,
                normals: extra.normals.as_ref().map(expand).transpose()?,
                ids: extra
                    .ids
                    .iter()
                    .map(|(k, f)| Ok((*k, expand(f)?)))
                    .collect::<Result<_>>()?,
            };
            for p in paths.all() {
                guard.add(p)?;
            }
            per_view.push(paths);
        }
        plan.push(per_view);
    }
    guard.create_folders()?;
    Ok(plan)
}

/// Renders one whole frame of one pass and checks its size (the backend must render whole
/// frames: no render region set).
pub fn render_pass(
    backend: &mut dyn Backend,
    view: &FrameView,
    label: &str,
    interrupt: &InterruptFlag,
) -> Result<(FrameImage, f64)> {
    let band = render_band(backend, view, 0..view.height, label, interrupt)?;
    if view.pass == Pass::Color {
        if let Some(warning) = band.stats.empty_picture_warning() {
            eprintln!("kantele: warning: {label}: {warning}");
        }
    }
    Ok((band.frame, band.ms))
}

/// A rendered band: its frame (`rows` of the view), the frame's counters and time.
struct RenderedBand {
    frame: FrameImage,
    stats: FrameStats,
    ms: f64,
}

/// Renders rows `rows` of one pass (the backend's render region must be those rows, or none
/// for a whole frame) and checks the band's size. An interrupt that cancelled the frame is
/// [`Interrupted`](crate::signals::Interrupted).
fn render_band(
    backend: &mut dyn Backend,
    view: &FrameView,
    rows: Range<u32>,
    label: &str,
    interrupt: &InterruptFlag,
) -> Result<RenderedBand> {
    let start = Instant::now();
    let stats = match backend.render(view) {
        Err(RenderError::Cancelled) => {
            interrupt.check()?;
            bail!("{label}: frame cancelled")
        }
        other => other.map_err(|e| anyhow!("{label}: {e}"))?,
    };
    let ms = start.elapsed().as_secs_f64() * 1000.0;
    let frame = backend.read_frame().map_err(|e| anyhow!("{label}: {e}"))?;
    let n = view.width as usize * rows.len();
    if (frame.width, frame.height) != (view.width, rows.len() as u32)
        || frame.color.len() != n
        || frame.depth.len() != n
    {
        bail!(
            "{label}: {} backend returned a {}x{} frame for rows {}..{} of a {}x{} view",
            backend.name(),
            frame.width,
            frame.height,
            rows.start,
            rows.end,
            view.width,
            view.height
        );
    }
    Ok(RenderedBand { frame, stats, ms })
}

/// Bytes a pixel of a band costs the CLI at `samples` samples per pixel: the CPU backend's
/// tiles (linear RGBA + depth, `f32`, per sample, and a centre depth when multisampled), the
/// band read back (resolved: linear RGBA + depth) and the rows converted for the files (at
/// most 16 bytes: normals as three floats plus their PNG bytes). 56 at 1 sample, 120 at 4,
/// 200 at 8.
pub const fn band_bytes_per_pixel(samples: SampleCount) -> usize {
    target_bytes_per_pixel(samples) + TARGET_BYTES_PER_PIXEL + 16
}

/// The default frame memory budget (`--frame-memory`): 1 GiB.
pub const DEFAULT_FRAME_MEMORY: u64 = 1 << 30;

/// The frame memory budget of `render`.
fn frame_memory(args: &RenderArgs) -> usize {
    usize::try_from(args.frame_memory.unwrap_or(DEFAULT_FRAME_MEMORY)).unwrap_or(usize::MAX)
}

/// Most time steps one `--time-range` may make.
const MAX_TIME_STEPS: u64 = 100_000;

/// The times of `--time-range A:B` at `--fps N`: A + k/N for k = 0, 1, … while it is at most
/// B (each computed from k, not summed, so a frame's time does not depend on the frames before
/// it); one step of no time without a range.
fn time_steps(args: &RenderArgs) -> Result<Vec<Option<f32>>> {
    let Some((a, b)) = args.time_range else {
        return Ok(vec![None]);
    };
    let fps = f64::from(args.fps);
    // The tolerance keeps B itself when (B - A) * fps is a whole number up to rounding.
    let count = ((f64::from(b) - f64::from(a)) * fps + 1e-6).floor() as u64 + 1;
    if count > MAX_TIME_STEPS {
        bail!(
            "--time-range {a}:{b} at --fps {} makes {count} time steps, more than {MAX_TIME_STEPS}",
            args.fps
        );
    }
    Ok((0..count)
        .map(|k| Some((f64::from(a) + k as f64 / fps) as f32))
        .collect())
}

/// The sidecar's depth entry.
fn depth_entry(args: &RenderArgs, file: Option<String>) -> SidecarDepth {
    let png = file
        .as_deref()
        .is_some_and(|f| extension(Path::new(f)) == "png");
    let what = match args.extra.depth_kind {
        DepthKind::Window => return SidecarDepth::window(file),
        DepthKind::Eye => "distance along the camera's view axis (-z in OpenGL eye space, +z in OpenCV camera space)",
        DepthKind::Ray => "distance from the camera centre to the surface point",
    };
    let unit = match depth_unit(args) {
        DepthUnit::M => "scene units",
        DepthUnit::Mm => "millimetres (scene units x 1000)",
    };
    let mut entry = SidecarDepth::eye(file);
    if args.extra.depth_kind == DepthKind::Ray {
        entry.kind = "ray".into();
    }
    if png {
        entry.description = format!("{what}, {unit}, rounded to 16-bit integers");
        entry.background = serde_json::Value::from(0);
    } else {
        entry.description = format!("{what}, {unit}, 32-bit float");
    }
    entry
}

/// Everything the sidecar of one image needs.
struct SidecarInputs<'a> {
    input: &'a Input,
    source: &'a str,
    scene: &'a Scene,
    pose: &'a CameraPose,
    paths: &'a FramePaths,
    backend: &'a dyn Backend,
    ms: f64,
    animation: Option<SidecarAnimation>,
}

fn sidecar(args: &RenderArgs, s: &SidecarInputs<'_>) -> Sidecar {
    let path = |p: &PathBuf| p.display().to_string();
    let scene = s.scene;
    let mut instances = std::collections::BTreeMap::new();
    for d in &scene.draws {
        instances
            .entry(d.node_index + 1)
            .or_insert_with(|| d.node_name.clone());
    }
    let instance_ids = instances
        .into_iter()
        .map(|(id, node_name)| InstanceId {
            id,
            node_index: id - 1,
            node_name,
        })
        .collect();
    let primitive_ids = scene
        .draws
        .iter()
        .enumerate()
        .map(|(i, d)| PrimitiveId {
            id: i + 1,
            mesh_index: d.mesh,
            mesh_name: scene
                .meshes
                .get(d.mesh)
                .map(|m| m.name.clone())
                .unwrap_or_default(),
            node_index: d.node_index,
            node_name: d.node_name.clone(),
        })
        .collect();
    let normals_space = match args.extra.normals_space {
        NormalSpace::World => "world-space",
        NormalSpace::Camera => "camera-space (OpenCV axes: x right, y down, z forward)",
    };
    Sidecar {
        scene: s.input.stem(),
        source: s.source.to_string(),
        output: s.paths.color.as_ref().map(path).unwrap_or_else(|| "-".into()),
        width: s.pose.width,
        height: s.pose.height,
        backend: s.backend.name().to_string(),
        renderer: s.backend.renderer(),
        threads: s.backend.threads(),
        render_ms: s.ms,
        camera: SidecarCamera::of_pose(s.pose),
        world_to_camera_gl: rows(&s.pose.view()),
        world_to_camera_opencv: rows(&s.pose.world_to_camera_opencv()),
        matrix_layout: MATRIX_LAYOUT.into(),
        depth: depth_entry(args, s.paths.depth.as_ref().map(path)),
        normals: s.paths.normals.as_ref().map(|p| SidecarNormals {
            file: path(p),
            encoding: match extension(p).as_str() {
                "exr" => format!("{normals_space} unit normal as float RGB, background 0"),
                "npy" => format!("{normals_space} unit normal, float32 (H, W, 3), background 0"),
                _ => format!("{normals_space} unit normal n as 8-bit linear (n * 0.5 + 0.5) * 255 in RGB, alpha 255; background 0 0 0 0"),
            },
        }),
        ids: SidecarIds {
            channels: ID_FILES.into(),
            files: s
                .paths
                .ids
                .iter()
                .map(|(k, p)| (k.name().to_string(), path(p)))
                .collect(),
            instance_ids,
            primitive_ids,
        },
        animation: s.animation.clone(),
    }
}

/// One scene's state while its views are rendered.
struct SceneJob<'a> {
    args: &'a RenderArgs,
    input: &'a Input,
    label: String,
    source: String,
    scene: Arc<Scene>,
    /// The pose of the scene as it is now (`None`: the rest pose).
    animation: Option<SidecarAnimation>,
}

impl SceneJob<'_> {
    /// Renders one view and writes its files together; an interrupt drops them all. A picture
    /// whose pixels would exceed the frame memory budget is rendered in horizontal bands, each
    /// band's rows streamed into every file before the next band is drawn.
    fn render_view(
        &self,
        backend: &mut dyn Backend,
        pose: &CameraPose,
        paths: &FramePaths,
        interrupt: &InterruptFlag,
    ) -> Result<f64> {
        let (args, label, scene) = (self.args, &self.label, &self.scene);
        let (width, height) = (pose.width, pose.height);
        // A frame with transmission draws its whole backdrop first, whatever its bands.
        let backdrop = if scene.has_transmission() {
            backdrop_bytes(width, height)
        } else {
            0
        };
        let budget = frame_memory(args).saturating_sub(backdrop);
        let per_pixel = band_bytes_per_pixel(backend.samples());
        let bands = plan_bands(width, height, per_pixel, budget);
        if bands.len() > 1 {
            backend
                .set_render_region(Some(bands[0].clone()))
                .map_err(|e| anyhow!("{label}: a {width}x{height} picture needs {} bands within the frame memory budget, and {e}; raise --frame-memory or use the cpu backend", bands.len()))?;
        }
        let mut set = OutputSet::new();
        let mut outputs = Vec::new();
        let extra = &args.extra;
        let contents = std::iter::once((paths.color.as_deref(), Content::Color))
            .chain(
                paths
                    .depth
                    .as_deref()
                    .map(|p| (Some(p), Content::Depth(extra.depth_kind, depth_unit(args)))),
            )
            .chain(
                paths
                    .normals
                    .as_deref()
                    .map(|p| (Some(p), Content::Normals(extra.normals_space))),
            )
            .chain(
                paths
                    .ids
                    .iter()
                    .map(|(k, p)| (Some(p.as_path()), Content::Ids(*k))),
            );
        for (path, content) in contents {
            outputs.push(OutputFile::open(
                &mut set,
                path,
                content,
                (width, height),
                bands.len(),
            )?);
        }
        let normals_pass = outputs.iter().any(OutputFile::needs_normals_pass);
        let ids_pass = outputs.iter().any(OutputFile::needs_ids_pass);
        let mut ms = 0.0;
        let mut covered = 0;
        let mut empty_warning = None;
        for rows in &bands {
            interrupt.check()?;
            let region = (bands.len() > 1).then(|| rows.clone());
            backend
                .set_render_region(region)
                .map_err(|e| anyhow!("{label}: {e}"))?;
            let ctx = BandContext {
                pose,
                scene,
                first_row: rows.start,
                interrupt,
            };
            let mut view = pose.frame_view(scene, Pass::Color);
            let band = render_band(backend, &view, rows.clone(), label, interrupt)?;
            ms += band.ms;
            covered += band.stats.fragments_covered;
            empty_warning = empty_warning.or(band.stats.empty_picture_warning());
            for out in outputs
                .iter_mut()
                .filter(|o| !o.needs_normals_pass() && !o.needs_ids_pass())
            {
                out.write_band(&mut set, &band.frame, &ctx)?;
            }
            for (pass, wanted) in [(Pass::Normals, normals_pass), (Pass::Ids, ids_pass)] {
                if !wanted {
                    continue;
                }
                interrupt.check()?;
                view.pass = pass;
                let band = render_band(backend, &view, rows.clone(), label, interrupt)?;
                for out in outputs.iter_mut().filter(|o| {
                    (pass == Pass::Normals && o.needs_normals_pass())
                        || (pass == Pass::Ids && o.needs_ids_pass())
                }) {
                    out.write_band(&mut set, &band.frame, &ctx)?;
                }
            }
        }
        backend
            .set_render_region(None)
            .map_err(|e| anyhow!("{label}: {e}"))?;
        if let Some(warning) = empty_warning.filter(|_| covered == 0) {
            eprintln!("kantele: warning: {label}: {warning}");
        }
        interrupt.check()?;
        for out in outputs {
            out.finish()?;
        }
        if let Some(p) = &paths.sidecar {
            let meta = sidecar(
                args,
                &SidecarInputs {
                    input: self.input,
                    source: &self.source,
                    scene,
                    pose,
                    paths,
                    backend: &*backend,
                    ms,
                    animation: self.animation.clone(),
                },
            );
            files::write_json(&mut set, p, &meta)?;
        }
        interrupt.check()?;
        set.commit()?;
        Ok(ms)
    }
}

fn progress_bar(total: usize) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let pb = ProgressBar::new(total as u64);
    if let Ok(style) =
        ProgressStyle::with_template("{spinner} {pos}/{len} {msg} [{elapsed_precise}{eta_suffix}]")
    {
        pb.set_style(style.with_key(
            "eta_suffix",
            |state: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
                if state.pos() > 0 && state.pos() < state.len().unwrap_or(0) {
                    let _ = write!(w, " < {}", indicatif::HumanDuration(state.eta()));
                }
            },
        ));
    }
    pb.enable_steady_tick(std::time::Duration::from_millis(200));
    pb
}

/// Runs `kantele render`.
pub fn run(args: &RenderArgs) -> Result<()> {
    let interrupt = InterruptFlag::install()?;
    check_flags(args)?;
    let mut scene_args = args.input.clone();
    if let Some((start, _)) = args.time_range {
        // Loaded at the range's first time: the cameras frame that pose.
        scene_args.load.choice.time = Some(start);
    }
    let inputs = scenes::inputs(&scene_args)?;
    let cameras = CameraPlan::new(&args.camera, args.size)?;
    let steps = time_steps(args)?;
    let views = cameras.views_per_scene();
    // Frame `step * views + view` of a scene is its view `view` at time step `step`.
    let frames = steps.len() * views;
    let mut guard = OutputGuard::new(&inputs);
    if let Some(v) = &args.camera.views {
        guard.protect(v);
    }
    let plan = plan_outputs(args, &inputs, frames, &mut guard)?;
    let total = inputs.len() * frames;

    let mut backend = make_backend(args.backend, &args.cpu, false)?;
    // Ctrl-C and SIGTERM cancel the frame in flight, not only the next one.
    backend.set_cancel_flag(Some(interrupt.flag()));
    let progress = progress_bar(total);
    let mut report = Report::new(args, &progress);
    let mut warnings = Warnings::default();

    for (input, outs) in inputs.iter().zip(&plan) {
        interrupt.check()?;
        let done = |paths: &FramePaths| paths.color.is_some() && paths.all().all(|p| p.exists());
        if args.skip_existing && outs.iter().all(done) {
            report.skip(outs.len() as u64, outs.len() as u64);
            continue;
        }
        let label = input.label();
        progress.set_message(input.stem());
        let mut loaded = input.load()?;
        guard.check_reads(&label, &loaded.info.files_read)?;
        warnings.report(&loaded, |w| progress.suspend(|| eprintln!("{w}")));
        // The cameras frame the scene as loaded: at --time, or at the first time of a range.
        let (width, height) = cameras.image_size(&loaded, args.size, &label)?;
        let poses = cameras.poses(&loaded, width, height, &label)?;
        for (kind, p) in outs.iter().flat_map(|o| &o.ids) {
            files::check_id_range(&loaded.scene, *kind, p)?;
        }
        if let Some(c) = args.camera.background {
            loaded.scene.clear_color = glam::Vec4::from_array(c);
        }
        let player = loaded.animation.take();
        let time = scene_args.load.choice.time.unwrap_or(0.0);
        let mut job = SceneJob {
            args,
            input,
            source: loaded.info.source.clone(),
            animation: player.as_ref().map(|p| sidecar_animation(p, time)),
            scene: Arc::new(loaded.scene),
            label,
        };
        if is_animation(&args.output) {
            let Some(path) = &outs[0].color else {
                bail!("an animation cannot go to standard output");
            };
            if args.skip_existing && path.exists() {
                report.skip(1, frames as u64);
                continue;
            }
            let mut animation = Animation::new(width, height, args.fps);
            let mut sidecars = Vec::new();
            let frame_paths = FramePaths {
                color: Some(path.clone()),
                ..FramePaths::default()
            };
            for time in &steps {
                job.pose_at(*time, player.as_ref())?;
                backend
                    .load(job.scene.clone())
                    .map_err(|e| anyhow!("{}: {e}", job.label))?;
                for pose in &poses {
                    interrupt.check()?;
                    let view = pose.frame_view(&job.scene, Pass::Color);
                    let (frame, ms) = render_pass(backend.as_mut(), &view, &job.label, &interrupt)?;
                    animation
                        .push(&frame)
                        .map_err(|e| anyhow!("{}: {e}", path.display()))?;
                    sidecars.push(sidecar(
                        args,
                        &SidecarInputs {
                            input,
                            source: &job.source,
                            scene: &job.scene,
                            pose,
                            paths: &frame_paths,
                            backend: backend.as_ref(),
                            ms,
                            animation: job.animation.clone(),
                        },
                    ));
                    progress.inc(1);
                }
            }
            interrupt.check()?;
            let mut set = OutputSet::new();
            animation.write(&mut set, path)?;
            let meta = AnimationSidecar {
                scene: input.stem(),
                source: job.source.clone(),
                output: path.display().to_string(),
                fps: args.fps,
                frames: sidecars.len(),
                views: sidecars,
            };
            if let Some(p) = &outs[0].sidecar {
                files::write_json(&mut set, p, &meta)?;
            }
            interrupt.check()?;
            set.commit()?;
            let written = FramePaths {
                sidecar: outs[0].sidecar.clone(),
                ..frame_paths
            };
            report.wrote(&written, width, height);
            continue;
        }
        for (time, outs) in steps.iter().zip(outs.chunks(views)) {
            if args.skip_existing && outs.iter().all(done) {
                report.skip(outs.len() as u64, outs.len() as u64);
                continue;
            }
            job.pose_at(*time, player.as_ref())?;
            backend
                .load(job.scene.clone())
                .map_err(|e| anyhow!("{}: {e}", job.label))?;
            for (pose, paths) in poses.iter().zip(outs) {
                interrupt.check()?;
                if args.skip_existing && done(paths) {
                    report.skip(1, 1);
                    continue;
                }
                let ms = job.render_view(backend.as_mut(), pose, paths, &interrupt)?;
                report.wrote(paths, pose.width, pose.height);
                if args.json {
                    let mut line = json!({
                        "scene": input.stem(),
                        "output": paths.color.as_ref().map_or("-".into(), |c| c.display().to_string()),
                        "width": pose.width,
                        "height": pose.height,
                        "ms": ms,
                    });
                    if let Some(t) = time {
                        line["time"] = json!(t);
                    }
                    progress.suspend(|| println!("{line}"));
                }
                progress.inc(1);
            }
        }
    }
    progress.finish_and_clear();
    report.finish();
    Ok(())
}

/// What `render` tells the user on stderr as it goes: a `wrote` line per image and, at the end,
/// how many images `--skip-existing` skipped; nothing with `--quiet`.
struct Report<'a> {
    quiet: bool,
    progress: &'a ProgressBar,
    skipped: u64,
}

impl<'a> Report<'a> {
    fn new(args: &RenderArgs, progress: &'a ProgressBar) -> Self {
        Self {
            quiet: args.quiet,
            progress,
            skipped: 0,
        }
    }

    /// One image written: its files (standard output for `-o -`).
    fn wrote(&self, files: &FramePaths, width: u32, height: u32) {
        if self.quiet {
            return;
        }
        let mut names: Vec<String> = files.all().map(|p| p.display().to_string()).collect();
        if files.color.is_none() {
            names.insert(0, "standard output".into());
        }
        self.progress.suspend(|| {
            eprintln!("kantele: wrote {} ({width}x{height})", names.join(", "));
        });
    }

    /// `images` skipped because their files exist: `frames` steps of the progress bar (an
    /// animation is one image of many frames).
    fn skip(&mut self, images: u64, frames: u64) {
        self.skipped += images;
        self.progress.inc(frames);
    }

    fn finish(&self) {
        if self.skipped > 0 && !self.quiet {
            eprintln!(
                "kantele: skipped {} image(s) whose files exist (--skip-existing)",
                self.skipped
            );
        }
    }
}

impl SceneJob<'_> {
    /// Poses the scene at `time` of the loaded animation; `None`, or the time it is posed at
    /// already, leaves it as it is.
    fn pose_at(&mut self, time: Option<f32>, player: Option<&AnimationPlayer>) -> Result<()> {
        let (Some(time), Some(player)) = (time, player) else {
            return Ok(());
        };
        if self.animation.as_ref().is_some_and(|a| a.time == time) {
            return Ok(());
        }
        let mut scene = Scene::clone(&self.scene);
        player
            .pose(&mut scene, time)
            .map_err(|e| anyhow!("{}: {e}", self.label))?;
        self.scene = Arc::new(scene);
        self.animation = Some(sidecar_animation(player, time));
        Ok(())
    }
}

/// What a sidecar records of a pose at `time` of `player`'s animation.
fn sidecar_animation(player: &AnimationPlayer, time: f32) -> SidecarAnimation {
    SidecarAnimation {
        index: player.index(),
        name: player.name().to_string(),
        time,
    }
}
