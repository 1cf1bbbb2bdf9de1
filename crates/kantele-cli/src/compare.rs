//! Tolerances for `kantele compare`, checked against [`kantele_testkit::compare::Comparison`].

use kantele_testkit::compare::Comparison;

/// Limits a comparison must stay within.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerances {
    /// Largest allowed share of pixels whose coverage differs (a fraction, 0..1).
    pub max_coverage_diff: f64,
    /// Largest allowed mean 8-bit colour difference.
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

/// Descriptions of the tolerances `c` breaks (empty when it passes).
pub fn violations(c: &Comparison, tol: &Tolerances) -> Vec<String> {
    let mut v = Vec::new();
    let coverage = c.coverage_mismatch_fraction();
    if coverage > tol.max_coverage_diff {
        v.push(format!(
            "coverage differs on {:.4}% of pixels ({} pixels), limit {:.4}% (--max-coverage-diff {})",
            coverage * 100.0,
            c.coverage_mismatches,
            tol.max_coverage_diff * 100.0,
            tol.max_coverage_diff
        ));
    }
    if c.mean_color_diff > tol.max_mean_diff {
        v.push(format!(
            "mean colour difference {:.3} exceeds {} (--max-mean-diff)",
            c.mean_color_diff, tol.max_mean_diff
        ));
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use kantele::backend::FrameImage;

    fn frame(color: [f32; 4], depth: f32, n: usize) -> FrameImage {
        FrameImage {
            width: n as u32,
            height: 1,
            color: vec![color; n],
            depth: vec![depth; n],
        }
    }

    #[test]
    fn tolerances_name_what_is_broken() {
        let a = frame([0.0, 0.0, 0.0, 1.0], 0.5, 100);
        let mut b = a.clone();
        b.depth[0] = 1.0;
        let c = kantele_testkit::compare::compare(&a, &b, None, 255).expect("same size");
        let v = violations(&c, &Tolerances::default());
        assert_eq!(v.len(), 1, "{v:?}");
        assert!(v[0].contains("--max-coverage-diff"));
        b.color = vec![[1.0, 1.0, 1.0, 1.0]; 100];
        let c = kantele_testkit::compare::compare(&a, &b, None, 255).expect("same size");
        let v = violations(
            &c,
            &Tolerances {
                max_coverage_diff: 0.5,
                max_mean_diff: 1.0,
            },
        );
        assert_eq!(v.len(), 1);
        assert!(v[0].contains("mean colour difference 255"));
        assert!(violations(
            &c,
            &Tolerances {
                max_coverage_diff: 1.0,
                max_mean_diff: 255.0
            }
        )
        .is_empty());
    }
}
