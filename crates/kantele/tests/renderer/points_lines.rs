//! Points and lines through the whole pipeline: the pixels they cover (one per column of an
//! x-major line, one per point), attributes interpolated along a line, never culled, always
//! front-facing, clipped at the near plane, bad index counts refused.

use glam::Vec4;
use kantele::pipeline::{
    FnShader, Fragment, Indices, RenderState, Renderer, RendererOptions, Topology,
};
use kantele::rop::BlendMode;
use kantele::setup::CullMode;
use kantele::RenderError;

/// Vertex: clip-space position (w from the vector) + one attribute.
type Vtx = (Vec4, f32);

const SIZE: u32 = 32;

/// Red = 1 on front faces (0.5 on back faces), green = the attribute; additive blending counts
/// how often a pixel is drawn in alpha.
fn shader() -> impl kantele::pipeline::Shader<Vertex = Vtx> {
    FnShader::new(
        1,
        |v: &Vtx, out: &mut [f32]| {
            out[0] = v.1;
            v.0
        },
        |f: &Fragment<'_>| {
            let face = if f.front_facing { 1.0 } else { 0.5 };
            Some(Vec4::new(face, f.varying(0), 0.0, 1.0))
        },
    )
}

/// Clip position of window pixel coordinate `(x, y)` (pixel centres at +0.5) at `w`.
fn at(x: f32, y: f32, w: f32) -> Vec4 {
    let ndc_x = x / SIZE as f32 * 2.0 - 1.0;
    let ndc_y = 1.0 - y / SIZE as f32 * 2.0;
    Vec4::new(ndc_x * w, ndc_y * w, 0.0, w)
}

/// Renders the vertices as `topology` (cull back faces, additive blending, no depth test) and
/// returns the RGBA picture.
fn render(vertices: &[Vtx], topology: Topology) -> Result<Vec<Vec4>, RenderError> {
    let mut renderer = Renderer::new(SIZE, SIZE, RendererOptions::default())?;
    let shader = shader();
    let state = RenderState {
        cull: CullMode::Back,
        depth_test: false,
        blend: BlendMode::Additive,
        ..RenderState::default()
    };
    let mut frame = renderer.begin_frame(Some(Vec4::ZERO), Some(1.0));
    frame.draw_primitives(&shader, vertices, Indices::None, topology, state)?;
    frame.end();
    Ok(renderer
        .framebuffer()
        .try_read_color()?
        .into_iter()
        .map(Vec4::from_array)
        .collect())
}

fn drawn(picture: &[Vec4]) -> Vec<(u32, u32)> {
    (0..SIZE * SIZE)
        .filter(|&i| picture[i as usize].w > 0.0)
        .map(|i| (i % SIZE, i / SIZE))
        .collect()
}

#[test]
fn a_point_is_one_pixel_drawn_once() {
    let picture = render(
        &[(at(7.3, 9.8, 1.0), 0.25), (at(20.5, 3.5, 2.0), 0.75)],
        Topology::Points,
    )
    .expect("render");
    assert_eq!(drawn(&picture), vec![(20, 3), (7, 9)]);
    let p = picture[(9 * SIZE + 7) as usize];
    assert_eq!(
        p,
        Vec4::new(1.0, 0.25, 0.0, 1.0),
        "front-facing, attribute kept"
    );
}

#[test]
fn an_x_major_line_covers_one_pixel_per_column_with_attributes_along_it() {
    // From the centre of pixel (2, 5) to the centre of pixel (29, 12): 27 columns (the end
    // pixel's diamond is only entered, so it is left to the next segment).
    let picture = render(
        &[(at(2.5, 5.5, 1.0), 0.0), (at(29.5, 12.5, 1.0), 1.0)],
        Topology::Lines,
    )
    .expect("render");
    let pixels = drawn(&picture);
    assert_eq!(pixels.len(), 27, "{pixels:?}");
    let columns: std::collections::BTreeSet<u32> = pixels.iter().map(|p| p.0).collect();
    assert_eq!(columns, (2..29).collect(), "one pixel per column");
    for &(x, y) in &pixels {
        let c = picture[(y * SIZE + x) as usize];
        assert_eq!(c.w, 1.0, "pixel ({x}, {y}) drawn once");
        assert_eq!(c.x, 1.0, "lines are front-facing");
        // The row is the line's at the column centre, the attribute its position along x.
        let t = (x as f32 + 0.5 - 2.5) / 27.0;
        let line_y = 5.5 + 7.0 * t;
        assert!((y as f32 + 0.5 - line_y).abs() <= 0.5, "({x}, {y})");
        assert!(
            (c.y - t).abs() < 1e-4,
            "attribute at ({x}, {y}): {} vs {t}",
            c.y
        );
    }
}

#[test]
fn lines_in_both_directions_and_both_majors_are_never_culled() {
    for (a, b) in [
        ((3.5, 4.5), (28.5, 4.5)),
        ((28.5, 4.5), (3.5, 4.5)),
        ((16.2, 1.1), (12.7, 30.4)),
        ((12.7, 30.4), (16.2, 1.1)),
    ] {
        let picture = render(
            &[(at(a.0, a.1, 1.0), 0.0), (at(b.0, b.1, 1.0), 1.0)],
            Topology::Lines,
        )
        .expect("render");
        let pixels = drawn(&picture);
        let y_major = (b.1 - a.1).abs() > (b.0 - a.0).abs();
        let span = if y_major { b.1 - a.1 } else { b.0 - a.0 }.abs();
        assert!(
            (pixels.len() as f32 - span).abs() <= 1.0,
            "{a:?} → {b:?}: {} pixels for a span of {span}",
            pixels.len()
        );
        let lanes: std::collections::BTreeSet<u32> = pixels
            .iter()
            .map(|p| if y_major { p.1 } else { p.0 })
            .collect();
        assert_eq!(lanes.len(), pixels.len(), "one pixel per column/row");
    }
}

#[test]
fn a_line_through_the_near_plane_is_clipped_not_dropped() {
    // One end behind the eye (w < 0): the part in front is drawn.
    let picture = render(
        &[
            (at(4.5, 16.5, 1.0), 0.0),
            (Vec4::new(0.5, 0.0, 0.0, -1.0), 1.0),
        ],
        Topology::Lines,
    )
    .expect("render");
    let pixels = drawn(&picture);
    assert!(pixels.len() >= 4, "{pixels:?}");
    assert!(pixels.contains(&(4, 16)), "{pixels:?}");
}

#[test]
fn points_outside_and_odd_line_counts() {
    let picture = render(
        &[
            (Vec4::new(2.0, 0.0, 0.0, 1.0), 0.0),
            (Vec4::new(0.0, 0.0, 0.0, -1.0), 0.0),
        ],
        Topology::Points,
    )
    .expect("render");
    assert!(drawn(&picture).is_empty());
    let odd = render(&[(at(1.0, 1.0, 1.0), 0.0); 3], Topology::Lines);
    assert!(
        matches!(odd, Err(RenderError::IncompleteLine(3))),
        "{odd:?}"
    );
}
