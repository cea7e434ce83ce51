//! Environment maps, cube maps and texture arrays: textures looked up by
//! a direction (or a layer index) instead of a 2-D coordinate.
//!
//! - [`crate::ImageKind`]: what a file's image is — a 2-D texture, an array of them, a
//!   cube map, an array of cube maps, or a 2-D image that is a lat-long
//!   environment.
//! - [`cube`]: face selection, face coordinates and their derivatives as
//!   the GL and Vulkan specifications define them, and [`CubeSampler`],
//!   every filter of [`crate::sample`] read seamlessly across face edges.
//! - [`latlong`]: [`LatLongSampler`], lookups of an equirectangular map
//!   as OpenImageIO's `TextureSystem::environment()` does them.
//! - [`prefilter`]: prefiltered specular levels (GGX, Beckmann, Phong
//!   lobes, the split-sum convention) and diffuse irradiance (and SH9).
//! - [`convert`]: a lat-long map as a cube map and back, by filtered
//!   lookups over each new texel's footprint.
//! - [`ArraySampler`]: a 2-D sampler per layer, the layer picked as GL
//!   picks it.
//!
//! A direction lookup is a [`DirQuery`]: the direction (any length) and its
//! change per pixel along screen x and y.

pub mod convert;
pub mod cube;
mod cube_ewa;
pub mod latlong;
pub mod prefilter;
pub(crate) mod vec3;

pub use cube::CubeSampler;
pub use latlong::LatLongSampler;

use crate::error::{Error, Result};
use crate::mip::MipChain;
use crate::sample::{Query, Sampler, SamplerOptions};

/// Where an environment map's texels sit on the sphere: the one thing
/// OpenEXR's definition and the GPU's (and maketx's) disagree on besides
/// the faces' orientation. The reader of a file says which
/// (`io::SourceInfo::placement`); a sampler follows it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Placement {
    /// Texel centres at `((i + ½)/w, (j + ½)/h)` of the map's `(s, t)`:
    /// the GL and Vulkan cube faces, maketx's `.tx` lat-long maps (and
    /// OpenImageIO's `environment()` on them), and every image that
    /// records no OpenEXR environment.
    #[default]
    Centred,
    /// OpenEXR's definition (`ImfEnvmap.cpp`): texel `i` at
    /// `i/(w − 1)`, so the first and last texel centres lie on the
    /// map's edges. A lat-long map's first row is the +y pole, its last
    /// the −y pole, and its first and last columns the same meridian (−z)
    /// (`LatLongMap::latLong`, `pixelPosition`); OpenImageIO reads
    /// OpenEXR environments this way too (`oiio:sampleborder` 1).
    Edges,
}

/// A lookup by direction: the direction (any non-zero length) and its
/// change per pixel along screen x (`ddx`) and y (`ddy`), as a shader
/// gets them with `dFdx`/`dFdy` of the reflection vector.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct DirQuery {
    /// Direction (x, y, z).
    pub dir: [f32; 3],
    /// ∂dir/∂x.
    pub ddx: [f32; 3],
    /// ∂dir/∂y.
    pub ddy: [f32; 3],
}

impl DirQuery {
    /// A query from its nine numbers, in the CLI's order
    /// (`x y z dxdx dydx dzdx dxdy dydy dzdy`).
    pub const fn new(dir: [f32; 3], ddx: [f32; 3], ddy: [f32; 3]) -> Self {
        DirQuery { dir, ddx, ddy }
    }

    /// A point lookup: zero derivatives.
    pub const fn point(dir: [f32; 3]) -> Self {
        DirQuery {
            dir,
            ddx: [0.0; 3],
            ddy: [0.0; 3],
        }
    }
}

/// The supersampled reference by direction, shared by the cube and
/// lat-long samplers: the mean of `lookup` at `n × n` directions over the
/// footprint `dir ± ddx/2 ± ddy/2`, one at the centre of each cell of the
/// 2-D reference's grid (summed in `f64`; non-finite derivative components
/// count as 0).
pub(crate) fn grid_average(
    q: &DirQuery,
    n: u32,
    mut lookup: impl FnMut([f64; 3]) -> [f32; 4],
) -> [f32; 4] {
    let n = n.clamp(1, 64);
    let inv = 1.0 / n as f64;
    // A NaN or infinite derivative component spans nothing (as the 2-D
    // samplers take it): the grid stays finite, so every lookup does.
    let finite = |v: [f32; 3]| v.map(|x| if x.is_finite() { f64::from(x) } else { 0.0 });
    let (d, dx, dy) = (q.dir.map(f64::from), finite(q.ddx), finite(q.ddy));
    let mut acc = [0.0f64; 4];
    for j in 0..n {
        let ty = (j as f64 + 0.5) * inv - 0.5;
        for i in 0..n {
            let tx = (i as f64 + 0.5) * inv - 0.5;
            let v = lookup(std::array::from_fn(|c| d[c] + tx * dx[c] + ty * dy[c]));
            for c in 0..4 {
                acc[c] += v[c] as f64;
            }
        }
    }
    let s = 1.0 / (n * n) as f64;
    acc.map(|x| (x * s) as f32)
}

/// The layer (or, in a cube-map array, the cube) GL reads for array
/// coordinate `layer` among `layers`: `clamp(floor(layer + 0.5), 0,
/// layers − 1)`, so 1.6 reads layer 2 and 1.4 layer 1 (OpenGL 4.6 §8.14.2,
/// Vulkan's "Cube Map Face Selection" for cube arrays); NaN reads layer 0,
/// as does any layer of an empty array.
pub fn layer_index(layer: f32, layers: usize) -> usize {
    let l = (layer as f64 + 0.5).floor();
    if l.is_nan() || layers == 0 {
        return 0;
    }
    l.clamp(0.0, (layers - 1) as f64) as usize
}

/// A 2-D texture array: one sampler per layer, sharing options.
#[derive(Clone, Debug)]
pub struct ArraySampler {
    layers: Vec<Sampler>,
}

impl ArraySampler {
    /// Samplers over `layers` (at least one; all of one size and format).
    pub fn new(layers: &[MipChain], options: SamplerOptions) -> Result<Self> {
        let first = layers
            .first()
            .ok_or_else(|| Error::InvalidOption("a texture array needs a layer".into()))?;
        let l0 = &first.levels()[0];
        for (i, l) in layers.iter().enumerate() {
            let t = &l.levels()[0];
            if (t.width(), t.height(), t.format(), l.len())
                != (l0.width(), l0.height(), l0.format(), first.len())
            {
                return Err(Error::InvalidOption(format!(
                    "array layer {i} ({}x{}, {} levels) differs from layer 0 ({}x{}, {} levels) in size, format or level count",
                    t.width(),
                    t.height(),
                    l.len(),
                    l0.width(),
                    l0.height(),
                    first.len()
                )));
            }
        }
        let layers = layers
            .iter()
            .map(|c| Sampler::new(c, options))
            .collect::<Result<Vec<_>>>()?;
        Ok(ArraySampler { layers })
    }

    /// Number of layers.
    pub fn layers(&self) -> usize {
        self.layers.len()
    }

    /// The layer GL reads for array coordinate `layer` ([`layer_index`]).
    pub fn layer_index(&self, layer: f32) -> usize {
        layer_index(layer, self.layers.len())
    }

    /// Filtered linear RGBA of layer `layer` (see [`Self::layer_index`]).
    pub fn sample(&self, q: &Query, layer: f32) -> [f32; 4] {
        self.layers[self.layer_index(layer)].sample(q)
    }

    /// The sampler of one layer (for the other lookups: level, bias,
    /// gather, compare, load).
    pub fn layer(&self, layer: usize) -> Option<&Sampler> {
        self.layers.get(layer)
    }
}
