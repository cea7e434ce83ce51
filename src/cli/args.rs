//! Argument types and parsers more than one subcommand takes.

use clap::ValueEnum;

/// How to interpret the colour channels of the input.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ColorArg {
    /// What the file says: PNG by its sRGB/cICP/gAMA chunks (sRGB when it has none), JPEG sRGB,
    /// KTX2 and DDS by their format, OpenEXR, TIFF and HDR linear.
    Auto,
    /// The input is linear light.
    Linear,
    /// The input is sRGB-encoded.
    Srgb,
}

/// `--quality` levels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum QualityArg {
    Fast,
    Normal,
    Slow,
}

/// A byte count such as 4G, 512M or 1000000.
pub(crate) fn parse_bytes(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let (num, mul) = match t.char_indices().last() {
        Some((i, c)) if c.is_ascii_alphabetic() => {
            let m: u64 = match c.to_ascii_uppercase() {
                'K' => 1 << 10,
                'M' => 1 << 20,
                'G' => 1 << 30,
                'T' => 1 << 40,
                _ => return Err(format!("`{s}`: unknown unit (use K, M, G or T)")),
            };
            (&t[..i], m)
        }
        _ => (t, 1),
    };
    num.parse::<u64>()
        .ok()
        .and_then(|n| n.checked_mul(mul))
        .ok_or_else(|| format!("`{s}` is not a byte count such as 4G or 512M"))
}

/// How `--env` reads the texture.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum EnvArg {
    /// A lat-long (equirectangular) map, y up, as OpenImageIO reads one.
    Latlong,
    /// Six square faces in one image: a strip (w x 6w, 6w x w) or a cross (4w x 3w, 3w x 4w).
    Cube,
}
