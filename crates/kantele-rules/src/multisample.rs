//! Multisample antialiasing: sample counts, the standard sample positions, and the limits of a
//! multisampled target.
//!
//! Kantele multisamples as OpenGL does without `centroid` or sample shading: coverage, the
//! depth test, the depth write and blending happen per sample, the fragment program runs once
//! per pixel (at the pixel centre) when any of the pixel's samples is covered and passes, and
//! the picture is resolved by averaging a pixel's samples in linear space on read-back.
//!
//! The sample positions are the standard ones (OpenGL/Vulkan/Direct3D; Mesa's
//! `u_default_sample_positions_*`, which llvmpipe reports as `GL_SAMPLE_POSITION`), given in
//! 1/16 pixel from the pixel's top-left corner. With 8 sub-pixel bits each one is an exact
//! sub-pixel offset from the pixel centre, so a sample's edge value is
//! `E(centre) + a·dx + b·dy` exactly and the same top-left rule decides ties.
//!
//! **Per-pixel outputs.** Depth read back from a multisampled frame (the CPU backend's `Framebuffer::read_depth`)
//! is the depth at the pixel *centre*, kept by a hidden extra sample at the centre that is
//! covered, depth-tested and written exactly as the single sample of a 1× frame: it equals the
//! depth of the same frame rendered at 1×, bit for bit. The id and normal passes of the
//! backends are always rendered at 1× (averaging ids would make no sense), so they too equal
//! their 1× pictures.

use std::str::FromStr;

use crate::fixed::{SUBPIXEL_BITS, SUBPIXEL_HALF};

/// Most samples per pixel.
pub const MAX_SAMPLES: usize = 8;

/// Most bytes the tiles of a multisampled CPU target may take (8 GiB): a target over it is
/// refused with a clear error before anything is allocated.
pub const MAX_MULTISAMPLE_TARGET_BYTES: usize = 8 << 30;

/// Samples per pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum SampleCount {
    /// One sample at the pixel centre (no antialiasing; the single-sample path).
    #[default]
    X1,
    /// Four samples, the standard 4× pattern.
    X4,
    /// Eight samples, the standard 8× pattern.
    X8,
}

/// 4× positions in 1/16 pixel from the pixel's top-left corner.
const POSITIONS_4X: [[i64; 2]; 4] = [[6, 2], [14, 6], [2, 10], [10, 14]];

/// 8× positions in 1/16 pixel from the pixel's top-left corner (the Direct3D/Vulkan pattern).
const POSITIONS_8X: [[i64; 2]; 8] = [
    [9, 5],
    [7, 11],
    [13, 7],
    [5, 3],
    [3, 13],
    [1, 9],
    [11, 15],
    [15, 1],
];

impl SampleCount {
    /// Every supported count.
    pub const ALL: [SampleCount; 3] = [SampleCount::X1, SampleCount::X4, SampleCount::X8];

    /// The count as a number (1, 4 or 8).
    #[inline]
    pub const fn count(self) -> usize {
        match self {
            SampleCount::X1 => 1,
            SampleCount::X4 => 4,
            SampleCount::X8 => 8,
        }
    }

    /// Whether this is more than one sample per pixel.
    #[inline]
    pub const fn is_multisampled(self) -> bool {
        !matches!(self, SampleCount::X1)
    }

    /// The count for `n` samples per pixel, or an error naming the supported counts.
    pub fn from_count(n: u32) -> Result<Self, String> {
        match n {
            1 => Ok(SampleCount::X1),
            4 => Ok(SampleCount::X4),
            8 => Ok(SampleCount::X8),
            _ => Err(format!("unsupported sample count {n} (expected 1, 4 or 8)")),
        }
    }

    /// Sample positions in 1/16 pixel from the pixel's top-left corner (x right, y down).
    #[inline]
    pub fn positions_sixteenths(self) -> &'static [[i64; 2]] {
        match self {
            SampleCount::X1 => &[[8, 8]],
            SampleCount::X4 => &POSITIONS_4X,
            SampleCount::X8 => &POSITIONS_8X,
        }
    }

    /// Sample offsets from the pixel centre in sub-pixel units (exact).
    #[inline]
    pub fn offsets_subpixel(self) -> [[i64; 2]; MAX_SAMPLES] {
        let mut out = [[0; 2]; MAX_SAMPLES];
        let to_subpixel = |p: i64| (p << (SUBPIXEL_BITS - 4)) - SUBPIXEL_HALF;
        for (o, p) in out.iter_mut().zip(self.positions_sixteenths()) {
            *o = [to_subpixel(p[0]), to_subpixel(p[1])];
        }
        out
    }

    /// The largest distance (sub-pixel units, in x or y) of a sample from its pixel centre: how
    /// far beyond the pixel centres a triangle's pixel box must reach.
    #[inline]
    pub fn reach_subpixel(self) -> i64 {
        self.offsets_subpixel()
            .iter()
            .take(self.count())
            .flat_map(|o| [o[0].abs(), o[1].abs()])
            .max()
            .unwrap_or(0)
    }
}

impl TryFrom<u32> for SampleCount {
    type Error = String;
    fn try_from(n: u32) -> Result<Self, String> {
        Self::from_count(n)
    }
}

impl FromStr for SampleCount {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let n: u32 = s
            .trim()
            .parse()
            .map_err(|_| format!("invalid sample count '{s}' (expected 1, 4 or 8)"))?;
        Self::from_count(n)
    }
}

impl std::fmt::Display for SampleCount {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.count())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_parse_and_others_are_refused() {
        assert_eq!("4".parse::<SampleCount>(), Ok(SampleCount::X4));
        assert_eq!(SampleCount::try_from(8), Ok(SampleCount::X8));
        assert_eq!(SampleCount::try_from(1), Ok(SampleCount::X1));
        for bad in [0, 2, 3, 16] {
            let e = SampleCount::try_from(bad).expect_err("refused");
            assert!(e.contains("1, 4 or 8"), "{e}");
        }
        assert!("four".parse::<SampleCount>().is_err());
    }

    #[test]
    fn offsets_are_exact_sub_pixel_steps_inside_the_pixel() {
        // 4×: (6, 2)/16 from the corner is (−2, −6)/16 from the centre = (−32, −96) units.
        assert_eq!(SampleCount::X4.offsets_subpixel()[0], [-32, -96]);
        assert_eq!(SampleCount::X1.offsets_subpixel()[0], [0, 0]);
        for s in SampleCount::ALL {
            let offsets = s.offsets_subpixel();
            assert!(offsets[..s.count()]
                .iter()
                .all(|o| o[0].abs() < SUBPIXEL_HALF && o[1].abs() < SUBPIXEL_HALF));
            // No two samples share a row or a column (the n-queens property of both patterns).
            for i in 0..s.count() {
                for j in 0..i {
                    assert_ne!(offsets[i][0], offsets[j][0]);
                    assert_ne!(offsets[i][1], offsets[j][1]);
                }
            }
        }
        assert_eq!(SampleCount::X4.reach_subpixel(), 96);
        assert_eq!(SampleCount::X8.reach_subpixel(), 112);
    }
}
