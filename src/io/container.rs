//! The container table: one type per file container, one trait, one list.
//!
//! Each container (OpenEXR, KTX2, DDS, PNG levels, TIFF, and the codecs
//! of the `image` crate) implements [`Container`] in its own file: how to
//! recognise a file by its first bytes, how to load it within [`Limits`],
//! what it can store (channel types, alpha convention, block formats,
//! level rules, fingerprints) and how to save a chain or a block chain.
//! [`CONTAINERS`] (in `io/mod.rs`, beside the module declarations) lists
//! them in detection order; everything else —
//! [`super::load`], [`OutputKind`], the `mip` pipeline's rules and the
//! command line's `--ext` choices — reads this table instead of naming
//! containers. Adding a container is a new file with an implementation,
//! and its `mod` line and entry in [`CONTAINERS`] in `io/mod.rs`.

use std::fmt;
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};

use super::{CONTAINERS, Limits, LoadOptions, Loaded, Overlap, SaveOptions};
use crate::compress::BlockChain;
use crate::error::{Error, Result};
use crate::mip::Rounding;
use crate::texel::{AlphaMode, ChannelType, Format};
use crate::texture::ImageKind;
use crate::texture::Texture;

/// What an output container can hold and how it names its files.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stores {
    /// Float channel types (f16, f32).
    pub float: bool,
    /// Integer channel types (u8, u16).
    pub integer: bool,
    /// Block-compressed levels ([`Container::save_blocks`]).
    pub blocks: bool,
    /// A mip-mapped file always holds the whole chain down to 1×1 (a
    /// shorter chain is refused).
    pub whole_chain: bool,
    /// Level sizes rounded up (OpenEXR's `ROUND_UP`); otherwise only the
    /// GPU rule, floor(size / 2^k).
    pub round_up: bool,
    /// The fingerprint of [`super::fingerprint`] is stored and read back
    /// ([`Container::stored_fingerprint`]).
    pub fingerprint: bool,
    /// Supercompression of every level (KTX2's zstd and zlib).
    pub supercompression: bool,
    /// Channel names ([`SaveOptions::channel_names`]).
    pub channel_names: bool,
    /// One file per level, named from a `{level}` template.
    pub file_per_level: bool,
    /// Level 0 can be written row band by row band while it is built
    /// (OpenEXR's tiles: [`super::exr::save_streamed`]).
    pub streamed_level0: bool,
    /// The alpha convention the container defines for colour with alpha;
    /// `None` when its header says which (the source's is kept).
    pub alpha: Option<AlphaMode>,
}

impl Stores {
    /// Stores nothing (a read-only container).
    pub const NOTHING: Stores = Stores {
        float: false,
        integer: false,
        blocks: false,
        whole_chain: false,
        round_up: false,
        fingerprint: false,
        supercompression: false,
        channel_names: false,
        file_per_level: false,
        streamed_level0: false,
        alpha: None,
    };
}

/// One file container (see the module docs).
pub trait Container: Send + Sync {
    /// Lower-case identifier and file extension: `exr`, `ktx2`, ...
    fn id(&self) -> &'static str;
    /// Display name: "OpenEXR", "KTX2", ...
    fn name(&self) -> &'static str;
    /// The name older fingerprints recorded for the output kind
    /// (`kind=Exr`); kept so that `--update` still recognises them.
    fn tag(&self) -> &'static str {
        self.name()
    }
    /// One line for the command line's list of output containers.
    fn summary(&self) -> &'static str {
        self.name()
    }

    /// True when a file starting with `magic` (up to 12 bytes) is this
    /// container's. The last entry of [`CONTAINERS`] takes every file no
    /// other claims.
    fn detect(&self, _magic: &[u8]) -> bool {
        false
    }
    /// Load the file at `path` within `limits` (only called after
    /// [`Container::detect`] claimed it). `overlap` is the caller's work
    /// for the core a single-threaded decoder leaves idle
    /// ([`super::load_overlapped`]); a loader that does not decode on one
    /// thread never calls it.
    fn load(
        &self,
        path: &Path,
        _limits: &Limits,
        _options: &LoadOptions,
        _overlap: Option<Overlap<'_>>,
    ) -> Result<Loaded> {
        Err(Error::Decode {
            format: self.name(),
            reason: format!(
                "parvo does not read {} files ({})",
                self.name(),
                path.display()
            ),
        })
    }
    /// The kind of image a file of this container holds (a cube map, an
    /// array, a recorded environment), from its first bytes `head` (up to
    /// 148) or its headers at `path`; `None` when it cannot tell or holds
    /// one 2-D image ([`super::peek_kind`]).
    fn peek_kind(&self, _head: &[u8], _path: &Path) -> Option<ImageKind> {
        None
    }
    /// File extensions (lower case) of the files it reads, for inputs
    /// given as a directory.
    fn read_extensions(&self) -> &'static [&'static str] {
        &[]
    }
    /// True when [`LoadOptions::channels`] (choosing channels by name)
    /// applies to this container's files.
    fn selects_channels(&self) -> bool {
        false
    }

    /// True when [`LoadOptions::subimage`] (a part or page other than the
    /// first) applies to this container's files.
    fn selects_subimage(&self) -> bool {
        false
    }

    /// What the container stores as an output; `None` for containers
    /// parvo only reads.
    fn stores(&self) -> Option<Stores> {
        None
    }
    /// How the command line names an output of this container in its
    /// list of choices (".exr", "a name with {level} for ...").
    fn output_hint(&self) -> String {
        format!(".{}", self.id())
    }
    /// The output file for `stem` in directory `dir` (batches).
    fn batch_path(&self, dir: &Path, stem: &str) -> PathBuf {
        dir.join(format!("{stem}.{}", self.id()))
    }
    /// The channel type written when none is asked for, for a source of
    /// type `src`.
    fn default_type(&self, src: ChannelType) -> ChannelType {
        src
    }
    /// The channel type of a one-channel data chain (roughness) beside a
    /// main output of type `main`, when none is asked for or the asked
    /// one is not storable.
    fn data_type(&self, main: ChannelType) -> ChannelType {
        main
    }
    /// `f` adjusted to what the container can describe (e.g. KTX2 has no
    /// sRGB 16-bit formats: stored as linear).
    fn storable(&self, f: Format) -> Format {
        f
    }
    /// Write an image of `kind` to `path` atomically: `images` holds each
    /// face or layer's levels (level 0 first, sizes following `rounding`,
    /// in [`super::Loaded::images`]'s order), one entry for a 2-D or
    /// lat-long image. Called by [`save_images`] after the common checks,
    /// only for a `kind` the container [`Container::holds`].
    fn save(
        &self,
        _images: &[&[Texture]],
        _kind: ImageKind,
        _rounding: Rounding,
        path: &Path,
        _options: &SaveOptions,
    ) -> Result<()> {
        Err(not_writable(self.name(), path))
    }
    /// Write block-compressed chains (one per face or layer, as in
    /// [`Container::save`]) of an image of `kind` to `path` atomically.
    fn save_blocks(
        &self,
        _chains: &[BlockChain],
        _kind: ImageKind,
        _path: &Path,
        _options: &SaveOptions,
    ) -> Result<()> {
        Err(Error::InvalidOption(format!(
            "{} cannot store block-compressed texels: use {}",
            self.name(),
            or_list(&block_hints())
        )))
    }
    /// The fingerprint stored in an existing output, or `None`.
    fn stored_fingerprint(&self, _path: &Path) -> Option<String> {
        None
    }
    /// True when the container can write an image of `kind` (every
    /// output writes [`ImageKind::Plain`]).
    fn holds(&self, kind: ImageKind) -> bool {
        kind == ImageKind::Plain
    }
    /// Where the texels of the environment maps this container writes
    /// sit ([`SaveOptions::placement`] says where those given to `save`
    /// do): centred for every container but OpenEXR.
    fn placement(&self) -> crate::env::Placement {
        crate::env::Placement::Centred
    }
    /// Refuses an output name `path` that cannot name an image of `kind`
    /// in this container (one PNG per level needs `{face}` or `{layer}`
    /// to tell a cube map's faces or an array's layers apart).
    fn check_path(&self, _path: &Path, _kind: ImageKind) -> Result<()> {
        Ok(())
    }
}

fn cannot_hold(name: &str, kind: ImageKind, path: &Path) -> Error {
    let holders: Vec<String> = outputs()
        .filter(|k| k.holds(kind))
        .map(|k| format!(".{}", k.id()))
        .collect();
    Error::InvalidOption(format!(
        "output `{}`: {name} cannot store a {}{}",
        path.display(),
        kind.describe(),
        if holders.is_empty() {
            String::new()
        } else {
            format!(" (use {})", or_list(&holders))
        }
    ))
}

fn not_writable(name: &str, path: &Path) -> Error {
    Error::InvalidOption(format!(
        "output `{}`: parvo does not write {name} files",
        path.display()
    ))
}

/// The container of a file whose first bytes are `magic` (`None` only
/// if the table were empty).
pub fn detect(magic: &[u8]) -> Option<&'static dyn Container> {
    CONTAINERS
        .iter()
        .copied()
        .find(|c| c.detect(magic))
        .or(CONTAINERS.last().copied())
}

/// Every extension some container reads (lower case), for inputs given
/// as a directory.
pub fn read_extensions() -> impl Iterator<Item = &'static str> {
    CONTAINERS
        .iter()
        .flat_map(|c| c.read_extensions().iter().copied())
}

/// The containers parvo writes, in table order.
pub fn outputs() -> impl Iterator<Item = OutputKind> {
    CONTAINERS
        .iter()
        .copied()
        .filter(|c| c.stores().is_some())
        .map(OutputKind)
}

/// What channel types each output container stores, from the table:
/// `OpenEXR: f16, f32; KTX2: all; ...` (for messages).
pub fn types_stored() -> String {
    let all = [
        ChannelType::U8,
        ChannelType::U16,
        ChannelType::F16,
        ChannelType::F32,
    ];
    outputs()
        .map(|k| {
            let types: Vec<String> = all
                .iter()
                .filter(|t| k.supports(**t))
                .map(|t| t.to_string())
                .collect();
            let list = if types.len() == all.len() {
                "all".to_string()
            } else {
                types.join(", ")
            };
            format!("{}: {list}", k.name())
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// `a`, `a or b`, `a, b, or c`.
fn or_list(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [a] => a.clone(),
        [a, b] => format!("{a} or {b}"),
        [rest @ .., last] => format!("{}, or {last}", rest.join(", ")),
    }
}

/// `a`, `a and b`, `a, b and c`.
fn and_list(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [a] => a.clone(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}

fn block_hints() -> Vec<String> {
    outputs()
        .filter(|k| k.stores().blocks)
        .map(|k| k.output_hint())
        .collect()
}

/// An output container: an entry of [`CONTAINERS`] that writes files.
#[derive(Clone, Copy)]
pub struct OutputKind(&'static dyn Container);

impl OutputKind {
    /// Tiled, mip-mapped OpenEXR.
    pub const EXR: OutputKind = OutputKind(&super::exr::OpenExr);
    /// KTX 2.0.
    pub const KTX2: OutputKind = OutputKind(&super::ktx2::Ktx2);
    /// DDS.
    pub const DDS: OutputKind = OutputKind(&super::dds::Dds);
    /// One PNG per level, from a `{level}` name template.
    pub const PNG_LEVELS: OutputKind = OutputKind(&super::png_levels::PngLevels);

    /// The output container with identifier `id` (`exr`, `ktx2`, `dds`,
    /// `png`).
    pub fn from_id(id: &str) -> Option<OutputKind> {
        outputs().find(|k| k.id() == id)
    }

    /// The container for an output of one level of one image: as
    /// [`OutputKind::from_path`], and a `.png` name without `{level}` is
    /// that one PNG.
    pub fn for_one_level(path: &Path) -> Result<Self> {
        let png = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("png"));
        if png {
            return Ok(OutputKind::PNG_LEVELS);
        }
        OutputKind::from_path(path)
    }

    /// Pick the container for an output name: `{level}` in the name means
    /// one file per level, otherwise the extension decides.
    pub fn from_path(path: &Path) -> Result<Self> {
        let s = path.to_string_lossy();
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        let templated = s.contains("{level}");
        if let Some(k) = outputs().find(|k| k.id() == ext && k.stores().file_per_level == templated)
        {
            return Ok(k);
        }
        if templated {
            // One file per level is PNG's way; the other containers hold
            // the whole chain in one file, and a `.exr` name must not get
            // PNG bytes.
            let per_level: Vec<String> = outputs()
                .filter(|k| k.stores().file_per_level)
                .map(|k| format!(".{}", k.id()))
                .collect();
            let whole: Vec<String> = outputs()
                .filter(|k| !k.stores().file_per_level)
                .map(|k| format!(".{}", k.id()))
                .collect();
            return Err(Error::InvalidOption(format!(
                "output `{s}`: a {{level}} template writes one PNG per level, so it must end in {} \
                 ({} hold the whole chain in one file: drop {{level}})",
                or_list(&per_level),
                and_list(&whole)
            )));
        }
        let hints: Vec<String> = outputs().map(|k| k.output_hint()).collect();
        Err(Error::InvalidOption(format!(
            "output `{s}`: unknown extension (use {})",
            or_list(&hints)
        )))
    }

    /// The container's entry in the table.
    pub fn container(self) -> &'static dyn Container {
        self.0
    }

    /// What the container stores.
    pub fn stores(self) -> Stores {
        // Every OutputKind is made from an entry that stores (`outputs`,
        // the constants below): `NOTHING` is never seen.
        self.0.stores().unwrap_or(Stores::NOTHING)
    }

    /// Where the texels of the environment maps this container writes
    /// sit.
    pub fn placement(self) -> crate::env::Placement {
        self.0.placement()
    }

    /// Refuses an output name that cannot name an image of `kind` in
    /// this container (PNG levels of a cube map without `{face}`).
    pub fn check_path(self, path: &Path, kind: ImageKind) -> Result<()> {
        self.0.check_path(path, kind)
    }

    /// Display name of the container ("OpenEXR", "PNG", ...).
    pub fn name(self) -> &'static str {
        self.0.name()
    }

    /// Identifier and extension (`exr`, `png`, ...).
    pub fn id(self) -> &'static str {
        self.0.id()
    }

    /// Channel types the container can store.
    pub fn supports(self, ty: ChannelType) -> bool {
        let s = self.stores();
        if ty.is_float() { s.float } else { s.integer }
    }
}

impl std::ops::Deref for OutputKind {
    type Target = dyn Container;
    fn deref(&self) -> &Self::Target {
        self.0
    }
}

impl PartialEq for OutputKind {
    fn eq(&self, other: &Self) -> bool {
        self.0.id() == other.0.id()
    }
}

impl Eq for OutputKind {}

impl Hash for OutputKind {
    fn hash<H: Hasher>(&self, state: &mut H) {
        self.0.id().hash(state)
    }
}

impl fmt::Debug for OutputKind {
    /// The tag older fingerprints recorded (`Exr`, `PngLevels`, ...).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.0.tag())
    }
}

/// Write `levels` (level 0 first, sizes following `rounding`) to `path`
/// atomically in the container `kind`: one 2-D image ([`save_images`]).
pub fn save(
    levels: &[Texture],
    rounding: Rounding,
    path: &Path,
    kind: OutputKind,
    options: &SaveOptions,
) -> Result<()> {
    save_images(&[levels], ImageKind::Plain, rounding, path, kind, options)
}

/// Write a texture of image kind `image_kind` to `path` atomically in the
/// container `kind`: `images` holds each face or layer's levels (level
/// 0 first, sizes following `rounding`, all of one size, format and
/// level count; a cube's faces square), one entry for a 2-D or lat-long
/// image.
pub fn save_images(
    images: &[&[Texture]],
    image_kind: ImageKind,
    rounding: Rounding,
    path: &Path,
    kind: OutputKind,
    options: &SaveOptions,
) -> Result<()> {
    check_images(images.len(), image_kind, path, kind)?;
    let first = images[0];
    check_levels(first, rounding)?;
    if !kind.supports(first[0].channel_type()) {
        return Err(Error::InvalidOption(format!(
            "{kind:?} output cannot store {} texels",
            first[0].channel_type()
        )));
    }
    for (i, levels) in images.iter().enumerate() {
        let same = levels.len() == first.len()
            && levels.first().map(|l| (l.width(), l.height(), l.format()))
                == first.first().map(|l| (l.width(), l.height(), l.format()));
        if !same {
            return Err(Error::InvalidOption(format!(
                "image {i} of the {} differs from the first in size, format or level count",
                image_kind.describe()
            )));
        }
        check_levels(levels, rounding)?;
    }
    if image_kind.is_cube() && first[0].width() != first[0].height() {
        return Err(Error::InvalidOption(format!(
            "a cube map's faces must be square, got {}x{}",
            first[0].width(),
            first[0].height()
        )));
    }
    kind.0.save(images, image_kind, rounding, path, options)
}

/// Write block-compressed chains of an image of kind `image_kind` (one
/// chain per face or layer, all of one format, size and level count) to
/// `path` atomically in the container `kind`.
pub fn save_blocks(
    chains: &[BlockChain],
    image_kind: ImageKind,
    path: &Path,
    kind: OutputKind,
    options: &SaveOptions,
) -> Result<()> {
    check_images(chains.len(), image_kind, path, kind)?;
    for (i, c) in chains.iter().enumerate() {
        c.validate()?;
        let shape = |c: &BlockChain| (c.format, c.srgb, c.alpha, c.width, c.height, c.levels.len());
        if shape(c) != shape(&chains[0]) {
            return Err(Error::InvalidOption(format!(
                "image {i} of the {} differs from the first in size, format or level count",
                image_kind.describe()
            )));
        }
    }
    if image_kind.is_cube() && chains[0].width != chains[0].height {
        return Err(Error::InvalidOption(format!(
            "a cube map's faces must be square, got {}x{}",
            chains[0].width, chains[0].height
        )));
    }
    kind.0.save_blocks(chains, image_kind, path, options)
}

/// `count` images make an image of `image_kind`, which `kind` holds.
fn check_images(count: usize, image_kind: ImageKind, path: &Path, kind: OutputKind) -> Result<()> {
    if !kind.holds(image_kind) {
        return Err(cannot_hold(kind.name(), image_kind, path));
    }
    kind.check_path(path, image_kind)?;
    if count != image_kind.images() {
        return Err(Error::InvalidOption(format!(
            "a {} holds {} images, got {count}",
            image_kind.describe(),
            image_kind.images(),
        )));
    }
    Ok(())
}

/// Every level of `levels` the size `rounding` gives and the format of
/// level 0.
fn check_levels(levels: &[Texture], rounding: Rounding) -> Result<()> {
    let Some(first) = levels.first() else {
        return Err(Error::InvalidOption("nothing to write: no levels".into()));
    };
    for (k, l) in levels.iter().enumerate() {
        let want = crate::mip::level_size(first.width(), first.height(), k as u32, rounding);
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
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Identifiers are unique, every output has a distinct tag, and
    /// `from_path` finds each output by its own batch name.
    #[test]
    fn the_table_is_consistent() {
        let ids: Vec<_> = CONTAINERS.iter().map(|c| c.id()).collect();
        let mut sorted = ids.clone();
        sorted.sort();
        sorted.dedup();
        assert_eq!(sorted.len(), ids.len(), "{ids:?}");
        for k in outputs() {
            let p = k.batch_path(Path::new("dir"), "stem");
            assert_eq!(OutputKind::from_path(&p).unwrap(), k, "{}", p.display());
            assert!(k.supports(k.default_type(ChannelType::U8)), "{}", k.id());
            assert!(k.supports(k.default_type(ChannelType::F32)), "{}", k.id());
        }
    }

    #[test]
    fn lists_read_as_english() {
        let s = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
        assert_eq!(or_list(&s(&["a", "b", "c"])), "a, b, or c");
        assert_eq!(or_list(&s(&["a", "b"])), "a or b");
        assert_eq!(and_list(&s(&["a", "b", "c"])), "a, b and c");
        assert_eq!(and_list(&s(&["a"])), "a");
    }
}
