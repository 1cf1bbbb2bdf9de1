//! The AVX2 implementation: one 256-bit register per value.
//!
//! Every method is `#[inline(always)]` and calls the intrinsics inside `unsafe` blocks whose
//! justification is the same: a value of these types exists only if an [`Avx2`] token was made,
//! and [`Avx2::new`] makes one only after detecting AVX2 at run time. The `fma` feature is never
//! enabled, so a multiply followed by an add stays two instructions (two roundings).

use std::arch::x86_64::*;
use std::fmt;
use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Not, Sub};

use super::{F32x8, Footprint15, I32x8, Isa, LaneKernel, Lanes, Mask8};

/// The AVX2 implementation's token: proof that this CPU runs AVX2.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Avx2 {
    _detected: (),
}

impl Avx2 {
    /// The token, if this CPU supports AVX2 and `popcnt` (runtime detection, cached by `std`;
    /// every AVX2 CPU has `popcnt`, which kernels use to count mask bits).
    #[inline(always)]
    pub fn new() -> Option<Avx2> {
        if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("popcnt") {
            Some(Avx2 { _detected: () })
        } else {
            None
        }
    }
}

/// Runs `kernel` compiled for AVX2: the kernel and the lane methods, all `#[inline(always)]`,
/// are inlined into this `#[target_feature]` function.
#[inline]
pub(super) fn run<K: LaneKernel>(token: Avx2, kernel: K) -> K::Output {
    #[target_feature(enable = "avx2,popcnt")]
    unsafe fn run_avx2<K: LaneKernel>(token: Avx2, kernel: K) -> K::Output {
        kernel.run(token)
    }
    // SAFETY: `token` exists, so AVX2 and `popcnt` were detected on this CPU.
    unsafe { run_avx2(token, kernel) }
}

/// Whether this CPU has AVX-512F and AVX-512VL (runtime detection, cached by `std`), which
/// [`run_avx512`] needs beside the AVX2 token.
#[inline]
pub(super) fn has_avx512() -> bool {
    is_x86_feature_detected!("avx512f") && is_x86_feature_detected!("avx512vl")
}

/// Runs `kernel` with the AVX2 lanes compiled with AVX-512F and AVX-512VL enabled: the same
/// 256-bit operations on the same lane types, encoded with EVEX and given 32 vector registers
/// instead of 16 (fewer spills in kernels with many live values, such as the sampler). No
/// 512-bit lane type exists and the `fma` feature stays off, so every result is the AVX2 one.
/// On a CPU without AVX-512F and AVX-512VL it runs [`run`]'s AVX2 code.
#[inline]
pub(super) fn run_avx512<K: LaneKernel>(token: Avx2, kernel: K) -> K::Output {
    #[target_feature(enable = "avx2,popcnt,avx512f,avx512vl")]
    unsafe fn run_avx512_vl<K: LaneKernel>(token: Avx2, kernel: K) -> K::Output {
        kernel.run(token)
    }
    if !has_avx512() {
        return run(token, kernel);
    }
    // SAFETY: `token` exists, so AVX2 and `popcnt` were detected, and `has_avx512` detected
    // AVX-512F and AVX-512VL on this CPU.
    unsafe { run_avx512_vl(token, kernel) }
}

/// 8 × `f32` in a `__m256`.
#[derive(Clone, Copy)]
pub struct Avx2F32(__m256);

/// 8 × `i32` in a `__m256i`.
#[derive(Clone, Copy)]
pub struct Avx2I32(__m256i);

/// 8 lane booleans as all-ones / all-zeros 32-bit lanes of a `__m256`.
#[derive(Clone, Copy)]
pub struct Avx2Mask(__m256);

/// Wraps intrinsic calls that need AVX/AVX2: sound because a token or a lane value exists.
macro_rules! avx {
    ($($body:tt)*) => {
        // SAFETY: AVX2 (which implies AVX) was detected before any `Avx2` token, and therefore
        // any value of this module, could be made; pointer arguments are checked by the caller.
        unsafe { $($body)* }
    };
}

impl fmt::Debug for Avx2F32 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_tuple("Avx2F32").field(&self.to_array()).finish()
    }
}

impl fmt::Debug for Avx2I32 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_tuple("Avx2I32").field(&self.to_array()).finish()
    }
}

impl fmt::Debug for Avx2Mask {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Avx2Mask({:#010b})", self.bits())
    }
}

impl Lanes for Avx2 {
    type F32 = Avx2F32;
    type I32 = Avx2I32;
    type Mask = Avx2Mask;

    #[inline(always)]
    fn isa(self) -> Isa {
        Isa::Avx2
    }
    #[inline(always)]
    fn splat_f32(self, v: f32) -> Avx2F32 {
        avx!(Avx2F32(_mm256_set1_ps(v)))
    }
    #[inline(always)]
    fn f32_from_array(self, a: [f32; 8]) -> Avx2F32 {
        // The pointer is to 8 readable f32.
        avx!(Avx2F32(_mm256_loadu_ps(a.as_ptr())))
    }
    #[inline(always)]
    fn load_f32(self, s: &[f32]) -> Avx2F32 {
        let s = &s[..8];
        avx!(Avx2F32(_mm256_loadu_ps(s.as_ptr())))
    }
    #[inline(always)]
    fn splat_i32(self, v: i32) -> Avx2I32 {
        avx!(Avx2I32(_mm256_set1_epi32(v)))
    }
    #[inline(always)]
    fn i32_from_array(self, a: [i32; 8]) -> Avx2I32 {
        avx!(Avx2I32(_mm256_loadu_si256(a.as_ptr().cast())))
    }
    #[inline(always)]
    fn load_i32(self, s: &[i32]) -> Avx2I32 {
        let s = &s[..8];
        avx!(Avx2I32(_mm256_loadu_si256(s.as_ptr().cast())))
    }
    #[inline(always)]
    fn lane_index(self) -> Avx2I32 {
        avx!(Avx2I32(_mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)))
    }
    #[inline(always)]
    fn mask_from_bits(self, bits: u8) -> Avx2Mask {
        avx!({
            let lane_bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
            let selected = _mm256_and_si256(_mm256_set1_epi32(i32::from(bits)), lane_bits);
            Avx2Mask(_mm256_castsi256_ps(_mm256_cmpeq_epi32(selected, lane_bits)))
        })
    }
    #[inline(always)]
    fn mask_all(self, value: bool) -> Avx2Mask {
        avx!(Avx2Mask(_mm256_castsi256_ps(_mm256_set1_epi32(
            -i32::from(value)
        ))))
    }
}

macro_rules! binary_ops {
    ($ty:ident, $($trait:ident $method:ident $intrinsic:ident;)*) => {$(
        impl $trait for $ty {
            type Output = $ty;
            #[inline(always)]
            fn $method(self, other: $ty) -> $ty {
                avx!($ty($intrinsic(self.0, other.0)))
            }
        }
    )*};
}

binary_ops!(Avx2F32,
    Add add _mm256_add_ps;
    Sub sub _mm256_sub_ps;
    Mul mul _mm256_mul_ps;
    Div div _mm256_div_ps;
);

binary_ops!(Avx2I32,
    Add add _mm256_add_epi32;
    Sub sub _mm256_sub_epi32;
    Mul mul _mm256_mullo_epi32;
    BitAnd bitand _mm256_and_si256;
    BitOr bitor _mm256_or_si256;
    BitXor bitxor _mm256_xor_si256;
);

impl Neg for Avx2F32 {
    type Output = Avx2F32;
    #[inline(always)]
    fn neg(self) -> Avx2F32 {
        avx!(Avx2F32(_mm256_xor_ps(self.0, _mm256_set1_ps(-0.0))))
    }
}

impl Not for Avx2I32 {
    type Output = Avx2I32;
    #[inline(always)]
    fn not(self) -> Avx2I32 {
        avx!(Avx2I32(_mm256_xor_si256(self.0, _mm256_set1_epi32(-1))))
    }
}

impl Avx2F32 {
    #[inline(always)]
    fn compare<const PREDICATE: i32>(self, other: Self) -> Avx2Mask {
        avx!(Avx2Mask(_mm256_cmp_ps::<PREDICATE>(self.0, other.0)))
    }
}

/// Reduces the 8 lanes of a `__m256` with the 128-bit operation `$op` in the shared tree
/// order: `(k, k + 4)`, then `(k, k + 2)`, then `(0, 1)`.
macro_rules! reduce {
    ($v:expr, $op:ident) => {
        avx!({
            let halves = $op(_mm256_castps256_ps128($v), _mm256_extractf128_ps::<1>($v));
            let pairs = $op(halves, _mm_movehl_ps(halves, halves));
            _mm_cvtss_f32($op(pairs, _mm_shuffle_ps::<0b01>(pairs, pairs)))
        })
    };
}

impl F32x8 for Avx2F32 {
    type Lanes = Avx2;

    #[inline(always)]
    fn lanes(self) -> Avx2 {
        Avx2 { _detected: () }
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        avx!(Avx2F32(_mm256_min_ps(self.0, other.0)))
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        avx!(Avx2F32(_mm256_max_ps(self.0, other.0)))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        avx!(Avx2F32(_mm256_sqrt_ps(self.0)))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        avx!(Avx2F32(_mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0)))
    }
    #[inline(always)]
    fn floor(self) -> Self {
        avx!(Avx2F32(_mm256_round_ps::<
            { _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC },
        >(self.0)))
    }
    #[inline(always)]
    fn round_ties_even(self) -> Self {
        avx!(Avx2F32(_mm256_round_ps::<
            { _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC },
        >(self.0)))
    }
    #[inline(always)]
    fn simd_lt(self, other: Self) -> Avx2Mask {
        self.compare::<_CMP_LT_OQ>(other)
    }
    #[inline(always)]
    fn simd_le(self, other: Self) -> Avx2Mask {
        self.compare::<_CMP_LE_OQ>(other)
    }
    #[inline(always)]
    fn simd_gt(self, other: Self) -> Avx2Mask {
        self.compare::<_CMP_GT_OQ>(other)
    }
    #[inline(always)]
    fn simd_ge(self, other: Self) -> Avx2Mask {
        self.compare::<_CMP_GE_OQ>(other)
    }
    #[inline(always)]
    fn simd_eq(self, other: Self) -> Avx2Mask {
        self.compare::<_CMP_EQ_OQ>(other)
    }
    #[inline(always)]
    fn simd_ne(self, other: Self) -> Avx2Mask {
        self.compare::<_CMP_NEQ_UQ>(other)
    }
    #[inline(always)]
    fn to_array(self) -> [f32; 8] {
        let mut out = [0.0; 8];
        // The pointer is to 8 writable f32.
        avx!(_mm256_storeu_ps(out.as_mut_ptr(), self.0));
        out
    }
    #[inline(always)]
    fn store(self, out: &mut [f32]) {
        let out = &mut out[..8];
        avx!(_mm256_storeu_ps(out.as_mut_ptr(), self.0));
    }
    #[inline(always)]
    fn store_masked(self, mask: Avx2Mask, out: &mut [f32]) {
        let out = &mut out[..8];
        avx!({
            let old = _mm256_loadu_ps(out.as_ptr());
            _mm256_storeu_ps(out.as_mut_ptr(), _mm256_blendv_ps(old, self.0, mask.0));
        });
    }
    #[inline(always)]
    fn to_i32_trunc(self) -> Avx2I32 {
        avx!(Avx2I32(_mm256_cvttps_epi32(self.0)))
    }
    #[inline(always)]
    fn to_i32_floor(self) -> Avx2I32 {
        self.floor().to_i32_trunc()
    }
    #[inline(always)]
    fn to_bits(self) -> Avx2I32 {
        avx!(Avx2I32(_mm256_castps_si256(self.0)))
    }
    #[inline(always)]
    fn from_bits(bits: Avx2I32) -> Self {
        avx!(Avx2F32(_mm256_castsi256_ps(bits.0)))
    }
    #[inline(always)]
    fn extract(self, k: usize) -> f32 {
        self.to_array()[k]
    }
    #[inline(always)]
    fn permute(self, index: Avx2I32) -> Avx2F32 {
        avx!(Avx2F32(_mm256_permutevar8x32_ps(self.0, index.0)))
    }
    #[inline(always)]
    fn reduce_min(self) -> f32 {
        reduce!(self.0, _mm_min_ps)
    }
    #[inline(always)]
    fn reduce_max(self) -> f32 {
        reduce!(self.0, _mm_max_ps)
    }
}

impl I32x8 for Avx2I32 {
    type Lanes = Avx2;

    #[inline(always)]
    fn lanes(self) -> Avx2 {
        Avx2 { _detected: () }
    }
    #[inline(always)]
    fn shl<const N: i32>(self) -> Self {
        const { assert!(N >= 0 && N < 32, "shift count must be in 0..32") };
        avx!(Avx2I32(_mm256_slli_epi32::<N>(self.0)))
    }
    #[inline(always)]
    fn shr_arith<const N: i32>(self) -> Self {
        const { assert!(N >= 0 && N < 32, "shift count must be in 0..32") };
        avx!(Avx2I32(_mm256_srai_epi32::<N>(self.0)))
    }
    #[inline(always)]
    fn shr_logical<const N: i32>(self) -> Self {
        const { assert!(N >= 0 && N < 32, "shift count must be in 0..32") };
        avx!(Avx2I32(_mm256_srli_epi32::<N>(self.0)))
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        avx!(Avx2I32(_mm256_min_epi32(self.0, other.0)))
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        avx!(Avx2I32(_mm256_max_epi32(self.0, other.0)))
    }
    #[inline(always)]
    fn simd_eq(self, other: Self) -> Avx2Mask {
        avx!(Avx2Mask(_mm256_castsi256_ps(_mm256_cmpeq_epi32(
            self.0, other.0
        ))))
    }
    #[inline(always)]
    fn simd_gt(self, other: Self) -> Avx2Mask {
        avx!(Avx2Mask(_mm256_castsi256_ps(_mm256_cmpgt_epi32(
            self.0, other.0
        ))))
    }
    #[inline(always)]
    fn simd_lt(self, other: Self) -> Avx2Mask {
        other.simd_gt(self)
    }
    #[inline(always)]
    fn to_f32(self) -> Avx2F32 {
        avx!(Avx2F32(_mm256_cvtepi32_ps(self.0)))
    }
    #[inline(always)]
    fn to_array(self) -> [i32; 8] {
        let mut out = [0; 8];
        avx!(_mm256_storeu_si256(out.as_mut_ptr().cast(), self.0));
        out
    }
    #[inline(always)]
    fn store(self, out: &mut [i32]) {
        let out = &mut out[..8];
        avx!(_mm256_storeu_si256(out.as_mut_ptr().cast(), self.0));
    }
    #[inline(always)]
    fn gather_u32(self, table: &[u32]) -> Self {
        let Some(last) = table.len().checked_sub(1) else {
            return avx!(Avx2I32(_mm256_setzero_si256()));
        };
        let last = i32::try_from(last).unwrap_or(i32::MAX);
        // Every clamped index is in `0..table.len()`, so every 4-byte read is inside `table`.
        avx!({
            let index = _mm256_min_epi32(
                _mm256_max_epi32(self.0, _mm256_setzero_si256()),
                _mm256_set1_epi32(last),
            );
            Avx2I32(_mm256_i32gather_epi32::<4>(table.as_ptr().cast(), index))
        })
    }
    #[inline(always)]
    fn extract(self, k: usize) -> i32 {
        self.to_array()[k]
    }
    #[inline(always)]
    fn sign_bits(self) -> u8 {
        avx!(_mm256_movemask_ps(_mm256_castsi256_ps(self.0)) as u8)
    }
}

impl Mask8 for Avx2Mask {
    type Lanes = Avx2;

    #[inline(always)]
    fn lanes(self) -> Avx2 {
        Avx2 { _detected: () }
    }
    #[inline(always)]
    fn and(self, other: Self) -> Self {
        avx!(Avx2Mask(_mm256_and_ps(self.0, other.0)))
    }
    #[inline(always)]
    fn or(self, other: Self) -> Self {
        avx!(Avx2Mask(_mm256_or_ps(self.0, other.0)))
    }
    #[inline(always)]
    fn xor(self, other: Self) -> Self {
        avx!(Avx2Mask(_mm256_xor_ps(self.0, other.0)))
    }
    #[inline(always)]
    fn not(self) -> Self {
        avx!(Avx2Mask(_mm256_xor_ps(
            self.0,
            _mm256_castsi256_ps(_mm256_set1_epi32(-1))
        )))
    }
    #[inline(always)]
    fn and_not(self, other: Self) -> Self {
        // `andnot(a, b)` is `!a & b`.
        avx!(Avx2Mask(_mm256_andnot_ps(other.0, self.0)))
    }
    #[inline(always)]
    fn any(self) -> bool {
        self.bits() != 0
    }
    #[inline(always)]
    fn all(self) -> bool {
        self.bits() == 0xff
    }
    #[inline(always)]
    fn none(self) -> bool {
        self.bits() == 0
    }
    #[inline(always)]
    fn bits(self) -> u8 {
        avx!(_mm256_movemask_ps(self.0) as u8)
    }
    #[inline(always)]
    fn count(self) -> u32 {
        self.bits().count_ones()
    }
    #[inline(always)]
    fn select_f32(self, if_true: Avx2F32, if_false: Avx2F32) -> Avx2F32 {
        avx!(Avx2F32(_mm256_blendv_ps(if_false.0, if_true.0, self.0)))
    }
    #[inline(always)]
    fn select_i32(self, if_true: Avx2I32, if_false: Avx2I32) -> Avx2I32 {
        avx!(Avx2I32(_mm256_castps_si256(_mm256_blendv_ps(
            _mm256_castsi256_ps(if_false.0),
            _mm256_castsi256_ps(if_true.0),
            self.0
        ))))
    }
}

// --- TexelGather: the texture sampler's lane operations ---

impl super::TexelGather for Avx2I32 {
    #[inline(always)]
    fn gather_u32_pair(self, table: &[u32]) -> (Self, Self) {
        let Some(last) = table.len().checked_sub(2) else {
            return avx!((
                Avx2I32(_mm256_setzero_si256()),
                Avx2I32(_mm256_setzero_si256())
            ));
        };
        let last = i32::try_from(last).unwrap_or(i32::MAX);
        avx!({
            // Every clamped index is in `0..=table.len() - 2`, so every 8-byte read (entries
            // `c` and `c + 1`) is inside `table`.
            let index = _mm256_min_epi32(
                _mm256_max_epi32(self.0, _mm256_setzero_si256()),
                _mm256_set1_epi32(last),
            );
            let base: *const i64 = table.as_ptr().cast();
            // [a0 b0 a1 b1 | a2 b2 a3 b3] and [a4 b4 a5 b5 | a6 b6 a7 b7] (a = table[c],
            // b = table[c + 1], one 64-bit element per lane).
            let low = _mm256_castsi256_ps(_mm256_i32gather_epi64::<4>(
                base,
                _mm256_castsi256_si128(index),
            ));
            let high = _mm256_castsi256_ps(_mm256_i32gather_epi64::<4>(
                base,
                _mm256_extracti128_si256::<1>(index),
            ));
            // [a0 a1 a4 a5 | a2 a3 a6 a7], then the 64-bit quarters in the order 0, 2, 1, 3.
            let first = _mm256_castps_si256(_mm256_shuffle_ps::<0b10_00_10_00>(low, high));
            let second = _mm256_castps_si256(_mm256_shuffle_ps::<0b11_01_11_01>(low, high));
            (
                Avx2I32(_mm256_permute4x64_epi64::<0b11_01_10_00>(first)),
                Avx2I32(_mm256_permute4x64_epi64::<0b11_01_10_00>(second)),
            )
        })
    }

    #[inline(always)]
    fn gather_u32_quad(self, table: &[u32]) -> [Self; 4] {
        let Some(last) = table.len().checked_sub(4) else {
            return avx!([Avx2I32(_mm256_setzero_si256()); 4]);
        };
        let last = i32::try_from(last).unwrap_or(i32::MAX);
        avx!({
            let index = _mm256_min_epi32(
                _mm256_max_epi32(self.0, _mm256_setzero_si256()),
                _mm256_set1_epi32(last),
            );
            let mut buffer = [0i32; 8];
            let at = lane_indices(index, &mut buffer);
            // Every clamped index is in `0..=table.len() - 4`, so every 16-byte read (entries
            // `c..c + 4`) is inside `table`; `c ≥ 0`, so the `usize` conversion is exact.
            let row = |k: usize| -> __m128i {
                _mm_loadu_si128(table.as_ptr().add(at[k] as usize).cast())
            };
            // Lane `k` in the low half and lane `k + 4` in the high half: [w0 w1 w2 w3] each.
            let r0 = _mm256_inserti128_si256::<1>(_mm256_castsi128_si256(row(0)), row(4));
            let r1 = _mm256_inserti128_si256::<1>(_mm256_castsi128_si256(row(1)), row(5));
            let r2 = _mm256_inserti128_si256::<1>(_mm256_castsi128_si256(row(2)), row(6));
            let r3 = _mm256_inserti128_si256::<1>(_mm256_castsi128_si256(row(3)), row(7));
            // A 4 × 4 transpose in each half: word `i` of lanes 0–3 (low) and 4–7 (high).
            let t0 = _mm256_unpacklo_epi32(r0, r1);
            let t1 = _mm256_unpacklo_epi32(r2, r3);
            let t2 = _mm256_unpackhi_epi32(r0, r1);
            let t3 = _mm256_unpackhi_epi32(r2, r3);
            [
                Avx2I32(_mm256_unpacklo_epi64(t0, t1)),
                Avx2I32(_mm256_unpackhi_epi64(t0, t1)),
                Avx2I32(_mm256_unpacklo_epi64(t2, t3)),
                Avx2I32(_mm256_unpackhi_epi64(t2, t3)),
            ]
        })
    }

    #[inline(always)]
    fn filter15(
        words: &[u32],
        first: Footprint15<Self>,
        second: Option<(Footprint15<Self>, Self)>,
    ) -> [Self; 4] {
        let Some(last) = words.len().checked_sub(4) else {
            return avx!([Avx2I32(_mm256_setzero_si256()); 4]);
        };
        let last = i32::try_from(last).unwrap_or(i32::MAX);
        let level = filter_level15(words, last, first);
        let packed = match second {
            None => level,
            Some((footprint, weight)) => {
                let other = filter_level15(words, last, footprint);
                let [w01, w23] = packed_weights15(weight.0);
                [
                    lerp15_packed(level[0], other[0], w01),
                    lerp15_packed(level[1], other[1], w23),
                ]
            }
        };
        unpack_packed15(packed)
    }

    #[inline(always)]
    fn lookup_rgb(self, table: &[u32; 256]) -> [Self; 3] {
        let byte = avx!(_mm256_set1_epi32(0xff));
        let base: *const i32 = table.as_ptr().cast();
        // Every index is a byte, below the table's 256 entries: no clamping needed. (24 scalar
        // loads instead: 25-37% more instructions per frame, no faster on AMD Zen.)
        avx!([
            Avx2I32(_mm256_i32gather_epi32::<4>(
                base,
                _mm256_and_si256(self.0, byte)
            )),
            Avx2I32(_mm256_i32gather_epi32::<4>(
                base,
                _mm256_and_si256(_mm256_srli_epi32::<8>(self.0), byte),
            )),
            Avx2I32(_mm256_i32gather_epi32::<4>(
                base,
                _mm256_and_si256(_mm256_srli_epi32::<16>(self.0), byte),
            )),
        ])
    }
}

// The packed fixed-point filter of `TexelGather::filter15`. A texel of a decoded copy is four
// 16-bit channels (8 bytes) and a row's two neighbouring texels are 16 bytes: one load per lane.
// Lanes are held in pairs, [lane k, lane k + 1 | lane k + 4, lane k + 5] (k = 0 in the first
// register of a pair, 2 in the second), one 64-bit quarter (four channels) per lane, so that
// every step is one 16-bit operation on two registers and the result unpacks to lane order.

/// `a + mulhrs(b − a, w)` per 16-bit element: `lerp15` (texel_gather.rs) for values and weights
/// in `0..=32767` (`vpmulhrsw` is `((x·w >> 14) + 1) >> 1`, which equals `(x·w + 2^14) >> 15`,
/// and every result fits 16 bits).
#[inline(always)]
fn lerp15_packed(a: __m256i, b: __m256i, w: __m256i) -> __m256i {
    avx!(_mm256_add_epi16(
        a,
        _mm256_mulhrs_epi16(_mm256_sub_epi16(b, a), w)
    ))
}

/// Per-lane weights (`0..=32767` in each 32-bit lane) repeated over the four 16-bit channels of
/// each lane, in the two registers' lane order.
#[inline(always)]
fn packed_weights15(weight: __m256i) -> [__m256i; 2] {
    avx!({
        let both = _mm256_or_si256(weight, _mm256_slli_epi32::<16>(weight));
        [
            _mm256_permutevar8x32_epi32(both, _mm256_setr_epi32(0, 0, 1, 1, 4, 4, 5, 5)),
            _mm256_permutevar8x32_epi32(both, _mm256_setr_epi32(2, 2, 3, 3, 6, 6, 7, 7)),
        ]
    })
}

/// The eight lanes of `index` as scalars for per-lane loads, through memory (`buffer`): one
/// 32-byte store, then each lane's 4-byte load (forwarded from the store). Left to itself, the
/// compiler extracts them from the register instead (`vmovd`, `vextracti128`, six `vpextrd`:
/// 15 µops, most of them on the shuffle port that the filter's unpacks and the sampler's
/// permutes also need); [`std::hint::black_box`] keeps the array in memory. It changes no value
/// and no instruction count. Measured (`avx512`, two threads,
/// 6 alternating rounds of every scene): cube-textured −8.6%, `paper-c2` −9.9%, `c4` −6.4%,
/// spot −3.9%, near-clip −3.7%.
#[inline(always)]
fn lane_indices(index: __m256i, buffer: &mut [i32; 8]) -> &[i32; 8] {
    avx!(_mm256_storeu_si256(buffer.as_mut_ptr().cast(), index));
    std::hint::black_box(buffer)
}

/// The two texels of one row per lane, from texel index `index` (the word index `2 · index`,
/// wrapping, clamped to `0..=last` as `gather_u32_quad` clamps it), as `[left, right]` in the
/// two registers' lane order.
#[inline(always)]
fn load_row15(words: &[u32], last: i32, index: __m256i) -> [[__m256i; 2]; 2] {
    avx!({
        let word = _mm256_min_epi32(
            _mm256_max_epi32(_mm256_add_epi32(index, index), _mm256_setzero_si256()),
            _mm256_set1_epi32(last),
        );
        let mut buffer = [0i32; 8];
        let at = lane_indices(word, &mut buffer);
        // Every clamped index is in `0..=words.len() - 4`, so every 16-byte read (words
        // `c..c + 4`) is inside `words`; `c ≥ 0`, so the `usize` conversion is exact.
        let p = words.as_ptr();
        let load = |k: usize| -> __m128i { _mm_loadu_si128(p.add(at[k] as usize).cast()) };
        // Lane `k` in the low half and lane `k + 4` in the high half: [left | right] each.
        let r0 = _mm256_inserti128_si256::<1>(_mm256_castsi128_si256(load(0)), load(4));
        let r1 = _mm256_inserti128_si256::<1>(_mm256_castsi128_si256(load(1)), load(5));
        let r2 = _mm256_inserti128_si256::<1>(_mm256_castsi128_si256(load(2)), load(6));
        let r3 = _mm256_inserti128_si256::<1>(_mm256_castsi128_si256(load(3)), load(7));
        [
            [_mm256_unpacklo_epi64(r0, r1), _mm256_unpacklo_epi64(r2, r3)],
            [_mm256_unpackhi_epi64(r0, r1), _mm256_unpackhi_epi64(r2, r3)],
        ]
    })
}

/// One level's bilinear filter (`filter_level15_reference`), packed.
#[inline(always)]
fn filter_level15(words: &[u32], last: i32, f: Footprint15<Avx2I32>) -> [__m256i; 2] {
    let alpha = packed_weights15(f.alpha.0);
    let beta = packed_weights15(f.beta.0);
    let [left, right] = load_row15(words, last, f.top.0);
    let top = [
        lerp15_packed(left[0], right[0], alpha[0]),
        lerp15_packed(left[1], right[1], alpha[1]),
    ];
    let [left, right] = load_row15(words, last, f.bottom.0);
    let bottom = [
        lerp15_packed(left[0], right[0], alpha[0]),
        lerp15_packed(left[1], right[1], alpha[1]),
    ];
    [
        lerp15_packed(top[0], bottom[0], beta[0]),
        lerp15_packed(top[1], bottom[1], beta[1]),
    ]
}

/// Packed channels (lanes [0, 1 | 4, 5] and [2, 3 | 6, 7]) to red, green, blue and alpha lanes
/// in lane order, zero-extended to 32 bits: two shuffles of 32-bit words, then
/// [`super::unpack_words15`]'s masks and shifts (not 16-bit unpacks, which would take the
/// shuffle port the loads' unpacks also use).
#[inline(always)]
fn unpack_packed15([v01, v23]: [__m256i; 2]) -> [Avx2I32; 4] {
    avx!({
        // A lane's texel is the words `r | g << 16`, `b | a << 16`: words 0 and 2 of each half
        // are its lanes' `rg`, words 1 and 3 their `ba`. [rg0 rg1 rg2 rg3 | rg4 .. rg7] and
        // the same for `ba`.
        let (v01, v23) = (_mm256_castsi256_ps(v01), _mm256_castsi256_ps(v23));
        let rg = _mm256_castps_si256(_mm256_shuffle_ps::<0b10_00_10_00>(v01, v23));
        let ba = _mm256_castps_si256(_mm256_shuffle_ps::<0b11_01_11_01>(v01, v23));
        super::unpack_words15::<Avx2>(Avx2I32(rg), Avx2I32(ba))
    })
}
