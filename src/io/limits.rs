//! Limits against decompression bombs.
//!
//! A 60-byte PNG can declare 100000×100000 texels; a few bytes of EXR header
//! can declare a mip chain of terabytes. Every decoder in [`crate::io`] checks
//! the declared size against a [`Limits`] *before* allocating: the `image`
//! codecs through [`image::Limits`], OpenEXR, KTX2 and DDS through
//! [`Limits::check`] on their headers.

use crate::error::{Error, Result};
use crate::setting::Setting;

/// Maximum width, height and allocation a decoder may use.
///
/// Defaults: 65536 × 65536 texels and 4 GiB for the decoded texels (a
/// 16384² RGBA f32 image, or a 32768² RGBA8 one). `parvo mip` and `parvo
/// info` raise them with `--max-width`, `--max-height` and `--max-alloc`;
/// docs/limits.md in the repository lists what each format counts, and
/// every other limit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Largest accepted width in texels.
    pub max_width: u32,
    /// Largest accepted height in texels.
    pub max_height: u32,
    /// Largest accepted size of the decoded texels in bytes (all levels).
    pub max_alloc: u64,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_width: 65536,
            max_height: 65536,
            max_alloc: 4 << 30,
        }
    }
}

impl Limits {
    /// No limits at all (trusted input only).
    pub fn none() -> Self {
        Limits {
            max_width: u32::MAX,
            max_height: u32::MAX,
            max_alloc: u64::MAX,
        }
    }

    /// Check a declared size: `width × height` texels and `bytes` of decoded
    /// data (which the caller computes for all the levels it will decode).
    pub fn check(&self, width: u64, height: u64, bytes: u64) -> Result<()> {
        if width > self.max_width as u64 || height > self.max_height as u64 {
            return Err(Error::Limits(format!(
                "image declares {width}x{height}, more than the {}x{} allowed (raise with {}/{})",
                self.max_width,
                self.max_height,
                Setting::MaxWidth,
                Setting::MaxHeight
            )));
        }
        if bytes > self.max_alloc {
            return Err(Error::Limits(format!(
                "image needs {}, more than the {} allowed (raise with {})",
                byte_size(bytes),
                byte_size(self.max_alloc),
                Setting::MaxAlloc
            )));
        }
        Ok(())
    }

    /// The same limits for the `image` crate's decoders.
    pub fn to_image(&self) -> image::Limits {
        let mut l = image::Limits::default();
        l.max_image_width = Some(self.max_width);
        l.max_image_height = Some(self.max_height);
        l.max_alloc = Some(self.max_alloc);
        l
    }
}

/// A byte count in words: `3 MiB`, `12 KiB` or `100 bytes` (rounded up,
/// so that a count over a limit never reads as equal to it).
pub(crate) fn byte_size(n: u64) -> String {
    if n >= 1 << 20 {
        format!("{} MiB", n.div_ceil(1 << 20))
    } else if n >= 1 << 10 {
        format!("{} KiB", n.div_ceil(1 << 10))
    } else {
        format!("{n} bytes")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn oversized_declarations_are_refused() {
        let l = Limits::default();
        assert!(l.check(100_000, 100_000, 0).is_err());
        assert!(l.check(4096, 4096, 5 << 30).is_err());
        assert!(l.check(4096, 4096, 4096 * 4096 * 4).is_ok());
    }
}
