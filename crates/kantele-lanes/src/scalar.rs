//! The scalar implementation: plain Rust over arrays, the readable reference every other
//! implementation must match bit for bit.

use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Not, Sub};

use super::{rounding, F32x8, I32x8, Isa, Lanes, Mask8};

/// The scalar implementation's token (always available).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Scalar;

/// 8 × `f32` as an array.
#[derive(Clone, Copy, Debug)]
pub struct ScalarF32([f32; 8]);

/// 8 × `i32` as an array.
#[derive(Clone, Copy, Debug)]
pub struct ScalarI32([i32; 8]);

/// 8 lane booleans as the bits of a byte (bit `k` = lane `k`).
#[derive(Clone, Copy, Debug)]
pub struct ScalarMask(u8);

/// x86 `minss`: `if a < b { a } else { b }`.
#[inline(always)]
fn min_f32(a: f32, b: f32) -> f32 {
    if a < b {
        a
    } else {
        b
    }
}

/// x86 `maxss`: `if a > b { a } else { b }`.
#[inline(always)]
fn max_f32(a: f32, b: f32) -> f32 {
    if a > b {
        a
    } else {
        b
    }
}

/// x86 `cvttss2si`: toward zero; NaN and out-of-range values give `i32::MIN`.
#[inline(always)]
fn trunc_to_i32(x: f32) -> i32 {
    if (-2_147_483_648.0..2_147_483_648.0).contains(&x) {
        x as i32
    } else {
        i32::MIN
    }
}

/// The reduction tree shared by every implementation: `(k, k + 4)`, then `(k, k + 2)`, then
/// `(0, 1)`.
#[inline(always)]
fn reduce(a: [f32; 8], op: fn(f32, f32) -> f32) -> f32 {
    let t = [
        op(a[0], a[4]),
        op(a[1], a[5]),
        op(a[2], a[6]),
        op(a[3], a[7]),
    ];
    let u = [op(t[0], t[2]), op(t[1], t[3])];
    op(u[0], u[1])
}

impl ScalarF32 {
    #[inline(always)]
    fn map(self, f: impl Fn(f32) -> f32) -> Self {
        ScalarF32(self.0.map(f))
    }

    #[inline(always)]
    fn zip(self, other: Self, f: impl Fn(f32, f32) -> f32) -> Self {
        ScalarF32(std::array::from_fn(|k| f(self.0[k], other.0[k])))
    }

    #[inline(always)]
    fn compare(self, other: Self, f: impl Fn(f32, f32) -> bool) -> ScalarMask {
        ScalarMask(bits_from_fn(|k| f(self.0[k], other.0[k])))
    }
}

impl ScalarI32 {
    #[inline(always)]
    fn map(self, f: impl Fn(i32) -> i32) -> Self {
        ScalarI32(self.0.map(f))
    }

    #[inline(always)]
    fn zip(self, other: Self, f: impl Fn(i32, i32) -> i32) -> Self {
        ScalarI32(std::array::from_fn(|k| f(self.0[k], other.0[k])))
    }

    #[inline(always)]
    fn compare(self, other: Self, f: impl Fn(i32, i32) -> bool) -> ScalarMask {
        ScalarMask(bits_from_fn(|k| f(self.0[k], other.0[k])))
    }
}

/// Bit `k` set when `f(k)`.
#[inline(always)]
fn bits_from_fn(f: impl Fn(usize) -> bool) -> u8 {
    (0..8).fold(0u8, |bits, k| bits | (u8::from(f(k)) << k))
}

impl Lanes for Scalar {
    type F32 = ScalarF32;
    type I32 = ScalarI32;
    type Mask = ScalarMask;

    #[inline(always)]
    fn isa(self) -> Isa {
        Isa::Scalar
    }
    #[inline(always)]
    fn splat_f32(self, v: f32) -> ScalarF32 {
        ScalarF32([v; 8])
    }
    #[inline(always)]
    fn f32_from_array(self, a: [f32; 8]) -> ScalarF32 {
        ScalarF32(a)
    }
    #[inline(always)]
    fn load_f32(self, s: &[f32]) -> ScalarF32 {
        let mut a = [0.0; 8];
        a.copy_from_slice(&s[..8]);
        ScalarF32(a)
    }
    #[inline(always)]
    fn splat_i32(self, v: i32) -> ScalarI32 {
        ScalarI32([v; 8])
    }
    #[inline(always)]
    fn i32_from_array(self, a: [i32; 8]) -> ScalarI32 {
        ScalarI32(a)
    }
    #[inline(always)]
    fn load_i32(self, s: &[i32]) -> ScalarI32 {
        let mut a = [0; 8];
        a.copy_from_slice(&s[..8]);
        ScalarI32(a)
    }
    #[inline(always)]
    fn lane_index(self) -> ScalarI32 {
        ScalarI32([0, 1, 2, 3, 4, 5, 6, 7])
    }
    #[inline(always)]
    fn mask_from_bits(self, bits: u8) -> ScalarMask {
        ScalarMask(bits)
    }
    #[inline(always)]
    fn mask_all(self, value: bool) -> ScalarMask {
        ScalarMask(if value { 0xff } else { 0 })
    }
}

macro_rules! scalar_binary_ops {
    ($ty:ident, $($trait:ident $method:ident $op:expr;)*) => {$(
        impl $trait for $ty {
            type Output = $ty;
            #[inline(always)]
            fn $method(self, other: $ty) -> $ty {
                self.zip(other, $op)
            }
        }
    )*};
}

scalar_binary_ops!(ScalarF32,
    Add add |a, b| a + b;
    Sub sub |a, b| a - b;
    Mul mul |a, b| a * b;
    Div div |a, b| a / b;
);

scalar_binary_ops!(ScalarI32,
    Add add i32::wrapping_add;
    Sub sub i32::wrapping_sub;
    Mul mul i32::wrapping_mul;
    BitAnd bitand |a, b| a & b;
    BitOr bitor |a, b| a | b;
    BitXor bitxor |a, b| a ^ b;
);

impl Neg for ScalarF32 {
    type Output = ScalarF32;
    #[inline(always)]
    fn neg(self) -> ScalarF32 {
        self.map(|a| -a)
    }
}

impl Not for ScalarI32 {
    type Output = ScalarI32;
    #[inline(always)]
    fn not(self) -> ScalarI32 {
        self.map(|a| !a)
    }
}

impl F32x8 for ScalarF32 {
    type Lanes = Scalar;

    #[inline(always)]
    fn lanes(self) -> Scalar {
        Scalar
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        self.zip(other, min_f32)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        self.zip(other, max_f32)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        self.map(f32::sqrt)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        self.map(f32::abs)
    }
    #[inline(always)]
    fn floor(self) -> Self {
        self.map(rounding::floor)
    }
    #[inline(always)]
    fn round_ties_even(self) -> Self {
        self.map(rounding::round_ties_even)
    }
    #[inline(always)]
    fn simd_lt(self, other: Self) -> ScalarMask {
        self.compare(other, |a, b| a < b)
    }
    #[inline(always)]
    fn simd_le(self, other: Self) -> ScalarMask {
        self.compare(other, |a, b| a <= b)
    }
    #[inline(always)]
    fn simd_gt(self, other: Self) -> ScalarMask {
        self.compare(other, |a, b| a > b)
    }
    #[inline(always)]
    fn simd_ge(self, other: Self) -> ScalarMask {
        self.compare(other, |a, b| a >= b)
    }
    #[inline(always)]
    fn simd_eq(self, other: Self) -> ScalarMask {
        self.compare(other, |a, b| a == b)
    }
    #[inline(always)]
    fn simd_ne(self, other: Self) -> ScalarMask {
        self.compare(other, |a, b| a != b)
    }
    #[inline(always)]
    fn to_array(self) -> [f32; 8] {
        self.0
    }
    #[inline(always)]
    fn store(self, out: &mut [f32]) {
        out[..8].copy_from_slice(&self.0);
    }
    #[inline(always)]
    fn store_masked(self, mask: ScalarMask, out: &mut [f32]) {
        for (k, slot) in out[..8].iter_mut().enumerate() {
            if mask.0 & (1 << k) != 0 {
                *slot = self.0[k];
            }
        }
    }
    #[inline(always)]
    fn to_i32_trunc(self) -> ScalarI32 {
        ScalarI32(self.0.map(trunc_to_i32))
    }
    #[inline(always)]
    fn to_i32_floor(self) -> ScalarI32 {
        ScalarI32(self.0.map(|a| trunc_to_i32(rounding::floor(a))))
    }
    #[inline(always)]
    fn to_bits(self) -> ScalarI32 {
        ScalarI32(self.0.map(|a| a.to_bits() as i32))
    }
    #[inline(always)]
    fn from_bits(bits: ScalarI32) -> Self {
        ScalarF32(bits.0.map(|b| f32::from_bits(b as u32)))
    }
    #[inline(always)]
    fn extract(self, k: usize) -> f32 {
        self.0[k]
    }
    #[inline(always)]
    fn permute(self, index: ScalarI32) -> ScalarF32 {
        let mut out = [0.0; 8];
        for (value, &i) in out.iter_mut().zip(&index.0) {
            *value = self.0[(i & 7) as usize];
        }
        ScalarF32(out)
    }
    #[inline(always)]
    fn reduce_min(self) -> f32 {
        reduce(self.0, min_f32)
    }
    #[inline(always)]
    fn reduce_max(self) -> f32 {
        reduce(self.0, max_f32)
    }
}

impl I32x8 for ScalarI32 {
    type Lanes = Scalar;

    #[inline(always)]
    fn lanes(self) -> Scalar {
        Scalar
    }
    #[inline(always)]
    fn shl<const N: i32>(self) -> Self {
        const { assert!(N >= 0 && N < 32, "shift count must be in 0..32") };
        self.map(|a| a << N)
    }
    #[inline(always)]
    fn shr_arith<const N: i32>(self) -> Self {
        const { assert!(N >= 0 && N < 32, "shift count must be in 0..32") };
        self.map(|a| a >> N)
    }
    #[inline(always)]
    fn shr_logical<const N: i32>(self) -> Self {
        const { assert!(N >= 0 && N < 32, "shift count must be in 0..32") };
        self.map(|a| ((a as u32) >> N) as i32)
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        self.zip(other, i32::min)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        self.zip(other, i32::max)
    }
    #[inline(always)]
    fn simd_eq(self, other: Self) -> ScalarMask {
        self.compare(other, |a, b| a == b)
    }
    #[inline(always)]
    fn simd_gt(self, other: Self) -> ScalarMask {
        self.compare(other, |a, b| a > b)
    }
    #[inline(always)]
    fn simd_lt(self, other: Self) -> ScalarMask {
        self.compare(other, |a, b| a < b)
    }
    #[inline(always)]
    fn to_f32(self) -> ScalarF32 {
        ScalarF32(self.0.map(|a| a as f32))
    }
    #[inline(always)]
    fn to_array(self) -> [i32; 8] {
        self.0
    }
    #[inline(always)]
    fn store(self, out: &mut [i32]) {
        out[..8].copy_from_slice(&self.0);
    }
    #[inline(always)]
    fn gather_u32(self, table: &[u32]) -> Self {
        let Some(last) = table.len().checked_sub(1) else {
            return ScalarI32([0; 8]);
        };
        self.map(|index| table[usize::try_from(index).unwrap_or(0).min(last)] as i32)
    }
    #[inline(always)]
    fn extract(self, k: usize) -> i32 {
        self.0[k]
    }
    #[inline(always)]
    fn sign_bits(self) -> u8 {
        bits_from_fn(|k| self.0[k] < 0)
    }
}

impl Mask8 for ScalarMask {
    type Lanes = Scalar;

    #[inline(always)]
    fn lanes(self) -> Scalar {
        Scalar
    }
    #[inline(always)]
    fn and(self, other: Self) -> Self {
        ScalarMask(self.0 & other.0)
    }
    #[inline(always)]
    fn or(self, other: Self) -> Self {
        ScalarMask(self.0 | other.0)
    }
    #[inline(always)]
    fn xor(self, other: Self) -> Self {
        ScalarMask(self.0 ^ other.0)
    }
    #[inline(always)]
    fn not(self) -> Self {
        ScalarMask(!self.0)
    }
    #[inline(always)]
    fn and_not(self, other: Self) -> Self {
        ScalarMask(self.0 & !other.0)
    }
    #[inline(always)]
    fn any(self) -> bool {
        self.0 != 0
    }
    #[inline(always)]
    fn all(self) -> bool {
        self.0 == 0xff
    }
    #[inline(always)]
    fn none(self) -> bool {
        self.0 == 0
    }
    #[inline(always)]
    fn bits(self) -> u8 {
        self.0
    }
    #[inline(always)]
    fn count(self) -> u32 {
        self.0.count_ones()
    }
    #[inline(always)]
    fn select_f32(self, if_true: ScalarF32, if_false: ScalarF32) -> ScalarF32 {
        ScalarF32(std::array::from_fn(|k| {
            if self.0 & (1 << k) != 0 {
                if_true.0[k]
            } else {
                if_false.0[k]
            }
        }))
    }
    #[inline(always)]
    fn select_i32(self, if_true: ScalarI32, if_false: ScalarI32) -> ScalarI32 {
        ScalarI32(std::array::from_fn(|k| {
            if self.0 & (1 << k) != 0 {
                if_true.0[k]
            } else {
                if_false.0[k]
            }
        }))
    }
}
