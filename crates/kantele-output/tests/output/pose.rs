//! Camera conventions of `kantele_output::pose` against hand-computed cases and the rasterizer.

use glam::{DVec3, Mat4, Vec2, Vec3, Vec4};
use kantele::pipeline::{FnShader, Indices, RenderState, Renderer, RendererOptions};
use kantele_output::pose::sidecar::{read_views, SidecarCamera, ViewDefaults};
use kantele_output::pose::{
    eye_depth, intrinsics_of_projection, opencv_from_opengl, rows, Bounds, CameraPose, Intrinsics,
    Projection, Silhouette, UpAxis,
};

fn bits(m: &Mat4) -> Vec<u32> {
    m.to_cols_array().iter().map(|v| v.to_bits()).collect()
}

#[test]
fn camera_on_plus_z_looking_at_the_origin() {
    let yfov = 60f32.to_radians();
    let pose = CameraPose::look_at(
        Vec3::new(0.0, 0.0, 5.0),
        Vec3::ZERO,
        Vec3::Y,
        yfov,
        640,
        480,
    )
    .unwrap();
    let gl = rows(&pose.view());
    assert_eq!(gl[0], [1.0, 0.0, 0.0, 0.0]);
    assert_eq!(gl[1], [0.0, 1.0, 0.0, 0.0]);
    assert_eq!(gl[2], [0.0, 0.0, 1.0, -5.0]);
    let cv = rows(&pose.world_to_camera_opencv());
    assert_eq!(cv[1], [0.0, -1.0, 0.0, 0.0]);
    assert_eq!(cv[2], [0.0, 0.0, -1.0, 5.0]);
    assert_eq!(
        opencv_from_opengl(&pose.world_to_camera_opencv()),
        pose.view()
    );
    let k = pose.intrinsics().unwrap();
    let f = 240.0 / (30f64.to_radians()).tan();
    assert!((k.fx - f).abs() < 1e-3 && (k.fy - f).abs() < 1e-3, "{k:?}");
    assert_eq!((k.cx, k.cy), (319.5, 239.5));
    // The origin is at the image centre, 5 units away; +Y world is up in the picture (v smaller).
    let (u, v, z) = pose.project(Vec3::ZERO).unwrap();
    assert!((u - 319.5).abs() < 1e-9 && (v - 239.5).abs() < 1e-9 && (z - 5.0).abs() < 1e-6);
    let (_, v_up, _) = pose.project(Vec3::Y).unwrap();
    assert!(v_up < 239.5);
    let (u_right, _, _) = pose.project(Vec3::X).unwrap();
    assert!((u_right - (319.5 + f / 5.0)).abs() < 1e-3);
    assert!((pose.eye() - Vec3::new(0.0, 0.0, 5.0)).length() < 1e-6);
    // Square pixels: the horizontal scale follows the aspect.
    let p = pose.projection();
    assert!((p.x_axis.x * 640.0 - p.y_axis.y * 480.0).abs() < 1e-3);
}

/// Renders a plane whose colour is its world position and checks, pixel by pixel, that the
/// OpenCV projection of the point the rasterizer drew at a pixel centre is that pixel centre.
#[test]
fn opencv_projection_matches_the_rasterizer() {
    let (w, h) = (96u32, 64u32);
    let k = Intrinsics {
        fx: 70.0,
        fy: 82.5,
        cx: 51.25,
        cy: 29.75,
    };
    let eye = Vec3::new(0.7, -0.4, 3.0);
    let gl_view = Mat4::look_at_rh(eye, Vec3::new(0.1, 0.2, 0.0), Vec3::Y);
    let pose =
        CameraPose::from_opencv(k, opencv_from_opengl(&gl_view), w, h, 0.1, Some(20.0)).unwrap();
    let clip_from_world = pose.projection() * pose.view();
    let quad = [
        Vec2::new(-4.0, -4.0),
        Vec2::new(4.0, -4.0),
        Vec2::new(4.0, 4.0),
        Vec2::new(-4.0, 4.0),
    ];
    let shader = FnShader::new(
        2,
        move |p: &Vec2, out: &mut [f32]| {
            out.copy_from_slice(&p.to_array());
            clip_from_world * Vec4::new(p.x, p.y, 0.0, 1.0)
        },
        |f: &kantele::pipeline::Fragment<'_>| Some(Vec4::new(f.varying(0), f.varying(1), 0.0, 1.0)),
    );
    let mut renderer = Renderer::new(w, h, RendererOptions::default()).unwrap();
    let mut frame = renderer.begin_frame(Some(Vec4::ZERO), Some(1.0));
    let state = RenderState {
        cull: kantele::setup::CullMode::None,
        ..RenderState::default()
    };
    frame
        .draw(&shader, &quad, Indices::U16(&[0, 1, 2, 0, 2, 3]), state)
        .unwrap();
    frame.end();
    let fb = renderer.framebuffer();
    let mut checked = 0;
    let mut worst = 0.0f64;
    for y in 0..h {
        for x in 0..w {
            let c = fb.pixel(x, y).unwrap();
            if c.w == 0.0 {
                continue;
            }
            let (u, v, _) = pose.project(Vec3::new(c.x, c.y, 0.0)).unwrap();
            worst = worst.max((u - x as f64).abs()).max((v - y as f64).abs());
            checked += 1;
        }
    }
    assert_eq!(
        checked,
        (w * h) as usize,
        "the plane should cover the picture"
    );
    assert!(worst < 0.01, "worst disagreement {worst} px");
}

#[test]
fn intrinsics_and_projection_round_trip() {
    let k = Intrinsics {
        fx: 1234.5,
        fy: 1200.25,
        cx: 700.1,
        cy: 410.9,
    };
    let pose = CameraPose::from_opencv(k, Mat4::IDENTITY, 1440, 900, 0.05, Some(100.0)).unwrap();
    let back = intrinsics_of_projection(&pose.projection(), 1440, 900);
    for (a, b) in [
        (k.fx, back.fx),
        (k.fy, back.fy),
        (k.cx, back.cx),
        (k.cy, back.cy),
    ] {
        assert!((a - b).abs() < 1e-3, "{k:?} -> {back:?}");
    }
    // A perspective camera and the pinhole camera of its intrinsics project alike.
    let persp = CameraPose::new(
        800,
        600,
        Projection::Perspective { yfov: 0.9 },
        0.1,
        None,
        Mat4::IDENTITY,
    )
    .unwrap();
    let pin = CameraPose::from_opengl(
        Projection::Pinhole(persp.intrinsics().unwrap()),
        Mat4::IDENTITY,
        800,
        600,
        0.1,
        None,
    )
    .unwrap();
    assert!(persp.projection().abs_diff_eq(pin.projection(), 1e-6));
    assert!(((pin.yfov().unwrap() - 0.9) as f64).abs() < 1e-6);
    // The file camera's aspect ratio is not forced on the image.
    let camera = kantele::scene::Camera {
        view: Mat4::IDENTITY,
        yfov: 0.9,
        ymag: None,
        aspect_ratio: Some(3.0),
        znear: 0.1,
        zfar: None,
    };
    let file = CameraPose::from_scene_camera(&camera, 800, 600).unwrap();
    assert_eq!(bits(&file.projection()), bits(&persp.projection()));
}

/// How points project: the fraction of the image they span along their tighter direction (for
/// a model as wide as tall, the shorter image side), the middle of their extent in NDC, and
/// whether all are inside.
fn fill(pose: &CameraPose, points: &[Vec3]) -> (f64, Vec2, bool) {
    let clip_from_world = pose.projection() * pose.view();
    let (mut lo, mut hi) = (Vec2::splat(f32::MAX), Vec2::splat(f32::MIN));
    let mut inside = true;
    for p in points {
        let c = clip_from_world * p.extend(1.0);
        assert!(c.is_finite() && c.w > 0.0, "{p} -> {c}");
        let ndc = Vec2::new(c.x / c.w, c.y / c.w);
        inside &= ndc.abs().max_element() <= 1.0 && c.z.abs() <= c.w;
        lo = lo.min(ndc);
        hi = hi.max(ndc);
    }
    let span = (hi - lo) / 2.0;
    (span.max_element() as f64, (hi + lo) / 2.0, inside)
}

/// How far from the picture's centre the points reach, in NDC (1 = the border).
fn reach(pose: &CameraPose, points: &[Vec3]) -> f64 {
    let clip_from_world = pose.projection() * pose.view();
    points
        .iter()
        .map(|p| {
            let c = clip_from_world * p.extend(1.0);
            (c.x / c.w).abs().max((c.y / c.w).abs()) as f64
        })
        .fold(0.0, f64::max)
}

fn blob(scale: f32, offset: Vec3, size: Vec3) -> Vec<Vec3> {
    // Corners of a box of half-extents `size` and points of the ellipsoid inside it.
    let mut points = Vec::new();
    for i in 0..8 {
        let s = |bit: i32| if i & bit == 0 { -1.0 } else { 1.0 };
        points.push(Vec3::new(s(1), s(2), s(4)) * size);
    }
    for i in 0..200 {
        let t = i as f32 * 0.37;
        let phi = i as f32 * 0.11;
        points.push(Vec3::new(t.cos() * phi.sin(), phi.cos(), t.sin() * phi.sin()) * size);
    }
    points
        .into_iter()
        .map(|p| p * scale + offset * scale)
        .collect()
}

#[test]
fn framing_fills_the_picture_at_any_scale() {
    for scale in [1.0f32, 1e-20, 1e20] {
        for (w, h) in [(640u32, 480u32), (300, 900)] {
            for (dir, up) in [
                (Vec3::new(0.3, 0.4, 1.0), UpAxis::Y),
                (Vec3::new(1.0, -1.0, 0.8), UpAxis::Z),
                (Vec3::Y, UpAxis::Y),
            ] {
                for size in [
                    Vec3::ONE,
                    Vec3::new(1.0, 0.5, 0.75),
                    Vec3::new(0.1, 2.0, 0.3),
                ] {
                    let points = blob(scale, Vec3::new(3.0, -2.0, 7.0), size);
                    let silhouette =
                        Silhouette::from_points(points.iter().map(|p| p.as_dvec3())).unwrap();
                    let perspective =
                        CameraPose::frame(&silhouette, dir, up, 45f32.to_radians(), w, h);
                    let orthographic = CameraPose::frame_orthographic(&silhouette, dir, up, w, h);
                    for pose in [perspective.unwrap(), orthographic.unwrap()] {
                        let (f, middle, inside) = fill(&pose, &points);
                        let case = format!("scale {scale} {w}x{h} from {dir} size {size}");
                        assert!(inside, "{case}: a point is outside the picture");
                        assert!((f - 0.92).abs() < 1e-3, "{case}: fills {f:.4}");
                        assert!(middle.abs().max_element() < 1e-3, "{case}: at {middle}");
                    }
                }
            }
        }
    }
}

/// A model much smaller than its box from the camera's side (a ring) fills the picture by its
/// own outline, not by its box's.
#[test]
fn framing_follows_the_silhouette_not_the_box() {
    let ring: Vec<Vec3> = (0..720)
        .map(|i| {
            let a = i as f32 / 720.0 * std::f32::consts::TAU;
            Vec3::new(a.cos() * 2.0, 0.5, a.sin() * 2.0)
        })
        .chain([Vec3::new(0.0, -0.5, 0.0)])
        .collect();
    let silhouette = Silhouette::from_points(ring.iter().map(|p| p.as_dvec3())).unwrap();
    let boxed = Silhouette::of_bounds(silhouette.bounds());
    let dir = Vec3::new(0.5, 0.6, 1.0);
    let yfov = 45f32.to_radians();
    let tight = CameraPose::frame(&silhouette, dir, UpAxis::Y, yfov, 512, 512).unwrap();
    let loose = CameraPose::frame(&boxed, dir, UpAxis::Y, yfov, 512, 512).unwrap();
    let (f_tight, middle, inside) = fill(&tight, &ring);
    let (f_loose, _, _) = fill(&loose, &ring);
    assert!(inside && (f_tight - 0.92).abs() < 1e-3, "{f_tight}");
    assert!(middle.abs().max_element() < 1e-3, "{middle}");
    assert!(
        f_loose < f_tight - 0.05,
        "box {f_loose}, silhouette {f_tight}"
    );
}

#[test]
fn orbit_cameras_all_look_at_the_centre() {
    for scale in [1.0f64, 1e-20, 1e20] {
        let bounds = Bounds {
            min: DVec3::new(-1.0, 0.0, -2.0) * scale,
            max: DVec3::new(3.0, 1.0, 0.0) * scale,
        };
        let silhouette = Silhouette::of_bounds(&bounds);
        let center = bounds.center().as_vec3();
        let poses =
            CameraPose::orbit(&silhouette, 8, 20.0, None, UpAxis::Y, 0.8, 320, 240).unwrap();
        assert_eq!(poses.len(), 8);
        let d0 = (poses[0].eye().as_dvec3() - bounds.center()).length();
        for pose in &poses {
            let (u, v, z) = pose.project(center).unwrap();
            assert!(
                (u - 159.5).abs() < 1e-2 && (v - 119.5).abs() < 1e-2,
                "{u} {v}"
            );
            let d = (pose.eye().as_dvec3() - bounds.center()).length();
            assert!((d - d0).abs() <= d0 * 1e-5 && (z - d0).abs() <= d0 * 1e-5);
            let elevation = ((pose.eye().as_dvec3().y - bounds.center().y) / d).asin();
            assert!((elevation.to_degrees() - 20.0).abs() < 1e-3);
            let (f, _, inside) = fill(pose, &bounds.corners().map(|c| c.as_vec3()));
            assert!(inside && f > 0.3, "{f}");
        }
        // Azimuth 90° with Y up is +X.
        assert!(
            poses[2].eye().x > center.x && (poses[2].eye().z - center.z).abs() < d0 as f32 * 1e-3
        );
        let given = CameraPose::orbit(
            &silhouette,
            3,
            0.0,
            Some(10.0 * scale as f32),
            UpAxis::Z,
            0.8,
            320,
            240,
        )
        .unwrap();
        assert!(
            ((given[0].eye().as_dvec3() - bounds.center()).length() / (10.0 * scale) - 1.0).abs()
                < 1e-5
        );
        assert!(given[0].eye().y < center.y, "Z up: azimuth 0 looks from -Y");
    }
    let unit = Silhouette::of_bounds(&Bounds {
        min: DVec3::ZERO,
        max: DVec3::ONE,
    });
    assert!(CameraPose::orbit(&unit, 0, 20.0, None, UpAxis::Y, 0.8, 32, 32).is_err());
    assert!(CameraPose::orbit(&unit, 4, 20.0, Some(-1.0), UpAxis::Y, 0.8, 32, 32).is_err());
}

/// A turntable's one distance keeps the model inside at every azimuth and is tight: at its
/// worst azimuth the model fills the picture's tighter direction.
#[test]
fn orbit_distance_fits_every_azimuth_tightly() {
    for (up, elevation, size, (w, h)) in [
        (UpAxis::Y, 20.0, Vec3::new(1.0, 0.5, 0.2), (512u32, 512u32)),
        (UpAxis::Z, -35.0, Vec3::new(0.3, 2.0, 0.6), (640, 360)),
        (UpAxis::Y, 70.0, Vec3::new(2.0, 0.1, 0.4), (300, 500)),
    ] {
        let points = blob(1.0, Vec3::new(0.4, -1.0, 2.0), size);
        let silhouette = Silhouette::from_points(points.iter().map(|p| p.as_dvec3())).unwrap();
        let poses = CameraPose::orbit(&silhouette, 720, elevation, None, up, 0.8, w, h).unwrap();
        let mut fullest = 0.0f64;
        for pose in &poses {
            let (_, _, inside) = fill(pose, &points);
            assert!(inside, "{up:?} {elevation}: a point is outside");
            fullest = fullest.max(reach(pose, &points));
        }
        assert!(fullest > 0.91, "{up:?} {elevation}: at most {fullest:.4}");
    }
}

#[test]
fn depth_conventions() {
    let pose = CameraPose::new(
        64,
        48,
        Projection::Pinhole(Intrinsics {
            fx: 50.0,
            fy: 55.0,
            cx: 30.0,
            cy: 20.0,
        }),
        0.5,
        Some(100.0),
        Mat4::look_at_rh(Vec3::new(1.0, 2.0, 3.0), Vec3::ZERO, Vec3::Y),
    )
    .unwrap();
    let p = pose.projection();
    // Window depth -> planar depth inverts the projection.
    for dist in [0.5f32, 1.0, 3.7, 20.0, 99.0] {
        let c = p * Vec4::new(0.3, -0.2, -dist, 1.0);
        let d = (c.z / c.w + 1.0) / 2.0;
        let back = eye_depth(d, &p);
        assert!((back - dist).abs() / dist < 1e-3, "{dist} -> {d} -> {back}");
    }
    assert_eq!(eye_depth(1.0, &p), f32::INFINITY);
    assert_eq!(pose.planar_depth(&[1.0])[0], f32::INFINITY);
    let infinite = pose.with_depth_range(0.1, None).unwrap().projection();
    for dist in [0.1f32, 1.0, 10.0, 500.0] {
        let c = infinite * Vec4::new(0.0, 0.0, -dist, 1.0);
        let back = eye_depth((c.z / c.w + 1.0) / 2.0, &infinite);
        assert!((back - dist).abs() / dist < 2e-2, "{dist} -> {back}");
    }
    // Ray distance: the world point at planar depth z through pixel (x, y) is that far away.
    let cam_to_world = opencv_from_opengl(&pose.view()).inverse();
    for (x, y) in [(0u32, 0u32), (30, 20), (63, 47), (10, 40)] {
        let z = 4.0f32;
        let cam = Vec3::new(
            (x as f32 - 30.0) / 50.0 * z,
            (y as f32 - 20.0) / 55.0 * z,
            z,
        );
        let world = cam_to_world.transform_point3(cam);
        let dist = (world - pose.eye()).length();
        let ray = pose.ray_distance(z, x, y);
        assert!((ray - dist).abs() < 1e-4, "{x},{y}: {ray} vs {dist}");
        let (u, v, _) = pose.project(world).unwrap();
        assert!((u - x as f64).abs() < 1e-3 && (v - y as f64).abs() < 1e-3);
    }
    assert_eq!(pose.ray_distance(2.0, 30, 20), 2.0);
    let window = {
        let c = p * Vec4::new(0.0, 0.0, -4.0, 1.0);
        (c.z / c.w + 1.0) / 2.0
    };
    let ray = pose.ray_depth(&vec![window; 64 * 48]);
    assert!((ray[0] / ray[20 * 64 + 30] - pose.ray_distance_factor(0, 0) as f32).abs() < 1e-5);
}

fn sidecar_json(pose: &CameraPose) -> String {
    // The camera part of a sidecar, as `render` writes it.
    serde_json::to_string_pretty(&serde_json::json!({
        "scene": "x",
        "camera": SidecarCamera::of_pose(pose),
        "world_to_camera_gl": rows(&pose.view()),
        "world_to_camera_opencv": rows(&pose.world_to_camera_opencv()),
    }))
    .unwrap()
}

#[test]
fn sidecar_round_trip_is_bit_identical() {
    let mut poses = vec![
        CameraPose::look_at(
            Vec3::new(0.1, 0.7, 2.3),
            Vec3::new(-0.3, 0.2, 0.1),
            Vec3::Y,
            0.8123,
            1920,
            1080,
        )
        .unwrap()
        .with_depth_range(0.012345679, Some(98.76543))
        .unwrap(),
        CameraPose::from_opencv(
            Intrinsics {
                fx: 1000.0 / 3.0,
                fy: 1001.0 / 7.0,
                cx: 319.123456789,
                cy: 240.1,
            },
            Mat4::from_rotation_y(0.3) * Mat4::from_translation(Vec3::new(0.1, -0.2, 0.3)),
            640,
            480,
            0.01,
            None,
        )
        .unwrap(),
        CameraPose::new(
            101,
            37,
            Projection::Orthographic { ymag: 1.0 / 3.0 },
            0.5,
            Some(7.25),
            Mat4::from_rotation_x(1.1),
        )
        .unwrap(),
    ];
    // Orbit views have long, irregular entries.
    let bounds = Bounds {
        min: DVec3::splat(-0.37),
        max: DVec3::new(1.1, 0.9, 0.77),
    };
    poses.extend(
        CameraPose::orbit(
            &Silhouette::of_bounds(&bounds),
            13,
            23.0,
            None,
            UpAxis::Z,
            0.61,
            333,
            222,
        )
        .unwrap(),
    );
    let texts: Vec<String> = poses.iter().map(sidecar_json).collect();
    let list = format!("[{}]", texts.join(","));
    let back = read_views(&list, &ViewDefaults::default()).unwrap();
    assert_eq!(back.len(), poses.len());
    for (a, b) in poses.iter().zip(&back) {
        assert_eq!(bits(&a.projection()), bits(&b.projection()), "{a:?}");
        assert_eq!(bits(&a.view()), bits(&b.view()), "{a:?}");
        assert_eq!(a, b);
    }
    // A single sidecar object reads as one view.
    assert_eq!(
        read_views(&texts[1], &ViewDefaults::default()).unwrap(),
        vec![poses[1]]
    );
}

#[test]
fn pose_lists_in_both_conventions() {
    let gl = Mat4::look_at_rh(Vec3::new(1.0, 2.0, 3.0), Vec3::ZERO, Vec3::Y);
    let cv = rows(&opencv_from_opengl(&gl));
    let text = serde_json::json!({"views": [
        {"world_to_camera": cv, "convention": "opencv", "fx": 500.0, "fy": 500.0, "cx": 319.5, "cy": 239.5,
         "width": 640, "height": 480, "znear": 0.1, "zfar": 50.0},
        {"world_to_camera": rows(&gl), "convention": "opengl", "yfov_deg": 45.0},
        {"world_to_camera_opencv": cv, "yfov": 0.5, "znear": 2.0},
    ]})
    .to_string();
    let defaults = ViewDefaults {
        size: Some((320, 200)),
        znear: Some(0.25),
        zfar: None,
    };
    let views = read_views(&text, &defaults).unwrap();
    assert_eq!(views.len(), 3);
    let k = Intrinsics {
        fx: 500.0,
        fy: 500.0,
        cx: 319.5,
        cy: 239.5,
    };
    assert_eq!(
        views[0],
        CameraPose::from_opencv(k, opencv_from_opengl(&gl), 640, 480, 0.1, Some(50.0)).unwrap()
    );
    for v in &views {
        assert!(v.view().abs_diff_eq(gl, 1e-6));
    }
    assert_eq!(
        (views[1].width, views[1].height, views[1].znear),
        (320, 200, 0.25)
    );
    assert!((views[1].yfov().unwrap() - 45f32.to_radians()).abs() < 1e-7);
    assert_eq!(views[2].znear, 2.0);

    let bad = |json: serde_json::Value, needle: &str| {
        let e = read_views(&json.to_string(), &defaults)
            .unwrap_err()
            .to_string();
        assert!(e.contains(needle), "{e} should mention {needle}");
        assert!(!e.contains('\n'));
    };
    bad(
        serde_json::json!([{"world_to_camera": cv, "yfov": 0.5}]),
        "convention",
    );
    bad(
        serde_json::json!([{"world_to_camera": cv, "convention": "opencv"}]),
        "projection",
    );
    bad(
        serde_json::json!([{"world_to_camera": cv, "convention": "opencv", "yfov": 0.5, "fx": 1.0}]),
        "projection",
    );
    bad(
        serde_json::json!([{"world_to_camera": cv, "convention": "opencv", "yfov": 45.0}]),
        "degrees",
    );
    bad(serde_json::json!([{"yfov": 0.5}]), "world_to_camera");
    bad(
        serde_json::json!([{"world_to_camera": [[0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]], "convention": "opengl", "yfov": 0.5}]),
        "singular",
    );
    bad(
        serde_json::json!([{"world_to_camera": [[1e39, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], "convention": "opengl", "yfov": 0.5}]),
        "finite",
    );
    bad(serde_json::json!([]), "no views");
    bad(serde_json::json!(3), "list of views");
    bad(
        serde_json::json!([{"world_to_camera": cv, "convention": "opencv", "ymag": 1.0}]),
        "zfar",
    );
    assert!(read_views("{", &defaults)
        .unwrap_err()
        .to_string()
        .contains("JSON"));
    let no_size = ViewDefaults::default();
    assert!(read_views(&serde_json::json!([{"world_to_camera": cv, "convention": "opencv", "yfov": 0.5, "znear": 1.0}]).to_string(), &no_size)
        .unwrap_err()
        .to_string()
        .contains("width"));
}

#[test]
fn frame_view_keeps_the_scene_light_rules() {
    let scene = kantele::scene::Scene::default();
    let pose =
        CameraPose::look_at(Vec3::new(4.0, 0.0, 0.0), Vec3::ZERO, Vec3::Y, 0.8, 64, 32).unwrap();
    let view = pose.frame_view(&scene, kantele::backend::Pass::Normals);
    assert_eq!((view.width, view.height), (64, 32));
    assert_eq!(view.pass, kantele::backend::Pass::Normals);
    assert_eq!(view.view, pose.view());
    assert_eq!(view.projection, pose.projection());
    // The default scene has a headlight: towards the camera.
    assert!(
        (view.to_light - Vec3::X).length() < 1e-6,
        "{}",
        view.to_light
    );
}

#[test]
fn bad_cameras_are_refused() {
    let id = Mat4::IDENTITY;
    let persp = |yfov| Projection::Perspective { yfov };
    assert!(CameraPose::new(0, 10, persp(0.8), 0.1, None, id).is_err());
    assert!(CameraPose::new(10, 10, persp(45.0), 0.1, None, id).is_err());
    assert!(CameraPose::new(10, 10, persp(f32::NAN), 0.1, None, id).is_err());
    assert!(CameraPose::new(10, 10, persp(0.8), 0.0, None, id).is_err());
    assert!(CameraPose::new(10, 10, persp(0.8), 1.0, Some(0.5), id).is_err());
    assert!(CameraPose::new(10, 10, persp(0.8), 0.1, None, Mat4::ZERO).is_err());
    assert!(CameraPose::look_at(Vec3::ONE, Vec3::ONE, Vec3::Y, 0.8, 10, 10).is_err());
    assert!(CameraPose::look_at(Vec3::NAN, Vec3::ONE, Vec3::Y, 0.8, 10, 10).is_err());
    // Looking straight down the up axis still gives a camera.
    let down = CameraPose::look_at(Vec3::Y * 3.0, Vec3::ZERO, Vec3::Y, 0.8, 10, 10).unwrap();
    assert!(down.view().is_finite());
    assert!("x".parse::<UpAxis>().is_err());
    assert_eq!("Z".parse::<UpAxis>().unwrap(), UpAxis::Z);
}
