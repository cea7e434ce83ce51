//! The checks of a job list and its settings that need no input read, and
//! [`Usage`], the typed problems they (and a few checks after the read)
//! find. The library names what is wrong (the setting, the value, the
//! container); a front end says it in its own option names.

use std::fmt;
use std::path::PathBuf;

use super::{Job, RoughnessSettings, RoughnessSource, Settings};
use crate::compress::BlockFormat;
use crate::env::prefilter::Lobe;
use crate::error::{Error, Result};
use crate::io::ktx2::Supercompression;
use crate::io::{Environment, OutputKind};
use crate::mip::Rounding;
use crate::mip::roughness::Specular;
use crate::setting::Setting;
use crate::texel::ChannelType;
use crate::texture::ImageKind;

/// A setting that does not fit the job or another setting
/// ([`Error::Usage`]). Each says which setting, which value and which
/// container; its `Display` says it in words that name no option.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Usage {
    /// [`Settings::levels`] is 0.
    LevelsZero,
    /// [`Settings::alpha_coverage`] is not strictly between 0 and 1.
    AlphaCoverageRange(f32),
    /// [`Settings::out_type`] is a type the container cannot store.
    TypeNotStored {
        /// The type asked for.
        ty: ChannelType,
        /// The container's name.
        container: &'static str,
    },
    /// A roughness chain without [`Settings::normal_map`].
    RoughnessNeedsNormalMap,
    /// A roughness output file with more than one job.
    RoughnessOutputOfBatch,
    /// The roughness both packed into alpha and written to its own file.
    RoughnessPackedAndWritten,
    /// The roughness neither packed into alpha nor written to a file.
    RoughnessNowhere,
    /// A constant base roughness outside 0..=1.
    RoughnessRange(f32),
    /// Alpha coverage with a normal map.
    CoverageOfNormalMap,
    /// Blinn-Phong exponents to an output that is not float.
    ExponentsNeedFloat,
    /// Block compression in a build without the block encoders.
    EncodersMissing(BlockFormat),
    /// Block compression to a container that stores no blocks.
    BlocksNotStored {
        /// The container's name.
        container: &'static str,
        /// The output.
        output: PathBuf,
    },
    /// An output type with block compression.
    TypeWithBlocks(ChannelType),
    /// Block compression with a roughness chain.
    BlocksWithRoughness,
    /// A supercompression level out of its scheme's range.
    SupercompressionLevel {
        /// The scheme and the level asked for.
        scheme: Supercompression,
        /// The lowest level.
        lo: i32,
        /// The highest level.
        hi: i32,
    },
    /// Supercompression to a container other than KTX2.
    SupercompressionNotStored {
        /// The scheme asked for.
        scheme: Supercompression,
        /// The output.
        output: PathBuf,
        /// The output's container.
        container: &'static str,
    },
    /// A resize of a normal map.
    ResizeNormalMap,
    /// Rounded-up level sizes to a container that defines them rounded
    /// down.
    RoundingUpNotStored {
        /// `KTX2` or `DDS`.
        container: &'static str,
        /// The output.
        output: PathBuf,
    },
    /// Roughness packed into the alpha of a normal map that has a fourth
    /// channel already.
    PackOverwritesAlpha,
    /// Fewer levels than the full chain to a mip-mapped OpenEXR file.
    ExrLevels {
        /// The full chain's level count.
        full: u32,
    },
    /// A setting that does not apply to an image of this kind.
    NotForKind {
        /// The setting.
        setting: Setting,
        /// The image kind being built.
        kind: ImageKind,
        /// Why, in a few words.
        why: &'static str,
    },
    /// An image kind the output container cannot store.
    KindNotStored {
        /// The image kind being built.
        kind: ImageKind,
        /// The container's name.
        container: &'static str,
        /// The containers that store it (`.exr`, `.ktx2`, ...).
        holders: Vec<String>,
    },
    /// An image that cannot become the environment asked for.
    NotAnEnvironment {
        /// What the input holds.
        kind: ImageKind,
        /// The environment asked for.
        target: Environment,
    },
    /// Prefiltered levels of anything but a cube map.
    PrefilterNeedsCube,
    /// An irradiance output of an input that is no environment.
    IrradianceNeedsEnvironment,
    /// An output of one file beside the job's (`--irradiance`,
    /// `--brdf-lut`) with more than one job.
    OneFileOfBatch(Setting),
    /// A BRDF table beside levels that are not prefiltered with GGX.
    BrdfLutNeedsGgx,
}

impl fmt::Display for Usage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Usage::LevelsZero => write!(f, "the level count must be at least 1"),
            Usage::AlphaCoverageRange(r) => {
                write!(f, "alpha coverage reference {r}: must be between 0 and 1")
            }
            Usage::TypeNotStored { ty, container } => write!(
                f,
                "{container} cannot store {ty} texels ({})",
                crate::io::container::types_stored()
            ),
            Usage::RoughnessNeedsNormalMap => {
                write!(f, "a roughness chain is made from a normal map")
            }
            Usage::RoughnessOutputOfBatch => {
                write!(
                    f,
                    "a roughness output names one file: use it with one input"
                )
            }
            Usage::RoughnessPackedAndWritten => write!(
                f,
                "roughness packed into alpha is stored in the normal output: give no roughness file"
            ),
            Usage::RoughnessNowhere => write!(
                f,
                "the roughness needs a file of its own or a normal output to pack it into"
            ),
            Usage::RoughnessRange(a) => write!(f, "roughness {a}: must be from 0 to 1"),
            Usage::CoverageOfNormalMap => {
                write!(f, "alpha coverage does not apply to normal maps")
            }
            Usage::ExponentsNeedFloat => write!(
                f,
                "Blinn-Phong exponents are above 1: the chain needs a float output"
            ),
            Usage::EncodersMissing(bf) => write!(
                f,
                "{bf}: this parvo was built without the `encode` feature (the block encoders)"
            ),
            Usage::BlocksNotStored { container, output } => write!(
                f,
                "{container} cannot store block-compressed texels; use KTX2 or DDS (output {})",
                output.display()
            ),
            Usage::TypeWithBlocks(t) => {
                write!(
                    f,
                    "type {t} with block compression: the block format fixes what is stored"
                )
            }
            Usage::BlocksWithRoughness => write!(
                f,
                "block compression with a roughness chain is not supported yet: compress the \
                 normal and roughness chains in two runs"
            ),
            Usage::SupercompressionLevel { scheme, lo, hi } => write!(
                f,
                "{} level {}: the level must be from {lo} to {hi}",
                scheme.name(),
                level_of(*scheme)
            ),
            Usage::SupercompressionNotStored {
                scheme,
                output,
                container,
            } => write!(
                f,
                "{}: supercompression is a KTX2 feature; output {} is {container}",
                scheme.name(),
                output.display()
            ),
            Usage::ResizeNormalMap => write!(
                f,
                "resizing a normal map is not supported: resize the normal map first"
            ),
            Usage::RoundingUpNotStored { container, output } => write!(
                f,
                "rounded-up level sizes: {container} defines its level sizes as \
                 floor(size / 2^k); use OpenEXR or PNG levels for rounded-up chains (output {})",
                output.display()
            ),
            Usage::PackOverwritesAlpha => write!(
                f,
                "the normal map has a fourth channel; packing the roughness into alpha would \
                 overwrite it"
            ),
            Usage::ExrLevels { full } => write!(
                f,
                "a mip-mapped OpenEXR file holds the full chain ({full} levels); a level count \
                 applies to KTX2, DDS and PNG"
            ),
            _ => self.fmt_kinds(f),
        }
    }
}

impl Usage {
    /// The words of the problems with an image's kind.
    fn fmt_kinds(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Usage::NotForKind { setting, kind, why } => write!(
                f,
                "{setting} does not apply to a {}: {why}",
                match kind {
                    ImageKind::Plain => "2-D texture".to_string(),
                    k => k.describe(),
                }
            ),
            Usage::KindNotStored {
                kind,
                container,
                holders,
            } => write!(
                f,
                "{container} cannot store a {}{}",
                kind.describe(),
                if holders.is_empty() {
                    String::new()
                } else {
                    format!(" (use {})", holders.join(" or "))
                }
            ),
            Usage::NotAnEnvironment { kind, target } => write!(
                f,
                "a {} cannot become a {target} environment map{}",
                kind.describe(),
                match target {
                    Environment::LatLong => " (one cube map can)",
                    Environment::Cube => " (a lat-long map or six faces can)",
                }
            ),
            Usage::PrefilterNeedsCube => write!(
                f,
                "{} builds a cube map: set {} to a cube map",
                Setting::Prefilter,
                Setting::Environment
            ),
            Usage::IrradianceNeedsEnvironment => write!(
                f,
                "{} needs an environment map (a cube map or a lat-long map; see {})",
                Setting::Irradiance,
                Setting::Environment
            ),
            Usage::OneFileOfBatch(setting) => {
                write!(f, "{setting} names one file: use it with one input")
            }
            Usage::BrdfLutNeedsGgx => write!(
                f,
                "{} is the table of GGX's split sum, which pairs with levels prefiltered with \
                 GGX: set {} to GGX",
                Setting::BrdfLut,
                Setting::Prefilter
            ),
            _ => Ok(()),
        }
    }
}

impl std::error::Error for Usage {}

impl From<Usage> for Error {
    fn from(u: Usage) -> Error {
        Error::Usage(Box::new(u))
    }
}

impl Usage {
    /// The usage problem `e` is, if it is one ([`Error::Usage`]).
    pub fn of(e: &Error) -> Option<&Usage> {
        match e {
            Error::Usage(u) => u.downcast_ref::<Usage>(),
            _ => None,
        }
    }
}

/// The level of a supercompression scheme.
fn level_of(sc: Supercompression) -> i32 {
    let (Supercompression::Zstd(l) | Supercompression::Zlib(l)) = sc;
    l
}

/// The checks that need no input read: option ranges, a channel type the
/// container cannot store, round-up sizes where the container fixes them.
/// The command line reports these as usage errors.
pub fn check(jobs: &[Job], s: &Settings) -> Result<()> {
    let bad = |u: Usage| Err(Error::from(u));
    if s.levels == Some(0) {
        return bad(Usage::LevelsZero);
    }
    if let Some(r) = s.alpha_coverage
        && !(r > 0.0 && r < 1.0)
    {
        return bad(Usage::AlphaCoverageRange(r));
    }
    if let Some(t) = s.out_type
        && let Some(j) = jobs.iter().find(|j| !j.kind.supports(t))
    {
        return bad(Usage::TypeNotStored {
            ty: t,
            container: j.kind.name(),
        });
    }
    if let Some(r) = &s.roughness {
        check_roughness(jobs, s, r)?;
    }
    if let Some((bf, _)) = s.compress {
        if !cfg!(feature = "encode") {
            return bad(Usage::EncodersMissing(bf));
        }
        if !crate::compress::can_encode(bf) {
            return Err(Error::InvalidOption(format!("parvo does not encode {bf}")));
        }
        if let Some(j) = jobs.iter().find(|j| !j.kind.stores().blocks) {
            return bad(Usage::BlocksNotStored {
                container: j.kind.name(),
                output: j.output.clone(),
            });
        }
        if let Some(t) = s.out_type {
            return bad(Usage::TypeWithBlocks(t));
        }
        if s.roughness.is_some() {
            return bad(Usage::BlocksWithRoughness);
        }
    }
    if let Some(sc) = s.ktx2.supercompression {
        let (lo, hi) = match sc {
            Supercompression::Zstd(_) => (1, 22),
            Supercompression::Zlib(_) => (1, 12),
        };
        if !(lo..=hi).contains(&level_of(sc)) {
            return bad(Usage::SupercompressionLevel { scheme: sc, lo, hi });
        }
        if let Some(j) = jobs.iter().find(|j| !j.kind.stores().supercompression) {
            return bad(Usage::SupercompressionNotStored {
                scheme: sc,
                output: j.output.clone(),
                container: j.kind.name(),
            });
        }
    }
    if s.resize_to.is_some() && s.normal_map {
        return bad(Usage::ResizeNormalMap);
    }
    check_env(jobs, s)?;
    let rough_out = s
        .roughness
        .as_ref()
        .and_then(|r| r.output.clone())
        .map(|(output, kind)| Job {
            input: String::new(),
            output,
            kind,
            faces: Vec::new(),
        });
    if s.rounding == Rounding::Up
        && let Some(j) = jobs
            .iter()
            .chain(&rough_out)
            .find(|j| !j.kind.stores().round_up)
    {
        return bad(Usage::RoundingUpNotStored {
            container: j.kind.name(),
            output: j.output.clone(),
        });
    }
    Ok(())
}

/// The environment settings' checks that need no input read.
fn check_env(jobs: &[Job], s: &Settings) -> Result<()> {
    let bad = |u: Usage| Err(Error::from(u));
    let e = &s.env;
    if e.prefilter.is_some() && e.target != Some(Environment::Cube) {
        return bad(Usage::PrefilterNeedsCube);
    }
    if e.irradiance.is_some() && jobs.len() > 1 {
        return bad(Usage::OneFileOfBatch(Setting::Irradiance));
    }
    if e.brdf_lut.is_some() && jobs.len() > 1 {
        return bad(Usage::OneFileOfBatch(Setting::BrdfLut));
    }
    if e.brdf_lut.is_some() && !matches!(e.prefilter, Some((Lobe::Ggx, _))) {
        return bad(Usage::BrdfLutNeedsGgx);
    }
    if let Some(target) = e.target {
        let kind = match target {
            Environment::Cube => ImageKind::Cube,
            Environment::LatLong => ImageKind::LatLong,
        };
        if let Some(j) = jobs.iter().find(|j| !j.kind.holds(kind)) {
            return Err(kind_not_stored(kind, j.kind));
        }
    }
    if let Some((_, k)) = &e.irradiance
        && !k.holds(ImageKind::Cube)
    {
        return Err(kind_not_stored(ImageKind::Cube, *k));
    }
    Ok(())
}

/// [`Usage::KindNotStored`] for `kind` in `container`.
pub(crate) fn kind_not_stored(kind: ImageKind, container: OutputKind) -> Error {
    Error::from(Usage::KindNotStored {
        kind,
        container: container.name(),
        holders: crate::io::container::outputs()
            .filter(|k| k.holds(kind))
            .map(|k| format!(".{}", k.id()))
            .collect(),
    })
}

/// The checks of a roughness chain's settings `r`.
fn check_roughness(jobs: &[Job], s: &Settings, r: &RoughnessSettings) -> Result<()> {
    let bad = |u: Usage| Err(Error::from(u));
    if !s.normal_map {
        return bad(Usage::RoughnessNeedsNormalMap);
    }
    if jobs.len() > 1 && r.output.is_some() {
        return bad(Usage::RoughnessOutputOfBatch);
    }
    if r.pack_alpha && r.output.is_some() {
        return bad(Usage::RoughnessPackedAndWritten);
    }
    if !r.pack_alpha && r.output.is_none() {
        return bad(Usage::RoughnessNowhere);
    }
    if let RoughnessSource::Constant(a) = r.base
        && !(0.0..=1.0).contains(&a)
    {
        return bad(Usage::RoughnessRange(a));
    }
    if s.alpha_coverage.is_some() {
        return bad(Usage::CoverageOfNormalMap);
    }
    // Exponents are not unorm values.
    if let Specular::BlinnPhong(_) = r.specular {
        let float = |kind: OutputKind| match s.out_type {
            Some(t) => t.is_float() && kind.supports(t),
            // A container whose own default is float, even for an
            // 8-bit source.
            None => kind.default_type(crate::texel::ChannelType::U8).is_float(),
        };
        let kinds: Vec<OutputKind> = match &r.output {
            Some((_, k)) => vec![*k],
            None => jobs.iter().map(|j| j.kind).collect(),
        };
        if kinds.iter().any(|&k| !float(k)) {
            return bad(Usage::ExponentsNeedFloat);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::compress::Quality;

    /// The library's words for every usage problem name no command-line
    /// option (the CLI adds its own), and the checks return them typed.
    #[test]
    fn usage_problems_name_no_option() {
        let out = PathBuf::from("a.ktx2");
        let all = [
            Usage::LevelsZero,
            Usage::AlphaCoverageRange(1.5),
            Usage::TypeNotStored {
                ty: ChannelType::F32,
                container: "PNG",
            },
            Usage::RoughnessNeedsNormalMap,
            Usage::RoughnessOutputOfBatch,
            Usage::RoughnessPackedAndWritten,
            Usage::RoughnessNowhere,
            Usage::RoughnessRange(2.0),
            Usage::CoverageOfNormalMap,
            Usage::ExponentsNeedFloat,
            Usage::EncodersMissing(BlockFormat::Bc7),
            Usage::BlocksNotStored {
                container: "OpenEXR",
                output: out.clone(),
            },
            Usage::TypeWithBlocks(ChannelType::F16),
            Usage::BlocksWithRoughness,
            Usage::SupercompressionLevel {
                scheme: Supercompression::Zstd(30),
                lo: 1,
                hi: 22,
            },
            Usage::SupercompressionNotStored {
                scheme: Supercompression::Zlib(3),
                output: out.clone(),
                container: "DDS",
            },
            Usage::ResizeNormalMap,
            Usage::RoundingUpNotStored {
                container: "KTX2",
                output: out.clone(),
            },
            Usage::PackOverwritesAlpha,
            Usage::ExrLevels { full: 7 },
            Usage::NotForKind {
                setting: Setting::Wrap,
                kind: ImageKind::Cube,
                why: "faces meet at their edges",
            },
            Usage::KindNotStored {
                kind: ImageKind::LatLong,
                container: "KTX2",
                holders: vec![".exr".into()],
            },
            Usage::NotAnEnvironment {
                kind: ImageKind::Array { layers: 3 },
                target: Environment::LatLong,
            },
            Usage::PrefilterNeedsCube,
            Usage::IrradianceNeedsEnvironment,
            Usage::OneFileOfBatch(Setting::Irradiance),
            Usage::OneFileOfBatch(Setting::BrdfLut),
            Usage::BrdfLutNeedsGgx,
        ];
        // A long option's prefix, spelt so that a search of the library
        // for flag names in string literals finds none here.
        let flag = "-".repeat(2);
        for u in &all {
            let text = Error::from(u.clone()).to_string();
            assert!(!text.contains(&flag), "{text}");
            assert!(text.starts_with("invalid option: "), "{text}");
        }
        let job = |name: &str| Job::new("builtin:checker:16", Path::new(name)).unwrap();
        let up = Settings {
            rounding: Rounding::Up,
            ..Settings::default()
        };
        assert!(matches!(
            check(&[job("a.ktx2")], &up)
                .err()
                .as_ref()
                .and_then(Usage::of),
            Some(Usage::RoundingUpNotStored {
                container: "KTX2",
                ..
            })
        ));
        let zstd = Settings {
            ktx2: crate::io::ktx2::Ktx2Options {
                supercompression: Some(Supercompression::Zstd(23)),
            },
            ..Settings::default()
        };
        assert!(matches!(
            check(&[job("a.ktx2")], &zstd)
                .err()
                .as_ref()
                .and_then(Usage::of),
            Some(Usage::SupercompressionLevel { lo: 1, hi: 22, .. })
        ));
        let bc7 = Settings {
            compress: Some((BlockFormat::Bc7, Quality::default())),
            ..Settings::default()
        };
        if cfg!(feature = "encode") {
            assert!(matches!(
                check(&[job("a.exr")], &bc7)
                    .err()
                    .as_ref()
                    .and_then(Usage::of),
                Some(Usage::BlocksNotStored {
                    container: "OpenEXR",
                    ..
                })
            ));
        }
    }
}
