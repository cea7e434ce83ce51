//! One query at a time: the path [`Sampler::sample`](super::Sampler::sample)
//! takes, chosen once per sampler.
//!
//! A rasterizer that shades while it rasterizes calls `sample` once per
//! pixel. The batch path ([`Sampler::run`](super::Sampler)) is built for
//! slices: it dispatches on the filters and mip mode per call, fills
//! blocks of 16 plans, and sends footprint assembly through the 16-lane
//! AVX-512 code, all of which a single query pays for in full. Here the
//! sampler picks, when it is made, a function monomorphised for its
//! filters, mip mode and kernel ([`pick`]); a call is then one indirect
//! call, the plan, and the probe(s) — the same functions the batch path
//! runs, so the results are the same bit for bit (`tests/core/sample_one.rs`).

use super::aniso;
use super::bilinear::{Filters, Lin, MagMin, Near, Rgba, pack};
use super::fetch::{Chain, Pixel, Store, Stored, with_chain};
use super::footprint::Lod;
#[cfg(target_arch = "x86_64")]
use super::simd;
use super::trilinear::{self, MIP_LINEAR, MIP_NEAREST, MIP_NONE};
use super::{Kernel, MipMode, Query, Sampler, SamplerOptions, TexelFilter, map4};
use crate::trace::NoTrace;

/// The untraced one-query function of a sampler.
///
/// `lod` and `o` are the sampler's own, or a copy with another LOD bias
/// (`Sampler::sample_bias`); the batched kernels take theirs from the
/// sampler and move their footprint instead.
///
/// It returns [`Rgba`] in registers, as the edge paths do (see there).
///
/// [`unpack`](super::bilinear::unpack) gives the four channels.
#[allow(improper_ctypes_definitions)] // called from Rust only: see `Rgba`
pub(super) type One = extern "C-unwind" fn(&Sampler, &Lod, &SamplerOptions, &Query) -> Rgba;

/// The untraced function of a 2×2 quad whose four queries share their
/// derivatives ([`super::quad_queries`]): λ, the levels and the probe
/// count are worked out once for the four.
pub(super) type Quad = fn(&Sampler, &[Query; 4]) -> [[f32; 4]; 4];

/// A sampler's one-query and quad functions.
#[derive(Clone, Copy)]
pub(super) struct Paths {
    pub one: One,
    pub quad: Quad,
}

impl std::fmt::Debug for Paths {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Paths")
    }
}

/// A filter pair made from the options (the batch path builds them in
/// `run_filters`).
trait FromOptions: Filters {
    fn from_options(o: &SamplerOptions) -> Self;
}

impl FromOptions for Near {
    #[inline(always)]
    fn from_options(_: &SamplerOptions) -> Self {
        Near
    }
}

impl FromOptions for Lin {
    #[inline(always)]
    fn from_options(_: &SamplerOptions) -> Self {
        Lin
    }
}

impl FromOptions for MagMin {
    #[inline(always)]
    fn from_options(o: &SamplerOptions) -> Self {
        MagMin {
            mag: o.mag,
            min: o.min,
        }
    }
}

/// The one-query and quad functions for `kernel` under `o` on a chain
/// stored as `store`.
pub(super) fn pick(kernel: Kernel, o: &SamplerOptions, store: &Store) -> Paths {
    use TexelFilter::{Linear, Nearest};
    macro_rules! by_mip {
        ($f:ty, $aniso:literal) => {
            match o.mip {
                MipMode::None => with_chain!(store, c => paths::<_, $f, MIP_NONE, $aniso>(c)),
                MipMode::Nearest => with_chain!(store, c => paths::<_, $f, MIP_NEAREST, $aniso>(c)),
                MipMode::Linear => with_chain!(store, c => paths::<_, $f, MIP_LINEAR, $aniso>(c)),
            }
        };
    }
    macro_rules! by_filters {
        ($aniso:literal) => {
            match (o.mag, o.min) {
                (Nearest, Nearest) => by_mip!(Near, $aniso),
                (Linear, Linear) => by_mip!(Lin, $aniso),
                _ => by_mip!(MagMin, $aniso),
            }
        };
    }
    match kernel {
        Kernel::Isotropic => by_filters!(false),
        Kernel::Texel => by_filters!(true),
        Kernel::Ewa | Kernel::Supersample | Kernel::Sat => Paths {
            one: batched,
            quad: batched_quad,
        },
    }
}

/// The functions for chains stored as `P` (the argument only names `P`):
/// one per storage, so that a call has no dispatch on the storage, whose
/// arms would meet in memory.
fn paths<P: Stored, F: FromOptions, const MIP: u8, const ANISO: bool>(_: &Chain<P>) -> Paths {
    Paths {
        one: texel::<P, F, MIP, ANISO>,
        quad: texel_quad::<P, F, MIP, ANISO>,
    }
}

/// The chain of `s`, stored as `P` ([`pick`] chose the functions by it).
#[inline(always)]
fn chain_of<P: Stored>(s: &Sampler) -> &Chain<P> {
    match P::of(&s.chain.store) {
        Some(c) => c,
        None => unreachable!("a sampler's functions are picked for its chain's storage"),
    }
}

fn batched_quad(s: &Sampler, qs: &[Query; 4]) -> [[f32; 4]; 4] {
    let mut out = [[0.0; 4]; 4];
    s.run(qs, &mut out, &mut NoTrace);
    out
}

/// A slice of one through the batch path (EWA, the reference and the
/// summed-area table do the same work per query either way).
#[allow(improper_ctypes_definitions)]
extern "C-unwind" fn batched(s: &Sampler, _: &Lod, _: &SamplerOptions, q: &Query) -> Rgba {
    let mut out = [[0.0; 4]];
    s.run(std::slice::from_ref(q), &mut out, &mut NoTrace);
    pack(out[0])
}

/// The isotropic or footprint-assembly lookup of one query.
#[allow(improper_ctypes_definitions)]
extern "C-unwind" fn texel<P: Stored, F: FromOptions, const MIP: u8, const ANISO: bool>(
    s: &Sampler,
    lod: &Lod,
    o: &SamplerOptions,
    q: &Query,
) -> Rgba {
    pack(texel_on::<P, F, MIP, ANISO>(s, chain_of(s), lod, o, q))
}

#[inline(always)]
fn texel_on<P: Pixel, F: FromOptions, const MIP: u8, const ANISO: bool>(
    s: &Sampler,
    c: &Chain<P>,
    lod: &Lod,
    o: &SamplerOptions,
    q: &Query,
) -> [f32; 4] {
    let a = &s.addr;
    let f = F::from_options(o);
    if ANISO {
        let setup = aniso::setup::<F, MIP>(lod, o, q);
        #[cfg(target_arch = "x86_64")]
        if let Some(table) = &s.simd
            && F::LINEAR
            && MIP != MIP_NONE
            && setup.probes > 1
        {
            let mut out = [[0.0; 4]];
            // SAFETY: `s.simd` is the level table of this sampler's chain
            // (`Sampler::build`), made only where the CPU runs AVX-512.
            #[allow(unsafe_code)]
            unsafe {
                simd::probes_of::<P, MIP, 16, 2>(c, table, a, &[setup], &mut out)
            };
            return out[0];
        }
        aniso::anisotropic(c, f, &setup, a, &mut NoTrace)
    } else {
        let plan = trilinear::plan::<F, MIP>(lod, o, q);
        let (u, v) = lod.reduce(q);
        trilinear::probe(c, f, &plan, u, v, a, &mut NoTrace)
    }
}

/// The lookups of a quad: one plan (or footprint-assembly set-up) for the
/// four, since they share their derivatives.
fn texel_quad<P: Stored, F: FromOptions, const MIP: u8, const ANISO: bool>(
    s: &Sampler,
    qs: &[Query; 4],
) -> [[f32; 4]; 4] {
    texel_quad_on::<P, F, MIP, ANISO>(s, chain_of(s), qs)
}

#[inline(always)]
fn texel_quad_on<P: Pixel, F: FromOptions, const MIP: u8, const ANISO: bool>(
    s: &Sampler,
    c: &Chain<P>,
    qs: &[Query; 4],
) -> [[f32; 4]; 4] {
    let (a, lod, o) = (&s.addr, &s.lod, &s.options);
    let f = F::from_options(o);
    if ANISO {
        let first = aniso::setup::<F, MIP>(lod, o, &qs[0]);
        let st = map4(*qs, |q| {
            let (u, v) = lod.reduce(&q);
            aniso::Setup { u, v, ..first }
        });
        #[cfg(target_arch = "x86_64")]
        if let Some(table) = &s.simd
            && F::LINEAR
            && MIP != MIP_NONE
        {
            let mut out = [[0.0; 4]; 4];
            // SAFETY: as in `texel_on`.
            #[allow(unsafe_code)]
            unsafe {
                simd::probes_of::<P, MIP, 64, 8>(c, table, a, &st, &mut out)
            };
            return out;
        }
        map4(st, |setup| {
            aniso::anisotropic(c, f, &setup, a, &mut NoTrace)
        })
    } else {
        let plan = trilinear::plan::<F, MIP>(lod, o, &qs[0]);
        map4(*qs, |q| {
            let (u, v) = lod.reduce(&q);
            trilinear::probe(c, f, &plan, u, v, a, &mut NoTrace)
        })
    }
}
