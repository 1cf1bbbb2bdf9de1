//! Coverage of an 8 × 8 block a row of eight pixels at a time: each edge's values along the
//! row as 32-bit lanes, a pixel covered where none of the three is negative, so a row costs
//! three additions, two ORs and one sign-bit mask, with no branch and no division.
//!
//! The 64-bit edge values are exact at any coordinate the guard band allows; within a block
//! they usually span far less than 32 bits. [`EdgeLanes::new`] takes a block only when a bound
//! of all its values fits in `i32`; then each lane holds the exact value, and the bits are
//! those of the 64-bit per-pixel test. Blocks of very long edges are left to the caller's
//! 64-bit path.

use kantele_lanes::{I32x8, Lanes};

/// The three biased edge values over an 8 × 8 block, every one known to fit in `i32`: at the
/// block's first pixel, and per lane along a row.
#[derive(Clone, Copy, Debug)]
pub(super) struct EdgeLanes<L: Lanes> {
    /// The values at the block's first pixel.
    origin: [i32; 3],
    /// The steps per pixel in y.
    pixel_y: [i32; 3],
    /// Lane `k` holds `k · step_x`: the offsets of a row's eight pixels from its first.
    columns: [L::I32; 3],
    /// The step per pixel in y, splatted.
    step_y: [L::I32; 3],
}

impl<L: Lanes> EdgeLanes<L> {
    /// The block whose first pixel has the values `origin`, stepped by `step_x` and `step_y`
    /// per pixel; `None` when `|origin| + 7·(|step_x| + |step_y|)` (a bound of every value of
    /// the block) exceeds `i32`. An edge given as `0` everywhere (origin and steps) covers
    /// every pixel.
    #[inline(always)]
    pub(super) fn new(
        lanes: L,
        origin: [i64; 3],
        step_x: [i64; 3],
        step_y: [i64; 3],
    ) -> Option<Self> {
        for e in 0..3 {
            // Every value of the block lies within `reach` of the first one: a sufficient
            // test (it refuses some blocks that fit, none that do not), cheaper than the
            // corners themselves, and its part from the steps is the same for every block of
            // a triangle.
            let reach = 7 * (step_x[e].abs() + step_y[e].abs());
            if origin[e].abs() + reach > i64::from(i32::MAX) {
                return None;
            }
        }
        // From here on arithmetic wraps (modulo 2^32): every sum it ends in is an edge value
        // at a pixel of the block, which fits, so it comes out exact. The steps fit too.
        let index = lanes.lane_index();
        let zero = lanes.splat_i32(0);
        let mut edges = Self {
            origin: origin.map(|v| v as i32),
            pixel_y: step_y.map(|v| v as i32),
            columns: [zero; 3],
            step_y: [zero; 3],
        };
        // Plain loops, not closures: a closure would be compiled without the instruction
        // set's target features and call the lane operations out of line.
        for e in 0..3 {
            edges.columns[e] = index * lanes.splat_i32(step_x[e] as i32);
            edges.step_y[e] = lanes.splat_i32(step_y[e] as i32);
        }
        Some(edges)
    }

    /// Coverage bits of rows `rows` (within `0..8`; other rows' bits are 0): bit `8·r + c` is
    /// set where every edge value at pixel `(c, r)` is at least 0.
    #[inline(always)]
    pub(super) fn mask(&self, lanes: L, rows: std::ops::Range<i32>) -> u64 {
        let mut row = self.columns;
        for (e, value) in row.iter_mut().enumerate() {
            let first = self.origin[e].wrapping_add(rows.start.wrapping_mul(self.pixel_y[e]));
            *value = lanes.splat_i32(first) + *value;
        }
        let mut bits = 0u64;
        for r in rows {
            // A pixel is outside when one of its values is negative: the OR of the three has
            // the sign bit set exactly then.
            let outside = (row[0] | row[1] | row[2]).sign_bits();
            bits |= u64::from(!outside) << (8 * r);
            for (value, step) in row.iter_mut().zip(self.step_y) {
                *value = *value + step;
            }
        }
        bits
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kantele_lanes::{dispatch, Isa, LaneKernel};

    /// A block's mask, or `None` where it is refused.
    #[derive(Clone)]
    struct Mask {
        origin: [i64; 3],
        sx: [i64; 3],
        sy: [i64; 3],
        rows: std::ops::Range<i32>,
    }

    impl LaneKernel for Mask {
        type Output = Option<u64>;
        #[inline(always)]
        fn run<L: Lanes>(self, lanes: L) -> Option<u64> {
            let edges = EdgeLanes::new(lanes, self.origin, self.sx, self.sy)?;
            Some(edges.mask(lanes, self.rows))
        }
    }

    /// The 64-bit per-pixel test of the same block.
    fn per_pixel(q: &Mask) -> u64 {
        let mut bits = 0;
        for r in q.rows.clone() {
            for c in 0..8 {
                let inside = (0..3).all(|e| q.origin[e] + q.sx[e] * c + q.sy[e] * r as i64 >= 0);
                bits |= u64::from(inside) << (8 * r + c as i32);
            }
        }
        bits
    }

    /// Random blocks crossed by edges at every scale, up to values at the edge of `i32` and
    /// past it: the lane masks at every supported level equal the 64-bit per-pixel test, and
    /// exactly the blocks whose bound exceeds `i32` are refused.
    #[test]
    fn lane_masks_match_the_per_pixel_test() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let isas: Vec<Isa> = Isa::supported().collect();
        let (mut taken, mut refused) = (0, 0);
        for case in 0..20_000 {
            let scale = [1i64 << 8, 1 << 20, 1 << 28, 1 << 33][case % 4];
            let sx: [i64; 3] = std::array::from_fn(|_| next() as i64 % scale);
            let sy: [i64; 3] = std::array::from_fn(|_| next() as i64 % scale);
            // Put each edge's zero somewhere across (or just beyond) the block.
            let origin: [i64; 3] = std::array::from_fn(|e| {
                let (c, r) = ((next() % 10) as i64 - 1, (next() % 10) as i64 - 1);
                -(sx[e] * c + sy[e] * r) + next() as i64 % (sx[e].abs() + 1)
            });
            let r0 = (next() % 8) as i32;
            let rows = r0..r0 + 1 + (next() % (8 - r0 as u64)) as i32;
            let query = Mask {
                origin,
                sx,
                sy,
                rows,
            };
            let fits = (0..3)
                .all(|e| origin[e].abs() + 7 * (sx[e].abs() + sy[e].abs()) <= i32::MAX as i64);
            let expected = fits.then(|| per_pixel(&query));
            if fits {
                taken += 1;
            } else {
                refused += 1;
            }
            for &isa in &isas {
                assert_eq!(
                    dispatch(isa, query.clone()),
                    expected,
                    "{isa}: origin {origin:?}, steps {sx:?} {sy:?}"
                );
            }
        }
        assert!(
            taken > 8_000 && refused > 1_000,
            "{taken} taken, {refused} refused"
        );
    }
}
