//! `kantele render`: colour, depth, normal and id images with a JSON sidecar.

use std::collections::HashSet;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use anyhow::{anyhow, bail, Result};
use indicatif::{ProgressBar, ProgressStyle};
use kantele::backend::{Backend, FrameImage, FrameView, Pass};
use kantele::scene::Scene;
use kantele_io::pose::sidecar::{
    DrawId, InstanceId, SidecarCamera, SidecarDepth, SidecarIds, SidecarNormals, ID_CHANNELS,
    MATRIX_LAYOUT,
};
use kantele_io::pose::{rows, Bounds, CameraPose, Sidecar, UpAxis};
use serde_json::json;

use crate::backends::make_backend;
use crate::cli::{DepthKind, RenderArgs};
use crate::output::{self, digits_for, expand_template, extension, has_placeholder, TemplateVars};
use crate::scenes::{self, Input, Warnings};

/// Elevation of the orbit cameras above the bounding sphere's equator.
pub const ORBIT_ELEVATION_DEG: f32 = 20.0;

/// Vertical field of view of the orbit cameras, degrees.
pub const ORBIT_YFOV_DEG: f32 = 45.0;

/// The files one image writes.
#[derive(Clone, Debug)]
struct Outputs {
    color: PathBuf,
    sidecar: PathBuf,
    depth: Option<PathBuf>,
    normals: Option<PathBuf>,
    ids: Option<PathBuf>,
}

fn check_ext(template: &str, flag: &str, allowed: &[&str]) -> Result<()> {
    let ext = extension(Path::new(template));
    if !allowed.contains(&ext.as_str()) {
        bail!(
            "{template}: unsupported file type for {flag} (use {})",
            allowed
                .iter()
                .map(|e| format!(".{e}"))
                .collect::<Vec<_>>()
                .join(" or ")
        );
    }
    Ok(())
}

/// Expands every output name and checks that no two images write the same file.
fn plan_outputs(args: &RenderArgs, inputs: &[Input], views: usize) -> Result<Vec<Vec<Outputs>>> {
    check_ext(&args.output, "-o", &["png", "exr"])?;
    let optional = [
        (&args.depth, "--depth", &["pfm", "exr"][..]),
        (&args.normals, "--normals", &["png", "exr"][..]),
        (&args.ids, "--ids", &["png", "exr"][..]),
    ];
    for (template, flag, allowed) in optional {
        if let Some(t) = template {
            check_ext(t, flag, allowed)?;
        }
    }
    let total = inputs.len() * views;
    if total > 1 {
        let all = std::iter::once(&args.output).chain(optional.iter().filter_map(|o| o.0.as_ref()));
        for t in all {
            if !has_placeholder(t) {
                bail!(
                    "{t}: {} images would be written to one file: use {{stem}}, {{index}} or {{frame}} in the name",
                    total
                );
            }
        }
    }
    let digits = digits_for(total.max(views));
    let mut seen = HashSet::new();
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
            let color = expand(&args.output)?;
            let mut sidecar = color.clone().into_os_string();
            sidecar.push(".json");
            let o = Outputs {
                sidecar: PathBuf::from(sidecar),
                color,
                depth: args.depth.as_ref().map(expand).transpose()?,
                normals: args.normals.as_ref().map(expand).transpose()?,
                ids: args.ids.as_ref().map(expand).transpose()?,
            };
            for p in [
                Some(&o.color),
                Some(&o.sidecar),
                o.depth.as_ref(),
                o.normals.as_ref(),
                o.ids.as_ref(),
            ]
            .into_iter()
            .flatten()
            {
                if !seen.insert(p.clone()) {
                    bail!(
                        "{}: would be written more than once (make the output names unique with {{stem}}, {{index}} or {{frame}})",
                        p.display()
                    );
                }
            }
            per_view.push(o);
        }
        plan.push(per_view);
    }
    Ok(plan)
}

/// The cameras of one scene at `width × height`: its own, or `n` orbit views.
fn cameras(
    scene: &Scene,
    orbit: Option<u32>,
    width: u32,
    height: u32,
    label: &str,
) -> Result<Vec<CameraPose>> {
    let Some(n) = orbit else {
        let pose = CameraPose::from_scene_camera(&scene.camera, width, height)
            .map_err(|e| anyhow!("{label}: camera: {e}"))?;
        return Ok(vec![pose]);
    };
    let bounds = Bounds::of_scene(scene)
        .ok_or_else(|| anyhow!("{label}: the scene draws nothing, so there is nothing to orbit"))?;
    CameraPose::orbit(
        &bounds,
        n,
        ORBIT_ELEVATION_DEG,
        None,
        UpAxis::Y,
        ORBIT_YFOV_DEG.to_radians(),
        width,
        height,
    )
    .map_err(|e| anyhow!("{label}: {e}"))
}

/// Highest ids of a scene's id pass: (instance, primitive, draw).
fn max_ids(scene: &Scene) -> (u64, u64, u64) {
    let instance = scene
        .draws
        .iter()
        .map(|d| d.node_index as u64 + 1)
        .max()
        .unwrap_or(0);
    let primitive = scene
        .draws
        .iter()
        .filter_map(|d| scene.meshes.get(d.mesh))
        .map(|m| m.triangle_count() as u64)
        .max()
        .unwrap_or(0);
    (instance, primitive, scene.draws.len() as u64)
}

fn check_id_range(scene: &Scene, ids_path: &Path) -> Result<()> {
    let (i, p, d) = max_ids(scene);
    let largest = i.max(p).max(d);
    let (limit, what) = match extension(ids_path).as_str() {
        "png" => (
            65535u64,
            "16-bit PNG cannot hold them; write the ids to .exr instead",
        ),
        _ => (
            1 << 24,
            "float EXR channels hold integers exactly only up to 2^24",
        ),
    };
    if largest > limit {
        bail!(
            "{}: ids reach {largest} (instances {i}, primitives {p}, draws {d}): {what}",
            ids_path.display()
        );
    }
    Ok(())
}

struct Rendered {
    color: FrameImage,
    normals: Option<FrameImage>,
    ids: Option<FrameImage>,
    ms: f64,
}

fn render_pass(
    backend: &mut dyn Backend,
    view: &FrameView,
    label: &str,
) -> Result<(FrameImage, f64)> {
    let start = Instant::now();
    backend.render(view).map_err(|e| anyhow!("{label}: {e}"))?;
    let ms = start.elapsed().as_secs_f64() * 1000.0;
    let frame = backend.read_frame().map_err(|e| anyhow!("{label}: {e}"))?;
    let n = view.width as usize * view.height as usize;
    if (frame.width, frame.height) != (view.width, view.height)
        || frame.color.len() != n
        || frame.depth.len() != n
    {
        bail!(
            "{label}: {} backend returned a {}x{} frame for a {}x{} view",
            backend.name(),
            frame.width,
            frame.height,
            view.width,
            view.height
        );
    }
    Ok((frame, ms))
}

fn write_color(path: &Path, frame: &FrameImage) -> Result<()> {
    if extension(path) == "exr" {
        let data: Vec<f32> = frame.color.iter().flatten().copied().collect();
        output::write_exr_rgba32f(path, frame.width, frame.height, &data)?;
    } else {
        output::write_png_rgba8(path, frame.width, frame.height, &frame.to_rgba8(true))?;
    }
    Ok(())
}

fn depth_values(frame: &FrameImage, kind: DepthKind, pose: &CameraPose) -> Vec<f32> {
    match kind {
        DepthKind::Window => frame.depth.clone(),
        DepthKind::Eye => pose.planar_depth(&frame.depth),
    }
}

fn write_depth(path: &Path, frame: &FrameImage, values: &[f32]) -> Result<()> {
    if extension(path) == "exr" {
        let rgb: Vec<f32> = values.iter().flat_map(|&v| [v, v, v]).collect();
        output::write_exr_rgb32f(path, frame.width, frame.height, &rgb)?;
    } else {
        output::write_pfm(path, frame.width, frame.height, values)?;
    }
    Ok(())
}

fn write_normals(path: &Path, frame: &FrameImage) -> Result<()> {
    let covered = |i: usize| frame.depth[i] < 1.0;
    if extension(path) == "exr" {
        let rgb: Vec<f32> = (0..frame.color.len())
            .flat_map(|i| {
                let c = frame.color[i];
                if covered(i) {
                    [c[0], c[1], c[2]]
                } else {
                    [0.0; 3]
                }
            })
            .collect();
        output::write_exr_rgb32f(path, frame.width, frame.height, &rgb)?;
    } else {
        let enc = |v: f32| ((v * 0.5 + 0.5).clamp(0.0, 1.0) * 255.0).round() as u8;
        let rgba: Vec<u8> = (0..frame.color.len())
            .flat_map(|i| {
                let c = frame.color[i];
                if covered(i) {
                    [enc(c[0]), enc(c[1]), enc(c[2]), 255]
                } else {
                    [0; 4]
                }
            })
            .collect();
        output::write_png_rgba8(path, frame.width, frame.height, &rgba)?;
    }
    Ok(())
}

fn write_ids(path: &Path, frame: &FrameImage) -> Result<()> {
    let id = |v: f32| -> Result<u32> {
        if v.is_finite() && v >= 0.0 && v.fract() == 0.0 && v <= 16_777_216.0 {
            Ok(v as u32)
        } else {
            Err(anyhow!(
                "{}: the backend's id pass holds a non-integer id {v}",
                path.display()
            ))
        }
    };
    if extension(path) == "exr" {
        let rgb: Vec<f32> = frame
            .color
            .iter()
            .flat_map(|c| [c[0], c[1], c[2]])
            .collect();
        for &v in &rgb {
            id(v)?;
        }
        output::write_exr_rgb32f(path, frame.width, frame.height, &rgb)?;
    } else {
        let mut rgb = Vec::with_capacity(frame.color.len() * 3);
        for c in &frame.color {
            for &v in &c[..3] {
                let v = id(v)?;
                let v = u16::try_from(v).map_err(|_| {
                    anyhow!(
                        "{}: id {v} does not fit 16-bit PNG; write the ids to .exr instead",
                        path.display()
                    )
                })?;
                rgb.push(v);
            }
        }
        output::write_png_rgb16(path, frame.width, frame.height, &rgb)?;
    }
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn sidecar(
    args: &RenderArgs,
    input: &Input,
    loaded_source: &str,
    scene: &Scene,
    pose: &CameraPose,
    out: &Outputs,
    backend: &dyn Backend,
    ms: f64,
) -> Sidecar {
    let path = |p: &PathBuf| p.display().to_string();
    let depth_file = out.depth.as_ref().map(path);
    let depth = match args.depth_kind {
        DepthKind::Eye => SidecarDepth::eye(depth_file),
        DepthKind::Window => SidecarDepth::window(depth_file),
    };
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
    let draw_ids = scene
        .draws
        .iter()
        .enumerate()
        .map(|(i, d)| DrawId {
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
    Sidecar {
        scene: input.stem(),
        source: loaded_source.to_string(),
        output: path(&out.color),
        width: pose.width,
        height: pose.height,
        backend: backend.name().to_string(),
        renderer: backend.renderer(),
        threads: backend.threads(),
        render_ms: ms,
        camera: SidecarCamera::of_pose(pose),
        world_to_camera_gl: rows(&pose.view()),
        world_to_camera_opencv: rows(&pose.world_to_camera_opencv()),
        matrix_layout: MATRIX_LAYOUT.into(),
        depth,
        normals: out.normals.as_ref().map(|p| SidecarNormals {
            file: path(p),
            encoding: if extension(p) == "exr" {
                "world-space unit normal as float RGB, background 0"
            } else {
                "world-space unit normal n as 8-bit linear (n * 0.5 + 0.5) * 255 in RGB, alpha 255; background 0 0 0 0"
            }
            .into(),
        }),
        ids: SidecarIds {
            file: out.ids.as_ref().map(path),
            channels: ID_CHANNELS.into(),
            instance_ids,
            draw_ids,
        },
    }
}

/// Runs `kantele render`.
pub fn run(args: &RenderArgs) -> Result<()> {
    let inputs = scenes::inputs(&args.input)?;
    let views = args.orbit.unwrap_or(1) as usize;
    let plan = plan_outputs(args, &inputs, views)?;
    let total = inputs.len() * views;

    let mut backend = make_backend(args.backend, &args.cpu, false)?;
    let progress = if total > 1 && std::io::stderr().is_terminal() {
        let pb = ProgressBar::new(total as u64);
        if let Ok(style) =
            ProgressStyle::with_template("{bar:40} {pos}/{len} {msg} [{elapsed_precise} < {eta}]")
        {
            pb.set_style(style);
        }
        pb
    } else {
        ProgressBar::hidden()
    };
    let mut warnings = Warnings::default();

    for (input, outs) in inputs.iter().zip(&plan) {
        let label = input.label();
        progress.set_message(input.stem());
        let loaded = input.load()?;
        warnings.report(&loaded, |w| progress.suspend(|| eprintln!("{w}")));
        let source = loaded.info.source.clone();
        let scene = Arc::new(loaded.scene);
        let (width, height) = match args.size {
            Some(s) => s,
            None => {
                let (w, h) = scene.resolution;
                if w == 0 || h == 0 || w > kantele::MAX_TARGET_SIZE || h > kantele::MAX_TARGET_SIZE
                {
                    bail!("{label}: the scene asks for an image of {w}x{h}, outside 1..={}; use --size", kantele::MAX_TARGET_SIZE);
                }
                (w, h)
            }
        };
        if let Some(ids) = &args.ids {
            check_id_range(&scene, Path::new(ids))?;
        }
        backend
            .load(scene.clone())
            .map_err(|e| anyhow!("{label}: {e}"))?;
        let cams = cameras(&scene, args.orbit, width, height, &label)?;
        for (pose, out) in cams.iter().zip(outs) {
            let mut view = pose.frame_view(&scene, Pass::Color);
            let (color, ms) = render_pass(backend.as_mut(), &view, &label)?;
            let mut rendered = Rendered {
                color,
                normals: None,
                ids: None,
                ms,
            };
            if out.normals.is_some() {
                view.pass = Pass::Normals;
                rendered.normals = Some(render_pass(backend.as_mut(), &view, &label)?.0);
            }
            if out.ids.is_some() {
                view.pass = Pass::Ids;
                rendered.ids = Some(render_pass(backend.as_mut(), &view, &label)?.0);
            }
            view.pass = Pass::Color;

            write_color(&out.color, &rendered.color)?;
            if let Some(p) = &out.depth {
                write_depth(
                    p,
                    &rendered.color,
                    &depth_values(&rendered.color, args.depth_kind, pose),
                )?;
            }
            if let (Some(p), Some(f)) = (&out.normals, &rendered.normals) {
                write_normals(p, f)?;
            }
            if let (Some(p), Some(f)) = (&out.ids, &rendered.ids) {
                write_ids(p, f)?;
            }
            let meta = sidecar(
                args,
                input,
                &source,
                &scene,
                pose,
                out,
                backend.as_ref(),
                rendered.ms,
            );
            output::write_atomic(&out.sidecar, |w| {
                serde_json::to_writer_pretty(&mut *w, &meta)?;
                std::io::Write::write_all(w, b"\n")
            })?;
            if args.json {
                let line = json!({
                    "scene": input.stem(),
                    "output": out.color.display().to_string(),
                    "width": width,
                    "height": height,
                    "ms": rendered.ms,
                });
                progress.suspend(|| println!("{line}"));
            }
            progress.inc(1);
        }
    }
    progress.finish_and_clear();
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn synthetic() -> FrameImage {
        // 3x2: background, then covered pixels with ids / normals / colours.
        FrameImage {
            width: 3,
            height: 2,
            color: vec![
                [0.0, 0.0, 0.0, 0.0],
                [1.0, 2.0, 3.0, 1.0],
                [300.0, 65535.0, 7.0, 1.0],
                [0.0, 0.0, 1.0, 1.0],
                [0.0, -1.0, 0.0, 1.0],
                [1.0, 0.0, 0.0, 1.0],
            ],
            depth: vec![1.0, 0.5, 0.25, 0.75, 0.1, 0.9],
        }
    }

    fn tmp(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("kantele-render-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(name)
    }

    #[test]
    fn ids_png_is_16_bit_with_exact_values() {
        let p = tmp("ids.png");
        let mut ids = synthetic();
        ids.color[4] = [4.0, 5.0, 6.0, 1.0];
        write_ids(&p, &ids).unwrap();
        let img = image::open(&p).unwrap();
        assert_eq!(img.color(), image::ColorType::Rgb16);
        let img = img.to_rgb16();
        assert_eq!(img.get_pixel(0, 0).0, [0, 0, 0]);
        assert_eq!(img.get_pixel(1, 0).0, [1, 2, 3]);
        assert_eq!(img.get_pixel(2, 0).0, [300, 65535, 7]);
        std::fs::remove_file(&p).unwrap();

        let mut big = ids.clone();
        big.color[1][1] = 65536.0;
        let err = write_ids(&p, &big).unwrap_err().to_string();
        assert!(err.contains(".exr"), "{err}");
        assert!(!p.exists());

        let e = tmp("ids.exr");
        write_ids(&e, &big).unwrap();
        let img = image::open(&e).unwrap().to_rgb32f();
        assert_eq!(img.get_pixel(1, 0).0, [1.0, 65536.0, 3.0]);
        std::fs::remove_file(&e).unwrap();
    }

    #[test]
    fn normals_png_encoding() {
        let p = tmp("n.png");
        write_normals(&p, &synthetic()).unwrap();
        let img = image::open(&p).unwrap().to_rgba8();
        assert_eq!(img.get_pixel(0, 0).0, [0, 0, 0, 0]);
        assert_eq!(img.get_pixel(0, 1).0, [128, 128, 255, 255]);
        assert_eq!(img.get_pixel(1, 1).0, [128, 0, 128, 255]);
        std::fs::remove_file(&p).unwrap();
    }

    #[test]
    fn depth_files() {
        let frame = synthetic();
        let view = CameraPose::new(
            3,
            2,
            kantele_io::pose::Projection::Perspective { yfov: 1.0 },
            0.5,
            Some(10.0),
            glam::Mat4::IDENTITY,
        )
        .unwrap();
        let eye = depth_values(&frame, DepthKind::Eye, &view);
        assert!(eye[0].is_infinite());
        assert!(eye[1..]
            .iter()
            .all(|d| d.is_finite() && *d >= 0.5 && *d <= 10.0));
        let p = tmp("d.pfm");
        write_depth(&p, &frame, &eye).unwrap();
        let (w, h, back) = kantele_io::output::decode_pfm(&std::fs::read(&p).unwrap()).unwrap();
        assert_eq!((w, h), (3, 2));
        assert_eq!(back, eye);
        std::fs::remove_file(&p).unwrap();
        let e = tmp("d.exr");
        let window = depth_values(&frame, DepthKind::Window, &view);
        write_depth(&e, &frame, &window).unwrap();
        let img = image::open(&e).unwrap().to_rgb32f();
        assert_eq!(img.get_pixel(0, 0).0, [1.0; 3]);
        assert_eq!(img.get_pixel(2, 1).0, [0.9; 3]);
        std::fs::remove_file(&e).unwrap();
    }

    #[test]
    fn orbit_cameras_circle_the_scene() {
        let mut scene = Scene::default();
        scene.meshes.push(kantele::scene::Mesh {
            positions: vec![
                Vec3::new(-1.0, -1.0, -1.0),
                Vec3::new(1.0, 1.0, 1.0),
                Vec3::X,
            ],
            indices: vec![0, 1, 2],
            ..Default::default()
        });
        scene.materials.push(Default::default());
        scene.draws.push(kantele::scene::Draw {
            mesh: 0,
            model: glam::Mat4::IDENTITY,
            node_name: "n".into(),
            node_index: 0,
        });
        let cams = cameras(&scene, Some(4), 64, 64, "x").unwrap();
        assert_eq!(cams.len(), 4);
        let eyes: Vec<Vec3> = cams.iter().map(|c| c.eye()).collect();
        let d0 = eyes[0].length();
        for e in &eyes {
            assert!((e.length() - d0).abs() < 1e-3);
            assert!(e.y > 0.0);
        }
        assert!(eyes[0].z > 0.0 && eyes[1].x > 0.0 && eyes[2].z < 0.0 && eyes[3].x < 0.0);
        assert!(cameras(&Scene::default(), Some(2), 64, 64, "x").is_err());
    }
}
