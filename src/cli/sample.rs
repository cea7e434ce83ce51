//! `parvo sample`: filter a texture at queries read from stdin.
//!
//! Input: one query per line, `u v dudx dvdx dudy dvdy`, separated by
//! whitespace and/or commas; `#` starts a comment; blank lines are skipped;
//! `nan`, `inf`, `-inf` are accepted. Output: one line per query, in input
//! order, with one value per texture channel (grey; grey alpha; RGB; RGBA),
//! linear light (sRGB textures are decoded before filtering), printed with
//! the shortest text that round-trips the `f32`.
//!
//! Queries are read in chunks and each chunk is sampled in parallel, so
//! memory stays bounded for any input length. A malformed line stops the
//! run with `parvo: stdin line N: ...` (exit 1) after the results of the
//! lines before it have been written. Invalid option combinations exit
//! with 2, like clap's own usage errors.

use std::io::{self, BufRead, BufWriter, Write};
use std::path::Path;
use std::process::ExitCode;

use super::lookup::{format_colour, pick_image};
use anyhow::{Context, Result, anyhow};
use parvo::ImageKind;
use parvo::Wrap;
use parvo::sample::{CompareOp, Filter, MipMode, Query, Sampler, SamplerOptions, TexelFilter};

/// Queries parsed and sampled per batch.
const CHUNK: usize = 1 << 16;

/// Arguments of `parvo sample`.
#[derive(clap::Args, Debug)]
#[command(
    about = "Sample a texture at queries read from stdin",
    long_about = "Sample a texture at queries read from stdin, one per line: \
                  `u v dudx dvdx dudy dvdy` (whitespace or comma separated, `#` comments, \
                  nan/inf accepted). Writes one line per query with one float per texture \
                  channel, in linear light. --filter picks a preset; the other flags override it. \
                  The shading languages' other calls: --level L (textureLod), --bias B \
                  (texture with a bias), --gather C (textureGather: four values per line) and \
                  --compare OP (a shadow sampler: a 7th column holds the reference depth, one \
                  value per line)."
)]
pub struct SampleArgs {
    /// Texture: builtin:checker[:SIZE], builtin:zoneplate[:SIZE], builtin:bumps[:SIZE], builtin:photo[:SIZE], builtin:sky[:SIZE], or a file `parvo mip` reads.
    #[arg(value_name = "TEXTURE")]
    texture: String,

    #[command(flatten)]
    read: super::texture::TextureArgs,

    /// Filter preset: nearest, bilinear, trilinear, aniso, ewa, sat, supersample.
    #[arg(long, default_value = "trilinear", value_name = "F")]
    filter: Filter,
    /// Magnification filter: nearest or linear.
    #[arg(long, value_name = "F")]
    mag: Option<TexelFilter>,
    /// Minification filter: nearest or linear.
    #[arg(long, value_name = "F")]
    min: Option<TexelFilter>,
    /// Mip mode: none, nearest or linear.
    #[arg(long, value_name = "MODE")]
    mip: Option<MipMode>,
    /// Maximum anisotropy, 1 to 16 (aniso and ewa default to 16).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=16))]
    max_aniso: Option<u32>,
    /// LOD bias added to λ.
    #[arg(long, value_name = "B", allow_negative_numbers = true)]
    lod_bias: Option<f32>,
    /// Lower LOD clamp.
    #[arg(long, value_name = "L", allow_negative_numbers = true)]
    lod_min: Option<f32>,
    /// Upper LOD clamp.
    #[arg(long, value_name = "L", allow_negative_numbers = true)]
    lod_max: Option<f32>,
    /// Wrap mode(s): repeat, mirror, clamp, border (black), mirror-clamp; MODE,MODE for u,v.
    #[arg(
        long,
        value_name = "MODE[,MODE]",
        long_help = "Wrap modes: repeat, mirror, clamp, border (black), mirror-clamp; MODE,MODE for u \
        and v. Default: the modes the file records (EXR and TIFF `wrapmodes` as maketx writes them, \
        parvo's KTX2 key), else repeat."
    )]
    wrap: Option<Wrap>,
    /// Border colour for `border` wrapping, linear RGBA.
    #[arg(long, value_name = "R,G,B,A", value_parser = parse_border, allow_hyphen_values = true)]
    border: Option<[f32; 4]>,
    /// Grid size n of the supersample filter (n×n lookups, 1 to 64; default 8).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=64))]
    supersample: Option<u32>,
    /// Sample every query on this explicit level (textureLod); derivatives are ignored.
    #[arg(
        long,
        value_name = "L",
        allow_negative_numbers = true,
        long_help = "Sample every query on this explicit level, as GLSL textureLod / WGSL \
        textureSampleLevel do: the derivative columns are read but ignored, the sampler's \
        --lod-bias and --lod-min/--lod-max apply, and the --mag/--min/--mip filters choose the \
        texels (no anisotropy). With --compare, the comparison is made on that level."
    )]
    level: Option<f32>,
    /// Shader LOD bias added to --lod-bias for every query (texture(s, p, bias)).
    #[arg(
        long,
        value_name = "B",
        allow_negative_numbers = true,
        conflicts_with = "level",
        long_help = "A shader LOD bias, as GLSL texture(s, p, bias) / WGSL textureSampleBias take \
        it: added to the sampler's --lod-bias for every query (λ = log2(ρ) + lod-bias + bias, then \
        the clamps)."
    )]
    bias: Option<f32>,
    /// Print component C (0-3) of the 4 texels of the bilinear footprint (textureGather).
    #[arg(
        long,
        value_name = "C",
        value_parser = clap::value_parser!(u8).range(0..=3),
        conflicts_with_all = ["compare", "level", "bias"],
        long_help = "Print, per query, component C (0-3) of the four texels a bilinear lookup of \
        level 0 reads, in GL's textureGather order: (i0,j1) (i1,j1) (i1,j0) (i0,j0), j growing \
        with v; wrapped as the sampler wraps, the border colour's component outside the level \
        under `border`. Values are decoded (sRGB to linear). Derivatives are ignored."
    )]
    gather: Option<u8>,
    /// Depth comparison: a 7th column per query is the reference; prints the filtered result.
    #[arg(
        long,
        value_name = "OP",
        long_help = "Depth comparison, as GLSL textureGrad on a sampler2DShadow (textureLod with \
        --level): each query line has a 7th column, the reference depth; channel 0 of every texel \
        read is compared (reference OP texel: never, less, equal, lequal, greater, notequal, gequal, \
        always), the 0/1 results filtered by --mag/--min/--mip isotropically, and one value printed \
        per query; --bias adds a shader bias as texture(sampler2DShadow, p, bias) does. The \
        reference is clamped to [0, 1] for 8- and 16-bit textures, as GL clamps it \
        for fixed-point depth."
    )]
    compare: Option<CompareOp>,
    /// Queries are directions: `x y z dxdx dydx dzdx dxdy dydy dzdy` per line.
    #[arg(
        long,
        conflicts_with_all = ["gather", "compare", "level", "bias"],
        long_help = "Each query line is a direction and its screen derivatives, `x y z dxdx dydx \
        dzdx dxdy dydy dzdy` (as dFdx/dFdy of a reflection vector give them), looked up in the \
        environment the file records (maketx's and OpenEXR's lat-long and cube-face maps) or \
        --env says it holds. Cube maps are filtered seamlessly across face \
        edges (GL's ARB_seamless_cube_map, every filter); lat-long maps as OpenImageIO's \
        environment() filters them."
    )]
    direction: bool,
    /// The environment the texture holds: latlong, or cube (six faces in a strip or a cross).
    #[arg(
        long,
        value_name = "KIND",
        requires = "direction",
        long_help = "The environment the texture holds. latlong: an equirectangular map, y up, \
        s = atan2(-x, z)/2pi + 1/2 (OpenImageIO's convention). cube: six square faces in one \
        image, the layout told by its aspect: a vertical strip w x 6w (+x -x +y -y +z -z from the \
        top, OpenEXR's cube-map layout as maketx --envcube writes it), a horizontal strip 6w x w \
        (the same order from the left), a horizontal cross 4w x 3w (-x +z +x -z across, +y above \
        and -y below +z) or a vertical cross 3w x 4w (-x +z +x across, +y above +z, -y below it, \
        -z below -y turned 180 degrees); each face mip-mapped on its own."
    )]
    env: Option<super::args::EnvArg>,
    /// Array layer to sample (2-D arrays), or cube (cube-map arrays, with --direction); GL rounds it.
    #[arg(
        long,
        value_name = "N",
        allow_negative_numbers = true,
        long_help = "The layer of a 2-D array (a KTX2 or DDS file with more than one layer) to \
        sample, or with --direction the cube of a cube-map array. N is an array coordinate and is \
        rounded as GL rounds one: floor(N + 0.5) clamped to [0, layers - 1], so --layer 1.6 reads \
        layer 2 and --layer 9 the last layer. An array of more than one layer is refused without \
        --layer (nothing is picked for you); a texture that is not an array is refused with it."
    )]
    layer: Option<f32>,
}

/// What `parvo sample` computes per query.
#[derive(Clone, Copy, Debug)]
enum Mode {
    /// Filtered colour (with gradients, an explicit level or a bias).
    Sample,
    Level(f32),
    Bias(f32),
    Gather(usize),
    /// Depth comparison on an explicit level, or with gradients and a
    /// shader bias (0 without `--bias`).
    Compare(CompareOp, Option<f32>, f32),
}

impl SampleArgs {
    fn mode(&self) -> Mode {
        match (self.gather, self.compare, self.level, self.bias) {
            (Some(c), ..) => Mode::Gather(c as usize),
            (None, Some(op), l, b) => Mode::Compare(op, l, b.unwrap_or(0.0)),
            (None, None, Some(l), _) => Mode::Level(l),
            (None, None, None, Some(b)) => Mode::Bias(b),
            _ => Mode::Sample,
        }
    }
}

fn parse_border(s: &str) -> Result<[f32; 4], String> {
    let v: Vec<f32> = s
        .split(',')
        .map(|t| t.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("`{s}`: {e}"))?;
    match v[..] {
        [r, g, b, a] => Ok([r, g, b, a]),
        _ => Err(format!(
            "`{s}`: expected four comma-separated numbers r,g,b,a"
        )),
    }
}

impl SampleArgs {
    /// The preset of `--filter` with the explicit flags applied on top.
    fn options(&self) -> SamplerOptions {
        let mut o = SamplerOptions::preset(self.filter, self.max_aniso.unwrap_or(16));
        if let Some(n) = self.max_aniso {
            o.max_aniso = n;
        }
        if let Some(f) = self.mag {
            o.mag = f;
        }
        if let Some(f) = self.min {
            o.min = f;
        }
        if let Some(m) = self.mip {
            o.mip = m;
        }
        if let Some(b) = self.lod_bias {
            o.lod_bias = b;
        }
        if let Some(l) = self.lod_min {
            o.lod_min = l;
        }
        if let Some(l) = self.lod_max {
            o.lod_max = l;
        }
        if let Some(w) = self.wrap {
            o.wrap = w;
        }
        if let Some(b) = self.border {
            o.border = b;
        }
        if let Some(n) = self.supersample {
            o.supersample = n;
        }
        o
    }
}

pub fn run(args: SampleArgs) -> Result<ExitCode> {
    let mut options = args.options();
    if let Err(e) = options.validate() {
        eprintln!("parvo: {}", super::words::words(&e));
        return Ok(ExitCode::from(2));
    }
    if args.direction {
        let env = args.env;
        let out = BufWriter::with_capacity(1 << 16, io::stdout().lock());
        super::env::run(
            &args.read,
            &args.texture,
            env,
            args.layer,
            options,
            io::stdin().lock(),
            out,
        )?;
        return Ok(ExitCode::SUCCESS);
    }
    // A mip-mapped EXR/KTX2/DDS keeps its own levels; anything else gets
    // box mips built on load. An array's layer is the one --layer picks.
    let chain = if args.layer.is_some()
        || matches!(
            parvo::io::peek_kind(Path::new(&args.texture)),
            ImageKind::Array { .. }
        ) {
        let loaded = args.read.load_environment(&args.texture)?;
        let kind = loaded.info.kind;
        if kind.is_cube() {
            return Err(anyhow!(
                "`{}` is a {}: look it up by direction with --direction",
                args.texture,
                kind.describe()
            ));
        }
        let layer = pick_image(&args.texture, kind, args.layer)?;
        loaded
            .into_image_chain(layer)
            .with_context(|| format!("cannot read texture `{}`", args.texture))?
    } else {
        args.read.load_chain(&args.texture)?.0
    };
    if args.wrap.is_none() {
        // The wrap modes the file records (EXR/TIFF `wrapmodes`, parvo's
        // KTX2 key), as OpenImageIO's texture system uses them; repeat when
        // it records none.
        options.wrap = chain.options().wrap;
    }
    let sampler = Sampler::new(&chain, options)?;
    drop(chain);
    let stdin = io::stdin().lock();
    let stdout = io::stdout().lock();
    let mode = args.mode();
    match stream(
        &sampler,
        mode,
        stdin,
        BufWriter::with_capacity(1 << 16, stdout),
    ) {
        Err(e) if is_broken_pipe(&e) => Ok(ExitCode::SUCCESS),
        Err(e) => Err(e),
        Ok(()) => Ok(ExitCode::SUCCESS),
    }
}

fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.downcast_ref::<io::Error>()
        .is_some_and(|e| e.kind() == io::ErrorKind::BrokenPipe)
}

/// Read queries from `input`, write results to `out`, chunk by chunk.
fn stream(
    sampler: &Sampler,
    mode: Mode,
    mut input: impl BufRead,
    mut out: impl Write,
) -> Result<()> {
    let channels = sampler.chain().format().channels as usize;
    let columns = if matches!(mode, Mode::Compare(..)) {
        7
    } else {
        6
    };
    let mut line = Vec::new();
    let mut line_no = 0usize;
    let mut queries = Vec::with_capacity(CHUNK);
    let mut refs = Vec::with_capacity(CHUNK);
    let mut colours = Vec::with_capacity(CHUNK);
    let mut text = String::new();
    loop {
        queries.clear();
        refs.clear();
        let mut failure = None;
        let mut eof = false;
        while queries.len() < CHUNK {
            line.clear();
            if input
                .read_until(b'\n', &mut line)
                .context("reading stdin")?
                == 0
            {
                eof = true;
                break;
            }
            line_no += 1;
            match parse_line(&line, columns) {
                Ok(Some((q, r))) => {
                    queries.push(q);
                    refs.push(r);
                }
                Ok(None) => {}
                Err(e) => {
                    failure = Some(anyhow!("stdin line {line_no}: {e}"));
                    break;
                }
            }
        }
        match mode {
            Mode::Sample => {
                colours.resize(queries.len(), [0f32; 4]);
                sampler.sample_batch(&queries, &mut colours)?;
                for c in &colours {
                    text.clear();
                    format_colour(&mut text, c, channels);
                    out.write_all(text.as_bytes())?;
                }
            }
            _ => {
                for (q, r) in queries.iter().zip(&refs) {
                    text.clear();
                    match mode {
                        Mode::Level(l) => {
                            format_colour(&mut text, &sampler.sample_level(q.u, q.v, l), channels)
                        }
                        Mode::Bias(b) => {
                            format_colour(&mut text, &sampler.sample_bias(q, b), channels)
                        }
                        Mode::Gather(c) => {
                            format_colour(&mut text, &sampler.gather(q.u, q.v, c), 4)
                        }
                        Mode::Compare(op, level, bias) => {
                            let x = match level {
                                Some(l) => sampler.sample_compare_level(q.u, q.v, l, *r, op),
                                None => sampler.sample_compare_bias(q, *r, op, bias),
                            };
                            format_colour(&mut text, &[x; 4], 1)
                        }
                        Mode::Sample => {}
                    }
                    out.write_all(text.as_bytes())?;
                }
            }
        }
        if let Some(e) = failure {
            out.flush()?;
            return Err(e);
        }
        if eof {
            out.flush()?;
            return Ok(());
        }
    }
}

/// Parse one input line of `columns` numbers (6, or 7 with the reference
/// depth of `--compare`): `Ok(None)` for blank and comment-only lines.
fn parse_line(raw: &[u8], columns: usize) -> Result<Option<(Query, f32)>, String> {
    let line = std::str::from_utf8(raw).map_err(|_| "not valid UTF-8".to_string())?;
    let body = line.split('#').next().unwrap_or("");
    let mut v = [0f32; 7];
    let mut n = 0usize;
    for tok in body
        .split(|c: char| c.is_whitespace() || c == ',')
        .filter(|t| !t.is_empty())
    {
        if n < columns {
            v[n] = tok
                .parse::<f32>()
                .map_err(|_| format!("`{tok}` is not a number"))?;
        }
        n += 1;
    }
    match n {
        0 => Ok(None),
        _ if n == columns => Ok(Some((Query::new(v[0], v[1], v[2], v[3], v[4], v[5]), v[6]))),
        _ if columns == 7 => Err(format!(
            "expected 7 numbers (u v dudx dvdx dudy dvdy reference), got {n}"
        )),
        _ => Err(format!("expected 6 numbers, got {n}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_parse_with_commas_comments_and_specials() {
        let (q, _) = parse_line(b"0.5, 0.25 1e-3,0  0 -inf # comment\n", 6)
            .unwrap()
            .unwrap();
        assert_eq!((q.u, q.v, q.dudx), (0.5, 0.25, 1e-3));
        assert_eq!(q.dvdy, f32::NEG_INFINITY);
        assert!(
            parse_line(b"nan NaN inf Infinity 0 0", 6)
                .unwrap()
                .unwrap()
                .0
                .u
                .is_nan()
        );
        assert_eq!(parse_line(b"   # only a comment", 6).unwrap(), None);
        assert_eq!(parse_line(b"\n", 6).unwrap(), None);
        assert_eq!(
            parse_line(b"1 2 3 4 5", 6).unwrap_err(),
            "expected 6 numbers, got 5"
        );
        assert_eq!(
            parse_line(b"1 2 3 4 5 6 7", 6).unwrap_err(),
            "expected 6 numbers, got 7"
        );
        assert!(parse_line(b"1 2 x 4 5 6", 6).unwrap_err().contains("`x`"));
        assert!(parse_line(b"1 2 3 4 5 \xff", 6).is_err());
        let (q, r) = parse_line(b"1 2 3 4 5 6 0.25", 7).unwrap().unwrap();
        assert_eq!((q.dvdy, r), (6.0, 0.25));
        assert!(
            parse_line(b"1 2 3 4 5 6", 7)
                .unwrap_err()
                .contains("reference")
        );
    }

    #[test]
    fn border_parses_four_numbers() {
        assert_eq!(parse_border("1,0,0.5,-1").unwrap(), [1.0, 0.0, 0.5, -1.0]);
        assert!(parse_border("1,0,0").is_err());
        assert!(parse_border("a,b,c,d").is_err());
    }
}
