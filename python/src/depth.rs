//! Eye depth from window depth (the CLI's `--depth-kind eye` convention).
// TODO(pose): use kantele_io::pose once the shared camera module lands on main.

use glam::Mat4;

/// Distance along the view axis (`−z_eye`) of window depth `d` under the OpenGL `projection`;
/// window depth 1.0 (background) and points at infinity give `+inf`.
pub fn eye_depth(d: f32, projection: &Mat4) -> f32 {
    if d >= 1.0 {
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
