//! Lane-wide texture sampling: eight pixels at a time, written once over [`Lanes`] and compiled
//! per instruction set.
//!
//! The rules are those of the scalar sampler ([`Texture::sample_lod`]): the level of detail per
//! lane from the analytic derivatives (OpenGL 4.6 §8.14), magnification or minification per
//! lane, every wrap mode and every filter. Texels are read through a `TexelSource`
//! (`texel_lanes`): one per lane, or, where the two columns of every
//! lane's bilinear footprint are neighbours in memory, one row's two texels at once (each lane's
//! level offset and size looked up in 16-entry tables by two permutes, whatever mix of levels
//! a row holds).
//!
//! Filtering is fixed point: texels in units of 1/32640 ([`LINEAR15_SCALE`]; a linear byte `k`
//! is `k · 128`, an sRGB byte its exact linear value rounded to that unit,
//! [`srgb_to_linear15`](super::texel::srgb_to_linear15)), weights in units of 1/32768, every
//! step one [`lerp15`](kantele_lanes::lerp15), scaled to [0, 1] once at the end. An sRGB texture
//! is read from its decoded copy when it has one, otherwise decoded lane-wide from the bytes
//! through the 256-entry table of the same values — the two give the same bits. Integer steps
//! and the same `f32` operations in the same order (no fused multiply-add) on every instruction
//! set give the scalar build and the SIMD builds identical bits.
//!
//! Against the scalar sampler, results differ by at most about 1.1e-4 per channel: `log2` is a
//! polynomial here (absolute error below 1e-6 for the level of detail), and each fixed-point
//! step rounds by at most one unit.

use kantele_lanes::{
    bilinear15, lerp15_channels, F32x8, Footprint15, I32x8, Lanes, Mask8, MaskOf, TexelGather,
};

use super::levels::{lookup16, LaneTable};
use super::texel::{linear15_table, LINEAR15_SCALE};
use super::texel_lanes::{Channels, TexelSource};
use super::texture::{ColorSpace, Filter, Linear15Copy, MinFilter, Sampler, Texture, Wrap};

impl Texture {
    /// Samples eight texture coordinates at once, each with the level of detail from its own
    /// screen-space derivatives (per pixel, in texture-coordinate units), as
    /// [`Texture::sample_grad`] does for one.
    ///
    /// `uv`, `duv_dx` and `duv_dy` hold `[u, v]`, `[∂u/∂x, ∂v/∂x]` and `[∂u/∂y, ∂v/∂y]` as
    /// lanes. Returns linear `[r, g, b, a]` lanes. Lanes outside `active` are not sampled, and
    /// they and lanes with a NaN or infinite coordinate give 0 (as [`Texture::sample_lod`]).
    #[inline(always)]
    pub fn sample_grad_lanes<L: Lanes>(
        &self,
        sampler: &Sampler,
        uv: [L::F32; 2],
        duv_dx: [L::F32; 2],
        duv_dy: [L::F32; 2],
        active: MaskOf<L>,
    ) -> [L::F32; 4] {
        self.sample_grad_lanes_from::<L>(
            self.lane_texels(),
            sampler,
            self.sizes(),
            uv,
            duv_dx,
            duv_dy,
            active,
        )
    }

    /// This texture and `sampler` as a [`TrilinearRepeat15`] when they are that configuration
    /// (the one most textures are sampled with), else `None`.
    pub fn trilinear_repeat15(&self, sampler: &Sampler) -> Option<TrilinearRepeat15<'_>> {
        let configuration = *sampler == TrilinearRepeat15::SAMPLER
            && self.width().is_power_of_two()
            && self.height().is_power_of_two()
            && self.color_space == ColorSpace::Srgb;
        let copy = self.linear15().filter(|_| configuration)?;
        Some(TrilinearRepeat15 {
            texture: self,
            copy,
            sizes: self.sizes(),
        })
    }

    /// This texture's [`Sizes`].
    #[inline(always)]
    fn sizes(&self) -> Sizes {
        Sizes {
            width: self.width() as f32,
            height: self.height() as f32,
            max_level: self.max_level() as f32,
            pot: self.width().is_power_of_two() && self.height().is_power_of_two(),
        }
    }

    /// Where [`Texture::sample_grad_lanes`] reads the texels: the decoded copy of an sRGB
    /// texture when it has one ([`Texture::linear15`]), otherwise the bytes.
    fn lane_texels(&self) -> TexelSource<'_> {
        match (self.color_space, self.linear15()) {
            (ColorSpace::Linear, _) => TexelSource::LinearBytes(&self.texels),
            (ColorSpace::Srgb, Some(copy)) => TexelSource::Linear15(copy),
            (ColorSpace::Srgb, None) => TexelSource::SrgbBytes(&self.texels, linear15_table()),
        }
    }

    /// How `source`, one of this texture's texel sources, lays out the levels.
    #[inline(always)]
    fn level_layout<'t>(&'t self, source: TexelSource<'t>) -> LevelLayout<'t> {
        match source {
            TexelSource::Linear15(copy) => LevelLayout {
                lane_offsets: &copy.lane_offsets,
                row_padding: 1,
            },
            TexelSource::LinearBytes(_) | TexelSource::SrgbBytes(..) => LevelLayout {
                lane_offsets: &self.levels.lane_offsets,
                row_padding: 0,
            },
        }
    }

    /// [`Texture::sample_grad_lanes`] reading `source`; `sizes`: this texture's ([`Texture::sizes`]).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn sample_grad_lanes_from<L: Lanes>(
        &self,
        source: TexelSource<'_>,
        sampler: &Sampler,
        sizes: Sizes,
        uv: [L::F32; 2],
        duv_dx: [L::F32; 2],
        duv_dy: [L::F32; 2],
        active: MaskOf<L>,
    ) -> [L::F32; 4] {
        let lanes = active.lanes();
        let zero = lanes.splat_f32(0.0);
        #[cfg(feature = "fault-injection")]
        let uv = if crate::fault::active(crate::fault::Fault::FlipV) {
            [uv[0], lanes.splat_f32(1.0) - uv[1]]
        } else {
            uv
        };
        let infinity = lanes.splat_f32(f32::INFINITY);
        let finite = uv[0]
            .abs()
            .simd_lt(infinity)
            .and(uv[1].abs().simd_lt(infinity));
        let live = active.and(finite);
        if live.none() {
            return [zero; 4];
        }
        let pot = sizes.pot;
        let rho2 = footprint_lanes::<L>(sizes, duv_dx, duv_dy);
        // λ ≤ 0 exactly where ρ² ≤ 1 (see `log2_normal`), so when every live lane is magnified
        // the level of detail is not needed: level 0, no blend.
        let selection = if rho2.simd_le(lanes.splat_f32(1.0)).or(live.not()).all() {
            LevelSelection::<L>::magnified(lanes, sampler)
        } else {
            LevelSelection::<L>::new(sizes, sampler, lod_lanes::<L>(sizes, rho2))
        };
        let nearest = selection.nearest;
        let layout = self.level_layout(source);
        let first =
            self.level_texels::<L>(layout, sampler, pot, selection.first, uv, nearest, live);
        // The second level only where some live lane blends (trilinear between levels).
        let blend = selection.fraction.simd_gt(zero).and(live);
        let texel = if blend.any() {
            let second =
                self.level_texels::<L>(layout, sampler, pot, selection.second, uv, nearest, live);
            // A lane with fraction 0 keeps `first` exactly (`lerp15` with weight 0).
            let fraction = weight15::<L>(selection.fraction);
            match (source, &first, &second) {
                (
                    TexelSource::Linear15(copy),
                    LevelTexels::Bilinear(f0),
                    LevelTexels::Bilinear(f1),
                ) => <L::I32 as TexelGather>::filter15(&copy.words, *f0, Some((*f1, fraction))),
                _ => lerp15_channels::<L>(
                    source.filter::<L>(&first),
                    source.filter::<L>(&second),
                    fraction,
                ),
            }
        } else {
            source.filter::<L>(&first)
        };
        // Fixed-point units to [0, 1], multiplied by the reciprocal (a division per channel
        // would cost more than the rest of the step; the full-scale value still gives 1 exactly).
        let unit = lanes.splat_f32(1.0 / LINEAR15_SCALE as f32);
        let mut out = [zero; 4];
        for (channel, value) in out.iter_mut().zip(texel) {
            *channel = live.select_f32(value.to_f32() * unit, zero);
        }
        out
    }

    /// The texels one level per lane reads (`level` holds each lane's level index) at `uv`, as
    /// indices into a source laid out as `layout`, and their weights: nearest where `nearest` is
    /// set and bilinear elsewhere; lanes outside `live` are unspecified; `pot` as in
    /// [`Texture::sample_grad_lanes_from`].
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn level_texels<L: Lanes>(
        &self,
        layout: LevelLayout<'_>,
        sampler: &Sampler,
        pot: bool,
        level: L::I32,
        uv: [L::F32; 2],
        nearest: MaskOf<L>,
        live: MaskOf<L>,
    ) -> LevelTexels<L> {
        let lanes = nearest.lanes();
        let (offset, width, height) = self.level_extents::<L>(layout, level);
        let row_length = width + lanes.splat_i32(layout.row_padding);
        let s = LaneAxis::<L>::new(sampler.wrap_s, uv[0], width);
        let t = LaneAxis::<L>::new(sampler.wrap_t, uv[1], height);
        if nearest.all() {
            let i = sampler
                .wrap_s
                .wrap_lanes::<L>(s.coord.to_i32_floor(), width, pot);
            let j = sampler
                .wrap_t
                .wrap_lanes::<L>(t.coord.to_i32_floor(), height, pot);
            return LevelTexels::Nearest(offset + j * row_length + i);
        }
        // Bilinear: texel centres at integer + ½. Each coordinate is rounded once to 1/32768 of
        // a texel: the whole texels are its left (top) texel, the fraction its weight in the
        // filter's units (`0..=32767`). A nearest lane reads texel ⌊u⌋ with weight 0: the filter
        // gives t00 exactly, the nearest result.
        let half = nearest.select_f32(lanes.splat_f32(0.0), lanes.splat_f32(0.5));
        let (i0, alpha) = fixed_texel::<L>(s.coord - half, nearest);
        let (j0, beta) = fixed_texel::<L>(t.coord - half, nearest);
        let one = lanes.splat_i32(1);
        let x0 = sampler.wrap_s.wrap_lanes::<L>(i0, width, pot);
        let x1 = sampler.wrap_s.wrap_lanes::<L>(i0 + one, width, pot);
        let row0 = offset + sampler.wrap_t.wrap_lanes::<L>(j0, height, pot) * row_length;
        let row1 = offset + sampler.wrap_t.wrap_lanes::<L>(j0 + one, height, pot) * row_length;
        // Where every live lane's two columns are neighbours in memory, each row's pair of
        // texels is one read per lane: always under REPEAT in a layout whose rows repeat their
        // first texel at the end (the texel after column `width − 1` is column 0, as REPEAT
        // wraps it), else where no live lane's columns wrap between them (the common case).
        let neighbours = (layout.row_padding == 1 && sampler.wrap_s == Wrap::Repeat)
            || x1.simd_eq(x0 + one).or(live.not()).all();
        let footprint = Footprint15 {
            top: row0 + x0,
            bottom: row1 + x0,
            alpha,
            beta,
        };
        if neighbours {
            LevelTexels::Bilinear(footprint)
        } else {
            // Column offsets `x1 − x0` of the right texels, from each row's left texel.
            LevelTexels::Wrapped(footprint, x1 - x0)
        }
    }

    /// Each lane's level offset (in `layout`), width and height, looked up in the
    /// [`LaneTable`]s: no branch on whether the lanes share a level, no gather.
    #[inline(always)]
    fn level_extents<L: Lanes>(
        &self,
        layout: LevelLayout<'_>,
        level: L::I32,
    ) -> (L::I32, L::I32, L::I32) {
        let [widths, heights] = &self.levels.lane_sizes;
        (
            lookup16::<L>(layout.lane_offsets, level),
            lookup16::<L>(widths, level),
            lookup16::<L>(heights, level),
        )
    }
}

/// An sRGB texture with a decoded copy and power-of-two sides, sampled with REPEAT on both
/// axes, LINEAR magnification and LINEAR_MIPMAP_LINEAR minification ([`Self::SAMPLER`]): the
/// glTF default most files use. [`TrilinearRepeat15::sample_grad_lanes`] is
/// [`Texture::sample_grad_lanes`] with that configuration fixed at compile time, so that a
/// program built on it holds none of the branches on wrap modes, filters and texel storage.
#[derive(Clone, Copy)]
pub struct TrilinearRepeat15<'t> {
    texture: &'t Texture,
    /// The texture's decoded copy ([`Texture::linear15`]).
    copy: &'t Linear15Copy,
    /// The texture's sizes ([`Texture::sizes`]).
    sizes: Sizes,
}

impl TrilinearRepeat15<'_> {
    /// The sampler of this configuration.
    pub const SAMPLER: Sampler = Sampler {
        wrap_s: Wrap::Repeat,
        wrap_t: Wrap::Repeat,
        mag_filter: Filter::Linear,
        min_filter: MinFilter::LinearMipmapLinear,
    };

    /// [`Texture::sample_grad_lanes`] with [`Self::SAMPLER`]: the same operations, the same bits.
    #[inline(always)]
    pub fn sample_grad_lanes<L: Lanes>(
        &self,
        uv: [L::F32; 2],
        duv_dx: [L::F32; 2],
        duv_dy: [L::F32; 2],
        active: MaskOf<L>,
    ) -> [L::F32; 4] {
        self.texture.sample_grad_lanes_from::<L>(
            TexelSource::Linear15(self.copy),
            &Self::SAMPLER,
            // Powers of two by construction: stated here so that the wrap is compiled as a mask.
            Sizes {
                pot: true,
                ..self.sizes
            },
            uv,
            duv_dx,
            duv_dy,
            active,
        )
    }
}

/// A texture's level-0 sizes and last level as the sampler reads them, in `f32`: worked out
/// once per draw for a [`TrilinearRepeat15`] (a program holding it then reloads nothing of the
/// texture per row), once per call otherwise.
#[derive(Clone, Copy, Debug)]
struct Sizes {
    /// Width of level 0 in texels.
    width: f32,
    /// Height of level 0 in texels.
    height: f32,
    /// Index of the last level.
    max_level: f32,
    /// Both sides of level 0 are powers of two (and so those of every level).
    pot: bool,
}

/// Per-lane squared footprint `ρ² = max(|∂uv/∂x|², |∂uv/∂y|²)` in texels of level 0
/// ([`Texture::lod`]) of a texture of `sizes`.
#[inline(always)]
fn footprint_lanes<L: Lanes>(sizes: Sizes, duv_dx: [L::F32; 2], duv_dy: [L::F32; 2]) -> L::F32 {
    let lanes = duv_dx[0].lanes();
    let width = lanes.splat_f32(sizes.width);
    let height = lanes.splat_f32(sizes.height);
    let (rx, ry) = (
        footprint2::<L>(duv_dx, width, height),
        footprint2::<L>(duv_dy, width, height),
    );
    // `f32::max` ignores a NaN operand; the lane `max` returns `ry` when either is NaN.
    let ry_is_nan = ry.simd_ne(ry);
    ry_is_nan.select_f32(rx, rx.max(ry))
}

/// Per-lane level of detail `λ = ½ log2 ρ²` ([`Texture::lod`]) from the squared footprint
/// ([`footprint_lanes`]): `−∞` where it is zero (or below the smallest normal float), the last
/// level of a texture of `sizes` where it is not finite.
#[inline(always)]
fn lod_lanes<L: Lanes>(sizes: Sizes, rho2: L::F32) -> L::F32 {
    let lanes = rho2.lanes();
    let normal = rho2
        .simd_ge(lanes.splat_f32(f32::MIN_POSITIVE))
        .and(rho2.simd_lt(lanes.splat_f32(f32::INFINITY)));
    let tiny = rho2.simd_lt(lanes.splat_f32(f32::MIN_POSITIVE));
    let lod = lanes.splat_f32(0.5) * log2_normal::<L>(rho2);
    let fallback = tiny.select_f32(
        lanes.splat_f32(f32::NEG_INFINITY),
        lanes.splat_f32(sizes.max_level),
    );
    normal.select_f32(lod, fallback)
}

/// Where a texel source holds each level: the index of its first texel, and rows of `width +
/// row_padding` texels.
#[derive(Clone, Copy)]
struct LevelLayout<'t> {
    /// Index of each level's first texel, level 0 first, as a [`LaneTable`].
    lane_offsets: &'t LaneTable,
    /// 0 (the texel storage), or 1 (a [`Linear15Copy`]: each row ends with a copy of its first
    /// texel).
    row_padding: i32,
}

/// `w ∈ [0, 1]` in the filter's units of 1/32768, rounded to the nearest and clamped to
/// `0..=32767` (a weight that rounds to 1 gives the second value 32767/32768 of the blend).
#[inline(always)]
fn weight15<L: Lanes>(w: L::F32) -> L::I32 {
    fixed15::<L>(w).min(w.lanes().splat_i32(32767))
}

/// `x` in units of 1/32768, rounded to the nearest (ties to even); `x · 32768` must fit `i32`.
#[inline(always)]
fn fixed15<L: Lanes>(x: L::F32) -> L::I32 {
    (x * x.lanes().splat_f32(32768.0))
        .round_ties_even()
        .to_i32_trunc()
}

/// A texel coordinate `u` (a [`LaneAxis`] coordinate less the half texel) rounded to 1/32768 of
/// a texel: its whole texels, the left (top) texel of the bilinear footprint, and its fraction,
/// the weight of the right (bottom) texel in `0..=32767`. A coordinate within 2^-16 below a
/// whole texel rounds up to it, with weight 0. Lanes in `nearest` take `⌊u⌋` and weight 0.
/// `u · 32768` fits `i32`: coordinates are at most `2 · 16384 + 2` texels.
#[inline(always)]
fn fixed_texel<L: Lanes>(u: L::F32, nearest: MaskOf<L>) -> (L::I32, L::I32) {
    let lanes = u.lanes();
    let fixed = fixed15::<L>(u);
    let (whole, fraction) = (fixed.shr_arith::<15>(), fixed & lanes.splat_i32(32767));
    if nearest.none() {
        return (whole, fraction);
    }
    (
        nearest.select_i32(u.to_i32_floor(), whole),
        nearest.select_i32(lanes.splat_i32(0), fraction),
    )
}

/// The texels of one level that [`Texture::level_texels`] chose per lane.
enum LevelTexels<L: Lanes> {
    /// One texel per lane (every lane nearest).
    Nearest(L::I32),
    /// A bilinear footprint per lane whose two texels of each row are neighbours in memory for
    /// every live lane.
    Bilinear(Footprint15<L::I32>),
    /// A bilinear footprint whose right texels lie the given offset from the left ones (a wrap
    /// between the columns).
    Wrapped(Footprint15<L::I32>, L::I32),
}

impl TexelSource<'_> {
    /// Filters `texels` from this source: the texel itself, or the bilinear blend of its
    /// footprint with [`lerp15`](kantele_lanes::lerp15) (rows first, then the two rows).
    #[inline(always)]
    fn filter<L: Lanes>(self, texels: &LevelTexels<L>) -> Channels<L> {
        let (f, right) = match *texels {
            LevelTexels::Nearest(index) => return self.fetch::<L>(index),
            LevelTexels::Bilinear(f) => (f, None),
            LevelTexels::Wrapped(f, right) => (f, Some(right)),
        };
        let ((t00, t10), (t01, t11)) = match (self, right) {
            (TexelSource::Linear15(copy), None) => {
                return <L::I32 as TexelGather>::filter15(&copy.words, f, None);
            }
            (_, None) => (self.fetch_pair::<L>(f.top), self.fetch_pair::<L>(f.bottom)),
            (_, Some(right)) => (
                (self.fetch::<L>(f.top), self.fetch::<L>(f.top + right)),
                (self.fetch::<L>(f.bottom), self.fetch::<L>(f.bottom + right)),
            ),
        };
        bilinear15::<L>([t00, t10, t01, t11], f.alpha, f.beta)
    }
}

/// The levels and filter each lane reads.
struct LevelSelection<L: Lanes> {
    /// The level read by every lane.
    first: L::I32,
    /// The second level of a trilinear blend.
    second: L::I32,
    /// Weight of `second` (0 where only `first` is read).
    fraction: L::F32,
    /// Lanes filtered with NEAREST (the others bilinear).
    nearest: L::Mask,
}

impl<L: Lanes> LevelSelection<L> {
    /// [`LevelSelection::new`] when every lane is magnified (λ ≤ 0): level 0 with the
    /// magnification filter, nothing blended (the same values `new` gives such lanes).
    #[inline(always)]
    fn magnified(lanes: L, sampler: &Sampler) -> Self {
        let level_zero = lanes.splat_i32(0);
        let second = match sampler.min_filter {
            MinFilter::NearestMipmapLinear | MinFilter::LinearMipmapLinear => lanes.splat_i32(1),
            _ => level_zero,
        };
        Self {
            first: level_zero,
            second,
            fraction: lanes.splat_f32(0.0),
            nearest: lanes.mask_all(sampler.mag_filter == Filter::Nearest),
        }
    }

    /// OpenGL's level selection ([`Texture::sample_lod`]) per lane: λ ≤ 0 magnifies from level 0
    /// with the magnification filter; otherwise the minification filter picks the level(s).
    #[inline(always)]
    fn new(sizes: Sizes, sampler: &Sampler, lod: L::F32) -> Self {
        let lanes = lod.lanes();
        let zero = lanes.splat_f32(0.0);
        let max_level = lanes.splat_f32(sizes.max_level);
        let magnified = lod.simd_gt(zero).not();
        let min_filter = sampler.min_filter;
        let nearest_min = min_filter.texel_filter() == Filter::Nearest;
        let nearest_mag = sampler.mag_filter == Filter::Nearest;
        let nearest = match (nearest_mag, nearest_min) {
            (true, true) => lanes.mask_all(true),
            (false, false) => lanes.mask_all(false),
            (true, false) => magnified,
            (false, true) => magnified.not(),
        };
        let level_zero = lanes.splat_i32(0);
        let (first, second, fraction) = match min_filter {
            MinFilter::Nearest | MinFilter::Linear => (level_zero, level_zero, zero),
            MinFilter::NearestMipmapNearest | MinFilter::LinearMipmapNearest => {
                // d = ceil(λ + ½) − 1 = −⌊−(λ + ½)⌋ − 1, clamped to the chain; 0 for λ ≤ ½.
                let d = (-(-(lod + lanes.splat_f32(0.5))).floor() - lanes.splat_f32(1.0))
                    .min(max_level);
                let d = lod.simd_le(lanes.splat_f32(0.5)).select_f32(zero, d);
                let d = magnified.select_f32(zero, d).to_i32_trunc();
                (d, d, zero)
            }
            MinFilter::NearestMipmapLinear | MinFilter::LinearMipmapLinear => {
                let clamped = lod.simd_ge(max_level).or(magnified);
                let lower = lod.floor();
                let fraction = clamped.select_f32(zero, lod - lower);
                let lower =
                    magnified.select_f32(zero, lod.simd_ge(max_level).select_f32(max_level, lower));
                let first = lower.to_i32_trunc();
                (first, first + lanes.splat_i32(1), fraction)
            }
        };
        Self {
            first,
            second,
            fraction,
            nearest,
        }
    }
}

/// One texture axis of eight lanes: the coordinate in texels of the level, reduced to the first
/// period of a repeating wrap mode.
struct LaneAxis<L: Lanes> {
    coord: L::F32,
}

impl<L: Lanes> LaneAxis<L> {
    /// `t` (texture coordinate) times the level size `size`, after [`Wrap`]'s reduction: in
    /// `[0, size]` for REPEAT, `[0, 2·size]` for MIRRORED_REPEAT, and limited to
    /// `[−2, size + 2]` for CLAMP_TO_EDGE (which changes no texel or weight that is read, and
    /// keeps the conversion to `i32` in range).
    #[inline(always)]
    fn new(wrap: Wrap, t: L::F32, size: L::I32) -> Self {
        let lanes = t.lanes();
        let size = size.to_f32();
        let coord = match wrap {
            Wrap::Repeat => (t - t.floor()) * size,
            Wrap::MirroredRepeat => {
                (t - lanes.splat_f32(2.0) * (t * lanes.splat_f32(0.5)).floor()) * size
            }
            Wrap::ClampToEdge => (t * size)
                .max(lanes.splat_f32(-2.0))
                .min(size + lanes.splat_f32(2.0)),
        };
        Self { coord }
    }
}

impl Wrap {
    /// [`Wrap::apply`] on lanes, for the integer coordinates [`LaneAxis`] produces: in
    /// `[−1, size]` for REPEAT, `[−1, 2·size]` for MIRRORED_REPEAT, anything for CLAMP_TO_EDGE.
    /// `pot`: every lane's `size` is a power of two, where REPEAT is one mask (`i & (size − 1)`,
    /// the same result on that range, and the same `1` for `size + 1` when `size ≥ 2`).
    #[inline(always)]
    fn wrap_lanes<L: Lanes>(self, i: L::I32, size: L::I32, pot: bool) -> L::I32 {
        let lanes = i.lanes();
        let zero = lanes.splat_i32(0);
        let one = lanes.splat_i32(1);
        match self {
            Wrap::Repeat if pot => i & (size - one),
            Wrap::Repeat => {
                let i = i.simd_lt(zero).select_i32(i + size, i);
                i.simd_gt(size - one).select_i32(i - size, i)
            }
            Wrap::ClampToEdge => i.max(zero).min(size - one),
            Wrap::MirroredRepeat => {
                let period = size + size;
                let p = i.simd_lt(zero).select_i32(i + period, i);
                let p = p.simd_gt(period - one).select_i32(p - period, p);
                p.simd_lt(size).select_i32(p, period - one - p)
            }
        }
    }
}

/// `x² + y²` of a derivative `[∂u, ∂v]` scaled to texels (`width`, `height`).
#[inline(always)]
fn footprint2<L: Lanes>(d: [L::F32; 2], width: L::F32, height: L::F32) -> L::F32 {
    let (x, y) = (d[0] * width, d[1] * height);
    x * x + y * y
}

/// The coefficients of [`log2_normal`]'s `P(t)`, lowest degree first (`P(0) ≈ 1/ln 2`).
pub(super) const LOG2_POLYNOMIAL: [f32; 7] = [
    1.442_699_7,
    -0.721_375_8,
    0.480_465_38,
    -0.358_963_73,
    0.297_259_54,
    -0.272_680_46,
    0.170_623_42,
];

/// `log2 x` for positive normal `x`, from the exponent bits and a polynomial in `t = m − 1`
/// with the mantissa `m` in `[√½, √2)`: `log2 m ≈ t · P(t)`, `P` of degree 6 fitted to
/// `log2(1 + t) / t` on that interval (absolute error below 4e-7 in `f32`). No division: the
/// fragment path calls it once per textured row, and a division's latency was on that row's
/// critical path. Other inputs give unspecified values.
///
/// The result is at most 0 exactly when `x ≤ 1`: it is 0 at 1; below 1 the exponent is negative,
/// or 0 with `m < 1` and so `t < 0`; above 1 the exponent is positive, or 0 with `m > 1`; `P` is
/// positive on the interval and `|t · P(t)| < ½`. The sampler relies on it to skip the level of
/// detail of magnified lanes (tested over the floats around 1 and around every power of two).
#[inline(always)]
pub(super) fn log2_normal<L: Lanes>(x: L::F32) -> L::F32 {
    let lanes = x.lanes();
    let bits = x.to_bits();
    // x = 2^e · m with m in [√½, √2): the exponent counted from the bits of √½ (`0x3f3504f3`,
    // whose mantissa bits are those of √2 in `f32`), so that a mantissa at or above √2's moves
    // to the next exponent, and m the bits less that exponent. The same e and m (bit for bit)
    // as taking the mantissa in [1, 2) and halving it (exactly) at or above √2, in four integer
    // steps instead of nine.
    let exponent = (bits - lanes.splat_i32(0x3f35_04f3)).shr_arith::<23>();
    let m = L::F32::from_bits(bits - exponent.shl::<23>());
    // Exact: `m` and 1 are within a factor of two.
    let t = m - lanes.splat_f32(1.0);
    const P: [f32; 7] = LOG2_POLYNOMIAL;
    // Estrin's scheme: pairs `P[k] + P[k+1]·t` combined with t² and t⁴, five dependent steps
    // instead of Horner's twelve (the row's critical path runs through this).
    // Splats written out, not a closure: a closure may be compiled out of line, without the
    // kernel's instruction set.
    let [p0, p1, p2, p3, p4, p5, p6] = [
        lanes.splat_f32(P[0]),
        lanes.splat_f32(P[1]),
        lanes.splat_f32(P[2]),
        lanes.splat_f32(P[3]),
        lanes.splat_f32(P[4]),
        lanes.splat_f32(P[5]),
        lanes.splat_f32(P[6]),
    ];
    let t2 = t * t;
    let t4 = t2 * t2;
    let low = (p0 + p1 * t) + t2 * (p2 + p3 * t);
    let high = (p4 + p5 * t) + t2 * p6;
    let poly = low + t4 * high;
    exponent.to_f32() + t * poly
}

#[cfg(test)]
#[path = "sample_lanes_tests.rs"]
mod tests;
