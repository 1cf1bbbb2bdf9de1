//! SIMD in one place: safe 8-lane types with one implementation per instruction set, chosen at
//! run time.
//!
//! The per-pixel path is written **once**, generic over a lane implementation ([`Lanes`]), and
//! instantiated for every instruction set the crate knows ([`Isa`]): plain Rust ([`Scalar`], the
//! readable reference and the fallback), SSE2 and SSE4.1 (`Sse2`, `Sse41`), AVX2 (`Avx2`, also
//! compiled a second time with AVX-512F/VL code generation: [`Isa::Avx512`]) on x86-64 and NEON
//! (`Neon`) on AArch64. A kernel is a type implementing [`LaneKernel`];
//! [`dispatch`] runs it with the implementation of the requested level:
//!
//! ```
//! use kantele_lanes::{dispatch, F32x8, Isa, LaneKernel, Lanes};
//!
//! /// Sums `a * b + c` over 8 lanes.
//! struct MulAdd<'a>(&'a [f32], &'a [f32], &'a [f32]);
//!
//! impl LaneKernel for MulAdd<'_> {
//!     type Output = [f32; 8];
//!     #[inline(always)]
//!     fn run<L: Lanes>(self, lanes: L) -> [f32; 8] {
//!         let (a, b, c) = (lanes.load_f32(self.0), lanes.load_f32(self.1), lanes.load_f32(self.2));
//!         (a * b + c).to_array() // two roundings on every instruction set: never a fused multiply-add
//!     }
//! }
//!
//! let (a, b, c) = ([1.5f32; 8], [2.0f32; 8], [0.25f32; 8]);
//! let best = dispatch(Isa::selected(), MulAdd(&a, &b, &c));
//! let reference = dispatch(Isa::Scalar, MulAdd(&a, &b, &c));
//! assert_eq!(best.map(f32::to_bits), reference.map(f32::to_bits));
//! ```
//!
//! # Design
//!
//! - **Tokens.** Each implementation is a zero-sized token type (`Avx2`, `Sse41`, …) that can
//!   only be constructed after runtime detection has confirmed the instruction set (`Avx2::new`
//!   returns `None` otherwise). Lane values ([`F32x8`], [`I32x8`], [`Mask8`]) can only be made
//!   through a token or from other lane values of the same implementation, so the existence of a
//!   value proves the instructions are available, and its methods are *safe* even though they
//!   call `std::arch` intrinsics. All `unsafe` code of the CPU path lives in this module, each
//!   block with a `// SAFETY:` comment (enforced by `clippy::undocumented_unsafe_blocks`).
//! - **`#[inline(always)]` everywhere, `#[target_feature]` once.** The lane methods carry no
//!   target feature of their own: alone, an AVX2 intrinsic could not be inlined into them.
//!   [`dispatch`] calls the kernel from a single `#[target_feature(enable = "avx2")]` (or
//!   `"sse4.1"`) entry point, and because the kernel and every lane method are
//!   `#[inline(always)]`, the whole kernel body is inlined into that entry point and compiled for
//!   its instruction set: `a * b` becomes one `vmulps`, with no calls. A kernel method that is
//!   *not* inlined would fall back to SSE2 code generation and call the intrinsics out of line,
//!   which is correct but slow, so mark the kernel's `run` and its helpers `#[inline(always)]`,
//!   and avoid handing lane code to std helpers in a closure (`[T; N]::map`): LLVM may keep
//!   such a closure out of line, compiled for the baseline.
//! - **Bit-identical everywhere, no fused multiply-add.** Every operation gives the same bits on
//!   every implementation for every input — ±0, ±∞, denormals (no flush-to-zero), huge values,
//!   NaN — so pictures do not depend on the machine. One exception, which Rust's own `f32`
//!   arithmetic shares: when arithmetic (`+ − × ÷`, `sqrt`, `floor`, `round_ties_even`)
//!   *produces* a NaN, it is a NaN everywhere but its payload and sign are unspecified (LLVM
//!   may commute `a + b`, which changes which input NaN x86 propagates). NaNs passed through
//!   `min`/`max`, `abs`, negation, selection, stores and bit casts keep their bits. `min`/`max` follow x86
//!   `minps`/`maxps` (`max(a, b) = if a > b { a } else { b }`), float-to-int conversion follows
//!   `cvttps2dq` (out of range or NaN gives `i32::MIN`), and the NEON and scalar implementations
//!   are written to match. The `fma` target feature is never enabled and no operation fuses:
//!   `a * b + c` always rounds twice, as in the scalar reference.
//! - **Reductions have a fixed order** (a tree: lanes `k` and `k + 4`, then `k` and `k + 2`,
//!   then 0 and 1), so `reduce_min`/`reduce_max` agree bit for bit even with NaN and ±0.
//!
//! The instruction set is chosen once per process by [`Isa::selected`]: the best one the CPU
//! supports ([`Isa::best`]), or the one named by the environment variable `KANTELE_ISA`
//! (`scalar`, `sse2`, `sse41`, `avx2`, `avx512`, `neon`) when that one is supported.
//!
//! [`round_ties_even`] and [`floor`] are scalar helpers for code outside the lanes: the x86-64
//! baseline turns `f32::round_ties_even` and `f32::floor` into libm calls, these use `roundss`
//! when SSE4.1 is present.
#![warn(missing_docs)]
#![warn(unsafe_op_in_unsafe_fn)]
#![deny(clippy::undocumented_unsafe_blocks)]

use std::fmt;
use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Not, Sub};
use std::str::FromStr;
use std::sync::OnceLock;

#[cfg(target_arch = "x86_64")]
mod avx2;
#[cfg(target_arch = "aarch64")]
mod neon;
mod prefetch;
mod rounding;
mod scalar;
#[cfg(target_arch = "x86_64")]
mod sse2;
#[cfg(test)]
mod tests;
// The texture sampler's lane operations.
mod texel_gather;

#[cfg(target_arch = "x86_64")]
pub use avx2::{Avx2, Avx2F32, Avx2I32, Avx2Mask};
#[cfg(target_arch = "aarch64")]
pub use neon::{Neon, NeonF32, NeonI32, NeonMask};
pub use prefetch::prefetch;
pub use rounding::{floor, round_ties_even};
pub use scalar::{Scalar, ScalarF32, ScalarI32, ScalarMask};
#[cfg(target_arch = "x86_64")]
pub use sse2::{Sse2, Sse41, SseF32, SseI32, SseLevel, SseMask};
pub use texel_gather::{
    bilinear15, filter15_reference, gather_texel_pair15, lerp15, lerp15_channels, unpack_words15,
    Footprint15, TexelGather,
};

/// The environment variable that forces an instruction set (see [`Isa::from_env`]).
pub const ISA_ENV: &str = "KANTELE_ISA";

/// Instruction-set levels, from the portable reference to the widest.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Isa {
    /// Plain Rust over arrays: the readable reference, available everywhere.
    Scalar,
    /// x86-64 SSE2 (two 4-lane halves), always available on x86-64.
    Sse2,
    /// x86-64 SSE4.1: SSE2 plus `roundps`, `blendvps`, `pmulld`, `pminsd`/`pmaxsd`.
    Sse41,
    /// x86-64 AVX2: one 256-bit register per value (FMA is never used).
    Avx2,
    /// AArch64 NEON (two 4-lane halves).
    Neon,
    /// x86-64 with AVX-512F and AVX-512VL: the [`Isa::Avx2`] lanes (same 256-bit operations,
    /// same results) compiled with EVEX encodings and 32 vector registers instead of 16.
    Avx512,
}

impl Isa {
    /// Every level, in declaration order.
    pub const ALL: [Isa; 6] = [
        Isa::Scalar,
        Isa::Sse2,
        Isa::Sse41,
        Isa::Avx2,
        Isa::Neon,
        Isa::Avx512,
    ];

    /// The lower-case name used by `KANTELE_ISA`, [`Display`](fmt::Display) and
    /// [`FromStr`]: `scalar`, `sse2`, `sse41`, `avx2`, `avx512` or `neon`.
    pub fn name(self) -> &'static str {
        match self {
            Isa::Scalar => "scalar",
            Isa::Sse2 => "sse2",
            Isa::Sse41 => "sse41",
            Isa::Avx2 => "avx2",
            Isa::Neon => "neon",
            Isa::Avx512 => "avx512",
        }
    }

    /// The lane implementation this level runs ([`Lanes::isa`] of its kernels): the level
    /// itself, except [`Isa::Avx512`], which compiles the [`Isa::Avx2`] lanes.
    pub fn lanes(self) -> Isa {
        match self {
            Isa::Avx512 => Isa::Avx2,
            isa => isa,
        }
    }

    /// Whether this CPU can run this level (runtime detection; the result is cached by `std`).
    pub fn is_supported(self) -> bool {
        match self {
            Isa::Scalar => true,
            #[cfg(target_arch = "x86_64")]
            Isa::Sse2 => Sse2::new().is_some(),
            #[cfg(target_arch = "x86_64")]
            Isa::Sse41 => Sse41::new().is_some(),
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => Avx2::new().is_some(),
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => Avx2::new().is_some() && avx2::has_avx512(),
            #[cfg(target_arch = "aarch64")]
            Isa::Neon => Neon::new().is_some(),
            #[allow(unreachable_patterns)]
            _ => false,
        }
    }

    /// Every level this CPU supports, in declaration order (always [`Isa::Scalar`] first).
    pub fn supported() -> impl Iterator<Item = Isa> {
        Isa::ALL.into_iter().filter(|isa| isa.is_supported())
    }

    /// The best level this CPU supports: AVX-512, then AVX2, SSE4.1 and SSE2 on x86-64; NEON
    /// on AArch64; [`Isa::Scalar`] elsewhere.
    pub fn best() -> Isa {
        [Isa::Avx512, Isa::Avx2, Isa::Sse41, Isa::Sse2, Isa::Neon]
            .into_iter()
            .find(|isa| isa.is_supported())
            .unwrap_or(Isa::Scalar)
    }

    /// The level forced by the environment variable `KANTELE_ISA`: `Ok(None)` when it is unset
    /// or empty, an error naming the accepted values when it names no level. Whether the level
    /// is supported is not checked here (see [`Isa::is_supported`]).
    pub fn from_env() -> Result<Option<Isa>, String> {
        match std::env::var(ISA_ENV) {
            Ok(value) => parse_override(Some(&value)),
            Err(std::env::VarError::NotPresent) => Ok(None),
            Err(std::env::VarError::NotUnicode(_)) => {
                Err(format!("{ISA_ENV} is not valid Unicode"))
            }
        }
    }

    /// What a front end tells its user about `KANTELE_ISA`, which the renderer reads without
    /// complaint ([`Isa::selected`]): an error (one line, naming the variable) when it names
    /// no level; `Ok(Some(warning))` when it names a level this CPU lacks, which renders
    /// replace by [`Isa::best`]; `Ok(None)` when it is unset, empty or supported.
    pub fn env_warning() -> Result<Option<String>, String> {
        Ok(Isa::from_env()?
            .filter(|forced| !forced.is_supported())
            .map(|forced| {
                format!(
                    "{ISA_ENV}={forced}: this CPU does not support it; using {}",
                    Isa::best()
                )
            }))
    }

    /// The level this process uses, decided once and cached: the `KANTELE_ISA` level when it
    /// is set, valid and supported by this CPU, otherwise [`Isa::best`]. (An invalid or
    /// unsupported `KANTELE_ISA` is ignored here; front ends report it with [`Isa::from_env`].)
    pub fn selected() -> Isa {
        static SELECTED: OnceLock<Isa> = OnceLock::new();
        *SELECTED.get_or_init(|| choose(Isa::from_env().ok().flatten()))
    }
}

/// Parses the value of `KANTELE_ISA` (`None` when unset): empty means no override.
fn parse_override(value: Option<&str>) -> Result<Option<Isa>, String> {
    match value.map(str::trim) {
        None | Some("") => Ok(None),
        Some(name) => name
            .parse::<Isa>()
            .map(Some)
            .map_err(|e| format!("{ISA_ENV}: {e}")),
    }
}

/// The level to use given an override: the override when supported, else the best level.
fn choose(forced: Option<Isa>) -> Isa {
    match forced {
        Some(isa) if isa.is_supported() => isa,
        _ => Isa::best(),
    }
}

impl fmt::Display for Isa {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Isa {
    type Err = String;

    /// Parses a level name, ignoring ASCII case; `sse4.1` is accepted for `sse41`.
    fn from_str(s: &str) -> Result<Isa, String> {
        let lower = s.to_ascii_lowercase();
        let name = if lower == "sse4.1" { "sse41" } else { &lower };
        Isa::ALL
            .into_iter()
            .find(|isa| isa.name() == name)
            .ok_or_else(|| {
                format!(
                    "unknown instruction set `{s}` (expected one of scalar, sse2, sse41, avx2, avx512, neon)"
                )
            })
    }
}

/// A computation written once over a lane implementation; [`dispatch`] runs it.
///
/// Mark `run` (and every helper it calls) `#[inline(always)]`, so that it is compiled inside
/// the instruction set's entry point (see the module docs).
pub trait LaneKernel {
    /// What the kernel returns.
    type Output;
    /// Runs the kernel with the lane implementation `lanes`.
    fn run<L: Lanes>(self, lanes: L) -> Self::Output;
}

/// Runs `kernel` with the implementation of `isa`, compiled for that instruction set.
///
/// `isa` must be supported by this CPU; an unsupported level (NEON on x86-64, AVX2 on a CPU
/// without it) falls back to [`Isa::Scalar`]. The kernel can tell which implementation it got
/// from [`Lanes::isa`] ([`Isa::Avx512`] runs the AVX2 lanes: see [`Isa::lanes`]).
#[inline]
pub fn dispatch<K: LaneKernel>(isa: Isa, kernel: K) -> K::Output {
    dispatch_within::<EveryIsa, K>(isa, kernel)
}

/// A set of instruction-set levels for [`dispatch_within`]: each constant says whether that
/// level's entry point is compiled. The scalar reference always is.
///
/// The constants are read where a kernel is instantiated, so a level left out is never
/// compiled for that kernel: no machine code, no compile time.
pub trait IsaSet {
    /// [`Isa::Sse2`].
    const SSE2: bool;
    /// [`Isa::Sse41`].
    const SSE41: bool;
    /// [`Isa::Avx2`].
    const AVX2: bool;
    /// [`Isa::Avx512`].
    const AVX512: bool;
    /// [`Isa::Neon`].
    const NEON: bool;

    /// Whether `isa`'s entry point is compiled.
    fn contains(isa: Isa) -> bool {
        match isa {
            Isa::Scalar => true,
            Isa::Sse2 => Self::SSE2,
            Isa::Sse41 => Self::SSE41,
            Isa::Avx2 => Self::AVX2,
            Isa::Avx512 => Self::AVX512,
            Isa::Neon => Self::NEON,
        }
    }
}

/// Every level: the set [`dispatch`] compiles.
#[derive(Clone, Copy, Debug)]
pub struct EveryIsa;

impl IsaSet for EveryIsa {
    const SSE2: bool = true;
    const SSE41: bool = true;
    const AVX2: bool = true;
    const AVX512: bool = true;
    const NEON: bool = true;
}

/// [`dispatch`] with only the levels of `S` compiled: a level outside `S`, like one the CPU
/// lacks, falls back to [`Isa::Scalar`].
#[inline]
pub fn dispatch_within<S: IsaSet, K: LaneKernel>(isa: Isa, kernel: K) -> K::Output {
    // Each guard is a constant of `S` by itself, which the compiler resolves when it
    // instantiates this function, before it generates code for the arm.
    match isa {
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 if S::AVX512 => {
            if let Some(token) = Avx2::new().filter(|_| avx2::has_avx512()) {
                return avx2::run_avx512(token, kernel);
            }
        }
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 if S::AVX2 => {
            if let Some(token) = Avx2::new() {
                return avx2::run(token, kernel);
            }
        }
        #[cfg(target_arch = "x86_64")]
        Isa::Sse41 if S::SSE41 => {
            if let Some(token) = Sse41::new() {
                return sse2::run_sse41(token, kernel);
            }
        }
        #[cfg(target_arch = "x86_64")]
        Isa::Sse2 if S::SSE2 => {
            if let Some(token) = Sse2::new() {
                return run_out_of_line(token, kernel);
            }
        }
        #[cfg(target_arch = "aarch64")]
        Isa::Neon if S::NEON => {
            if let Some(token) = Neon::new() {
                return run_out_of_line(token, kernel);
            }
        }
        _ => {}
    }
    run_out_of_line(Scalar, kernel)
}

/// Runs `kernel` with `lanes` in a function of its own, as the `#[target_feature]` entry
/// points of the other levels do. Inlined into [`dispatch`] instead, the scalar and SSE2
/// kernels made every `dispatch` a function of several kilobytes with a frame of up to 16 KiB
/// (probed page by page), paid on each call whatever the level. Now `dispatch` is a few
/// instructions, and a third of its instances are inlined into their callers.
#[inline(never)]
fn run_out_of_line<L: Lanes, K: LaneKernel>(lanes: L, kernel: K) -> K::Output {
    kernel.run(lanes)
}

/// The mask type of a lane value's implementation.
pub type MaskOf<L> = <L as Lanes>::Mask;

/// A zero-sized token proving that an instruction set is available; lane values are made
/// through it.
pub trait Lanes: Copy + fmt::Debug + Send + Sync + 'static {
    /// 8 × `f32`.
    type F32: F32x8<Lanes = Self>;
    /// 8 × `i32`.
    type I32: I32x8<Lanes = Self> + TexelGather;
    /// 8 lane booleans.
    type Mask: Mask8<Lanes = Self>;

    /// The instruction set of this implementation.
    fn isa(self) -> Isa;
    /// Every lane `v`.
    fn splat_f32(self, v: f32) -> Self::F32;
    /// Lane `k` is `a[k]`.
    fn f32_from_array(self, a: [f32; 8]) -> Self::F32;
    /// The first 8 elements of `s`. Panics if `s` has fewer than 8.
    fn load_f32(self, s: &[f32]) -> Self::F32;
    /// Every lane `v`.
    fn splat_i32(self, v: i32) -> Self::I32;
    /// Lane `k` is `a[k]`.
    fn i32_from_array(self, a: [i32; 8]) -> Self::I32;
    /// The first 8 elements of `s`. Panics if `s` has fewer than 8.
    fn load_i32(self, s: &[i32]) -> Self::I32;
    /// `[0, 1, 2, 3, 4, 5, 6, 7]`.
    fn lane_index(self) -> Self::I32;
    /// Lane `k` is set when bit `k` of `bits` is set.
    fn mask_from_bits(self, bits: u8) -> Self::Mask;
    /// Every lane `value`.
    fn mask_all(self, value: bool) -> Self::Mask;
}

/// 8 × `f32`. Arithmetic is IEEE 754 single precision, rounded to nearest even, lane by lane,
/// with x86 NaN propagation; every implementation gives the same bits.
pub trait F32x8:
    Copy
    + fmt::Debug
    + Send
    + Sync
    + 'static
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// The implementation's token.
    type Lanes: Lanes;

    /// The token of this value's implementation.
    fn lanes(self) -> Self::Lanes;
    /// `if self < other { self } else { other }` per lane (x86 `minps`: NaN or equal lanes give
    /// `other`).
    fn min(self, other: Self) -> Self;
    /// `if self > other { self } else { other }` per lane (x86 `maxps`: NaN or equal lanes give
    /// `other`).
    fn max(self, other: Self) -> Self;
    /// Correctly rounded square root.
    fn sqrt(self) -> Self;
    /// The sign bit cleared (NaN too).
    fn abs(self) -> Self;
    /// Rounded toward −∞ (−0 stays −0; NaN is quieted).
    fn floor(self) -> Self;
    /// Rounded to the nearest integer, ties to even (−0.4 gives −0; NaN is quieted).
    fn round_ties_even(self) -> Self;
    /// `self < other` (false for NaN).
    fn simd_lt(self, other: Self) -> MaskOf<Self::Lanes>;
    /// `self <= other` (false for NaN).
    fn simd_le(self, other: Self) -> MaskOf<Self::Lanes>;
    /// `self > other` (false for NaN).
    fn simd_gt(self, other: Self) -> MaskOf<Self::Lanes>;
    /// `self >= other` (false for NaN).
    fn simd_ge(self, other: Self) -> MaskOf<Self::Lanes>;
    /// `self == other` (false for NaN; `-0 == +0`).
    fn simd_eq(self, other: Self) -> MaskOf<Self::Lanes>;
    /// `self != other` (true for NaN).
    fn simd_ne(self, other: Self) -> MaskOf<Self::Lanes>;
    /// The lanes as an array.
    fn to_array(self) -> [f32; 8];
    /// Writes the lanes to the first 8 elements of `out`. Panics if `out` has fewer than 8.
    fn store(self, out: &mut [f32]);
    /// Writes the lanes set in `mask` to the first 8 elements of `out`; the others keep their
    /// value (read-modify-write of all 8). Panics if `out` has fewer than 8.
    fn store_masked(self, mask: MaskOf<Self::Lanes>, out: &mut [f32]);
    /// Converted toward zero (`cvttps2dq`): NaN and values outside the `i32` range give
    /// `i32::MIN`.
    fn to_i32_trunc(self) -> <Self::Lanes as Lanes>::I32;
    /// [`floor`](F32x8::floor), then [`to_i32_trunc`](F32x8::to_i32_trunc).
    fn to_i32_floor(self) -> <Self::Lanes as Lanes>::I32;
    /// The IEEE bit patterns.
    fn to_bits(self) -> <Self::Lanes as Lanes>::I32;
    /// The floats with these bit patterns.
    fn from_bits(bits: <Self::Lanes as Lanes>::I32) -> Self;
    /// Lane `k`. Panics if `k >= 8`.
    fn extract(self, k: usize) -> f32;
    /// Lanes moved: lane `k` of the result is lane `index[k] mod 8` of `self` (AVX2
    /// `vpermps`; the bits of the value move unchanged).
    fn permute(self, index: <Self::Lanes as Lanes>::I32) -> Self;
    /// The [`min`](F32x8::min) of all lanes, as the tree `min(min(min(a0,a4), min(a2,a6)),
    /// min(min(a1,a5), min(a3,a7)))`.
    fn reduce_min(self) -> f32;
    /// The [`max`](F32x8::max) of all lanes, in the same tree order as
    /// [`reduce_min`](F32x8::reduce_min).
    fn reduce_max(self) -> f32;
}

/// [`F32x8::permute`] through arrays, for implementations without a permutation across all
/// eight lanes (SSE2 and NEON hold two 4-lane halves).
#[inline(always)]
fn permute_through_arrays<L: Lanes>(value: L::F32, index: L::I32) -> L::F32 {
    let lanes = value.lanes();
    let (value, index) = (value.to_array(), index.to_array());
    let mut out = [0.0; 8];
    for (lane, &i) in out.iter_mut().zip(&index) {
        *lane = value[(i & 7) as usize];
    }
    lanes.f32_from_array(out)
}

/// 8 × `i32`, two's complement: arithmetic wraps (the low 32 bits).
pub trait I32x8:
    Copy
    + fmt::Debug
    + Send
    + Sync
    + 'static
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + BitAnd<Output = Self>
    + BitOr<Output = Self>
    + BitXor<Output = Self>
    + Not<Output = Self>
{
    /// The implementation's token.
    type Lanes: Lanes;

    /// The token of this value's implementation.
    fn lanes(self) -> Self::Lanes;
    /// Shifted left by `N` (`0..32`, checked at compile time).
    fn shl<const N: i32>(self) -> Self;
    /// Shifted right by `N` (`0..32`), copying the sign bit.
    fn shr_arith<const N: i32>(self) -> Self;
    /// Shifted right by `N` (`0..32`), shifting in zeros.
    fn shr_logical<const N: i32>(self) -> Self;
    /// The smaller per lane (signed).
    fn min(self, other: Self) -> Self;
    /// The larger per lane (signed).
    fn max(self, other: Self) -> Self;
    /// `self == other`.
    fn simd_eq(self, other: Self) -> MaskOf<Self::Lanes>;
    /// `self > other` (signed).
    fn simd_gt(self, other: Self) -> MaskOf<Self::Lanes>;
    /// `self < other` (signed).
    fn simd_lt(self, other: Self) -> MaskOf<Self::Lanes>;
    /// Converted to the nearest `f32`, ties to even (`cvtdq2ps`).
    fn to_f32(self) -> <Self::Lanes as Lanes>::F32;
    /// The lanes as an array.
    fn to_array(self) -> [i32; 8];
    /// Writes the lanes to the first 8 elements of `out`. Panics if `out` has fewer than 8.
    fn store(self, out: &mut [i32]);
    /// Lane `k` is `table[clamp(self[k], 0, table.len() - 1)]` (as `i32` bits); all zeros when
    /// `table` is empty. AVX2 uses `vpgatherdd`.
    fn gather_u32(self, table: &[u32]) -> Self;
    /// Lane `k`. Panics if `k >= 8`.
    fn extract(self, k: usize) -> i32;
    /// Bit `k` is the sign bit of lane `k` (`movmskps`).
    fn sign_bits(self) -> u8;
}

/// 8 lane booleans. Selection is a method of the mask:
/// `mask.select_f32(if_true, if_false)`.
pub trait Mask8: Copy + fmt::Debug + Send + Sync + 'static {
    /// The implementation's token.
    type Lanes: Lanes;

    /// The token of this value's implementation.
    fn lanes(self) -> Self::Lanes;
    /// Lanes set in both.
    fn and(self, other: Self) -> Self;
    /// Lanes set in either.
    fn or(self, other: Self) -> Self;
    /// Lanes set in exactly one.
    fn xor(self, other: Self) -> Self;
    /// Lanes not set.
    fn not(self) -> Self;
    /// Lanes set in `self` but not in `other` (`self & !other`).
    fn and_not(self, other: Self) -> Self;
    /// Whether any lane is set.
    fn any(self) -> bool;
    /// Whether every lane is set.
    fn all(self) -> bool;
    /// Whether no lane is set.
    fn none(self) -> bool;
    /// Bit `k` set when lane `k` is set.
    fn bits(self) -> u8;
    /// How many lanes are set.
    fn count(self) -> u32;
    /// Per lane: `if_true` where set, else `if_false`.
    fn select_f32(
        self,
        if_true: <Self::Lanes as Lanes>::F32,
        if_false: <Self::Lanes as Lanes>::F32,
    ) -> <Self::Lanes as Lanes>::F32;
    /// Per lane: `if_true` where set, else `if_false`.
    fn select_i32(
        self,
        if_true: <Self::Lanes as Lanes>::I32,
        if_false: <Self::Lanes as Lanes>::I32,
    ) -> <Self::Lanes as Lanes>::I32;
}
