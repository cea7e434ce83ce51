//! Normal-map renormalisation: filtering unit vectors shortens them, which
//! dims specular highlights in the distance; each reduced level is
//! renormalised. Unorm data encodes a component `n` as `(n + 1) / 2`; float
//! data stores components as they are.

use crate::texture::Texture;

/// Renormalise the first three channels of every texel of `level` to unit
/// length (zero vectors become +Z).
pub fn renormalize(level: &mut Texture) {
    let fmt = level.format();
    let ch = level.channels();
    let unorm = !fmt.channel_type.is_float();
    let mut lin = level.to_linear();
    for t in lin.chunks_exact_mut(ch) {
        let mut n = [t[0], t[1], t[2]];
        if unorm {
            for c in &mut n {
                *c = *c * 2.0 - 1.0;
            }
        }
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        let n = if len > 1e-12 && len.is_finite() {
            [n[0] / len, n[1] / len, n[2] / len]
        } else {
            [0.0, 0.0, 1.0]
        };
        for c in 0..3 {
            t[c] = if unorm { n[c] * 0.5 + 0.5 } else { n[c] };
        }
    }
    crate::texel::encode_from_linear(&fmt, &lin, level.texels_mut());
}
