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
//!
//! This module holds what is prepared and the lookups, per lane and per point; the preparation
//! itself (filtering, the harmonics, the split-sum integral, the studio) is in
//! `environment_prepare.rs`.

use std::sync::{Arc, OnceLock};

use glam::{Vec2, Vec3};
use kantele_lanes::{F32x8, I32x8, Lanes, Mask8, Scalar, TexelGather};

use super::levels::{bilinear_rgb, lane_table, lookup16, LaneTable};

#[path = "environment_prepare.rs"]
mod prepare;
pub use prepare::brdf_table;

/// Roughness of each pre-filtered specular level: level `k` holds roughness `k / (LEVELS − 1)`.
pub const SPECULAR_LEVELS: usize = 6;

/// Size (without border) of each specular level.
pub const LEVEL_SIZES: [u32; SPECULAR_LEVELS] = [128, 64, 32, 32, 16, 16];

/// Size of the split-sum BRDF table (`NdotV` × roughness).
pub const BRDF_TABLE_SIZE: usize = 32;

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
    pair_table_lanes(lanes, brdf_table_bits(), n_dot_v, roughness)
}

/// Two values read bilinearly at `(n_dot_v, roughness)` from `table`, a
/// `BRDF_TABLE_SIZE²` table of pairs laid out as [`brdf_table_bits`] (cell `(x, y)`'s pair at
/// words `2 (y size + x)`, then one cell of zeros), clamped to its cell centres: the lookup of
/// [`brdf_ab_lanes`] and of the sheen's albedo table.
#[inline(always)]
pub(super) fn pair_table_lanes<L: Lanes>(
    lanes: L,
    table: &[u32],
    n_dot_v: L::F32,
    roughness: L::F32,
) -> [L::F32; 2] {
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
    let [lane_sizes, lane_offsets] = &LANE_LEVEL_TABLES;
    let size_i = lookup16::<L>(lane_sizes, level);
    let size = size_i.to_f32();
    let stride = size_i + lanes.splat_i32(2);
    let first = lookup16::<L>(lane_offsets, level);
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
    bilinear_rgb(lanes, table, top, bottom, fx, fy)
}

/// [`LEVEL_SIZES`] and [`LEVEL_OFFSETS`] as [`LaneTable`]s, the form the lane lookups read
/// per-level values in (as the texture sampler reads its mip levels').
const LANE_LEVEL_TABLES: [LaneTable; 2] = [lane_table(&LEVEL_SIZES), lane_table(&LEVEL_OFFSETS)];

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

#[cfg(test)]
#[path = "environment_tests.rs"]
mod tests;
