//! What a texel is: channel count, channel type, colour space and alpha mode,
//! and the conversions between stored values and linear-light `f32`.
//!
//! Every filter in parvo works on linear light. Stored data is decoded once
//! (u8/u16 normalised, f16 widened, sRGB linearised through tables) and
//! encoded back with round-to-nearest. The conversions here are the single
//! home of those rules; fast paths elsewhere are tested against them.

pub(crate) mod codec8;
pub mod srgb;

use std::borrow::Cow;
use std::fmt;
use std::str::FromStr;

use half::f16;
use half::slice::HalfFloatSliceExt;

use crate::error::{Error, Result};

/// How one channel value is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum ChannelType {
    /// 8-bit unsigned normalised: code / 255.
    #[default]
    U8,
    /// 16-bit unsigned normalised: code / 65535.
    U16,
    /// IEEE half float.
    F16,
    /// IEEE single float.
    F32,
}

impl ChannelType {
    /// Bytes per channel value.
    pub fn bytes(self) -> usize {
        match self {
            ChannelType::U8 => 1,
            ChannelType::U16 | ChannelType::F16 => 2,
            ChannelType::F32 => 4,
        }
    }

    /// True for the float types, which may hold values outside [0, 1],
    /// NaN and infinities.
    pub fn is_float(self) -> bool {
        matches!(self, ChannelType::F16 | ChannelType::F32)
    }

    /// Short name: `u8`, `u16`, `f16`, `f32`.
    pub fn name(self) -> &'static str {
        match self {
            ChannelType::U8 => "u8",
            ChannelType::U16 => "u16",
            ChannelType::F16 => "f16",
            ChannelType::F32 => "f32",
        }
    }
}

impl fmt::Display for ChannelType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for ChannelType {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        Ok(match s.to_ascii_lowercase().as_str() {
            "u8" => ChannelType::U8,
            "u16" => ChannelType::U16,
            "f16" | "half" => ChannelType::F16,
            "f32" | "float" => ChannelType::F32,
            _ => {
                return Err(Error::parse(
                    "channel type",
                    s,
                    "expected u8, u16, f16 or f32",
                ));
            }
        })
    }
}

/// Transfer function of the colour channels (alpha is always linear).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum ColorSpace {
    /// Values are linear light.
    #[default]
    Linear,
    /// Values are sRGB-encoded (IEC 61966-2-1 piecewise curve).
    Srgb,
}

impl fmt::Display for ColorSpace {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ColorSpace::Linear => "linear",
            ColorSpace::Srgb => "srgb",
        })
    }
}

impl FromStr for ColorSpace {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        Ok(match s.to_ascii_lowercase().as_str() {
            "linear" => ColorSpace::Linear,
            "srgb" => ColorSpace::Srgb,
            _ => return Err(Error::parse("colour space", s, "expected linear or srgb")),
        })
    }
}

/// How colour relates to alpha in textures that have an alpha channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum AlphaMode {
    /// Colour is independent of alpha (unassociated). Filters weight colour
    /// by alpha and divide it back out, so transparent texels do not darken
    /// their neighbours.
    #[default]
    Straight,
    /// Colour is already multiplied by alpha (associated); filtered as is.
    Premultiplied,
    /// No channel is alpha: the second of two or the fourth of four
    /// channels is data (a `U,V` flow map, an `R,G` two-channel normal map,
    /// a packed mask), filtered independently like every other channel.
    None,
}

impl fmt::Display for AlphaMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            AlphaMode::Straight => "straight",
            AlphaMode::Premultiplied => "premultiplied",
            AlphaMode::None => "none",
        })
    }
}

impl FromStr for AlphaMode {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        Ok(match s.to_ascii_lowercase().as_str() {
            "straight" | "unassociated" => AlphaMode::Straight,
            "premultiplied" | "associated" => AlphaMode::Premultiplied,
            "none" | "data" => AlphaMode::None,
            _ => {
                return Err(Error::parse(
                    "alpha mode",
                    s,
                    "expected straight, premultiplied or none",
                ));
            }
        })
    }
}

/// The full description of a texel.
///
/// Channel layouts: 1 = grey (or R), 2 = grey + alpha, 3 = RGB, 4 = RGBA.
/// The alpha channel, when present, is the last one; with
/// [`AlphaMode::None`] two channels are R, G and four are R, G, B and a
/// fourth data channel, none of them alpha.
///
/// Equality and hashing ignore `alpha` for one and three channels, which
/// have no alpha channel whatever the field says.
#[derive(Clone, Copy, Debug)]
pub struct Format {
    /// Channels per texel, 1 to 4.
    pub channels: u8,
    /// Storage type of each channel.
    pub channel_type: ChannelType,
    /// Transfer function of the colour (non-alpha) channels.
    pub color_space: ColorSpace,
    /// Alpha convention (ignored without an alpha channel).
    pub alpha: AlphaMode,
}

impl Format {
    /// The alpha mode that matters: the field for two and four channels,
    /// [`AlphaMode::Straight`] (the default) otherwise.
    fn effective_alpha(&self) -> AlphaMode {
        if self.channels == 2 || self.channels == 4 {
            self.alpha
        } else {
            AlphaMode::Straight
        }
    }
}

impl PartialEq for Format {
    fn eq(&self, o: &Self) -> bool {
        self.channels == o.channels
            && self.channel_type == o.channel_type
            && self.color_space == o.color_space
            && self.effective_alpha() == o.effective_alpha()
    }
}

impl Eq for Format {}

impl std::hash::Hash for Format {
    fn hash<H: std::hash::Hasher>(&self, h: &mut H) {
        (
            self.channels,
            self.channel_type,
            self.color_space,
            self.effective_alpha(),
        )
            .hash(h);
    }
}

impl Default for Format {
    /// RGBA8, sRGB, straight alpha: what an ordinary PNG holds.
    fn default() -> Self {
        Format::new(4, ChannelType::U8, ColorSpace::Srgb)
    }
}

impl Format {
    /// A format with straight alpha.
    pub const fn new(channels: u8, channel_type: ChannelType, color_space: ColorSpace) -> Self {
        Format {
            channels,
            channel_type,
            color_space,
            alpha: AlphaMode::Straight,
        }
    }

    /// Same format with another alpha mode.
    pub const fn with_alpha(mut self, alpha: AlphaMode) -> Self {
        self.alpha = alpha;
        self
    }

    /// True when the last channel is alpha (2 or 4 channels, alpha mode
    /// other than [`AlphaMode::None`]).
    pub fn has_alpha(&self) -> bool {
        (self.channels == 2 || self.channels == 4) && self.alpha != AlphaMode::None
    }

    /// Index of the alpha channel, if any.
    pub fn alpha_channel(&self) -> Option<usize> {
        self.has_alpha().then(|| self.channels as usize - 1)
    }

    /// Number of colour (non-alpha) channels.
    pub fn color_channels(&self) -> usize {
        self.channels as usize - usize::from(self.has_alpha())
    }

    /// Bytes per texel.
    pub fn texel_bytes(&self) -> usize {
        self.channels as usize * self.channel_type.bytes()
    }

    pub(crate) fn validate(&self) -> Result<()> {
        if !(1..=4).contains(&self.channels) {
            return Err(Error::InvalidOption(format!(
                "{} channels: parvo supports 1 to 4",
                self.channels
            )));
        }
        Ok(())
    }

    /// True when channel `c` is decoded with the sRGB curve.
    #[inline]
    pub fn is_srgb_channel(&self, c: usize) -> bool {
        self.color_space == ColorSpace::Srgb && c < self.color_channels()
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let layout = match (self.channels, self.has_alpha()) {
            (1, _) => "R",
            (2, true) => "RA",
            (2, false) => "RG",
            (3, _) => "RGB",
            _ => "RGBA",
        };
        write!(f, "{layout} {} {}", self.channel_type, self.color_space)?;
        if self.has_alpha() {
            write!(f, " {} alpha", self.alpha)?;
        } else if self.channels == 4 {
            f.write_str(" (A is data)")?;
        }
        Ok(())
    }
}

/// Owned channel values of one image, in one of the storage types.
#[derive(Clone, Debug, PartialEq)]
pub enum Texels {
    /// 8-bit normalised values.
    U8(Vec<u8>),
    /// 16-bit normalised values.
    U16(Vec<u16>),
    /// Half floats.
    F16(Vec<f16>),
    /// Single floats.
    F32(Vec<f32>),
}

impl Texels {
    /// Number of channel values.
    pub fn len(&self) -> usize {
        match self {
            Texels::U8(v) => v.len(),
            Texels::U16(v) => v.len(),
            Texels::F16(v) => v.len(),
            Texels::F32(v) => v.len(),
        }
    }

    /// True when there are no values.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The storage type.
    pub fn channel_type(&self) -> ChannelType {
        match self {
            Texels::U8(_) => ChannelType::U8,
            Texels::U16(_) => ChannelType::U16,
            Texels::F16(_) => ChannelType::F16,
            Texels::F32(_) => ChannelType::F32,
        }
    }

    /// `len` zero values of the given type.
    pub fn zeroed(ty: ChannelType, len: usize) -> Self {
        match ty {
            ChannelType::U8 => Texels::U8(crate::mem::zeroed(len)),
            ChannelType::U16 => Texels::U16(crate::mem::zeroed(len)),
            ChannelType::F16 => Texels::F16(crate::mem::zeroed(len)),
            ChannelType::F32 => Texels::F32(crate::mem::zeroed(len)),
        }
    }

    /// Shorten to, or extend with zeros to, `len` values (keeping the
    /// allocation when it is large enough).
    pub fn resize(&mut self, len: usize) {
        match self {
            Texels::U8(v) => v.resize(len, 0),
            Texels::U16(v) => v.resize(len, 0),
            Texels::F16(v) => v.resize(len, f16::ZERO),
            Texels::F32(v) => v.resize(len, 0.0),
        }
    }

    /// The values in runs of `n` (the last may be shorter), for writers
    /// that fill disjoint parts in parallel.
    pub fn chunks_mut(&mut self, n: usize) -> Vec<TexelsMut<'_>> {
        match self {
            Texels::U8(v) => v.chunks_mut(n).map(TexelsMut::U8).collect(),
            Texels::U16(v) => v.chunks_mut(n).map(TexelsMut::U16).collect(),
            Texels::F16(v) => v.chunks_mut(n).map(TexelsMut::F16).collect(),
            Texels::F32(v) => v.chunks_mut(n).map(TexelsMut::F32).collect(),
        }
    }

    /// The values as bytes in the host's byte order (little-endian on
    /// every platform parvo's writers run on).
    pub fn bytes_mut(&mut self) -> &mut [u8] {
        match self {
            Texels::U8(v) => v,
            Texels::U16(v) => bytemuck::cast_slice_mut(v),
            Texels::F16(v) => bytemuck::cast_slice_mut(v),
            Texels::F32(v) => bytemuck::cast_slice_mut(v),
        }
    }
}

/// A run of values of one storage type to fill ([`Texels::chunks_mut`]).
#[derive(Debug)]
pub enum TexelsMut<'a> {
    /// 8-bit normalised values.
    U8(&'a mut [u8]),
    /// 16-bit normalised values.
    U16(&'a mut [u16]),
    /// Half floats.
    F16(&'a mut [f16]),
    /// Single floats.
    F32(&'a mut [f32]),
}

/// Decode stored values to linear-light f32 (`channels` values per texel).
///
/// `out` must have the same length as the stored values. Runs in parallel
/// (rayon) on large inputs.
pub fn decode_to_linear(format: &Format, texels: &Texels, out: &mut [f32]) {
    let chunk = format.channels as usize * 16384;
    match texels {
        Texels::U8(v) => par_zip(v, out, chunk, |i, o| decode_u8(format, i, o)),
        Texels::U16(v) => par_zip(v, out, chunk, |i, o| decode_u16(format, i, o)),
        Texels::F16(v) => par_zip(v, out, chunk, |i, o| decode_f16(format, i, o)),
        Texels::F32(v) => par_zip(v, out, chunk, |i, o| decode_f32(format, i, o)),
    }
}

/// [`decode_to_linear`] of the values `start .. start + out.len()` only,
/// on the calling thread: the same values, for code that decodes a band of
/// rows at a time.
pub fn decode_range_to_linear(format: &Format, texels: &Texels, start: usize, out: &mut [f32]) {
    let r = start..start + out.len();
    match texels {
        Texels::U8(v) => decode_u8(format, &v[r], out),
        Texels::U16(v) => decode_u16(format, &v[r], out),
        Texels::F16(v) => decode_f16(format, &v[r], out),
        Texels::F32(v) => decode_f32(format, &v[r], out),
    }
}

fn decode_f16(format: &Format, i: &[f16], o: &mut [f32]) {
    i.convert_to_f32_slice(o);
    decode_float_srgb(format, o);
}

fn decode_f32(format: &Format, i: &[f32], o: &mut [f32]) {
    o.copy_from_slice(i);
    decode_float_srgb(format, o);
}

/// Encode linear-light f32 values to storage, rounding to nearest.
///
/// Normalised types clamp to [0, 1] (NaN becomes 0). Float types keep the
/// value, except that finite values beyond the f16 range saturate to
/// ±65504 rather than becoming infinite (filter overshoot near the top of
/// the range must not create infinities). Runs in parallel on large inputs.
pub fn encode_from_linear(format: &Format, linear: &[f32], out: &mut Texels) {
    use rayon::prelude::*;
    assert_eq!(linear.len(), out.len(), "decode/encode length mismatch");
    let chunk = format.channels as usize * 16384;
    if linear.len() <= chunk {
        if let Some(o) = out.chunks_mut(chunk.max(1)).pop() {
            encode_into(format, linear, o);
        }
        return;
    }
    out.chunks_mut(chunk)
        .into_par_iter()
        .zip(linear.par_chunks(chunk))
        .for_each(|(o, i)| encode_into(format, i, o));
}

/// [`encode_from_linear`] of whole texels into a run of values, on the
/// calling thread.
pub fn encode_into(format: &Format, linear: &[f32], out: TexelsMut<'_>) {
    match out {
        TexelsMut::U8(o) => encode_u8(format, linear, o),
        TexelsMut::U16(o) => encode_u16(format, linear, o),
        TexelsMut::F16(o) => {
            let mut tmp = linear.to_vec();
            encode_float_srgb(format, &mut tmp);
            for v in &mut tmp {
                if v.is_finite() {
                    *v = v.clamp(-65504.0, 65504.0);
                }
            }
            o.convert_from_f32_slice(&tmp);
        }
        TexelsMut::F32(o) => {
            o.copy_from_slice(linear);
            encode_float_srgb(format, o);
        }
    }
}

fn par_zip<A: Sync, B: Send>(
    a: &[A],
    b: &mut [B],
    chunk: usize,
    f: impl Fn(&[A], &mut [B]) + Sync,
) {
    use rayon::prelude::*;
    assert_eq!(a.len(), b.len(), "decode/encode length mismatch");
    if a.len() <= chunk {
        f(a, b);
    } else {
        a.par_chunks(chunk)
            .zip(b.par_chunks_mut(chunk))
            .for_each(|(a, b)| f(a, b));
    }
}

/// Decode 8-bit values (whole texels) to linear f32: one table look-up
/// per value, the table (sRGB or `c / 255`) chosen per channel once, not
/// per value.
pub fn decode_u8(format: &Format, i: &[u8], o: &mut [f32]) {
    let (ch, cc) = (format.channels as usize, srgb_channels(format));
    if i.len() >= 64 && codec8::decode(i, o, ch, cc) {
        return;
    }
    let t = decode8_tables(format);
    match format.channels {
        1 => decode_u8_n::<1>(&t, i, o),
        2 => decode_u8_n::<2>(&t, i, o),
        3 => decode_u8_n::<3>(&t, i, o),
        _ => decode_u8_n::<4>(&t, i, o),
    }
}

/// How many leading channels of `format` are sRGB-encoded (the colour
/// channels of an sRGB format, none of a linear one).
fn srgb_channels(format: &Format) -> usize {
    (0..format.channels as usize)
        .take_while(|&c| format.is_srgb_channel(c))
        .count()
}

/// The decode table of each channel of an 8-bit `format`.
fn decode8_tables(format: &Format) -> [&'static [f32; 256]; 4] {
    static LINEAR: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
    let linear = LINEAR.get_or_init(|| std::array::from_fn(|k| k as f32 * (1.0 / 255.0)));
    let srgb = &srgb::tables().decode8;
    std::array::from_fn(|c| {
        if format.is_srgb_channel(c) {
            srgb
        } else {
            linear
        }
    })
}

#[inline]
fn decode_u8_n<const CH: usize>(t: &[&[f32; 256]; 4], i: &[u8], o: &mut [f32]) {
    for (o, i) in o.chunks_exact_mut(CH).zip(i.chunks_exact(CH)) {
        for c in 0..CH {
            o[c] = t[c][i[c] as usize];
        }
    }
}

/// Decode 16-bit values (whole texels) to linear f32.
pub fn decode_u16(format: &Format, i: &[u16], o: &mut [f32]) {
    let ch = format.channels as usize;
    let table = (format.color_space == ColorSpace::Srgb).then(srgb::decode16);
    for (o, i) in o.chunks_exact_mut(ch).zip(i.chunks_exact(ch)) {
        for c in 0..ch {
            o[c] = match table {
                Some(t) if format.is_srgb_channel(c) => t[i[c] as usize],
                _ => i[c] as f32 * (1.0 / 65535.0),
            };
        }
    }
}

/// Encode linear f32 (whole texels) to 8-bit values, rounding to nearest
/// (sRGB channels by the exact curve's decision thresholds).
pub fn encode_u8(format: &Format, i: &[f32], o: &mut [u8]) {
    let (ch, cc) = (format.channels as usize, srgb_channels(format));
    if i.len() >= 64 && codec8::encode(i, o, ch, cc) {
        return;
    }
    match (format.channels, format.color_space, format.has_alpha()) {
        (1, ColorSpace::Srgb, _) => encode_u8_n::<1, 1>(i, o),
        (2, ColorSpace::Srgb, true) => encode_u8_n::<2, 1>(i, o),
        (2, ColorSpace::Srgb, false) => encode_u8_n::<2, 2>(i, o),
        (3, ColorSpace::Srgb, _) => encode_u8_n::<3, 3>(i, o),
        (4, ColorSpace::Srgb, true) => encode_u8_n::<4, 3>(i, o),
        (4, ColorSpace::Srgb, false) => encode_u8_n::<4, 4>(i, o),
        (1, _, _) => encode_u8_n::<1, 0>(i, o),
        (2, _, _) => encode_u8_n::<2, 0>(i, o),
        (3, _, _) => encode_u8_n::<3, 0>(i, o),
        _ => encode_u8_n::<4, 0>(i, o),
    }
}

/// `CH` channels of which the first `CC` are sRGB-encoded, the rest
/// linear.
#[inline]
fn encode_u8_n<const CH: usize, const CC: usize>(i: &[f32], o: &mut [u8]) {
    let t = srgb::tables();
    for (o, i) in o.chunks_exact_mut(CH).zip(i.chunks_exact(CH)) {
        for c in 0..CC {
            o[c] = srgb::encode_u8_with(t, i[c]);
        }
        for c in CC..CH {
            o[c] = unorm8(i[c]);
        }
    }
}

/// Encode linear f32 (whole texels) to 16-bit values.
pub fn encode_u16(format: &Format, i: &[f32], o: &mut [u16]) {
    let ch = format.channels as usize;
    for (o, i) in o.chunks_exact_mut(ch).zip(i.chunks_exact(ch)) {
        for c in 0..ch {
            let v = if format.is_srgb_channel(c) {
                srgb::encode_f64(i[c].clamp(0.0, 1.0) as f64) as f32
            } else {
                i[c]
            };
            o[c] = unorm16(v);
        }
    }
}

fn decode_float_srgb(format: &Format, out: &mut [f32]) {
    if format.color_space != ColorSpace::Srgb {
        return;
    }
    let ch = format.channels as usize;
    let cc = format.color_channels();
    for t in out.chunks_exact_mut(ch) {
        for v in &mut t[..cc] {
            // Odd extension for negative values, as scRGB-style data needs;
            // f64 so that decode then encode gives the value back.
            *v = (v.signum() as f64 * srgb::decode_f64(v.abs() as f64)) as f32;
        }
    }
}

fn encode_float_srgb(format: &Format, v: &mut [f32]) {
    if format.color_space != ColorSpace::Srgb {
        return;
    }
    let ch = format.channels as usize;
    let cc = format.color_channels();
    for t in v.chunks_exact_mut(ch) {
        for x in &mut t[..cc] {
            *x = (x.signum() as f64 * srgb::encode_f64(x.abs() as f64)) as f32;
        }
    }
}

/// Linear [0, 1] to an 8-bit code, round to nearest, NaN to 0.
#[inline]
pub fn unorm8(v: f32) -> u8 {
    // `as` saturates and maps NaN to 0.
    (v * 255.0 + 0.5) as u8
}

/// Linear [0, 1] to a 16-bit code, round to nearest, NaN to 0.
#[inline]
pub fn unorm16(v: f32) -> u16 {
    (v * 65535.0 + 0.5) as u16
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unorm_round_trip_is_exact() {
        let f = Format::new(1, ChannelType::U8, ColorSpace::Linear);
        let src = Texels::U8((0..=255).collect());
        let mut lin = vec![0.0; 256];
        decode_to_linear(&f, &src, &mut lin);
        let mut back = Texels::zeroed(ChannelType::U8, 256);
        encode_from_linear(&f, &lin, &mut back);
        assert_eq!(back, src);
        let f = Format::new(1, ChannelType::U16, ColorSpace::Srgb);
        let src = Texels::U16((0..=65535).collect());
        let mut lin = vec![0.0; 65536];
        decode_to_linear(&f, &src, &mut lin);
        let mut back = Texels::zeroed(ChannelType::U16, 65536);
        encode_from_linear(&f, &lin, &mut back);
        assert_eq!(back, src);
    }
}
