//! `kantele thumbnail IN OUT --size N`: a square PNG of a scene framed by its bounding box on a
//! transparent background, for file managers (`data/kantele.thumbnailer`).

use std::sync::Arc;

use anyhow::{anyhow, Result};
use kantele::backend::Pass;
use kantele::multisample::SampleCount;
use kantele_output::output::{encode_png_rgba8, write_atomic};

use crate::backends::make_backend;
use crate::camera_args::CameraPlan;
use crate::cli::{BackendKind, CameraArgs, CpuArgs, ThumbnailArgs};
use crate::output_plan::{create_folder, OutputGuard};
use crate::scenes::{self, Input};

/// Runs `kantele thumbnail`.
pub fn run(args: &ThumbnailArgs) -> Result<()> {
    let mut found = scenes::inputs(&crate::cli::SceneArgs {
        scenes: vec![args.input.clone()],
        builtins: Vec::new(),
        strict: false,
        max_memory: None,
        allow_read: Vec::new(),
        shading: crate::cli::ShadingArg::Auto,
        environment: None,
        environment_intensity: 1.0,
        environment_rotation: 0.0,
        exposure: 0.0,
        tonemap: crate::cli::TonemapArg::PbrNeutral,
        choice: args.choice.clone(),
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
    loaded.scene.clear_color = glam::Vec4::ZERO;
    let plan = CameraPlan::new(
        &CameraArgs {
            camera: Some("auto".into()),
            ..Default::default()
        },
        None,
    )?;
    let pose = plan.poses(&loaded, args.size, args.size, &label)?.remove(0);
    let scene = Arc::new(loaded.scene);
    // The preset antialiases: 4 samples per pixel.
    let cpu = CpuArgs {
        msaa: SampleCount::X4,
        ..CpuArgs::default()
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
