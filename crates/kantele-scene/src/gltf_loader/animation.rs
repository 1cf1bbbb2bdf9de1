//! Sampling glTF animation samplers (glTF 2.0 §3.11): keyframe times and values in, the value at
//! a time out. `STEP`, `LINEAR` (rotations by spherical interpolation along the shorter arc) and
//! `CUBICSPLINE` (Hermite, tangents scaled by the key interval). Times before the first key give
//! the first key's value, times after the last the last key's.
//!
//! Plain arithmetic on `f32` in a fixed order: the same sampler and time give the same bits.

use glam::{Quat, Vec4};

/// How a sampler interpolates between keys (glTF `interpolation`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Interpolation {
    /// The value of the key at or before the time.
    Step,
    /// Linear between the two keys around the time (rotations: spherical, shorter arc).
    Linear,
    /// Cubic Hermite spline; each key stores an in-tangent, a value and an out-tangent.
    CubicSpline,
}

impl Interpolation {
    /// The glTF name (`LINEAR` when absent), or `None` for an unknown one.
    pub(crate) fn from_name(name: Option<&str>) -> Option<Self> {
        match name {
            None | Some("LINEAR") => Some(Self::Linear),
            Some("STEP") => Some(Self::Step),
            Some("CUBICSPLINE") => Some(Self::CubicSpline),
            Some(_) => None,
        }
    }
}

/// Keyframes: increasing times and, per key, `width` values (three times that, in-tangent, value,
/// out-tangent, for [`Interpolation::CubicSpline`]). Built by [`Keyframes::new`], which checks
/// the layout.
#[derive(Clone, Debug)]
pub(crate) struct Keyframes {
    times: Vec<f32>,
    values: Vec<f32>,
    width: usize,
    interpolation: Interpolation,
}

impl Keyframes {
    /// Checks and wraps keyframes: at least one key, finite times that never decrease, and
    /// `times × width` values (× 3 for cubic splines). Equal neighbouring times are allowed: the
    /// later key holds from that time on.
    pub(crate) fn new(
        times: Vec<f32>,
        values: Vec<f32>,
        width: usize,
        interpolation: Interpolation,
    ) -> Result<Self, String> {
        if times.is_empty() {
            return Err("has no keyframes".to_string());
        }
        if let Some(i) = times.iter().position(|t| !t.is_finite()) {
            return Err(format!("key time {i} is {} (not finite)", times[i]));
        }
        if let Some(i) = times.windows(2).position(|w| w[1] < w[0]) {
            return Err(format!(
                "key times decrease ({} then {} at key {})",
                times[i],
                times[i + 1],
                i + 1
            ));
        }
        let per_key = match interpolation {
            Interpolation::CubicSpline => 3 * width,
            _ => width,
        };
        if width == 0 || Some(values.len()) != times.len().checked_mul(per_key) {
            return Err(format!(
                "has {} output values for {} keys of {per_key}",
                values.len(),
                times.len()
            ));
        }
        Ok(Self {
            times,
            values,
            width,
            interpolation,
        })
    }

    /// Values per key (not counting cubic-spline tangents).
    pub(crate) fn width(&self) -> usize {
        self.width
    }

    /// The first and last key times.
    pub(crate) fn time_range(&self) -> (f32, f32) {
        (self.times[0], self.times[self.times.len() - 1])
    }

    /// The `width` values of key `k` (cubic splines: the value, not the tangents).
    fn value(&self, k: usize) -> &[f32] {
        let w = self.width;
        match self.interpolation {
            Interpolation::CubicSpline => &self.values[(3 * k + 1) * w..(3 * k + 2) * w],
            _ => &self.values[k * w..(k + 1) * w],
        }
    }

    /// Where `time` falls: `Err(k)` for exactly key `k`'s value (clamped ends, `STEP`), or
    /// `Ok((k, u))` for `u` in [0, 1) of the way from key `k` to key `k + 1`.
    fn locate(&self, time: f32) -> Result<(usize, f32), usize> {
        let n = self.times.len();
        // Keys at or before the time (a NaN time counts as before every key).
        let after = self.times.partition_point(|&t| t <= time);
        if after == 0 {
            return Err(0);
        }
        if after == n {
            return Err(n - 1);
        }
        let k = after - 1;
        let (t0, t1) = (self.times[k], self.times[after]);
        let u = (time - t0) / (t1 - t0);
        match self.interpolation {
            Interpolation::Step => Err(k),
            _ => Ok((k, u.clamp(0.0, 1.0))),
        }
    }

    /// The value at `time`, component by component, into `out` (`width` long).
    pub(crate) fn sample(&self, time: f32, out: &mut [f32]) {
        let w = self.width;
        let (k, u) = match self.locate(time) {
            Err(k) => {
                out.copy_from_slice(self.value(k));
                return;
            }
            Ok(found) => found,
        };
        match self.interpolation {
            Interpolation::Step => out.copy_from_slice(self.value(k)),
            Interpolation::Linear => {
                let (a, b) = (self.value(k), self.value(k + 1));
                for ((o, &a), &b) in out.iter_mut().zip(a).zip(b) {
                    *o = a + (b - a) * u;
                }
            }
            Interpolation::CubicSpline => {
                let td = self.times[k + 1] - self.times[k];
                let (u2, u3) = (u * u, u * u * u);
                let h00 = 2.0 * u3 - 3.0 * u2 + 1.0;
                let h10 = u3 - 2.0 * u2 + u;
                let h01 = -2.0 * u3 + 3.0 * u2;
                let h11 = u3 - u2;
                let base0 = 3 * k * w;
                let base1 = 3 * (k + 1) * w;
                for (c, o) in out.iter_mut().enumerate().take(w) {
                    let v0 = self.values[base0 + w + c];
                    let out_tangent0 = self.values[base0 + 2 * w + c];
                    let in_tangent1 = self.values[base1 + c];
                    let v1 = self.values[base1 + w + c];
                    *o = h00 * v0 + h10 * td * out_tangent0 + h01 * v1 + h11 * td * in_tangent1;
                }
            }
        }
    }

    /// The rotation at `time` (`width` 4, `x, y, z, w`): spherical interpolation along the
    /// shorter arc for `LINEAR`, the normalised spline for `CUBICSPLINE`. Keys are normalised
    /// first; a zero or non-finite result is the identity.
    pub(crate) fn sample_rotation(&self, time: f32) -> Quat {
        let key = |k: usize| unit_quat(Vec4::from_slice(self.value(k)));
        match (self.locate(time), self.interpolation) {
            (Err(k), _) => key(k),
            (Ok((k, _)), Interpolation::Step) => key(k),
            (Ok((k, u)), Interpolation::Linear) => slerp(key(k), key(k + 1), u),
            (Ok(_), Interpolation::CubicSpline) => {
                let mut q = [0.0; 4];
                self.sample(time, &mut q);
                unit_quat(Vec4::from_array(q))
            }
        }
    }
}

/// `q` normalised as a rotation; the identity when it has no direction.
fn unit_quat(q: Vec4) -> Quat {
    q.try_normalize().map_or(Quat::IDENTITY, Quat::from_vec4)
}

/// Spherical linear interpolation of unit quaternions along the shorter arc; nearly equal ones
/// are interpolated linearly and normalised.
pub(crate) fn slerp(a: Quat, b: Quat, u: f32) -> Quat {
    let (a, mut b) = (Vec4::from(a), Vec4::from(b));
    let mut dot = a.dot(b);
    if dot < 0.0 {
        b = -b;
        dot = -dot;
    }
    if dot > 0.9995 {
        return unit_quat(a + (b - a) * u);
    }
    let theta = dot.min(1.0).acos();
    let sin_theta = theta.sin();
    let wa = ((1.0 - u) * theta).sin() / sin_theta;
    let wb = (u * theta).sin() / sin_theta;
    unit_quat(a * wa + b * wb)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f32, b: f32) -> bool {
        (a - b).abs() <= 1e-6
    }

    #[test]
    fn step_holds_each_key_and_clamps_the_ends() {
        let k = Keyframes::new(
            vec![1.0, 2.0, 4.0],
            vec![10.0, 20.0, 40.0],
            1,
            Interpolation::Step,
        )
        .unwrap();
        let at = |t: f32| {
            let mut v = [0.0];
            k.sample(t, &mut v);
            v[0]
        };
        assert_eq!(at(-5.0), 10.0);
        assert_eq!(at(1.0), 10.0);
        assert_eq!(at(1.999), 10.0);
        assert_eq!(at(2.0), 20.0);
        assert_eq!(at(3.9), 20.0);
        assert_eq!(at(4.0), 40.0);
        assert_eq!(at(100.0), 40.0);
        assert_eq!(at(f32::NAN), 10.0);
    }

    #[test]
    fn linear_interpolates_each_component() {
        let k = Keyframes::new(
            vec![0.0, 2.0],
            vec![0.0, 10.0, 4.0, -10.0],
            2,
            Interpolation::Linear,
        )
        .unwrap();
        let mut v = [0.0; 2];
        k.sample(0.5, &mut v);
        assert_eq!(v, [1.0, 5.0]);
        k.sample(-1.0, &mut v);
        assert_eq!(v, [0.0, 10.0]);
        k.sample(3.0, &mut v);
        assert_eq!(v, [4.0, -10.0]);
    }

    #[test]
    fn cubic_spline_matches_the_hermite_formula_by_hand() {
        // Keys at t = 1 and t = 3 (interval 2): value 0 → 1, out-tangent of key 0 is 2, in-tangent
        // of key 1 is −1. At t = 2, u = 0.5: h00 = 0.5, h10 = 0.125, h01 = 0.5, h11 = −0.125, so
        // p = 0.5·0 + 0.125·2·2 + 0.5·1 + (−0.125)·2·(−1) = 0.5 + 0.5 + 0.25 = 1.25.
        // At t = 1.5, u = 0.25: h00 = 0.84375, h10 = 0.140625, h01 = 0.15625, h11 = −0.046875:
        // p = 0.140625·2·2 + 0.15625 + (−0.046875)·2·(−1) = 0.5625 + 0.15625 + 0.09375 = 0.8125.
        let k = Keyframes::new(
            vec![1.0, 3.0],
            vec![
                9.0, 0.0, 2.0, // key 0: in-tangent (unused), value, out-tangent
                -1.0, 1.0, 7.0, // key 1: in-tangent, value, out-tangent (unused)
            ],
            1,
            Interpolation::CubicSpline,
        )
        .unwrap();
        let at = |t: f32| {
            let mut v = [0.0];
            k.sample(t, &mut v);
            v[0]
        };
        assert!(close(at(2.0), 1.25), "{}", at(2.0));
        assert!(close(at(1.5), 0.8125), "{}", at(1.5));
        assert_eq!(at(1.0), 0.0);
        assert_eq!(at(0.0), 0.0);
        assert_eq!(at(3.0), 1.0);
        assert_eq!(at(5.0), 1.0);
    }

    #[test]
    fn rotations_take_the_shorter_arc_and_stay_unit() {
        let a = Quat::from_rotation_z(0.0);
        let b = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
        // The same rotation written with the opposite sign: still a quarter turn away.
        let k = Keyframes::new(
            vec![0.0, 1.0],
            [a.to_array(), (-b).to_array()].concat(),
            4,
            Interpolation::Linear,
        )
        .unwrap();
        let q = k.sample_rotation(0.5);
        let expected = Quat::from_rotation_z(std::f32::consts::FRAC_PI_4);
        assert!(q.dot(expected).abs() > 1.0 - 1e-6, "{q}");
        assert!(close(q.length(), 1.0));
        let cubic = Keyframes::new(
            vec![0.0, 1.0],
            [
                [0.0; 4],
                a.to_array(),
                [0.0; 4],
                [0.0; 4],
                b.to_array(),
                [0.0; 4],
            ]
            .concat(),
            4,
            Interpolation::CubicSpline,
        )
        .unwrap();
        let q = cubic.sample_rotation(0.5);
        assert!(close(q.length(), 1.0));
        // Zero tangents: the value is the normalised average of the two keys, 45°.
        assert!(q.dot(expected).abs() > 1.0 - 1e-6, "{q}");
    }

    #[test]
    fn malformed_keyframes_are_refused_by_line() {
        let lin = Interpolation::Linear;
        assert!(Keyframes::new(vec![], vec![], 1, lin).is_err());
        assert!(Keyframes::new(vec![0.0, f32::NAN], vec![0.0; 2], 1, lin)
            .unwrap_err()
            .contains("not finite"));
        assert!(Keyframes::new(vec![1.0, 0.0], vec![0.0; 2], 1, lin)
            .unwrap_err()
            .contains("decrease"));
        assert!(Keyframes::new(vec![0.0, 1.0], vec![0.0; 3], 1, lin).is_err());
        assert!(
            Keyframes::new(vec![0.0, 1.0], vec![0.0; 2], 1, Interpolation::CubicSpline).is_err()
        );
        // Equal neighbouring times: the later key holds from then on.
        let k = Keyframes::new(vec![0.0, 1.0, 1.0, 2.0], vec![0.0, 1.0, 5.0, 6.0], 1, lin).unwrap();
        let mut v = [0.0];
        k.sample(1.0, &mut v);
        assert_eq!(v, [5.0]);
        k.sample(0.5, &mut v);
        assert_eq!(v, [0.5]);
    }
}
