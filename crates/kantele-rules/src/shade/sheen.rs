//! `KHR_materials_sheen`: a layer of fibres over the base (velvet, cloth), shaded as the
//! specification and the glTF sample viewer do, with Filament's image-based light.
//!
//! - The **lobe** is `sheenColor × D × V`: Estevez and Kulla's "Charlie" distribution
//!   `D = (2 + 1/α) (1 − NdotH²)^(1/(2α)) / (2π)` with `α = roughness²` (perceptual roughness
//!   no smaller than [`MIN_PUNCTUAL_ROUGHNESS`]), and their visibility, the one the
//!   specification gives: `V = 1 / ((1 + Λ(NdotV) + Λ(NdotL)) 4 NdotV NdotL)`, `Λ` their fit
//!   ([`sheen_lambda`]), at most 1 (as the glTF sample viewer clamps it). Its albedo stays
//!   below 1, where the simpler Neubelt visibility reflects several times the light it
//!   receives at grazing views of smooth sheens.
//! - Its **directional albedo** `E(NdotV, roughness) = ∫ D V NdotL dω` (sheen colour 1) is a
//!   table computed once per process ([`sheen_table`]).
//! - The **base** under the layer (everything but the emission and a clear coat) is scaled by
//!   `1 − max(sheenColor) × E(NdotV)`, the energy the layer keeps from it. Filament's choice:
//!   one scale per point from the view alone, for lights and the environment alike (the
//!   specification's stricter form also takes the minimum with `E(NdotL)` per light).
//! - **Image-based light** lights the layer as Filament does: the pre-filtered specular
//!   radiance along the reflected view at the sheen's roughness × `sheenColor × E(NdotV)`.

use std::f64::consts::PI as PI64;
use std::sync::OnceLock;

use kantele_lanes::{F32x8, I32x8, Lanes, Mask8, Scalar};

use super::environment::{pair_table_lanes, BRDF_TABLE_SIZE};
use super::pbr::MIN_PUNCTUAL_ROUGHNESS;
use super::transmission::{exp2, exp2_nonpositive};

/// `KHR_materials_sheen`'s layer over a surface point, per lane.
#[derive(Clone, Copy, Debug)]
pub struct SheenLayer<L: Lanes> {
    /// `sheenColorFactor` × texture (linear RGB in [0, 1]).
    pub color: [L::F32; 3],
    /// `sheenRoughnessFactor` × texture, perceptual, in [0, 1].
    pub roughness: L::F32,
}

/// What a surface point's sheen needs besides its colour, once per point: the distribution's
/// `α` and exponent, the layer's albedo at the view and the scale of the base under it.
#[derive(Clone, Copy, Debug)]
pub struct SheenTerms<L: Lanes> {
    /// `α = roughness²`, of the roughness clamped to [`MIN_PUNCTUAL_ROUGHNESS`].
    pub alpha: L::F32,
    /// `1 / (2α)`, the distribution's exponent.
    pub exponent: L::F32,
    /// `E(NdotV, roughness)`, the lobe's directional albedo ([`sheen_albedo_lanes`]).
    pub albedo: L::F32,
    /// `1 − max(color) × albedo` (at least 0): what the layer lets through of the base.
    pub base_scale: L::F32,
    /// The coefficients of [`sheen_lambda`] at `alpha`.
    pub fit: [L::F32; 5],
    /// `2 L(½)`, twice the fit's exponent at ½ ([`sheen_lambda`]).
    pub twice_at_half: L::F32,
    /// `Λ(NdotV)`.
    pub lambda_view: L::F32,
}

impl<L: Lanes> SheenLayer<L> {
    /// The layer's per-point terms at `n_dot_v` (clamped to [0, 1]).
    #[inline(always)]
    pub fn terms(&self, lanes: L, n_dot_v: L::F32) -> SheenTerms<L> {
        let roughness = self
            .roughness
            .max(lanes.splat_f32(MIN_PUNCTUAL_ROUGHNESS))
            .min(lanes.splat_f32(1.0));
        let alpha = roughness * roughness;
        let albedo = sheen_albedo_lanes(lanes, n_dot_v, roughness);
        let brightest = self.color[0].max(self.color[1]).max(self.color[2]);
        let fit = lambda_fit(lanes, alpha);
        let at_half = lambda_exponent(lanes, &fit, lanes.splat_f32(0.5));
        let twice_at_half = at_half + at_half;
        SheenTerms {
            alpha,
            exponent: lanes.splat_f32(0.5) / alpha,
            albedo,
            base_scale: (lanes.splat_f32(1.0) - brightest * albedo).max(lanes.splat_f32(0.0)),
            lambda_view: sheen_lambda(lanes, &fit, twice_at_half, n_dot_v),
            fit,
            twice_at_half,
        }
    }
}

/// Estevez and Kulla's fit of the sheen's `Λ`: five coefficients `(a, b, c, d, e)`, each as
/// `[at α = 1, at α = 0]`, mixed by `(1 − α)²` (public for the OpenGL shader, which follows
/// [`sheen_lambda`]).
pub const LAMBDA_FIT: [[f32; 2]; 5] = [
    [21.5473, 25.3245],
    [3.82987, 3.32435],
    [0.19823, 0.16801],
    [-1.97760, -1.27393],
    [-4.32054, -4.85967],
];

/// The coefficients `(a, b, c, d, e)` of [`LAMBDA_FIT`] at `alpha`, per lane. A loop, not
/// `[T; N]::map`: LLVM may compile a closure's body out of line, without the kernel's
/// instruction set, and then each lane operation in it is a call.
#[inline(always)]
fn lambda_fit<L: Lanes>(lanes: L, alpha: L::F32) -> [L::F32; 5] {
    let one_minus = lanes.splat_f32(1.0) - alpha;
    let t = one_minus * one_minus;
    let mut fit = [t; 5];
    for (value, [at_one, at_zero]) in fit.iter_mut().zip(LAMBDA_FIT) {
        *value = lanes.splat_f32(at_one) + (lanes.splat_f32(at_zero) - lanes.splat_f32(at_one)) * t;
    }
    fit
}

/// The exponent of the fit, `a / (1 + b x^c) + d x + e`, for `x` in [0, 1] (`x^c` as
/// `2^(c log2 x)`, `x` no smaller than the least normal `f32`).
#[inline(always)]
fn lambda_exponent<L: Lanes>(lanes: L, fit: &[L::F32; 5], x: L::F32) -> L::F32 {
    let [a, b, c, d, e] = *fit;
    let one = lanes.splat_f32(1.0);
    let x = x.max(lanes.splat_f32(f32::MIN_POSITIVE));
    let power = exp2_nonpositive(lanes, c * log2_positive(lanes, x));
    a / (one + b * power) + d * x + e
}

/// The sheen's `Λ(cos θ)` for `cos θ` in [0, 1]: `exp(L(cos θ))` below ½,
/// `exp(2 L(½) − L(1 − cos θ))` from there, `L` the fit's exponent (`lambda_exponent`) and
/// `twice_at_half = 2 L(½)`. One evaluation of `L`, at `cos θ` or `1 − cos θ`.
#[inline(always)]
pub fn sheen_lambda<L: Lanes>(
    lanes: L,
    fit: &[L::F32; 5],
    twice_at_half: L::F32,
    cos_theta: L::F32,
) -> L::F32 {
    let below_half = cos_theta.simd_lt(lanes.splat_f32(0.5));
    let x = below_half.select_f32(cos_theta, lanes.splat_f32(1.0) - cos_theta);
    let l = lambda_exponent(lanes, fit, x);
    let exponent = below_half.select_f32(l, twice_at_half - l);
    exp2(lanes, exponent * lanes.splat_f32(std::f32::consts::LOG2_E))
}

/// The sheen's visibility `1 / ((1 + Λ(NdotV) + Λ(NdotL)) 4 NdotV NdotL)`, at most 1, for
/// `NdotL`, `NdotV` in [0, 1] and `lambda_view = Λ(NdotV)`.
#[inline(always)]
pub fn charlie_v<L: Lanes>(
    lanes: L,
    terms: &SheenTerms<L>,
    n_dot_l: L::F32,
    n_dot_v: L::F32,
) -> L::F32 {
    let one = lanes.splat_f32(1.0);
    let lambda_light = sheen_lambda(lanes, &terms.fit, terms.twice_at_half, n_dot_l);
    let denominator =
        (one + terms.lambda_view + lambda_light) * lanes.splat_f32(4.0) * n_dot_v * n_dot_l;
    // 1 / 0 is infinite, and clamps to 1.
    (one / denominator).min(one)
}

/// Estevez and Kulla's "Charlie" distribution, `(2 + 1/α) (1 − NdotH²)^exponent / (2π)` with
/// `exponent = 1 / (2α)`, per lane (the power as `2^(exponent × log2(…))`, built of plain lane
/// operations).
#[inline(always)]
pub fn charlie_d<L: Lanes>(lanes: L, alpha: L::F32, exponent: L::F32, n_dot_h: L::F32) -> L::F32 {
    let one = lanes.splat_f32(1.0);
    let sin2 = (one - n_dot_h * n_dot_h).max(lanes.splat_f32(f32::MIN_POSITIVE));
    let power = exp2_nonpositive(lanes, exponent * log2_positive(lanes, sin2));
    (lanes.splat_f32(2.0) + one / alpha) * power * lanes.splat_f32(0.5 / std::f32::consts::PI)
}

/// `log2(x)` per lane for positive normal `x` (relative error near 1e-7): the exponent from
/// the bits, and `2 atanh(t) / ln 2` with `t = (m − 1) / (m + 1)` for the mantissa `m` in
/// [√½, √2), five terms of its series (|t| ≤ 0.172).
#[inline(always)]
pub fn log2_positive<L: Lanes>(lanes: L, x: L::F32) -> L::F32 {
    let bits = x.to_bits();
    let exponent = bits.shr_logical::<23>() - lanes.splat_i32(127);
    let mantissa =
        L::F32::from_bits((bits & lanes.splat_i32(0x007f_ffff)) | lanes.splat_i32(0x3f80_0000));
    let one = lanes.splat_f32(1.0);
    let high = mantissa.simd_gt(lanes.splat_f32(std::f32::consts::SQRT_2));
    let m = high.select_f32(mantissa * lanes.splat_f32(0.5), mantissa);
    let e = exponent.to_f32() + high.select_f32(one, lanes.splat_f32(0.0));
    let t = (m - one) / (m + one);
    let t2 = t * t;
    let mut series = lanes.splat_f32(1.0 / 9.0);
    for c in [1.0 / 7.0, 1.0 / 5.0, 1.0 / 3.0, 1.0] {
        series = series * t2 + lanes.splat_f32(c);
    }
    e + t * series * lanes.splat_f32(2.0 * std::f32::consts::LOG2_E)
}

/// The sheen lobe's directional albedo, `BRDF_TABLE_SIZE²` cells: cell `(i, j)` holds
/// `E(NdotV = (i + 0.5) / size, roughness = (j + 0.5) / size)` (the roughness clamped to
/// [`MIN_PUNCTUAL_ROUGHNESS`]), integrated in `f64`; computed once per process.
pub fn sheen_table() -> &'static [f32] {
    static TABLE: OnceLock<Vec<f32>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let n = BRDF_TABLE_SIZE;
        let mut table = Vec::with_capacity(n * n);
        for j in 0..n {
            for i in 0..n {
                let n_dot_v = (i as f64 + 0.5) / n as f64;
                let roughness = (j as f64 + 0.5) / n as f64;
                table.push(sheen_albedo_integral(n_dot_v, roughness) as f32);
            }
        }
        table
    })
}

/// Steps of the integral of [`sheen_table`] in `cos θ` of the light (quadratic, denser where
/// the lobe peaks: at grazing light) and in its azimuth over a half circle.
const COSINE_STEPS: usize = 192;
const AZIMUTH_STEPS: usize = 48;

/// `∫ D V NdotL dω` over the hemisphere of lights, by the midpoint rule in `u` with
/// `cos θ = u²` and in the azimuth (the lobe is symmetric about the plane of N and V).
pub(super) fn sheen_albedo_integral(n_dot_v: f64, roughness: f64) -> f64 {
    let roughness = roughness.clamp(f64::from(MIN_PUNCTUAL_ROUGHNESS), 1.0);
    let alpha = roughness * roughness;
    let v = [(1.0 - n_dot_v * n_dot_v).max(0.0).sqrt(), 0.0, n_dot_v];
    let du = 1.0 / COSINE_STEPS as f64;
    let dphi = PI64 / AZIMUTH_STEPS as f64;
    let mut sum = 0.0;
    for a in 0..COSINE_STEPS {
        let u = (a as f64 + 0.5) * du;
        let n_dot_l = u * u;
        let sin_l = (1.0 - n_dot_l * n_dot_l).max(0.0).sqrt();
        let visibility = charlie_v_f64(alpha, n_dot_l, n_dot_v);
        for b in 0..AZIMUTH_STEPS {
            let phi = (b as f64 + 0.5) * dphi;
            let l = [sin_l * phi.cos(), sin_l * phi.sin(), n_dot_l];
            let h = [v[0] + l[0], v[1] + l[1], v[2] + l[2]];
            let length2 = h[0] * h[0] + h[1] * h[1] + h[2] * h[2];
            let sin2 = 1.0 - h[2] * h[2] / length2;
            sum += charlie_d_f64(alpha, sin2) * visibility * n_dot_l * 2.0 * u;
        }
    }
    // × 2: the other half circle; d(cos θ) = 2u du.
    sum * du * dphi * 2.0
}

/// [`charlie_v`] in `f64`.
pub(super) fn charlie_v_f64(alpha: f64, n_dot_l: f64, n_dot_v: f64) -> f64 {
    let t = (1.0 - alpha) * (1.0 - alpha);
    let [a, b, c, d, e] =
        LAMBDA_FIT.map(|[one, zero]| f64::from(one) + (f64::from(zero) - f64::from(one)) * t);
    let exponent = |x: f64| a / (1.0 + b * x.powf(c)) + d * x + e;
    let lambda = |cos: f64| {
        if cos < 0.5 {
            exponent(cos).exp()
        } else {
            (2.0 * exponent(0.5) - exponent(1.0 - cos)).exp()
        }
    };
    (1.0 / ((1.0 + lambda(n_dot_v) + lambda(n_dot_l)) * 4.0 * n_dot_v * n_dot_l)).min(1.0)
}

/// [`charlie_d`] in `f64`, of `sin²θ_h`.
pub(super) fn charlie_d_f64(alpha: f64, sin2: f64) -> f64 {
    (2.0 + 1.0 / alpha) * sin2.max(0.0).powf(0.5 / alpha) / (2.0 * PI64)
}

/// [`sheen_table`] as `f32` bits, each cell a pair `(E, 0)`, then one cell of zeros: the
/// layout of the split-sum table, read by the same lookup.
fn sheen_table_bits() -> &'static [u32] {
    static BITS: OnceLock<Vec<u32>> = OnceLock::new();
    BITS.get_or_init(|| {
        sheen_table()
            .iter()
            .chain([&0.0])
            .flat_map(|&e| [e.to_bits(), 0])
            .collect()
    })
}

/// `E(NdotV, roughness)` per lane, read bilinearly from [`sheen_table`] (clamped to its cell
/// centres, as the split-sum table).
#[inline(always)]
pub fn sheen_albedo_lanes<L: Lanes>(lanes: L, n_dot_v: L::F32, roughness: L::F32) -> L::F32 {
    pair_table_lanes(lanes, sheen_table_bits(), n_dot_v, roughness)[0]
}

/// [`sheen_albedo_lanes`] for one point.
pub fn sheen_albedo(n_dot_v: f32, roughness: f32) -> f32 {
    let lanes = Scalar;
    sheen_albedo_lanes(lanes, lanes.splat_f32(n_dot_v), lanes.splat_f32(roughness)).extract(0)
}

#[cfg(test)]
#[path = "sheen_tests.rs"]
mod tests;
