//! `kantele thumbnail IN OUT --size N`: a square PNG of a scene framed by its silhouette on a
//! transparent background, for file managers (`data/kantele.thumbnailer`); the load, CPU and
//! camera options of `render` apply.

use std::sync::Arc;

use anyhow::{anyhow, Result};
use kantele::backend::Pass;
use kantele::multisample::SampleCount;
use kantele_output::output::{encode_png_rgba8, write_atomic};

use crate::backends::make_backend;
use crate::camera_args::CameraPlan;
use crate::cli::{BackendKind, CameraArgs, CpuArgs, SceneArgs, ThumbnailArgs};
use crate::output_plan::{create_folder, OutputGuard};
use crate::scenes::{self, Input};

/// Runs `kantele thumbnail`.
pub fn run(args: &ThumbnailArgs) -> Result<()> {
    if args.camera.orbit.is_some() || args.camera.views.is_some() {
        anyhow::bail!("a thumbnail is one picture: --orbit and --views belong to `kantele render`");
    }
    let mut found = scenes::inputs(&SceneArgs {
        scenes: vec![args.input.clone()],
        builtins: Vec::new(),
        load: args.load.clone(),
    })?;
    if found.len() != 1 {
        anyhow::bail!(
            "{}: a thumbnail is made of one scene file",
            args.input.display()
        );
    }
    let input: Input = found.remove(0);
    if crate::output::extension(&args.output) != "png" {
        anyhow::bail!("{}: a thumbnail is a .png", args.output.display());
    }
    let mut guard = OutputGuard::new(std::slice::from_ref(&input));
    guard.add(&args.output)?;
    if let Some(dir) = args.output.parent().filter(|d| !d.as_os_str().is_empty()) {
        create_folder(dir)?;
    }
    let label = input.label();
    let mut loaded = input.load()?;
    guard.check_reads(&label, &loaded.info.files_read)?;
    let mut warnings = scenes::Warnings::default();
    warnings.report(&loaded, |w| eprintln!("{w}"));
    loaded.scene.clear_color = glam::Vec4::from_array(args.camera.background.unwrap_or([0.0; 4]));
    // The model framed by its silhouette unless --camera names another camera.
    let camera = CameraArgs {
        camera: args.camera.camera.clone().or_else(|| Some("auto".into())),
        ..args.camera.clone()
    };
    let plan = CameraPlan::new(&camera, None)?;
    let pose = plan.poses(&loaded, args.size, args.size, &label)?.remove(0);
    let scene = Arc::new(loaded.scene);
    let cpu = CpuArgs {
        msaa: Some(args.cpu.msaa.unwrap_or(SampleCount::X4)),
        ..args.cpu.clone()
    };
    let mut backend = make_backend(BackendKind::Cpu, &cpu, false)?;
    backend
        .load(scene.clone())
        .map_err(|e| anyhow!("{label}: {e}"))?;
    let view = pose.frame_view(&scene, Pass::Color);
    let interrupt = crate::signals::InterruptFlag::install()?;
    backend.set_cancel_flag(Some(interrupt.flag()));
    let (frame, _) = crate::render_cmd::render_pass(backend.as_mut(), &view, &label, &interrupt)?;
    let rgba = frame.to_rgba8(true);
    write_atomic(&args.output, |w| {
        encode_png_rgba8(w, frame.width, frame.height, &rgba)
    })?;
    Ok(())
}
