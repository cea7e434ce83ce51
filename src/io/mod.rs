//! Loading and saving textures: the `image` codecs (PNG, JPEG, TIFF,
//! Radiance HDR), OpenEXR (scanline, tiled, mip-mapped) via `exr`, KTX 2.0
//! (written by hand, read with `ktx2`), DDS (written and read by hand, see
//! [`dds`]), and one PNG per mip level.
//!
//! Design decisions:
//! - Files are recognised by their first bytes (EXR, KTX2, DDS magic
//!   numbers), everything else goes to `image`'s format guesser, so a
//!   misnamed file still loads and a wrong extension is never trusted.
//! - Channels are kept as they are: grey stays one channel, grey + alpha
//!   two. The loader records what it knows about the source
//!   ([`SourceInfo`]): its own mip levels, wrap modes, tiling, attributes.
//! - Colour space: 8-bit PNG and JPEG load as sRGB, everything else as
//!   linear (what `--color auto` means); callers reinterpret when they know
//!   better.
//! - Every decoder checks the declared size against [`Limits`] before it
//!   allocates; every writer goes through [`atomic`].

pub mod atomic;
pub mod dds;
pub mod exr;
mod image_errors;
pub mod ktx2;
pub mod limits;
pub mod png_levels;
pub mod tiff;

use std::borrow::Cow;
use std::fmt;
use std::io::Read;
use std::path::Path;

use half::slice::HalfFloatSliceExt;

use crate::error::{Error, Result};
use crate::mip::{self, MipChain, MipOptions, NanPolicy, Rounding};
use crate::texel::{ChannelType, ColorSpace, Format, Texels};
use crate::texture::Texture;
use crate::wrap::Wrap;

pub use limits::Limits;

/// A file format parvo reads or writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FileFormat {
    /// A procedural `builtin:` texture.
    Builtin,
    /// PNG.
    Png,
    /// JPEG.
    Jpeg,
    /// TIFF.
    Tiff,
    /// Radiance RGBE (.hdr).
    Hdr,
    /// OpenEXR.
    Exr,
    /// KTX 2.0.
    Ktx2,
    /// DirectDraw Surface.
    Dds,
}

impl FileFormat {
    /// Display name ("PNG", "OpenEXR", ...).
    pub fn name(self) -> &'static str {
        match self {
            FileFormat::Builtin => "builtin",
            FileFormat::Png => "PNG",
            FileFormat::Jpeg => "JPEG",
            FileFormat::Tiff => "TIFF",
            FileFormat::Hdr => "Radiance HDR",
            FileFormat::Exr => "OpenEXR",
            FileFormat::Ktx2 => "KTX2",
            FileFormat::Dds => "DDS",
        }
    }
}

impl fmt::Display for FileFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// What a loader learned about the source besides its texels.
#[derive(Clone, Debug, PartialEq)]
pub struct SourceInfo {
    /// The file format.
    pub format: FileFormat,
    /// True when the file stores its own mip levels (more than one).
    pub own_mips: bool,
    /// Size rounding of the stored mip levels.
    pub rounding: Rounding,
    /// Wrap modes stored in the file (EXR `wrapmodes`), if any.
    pub wrap: Option<Wrap>,
    /// Tile size of a tiled file.
    pub tile: Option<(u32, u32)>,
    /// Channel names as stored (EXR), or implied by the layout.
    pub channel_names: Vec<String>,
    /// Other metadata as name/value text, sorted by name.
    pub attributes: Vec<(String, String)>,
    /// What the loader did that a user would not assume (channels mapped,
    /// a part or page chosen among several, a data window placed, an
    /// orientation applied), one sentence each; the CLI prints them on
    /// stderr.
    pub notes: Vec<String>,
    /// The block format the file stores its levels in (decoded on load),
    /// if it is block-compressed.
    pub blocks: Option<crate::compress::BlockFormat>,
    /// False when the file says nothing about how its colour values are
    /// encoded and the colour space is parvo's assumption (OpenImageIO's
    /// reading): a PNG without `sRGB`, `cICP`, `gAMA` or `iCCP` chunk is
    /// read as sRGB, a TIFF as linear. True otherwise (by the format's
    /// definition or the file's own statement).
    pub color_stated: bool,
    /// The kind of environment map the file declares (only ever set when
    /// [`LoadOptions::environment`] asks to describe them; see
    /// [`EnvironmentMaps`]).
    pub environment: Option<Environment>,
}

impl SourceInfo {
    fn new(format: FileFormat, texels: &Format) -> Self {
        SourceInfo {
            format,
            own_mips: false,
            rounding: Rounding::Down,
            wrap: None,
            tile: None,
            channel_names: layout_names(texels),
            attributes: Vec::new(),
            notes: Vec::new(),
            blocks: None,
            color_stated: true,
            environment: None,
        }
    }

    /// The value of attribute `name`, if present.
    pub fn attribute(&self, name: &str) -> Option<&str> {
        self.attributes
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }
}

/// The channel names a texel format implies: `Y`, `Y,A` (grey + alpha),
/// `R,G` (two data channels), `R,G,B`, `R,G,B,A`, and `R,G,B,W` when the
/// fourth channel is data, not alpha.
pub fn layout_names(format: &Format) -> Vec<String> {
    let names: &[&str] = match (format.channels, format.has_alpha()) {
        (1, _) => &["Y"],
        (2, true) => &["Y", "A"],
        (2, false) => &["R", "G"],
        (3, _) => &["R", "G", "B"],
        (_, true) => &["R", "G", "B", "A"],
        (_, false) => &["R", "G", "B", "W"],
    };
    names.iter().map(|s| s.to_string()).collect()
}

/// A loaded texture: level 0 and, when the file had them, its own mip
/// levels (level 0 first), plus what the file said about itself.
#[derive(Clone, Debug)]
pub struct Loaded {
    /// Level 0 first; more than one entry only when the file stores mips.
    pub levels: Vec<Texture>,
    /// Source metadata.
    pub info: SourceInfo,
}

impl Loaded {
    /// Level 0.
    pub fn base(&self) -> &Texture {
        &self.levels[0]
    }

    /// Consume into level 0.
    pub fn into_base(mut self) -> Texture {
        self.levels.swap_remove(0)
    }

    /// Consume into a mip chain: the file's own levels when it stores
    /// them, otherwise a box-filtered chain built from level 0 (wrap modes
    /// from the file when it names them, else repeat); and the block
    /// format the file stored its levels in, if any.
    pub fn into_chain(self) -> Result<(MipChain, Option<crate::compress::BlockFormat>)> {
        let blocks = self.info.blocks;
        let options = MipOptions {
            rounding: self.info.rounding,
            wrap: self.info.wrap.unwrap_or_default(),
            ..MipOptions::default()
        };
        let chain = if self.levels.len() > 1 {
            MipChain::from_levels(self.levels, options)?
        } else {
            mip::build(self.into_base(), &options)?
        };
        Ok((chain, blocks))
    }
}

/// When the colour space of a source with texels `f` is parvo's
/// assumption ([`SourceInfo::color_stated`]) and integer data is read by
/// it, the sentence that says so (the CLI prints it once per file).
pub fn assumed_color_note(info: &SourceInfo, f: &Format) -> Option<String> {
    if info.color_stated || f.channel_type.is_float() {
        return None;
    }
    Some(match f.color_space {
        ColorSpace::Srgb => format!(
            "the {} file does not say how its values encode colour: read as sRGB-encoded colour, \
             as OpenImageIO reads such files (--color linear reads them as data, e.g. a height map)",
            info.format
        ),
        ColorSpace::Linear => format!(
            "the {} file does not say how its values encode colour: read as linear values, as \
             OpenImageIO reads such files (--color srgb decodes them as sRGB)",
            info.format
        ),
    })
}

/// A recorded `wrapmodes` text as wrap modes; one that does not parse is
/// noted (and repeat applies) rather than dropped without a word.
pub(crate) fn recorded_wrap(text: Option<&str>, notes: &mut Vec<String>) -> Option<Wrap> {
    let t = text?;
    match t.parse() {
        Ok(w) => Some(w),
        Err(_) => {
            notes.push(format!(
                "wrap modes `{t}` not understood (expected MODE or U,V of repeat/periodic, mirror, \
                 clamp, black/border, mirror-clamp): repeat applies unless --wrap says otherwise"
            ));
            None
        }
    }
}

/// An environment map's projection, as OpenEXR's `envmap` attribute and
/// the `textureformat` maketx writes name it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Environment {
    /// Latitude-longitude (equirectangular): `LatLong Environment`,
    /// `envmap` 0.
    LatLong,
    /// Six cube faces in one image: `CubeFace Environment`, `envmap` 1
    /// (OpenEXR stacks the faces top to bottom).
    Cube,
}

impl Environment {
    /// The kind in words ("lat-long", "cube-face").
    pub fn name(self) -> &'static str {
        match self {
            Environment::LatLong => "lat-long",
            Environment::Cube => "cube-face",
        }
    }
}

impl fmt::Display for Environment {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// What a loader does with an environment map (a cube-face or lat-long
/// OpenEXR or TIFF): nothing in parvo filters or samples one as what it
/// is yet, and taking it for a plain texture filters a cube's faces
/// into each other and wraps a lat-long map's poles, so the default
/// refuses it. Describing it (what `parvo info` does) loads its texels
/// as stored with [`SourceInfo::environment`] set and a note.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum EnvironmentMaps {
    /// Refuse the file with an error naming the kind (the default).
    #[default]
    Refuse,
    /// Load it as stored, marked as an environment map.
    Describe,
}

/// Refuse an environment map of `kind` or note it, as `options` say;
/// `detail` describes what the file holds.
pub(crate) fn environment_map(
    format: &'static str,
    kind: Environment,
    detail: &str,
    options: &LoadOptions,
    notes: &mut Vec<String>,
) -> Result<()> {
    match options.environment {
        EnvironmentMaps::Refuse => Err(Error::Decode {
            format,
            reason: format!(
                "a {kind} environment map ({detail}), which parvo cannot filter or sample yet: \
                 filtering it as a flat image would blend {}",
                match kind {
                    Environment::Cube => "its six faces into each other across their edges",
                    Environment::LatLong => "across its poles as if the image repeated vertically",
                }
            ),
        }),
        EnvironmentMaps::Describe => {
            notes.push(format!(
                "{kind} environment map ({detail}): described only; parvo cannot filter or \
                 sample environment maps yet"
            ));
            Ok(())
        }
    }
}

/// Choices a loader cannot make from the file alone.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LoadOptions {
    /// The channels to load, by name in the order wanted (OpenEXR); `None`
    /// follows OpenImageIO's conventions (see [`exr::load`]).
    pub channels: Option<Vec<String>>,
    /// Which part of a multi-part EXR or page of a multi-page TIFF (0, the
    /// default, is the first).
    pub subimage: usize,
    /// Rotate JPEG, PNG and TIFF images by their EXIF orientation, as
    /// image viewers and `oiiotool --autoorient` do. Default: true. (A
    /// KTX2 file's `KTXorientation` is always applied.)
    pub auto_orient: bool,
    /// Read the colour channels as this colour space whatever the file
    /// says or does not say; `None` (the default) reads them as the file
    /// says (see the module docs; [`SourceInfo::color_stated`] tells when
    /// that is parvo's assumption).
    pub color: Option<ColorSpace>,
    /// Apply this policy to non-finite values (NaN, ±Inf) in every level
    /// of float data as it is loaded; `None` (the default) leaves them for
    /// the caller (`mip::build` applies its own [`MipOptions::nan_policy`]
    /// while it builds). [`LoadOptions::for_sampling`] sets
    /// [`NanPolicy::Error`].
    pub nan_policy: Option<NanPolicy>,
    /// Refuse environment maps (the default) or describe them (see
    /// [`EnvironmentMaps`]).
    pub environment: EnvironmentMaps,
}

impl LoadOptions {
    /// The options of a load whose levels are sampled as they are: the
    /// file's colour space, and non-finite values refused
    /// ([`NanPolicy::Error`]), as `mip::build` refuses them.
    pub fn for_sampling() -> Self {
        LoadOptions {
            nan_policy: Some(NanPolicy::Error),
            ..Default::default()
        }
    }
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            channels: None,
            subimage: 0,
            auto_orient: true,
            color: None,
            nan_policy: None,
            environment: EnvironmentMaps::Refuse,
        }
    }
}

/// Load a texture file or a `builtin:` name (see the module docs).
pub fn load(spec: &str, limits: &Limits) -> Result<Loaded> {
    load_with(spec, limits, &LoadOptions::default())
}

/// [`load`] with [`LoadOptions`].
pub fn load_with(spec: &str, limits: &Limits, options: &LoadOptions) -> Result<Loaded> {
    load_overlapped(spec, limits, options, None)
}

/// Work for the core a single-threaded decoder leaves idle, given the
/// image's width, height, channel count and channel type as soon as its
/// header is read (see [`load_overlapped`]).
pub type Overlap<'a> = &'a mut (dyn FnMut(u32, u32, u8, ChannelType) + Send);

/// [`load_with`], running `overlap` on another thread while the image is
/// decoded, where the decoder runs on one thread (PNG, JPEG and the other
/// formats `image` reads); the load returns once both are done. Other
/// formats (OpenEXR, read on all threads; TIFF, KTX2, DDS, `builtin:`)
/// never call it. A caller uses it to allocate and fault in the buffers
/// it will fill next, off the critical path.
pub fn load_overlapped(
    spec: &str,
    limits: &Limits,
    options: &LoadOptions,
    overlap: Option<Overlap<'_>>,
) -> Result<Loaded> {
    let mut loaded = load_stored(spec, limits, options, overlap)?;
    if let Some(cs) = options.color {
        loaded.levels = std::mem::take(&mut loaded.levels)
            .into_iter()
            .map(|l| {
                let f = Format {
                    color_space: cs,
                    ..l.format()
                };
                l.reinterpret(f)
            })
            .collect::<Result<_>>()?;
    }
    if let Some(policy) = options.nan_policy {
        for (k, l) in loaded.levels.iter_mut().enumerate() {
            crate::mip::nan::apply(l, policy).map_err(|e| match e {
                Error::NonFinite {
                    x,
                    y,
                    channel,
                    value,
                    ..
                } => Error::NonFinite {
                    level: k as u32,
                    x,
                    y,
                    channel,
                    value,
                },
                other => other,
            })?;
        }
    }
    Ok(loaded)
}

/// The texels as the file stores them (see [`load_overlapped`]).
fn load_stored(
    spec: &str,
    limits: &Limits,
    options: &LoadOptions,
    overlap: Option<Overlap<'_>>,
) -> Result<Loaded> {
    if crate::builtin::is_builtin(spec) {
        let (kind, size) = crate::builtin::parse(spec)?;
        limits.check(size as u64, size as u64, size as u64 * size as u64 * 4)?;
        let t = crate::builtin::generate(kind, size)?;
        let info = SourceInfo::new(FileFormat::Builtin, &t.format());
        return Ok(Loaded {
            levels: vec![t],
            info,
        });
    }
    let path = Path::new(spec);
    let meta = std::fs::metadata(path).map_err(|e| Error::Io {
        path: path.to_path_buf(),
        action: "cannot open".into(),
        error: e,
    })?;
    if meta.is_dir() {
        return Err(Error::Io {
            path: path.to_path_buf(),
            action: "cannot read".into(),
            error: std::io::Error::other("it is a directory, not a texture file"),
        });
    }
    if meta.len() == 0 {
        return Err(Error::Decode {
            format: "input",
            reason: "the file is empty".into(),
        });
    }
    let mut magic = [0u8; 12];
    let n = std::fs::File::open(path)
        .and_then(|mut f| {
            let mut n = 0;
            while n < magic.len() {
                match f.read(&mut magic[n..])? {
                    0 => break,
                    k => n += k,
                }
            }
            Ok(n)
        })
        .map_err(|e| Error::Io {
            path: path.to_path_buf(),
            action: "cannot read".into(),
            error: e,
        })?;
    let magic = &magic[..n];
    // The decoders are dependencies; a panic in one on a malformed file
    // becomes a decode error, never a crash of the caller. (What `overlap`
    // did before a panic is the caller's buffers, valid as they are.)
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        if options.channels.is_some() && !magic.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
            return Err(Error::InvalidOption(
                "--channels selects channels of OpenEXR files; this input is not one".into(),
            ));
        }
        if magic.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
            exr::load(path, limits, options)
        } else if magic.starts_with(ktx2::IDENTIFIER.as_slice()) {
            ktx2::load(path, limits)
        } else if magic.starts_with(b"DDS ") {
            dds::load(path, limits)
        } else if magic.starts_with(b"II*\0")
            || magic.starts_with(b"MM\0*")
            || magic.starts_with(b"II+\0")
            || magic.starts_with(b"MM\0+")
        {
            tiff::load(path, limits, options)
        } else {
            load_image(path, limits, options, overlap)
        }
    }))
    .unwrap_or_else(|p| {
        Err(Error::Decode {
            format: "input",
            reason: format!("decoder panicked: {}", atomic::panic_message(&*p)),
        })
    })
}

/// Load a texture as a mip chain: the file's own levels when it stores them
/// (EXR, KTX2, DDS), otherwise a box-filtered chain built from level 0
/// (wrap modes from the file when it names them, else repeat).
/// Non-finite values in float data are refused
/// ([`LoadOptions::for_sampling`]).
pub fn load_chain(spec: &str, limits: &Limits) -> Result<MipChain> {
    load_chain_stored(spec, limits, &LoadOptions::for_sampling()).map(|c| c.0)
}

/// [`load_chain`] with [`LoadOptions`], and the block format a
/// block-compressed file stores its levels in (they are decoded), if any.
pub fn load_chain_stored(
    spec: &str,
    limits: &Limits,
    options: &LoadOptions,
) -> Result<(MipChain, Option<crate::compress::BlockFormat>)> {
    load_with(spec, limits, options)?.into_chain()
}

/// The colour transfer a PNG's chunks declare, as OpenImageIO reads them:
/// `sRGB` → sRGB; else `cICP` (transfer 13 sRGB, 8 linear); else `gAMA`
/// (1.0 linear, 1/2.2 sRGB, other exponents sRGB with a note); an `iCCP`
/// profile is not interpreted (sRGB, with a note unless it names sRGB); no
/// chunk at all means sRGB, at any bit depth.
fn png_transfer(path: &Path, limits: &Limits) -> Result<(ColorSpace, Option<String>, bool)> {
    let file = std::fs::File::open(path).map_err(|e| Error::Io {
        path: path.to_path_buf(),
        action: "cannot open".into(),
        error: e,
    })?;
    let reader = png::Decoder::new_with_limits(
        std::io::BufReader::new(file),
        png::Limits {
            bytes: usize::try_from(limits.max_alloc).unwrap_or(usize::MAX),
        },
    )
    .read_info()
    .map_err(|e| image_errors::png_error(limits, &e))?;
    let info = reader.info();
    if info.srgb.is_some() {
        return Ok((ColorSpace::Srgb, None, true));
    }
    if let Some(c) = &info.coding_independent_code_points {
        return Ok(match c.transfer_function {
            13 => (ColorSpace::Srgb, None, true),
            8 => (ColorSpace::Linear, None, true),
            t => (
                ColorSpace::Srgb,
                Some(format!(
                    "cICP transfer characteristics {t} is neither sRGB (13) nor linear (8): read as sRGB"
                )),
                true,
            ),
        });
    }
    if let Some(g) = info.gama_chunk {
        let gamma = g.into_value() as f64;
        if (gamma - 1.0).abs() < 0.01 {
            return Ok((ColorSpace::Linear, None, true));
        }
        let note = ((1.0 / gamma - 2.2).abs() > 0.05).then(|| {
            format!(
                "gAMA {gamma:.5} (a {:.2} power law) read as sRGB, parvo's nearest transfer",
                1.0 / gamma
            )
        });
        return Ok((ColorSpace::Srgb, note, true));
    }
    if let Some(icc) = &info.icc_profile {
        let names_srgb = icc.windows(4).any(|w| w == b"sRGB");
        return Ok((
            ColorSpace::Srgb,
            (!names_srgb).then(|| "the ICC profile is not interpreted: read as sRGB".to_string()),
            true,
        ));
    }
    // Nothing said: OpenImageIO's reading, marked as an assumption.
    Ok((ColorSpace::Srgb, None, false))
}

/// What a PNG's chunks before the image data say that the `image` decoder
/// does not apply (see [`png_extras`]).
#[derive(Debug, Default)]
struct PngExtras {
    /// For 1-, 2- and 4-bit grey whose `tRNS` grey lies beyond the bit
    /// depth: the expanded 8-bit grey that is transparent. libpng (so
    /// OpenImageIO) keeps the sample's low bits, as the PNG specification
    /// says a sample is stored; the `png` decoder compares the whole low
    /// byte and so makes nothing transparent.
    grey_trns: Option<u8>,
    /// The orientation tag of the `eXIf` chunk, if it has one.
    exif_orientation: Option<u16>,
    /// The orientation tag of the EXIF block ImageMagick stores as hex in
    /// a `Raw profile type exif` text chunk, if it has one.
    text_orientation: Option<u16>,
    /// What was not understood, one sentence each.
    notes: Vec<String>,
}

/// The text of ImageMagick's raw profile form (`\nexif\n<length>\n<hex>`):
/// the EXIF block as bytes from its TIFF header on, when the text is one.
/// As OpenImageIO and Pillow read it: hex digits after the length, other
/// characters skipped; the block's `Exif\0\0` prefix dropped (Pillow also
/// takes a block that starts with the TIFF header).
fn raw_profile_exif(text: &str) -> Option<Vec<u8>> {
    let rest = text.trim_start().strip_prefix("exif")?.trim_start();
    let end = rest
        .find(|c: char| !c.is_ascii_digit())
        .unwrap_or(rest.len());
    let declared: usize = rest[..end].parse().ok().filter(|&n| n > 0)?;
    let nibbles: Vec<u8> = rest[end..]
        .chars()
        .filter_map(|c| c.to_digit(16).map(|d| d as u8))
        .collect();
    let mut bytes: Vec<u8> = nibbles.chunks_exact(2).map(|p| p[0] << 4 | p[1]).collect();
    bytes.truncate(declared);
    if bytes.len() >= 6 && bytes[..4].eq_ignore_ascii_case(b"Exif") {
        Some(bytes.split_off(6))
    } else if bytes.starts_with(b"II*\0") || bytes.starts_with(b"MM\0*") {
        Some(bytes)
    } else {
        None
    }
}

/// Read the chunks before a PNG's image data for what [`PngExtras`]
/// holds. A file whose header does not read gives nothing (the decoder
/// reports it).
fn png_extras(path: &Path) -> PngExtras {
    use image::metadata::Orientation;
    let mut out = PngExtras::default();
    let Ok(file) = std::fs::File::open(path) else {
        return out;
    };
    let mut decoder = png::Decoder::new(std::io::BufReader::new(file));
    decoder.set_ignore_text_chunk(false);
    let Ok(reader) = decoder.read_info() else {
        return out;
    };
    let info = reader.info();
    if info.color_type == png::ColorType::Grayscale
        && let Some(&[low]) = info.trns.as_deref()
    {
        let max = match info.bit_depth {
            png::BitDepth::One => 1u8,
            png::BitDepth::Two => 3,
            png::BitDepth::Four => 15,
            _ => 255,
        };
        if low > max {
            out.grey_trns = Some((low & max) * (255 / max));
        }
    }
    let tag = |exif: &[u8]| Orientation::from_exif_chunk(exif).map(|o| o.to_exif() as u16);
    out.exif_orientation = info.exif_metadata.as_deref().and_then(tag);
    const KEY: &str = "Raw profile type exif";
    // The text can be large (an EXIF thumbnail); a profile beyond this is
    // not read.
    const LIMIT: usize = 16 << 20;
    let texts = info
        .uncompressed_latin1_text
        .iter()
        .filter(|t| t.keyword.eq_ignore_ascii_case(KEY))
        .map(|t| Some(t.text.clone()))
        .chain(
            info.compressed_latin1_text
                .iter()
                .filter(|t| t.keyword.eq_ignore_ascii_case(KEY))
                .map(|t| {
                    let mut t = t.clone();
                    t.decompress_text_with_limit(LIMIT).ok()?;
                    t.get_text().ok()
                }),
        )
        .chain(
            info.utf8_text
                .iter()
                .filter(|t| t.keyword.eq_ignore_ascii_case(KEY))
                .map(|t| {
                    let mut t = t.clone();
                    t.decompress_text_with_limit(LIMIT).ok()?;
                    t.get_text().ok()
                }),
        );
    for text in texts {
        match text.as_deref().map(raw_profile_exif) {
            Some(Some(exif)) => {
                out.text_orientation = out.text_orientation.or_else(|| tag(&exif));
            }
            Some(None) => out.notes.push(format!(
                "the `{KEY}` text chunk is not an EXIF block in ImageMagick's hex form: ignored"
            )),
            None => out.notes.push(format!(
                "the compressed `{KEY}` text chunk does not inflate (damaged, or beyond 16 MiB): \
                 ignored"
            )),
        }
    }
    out
}

fn load_image(
    path: &Path,
    limits: &Limits,
    options: &LoadOptions,
    overlap: Option<Overlap<'_>>,
) -> Result<Loaded> {
    use image::{DynamicImage, ImageDecoder, ImageFormat};
    let io_err = |action: &str, e| Error::Io {
        path: path.to_path_buf(),
        action: action.into(),
        error: e,
    };
    let mut reader = image::ImageReader::open(path)
        .map_err(|e| io_err("cannot open", e))?
        .with_guessed_format()
        .map_err(|e| io_err("cannot read", e))?;
    let file_format = match reader.format() {
        Some(ImageFormat::Png) => FileFormat::Png,
        Some(ImageFormat::Jpeg) => FileFormat::Jpeg,
        Some(ImageFormat::Hdr) => FileFormat::Hdr,
        _ => {
            return Err(Error::Decode {
                format: "input",
                reason: "not a file format parvo reads (PNG, JPEG, TIFF, Radiance HDR, OpenEXR, \
                         KTX2, DDS)"
                    .into(),
            });
        }
    };
    let mut notes = Vec::new();
    let mut color_stated = true;
    let png_cs = if file_format == FileFormat::Png {
        let (cs, note, stated) = png_transfer(path, limits)?;
        notes.extend(note);
        color_stated = stated;
        Some(cs)
    } else {
        None
    };
    let extras = if file_format == FileFormat::Png {
        png_extras(path)
    } else {
        PngExtras::default()
    };
    notes.extend(extras.notes.iter().cloned());
    if file_format == FileFormat::Jpeg {
        // zune-jpeg decodes a file cut short without a word, as libjpeg
        // does with a warning (and OpenImageIO without one).
        if !image_errors::jpeg_has_end_marker(path).map_err(|e| io_err("cannot read", e))? {
            notes.push(
                "the JPEG ends without its end-of-image marker: it is probably truncated, and \
                 what lies past its end is decoded from incomplete data"
                    .into(),
            );
        }
    }
    let lim = |e: image::ImageError| image_errors::image_error(file_format, limits, e);
    // Width and height are checked below against `limits` (whose error
    // names the limit); the decoders keep the allocation limit.
    let mut il = limits.to_image();
    il.max_image_width = None;
    il.max_image_height = None;
    reader.limits(il);
    let mut decoder = reader.into_decoder().map_err(lim)?;
    let mut orientation = decoder.orientation().map_err(lim)?.to_exif() as u16;
    // A PNG's `eXIf` tag first, else ImageMagick's text form (OpenImageIO
    // reads both, the chunk last).
    if extras.exif_orientation.is_none()
        && let Some(o) = extras.text_orientation
    {
        orientation = o;
    }
    let (w, h) = decoder.dimensions();
    limits.check(w as u64, h as u64, decoder.total_bytes())?;
    let ct = decoder.color_type();
    let overlap = overlap.map(|f| {
        let ch = ct.channel_count();
        let ty = match ct.bytes_per_pixel() / ch {
            1 => ChannelType::U8,
            2 => ChannelType::U16,
            _ => ChannelType::F32,
        };
        move || f(w, h, ch, ty)
    });
    let mut img = match ct {
        // 8-bit images (the common large case) are decoded into a buffer
        // whose pages another thread maps meanwhile (`mem::populate`):
        // the decoder runs on one core, and first touches of a 16384²
        // RGBA8 image cost it seconds. `overlap` follows on that thread.
        image::ColorType::L8
        | image::ColorType::La8
        | image::ColorType::Rgb8
        | image::ColorType::Rgba8 => {
            let mut buf: Vec<u8> = crate::mem::zeroed(
                usize::try_from(decoder.total_bytes())
                    .map_err(|_| Error::Limits("image larger than memory".into()))?,
            );
            let (ptr, len) = (buf.as_ptr() as usize, buf.len());
            let populate = len >= 64 << 20;
            std::thread::scope(|s| {
                if populate || overlap.is_some() {
                    s.spawn(move || {
                        if populate {
                            crate::mem::populate(ptr as *const u8, len);
                        }
                        if let Some(mut f) = overlap {
                            f();
                        }
                    });
                }
                decoder.read_image(&mut buf)
            })
            .map_err(lim)?;
            let bad = || Error::Decode {
                format: file_format.name(),
                reason: "the decoded image does not match its declared size".into(),
            };
            match ct {
                image::ColorType::L8 => DynamicImage::ImageLuma8(
                    image::ImageBuffer::from_raw(w, h, buf).ok_or_else(bad)?,
                ),
                image::ColorType::La8 => DynamicImage::ImageLumaA8(
                    image::ImageBuffer::from_raw(w, h, buf).ok_or_else(bad)?,
                ),
                image::ColorType::Rgb8 => DynamicImage::ImageRgb8(
                    image::ImageBuffer::from_raw(w, h, buf).ok_or_else(bad)?,
                ),
                _ => DynamicImage::ImageRgba8(
                    image::ImageBuffer::from_raw(w, h, buf).ok_or_else(bad)?,
                ),
            }
        }
        _ => std::thread::scope(|s| {
            if let Some(f) = overlap {
                s.spawn(f);
            }
            DynamicImage::from_decoder(decoder)
        })
        .map_err(lim)?,
    };
    if let (Some(t), DynamicImage::ImageLumaA8(b)) = (extras.grey_trns, &mut img) {
        for px in b.chunks_exact_mut(2) {
            px[1] = if px[0] == t { 0 } else { u8::MAX };
        }
    }
    let (w, h) = (img.width(), img.height());
    let f = |ch: u8, ty: ChannelType| {
        let cs = match (file_format, png_cs) {
            (FileFormat::Png, Some(cs)) if !ty.is_float() => cs,
            (FileFormat::Jpeg, _) if ty == ChannelType::U8 => ColorSpace::Srgb,
            _ => ColorSpace::Linear,
        };
        Format::new(ch, ty, cs)
    };
    use ChannelType::*;
    let mut tex = match img {
        DynamicImage::ImageLuma8(b) => Texture::from_u8(w, h, f(1, U8), b.into_raw()),
        DynamicImage::ImageLumaA8(b) => Texture::from_u8(w, h, f(2, U8), b.into_raw()),
        DynamicImage::ImageRgb8(b) => Texture::from_u8(w, h, f(3, U8), b.into_raw()),
        DynamicImage::ImageRgba8(b) => Texture::from_u8(w, h, f(4, U8), b.into_raw()),
        DynamicImage::ImageLuma16(b) => Texture::from_u16(w, h, f(1, U16), b.into_raw()),
        DynamicImage::ImageLumaA16(b) => Texture::from_u16(w, h, f(2, U16), b.into_raw()),
        DynamicImage::ImageRgb16(b) => Texture::from_u16(w, h, f(3, U16), b.into_raw()),
        DynamicImage::ImageRgba16(b) => Texture::from_u16(w, h, f(4, U16), b.into_raw()),
        DynamicImage::ImageRgb32F(b) => Texture::from_f32(w, h, f(3, F32), b.into_raw()),
        other => Texture::from_f32(w, h, f(4, F32), other.into_rgba32f().into_raw()),
    }?;
    let mut attributes = Vec::new();
    if orientation != 1 {
        attributes.push(("Orientation".to_string(), orientation.to_string()));
        if options.auto_orient {
            tex = orient(&tex, orientation)?;
            notes.push(format!(
                "EXIF orientation {orientation} applied (--no-auto-orient keeps the stored order)"
            ));
        } else {
            notes.push(format!(
                "EXIF orientation {orientation} not applied (--no-auto-orient)"
            ));
        }
    }
    let mut info = SourceInfo::new(file_format, &tex.format());
    info.attributes = attributes;
    info.notes = notes;
    info.color_stated = color_stated;
    Ok(Loaded {
        levels: vec![tex],
        info,
    })
}

/// `t` turned by an EXIF/TIFF orientation code (1–8: how the stored rows
/// map to the displayed image), so that row 0 is the top of the picture:
/// 2 mirrors, 3 turns 180°, 4 flips, 5 transposes, 6 turns 90° clockwise,
/// 7 transverses, 8 turns 90° anticlockwise. Codes outside 1–8 are an
/// error.
pub fn orient(t: &Texture, code: u16) -> Result<Texture> {
    let (w, h) = (t.width() as usize, t.height() as usize);
    let swap = matches!(code, 5..=8);
    let (ow, oh) = if swap { (h, w) } else { (w, h) };
    // Source texel of output texel (x, y).
    let src = |x: usize, y: usize| -> (usize, usize) {
        match code {
            2 => (w - 1 - x, y),
            3 => (w - 1 - x, h - 1 - y),
            4 => (x, h - 1 - y),
            5 => (y, x),
            6 => (y, h - 1 - x),
            7 => (w - 1 - y, h - 1 - x),
            8 => (w - 1 - y, x),
            _ => (x, y),
        }
    };
    if !(1..=8).contains(&code) {
        return Err(Error::Decode {
            format: "image",
            reason: format!("orientation {code} is not an EXIF orientation (1 to 8)"),
        });
    }
    if code == 1 {
        return Ok(t.clone());
    }
    let ch = t.channels();
    fn turn<T: Copy>(
        v: &[T],
        ch: usize,
        w: usize,
        ow: usize,
        oh: usize,
        src: &dyn Fn(usize, usize) -> (usize, usize),
    ) -> Vec<T> {
        let mut out = Vec::with_capacity(v.len());
        for y in 0..oh {
            for x in 0..ow {
                let (sx, sy) = src(x, y);
                let i = (sy * w + sx) * ch;
                out.extend_from_slice(&v[i..i + ch]);
            }
        }
        out
    }
    let texels = match t.texels() {
        Texels::U8(v) => Texels::U8(turn(v, ch, w, ow, oh, &src)),
        Texels::U16(v) => Texels::U16(turn(v, ch, w, ow, oh, &src)),
        Texels::F16(v) => Texels::F16(turn(v, ch, w, ow, oh, &src)),
        Texels::F32(v) => Texels::F32(turn(v, ch, w, ow, oh, &src)),
    };
    Texture::from_texels(ow as u32, oh as u32, t.format(), texels)
}

/// The stored values as little-endian bytes (borrowed on little-endian
/// machines).
pub fn le_bytes(texels: &Texels) -> Cow<'_, [u8]> {
    #[cfg(target_endian = "little")]
    {
        match texels {
            Texels::U8(v) => Cow::Borrowed(v.as_slice()),
            Texels::U16(v) => Cow::Borrowed(bytemuck::cast_slice(v)),
            Texels::F16(v) => Cow::Borrowed(bytemuck::cast_slice(v.reinterpret_cast())),
            Texels::F32(v) => Cow::Borrowed(bytemuck::cast_slice(v)),
        }
    }
    #[cfg(not(target_endian = "little"))]
    {
        match texels {
            Texels::U8(v) => Cow::Borrowed(v.as_slice()),
            Texels::U16(v) => Cow::Owned(v.iter().flat_map(|x| x.to_le_bytes()).collect()),
            Texels::F16(v) => Cow::Owned(v.iter().flat_map(|x| x.to_le_bytes()).collect()),
            Texels::F32(v) => Cow::Owned(v.iter().flat_map(|x| x.to_le_bytes()).collect()),
        }
    }
}

/// Texels of the given type from little-endian bytes (length must be a
/// multiple of the type's size).
pub fn texels_from_le(ty: ChannelType, bytes: &[u8]) -> Texels {
    match ty {
        ChannelType::U8 => Texels::U8(bytes.to_vec()),
        ChannelType::U16 => Texels::U16(
            bytes
                .chunks_exact(2)
                .map(|b| u16::from_le_bytes([b[0], b[1]]))
                .collect(),
        ),
        ChannelType::F16 => Texels::F16(
            bytes
                .chunks_exact(2)
                .map(|b| half::f16::from_le_bytes([b[0], b[1]]))
                .collect(),
        ),
        ChannelType::F32 => Texels::F32(
            bytes
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect(),
        ),
    }
}

/// The fingerprint `--update` compares: a 128-bit XXH3 hash of level 0's
/// format, size and texel bytes and of `options` (every setting that changes
/// the output), as 32 hex digits.
pub fn fingerprint(level0: &Texture, options: &str) -> String {
    let mut h = xxhash_rust::xxh3::Xxh3::new();
    h.update(
        format!(
            "{}x{} {}|{}|",
            level0.width(),
            level0.height(),
            level0.format(),
            options
        )
        .as_bytes(),
    );
    h.update(&le_bytes(level0.texels()));
    format!("{:032x}", h.digest128())
}

/// Container of an output file, chosen from its name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum OutputKind {
    /// `.exr`: tiled, mip-mapped OpenEXR.
    Exr,
    /// `.ktx2`: KTX 2.0, uncompressed.
    Ktx2,
    /// `.dds`: DDS, uncompressed, legacy or DX10 header as the format needs.
    Dds,
    /// A name containing `{level}` and ending in `.png`: one PNG per level.
    PngLevels,
}

impl OutputKind {
    /// Pick the container for an output name: `{level}` in the name means
    /// one PNG per level, otherwise the extension decides.
    pub fn from_path(path: &Path) -> Result<Self> {
        let s = path.to_string_lossy();
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        if s.contains("{level}") {
            // One file per level is PNG's way; the other containers hold the
            // whole chain in one file, and a `.exr` name must not get PNG
            // bytes.
            return if ext == "png" {
                Ok(OutputKind::PngLevels)
            } else {
                Err(Error::InvalidOption(format!(
                    "output `{s}`: a {{level}} template writes one PNG per level, so it must end in .png \
                     (.exr, .ktx2 and .dds hold the whole chain in one file: drop {{level}})"
                )))
            };
        }
        match ext.as_str() {
            "exr" => Ok(OutputKind::Exr),
            "ktx2" => Ok(OutputKind::Ktx2),
            "dds" => Ok(OutputKind::Dds),
            _ => Err(Error::InvalidOption(format!(
                "output `{s}`: unknown extension (use .exr, .ktx2, .dds, or a name with {{level}} for one PNG per level)"
            ))),
        }
    }

    /// Display name of the container ("OpenEXR", "PNG", ...).
    pub fn name(self) -> &'static str {
        match self {
            OutputKind::Exr => "OpenEXR",
            OutputKind::Ktx2 => "KTX2",
            OutputKind::Dds => "DDS",
            OutputKind::PngLevels => "PNG",
        }
    }

    /// Channel types the container can store.
    pub fn supports(self, ty: ChannelType) -> bool {
        match self {
            OutputKind::Exr => ty.is_float(),
            OutputKind::PngLevels => !ty.is_float(),
            OutputKind::Ktx2 | OutputKind::Dds => true,
        }
    }
}

/// Everything a writer needs besides the levels.
#[derive(Clone, Debug, PartialEq)]
pub struct SaveOptions {
    /// Wrap modes to record.
    pub wrap: Wrap,
    /// EXR tile size.
    pub tile: (u32, u32),
    /// EXR compression.
    pub compression: exr::ExrCompression,
    /// Fingerprint to record (EXR attribute, KTX2 key/value).
    pub fingerprint: Option<String>,
    /// More attributes to record (EXR, KTX2).
    pub attributes: Vec<(String, String)>,
    /// Channel names for EXR output (one per channel, e.g. the source's
    /// `N.X,N.Y,N.Z`); `None` writes `R,G,B,A`, `Y,A` or `Y`.
    pub channel_names: Option<Vec<String>>,
    /// KTX2 supercompression of every level (zstd or zlib).
    pub supercompression: Option<ktx2::Supercompression>,
}

impl Default for SaveOptions {
    fn default() -> Self {
        SaveOptions {
            wrap: Wrap::default(),
            tile: (64, 64),
            compression: exr::ExrCompression::Zip,
            fingerprint: None,
            attributes: Vec::new(),
            channel_names: None,
            supercompression: None,
        }
    }
}

/// Write `levels` (level 0 first, sizes following `rounding`) to `path`
/// atomically in the container `kind`.
pub fn save(
    levels: &[Texture],
    rounding: Rounding,
    path: &Path,
    kind: OutputKind,
    options: &SaveOptions,
) -> Result<()> {
    let first = levels
        .first()
        .ok_or_else(|| Error::InvalidOption("nothing to write: no levels".into()))?;
    if !kind.supports(first.channel_type()) {
        return Err(Error::InvalidOption(format!(
            "{kind:?} output cannot store {} texels",
            first.channel_type()
        )));
    }
    for (k, l) in levels.iter().enumerate() {
        let want = mip::level_size(first.width(), first.height(), k as u32, rounding);
        if (l.width(), l.height()) != want || l.format() != first.format() {
            return Err(Error::InvalidOption(format!(
                "level {k} is {}x{} {}, expected {}x{} {}",
                l.width(),
                l.height(),
                l.format(),
                want.0,
                want.1,
                first.format()
            )));
        }
    }
    match kind {
        OutputKind::Exr => exr::save(levels, rounding, path, options),
        OutputKind::Ktx2 => ktx2::save(levels, path, options),
        OutputKind::Dds => dds::save(levels, path),
        OutputKind::PngLevels => png_levels::save(levels, path),
    }
}

/// Write a block-compressed chain to `path` atomically: KTX2 (with
/// `options`' key/value data and supercompression) or DDS (DX10 header).
pub fn save_blocks(
    chain: &crate::compress::BlockChain,
    path: &Path,
    kind: OutputKind,
    options: &SaveOptions,
) -> Result<()> {
    match kind {
        OutputKind::Ktx2 => ktx2::save_blocks(chain, path, options),
        OutputKind::Dds => dds::save_blocks(chain, path),
        _ => Err(Error::InvalidOption(format!(
            "{} cannot store block-compressed texels: use .ktx2 or .dds",
            kind.name()
        ))),
    }
}

/// The fingerprint stored in an existing output (EXR attribute or KTX2
/// key/value), or `None` when there is none or the file cannot be read.
pub fn stored_fingerprint(path: &Path, kind: OutputKind) -> Option<String> {
    match kind {
        OutputKind::Exr => exr::stored_fingerprint(path),
        OutputKind::Ktx2 => ktx2::stored_fingerprint(path),
        OutputKind::Dds | OutputKind::PngLevels => None,
    }
}

/// Name of the fingerprint attribute (EXR) and key (KTX2).
pub const FINGERPRINT_KEY: &str = "parvo:fingerprint";
