//! What a loaded file holds, read as a texture of one [`ImageKind`]: the
//! one place that decides it, for the mip pipeline, the direction
//! sampler and a library user alike.
//!
//! A KTX2 or DDS file says it holds a cube map or an array in its header;
//! an OpenEXR or TIFF file may record an environment (`envmap`,
//! `textureformat`); a plain image holds one only when the caller says so
//! ([`Environment`], the hint): six faces in a strip or a cross (told by
//! the aspect), or a lat-long map.

use super::{Environment, Loaded};
use crate::env::Placement;
use crate::env::cube::{CubeLayout, faces_from_strip, faces_in_layout, layouts_sentence};
use crate::error::{Error, Result};
use crate::texture::{ImageKind, Texture};

/// A loaded file read as a texture of one kind: its images (faces or
/// layers, each its levels, level 0 first; one for a 2-D or lat-long
/// image) in [`Loaded::images`]'s order.
#[derive(Clone, Debug)]
pub struct Source {
    /// What the images make.
    pub kind: ImageKind,
    /// Each face or layer's levels: the file's own levels where it
    /// stores them whole (a KTX2 or DDS cube map or array, a mip-mapped
    /// lat-long file); level 0 only for faces cut from a strip or a cross.
    pub images: Vec<Vec<Texture>>,
    /// Where the texels sit on the sphere: the file's convention for an
    /// environment it records ([`super::SourceInfo::placement`]), centred
    /// for everything else.
    pub placement: Placement,
}

impl Source {
    /// Level 0 of every image.
    pub fn bases(&self) -> impl Iterator<Item = &Texture> {
        self.images.iter().map(|l| &l[0])
    }

    /// Level 0 of the first image.
    pub fn base(&self) -> &Texture {
        &self.images[0][0]
    }
}

/// `loaded` (read from `name`, for messages) as a texture: what its
/// header says (a cube map, an array), else the environment it records,
/// else the environment `hint` says it holds, else one 2-D image.
///
/// A hint of a cube map reads an image whose file records none as six
/// faces in the strip or cross its aspect tells ([`CubeLayout`]), or, at
/// 2:1, as a lat-long map (to be made a cube map); a hint of a lat-long
/// map reads it as one. A hint that contradicts the file (a lat-long
/// reading of a cube map) is the caller's to refuse or convert: the
/// source is what the file holds.
pub fn interpret(loaded: Loaded, name: &str, hint: Option<Environment>) -> Result<Source> {
    let kind = loaded.info.kind;
    if kind != ImageKind::Plain {
        return Ok(Source {
            kind,
            images: loaded.into_images(),
            placement: Placement::Centred,
        });
    }
    let recorded = loaded.info.environment;
    let placement = loaded.info.placement;
    match (recorded, hint) {
        (Some(Environment::Cube), _) => {
            let (w, h) = (loaded.base().width(), loaded.base().height());
            let strip = faces_from_strip(loaded.base()).map_err(|_| {
                Error::InvalidOption(format!(
                    "`{name}` is a cube-face environment map of {w}x{h}, which parvo reads \
                     only as OpenEXR's vertical strip of six square faces (w x 6w, +x -x +y -y \
                     +z -z from the top)"
                ))
            })?;
            // OpenEXR's own cube (its `envmap` attribute) holds OpenEXR's
            // faces; maketx's `textureformat` alone, GL's.
            if placement == Placement::Edges {
                let faces = super::exr::mirror_cube_faces(&strip)?;
                return Ok(Source {
                    placement,
                    ..cube(faces)
                });
            }
            Ok(cube(strip))
        }
        (Some(Environment::LatLong), _) => Ok(Source {
            kind: ImageKind::LatLong,
            images: vec![loaded.levels],
            placement,
        }),
        (None, Some(Environment::LatLong)) => Ok(Source {
            kind: ImageKind::LatLong,
            images: vec![loaded.levels],
            placement: Placement::Centred,
        }),
        (None, Some(Environment::Cube)) => {
            let base = loaded.base();
            let (w, h) = (base.width(), base.height());
            if let Some((layout, _)) = CubeLayout::detect(w, h) {
                let faces = faces_in_layout(base, layout).map_err(|e| {
                    Error::InvalidOption(format!(
                        "cannot read `{name}` as a cube map ({layout}): {e}"
                    ))
                })?;
                return Ok(cube(faces));
            }
            if w == 2 * h {
                return Ok(Source {
                    kind: ImageKind::LatLong,
                    images: vec![loaded.levels],
                    placement: Placement::Centred,
                });
            }
            Err(Error::InvalidOption(format!(
                "`{name}` is {w}x{h}: a cube map comes from six faces in one image ({}), a \
                 lat-long map (2:1), a KTX2 or DDS cube map, or six face files",
                layouts_sentence()
            )))
        }
        (None, None) => Ok(Source {
            kind: ImageKind::Plain,
            images: vec![loaded.levels],
            placement: Placement::Centred,
        }),
    }
}

/// Six face files (+X, −X, +Y, −Y, +Z, −Z; `names` for messages) as a
/// cube map: level 0 of each, square and of one size and format.
pub fn from_faces(faces: Vec<Loaded>, names: &[String]) -> Result<Source> {
    if faces.len() != 6 {
        return Err(Error::InvalidOption(format!(
            "a cube map is built from six face files (+x -x +y -y +z -z), got {}",
            faces.len()
        )));
    }
    let bases: Vec<Texture> = faces.into_iter().map(Loaded::into_base).collect();
    let first = (bases[0].width(), bases[0].height(), bases[0].format());
    for (b, name) in bases.iter().zip(names) {
        if (b.width(), b.height(), b.format()) != first || b.width() != b.height() {
            return Err(Error::InvalidOption(format!(
                "face `{name}` is {}x{} {}: the six faces of a cube map are square, of one size \
                 and format (the first is {}x{} {})",
                b.width(),
                b.height(),
                b.format(),
                first.0,
                first.1,
                first.2
            )));
        }
    }
    Ok(cube(bases))
}

fn cube(faces: Vec<Texture>) -> Source {
    Source {
        kind: ImageKind::Cube,
        images: faces.into_iter().map(|f| vec![f]).collect(),
        placement: Placement::Centred,
    }
}
