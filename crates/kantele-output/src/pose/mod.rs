//! Cameras: one type, [`CameraPose`], that fully determines how a picture sees the world, and
//! the conventions every part of Kantele (the CLI, its JSON sidecar, the Python package) uses.
//!
//! # Conventions
//!
//! - **Image**: `width × height` pixels, row 0 at the top. Pixels are always square: when a
//!   camera gives a vertical field of view (`yfov`) or a vertical magnification (`ymag`), that
//!   is kept and the horizontal one follows from the image's aspect (`width / height`). A file
//!   camera's own `aspectRatio` is ignored for that reason.
//! - **OpenGL camera frame** (what the backends take): x right, y up, the camera looks down
//!   −Z. [`CameraPose::world_to_camera`] is stored in this convention and is exactly the
//!   backends' view matrix ([`CameraPose::view`]).
//! - **OpenCV camera frame**: x right, y down, the camera looks down +Z. The world-to-camera
//!   matrix is the OpenGL one with its y and z rows negated ([`opencv_from_opengl`], its own
//!   inverse).
//! - **Intrinsics** ([`Intrinsics`], pixels, OpenCV): a camera-frame point `(x, y, z)` (OpenCV)
//!   lands at pixel coordinates `u = fx·x/z + cx`, `v = fy·y/z + cy`, where the **centre** of the
//!   top-left pixel is `(0, 0)` (so the image centre of a symmetric camera is
//!   `((w − 1)/2, (h − 1)/2)`). In the rasterizer's window coordinates (pixel centres at
//!   `x + 0.5`) that is `u + 0.5`, `v + 0.5`.
//! - **Projection** ([`CameraPose::projection`]): an OpenGL clip-space matrix (`-w ≤ x, y, z ≤
//!   w`), window depth `d = (z_ndc + 1) / 2` in [0, 1]; a perspective camera without `zfar` gets
//!   an infinite far plane. Matrices are computed in `f64` and rounded once to `f32`, so scenes
//!   from 1e-30 to 1e30 units keep their precision.
//! - **Depth**: *window depth* `d` (what the depth buffer holds, background 1.0); *planar* or
//!   *eye depth* `z`, the distance along the view axis (−z in OpenGL eye space, +z in OpenCV
//!   camera space, background `+inf`; [`eye_depth`]); *ray distance*, the Euclidean distance
//!   from the camera centre to the point, `z · √(1 + ((u − cx)/fx)² + ((v − cy)/fy)²)`
//!   ([`CameraPose::ray_distance`]; equal to planar depth for orthographic cameras).
//! - **Matrices in JSON** are row-major (`m[row][column]`), points are columns
//!   (`p_camera = M · p_world`).
//!
//! Constructors: [`CameraPose::from_scene_camera`], [`CameraPose::look_at`],
//! [`CameraPose::from_opencv`], [`CameraPose::from_opengl`], and in [`framing`] the automatic
//! framing ([`CameraPose::frame`]) and orbits ([`CameraPose::orbit`]). The JSON sidecar
//! and the pose-list reader are in [`sidecar`].

pub mod framing;
pub mod sidecar;

use glam::{DMat4, DVec3, DVec4, Mat4, Vec3, Vec4};
use kantele_rules::backend::{FrameView, Pass};
use kantele_rules::scene::{Camera, Scene};
use serde::{Deserialize, Serialize};
use thiserror::Error;

pub use framing::{Bounds, Silhouette, UpAxis};
pub use sidecar::{read_views, Sidecar, ViewDefaults};

/// A camera that cannot be built or read: the message says which value is wrong.
#[derive(Debug, Error, Clone, PartialEq)]
#[error("{0}")]
pub struct PoseError(pub String);

fn err(message: impl Into<String>) -> PoseError {
    PoseError(message.into())
}

/// Pinhole intrinsics in pixels, OpenCV conventions: x right, y down, the top-left pixel's
/// centre at `(0, 0)`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Intrinsics {
    /// Focal length along x, pixels.
    pub fx: f64,
    /// Focal length along y, pixels.
    pub fy: f64,
    /// Principal point x, pixels.
    pub cx: f64,
    /// Principal point y, pixels.
    pub cy: f64,
}

impl Intrinsics {
    /// Pixel coordinates (OpenCV: top-left pixel centre `(0, 0)`) of an OpenCV camera-frame
    /// point, or `None` when it is not in front of the camera.
    pub fn project(&self, p: DVec3) -> Option<(f64, f64)> {
        (p.z > 0.0).then(|| (self.fx * p.x / p.z + self.cx, self.fy * p.y / p.z + self.cy))
    }
}

/// How the camera maps its frame to the image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Symmetric perspective with vertical field of view `yfov` (radians, in (0, π)); the
    /// horizontal one follows from the image's aspect.
    Perspective {
        /// Vertical field of view, radians.
        yfov: f32,
    },
    /// Pinhole camera given by its intrinsics (any principal point, `fx` and `fy` may differ).
    Pinhole(Intrinsics),
    /// Orthographic: the view volume is `2·xmag × 2·ymag` scene units, `xmag = ymag · width /
    /// height`. Needs a finite `zfar`.
    Orthographic {
        /// Half the view volume's height, scene units.
        ymag: f32,
    },
}

/// Everything that decides a picture's camera: image size, projection, depth range and the
/// world-to-camera transform.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraPose {
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// The projection model.
    pub projection: Projection,
    /// Near plane distance (> 0).
    pub znear: f32,
    /// Far plane distance; `None` is an infinite perspective projection.
    pub zfar: Option<f32>,
    /// World → camera in the OpenGL convention (x right, y up, looking down −Z).
    pub world_to_camera: Mat4,
}

/// The diagonal that converts between the OpenGL and the OpenCV camera frame.
const GL_CV_FLIP: Vec4 = Vec4::new(1.0, -1.0, -1.0, 1.0);

/// World → camera in one convention from world → camera in the other: the y and z rows are
/// negated (exactly, no rounding), so the function is its own inverse.
pub fn opencv_from_opengl(world_to_camera: &Mat4) -> Mat4 {
    Mat4::from_diagonal(GL_CV_FLIP) * *world_to_camera
}

/// A matrix as rows (`m[row][column]`), the layout of the JSON files.
pub fn rows(m: &Mat4) -> [[f32; 4]; 4] {
    m.transpose().to_cols_array_2d()
}

/// A matrix from rows (`m[row][column]`).
pub fn from_rows(rows: &[[f32; 4]; 4]) -> Mat4 {
    Mat4::from_cols_array_2d(rows).transpose()
}

/// Intrinsics of an OpenGL perspective projection matrix for a `width × height` image (the
/// inverse of what [`Projection::Pinhole`] builds).
pub fn intrinsics_of_projection(projection: &Mat4, width: u32, height: u32) -> Intrinsics {
    let (w, h) = (width as f64, height as f64);
    Intrinsics {
        fx: projection.x_axis.x as f64 * w / 2.0,
        fy: projection.y_axis.y as f64 * h / 2.0,
        cx: w / 2.0 * (1.0 - projection.z_axis.x as f64) - 0.5,
        cy: h / 2.0 * (1.0 + projection.z_axis.y as f64) - 0.5,
    }
}

/// Eye-space distance along the view axis (`−z_eye`, positive in front of the camera) of a
/// window depth `d` in [0, 1] under the OpenGL `projection` (window z = (ndc z + 1) / 2).
///
/// Works for finite and infinite perspective projections and orthographic ones: with
/// `z_clip = A z + B` and `w_clip = C z + D`, `ndc = z_clip / w_clip` is solved for `z`.
/// Window depth 1.0 (the cleared background) gives `+inf`; so does the far end of an infinite
/// projection, and any depth that maps behind the camera.
pub fn eye_depth(d: f32, projection: &Mat4) -> f32 {
    if d >= 1.0 || d.is_nan() {
        return f32::INFINITY;
    }
    let ndc = 2.0 * d as f64 - 1.0;
    let a = projection.z_axis.z as f64;
    let b = projection.w_axis.z as f64;
    let c = projection.z_axis.w as f64;
    let dd = projection.w_axis.w as f64;
    let denom = ndc * c - a;
    if denom == 0.0 {
        return f32::INFINITY;
    }
    let dist = -(b - ndc * dd) / denom;
    if dist.is_finite() && dist > 0.0 {
        dist as f32
    } else {
        f32::INFINITY
    }
}

fn check_matrix(m: &Mat4, what: &str) -> Result<(), PoseError> {
    if !m.is_finite() {
        return Err(err(format!("{what}: the matrix has a non-finite entry")));
    }
    let det = m.as_dmat4().determinant();
    if !(det.is_finite() && det != 0.0) {
        return Err(err(format!("{what}: the matrix is singular")));
    }
    Ok(())
}

impl CameraPose {
    /// A checked pose: size in 1..=[`kantele_rules::MAX_TARGET_SIZE`], `0 < znear < zfar` (finite),
    /// a valid projection (`yfov` in (0, π), positive focal lengths or `ymag`, orthographic
    /// needs `zfar`) and a finite, invertible world-to-camera matrix (OpenGL convention).
    pub fn new(
        width: u32,
        height: u32,
        projection: Projection,
        znear: f32,
        zfar: Option<f32>,
        world_to_camera: Mat4,
    ) -> Result<Self, PoseError> {
        let max = kantele_rules::MAX_TARGET_SIZE;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(err(format!(
                "image size {width}x{height} is outside 1..={max}"
            )));
        }
        if !(znear.is_finite() && znear > 0.0) {
            return Err(err(format!("znear {znear} must be finite and > 0")));
        }
        if let Some(far) = zfar {
            if !(far.is_finite() && far > znear) {
                return Err(err(format!(
                    "zfar {far} must be finite and beyond znear {znear}"
                )));
            }
        }
        match projection {
            Projection::Perspective { yfov } => {
                if !(yfov > 0.0 && yfov < std::f32::consts::PI) {
                    return Err(err(format!(
                        "yfov {yfov} rad is outside (0, π) (is it in degrees?)"
                    )));
                }
            }
            Projection::Pinhole(k) => {
                let ok = |v: f64| v.is_finite();
                if !(ok(k.fx) && ok(k.fy) && k.fx > 0.0 && k.fy > 0.0 && ok(k.cx) && ok(k.cy)) {
                    return Err(err(format!(
                        "intrinsics fx {} fy {} cx {} cy {}: focal lengths must be finite and > 0, the principal point finite",
                        k.fx, k.fy, k.cx, k.cy
                    )));
                }
            }
            Projection::Orthographic { ymag } => {
                if !(ymag.is_finite() && ymag > 0.0) {
                    return Err(err(format!("ymag {ymag} must be finite and > 0")));
                }
                if zfar.is_none() {
                    return Err(err("an orthographic camera needs a finite zfar"));
                }
            }
        }
        check_matrix(&world_to_camera, "world_to_camera")?;
        Ok(Self {
            width,
            height,
            projection,
            znear,
            zfar,
            world_to_camera,
        })
    }

    /// The scene file's camera at `width × height`: its view, `yfov` (or `ymag` for an
    /// orthographic camera) and depth range. Its `aspect_ratio` is ignored (pixels stay square;
    /// the image's aspect wins).
    pub fn from_scene_camera(camera: &Camera, width: u32, height: u32) -> Result<Self, PoseError> {
        let projection = match camera.ymag {
            Some(ymag) => Projection::Orthographic { ymag },
            None => Projection::Perspective { yfov: camera.yfov },
        };
        Self::new(
            width,
            height,
            projection,
            camera.znear,
            camera.zfar,
            camera.view,
        )
    }

    /// A perspective camera at `eye` looking at `target`, `up` roughly up (when `up` is
    /// parallel to the view direction another axis is used), vertical field of view `yfov`
    /// (radians). The depth range is `[0.01·d, ∞)` with `d = |eye − target|`; change it with
    /// [`CameraPose::with_depth_range`] or [`CameraPose::fit_depth_range`].
    pub fn look_at(
        eye: Vec3,
        target: Vec3,
        up: Vec3,
        yfov: f32,
        width: u32,
        height: u32,
    ) -> Result<Self, PoseError> {
        let (eye, target) = (eye.as_dvec3(), target.as_dvec3());
        let view = look_at_f64(eye, target, up.as_dvec3())?;
        let distance = distance_f64(eye, target);
        Self::new(
            width,
            height,
            Projection::Perspective { yfov },
            (distance * 0.01) as f32,
            None,
            view,
        )
    }

    /// A pinhole camera from OpenCV intrinsics and an OpenCV world-to-camera matrix.
    pub fn from_opencv(
        intrinsics: Intrinsics,
        world_to_camera_opencv: Mat4,
        width: u32,
        height: u32,
        znear: f32,
        zfar: Option<f32>,
    ) -> Result<Self, PoseError> {
        Self::new(
            width,
            height,
            Projection::Pinhole(intrinsics),
            znear,
            zfar,
            opencv_from_opengl(&world_to_camera_opencv),
        )
    }

    /// A camera from an OpenGL world-to-camera matrix (the backends' view matrix).
    pub fn from_opengl(
        projection: Projection,
        world_to_camera_opengl: Mat4,
        width: u32,
        height: u32,
        znear: f32,
        zfar: Option<f32>,
    ) -> Result<Self, PoseError> {
        Self::new(
            width,
            height,
            projection,
            znear,
            zfar,
            world_to_camera_opengl,
        )
    }

    /// The same camera with another depth range (checked like [`CameraPose::new`]).
    pub fn with_depth_range(self, znear: f32, zfar: Option<f32>) -> Result<Self, PoseError> {
        Self::new(
            self.width,
            self.height,
            self.projection,
            znear,
            zfar,
            self.world_to_camera,
        )
    }

    /// The same camera with a depth range that holds the sphere `(center, radius)`: near at
    /// half the distance to its front (at least 1/1000 of the distance to its centre), far
    /// twice its radius behind it. Unchanged when the sphere is behind the camera.
    pub fn fit_depth_range(self, center: Vec3, radius: f32) -> Result<Self, PoseError> {
        let c = self
            .world_to_camera
            .as_dmat4()
            .transform_point3(center.as_dvec3());
        let distance = -c.z;
        let radius = (radius as f64).abs();
        if !(distance.is_finite() && distance > 0.0 && radius.is_finite()) {
            return Ok(self);
        }
        let (near, far) = framing::depth_range(distance, radius);
        self.with_depth_range(near as f32, Some(far as f32))
    }

    /// Width / height.
    pub fn aspect(&self) -> f64 {
        self.width as f64 / self.height as f64
    }

    /// World → camera, OpenGL convention: the backends' view matrix.
    pub fn view(&self) -> Mat4 {
        self.world_to_camera
    }

    /// World → camera, OpenCV convention.
    pub fn world_to_camera_opencv(&self) -> Mat4 {
        opencv_from_opengl(&self.world_to_camera)
    }

    /// Camera → world (the camera's placement), OpenGL convention.
    pub fn camera_to_world(&self) -> Mat4 {
        self.world_to_camera.as_dmat4().inverse().as_mat4()
    }

    /// The camera centre in world space.
    pub fn eye(&self) -> Vec3 {
        self.world_to_camera
            .as_dmat4()
            .inverse()
            .transform_point3(DVec3::ZERO)
            .as_vec3()
    }

    /// Pinhole intrinsics (`None` for an orthographic camera).
    pub fn intrinsics(&self) -> Option<Intrinsics> {
        let (w, h) = (self.width as f64, self.height as f64);
        match self.projection {
            Projection::Perspective { yfov } => {
                let f = h / 2.0 / (yfov as f64 / 2.0).tan();
                Some(Intrinsics {
                    fx: f,
                    fy: f,
                    cx: w / 2.0 - 0.5,
                    cy: h / 2.0 - 0.5,
                })
            }
            Projection::Pinhole(k) => Some(k),
            Projection::Orthographic { .. } => None,
        }
    }

    /// Vertical field of view in radians (`None` for an orthographic camera): `yfov` itself,
    /// or for a pinhole camera the angle its `fy` spans over the image height.
    pub fn yfov(&self) -> Option<f32> {
        match self.projection {
            Projection::Perspective { yfov } => Some(yfov),
            Projection::Pinhole(k) => Some((2.0 * (self.height as f64 / 2.0 / k.fy).atan()) as f32),
            Projection::Orthographic { .. } => None,
        }
    }

    /// `(xmag, ymag)` of an orthographic camera (`xmag = ymag · width / height`).
    pub fn magnification(&self) -> Option<(f32, f32)> {
        match self.projection {
            Projection::Orthographic { ymag } => Some(((ymag as f64 * self.aspect()) as f32, ymag)),
            _ => None,
        }
    }

    /// Eye → clip, OpenGL conventions: the backends' projection matrix. Computed in `f64`
    /// from the pose's parameters and rounded once, so the same pose always gives the same
    /// matrix.
    pub fn projection(&self) -> Mat4 {
        let (w, h) = (self.width as f64, self.height as f64);
        let n = self.znear as f64;
        let far = self.zfar.map(|f| f as f64);
        // Depth rows of a perspective projection: z_clip = a z + b, w_clip = −z.
        let (a, b) = match far {
            Some(f) => ((f + n) / (n - f), 2.0 * f * n / (n - f)),
            None => (-1.0, -2.0 * n),
        };
        let m = match self.projection {
            Projection::Perspective { .. } | Projection::Pinhole(_) => {
                let k = self.intrinsics().unwrap_or(Intrinsics {
                    fx: 1.0,
                    fy: 1.0,
                    cx: 0.0,
                    cy: 0.0,
                });
                DMat4::from_cols(
                    DVec4::new(2.0 * k.fx / w, 0.0, 0.0, 0.0),
                    DVec4::new(0.0, 2.0 * k.fy / h, 0.0, 0.0),
                    DVec4::new(
                        1.0 - 2.0 * (k.cx + 0.5) / w,
                        2.0 * (k.cy + 0.5) / h - 1.0,
                        a,
                        -1.0,
                    ),
                    DVec4::new(0.0, 0.0, b, 0.0),
                )
            }
            Projection::Orthographic { ymag } => {
                let ymag = ymag as f64;
                let xmag = ymag * self.aspect();
                // `new` guarantees zfar; fall back to a unit depth range otherwise.
                let f = far.unwrap_or(n + 1.0);
                DMat4::from_cols(
                    DVec4::new(1.0 / xmag, 0.0, 0.0, 0.0),
                    DVec4::new(0.0, 1.0 / ymag, 0.0, 0.0),
                    DVec4::new(0.0, 0.0, 2.0 / (n - f), 0.0),
                    DVec4::new(0.0, 0.0, (f + n) / (n - f), 1.0),
                )
            }
        };
        m.as_mat4()
    }

    /// The frame the backends render: this camera, the scene's light (a headlight follows the
    /// camera, as in [`FrameView::of_scene`]) and the given pass.
    pub fn frame_view(&self, scene: &Scene, pass: Pass) -> FrameView {
        let mut view = FrameView::with_matrices(
            scene,
            self.view(),
            self.projection(),
            self.width,
            self.height,
        );
        view.pass = pass;
        view
    }

    /// Pixel coordinates (OpenCV: top-left pixel centre `(0, 0)`) of a world point, and its
    /// planar depth; `None` behind the camera (or for an orthographic camera, outside the
    /// depth range never matters: orthographic points are always projected).
    pub fn project(&self, world: Vec3) -> Option<(f64, f64, f64)> {
        let cv = DMat4::from_diagonal(GL_CV_FLIP.as_dvec4()) * self.world_to_camera.as_dmat4();
        let p = cv.transform_point3(world.as_dvec3());
        match (self.intrinsics(), self.magnification()) {
            (Some(k), _) => k.project(p).map(|(u, v)| (u, v, p.z)),
            (None, Some((xmag, ymag))) => {
                let (w, h) = (self.width as f64, self.height as f64);
                let u = (p.x / xmag as f64 + 1.0) * w / 2.0 - 0.5;
                let v = (p.y / ymag as f64 + 1.0) * h / 2.0 - 0.5;
                Some((u, v, p.z))
            }
            _ => None,
        }
    }

    /// Ratio of ray distance to planar depth at pixel `(x, y)` (its centre): 1 on the optical
    /// axis, larger towards the corners; 1 everywhere for an orthographic camera.
    pub fn ray_distance_factor(&self, x: u32, y: u32) -> f64 {
        match self.intrinsics() {
            Some(k) => {
                let dx = (x as f64 - k.cx) / k.fx;
                let dy = (y as f64 - k.cy) / k.fy;
                (1.0 + dx * dx + dy * dy).sqrt()
            }
            None => 1.0,
        }
    }

    /// Ray distance (camera centre to surface point) at pixel `(x, y)` for a planar depth.
    pub fn ray_distance(&self, planar_depth: f32, x: u32, y: u32) -> f32 {
        (planar_depth as f64 * self.ray_distance_factor(x, y)) as f32
    }

    /// Planar depth (distance along the view axis, background `+inf`) of every pixel of a
    /// row-major window-depth buffer rendered with this camera.
    pub fn planar_depth(&self, window_depth: &[f32]) -> Vec<f32> {
        let projection = self.projection();
        window_depth
            .iter()
            .map(|&d| eye_depth(d, &projection))
            .collect()
    }

    /// Ray distance of every pixel of a row-major window-depth buffer (background `+inf`).
    pub fn ray_depth(&self, window_depth: &[f32]) -> Vec<f32> {
        self.ray_depth_rows(window_depth, 0)
    }

    /// [`CameraPose::ray_depth`] of a band of whole rows starting at picture row `first_row`
    /// (a picture rendered in bands).
    pub fn ray_depth_rows(&self, window_depth: &[f32], first_row: u32) -> Vec<f32> {
        let w = self.width.max(1) as usize;
        self.planar_depth(window_depth)
            .into_iter()
            .enumerate()
            .map(|(i, z)| self.ray_distance(z, (i % w) as u32, first_row + (i / w) as u32))
            .collect()
    }
}

fn distance_f64(a: DVec3, b: DVec3) -> f64 {
    // Scaled so that neither 1e30 nor 1e-30 coordinates overflow or underflow when squared.
    let d = a - b;
    let s = d.abs().max_element();
    if s == 0.0 || !s.is_finite() {
        return s;
    }
    (d / s).length() * s
}

/// Unit vector of `v` without overflow or underflow (`None` for zero or non-finite).
fn unit(v: DVec3) -> Option<DVec3> {
    let s = v.abs().max_element();
    if s == 0.0 || !s.is_finite() {
        return None;
    }
    (v / s).try_normalize()
}

/// World → camera (OpenGL) looking from `eye` at `target`, computed in `f64`.
pub(crate) fn look_at_f64(eye: DVec3, target: DVec3, up: DVec3) -> Result<Mat4, PoseError> {
    if !eye.is_finite() || !target.is_finite() {
        return Err(err(format!(
            "look-at eye {eye} and target {target} must be finite"
        )));
    }
    let back = unit(eye - target)
        .ok_or_else(|| err(format!("look-at eye and target are the same point {eye}")))?;
    let up = unit(up).unwrap_or(DVec3::Y);
    let up = if back.cross(up).length_squared() < 1e-12 {
        // Looking along `up`: any perpendicular axis will do.
        if back.cross(DVec3::Z).length_squared() < 1e-12 {
            DVec3::Y
        } else {
            DVec3::Z
        }
    } else {
        up
    };
    let right = up.cross(back).normalize();
    let up = back.cross(right);
    let m = DMat4::from_cols(
        DVec4::new(right.x, up.x, back.x, 0.0),
        DVec4::new(right.y, up.y, back.y, 0.0),
        DVec4::new(right.z, up.z, back.z, 0.0),
        DVec4::new(-right.dot(eye), -up.dot(eye), -back.dot(eye), 1.0),
    );
    Ok(m.as_mat4())
}
