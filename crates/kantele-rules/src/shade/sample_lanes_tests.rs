//! Tests of the lane-wide sampler (`sample_lanes.rs`): lanes against the scalar sampler, the
//! decoded copy against the bytes, the `log2` polynomial, defined results for hostile
//! coordinates.

use glam::{Vec2, Vec4};

use super::*;
use crate::shade::texel::srgb_texel_to_linear15;
use kantele_lanes::{dispatch, Isa, LaneKernel};

/// Eight samples: uv and its derivatives per lane.
#[derive(Clone, Copy, Debug)]
struct Query {
    uv: [Vec2; 8],
    duv_dx: [Vec2; 8],
    duv_dy: [Vec2; 8],
    active: u8,
}

struct Sample<'a> {
    texture: &'a Texture,
    sampler: Sampler,
    query: Query,
    /// Read an sRGB texture's bytes through the table even where it has a decoded copy.
    bytes: bool,
}

impl LaneKernel for Sample<'_> {
    type Output = [[f32; 8]; 4];
    #[inline(always)]
    fn run<L: Lanes>(self, lanes: L) -> [[f32; 8]; 4] {
        let q = self.query;
        let pair = |v: [Vec2; 8]| {
            [
                lanes.f32_from_array(v.map(|p| p.x)),
                lanes.f32_from_array(v.map(|p| p.y)),
            ]
        };
        let source = match self.texture.lane_texels() {
            TexelSource::Linear15(_) if self.bytes => {
                TexelSource::SrgbBytes(&self.texture.texels, linear15_table())
            }
            source => source,
        };
        self.texture
            .sample_grad_lanes_from::<L>(
                source,
                &self.sampler,
                self.texture.sizes(),
                pair(q.uv),
                pair(q.duv_dx),
                pair(q.duv_dy),
                lanes.mask_from_bits(q.active),
            )
            .map(F32x8::to_array)
    }
}

struct Log2([f32; 8]);

impl LaneKernel for Log2 {
    type Output = [f32; 8];
    #[inline(always)]
    fn run<L: Lanes>(self, lanes: L) -> [f32; 8] {
        log2_normal::<L>(lanes.f32_from_array(self.0)).to_array()
    }
}

/// A small deterministic generator (xorshift).
struct Rng(u32);

impl Rng {
    fn next(&mut self) -> u32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 17;
        self.0 ^= self.0 << 5;
        self.0
    }
    /// Uniform in [lo, hi).
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * (self.next() >> 8) as f32 / (1 << 24) as f32
    }
}

fn noise_texture(width: u32, height: u32, color_space: ColorSpace) -> Texture {
    let mut rng = Rng(0x1234_5678);
    let rgba: Vec<u8> = (0..width * height * 4).map(|_| rng.next() as u8).collect();
    Texture::from_rgba8(width, height, &rgba, color_space).expect("texture")
}

const WRAPS: [Wrap; 3] = [Wrap::Repeat, Wrap::ClampToEdge, Wrap::MirroredRepeat];
const MIN_FILTERS: [MinFilter; 6] = [
    MinFilter::Nearest,
    MinFilter::Linear,
    MinFilter::NearestMipmapNearest,
    MinFilter::LinearMipmapNearest,
    MinFilter::NearestMipmapLinear,
    MinFilter::LinearMipmapLinear,
];

fn samplers() -> impl Iterator<Item = Sampler> {
    WRAPS.into_iter().flat_map(|wrap_s| {
        WRAPS.into_iter().flat_map(move |wrap_t| {
            [Filter::Nearest, Filter::Linear]
                .into_iter()
                .flat_map(move |mag_filter| {
                    MIN_FILTERS.into_iter().map(move |min_filter| Sampler {
                        wrap_s,
                        wrap_t,
                        mag_filter,
                        min_filter,
                    })
                })
        })
    })
}

/// Random queries: coordinates around and beyond [0, 1], footprints from magnified to
/// beyond the last level, anisotropic.
fn queries(rng: &mut Rng, count: usize) -> Vec<Query> {
    (0..count)
        .map(|_| {
            let mut uv = [Vec2::ZERO; 8];
            let mut duv_dx = [Vec2::ZERO; 8];
            let mut duv_dy = [Vec2::ZERO; 8];
            for k in 0..8 {
                uv[k] = Vec2::new(rng.range(-3.0, 3.0), rng.range(-3.0, 3.0));
                let scale = 2f32.powf(rng.range(-12.0, 2.0));
                duv_dx[k] = Vec2::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)) * scale;
                duv_dy[k] = Vec2::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)) * scale;
            }
            // Half the rows share one footprint (one level for all lanes, as in a typical
            // row of pixels), half have one per lane.
            if rng.next().is_multiple_of(2) {
                duv_dx = [duv_dx[0]; 8];
                duv_dy = [duv_dy[0]; 8];
            }
            Query {
                uv,
                duv_dx,
                duv_dy,
                active: rng.next() as u8 | 1,
            }
        })
        .collect()
}

fn scalar_reference(texture: &Texture, sampler: &Sampler, q: &Query, k: usize) -> Vec4 {
    texture.sample_grad(sampler, q.uv[k], q.duv_dx[k], q.duv_dy[k])
}

#[test]
fn log2_polynomial_is_close_to_libm() {
    let mut rng = Rng(99);
    let isas: Vec<Isa> = Isa::supported().collect();
    for _ in 0..2000 {
        let x: [f32; 8] = std::array::from_fn(|_| 2f32.powf(rng.range(-126.0, 127.0)));
        let reference = dispatch(Isa::Scalar, Log2(x));
        for &isa in &isas {
            let got = dispatch(isa, Log2(x));
            assert_eq!(got.map(f32::to_bits), reference.map(f32::to_bits), "{isa}");
        }
        for k in 0..8 {
            let exact = (x[k] as f64).log2();
            let error = (reference[k] as f64 - exact).abs();
            assert!(
                error < 2e-6 + exact.abs() * 1e-7,
                "log2 {} = {}",
                x[k],
                reference[k]
            );
        }
    }
    for (x, expected) in [(1.0f32, 0.0f32), (2.0, 1.0), (0.5, -1.0), (1024.0, 10.0)] {
        assert_eq!(dispatch(Isa::Scalar, Log2([x; 8]))[0], expected);
    }
}

/// The reduction `x = 2^e · m`, `m` in `[√½, √2)`, is the one the sampler used before it was
/// taken from the bits of √½: the mantissa in `[1, 2)`, halved with the exponent raised at or
/// above √2. Both give the same `e` and `m` for every positive normal float whose mantissa
/// bits are those of √2's or next to them, and for a sweep of the others; so `log2_normal`
/// keeps its bits.
#[test]
fn log2_reduction_is_the_earlier_one() {
    let earlier = |x: f32| -> (i32, f32) {
        let bits = x.to_bits() as i32;
        let exponent = (bits >> 23) - 127;
        let m = f32::from_bits(((bits & 0x007f_ffff) | 0x3f80_0000) as u32);
        if m >= std::f32::consts::SQRT_2 {
            (exponent + 1, m * 0.5)
        } else {
            (exponent, m)
        }
    };
    let now = |x: f32| -> (i32, f32) {
        let bits = x.to_bits() as i32;
        let exponent = bits.wrapping_sub(0x3f35_04f3) >> 23;
        (
            exponent,
            f32::from_bits(bits.wrapping_sub(exponent << 23) as u32),
        )
    };
    let sqrt2_mantissa = std::f32::consts::SQRT_2.to_bits() & 0x007f_ffff;
    let mut rng = Rng(7);
    for biased in 1u32..=254 {
        let near = (sqrt2_mantissa - 4..sqrt2_mantissa + 4).chain([0, 1, 0x007f_ffff]);
        let swept = (0..64).map(|_| rng.range(0.0, 8_388_607.0) as u32);
        for mantissa in near.chain(swept) {
            let x = f32::from_bits(biased << 23 | mantissa);
            let (e0, m0) = earlier(x);
            let (e1, m1) = now(x);
            assert_eq!((e0, m0.to_bits()), (e1, m1.to_bits()), "{x:e}");
        }
    }
    // The lane `log2` of one float per exponent, at its mantissa nearest √2, against the
    // polynomial on the earlier reduction (same steps, plain `f32`).
    for biased in 1u32..=254 {
        let x = f32::from_bits(biased << 23 | sqrt2_mantissa);
        let got = dispatch(Isa::Scalar, Log2([x; 8]))[0];
        let (e, m) = earlier(x);
        let t = m - 1.0;
        const P: [f32; 7] = LOG2_POLYNOMIAL;
        let (t2, t4) = (t * t, t * t * (t * t));
        let low = (P[0] + P[1] * t) + t2 * (P[2] + P[3] * t);
        let high = (P[4] + P[5] * t) + t2 * P[6];
        let expected = e as f32 + t * (low + t4 * high);
        assert_eq!(got.to_bits(), expected.to_bits(), "{x:e}");
    }
}

/// The polynomial `log2` is at most 0 exactly when its argument is at most 1 (the sampler
/// skips the level of detail of magnified lanes on it): over the 2^21 floats on each side of
/// 1 and the 2^13 on each side of every power of two.
#[test]
fn log2_polynomial_is_positive_exactly_above_one() {
    let check = |centre: f32, reach: u32| {
        let first = centre.to_bits() - reach.min(centre.to_bits() - f32::MIN_POSITIVE.to_bits());
        let last = centre.to_bits() + reach;
        let bits: Vec<u32> = (first..last).collect();
        for chunk in bits.chunks_exact(8) {
            let x: [f32; 8] = std::array::from_fn(|k| f32::from_bits(chunk[k]));
            let log2 = dispatch(Isa::Scalar, Log2(x));
            for k in 0..8 {
                assert_eq!(log2[k] <= 0.0, x[k] <= 1.0, "log2 {} = {}", x[k], log2[k]);
            }
        }
    };
    check(1.0, 1 << 21);
    for exponent in -125..=127 {
        check(2f32.powi(exponent), 1 << 13);
    }
}

/// How far the lane sampler may be from the scalar one: each of the three fixed-point steps
/// (row, column, level) rounds its product and its weight by half a unit of 1/32640 or
/// 1/32768, and an sRGB texel is half a unit from its exact decode: 3.5 units, 1.1e-4.
const FIXED_POINT_TOLERANCE: f32 = 1.1e-4;

#[test]
fn lanes_agree_with_the_scalar_sampler_for_every_wrap_and_filter() {
    let mut rng = Rng(7);
    let isas: Vec<Isa> = Isa::supported().collect();
    for (texture, tolerance) in [
        (
            noise_texture(16, 8, ColorSpace::Srgb),
            FIXED_POINT_TOLERANCE,
        ),
        (
            noise_texture(5, 3, ColorSpace::Linear),
            FIXED_POINT_TOLERANCE,
        ),
        (noise_texture(1, 1, ColorSpace::Srgb), FIXED_POINT_TOLERANCE),
    ] {
        for sampler in samplers() {
            for query in queries(&mut rng, 12) {
                let kernel = || Sample {
                    texture: &texture,
                    sampler,
                    query,
                    bytes: false,
                };
                let lanes = dispatch(Isa::Scalar, kernel());
                for &isa in &isas {
                    let got = dispatch(isa, kernel());
                    assert!(
                        got.map(|c| c.map(f32::to_bits)) == lanes.map(|c| c.map(f32::to_bits)),
                        "{isa} differs from scalar lanes: {sampler:?} {query:?}"
                    );
                }
                for k in (0..8).filter(|k| query.active & (1 << k) != 0) {
                    let expected = scalar_reference(&texture, &sampler, &query, k);
                    let got = Vec4::new(lanes[0][k], lanes[1][k], lanes[2][k], lanes[3][k]);
                    // Where λ sits on a level boundary the two may pick neighbouring
                    // levels; compare against both sides of the boundary then.
                    let close = (got - expected).abs().max_element() <= tolerance;
                    let lod = texture.lod(query.duv_dx[k], query.duv_dy[k]);
                    let near_boundary = (lod - lod.round()).abs() < 1e-4
                        || (lod + 0.5 - (lod + 0.5).round()).abs() < 1e-4;
                    let either_side = near_boundary
                        && [lod - 2e-4, lod + 2e-4].into_iter().any(|l| {
                            let e = texture.sample_lod(&sampler, query.uv[k], l);
                            (got - e).abs().max_element() <= 1e-3
                        });
                    assert!(
                        close || either_side,
                        "lane {k}: {got} vs scalar {expected} (λ {lod}), {sampler:?} {query:?}"
                    );
                }
            }
        }
    }
}

/// An sRGB texture sampled from its decoded copy and from its bytes through the table gives
/// the same bits, on every instruction set, wrap mode and filter.
#[test]
fn decoded_copy_and_bytes_sample_alike() {
    let mut rng = Rng(11);
    let isas: Vec<Isa> = Isa::supported().collect();
    for texture in [
        noise_texture(16, 8, ColorSpace::Srgb),
        noise_texture(7, 5, ColorSpace::Srgb),
    ] {
        assert!(matches!(texture.lane_texels(), TexelSource::Linear15(_)));
        for sampler in samplers() {
            for query in queries(&mut rng, 6) {
                let kernel = |bytes| Sample {
                    texture: &texture,
                    sampler,
                    query,
                    bytes,
                };
                let copy = dispatch(Isa::Scalar, kernel(false));
                for &isa in &isas {
                    for bytes in [false, true] {
                        let got = dispatch(isa, kernel(bytes));
                        assert!(
                            got.map(|c| c.map(f32::to_bits)) == copy.map(|c| c.map(f32::to_bits)),
                            "{isa}, bytes {bytes}: {sampler:?} {query:?}"
                        );
                    }
                }
            }
        }
    }
}

/// Only sRGB textures up to 2048 × 2048 keep a decoded copy (8 bytes a texel, rows one
/// texel longer), and its every row ends with its first texel again.
#[test]
fn decoded_copy_is_kept_for_small_srgb_textures_only() {
    let srgb = noise_texture(4, 4, ColorSpace::Srgb);
    let before = srgb.memory_bytes();
    srgb.prepare_lane_sampling();
    let copy = srgb.linear15().expect("a decoded copy");
    let padded: usize = srgb
        .levels()
        .map(|l| (l.width as usize + 1) * l.height as usize)
        .sum();
    assert_eq!(copy.words.len(), 2 * padded);
    assert_eq!(
        srgb.memory_bytes() - before,
        4 * (2 * padded + srgb.level_count())
    );
    for (level, &offset) in srgb.levels().zip(&copy.offsets) {
        let row_length = level.width as usize + 1;
        for y in 0..level.height {
            let row = 2 * (offset as usize + y as usize * row_length);
            let word = |x: usize| &copy.words[row + 2 * x..][..2];
            for x in 0..level.width {
                assert_eq!(word(x as usize), srgb_texel_to_linear15(level.packed(x, y)));
            }
            assert_eq!(word(level.width as usize), word(0));
        }
    }
    let linear = noise_texture(4, 4, ColorSpace::Linear);
    linear.prepare_lane_sampling();
    assert!(linear.linear15().is_none());
    let wide = Texture::from_rgba8(4097, 1024, &vec![7; 4097 * 1024 * 4], ColorSpace::Srgb)
        .expect("texture");
    assert!(wide.linear15().is_none());
    assert!(matches!(wide.lane_texels(), TexelSource::SrgbBytes(..)));
}

#[test]
fn nan_and_huge_coordinates_are_defined() {
    let texture = noise_texture(8, 8, ColorSpace::Srgb);
    let big = [
        1e30f32,
        -1e30,
        3e38,
        -3e38,
        8_388_609.0,
        -16_777_217.0,
        1e9,
        0.5,
    ];
    let mut uv = big.map(|x| Vec2::new(x, 0.25));
    uv[7] = Vec2::new(f32::NAN, 0.5);
    uv[6] = Vec2::new(0.5, f32::INFINITY);
    let query = Query {
        uv,
        duv_dx: [Vec2::new(f32::NAN, 0.0); 8],
        duv_dy: [Vec2::new(0.0, f32::INFINITY); 8],
        active: 0xff,
    };
    for sampler in samplers() {
        for isa in Isa::supported() {
            let got = dispatch(
                isa,
                Sample {
                    texture: &texture,
                    sampler,
                    query,
                    bytes: false,
                },
            );
            for (k, uv) in query.uv.iter().enumerate() {
                let texel = Vec4::new(got[0][k], got[1][k], got[2][k], got[3][k]);
                let expected = scalar_reference(&texture, &sampler, &query, k);
                assert!(texel.is_finite(), "{isa} lane {k} at {uv}: {texel}");
                assert!(
                    (texel - expected).abs().max_element() <= FIXED_POINT_TOLERANCE,
                    "{isa} lane {k}: {texel} vs {expected}, {sampler:?}"
                );
            }
            assert_eq!([got[0][7], got[3][7], got[0][6], got[3][6]], [0.0; 4]);
        }
    }
}

#[test]
fn inactive_lanes_are_not_sampled() {
    let texture = noise_texture(4, 4, ColorSpace::Linear);
    let query = Query {
        uv: [Vec2::splat(0.5); 8],
        duv_dx: [Vec2::ZERO; 8],
        duv_dy: [Vec2::ZERO; 8],
        active: 0,
    };
    let got = dispatch(
        Isa::Scalar,
        Sample {
            texture: &texture,
            sampler: Sampler::default(),
            query,
            bytes: false,
        },
    );
    assert_eq!(got, [[0.0; 8]; 4]);
}

/// Each lane's level offset and size through [`Texture::level_extents`].
struct Extents<'a> {
    texture: &'a Texture,
    source: TexelSource<'a>,
    levels: [i32; 8],
}

impl LaneKernel for Extents<'_> {
    type Output = [[i32; 8]; 3];
    #[inline(always)]
    fn run<L: Lanes>(self, lanes: L) -> [[i32; 8]; 3] {
        let layout = self.texture.level_layout(self.source);
        let level = lanes.i32_from_array(self.levels);
        let (offset, width, height) = self.texture.level_extents::<L>(layout, level);
        [offset.to_array(), width.to_array(), height.to_array()]
    }
}

/// The level tables looked up lane-wide give every level's offset (in the bytes and in the
/// decoded copy) and size, in any mix of levels per row, on every instruction set; the
/// tables repeat the last level past it.
#[test]
fn level_extents_are_the_level_table() {
    // 512 × 8: ten levels, the height clamped at 1 from level 3 on.
    let texture = noise_texture(512, 8, ColorSpace::Srgb);
    let copy = texture.linear15().expect("decoded copy");
    let count = texture.level_count();
    assert_eq!(count, 10);
    let expected = |source_is_copy: bool, level: usize| {
        let l = level.min(count - 1);
        let offset = if source_is_copy {
            copy.offsets[l]
        } else {
            texture.levels.offsets[l]
        };
        [
            offset as i32,
            texture.levels.widths[l] as i32,
            texture.levels.heights[l] as i32,
        ]
    };
    for isa in Isa::ALL.into_iter().filter(|isa| isa.is_supported()) {
        for first in 0..16 {
            let levels: [i32; 8] = std::array::from_fn(|k| ((first + 3 * k) % 16) as i32);
            for (is_copy, source) in [
                (true, TexelSource::Linear15(copy)),
                (false, TexelSource::LinearBytes(&texture.texels)),
            ] {
                let got = dispatch(
                    isa,
                    Extents {
                        texture: &texture,
                        source,
                        levels,
                    },
                );
                for (k, &level) in levels.iter().enumerate() {
                    let lane = [got[0][k], got[1][k], got[2][k]];
                    assert_eq!(lane, expected(is_copy, level as usize), "{isa} lane {k}");
                }
            }
        }
    }
}
