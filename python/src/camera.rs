//! `kantele.Camera`: a [`CameraPose`] from `kantele_output::pose` — the conventions the CLI and its
//! JSON sidecar use — with an optional image size.

use glam::{Mat4, Vec3};
use kantele::backend::{FrameView, Pass};
use kantele::scene::Scene;
use kantele_output::pose::{
    self, sidecar::SidecarCamera, CameraPose, Intrinsics, PoseError, Projection, Silhouette, UpAxis,
};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::value_error;

/// A camera: where it is, how it projects, its depth range and, when it has one, its image size.
///
/// Conventions (`kantele_output::pose`): the OpenGL camera frame looks down −Z with y up; the OpenCV
/// frame looks down +Z with y down; intrinsics are in pixels with the top-left pixel's centre at
/// (0, 0); matrices are row-major with points as columns.
#[pyclass(name = "Camera", module = "kantele", frozen, from_py_object)]
#[derive(Clone, Debug)]
pub struct PyCamera {
    /// The pose, at `size` or, without one, at a placeholder size replaced when rendering.
    pose: CameraPose,
    /// The image size the camera was made for, if any.
    size: Option<(u32, u32)>,
}

pub(crate) fn pose_error(e: PoseError) -> PyErr {
    value_error(e.0)
}

impl PyCamera {
    /// A camera with the given pose, tied to its size or not.
    pub fn new(pose: CameraPose, sized: bool) -> Self {
        let size = sized.then_some((pose.width, pose.height));
        Self { pose, size }
    }

    /// The image size the camera was made for, if any.
    pub fn size(&self) -> Option<(u32, u32)> {
        self.size
    }

    /// The pose at `width × height`. A pinhole camera's intrinsics belong to its own size, so
    /// another size is an error; the other projections keep their field of view.
    pub fn pose_at(&self, width: u32, height: u32) -> Result<CameraPose, PoseError> {
        if (width, height) == (self.pose.width, self.pose.height) {
            return Ok(self.pose);
        }
        if let (Projection::Pinhole(_), Some((w, h))) = (self.pose.projection, self.size) {
            return Err(PoseError(format!(
                "the camera's intrinsics are for {w}x{h} images, not {width}x{height}"
            )));
        }
        let p = &self.pose;
        CameraPose::new(
            width,
            height,
            p.projection,
            p.znear,
            p.zfar,
            p.world_to_camera,
        )
    }

    /// The frame view of `scene` through this camera at `width × height`.
    pub fn frame_view(&self, scene: &Scene, width: u32, height: u32) -> PyResult<FrameView> {
        let pose = self.pose_at(width, height).map_err(pose_error)?;
        Ok(pose.frame_view(scene, Pass::Color))
    }
}

fn vec3(v: [f64; 3]) -> Vec3 {
    Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)
}

fn size_arg(size: Option<(i64, i64)>) -> PyResult<Option<(u32, u32)>> {
    let max = kantele::MAX_TARGET_SIZE as i64;
    match size {
        None => Ok(None),
        Some((w, h)) if (1..=max).contains(&w) && (1..=max).contains(&h) => {
            Ok(Some((w as u32, h as u32)))
        }
        Some((w, h)) => Err(value_error(format!(
            "size {w}x{h} is outside 1..={max} on a side"
        ))),
    }
}

/// A 4×4 matrix from a (4, 4) or (3, 4) array (the missing row is `0 0 0 1`).
fn matrix_arg(m: &Bound<'_, PyAny>, name: &str) -> PyResult<Mat4> {
    let numpy = m.py().import("numpy")?;
    let array = numpy
        .call_method1("ascontiguousarray", (m, "float32"))
        .map_err(|e| value_error(format!("{name}: not a matrix ({e})")))?;
    let array: PyReadonlyArray2<'_, f32> = array
        .extract()
        .map_err(|_| value_error(format!("{name}: expected a (4, 4) or (3, 4) matrix")))?;
    let shape = array.shape().to_vec();
    if shape[1] != 4 || !(shape[0] == 4 || shape[0] == 3) {
        return Err(value_error(format!(
            "{name}: expected a (4, 4) or (3, 4) matrix, got {shape:?}"
        )));
    }
    let mut rows = [[0.0, 0.0, 0.0, 1.0]; 4];
    for (r, row) in rows.iter_mut().enumerate().take(shape[0]) {
        for (c, v) in row.iter_mut().enumerate() {
            *v = *array.get([r, c]).expect("index within the checked shape");
        }
    }
    Ok(pose::from_rows(&rows))
}

fn matrix<'py>(py: Python<'py>, m: &Mat4) -> Bound<'py, PyArray2<f32>> {
    let rows: Vec<f32> = pose::rows(m).iter().flatten().copied().collect();
    Array2::from_shape_vec((4, 4), rows)
        .expect("16 values make a 4x4 matrix")
        .into_pyarray(py)
}

/// Orbit cameras of `scene` (the CLI's `--orbit`).
pub fn orbit(
    scene: &Scene,
    views: u32,
    width: u32,
    height: u32,
    elevation_deg: f32,
    yfov_deg: f32,
) -> Result<Vec<CameraPose>, PoseError> {
    let silhouette = Silhouette::of_scene(scene)
        .ok_or_else(|| PoseError("the scene draws nothing, so there is nothing to orbit".into()))?;
    CameraPose::orbit(
        &silhouette,
        views,
        elevation_deg,
        None,
        UpAxis::Y,
        yfov_deg.to_radians(),
        width,
        height,
    )
}

/// A camera framing all of `scene` from `direction` (towards the camera).
pub fn framing(
    scene: &Scene,
    direction: Vec3,
    width: u32,
    height: u32,
    yfov_deg: f32,
) -> Result<CameraPose, PoseError> {
    let silhouette = Silhouette::of_scene(scene)
        .ok_or_else(|| PoseError("the scene draws nothing, so there is nothing to frame".into()))?;
    CameraPose::frame(
        &silhouette,
        direction,
        UpAxis::Y,
        yfov_deg.to_radians(),
        width,
        height,
    )
}

#[pymethods]
impl PyCamera {
    /// A perspective camera at `eye` looking at `target`, `up` roughly up, with a vertical field
    /// of view of `yfov` radians. The depth range is `[0.01·|eye − target|, ∞)` unless `znear`
    /// / `zfar` are given. `size` ties the camera to an image size (the default size of
    /// `render`).
    #[staticmethod]
    // The text signature spells the array default as Python does, so that `help()` shows it.
    #[pyo3(
        signature = (eye, target, up = [0.0, 1.0, 0.0], yfov = 0.8, size = None, znear = None, zfar = None),
        text_signature = "(eye, target, up=(0.0, 1.0, 0.0), yfov=0.8, size=None, znear=None, zfar=None)"
    )]
    fn look_at(
        eye: [f64; 3],
        target: [f64; 3],
        up: [f64; 3],
        yfov: f32,
        size: Option<(i64, i64)>,
        znear: Option<f32>,
        zfar: Option<f32>,
    ) -> PyResult<Self> {
        let sized = size_arg(size)?;
        let (w, h) = sized.unwrap_or((1, 1));
        let mut pose = CameraPose::look_at(vec3(eye), vec3(target), vec3(up), yfov, w, h)
            .map_err(pose_error)?;
        if znear.is_some() || zfar.is_some() {
            pose = pose
                .with_depth_range(znear.unwrap_or(pose.znear), zfar)
                .map_err(pose_error)?;
        }
        Ok(Self::new(pose, sized.is_some()))
    }

    /// A pinhole camera from OpenCV intrinsics (`fx`, `fy`, `cx`, `cy` in pixels, the top-left
    /// pixel's centre at (0, 0)) and an OpenCV world-to-camera matrix ((4, 4) or (3, 4): x
    /// right, y down, looking down +Z), for images of `size` = (width, height).
    #[staticmethod]
    #[pyo3(signature = (fx, fy, cx, cy, world_to_camera, size, znear = 0.01, zfar = None))]
    #[allow(clippy::too_many_arguments)]
    fn from_opencv(
        fx: f64,
        fy: f64,
        cx: f64,
        cy: f64,
        world_to_camera: Bound<'_, PyAny>,
        size: (i64, i64),
        znear: f32,
        zfar: Option<f32>,
    ) -> PyResult<Self> {
        let (w, h) = size_arg(Some(size))?.expect("a size was given");
        let m = matrix_arg(&world_to_camera, "world_to_camera")?;
        let pose = CameraPose::from_opencv(Intrinsics { fx, fy, cx, cy }, m, w, h, znear, zfar)
            .map_err(pose_error)?;
        Ok(Self::new(pose, true))
    }

    /// A perspective camera from an OpenGL world-to-camera matrix (the backends' view matrix: x
    /// right, y up, looking down −Z) and a vertical field of view `yfov` in radians.
    #[staticmethod]
    #[pyo3(signature = (world_to_camera, yfov = 0.8, size = None, znear = 0.01, zfar = None))]
    fn from_opengl(
        world_to_camera: Bound<'_, PyAny>,
        yfov: f32,
        size: Option<(i64, i64)>,
        znear: f32,
        zfar: Option<f32>,
    ) -> PyResult<Self> {
        let sized = size_arg(size)?;
        let (w, h) = sized.unwrap_or((1, 1));
        let m = matrix_arg(&world_to_camera, "world_to_camera")?;
        let pose = CameraPose::from_opengl(Projection::Perspective { yfov }, m, w, h, znear, zfar)
            .map_err(pose_error)?;
        Ok(Self::new(pose, sized.is_some()))
    }

    /// The cameras of a view file: a sidecar `kantele render` wrote, a list of them, or a list
    /// of pose records (see `kantele render --views`); `size` where a record has none.
    #[staticmethod]
    #[pyo3(signature = (path, size = None))]
    fn read_views(path: std::path::PathBuf, size: Option<(i64, i64)>) -> PyResult<Vec<Self>> {
        // Missing or unreadable files raise what `kantele.load` raises for them.
        if let Err(e) = std::fs::metadata(&path) {
            return Err(crate::errors::io_error(&path, e));
        }
        let defaults = pose::ViewDefaults {
            size: size_arg(size)?,
            ..Default::default()
        };
        let poses = pose::sidecar::read_views_file(&path, &defaults).map_err(pose_error)?;
        Ok(poses.into_iter().map(|p| Self::new(p, true)).collect())
    }

    /// The same camera with another depth range (`zfar=None`: infinite).
    #[pyo3(signature = (znear, zfar = None))]
    fn with_depth_range(&self, znear: f32, zfar: Option<f32>) -> PyResult<Self> {
        let pose = self
            .pose
            .with_depth_range(znear, zfar)
            .map_err(pose_error)?;
        Ok(Self { pose, ..*self })
    }

    /// The image size `(width, height)` the camera was made for, or `None`.
    #[getter(size)]
    fn size_py(&self) -> Option<(u32, u32)> {
        self.size
    }

    /// World → camera, 4×4, OpenGL camera frame (x right, y up, looking down −Z).
    #[getter]
    fn world_to_camera_gl<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f32>> {
        matrix(py, &self.pose.view())
    }

    /// World → camera, 4×4, OpenCV camera frame (x right, y down, looking down +Z).
    #[getter]
    fn world_to_camera_opencv<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f32>> {
        matrix(py, &self.pose.world_to_camera_opencv())
    }

    /// The camera's position in the world.
    #[getter]
    fn eye(&self) -> (f32, f32, f32) {
        self.pose.eye().into()
    }

    /// Vertical field of view in radians (for a pinhole camera, the angle `fy` spans).
    #[getter]
    fn yfov(&self) -> Option<f32> {
        self.pose.yfov()
    }

    /// Near plane distance.
    #[getter]
    fn znear(&self) -> f32 {
        self.pose.znear
    }

    /// Far plane distance (`None`: infinite).
    #[getter]
    fn zfar(&self) -> Option<f32> {
        self.pose.zfar
    }

    /// OpenCV intrinsics `(fx, fy, cx, cy)` in pixels for images of `size` (default: the
    /// camera's own size).
    #[pyo3(signature = (size = None))]
    fn intrinsics(&self, size: Option<(i64, i64)>) -> PyResult<(f64, f64, f64, f64)> {
        let pose = self.sized_pose(size)?;
        let k = pose
            .intrinsics()
            .ok_or_else(|| value_error("an orthographic camera has no intrinsics"))?;
        Ok((k.fx, k.fy, k.cx, k.cy))
    }

    /// The OpenGL projection matrix (4×4, eye → clip) for images of `size` (default: the
    /// camera's own size).
    #[pyo3(signature = (size = None))]
    fn projection<'py>(
        &self,
        py: Python<'py>,
        size: Option<(i64, i64)>,
    ) -> PyResult<Bound<'py, PyArray2<f32>>> {
        Ok(matrix(py, &self.sized_pose(size)?.projection()))
    }

    /// The camera as a `kantele render` sidecar describes it, for images of `size` (default: the
    /// camera's own size): `{"camera": {model, fx, fy, cx, cy, width, height, yfov, znear, zfar,
    /// projection_gl, ...}, "world_to_camera_gl": rows, "world_to_camera_opencv": rows}`.
    /// `Camera.read_views` reads a list of these back as the same cameras.
    #[pyo3(signature = (size = None))]
    fn to_dict<'py>(
        &self,
        py: Python<'py>,
        size: Option<(i64, i64)>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let pose = self.sized_pose(size)?;
        let camera = serde_json::to_string(&SidecarCamera::of_pose(&pose))
            .map_err(|e| value_error(format!("camera: {e}")))?;
        let dict = PyDict::new(py);
        dict.set_item(
            "camera",
            py.import("json")?.call_method1("loads", (camera,))?,
        )?;
        dict.set_item("world_to_camera_gl", pose::rows(&pose.view()))?;
        dict.set_item(
            "world_to_camera_opencv",
            pose::rows(&pose.world_to_camera_opencv()),
        )?;
        Ok(dict)
    }

    fn __repr__(&self) -> String {
        let eye = self.pose.eye();
        let size = match self.size {
            Some((w, h)) => format!("{w}x{h}"),
            None => "None".into(),
        };
        format!(
            "Camera(eye=({:.4}, {:.4}, {:.4}), yfov={:?}, znear={}, zfar={:?}, size={size})",
            eye.x,
            eye.y,
            eye.z,
            self.pose.yfov(),
            self.pose.znear,
            self.pose.zfar
        )
    }
}

impl PyCamera {
    fn sized_pose(&self, size: Option<(i64, i64)>) -> PyResult<CameraPose> {
        let (w, h) = match (size_arg(size)?, self.size) {
            (Some(s), _) | (None, Some(s)) => s,
            (None, None) => {
                return Err(value_error(
                    "the camera has no image size of its own: pass size=(width, height)",
                ))
            }
        };
        self.pose_at(w, h).map_err(pose_error)
    }
}
