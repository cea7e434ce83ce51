//! Cube faces from strips and crosses (`env::cube::CubeLayout`): every
//! layout is built here from a known function of the direction, with each
//! cell's frame (outward normal, image right, image down) written out by
//! hand; the crosses' frames are first shown to be an unfolding of the
//! cube (texels on both sides of every border between two cells are a
//! texel apart on the sphere), then the faces parvo cuts out are checked
//! texel by texel against the function at the direction GL's Table 8.19
//! gives each texel centre (`face_direction`), at awkward face sizes.

use parvo::env::cube::{CubeLayout, faces_from_image, faces_from_strip, faces_in_layout};
use parvo::env::cube::{face_direction, strip_from_faces};
use parvo::{ChannelType, ColorSpace, Format, Texture};

type V3 = [f64; 3];

/// A cell of a layout: its column and row, and the face's outward
/// normal and the directions image-right and image-down point to on it.
struct Cell {
    col: u32,
    row: u32,
    normal: V3,
    right: V3,
    down: V3,
}

const fn cell(col: u32, row: u32, normal: V3, right: V3, down: V3) -> Cell {
    Cell {
        col,
        row,
        normal,
        right,
        down,
    }
}

const PX: V3 = [1.0, 0.0, 0.0];
const NX: V3 = [-1.0, 0.0, 0.0];
const PY: V3 = [0.0, 1.0, 0.0];
const NY: V3 = [0.0, -1.0, 0.0];
const PZ: V3 = [0.0, 0.0, 1.0];
const NZ: V3 = [0.0, 0.0, -1.0];

/// The frames of GL's faces as a strip stores them (Table 8.19: s along
/// `sc`, t along `tc`, row 0 at t = 0), +X −X +Y −Y +Z −Z.
const GL_FRAMES: [(V3, V3, V3); 6] = [
    (PX, NZ, NY),
    (NX, PZ, NY),
    (PY, PX, PZ),
    (NY, PX, NZ),
    (PZ, PX, NY),
    (NZ, NX, NY),
];

/// The cells of `layout`, written from the picture of the layout (the
/// crosses as the cube unfolded around +Z, seen from inside: going right
/// along the middle row turns about y, going down from +Y through +Z,
/// −Y and, in the vertical cross, −Z turns about x).
fn cells(layout: CubeLayout) -> Vec<Cell> {
    match layout {
        CubeLayout::VerticalStrip => (0..6)
            .map(|f| {
                let (n, r, d) = GL_FRAMES[f];
                cell(0, f as u32, n, r, d)
            })
            .collect(),
        CubeLayout::HorizontalStrip => (0..6)
            .map(|f| {
                let (n, r, d) = GL_FRAMES[f];
                cell(f as u32, 0, n, r, d)
            })
            .collect(),
        CubeLayout::HorizontalCross => vec![
            cell(1, 0, PY, PX, PZ),
            cell(0, 1, NX, PZ, NY),
            cell(1, 1, PZ, PX, NY),
            cell(2, 1, PX, NZ, NY),
            cell(3, 1, NZ, NX, NY),
            cell(1, 2, NY, PX, NZ),
        ],
        CubeLayout::VerticalCross => vec![
            cell(1, 0, PY, PX, PZ),
            cell(0, 1, NX, PZ, NY),
            cell(1, 1, PZ, PX, NY),
            cell(2, 1, PX, NZ, NY),
            cell(1, 2, NY, PX, NZ),
            // Below −Y the unfolding goes on towards +y, +x still right.
            cell(1, 3, NZ, PX, PY),
        ],
    }
}

fn unit(d: V3) -> V3 {
    let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    d.map(|c| c / l)
}

/// The direction through pixel `(x, y)` of a `cells`-laid image of face
/// size `n`, or `None` in an empty cell.
fn pixel_direction(cells: &[Cell], n: u32, x: u32, y: u32) -> Option<V3> {
    let c = cells.iter().find(|c| c.col == x / n && c.row == y / n)?;
    let u = 2.0 * ((x % n) as f64 + 0.5) / n as f64 - 1.0;
    let v = 2.0 * ((y % n) as f64 + 0.5) / n as f64 - 1.0;
    Some(unit(std::array::from_fn(|k| {
        c.normal[k] + u * c.right[k] + v * c.down[k]
    })))
}

/// The known environment: colour = direction / 2 + 1/2, alpha 1.
fn env(d: V3) -> [f32; 4] {
    let d = unit(d);
    [
        (d[0] * 0.5 + 0.5) as f32,
        (d[1] * 0.5 + 0.5) as f32,
        (d[2] * 0.5 + 0.5) as f32,
        1.0,
    ]
}

const EMPTY: [f32; 4] = [-7.0, -7.0, -7.0, -7.0];

fn rgba_f32() -> Format {
    Format::new(4, ChannelType::F32, ColorSpace::Linear)
}

/// The image of `layout` with face size `n` holding [`env`] (empty
/// cells hold a value no face has).
fn build(layout: CubeLayout, n: u32) -> Texture {
    build_with(layout, &cells(layout), n)
}

/// [`build`] with the cells given.
fn build_with(layout: CubeLayout, cells: &[Cell], n: u32) -> Texture {
    let (a, b) = layout.cells();
    let (w, h) = (a * n, b * n);
    let mut v = Vec::with_capacity((w * h * 4) as usize);
    for y in 0..h {
        for x in 0..w {
            v.extend(pixel_direction(cells, n, x, y).map_or(EMPTY, env));
        }
    }
    Texture::from_f32(w, h, rgba_f32(), v).unwrap()
}

fn angle(a: V3, b: V3) -> f64 {
    let dot: f64 = (0..3).map(|k| a[k] * b[k]).sum();
    dot.clamp(-1.0, 1.0).acos()
}

/// The test's crosses are unfoldings of the cube: across every border
/// between two occupied cells, the two pixels' directions are as close
/// as two neighbours inside a face (at most 2/n radians apart), while a
/// face misplaced or turned would put them far apart. (The strips are
/// not unfoldings: their frames are GL's table itself.)
#[test]
fn the_test_crosses_are_unfoldings_of_the_cube() {
    let n = 7;
    for layout in [CubeLayout::HorizontalCross, CubeLayout::VerticalCross] {
        let cells = cells(layout);
        let (a, b) = layout.cells();
        let (w, h) = (a * n, b * n);
        let mut borders = 0;
        for y in 0..h {
            for x in 0..w {
                let Some(d) = pixel_direction(&cells, n, x, y) else {
                    continue;
                };
                for (x2, y2) in [(x + 1, y), (x, y + 1)] {
                    if x2 >= w || y2 >= h || (x2 / n, y2 / n) == (x / n, y / n) {
                        continue;
                    }
                    let Some(d2) = pixel_direction(&cells, n, x2, y2) else {
                        continue;
                    };
                    let a = angle(d, d2);
                    assert!(
                        a <= 2.0 / n as f64,
                        "{layout}: ({x},{y}) and ({x2},{y2}) are {a} rad apart"
                    );
                    borders += 1;
                }
            }
        }
        // Five borders of n pixel pairs in either cross.
        assert_eq!(borders, 5 * n, "{layout}");
    }
}

/// Every face cut from every layout holds, at each texel centre, the
/// environment at the direction GL gives that centre, at face sizes 1,
/// 2, 5, 7 and 8; `faces_from_image` tells the layout by the aspect.
#[test]
fn faces_cut_from_strips_and_crosses_follow_gl_face_directions() {
    for layout in CubeLayout::ALL {
        for n in [1u32, 2, 5, 7, 8] {
            let image = build(layout, n);
            assert_eq!(
                CubeLayout::detect(image.width(), image.height()),
                Some((layout, n)),
                "{layout} {n}"
            );
            let faces = faces_from_image(&image).unwrap();
            assert_eq!(faces, faces_in_layout(&image, layout).unwrap());
            assert_eq!(faces.len(), 6);
            let mut worst = 0.0f32;
            for (f, face) in faces.iter().enumerate() {
                assert_eq!((face.width(), face.height()), (n, n));
                for j in 0..n {
                    for i in 0..n {
                        let s = (i as f64 + 0.5) / n as f64;
                        let t = (j as f64 + 0.5) / n as f64;
                        let want = env(face_direction(f, s, t));
                        let got = face.texel_linear(i, j);
                        for c in 0..4 {
                            let e = (got[c] - want[c]).abs();
                            worst = worst.max(e);
                            assert!(
                                e <= 1e-6,
                                "{layout} n={n} face {f} texel ({i},{j}): {got:?}, want {want:?}"
                            );
                        }
                    }
                }
            }
            assert!(worst <= 1e-6);
        }
    }
}

/// The vertical strip is `faces_from_strip`'s layout and
/// `strip_from_faces`'s inverse.
#[test]
fn the_vertical_strip_is_openexrs_strip() {
    for n in [1u32, 5, 8] {
        let image = build(CubeLayout::VerticalStrip, n);
        let faces = faces_from_image(&image).unwrap();
        assert_eq!(faces, faces_from_strip(&image).unwrap());
        assert_eq!(
            strip_from_faces(&faces.iter().collect::<Vec<_>>()).unwrap(),
            image
        );
    }
}

/// Every texel type is cut the same: the faces of a layout converted to
/// u8, u16 and f16 (one and three channels too) equal the f32 faces
/// converted.
#[test]
fn every_texel_type_and_channel_count_is_cut_alike() {
    for layout in CubeLayout::ALL {
        let image = build(layout, 5);
        let faces = faces_from_image(&image).unwrap();
        for (ch, ty) in [
            (4u8, ChannelType::U8),
            (3, ChannelType::U16),
            (1, ChannelType::F16),
            (2, ChannelType::F32),
        ] {
            let f = Format::new(ch, ty, ColorSpace::Linear);
            let conv = |t: &Texture| {
                // Keep the first `ch` channels, then store as `ty`.
                let lin = t.to_linear();
                let v: Vec<f32> = lin
                    .chunks(4)
                    .flat_map(|p| p[..ch as usize].to_vec())
                    .map(|x| x.max(0.0))
                    .collect();
                Texture::from_linear(t.width(), t.height(), f, &v).unwrap()
            };
            let got = faces_from_image(&conv(&image)).unwrap();
            let want: Vec<Texture> = faces.iter().map(conv).collect();
            assert_eq!(got, want, "{layout} {ch}x{ty}");
        }
    }
}

/// Any other aspect is refused with one message naming every layout
/// read; so is an image of the wrong shape for an asked layout.
#[test]
fn other_aspects_are_refused_listing_the_layouts() {
    let f = Format::new(1, ChannelType::U8, ColorSpace::Linear);
    for (w, h) in [
        (4, 4),
        (5, 3),
        (12, 8),
        (2, 1),
        (7, 41),
        (8, 6 * 8 + 1),
        (1, 1),
    ] {
        let t = Texture::new(w, h, f).unwrap();
        assert_eq!(CubeLayout::detect(w, h), None, "{w}x{h}");
        let e = faces_from_image(&t).unwrap_err().to_string();
        for needle in [
            format!("{w}x{h}").as_str(),
            "vertical strip w x 6w",
            "horizontal strip 6w x w",
            "horizontal cross 4w x 3w",
            "vertical cross 3w x 4w",
        ] {
            assert!(e.contains(needle), "{w}x{h}: {e}");
        }
    }
    let t = Texture::new(8, 6, f).unwrap();
    let e = faces_in_layout(&t, CubeLayout::VerticalCross)
        .unwrap_err()
        .to_string();
    assert!(e.contains("8x6") && e.contains("vertical cross"), "{e}");
}

/// The largest difference between `faces` and the environment at GL's
/// direction of each texel centre.
fn worst_error(faces: &[Texture]) -> f32 {
    let mut worst = 0.0f32;
    for (f, face) in faces.iter().enumerate() {
        let n = face.width();
        for j in 0..n {
            for i in 0..n {
                let s = (i as f64 + 0.5) / n as f64;
                let t = (j as f64 + 0.5) / n as f64;
                let want = env(face_direction(f, s, t));
                let got = face.texel_linear(i, j);
                for c in 0..4 {
                    worst = worst.max((got[c] - want[c]).abs());
                }
            }
        }
    }
    worst
}

/// The check above sees a face misplaced, mirrored or turned: a cross
/// whose −Z is stored unturned (or turned in the horizontal cross), or
/// whose +X and −X are swapped, is read far from the environment.
#[test]
fn a_face_turned_or_misplaced_would_be_caught() {
    for layout in [CubeLayout::HorizontalCross, CubeLayout::VerticalCross] {
        let good = build(layout, 5);
        assert!(worst_error(&faces_from_image(&good).unwrap()) <= 1e-6);
        // −Z (the last cell) turned by 180°.
        let mut turned = cells(layout);
        let z = turned.len() - 1;
        turned[z].right = turned[z].right.map(|c| -c);
        turned[z].down = turned[z].down.map(|c| -c);
        // +X and −X swapped (their cells are (2, 1) and (0, 1)).
        let mut swapped = cells(layout);
        for c in swapped.iter_mut() {
            if c.row == 1 && c.col != 1 && c.col != 3 {
                c.col = 2 - c.col;
            }
        }
        for (what, wrong) in [("turned -z", turned), ("swapped x", swapped)] {
            let image = build_with(layout, &wrong, 5);
            let e = worst_error(&faces_from_image(&image).unwrap());
            assert!(e > 0.1, "{layout} {what}: only {e} off");
        }
    }
}
