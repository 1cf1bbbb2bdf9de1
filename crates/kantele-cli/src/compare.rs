//! Image comparison metrics between two renderings of the same view.
//!
//! Pure functions over plain buffers; depends only on `std` and `kantele::backend::FrameImage`,
//! so other crates' tests can include this file with `#[path = ".../compare.rs"] mod compare;`.
//!
//! Conventions: colours are 8-bit sRGB RGBA (`FrameImage::to_rgba8(true)`), depth is window
//! depth in [0, 1]; a pixel is *covered* when its depth is below 1.0.

use kantele::backend::FrameImage;

/// How far two images differ.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Metrics {
    /// Pixels compared.
    pub pixels: usize,
    /// Pixels covered in exactly one image.
    pub coverage_mismatches: usize,
    /// `coverage_mismatches / pixels`.
    pub coverage_diff: f64,
    /// Largest absolute difference of an 8-bit sRGB R, G or B value.
    pub max_color_diff: u8,
    /// Mean absolute difference over the R, G and B values of every pixel.
    pub mean_color_diff: f64,
    /// Pixels covered in both images.
    pub both_covered: usize,
    /// Largest absolute window-depth difference over pixels covered in both (0 if none).
    pub max_depth_diff: f64,
    /// Mean absolute window-depth difference over pixels covered in both (0 if none).
    pub mean_depth_diff: f64,
}

/// Limits a comparison must stay within.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerances {
    /// Largest allowed [`Metrics::coverage_diff`] (a fraction, 0..1).
    pub max_coverage_diff: f64,
    /// Largest allowed [`Metrics::mean_color_diff`] (8-bit units).
    pub max_mean_diff: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Self {
            max_coverage_diff: 0.001,
            max_mean_diff: 1.0,
        }
    }
}

impl Metrics {
    /// Descriptions of the tolerances this comparison breaks (empty when it passes).
    pub fn violations(&self, tol: &Tolerances) -> Vec<String> {
        let mut v = Vec::new();
        if self.coverage_diff > tol.max_coverage_diff {
            v.push(format!(
                "coverage differs on {:.4}% of pixels ({} pixels), limit {:.4}% (--max-coverage-diff {})",
                self.coverage_diff * 100.0,
                self.coverage_mismatches,
                tol.max_coverage_diff * 100.0,
                tol.max_coverage_diff
            ));
        }
        if self.mean_color_diff > tol.max_mean_diff {
            v.push(format!(
                "mean colour difference {:.3} exceeds {} (--max-mean-diff)",
                self.mean_color_diff, tol.max_mean_diff
            ));
        }
        v
    }
}

/// Why two images cannot be compared.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SizeMismatch(pub String);

impl std::fmt::Display for SizeMismatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for SizeMismatch {}

/// Whether a window depth counts as covered.
#[inline]
pub fn covered(depth: f32) -> bool {
    depth < 1.0
}

fn check(
    pixels: usize,
    rgba_a: &[u8],
    depth_a: &[f32],
    rgba_b: &[u8],
    depth_b: &[f32],
) -> Result<(), SizeMismatch> {
    if rgba_a.len() != pixels * 4
        || rgba_b.len() != pixels * 4
        || depth_a.len() != pixels
        || depth_b.len() != pixels
    {
        return Err(SizeMismatch(format!(
            "buffers do not match: {pixels} pixels, colours {} / {} bytes, depths {} / {}",
            rgba_a.len(),
            rgba_b.len(),
            depth_a.len(),
            depth_b.len()
        )));
    }
    Ok(())
}

/// Compares two images of `pixels` pixels given as 8-bit RGBA and window depth.
pub fn compare_buffers(
    pixels: usize,
    rgba_a: &[u8],
    depth_a: &[f32],
    rgba_b: &[u8],
    depth_b: &[f32],
) -> Result<Metrics, SizeMismatch> {
    check(pixels, rgba_a, depth_a, rgba_b, depth_b)?;
    let mut m = Metrics {
        pixels,
        ..Metrics::default()
    };
    let mut color_sum = 0u64;
    let mut depth_sum = 0f64;
    for i in 0..pixels {
        for c in 0..3 {
            let d = rgba_a[i * 4 + c].abs_diff(rgba_b[i * 4 + c]);
            color_sum += d as u64;
            m.max_color_diff = m.max_color_diff.max(d);
        }
        let (ca, cb) = (covered(depth_a[i]), covered(depth_b[i]));
        if ca != cb {
            m.coverage_mismatches += 1;
        } else if ca {
            let d = (depth_a[i] as f64 - depth_b[i] as f64).abs();
            m.both_covered += 1;
            depth_sum += d;
            m.max_depth_diff = m.max_depth_diff.max(d);
        }
    }
    if pixels > 0 {
        m.coverage_diff = m.coverage_mismatches as f64 / pixels as f64;
        m.mean_color_diff = color_sum as f64 / (pixels as f64 * 3.0);
    }
    if m.both_covered > 0 {
        m.mean_depth_diff = depth_sum / m.both_covered as f64;
    }
    Ok(m)
}

/// Compares two frames (colours encoded to 8-bit sRGB first).
#[allow(dead_code)] // the binary compares buffers it already encoded; other users call this
pub fn compare_frames(a: &FrameImage, b: &FrameImage) -> Result<Metrics, SizeMismatch> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(SizeMismatch(format!(
            "image sizes differ: {}x{} and {}x{}",
            a.width, a.height, b.width, b.height
        )));
    }
    let pixels = a.width as usize * a.height as usize;
    compare_buffers(
        pixels,
        &a.to_rgba8(true),
        &a.depth,
        &b.to_rgba8(true),
        &b.depth,
    )
}

/// Factor the colour difference is multiplied by in [`diff_image`].
pub const DIFF_GAIN: u32 = 16;
/// Marks pixels covered only in the first image.
pub const ONLY_A: [u8; 4] = [255, 0, 255, 255];
/// Marks pixels covered only in the second image.
pub const ONLY_B: [u8; 4] = [0, 255, 255, 255];

/// An RGBA8 picture of the differences: grey = largest RGB difference × [`DIFF_GAIN`],
/// [`ONLY_A`] / [`ONLY_B`] where coverage differs.
pub fn diff_image(
    pixels: usize,
    rgba_a: &[u8],
    depth_a: &[f32],
    rgba_b: &[u8],
    depth_b: &[f32],
) -> Result<Vec<u8>, SizeMismatch> {
    check(pixels, rgba_a, depth_a, rgba_b, depth_b)?;
    let mut out = Vec::with_capacity(pixels * 4);
    for i in 0..pixels {
        let px = match (covered(depth_a[i]), covered(depth_b[i])) {
            (true, false) => ONLY_A,
            (false, true) => ONLY_B,
            _ => {
                let d = (0..3)
                    .map(|c| rgba_a[i * 4 + c].abs_diff(rgba_b[i * 4 + c]))
                    .max()
                    .unwrap_or(0);
                let g = (d as u32 * DIFF_GAIN).min(255) as u8;
                [g, g, g, 255]
            }
        };
        out.extend_from_slice(&px);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(colors: &[[f32; 4]], depth: &[f32]) -> FrameImage {
        FrameImage {
            width: colors.len() as u32,
            height: 1,
            color: colors.to_vec(),
            depth: depth.to_vec(),
        }
    }

    #[test]
    fn identical_images_have_no_difference() {
        let f = frame(&[[0.2, 0.4, 0.6, 1.0], [0.0; 4]], &[0.5, 1.0]);
        let m = compare_frames(&f, &f).unwrap();
        assert_eq!(m.pixels, 2);
        assert_eq!(m.coverage_mismatches, 0);
        assert_eq!(m.max_color_diff, 0);
        assert_eq!(m.mean_color_diff, 0.0);
        assert_eq!(m.both_covered, 1);
        assert_eq!(m.max_depth_diff, 0.0);
        assert!(m.violations(&Tolerances::default()).is_empty());
    }

    #[test]
    fn metrics_by_hand() {
        // 4 pixels: equal, colour off by (3, 0, 6), covered only in a, covered only in b.
        let a = [
            10, 10, 10, 255, 100, 50, 20, 255, 0, 0, 0, 255, 0, 0, 0, 255,
        ];
        let b = [
            10, 10, 10, 255, 103, 50, 14, 255, 0, 0, 0, 255, 0, 0, 0, 255,
        ];
        let da = [0.5, 0.25, 0.5, 1.0];
        let db = [0.5, 0.75, 1.0, 0.5];
        let m = compare_buffers(4, &a, &da, &b, &db).unwrap();
        assert_eq!(m.coverage_mismatches, 2);
        assert_eq!(m.coverage_diff, 0.5);
        assert_eq!(m.max_color_diff, 6);
        assert!((m.mean_color_diff - 9.0 / 12.0).abs() < 1e-12);
        assert_eq!(m.both_covered, 2);
        assert!((m.max_depth_diff - 0.5).abs() < 1e-12);
        assert!((m.mean_depth_diff - 0.25).abs() < 1e-12);
        let v = m.violations(&Tolerances::default());
        assert_eq!(v.len(), 1, "{v:?}");
        assert!(v[0].contains("coverage"));
        let loose = Tolerances {
            max_coverage_diff: 0.5,
            max_mean_diff: 0.5,
        };
        let v = m.violations(&loose);
        assert_eq!(v.len(), 1);
        assert!(v[0].contains("mean colour"));

        let d = diff_image(4, &a, &da, &b, &db).unwrap();
        assert_eq!(&d[0..4], &[0, 0, 0, 255]);
        assert_eq!(&d[4..8], &[96, 96, 96, 255]);
        assert_eq!(&d[8..12], &ONLY_A);
        assert_eq!(&d[12..16], &ONLY_B);
    }

    #[test]
    fn size_mismatch_is_an_error() {
        let a = frame(&[[0.0; 4]], &[1.0]);
        let b = frame(&[[0.0; 4], [0.0; 4]], &[1.0, 1.0]);
        assert!(compare_frames(&a, &b).is_err());
        assert!(compare_buffers(2, &[0; 8], &[1.0], &[0; 8], &[1.0, 1.0]).is_err());
    }

    #[test]
    fn empty_images() {
        let m = compare_buffers(0, &[], &[], &[], &[]).unwrap();
        assert_eq!(m, Metrics::default());
    }
}
