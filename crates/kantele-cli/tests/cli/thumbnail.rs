//! `kantele thumbnail`: a square, framed, transparent PNG, and the options it shares with
//! `render`.

use crate::common::{kantele, ok, TempDir};

#[test]
fn thumbnail_is_square_framed_and_transparent() {
    let dir = TempDir::new("thumb");
    std::fs::write(
        dir.path("t.obj"),
        "v 0 0 0\nv 4 0 0\nv 0 2 0\nv 4 2 0\nf 1 2 4\nf 1 4 3\n",
    )
    .unwrap();
    let o = kantele(&[
        "thumbnail",
        &dir.s("t.obj"),
        &dir.s("t.png"),
        "--size",
        "64",
    ]);
    ok(&o);
    let img = image::open(dir.path("t.png")).unwrap().to_rgba8();
    assert_eq!(img.dimensions(), (64, 64));
    assert_eq!(img.get_pixel(0, 0).0[3], 0, "transparent corner");
    assert_eq!(img.get_pixel(32, 32).0[3], 255, "the model in the middle");
    assert_eq!(
        dir.files(),
        ["t.obj", "t.png"],
        "no sidecar, no temporaries"
    );
    let entry = include_str!("../../data/kantele.thumbnailer");
    assert!(entry.contains("Exec=kantele thumbnail %i %o --size %s"));
}

/// `thumbnail` takes the options every command shares: budgets and read policy, shading, the
/// CPU options, camera and background; `--orbit` and `--views` are refused in one line.
#[test]
fn thumbnail_takes_the_shared_options() {
    let dir = TempDir::new("thumb-options");
    std::fs::write(
        dir.path("t.obj"),
        "v 0 0 0\nv 4 0 0\nv 0 2 0\nv 4 2 0\nf 1 2 4\nf 1 4 3\n",
    )
    .unwrap();
    let (scene, out) = (dir.s("t.obj"), dir.s("t.png"));
    let o = kantele(&[
        "thumbnail",
        &scene,
        &out,
        "--size",
        "40",
        "--strict",
        "--max-memory",
        "64M",
        "--allow-read",
        &dir.s(""),
        "--shading",
        "pbr",
        "--msaa",
        "1",
        "--threads",
        "1",
        "--background",
        "white",
        "--camera",
        "look-at:2,1,10:2,1,0",
        "--fov",
        "30",
    ]);
    ok(&o);
    let img = image::open(dir.path("t.png")).unwrap().to_rgba8();
    assert_eq!(img.get_pixel(0, 0).0, [255; 4], "white background");
    // At 1x there are no partly covered pixels.
    assert!(img.pixels().all(|p| p.0[3] == 255));
    // The look-at camera, 10 away with a 30° field of view, leaves the quad small: the
    // automatic framing would fill the picture.
    let model = img.pixels().filter(|p| p.0 != [255; 4]).count();
    assert!(model > 0 && model < 40 * 40 / 2, "{model} model pixels");
    for extra in [["--orbit", "4"], ["--views", "v.json"]] {
        let o = kantele(&["thumbnail", &scene, &dir.s("u.png"), extra[0], extra[1]]);
        assert!(!o.status.success());
        let e = crate::common::stderr(&o);
        assert!(
            e.contains("belong to `kantele render`") && e.lines().count() == 1,
            "{e}"
        );
    }
}
