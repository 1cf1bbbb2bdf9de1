//! Points and lines as window-space quads, so that they go through the triangle setup and the
//! per-pixel path unchanged (as Mesa's llvmpipe rasterizes them, `lp_setup_point.c` and
//! `lp_setup_line.c`).
//!
//! - **Point** (size 1, OpenGL 3.3 §3.4): the 1 × 1 square centred on the snapped vertex. Under
//!   the top-left rule it covers exactly the pixel whose centre lies in
//!   `[x − ½, x + ½) × [y − ½, y + ½)`.
//! - **Line** (width 1, §3.5, non-antialiased): an x-major line (|Δx| ≥ |Δy|) is the
//!   parallelogram from end to end, one pixel tall and centred on the segment, so it covers one
//!   pixel per column whose centre lies between its ends (left end included, right excluded);
//!   a y-major line is the same turned, one pixel per row. The ends follow the diamond-exit
//!   rule as llvmpipe approximates it: the first pixel is drawn when the segment leaves its
//!   diamond `|x − x_c| + |y − y_c| < ½` (the tests on the start and end point are llvmpipe's);
//!   an end whose half-open column (or row) choice disagrees is moved along the segment to the
//!   pixel boundary that gives the wanted choice. The quad's corners carry their end's
//!   attributes: values are interpolated along the line and constant across it.
//!
//! What differs from llvmpipe: an end that is moved keeps its attributes (llvmpipe
//! extrapolates them from the unmoved segment: the difference is at most one pixel's step of
//! the gradient along the line), and moved ends go to the pixel boundary itself rather than to
//! llvmpipe's float offset (same column choice, exact in fixed point).

use crate::fixed::{snap, SUBPIXEL_HALF, SUBPIXEL_ONE};

/// A quad in window space: four corners in order around it, each an `(x, y)` in pixels that is a
/// multiple of 1/256 (so setup snaps it to itself), and for each corner the index (0 or 1) of
/// the primitive's vertex whose depth, `1/w` and varyings it takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WideQuad {
    /// Corner positions in window pixels.
    pub corners: [[f32; 2]; 4],
    /// Which end of the quad (0 or 1) each corner belongs to.
    pub ends: [usize; 4],
    /// Where each end of the quad lies on the primitive, as the parameter `t` of
    /// `v1 + (v2 − v1)·t` in window space: 0 and 1 unless the diamond-exit rule moved an end
    /// (then slightly outside or inside [0, 1]); both 0 for a point. Attributes are taken there.
    pub t: [f32; 2],
}

impl WideQuad {
    /// The two triangles covering the quad without overlap: corners `(0, 1, 2)` and `(0, 2, 3)`.
    pub const TRIANGLES: [[usize; 3]; 2] = [[0, 1, 2], [0, 2, 3]];
}

/// Window pixels of a sub-pixel coordinate (exact: |units| ≤ 2^24 + 2^8).
fn pixels(units: i64) -> f32 {
    units as f32 / SUBPIXEL_ONE as f32
}

/// The quad of a size-1 point at window position `p`.
pub fn point_quad(p: [f32; 2]) -> WideQuad {
    let (x, y) = (snap(p[0]), snap(p[1]));
    let (x0, x1) = (pixels(x - SUBPIXEL_HALF), pixels(x + SUBPIXEL_HALF));
    let (y0, y1) = (pixels(y - SUBPIXEL_HALF), pixels(y + SUBPIXEL_HALF));
    WideQuad {
        corners: [[x0, y0], [x1, y0], [x1, y1], [x0, y1]],
        ends: [0; 4],
        t: [0.0; 2],
    }
}

/// Whether `x ≥ 0` (llvmpipe's `sign`).
fn sign(x: f32) -> bool {
    x >= 0.0
}

/// Offset of `v` from the centre of its pixel, in `[−½, ½)`.
fn centre_offset(v: f32) -> f32 {
    v - v.floor() - 0.5
}

/// Fractional part of `v` (llvmpipe's `fracf`).
fn fraction(v: f32) -> f32 {
    v - v.floor()
}

/// Diamond-exit decisions for the two ends of a line, `(draw the start pixel, draw the end
/// pixel)`: llvmpipe's tests (`try_setup_line`), kept branch for branch, including how they
/// treat values exactly on a pixel's centre line. `d` is `v1 − v2`.
fn diamond_exit(v1: [f32; 2], v2: [f32; 2], d: [f32; 2], y_major: bool) -> (bool, bool) {
    let [x1, y1] = v1.map(centre_offset);
    let [mut x2, mut y2] = v2.map(centre_offset);
    let [dx, dy] = d;
    if !y_major {
        let dydx = dy / dx;
        if y2 == -0.5 && dy < 0.0 {
            y2 = 0.5;
        }
        let start = if x1.abs() + y1.abs() < 0.5 {
            true
        } else if sign(x1) == sign(-dx) {
            false
        } else if sign(-y1) != sign(dy) {
            true
        } else {
            let intersect = fraction(v1[1]) + x1 * dydx;
            intersect < 1.0 && intersect > 0.0
        };
        let end = if x2.abs() + y2.abs() < 0.5 || sign(x2) != sign(-dx) {
            false
        } else if sign(-y2) == sign(dy) {
            true
        } else {
            let intersect = fraction(v2[1]) + x2 * dydx;
            intersect < 1.0 && intersect > 0.0
        };
        (start, end)
    } else {
        let dxdy = dx / dy;
        if x2 == -0.5 && dx < 0.0 {
            x2 = 0.5;
        }
        let start = if x1.abs() + y1.abs() < 0.5 {
            true
        } else if sign(-y1) == sign(dy) {
            false
        } else if sign(x1) != sign(-dx) {
            true
        } else {
            let intersect = fraction(v1[0]) + y1 * dxdy;
            intersect < 1.0 && intersect > 0.0
        };
        let end = if x2.abs() + y2.abs() < 0.5 || sign(-y2) != sign(dy) {
            false
        } else if sign(x2) == sign(-dx) {
            true
        } else {
            let intersect = fraction(v2[0]) + y2 * dxdy;
            (0.0..1.0).contains(&intersect)
        };
        (start, end)
    }
}

/// The quad of a width-1 line from window position `v1` to `v2`; `None` for a zero-length or
/// non-finite line, or one whose diamond-exit ends leave no pixel.
pub fn line_quad(v1: [f32; 2], v2: [f32; 2]) -> Option<WideQuad> {
    if !(v1.iter().chain(&v2).all(|c| c.is_finite())) {
        return None;
    }
    let d = [v1[0] - v2[0], v1[1] - v2[1]];
    if d[0] * d[0] + d[1] * d[1] == 0.0 {
        return None;
    }
    let y_major = d[0].abs() < d[1].abs();
    let (m, n) = if y_major { (1, 0) } else { (0, 1) };
    let slope = d[n] / d[m];
    let (draw_start, draw_end) = diamond_exit(v1, v2, d, y_major);
    // Along the major axis the quad covers the pixel centres c with lo ≤ c < hi (left and top
    // edges are included by the top-left rule). Move an end whose pixel would be chosen
    // differently to the boundary of its pixel that gives the wanted choice.
    let low_is_v1 = v1[m] < v2[m];
    let place = |v: [f32; 2], draw: bool, is_low: bool| -> [f32; 2] {
        let pixel = v[m].floor();
        let centre = pixel + 0.5;
        let drawn = if is_low {
            centre >= v[m]
        } else {
            centre < v[m]
        };
        if drawn == draw {
            return v;
        }
        let target = match (is_low, draw) {
            (true, true) | (false, false) => pixel,
            (true, false) | (false, true) => pixel + 1.0,
        };
        let mut out = v;
        out[n] += (target - v[m]) * slope;
        out[m] = target;
        out
    };
    let a = place(v1, draw_start, low_is_v1);
    let b = place(v2, draw_end, !low_is_v1);
    // An end moved past the other leaves nothing to draw.
    if (a[m] < b[m]) != low_is_v1 || a[m] == b[m] {
        return None;
    }
    let (sa, sb) = ([snap(a[0]), snap(a[1])], [snap(b[0]), snap(b[1])]);
    let offset = |s: [i64; 2], side: i64| -> [f32; 2] {
        let mut c = s;
        c[n] += side * SUBPIXEL_HALF;
        [pixels(c[0]), pixels(c[1])]
    };
    Some(WideQuad {
        corners: [offset(sa, -1), offset(sb, -1), offset(sb, 1), offset(sa, 1)],
        ends: [0, 1, 1, 0],
        t: [
            (a[m] - v1[m]) / (v2[m] - v1[m]),
            (b[m] - v1[m]) / (v2[m] - v1[m]),
        ],
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::setup::{setup_window_triangle, CullMode, FrontFace, Viewport, WindowVertex};
    use std::collections::BTreeSet;

    /// The pixels a quad covers, through the real triangle setup.
    fn covered(quad: &WideQuad, size: u32) -> BTreeSet<(i32, i32)> {
        let vp = Viewport::new(size, size);
        let mut out = BTreeSet::new();
        for tri in WideQuad::TRIANGLES {
            let window = tri
                .map(|i| WindowVertex::snapped([quad.corners[i][0], quad.corners[i][1], 0.5], 1.0));
            let Ok(t) = setup_window_triangle(&vp, window, CullMode::None, FrontFace::Ccw) else {
                continue;
            };
            for y in t.bbox.y0..t.bbox.y1 {
                for x in t.bbox.x0..t.bbox.x1 {
                    if t.covers(x, y) {
                        assert!(out.insert((x, y)), "pixel ({x}, {y}) covered twice");
                    }
                }
            }
        }
        out
    }

    #[test]
    fn a_point_covers_the_one_pixel_whose_centre_is_in_its_square() {
        for (p, pixel) in [
            ([5.5, 7.5], (5, 7)),
            ([5.0, 7.0], (4, 6)), // on a corner: the square [4.5, 5.5) × [6.5, 7.5)
            ([5.99, 7.01], (5, 7)),
            ([4.99, 8.01], (4, 8)),
        ] {
            let got = covered(&point_quad(p), 16);
            assert_eq!(got, BTreeSet::from([pixel]), "point at {p:?}");
        }
    }

    #[test]
    fn an_x_major_line_covers_one_pixel_per_column_between_its_ends() {
        // From the centre of pixel 2 to the centre of pixel 12 of row 3: the start's diamond is
        // left (drawn), the end's is only entered (not drawn): columns 2..12.
        let got = covered(&line_quad([2.5, 3.5], [12.5, 3.5]).expect("quad"), 16);
        let want: BTreeSet<_> = (2..12).map(|x| (x, 3)).collect();
        assert_eq!(got, want);
        // The same line drawn backwards: columns 3..=12.
        let got = covered(&line_quad([12.5, 3.5], [2.5, 3.5]).expect("quad"), 16);
        let want: BTreeSet<_> = (3..13).map(|x| (x, 3)).collect();
        assert_eq!(got, want);
        // A sloped one: exactly one pixel per column, never two in a column.
        let got = covered(&line_quad([1.2, 1.7], [14.9, 9.3]).expect("quad"), 16);
        let columns: BTreeSet<i32> = got.iter().map(|p| p.0).collect();
        assert_eq!(columns.len(), got.len(), "{got:?}");
        assert!(got.len() >= 13 && got.len() <= 14, "{got:?}");
    }

    #[test]
    fn a_y_major_line_covers_one_pixel_per_row() {
        let got = covered(&line_quad([4.3, 1.2], [6.1, 13.8]).expect("quad"), 16);
        let rows: BTreeSet<i32> = got.iter().map(|p| p.1).collect();
        assert_eq!(rows.len(), got.len(), "{got:?}");
        assert!(got.len() >= 12 && got.len() <= 13, "{got:?}");
        assert!(got.iter().all(|&(x, _)| (4..=6).contains(&x)));
    }

    #[test]
    fn a_strip_of_lines_draws_shared_ends_once() {
        // Diamond exit: the shared vertex's pixel belongs to exactly one of the two segments.
        let a = covered(&line_quad([1.5, 2.5], [8.5, 4.5]).expect("a"), 16);
        let b = covered(&line_quad([8.5, 4.5], [14.5, 9.5]).expect("b"), 16);
        assert!(a.is_disjoint(&b), "{a:?} {b:?}");
        assert!(a.contains(&(1, 2)) && b.contains(&(8, 4)));
    }

    #[test]
    fn zero_length_and_non_finite_lines_draw_nothing() {
        assert_eq!(line_quad([3.0, 3.0], [3.0, 3.0]), None);
        assert_eq!(line_quad([f32::NAN, 3.0], [3.0, 3.0]), None);
    }
}
