//! The SSE2 and SSE4.1 implementations: two 128-bit halves per value.
//!
//! One set of types serves both levels, parameterised by the token ([`Sse2`] or [`Sse41`]);
//! where SSE4.1 has a better instruction (`roundps`, `blendvps`, `pmulld`, `pminsd`/`pmaxsd`)
//! the method branches on the constant [`SseLevel::SSE41`], so each level compiles to straight
//! code. The SSE2 fallbacks are exact: rounding adds and subtracts 2²³ (which rounds to the
//! nearest even integer in the default rounding mode) for magnitudes below 2²³, where every
//! larger float is already an integer.
//!
//! SSE2 is part of the x86-64 baseline. Its intrinsics are wrapped in [`sse!`], which allows
//! the `unsafe` block to be unused (newer compilers treat baseline intrinsics as safe, older
//! ones do not); SSE4.1 intrinsics are called only on branches where `T::SSE41` is true, that
//! is with an [`Sse41`] token, which exists only after runtime detection.

use std::arch::x86_64::*;
use std::fmt;
use std::marker::PhantomData;
use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Not, Sub};

use super::{F32x8, I32x8, Isa, LaneKernel, Lanes, Mask8};

mod sealed {
    /// Only this module's tokens are SSE levels.
    pub trait Sealed {
        /// The token, for methods of lane values (whose existence proves the level available).
        /// Nothing outside this module can make a [`Proof`], so nothing else can call this.
        fn token(proof: Proof) -> Self;
    }

    /// A witness that the caller is a method of this module.
    pub struct Proof(pub(super) ());
}

/// An SSE level token: [`Sse2`] or [`Sse41`].
pub trait SseLevel:
    sealed::Sealed + Lanes<F32 = SseF32<Self>, I32 = SseI32<Self>, Mask = SseMask<Self>>
{
    /// Whether SSE4.1 instructions may be used.
    const SSE41: bool;
}

/// The SSE2 implementation's token (SSE2 is part of the x86-64 baseline).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Sse2 {
    _private: (),
}

/// The SSE4.1 implementation's token: proof that this CPU runs SSE4.1.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Sse41 {
    _detected: (),
}

impl Sse2 {
    /// The token (always available on x86-64).
    #[inline(always)]
    pub fn new() -> Option<Sse2> {
        Some(Sse2 { _private: () })
    }
}

impl Sse41 {
    /// The token, if this CPU supports SSE4.1 (runtime detection, cached by `std`).
    #[inline(always)]
    pub fn new() -> Option<Sse41> {
        if is_x86_feature_detected!("sse4.1") {
            Some(Sse41 { _detected: () })
        } else {
            None
        }
    }
}

impl sealed::Sealed for Sse2 {
    #[inline(always)]
    fn token(_: sealed::Proof) -> Sse2 {
        Sse2 { _private: () }
    }
}

impl sealed::Sealed for Sse41 {
    #[inline(always)]
    fn token(_: sealed::Proof) -> Sse41 {
        Sse41 { _detected: () }
    }
}

/// The token of `T`, for methods of `T`'s lane values (a value exists, so `T` is available).
#[inline(always)]
fn token<T: SseLevel>() -> T {
    T::token(sealed::Proof(()))
}

impl SseLevel for Sse2 {
    const SSE41: bool = false;
}

impl SseLevel for Sse41 {
    const SSE41: bool = true;
}

/// Runs `kernel` compiled for SSE4.1 (see [`super::dispatch`]).
#[inline]
pub(super) fn run_sse41<K: LaneKernel>(token: Sse41, kernel: K) -> K::Output {
    #[target_feature(enable = "sse4.1")]
    unsafe fn run_sse41_inner<K: LaneKernel>(token: Sse41, kernel: K) -> K::Output {
        kernel.run(token)
    }
    // SAFETY: `token` exists, so SSE4.1 was detected on this CPU.
    unsafe { run_sse41_inner(token, kernel) }
}

/// Wraps SSE2 intrinsic calls (and pointer accesses the caller has bounds-checked).
macro_rules! sse {
    ($($body:tt)*) => {{
        #[allow(unused_unsafe)]
        // SAFETY: SSE2 is part of the x86-64 baseline; pointer arguments are checked by the
        // caller.
        let value = unsafe { $($body)* };
        value
    }};
}

/// Wraps SSE4.1 intrinsic calls, used only where `T::SSE41` holds.
macro_rules! sse41 {
    ($($body:tt)*) => {{
        // SAFETY: only called on `T::SSE41` branches: `T` is then `Sse41`, whose token (and
        // therefore any value of these types) exists only after SSE4.1 was detected.
        unsafe { $($body)* }
    }};
}

/// 8 × `f32` as two `__m128` (lanes 0–3, 4–7).
#[derive(Clone, Copy)]
pub struct SseF32<T>(__m128, __m128, PhantomData<T>);

/// 8 × `i32` as two `__m128i` (lanes 0–3, 4–7).
#[derive(Clone, Copy)]
pub struct SseI32<T>(__m128i, __m128i, PhantomData<T>);

/// 8 lane booleans as all-ones / all-zeros lanes of two `__m128`.
#[derive(Clone, Copy)]
pub struct SseMask<T>(__m128, __m128, PhantomData<T>);

impl<T> SseF32<T> {
    #[inline(always)]
    fn new(lo: __m128, hi: __m128) -> Self {
        SseF32(lo, hi, PhantomData)
    }
    #[inline(always)]
    fn map(self, f: impl Fn(__m128) -> __m128) -> Self {
        SseF32::new(f(self.0), f(self.1))
    }
    #[inline(always)]
    fn zip(self, other: Self, f: impl Fn(__m128, __m128) -> __m128) -> Self {
        SseF32::new(f(self.0, other.0), f(self.1, other.1))
    }
    #[inline(always)]
    fn compare(self, other: Self, f: impl Fn(__m128, __m128) -> __m128) -> SseMask<T> {
        SseMask(f(self.0, other.0), f(self.1, other.1), PhantomData)
    }
}

impl<T> SseI32<T> {
    #[inline(always)]
    fn new(lo: __m128i, hi: __m128i) -> Self {
        SseI32(lo, hi, PhantomData)
    }
    #[inline(always)]
    fn map(self, f: impl Fn(__m128i) -> __m128i) -> Self {
        SseI32::new(f(self.0), f(self.1))
    }
    #[inline(always)]
    fn zip(self, other: Self, f: impl Fn(__m128i, __m128i) -> __m128i) -> Self {
        SseI32::new(f(self.0, other.0), f(self.1, other.1))
    }
    #[inline(always)]
    fn compare(self, other: Self, f: impl Fn(__m128i, __m128i) -> __m128i) -> SseMask<T> {
        SseMask(
            sse!(_mm_castsi128_ps(f(self.0, other.0))),
            sse!(_mm_castsi128_ps(f(self.1, other.1))),
            PhantomData,
        )
    }
}

/// `if mask { t } else { f }` per 32-bit lane (mask lanes all ones or all zeros).
#[inline(always)]
fn blend<T: SseLevel>(mask: __m128, t: __m128, f: __m128) -> __m128 {
    if T::SSE41 {
        sse41!(_mm_blendv_ps(f, t, mask))
    } else {
        sse!(_mm_or_ps(_mm_and_ps(mask, t), _mm_andnot_ps(mask, f)))
    }
}

/// [`blend`] for integer lanes.
#[inline(always)]
fn blend_i<T: SseLevel>(mask: __m128, t: __m128i, f: __m128i) -> __m128i {
    sse!(_mm_castps_si128(blend::<T>(
        mask,
        _mm_castsi128_ps(t),
        _mm_castsi128_ps(f)
    )))
}

// SSE4.1 operations are `#[inline(always)]` functions rather than closures: a closure is a
// function of its own, compiled without SSE4.1, and if LLVM kept it out of line the intrinsic
// inside would become a call.

/// `pmulld`; only called where `T::SSE41` holds.
#[inline(always)]
fn mullo_sse41<T: SseLevel>(a: __m128i, b: __m128i) -> __m128i {
    debug_assert!(T::SSE41);
    sse41!(_mm_mullo_epi32(a, b))
}

/// `pminsd`; only called where `T::SSE41` holds.
#[inline(always)]
fn min_epi32_sse41<T: SseLevel>(a: __m128i, b: __m128i) -> __m128i {
    debug_assert!(T::SSE41);
    sse41!(_mm_min_epi32(a, b))
}

/// `pmaxsd`; only called where `T::SSE41` holds.
#[inline(always)]
fn max_epi32_sse41<T: SseLevel>(a: __m128i, b: __m128i) -> __m128i {
    debug_assert!(T::SSE41);
    sse41!(_mm_max_epi32(a, b))
}

/// Rounds to the nearest integer, ties to even (`roundps` semantics for every non-NaN input).
#[inline(always)]
fn round_ties_even4<T: SseLevel>(x: __m128) -> __m128 {
    if T::SSE41 {
        return sse41!(_mm_round_ps::<
            { _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC },
        >(x));
    }
    sse!({
        let sign_bit = _mm_set1_ps(-0.0);
        let two_pow_23 = _mm_set1_ps(8_388_608.0);
        let magnitude = _mm_andnot_ps(sign_bit, x);
        // Exact for magnitudes below 2^23: the sum lies in [2^23, 2^24), where the spacing of
        // floats is 1, so the addition rounds to the nearest even integer.
        let rounded = _mm_sub_ps(_mm_add_ps(magnitude, two_pow_23), two_pow_23);
        let signed = _mm_or_ps(rounded, _mm_and_ps(x, sign_bit));
        // Larger magnitudes, infinities and NaN pass through.
        let small = _mm_cmplt_ps(magnitude, two_pow_23);
        _mm_or_ps(_mm_and_ps(small, signed), _mm_andnot_ps(small, x))
    })
}

/// Rounds toward −∞ (`roundps` semantics for every non-NaN input).
#[inline(always)]
fn floor4<T: SseLevel>(x: __m128) -> __m128 {
    if T::SSE41 {
        return sse41!(_mm_round_ps::<{ _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC }>(x));
    }
    let rounded = round_ties_even4::<T>(x);
    // Rounded up: step down by one (exact, the value is an integer of magnitude <= 2^23).
    // `-0 - 0` stays `-0`, and `1 - 1` is `+0`, as `floor` gives.
    sse!(_mm_sub_ps(
        rounded,
        _mm_and_ps(_mm_cmpgt_ps(rounded, x), _mm_set1_ps(1.0))
    ))
}

/// Reduces `lo` and `hi` (lanes 0–3, 4–7) with `$op` in the shared tree order.
macro_rules! reduce {
    ($lo:expr, $hi:expr, $op:ident) => {
        sse!({
            let halves = $op($lo, $hi);
            let pairs = $op(halves, _mm_movehl_ps(halves, halves));
            _mm_cvtss_f32($op(pairs, _mm_shuffle_ps::<0b01>(pairs, pairs)))
        })
    };
}

impl<T> fmt::Debug for SseF32<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut a = [0.0f32; 8];
        sse!({
            _mm_storeu_ps(a.as_mut_ptr(), self.0);
            _mm_storeu_ps(a[4..].as_mut_ptr(), self.1);
        });
        f.debug_tuple("SseF32").field(&a).finish()
    }
}

impl<T> fmt::Debug for SseI32<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut a = [0i32; 8];
        sse!({
            _mm_storeu_si128(a.as_mut_ptr().cast(), self.0);
            _mm_storeu_si128(a[4..].as_mut_ptr().cast(), self.1);
        });
        f.debug_tuple("SseI32").field(&a).finish()
    }
}

impl<T> fmt::Debug for SseMask<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let bits = sse!(_mm_movemask_ps(self.0) | (_mm_movemask_ps(self.1) << 4));
        write!(f, "SseMask({bits:#010b})")
    }
}

/// Implements [`Lanes`] for an SSE level token.
macro_rules! impl_lanes {
    ($token:ident) => {
        impl Lanes for $token {
            type F32 = SseF32<$token>;
            type I32 = SseI32<$token>;
            type Mask = SseMask<$token>;

            #[inline(always)]
            fn isa(self) -> Isa {
                if <$token as SseLevel>::SSE41 {
                    Isa::Sse41
                } else {
                    Isa::Sse2
                }
            }
            #[inline(always)]
            fn splat_f32(self, v: f32) -> SseF32<$token> {
                let v = sse!(_mm_set1_ps(v));
                SseF32::new(v, v)
            }
            #[inline(always)]
            fn f32_from_array(self, a: [f32; 8]) -> SseF32<$token> {
                self.load_f32(&a)
            }
            #[inline(always)]
            fn load_f32(self, s: &[f32]) -> SseF32<$token> {
                let s = &s[..8];
                sse!(SseF32::new(
                    _mm_loadu_ps(s.as_ptr()),
                    _mm_loadu_ps(s[4..].as_ptr())
                ))
            }
            #[inline(always)]
            fn splat_i32(self, v: i32) -> SseI32<$token> {
                let v = sse!(_mm_set1_epi32(v));
                SseI32::new(v, v)
            }
            #[inline(always)]
            fn i32_from_array(self, a: [i32; 8]) -> SseI32<$token> {
                self.load_i32(&a)
            }
            #[inline(always)]
            fn load_i32(self, s: &[i32]) -> SseI32<$token> {
                let s = &s[..8];
                sse!(SseI32::new(
                    _mm_loadu_si128(s.as_ptr().cast()),
                    _mm_loadu_si128(s[4..].as_ptr().cast())
                ))
            }
            #[inline(always)]
            fn lane_index(self) -> SseI32<$token> {
                sse!(SseI32::new(
                    _mm_setr_epi32(0, 1, 2, 3),
                    _mm_setr_epi32(4, 5, 6, 7)
                ))
            }
            #[inline(always)]
            fn mask_from_bits(self, bits: u8) -> SseMask<$token> {
                sse!({
                    let all = _mm_set1_epi32(i32::from(bits));
                    let lo_bits = _mm_setr_epi32(1, 2, 4, 8);
                    let hi_bits = _mm_setr_epi32(16, 32, 64, 128);
                    SseMask(
                        _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(all, lo_bits), lo_bits)),
                        _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(all, hi_bits), hi_bits)),
                        PhantomData,
                    )
                })
            }
            #[inline(always)]
            fn mask_all(self, value: bool) -> SseMask<$token> {
                let v = sse!(_mm_castsi128_ps(_mm_set1_epi32(-i32::from(value))));
                SseMask(v, v, PhantomData)
            }
        }
    };
}
impl_lanes!(Sse2);
impl_lanes!(Sse41);

macro_rules! binary_ops {
    ($ty:ident, $($trait:ident $method:ident $intrinsic:ident;)*) => {$(
        impl<T: SseLevel> $trait for $ty<T> {
            type Output = $ty<T>;
            #[inline(always)]
            fn $method(self, other: $ty<T>) -> $ty<T> {
                self.zip(other, |a, b| sse!($intrinsic(a, b)))
            }
        }
    )*};
}

binary_ops!(SseF32,
    Add add _mm_add_ps;
    Sub sub _mm_sub_ps;
    Mul mul _mm_mul_ps;
    Div div _mm_div_ps;
);

binary_ops!(SseI32,
    Add add _mm_add_epi32;
    Sub sub _mm_sub_epi32;
    BitAnd bitand _mm_and_si128;
    BitOr bitor _mm_or_si128;
    BitXor bitxor _mm_xor_si128;
);

impl<T: SseLevel> Mul for SseI32<T> {
    type Output = SseI32<T>;
    #[inline(always)]
    fn mul(self, other: SseI32<T>) -> SseI32<T> {
        if T::SSE41 {
            return self.zip(other, mullo_sse41::<T>);
        }
        // The low 32 bits of the unsigned products are those of the signed ones.
        self.zip(other, |a, b| {
            sse!({
                let even = _mm_mul_epu32(a, b);
                let odd = _mm_mul_epu32(_mm_srli_epi64::<32>(a), _mm_srli_epi64::<32>(b));
                _mm_unpacklo_epi32(
                    _mm_shuffle_epi32::<0b00_00_10_00>(even),
                    _mm_shuffle_epi32::<0b00_00_10_00>(odd),
                )
            })
        })
    }
}

impl<T: SseLevel> Neg for SseF32<T> {
    type Output = SseF32<T>;
    #[inline(always)]
    fn neg(self) -> SseF32<T> {
        self.map(|a| sse!(_mm_xor_ps(a, _mm_set1_ps(-0.0))))
    }
}

impl<T: SseLevel> Not for SseI32<T> {
    type Output = SseI32<T>;
    #[inline(always)]
    fn not(self) -> SseI32<T> {
        self.map(|a| sse!(_mm_xor_si128(a, _mm_set1_epi32(-1))))
    }
}

impl<T: SseLevel> F32x8 for SseF32<T> {
    type Lanes = T;

    #[inline(always)]
    fn lanes(self) -> T {
        token::<T>()
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        self.zip(other, |a, b| sse!(_mm_min_ps(a, b)))
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        self.zip(other, |a, b| sse!(_mm_max_ps(a, b)))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        self.map(|a| sse!(_mm_sqrt_ps(a)))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        self.map(|a| sse!(_mm_andnot_ps(_mm_set1_ps(-0.0), a)))
    }
    #[inline(always)]
    fn floor(self) -> Self {
        self.map(floor4::<T>)
    }
    #[inline(always)]
    fn round_ties_even(self) -> Self {
        self.map(round_ties_even4::<T>)
    }
    #[inline(always)]
    fn simd_lt(self, other: Self) -> SseMask<T> {
        self.compare(other, |a, b| sse!(_mm_cmplt_ps(a, b)))
    }
    #[inline(always)]
    fn simd_le(self, other: Self) -> SseMask<T> {
        self.compare(other, |a, b| sse!(_mm_cmple_ps(a, b)))
    }
    #[inline(always)]
    fn simd_gt(self, other: Self) -> SseMask<T> {
        self.compare(other, |a, b| sse!(_mm_cmpgt_ps(a, b)))
    }
    #[inline(always)]
    fn simd_ge(self, other: Self) -> SseMask<T> {
        self.compare(other, |a, b| sse!(_mm_cmpge_ps(a, b)))
    }
    #[inline(always)]
    fn simd_eq(self, other: Self) -> SseMask<T> {
        self.compare(other, |a, b| sse!(_mm_cmpeq_ps(a, b)))
    }
    #[inline(always)]
    fn simd_ne(self, other: Self) -> SseMask<T> {
        self.compare(other, |a, b| sse!(_mm_cmpneq_ps(a, b)))
    }
    #[inline(always)]
    fn to_array(self) -> [f32; 8] {
        let mut out = [0.0; 8];
        self.store(&mut out);
        out
    }
    #[inline(always)]
    fn store(self, out: &mut [f32]) {
        let out = &mut out[..8];
        sse!({
            _mm_storeu_ps(out.as_mut_ptr(), self.0);
            _mm_storeu_ps(out[4..].as_mut_ptr(), self.1);
        });
    }
    #[inline(always)]
    fn store_masked(self, mask: SseMask<T>, out: &mut [f32]) {
        let out = &mut out[..8];
        let old = token::<T>().load_f32(out);
        SseF32::<T>::new(
            blend::<T>(mask.0, self.0, old.0),
            blend::<T>(mask.1, self.1, old.1),
        )
        .store(out);
    }
    #[inline(always)]
    fn to_i32_trunc(self) -> SseI32<T> {
        sse!(SseI32::new(
            _mm_cvttps_epi32(self.0),
            _mm_cvttps_epi32(self.1)
        ))
    }
    #[inline(always)]
    fn to_i32_floor(self) -> SseI32<T> {
        self.floor().to_i32_trunc()
    }
    #[inline(always)]
    fn to_bits(self) -> SseI32<T> {
        sse!(SseI32::new(
            _mm_castps_si128(self.0),
            _mm_castps_si128(self.1)
        ))
    }
    #[inline(always)]
    fn from_bits(bits: SseI32<T>) -> Self {
        sse!(SseF32::new(
            _mm_castsi128_ps(bits.0),
            _mm_castsi128_ps(bits.1)
        ))
    }
    #[inline(always)]
    fn extract(self, k: usize) -> f32 {
        self.to_array()[k]
    }
    #[inline(always)]
    fn permute(self, index: SseI32<T>) -> Self {
        super::permute_through_arrays::<T>(self, index)
    }
    #[inline(always)]
    fn reduce_min(self) -> f32 {
        reduce!(self.0, self.1, _mm_min_ps)
    }
    #[inline(always)]
    fn reduce_max(self) -> f32 {
        reduce!(self.0, self.1, _mm_max_ps)
    }
}

impl<T: SseLevel> I32x8 for SseI32<T> {
    type Lanes = T;

    #[inline(always)]
    fn lanes(self) -> T {
        token::<T>()
    }
    #[inline(always)]
    fn shl<const N: i32>(self) -> Self {
        const { assert!(N >= 0 && N < 32, "shift count must be in 0..32") };
        self.map(|a| sse!(_mm_slli_epi32::<N>(a)))
    }
    #[inline(always)]
    fn shr_arith<const N: i32>(self) -> Self {
        const { assert!(N >= 0 && N < 32, "shift count must be in 0..32") };
        self.map(|a| sse!(_mm_srai_epi32::<N>(a)))
    }
    #[inline(always)]
    fn shr_logical<const N: i32>(self) -> Self {
        const { assert!(N >= 0 && N < 32, "shift count must be in 0..32") };
        self.map(|a| sse!(_mm_srli_epi32::<N>(a)))
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        if T::SSE41 {
            return self.zip(other, min_epi32_sse41::<T>);
        }
        self.simd_gt(other).select_i32(other, self)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        if T::SSE41 {
            return self.zip(other, max_epi32_sse41::<T>);
        }
        self.simd_gt(other).select_i32(self, other)
    }
    #[inline(always)]
    fn simd_eq(self, other: Self) -> SseMask<T> {
        self.compare(other, |a, b| sse!(_mm_cmpeq_epi32(a, b)))
    }
    #[inline(always)]
    fn simd_gt(self, other: Self) -> SseMask<T> {
        self.compare(other, |a, b| sse!(_mm_cmpgt_epi32(a, b)))
    }
    #[inline(always)]
    fn simd_lt(self, other: Self) -> SseMask<T> {
        self.compare(other, |a, b| sse!(_mm_cmplt_epi32(a, b)))
    }
    #[inline(always)]
    fn to_f32(self) -> SseF32<T> {
        sse!(SseF32::new(
            _mm_cvtepi32_ps(self.0),
            _mm_cvtepi32_ps(self.1)
        ))
    }
    #[inline(always)]
    fn to_array(self) -> [i32; 8] {
        let mut out = [0; 8];
        self.store(&mut out);
        out
    }
    #[inline(always)]
    fn store(self, out: &mut [i32]) {
        let out = &mut out[..8];
        sse!({
            _mm_storeu_si128(out.as_mut_ptr().cast(), self.0);
            _mm_storeu_si128(out[4..].as_mut_ptr().cast(), self.1);
        });
    }
    #[inline(always)]
    fn gather_u32(self, table: &[u32]) -> Self {
        let Some(last) = table.len().checked_sub(1) else {
            return token::<T>().splat_i32(0);
        };
        let index = self.to_array();
        let gathered = index.map(|i| table[usize::try_from(i).unwrap_or(0).min(last)] as i32);
        token::<T>().i32_from_array(gathered)
    }
    #[inline(always)]
    fn extract(self, k: usize) -> i32 {
        self.to_array()[k]
    }
    #[inline(always)]
    fn sign_bits(self) -> u8 {
        sse!(
            (_mm_movemask_ps(_mm_castsi128_ps(self.0))
                | (_mm_movemask_ps(_mm_castsi128_ps(self.1)) << 4)) as u8
        )
    }
}

impl<T: SseLevel> Mask8 for SseMask<T> {
    type Lanes = T;

    #[inline(always)]
    fn lanes(self) -> T {
        token::<T>()
    }
    #[inline(always)]
    fn and(self, other: Self) -> Self {
        sse!(SseMask(
            _mm_and_ps(self.0, other.0),
            _mm_and_ps(self.1, other.1),
            PhantomData
        ))
    }
    #[inline(always)]
    fn or(self, other: Self) -> Self {
        sse!(SseMask(
            _mm_or_ps(self.0, other.0),
            _mm_or_ps(self.1, other.1),
            PhantomData
        ))
    }
    #[inline(always)]
    fn xor(self, other: Self) -> Self {
        sse!(SseMask(
            _mm_xor_ps(self.0, other.0),
            _mm_xor_ps(self.1, other.1),
            PhantomData
        ))
    }
    #[inline(always)]
    fn not(self) -> Self {
        self.xor(token::<T>().mask_all(true))
    }
    #[inline(always)]
    fn and_not(self, other: Self) -> Self {
        // `andnot(a, b)` is `!a & b`.
        sse!(SseMask(
            _mm_andnot_ps(other.0, self.0),
            _mm_andnot_ps(other.1, self.1),
            PhantomData
        ))
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
        sse!((_mm_movemask_ps(self.0) | (_mm_movemask_ps(self.1) << 4)) as u8)
    }
    #[inline(always)]
    fn count(self) -> u32 {
        self.bits().count_ones()
    }
    #[inline(always)]
    fn select_f32(self, if_true: SseF32<T>, if_false: SseF32<T>) -> SseF32<T> {
        SseF32::new(
            blend::<T>(self.0, if_true.0, if_false.0),
            blend::<T>(self.1, if_true.1, if_false.1),
        )
    }
    #[inline(always)]
    fn select_i32(self, if_true: SseI32<T>, if_false: SseI32<T>) -> SseI32<T> {
        SseI32::new(
            blend_i::<T>(self.0, if_true.0, if_false.0),
            blend_i::<T>(self.1, if_true.1, if_false.1),
        )
    }
}
