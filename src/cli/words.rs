//! The command line's words for the library's messages: each setting a
//! message names spelt as its flag, and the pipeline's usage problems in
//! `parvo mip`'s option names.

use parvo::io::ktx2::Supercompression;
use parvo::pipeline::Usage;

/// The flag of each setting a library message names.
pub(crate) fn flag(s: parvo::setting::Setting) -> &'static str {
    use parvo::setting::Setting;
    match s {
        Setting::MaxWidth => "--max-width",
        Setting::MaxHeight => "--max-height",
        Setting::MaxAlloc => "--max-alloc",
        Setting::Channels => "--channels",
        Setting::Subimage => "--subimage",
        Setting::Color => "--color",
        Setting::NoAutoOrient => "--no-auto-orient",
        Setting::Wrap => "--wrap",
        Setting::Levels => "--levels",
        Setting::Alpha => "--alpha",
        Setting::Filter => "--filter",
        Setting::Rounding => "--rounding",
        Setting::AlphaCoverage => "--alpha-coverage",
        Setting::NormalMap => "--normal-map",
        Setting::Roughness => "--roughness",
        Setting::Environment => "--env",
        Setting::Prefilter => "--prefilter",
        Setting::Irradiance => "--irradiance",
        Setting::BrdfLut => "--brdf-lut",
        Setting::FaceSize => "--face-size",
        Setting::NoEdgeFixup => "--no-edge-fixup",
    }
}

/// Library text (an error, a note) in the command line's words: each
/// setting it names as its flag.
pub(crate) fn words(text: impl std::fmt::Display) -> String {
    parvo::setting::respell(&text.to_string(), flag)
}

/// The CLI's words for a library error: the error and, where a flag
/// deals with it, that flag.
pub(crate) fn error_text(e: &parvo::Error) -> String {
    if let Some(u) = parvo::pipeline::Usage::of(e) {
        return format!("invalid option: {}", usage_text(u));
    }
    let hint = match e {
        parvo::Error::NonFinite { .. } => {
            Some("--fixnan black or --fixnan neighbors replaces such values")
        }
        _ => None,
    };
    match hint {
        Some(h) => format!("{} ({h})", words(e)),
        None => words(e),
    }
}

/// [`error_text`] as an error of the CLI.
pub(crate) fn with_hint(e: parvo::Error) -> anyhow::Error {
    anyhow::anyhow!(error_text(&e))
}

/// A pipeline usage problem in this command's option names.
pub(crate) fn usage_text(u: &Usage) -> String {
    match u {
        Usage::LevelsZero => "--levels must be at least 1".into(),
        Usage::AlphaCoverageRange(r) => format!("--alpha-coverage {r}: must be between 0 and 1"),
        Usage::TypeNotStored { ty: t, container } => format!(
            "--type {t}: {container} cannot store {t} texels ({})",
            parvo::io::container::types_stored()
        ),
        Usage::RoughnessNeedsNormalMap => {
            "a roughness chain is made from a normal map: add --normal-map".into()
        }
        Usage::RoughnessOutputOfBatch => {
            "--roughness-out names one file: use it with -o (one input)".into()
        }
        Usage::RoughnessPackedAndWritten => {
            "--pack-roughness stores the roughness in the normal output: drop --roughness-out"
                .into()
        }
        Usage::RoughnessNowhere => {
            "give --roughness-out FILE or --pack-roughness A for the roughness".into()
        }
        Usage::RoughnessRange(a) => format!("--roughness {a}: must be from 0 to 1"),
        Usage::CoverageOfNormalMap => "--alpha-coverage does not apply to normal maps".into(),
        Usage::ExponentsNeedFloat => "--specular blinn-phong writes exponents above 1: the chain \
                                      needs a float output (.exr, or --type f16/f32 with \
                                      .ktx2/.dds)"
            .into(),
        Usage::EncodersMissing(bf) => format!(
            "--compress {}: this parvo was built without the `encode` feature (the block encoders)",
            bf.name().to_ascii_lowercase()
        ),
        Usage::BlocksNotStored { container, output } => format!(
            "--compress: {container} cannot store block-compressed texels; use .ktx2 or .dds \
             (output {})",
            output.display()
        ),
        Usage::TypeWithBlocks(t) => {
            format!("--type {t} with --compress: the block format fixes what is stored")
        }
        Usage::BlocksWithRoughness => "--compress with --roughness is not supported yet: \
                                       compress the normal and roughness chains in two runs"
            .into(),
        Usage::SupercompressionLevel { scheme, lo, hi } => format!(
            "--{} {}: the level must be from {lo} to {hi}",
            scheme.name(),
            match scheme {
                Supercompression::Zstd(l) | Supercompression::Zlib(l) => l,
            }
        ),
        Usage::SupercompressionNotStored {
            scheme,
            output,
            container,
        } => format!(
            "--{}: supercompression is a KTX2 feature; output {} is {container}",
            scheme.name(),
            output.display()
        ),
        Usage::ResizeNormalMap => {
            "--resize-to with --normal-map is not supported: resize the normal map first".into()
        }
        Usage::RoundingUpNotStored { container, output } => format!(
            "--rounding up: {container} defines its level sizes as floor(size / 2^k); use .exr \
             or PNG levels for rounded-up chains (output {})",
            output.display()
        ),
        Usage::PackOverwritesAlpha => "the normal map has a fourth channel; --pack-roughness \
                                       would overwrite it (write the roughness with \
                                       --roughness-out instead)"
            .into(),
        Usage::ExrLevels { full } => format!(
            "a mip-mapped OpenEXR file holds the full chain ({full} levels); --levels applies to \
             .ktx2, .dds and PNG"
        ),
        _ => u.to_string(),
    }
}
