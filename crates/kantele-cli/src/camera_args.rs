//! Which cameras `render` draws a scene with: `--camera`, `--fov`, `--views`, `--orbit`
//! (`--elevation`, `--radius`), `--up`; and the image size each camera gets.

use anyhow::{anyhow, bail, Result};
use glam::Vec3;
use kantele::scene::NamedCamera;
use kantele_output::pose::sidecar::{read_views_file, ViewDefaults};
use kantele_output::pose::{Bounds, CameraPose, Silhouette, UpAxis};
use kantele_scene::LoadedScene;

use crate::cli::{CameraArgs, UpArg};

/// Vertical field of view of `auto`, `look-at` and orbit cameras unless `--fov` says otherwise.
pub const DEFAULT_YFOV_DEG: f32 = 45.0;

/// Azimuth of the automatic framing camera (a three-quarter view), degrees.
pub const AUTO_AZIMUTH_DEG: f64 = 30.0;

/// Elevation of the automatic framing camera, degrees.
pub const AUTO_ELEVATION_DEG: f64 = 20.0;

/// A parsed `--camera`.
#[derive(Clone, Debug, PartialEq)]
pub enum CameraSpec {
    /// The file's camera with this index.
    FileIndex(usize),
    /// The file's camera with this name.
    FileName(String),
    /// Frame the model by its silhouette, ignoring the file's cameras.
    Auto,
    /// A camera at `eye` looking at `target`.
    LookAt {
        /// Camera centre.
        eye: Vec3,
        /// Point looked at.
        target: Vec3,
        /// Roughly up (default: the `--up` axis).
        up: Option<Vec3>,
    },
}

fn parse_vec3(s: &str, what: &str, spec: &str) -> Result<Vec3> {
    let parts: Vec<f32> = s
        .split(',')
        .map(|p| p.trim().parse::<f32>().ok().filter(|v| v.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(|| anyhow!("--camera {spec}: {what} '{s}' is not x,y,z"))?;
    match parts[..] {
        [x, y, z] => Ok(Vec3::new(x, y, z)),
        _ => bail!("--camera {spec}: {what} '{s}' is not x,y,z"),
    }
}

/// Parses `--camera`: `auto`, `look-at:EYE:TARGET[:UP]`, an index or a name.
pub fn parse_camera(spec: &str) -> Result<CameraSpec> {
    if spec == "auto" {
        return Ok(CameraSpec::Auto);
    }
    if let Some(rest) = spec.strip_prefix("look-at:") {
        let parts: Vec<&str> = rest.split(':').collect();
        if parts.len() != 2 && parts.len() != 3 {
            bail!("--camera {spec}: use look-at:EYE:TARGET[:UP] with x,y,z each");
        }
        let eye = parse_vec3(parts[0], "eye", spec)?;
        let target = parse_vec3(parts[1], "target", spec)?;
        let up = parts
            .get(2)
            .map(|u| parse_vec3(u, "up", spec))
            .transpose()?;
        if eye == target {
            bail!("--camera {spec}: the eye and the target are the same point");
        }
        return Ok(CameraSpec::LookAt { eye, target, up });
    }
    if let Ok(i) = spec.parse::<usize>() {
        return Ok(CameraSpec::FileIndex(i));
    }
    if spec.is_empty() {
        bail!("--camera needs N, NAME, auto or look-at:EYE:TARGET[:UP]");
    }
    Ok(CameraSpec::FileName(spec.to_string()))
}

/// The cameras of one command, checked before anything is rendered.
#[derive(Clone, Debug)]
pub struct CameraPlan {
    spec: Option<CameraSpec>,
    views: Option<Vec<CameraPose>>,
    orbit: Option<u32>,
    elevation: f32,
    radius: Option<f32>,
    up: UpAxis,
    yfov: f32,
    /// `--ortho`: the automatic framing is orthographic.
    ortho: bool,
}

impl CameraPlan {
    /// Parses the camera flags and reads `--views` (sizes there win over `size`).
    pub fn new(args: &CameraArgs, size: Option<(u32, u32)>) -> Result<Self> {
        let spec = args.camera.as_deref().map(parse_camera).transpose()?;
        if args.ortho && !matches!(spec, None | Some(CameraSpec::Auto)) {
            bail!("--ortho frames the model itself: it combines only with --camera auto");
        }
        // `--ortho` is the automatic framing, whatever cameras the file has.
        let spec = if args.ortho {
            Some(CameraSpec::Auto)
        } else {
            spec
        };
        let views = args
            .views
            .as_ref()
            .map(|path| {
                let defaults = ViewDefaults {
                    size,
                    ..Default::default()
                };
                read_views_file(path, &defaults).map_err(|e| anyhow!("--views {e}"))
            })
            .transpose()?;
        if let Some(r) = args.radius {
            if !(r.is_finite() && r > 0.0) {
                bail!("--radius {r}: must be a positive distance");
            }
        }
        if !args.elevation.is_finite() || args.elevation.abs() >= 90.0 {
            bail!("--elevation {}: use degrees in (-90, 90)", args.elevation);
        }
        Ok(Self {
            spec,
            views,
            orbit: args.orbit,
            elevation: args.elevation,
            radius: args.radius,
            up: match args.up {
                UpArg::Y => UpAxis::Y,
                UpArg::Z => UpAxis::Z,
            },
            yfov: args.fov.unwrap_or(DEFAULT_YFOV_DEG).to_radians(),
            ortho: args.ortho,
        })
    }

    /// How many images each scene gives.
    pub fn views_per_scene(&self) -> usize {
        match (&self.views, self.orbit) {
            (Some(v), _) => v.len(),
            (None, Some(n)) => n as usize,
            (None, None) => 1,
        }
    }

    /// Whether the file's own camera is used (when the scene has one).
    fn uses_file_camera(&self, loaded: &LoadedScene) -> bool {
        self.views.is_none()
            && self.orbit.is_none()
            && match &self.spec {
                None => loaded.info.camera_from_file,
                Some(CameraSpec::FileIndex(_) | CameraSpec::FileName(_)) => true,
                _ => false,
            }
    }

    /// The image size of a scene: `--size`, else the scene's resolution, with the width
    /// following the file camera's aspect ratio when that camera is used.
    pub fn image_size(
        &self,
        loaded: &LoadedScene,
        size: Option<(u32, u32)>,
        label: &str,
    ) -> Result<(u32, u32)> {
        if let Some(s) = size {
            return Ok(s);
        }
        let max = kantele::MAX_TARGET_SIZE;
        let (w, h) = loaded.scene.resolution;
        if w == 0 || h == 0 || w > max || h > max {
            bail!("{label}: the scene asks for an image of {w}x{h}, outside 1..={max}; use --size");
        }
        match loaded.scene.camera.aspect_ratio {
            Some(a) if self.uses_file_camera(loaded) && a.is_finite() && a > 0.0 => {
                let width = (h as f64 * a as f64).round().clamp(1.0, max as f64) as u32;
                Ok((width, h))
            }
            _ => Ok((w, h)),
        }
    }

    /// The cameras of one scene at `width × height` (views from `--views` keep their own size).
    pub fn poses(
        &self,
        loaded: &LoadedScene,
        width: u32,
        height: u32,
        label: &str,
    ) -> Result<Vec<CameraPose>> {
        let pose_err = |e: kantele_output::pose::PoseError| anyhow!("{label}: camera: {}", e.0);
        if let Some(views) = &self.views {
            return Ok(views.clone());
        }
        let silhouette = || {
            Silhouette::of_scene(&loaded.scene).ok_or_else(|| {
                anyhow!("{label}: the scene draws nothing, so there is nothing to frame")
            })
        };
        if let Some(n) = self.orbit {
            return CameraPose::orbit(
                &silhouette()?,
                n,
                self.elevation,
                self.radius,
                self.up,
                self.yfov,
                width,
                height,
            )
            .map_err(pose_err);
        }
        let file_camera =
            || CameraPose::from_scene_camera(&loaded.scene.camera, width, height).map_err(pose_err);
        let cameras = file_cameras(loaded);
        let numbered_camera = |index: usize, asked: &str| -> Result<CameraPose> {
            let chosen = cameras.get(index).ok_or_else(|| {
                if cameras.is_empty() {
                    anyhow!(
                        "{label}: --camera {asked}: the file has no camera (use auto or look-at)"
                    )
                } else {
                    anyhow!(
                        "{label}: --camera {asked}: the file has {} camera(s): {}",
                        cameras.len(),
                        camera_list(loaded)
                    )
                }
            })?;
            CameraPose::from_scene_camera(&chosen.camera, width, height).map_err(pose_err)
        };
        let pose = match &self.spec {
            None if loaded.info.camera_from_file => file_camera()?,
            None | Some(CameraSpec::Auto) => self.auto(&silhouette()?, width, height, label)?,
            Some(CameraSpec::FileIndex(i)) => numbered_camera(*i, &i.to_string())?,
            Some(CameraSpec::FileName(name)) => {
                let i = cameras
                    .iter()
                    .position(|c| &c.name == name)
                    .ok_or_else(|| {
                        anyhow!(
                            "{label}: no camera named '{name}' (cameras: {})",
                            camera_list(loaded)
                        )
                    })?;
                numbered_camera(i, name)?
            }
            Some(CameraSpec::LookAt { eye, target, up }) => {
                let up = up.unwrap_or(self.up.vector().as_vec3());
                let pose = CameraPose::look_at(*eye, *target, up, self.yfov, width, height)
                    .map_err(pose_err)?;
                match Bounds::of_scene(&loaded.scene) {
                    Some(b) => pose
                        .fit_depth_range(b.center().as_vec3(), b.radius() as f32)
                        .map_err(pose_err)?,
                    None => pose,
                }
            }
        };
        Ok(vec![pose])
    }

    fn auto(
        &self,
        silhouette: &Silhouette,
        width: u32,
        height: u32,
        label: &str,
    ) -> Result<CameraPose> {
        let dir = self.up.direction(
            AUTO_AZIMUTH_DEG.to_radians(),
            AUTO_ELEVATION_DEG.to_radians(),
        );
        let pose = if self.ortho {
            CameraPose::frame_orthographic(silhouette, dir.as_vec3(), self.up, width, height)
        } else {
            CameraPose::frame(silhouette, dir.as_vec3(), self.up, self.yfov, width, height)
        };
        pose.map_err(|e| anyhow!("{label}: camera: {}", e.0))
    }
}

/// The file's usable cameras, numbered as `--camera N` takes them: the loader's list, or the
/// scene's own camera when a source (a built-in scene) has one but lists none.
fn file_cameras(loaded: &LoadedScene) -> Vec<NamedCamera> {
    if loaded.scene.file_cameras.is_empty() && loaded.info.camera_from_file {
        vec![NamedCamera {
            name: "camera".into(),
            camera: loaded.scene.camera,
        }]
    } else {
        loaded.scene.file_cameras.clone()
    }
}

/// The file's usable cameras, numbered, for messages.
fn camera_list(loaded: &LoadedScene) -> String {
    let cameras = file_cameras(loaded);
    if cameras.is_empty() {
        return "none".into();
    }
    cameras
        .iter()
        .enumerate()
        .map(|(i, c)| format!("{i} '{}'", c.name))
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camera_specs() {
        assert_eq!(parse_camera("auto").unwrap(), CameraSpec::Auto);
        assert_eq!(parse_camera("2").unwrap(), CameraSpec::FileIndex(2));
        assert_eq!(
            parse_camera("Camera.001").unwrap(),
            CameraSpec::FileName("Camera.001".into())
        );
        assert_eq!(
            parse_camera("look-at:0,1,5:0,0,0").unwrap(),
            CameraSpec::LookAt {
                eye: Vec3::new(0.0, 1.0, 5.0),
                target: Vec3::ZERO,
                up: None
            }
        );
        assert_eq!(
            parse_camera("look-at:0,1,5:0,0,0:0,0,1").unwrap(),
            CameraSpec::LookAt {
                eye: Vec3::new(0.0, 1.0, 5.0),
                target: Vec3::ZERO,
                up: Some(Vec3::Z)
            }
        );
        for bad in [
            "look-at:1,2:0,0,0",
            "look-at:0,0,0",
            "look-at:1,1,1:1,1,1",
            "look-at:a,b,c:0,0,0",
            "look-at:nan,0,0:0,0,0",
            "",
        ] {
            assert!(parse_camera(bad).is_err(), "{bad}");
        }
    }

    fn cube() -> LoadedScene {
        kantele_scene::builtin_scene("cube").unwrap()
    }

    #[test]
    fn auto_framing_keeps_the_model_inside_and_large() {
        for ortho in [false, true] {
            auto_framing_case(ortho);
        }
    }

    #[test]
    fn ortho_combines_only_with_auto() {
        let args = |camera: Option<&str>| CameraArgs {
            camera: camera.map(str::to_string),
            ortho: true,
            ..Default::default()
        };
        assert!(CameraPlan::new(&args(Some("0")), None).is_err());
        assert!(CameraPlan::new(&args(Some("look-at:0,0,5:0,0,0")), None).is_err());
        // Without --camera it frames the model even where the file has a camera.
        let loaded = cube();
        assert!(loaded.info.camera_from_file);
        let plan = CameraPlan::new(&args(None), None).unwrap();
        let pose = &plan.poses(&loaded, 64, 48, "cube").unwrap()[0];
        assert!(matches!(
            pose.projection,
            kantele_output::pose::Projection::Orthographic { .. }
        ));
    }

    fn auto_framing_case(ortho: bool) {
        let loaded = cube();
        let args = CameraArgs {
            camera: Some("auto".into()),
            ortho,
            ..Default::default()
        };
        let plan = CameraPlan::new(&args, None).unwrap();
        let pose = &plan.poses(&loaded, 200, 100, "cube").unwrap()[0];
        assert_eq!(
            matches!(
                pose.projection,
                kantele_output::pose::Projection::Orthographic { .. }
            ),
            ortho
        );
        let b = Bounds::of_scene(&loaded.scene).unwrap();
        let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
        for c in b.corners() {
            let (x, y, _) = pose.project(c.as_vec3()).unwrap();
            assert!((0.0..200.0).contains(&x) && (0.0..100.0).contains(&y));
            lo = [lo[0].min(x), lo[1].min(y)];
            hi = [hi[0].max(x), hi[1].max(y)];
        }
        // Fills the tighter direction (the height here) almost entirely.
        assert!(hi[1] - lo[1] > 80.0, "{lo:?} {hi:?}");
    }

    #[test]
    fn file_camera_choice_and_size() {
        let loaded = cube();
        let plan = CameraPlan::new(&CameraArgs::default(), None).unwrap();
        let (w, h) = plan.image_size(&loaded, None, "cube").unwrap();
        assert_eq!(h, loaded.scene.resolution.1);
        if let Some(a) = loaded.scene.camera.aspect_ratio {
            assert_eq!(w, (h as f32 * a).round() as u32);
        }
        let by_index = CameraPlan::new(
            &CameraArgs {
                camera: Some("0".into()),
                ..Default::default()
            },
            None,
        )
        .unwrap();
        let default_pose = &plan.poses(&loaded, 64, 48, "cube").unwrap()[0];
        let index_pose = &by_index.poses(&loaded, 64, 48, "cube").unwrap()[0];
        assert_eq!(default_pose.view(), index_pose.view());
        let missing = CameraPlan::new(
            &CameraArgs {
                camera: Some("7".into()),
                ..Default::default()
            },
            None,
        )
        .unwrap();
        assert!(missing.poses(&loaded, 64, 48, "cube").is_err());
    }

    #[test]
    fn every_file_camera_by_index_and_name() {
        let mut loaded = cube();
        let first = loaded.scene.camera;
        let second = kantele::scene::Camera {
            view: kantele::camera::look_at(Vec3::new(3.0, 2.0, 1.0), Vec3::ZERO, Vec3::Y),
            ..first
        };
        loaded.scene.file_cameras = vec![
            NamedCamera {
                name: "front".into(),
                camera: first,
            },
            NamedCamera {
                name: "side".into(),
                camera: second,
            },
        ];
        let pose = |camera: &str| {
            let plan = CameraPlan::new(
                &CameraArgs {
                    camera: Some(camera.into()),
                    ..Default::default()
                },
                None,
            )
            .unwrap();
            plan.poses(&loaded, 64, 48, "cube").map(|p| p[0].view())
        };
        let expected = CameraPose::from_scene_camera(&second, 64, 48)
            .unwrap()
            .view();
        assert_eq!(pose("1").unwrap(), expected);
        assert_eq!(pose("side").unwrap(), expected);
        assert_ne!(pose("0").unwrap(), expected);
        let err = pose("top").unwrap_err().to_string();
        assert!(err.contains("0 'front', 1 'side'"), "{err}");
        assert!(pose("2").is_err());
    }

    #[test]
    fn orbit_cameras_circle_the_scene() {
        let loaded = cube();
        let args = CameraArgs {
            orbit: Some(4),
            elevation: 20.0,
            ..Default::default()
        };
        let plan = CameraPlan::new(&args, None).unwrap();
        assert_eq!(plan.views_per_scene(), 4);
        let cams = plan.poses(&loaded, 64, 64, "cube").unwrap();
        let center = Bounds::of_scene(&loaded.scene).unwrap().center().as_vec3();
        let d0 = (cams[0].eye() - center).length();
        for c in &cams {
            assert!(((c.eye() - center).length() - d0).abs() < 1e-3 * d0);
            assert!(c.eye().y > center.y);
        }
        assert_ne!(cams[0].eye(), cams[1].eye());
    }
}
