//! `KHR_materials_transmission` and `KHR_materials_volume` as a rasterizer draws them (the
//! glTF sample viewer's method): a transmissive surface shows the opaque scene behind it.
//!
//! - The **backdrop** ([`Backdrop`]) is the frame drawn without its transmissive and blended
//!   draws, linear and before exposure and tone mapping, with a mip chain (2 × 2 box filter,
//!   level `k + 1` of size `max(1, ⌊size_k / 2⌋)`, OpenGL's level sizes).
//! - A surface reads it where the view ray, refracted into the volume (`1 / ior`) and followed
//!   for `thickness` (the mesh's units, scaled by the draw's model matrix per axis), leaves the
//!   volume again, projected to the screen; a thin wall (`thickness` 0) reads it under itself.
//! - Rough surfaces read a blurred level: `log2(width) × roughness × clamp(2 ior − 2, 0, 1)`
//!   (trilinear, clamped to the edge).
//! - Inside a volume the light is dimmed by Beer's law: `attenuation_color^(d / distance)`
//!   per channel over the distance `d` travelled.
//!
//! The transmitted light replaces `transmission` of the dielectric's diffuse light (image-based
//! and punctual); how [`super::pbr::shade`] mixes it is described there.

use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3};
use kantele_lanes::{F32x8, I32x8, Lanes, Mask8, Scalar};

use super::environment::MAX_RADIANCE;
use super::levels::{bilinear_rgb, lookup16, LevelTable};

/// The longest side of a backdrop: frames larger than this are drawn into a backdrop scaled
/// down to fit (memory stays at most 2048² × 16 bytes × 4/3).
pub const MAX_BACKDROP_SIZE: u32 = 2048;

/// The opaque picture behind a frame's transmissive surfaces, as they read it (see the module
/// docs).
#[derive(Clone, Debug)]
pub struct Backdrop {
    /// Where each level lies in `texel_bits` (in texels) and its size.
    levels: LevelTable,
    /// Every level's texels, one after another, as `f32` bits, four words a texel (RGB and a
    /// 0), row 0 at the top; then one texel of zeros, so that a read of a row's two texels at
    /// the chain's last texel stays inside the table.
    texel_bits: Vec<u32>,
}

/// Bytes a backdrop pixel costs while a frame is drawn: its target (linear RGBA and depth,
/// `f32`: 20), the colour read back (16) and the mip chain (four words a texel, a third more
/// for the smaller levels: 22).
pub const BACKDROP_BYTES_PER_PIXEL: usize = 20 + 16 + 22;

/// Bytes the backdrop of a `width` × `height` frame costs ([`BACKDROP_BYTES_PER_PIXEL`] at
/// [`backdrop_size`]): what a frame memory budget sets aside for a scene with transmission.
pub fn backdrop_bytes(width: u32, height: u32) -> usize {
    let (w, h) = backdrop_size(width, height);
    w as usize * h as usize * BACKDROP_BYTES_PER_PIXEL
}

/// The size of the backdrop of a `width` × `height` frame: the frame's, scaled down (keeping
/// its aspect, at least 1 × 1) so that neither side exceeds [`MAX_BACKDROP_SIZE`].
pub fn backdrop_size(width: u32, height: u32) -> (u32, u32) {
    let longest = width.max(height).max(1);
    if longest <= MAX_BACKDROP_SIZE {
        return (width.max(1), height.max(1));
    }
    let scale = |side: u32| {
        ((u64::from(side) * u64::from(MAX_BACKDROP_SIZE)) / u64::from(longest)).max(1) as u32
    };
    (scale(width), scale(height))
}

impl Backdrop {
    /// The backdrop of a `width` × `height` picture of linear RGBA rows (row 0 at the top;
    /// alpha is ignored). Non-finite and negative channels count as 0, channels above
    /// [`MAX_RADIANCE`] as that. `None` when `rgba` does not hold `width × height` pixels or a
    /// side is 0 or above [`MAX_BACKDROP_SIZE`].
    pub fn new(width: u32, height: u32, rgba: &[[f32; 4]]) -> Option<Self> {
        let sides = 1..=MAX_BACKDROP_SIZE;
        if !sides.contains(&width)
            || !sides.contains(&height)
            || rgba.len() != width as usize * height as usize
        {
            return None;
        }
        let clean = |v: f32| if v > 0.0 { v.min(MAX_RADIANCE) } else { 0.0 };
        let mut sizes = vec![(width, height)];
        let (mut w, mut h) = (width, height);
        while w > 1 || h > 1 {
            (w, h) = ((w / 2).max(1), (h / 2).max(1));
            sizes.push((w, h));
        }
        let texels: usize = sizes.iter().map(|&(w, h)| w as usize * h as usize).sum();
        // Every level's texels, four words each, and the zero texel after them.
        let mut texel_bits = vec![0u32; (texels + 1) * 4];
        for (t, p) in texel_bits.chunks_exact_mut(4).zip(rgba) {
            t[..3].copy_from_slice(&[
                clean(p[0]).to_bits(),
                clean(p[1]).to_bits(),
                clean(p[2]).to_bits(),
            ]);
        }
        let mut first = 0;
        for pair in sizes.windows(2) {
            let [(w, h), (next_w, next_h)] = [pair[0], pair[1]];
            let next_first = first + w as usize * h as usize;
            let (done, rest) = texel_bits.split_at_mut(next_first * 4);
            let source = &done[first * 4..];
            let row = |y: u32| &source[(y * w) as usize * 4..][..w as usize * 4];
            let next_row = next_w as usize * 4;
            for (y, target) in rest[..next_row * next_h as usize]
                .chunks_exact_mut(next_row)
                .enumerate()
            {
                let y = y as u32;
                // The rows and columns of each 2 × 2 block, the last repeated at an odd edge
                // (a side of 1 halves to 1).
                let (top, bottom) = (row((2 * y).min(h - 1)), row((2 * y + 1).min(h - 1)));
                for (x, out) in target.chunks_exact_mut(4).enumerate() {
                    let x = x as u32;
                    let (x0, x1) = ((2 * x).min(w - 1) as usize, (2 * x + 1).min(w - 1) as usize);
                    for c in 0..3 {
                        let channel = |r: &[u32], x: usize| f32::from_bits(r[x * 4 + c]);
                        let upper = channel(top, x0) + channel(top, x1);
                        let lower = channel(bottom, x0) + channel(bottom, x1);
                        out[c] = ((upper + lower) * 0.25).to_bits();
                    }
                }
            }
            first = next_first;
        }
        Some(Self {
            levels: LevelTable::new(&sizes),
            texel_bits,
        })
    }

    /// The number of levels (level 0 is the picture itself, the last is 1 × 1).
    pub fn level_count(&self) -> usize {
        self.levels.widths.len()
    }

    /// Level `k`'s size and its texels (RGB, row 0 at the top), for a backend that uploads
    /// the chain; `None` past the last level.
    pub fn level(&self, k: usize) -> Option<(u32, u32, Vec<[f32; 3]>)> {
        let (w, h) = (*self.levels.widths.get(k)?, self.levels.heights[k]);
        let first = self.levels.offsets[k] as usize;
        let words = &self.texel_bits[first * 4..(first + (w * h) as usize) * 4];
        let texels = words
            .chunks_exact(4)
            .map(|t| [0, 1, 2].map(|c| f32::from_bits(t[c])))
            .collect();
        Some((w, h, texels))
    }

    /// The level-of-detail of a read at perceptual `roughness` through a surface of index of
    /// refraction `ior`: `log2(width) × roughness × clamp(2 ior − 2, 0, 1)` (before clamping to
    /// the chain).
    pub fn lod_scale(&self, ior: f32) -> f32 {
        (self.levels.widths[0] as f32).log2() * (2.0 * ior - 2.0).clamp(0.0, 1.0)
    }

    /// The backdrop at `uv` (0 to 1 left to right and top to bottom) and level of detail `lod`,
    /// per lane: bilinear in the two levels around `lod` (clamped to the chain; not finite
    /// reads level 0), linear between them, clamped to the edge.
    #[inline(always)]
    pub fn sample_lanes<L: Lanes>(&self, lanes: L, uv: [L::F32; 2], lod: L::F32) -> [L::F32; 3] {
        let zero = lanes.splat_f32(0.0);
        let last = (self.level_count() - 1) as i32;
        let lod = lod.max(zero).min(lanes.splat_f32(last as f32));
        let level = lod.floor();
        let t = lod - level;
        let lo_level = level.to_i32_trunc();
        let hi_level = (lo_level + lanes.splat_i32(1)).min(lanes.splat_i32(last));
        let lo = self.sample_level_lanes(lanes, lo_level, &uv);
        let hi = self.sample_level_lanes(lanes, hi_level, &uv);
        let exact = t.simd_eq(zero);
        [
            exact.select_f32(lo[0], lo[0] + (hi[0] - lo[0]) * t),
            exact.select_f32(lo[1], lo[1] + (hi[1] - lo[1]) * t),
            exact.select_f32(lo[2], lo[2] + (hi[2] - lo[2]) * t),
        ]
    }

    /// [`Backdrop::sample_lanes`] at one point.
    pub fn sample(&self, uv: Vec2, lod: f32) -> Vec3 {
        let lanes = Scalar;
        let uv = [lanes.splat_f32(uv.x), lanes.splat_f32(uv.y)];
        let out = self.sample_lanes(lanes, uv, lanes.splat_f32(lod));
        Vec3::new(out[0].extract(0), out[1].extract(0), out[2].extract(0))
    }

    /// Bilinear in level `level` per lane, clamped to the edge. Each row's two texels are read
    /// together, the right one always at the next texel in memory: the clamped right column
    /// differs from it only at the last column, where the coordinate is that column's centre
    /// and the right texel's weight is 0 (every texel is finite).
    #[inline(always)]
    fn sample_level_lanes<L: Lanes>(
        &self,
        lanes: L,
        level: L::I32,
        uv: &[L::F32; 2],
    ) -> [L::F32; 3] {
        let zero = lanes.splat_f32(0.0);
        let one = lanes.splat_i32(1);
        let [widths, heights] = &self.levels.lane_sizes;
        let (w, h) = (lookup16::<L>(widths, level), lookup16::<L>(heights, level));
        let first = lookup16::<L>(&self.levels.lane_offsets, level);
        let half = lanes.splat_f32(0.5);
        // Texel centre i sits at (i + 0.5) / size.
        let x = (uv[0] * w.to_f32() - half)
            .max(zero)
            .min((w - one).to_f32());
        let y = (uv[1] * h.to_f32() - half)
            .max(zero)
            .min((h - one).to_f32());
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0.to_i32_trunc(), y0.to_i32_trunc());
        let y1 = (y0 + one).min(h - one);
        let top = (first + y0 * w + x0).shl::<2>();
        let bottom = (first + y1 * w + x0).shl::<2>();
        bilinear_rgb(lanes, &self.texel_bits, top, bottom, fx, fy)
    }
}

/// What a frame's transmissive draws see through: the backdrop and the projection that finds
/// a point's place in it.
#[derive(Clone, Debug)]
pub struct TransmissionView {
    /// The opaque picture behind them.
    pub backdrop: Arc<Backdrop>,
    /// World to clip space of the frame (and of the backdrop).
    pub view_projection: Mat4,
}

/// The volume constants of a transmissive draw: its material's and its model matrix's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Volume {
    /// Index of refraction.
    pub ior: f32,
    /// The model matrix's scale along each local axis (the lengths of its first three
    /// columns), which turns the material's thickness into world units.
    pub scale: Vec3,
    /// Beer's law in base 2: `−log2(attenuation_color) / attenuation_distance` per channel
    /// (0: no attenuation).
    pub attenuation: Vec3,
    /// `log2(backdrop width) × clamp(2 ior − 2, 0, 1)`: the level of detail per unit of
    /// roughness ([`Backdrop::lod_scale`]).
    pub lod_scale: f32,
}

impl Volume {
    /// The constants of a material of index of refraction `ior` and attenuation
    /// (`attenuation_color`, `attenuation_distance`), drawn with `model`, over `backdrop`.
    /// An infinite or non-positive distance attenuates nothing; a colour channel of 0 stops
    /// that channel's light within any distance.
    pub fn new(
        ior: f32,
        attenuation_color: Vec3,
        attenuation_distance: f32,
        model: &Mat4,
        backdrop: &Backdrop,
    ) -> Self {
        let ior = if ior.is_finite() && ior >= 1.0 {
            ior
        } else {
            1.5
        };
        let attenuation = if attenuation_distance.is_finite() && attenuation_distance > 0.0 {
            attenuation_color.to_array().map(|c| {
                let c = if c.is_finite() {
                    c.clamp(0.0, 1.0)
                } else {
                    1.0
                };
                // A channel of 0 (or below f32's smallest normal) loses 2^126 per distance.
                (-c.max(f32::MIN_POSITIVE).log2() / attenuation_distance).min(f32::MAX)
            })
        } else {
            [0.0; 3]
        };
        let column = |i: usize| model.col(i).truncate().length();
        let scale = Vec3::new(column(0), column(1), column(2));
        Self {
            ior,
            scale: if scale.is_finite() { scale } else { Vec3::ONE },
            attenuation: Vec3::from(attenuation),
            lod_scale: backdrop.lod_scale(ior),
        }
    }
}

/// `KHR_materials_transmission` (and `KHR_materials_volume`) at a surface point, per lane.
#[derive(Clone, Copy, Debug)]
pub struct TransmissionLayer<L: Lanes> {
    /// `transmissionFactor` × texture, in [0, 1].
    pub factor: L::F32,
    /// `thicknessFactor` × texture, in the mesh's units (0: thin-walled).
    pub thickness: L::F32,
    /// The draw's volume constants.
    pub volume: Volume,
}

#[inline(always)]
fn dot3<L: Lanes>(a: &[L::F32; 3], b: &[L::F32; 3]) -> L::F32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The path of the view ray through the volume under a surface point, per lane: the unit view
/// vector `view` (towards the eye) refracted at the unit normal `n` by `1 / ior` (GLSL's
/// `refract`; total internal reflection gives no path), normalised, times the thickness and
/// the draw's scale per axis. Zero for a thin wall.
#[inline(always)]
pub fn refraction_path<L: Lanes>(
    lanes: L,
    layer: &TransmissionLayer<L>,
    n: &[L::F32; 3],
    view: &[L::F32; 3],
) -> [L::F32; 3] {
    let one = lanes.splat_f32(1.0);
    let zero = lanes.splat_f32(0.0);
    let eta = lanes.splat_f32(1.0 / layer.volume.ior);
    // i = −view; k = 1 − η² (1 − (n·i)²); t = η i − (η (n·i) + √k) n.
    let n_dot_i = -dot3::<L>(n, view);
    let k = one - eta * eta * (one - n_dot_i * n_dot_i);
    let refracts = k.simd_ge(zero);
    let along_n = eta * n_dot_i + k.max(zero).sqrt();
    let t = [
        -(eta * view[0]) - along_n * n[0],
        -(eta * view[1]) - along_n * n[1],
        -(eta * view[2]) - along_n * n[2],
    ];
    let t = super::pbr::normalize3(lanes, t);
    let s = layer.volume.scale;
    let scale = [s.x, s.y, s.z];
    let mut out = [zero; 3];
    for c in 0..3 {
        let length = layer.thickness * lanes.splat_f32(scale[c]);
        out[c] = refracts.select_f32(t[c] * length, zero);
    }
    out
}

/// Where world point `p` lies in the backdrop, per lane: `(u, v)` from 0 to 1 left to right and
/// top to bottom (a point at or behind the eye plane is projected as if just in front of it;
/// the lookup clamps to the edge).
#[inline(always)]
pub fn backdrop_uv<L: Lanes>(lanes: L, view_projection: &Mat4, p: &[L::F32; 3]) -> [L::F32; 2] {
    let (x, y, w) = (
        clip_row(lanes, view_projection, 0, p),
        clip_row(lanes, view_projection, 1, p),
        clip_row(lanes, view_projection, 3, p),
    );
    let w = w.max(lanes.splat_f32(1e-6));
    let half = lanes.splat_f32(0.5);
    [half + half * (x / w), half - half * (y / w)]
}

/// Row `r` of `m × (p, 1)`, per lane (a function, not a closure: see `kantele_lanes`).
#[inline(always)]
fn clip_row<L: Lanes>(lanes: L, m: &Mat4, r: usize, p: &[L::F32; 3]) -> L::F32 {
    let m = m.row(r);
    lanes.splat_f32(m.x) * p[0]
        + lanes.splat_f32(m.y) * p[1]
        + lanes.splat_f32(m.z) * p[2]
        + lanes.splat_f32(m.w)
}

/// `2^x` per lane for `x ≤ 0` (values below −126 give 2^−126, above 0 give 1; NaN gives
/// 2^−126): a degree-7 polynomial of the fraction (relative error below 2·10⁻⁶) scaled by the
/// exponent. Built of plain lane operations, so every instruction set gives the same bits.
#[inline(always)]
pub fn exp2_nonpositive<L: Lanes>(lanes: L, x: L::F32) -> L::F32 {
    exp2_up_to(lanes, x, 0.0)
}

/// `2^x` per lane for `x` in [−126, 127] (values outside are clamped to it; NaN gives
/// 2^−126): [`exp2_nonpositive`]'s polynomial over the whole exponent range.
#[inline(always)]
pub fn exp2<L: Lanes>(lanes: L, x: L::F32) -> L::F32 {
    exp2_up_to(lanes, x, 127.0)
}

/// `2^x` for `x` clamped to [−126, `highest`] (`highest` at most 127).
#[inline(always)]
fn exp2_up_to<L: Lanes>(lanes: L, x: L::F32, highest: f32) -> L::F32 {
    // Taylor coefficients of 2^f = e^(f ln 2): (ln 2)^k / k!.
    const C: [f32; 7] = [
        std::f32::consts::LN_2,
        0.240_226_5,
        0.055_504_11,
        0.009_618_129,
        0.001_333_355_8,
        0.000_154_035_3,
        0.000_015_252_73,
    ];
    let x = x.max(lanes.splat_f32(-126.0)).min(lanes.splat_f32(highest));
    let n = x.floor();
    let f = x - n;
    let mut p = lanes.splat_f32(C[6]);
    for c in C[..6].iter().rev() {
        p = p * f + lanes.splat_f32(*c);
    }
    let p = p * f + lanes.splat_f32(1.0);
    let scale = L::F32::from_bits((n.to_i32_trunc() + lanes.splat_i32(127)).shl::<23>());
    p * scale
}

/// The light that comes out of the volume of `layer` at a surface point, per lane: the
/// backdrop where the refracted view ray leaves the volume, blurred for `roughness`
/// (perceptual), dimmed over the path's length.
#[inline(always)]
pub fn transmitted_light<L: Lanes>(
    lanes: L,
    view: &TransmissionView,
    layer: &TransmissionLayer<L>,
    position: &[L::F32; 3],
    n: &[L::F32; 3],
    to_eye: &[L::F32; 3],
    roughness: L::F32,
) -> [L::F32; 3] {
    let path = refraction_path(lanes, layer, n, to_eye);
    let exit = [
        position[0] + path[0],
        position[1] + path[1],
        position[2] + path[2],
    ];
    let uv = backdrop_uv(lanes, &view.view_projection, &exit);
    let lod = roughness * lanes.splat_f32(layer.volume.lod_scale);
    let light = view.backdrop.sample_lanes(lanes, uv, lod);
    attenuate(lanes, &layer.volume, &path, light)
}

/// `light` after travelling along `path` inside a volume of `volume`'s attenuation.
#[inline(always)]
pub fn attenuate<L: Lanes>(
    lanes: L,
    volume: &Volume,
    path: &[L::F32; 3],
    light: [L::F32; 3],
) -> [L::F32; 3] {
    if volume.attenuation == Vec3::ZERO {
        return light;
    }
    let distance = dot3::<L>(path, path).sqrt();
    let k = volume.attenuation.to_array();
    let mut out = light;
    for c in 0..3 {
        if k[c] > 0.0 {
            out[c] = light[c] * exp2_nonpositive(lanes, -(lanes.splat_f32(k[c]) * distance));
        }
    }
    out
}

#[cfg(test)]
#[path = "transmission_tests.rs"]
mod tests;
