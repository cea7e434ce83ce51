//! The library's error type.
//!
//! Errors are values: every failure that input data, a file or a command line
//! can cause is reported here, never as a panic. The enum is
//! `#[non_exhaustive]` so new kinds can be added without breaking callers.

use std::fmt;

/// Result alias used throughout parvo.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong in the library.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A width, height or channel count that cannot describe a texture
    /// (zero, or a byte size that overflows the address space).
    #[error("invalid dimensions {width}x{height} with {channels} channel(s): {reason}")]
    InvalidDimensions {
        /// Requested width in texels.
        width: u64,
        /// Requested height in texels.
        height: u64,
        /// Requested channel count.
        channels: u64,
        /// Why the combination is refused.
        reason: &'static str,
    },
    /// A texel buffer whose length does not match the dimensions.
    #[error("texel buffer has {actual} values, {width}x{height}x{channels} needs {expected}")]
    DataLength {
        /// Width in texels.
        width: u32,
        /// Height in texels.
        height: u32,
        /// Channels per texel.
        channels: u8,
        /// Values the dimensions require.
        expected: usize,
        /// Values supplied.
        actual: usize,
    },
    /// A NaN or infinite value in float input under [`crate::NanPolicy::Error`].
    #[error("non-finite value {value} at texel ({x}, {y}) channel {channel}{}", level_suffix(*level))]
    NonFinite {
        /// The mip level (0 unless a file's own level holds the value).
        level: u32,
        /// Column of the first bad texel (row-major scan order).
        x: u32,
        /// Row of the first bad texel.
        y: u32,
        /// Channel index within the texel.
        channel: u8,
        /// The offending value.
        value: f32,
    },
    /// A name that does not parse (filter, wrap mode, built-in texture, ...).
    #[error("invalid {what} `{value}`: {reason}")]
    Parse {
        /// What was being parsed ("wrap mode", "mip filter", ...).
        what: &'static str,
        /// The text that was given.
        value: String,
        /// What was expected instead.
        reason: String,
    },
    /// An option that is valid on its own but not for this texture or in this
    /// combination.
    #[error("invalid option: {0}")]
    InvalidOption(String),
    /// A setting of the mip pipeline that does not fit the job or another
    /// setting: which setting, which value, which container. Front ends
    /// say it in their own option names.
    /// (The problem is a `pipeline::Usage`; `Usage::of` reads it back.)
    #[error("invalid option: {0}")]
    Usage(Box<dyn std::error::Error + Send + Sync>),
    /// A file or directory could not be opened, read or written.
    #[error("{action}: {}", io_words(error))]
    Io {
        /// The file or directory involved.
        path: std::path::PathBuf,
        /// What was being done ("cannot open", "cannot rename into place", ...).
        action: String,
        /// The operating system's error (part of the message, so not
        /// also reported as the error's `source`).
        error: std::io::Error,
    },
    /// A file's contents could not be decoded: corrupt, truncated, or a
    /// variant of the format parvo does not support.
    #[error("cannot decode {format}: {reason}")]
    Decode {
        /// The file format ("PNG", "OpenEXR", ...).
        format: &'static str,
        /// What is wrong, in one line.
        reason: String,
    },
    /// A texture could not be encoded in the requested file format.
    #[error("cannot write {format}: {reason}")]
    Encode {
        /// The file format ("OpenEXR", "KTX2", ...).
        format: &'static str,
        /// What is wrong, in one line.
        reason: String,
    },
    /// A decoder limit (width, height, allocation) refused the file; see
    /// `io::Limits` for the defaults and how to raise them.
    #[error("limit exceeded: {0}")]
    Limits(String),
}

fn level_suffix(level: u32) -> String {
    if level == 0 {
        String::new()
    } else {
        format!(" of level {level}")
    }
}

impl Error {
    pub(crate) fn parse(what: &'static str, value: &str, reason: impl fmt::Display) -> Self {
        Error::Parse {
            what,
            value: value.to_string(),
            reason: reason.to_string(),
        }
    }
}

/// An operating-system error in words: its message without Rust's
/// "(os error N)" code ("No such file or directory").
pub(crate) fn io_words(e: &std::io::Error) -> String {
    let text = e.to_string();
    match text.rfind(" (os error ") {
        Some(i) if text.ends_with(')') => text[..i].to_string(),
        _ => text,
    }
}
