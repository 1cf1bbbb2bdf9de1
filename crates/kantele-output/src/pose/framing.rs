//! Cameras made from a model's extent: automatic framing that makes the model fill the picture,
//! and orbits around it.
//!
//! Everything is computed in `f64` relative to the model's size, so a model of 1e-30 units and
//! one of 1e30 units are framed alike.

use std::str::FromStr;

use glam::{DVec3, Vec3};
use kantele_rules::scene::{Mesh, Scene};

use super::{err, look_at_f64, unit, CameraPose, PoseError, Projection};

/// Fraction of the image the framed model spans along its tighter direction.
pub const FRAMING_FILL: f64 = 0.92;

/// Largest number of orbit views one call makes.
pub const MAX_ORBIT_VIEWS: u32 = 1_000_000;

/// Which world axis points up.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum UpAxis {
    /// +Y up (glTF); azimuth 0 looks from +Z.
    #[default]
    Y,
    /// +Z up (scans, CAD); azimuth 0 looks from −Y.
    Z,
}

impl UpAxis {
    /// The up vector.
    pub fn vector(self) -> DVec3 {
        match self {
            UpAxis::Y => DVec3::Y,
            UpAxis::Z => DVec3::Z,
        }
    }

    /// Unit direction from the model's centre towards a camera at `azimuth` (around the up
    /// axis, counter-clockwise seen from above) and `elevation` above the horizon, radians.
    /// With Y up, azimuth 0 is +Z and azimuth 90° is +X; with Z up, −Y and +X.
    pub fn direction(self, azimuth: f64, elevation: f64) -> DVec3 {
        let (x, y, z) = (
            azimuth.sin() * elevation.cos(),
            elevation.sin(),
            azimuth.cos() * elevation.cos(),
        );
        match self {
            UpAxis::Y => DVec3::new(x, y, z),
            // Rotate the Y-up frame by +90° about X: Y → Z, Z → −Y.
            UpAxis::Z => DVec3::new(x, -z, y),
        }
    }
}

impl FromStr for UpAxis {
    type Err = PoseError;

    fn from_str(s: &str) -> Result<Self, PoseError> {
        match s.to_ascii_lowercase().as_str() {
            "y" | "+y" => Ok(UpAxis::Y),
            "z" | "+z" => Ok(UpAxis::Z),
            _ => Err(err(format!("up axis {s:?}: use y or z"))),
        }
    }
}

/// An axis-aligned box in world space, `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// Smallest corner.
    pub min: DVec3,
    /// Largest corner.
    pub max: DVec3,
}

impl Bounds {
    /// The box around the finite points (`None` when there is none).
    pub fn from_points(points: impl IntoIterator<Item = DVec3>) -> Option<Self> {
        let mut it = points.into_iter().filter(|p| p.is_finite());
        let first = it.next()?;
        let (min, max) = it.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p)));
        Some(Self { min, max })
    }

    /// World-space box of everything the scene draws (mesh boxes through their transforms);
    /// `None` when nothing finite is drawn.
    pub fn of_scene(scene: &Scene) -> Option<Self> {
        let corners = scene.draws.iter().flat_map(|draw| {
            let model = draw.model.as_dmat4();
            let bounds = scene.meshes.get(draw.mesh).and_then(Mesh::bounds);
            bounds.into_iter().flat_map(move |(a, b)| {
                let (a, b) = (a.as_dvec3(), b.as_dvec3());
                (0..8).map(move |i| {
                    model.transform_point3(DVec3::new(
                        if i & 1 == 0 { a.x } else { b.x },
                        if i & 2 == 0 { a.y } else { b.y },
                        if i & 4 == 0 { a.z } else { b.z },
                    ))
                })
            })
        });
        Self::from_points(corners)
    }

    /// Centre of the box.
    pub fn center(&self) -> DVec3 {
        self.min * 0.5 + self.max * 0.5
    }

    /// Half the diagonal: the radius of the sphere through the corners (no overflow).
    pub fn radius(&self) -> f64 {
        super::distance_f64(self.max, self.min) * 0.5
    }

    /// The eight corners.
    pub fn corners(&self) -> [DVec3; 8] {
        std::array::from_fn(|i| {
            DVec3::new(
                if i & 1 == 0 { self.min.x } else { self.max.x },
                if i & 2 == 0 { self.min.y } else { self.max.y },
                if i & 4 == 0 { self.min.z } else { self.max.z },
            )
        })
    }

    /// A radius to scale by that is never 0: a single point gets a small size of its own.
    fn scale(&self) -> f64 {
        let r = self.radius();
        if r > 0.0 && r.is_finite() {
            return r;
        }
        let c = self.center().abs().max_element();
        if c > 0.0 && c.is_finite() {
            c * 1e-3
        } else {
            1.0
        }
    }
}

/// Near and far planes around a sphere `distance` away with `radius`: near at half the
/// distance to its front (at least 1/2000 of the distance to its centre), far at its back plus
/// one more radius.
pub(crate) fn depth_range(distance: f64, radius: f64) -> (f64, f64) {
    let near = (distance - radius).max(distance * 1e-3) * 0.5;
    (near, distance + radius * 2.0)
}

/// Half of the smaller of the two field-of-view angles of a `yfov` camera on an image of
/// `aspect`.
fn half_min_fov(yfov: f64, aspect: f64) -> f64 {
    0.5 * yfov.min(2.0 * (aspect * (0.5 * yfov).tan()).atan())
}

fn check_yfov(yfov: f32) -> Result<f64, PoseError> {
    if yfov > 0.0 && yfov < std::f32::consts::PI {
        Ok(yfov as f64)
    } else {
        Err(err(format!(
            "yfov {yfov} rad is outside (0, π) (is it in degrees?)"
        )))
    }
}

fn check_size(width: u32, height: u32) -> Result<f64, PoseError> {
    if width == 0 || height == 0 {
        return Err(err(format!("image size {width}x{height} has a zero side")));
    }
    Ok(width as f64 / height as f64)
}

/// A box seen from a framing direction: the camera basis the framed camera will have
/// ([`look_at_f64`] picks the same) and the box's corners in it, relative to the box's centre in
/// units of its radius.
struct BoxInView {
    /// Unit vector from the box towards the eye.
    back: DVec3,
    /// The camera's right and up axes.
    right: DVec3,
    cam_up: DVec3,
    /// The box's centre and radius (world units).
    center: DVec3,
    scale: f64,
    /// Corners as (right, up, back) coordinates, in radii from the centre.
    corners: [DVec3; 8],
}

impl BoxInView {
    fn new(bounds: &Bounds, from_dir: Vec3, up: UpAxis) -> Result<Self, PoseError> {
        if !bounds.min.is_finite() || !bounds.max.is_finite() {
            return Err(err("the bounds to frame are not finite"));
        }
        let back = unit(from_dir.as_dvec3())
            .ok_or_else(|| err(format!("framing direction {from_dir} is not a direction")))?;
        let up_hint = if back.cross(up.vector()).length_squared() < 1e-12 {
            if back.cross(DVec3::Z).length_squared() < 1e-12 {
                DVec3::Y
            } else {
                DVec3::Z
            }
        } else {
            up.vector()
        };
        let right = up_hint.cross(back).normalize();
        let cam_up = back.cross(right);
        let scale = bounds.scale();
        let center = bounds.center();
        let corners = bounds.corners().map(|p| {
            let q = (p - center) / scale;
            DVec3::new(q.dot(right), q.dot(cam_up), q.dot(back))
        });
        Ok(Self {
            back,
            right,
            cam_up,
            center,
            scale,
            corners,
        })
    }
}

impl CameraPose {
    /// A perspective camera that looks at `bounds` from direction `from_dir` (centre towards
    /// the eye) and makes the box fill the picture: every corner inside the image and the box
    /// spanning [`FRAMING_FILL`] of it along its tighter direction, centred. The depth range
    /// holds the whole box.
    pub fn frame_bounds(
        bounds: &Bounds,
        from_dir: Vec3,
        up: UpAxis,
        yfov: f32,
        width: u32,
        height: u32,
    ) -> Result<Self, PoseError> {
        let yfov_f = check_yfov(yfov)?;
        let aspect = check_size(width, height)?;
        let BoxInView {
            back,
            right,
            cam_up,
            center,
            scale,
            corners,
        } = BoxInView::new(bounds, from_dir, up)?;
        let ty = (0.5 * yfov_f).tan() * FRAMING_FILL;
        let tx = (0.5 * yfov_f).tan() * aspect * FRAMING_FILL;
        // Target offset in the image plane (right, up), re-centred a few times.
        let (mut sx, mut sy) = (0.0f64, 0.0f64);
        let mut distance = 0.0;
        for _ in 0..8 {
            distance = corners
                .iter()
                .map(|c| {
                    let z = c.z;
                    (z + (c.x - sx).abs() / tx).max(z + (c.y - sy).abs() / ty)
                })
                .fold(f64::NEG_INFINITY, f64::max);
            let max_z = corners
                .iter()
                .map(|c| c.z)
                .fold(f64::NEG_INFINITY, f64::max);
            distance = distance.max(max_z + 1e-3);
            // Projected extent (tangent units) and its middle.
            let (mut lo_x, mut hi_x, mut lo_y, mut hi_y) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
            for c in &corners {
                let depth = distance - c.z;
                let (px, py) = ((c.x - sx) / depth, (c.y - sy) / depth);
                lo_x = lo_x.min(px);
                hi_x = hi_x.max(px);
                lo_y = lo_y.min(py);
                hi_y = hi_y.max(py);
            }
            sx += (lo_x + hi_x) * 0.5 * distance;
            sy += (lo_y + hi_y) * 0.5 * distance;
        }
        let depths = corners.iter().map(|c| distance - c.z);
        let nearest = depths.clone().fold(f64::INFINITY, f64::min);
        let farthest = depths.fold(f64::NEG_INFINITY, f64::max);
        let target = center + (right * sx + cam_up * sy) * scale;
        let eye = target + back * (distance * scale);
        let view = look_at_f64(eye, target, up.vector())?;
        let near = (nearest * 0.5).max(distance * 1e-4) * scale;
        let far = farthest * 2.0 * scale;
        CameraPose::new(
            width,
            height,
            Projection::Perspective { yfov },
            near as f32,
            Some(far as f32),
            view,
        )
    }

    /// An orthographic camera that looks at `bounds` from direction `from_dir` (centre towards
    /// the eye) and makes the box fill the picture as [`CameraPose::frame_bounds`] does: the
    /// box's projection centred and spanning [`FRAMING_FILL`] of the image along its tighter
    /// direction (`ymag` chosen for that; pixels stay square). The eye sits one radius in front
    /// of the box and the depth range holds all of it.
    pub fn frame_bounds_orthographic(
        bounds: &Bounds,
        from_dir: Vec3,
        up: UpAxis,
        width: u32,
        height: u32,
    ) -> Result<Self, PoseError> {
        let aspect = check_size(width, height)?;
        let BoxInView {
            back,
            right,
            cam_up,
            center,
            scale,
            corners,
        } = BoxInView::new(bounds, from_dir, up)?;
        let fold = |f: fn(&DVec3) -> f64, pick: fn(f64, f64) -> f64, start: f64| {
            corners.iter().map(f).fold(start, pick)
        };
        let (lo_x, hi_x) = (
            fold(|c| c.x, f64::min, f64::MAX),
            fold(|c| c.x, f64::max, f64::MIN),
        );
        let (lo_y, hi_y) = (
            fold(|c| c.y, f64::min, f64::MAX),
            fold(|c| c.y, f64::max, f64::MIN),
        );
        let (lo_z, hi_z) = (
            fold(|c| c.z, f64::min, f64::MAX),
            fold(|c| c.z, f64::max, f64::MIN),
        );
        let half_x = 0.5 * (hi_x - lo_x);
        let half_y = 0.5 * (hi_y - lo_y);
        let ymag = (half_y.max(half_x / aspect) / FRAMING_FILL).max(1e-6);
        let (sx, sy) = (0.5 * (lo_x + hi_x), 0.5 * (lo_y + hi_y));
        // The eye one radius (in box units) in front of the nearest corner.
        let distance = hi_z + 1.0;
        let target = center + (right * sx + cam_up * sy) * scale;
        let eye = target + back * (distance * scale);
        let view = look_at_f64(eye, target, up.vector())?;
        let near = 0.5 * scale;
        let far = (distance - lo_z + 1.0) * scale;
        CameraPose::new(
            width,
            height,
            Projection::Orthographic {
                ymag: (ymag * scale) as f32,
            },
            near as f32,
            Some(far as f32),
            view,
        )
    }

    /// `n` perspective cameras on a circle around the centre of `bounds`, all looking at it:
    /// at `elevation_deg` above the horizon of `up`, azimuths `360° · k / n` from the front
    /// (see [`UpAxis::direction`]), `radius` from the centre, or when `None` far enough that
    /// the bounding sphere fits the picture.
    #[allow(clippy::too_many_arguments)]
    pub fn orbit(
        bounds: &Bounds,
        n: u32,
        elevation_deg: f32,
        radius: Option<f32>,
        up: UpAxis,
        yfov: f32,
        width: u32,
        height: u32,
    ) -> Result<Vec<Self>, PoseError> {
        let yfov_f = check_yfov(yfov)?;
        let aspect = check_size(width, height)?;
        if n == 0 || n > MAX_ORBIT_VIEWS {
            return Err(err(format!(
                "orbit of {n} views: use 1..={MAX_ORBIT_VIEWS}"
            )));
        }
        if !elevation_deg.is_finite() {
            return Err(err(format!(
                "orbit elevation {elevation_deg}° is not finite"
            )));
        }
        if !bounds.min.is_finite() || !bounds.max.is_finite() {
            return Err(err("the bounds to orbit are not finite"));
        }
        let center = bounds.center();
        let sphere = bounds.scale();
        let distance = match radius {
            Some(r) if r.is_finite() && r > 0.0 => r as f64,
            Some(r) => return Err(err(format!("orbit radius {r} must be finite and > 0"))),
            None => sphere / half_min_fov(yfov_f, aspect).sin(),
        };
        let (near, far) = depth_range(distance, sphere);
        let elevation = (elevation_deg as f64).to_radians();
        (0..n)
            .map(|k| {
                let azimuth = std::f64::consts::TAU * k as f64 / n as f64;
                let eye = center + up.direction(azimuth, elevation) * distance;
                let view = look_at_f64(eye, center, up.vector())?;
                CameraPose::new(
                    width,
                    height,
                    Projection::Perspective { yfov },
                    near as f32,
                    Some(far as f32),
                    view,
                )
            })
            .collect()
    }
}
