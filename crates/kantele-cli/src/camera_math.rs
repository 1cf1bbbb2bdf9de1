//! Camera conventions for outputs: eye depth from window depth, pinhole intrinsics, and the
//! OpenGL → OpenCV camera frame conversion.

use glam::{Mat4, Vec4};

/// Eye-space distance along the view axis (`−z_eye`, positive in front of the camera) of a
/// window depth `d` in [0, 1] under the OpenGL `projection` (window z = (ndc z + 1) / 2).
///
/// Works for finite and infinite perspective projections (and orthographic ones): with
/// `z_clip = A z + B` and `w_clip = C z + D`, `ndc = z_clip / w_clip` is solved for `z`.
/// Window depth 1.0 (the cleared background) gives `+inf`; so does the far end of an infinite
/// projection.
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
    let z = (b - ndc * dd) / denom;
    let dist = -z;
    if dist.is_finite() && dist > 0.0 {
        dist as f32
    } else {
        f32::INFINITY
    }
}

/// Pinhole intrinsics in pixels, OpenCV conventions: x right, y down, pixel centres at integer
/// coordinates (the top-left pixel's centre is (0, 0)).
#[derive(Clone, Copy, Debug, PartialEq)]
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

/// Intrinsics of an OpenGL perspective projection for a `width × height` target.
pub fn intrinsics(projection: &Mat4, width: u32, height: u32) -> Intrinsics {
    let (w, h) = (width as f64, height as f64);
    let p00 = projection.x_axis.x as f64;
    let p11 = projection.y_axis.y as f64;
    let p20 = projection.z_axis.x as f64; // x offset of an off-centre frustum
    let p21 = projection.z_axis.y as f64;
    Intrinsics {
        fx: p00 * w / 2.0,
        fy: p11 * h / 2.0,
        cx: w / 2.0 * (1.0 - p20) - 0.5,
        cy: h / 2.0 * (1.0 + p21) - 0.5,
    }
}

/// World → camera in OpenCV convention (x right, y down, z forward) from an OpenGL view
/// matrix (x right, y up, looking down −z): the y and z rows are negated.
pub fn opencv_from_gl(view: &Mat4) -> Mat4 {
    Mat4::from_diagonal(Vec4::new(1.0, -1.0, -1.0, 1.0)) * *view
}

/// A matrix as rows, for JSON.
pub fn rows(m: &Mat4) -> [[f32; 4]; 4] {
    m.transpose().to_cols_array_2d()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use kantele::camera::{look_at, perspective, perspective_infinite};

    fn window_depth(p: &Mat4, dist: f32) -> f32 {
        let c = *p * Vec4::new(0.3, -0.2, -dist, 1.0);
        (c.z / c.w + 1.0) / 2.0
    }

    #[test]
    fn eye_depth_inverts_a_finite_projection() {
        let p = perspective(0.8, 1.5, 0.5, 100.0);
        for dist in [0.5f32, 1.0, 3.7, 20.0, 99.0] {
            let d = window_depth(&p, dist);
            let back = eye_depth(d, &p);
            assert!((back - dist).abs() / dist < 1e-3, "{dist} -> {d} -> {back}");
        }
        assert!((eye_depth(0.0, &p) - 0.5).abs() < 1e-5);
        assert!((eye_depth(0.999_999_9, &p) - 100.0).abs() < 1.0);
        assert_eq!(eye_depth(1.0, &p), f32::INFINITY);
    }

    #[test]
    fn eye_depth_inverts_an_infinite_projection() {
        let p = perspective_infinite(0.8, 1.5, 0.1);
        for dist in [0.1f32, 1.0, 10.0, 500.0] {
            let d = window_depth(&p, dist);
            let back = eye_depth(d, &p);
            assert!((back - dist).abs() / dist < 2e-2, "{dist} -> {d} -> {back}");
        }
        assert_eq!(eye_depth(1.0, &p), f32::INFINITY);
    }

    #[test]
    fn opencv_conversion_flips_y_and_z() {
        let view = look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y);
        let cv = opencv_from_gl(&view);
        // The target is 5 units in front: OpenCV z = +5.
        let p = cv.transform_point3(Vec3::ZERO);
        assert!((p - Vec3::new(0.0, 0.0, 5.0)).length() < 1e-5);
        // A point above the target is "up" in GL (y > 0) and has y < 0 in OpenCV.
        let up = cv.transform_point3(Vec3::new(0.0, 1.0, 0.0));
        assert!(up.y < 0.0);
        let right = cv.transform_point3(Vec3::new(1.0, 0.0, 0.0));
        assert!(right.x > 0.0);
        let r = rows(&cv);
        assert_eq!(r[1], [0.0, -1.0, 0.0, 0.0]);
        assert_eq!(r[2], [0.0, 0.0, -1.0, 5.0]);
    }

    #[test]
    fn intrinsics_project_like_the_gl_pipeline() {
        let (w, h) = (640u32, 480u32);
        let p = perspective(1.0, w as f32 / h as f32, 0.1, 50.0);
        let k = intrinsics(&p, w, h);
        assert!((k.cx - 319.5).abs() < 1e-9 && (k.cy - 239.5).abs() < 1e-9);
        // Project an eye-space point both ways.
        let eye = Vec3::new(0.4, 0.3, -2.0);
        let c = p * eye.extend(1.0);
        let (nx, ny) = (c.x / c.w, c.y / c.w);
        let u_gl = (nx + 1.0) / 2.0 * w as f32 - 0.5; // pixel-centre coordinates
        let v_gl = (1.0 - ny) / 2.0 * h as f32 - 0.5;
        let (xc, yc, zc) = (eye.x as f64, -eye.y as f64, -eye.z as f64);
        let u = k.fx * xc / zc + k.cx;
        let v = k.fy * yc / zc + k.cy;
        assert!((u - u_gl as f64).abs() < 1e-3, "{u} {u_gl}");
        assert!((v - v_gl as f64).abs() < 1e-3, "{v} {v_gl}");
    }
}
