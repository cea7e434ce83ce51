//! The settings that library messages name.
//!
//! An error or a note often says which setting would change the outcome
//! ("raise the allocation limit", "pick channels by name"). The library
//! does not know how a front end spells its settings — the command line
//! has flags, a program has struct fields — so a message names a
//! [`Setting`], which displays as the library's field
//! (`Limits::max_alloc`), and a front end respells every setting in the
//! text with [`respell`] before showing it (the `parvo` binary writes its
//! flags: `--max-alloc`).

use std::fmt;

/// A setting a library message names (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Setting {
    /// `io::Limits::max_width`.
    MaxWidth,
    /// `io::Limits::max_height`.
    MaxHeight,
    /// `io::Limits::max_alloc`.
    MaxAlloc,
    /// `io::LoadOptions::channels`.
    Channels,
    /// `io::LoadOptions::subimage`.
    Subimage,
    /// `io::LoadOptions::color`.
    Color,
    /// `io::LoadOptions::auto_orient` set to false.
    NoAutoOrient,
    /// [`crate::mip::MipOptions::wrap`].
    Wrap,
    /// [`crate::mip::MipOptions::max_levels`].
    Levels,
    /// The alpha convention of an input (`pipeline::Settings::alpha`).
    Alpha,
    /// The mip filter (`pipeline::Settings::filter`).
    Filter,
    /// Level size rounding (`pipeline::Settings::rounding`).
    Rounding,
    /// Alpha coverage (`pipeline::Settings::alpha_coverage`).
    AlphaCoverage,
    /// The input is a normal map (`pipeline::Settings::normal_map`).
    NormalMap,
    /// A roughness chain (`pipeline::Settings::roughness`).
    Roughness,
    /// The environment to build (`pipeline::EnvSettings::target`).
    Environment,
    /// Prefiltered specular levels (`pipeline::EnvSettings::prefilter`).
    Prefilter,
    /// The irradiance output (`pipeline::EnvSettings::irradiance`).
    Irradiance,
    /// The split-sum BRDF table output (`pipeline::EnvSettings::brdf_lut`).
    BrdfLut,
    /// Cube faces' size (`pipeline::EnvSettings::face_size`).
    FaceSize,
    /// Cube faces' edges left as filtered
    /// (`pipeline::EnvSettings::edge_fixup` set to false).
    NoEdgeFixup,
}

impl Setting {
    /// Every setting.
    pub const ALL: [Setting; 21] = [
        Setting::MaxWidth,
        Setting::MaxHeight,
        Setting::MaxAlloc,
        Setting::Channels,
        Setting::Subimage,
        Setting::Color,
        Setting::NoAutoOrient,
        Setting::Wrap,
        Setting::Levels,
        Setting::Alpha,
        Setting::Filter,
        Setting::Rounding,
        Setting::AlphaCoverage,
        Setting::NormalMap,
        Setting::Roughness,
        Setting::Environment,
        Setting::Prefilter,
        Setting::Irradiance,
        Setting::BrdfLut,
        Setting::FaceSize,
        Setting::NoEdgeFixup,
    ];

    /// The library's name of the setting, as messages show it.
    pub fn library_name(self) -> &'static str {
        match self {
            Setting::MaxWidth => "Limits::max_width",
            Setting::MaxHeight => "Limits::max_height",
            Setting::MaxAlloc => "Limits::max_alloc",
            Setting::Channels => "LoadOptions::channels",
            Setting::Subimage => "LoadOptions::subimage",
            Setting::Color => "LoadOptions::color",
            Setting::NoAutoOrient => "LoadOptions::auto_orient=false",
            Setting::Wrap => "MipOptions::wrap",
            Setting::Levels => "MipOptions::max_levels",
            Setting::Alpha => "Settings::alpha",
            Setting::Filter => "Settings::filter",
            Setting::Rounding => "Settings::rounding",
            Setting::AlphaCoverage => "Settings::alpha_coverage",
            Setting::NormalMap => "Settings::normal_map",
            Setting::Roughness => "Settings::roughness",
            Setting::Environment => "EnvSettings::target",
            Setting::Prefilter => "EnvSettings::prefilter",
            Setting::Irradiance => "EnvSettings::irradiance",
            Setting::BrdfLut => "EnvSettings::brdf_lut",
            Setting::FaceSize => "EnvSettings::face_size",
            Setting::NoEdgeFixup => "EnvSettings::edge_fixup=false",
        }
    }
}

impl fmt::Display for Setting {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.library_name())
    }
}

/// `text` with every setting's library name replaced by `spell(setting)`.
pub fn respell(text: &str, spell: impl Fn(Setting) -> &'static str) -> String {
    let mut out = text.to_string();
    // Longer names first, so that no name is replaced inside another.
    let mut all = Setting::ALL;
    all.sort_by_key(|s| std::cmp::Reverse(s.library_name().len()));
    for s in all {
        if out.contains(s.library_name()) {
            out = out.replace(s.library_name(), spell(s));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_distinct_and_respelled_whole() {
        let mut names: Vec<_> = Setting::ALL.iter().map(|s| s.library_name()).collect();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), Setting::ALL.len());
        let text = format!(
            "raise {}/{} or {} N; {} picks",
            Setting::MaxWidth,
            Setting::MaxHeight,
            Setting::Subimage,
            Setting::NoAutoOrient
        );
        let out = respell(&text, |s| match s {
            Setting::MaxWidth => "<max-width>",
            Setting::MaxHeight => "<max-height>",
            Setting::Subimage => "<subimage>",
            Setting::NoAutoOrient => "<no-auto-orient>",
            _ => "?",
        });
        assert_eq!(
            out,
            "raise <max-width>/<max-height> or <subimage> N; <no-auto-orient> picks"
        );
    }
}
