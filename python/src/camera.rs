//! `kantele.Camera`: where a picture is taken from.
// TODO(pose): build on kantele_io::pose (look-at, OpenCV intrinsics, orbit) once it is on main.

use glam::{Mat4, Vec3};
use kantele::backend::FrameView;
use kantele::scene::{Camera, Scene};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2};
use pyo3::prelude::*;

use crate::errors::value_error;

/// A perspective camera (OpenGL conventions: looks down −Z of its own frame, y up).
#[pyclass(name = "Camera", module = "kantele", frozen, from_py_object)]
#[derive(Clone, Debug)]
pub struct PyCamera {
    pub(crate) camera: Camera,
}

impl PyCamera {
    /// The frame view of `scene` through this camera at `width × height`.
    pub fn frame_view(&self, scene: &Scene, width: u32, height: u32) -> FrameView {
        FrameView::with_camera(scene, &self.camera, width, height)
    }
}

fn vec3(v: [f64; 3], name: &str) -> PyResult<Vec3> {
    let v = Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32);
    if v.is_finite() {
        Ok(v)
    } else {
        Err(value_error(format!("{name}: not finite: {v}")))
    }
}

fn matrix<'py>(py: Python<'py>, m: &Mat4) -> Bound<'py, PyArray2<f32>> {
    let rows: Vec<f32> = m.transpose().to_cols_array().to_vec();
    Array2::from_shape_vec((4, 4), rows)
        .expect("16 values make a 4x4 matrix")
        .into_pyarray(py)
}

#[pymethods]
impl PyCamera {
    /// A camera at `eye` looking at `target`, with `up` roughly up and a vertical field of
    /// view of `yfov` radians.
    #[staticmethod]
    #[pyo3(signature = (eye, target, up = [0.0, 1.0, 0.0], yfov = 0.8, znear = 0.01, zfar = None))]
    fn look_at(
        eye: [f64; 3],
        target: [f64; 3],
        up: [f64; 3],
        yfov: f64,
        znear: f64,
        zfar: Option<f64>,
    ) -> PyResult<Self> {
        let (eye, target, up) = (vec3(eye, "eye")?, vec3(target, "target")?, vec3(up, "up")?);
        let forward = target - eye;
        if forward.length_squared() == 0.0 || forward.cross(up).length_squared() == 0.0 {
            return Err(value_error(
                "look_at: eye, target and up must not be collinear (and eye != target)",
            ));
        }
        if !(yfov > 0.0 && yfov < std::f64::consts::PI) {
            return Err(value_error(format!(
                "yfov {yfov} is outside (0, pi) radians"
            )));
        }
        let far_ok = zfar.is_none_or(|f| f > znear && f.is_finite());
        if !(znear.is_finite() && znear > 0.0 && far_ok) {
            return Err(value_error("znear must be > 0 and zfar > znear"));
        }
        Ok(Self {
            camera: Camera {
                view: kantele::camera::look_at(eye, target, up),
                yfov: yfov as f32,
                aspect_ratio: None,
                znear: znear as f32,
                zfar: zfar.map(|f| f as f32),
            },
        })
    }

    /// World → camera matrix (4×4, OpenGL camera frame: x right, y up, looking down −z).
    #[getter]
    fn world_to_camera_gl<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f32>> {
        matrix(py, &self.camera.view)
    }

    /// Vertical field of view in radians.
    #[getter]
    fn yfov(&self) -> f32 {
        self.camera.yfov
    }

    /// Near plane distance.
    #[getter]
    fn znear(&self) -> f32 {
        self.camera.znear
    }

    /// Far plane distance (`None`: infinite projection).
    #[getter]
    fn zfar(&self) -> Option<f32> {
        self.camera.zfar
    }

    fn __repr__(&self) -> String {
        let eye = self.camera.world_from_eye().transform_point3(Vec3::ZERO);
        format!(
            "Camera(eye=({:.4}, {:.4}, {:.4}), yfov={:.4}, znear={}, zfar={:?})",
            eye.x, eye.y, eye.z, self.camera.yfov, self.camera.znear, self.camera.zfar
        )
    }
}

/// Elevation of orbit cameras above the bounding sphere's equator, as `kantele render --orbit`.
pub const ORBIT_ELEVATION_DEG: f32 = 20.0;

/// Most cameras one orbit call makes.
pub const MAX_ORBIT_VIEWS: usize = 1 << 20;

/// `n` cameras circling the scene's bounding sphere at `elevation_deg`, each framing it for
/// `aspect` (width / height), starting on +Z and turning towards +X: the cameras of
/// `kantele render --orbit n`.
pub fn orbit_cameras(
    scene: &Scene,
    n: usize,
    aspect: f32,
    elevation_deg: f32,
) -> Result<Vec<Camera>, String> {
    let (center, radius) = scene
        .bounding_sphere()
        .ok_or("the scene draws nothing, so there is nothing to orbit")?;
    if n == 0 || n > MAX_ORBIT_VIEWS {
        return Err(format!("views {n} is outside 1..={MAX_ORBIT_VIEWS}"));
    }
    if !(-90.0..=90.0).contains(&elevation_deg) {
        return Err(format!(
            "elevation {elevation_deg} is outside -90..=90 degrees"
        ));
    }
    let elevation = elevation_deg.to_radians();
    Ok((0..n)
        .map(|k| {
            let theta = std::f32::consts::TAU * k as f32 / n as f32;
            let dir = Vec3::new(
                theta.sin() * elevation.cos(),
                elevation.sin(),
                theta.cos() * elevation.cos(),
            );
            Camera::framing(center, radius, dir, aspect)
        })
        .collect())
}
