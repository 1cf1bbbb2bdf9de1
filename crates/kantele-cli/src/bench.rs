//! `kantele bench`: frame times per scene and backend, by the timing rules of the reference
//! scenes (warm-up, then N timed `render()` calls; median, min, max).

use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Result};
use kantele::backend::{Backend, FrameView};
use kantele::stats::FrameStats;
use serde_json::json;

use crate::backends::make_backend;
use crate::cli::BenchArgs;
use crate::scenes::{self, Warnings};

/// Summary of timed frames in milliseconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Timing {
    /// Median (mean of the two middle values for an even count).
    pub median: f64,
    /// Fastest frame.
    pub min: f64,
    /// Slowest frame.
    pub max: f64,
}

/// Median milliseconds of each stage over the timed frames, as the backend reports them
/// ([`kantele::stats::FrameStats`]): where a frame's time goes, and how much of it runs serially
/// when the thread count changes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StageTimes {
    /// Vertex shading, primitive assembly, clipping, culling and setup.
    pub geometry: f64,
    /// Sorting triangles into tile bins.
    pub binning: f64,
    /// Rasterizing, shading and merging on every tile.
    pub raster: f64,
}

impl StageTimes {
    /// The medians of `stages` (one `[geometry, binning, raster]` per frame, milliseconds);
    /// `None` for no frames, or when every stage time is zero (a backend that does not time
    /// its stages, such as OpenGL's).
    pub fn median_of(stages: &[[f64; 3]]) -> Option<Self> {
        if stages.iter().flatten().all(|&t| t == 0.0) {
            return None;
        }
        let median = |k: usize| -> Option<f64> {
            let times: Vec<f64> = stages.iter().map(|s| s[k]).collect();
            summarize(&times).map(|t| t.median)
        };
        Some(Self {
            geometry: median(0)?,
            binning: median(1)?,
            raster: median(2)?,
        })
    }
}

/// What the last timed frame drew, as the backend counts it ([`FrameStats`]): the same every
/// frame for a fixed view, so frame times can be read per fragment or per triangle (the
/// instructions-per-fragment figures of BENCHMARKS.md).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameWork {
    /// Triangles handed to binning (after clipping, culling and degenerate removal).
    pub triangles_binned: u64,
    /// Triangle references written to tile bins.
    pub bin_entries: u64,
    /// Pixels covered by triangles, outside tiles rejected by depth.
    pub fragments_covered: u64,
    /// Fragments that passed the early depth test and were shaded.
    pub fragments_shaded: u64,
}

impl FrameWork {
    /// The counts of `stats`; `None` when it counts nothing (a backend that does not count,
    /// such as OpenGL's).
    pub fn of(stats: &FrameStats) -> Option<Self> {
        let work = Self {
            triangles_binned: stats.triangles_binned,
            bin_entries: stats.bin_entries,
            fragments_covered: stats.fragments_covered,
            fragments_shaded: stats.fragments_shaded,
        };
        (work != Self::default()).then_some(work)
    }
}

/// Timed frames: the whole frames, and their stages where the backend times them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameTimes {
    /// Whole frames.
    pub frames: Timing,
    /// Median stage times.
    pub stages: Option<StageTimes>,
    /// What the last timed frame drew, where the backend counts it.
    pub work: Option<FrameWork>,
    /// Untimed warm-up frames rendered before them.
    pub warmup_frames: u64,
}

/// Median, min and max of frame times; `None` for no frames.
pub fn summarize(times: &[f64]) -> Option<Timing> {
    if times.is_empty() {
        return None;
    }
    let mut t = times.to_vec();
    t.sort_by(f64::total_cmp);
    let n = t.len();
    let median = if n % 2 == 1 {
        t[n / 2]
    } else {
        (t[n / 2 - 1] + t[n / 2]) / 2.0
    };
    Some(Timing {
        median,
        min: t[0],
        max: t[n - 1],
    })
}

/// A backend, or why it could not start.
type MaybeBackend = Result<Box<dyn Backend>, String>;

struct Row {
    scene: String,
    width: u32,
    height: u32,
    triangles: usize,
    draws: usize,
    backend: String,
    renderer: String,
    threads: usize,
    isa: String,
    /// How colour frames are stored (`f32`, `srgb8`, `rgba8`).
    target: String,
    /// Samples per pixel of the colour frames.
    msaa: usize,
    result: Result<FrameTimes, String>,
    ratio: Option<f64>,
}

/// The untimed warm-up of one scene on one backend: at least `frames` frames and at least `time`.
#[derive(Clone, Copy, Debug)]
struct Warmup {
    frames: u32,
    time: Duration,
}

impl Warmup {
    /// Calls `render` until both this many frames and this long have passed; returns how many
    /// frames that took, or the first error.
    fn run<E>(&self, mut render: impl FnMut() -> Result<(), E>) -> Result<u64, E> {
        let start = Instant::now();
        let mut done = 0u64;
        while done < u64::from(self.frames) || start.elapsed() < self.time {
            render()?;
            done += 1;
        }
        Ok(done)
    }
}

/// Warms `backend` up on `view`, then times `frames` frames.
fn time_frames(
    backend: &mut dyn Backend,
    view: &FrameView,
    warmup: Warmup,
    frames: u32,
) -> Result<FrameTimes, String> {
    let warmup_frames = warmup
        .run(|| backend.render(view).map(drop))
        .map_err(|e| e.to_string())?;
    let mut times = Vec::with_capacity(frames as usize);
    let mut stages = Vec::with_capacity(frames as usize);
    let mut last = None;
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1000.0;
    for _ in 0..frames {
        let start = Instant::now();
        let stats = backend.render(view).map_err(|e| e.to_string())?;
        times.push(ms(start.elapsed()));
        stages.push([
            ms(stats.geometry_time),
            ms(stats.binning_time),
            ms(stats.raster_time),
        ]);
        last = Some(stats);
    }
    let frames = summarize(&times).ok_or_else(|| "no frames timed".to_string())?;
    Ok(FrameTimes {
        frames,
        stages: StageTimes::median_of(&stages),
        work: last.as_ref().and_then(FrameWork::of),
        warmup_frames,
    })
}

fn print_table(rows: &[Row], ratios: bool) {
    let mut header = format!(
        "{:<24} {:>11} {:>10} {:>6}  {:<7} {:<36} {:>7} {:<6} {:<6} {:>4} {:>10} {:>10} {:>10}",
        "scene",
        "size",
        "triangles",
        "draws",
        "backend",
        "renderer",
        "threads",
        "isa",
        "target",
        "msaa",
        "median ms",
        "min ms",
        "max ms"
    );
    if ratios {
        header.push_str(&format!(" {:>8}", "ratio"));
    }
    println!("{header}");
    for r in rows {
        let size = format!("{}x{}", r.width, r.height);
        let mut line = format!(
            "{:<24} {:>11} {:>10} {:>6}  {:<7} {:<36} {:>7} {:<6} {:<6} {:>4}",
            r.scene,
            size,
            r.triangles,
            r.draws,
            r.backend,
            r.renderer,
            r.threads,
            r.isa,
            r.target,
            r.msaa
        );
        match &r.result {
            Ok(FrameTimes { frames: t, .. }) => {
                line.push_str(&format!(
                    " {:>10.3} {:>10.3} {:>10.3}",
                    t.median, t.min, t.max
                ));
                if ratios {
                    match r.ratio {
                        Some(x) => line.push_str(&format!(" {x:>8.3}")),
                        None => line.push_str(&format!(" {:>8}", "-")),
                    }
                }
            }
            Err(e) => line.push_str(&format!(" unavailable: {e}")),
        }
        println!("{line}");
    }
}

/// With several backends: one row per scene, a median column per backend, and each backend's
/// ratio to the first (the layout of the thesis' comparison tables).
fn print_side_by_side(rows: &[Row], backends: &[String]) {
    println!();
    for name in backends {
        if let Some(r) = rows.iter().find(|r| &r.backend == name && r.result.is_ok()) {
            println!(
                "{name}: {} ({} threads, isa {}, target {}, msaa {})",
                r.renderer, r.threads, r.isa, r.target, r.msaa
            );
        }
    }
    let mut header = format!(
        "{:<24} {:>11} {:>10} {:>6}",
        "scene", "size", "triangles", "draws"
    );
    for name in backends {
        header.push_str(&format!(" {:>10}", format!("{name} ms")));
    }
    for name in &backends[1..] {
        header.push_str(&format!(" {:>10}", format!("{name}/{}", backends[0])));
    }
    println!("{header}");
    for scene_rows in rows.chunks(backends.len()) {
        let first = &scene_rows[0];
        let size = format!("{}x{}", first.width, first.height);
        let mut line = format!(
            "{:<24} {:>11} {:>10} {:>6}",
            first.scene, size, first.triangles, first.draws
        );
        for r in scene_rows {
            match &r.result {
                Ok(t) => line.push_str(&format!(" {:>10.2}", t.frames.median)),
                Err(_) => line.push_str(&format!(" {:>10}", "-")),
            }
        }
        for r in &scene_rows[1..] {
            match r.ratio {
                Some(x) => line.push_str(&format!(" {x:>10.2}")),
                None => line.push_str(&format!(" {:>10}", "-")),
            }
        }
        println!("{line}");
    }
    // Geometric mean of each ratio column, over the scenes where both backends rendered.
    let mut line = format!("{:<24} {:>11} {:>10} {:>6}", "geometric mean", "", "", "");
    line.push_str(&" ".repeat(11 * backends.len()));
    for column in 1..backends.len() {
        let ratios: Vec<f64> = rows
            .chunks(backends.len())
            .filter_map(|scene_rows| scene_rows.get(column).and_then(|r| r.ratio))
            .collect();
        match geometric_mean(&ratios) {
            Some(g) => line.push_str(&format!(" {g:>10.2}")),
            None => line.push_str(&format!(" {:>10}", "-")),
        }
    }
    println!("{line}");
}

/// The geometric mean of positive values (`None` for none).
fn geometric_mean(values: &[f64]) -> Option<f64> {
    if values.is_empty() || values.iter().any(|v| v.is_nan() || *v <= 0.0) {
        return None;
    }
    Some((values.iter().map(|v| v.ln()).sum::<f64>() / values.len() as f64).exp())
}

/// Runs `kantele bench`.
pub fn run(args: &BenchArgs) -> Result<()> {
    let inputs = scenes::inputs(&args.input)?;
    if args.backends.is_empty() {
        bail!("--backend: no backend given");
    }
    let several = args.backends.len() > 1;
    // Each backend is created once and reused for every scene.
    let mut backends: Vec<(String, MaybeBackend)> = Vec::new();
    for kind in &args.backends {
        match make_backend(*kind, &args.cpu, true) {
            Ok(b) => backends.push((kind.name().to_string(), Ok(b))),
            Err(e) if several => {
                eprintln!("kantele: warning: {e}; continuing without it");
                backends.push((kind.name().to_string(), Err(e.to_string())));
            }
            Err(e) => return Err(e),
        }
    }

    let warmup = Warmup {
        frames: args.warmup,
        time: Duration::from_millis(args.warmup_ms),
    };
    let mut warnings = Warnings::default();
    let mut rows = Vec::new();
    for input in &inputs {
        let label = input.label();
        let loaded = input.load()?;
        warnings.report(&loaded, |w| eprintln!("{w}"));
        let scene = Arc::new(loaded.scene);
        let (width, height) = args.size.unwrap_or(scene.resolution);
        let view = FrameView::with_camera(&scene, &scene.camera, width, height);
        let mut reference: Option<f64> = None;
        let mut any_ok = false;
        for (i, (name, backend)) in backends.iter_mut().enumerate() {
            let msaa = backend.as_ref().map_or(0, |b| b.samples().count());
            let target = backend.as_ref().map_or("-".to_string(), |b| b.target());
            let (renderer, threads, isa, result) = match backend {
                Ok(b) => {
                    let result = b
                        .load(scene.clone())
                        .map_err(|e| e.to_string())
                        .and_then(|()| time_frames(b.as_mut(), &view, warmup, args.frames));
                    (b.renderer(), b.threads(), b.isa(), result)
                }
                Err(e) => ("-".to_string(), 0, "-".to_string(), Err(e.clone())),
            };
            if let Err(e) = &result {
                if !several {
                    bail!("{label}: {e}");
                }
                eprintln!("kantele: warning: {label}: {name}: {e}");
            }
            let median = result.as_ref().ok().map(|t| t.frames.median);
            any_ok |= median.is_some();
            if i == 0 {
                reference = median;
            }
            let ratio = match (median, reference) {
                (Some(m), Some(r)) if i > 0 && r > 0.0 => Some(m / r),
                _ => None,
            };
            let row = Row {
                scene: input.stem(),
                width,
                height,
                triangles: scene.triangle_count(),
                draws: scene.draws.len(),
                backend: name.clone(),
                renderer,
                threads,
                isa,
                target,
                msaa,
                result,
                ratio,
            };
            if args.json {
                // Every figure is null when the backend could not render the scene.
                let timed = row.result.as_ref().ok();
                let error = row.result.as_ref().err();
                let (stages, work) = (timed.and_then(|t| t.stages), timed.and_then(|t| t.work));
                println!(
                    "{}",
                    json!({
                        "scene": row.scene, "source": loaded.info.source,
                        "width": row.width, "height": row.height,
                        "triangles": row.triangles, "draws": row.draws,
                        "backend": row.backend, "renderer": row.renderer, "threads": row.threads, "isa": row.isa, "target": row.target, "msaa": row.msaa,
                        "frames": args.frames, "warmup": args.warmup, "warmup_ms": args.warmup_ms,
                        "warmup_frames": timed.map(|t| t.warmup_frames),
                        // How this binary was compiled (build.rs): figures name their build.
                        "build": env!("KANTELE_BUILD"),
                        "median_ms": timed.map(|t| t.frames.median),
                        "min_ms": timed.map(|t| t.frames.min),
                        "max_ms": timed.map(|t| t.frames.max),
                        "geometry_ms": stages.map(|s| s.geometry),
                        "binning_ms": stages.map(|s| s.binning),
                        "raster_ms": stages.map(|s| s.raster),
                        "triangles_binned": work.map(|w| w.triangles_binned),
                        "bin_entries": work.map(|w| w.bin_entries),
                        "fragments_covered": work.map(|w| w.fragments_covered),
                        "fragments_shaded": work.map(|w| w.fragments_shaded),
                        "ratio": row.ratio, "available": error.is_none(), "error": error,
                    })
                );
            }
            rows.push(row);
        }
        if !any_ok {
            if !args.json {
                print_table(&rows, several);
            }
            return Err(anyhow!("{label}: no backend could render it"));
        }
    }
    if !args.json {
        print_table(&rows, several);
        if several {
            let names: Vec<String> = backends.iter().map(|(n, _)| n.clone()).collect();
            print_side_by_side(&rows, &names);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summary() {
        assert_eq!(summarize(&[]), None);
        let t = summarize(&[3.0, 1.0, 2.0]).unwrap();
        assert_eq!((t.median, t.min, t.max), (2.0, 1.0, 3.0));
        let t = summarize(&[4.0, 1.0, 2.0, 3.0]).unwrap();
        assert_eq!((t.median, t.min, t.max), (2.5, 1.0, 4.0));
    }

    #[test]
    fn stage_medians_per_stage_and_none_without_stage_times() {
        assert_eq!(StageTimes::median_of(&[]), None);
        assert_eq!(StageTimes::median_of(&[[0.0; 3], [0.0; 3]]), None);
        let s = StageTimes::median_of(&[[1.0, 0.5, 9.0], [3.0, 0.0, 7.0], [2.0, 0.25, 8.0]]);
        assert_eq!(
            s,
            Some(StageTimes {
                geometry: 2.0,
                binning: 0.25,
                raster: 8.0
            })
        );
    }

    #[test]
    fn warm_up_lasts_for_both_its_frames_and_its_time() {
        let count = |warmup: Warmup, frame: Duration| {
            warmup.run(|| {
                std::thread::sleep(frame);
                Ok::<(), ()>(())
            })
        };
        let frames_only = Warmup {
            frames: 3,
            time: Duration::ZERO,
        };
        assert_eq!(count(frames_only, Duration::ZERO), Ok(3));
        // 40 ms of 1 ms frames: at least one frame per elapsed millisecond is impossible to
        // exceed, so the count is at most 40 and more than the 3 frames asked for.
        let timed = Warmup {
            frames: 3,
            time: Duration::from_millis(40),
        };
        let start = Instant::now();
        let n = count(timed, Duration::from_millis(1)).unwrap();
        assert!(start.elapsed() >= Duration::from_millis(40));
        assert!((4..=40).contains(&n), "{n} frames");
        // Slow frames: the frame count still holds.
        let slow = Warmup {
            frames: 2,
            time: Duration::from_millis(1),
        };
        assert_eq!(count(slow, Duration::from_millis(5)), Ok(2));
        // No warm-up at all, and the first error ends it.
        let none = Warmup {
            frames: 0,
            time: Duration::ZERO,
        };
        assert_eq!(count(none, Duration::ZERO), Ok(0));
        let mut calls = 0;
        let failing = timed.run(|| {
            calls += 1;
            Err::<(), _>("lost")
        });
        assert_eq!((failing, calls), (Err("lost"), 1));
    }

    #[test]
    fn geometric_mean_of_ratios() {
        assert_eq!(geometric_mean(&[]), None);
        assert_eq!(geometric_mean(&[2.0, 0.0]), None);
        let g = geometric_mean(&[2.0, 8.0]).unwrap();
        assert!((g - 4.0).abs() < 1e-12, "{g}");
    }
}
