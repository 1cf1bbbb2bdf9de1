//! Morph targets (glTF 2.0 §3.7.2.2): a primitive's attribute plus `weight ×` each target's
//! displacement. The one rule for the default weights at load and for animated weights.

use glam::Vec3;

/// Whether a target with this weight changes anything: zero and non-finite weights are skipped.
pub(crate) fn applies(weight: f32) -> bool {
    weight != 0.0 && weight.is_finite()
}

/// Adds `weight ×` the displacements `deltas` (three floats per vertex) to `values`.
pub(crate) fn add_target(values: &mut [Vec3], deltas: &[f32], weight: f32) {
    for (v, d) in values.iter_mut().zip(deltas.chunks_exact(3)) {
        *v += weight * Vec3::from_slice(d);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn adds_weighted_displacements_and_skips_zero_and_nan_weights() {
        let mut v = [Vec3::ZERO, Vec3::ONE];
        add_target(&mut v, &[1.0, 2.0, 3.0, -1.0, 0.0, 0.0], 0.5);
        assert_eq!(v, [Vec3::new(0.5, 1.0, 1.5), Vec3::new(0.5, 1.0, 1.0)]);
        assert!(!applies(0.0) && !applies(f32::NAN) && !applies(f32::INFINITY));
        assert!(applies(-0.25));
    }
}
