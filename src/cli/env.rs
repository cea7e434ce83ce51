//! `parvo sample --direction`: environment lookups by direction, read
//! from stdin as `x y z dxdx dydx dzdx dxdy dydy dzdy` (the direction and
//! its screen derivatives), one per line, same syntax and output as the
//! 2-D queries.

use std::io::{self, BufRead, Write};

use anyhow::{Context, Result, anyhow};
use parvo::MipOptions;
use parvo::env::cube::{build_faces, faces_from_strip};
use parvo::env::{CubeSampler, DirQuery, LatLongSampler, latlong};
use parvo::io::Environment;
use parvo::sample::SamplerOptions;

use super::texture::TextureArgs;

/// How `--env` reads the texture.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum EnvArg {
    /// A lat-long (equirectangular) map, y up, as OpenImageIO reads one.
    Latlong,
    /// A vertical strip of six square faces (w x 6w, +x -x +y -y +z -z from the top).
    Cube,
}

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
/// environment the file records; and the texture's channel count.
fn sampler(
    read: &TextureArgs,
    texture: &str,
    env: Option<EnvArg>,
    options: SamplerOptions,
) -> Result<(EnvSampler, usize)> {
    let loaded = read.load_environment(texture)?;
    let channels = loaded.base().format().channels as usize;
    let env = match (env, loaded.info.environment) {
        (Some(e), _) => e,
        (None, Some(Environment::LatLong)) => EnvArg::Latlong,
        (None, Some(Environment::Cube)) => EnvArg::Cube,
        (None, None) => {
            return Err(anyhow!(
                "`{texture}` records no environment (no OpenEXR envmap, no maketx \
                 textureformat): say what it holds with --env latlong or --env cube"
            ));
        }
    };
    match env {
        EnvArg::Latlong => {
            // A file's own levels are kept; otherwise the levels are built
            // as a lat-long map needs them (rows weighted by solid angle).
            let chain = if loaded.levels.len() > 1 {
                loaded
                    .into_chain()
                    .with_context(|| format!("cannot read texture `{texture}`"))?
                    .0
            } else {
                latlong::build_chain(loaded.into_base())?
            };
            Ok((
                EnvSampler::LatLong(Box::new(LatLongSampler::new(&chain, options)?)),
                channels,
            ))
        }
        EnvArg::Cube => {
            // The faces of level 0, each mip-mapped on its own (a strip's
            // own levels would mix faces once they are 1 texel high).
            let faces = faces_from_strip(&loaded.into_base())
                .with_context(|| format!("cannot read `{texture}` as a cube map"))?;
            let chains = build_faces(faces, &MipOptions::default())?;
            Ok((
                EnvSampler::Cube(CubeSampler::new(&chains, options)?),
                channels,
            ))
        }
    }
}

/// Run direction queries from stdin against `texture` read as `env` (or
/// as the environment the file records).
pub fn run(
    read: &TextureArgs,
    texture: &str,
    env: Option<EnvArg>,
    options: SamplerOptions,
    input: impl BufRead,
    mut out: impl Write,
) -> Result<()> {
    let (s, channels) = sampler(read, texture, env, options)?;
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
        super::sample::format_colour(&mut text, &s.sample(&q), channels);
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
