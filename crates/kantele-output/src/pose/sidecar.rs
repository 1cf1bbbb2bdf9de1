//! The JSON sidecar `kantele render` writes next to each picture, and the reader of view files
//! (`--views FILE`): a sidecar, a list of sidecars, or a plain list of poses.
//!
//! A pose record is a JSON object with
//! - the world-to-camera 4×4 matrix, row-major: `"world_to_camera": [[...], ...]` with
//!   `"convention": "opencv"` or `"opengl"`, or the keys `"world_to_camera_opencv"` /
//!   `"world_to_camera_gl"` (as a sidecar has them);
//! - the projection: intrinsics `"fx"`, `"fy"`, `"cx"`, `"cy"` (pixels, top-left pixel centre at
//!   (0, 0)), or a vertical field of view `"yfov"` (radians) or `"yfov_deg"`, or an orthographic
//!   `"ymag"`;
//! - optionally `"width"`, `"height"` (else the [`ViewDefaults`]' size), `"znear"` (else the
//!   defaults', else [`DEFAULT_ZNEAR`], as Python's `Camera.from_opencv`) and `"zfar"` (else the
//!   defaults', else infinite).
//!
//! A file is one record, a list of records, or `{"views": [records]}`. A sidecar is read
//! through its `camera` and `world_to_camera_gl`, so it reproduces the projection and view
//! matrices of the picture it describes bit for bit.

use std::path::Path;

use glam::Mat4;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::{
    err, from_rows, opencv_from_opengl, rows, CameraPose, Intrinsics, PoseError, Projection,
};

/// Near plane of a pose record that gives none, scene units (Python's `Camera.from_opencv` and
/// `Camera.from_opengl` default to it too).
pub const DEFAULT_ZNEAR: f32 = 0.01;

/// What [`SidecarCamera::pixel_centers`] says.
pub const PIXEL_CENTERS: &str =
    "integer coordinates (OpenCV): the top-left pixel's centre is (0, 0)";
/// What [`Sidecar::matrix_layout`] says.
pub const MATRIX_LAYOUT: &str =
    "row-major: matrix[row][column]; points are columns (p_cam = M * p_world)";
/// What [`SidecarIds::channels`] says.
pub const ID_CHANNELS: &str = "R = instance id (node_index + 1), G = triangle id (triangle index in its primitive + 1), B = primitive id (draw index + 1: a mesh primitive placed by a node); 0 = background";

/// One rendered view: the picture's files, the renderer, and the camera.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sidecar {
    /// The scene's file stem or built-in name.
    pub scene: String,
    /// Where the scene came from (path or `builtin:NAME`).
    pub source: String,
    /// The colour image's path.
    pub output: String,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Backend name (`cpu`, `gl`).
    pub backend: String,
    /// What actually rendered.
    pub renderer: String,
    /// Threads the backend rendered with.
    pub threads: usize,
    /// Time of the colour frame, milliseconds.
    pub render_ms: f64,
    /// Intrinsics and projection.
    pub camera: SidecarCamera,
    /// World → camera, OpenGL convention (the backends' view matrix), rows.
    pub world_to_camera_gl: [[f32; 4]; 4],
    /// World → camera, OpenCV convention, rows.
    pub world_to_camera_opencv: [[f32; 4]; 4],
    /// How the matrices are laid out ([`MATRIX_LAYOUT`]).
    pub matrix_layout: String,
    /// The depth image.
    pub depth: SidecarDepth,
    /// The normal image, if written.
    pub normals: Option<SidecarNormals>,
    /// The id image and what the ids mean.
    pub ids: SidecarIds,
    /// The animation the scene was posed by and the time it was posed at; absent for the
    /// rest pose.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub animation: Option<SidecarAnimation>,
}

/// The animation pose of one rendered view (`--animation`, `--time`, `--time-range`): loading
/// the scene with this animation at this time gives the pictured pose.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SidecarAnimation {
    /// The animation's index in the file.
    pub index: usize,
    /// Its name (`animation N` for one without a name).
    pub name: String,
    /// The time posed at, seconds.
    pub time: f32,
}

/// The sidecar of an animation (a turntable, `--orbit N -o spin.gif`): one [`Sidecar`] per
/// frame, frame `k` at `views[k]`. As a views file (`--views`) it renders every frame again.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AnimationSidecar {
    /// The scene's file stem or built-in name.
    pub scene: String,
    /// Where the scene came from (path or `builtin:NAME`).
    pub source: String,
    /// The animation's path.
    pub output: String,
    /// Frames per second.
    pub fps: u16,
    /// Number of frames (`views.len()`).
    pub frames: usize,
    /// Each frame's view, in frame order.
    pub views: Vec<Sidecar>,
}

/// The kind of projection a sidecar camera has.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ProjectionModel {
    /// Symmetric perspective from `yfov`.
    Perspective,
    /// Pinhole from `fx fy cx cy`.
    Pinhole,
    /// Orthographic from `ymag`.
    Orthographic,
}

/// A sidecar's camera: intrinsics, field of view, depth range and the projection matrix.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SidecarCamera {
    /// The projection model; absent in older sidecars (then `yfov` decides).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<ProjectionModel>,
    /// Focal length along x, pixels (`null` for orthographic).
    pub fx: Option<f64>,
    /// Focal length along y, pixels.
    pub fy: Option<f64>,
    /// Principal point x, pixels.
    pub cx: Option<f64>,
    /// Principal point y, pixels.
    pub cy: Option<f64>,
    /// Where pixel centres are ([`PIXEL_CENTERS`]).
    pub pixel_centers: String,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Vertical field of view, radians (`null` for orthographic).
    pub yfov: Option<f32>,
    /// Width / height (pixels are square).
    pub aspect_ratio: f32,
    /// Orthographic half width, scene units.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub xmag: Option<f32>,
    /// Orthographic half height, scene units.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ymag: Option<f32>,
    /// Near plane distance.
    pub znear: f32,
    /// Far plane distance (`null`: infinite).
    pub zfar: Option<f32>,
    /// Eye → clip, OpenGL conventions, rows.
    pub projection_gl: [[f32; 4]; 4],
}

/// A sidecar's depth entry.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SidecarDepth {
    /// The depth file, if written.
    pub file: Option<String>,
    /// `eye` (planar distance along the view axis) or `window` (depth buffer value).
    pub kind: String,
    /// The convention in words.
    pub description: String,
    /// The value of pixels nothing covers (`"inf"` or a number).
    pub background: Value,
}

impl SidecarDepth {
    /// Planar eye depth, background `+inf`.
    pub fn eye(file: Option<String>) -> Self {
        Self {
            file,
            kind: "eye".into(),
            description: "distance along the camera's view axis (-z in OpenGL eye space, +z in OpenCV camera space), scene units, 32-bit float".into(),
            background: Value::from("inf"),
        }
    }

    /// Window depth in [0, 1], background 1.
    pub fn window(file: Option<String>) -> Self {
        Self {
            file,
            kind: "window".into(),
            description:
                "window depth (ndc_z + 1) / 2 in [0, 1] under the projection below, 32-bit float"
                    .into(),
            background: Value::from(1.0),
        }
    }
}

/// A sidecar's normals entry.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SidecarNormals {
    /// The normal file.
    pub file: String,
    /// How normals are stored.
    pub encoding: String,
}

/// A sidecar's id entry: the id files and the meaning of every id. (Sidecars written before the
/// one-channel files had a `file` entry, always `null`; it is ignored when read.)
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SidecarIds {
    /// What each channel holds ([`ID_CHANNELS`]).
    pub channels: String,
    /// One-channel id files by kind (`instance`, `mesh`, `material`, `primitive` = a glTF mesh
    /// primitive placed by a node, i.e. one draw, `triangle` = triangle index in its primitive
    /// + 1), each 0 on the background.
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub files: std::collections::BTreeMap<String, String>,
    /// Instance ids and their nodes.
    pub instance_ids: Vec<InstanceId>,
    /// Primitive ids (one per draw: a mesh primitive placed by a node) and their meshes and
    /// nodes. Sidecars written before the id names were unified call this `draw_ids`.
    #[serde(alias = "draw_ids")]
    pub primitive_ids: Vec<PrimitiveId>,
}

/// One instance id.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct InstanceId {
    /// The id (`node_index + 1`).
    pub id: usize,
    /// The node's index.
    pub node_index: usize,
    /// The node's name.
    pub node_name: String,
}

/// One primitive id: a glTF mesh primitive placed by a node (one draw).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PrimitiveId {
    /// The id (draw index + 1).
    pub id: usize,
    /// The mesh drawn.
    pub mesh_index: usize,
    /// Its name.
    pub mesh_name: String,
    /// The node that draws it.
    pub node_index: usize,
    /// Its name.
    pub node_name: String,
}

impl SidecarCamera {
    /// The camera entry of a pose.
    pub fn of_pose(pose: &CameraPose) -> Self {
        let k = pose.intrinsics();
        let mag = pose.magnification();
        Self {
            model: Some(match pose.projection {
                Projection::Perspective { .. } => ProjectionModel::Perspective,
                Projection::Pinhole(_) => ProjectionModel::Pinhole,
                Projection::Orthographic { .. } => ProjectionModel::Orthographic,
            }),
            fx: k.map(|k| k.fx),
            fy: k.map(|k| k.fy),
            cx: k.map(|k| k.cx),
            cy: k.map(|k| k.cy),
            pixel_centers: PIXEL_CENTERS.into(),
            width: pose.width,
            height: pose.height,
            yfov: pose.yfov(),
            aspect_ratio: pose.aspect() as f32,
            xmag: mag.map(|m| m.0),
            ymag: mag.map(|m| m.1),
            znear: pose.znear,
            zfar: pose.zfar,
            projection_gl: rows(&pose.projection()),
        }
    }

    /// The projection this entry describes: its `model`, or for older sidecars `yfov` when
    /// present, else the intrinsics.
    pub fn projection(&self) -> Result<Projection, PoseError> {
        let intrinsics = || -> Result<Projection, PoseError> {
            match (self.fx, self.fy, self.cx, self.cy) {
                (Some(fx), Some(fy), Some(cx), Some(cy)) => {
                    Ok(Projection::Pinhole(Intrinsics { fx, fy, cx, cy }))
                }
                _ => Err(err("camera: pinhole needs fx, fy, cx and cy")),
            }
        };
        match self.model {
            Some(ProjectionModel::Perspective) | None if self.yfov.is_some() => {
                Ok(Projection::Perspective {
                    yfov: self.yfov.unwrap_or_default(),
                })
            }
            Some(ProjectionModel::Perspective) => Err(err("camera: perspective needs yfov")),
            Some(ProjectionModel::Pinhole) | None => intrinsics(),
            Some(ProjectionModel::Orthographic) => self
                .ymag
                .map(|ymag| Projection::Orthographic { ymag })
                .ok_or_else(|| err("camera: orthographic needs ymag")),
        }
    }
}

impl SidecarCamera {
    /// The pose of this camera with the sidecar's `world_to_camera_gl` rows.
    pub fn pose(&self, world_to_camera_gl: &[[f32; 4]; 4]) -> Result<CameraPose, PoseError> {
        CameraPose::new(
            self.width,
            self.height,
            self.projection()?,
            self.znear,
            self.zfar,
            from_rows(world_to_camera_gl),
        )
    }
}

impl Sidecar {
    /// The camera that rendered this view.
    pub fn pose(&self) -> Result<CameraPose, PoseError> {
        self.camera.pose(&self.world_to_camera_gl)
    }
}

/// Values a pose record may leave out.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ViewDefaults {
    /// Image size when a record has none.
    pub size: Option<(u32, u32)>,
    /// Near plane when a record has none.
    pub znear: Option<f32>,
    /// Far plane when a record has none (`None`: infinite, or an error for orthographic).
    pub zfar: Option<f32>,
}

/// Which camera frame a pose record's matrix is in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Convention {
    /// x right, y down, looking down +Z.
    Opencv,
    /// x right, y up, looking down −Z.
    Opengl,
}

/// One pose of a plain pose list (see the module docs).
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
struct PoseRecord {
    world_to_camera: Option<[[f64; 4]; 4]>,
    convention: Option<Convention>,
    world_to_camera_opencv: Option<[[f64; 4]; 4]>,
    world_to_camera_gl: Option<[[f64; 4]; 4]>,
    width: Option<u32>,
    height: Option<u32>,
    fx: Option<f64>,
    fy: Option<f64>,
    cx: Option<f64>,
    cy: Option<f64>,
    yfov: Option<f32>,
    yfov_deg: Option<f32>,
    ymag: Option<f32>,
    znear: Option<f32>,
    zfar: Option<f32>,
}

fn matrix(rows64: &[[f64; 4]; 4]) -> Result<Mat4, PoseError> {
    let rows32 = rows64.map(|r| r.map(|v| v as f32));
    let m = from_rows(&rows32);
    if !m.is_finite() {
        return Err(err("world_to_camera has an entry that is not a finite f32"));
    }
    Ok(m)
}

impl PoseRecord {
    fn pose(&self, defaults: &ViewDefaults) -> Result<CameraPose, PoseError> {
        let world_to_camera_gl = match (
            &self.world_to_camera,
            self.convention,
            &self.world_to_camera_opencv,
            &self.world_to_camera_gl,
        ) {
            (Some(m), Some(Convention::Opencv), None, None) | (None, None, Some(m), None) => {
                opencv_from_opengl(&matrix(m)?)
            }
            (Some(m), Some(Convention::Opengl), None, None) | (None, None, None, Some(m)) => {
                matrix(m)?
            }
            (Some(_), None, None, None) => {
                return Err(err(
                    "world_to_camera needs \"convention\": \"opencv\" or \"opengl\"",
                ))
            }
            (None, _, None, None) => {
                return Err(err(
                    "no world_to_camera (or world_to_camera_opencv / world_to_camera_gl) matrix",
                ))
            }
            _ => {
                return Err(err(
                    "give exactly one world-to-camera matrix (world_to_camera with a convention, world_to_camera_opencv or world_to_camera_gl)",
                ))
            }
        };
        let (width, height) = match (self.width, self.height, defaults.size) {
            (Some(w), Some(h), _) => (w, h),
            (None, None, Some(size)) => size,
            _ => {
                return Err(err(
                    "the pose needs both width and height (or an image size)",
                ))
            }
        };
        let has_intrinsics = [self.fx, self.fy, self.cx, self.cy];
        let projection = match (has_intrinsics, self.yfov, self.yfov_deg, self.ymag) {
            ([Some(fx), Some(fy), Some(cx), Some(cy)], None, None, None) => {
                Projection::Pinhole(Intrinsics { fx, fy, cx, cy })
            }
            ([None, None, None, None], Some(yfov), None, None) => Projection::Perspective { yfov },
            ([None, None, None, None], None, Some(deg), None) => Projection::Perspective {
                yfov: deg.to_radians(),
            },
            ([None, None, None, None], None, None, Some(ymag)) => {
                Projection::Orthographic { ymag }
            }
            _ => {
                return Err(err(
                    "give exactly one projection: intrinsics fx, fy, cx, cy, or yfov, or yfov_deg, or ymag",
                ))
            }
        };
        let znear = self.znear.or(defaults.znear).unwrap_or(DEFAULT_ZNEAR);
        let zfar = self.zfar.or(defaults.zfar);
        CameraPose::new(width, height, projection, znear, zfar, world_to_camera_gl)
    }
}

/// One view of a views file: a sidecar (it has `camera`) or a pose record.
fn view_pose(value: &Value, defaults: &ViewDefaults) -> Result<CameraPose, PoseError> {
    let object = value
        .as_object()
        .ok_or_else(|| err("a view must be a JSON object"))?;
    if object.contains_key("camera") {
        let camera: SidecarCamera = serde_json::from_value(value["camera"].clone())
            .map_err(|e| err(format!("camera: {e}")))?;
        let gl = value
            .get("world_to_camera_gl")
            .ok_or_else(|| err("a sidecar view needs world_to_camera_gl"))?;
        let gl: [[f32; 4]; 4] = serde_json::from_value(gl.clone())
            .map_err(|e| err(format!("world_to_camera_gl: {e}")))?;
        return camera.pose(&gl);
    }
    let record: PoseRecord =
        serde_json::from_value(value.clone()).map_err(|e| err(e.to_string()))?;
    record.pose(defaults)
}

/// Reads the views of a views file's text (see the module docs).
pub fn read_views(text: &str, defaults: &ViewDefaults) -> Result<Vec<CameraPose>, PoseError> {
    let value: Value =
        serde_json::from_str(text).map_err(|e| err(format!("not valid JSON: {e}")))?;
    let list = match &value {
        Value::Array(list) => list.as_slice(),
        Value::Object(o) => match o.get("views") {
            Some(Value::Array(list)) => list.as_slice(),
            Some(_) => return Err(err("\"views\" must be a list")),
            None => std::slice::from_ref(&value),
        },
        _ => return Err(err("expected a view object or a list of views")),
    };
    if list.is_empty() {
        return Err(err("the file lists no views"));
    }
    list.iter()
        .enumerate()
        .map(|(i, v)| view_pose(v, defaults).map_err(|e| err(format!("view {i}: {}", e.0))))
        .collect()
}

/// Reads a views file; errors name the file.
pub fn read_views_file(path: &Path, defaults: &ViewDefaults) -> Result<Vec<CameraPose>, PoseError> {
    let text = read_views_text(path).map_err(|e| err(format!("{}: {e}", path.display())))?;
    read_views(&text, defaults).map_err(|e| err(format!("{}: {}", path.display(), e.0)))
}

/// The most bytes a views file may have (a sidecar of a million views takes far less).
pub const MAX_VIEWS_FILE_BYTES: u64 = 256 << 20;

/// The text of a views file: a regular file (never a device, FIFO or socket, checked on the
/// opened file too) of at most [`MAX_VIEWS_FILE_BYTES`], in UTF-8.
fn read_views_text(path: &Path) -> Result<String, String> {
    use std::io::Read;
    let not_regular = "not a regular file".to_string();
    let meta = std::fs::metadata(path).map_err(|e| e.to_string())?;
    if !meta.is_file() {
        return Err(not_regular);
    }
    let too_large =
        |len: u64| format!("{len} bytes, more than a views file may have ({MAX_VIEWS_FILE_BYTES})");
    if meta.len() > MAX_VIEWS_FILE_BYTES {
        return Err(too_large(meta.len()));
    }
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let meta = file.metadata().map_err(|e| e.to_string())?;
    if !meta.is_file() {
        return Err(not_regular);
    }
    if meta.len() > MAX_VIEWS_FILE_BYTES {
        return Err(too_large(meta.len()));
    }
    let mut text = String::new();
    file.take(MAX_VIEWS_FILE_BYTES)
        .read_to_string(&mut text)
        .map_err(|e| e.to_string())?;
    Ok(text)
}
