//! The instruction sets the per-pixel shading kernels are compiled for.
//!
//! Every shading kernel is compiled once per instruction set, for every shader and lane program
//! (the longest part of building this crate). The library compiles them for every level. This
//! crate's own unit-test build compiles the scalar reference and one vector level (AVX2, or
//! NEON on AArch64): it is compiled beside the library, and with every level it took as long
//! as the library. The tests of the whole renderer over every level (`isa_identical` and the
//! reference scenes under `KANTELE_ISA`) run the library's kernels, all of them. The
//! `lean-kernels` feature gives the library the unit-test build's levels, for a quick build.

use kantele_lanes::{dispatch_within, Isa, IsaSet, LaneKernel};

#[cfg(not(any(test, feature = "lean-kernels")))]
type Compiled = kantele_lanes::EveryIsa;
#[cfg(any(test, feature = "lean-kernels"))]
type Compiled = ScalarAndOneVector;

/// The levels of the unit-test build and of the `lean-kernels` feature: the scalar reference
/// and one vector level.
#[cfg(any(test, feature = "lean-kernels"))]
struct ScalarAndOneVector;

#[cfg(any(test, feature = "lean-kernels"))]
impl IsaSet for ScalarAndOneVector {
    const SSE2: bool = false;
    const SSE41: bool = false;
    const AVX2: bool = true;
    const AVX512: bool = false;
    const NEON: bool = true;
}

/// Runs a shading kernel with `isa`, a level [`compiled_level`] gave.
#[inline]
pub(super) fn dispatch_shading<K: LaneKernel>(isa: Isa, kernel: K) -> K::Output {
    debug_assert!(
        Compiled::contains(isa),
        "{isa}: shading kernels not compiled"
    );
    dispatch_within::<Compiled, K>(isa, kernel)
}

/// The level a renderer draws with when `isa` (supported by this CPU) is asked for: `isa`
/// itself, except in the unit-test build and with `lean-kernels`, where a level whose kernels are not compiled gives
/// the widest compiled level that runs the same lanes or fewer: AVX-512 runs the AVX2 lanes
/// (same results, other encodings), SSE2 and SSE4.1 the scalar ones.
pub(super) fn compiled_level(isa: Isa) -> Isa {
    if Compiled::contains(isa) {
        isa
    } else if Compiled::contains(isa.lanes()) {
        isa.lanes()
    } else {
        Isa::Scalar
    }
}

/// Every level this CPU supports whose shading kernels are compiled: what tests that compare
/// levels go over.
#[cfg(test)]
pub(crate) fn compiled_supported() -> impl Iterator<Item = Isa> {
    Isa::supported().filter(|&isa| Compiled::contains(isa))
}
