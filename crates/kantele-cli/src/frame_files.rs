//! The files of one rendered image: what each holds (colour, depth, normals, ids) as values
//! computed from a rendered frame or band; the encoding is in [`crate::frame_writer`].

use std::io;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Result};
use glam::{Mat3, Vec3};
use kantele::backend::FrameImage;
use kantele::scene::Scene;
use kantele_output::output::OutputSet;
use kantele_output::pose::CameraPose;

use crate::cli::{DepthKind, DepthUnit, IdKind, NormalSpace};
use crate::output::extension;

/// File types each output accepts.
pub const COLOR_TYPES: &[&str] = &["png", "exr", "npy"];
/// File types of `--depth`.
pub const DEPTH_TYPES: &[&str] = &["png", "exr", "pfm", "npy"];
/// File types of `--normals`.
pub const NORMAL_TYPES: &[&str] = &["png", "exr", "npy"];
/// File types of `--ids`.
pub const ID_TYPES: &[&str] = &["png", "exr", "npy"];

/// Largest id a 16-bit PNG holds.
const PNG_MAX_ID: u64 = u16::MAX as u64;

fn io_err(e: anyhow::Error) -> io::Error {
    io::Error::other(format!("{e:#}"))
}

/// Checks that `path`'s extension is one of `allowed`.
pub fn check_type(path: &str, flag: &str, allowed: &[&str]) -> Result<()> {
    let ext = extension(Path::new(path));
    if !allowed.contains(&ext.as_str()) {
        bail!(
            "{path}: unsupported file type for {flag} (use {})",
            allowed
                .iter()
                .map(|e| format!(".{e}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    Ok(())
}

/// Depth values of a frame, or of a band of it starting at picture row `first_row` (eye and
/// ray depth in `unit`), background `+inf` (window: 1).
pub fn depth_values(
    frame: &FrameImage,
    kind: DepthKind,
    unit: DepthUnit,
    pose: &CameraPose,
    first_row: u32,
) -> Vec<f32> {
    let scale = match unit {
        DepthUnit::M => 1.0,
        DepthUnit::Mm => 1000.0,
    };
    let mut values = match kind {
        DepthKind::Window => return frame.depth.clone(),
        DepthKind::Eye => pose.planar_depth(&frame.depth),
        DepthKind::Ray => pose.ray_depth_rows(&frame.depth, first_row),
    };
    if scale != 1.0 {
        for v in &mut values {
            *v *= scale;
        }
    }
    values
}

/// 16-bit PNG depth (BOP): `round(value)`, 0 = background; a value that does not fit is an
/// error naming the largest.
pub fn depth_png(values: &[f32], path: &Path) -> Result<Vec<u16>> {
    let mut largest = 0.0f32;
    let out = values
        .iter()
        .map(|&v| {
            if !v.is_finite() {
                0
            } else {
                largest = largest.max(v);
                v.round().clamp(0.0, 65535.0) as u16
            }
        })
        .collect();
    if largest.round() > 65535.0 {
        bail!(
            "{}: depth reaches {largest}, more than a 16-bit PNG holds (use --depth-unit m, or .exr, .pfm or .npy)",
            path.display()
        );
    }
    Ok(out)
}

/// Unit normals of a normals-pass frame in `space` (camera: OpenCV axes), background 0.
pub fn normal_values(frame: &FrameImage, space: NormalSpace, pose: &CameraPose) -> Vec<[f32; 3]> {
    let rotation = Mat3::from_mat4(pose.world_to_camera_opencv());
    frame
        .color
        .iter()
        .zip(&frame.depth)
        .map(|(c, &d)| {
            if d >= 1.0 {
                return [0.0; 3];
            }
            let n = Vec3::new(c[0], c[1], c[2]);
            match space {
                NormalSpace::World => n.to_array(),
                NormalSpace::Camera => (rotation * n).normalize_or_zero().to_array(),
            }
        })
        .collect()
}

/// The largest id of `kind` the scene can produce (0 when it draws nothing).
pub fn max_id(scene: &Scene, kind: IdKind) -> u64 {
    let draws = scene.draws.iter();
    match kind {
        IdKind::Instance => draws.map(|d| d.node_index as u64 + 1).max().unwrap_or(0),
        IdKind::Primitive => scene.draws.len() as u64,
        IdKind::Mesh => draws.map(|d| d.mesh as u64 + 1).max().unwrap_or(0),
        IdKind::Material => draws
            .filter_map(|d| scene.meshes.get(d.mesh))
            .map(|m| m.material as u64 + 1)
            .max()
            .unwrap_or(0),
        IdKind::Triangle => draws
            .filter_map(|d| scene.meshes.get(d.mesh))
            .map(|m| m.triangle_count() as u64)
            .max()
            .unwrap_or(0),
    }
}

/// Refuses, before rendering, an id file whose format cannot hold the scene's ids.
pub fn check_id_range(scene: &Scene, kind: IdKind, path: &Path) -> Result<()> {
    let largest = max_id(scene, kind);
    let exact = kantele::state::ids::MAX_EXACT_ID as u64;
    if largest > exact {
        bail!(
            "{}: {} ids reach {largest}, beyond the {exact} the id pass carries exactly",
            path.display(),
            kind.name()
        );
    }
    if extension(path) == "png" && largest > PNG_MAX_ID {
        bail!(
            "{}: {} ids reach {largest}, more than a 16-bit PNG holds; write them to .exr or .npy (32-bit)",
            path.display(),
            kind.name()
        );
    }
    Ok(())
}

/// One id per pixel of `kind`, from an ids-pass frame (`(instance, triangle, draw)`).
pub fn id_values(frame: &FrameImage, scene: &Scene, kind: IdKind) -> Result<Vec<u32>> {
    let exact = |v: f32| -> Result<u32> {
        if v.is_finite() && v >= 0.0 && v.fract() == 0.0 && v <= 16_777_216.0 {
            Ok(v as u32)
        } else {
            Err(anyhow!("the backend's id pass holds a non-integer id {v}"))
        }
    };
    frame
        .color
        .iter()
        .map(|c| {
            let draw = exact(c[2])?;
            if draw == 0 {
                return Ok(0);
            }
            let d = scene
                .draws
                .get(draw as usize - 1)
                .ok_or_else(|| anyhow!("the id pass names draw {draw}, which does not exist"))?;
            let mesh_material = || {
                scene
                    .meshes
                    .get(d.mesh)
                    .map_or(0, |m| m.material as u32 + 1)
            };
            Ok(match kind {
                IdKind::Instance => exact(c[0])?,
                IdKind::Triangle => exact(c[1])?,
                IdKind::Primitive => draw,
                IdKind::Mesh => d.mesh as u32 + 1,
                IdKind::Material => mesh_material(),
            })
        })
        .collect()
}

/// The sidecar, last file of the set.
pub fn write_json(set: &mut OutputSet, path: &Path, value: &impl serde::Serialize) -> Result<()> {
    set.write(path, |w| {
        serde_json::to_writer_pretty(&mut *w, value).map_err(|e| io_err(e.into()))?;
        io::Write::write_all(w, b"\n")
    })?;
    Ok(())
}

/// The paths of one image's files.
#[derive(Clone, Debug, Default)]
pub struct FramePaths {
    /// Colour image (`None`: standard output).
    pub color: Option<PathBuf>,
    /// JSON sidecar (`None` with standard output).
    pub sidecar: Option<PathBuf>,
    /// Depth image.
    pub depth: Option<PathBuf>,
    /// Normal image.
    pub normals: Option<PathBuf>,
    /// Id images by kind.
    pub ids: Vec<(IdKind, PathBuf)>,
}

impl FramePaths {
    /// Every file this image writes.
    pub fn all(&self) -> impl Iterator<Item = &PathBuf> {
        self.color
            .iter()
            .chain(&self.sidecar)
            .chain(&self.depth)
            .chain(&self.normals)
            .chain(self.ids.iter().map(|(_, p)| p))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn synthetic() -> FrameImage {
        // 3x2: background, then covered pixels.
        FrameImage {
            width: 3,
            height: 2,
            color: vec![
                [0.0, 0.0, 0.0, 0.0],
                [1.0, 2.0, 1.0, 1.0],
                [300.0, 65535.0, 2.0, 1.0],
                [0.0, 0.0, 1.0, 1.0],
                [0.0, -1.0, 0.0, 1.0],
                [1.0, 0.0, 0.0, 1.0],
            ],
            depth: vec![1.0, 0.5, 0.25, 0.75, 0.1, 0.9],
        }
    }

    fn two_draw_scene() -> Scene {
        let mut scene = Scene::default();
        for material in [0, 3] {
            scene.meshes.push(kantele::scene::Mesh {
                positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
                indices: vec![0, 1, 2],
                material,
                ..Default::default()
            });
        }
        for (mesh, node_index) in [(0, 299), (1, 4)] {
            scene.draws.push(kantele::scene::Draw {
                mesh,
                model: glam::Mat4::IDENTITY,
                node_name: "n".into(),
                node_index,
            });
        }
        scene
    }

    #[test]
    fn ids_of_every_kind() {
        let frame = synthetic();
        let scene = two_draw_scene();
        let ids = |k| id_values(&frame, &scene, k).unwrap();
        assert_eq!(ids(IdKind::Instance)[..3], [0, 1, 300]);
        assert_eq!(ids(IdKind::Triangle)[..3], [0, 2, 65535]);
        assert_eq!(ids(IdKind::Primitive)[..3], [0, 1, 2]);
        assert_eq!(ids(IdKind::Mesh)[..3], [0, 1, 2]);
        assert_eq!(ids(IdKind::Material)[..3], [0, 1, 4]);
        assert_eq!(max_id(&scene, IdKind::Instance), 300);
        assert_eq!(max_id(&scene, IdKind::Material), 4);
        let mut bad = synthetic();
        bad.color[1][2] = 9.0;
        assert!(id_values(&bad, &scene, IdKind::Instance).is_err());
        bad.color[1][2] = 0.5;
        assert!(id_values(&bad, &scene, IdKind::Instance).is_err());
    }

    #[test]
    fn depth_png_is_bop() {
        let p = Path::new("d.png");
        let v = depth_png(&[f32::INFINITY, 1234.4, 0.6, 65535.0], p).unwrap();
        assert_eq!(v, [0, 1234, 1, 65535]);
        let err = depth_png(&[70000.0], p).unwrap_err().to_string();
        assert!(err.contains("16-bit"), "{err}");
    }

    #[test]
    fn camera_space_normals() {
        let frame = synthetic();
        let pose =
            CameraPose::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 1.0, 3, 2).unwrap();
        let world = normal_values(&frame, NormalSpace::World, &pose);
        let cam = normal_values(&frame, NormalSpace::Camera, &pose);
        assert_eq!(world[0], [0.0; 3]);
        // World +Z faces the camera: OpenCV camera z points away from it, so -Z.
        assert!((Vec3::from(cam[3]) - Vec3::new(0.0, 0.0, -1.0)).length() < 1e-6);
        // World -Y (down) is camera +Y (OpenCV y down).
        assert!((Vec3::from(cam[4]) - Vec3::new(0.0, 1.0, 0.0)).length() < 1e-6);
    }
}
