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
pub mod container;
pub mod dds;
pub mod exr;
pub mod image_codecs;
mod image_errors;
pub mod ktx2;
pub mod limits;
pub mod png_levels;
pub mod source;
pub mod tiff;

use std::fmt;
use std::io::Read;
use std::path::Path;

use crate::error::{Error, Result};
use crate::mip::{self, MipChain, MipOptions, NanPolicy, Rounding};
use crate::setting::Setting;
use crate::texel::{ChannelType, ColorSpace, Format, Texels};
use crate::texture::Texture;
use crate::wrap::Wrap;

pub use crate::texel::{le_bytes, texels_from_le};
pub use container::{Container, OutputKind, Stores, save, save_blocks, save_images};

/// The container table ([`container`]): every container, in detection
/// order; the last reads whatever no other claims. A new container is a
/// module above and one entry here.
pub static CONTAINERS: &[&dyn Container] = &[
    &exr::OpenExr,
    &ktx2::Ktx2,
    &dds::Dds,
    &tiff::Tiff,
    &png_levels::PngLevels,
    &image_codecs::ImageCodecs,
];
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
    /// Where the environment's texels sit on the sphere, as the file's
    /// format defines it: [`crate::env::Placement::Edges`] for an OpenEXR
    /// file with an `envmap` attribute (OpenEXR's `ImfEnvmap`, which
    /// OpenImageIO follows on such files), else centred.
    pub placement: crate::env::Placement,
    /// What kind of image the file holds: one 2-D image, an array, a
    /// cube map or an array of them (KTX2, DDS); [`Loaded::images`] holds
    /// the faces or layers after the first. Loaders set it only when
    /// [`LoadOptions::environment`] lets them read such files (see
    /// [`EnvironmentMaps`]); a lat-long OpenEXR stays `Plain` here and is
    /// told by [`SourceInfo::environment`].
    pub kind: crate::texture::ImageKind,
    /// A 1-D texture or 1-D array (KTX2 `pixelHeight` 0, DDS
    /// `TEXTURE1D`): its images are one row high, and a KTX2 output of
    /// the same kind stays 1-D.
    pub one_d: bool,
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
            placement: crate::env::Placement::Centred,
            kind: crate::texture::ImageKind::Plain,
            one_d: false,
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
    /// For a cube map or an array, the first face or layer.
    pub levels: Vec<Texture>,
    /// Source metadata.
    pub info: SourceInfo,
    /// The faces or layers after the first of a cube map or an array
    /// ([`SourceInfo::kind`]), in the file's order (layer by layer, each
    /// cube's faces +X, −X, +Y, −Y, +Z, −Z), each with as many levels as
    /// [`Loaded::levels`]; empty for one 2-D image.
    pub images: Vec<Vec<Texture>>,
}

impl Loaded {
    /// One 2-D image and what the file said about it.
    pub fn plain(levels: Vec<Texture>, info: SourceInfo) -> Self {
        Loaded {
            levels,
            info,
            images: Vec::new(),
        }
    }

    /// Every face or layer (the first too), each its levels, level 0
    /// first: one entry for a 2-D image.
    pub fn into_images(self) -> Vec<Vec<Texture>> {
        let mut all = Vec::with_capacity(1 + self.images.len());
        all.push(self.levels);
        all.extend(self.images);
        all
    }

    /// Every face or layer as a mip chain: the file's own levels when it
    /// stores them, otherwise box-filtered levels built per image (wrap
    /// modes from the file, else repeat; a cube's faces are not joined
    /// at their edges here, see [`crate::env::cube::build_faces`]).
    pub fn into_image_chains(self) -> Result<Vec<MipChain>> {
        let options = self.chain_options();
        self.into_images()
            .into_iter()
            .map(|levels| image_chain(levels, &options))
            .collect()
    }

    /// Face or layer `index` (in [`Loaded::into_images`]'s order) as a
    /// mip chain, made as [`Loaded::into_image_chains`] makes each; the
    /// other images are dropped without building their levels.
    pub fn into_image_chain(self, index: usize) -> Result<MipChain> {
        let options = self.chain_options();
        let count = 1 + self.images.len();
        let levels = self.into_images().into_iter().nth(index).ok_or_else(|| {
            Error::InvalidOption(format!(
                "image {index} asked for, and the file holds {count}"
            ))
        })?;
        image_chain(levels, &options)
    }

    /// Level 0.
    pub fn base(&self) -> &Texture {
        &self.levels[0]
    }

    /// Consume into level 0.
    pub fn into_base(mut self) -> Texture {
        self.levels.swap_remove(0)
    }

    /// The options a chain of this file is built or kept with: the file's
    /// level rounding, and its wrap modes (repeat when it records none).
    /// [`Loaded::into_chain`] and [`crate::store::TextureStore`] both use
    /// them.
    pub fn chain_options(&self) -> MipOptions {
        MipOptions {
            rounding: self.info.rounding,
            wrap: self.info.wrap.unwrap_or_default(),
            ..MipOptions::default()
        }
    }

    /// Consume into a mip chain: the file's own levels when it stores
    /// them, otherwise a box-filtered chain built from level 0 (wrap modes
    /// from the file when it names them, else repeat); and the block
    /// format the file stored its levels in, if any.
    pub fn into_chain(self) -> Result<(MipChain, Option<crate::compress::BlockFormat>)> {
        let blocks = self.info.blocks;
        let options = self.chain_options();
        let chain = if self.levels.len() > 1 {
            MipChain::from_levels(self.levels, options)?
        } else {
            mip::build(self.into_base(), &options)?
        };
        Ok((chain, blocks))
    }
}

/// One image's chain: its own levels, or box levels built from level 0.
fn image_chain(levels: Vec<Texture>, options: &MipOptions) -> Result<MipChain> {
    let mut levels = levels.into_iter();
    match (levels.next(), levels.len()) {
        (Some(base), 0) => mip::build(base, options),
        (Some(base), _) => {
            MipChain::from_levels(std::iter::once(base).chain(levels).collect(), *options)
        }
        (None, _) => Err(Error::InvalidOption("an image without levels".into())),
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
             as OpenImageIO reads such files ({} linear reads them as data, e.g. a height map)",
            info.format,
            Setting::Color
        ),
        ColorSpace::Linear => format!(
            "the {} file does not say how its values encode colour: read as linear values, as \
             OpenImageIO reads such files ({} srgb decodes them as sRGB)",
            info.format,
            Setting::Color
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
                 clamp, black/border, mirror-clamp): repeat applies unless {} says otherwise",
                Setting::Wrap
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
/// OpenEXR or TIFF): taking it for a plain texture filters a cube's faces
/// into each other and wraps a lat-long map's poles, so the default
/// refuses it. Describing it (what `parvo info` does) loads its texels
/// as stored with [`SourceInfo::environment`] set and a note; accepting
/// it (what a direction lookup, [`crate::env`], does) loads them marked,
/// without a note.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum EnvironmentMaps {
    /// Refuse the file with an error naming the kind (the default).
    #[default]
    Refuse,
    /// Load it as stored, marked as an environment map, with a note.
    Describe,
    /// Load it as stored, marked as an environment map: the caller
    /// samples it as one.
    Accept,
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
                "a {kind} environment map ({detail}), which parvo reads as an environment map \
                 only: filtering it as a flat image would blend {}",
                match kind {
                    Environment::Cube => "its six faces into each other across their edges",
                    Environment::LatLong => "across its poles as if the image repeated vertically",
                }
            ),
        }),
        EnvironmentMaps::Describe => {
            notes.push(format!(
                "{kind} environment map ({detail}): looked up by direction, its levels built \
                 per face (cube) or weighted by solid angle (lat-long)"
            ));
            Ok(())
        }
        EnvironmentMaps::Accept => Ok(()),
    }
}

/// Refuse a cube map or an array of `kind` (`size` its faces' or
/// layers' level-0 size) or note it, as `options` say: read as one 2-D
/// image it would lose every face or layer but the first.
pub(crate) fn layered_image(
    format: &'static str,
    kind: crate::texture::ImageKind,
    (w, h): (u32, u32),
    options: &LoadOptions,
) -> Result<()> {
    let what = match kind {
        crate::texture::ImageKind::Cube => format!("a cube map of six {w}x{h} faces"),
        crate::texture::ImageKind::CubeArray { cubes } => {
            format!("an array of {cubes} cube maps ({w}x{h} faces)")
        }
        // One layer is all of a one-layer array.
        crate::texture::ImageKind::Array { layers } if layers > 1 => {
            format!("a 2-D array of {layers} {w}x{h} layers")
        }
        _ => return Ok(()),
    };
    match options.environment {
        EnvironmentMaps::Refuse => Err(Error::Decode {
            format,
            reason: format!(
                "{what}, which this reader does not take as one 2-D image (it would keep only the \
                 first {})",
                if kind.is_cube() { "face" } else { "layer" }
            ),
        }),
        EnvironmentMaps::Describe | EnvironmentMaps::Accept => Ok(()),
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

/// The kind of image the file at `path` holds (a cube map, an array),
/// from its first bytes only; [`crate::texture::ImageKind::Plain`] for every file
/// that is neither or cannot be read (the load says why).
pub fn peek_kind(path: &Path) -> crate::texture::ImageKind {
    let mut head = [0u8; 148];
    let n = std::fs::File::open(path)
        .and_then(|mut f| {
            let mut n = 0;
            while n < head.len() {
                match f.read(&mut head[n..])? {
                    0 => break,
                    k => n += k,
                }
            }
            Ok(n)
        })
        .unwrap_or(0);
    let head = &head[..n];
    container::detect(head)
        .and_then(|c| c.peek_kind(head, path))
        .unwrap_or(crate::texture::ImageKind::Plain)
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
        let recolor = |levels: Vec<Texture>| {
            levels
                .into_iter()
                .map(|l| {
                    let f = Format {
                        color_space: cs,
                        ..l.format()
                    };
                    l.reinterpret(f)
                })
                .collect::<Result<Vec<_>>>()
        };
        loaded.levels = recolor(std::mem::take(&mut loaded.levels))?;
        for image in &mut loaded.images {
            *image = recolor(std::mem::take(image))?;
        }
    }
    if let Some(policy) = options.nan_policy {
        let every = loaded
            .images
            .iter_mut()
            .flat_map(|i| i.iter_mut().enumerate());
        for (k, l) in loaded.levels.iter_mut().enumerate().chain(every) {
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
        let (w, h) = crate::builtin::dimensions(kind, size);
        limits.check(w as u64, h as u64, w as u64 * h as u64 * 4)?;
        let t = crate::builtin::generate(kind, size)?;
        let info = SourceInfo::new(FileFormat::Builtin, &t.format());
        return Ok(Loaded::plain(vec![t], info));
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
    let container = container::detect(magic).ok_or(Error::Decode {
        format: "input",
        reason: "no container reads it".into(),
    })?;
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        if options.channels.is_some() && !container.selects_channels() {
            return Err(Error::InvalidOption(format!(
                "{} selects channels of OpenEXR files; this input is not one",
                Setting::Channels
            )));
        }
        if options.subimage != 0 && !container.selects_subimage() {
            return Err(Error::InvalidOption(format!(
                "{} picks a part of a multi-part OpenEXR file or a page of a multi-page TIFF; \
                 this input is a {} file, which holds one",
                Setting::Subimage,
                container.name()
            )));
        }
        container.load(path, limits, options, overlap)
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

/// Everything a writer needs besides the levels.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SaveOptions {
    /// Wrap modes to record.
    pub wrap: Wrap,
    /// OpenEXR's options (tile size, compression).
    pub exr: exr::ExrOptions,
    /// Fingerprint to record (EXR attribute, KTX2 key/value).
    pub fingerprint: Option<String>,
    /// More attributes to record (EXR, KTX2).
    pub attributes: Vec<(String, String)>,
    /// Channel names for EXR output (one per channel, e.g. the source's
    /// `N.X,N.Y,N.Z`); `None` writes `R,G,B,A`, `Y,A` or `Y`.
    pub channel_names: Option<Vec<String>>,
    /// KTX2's options (supercompression).
    pub ktx2: ktx2::Ktx2Options,
    /// Where the texels of the environment maps given to `save` sit:
    /// centred (the default, what parvo builds) is resampled to the
    /// container's own placement where it defines another (OpenEXR's
    /// lat-long and cube maps, [`exr::edges_from_centred`]); `Edges` says
    /// they are placed as OpenEXR places them already.
    pub placement: crate::env::Placement,
    /// Write a texture one row high as 1-D where the container has 1-D
    /// textures (KTX2 `pixelHeight` 0); the source was 1-D.
    pub one_d: bool,
}

/// The fingerprint stored in an existing output (EXR attribute or KTX2
/// key/value), or `None` when there is none or the file cannot be read.
pub fn stored_fingerprint(path: &Path, kind: OutputKind) -> Option<String> {
    kind.container().stored_fingerprint(path)
}

/// Name of the fingerprint attribute (EXR) and key (KTX2).
pub const FINGERPRINT_KEY: &str = "parvo:fingerprint";
