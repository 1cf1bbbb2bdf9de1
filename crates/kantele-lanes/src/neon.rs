//! The NEON implementation (AArch64): two 128-bit halves per value.
//!
//! NEON's own `fmin`/`fmax` and float-to-int conversion differ from x86 (NaN handling,
//! saturation), so `min`/`max` are written as compare-and-select and `to_i32_trunc` maps NaN
//! and out-of-range lanes to `i32::MIN`, as `cvttps2dq` does; everything else maps to one
//! instruction per half. NEON is part of the AArch64 baseline, so its intrinsics are wrapped in
//! [`neon!`], which allows the `unsafe` block to be unused (newer compilers treat baseline
//! intrinsics as safe, older ones do not).

use std::arch::aarch64::*;
use std::fmt;
use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Not, Sub};

use super::{F32x8, I32x8, Isa, Lanes, Mask8};

/// The NEON implementation's token: proof that this CPU runs NEON (every AArch64 CPU does).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Neon {
    _detected: (),
}

impl Neon {
    /// The token, if this CPU supports NEON (runtime detection, cached by `std`).
    #[inline(always)]
    pub fn new() -> Option<Neon> {
        if std::arch::is_aarch64_feature_detected!("neon") {
            Some(Neon { _detected: () })
        } else {
            None
        }
    }
}

/// Wraps NEON intrinsic calls (and pointer accesses the caller has bounds-checked).
macro_rules! neon {
    ($($body:tt)*) => {{
        #[allow(unused_unsafe)]
        // SAFETY: NEON was detected before any `Neon` token, and therefore any value of this
        // module, could be made (it is part of the AArch64 baseline); pointer arguments are
        // checked by the caller.
        let value = unsafe { $($body)* };
        value
    }};
}

/// 8 × `f32` as two `float32x4_t` (lanes 0–3, 4–7).
#[derive(Clone, Copy)]
pub struct NeonF32(float32x4_t, float32x4_t);

/// 8 × `i32` as two `int32x4_t` (lanes 0–3, 4–7).
#[derive(Clone, Copy)]
pub struct NeonI32(int32x4_t, int32x4_t);

/// 8 lane booleans as all-ones / all-zeros lanes of two `uint32x4_t`.
#[derive(Clone, Copy)]
pub struct NeonMask(uint32x4_t, uint32x4_t);

const TOKEN: Neon = Neon { _detected: () };

impl NeonF32 {
    #[inline(always)]
    fn map(self, f: impl Fn(float32x4_t) -> float32x4_t) -> Self {
        NeonF32(f(self.0), f(self.1))
    }
    #[inline(always)]
    fn zip(self, other: Self, f: impl Fn(float32x4_t, float32x4_t) -> float32x4_t) -> Self {
        NeonF32(f(self.0, other.0), f(self.1, other.1))
    }
    #[inline(always)]
    fn compare(self, other: Self, f: impl Fn(float32x4_t, float32x4_t) -> uint32x4_t) -> NeonMask {
        NeonMask(f(self.0, other.0), f(self.1, other.1))
    }
}

impl NeonI32 {
    #[inline(always)]
    fn map(self, f: impl Fn(int32x4_t) -> int32x4_t) -> Self {
        NeonI32(f(self.0), f(self.1))
    }
    #[inline(always)]
    fn zip(self, other: Self, f: impl Fn(int32x4_t, int32x4_t) -> int32x4_t) -> Self {
        NeonI32(f(self.0, other.0), f(self.1, other.1))
    }
    #[inline(always)]
    fn compare(self, other: Self, f: impl Fn(int32x4_t, int32x4_t) -> uint32x4_t) -> NeonMask {
        NeonMask(f(self.0, other.0), f(self.1, other.1))
    }
}

/// x86 `minps` on four lanes: `if a < b { a } else { b }`.
#[inline(always)]
fn min4(a: float32x4_t, b: float32x4_t) -> float32x4_t {
    neon!(vbslq_f32(vcltq_f32(a, b), a, b))
}

/// x86 `maxps` on four lanes: `if a > b { a } else { b }`.
#[inline(always)]
fn max4(a: float32x4_t, b: float32x4_t) -> float32x4_t {
    neon!(vbslq_f32(vcgtq_f32(a, b), a, b))
}

/// x86 `cvttps2dq` on four lanes: toward zero, NaN and out of range give `i32::MIN`.
#[inline(always)]
fn trunc4(x: float32x4_t) -> int32x4_t {
    neon!({
        let in_range = vandq_u32(
            vcgeq_f32(x, vdupq_n_f32(-2_147_483_648.0)),
            vcltq_f32(x, vdupq_n_f32(2_147_483_648.0)),
        );
        vbslq_s32(in_range, vcvtq_s32_f32(x), vdupq_n_s32(i32::MIN))
    })
}

/// Bit `k` set when lane `k` of the four is set.
#[inline(always)]
fn bits4(mask: uint32x4_t) -> u32 {
    const LANE_BITS: [u32; 4] = [1, 2, 4, 8];
    neon!(vaddvq_u32(vandq_u32(mask, vld1q_u32(LANE_BITS.as_ptr()))))
}

/// Reduces `lo` and `hi` (lanes 0–3, 4–7) with `op` in the shared tree order.
#[inline(always)]
fn reduce(
    lo: float32x4_t,
    hi: float32x4_t,
    op: impl Fn(float32x4_t, float32x4_t) -> float32x4_t,
) -> f32 {
    let halves = op(lo, hi);
    let pairs = op(halves, neon!(vextq_f32::<2>(halves, halves)));
    let last = op(pairs, neon!(vextq_f32::<1>(pairs, pairs)));
    neon!(vgetq_lane_f32::<0>(last))
}

impl fmt::Debug for NeonF32 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_tuple("NeonF32").field(&self.to_array()).finish()
    }
}

impl fmt::Debug for NeonI32 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_tuple("NeonI32").field(&self.to_array()).finish()
    }
}

impl fmt::Debug for NeonMask {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "NeonMask({:#010b})", self.bits())
    }
}

impl Lanes for Neon {
    type F32 = NeonF32;
    type I32 = NeonI32;
    type Mask = NeonMask;

    #[inline(always)]
    fn isa(self) -> Isa {
        Isa::Neon
    }
    #[inline(always)]
    fn splat_f32(self, v: f32) -> NeonF32 {
        let v = neon!(vdupq_n_f32(v));
        NeonF32(v, v)
    }
    #[inline(always)]
    fn f32_from_array(self, a: [f32; 8]) -> NeonF32 {
        self.load_f32(&a)
    }
    #[inline(always)]
    fn load_f32(self, s: &[f32]) -> NeonF32 {
        let s = &s[..8];
        neon!(NeonF32(vld1q_f32(s.as_ptr()), vld1q_f32(s[4..].as_ptr())))
    }
    #[inline(always)]
    fn splat_i32(self, v: i32) -> NeonI32 {
        let v = neon!(vdupq_n_s32(v));
        NeonI32(v, v)
    }
    #[inline(always)]
    fn i32_from_array(self, a: [i32; 8]) -> NeonI32 {
        self.load_i32(&a)
    }
    #[inline(always)]
    fn load_i32(self, s: &[i32]) -> NeonI32 {
        let s = &s[..8];
        neon!(NeonI32(vld1q_s32(s.as_ptr()), vld1q_s32(s[4..].as_ptr())))
    }
    #[inline(always)]
    fn lane_index(self) -> NeonI32 {
        self.i32_from_array([0, 1, 2, 3, 4, 5, 6, 7])
    }
    #[inline(always)]
    fn mask_from_bits(self, bits: u8) -> NeonMask {
        const LO_BITS: [u32; 4] = [1, 2, 4, 8];
        const HI_BITS: [u32; 4] = [16, 32, 64, 128];
        neon!({
            let all = vdupq_n_u32(u32::from(bits));
            NeonMask(
                vtstq_u32(all, vld1q_u32(LO_BITS.as_ptr())),
                vtstq_u32(all, vld1q_u32(HI_BITS.as_ptr())),
            )
        })
    }
    #[inline(always)]
    fn mask_all(self, value: bool) -> NeonMask {
        let v = neon!(vdupq_n_u32(if value { u32::MAX } else { 0 }));
        NeonMask(v, v)
    }
}

macro_rules! binary_ops {
    ($ty:ident, $($trait:ident $method:ident $intrinsic:ident;)*) => {$(
        impl $trait for $ty {
            type Output = $ty;
            #[inline(always)]
            fn $method(self, other: $ty) -> $ty {
                self.zip(other, |a, b| neon!($intrinsic(a, b)))
            }
        }
    )*};
}

binary_ops!(NeonF32,
    Add add vaddq_f32;
    Sub sub vsubq_f32;
    Mul mul vmulq_f32;
    Div div vdivq_f32;
);

binary_ops!(NeonI32,
    Add add vaddq_s32;
    Sub sub vsubq_s32;
    Mul mul vmulq_s32;
    BitAnd bitand vandq_s32;
    BitOr bitor vorrq_s32;
    BitXor bitxor veorq_s32;
);

impl Neg for NeonF32 {
    type Output = NeonF32;
    #[inline(always)]
    fn neg(self) -> NeonF32 {
        self.map(|a| neon!(vnegq_f32(a)))
    }
}

impl Not for NeonI32 {
    type Output = NeonI32;
    #[inline(always)]
    fn not(self) -> NeonI32 {
        self.map(|a| neon!(vmvnq_s32(a)))
    }
}

impl F32x8 for NeonF32 {
    type Lanes = Neon;

    #[inline(always)]
    fn lanes(self) -> Neon {
        TOKEN
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        self.zip(other, min4)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        self.zip(other, max4)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        self.map(|a| neon!(vsqrtq_f32(a)))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        self.map(|a| neon!(vabsq_f32(a)))
    }
    #[inline(always)]
    fn floor(self) -> Self {
        self.map(|a| neon!(vrndmq_f32(a)))
    }
    #[inline(always)]
    fn round_ties_even(self) -> Self {
        self.map(|a| neon!(vrndnq_f32(a)))
    }
    #[inline(always)]
    fn simd_lt(self, other: Self) -> NeonMask {
        self.compare(other, |a, b| neon!(vcltq_f32(a, b)))
    }
    #[inline(always)]
    fn simd_le(self, other: Self) -> NeonMask {
        self.compare(other, |a, b| neon!(vcleq_f32(a, b)))
    }
    #[inline(always)]
    fn simd_gt(self, other: Self) -> NeonMask {
        self.compare(other, |a, b| neon!(vcgtq_f32(a, b)))
    }
    #[inline(always)]
    fn simd_ge(self, other: Self) -> NeonMask {
        self.compare(other, |a, b| neon!(vcgeq_f32(a, b)))
    }
    #[inline(always)]
    fn simd_eq(self, other: Self) -> NeonMask {
        self.compare(other, |a, b| neon!(vceqq_f32(a, b)))
    }
    #[inline(always)]
    fn simd_ne(self, other: Self) -> NeonMask {
        self.compare(other, |a, b| neon!(vmvnq_u32(vceqq_f32(a, b))))
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
        neon!({
            vst1q_f32(out.as_mut_ptr(), self.0);
            vst1q_f32(out[4..].as_mut_ptr(), self.1);
        });
    }
    #[inline(always)]
    fn store_masked(self, mask: NeonMask, out: &mut [f32]) {
        let out = &mut out[..8];
        let old = TOKEN.load_f32(out);
        mask.select_f32(self, old).store(out);
    }
    #[inline(always)]
    fn to_i32_trunc(self) -> NeonI32 {
        NeonI32(trunc4(self.0), trunc4(self.1))
    }
    #[inline(always)]
    fn to_i32_floor(self) -> NeonI32 {
        self.floor().to_i32_trunc()
    }
    #[inline(always)]
    fn to_bits(self) -> NeonI32 {
        neon!(NeonI32(
            vreinterpretq_s32_f32(self.0),
            vreinterpretq_s32_f32(self.1)
        ))
    }
    #[inline(always)]
    fn from_bits(bits: NeonI32) -> Self {
        neon!(NeonF32(
            vreinterpretq_f32_s32(bits.0),
            vreinterpretq_f32_s32(bits.1)
        ))
    }
    #[inline(always)]
    fn extract(self, k: usize) -> f32 {
        self.to_array()[k]
    }
    #[inline(always)]
    fn permute(self, index: NeonI32) -> Self {
        super::permute_through_arrays::<Neon>(self, index)
    }
    #[inline(always)]
    fn reduce_min(self) -> f32 {
        reduce(self.0, self.1, min4)
    }
    #[inline(always)]
    fn reduce_max(self) -> f32 {
        reduce(self.0, self.1, max4)
    }
}

impl I32x8 for NeonI32 {
    type Lanes = Neon;

    #[inline(always)]
    fn lanes(self) -> Neon {
        TOKEN
    }
    #[inline(always)]
    fn shl<const N: i32>(self) -> Self {
        const { assert!(N >= 0 && N < 32, "shift count must be in 0..32") };
        self.map(|a| neon!(vshlq_s32(a, vdupq_n_s32(N))))
    }
    #[inline(always)]
    fn shr_arith<const N: i32>(self) -> Self {
        const { assert!(N >= 0 && N < 32, "shift count must be in 0..32") };
        // A negative count shifts right; signed lanes copy the sign bit.
        self.map(|a| neon!(vshlq_s32(a, vdupq_n_s32(-N))))
    }
    #[inline(always)]
    fn shr_logical<const N: i32>(self) -> Self {
        const { assert!(N >= 0 && N < 32, "shift count must be in 0..32") };
        // A negative count shifts right; unsigned lanes shift in zeros.
        self.map(|a| {
            neon!(vreinterpretq_s32_u32(vshlq_u32(
                vreinterpretq_u32_s32(a),
                vdupq_n_s32(-N)
            )))
        })
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        self.zip(other, |a, b| neon!(vminq_s32(a, b)))
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        self.zip(other, |a, b| neon!(vmaxq_s32(a, b)))
    }
    #[inline(always)]
    fn simd_eq(self, other: Self) -> NeonMask {
        self.compare(other, |a, b| neon!(vceqq_s32(a, b)))
    }
    #[inline(always)]
    fn simd_gt(self, other: Self) -> NeonMask {
        self.compare(other, |a, b| neon!(vcgtq_s32(a, b)))
    }
    #[inline(always)]
    fn simd_lt(self, other: Self) -> NeonMask {
        self.compare(other, |a, b| neon!(vcltq_s32(a, b)))
    }
    #[inline(always)]
    fn to_f32(self) -> NeonF32 {
        neon!(NeonF32(vcvtq_f32_s32(self.0), vcvtq_f32_s32(self.1)))
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
        neon!({
            vst1q_s32(out.as_mut_ptr(), self.0);
            vst1q_s32(out[4..].as_mut_ptr(), self.1);
        });
    }
    #[inline(always)]
    fn gather_u32(self, table: &[u32]) -> Self {
        let Some(last) = table.len().checked_sub(1) else {
            return TOKEN.splat_i32(0);
        };
        let gathered = self
            .to_array()
            .map(|i| table[usize::try_from(i).unwrap_or(0).min(last)] as i32);
        TOKEN.i32_from_array(gathered)
    }
    #[inline(always)]
    fn extract(self, k: usize) -> i32 {
        self.to_array()[k]
    }
    #[inline(always)]
    fn sign_bits(self) -> u8 {
        let negative = self.simd_lt(TOKEN.splat_i32(0));
        negative.bits()
    }
}

impl Mask8 for NeonMask {
    type Lanes = Neon;

    #[inline(always)]
    fn lanes(self) -> Neon {
        TOKEN
    }
    #[inline(always)]
    fn and(self, other: Self) -> Self {
        neon!(NeonMask(
            vandq_u32(self.0, other.0),
            vandq_u32(self.1, other.1)
        ))
    }
    #[inline(always)]
    fn or(self, other: Self) -> Self {
        neon!(NeonMask(
            vorrq_u32(self.0, other.0),
            vorrq_u32(self.1, other.1)
        ))
    }
    #[inline(always)]
    fn xor(self, other: Self) -> Self {
        neon!(NeonMask(
            veorq_u32(self.0, other.0),
            veorq_u32(self.1, other.1)
        ))
    }
    #[inline(always)]
    fn not(self) -> Self {
        neon!(NeonMask(vmvnq_u32(self.0), vmvnq_u32(self.1)))
    }
    #[inline(always)]
    fn and_not(self, other: Self) -> Self {
        // `vbic(a, b)` is `a & !b`.
        neon!(NeonMask(
            vbicq_u32(self.0, other.0),
            vbicq_u32(self.1, other.1)
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
        (bits4(self.0) | (bits4(self.1) << 4)) as u8
    }
    #[inline(always)]
    fn count(self) -> u32 {
        self.bits().count_ones()
    }
    #[inline(always)]
    fn select_f32(self, if_true: NeonF32, if_false: NeonF32) -> NeonF32 {
        neon!(NeonF32(
            vbslq_f32(self.0, if_true.0, if_false.0),
            vbslq_f32(self.1, if_true.1, if_false.1)
        ))
    }
    #[inline(always)]
    fn select_i32(self, if_true: NeonI32, if_false: NeonI32) -> NeonI32 {
        neon!(NeonI32(
            vbslq_s32(self.0, if_true.0, if_false.0),
            vbslq_s32(self.1, if_true.1, if_false.1)
        ))
    }
}
