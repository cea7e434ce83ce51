//! `parvo sample --direction`: environment lookups by direction, read
//! from stdin as `x y z dxdx dydx dzdx dxdy dydy dzdy` (the direction and
//! its screen derivatives), one per line, same syntax and output as the
//! 2-D queries. A cube map comes as a KTX2/DDS cube (`--layer` picks the
//! cube of a cube-map array), an OpenEXR strip, or any strip or cross
//! [`parvo::env::cube::CubeLayout`] reads.

use std::io::{self, BufRead, Write};

use anyhow::{Context, Result, anyhow};
use parvo::MipOptions;
use parvo::env::cube::{build_faces, faces_from_image, faces_from_strip};
use parvo::env::{CubeSampler, DirQuery, Kind, LatLongSampler, latlong};
use parvo::io::Environment;
use parvo::sample::SamplerOptions;

use super::texture::TextureArgs;

/// How `--env` reads the texture.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum EnvArg {
    /// A lat-long (equirectangular) map, y up, as OpenImageIO reads one.
    Latlong,
    /// Six square faces in one image: a strip (w x 6w, 6w x w) or a cross (4w x 3w, 3w x 4w).
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
    layer: Option<f32>,
    options: SamplerOptions,
) -> Result<(EnvSampler, usize)> {
    let loaded = read.load_environment(texture)?;
    let channels = loaded.base().format().channels as usize;
    let kind = loaded.info.kind;
    match kind {
        Kind::Cube | Kind::CubeArray { .. } if env != Some(EnvArg::Latlong) => {
            // A KTX2 or DDS cube map, or the cube --layer picks of a
            // cube-map array: its faces, with their own levels.
            let cube = super::sample::pick_image(texture, kind, layer)?;
            let chains = loaded
                .into_image_chains()
                .with_context(|| format!("cannot read texture `{texture}`"))?;
            return Ok((
                EnvSampler::Cube(CubeSampler::new(&chains[6 * cube..6 * cube + 6], options)?),
                channels,
            ));
        }
        Kind::Plain | Kind::LatLong => {
            // --layer on a texture that is not an array is refused.
            super::sample::pick_image(texture, kind, layer)?;
        }
        other => {
            return Err(anyhow!(
                "`{texture}` is a {}: direction lookups read one cube map or a lat-long map",
                other.describe()
            ));
        }
    }
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
            // own levels would mix faces once they are 1 texel high). A
            // file that records a cube map is OpenEXR's strip; otherwise
            // the image's aspect tells the strip or cross.
            let recorded = loaded.info.environment == Some(Environment::Cube);
            let base = loaded.into_base();
            let faces = if recorded {
                faces_from_strip(&base)
            } else {
                faces_from_image(&base)
            }
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
