//! `--msaa` through the binary: antialiased edges in the picture, per-pixel depth and ids equal
//! to a 1× render's, the thumbnail preset's soft edges, and a clear error for other counts.

use crate::common::{kantele, ok, stderr, TempDir};

/// One flat-lit triangle with slanted edges.
const TRIANGLE: &str = "v 0 0 0\nv 4 1 0\nv 1 3 0\nvn 0 0 1\nf 1//1 2//1 3//1\n";

/// Renders the triangle at `msaa` samples with depth and instance ids; returns (rgba, depth
/// file bytes, ids file bytes).
fn render(dir: &TempDir, msaa: &str) -> (Vec<u8>, Vec<u8>, Vec<u8>) {
    let (png, depth, ids) = (
        dir.s(&format!("c{msaa}.png")),
        dir.s(&format!("d{msaa}.npy")),
        dir.s(&format!("i{msaa}.png")),
    );
    let o = kantele(&[
        "render",
        &dir.s("t.obj"),
        "--camera",
        "auto",
        "--size",
        "48x48",
        "--background",
        "black",
        "--msaa",
        msaa,
        "-o",
        &png,
        "--depth",
        &depth,
        "--ids",
        &format!("instance={ids}"),
    ]);
    ok(&o);
    let rgba = image::open(&png).unwrap().to_rgba8().into_raw();
    (
        rgba,
        std::fs::read(&depth).unwrap(),
        std::fs::read(&ids).unwrap(),
    )
}

/// Distinct red values of the picture.
fn reds(rgba: &[u8]) -> std::collections::BTreeSet<u8> {
    rgba.chunks_exact(4).map(|p| p[0]).collect()
}

#[test]
fn msaa_4_softens_edges_and_keeps_depth_and_ids_per_pixel() {
    let dir = TempDir::new("msaa");
    std::fs::write(dir.path("t.obj"), TRIANGLE).unwrap();
    let (one, depth_one, ids_one) = render(&dir, "1");
    let (four, depth_four, ids_four) = render(&dir, "4");
    // 1×: the background and the triangle's one colour, nothing between.
    assert_eq!(reds(&one).len(), 2, "{:?}", reds(&one));
    // 4×: partly covered pixels take values between the two (a quarter, half, ...).
    let between = reds(&four).len() - 2;
    assert!(between >= 3, "{:?}", reds(&four));
    assert!(four != one);
    assert_eq!(depth_four, depth_one, "depth stays per pixel");
    assert_eq!(ids_four, ids_one, "ids stay per pixel");
}

#[test]
fn the_thumbnail_preset_antialiases_its_silhouette() {
    let dir = TempDir::new("msaa-thumb");
    std::fs::write(dir.path("t.obj"), TRIANGLE).unwrap();
    let o = kantele(&[
        "thumbnail",
        &dir.s("t.obj"),
        &dir.s("t.png"),
        "--size",
        "48",
    ]);
    ok(&o);
    let img = image::open(dir.path("t.png")).unwrap().to_rgba8();
    let partial = img.pixels().filter(|p| p.0[3] > 0 && p.0[3] < 255).count();
    assert!(partial > 20, "soft alpha edges: {partial} pixels");
}

#[test]
fn other_sample_counts_are_refused_in_one_line() {
    let dir = TempDir::new("msaa-bad");
    let o = kantele(&[
        "render",
        "--builtin",
        "cube",
        "--msaa",
        "2",
        "-o",
        &dir.s("c.png"),
    ]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(e.contains("1, 4 or 8"), "{e}");
    assert!(!e.contains("panicked"), "{e}");
    assert!(!dir.path("c.png").exists());
}
