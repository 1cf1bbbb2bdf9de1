//! Picture agreement between two renderings of the same frame (e.g. Kantele and OpenGL):
//! coverage, 8-bit colour and depth differences, and a difference image.

use kantele::backend::FrameImage;

/// How two frames differ. Colour differences are in 8-bit sRGB levels over the RGB channels.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// Pixels compared.
    pub pixels: usize,
    /// Pixels covered (depth < 1) in one frame and not in the other.
    pub coverage_mismatches: usize,
    /// Largest per-channel difference.
    pub max_color_diff: u8,
    /// Mean per-channel difference over all pixels and RGB channels.
    pub mean_color_diff: f64,
    /// Pixels whose largest channel difference exceeds the bound given to [`compare`], not
    /// counting pixels on triangle edges (when edge information was given).
    pub interior_over_bound: usize,
    /// Largest depth difference over pixels covered in both.
    pub max_depth_diff: f32,
    /// Mean depth difference over pixels covered in both.
    pub mean_depth_diff: f64,
    /// RGBA8 difference image: grey = colour difference × 8, red = covered only in `a`,
    /// green = covered only in `b`.
    pub difference_image: Vec<u8>,
}

impl Comparison {
    /// Share of pixels whose coverage differs.
    pub fn coverage_mismatch_fraction(&self) -> f64 {
        self.coverage_mismatches as f64 / self.pixels.max(1) as f64
    }
}

/// Compares frames `a` and `b` of equal size. `edges`, if given, marks pixels on triangle edges
/// (see [`edge_mask`]); they are excluded from `interior_over_bound`, which counts pixels whose
/// colour differs by more than `bound` levels.
pub fn compare(
    a: &FrameImage,
    b: &FrameImage,
    edges: Option<&[bool]>,
    bound: u8,
) -> Option<Comparison> {
    if a.width != b.width || a.height != b.height || a.color.len() != b.color.len() {
        return None;
    }
    let ca = a.to_rgba8(true);
    let cb = b.to_rgba8(true);
    let pixels = a.color.len();
    let mut result = Comparison {
        pixels,
        coverage_mismatches: 0,
        max_color_diff: 0,
        mean_color_diff: 0.0,
        interior_over_bound: 0,
        max_depth_diff: 0.0,
        mean_depth_diff: 0.0,
        difference_image: Vec::with_capacity(pixels * 4),
    };
    let mut sum = 0u64;
    let mut depth_sum = 0f64;
    let mut both = 0usize;
    for i in 0..pixels {
        let pa = &ca[4 * i..4 * i + 3];
        let pb = &cb[4 * i..4 * i + 3];
        let d = (0..3).map(|k| pa[k].abs_diff(pb[k])).max().unwrap_or(0);
        sum += (0..3).map(|k| pa[k].abs_diff(pb[k]) as u64).sum::<u64>();
        result.max_color_diff = result.max_color_diff.max(d);
        if d > bound && !edges.is_some_and(|e| e[i]) {
            result.interior_over_bound += 1;
        }
        let covered_a = a.depth[i] < 1.0;
        let covered_b = b.depth[i] < 1.0;
        let pixel = if covered_a != covered_b {
            result.coverage_mismatches += 1;
            if covered_a {
                [255, 0, 0, 255]
            } else {
                [0, 255, 0, 255]
            }
        } else {
            if covered_a {
                let dd = (a.depth[i] - b.depth[i]).abs();
                result.max_depth_diff = result.max_depth_diff.max(dd);
                depth_sum += dd as f64;
                both += 1;
            }
            let v = d.saturating_mul(8);
            [v, v, v, 255]
        };
        result.difference_image.extend_from_slice(&pixel);
    }
    result.mean_color_diff = sum as f64 / (3 * pixels.max(1)) as f64;
    result.mean_depth_diff = depth_sum / both.max(1) as f64;
    Some(result)
}

/// Marks pixels on triangle edges from an id frame ([`kantele::backend::Pass::Ids`]): a pixel is
/// on an edge when any of its 8 neighbours shows a different triangle (or background).
pub fn edge_mask(ids: &FrameImage) -> Vec<bool> {
    let (w, h) = (ids.width as i64, ids.height as i64);
    let id = |x: i64, y: i64| ids.color[(y * w + x) as usize];
    let mut mask = vec![false; ids.color.len()];
    for y in 0..h {
        for x in 0..w {
            let here = id(x, y);
            'n: for dy in -1..=1 {
                for dx in -1..=1 {
                    let (nx, ny) = (x + dx, y + dy);
                    if nx >= 0 && ny >= 0 && nx < w && ny < h && id(nx, ny) != here {
                        mask[(y * w + x) as usize] = true;
                        break 'n;
                    }
                }
            }
        }
    }
    mask
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(color: [f32; 4], depth: f32) -> FrameImage {
        FrameImage {
            width: 2,
            height: 2,
            color: vec![color; 4],
            depth: vec![depth; 4],
        }
    }

    #[test]
    fn identical_frames_agree_and_differences_are_measured() {
        let a = frame([0.5, 0.5, 0.5, 1.0], 0.5);
        let same = compare(&a, &a, None, 0).expect("same size");
        assert_eq!(
            (
                same.max_color_diff,
                same.coverage_mismatches,
                same.interior_over_bound
            ),
            (0, 0, 0)
        );
        let mut b = a.clone();
        b.color[0] = [1.0, 0.5, 0.5, 1.0];
        b.depth[3] = 1.0;
        let diff = compare(&a, &b, None, 3).expect("same size");
        assert_eq!(diff.max_color_diff, 255 - 188);
        assert_eq!(diff.coverage_mismatches, 1);
        assert_eq!(diff.interior_over_bound, 1);
        let edges = [true, false, false, false];
        assert_eq!(
            compare(&a, &b, Some(&edges), 3)
                .expect("same")
                .interior_over_bound,
            0
        );
        assert!(compare(
            &a,
            &FrameImage {
                width: 1,
                ..a.clone()
            },
            None,
            0
        )
        .is_none());
    }

    #[test]
    fn edges_are_where_ids_change() {
        let mut ids = frame([0.0; 4], 1.0);
        ids.width = 4;
        ids.height = 1;
        ids.color = vec![[1.0; 4], [1.0; 4], [2.0; 4], [2.0; 4]];
        ids.depth = vec![1.0; 4];
        assert_eq!(edge_mask(&ids), vec![false, true, true, false]);
    }
}
