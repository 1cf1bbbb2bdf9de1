//! Render regions (bands): a picture rendered band by band equals the unbanded picture bit for
//! bit, and a band allocates only its own tiles.

use kantele::pipeline::{Renderer, RendererOptions};
use kantele::raster::Strategy;
use kantele::stats::FrameStats;
use kantele::RenderError;
use kantele_testkit::demo::{render_exercise, render_thesis_cube};

type Demo = fn(&mut Renderer) -> Result<FrameStats, RenderError>;

const WIDTH: u32 = 200;
const HEIGHT: u32 = 150;

fn renderer(strategy: Strategy) -> Renderer {
    let options = RendererOptions {
        threads: Some(2),
        strategy,
        ..RendererOptions::default()
    };
    Renderer::new(1, 1, options).expect("renderer")
}

/// Colour bits and depth bits of rows `rows`, rendered as a band of those rows.
fn band(demo: Demo, strategy: Strategy, rows: std::ops::Range<u32>) -> (Vec<u32>, Vec<u32>) {
    let mut r = renderer(strategy);
    r.resize_band(WIDTH, HEIGHT, rows.clone()).expect("band");
    let stats = demo(&mut r).expect("render");
    assert!(stats.stopped.is_none());
    let fb = r.framebuffer();
    assert_eq!(fb.rows(), rows);
    // Only the tile rows holding the band are allocated.
    let tile_rows = rows.end.div_ceil(64) - rows.start / 64;
    assert_eq!(
        fb.grid().tile_count(),
        (tile_rows * WIDTH.div_ceil(64)) as usize
    );
    let color = fb.read_color();
    assert_eq!(color.len(), rows.len() * WIDTH as usize);
    let bits = color.iter().flatten().map(|c| c.to_bits()).collect();
    let depth = fb.read_depth().iter().map(|d| d.to_bits()).collect();
    (bits, depth)
}

#[test]
fn bands_equal_the_whole_picture_bit_for_bit() {
    let demos: [(&str, Demo); 2] = [
        ("thesis cube", render_thesis_cube),
        ("exercise", render_exercise),
    ];
    for (name, demo) in demos {
        for strategy in [Strategy::Bisector, Strategy::BoundingBox] {
            let (color, depth) = band(demo, strategy, 0..HEIGHT);
            let row = WIDTH as usize;
            // Tile-aligned bands, bands that start and end inside tiles, single rows.
            for rows in [0..64, 64..128, 128..150, 10..100, 63..65, 149..150, 0..1] {
                let (c, d) = band(demo, strategy, rows.clone());
                let (y0, y1) = (rows.start as usize, rows.end as usize);
                assert!(
                    c == color[y0 * row * 4..y1 * row * 4],
                    "{name} {strategy:?}: colour of rows {rows:?} differs from the whole picture"
                );
                assert!(
                    d == depth[y0 * row..y1 * row],
                    "{name} {strategy:?}: depth of rows {rows:?} differs from the whole picture"
                );
            }
        }
    }
}

#[test]
fn a_band_draws_only_its_rows_and_regions_are_checked() {
    let mut r = renderer(Strategy::default());
    r.resize_band(WIDTH, HEIGHT, 64..128).expect("band");
    let stats = render_thesis_cube(&mut r).expect("render");
    let mut whole = renderer(Strategy::default());
    whole.resize(WIDTH, HEIGHT).expect("whole");
    let all = render_thesis_cube(&mut whole).expect("render");
    assert!(stats.fragments_covered > 0);
    assert!(stats.fragments_covered < all.fragments_covered);
    assert!(stats.bin_entries < all.bin_entries);
    assert_eq!(
        r.framebuffer().pixel(0, 10),
        None,
        "row 10 is outside the band"
    );
    assert!(r.framebuffer().pixel(0, 70).is_some());
    for bad in [10..10, 100..151, 151..160] {
        assert!(
            matches!(
                r.resize_band(WIDTH, HEIGHT, bad.clone()),
                Err(RenderError::InvalidRegion { .. })
            ),
            "{bad:?}"
        );
    }
}
