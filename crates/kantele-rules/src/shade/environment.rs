//! Image-based light: an environment (an equirectangular HDR image, or the built-in studio)
//! prepared once into what the shading reads per pixel — diffuse irradiance as nine spherical
//! harmonics, specular radiance pre-filtered for six roughnesses into octahedral maps, and the
//! split-sum BRDF table — and the lookups into them, on the CPU for every backend (the OpenGL
//! backend uploads the same arrays and reads them with the same arithmetic).
//!
//! Directions are world space. An octahedral map stores direction `d` at
//! `p = (d.x, d.y) / (|d.x| + |d.y| + |d.z|)`, folded over the diagonals where `d.z < 0`,
//! `uv = p / 2 + 1/2`; each level keeps a one-texel border copied from across its edges, so
//! bilinear reads need no wrapping.

use std::f32::consts::PI;
use std::sync::{Arc, OnceLock};

use glam::{Vec2, Vec3};
use kantele_lanes::{F32x8, I32x8, Lanes, Mask8, Scalar, TexelGather};

use crate::error::RenderError;

/// Roughness of each pre-filtered specular level: level `k` holds roughness `k / (LEVELS − 1)`.
pub const SPECULAR_LEVELS: usize = 6;

/// Size (without border) of each specular level.
pub const LEVEL_SIZES: [u32; SPECULAR_LEVELS] = [128, 64, 32, 32, 16, 16];

/// Size of the split-sum BRDF table (`NdotV` × roughness).
pub const BRDF_TABLE_SIZE: usize = 32;

/// Importance samples per texel of the pre-filtered levels and per cell of the BRDF table.
const SAMPLES: u32 = 128;

/// The largest radiance an environment texel keeps (larger ones are clamped to it): far above
/// any real light (the sun's disc is about 1e9 in the units HDR images use), and small enough
/// that sums over a whole image stay finite.
pub const MAX_RADIANCE: f32 = 1e30;

/// The largest equirectangular image accepted, in pixels per side.
pub const MAX_ENVIRONMENT_SIZE: u32 = 16384;

/// One pre-filtered level: `(size + 2)²` linear RGB texels, row-major, with the border.
#[derive(Clone, Debug, PartialEq)]
pub struct OctahedralLevel {
    /// Texels per side without the border.
    pub size: u32,
    /// `(size + 2)²` texels.
    pub texels: Vec<[f32; 3]>,
}

impl OctahedralLevel {
    /// Texels per side with the border.
    pub fn stride(&self) -> u32 {
        self.size + 2
    }

    /// Bilinear read at direction `d` (unit).
    pub fn sample(&self, d: Vec3) -> Vec3 {
        let uv = octahedral_encode(d);
        let size = self.size as f32;
        // Texel centre i sits at (i + 0.5) / size; the border shifts indices by one.
        let x = (uv.x * size + 0.5).clamp(0.0, size + 1.0);
        let y = (uv.y * size + 0.5).clamp(0.0, size + 1.0);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let stride = self.stride() as usize;
        let (x0, y0) = (x0 as usize, y0 as usize);
        let (x1, y1) = ((x0 + 1).min(stride - 1), (y0 + 1).min(stride - 1));
        let t = |x: usize, y: usize| Vec3::from(self.texels[y * stride + x]);
        let top = t(x0, y0) + (t(x1, y0) - t(x0, y0)) * fx;
        let bottom = t(x0, y1) + (t(x1, y1) - t(x0, y1)) * fx;
        top + (bottom - top) * fy
    }
}

/// The octahedral coordinates in [0, 1]² of the unit direction `d`.
pub fn octahedral_encode(d: Vec3) -> Vec2 {
    let sum = d.x.abs() + d.y.abs() + d.z.abs();
    let mut p = if sum > 0.0 {
        Vec2::new(d.x / sum, d.y / sum)
    } else {
        Vec2::ZERO
    };
    if d.z < 0.0 {
        let sign = |v: f32| if v >= 0.0 { 1.0 } else { -1.0 };
        p = Vec2::new((1.0 - p.y.abs()) * sign(p.x), (1.0 - p.x.abs()) * sign(p.y));
    }
    p * 0.5 + 0.5
}

/// The unit direction at octahedral coordinates `uv` in [0, 1]².
pub fn octahedral_decode(uv: Vec2) -> Vec3 {
    let p = uv * 2.0 - 1.0;
    let z = 1.0 - p.x.abs() - p.y.abs();
    let (x, y) = if z < 0.0 {
        let sign = |v: f32| if v >= 0.0 { 1.0 } else { -1.0 };
        ((1.0 - p.y.abs()) * sign(p.x), (1.0 - p.x.abs()) * sign(p.y))
    } else {
        (p.x, p.y)
    };
    Vec3::new(x, y, z).normalize_or_zero()
}

/// An environment prepared for shading (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    /// Irradiance ÷ π as nine spherical-harmonic coefficients (bands 0–2), each RGB, with the
    /// cosine lobe's convolution constants folded in: `E(n)/π = Σ sh[i] × Y_i(n)`.
    pub irradiance_sh: [Vec3; 9],
    /// Pre-filtered specular radiance, level `k` for roughness `k / (SPECULAR_LEVELS − 1)`.
    pub levels: Vec<OctahedralLevel>,
    /// The source's size `(width, height)`, for reports.
    pub source_size: (u32, u32),
    /// The texels of every level, one after another (level `k` from `LEVEL_OFFSETS[k]`), as
    /// `f32` bits, four words a texel (RGB and a 0), then one texel of zeros: what the lane
    /// lookups read. A bilinear row's two texels are eight neighbouring words, two 16-byte
    /// reads per lane ([`TexelGather::gather_u32_quad`]); the texel after the last lets a read
    /// at the last column (whose right texel has weight 0) stay inside the table.
    texel_bits: Vec<u32>,
}

/// An environment as a frame uses it: the prepared maps, their intensity and rotation.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentLight {
    /// The prepared environment.
    pub environment: Arc<Environment>,
    /// Multiplies all its light.
    pub intensity: f32,
    /// Rotation about world +Y in radians (positive turns the environment counter-clockwise
    /// seen from above).
    pub rotation: f32,
}

impl EnvironmentLight {
    /// The built-in studio at intensity 1, unrotated.
    pub fn studio() -> Self {
        Self {
            environment: Environment::studio(),
            intensity: 1.0,
            rotation: 0.0,
        }
    }

    /// `(sin, cos)` of the rotation applied to a world direction before a lookup (the inverse
    /// of the environment's rotation).
    #[inline]
    pub fn lookup_rotation(&self) -> (f32, f32) {
        (-self.rotation).sin_cos()
    }

    /// Irradiance ÷ π at unit normals `n`, per lane (intensity not applied).
    #[inline(always)]
    pub fn irradiance_lanes<L: Lanes>(&self, lanes: L, n: &[L::F32; 3]) -> [L::F32; 3] {
        let (sin, cos) = self.lookup_rotation();
        let (s, c) = (lanes.splat_f32(sin), lanes.splat_f32(cos));
        let x = c * n[0] + s * n[2];
        let y = n[1];
        let z = c * n[2] - s * n[0];
        let basis = [
            lanes.splat_f32(SH_Y0),
            lanes.splat_f32(SH_Y1) * y,
            lanes.splat_f32(SH_Y1) * z,
            lanes.splat_f32(SH_Y1) * x,
            lanes.splat_f32(SH_Y2) * x * y,
            lanes.splat_f32(SH_Y2) * y * z,
            lanes.splat_f32(SH_Y20) * (lanes.splat_f32(3.0) * z * z - lanes.splat_f32(1.0)),
            lanes.splat_f32(SH_Y2) * x * z,
            lanes.splat_f32(SH_Y22) * (x * x - y * y),
        ];
        let sh = &self.environment.irradiance_sh;
        let mut out = [lanes.splat_f32(0.0); 3];
        for (coefficient, b) in sh.iter().zip(basis) {
            out[0] = out[0] + lanes.splat_f32(coefficient.x) * b;
            out[1] = out[1] + lanes.splat_f32(coefficient.y) * b;
            out[2] = out[2] + lanes.splat_f32(coefficient.z) * b;
        }
        let zero = lanes.splat_f32(0.0);
        [out[0].max(zero), out[1].max(zero), out[2].max(zero)]
    }

    /// Pre-filtered specular radiance along `r` (need not be unit) at `roughness`, per lane:
    /// bilinear in the two levels around `roughness × (SPECULAR_LEVELS − 1)`, linear between
    /// them (intensity not applied). Every lane reads its own levels, by gathers from the
    /// environment's texels (all levels in one table of `f32` bits).
    #[inline(always)]
    pub fn specular_lanes<L: Lanes>(
        &self,
        lanes: L,
        r: &[L::F32; 3],
        roughness: L::F32,
    ) -> [L::F32; 3] {
        let (sin, cos) = self.lookup_rotation();
        let (s, c) = (lanes.splat_f32(sin), lanes.splat_f32(cos));
        let rotated = [c * r[0] + s * r[2], r[1], c * r[2] - s * r[0]];
        let d = normalize_or_zero_lanes(lanes, rotated);
        let uv = octahedral_encode_lanes(lanes, &d);
        let last = lanes.splat_f32((SPECULAR_LEVELS - 1) as f32);
        let zero = lanes.splat_f32(0.0);
        let finite = roughness.abs().simd_lt(lanes.splat_f32(f32::INFINITY));
        let lod = finite.select_f32((roughness * last).max(zero).min(last), last);
        let level = lod.floor();
        let t = lod - level;
        let lo_level = level.to_i32_trunc();
        let hi_level =
            (lo_level + lanes.splat_i32(1)).min(lanes.splat_i32(SPECULAR_LEVELS as i32 - 1));
        let table = &self.environment.texel_bits;
        let lo = sample_level_lanes(lanes, table, lo_level, &uv);
        let hi = sample_level_lanes(lanes, table, hi_level, &uv);
        let exact = t.simd_eq(zero);
        [
            exact.select_f32(lo[0], lo[0] + (hi[0] - lo[0]) * t),
            exact.select_f32(lo[1], lo[1] + (hi[1] - lo[1]) * t),
            exact.select_f32(lo[2], lo[2] + (hi[2] - lo[2]) * t),
        ]
    }

    /// [`EnvironmentLight::specular_lanes`] for one direction.
    pub fn specular(&self, r: Vec3, roughness: f32) -> Vec3 {
        let lanes = Scalar;
        let r = r.to_array().map(|c| lanes.splat_f32(c));
        let out = self.specular_lanes(lanes, &r, lanes.splat_f32(roughness));
        Vec3::new(out[0].extract(0), out[1].extract(0), out[2].extract(0))
    }

    /// The split-sum terms `(A, B)` at `NdotV` and `roughness`, per lane ([`brdf_ab_lanes`]).
    #[inline(always)]
    pub fn brdf_lanes<L: Lanes>(
        &self,
        lanes: L,
        n_dot_v: L::F32,
        roughness: L::F32,
    ) -> [L::F32; 2] {
        brdf_ab_lanes(lanes, n_dot_v, roughness)
    }
}

/// The split-sum terms `(A, B)` at `NdotV` and `roughness`, per lane: read bilinearly from
/// [`brdf_table`], clamped to its cell centres (a non-finite coordinate reads as 1).
///
/// Each row's two cells are read together, the right one always at the next column: the
/// clamped right column differs from it only at the last column, where the coordinate is that
/// cell's centre and the right cell's weight is 0 (every cell is finite).
#[inline(always)]
pub fn brdf_ab_lanes<L: Lanes>(lanes: L, n_dot_v: L::F32, roughness: L::F32) -> [L::F32; 2] {
    let zero = lanes.splat_f32(0.0);
    let (x, y) = (
        brdf_coordinate(lanes, n_dot_v),
        brdf_coordinate(lanes, roughness),
    );
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (x0, y0) = (x0.to_i32_trunc(), y0.to_i32_trunc());
    let last = lanes.splat_i32(BRDF_TABLE_SIZE as i32 - 1);
    let y1 = (y0 + lanes.splat_i32(1)).min(last);
    let size = lanes.splat_i32(BRDF_TABLE_SIZE as i32);
    let table = brdf_table_bits();
    // Cell (x, y) holds A at 2 (y size + x) and B after it: [A, B, A, B] of a row's two cells.
    let top = (y0 * size + x0).shl::<1>().gather_u32_quad(table);
    let bottom = (y1 * size + x0).shl::<1>().gather_u32_quad(table);
    let mut out = [zero; 2];
    for (c, o) in out.iter_mut().enumerate() {
        let t = [
            L::F32::from_bits(top[c]),
            L::F32::from_bits(top[2 + c]),
            L::F32::from_bits(bottom[c]),
            L::F32::from_bits(bottom[2 + c]),
        ];
        let top = t[0] + (t[1] - t[0]) * fx;
        let bottom = t[2] + (t[3] - t[2]) * fx;
        *o = top + (bottom - top) * fy;
    }
    out
}

/// A split-sum table coordinate in cells, per lane: `v × size − ½` clamped to the cell centres
/// `[0, size − 1]` (a non-finite `v` reads as 1). A function, not a closure: LLVM may compile
/// a closure's body out of line, without the kernel's instruction set, and then each lane
/// operation in it is a call.
#[inline(always)]
fn brdf_coordinate<L: Lanes>(lanes: L, v: L::F32) -> L::F32 {
    let n = BRDF_TABLE_SIZE as f32;
    let v = v
        .abs()
        .simd_lt(lanes.splat_f32(f32::INFINITY))
        .select_f32(v, lanes.splat_f32(1.0));
    (v * lanes.splat_f32(n) - lanes.splat_f32(0.5))
        .max(lanes.splat_f32(0.0))
        .min(lanes.splat_f32(n - 1.0))
}

/// `v / |v|` per lane, or 0 where that is not finite or not positive (glam's
/// `normalize_or_zero`, operation for operation).
#[inline(always)]
fn normalize_or_zero_lanes<L: Lanes>(lanes: L, v: [L::F32; 3]) -> [L::F32; 3] {
    let length = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let rcp = lanes.splat_f32(1.0) / length;
    let zero = lanes.splat_f32(0.0);
    let usable = rcp
        .abs()
        .simd_lt(lanes.splat_f32(f32::INFINITY))
        .and(rcp.simd_gt(zero));
    [
        usable.select_f32(v[0] * rcp, zero),
        usable.select_f32(v[1] * rcp, zero),
        usable.select_f32(v[2] * rcp, zero),
    ]
}

/// [`octahedral_encode`] per lane, operation for operation.
#[inline(always)]
fn octahedral_encode_lanes<L: Lanes>(lanes: L, d: &[L::F32; 3]) -> [L::F32; 2] {
    let (zero, one, half) = (
        lanes.splat_f32(0.0),
        lanes.splat_f32(1.0),
        lanes.splat_f32(0.5),
    );
    let sum = d[0].abs() + d[1].abs() + d[2].abs();
    let positive = sum.simd_gt(zero);
    let px = positive.select_f32(d[0] / sum, zero);
    let py = positive.select_f32(d[1] / sum, zero);
    let (sign_x, sign_y) = (
        px.simd_ge(zero).select_f32(one, -one),
        py.simd_ge(zero).select_f32(one, -one),
    );
    let below = d[2].simd_lt(zero);
    let fx = below.select_f32((one - py.abs()) * sign_x, px);
    let fy = below.select_f32((one - px.abs()) * sign_y, py);
    [fx * half + half, fy * half + half]
}

/// [`OctahedralLevel::sample`] per lane, each lane in its own `level`, from `table`
/// ([`Environment::texel_bits`]) at octahedral coordinates `uv`.
///
/// Each row's two texels are read together, the right one always at the next column: the
/// clamped right column of the scalar lookup differs from it only at the last column, where
/// the coordinate is clamped to that column's centre and the right texel's weight is 0, so the
/// blend gives the left texel there too (every texel is finite).
#[inline(always)]
fn sample_level_lanes<L: Lanes>(
    lanes: L,
    table: &[u32],
    level: L::I32,
    uv: &[L::F32; 2],
) -> [L::F32; 3] {
    let zero = lanes.splat_f32(0.0);
    let size_i = level_entry::<L>(lanes, &LANE_LEVEL_SIZES, level);
    let size = size_i.to_f32();
    let stride = size_i + lanes.splat_i32(2);
    let first = level_entry::<L>(lanes, &LANE_LEVEL_OFFSETS, level);
    let half = lanes.splat_f32(0.5);
    let limit = size + lanes.splat_f32(1.0);
    // Texel centre i sits at (i + 0.5) / size; the border shifts indices by one.
    let x = (uv[0] * size + half).max(zero).min(limit);
    let y = (uv[1] * size + half).max(zero).min(limit);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (x0, y0) = (x0.to_i32_trunc(), y0.to_i32_trunc());
    let edge = stride - lanes.splat_i32(1);
    let y1 = (y0 + lanes.splat_i32(1)).min(edge);
    // Word index of a row's left texel; its right texel follows four words on.
    let top = (first + y0 * stride + x0).shl::<2>();
    let bottom = (first + y1 * stride + x0).shl::<2>();
    let right = lanes.splat_i32(4);
    let [top_left, top_right, bottom_left, bottom_right] = [
        top.gather_u32_quad(table),
        (top + right).gather_u32_quad(table),
        bottom.gather_u32_quad(table),
        (bottom + right).gather_u32_quad(table),
    ];
    let mut out = [zero; 3];
    for (c, o) in out.iter_mut().enumerate() {
        let t = [
            L::F32::from_bits(top_left[c]),
            L::F32::from_bits(top_right[c]),
            L::F32::from_bits(bottom_left[c]),
            L::F32::from_bits(bottom_right[c]),
        ];
        let top = t[0] + (t[1] - t[0]) * fx;
        let bottom = t[2] + (t[3] - t[2]) * fx;
        *o = top + (bottom - top) * fy;
    }
    out
}

/// Lane `k`: `table[level[k]]`, for levels in `0..SPECULAR_LEVELS` (one permute, no gather).
#[inline(always)]
fn level_entry<L: Lanes>(lanes: L, table: &[i32; 8], level: L::I32) -> L::I32 {
    L::F32::from_bits(lanes.load_i32(table))
        .permute(level)
        .to_bits()
}

/// [`LEVEL_SIZES`] as eight lanes, for [`level_entry`].
const LANE_LEVEL_SIZES: [i32; 8] = lane_table(LEVEL_SIZES);

/// [`LEVEL_OFFSETS`] as eight lanes, for [`level_entry`].
const LANE_LEVEL_OFFSETS: [i32; 8] = lane_table(LEVEL_OFFSETS);

const fn lane_table(values: [u32; SPECULAR_LEVELS]) -> [i32; 8] {
    let mut out = [0; 8];
    let mut k = 0;
    while k < SPECULAR_LEVELS {
        out[k] = values[k] as i32;
        k += 1;
    }
    out
}

/// Where each specular level's texels start in [`Environment::texel_bits`], in texels.
const LEVEL_OFFSETS: [u32; SPECULAR_LEVELS] = {
    let mut offsets = [0; SPECULAR_LEVELS];
    let mut k = 1;
    while k < SPECULAR_LEVELS {
        let stride = LEVEL_SIZES[k - 1] + 2;
        offsets[k] = offsets[k - 1] + stride * stride;
        k += 1;
    }
    offsets
};

/// Real spherical harmonic of band 0: `Y0 = 1 / (2 √π)`.
pub const SH_Y0: f32 = 0.282_094_8;
/// Band 1: `Y = SH_Y1 × (y, z, x)`.
pub const SH_Y1: f32 = 0.488_602_5;
/// Band 2: `SH_Y2 × (xy, yz, xz)`.
pub const SH_Y2: f32 = 1.092_548_4;
/// Band 2: `SH_Y20 × (3z² − 1)`.
pub const SH_Y20: f32 = 0.315_391_57;
/// Band 2: `SH_Y22 × (x² − y²)`.
pub const SH_Y22: f32 = 0.546_274_2;
// The cosine lobe's band factors (π, 2π/3, π/4), divided by π so the sum gives irradiance ÷ π.
const SH_BAND: [f32; 3] = [1.0, 2.0 / 3.0, 0.25];

fn sh_basis(d: Vec3) -> [f32; 9] {
    let (x, y, z) = (d.x, d.y, d.z);
    [
        SH_Y0,
        SH_Y1 * y,
        SH_Y1 * z,
        SH_Y1 * x,
        SH_Y2 * x * y,
        SH_Y2 * y * z,
        SH_Y20 * (3.0 * z * z - 1.0),
        SH_Y2 * x * z,
        SH_Y22 * (x * x - y * y),
    ]
}

const SH_BAND_OF: [usize; 9] = [0, 1, 1, 1, 2, 2, 2, 2, 2];

/// The split-sum table, `BRDF_TABLE_SIZE²` cells of `(A, B)`: cell `(i, j)` at `NdotV = (i +
/// 0.5) / size`, roughness `(j + 0.5) / size`, computed once per process.
pub fn brdf_table() -> &'static [[f32; 2]] {
    static TABLE: OnceLock<Vec<[f32; 2]>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let n = BRDF_TABLE_SIZE;
        let mut table = Vec::with_capacity(n * n);
        for j in 0..n {
            for i in 0..n {
                let n_dot_v = (i as f32 + 0.5) / n as f32;
                let roughness = (j as f32 + 0.5) / n as f32;
                table.push(integrate_brdf(n_dot_v, roughness));
            }
        }
        table
    })
}

/// [`brdf_table`] as `f32` bits, `(A, B)` interleaved, then one cell of zeros: a bilinear
/// row's two cells are four neighbouring words, one 16-byte read per lane
/// ([`TexelGather::gather_u32_quad`]), and the extra cell keeps a read at the last cell inside
/// the table.
fn brdf_table_bits() -> &'static [u32] {
    static BITS: OnceLock<Vec<u32>> = OnceLock::new();
    BITS.get_or_init(|| {
        brdf_table()
            .iter()
            .chain([&[0.0; 2]])
            .flat_map(|ab| ab.map(f32::to_bits))
            .collect()
    })
}

/// `(A, B)` read bilinearly from [`brdf_table`] (clamped to its cell centres):
/// [`brdf_ab_lanes`] for one point.
pub fn brdf_ab(n_dot_v: f32, roughness: f32) -> [f32; 2] {
    let lanes = Scalar;
    let [a, b] = brdf_ab_lanes(lanes, lanes.splat_f32(n_dot_v), lanes.splat_f32(roughness));
    [a.extract(0), b.extract(0)]
}

/// The `i`-th of `n` points of the Hammersley set.
fn hammersley(i: u32, n: u32) -> Vec2 {
    Vec2::new(
        i as f32 / n as f32,
        i.reverse_bits() as f32 * (1.0 / 4_294_967_296.0),
    )
}

/// A half vector around +Z drawn from the GGX distribution of `alpha` at `xi`.
fn ggx_half_vector(xi: Vec2, alpha: f32) -> Vec3 {
    let phi = 2.0 * PI * xi.x;
    let cos_theta = ((1.0 - xi.y) / (1.0 + (alpha * alpha - 1.0) * xi.y))
        .max(0.0)
        .sqrt();
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta)
}

/// The split-sum integral of the GGX BRDF with Smith height-correlated visibility (the same
/// `V` as the punctual lights): `∫ f cosθ = F0 × A + B`.
fn integrate_brdf(n_dot_v: f32, roughness: f32) -> [f32; 2] {
    let alpha = roughness * roughness;
    let v = Vec3::new((1.0 - n_dot_v * n_dot_v).max(0.0).sqrt(), 0.0, n_dot_v);
    let (mut a, mut b) = (0.0f64, 0.0f64);
    let a2 = alpha * alpha;
    for i in 0..SAMPLES {
        let h = ggx_half_vector(hammersley(i, SAMPLES), alpha);
        let l = 2.0 * v.dot(h) * h - v;
        let n_dot_l = l.z;
        if n_dot_l <= 0.0 {
            continue;
        }
        let n_dot_h = h.z.max(0.0);
        let v_dot_h = v.dot(h).max(0.0);
        let ggx_v = n_dot_l * (n_dot_v * n_dot_v * (1.0 - a2) + a2).sqrt();
        let ggx_l = n_dot_v * (n_dot_l * n_dot_l * (1.0 - a2) + a2).sqrt();
        let vis = 0.5 / (ggx_v + ggx_l);
        // pdf(l) = D n·h / (4 v·h): f cosθ / pdf = V × 4 (v·h) n·l / n·h.
        let g = vis * 4.0 * v_dot_h * n_dot_l / n_dot_h;
        let fc = (1.0 - v_dot_h).powi(5);
        a += ((1.0 - fc) * g) as f64;
        b += (fc * g) as f64;
    }
    [(a / SAMPLES as f64) as f32, (b / SAMPLES as f64) as f32]
}

impl Environment {
    /// The built-in neutral studio: a white room lit by a soft gradient (bright above, dark
    /// floor) and four soft boxes (key at the front left, fill at the right, a rim light behind
    /// and one above), generated by code and prepared once per process.
    pub fn studio() -> Arc<Environment> {
        static STUDIO: OnceLock<Arc<Environment>> = OnceLock::new();
        STUDIO
            .get_or_init(|| {
                let (width, height) = (256u32, 128u32);
                let texels: Vec<Vec3> = (0..height)
                    .flat_map(|y| (0..width).map(move |x| (x, y)))
                    .map(|(x, y)| studio_radiance(equirect_direction(x, y, width, height)))
                    .collect();
                Arc::new(
                    Environment::from_equirect(width, height, &texels)
                        .expect("the studio is a valid environment"),
                )
            })
            .clone()
    }

    /// Prepares an equirectangular image (`width × height` linear RGB, row 0 at the top =
    /// straight up, column 0 looking along −Z, turning towards +X) for shading. Non-finite
    /// and negative texels count as 0, and texels above [`MAX_RADIANCE`] as that: no sum
    /// the preparation makes then overflows, and every prepared value is finite.
    pub fn from_equirect(width: u32, height: u32, texels: &[Vec3]) -> Result<Self, RenderError> {
        if width < 2
            || height < 1
            || width > MAX_ENVIRONMENT_SIZE
            || height > MAX_ENVIRONMENT_SIZE
            || texels.len() != width as usize * height as usize
        {
            return Err(RenderError::InvalidScene(format!(
                "an environment image must be 2..={MAX_ENVIRONMENT_SIZE} pixels wide and 1..={MAX_ENVIRONMENT_SIZE} high with one texel per pixel ({width}x{height}, {} texels)",
                texels.len()
            )));
        }
        let clean = |t: Vec3| {
            if t.is_finite() {
                t.clamp(Vec3::ZERO, Vec3::splat(MAX_RADIANCE))
            } else {
                Vec3::ZERO
            }
        };
        // Box-filter down to at most 512 × 256: the finest level has 128² texels.
        let mut source = Equirect {
            width,
            height,
            texels: texels.iter().map(|&t| clean(t)).collect(),
        };
        while source.width > 512 && source.height > 1 {
            source = source.halved();
        }
        let irradiance_sh = source.irradiance_sh();
        let finest = source.octahedral(LEVEL_SIZES[0]);
        let chain = mip_chain(&finest);
        let mut levels = vec![finest.clone()];
        for (k, &size) in LEVEL_SIZES.iter().enumerate().skip(1) {
            let roughness = k as f32 / (SPECULAR_LEVELS - 1) as f32;
            levels.push(prefilter(&chain, size, roughness));
        }
        let texel_bits = levels
            .iter()
            .flat_map(|level| level.texels.iter())
            .chain([&[0.0; 3]])
            .flat_map(|&[r, g, b]| [r, g, b, 0.0].map(f32::to_bits))
            .collect();
        Ok(Self {
            irradiance_sh,
            levels,
            source_size: (width, height),
            texel_bits,
        })
    }
}

/// The unit direction at the centre of equirect pixel `(x, y)`.
fn equirect_direction(x: u32, y: u32, width: u32, height: u32) -> Vec3 {
    let phi = (x as f32 + 0.5) / width as f32 * 2.0 * PI;
    let theta = (y as f32 + 0.5) / height as f32 * PI;
    let (sin_t, cos_t) = theta.sin_cos();
    let (sin_p, cos_p) = phi.sin_cos();
    Vec3::new(sin_t * sin_p, cos_t, -sin_t * cos_p)
}

/// The equirect coordinates in pixels of unit direction `d` (inverse of
/// [`equirect_direction`], without the half-pixel centre offset).
fn equirect_coordinates(d: Vec3, width: u32, height: u32) -> Vec2 {
    let phi = d.x.atan2(-d.z).rem_euclid(2.0 * PI);
    let theta = d.y.clamp(-1.0, 1.0).acos();
    Vec2::new(phi / (2.0 * PI) * width as f32, theta / PI * height as f32)
}

/// Radiance of the built-in studio towards `d`.
fn studio_radiance(d: Vec3) -> Vec3 {
    let smoothstep = |a: f32, b: f32, x: f32| {
        let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
        t * t * (3.0 - 2.0 * t)
    };
    // Floor 0.12, horizon 0.45, ceiling 0.7.
    let y = d.y;
    let mut value = if y >= 0.0 {
        0.45 + (0.7 - 0.45) * smoothstep(0.0, 1.0, y)
    } else {
        0.45 + (0.12 - 0.45) * smoothstep(0.0, 0.3, -y)
    };
    // (direction towards the box, angular radius in degrees, radiance)
    let boxes = [
        (Vec3::new(-0.55, 0.55, 0.63), 22.0f32, 5.0f32),
        (Vec3::new(0.85, 0.2, 0.45), 28.0, 1.6),
        (Vec3::new(0.3, 0.45, -0.84), 18.0, 4.0),
        (Vec3::new(0.0, 1.0, 0.0), 30.0, 1.5),
    ];
    for (towards, radius, radiance) in boxes {
        let cos = d.dot(towards.normalize());
        let outer = (radius.to_radians()).cos();
        let inner = ((radius * 0.8).to_radians()).cos();
        value += radiance * smoothstep(outer, inner, cos);
    }
    Vec3::splat(value)
}

/// An equirectangular image of linear RGB.
struct Equirect {
    width: u32,
    height: u32,
    texels: Vec<Vec3>,
}

impl Equirect {
    /// Half the size, each texel the mean of (up to) 2 × 2.
    fn halved(&self) -> Self {
        let (w, h) = (self.width.div_ceil(2), self.height.div_ceil(2));
        let mut texels = Vec::with_capacity((w * h) as usize);
        for y in 0..h {
            for x in 0..w {
                let mut sum = Vec3::ZERO;
                let mut count = 0.0;
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let (sx, sy) = (2 * x + dx, 2 * y + dy);
                    if sx < self.width && sy < self.height {
                        sum += self.texels[(sy * self.width + sx) as usize];
                        count += 1.0;
                    }
                }
                texels.push(sum / count);
            }
        }
        Self {
            width: w,
            height: h,
            texels,
        }
    }

    /// Bilinear read at unit direction `d` (wrapping around horizontally).
    fn sample(&self, d: Vec3) -> Vec3 {
        let p = equirect_coordinates(d, self.width, self.height) - 0.5;
        let (x0, y0) = (p.x.floor(), p.y.floor());
        let (fx, fy) = (p.x - x0, p.y - y0);
        let w = self.width as i64;
        let h = self.height as i64;
        let t = |x: i64, y: i64| {
            let x = x.rem_euclid(w);
            let y = y.clamp(0, h - 1);
            self.texels[(y * w + x) as usize]
        };
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = t(x0, y0).lerp(t(x0 + 1, y0), fx);
        let bottom = t(x0, y0 + 1).lerp(t(x0 + 1, y0 + 1), fx);
        top.lerp(bottom, fy)
    }

    /// Irradiance ÷ π as spherical harmonics (see [`Environment::irradiance_sh`]).
    fn irradiance_sh(&self) -> [Vec3; 9] {
        let mut sh = [Vec3::ZERO; 9];
        let (w, h) = (self.width, self.height);
        let pixel_area = (2.0 * PI / w as f32) * (PI / h as f32);
        for y in 0..h {
            let theta = (y as f32 + 0.5) / h as f32 * PI;
            let solid_angle = pixel_area * theta.sin();
            for x in 0..w {
                let d = equirect_direction(x, y, w, h);
                let radiance = self.texels[(y * w + x) as usize];
                for (i, b) in sh_basis(d).into_iter().enumerate() {
                    sh[i] += radiance * (b * solid_angle);
                }
            }
        }
        for (i, c) in sh.iter_mut().enumerate() {
            *c *= SH_BAND[SH_BAND_OF[i]];
        }
        sh
    }

    /// The finest octahedral level: each texel the mean of 2 × 2 reads inside it.
    fn octahedral(&self, size: u32) -> OctahedralLevel {
        let inner: Vec<Vec3> = (0..size * size)
            .map(|i| {
                let (x, y) = (i % size, i / size);
                let mut sum = Vec3::ZERO;
                for (sx, sy) in [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)] {
                    let uv =
                        Vec2::new((x as f32 + sx) / size as f32, (y as f32 + sy) / size as f32);
                    sum += self.sample(octahedral_decode(uv));
                }
                sum * 0.25
            })
            .collect();
        with_border(size, &inner)
    }
}

/// An octahedral level from its `size²` inner texels, adding the border: the texel across an
/// edge of the map is its mirror image along that edge.
fn with_border(size: u32, inner: &[Vec3]) -> OctahedralLevel {
    let s = size as i64;
    let stride = (size + 2) as usize;
    let mut texels = vec![[0.0; 3]; stride * stride];
    for y in -1..=s {
        for x in -1..=s {
            let (mut sx, mut sy) = (x, y);
            if sx < 0 || sx >= s {
                sx = sx.clamp(0, s - 1);
                sy = s - 1 - sy;
            }
            if sy < 0 || sy >= s {
                sy = sy.clamp(0, s - 1);
                sx = s - 1 - sx;
            }
            let t = inner[(sy.clamp(0, s - 1) * s + sx.clamp(0, s - 1)) as usize];
            texels[(y + 1) as usize * stride + (x + 1) as usize] = t.to_array();
        }
    }
    OctahedralLevel { size, texels }
}

/// The inner texels of a level.
fn inner_texels(level: &OctahedralLevel) -> Vec<Vec3> {
    let stride = level.stride() as usize;
    let s = level.size as usize;
    (0..s * s)
        .map(|i| Vec3::from(level.texels[(i / s + 1) * stride + i % s + 1]))
        .collect()
}

/// The finest level and its 2 × 2 box-filtered halvings down to 1 × 1.
fn mip_chain(finest: &OctahedralLevel) -> Vec<OctahedralLevel> {
    let mut chain = vec![finest.clone()];
    while chain.last().is_some_and(|l| l.size > 1) {
        let last = chain.last().expect("non-empty");
        let inner = inner_texels(last);
        let (s, half) = (last.size as usize, (last.size / 2) as usize);
        let halved: Vec<Vec3> = (0..half * half)
            .map(|i| {
                let (x, y) = (2 * (i % half), 2 * (i / half));
                (inner[y * s + x]
                    + inner[y * s + x + 1]
                    + inner[(y + 1) * s + x]
                    + inner[(y + 1) * s + x + 1])
                    * 0.25
            })
            .collect();
        chain.push(with_border(half as u32, &halved));
    }
    chain
}

/// A specular level of `size²` texels for `roughness`: the radiance of the chain convolved with
/// the GGX lobe around each texel's direction (`N = V = R`), by importance sampling, each sample
/// read at the level of detail of its solid angle (filtered importance sampling).
fn prefilter(chain: &[OctahedralLevel], size: u32, roughness: f32) -> OctahedralLevel {
    let alpha = roughness * roughness;
    let finest = chain[0].size as f32;
    let texel_solid_angle = 4.0 * PI / (finest * finest);
    let samples: Vec<(Vec3, f32)> = (0..SAMPLES)
        .filter_map(|i| {
            let h = ggx_half_vector(hammersley(i, SAMPLES), alpha);
            // With N = V = +Z: L = 2 (V·H) H − V.
            let l = 2.0 * h.z * h - Vec3::Z;
            if l.z <= 0.0 {
                return None;
            }
            let a2 = alpha * alpha;
            let f = h.z * h.z * (a2 - 1.0) + 1.0;
            let d = a2 / (PI * f * f);
            // pdf(l) = D n·h / (4 v·h) = D / 4 here.
            let pdf = (d / 4.0).max(1e-8);
            let sample_solid_angle = 1.0 / (SAMPLES as f32 * pdf);
            let lod = (0.5 * (sample_solid_angle / texel_solid_angle).log2() + 1.0).max(0.0);
            Some((l, lod))
        })
        .collect();
    let read = |d: Vec3, lod: f32| {
        let last = (chain.len() - 1) as f32;
        let lod = lod.min(last);
        let lo = lod.floor();
        let t = lod - lo;
        let a = chain[lo as usize].sample(d);
        if t == 0.0 {
            return a;
        }
        a.lerp(chain[(lo as usize + 1).min(chain.len() - 1)].sample(d), t)
    };
    let inner: Vec<Vec3> = (0..size * size)
        .map(|i| {
            let (x, y) = (i % size, i / size);
            let uv = Vec2::new(
                (x as f32 + 0.5) / size as f32,
                (y as f32 + 0.5) / size as f32,
            );
            let n = octahedral_decode(uv);
            // A frame around n.
            let up = if n.z.abs() < 0.999 { Vec3::Z } else { Vec3::X };
            let tangent = up.cross(n).normalize();
            let bitangent = n.cross(tangent);
            let mut sum = Vec3::ZERO;
            let mut weight = 0.0;
            for &(l, lod) in &samples {
                let d = tangent * l.x + bitangent * l.y + n * l.z;
                sum += read(d, lod) * l.z;
                weight += l.z;
            }
            if weight > 0.0 {
                sum / weight
            } else {
                read(n, 0.0)
            }
        })
        .collect();
    with_border(size, &inner)
}

#[cfg(test)]
#[path = "environment_tests.rs"]
mod tests;
