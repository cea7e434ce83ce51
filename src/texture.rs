//! [`Texture`]: an owned 2-D array of texels with checked dimensions.
//!
//! Construction is the only place sizes are validated: a zero width or
//! height, or a byte size that overflows `usize`/`isize`, is an
//! [`Error::InvalidDimensions`], never a panic or wrapped arithmetic. After
//! that every index computation stays in range.

use half::f16;

use crate::error::{Error, Result};
use crate::texel::{self, AlphaMode, ChannelType, Format, Texels};

/// What kind of image a texture is: the shape a file's images make (a
/// 2-D texture, an array of them, a cube map, an array of cube maps, or a
/// 2-D image holding a lat-long environment). Every loader reports it
/// (`io::SourceInfo::kind`), every container says which it
/// stores, and the mip pipeline builds each by its own rule.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum ImageKind {
    /// One 2-D image (with its mip levels).
    #[default]
    Plain,
    /// `layers` 2-D images of one size and format.
    Array {
        /// Layer count (at least 1).
        layers: u32,
    },
    /// Six square faces, in the order +X, −X, +Y, −Y, +Z, −Z.
    Cube,
    /// `cubes` cube maps (6 × `cubes` faces, cube by cube).
    CubeArray {
        /// Cube count (at least 1).
        cubes: u32,
    },
    /// A 2-D image holding the sphere of directions in latitude and
    /// longitude (equirectangular), OpenImageIO's `LatLong Environment`.
    LatLong,
}

impl ImageKind {
    /// How many 2-D images (faces or layers, each with its own mip chain)
    /// a texture of this kind holds.
    pub fn images(self) -> usize {
        match self {
            ImageKind::Plain | ImageKind::LatLong => 1,
            ImageKind::Array { layers } => layers as usize,
            ImageKind::Cube => 6,
            ImageKind::CubeArray { cubes } => 6 * cubes as usize,
        }
    }

    /// True for a cube map or an array of them.
    pub fn is_cube(self) -> bool {
        matches!(self, ImageKind::Cube | ImageKind::CubeArray { .. })
    }

    /// A one-word identifier (`2d`, `array`, `cube`, `cube-array`,
    /// `latlong`), as JSON reports give it.
    pub fn id(self) -> &'static str {
        match self {
            ImageKind::Plain => "2d",
            ImageKind::Array { .. } => "array",
            ImageKind::Cube => "cube",
            ImageKind::CubeArray { .. } => "cube-array",
            ImageKind::LatLong => "latlong",
        }
    }

    /// A short description, as `parvo info` prints it.
    pub fn describe(self) -> String {
        match self {
            ImageKind::Plain => "2-D".into(),
            ImageKind::Array { layers: 1 } => "2-D array, 1 layer".into(),
            ImageKind::Array { layers } => format!("2-D array, {layers} layers"),
            ImageKind::Cube => "cube map (+x -x +y -y +z -z)".into(),
            ImageKind::CubeArray { cubes } => format!("cube map array, {cubes} cubes"),
            ImageKind::LatLong => "lat-long environment".into(),
        }
    }
}

/// One image level: `width × height` texels of one [`Format`], row-major,
/// row 0 first (at v = 0), channels interleaved.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    width: u32,
    height: u32,
    format: Format,
    texels: Texels,
}

/// Number of channel values for the given size, or an error if it cannot be
/// allocated.
pub fn checked_len(width: u64, height: u64, format: &Format) -> Result<usize> {
    let bad = |reason| Error::InvalidDimensions {
        width,
        height,
        channels: format.channels as u64,
        reason,
    };
    format.validate()?;
    if width == 0 || height == 0 {
        return Err(bad("width and height must be at least 1"));
    }
    if width > u32::MAX as u64 || height > u32::MAX as u64 {
        return Err(bad("width and height must fit in 32 bits"));
    }
    let values = width
        .checked_mul(height)
        .and_then(|t| t.checked_mul(format.channels as u64))
        .ok_or(bad("texel count overflows"))?;
    let bytes = values
        .checked_mul(format.channel_type.bytes() as u64)
        .ok_or(bad("byte size overflows"))?;
    if bytes > isize::MAX as u64 || values > usize::MAX as u64 {
        return Err(bad("byte size exceeds the address space"));
    }
    Ok(values as usize)
}

impl Texture {
    /// A texture of zeros (transparent black).
    pub fn new(width: u32, height: u32, format: Format) -> Result<Self> {
        let len = checked_len(width as u64, height as u64, &format)?;
        Ok(Texture {
            width,
            height,
            format,
            texels: Texels::zeroed(format.channel_type, len),
        })
    }

    /// Wrap existing values; the storage type must match `format` and the
    /// length must be `width · height · channels`.
    pub fn from_texels(width: u32, height: u32, format: Format, texels: Texels) -> Result<Self> {
        let len = checked_len(width as u64, height as u64, &format)?;
        if texels.channel_type() != format.channel_type {
            return Err(Error::InvalidOption(format!(
                "texels are {} but the format says {}",
                texels.channel_type(),
                format.channel_type
            )));
        }
        if texels.len() != len {
            return Err(Error::DataLength {
                width,
                height,
                channels: format.channels,
                expected: len,
                actual: texels.len(),
            });
        }
        Ok(Texture {
            width,
            height,
            format,
            texels,
        })
    }

    /// Convenience: 8-bit values.
    pub fn from_u8(width: u32, height: u32, format: Format, v: Vec<u8>) -> Result<Self> {
        Self::from_texels(width, height, format, Texels::U8(v))
    }
    /// Convenience: 16-bit values.
    pub fn from_u16(width: u32, height: u32, format: Format, v: Vec<u16>) -> Result<Self> {
        Self::from_texels(width, height, format, Texels::U16(v))
    }
    /// Convenience: half floats.
    pub fn from_f16(width: u32, height: u32, format: Format, v: Vec<f16>) -> Result<Self> {
        Self::from_texels(width, height, format, Texels::F16(v))
    }
    /// Convenience: single floats.
    pub fn from_f32(width: u32, height: u32, format: Format, v: Vec<f32>) -> Result<Self> {
        Self::from_texels(width, height, format, Texels::F32(v))
    }

    /// Build from linear-light f32 values, encoding to `format` (sRGB
    /// encoded and rounded as [`texel::encode_from_linear`] does).
    pub fn from_linear(width: u32, height: u32, format: Format, linear: &[f32]) -> Result<Self> {
        let mut t = Texture::new(width, height, format)?;
        if linear.len() != t.texels.len() {
            return Err(Error::DataLength {
                width,
                height,
                channels: format.channels,
                expected: t.texels.len(),
                actual: linear.len(),
            });
        }
        texel::encode_from_linear(&format, linear, &mut t.texels);
        Ok(t)
    }

    /// Width in texels (at least 1).
    pub fn width(&self) -> u32 {
        self.width
    }
    /// Height in texels (at least 1).
    pub fn height(&self) -> u32 {
        self.height
    }
    /// The texel format.
    pub fn format(&self) -> Format {
        self.format
    }
    /// Channels per texel.
    pub fn channels(&self) -> usize {
        self.format.channels as usize
    }
    /// The stored values.
    pub fn texels(&self) -> &Texels {
        &self.texels
    }
    /// Mutable stored values (the length cannot change).
    pub fn texels_mut(&mut self) -> &mut Texels {
        &mut self.texels
    }
    /// Consume into the stored values.
    pub fn into_texels(self) -> Texels {
        self.texels
    }
    /// Number of texels.
    pub fn texel_count(&self) -> usize {
        self.width as usize * self.height as usize
    }
    /// Size of the stored values in bytes.
    pub fn byte_len(&self) -> usize {
        self.texels.len() * self.format.channel_type.bytes()
    }

    /// Change how the values are interpreted (colour space, alpha mode)
    /// without touching them. Channel count and type must stay the same.
    pub fn reinterpret(mut self, format: Format) -> Result<Self> {
        if format.channels != self.format.channels
            || format.channel_type != self.format.channel_type
        {
            return Err(Error::InvalidOption(format!(
                "cannot reinterpret {} as {}",
                self.format, format
            )));
        }
        self.format = format;
        Ok(self)
    }

    /// All values decoded to linear-light f32.
    pub fn to_linear(&self) -> Vec<f32> {
        let mut out = vec![0.0; self.texels.len()];
        texel::decode_to_linear(&self.format, &self.texels, &mut out);
        out
    }

    /// One texel decoded to linear light; missing channels are 0 (alpha 1).
    /// Panics if (x, y) is out of range.
    pub fn texel_linear(&self, x: u32, y: u32) -> [f32; 4] {
        assert!(x < self.width && y < self.height, "texel out of range");
        let ch = self.channels();
        let i = (y as usize * self.width as usize + x as usize) * ch;
        let mut buf = [0f32; 4];
        let one = match &self.texels {
            Texels::U8(v) => Texels::U8(v[i..i + ch].to_vec()),
            Texels::U16(v) => Texels::U16(v[i..i + ch].to_vec()),
            Texels::F16(v) => Texels::F16(v[i..i + ch].to_vec()),
            Texels::F32(v) => Texels::F32(v[i..i + ch].to_vec()),
        };
        texel::decode_to_linear(&self.format, &one, &mut buf[..ch]);
        expand_to_rgba(&buf[..ch])
    }

    /// Convert to another storage type / colour space through linear light.
    pub fn convert(&self, format: Format) -> Result<Self> {
        if format.channels != self.format.channels {
            return Err(Error::InvalidOption(
                "conversion cannot change the channel count".into(),
            ));
        }
        Texture::from_linear(self.width, self.height, format, &self.to_linear())
    }

    /// The channel type.
    pub fn channel_type(&self) -> ChannelType {
        self.format.channel_type
    }

    /// Widen to `channels` (3 or 4) channels: grey is replicated into RGB,
    /// R,G data (no alpha) gets B = 0, a missing alpha becomes opaque. Used
    /// where a container has no format for the source layout (DDS has no
    /// RGB8, PNG no two-channel colour, KTX2's `R8G8_SRGB` would decode
    /// alpha as sRGB) and where a block encoder reads more channels than
    /// the level has.
    pub fn expand_channels(&self, channels: u8) -> Result<Texture> {
        let f = self.format();
        let from = f.channels;
        if from == channels {
            return Ok(self.clone());
        }
        if channels < from || !(3..=4).contains(&channels) {
            return Err(Error::InvalidOption(format!(
                "cannot widen {from} channels to {channels}"
            )));
        }
        // Source channel feeding each destination channel; `None` = 0 for a
        // colour channel, 1 (opaque) for the alpha at index 3.
        let map: [Option<usize>; 4] = match (from, f.has_alpha()) {
            (1, _) => [Some(0), Some(0), Some(0), None],
            (2, true) => [Some(0), Some(0), Some(0), Some(1)],
            (2, false) => [Some(0), Some(1), None, None],
            _ => [Some(0), Some(1), Some(2), None],
        };
        let map = &map[..channels as usize];
        fn widen<T: Copy>(v: &[T], from: usize, map: &[Option<usize>], zero: T, one: T) -> Vec<T> {
            let mut out = Vec::with_capacity(v.len() / from * map.len());
            for px in v.chunks_exact(from) {
                out.extend(map.iter().enumerate().map(|(c, m)| match m {
                    Some(i) => px[*i],
                    None if c == 3 => one,
                    None => zero,
                }));
            }
            out
        }
        let n = from as usize;
        let texels = match self.texels() {
            Texels::U8(v) => Texels::U8(widen(v, n, map, 0, u8::MAX)),
            Texels::U16(v) => Texels::U16(widen(v, n, map, 0, u16::MAX)),
            Texels::F16(v) => Texels::F16(widen(v, n, map, f16::ZERO, f16::ONE)),
            Texels::F32(v) => Texels::F32(widen(v, n, map, 0.0, 1.0)),
        };
        let mut format = f;
        format.channels = channels;
        if channels == 4 && !f.has_alpha() {
            // The added channel is an opaque alpha.
            format.alpha = AlphaMode::Straight;
        }
        Texture::from_texels(self.width(), self.height(), format, texels)
    }
}

/// Expand 1–4 channel values to RGBA: grey is replicated, missing alpha is 1.
pub fn expand_to_rgba(v: &[f32]) -> [f32; 4] {
    match *v {
        [g] => [g, g, g, 1.0],
        [g, a] => [g, g, g, a],
        [r, g, b] => [r, g, b, 1.0],
        [r, g, b, a, ..] => [r, g, b, a],
        [] => [0.0, 0.0, 0.0, 1.0],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texel::ColorSpace;

    #[test]
    fn zero_and_overflowing_sizes_are_errors() {
        let f = Format::new(4, ChannelType::F32, ColorSpace::Linear);
        assert!(Texture::new(0, 5, f).is_err());
        assert!(Texture::new(5, 0, f).is_err());
        assert!(checked_len(u32::MAX as u64, u32::MAX as u64, &f).is_err());
        assert!(checked_len(1 << 33, 1, &f).is_err());
        assert!(Texture::from_u8(2, 2, Format::default(), vec![0; 15]).is_err());
    }
}
