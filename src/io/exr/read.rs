//! Reading OpenEXR: scanline, tiled and mip-mapped parts, channels chosen
//! as OpenImageIO chooses them, data windows placed, environments told.

use super::*;

/// The kind of environment an OpenEXR file's first header declares
/// (`envmap`, or maketx's `textureformat`), from its headers alone:
/// [`crate::texture::ImageKind::Cube`] for a cube-face strip, `LatLong`, else
/// `Plain` (also for a file whose headers do not read).
pub(crate) fn peek_kind(path: &Path) -> crate::texture::ImageKind {
    use crate::texture::ImageKind;
    use ::exr::meta::attribute::EnvironmentMap;
    let read = || {
        let meta = MetaData::read_from_file(path, false).ok()?;
        let h = meta.headers.first()?;
        let format = match h.own_attributes.other.get(&Text::from("textureformat")) {
            Some(AttributeValue::Text(t)) => t.to_string(),
            _ => String::new(),
        };
        Some(match (h.own_attributes.environment_map, format.as_str()) {
            (Some(EnvironmentMap::Cube), _) | (None, "CubeFace Environment") => ImageKind::Cube,
            (Some(EnvironmentMap::LatitudeLongitude), _) | (None, "LatLong Environment") => {
                ImageKind::LatLong
            }
            _ => ImageKind::Plain,
        })
    };
    std::panic::catch_unwind(read)
        .ok()
        .flatten()
        .unwrap_or(ImageKind::Plain)
}

pub(super) fn attribute_text(v: &AttributeValue) -> String {
    match v {
        AttributeValue::Text(t) => t.to_string(),
        AttributeValue::F32(x) => x.to_string(),
        AttributeValue::F64(x) => x.to_string(),
        AttributeValue::I32(x) => x.to_string(),
        AttributeValue::TextVector(v) => v
            .iter()
            .map(|t| t.to_string())
            .collect::<Vec<_>>()
            .join(", "),
        other => format!("{other:?}"),
    }
}

/// OpenImageIO's order of channel suffixes within a layer (its
/// `ChanNameHolder::compute_special_index`); a layer holding `X` and `Y` or
/// `Z` uses the second list, so positions and normals keep X, Y, Z order.
pub(super) const SPECIAL: [&str; 20] = [
    "R", "Red", "G", "Green", "B", "Blue", "Y", "real", "imag", "A", "Alpha", "AR", "RA", "AG",
    "GA", "AB", "BA", "Z", "Depth", "Zback",
];
pub(super) const SPECIAL_XYZ: [&str; 21] = [
    "R", "Red", "G", "Green", "B", "Blue", "X", "Y", "Z", "real", "imag", "A", "Alpha", "AR", "RA",
    "AG", "GA", "AB", "BA", "Depth", "Zback",
];

/// `diffuse.R` → (`diffuse`, `R`); `R` → (``, `R`).
pub(super) fn split_name(n: &str) -> (&str, &str) {
    match n.rfind('.') {
        Some(i) => (&n[..i], &n[i + 1..]),
        None => ("", n),
    }
}

pub(super) fn is_alpha_name(n: &str) -> bool {
    let s = split_name(n).1;
    s.eq_ignore_ascii_case("A") || s.eq_ignore_ascii_case("Alpha")
}

/// Channel indices in the order OpenImageIO presents them: by layer, then
/// by the special-name order, then by name.
pub(super) fn oiio_order(names: &[String]) -> Vec<usize> {
    let has = |layer: &str, suffix: &str| {
        names.iter().any(|n| {
            let (l, s) = split_name(n);
            l == layer && s.eq_ignore_ascii_case(suffix)
        })
    };
    let key = |i: usize| {
        let (layer, suffix) = split_name(&names[i]);
        let xyz = has(layer, "X") && (has(layer, "Y") || has(layer, "Z"));
        let list: &[&str] = if xyz { &SPECIAL_XYZ } else { &SPECIAL };
        let special = list
            .iter()
            .position(|s| s.eq_ignore_ascii_case(suffix))
            .unwrap_or(10_000);
        (layer.to_string(), special, suffix.to_string())
    };
    let mut order: Vec<usize> = (0..names.len()).collect();
    order.sort_by_key(|&i| key(i));
    order
}

/// Which channels to load, and whether the last is alpha: `requested`
/// names (full names, in the order given), or by OpenImageIO's
/// conventions: every channel when there are at most four, else the first
/// layer's `R,G,B[,A]` or `Y[,A]`. A channel is alpha only when it is
/// named `A` (or `Alpha`) and is the last of two or four. Returns the
/// indices, the alpha flag and a note when the mapping is not the obvious
/// one.
pub(super) fn choose_channels(
    names: &[String],
    requested: Option<&[String]>,
) -> Result<(Vec<usize>, bool, Option<String>)> {
    let list = names.join(",");
    let order: Vec<usize> = match requested {
        Some(req) => {
            if req.is_empty() || req.len() > 4 {
                return Err(Error::InvalidOption(format!(
                    "{} takes 1 to 4 names, got {}",
                    Setting::Channels,
                    req.len()
                )));
            }
            let mut v = Vec::new();
            for r in req {
                let i = names.iter().position(|n| n == r).ok_or_else(|| {
                    Error::InvalidOption(format!(
                        "{}: no channel `{r}` (the file has {list})",
                        Setting::Channels
                    ))
                })?;
                if v.contains(&i) {
                    return Err(Error::InvalidOption(format!(
                        "{}: `{r}` given twice",
                        Setting::Channels
                    )));
                }
                v.push(i);
            }
            v
        }
        None => {
            let sorted = oiio_order(names);
            if sorted.len() <= 4 {
                sorted
            } else {
                let mut layers: Vec<&str> =
                    sorted.iter().map(|&i| split_name(&names[i]).0).collect();
                layers.dedup();
                let find = |layer: &str, suffix: &str| {
                    sorted.iter().copied().find(|&i| {
                        let (l, s) = split_name(&names[i]);
                        l == layer && s == suffix
                    })
                };
                let pick = layers.iter().find_map(|&l| {
                    let a = find(l, "A");
                    match (find(l, "R"), find(l, "G"), find(l, "B"), find(l, "Y")) {
                        (Some(r), Some(g), Some(b), _) => Some(
                            [Some(r), Some(g), Some(b), a]
                                .into_iter()
                                .flatten()
                                .collect(),
                        ),
                        (_, _, _, Some(y)) => Some([Some(y), a].into_iter().flatten().collect()),
                        _ => None,
                    }
                });
                pick.ok_or_else(|| {
                    decode_err(format!(
                        "{} channels ({list}) and no layer with R,G,B or Y: parvo reads 1 to 4 channels, pick them with {}",
                        names.len(),
                        Setting::Channels
                    ))
                })?
            }
        }
    };
    let n = order.len();
    let alpha = matches!(n, 2 | 4) && is_alpha_name(&names[order[n - 1]]);
    let chosen: Vec<&str> = order.iter().map(|&i| names[i].as_str()).collect();
    let suffixes: Vec<&str> = chosen.iter().map(|n| split_name(n).1).collect();
    let obvious = matches!(
        suffixes.as_slice(),
        ["R", "G", "B"] | ["R", "G", "B", "A"] | ["Y"] | ["Y", "A"]
    );
    let mut note = None;
    if !obvious || chosen.len() < names.len() {
        let layout = match (n, alpha) {
            (1, _) => "one channel".to_string(),
            (2, true) => "grey + alpha".to_string(),
            (3, _) => "R,G,B".to_string(),
            (4, true) => "R,G,B + alpha".to_string(),
            (k, false) => format!("{k} data channels, no alpha"),
            _ => unreachable!("1 to 4 channels"),
        };
        let mut s = format!("channels {} read as {layout}", chosen.join(","));
        if chosen.len() < names.len() {
            s.push_str(&format!(
                " (the file has {list}; {} picks others)",
                Setting::Channels
            ));
        }
        if !alpha && chosen.iter().any(|c| is_alpha_name(c)) {
            s.push_str("; the A channel is not last of 2 or 4, so it is data");
        }
        note = Some(s);
    }
    Ok((order, alpha, note))
}

/// The pixels of one part as the `exr` crate reads them: every resolution
/// level of every channel.
pub(super) type Part =
    ::exr::image::Layer<::exr::image::AnyChannels<::exr::image::Levels<FlatSamples>>>;

/// Load an EXR file: the first part (or `options.subimage`), all its mip
/// levels, the channels chosen as the module docs say; a data window that is
/// not the display window is placed in the display window, black outside
/// (as maketx pads it), what lies outside is cropped, and a note says so.
pub fn load(path: &Path, limits: &Limits, options: &crate::io::LoadOptions) -> Result<Loaded> {
    let meta = MetaData::read_from_file(path, false).map_err(read_err)?;
    let parts = meta.headers.len();
    let part = options.subimage;
    let header = meta.headers.get(part).ok_or_else(|| {
        Error::InvalidOption(format!(
            "{} {part}: the file has {parts} part{}",
            Setting::Subimage,
            if parts == 1 { "" } else { "s" }
        ))
    })?;
    if header.deep {
        return Err(decode_err(DEEP));
    }
    if (header.channels.list.iter()).any(|c| c.sampling != ::exr::math::Vec2(1, 1)) {
        return Err(decode_err(SUBSAMPLED));
    }
    let mut notes = Vec::new();
    if parts > 1 {
        notes.push(format!(
            "multi-part file: using part {part} ({}) of {parts}; {} N picks another",
            header
                .own_attributes
                .layer_name
                .as_ref()
                .map_or_else(|| "unnamed".to_string(), |t| format!("`{t}`")),
            Setting::Subimage
        ));
    }
    let Declared {
        sizes,
        tile,
        rounding,
        mipmapped,
    } = declared_levels(header);
    let all_names: Vec<String> = header
        .channels
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect();
    let (order, alpha, note) = choose_channels(&all_names, options.channels.as_deref())?;
    notes.extend(note);
    check_decoded_size(&meta, part, &sizes, order.len(), limits)?;
    let mut attributes = header_attributes(header);
    let environment = environment_of(header, &attributes, options, &mut notes)?;
    let data_window = header.data_window();
    let display = header.shared_attributes.display_window;
    if data_window != display {
        check_display_window(data_window, display, order.len(), limits, &mut attributes)?;
    }
    attributes.sort();
    let wrap = crate::io::recorded_wrap(
        attributes
            .iter()
            .find(|(k, _)| k == "wrapmodes")
            .map(|(_, v)| v.as_str()),
        &mut notes,
    );

    let layer = read_part(path, part)?;
    let list = &layer.channel_data.list;
    // The crate's channel list is sorted by name, as the header's is.
    let by_name = |n: &str| list.iter().position(|c| c.name.to_string() == n);
    let order: Vec<usize> = order
        .iter()
        .map(|&i| by_name(&all_names[i]).ok_or_else(|| decode_err("channel list changed")))
        .collect::<Result<_>>()?;
    let mut levels = read_levels(list, &order, &sizes, mipmapped, alpha)?;
    if data_window != display {
        let (placed, note) = place_in_display_window(&levels[0], data_window, display)?;
        if levels.len() > 1 {
            notes.push(format!(
                "{note}; the file's own {} mip levels are dropped (they cover the data window) and rebuilt",
                levels.len()
            ));
        } else {
            notes.push(note);
        }
        levels = vec![placed];
    }
    let info = SourceInfo {
        format: FileFormat::Exr,
        own_mips: levels.len() > 1,
        rounding,
        wrap,
        tile,
        channel_names: order.iter().map(|&i| list[i].name.to_string()).collect(),
        attributes,
        notes,
        blocks: None,
        // OpenEXR stores linear values by definition.
        color_stated: true,
        environment,
        // OpenEXR's own environments (the `envmap` attribute) place their
        // texels as ImfEnvmap.cpp defines; maketx's `textureformat` alone
        // keeps maketx's centred texels.
        placement: if header.own_attributes.environment_map.is_some() {
            crate::env::Placement::Edges
        } else {
            crate::env::Placement::Centred
        },
        // A cube-face environment stays one strip image here
        // (`environment` says what it is).
        one_d: false,
        kind: crate::texture::ImageKind::Plain,
    };
    Ok(Loaded::plain(levels, info))
}

/// The levels a header declares.
pub(super) struct Declared {
    /// Level sizes: all of a mip map; level 0 of scan lines and of a rip
    /// map, whose anisotropic levels are not a mip chain.
    sizes: Vec<(usize, usize)>,
    /// The tile size of a tiled file.
    tile: Option<(u32, u32)>,
    rounding: Rounding,
    /// A mip map: every level in `sizes` must be in the file.
    mipmapped: bool,
}

/// The levels `header` declares.
pub(super) fn declared_levels(header: &Header) -> Declared {
    let (w, h) = (header.layer_size.width(), header.layer_size.height());
    let BlockDescription::Tiles(t) = header.blocks else {
        return Declared {
            sizes: vec![(w, h)],
            tile: None,
            rounding: Rounding::Down,
            mipmapped: false,
        };
    };
    let rounding = match t.rounding_mode {
        RoundingMode::Down => Rounding::Down,
        RoundingMode::Up => Rounding::Up,
    };
    let tile = Some((t.tile_size.width() as u32, t.tile_size.height() as u32));
    let mipmapped = t.level_mode == LevelMode::MipMap;
    let sizes = if mipmapped {
        ::exr::meta::mip_map_levels(t.rounding_mode, header.layer_size)
            .map(|(_, s)| (s.width(), s.height()))
            .collect()
    } else {
        // Rip maps: only level 0 (anisotropic levels are not a mip chain).
        vec![(w, h)]
    };
    Declared {
        sizes,
        tile,
        rounding,
        mipmapped,
    }
}

/// Hold what decoding part `part` allocates to `limits`, from the headers
/// alone: the `exr` crate's planes of the declared levels (of every part
/// when another than the first is read) plus our interleaved copy of
/// `kept` channels.
pub(super) fn check_decoded_size(
    meta: &MetaData,
    part: usize,
    sizes: &[(usize, usize)],
    kept: usize,
    limits: &Limits,
) -> Result<()> {
    let header = &meta.headers[part];
    let (w, h) = (header.layer_size.width(), header.layer_size.height());
    let channels = header.channels.list.len() as u64;
    let texels: u64 = sizes.iter().map(|&(a, b)| a as u64 * b as u64).sum();
    let planes: u64 = if part == 0 {
        texels.saturating_mul(channels).saturating_mul(4)
    } else {
        meta.headers
            .iter()
            .map(|h| {
                (h.layer_size.area() as u64)
                    .saturating_mul(h.channels.list.len() as u64)
                    .saturating_mul(8)
            })
            .sum()
    };
    limits.check(
        w as u64,
        h as u64,
        planes.saturating_add(texels.saturating_mul(kept as u64 * 4)),
    )
}

/// The header's attributes as text for `parvo info`: the other (custom)
/// ones, the standard ones that are set, and the compression; unsorted.
pub(super) fn header_attributes(header: &Header) -> Vec<(String, String)> {
    let mut attributes: Vec<(String, String)> = Vec::new();
    for (k, v) in header
        .shared_attributes
        .other
        .iter()
        .chain(header.own_attributes.other.iter())
    {
        attributes.push((k.to_string(), attribute_text(v)));
    }
    let own = &header.own_attributes;
    for (k, v) in [
        ("software", &own.software_name),
        ("comments", &own.comments),
        ("owner", &own.owner),
        ("capDate", &own.capture_date),
        ("name", &own.layer_name),
        ("wrapmodes", &own.wrap_mode_name),
    ] {
        if let Some(t) = v {
            attributes.push((k.to_string(), t.to_string()));
        }
    }
    attributes.push(("compression".into(), header.compression.to_string()));
    attributes
}

/// An environment map, by OpenEXR's `envmap` attribute or the
/// `textureformat` maketx writes: refused, or described in `notes`, as
/// [`crate::io::environment_map`] decides.
pub(super) fn environment_of(
    header: &Header,
    attributes: &[(String, String)],
    options: &crate::io::LoadOptions,
    notes: &mut Vec<String>,
) -> Result<Option<crate::io::Environment>> {
    use ::exr::meta::attribute::EnvironmentMap;
    let own = &header.own_attributes;
    let (w, h) = (header.layer_size.width(), header.layer_size.height());
    let texture_format = attributes
        .iter()
        .find(|(k, _)| k == "textureformat")
        .map(|(_, v)| v.clone());
    let environment = match (own.environment_map, texture_format.as_deref()) {
        (Some(EnvironmentMap::Cube), _) | (None, Some("CubeFace Environment")) => {
            Some(crate::io::Environment::Cube)
        }
        (Some(EnvironmentMap::LatitudeLongitude), _) | (None, Some("LatLong Environment")) => {
            Some(crate::io::Environment::LatLong)
        }
        _ => None,
    };
    if let Some(kind) = environment {
        let mut detail = Vec::new();
        if let Some(t) = &texture_format {
            detail.push(format!("textureformat \"{t}\""));
        }
        if let Some(e) = own.environment_map {
            detail.push(format!(
                "envmap {}",
                match e {
                    EnvironmentMap::LatitudeLongitude => "latlong",
                    EnvironmentMap::Cube => "cube",
                }
            ));
        }
        detail.push(if kind == crate::io::Environment::Cube && h == 6 * w {
            format!("six {w}x{w} faces stacked top to bottom")
        } else {
            format!("{w}x{h}")
        });
        crate::io::environment_map("OpenEXR", kind, &detail.join(", "), options, notes)?;
    }
    Ok(environment)
}

/// A data window that is not the display window: level 0 is placed in the
/// display window, so its size is what is allocated and is held to the
/// limits too (an 8x8 data window in an 83886074x8 display window asked
/// for 18 GB: tests/files/regression/exr_display_window_unbounded.rs); both
/// windows go into `attributes`.
pub(super) fn check_display_window(
    data_window: ::exr::meta::attribute::IntegerBounds,
    display: ::exr::meta::attribute::IntegerBounds,
    kept: usize,
    limits: &Limits,
    attributes: &mut Vec<(String, String)>,
) -> Result<()> {
    let (dw, dh) = (display.size.width() as u64, display.size.height() as u64);
    limits.check(
        dw,
        dh,
        dw.saturating_mul(dh).saturating_mul(kept as u64 * 4),
    )?;
    for (name, window) in [("dataWindow", data_window), ("displayWindow", display)] {
        attributes.push((
            name.into(),
            format!(
                "({}, {}) {}x{}",
                window.position.x(),
                window.position.y(),
                window.size.width(),
                window.size.height()
            ),
        ));
    }
    Ok(())
}

/// Read the pixels of part `part`, every level of every channel.
pub(super) fn read_part(path: &Path, part: usize) -> Result<Part> {
    let reader = ::exr::prelude::read()
        .no_deep_data()
        .all_resolution_levels()
        .all_channels();
    if part == 0 {
        return Ok(reader
            .first_valid_layer()
            .all_attributes()
            .from_file(path)
            .map_err(read_err)?
            .layer_data);
    }
    let mut layers = reader
        .all_layers()
        .all_attributes()
        .from_file(path)
        .map_err(read_err)?
        .layer_data;
    if part >= layers.len() {
        return Err(decode_err(format!("part {part} has no readable pixels")));
    }
    Ok(layers.swap_remove(part))
}

/// The levels of channels `order` of `list` (indices into it),
/// interleaved: f16 when every chosen channel is half, else f32; linear,
/// with premultiplied alpha when `alpha`. `sizes` are the declared level
/// sizes, all of which a mip map (`mipmapped`) must hold.
pub(super) fn read_levels(
    list: &[::exr::image::AnyChannel<::exr::image::Levels<FlatSamples>>],
    order: &[usize],
    sizes: &[(usize, usize)],
    mipmapped: bool,
    alpha: bool,
) -> Result<Vec<Texture>> {
    let half = order.iter().all(|&i| {
        matches!(
            list[i].sample_data.levels_as_slice()[0],
            FlatSamples::F16(_)
        )
    });
    let per_channel: Vec<Vec<&FlatSamples>> = order
        .iter()
        .map(|&i| match &list[i].sample_data {
            ::exr::image::Levels::Singular(s) => vec![s],
            ::exr::image::Levels::Mip { level_data, .. } => level_data.iter().collect(),
            ::exr::image::Levels::Rip { level_data, .. } => {
                level_data.map_data.iter().take(1).collect()
            }
        })
        .collect();
    let nlev = per_channel[0].len();
    if nlev == 0
        || per_channel.iter().any(|c| c.len() != nlev)
        || (mipmapped && nlev != sizes.len())
    {
        return Err(decode_err("inconsistent mip levels between channels"));
    }
    let ty = if half {
        ChannelType::F16
    } else {
        ChannelType::F32
    };
    // OpenEXR stores colour associated with (premultiplied by) alpha.
    let mut format = Format::new(order.len() as u8, ty, ColorSpace::Linear);
    format = format.with_alpha(if alpha {
        AlphaMode::Premultiplied
    } else {
        AlphaMode::None
    });
    let mut levels = Vec::with_capacity(nlev);
    for (k, &(lw, lh)) in sizes.iter().enumerate().take(nlev) {
        let planes: Vec<&FlatSamples> = per_channel.iter().map(|c| c[k]).collect();
        let texels = interleave(&planes, lw * lh, half)?;
        levels.push(Texture::from_texels(lw as u32, lh as u32, format, texels)?);
    }
    Ok(levels)
}

/// One level's channel planes of `n` samples each, interleaved (f16 when
/// `half`, else every plane converted to f32).
pub(super) fn interleave(planes: &[&FlatSamples], n: usize, half: bool) -> Result<Texels> {
    let ch = planes.len();
    if half {
        let mut out = vec![f16::ZERO; n * ch];
        for (c, plane) in planes.iter().enumerate() {
            let FlatSamples::F16(p) = plane else {
                return Err(decode_err("channel type changed between levels"));
            };
            if p.len() != n {
                return Err(decode_err("level has the wrong number of samples"));
            }
            for (o, v) in out.iter_mut().skip(c).step_by(ch).zip(p.iter()) {
                *o = *v;
            }
        }
        Ok(Texels::F16(out))
    } else {
        let mut out = vec![0f32; n * ch];
        for (c, p) in planes.iter().enumerate() {
            if p.len() != n {
                return Err(decode_err("level has the wrong number of samples"));
            }
            for (o, v) in out.iter_mut().skip(c).step_by(ch).zip(p.values_as_f32()) {
                *o = v;
            }
        }
        Ok(Texels::F32(out))
    }
}

/// Level 0 placed in the display window: texels of the data window inside
/// it copied at their offset, zero (transparent black) elsewhere.
pub(super) fn place_in_display_window(
    t: &Texture,
    data: ::exr::meta::attribute::IntegerBounds,
    display: ::exr::meta::attribute::IntegerBounds,
) -> Result<(Texture, String)> {
    let (dw, dh) = (display.size.width() as u32, display.size.height() as u32);
    let mut out = Texture::new(dw, dh, t.format())?;
    let ch = t.channels();
    let (ox, oy) = (
        data.position.x() as i64 - display.position.x() as i64,
        data.position.y() as i64 - display.position.y() as i64,
    );
    let (sw, sh) = (t.width() as i64, t.height() as i64);
    let x0 = ox.max(0);
    let x1 = (ox + sw).min(dw as i64);
    let y0 = oy.max(0);
    let y1 = (oy + sh).min(dh as i64);
    let inside = (x1 - x0).max(0) * (y1 - y0).max(0);
    fn copy<T: Copy>(src: &[T], dst: &mut [T], ch: usize, sw: i64, dw: i64, r: [i64; 6]) {
        let [ox, oy, x0, x1, y0, y1] = r;
        if x1 <= x0 {
            return;
        }
        for y in y0..y1 {
            let s = (((y - oy) * sw + (x0 - ox)) as usize) * ch;
            let d = ((y * dw + x0) as usize) * ch;
            let n = ((x1 - x0) as usize) * ch;
            dst[d..d + n].copy_from_slice(&src[s..s + n]);
        }
    }
    let r = [ox, oy, x0, x1, y0, y1];
    match (t.texels(), out.texels_mut()) {
        (Texels::F16(s), Texels::F16(d)) => copy(s, d, ch, sw, dw as i64, r),
        (Texels::F32(s), Texels::F32(d)) => copy(s, d, ch, sw, dw as i64, r),
        _ => return Err(decode_err("EXR levels are f16 or f32")),
    }
    let cropped = sw * sh - inside;
    let mut note = format!(
        "data window ({}, {}) {}x{} placed in the display window ({}, {}) {dw}x{dh}, black outside (as maketx pads it)",
        data.position.x(),
        data.position.y(),
        sw,
        sh,
        display.position.x(),
        display.position.y()
    );
    if cropped > 0 {
        note.push_str(&format!(
            "; {cropped} texels outside the display window are cropped"
        ));
    }
    Ok((out, note))
}
