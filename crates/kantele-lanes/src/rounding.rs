//! Scalar `round_ties_even` and `floor` without the libm call the x86-64 baseline makes.

/// `x` rounded to the nearest integer, ties to even: the same bits as
/// [`f32::round_ties_even`] (−0.4 gives −0; NaN is quieted).
///
/// On x86-64 this is `roundss` when SSE4.1 is present (detected once; inlined as `vroundss`
/// into code compiled for AVX2), where the baseline target would call libm.
#[inline(always)]
pub fn round_ties_even(x: f32) -> f32 {
    #[cfg(target_arch = "x86_64")]
    {
        if cfg!(target_feature = "sse4.1") || std::arch::is_x86_feature_detected!("sse4.1") {
            // SAFETY: SSE4.1 is enabled at compile time or was detected at run time.
            return unsafe { x86::round_ties_even_sse41(x) };
        }
    }
    x.round_ties_even()
}

/// `x` rounded toward −∞: the same bits as [`f32::floor`] (−0 stays −0; NaN is quieted).
///
/// On x86-64 this is `roundss` when SSE4.1 is present (detected once), where the baseline
/// target would call libm.
#[inline(always)]
pub fn floor(x: f32) -> f32 {
    #[cfg(target_arch = "x86_64")]
    {
        if cfg!(target_feature = "sse4.1") || std::arch::is_x86_feature_detected!("sse4.1") {
            // SAFETY: SSE4.1 is enabled at compile time or was detected at run time.
            return unsafe { x86::floor_sse41(x) };
        }
    }
    x.floor()
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::*;

    /// `roundss` to nearest even. Callers must make sure SSE4.1 is available.
    #[inline]
    #[target_feature(enable = "sse4.1")]
    pub(super) unsafe fn round_ties_even_sse41(x: f32) -> f32 {
        let v = _mm_set_ss(x);
        _mm_cvtss_f32(_mm_round_ss::<
            { _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC },
        >(v, v))
    }

    /// `roundss` toward −∞. Callers must make sure SSE4.1 is available.
    #[inline]
    #[target_feature(enable = "sse4.1")]
    pub(super) unsafe fn floor_sse41(x: f32) -> f32 {
        let v = _mm_set_ss(x);
        _mm_cvtss_f32(_mm_round_ss::<{ _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC }>(v, v))
    }
}
