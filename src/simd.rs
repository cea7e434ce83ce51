//! The AVX-512 loads and stores the kernels share: 16 floats to and from a
//! register, through arrays, so a kernel's own code needs no `unsafe`.
//! Callers are compiled with AVX-512 F enabled (they checked the CPU).

#![cfg(target_arch = "x86_64")]

use std::arch::x86_64::{__m512, _mm512_loadu_ps, _mm512_storeu_ps};

/// `v` as one register (one unaligned load).
#[inline]
#[target_feature(enable = "avx512f")]
pub(crate) fn load_ps(v: &[f32; 16]) -> __m512 {
    #[allow(unsafe_code)]
    // SAFETY: AVX-512 F is enabled for this function; `v` is 16 readable
    // floats, exactly one unaligned load.
    unsafe {
        _mm512_loadu_ps(v.as_ptr())
    }
}

/// `v` into `d` (one unaligned store).
#[inline]
#[target_feature(enable = "avx512f")]
pub(crate) fn store_ps(d: &mut [f32; 16], v: __m512) {
    #[allow(unsafe_code)]
    // SAFETY: AVX-512 F is enabled for this function; `d` is 16 writable
    // floats, exactly one unaligned store.
    unsafe {
        _mm512_storeu_ps(d.as_mut_ptr(), v)
    }
}
