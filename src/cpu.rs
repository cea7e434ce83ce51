//! Run-time CPU feature probes: the one place that asks the CPU what it
//! has (`is_x86_feature_detected!`). Every SIMD kernel calls the probe of
//! its feature set here.
//!
//! Each probe whose kernels run by default also checks [`simd_allowed`],
//! so that one switch, the environment variable `PARVO_NO_AVX` (any
//! value), turns every run-time AVX path off: for A/B measurements in one
//! binary, and as a way out should a kernel misbehave on some CPU. The
//! results are the same either way, bit for bit, except where a kernel
//! uses fused multiply-adds (EWA: the last bits differ); every kernel is
//! tested against the portable code it replaces. Probes are answered once
//! per process; on other architectures they answer false.

use std::sync::OnceLock;

/// False when `PARVO_NO_AVX` is set (read once per process).
pub(crate) fn simd_allowed() -> bool {
    static OK: OnceLock<bool> = OnceLock::new();
    *OK.get_or_init(|| std::env::var_os("PARVO_NO_AVX").is_none())
}

/// True when the CPU has AVX2 and FMA (whatever `PARVO_NO_AVX` says).
pub(crate) fn avx2_fma_detected() -> bool {
    static OK: OnceLock<bool> = OnceLock::new();
    *OK.get_or_init(|| {
        #[cfg(target_arch = "x86_64")]
        return is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma");
        #[cfg(not(target_arch = "x86_64"))]
        false
    })
}

/// True when the CPU has AVX2 and FMA and [`simd_allowed`]: the EWA
/// kernels and the separable mip row kernel.
pub(crate) fn avx2_fma() -> bool {
    simd_allowed() && avx2_fma_detected()
}

/// True when the CPU has AVX-512 F, BW, DQ, VL and VBMI and
/// [`simd_allowed`]: the sampler's AVX-512 paths (`sample/simd.rs`).
pub(crate) fn avx512_sample() -> bool {
    static OK: OnceLock<bool> = OnceLock::new();
    *OK.get_or_init(|| {
        #[cfg(target_arch = "x86_64")]
        return simd_allowed()
            && is_x86_feature_detected!("avx512f")
            && is_x86_feature_detected!("avx512bw")
            && is_x86_feature_detected!("avx512dq")
            && is_x86_feature_detected!("avx512vl")
            && is_x86_feature_detected!("avx512vbmi");
        #[cfg(not(target_arch = "x86_64"))]
        false
    })
}

/// True when the CPU has AVX-512 F, BW, VBMI and VNNI (whatever
/// `PARVO_NO_AVX` says): the sRGB 8-bit box kernel (`mip/srgb_simd.rs`).
pub(crate) fn avx512_vnni_detected() -> bool {
    static OK: OnceLock<bool> = OnceLock::new();
    *OK.get_or_init(|| {
        #[cfg(target_arch = "x86_64")]
        return is_x86_feature_detected!("avx512f")
            && is_x86_feature_detected!("avx512bw")
            && is_x86_feature_detected!("avx512vbmi")
            && is_x86_feature_detected!("avx512vnni");
        #[cfg(not(target_arch = "x86_64"))]
        false
    })
}
