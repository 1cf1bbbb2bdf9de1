//! Camera and matrix helpers (OpenGL conventions: right-handed eye space looking down −Z,
//! clip space `-w ≤ x, y, z ≤ w`).

use glam::{Mat3, Mat4, Vec3, Vec4};

/// View matrix (world → eye) from the eye position and the camera's orthonormal basis, as in the
/// thesis §2.2.1: `right`, `up` and `back` (the camera looks along `−back`).
pub fn view_from_basis(eye: Vec3, right: Vec3, up: Vec3, back: Vec3) -> Mat4 {
    Mat4::from_cols(
        Vec4::new(right.x, up.x, back.x, 0.0),
        Vec4::new(right.y, up.y, back.y, 0.0),
        Vec4::new(right.z, up.z, back.z, 0.0),
        Vec4::new(-right.dot(eye), -up.dot(eye), -back.dot(eye), 1.0),
    )
}

/// View matrix looking from `eye` towards `target` with `up` roughly up.
pub fn look_at(eye: Vec3, target: Vec3, up: Vec3) -> Mat4 {
    Mat4::look_at_rh(eye, target, up)
}

/// Perspective projection from the near-plane rectangle (`glFrustum`): depth `near` maps to
/// NDC −1 and `far` to +1.
pub fn frustum(left: f32, right: f32, bottom: f32, top: f32, near: f32, far: f32) -> Mat4 {
    Mat4::from_cols(
        Vec4::new(2.0 * near / (right - left), 0.0, 0.0, 0.0),
        Vec4::new(0.0, 2.0 * near / (top - bottom), 0.0, 0.0),
        Vec4::new(
            (right + left) / (right - left),
            (top + bottom) / (top - bottom),
            -(far + near) / (far - near),
            -1.0,
        ),
        Vec4::new(0.0, 0.0, -2.0 * far * near / (far - near), 0.0),
    )
}

/// Perspective projection from the vertical field of view (radians), aspect ratio (width /
/// height) and depth range, as `gluPerspective` and glTF define it.
pub fn perspective(fovy: f32, aspect: f32, near: f32, far: f32) -> Mat4 {
    Mat4::perspective_rh_gl(fovy, aspect, near, far)
}

/// Infinite perspective projection (glTF cameras without `zfar`).
pub fn perspective_infinite(fovy: f32, aspect: f32, near: f32) -> Mat4 {
    let f = 1.0 / (0.5 * fovy).tan();
    Mat4::from_cols(
        Vec4::new(f / aspect, 0.0, 0.0, 0.0),
        Vec4::new(0.0, f, 0.0, 0.0),
        Vec4::new(0.0, 0.0, -1.0, -1.0),
        Vec4::new(0.0, 0.0, -2.0 * near, 0.0),
    )
}

/// Normal matrix: the inverse transpose of the upper 3 × 3 of `model`. A singular matrix yields
/// the upper 3 × 3 itself (normals are renormalised later, so scale does not matter there).
pub fn normal_matrix(model: &Mat4) -> Mat3 {
    let m = Mat3::from_mat4(*model);
    let det = m.determinant();
    if det.is_finite() && det.abs() > f32::MIN_POSITIVE {
        m.inverse().transpose()
    } else {
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn view_from_basis_matches_look_at() {
        let eye = Vec3::new(1.0, 2.0, 3.0);
        let target = Vec3::new(0.0, 0.5, -1.0);
        let back = (eye - target).normalize();
        let right = Vec3::Y.cross(back).normalize();
        let up = back.cross(right);
        let a = view_from_basis(eye, right, up, back);
        let b = look_at(eye, target, Vec3::Y);
        assert!(a.abs_diff_eq(b, 1e-5), "{a:?} vs {b:?}");
    }

    #[test]
    fn frustum_matches_perspective_when_symmetric() {
        let (fovy, aspect, n, f) = (0.9f32, 1.5f32, 0.3, 50.0);
        let top = n * (fovy / 2.0).tan();
        let right = top * aspect;
        let a = frustum(-right, right, -top, top, n, f);
        let b = perspective(fovy, aspect, n, f);
        assert!(a.abs_diff_eq(b, 1e-5));
        // Near maps to -1, far to +1.
        let near_ndc = a * Vec4::new(0.0, 0.0, -n, 1.0);
        let far_ndc = a * Vec4::new(0.0, 0.0, -f, 1.0);
        assert!((near_ndc.z / near_ndc.w + 1.0).abs() < 1e-5);
        assert!((far_ndc.z / far_ndc.w - 1.0).abs() < 1e-4);
    }

    #[test]
    fn infinite_perspective_is_the_limit() {
        let a = perspective_infinite(1.0, 1.3, 0.1);
        let b = perspective(1.0, 1.3, 0.1, 1e9);
        assert!(a.abs_diff_eq(b, 1e-4));
    }

    #[test]
    fn normal_matrix_keeps_normals_perpendicular_under_nonuniform_scale() {
        let model = Mat4::from_scale(Vec3::new(3.0, 1.0, 1.0)) * Mat4::from_rotation_z(0.3);
        let tangent = Vec3::new(1.0, 1.0, 0.0);
        let normal = Vec3::new(1.0, -1.0, 0.0);
        let t = model.transform_vector3(tangent);
        let n = normal_matrix(&model) * normal;
        assert!(t.dot(n).abs() < 1e-5);
    }
}
