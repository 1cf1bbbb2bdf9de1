//! Cameras made from a model's extent: automatic framing that makes the model fill the picture,
//! and orbits around it.
//!
//! Everything is computed in `f64` relative to the model's size, so a model of 1e-30 units and
//! one of 1e30 units are framed alike.

use std::str::FromStr;

use glam::{DVec3, Vec3};
use kantele_rules::scene::{Draw, Mesh, Scene};

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
        Self::from_points(
            scene
                .draws
                .iter()
                .flat_map(|draw| draw_box_corners(scene, draw).into_iter().flatten()),
        )
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

/// The world-space corners of a draw's mesh box (`None` for a mesh with no finite position).
fn draw_box_corners(scene: &Scene, draw: &Draw) -> Option<[DVec3; 8]> {
    let (a, b) = scene.meshes.get(draw.mesh).and_then(Mesh::bounds)?;
    let model = draw.model.as_dmat4();
    let local = Bounds {
        min: a.as_dvec3(),
        max: b.as_dvec3(),
    };
    Some(local.corners().map(|c| model.transform_point3(c)))
}

/// Near and far planes around a sphere `distance` away with `radius`: near at half the
/// distance to its front (at least 1/2000 of the distance to its centre), far at its back plus
/// one more radius.
pub(crate) fn depth_range(distance: f64, radius: f64) -> (f64, f64) {
    let near = (distance - radius).max(distance * 1e-3) * 0.5;
    (near, distance + radius * 2.0)
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

/// Largest number of points a [`Silhouette`] of a scene keeps: draws beyond it are framed by the
/// eight corners of their boxes (bounded work and memory for scenes of many large instances).
pub const MAX_SILHOUETTE_POINTS: usize = 4 << 20;

/// What a framing fits into the picture: a model's points in world space — the vertices of
/// everything a scene draws, so that the framing follows the model's projected silhouette, not
/// its bounding box — and the box around them.
#[derive(Clone, Debug, PartialEq)]
pub struct Silhouette {
    points: Vec<DVec3>,
    bounds: Bounds,
}

impl Silhouette {
    /// The finite points among `points` (`None` when there is none).
    pub fn from_points(points: impl IntoIterator<Item = DVec3>) -> Option<Self> {
        let points: Vec<DVec3> = points.into_iter().filter(|p| p.is_finite()).collect();
        let bounds = Bounds::from_points(points.iter().copied())?;
        Some(Self { points, bounds })
    }

    /// A box's eight corners.
    pub fn of_bounds(bounds: &Bounds) -> Self {
        Self {
            points: bounds.corners().to_vec(),
            bounds: *bounds,
        }
    }

    /// Every vertex the scene draws, placed by its draw's transform (up to
    /// [`MAX_SILHOUETTE_POINTS`]; the draws beyond by their boxes' corners); `None` when nothing
    /// finite is drawn.
    pub fn of_scene(scene: &Scene) -> Option<Self> {
        let mut points = Vec::new();
        for draw in &scene.draws {
            let Some(mesh) = scene.meshes.get(draw.mesh) else {
                continue;
            };
            if points.len() + mesh.positions.len() <= MAX_SILHOUETTE_POINTS {
                let model = draw.model.as_dmat4();
                points.extend(
                    mesh.positions
                        .iter()
                        .map(|p| model.transform_point3(p.as_dvec3())),
                );
            } else if let Some(corners) = draw_box_corners(scene, draw) {
                points.extend(corners);
            }
        }
        Self::from_points(points)
    }

    /// The box around the points.
    pub fn bounds(&self) -> &Bounds {
        &self.bounds
    }

    /// The points.
    pub fn points(&self) -> &[DVec3] {
        &self.points
    }
}

/// The camera basis a framing from one direction will have ([`look_at_f64`] picks the same), in
/// which points are measured relative to the model's centre in units of its size.
struct ViewBasis {
    /// Unit vector from the model towards the eye.
    back: DVec3,
    /// The camera's right and up axes.
    right: DVec3,
    cam_up: DVec3,
    /// The model's centre and size (world units).
    center: DVec3,
    scale: f64,
}

impl ViewBasis {
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
        Ok(Self {
            back,
            right,
            cam_up,
            center: bounds.center(),
            scale: bounds.scale(),
        })
    }

    /// A point as (right, up, back) coordinates, in model sizes from the centre.
    fn coords(&self, p: DVec3) -> DVec3 {
        let q = (p - self.center) / self.scale;
        DVec3::new(q.dot(self.right), q.dot(self.cam_up), q.dot(self.back))
    }

    /// The world point at view coordinates `(x, y, z)`.
    fn world(&self, x: f64, y: f64, z: f64) -> DVec3 {
        self.center + (self.right * x + self.cam_up * y + self.back * z) * self.scale
    }
}

/// The lowest and highest projections (tangents) of points along one image axis, with the
/// depths they lie at.
struct Extent {
    low: (f64, f64),
    high: (f64, f64),
}

impl Default for Extent {
    fn default() -> Self {
        Self {
            low: (f64::INFINITY, 1.0),
            high: (f64::NEG_INFINITY, 1.0),
        }
    }
}

impl Extent {
    fn include(&mut self, projection: f64, depth: f64) {
        if projection < self.low.0 {
            self.low = (projection, depth);
        }
        if projection > self.high.0 {
            self.high = (projection, depth);
        }
    }

    /// How far to move the camera along the axis (model units) so that the two extreme points,
    /// each at its own depth, project to symmetric places.
    fn centring_shift(&self) -> f64 {
        let ((low, d_low), (high, d_high)) = (self.low, self.high);
        (low + high) / (1.0 / d_low + 1.0 / d_high)
    }
}

/// Tangents of the half field-of-view angles a framing fills: horizontal and vertical.
fn fill_tangents(yfov: f64, aspect: f64) -> (f64, f64) {
    let ty = (0.5 * yfov).tan() * FRAMING_FILL;
    (ty * aspect, ty)
}

impl CameraPose {
    /// A perspective camera that looks at `silhouette` from direction `from_dir` (model
    /// towards the eye) and makes it fill the picture: every point inside the image, the
    /// projection spanning [`FRAMING_FILL`] of the image along its tighter direction and centred
    /// along both. The depth range holds every point.
    ///
    /// In the view basis, a camera at `(cx, cy, e)` sees point `(x, y, z)` inside the half-angle
    /// tangent `t` horizontally when `|x − cx| ≤ t (e − z)`, that is `cx + t e ≥ max(x + t z)`
    /// and `t e − cx ≥ max(t z − x)`: the nearest such camera is in closed form, per direction;
    /// the farther of the two wins, and the looser direction is then centred.
    pub fn frame(
        silhouette: &Silhouette,
        from_dir: Vec3,
        up: UpAxis,
        yfov: f32,
        width: u32,
        height: u32,
    ) -> Result<Self, PoseError> {
        let (tx, ty) = fill_tangents(check_yfov(yfov)?, check_size(width, height)?);
        let basis = ViewBasis::new(silhouette.bounds(), from_dir, up)?;
        let points = silhouette.points();
        let mut reach = [f64::NEG_INFINITY; 5];
        for p in points.iter().map(|&p| basis.coords(p)) {
            let candidates = [
                p.x + tx * p.z,
                tx * p.z - p.x,
                p.y + ty * p.z,
                ty * p.z - p.y,
                p.z,
            ];
            for (r, c) in reach.iter_mut().zip(candidates) {
                *r = r.max(c);
            }
        }
        let [right_x, left_x, top_y, bottom_y, front_z] = reach;
        let distance = ((right_x + left_x) / (2.0 * tx))
            .max((top_y + bottom_y) / (2.0 * ty))
            .max(front_z + 1e-3);
        let (mut sx, mut sy) = (0.5 * (right_x - left_x), 0.5 * (top_y - bottom_y));
        // Centre the projection: exact already along the tight direction; a few steps along
        // the other (each moves the extreme points, at their own depths, to symmetric places),
        // whose slack leaves every point inside (FRAMING_FILL < 1).
        let (mut nearest, mut farthest) = (f64::INFINITY, f64::NEG_INFINITY);
        for _ in 0..6 {
            let (mut x, mut y) = (Extent::default(), Extent::default());
            (nearest, farthest) = (f64::INFINITY, f64::NEG_INFINITY);
            for p in points.iter().map(|&p| basis.coords(p)) {
                let depth = distance - p.z;
                x.include((p.x - sx) / depth, depth);
                y.include((p.y - sy) / depth, depth);
                nearest = nearest.min(depth);
                farthest = farthest.max(depth);
            }
            let (dx, dy) = (x.centring_shift(), y.centring_shift());
            sx += dx;
            sy += dy;
            if dx.abs().max(dy.abs()) <= distance * 1e-9 {
                break;
            }
        }
        let target = basis.world(sx, sy, 0.0);
        let eye = basis.world(sx, sy, distance);
        let view = look_at_f64(eye, target, up.vector())?;
        let near = (nearest * 0.5).max(distance * 1e-4) * basis.scale;
        let far = farthest * 2.0 * basis.scale;
        CameraPose::new(
            width,
            height,
            Projection::Perspective { yfov },
            near as f32,
            Some(far as f32),
            view,
        )
    }

    /// An orthographic camera that looks at `silhouette` from direction `from_dir` (model
    /// towards the eye) and makes it fill the picture as [`CameraPose::frame`] does: the
    /// projection centred and spanning [`FRAMING_FILL`] of the image along its tighter direction
    /// (`ymag` chosen for that; pixels stay square). The eye sits one model size in front of the
    /// nearest point and the depth range holds all of them.
    pub fn frame_orthographic(
        silhouette: &Silhouette,
        from_dir: Vec3,
        up: UpAxis,
        width: u32,
        height: u32,
    ) -> Result<Self, PoseError> {
        let aspect = check_size(width, height)?;
        let basis = ViewBasis::new(silhouette.bounds(), from_dir, up)?;
        let (lo, hi) = silhouette
            .points()
            .iter()
            .map(|&p| basis.coords(p))
            .fold((DVec3::MAX, DVec3::MIN), |(lo, hi), p| {
                (lo.min(p), hi.max(p))
            });
        let half = 0.5 * (hi - lo);
        let ymag = (half.y.max(half.x / aspect) / FRAMING_FILL).max(1e-6);
        let (sx, sy) = (0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y));
        let distance = hi.z + 1.0;
        let target = basis.world(sx, sy, 0.0);
        let eye = basis.world(sx, sy, distance);
        let view = look_at_f64(eye, target, up.vector())?;
        let near = 0.5 * basis.scale;
        let far = (distance - lo.z + 1.0) * basis.scale;
        CameraPose::new(
            width,
            height,
            Projection::Orthographic {
                ymag: (ymag * basis.scale) as f32,
            },
            near as f32,
            Some(far as f32),
            view,
        )
    }

    /// `n` perspective cameras on a circle around the centre of `silhouette`'s box, all looking
    /// at it: at `elevation_deg` above the horizon of `up`, azimuths `360° · k / n` from the
    /// front (see [`UpAxis::direction`]), `radius` from the centre, or when `None` at the one
    /// distance from which every point stays inside [`FRAMING_FILL`] of the picture at *every*
    /// azimuth, so a turntable neither clips nor zooms.
    ///
    /// A point at height `h` over the centre and `r` from the up axis, seen from azimuth `φ`
    /// away from its own, has view coordinates `z = r cos φ cos e + h sin e`, `x = r sin φ`,
    /// `y = h cos e − r cos φ sin e`; the distance it needs, `max(z + |x|/tx, z + |y|/ty)`,
    /// peaks over `φ` at `h sin e + r √(cos² e + 1/tx²)` and at `cos φ = ±1`.
    #[allow(clippy::too_many_arguments)]
    pub fn orbit(
        silhouette: &Silhouette,
        n: u32,
        elevation_deg: f32,
        radius: Option<f32>,
        up: UpAxis,
        yfov: f32,
        width: u32,
        height: u32,
    ) -> Result<Vec<Self>, PoseError> {
        let (tx, ty) = fill_tangents(check_yfov(yfov)?, check_size(width, height)?);
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
        let bounds = silhouette.bounds();
        if !bounds.min.is_finite() || !bounds.max.is_finite() {
            return Err(err("the bounds to orbit are not finite"));
        }
        let center = bounds.center();
        let scale = bounds.scale();
        let elevation = (elevation_deg as f64).to_radians();
        let (sin_e, cos_e) = elevation.sin_cos();
        let up_axis = up.vector();
        // Per point: the distance it needs, and its nearest and farthest view depth offsets,
        // over every azimuth (model sizes).
        let (mut needed, mut front, mut back) = (0.0f64, f64::NEG_INFINITY, f64::INFINITY);
        for &p in silhouette.points() {
            let q = (p - center) / scale;
            let h = q.dot(up_axis);
            let r = (q - up_axis * h).length();
            let sideways = h * sin_e + r * (cos_e * cos_e + 1.0 / (tx * tx)).sqrt();
            let upright = [1.0, -1.0]
                .map(|u: f64| r * u * cos_e + h * sin_e + (h * cos_e - r * u * sin_e).abs() / ty);
            needed = needed.max(sideways).max(upright[0]).max(upright[1]);
            front = front.max(r * cos_e.abs() + h * sin_e);
            back = back.min(h * sin_e - r * cos_e.abs());
        }
        let distance = match radius {
            Some(r) if r.is_finite() && r > 0.0 => r as f64,
            Some(r) => return Err(err(format!("orbit radius {r} must be finite and > 0"))),
            None => needed.max(front + 1e-3) * scale,
        };
        let model_depth = distance / scale;
        let near = ((model_depth - front) * 0.5).max(model_depth * 1e-4) * scale;
        let far = (model_depth - back) * 2.0 * scale;
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
