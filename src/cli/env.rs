//! `parvo sample --direction`: environment lookups by direction, read
//! from stdin as `x y z dxdx dydx dzdx dxdy dydy dzdy` (the direction and
//! its screen derivatives), one per line, same syntax and output as the
//! 2-D queries. A cube map comes as a KTX2/DDS cube (`--layer` picks the
//! cube of a cube-map array), an OpenEXR strip, or any strip or cross
//! [`parvo::env::cube::CubeLayout`] reads.

use std::io::{self, BufRead, Write};

use anyhow::{Context, Result, anyhow};
use parvo::env::cube::build_faces;
use parvo::env::{CubeSampler, DirQuery, LatLongSampler, latlong};
use parvo::io::Environment;
use parvo::io::source::interpret;
use parvo::sample::SamplerOptions;
use parvo::{ImageKind, MipChain, MipOptions, Texture};

use super::args::EnvArg;
use super::texture::TextureArgs;

/// A direction sampler of either kind.
enum EnvSampler {
    LatLong(Box<LatLongSampler>),
    Cube(CubeSampler),
}

impl EnvSampler {
    fn sample(&self, q: &DirQuery) -> [f32; 4] {
        match self {
            EnvSampler::LatLong(s) => s.sample(q),
            EnvSampler::Cube(s) => s.sample(q),
        }
    }
}

/// Build the sampler for `texture`, read as `env` or, without it, as the
/// environment the file records ([`parvo::io::source::interpret`], the
/// library's one reading); and the texture's channel count.
fn sampler(
    read: &TextureArgs,
    texture: &str,
    env: Option<EnvArg>,
    layer: Option<f32>,
    options: SamplerOptions,
) -> Result<(EnvSampler, usize)> {
    let loaded = read.load_environment(texture)?;
    let channels = loaded.base().format().channels as usize;
    let kind = loaded.info.kind;
    let direction_kind = match kind {
        ImageKind::Cube | ImageKind::CubeArray { .. } => env != Some(EnvArg::Latlong),
        ImageKind::Plain | ImageKind::LatLong => true,
        ImageKind::Array { .. } => false,
    };
    if !direction_kind {
        return Err(anyhow!(
            "`{texture}` is a {}: direction lookups read one cube map or a lat-long map",
            kind.describe()
        ));
    }
    // --layer on a texture that is not an array is refused.
    let picked = super::lookup::pick_image(texture, kind, layer)?;
    // A file's own levels are kept, with its rounding and wrap modes.
    let file = loaded.chain_options();
    let hint = env.map(|e| match e {
        EnvArg::Latlong => Environment::LatLong,
        EnvArg::Cube => Environment::Cube,
    });
    let source = interpret(loaded, texture, hint)
        .with_context(|| format!("cannot read texture `{texture}`"))?;
    let own = |levels: Vec<Texture>, build: &dyn Fn(Texture) -> parvo::Result<MipChain>| {
        let mut rest = levels.into_iter();
        match (rest.next(), rest.len()) {
            (Some(base), 0) => build(base),
            (Some(base), _) => {
                MipChain::from_levels(std::iter::once(base).chain(rest).collect(), file)
            }
            (None, _) => Err(parvo::Error::InvalidOption(
                "an image without levels".into(),
            )),
        }
    };
    let placement = source.placement;
    match source.kind {
        ImageKind::LatLong => {
            // Without levels of its own, the levels a lat-long map needs
            // (rows weighted by solid angle).
            let levels = source.images.into_iter().next().unwrap_or_default();
            let chain = own(levels, &latlong::build_chain)?;
            Ok((
                EnvSampler::LatLong(Box::new(
                    LatLongSampler::new(&chain, options)?.with_placement(placement),
                )),
                channels,
            ))
        }
        ImageKind::Cube | ImageKind::CubeArray { .. } => {
            // A KTX2 or DDS cube map (the cube --layer picks of an array)
            // keeps its levels; faces cut from a strip or cross are each
            // mip-mapped on their own (a strip's own levels would mix
            // faces once they are 1 texel high).
            let from_header = kind.is_cube();
            let faces: Vec<Vec<Texture>> =
                source.images.into_iter().skip(6 * picked).take(6).collect();
            let chains = if from_header {
                faces
                    .into_iter()
                    .map(|l| own(l, &|b| parvo::mip::build(b, &file)))
                    .collect::<parvo::Result<Vec<_>>>()?
            } else {
                build_faces(
                    faces.into_iter().map(|mut l| l.swap_remove(0)).collect(),
                    &MipOptions::default(),
                )?
            };
            Ok((
                EnvSampler::Cube(CubeSampler::new(&chains, options)?.with_placement(placement)),
                channels,
            ))
        }
        _ => Err(anyhow!(
            "`{texture}` records no environment (no OpenEXR envmap, no maketx \
             textureformat): say what it holds with --env latlong or --env cube"
        )),
    }
}

/// Run direction queries from stdin against `texture` read as `env` (or
/// as the environment the file records); `layer` picks the cube of a
/// cube-map array.
pub fn run(
    read: &TextureArgs,
    texture: &str,
    env: Option<EnvArg>,
    layer: Option<f32>,
    options: SamplerOptions,
    input: impl BufRead,
    mut out: impl Write,
) -> Result<()> {
    let (s, channels) = sampler(read, texture, env, layer, options)?;
    let mut text = String::new();
    for (n, line) in input.split(b'\n').enumerate() {
        let line = line.context("reading stdin")?;
        let q = match parse_direction(&line) {
            Ok(Some(q)) => q,
            Ok(None) => continue,
            Err(e) => {
                out.flush()?;
                return Err(anyhow!("stdin line {}: {e}", n + 1));
            }
        };
        text.clear();
        super::lookup::format_colour(&mut text, &s.sample(&q), channels);
        match out.write_all(text.as_bytes()) {
            Err(e) if e.kind() == io::ErrorKind::BrokenPipe => return Ok(()),
            r => r?,
        }
    }
    out.flush()?;
    Ok(())
}

/// One line of 9 numbers; `Ok(None)` for blank and comment lines.
fn parse_direction(raw: &[u8]) -> Result<Option<DirQuery>, String> {
    let line = std::str::from_utf8(raw).map_err(|_| "not valid UTF-8".to_string())?;
    let body = line.split('#').next().unwrap_or("");
    let v = body
        .split(|c: char| c.is_whitespace() || c == ',')
        .filter(|t| !t.is_empty())
        .map(|t| {
            t.parse::<f32>()
                .map_err(|_| format!("`{t}` is not a number"))
        })
        .collect::<Result<Vec<f32>, String>>()?;
    match v[..] {
        [] => Ok(None),
        [x, y, z, a, b, c, d, e, f] => Ok(Some(DirQuery::new([x, y, z], [a, b, c], [d, e, f]))),
        _ => Err(format!(
            "expected 9 numbers (x y z dxdx dydx dzdx dxdy dydy dzdy), got {}",
            v.len()
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn direction_lines_parse_and_bad_ones_say_why() {
        let q = parse_direction(b"1, 0 0  0.1 0 0 0 0.2 0 # c\n")
            .unwrap()
            .unwrap();
        assert_eq!(q.dir, [1.0, 0.0, 0.0]);
        assert_eq!(q.ddy, [0.0, 0.2, 0.0]);
        assert!(parse_direction(b"  # only a comment\n").unwrap().is_none());
        let e = parse_direction(b"1 2 3\n").unwrap_err();
        assert!(e.contains("9 numbers"), "{e}");
        let e = parse_direction(b"1 2 x 0 0 0 0 0 0\n").unwrap_err();
        assert!(e.contains("`x`"), "{e}");
    }
}
