//! Run-time CPU feature choices shared by the SIMD kernels.
//!
//! Each kernel checks the features it needs (`is_x86_feature_detected!`)
//! and also [`simd_allowed`], so that one switch, the environment
//! variable `PARVO_NO_AVX` (any value), turns every run-time AVX path off:
//! for A/B measurements in one binary, and as a way out should a kernel
//! misbehave on some CPU. The results are the same either way, bit for
//! bit, except where a kernel uses fused multiply-adds (EWA: the last
//! bits differ); every kernel is tested against the portable code it
//! replaces.

use std::sync::OnceLock;

/// False when `PARVO_NO_AVX` is set (read once per process).
pub(crate) fn simd_allowed() -> bool {
    static OK: OnceLock<bool> = OnceLock::new();
    *OK.get_or_init(|| std::env::var_os("PARVO_NO_AVX").is_none())
}

/// True when the CPU has AVX2 and FMA and [`simd_allowed`] (detected once).
#[cfg(target_arch = "x86_64")]
pub(crate) fn avx2_fma() -> bool {
    static OK: OnceLock<bool> = OnceLock::new();
    *OK.get_or_init(|| {
        simd_allowed() && is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma")
    })
}
