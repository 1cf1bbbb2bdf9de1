//! A cache hint: ask the CPU to start loading a value that the caller will read soon.
//!
//! The per-pixel path reads each triangle's setup record and vertex varyings when the triangle
//! reaches a tile; on meshes with many small triangles those reads are scattered over megabytes
//! written by the geometry stage and miss the cache. Hinting the next triangle's records while
//! the current one is shaded hides part of that latency. A hint changes no result.

/// Hints that the cache lines holding the first and the last byte of `value` will be read soon
/// (x86-64: `prefetcht0`; elsewhere nothing).
#[inline(always)]
pub fn prefetch<T: ?Sized>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        let first: *const i8 = (value as *const T).cast();
        let size = std::mem::size_of_val(value);
        let last = first.wrapping_add(size.saturating_sub(1));
        // SAFETY: `prefetcht0` (SSE, part of every x86-64 CPU) is a hint: it never faults and
        // makes no data visible to the program, whatever the address; both addresses lie
        // within `value` anyway.
        unsafe {
            _mm_prefetch::<_MM_HINT_T0>(first);
            _mm_prefetch::<_MM_HINT_T0>(last);
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}
