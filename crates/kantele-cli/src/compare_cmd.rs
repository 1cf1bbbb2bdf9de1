//! `kantele compare`: the same scenes through several backends, and how far the pictures differ.

use std::path::Path;
use std::sync::Arc;

use anyhow::{anyhow, bail, Result};
use kantele::backend::{Backend, FrameImage, FrameView};
use serde_json::json;

use crate::backends::make_backend;
use crate::cli::CompareArgs;
use crate::compare::{violations, Tolerances};
use crate::output::write_png_rgba8;
use crate::scenes::{self, Warnings};

fn render(backend: &mut dyn Backend, view: &FrameView, label: &str) -> Result<FrameImage> {
    let name = backend.name().to_string();
    backend.render(view).map_err(|e| anyhow!("{label}: {e}"))?;
    let frame = backend.read_frame().map_err(|e| anyhow!("{label}: {e}"))?;
    let n = view.width as usize * view.height as usize;
    if frame.color.len() != n || frame.depth.len() != n {
        bail!("{label}: {name} backend returned a frame of the wrong size");
    }
    Ok(frame)
}

/// Runs `kantele compare`; `Ok(false)` when a tolerance is broken.
pub fn run(args: &CompareArgs) -> Result<bool> {
    if args.backends.len() < 2 {
        bail!("--backends: compare needs at least two backends (e.g. cpu,gl)");
    }
    for (i, b) in args.backends.iter().enumerate() {
        if args.backends[..i].contains(b) {
            bail!("--backends: {} is listed twice", b.name());
        }
    }
    for (name, value) in [
        ("--max-coverage-diff", args.max_coverage_diff),
        ("--max-mean-diff", args.max_mean_diff),
    ] {
        if !(value.is_finite() && value >= 0.0) {
            bail!("{name}: {value} is not a non-negative number");
        }
    }
    let inputs = scenes::inputs(&args.input)?;
    let guard = match &args.out {
        Some(dir) => Some(check_out_names(args, &inputs, dir)?),
        None => None,
    };
    let tol = Tolerances {
        max_coverage_diff: args.max_coverage_diff,
        max_mean_diff: args.max_mean_diff,
    };
    let mut backends = args
        .backends
        .iter()
        .map(|k| make_backend(*k, &args.cpu, false))
        .collect::<Result<Vec<_>>>()?;

    let mut warnings = Warnings::default();
    let mut passed = true;
    if !args.json {
        println!(
            "{:<24} {:<5} {:<5} {:>10} {:>6} {:>9} {:>12} {:>12}  result",
            "scene", "a", "b", "coverage%", "max", "mean", "max depth", "mean depth"
        );
    }
    for input in &inputs {
        let label = input.label();
        let stem = input.stem();
        let loaded = input.load()?;
        if let Some(guard) = &guard {
            guard.check_reads(&label, &loaded.info.files_read)?;
        }
        warnings.report(&loaded, |w| eprintln!("{w}"));
        let scene = Arc::new(loaded.scene);
        let view = FrameView::of_scene(&scene);
        let mut frames = Vec::new();
        for b in backends.iter_mut() {
            b.load(scene.clone()).map_err(|e| anyhow!("{label}: {e}"))?;
            let frame = render(b.as_mut(), &view, &label)?;
            if let Some(dir) = &args.out {
                let p = dir.join(format!("{stem}-{}.png", b.name()));
                write_png_rgba8(&p, frame.width, frame.height, &frame.to_rgba8(true))?;
            }
            frames.push((b.name().to_string(), frame));
        }
        for i in 0..frames.len() {
            for j in i + 1..frames.len() {
                let (na, fa) = &frames[i];
                let (nb, fb) = &frames[j];
                let m = kantele_testkit::compare::compare(fa, fb, None, u8::MAX)
                    .ok_or_else(|| anyhow!("{label}: {na} and {nb} frames differ in size"))?;
                if let Some(dir) = &args.out {
                    let name = if frames.len() == 2 {
                        format!("{stem}-diff.png")
                    } else {
                        format!("{stem}-{na}-vs-{nb}-diff.png")
                    };
                    let path = Path::new(dir).join(name);
                    write_png_rgba8(&path, view.width, view.height, &m.difference_image)?;
                }
                let violations = violations(&m, &tol);
                passed &= violations.is_empty();
                for v in &violations {
                    eprintln!("kantele: error: {label}: {na} vs {nb}: {v}");
                }
                if args.json {
                    println!(
                        "{}",
                        json!({
                            "scene": stem, "source": loaded.info.source, "a": na, "b": nb,
                            "width": view.width, "height": view.height,
                            "coverage_mismatches": m.coverage_mismatches, "coverage_diff": m.coverage_mismatch_fraction(),
                            "max_color_diff": m.max_color_diff, "mean_color_diff": m.mean_color_diff,
                            "max_depth_diff": m.max_depth_diff, "mean_depth_diff": m.mean_depth_diff,
                            "passed": violations.is_empty(), "violations": violations,
                        })
                    );
                } else {
                    println!(
                        "{:<24} {:<5} {:<5} {:>10.4} {:>6} {:>9.4} {:>12.3e} {:>12.3e}  {}",
                        stem,
                        na,
                        nb,
                        m.coverage_mismatch_fraction() * 100.0,
                        m.max_color_diff,
                        m.mean_color_diff,
                        m.max_depth_diff,
                        m.mean_depth_diff,
                        if violations.is_empty() {
                            "ok"
                        } else {
                            "FAILED"
                        }
                    );
                }
            }
        }
    }
    Ok(passed)
}

/// Refuses, before rendering, `--out` files that would overwrite an input or each other (two
/// scenes with one stem), and creates the folder; the guard then checks each loaded scene's
/// files.
fn check_out_names(
    args: &CompareArgs,
    inputs: &[scenes::Input],
    dir: &Path,
) -> Result<crate::output_plan::OutputGuard> {
    let mut guard = crate::output_plan::OutputGuard::new(inputs);
    let n = args.backends.len();
    for input in inputs {
        let stem = input.stem();
        for b in &args.backends {
            guard.add(&dir.join(format!("{stem}-{}.png", b.name())))?;
        }
        for i in 0..n {
            for j in i + 1..n {
                let name = if n == 2 {
                    format!("{stem}-diff.png")
                } else {
                    format!(
                        "{stem}-{}-vs-{}-diff.png",
                        args.backends[i].name(),
                        args.backends[j].name()
                    )
                };
                guard.add(&dir.join(name))?;
            }
        }
    }
    crate::output_plan::create_folder(dir)?;
    Ok(guard)
}
