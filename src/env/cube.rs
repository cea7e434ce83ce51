//! Cube maps sampled by direction, with seamless filtering across face
//! edges (OpenGL 4.6 §8.13 "Cube Map Texture Selection",
//! `ARB_seamless_cube_map`; Vulkan "Cube Map Face Selection" and "Cube Map
//! Edge Handling").
//!
//! # Face selection
//! The direction's component of largest magnitude picks the face (ties go
//! to x, then y, as Mesa does); GL's Table 8.19 gives the face's `sc`,
//! `tc` and `ma`, and `s = (sc/|ma| + 1)/2`, `t = (tc/|ma| + 1)/2`. The
//! derivatives of `(s, t)` follow from the direction's derivatives by the
//! quotient rule (GL's equations 8.9–8.10), taken on the face of the
//! centre direction. λ, the anisotropy and the mip levels are then those
//! of a 2-D texture the size of a face ([`mod@crate::sample::footprint`]).
//!
//! # Seamless texels
//! A filter reads texel `(i, j)` of face `f` at level `k` even when `i` or
//! `j` is outside the face: the texel's centre is turned back into a
//! direction (extending the face's plane) and looked up on the face that
//! direction selects. Across one edge this is the neighbour face's edge
//! texel, at the same position along the edge (shown in the tests for
//! every edge). When both `i` and `j` are outside (a corner, where only
//! three faces meet), the texel is the average of the three texels around
//! the corner, as GL and Vulkan define it. Anisotropic probes and the
//! supersampled reference's positions that leave the face are turned into
//! directions the same way and looked up on their own face, so every
//! filter crosses edges without a seam.
//!
//! This is the plain, portable form (each texel decoded through
//! [`LinearChain::texel`]); it is the cube's reference, not yet its fast
//! path.

use crate::error::{Error, Result};
use crate::mip::{MipChain, MipOptions};
use crate::sample::footprint::{Footprint, footprint};
use crate::sample::{LinearChain, Method, MipMode, Query, SamplerOptions, TexelFilter};
use crate::texel::Texels;
use crate::texture::Texture;
use crate::wrap::{Wrap, WrapMode};

use super::{DirQuery, Placement};

/// The six faces in GL's order: +X, −X, +Y, −Y, +Z, −Z (KTX2's, DDS's and
/// Vulkan's order too).
pub const FACE_NAMES: [&str; 6] = ["+x", "-x", "+y", "-y", "+z", "-z"];

/// One face's row of GL's Table 8.19: the major axis and its sign, and the
/// axis and sign of `sc` and `tc`.
#[derive(Clone, Copy, Debug)]
struct FaceAxes {
    major: usize,
    major_sign: f64,
    sc: (usize, f64),
    tc: (usize, f64),
}

/// GL Table 8.19, in face order.
const FACES: [FaceAxes; 6] = [
    // +X: sc = −rz, tc = −ry
    FaceAxes {
        major: 0,
        major_sign: 1.0,
        sc: (2, -1.0),
        tc: (1, -1.0),
    },
    // −X: sc = +rz, tc = −ry
    FaceAxes {
        major: 0,
        major_sign: -1.0,
        sc: (2, 1.0),
        tc: (1, -1.0),
    },
    // +Y: sc = +rx, tc = +rz
    FaceAxes {
        major: 1,
        major_sign: 1.0,
        sc: (0, 1.0),
        tc: (2, 1.0),
    },
    // −Y: sc = +rx, tc = −rz
    FaceAxes {
        major: 1,
        major_sign: -1.0,
        sc: (0, 1.0),
        tc: (2, -1.0),
    },
    // +Z: sc = +rx, tc = −ry
    FaceAxes {
        major: 2,
        major_sign: 1.0,
        sc: (0, 1.0),
        tc: (1, -1.0),
    },
    // −Z: sc = −rx, tc = −ry
    FaceAxes {
        major: 2,
        major_sign: -1.0,
        sc: (0, -1.0),
        tc: (1, -1.0),
    },
];

/// The face a direction selects: the component of largest magnitude
/// (ties to x, then y), its sign. A zero or NaN direction selects +X.
pub fn select_face(d: [f64; 3]) -> usize {
    let a = d.map(|x| if x.is_nan() { 0.0 } else { x.abs() });
    let (axis, neg) = if a[0] >= a[1] && a[0] >= a[2] {
        (0, d[0] < 0.0)
    } else if a[1] >= a[2] {
        (1, d[1] < 0.0)
    } else {
        (2, d[2] < 0.0)
    };
    2 * axis + usize::from(neg)
}

/// `(s, t)` of direction `d` on face `f` (in [0, 1] when `f` is the face
/// `d` selects; outside when it is not), as GL computes them.
pub fn face_st(f: usize, d: [f64; 3]) -> (f64, f64) {
    let fa = &FACES[f];
    let ma = (d[fa.major] * fa.major_sign).abs();
    let sc = d[fa.sc.0] * fa.sc.1;
    let tc = d[fa.tc.0] * fa.tc.1;
    (0.5 * (sc / ma + 1.0), 0.5 * (tc / ma + 1.0))
}

/// The direction through `(s, t)` on face `f`'s plane (|ma| = 1); `s`, `t`
/// may be outside [0, 1] (the plane extended).
pub fn face_direction(f: usize, s: f64, t: f64) -> [f64; 3] {
    let fa = &FACES[f];
    let mut d = [0.0; 3];
    d[fa.major] = fa.major_sign;
    d[fa.sc.0] = (2.0 * s - 1.0) * fa.sc.1;
    d[fa.tc.0] = (2.0 * t - 1.0) * fa.tc.1;
    d
}

/// The face of a direction query and its face-space query: `(s, t)` and
/// their screen derivatives (GL's equations 8.9–8.10, on the face of the
/// centre direction).
pub fn face_query(q: &DirQuery) -> (usize, Query) {
    let d = q.dir.map(f64::from);
    let f = select_face(d);
    let fa = &FACES[f];
    let ma = (d[fa.major] * fa.major_sign).abs();
    let sc = d[fa.sc.0] * fa.sc.1;
    let tc = d[fa.tc.0] * fa.tc.1;
    // ∂s = ½·(∂sc·|ma| − sc·∂|ma|)/ma², with ∂|ma| = sign·∂r_major (the
    // major component keeps its sign on its own face).
    let deriv = |dd: [f32; 3]| {
        let dd = dd.map(f64::from);
        let dma = dd[fa.major] * fa.major_sign;
        let dsc = dd[fa.sc.0] * fa.sc.1;
        let dtc = dd[fa.tc.0] * fa.tc.1;
        let m2 = ma * ma;
        (
            0.5 * (dsc * ma - sc * dma) / m2,
            0.5 * (dtc * ma - tc * dma) / m2,
        )
    };
    let (dsdx, dtdx) = deriv(q.ddx);
    let (dsdy, dtdy) = deriv(q.ddy);
    let (s, t) = (0.5 * (sc / ma + 1.0), 0.5 * (tc / ma + 1.0));
    let face = Query::new(
        s as f32,
        t as f32,
        dsdx as f32,
        dtdx as f32,
        dsdy as f32,
        dtdy as f32,
    );
    (f, face)
}

/// A cube map's six faces, each a square mip chain of the same size,
/// format and level count, sampled by direction (see the module docs).
#[derive(Clone, Debug)]
pub struct CubeSampler {
    faces: Vec<LinearChain>,
    options: SamplerOptions,
    /// Level-0 face size.
    size: u32,
    /// Where the texels sit on each face.
    placement: Placement,
}

impl CubeSampler {
    /// A sampler over `faces` in GL's order (+X, −X, +Y, −Y, +Z, −Z).
    /// Refuses a face count other than 6, faces that are not square or
    /// differ in size, format or level count, and the summed-area-table
    /// method (a table does not cross faces).
    pub fn new(faces: &[MipChain], options: SamplerOptions) -> Result<Self> {
        options.validate()?;
        check_faces(faces)?;
        if options.method == Method::Sat {
            return Err(Error::InvalidOption(
                "summed-area-table sampling of a cube map (a table cannot cross faces)".into(),
            ));
        }
        Ok(CubeSampler {
            faces: faces.iter().map(LinearChain::new).collect(),
            options,
            size: faces[0].levels()[0].width(),
            placement: Placement::Centred,
        })
    }

    /// This sampler reading its faces' texels as `placement` places them:
    /// [`Placement::Edges`] for OpenEXR's cube maps, whose outermost texel
    /// centres lie on the cube's edges (`CubeMap::faceAndPixelPosition`
    /// scales by `sof − 1`), so a nearest or bilinear lookup reads face
    /// `f` alone, at `(s·(n − 1), t·(n − 1))`, and the edge texels it
    /// shares with the next face hold the same values. The EWA filter
    /// and the footprint keep GL's centres (a fraction of a texel apart).
    pub fn with_placement(mut self, placement: Placement) -> Self {
        self.placement = placement;
        self
    }

    /// Where this sampler places the texels.
    pub fn placement(&self) -> Placement {
        self.placement
    }

    /// The options this sampler filters with.
    pub fn options(&self) -> &SamplerOptions {
        &self.options
    }

    /// Level-0 face size in texels.
    pub fn face_size(&self) -> u32 {
        self.size
    }

    /// Number of mip levels per face.
    pub fn levels(&self) -> usize {
        self.faces[0].len()
    }

    /// The footprint of `q` on its face (λ, anisotropy, probes).
    pub fn footprint(&self, q: &DirQuery) -> Footprint {
        let (_, fq) = face_query(q);
        footprint(&fq, self.size, self.size, &self.options)
    }

    /// Filtered linear RGBA at direction `q.dir` with the footprint its
    /// derivatives give. The direction need not be unit length; a zero or
    /// NaN direction reads face +X's centre.
    pub fn sample(&self, q: &DirQuery) -> [f32; 4] {
        let q = sanitize(q);
        let (f, fq) = face_query(&q);
        match self.options.method {
            Method::Supersample => self.supersample(&q),
            Method::Ewa => super::cube_ewa::ewa(self, f, &fq),
            _ => self.texel_method(f, &fq),
        }
    }

    /// Linear RGBA at direction `dir` on explicit level `lod` (GLSL
    /// `textureLod` on a `samplerCube`: the sampler's bias and LOD clamps
    /// apply, its magnification/minification filters and mip mode choose
    /// the texels, no anisotropy).
    pub fn sample_level(&self, dir: [f32; 3], lod: f32) -> [f32; 4] {
        let q = sanitize(&DirQuery::point(dir));
        let (f, fq) = face_query(&q);
        let o = &self.options;
        let lambda = (lod + o.lod_bias).clamp(o.lod_min, o.lod_max);
        let lambda = if lambda.is_nan() { 0.0 } else { lambda };
        let plan = Plan::at(lambda, self.last_level(), o);
        self.probe(f, &plan, fq.u as f64, fq.v as f64)
    }

    /// Nearest, bilinear, the mip modes and footprint assembly.
    fn texel_method(&self, f: usize, fq: &Query) -> [f32; 4] {
        let o = &self.options;
        let fp = footprint(fq, self.size, self.size, o);
        let plan = Plan::at(fp.lambda, self.levels() - 1, o);
        let (s, t) = (fq.u as f64, fq.v as f64);
        if fp.probes <= 1 {
            return self.probe(f, &plan, s, t);
        }
        let n = fp.probes;
        let step = 1.0 / (n as f64 + 1.0);
        let inv = 1.0 / n as f32;
        let mut acc = [0.0f32; 4];
        for i in 1..=n {
            let k = i as f64 * step - 0.5;
            let p = self.probe(f, &plan, s + k * fp.major[0], t + k * fp.major[1]);
            for c in 0..4 {
                acc[c] += p[c] * inv;
            }
        }
        acc
    }

    /// One isotropic lookup with `plan` at `(s, t)` of face `f`'s plane;
    /// a position off the face is looked up on the face its direction
    /// selects.
    fn probe(&self, f: usize, plan: &Plan, s: f64, t: f64) -> [f32; 4] {
        let (f, s, t) = onto_face(f, s, t);
        let filter = if plan.magnify {
            self.options.mag
        } else {
            self.options.min
        };
        let a = self.filtered(filter, f, plan.hi, s, t);
        if plan.delta > 0.0 && plan.lo != plan.hi {
            let b = self.filtered(self.options.min, f, plan.lo, s, t);
            lerp(a, b, plan.delta)
        } else {
            a
        }
    }

    fn filtered(&self, filter: TexelFilter, f: usize, k: usize, s: f64, t: f64) -> [f32; 4] {
        match filter {
            TexelFilter::Nearest => self.nearest(f, k, s, t),
            TexelFilter::Linear => self.bilinear(f, k, s, t),
        }
    }

    /// Level `k`'s size.
    pub(crate) fn level_size(&self, k: usize) -> i64 {
        self.faces[0].level_size(k).map_or(1, |(w, _)| w as i64)
    }

    /// Nearest texel of level `k` at `(s, t)` on face `f` (clamped into
    /// the face: the position is on it).
    pub(crate) fn nearest(&self, f: usize, k: usize, s: f64, t: f64) -> [f32; 4] {
        let n = self.level_size(k);
        if self.placement == Placement::Edges {
            let idx = |x: f64| ((x * (n - 1) as f64).round() as i64).clamp(0, n - 1);
            return self.stored(f, k, idx(s), idx(t));
        }
        let idx = |x: f64| ((x * n as f64).floor() as i64).clamp(0, n - 1);
        self.texel(f, k, idx(s), idx(t))
    }

    /// Bilinear lookup at `(s, t)` of face `f`, level `k`, reading across
    /// edges (GL: i0 = ⌊s·n − ½⌋, α its fraction).
    pub(crate) fn bilinear(&self, f: usize, k: usize, s: f64, t: f64) -> [f32; 4] {
        if self.placement == Placement::Edges {
            return self.bilinear_edges(f, k, s, t);
        }
        let n = self.level_size(k) as f64;
        let (x, y) = (s * n - 0.5, t * n - 0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (a, b) = ((x - x0) as f32, (y - y0) as f32);
        let (i, j) = (x0 as i64, y0 as i64);
        let t00 = self.texel(f, k, i, j);
        let t10 = self.texel(f, k, i + 1, j);
        let t01 = self.texel(f, k, i, j + 1);
        let t11 = self.texel(f, k, i + 1, j + 1);
        lerp(lerp(t00, t10, a), lerp(t01, t11, a), b)
    }

    /// Bilinear with OpenEXR's placement: at `(s·(n − 1), t·(n − 1))` on
    /// face `f` alone, indices clamped to it (the position never leaves
    /// the face, and the edge texels are the neighbour's too).
    fn bilinear_edges(&self, f: usize, k: usize, s: f64, t: f64) -> [f32; 4] {
        let n = self.level_size(k);
        let m = (n - 1) as f64;
        let (x, y) = (s.clamp(0.0, 1.0) * m, t.clamp(0.0, 1.0) * m);
        let (x0, y0) = (x.floor(), y.floor());
        let (a, b) = ((x - x0) as f32, (y - y0) as f32);
        let (i, j) = (x0 as i64, y0 as i64);
        let at = |i: i64, j: i64| self.stored(f, k, i.clamp(0, n - 1), j.clamp(0, n - 1));
        lerp(
            lerp(at(i, j), at(i + 1, j), a),
            lerp(at(i, j + 1), at(i + 1, j + 1), a),
            b,
        )
    }

    /// Texel `(i, j)` of face `f`, level `k`, seamless (module docs): `i`
    /// and `j` may lie outside the face.
    pub fn texel_seamless(&self, f: usize, k: usize, i: i64, j: i64) -> [f32; 4] {
        self.texel(f.min(5), k.min(self.last_level()), i, j)
    }

    /// [`Self::texel_seamless`] for a face and level known to exist.
    pub(crate) fn texel(&self, f: usize, k: usize, i: i64, j: i64) -> [f32; 4] {
        let n = self.level_size(k);
        let inside = |x: i64| (0..n).contains(&x);
        match (inside(i), inside(j)) {
            (true, true) => self.stored(f, k, i, j),
            (false, false) => {
                let (ic, jc) = (i.clamp(0, n - 1), j.clamp(0, n - 1));
                let three = [
                    self.stored(f, k, ic, jc),
                    self.across(f, k, i, jc),
                    self.across(f, k, ic, j),
                ];
                std::array::from_fn(|c| (three[0][c] + three[1][c] + three[2][c]) / 3.0)
            }
            _ => self.across(f, k, i, j),
        }
    }

    /// The texel whose centre's direction falls on another face (one of
    /// `i`, `j` outside face `f`).
    fn across(&self, f: usize, k: usize, i: i64, j: i64) -> [f32; 4] {
        let n = self.level_size(k);
        let nf = n as f64;
        let d = face_direction(f, (i as f64 + 0.5) / nf, (j as f64 + 0.5) / nf);
        let g = select_face(d);
        let (s, t) = face_st(g, d);
        let idx = |x: f64| ((x * nf).floor() as i64).clamp(0, n - 1);
        self.stored(g, k, idx(s), idx(t))
    }

    fn stored(&self, f: usize, k: usize, i: i64, j: i64) -> [f32; 4] {
        self.faces[f]
            .texel(k, i as u32, j as u32)
            .unwrap_or([0.0; 4])
    }

    /// The supersampled reference: `n × n` bilinear lookups of level 0 at
    /// directions spread over the pixel's footprint `dir ± ddx/2 ± ddy/2`
    /// (the 2-D reference's grid, in direction space).
    fn supersample(&self, q: &DirQuery) -> [f32; 4] {
        super::grid_average(q, self.options.supersample, |p| {
            let f = select_face(p);
            let (s, t) = face_st(f, p);
            self.bilinear(f, 0, s, t)
        })
    }

    /// Level count minus one (the last level's index).
    pub(crate) fn last_level(&self) -> usize {
        self.levels() - 1
    }
}

/// `(s, t)` on face `f`'s plane moved onto the face its direction
/// selects, when it is off face `f`.
fn onto_face(f: usize, s: f64, t: f64) -> (usize, f64, f64) {
    if (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t) || !(s.is_finite() && t.is_finite()) {
        return (f, s, t);
    }
    let d = face_direction(f, s, t);
    let g = select_face(d);
    let (s, t) = face_st(g, d);
    (g, s, t)
}

/// A query with NaN direction components read as 0 and a zero direction
/// replaced by +X, so every lookup has a face and finite `(s, t)`.
fn sanitize(q: &DirQuery) -> DirQuery {
    let mut q = *q;
    q.dir = q.dir.map(|x| if x.is_nan() { 0.0 } else { x });
    if q.dir.iter().all(|&x| x == 0.0) {
        q.dir = [1.0, 0.0, 0.0];
    }
    // An infinite component: keep only the infinite ones' signs (the
    // direction they point to).
    if q.dir.iter().any(|x| x.is_infinite()) {
        q.dir = q
            .dir
            .map(|x| if x.is_infinite() { x.signum() } else { 0.0 });
    }
    q
}

/// The levels a lookup reads (as the 2-D sampler's plan).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Plan {
    magnify: bool,
    hi: usize,
    lo: usize,
    delta: f32,
}

impl Plan {
    fn at(lambda: f32, q: usize, o: &SamplerOptions) -> Plan {
        if lambda <= 0.0 || lambda.is_nan() {
            return Plan {
                magnify: true,
                hi: 0,
                lo: 0,
                delta: 0.0,
            };
        }
        let (hi, lo, delta) = match o.mip {
            MipMode::None => (0, 0, 0.0),
            MipMode::Nearest => {
                let d = crate::sample::mip_nearest(lambda, q);
                (d, d, 0.0)
            }
            MipMode::Linear => crate::sample::mip_linear(lambda, q),
        };
        Plan {
            magnify: false,
            hi,
            lo,
            delta,
        }
    }
}

fn lerp(a: [f32; 4], b: [f32; 4], t: f32) -> [f32; 4] {
    std::array::from_fn(|c| a[c] + (b[c] - a[c]) * t)
}

/// Six square faces of one size, format and level count.
pub(crate) fn check_faces(faces: &[MipChain]) -> Result<()> {
    if faces.len() != 6 {
        return Err(Error::InvalidOption(format!(
            "a cube map has 6 faces, not {}",
            faces.len()
        )));
    }
    let first = &faces[0].levels()[0];
    if first.width() != first.height() {
        return Err(Error::InvalidOption(format!(
            "cube map faces must be square, not {}x{}",
            first.width(),
            first.height()
        )));
    }
    for (k, f) in faces.iter().enumerate().skip(1) {
        let l = &f.levels()[0];
        if (l.width(), l.height()) != (first.width(), first.height())
            || l.format() != first.format()
            || f.len() != faces[0].len()
        {
            return Err(Error::InvalidOption(format!(
                "cube map face {} ({}x{}, {} levels) differs from face {} ({}x{}, {} levels) in size, format or level count",
                FACE_NAMES[k],
                l.width(),
                l.height(),
                f.len(),
                FACE_NAMES[0],
                first.width(),
                first.height(),
                faces[0].len()
            )));
        }
    }
    Ok(())
}

/// How six square faces lie in one 2-D image: the strips and crosses
/// cube-map tools export. A layout is told by the image's aspect ratio
/// alone ([`CubeLayout::detect`]), as the four aspects differ.
///
/// Every face is stored as GL orients it (column `i` along `s`, row `j`
/// along `t`, row 0 at the top of the image), except the vertical
/// cross's −Z, turned 180°. The crosses are the cube unfolded so that
/// texels on both sides of every border between two cells of the cross
/// are neighbours on the cube too; this follows from GL's Table 8.19:
/// `+Z` has `s` along +x and `t` along −y, so its right edge meets `+X`'s
/// left edge (`s = 0` is `z = +1` there), `+X`'s right edge `−Z`'s left
/// edge, `+Y`'s last row (`t = 1`, `z = +1`) `+Z`'s first row, and `−Y`'s
/// first row (`t = 0`, `z = +1`) `+Z`'s last row. Below `−Y` (whose last
/// row is `z = −1`) the unfolding continues onto `−Z` with +x to the
/// right and +y downwards, which is GL's `−Z` turned 180°.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CubeLayout {
    /// `w × 6w`: +X, −X, +Y, −Y, +Z, −Z from the top (OpenEXR's cube
    /// map, as `maketx --envcube` writes it).
    VerticalStrip,
    /// `6w × w`: +X, −X, +Y, −Y, +Z, −Z from the left.
    HorizontalStrip,
    /// `4w × 3w`: −X, +Z, +X, −Z in the middle row, +Y above +Z and −Y
    /// below it (AMD CubeMapGen's and cmft's cross).
    HorizontalCross,
    /// `3w × 4w`: −X, +Z, +X in the second row, +Y above +Z, −Y below it
    /// and −Z below −Y, turned 180°.
    VerticalCross,
}

impl CubeLayout {
    /// Every layout, in the order error messages list them.
    pub const ALL: [CubeLayout; 4] = [
        CubeLayout::VerticalStrip,
        CubeLayout::HorizontalStrip,
        CubeLayout::HorizontalCross,
        CubeLayout::VerticalCross,
    ];

    /// The image size, in faces across and down.
    pub fn cells(self) -> (u32, u32) {
        match self {
            CubeLayout::VerticalStrip => (1, 6),
            CubeLayout::HorizontalStrip => (6, 1),
            CubeLayout::HorizontalCross => (4, 3),
            CubeLayout::VerticalCross => (3, 4),
        }
    }

    /// The layout of a `w × h` image and its face size, if its aspect is
    /// one of the four.
    pub fn detect(w: u32, h: u32) -> Option<(CubeLayout, u32)> {
        CubeLayout::ALL
            .into_iter()
            .find_map(|l| l.face_size(w, h).map(|n| (l, n)))
    }

    /// The face size of a `w × h` image in this layout, if it is one.
    pub fn face_size(self, w: u32, h: u32) -> Option<u32> {
        let (a, b) = self.cells();
        let n = w / a;
        (n > 0 && w.is_multiple_of(a) && u64::from(h) == u64::from(n) * u64::from(b)).then_some(n)
    }

    /// Where face `f` (GL's order) lies: its cell's column and row, and
    /// whether it is stored turned by 180°.
    pub fn face_cell(self, f: usize) -> (u32, u32, bool) {
        const CROSS: [(u32, u32); 6] = [(2, 1), (0, 1), (1, 0), (1, 2), (1, 1), (3, 1)];
        let f = f.min(5);
        match self {
            CubeLayout::VerticalStrip => (0, f as u32, false),
            CubeLayout::HorizontalStrip => (f as u32, 0, false),
            CubeLayout::HorizontalCross => (CROSS[f].0, CROSS[f].1, false),
            CubeLayout::VerticalCross if f == 5 => (1, 3, true),
            CubeLayout::VerticalCross => (CROSS[f].0, CROSS[f].1, false),
        }
    }

    /// The layout's name and shape, as messages print it.
    pub fn describe(self) -> &'static str {
        match self {
            CubeLayout::VerticalStrip => "a vertical strip w x 6w (+x -x +y -y +z -z from the top)",
            CubeLayout::HorizontalStrip => {
                "a horizontal strip 6w x w (+x -x +y -y +z -z from the left)"
            }
            CubeLayout::HorizontalCross => {
                "a horizontal cross 4w x 3w (-x +z +x -z across, +y above and -y below +z)"
            }
            CubeLayout::VerticalCross => {
                "a vertical cross 3w x 4w (-x +z +x across, +y above +z, -y below it, -z below -y \
                 turned 180 degrees)"
            }
        }
    }
}

impl std::fmt::Display for CubeLayout {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            CubeLayout::VerticalStrip => "vertical strip",
            CubeLayout::HorizontalStrip => "horizontal strip",
            CubeLayout::HorizontalCross => "horizontal cross",
            CubeLayout::VerticalCross => "vertical cross",
        })
    }
}

/// The six faces of a vertical strip (`w × 6w`, faces +X, −X, +Y, −Y, +Z,
/// −Z from the top: OpenEXR's cube-map layout, as `maketx --envcube`
/// writes it), stored as the strip stores them.
pub fn faces_from_strip(strip: &Texture) -> Result<Vec<Texture>> {
    let (w, h) = (strip.width(), strip.height());
    if w == 0 || u64::from(h) != 6 * u64::from(w) {
        return Err(Error::InvalidOption(format!(
            "a cube-map strip is w x 6w (six square faces stacked, +x -x +y -y +z -z from the top), not {w}x{h}"
        )));
    }
    faces_in_layout(strip, CubeLayout::VerticalStrip)
}

/// The six faces of a strip or a cross, its layout told by its aspect
/// ([`CubeLayout::detect`]); any other size is refused with the layouts
/// that are read.
pub fn faces_from_image(image: &Texture) -> Result<Vec<Texture>> {
    let (w, h) = (image.width(), image.height());
    match CubeLayout::detect(w, h) {
        Some((layout, _)) => faces_in_layout(image, layout),
        None => Err(Error::InvalidOption(format!(
            "a {w}x{h} image is not six cube faces in a layout parvo reads: {}",
            layouts_sentence()
        ))),
    }
}

/// The accepted layouts, one clause each (for messages).
pub fn layouts_sentence() -> String {
    CubeLayout::ALL
        .iter()
        .map(|l| l.describe())
        .collect::<Vec<_>>()
        .join(", ")
}

/// The six faces (GL's order, GL's orientation) of `image` laid out as
/// `layout`; the image's size must be the layout's multiple of one face.
pub fn faces_in_layout(image: &Texture, layout: CubeLayout) -> Result<Vec<Texture>> {
    let (w, h) = (image.width(), image.height());
    let Some(n) = layout.face_size(w, h) else {
        return Err(Error::InvalidOption(format!(
            "a {w}x{h} image is not {}",
            layout.describe()
        )));
    };
    let ch = image.channels();
    fn cut<T: Copy>(v: &[T], w: usize, ch: usize, n: usize, cell: (u32, u32, bool)) -> Vec<T> {
        let (x0, y0) = (cell.0 as usize * n, cell.1 as usize * n);
        let mut out = Vec::with_capacity(n * n * ch);
        for j in 0..n {
            for i in 0..n {
                // A face turned 180°: its texel (i, j) is the cell's
                // (n-1-i, n-1-j).
                let (x, y) = if cell.2 {
                    (x0 + n - 1 - i, y0 + n - 1 - j)
                } else {
                    (x0 + i, y0 + j)
                };
                let at = (y * w + x) * ch;
                out.extend_from_slice(&v[at..at + ch]);
            }
        }
        out
    }
    let (wu, nu) = (w as usize, n as usize);
    (0..6)
        .map(|f| {
            let cell = layout.face_cell(f);
            let texels = match image.texels() {
                Texels::U8(v) => Texels::U8(cut(v, wu, ch, nu, cell)),
                Texels::U16(v) => Texels::U16(cut(v, wu, ch, nu, cell)),
                Texels::F16(v) => Texels::F16(cut(v, wu, ch, nu, cell)),
                Texels::F32(v) => Texels::F32(cut(v, wu, ch, nu, cell)),
            };
            Texture::from_texels(n, n, image.format(), texels)
        })
        .collect()
}

/// The texel across an edge: `(i, j)` lies one texel outside face `f`
/// of `n × n` texels in one of its coordinates (not both); the texel of
/// the neighbour face its centre's direction lands on (the seamless
/// rule of the GL specification, as [`CubeSampler`] reads it).
pub fn across_edge(f: usize, n: u32, i: i64, j: i64) -> (usize, u32, u32) {
    let nf = n as f64;
    let d = face_direction(f, (i as f64 + 0.5) / nf, (j as f64 + 0.5) / nf);
    let g = select_face(d);
    let (s, t) = face_st(g, d);
    let idx = |x: f64| ((x * nf).floor() as i64).clamp(0, n as i64 - 1) as u32;
    (g, idx(s), idx(t))
}

/// Edge fix-up (as AMD CubeMapGen's "average" fix-up): in every level
/// from `from_level` on whose faces are at least 2×2, each texel on a
/// face edge becomes the mean of itself and the texel across the edge,
/// and each corner texel the mean of the three texels that meet at the
/// cube's corner. The texels on both sides of every edge are then equal,
/// and equal to a box filter of the finer texels on both sides (for a
/// box chain of power-of-two faces; colour weighted by alpha when alpha
/// is straight, as the box filter weights it); a sampler without
/// seamless cube filtering shows no seam. Levels of 1×1 faces are left alone (their
/// one texel touches four faces). Values are computed in linear `f32`
/// and stored back in each level's format.
pub fn fix_edges(faces: Vec<MipChain>, from_level: usize) -> Result<Vec<MipChain>> {
    if faces.len() != 6 {
        return Err(Error::InvalidOption(format!(
            "a cube map has six faces, got {}",
            faces.len()
        )));
    }
    let options: Vec<MipOptions> = faces.iter().map(|c| *c.options()).collect();
    let mut levels: Vec<Vec<Texture>> = faces.into_iter().map(MipChain::into_levels).collect();
    let count = levels.iter().map(Vec::len).min().unwrap_or(0);
    for k in from_level..count {
        let n = levels[0][k].width();
        if n < 2 {
            continue;
        }
        let lin: Vec<Vec<f32>> = levels.iter().map(|face| face[k].to_linear()).collect();
        let ch = levels[0][k].channels();
        let f0 = levels[0][k].format();
        let straight = (f0.alpha == crate::texel::AlphaMode::Straight)
            .then(|| f0.alpha_channel())
            .flatten();
        let mut out = lin.clone();
        let at = |i: u32, j: u32| (j as usize * n as usize + i as usize) * ch;
        let last = n as i64 - 1;
        for (f, face_out) in out.iter_mut().enumerate() {
            for j in 0..n {
                for i in 0..n {
                    let (ii, jj) = (i as i64, j as i64);
                    let off_i = if ii == 0 {
                        -1
                    } else if ii == last {
                        n as i64
                    } else {
                        ii
                    };
                    let off_j = if jj == 0 {
                        -1
                    } else if jj == last {
                        n as i64
                    } else {
                        jj
                    };
                    let mut group = vec![(f, i, j)];
                    if off_i != ii {
                        group.push(across_edge(f, n, off_i, jj));
                    }
                    if off_j != jj {
                        group.push(across_edge(f, n, ii, off_j));
                    }
                    if group.len() == 1 {
                        continue;
                    }
                    let texels: Vec<&[f32]> = group
                        .iter()
                        .map(|&(g, a, b)| &lin[g][at(a, b)..at(a, b) + ch])
                        .collect();
                    let o = at(i, j);
                    face_out[o..o + ch].copy_from_slice(&mean_texel(&texels, straight));
                }
            }
        }
        for (f, v) in out.into_iter().enumerate() {
            let t = &levels[f][k];
            levels[f][k] = Texture::from_linear(n, n, t.format(), &v)?;
        }
    }
    levels
        .into_iter()
        .zip(options)
        .map(|(l, o)| MipChain::from_levels(l, o))
        .collect()
}

/// The mean of `texels` (linear values), colour weighted by alpha when
/// alpha is straight (channel `straight`), as the box filter averages
/// (plain means when every alpha is 0).
fn mean_texel(texels: &[&[f32]], straight: Option<usize>) -> Vec<f32> {
    let ch = texels[0].len();
    let n = texels.len() as f32;
    let plain: Vec<f32> = (0..ch)
        .map(|c| texels.iter().map(|t| t[c]).sum::<f32>() / n)
        .collect();
    let Some(a) = straight else {
        return plain;
    };
    let wsum: f32 = texels.iter().map(|t| t[a]).sum();
    if wsum <= 0.0 {
        return plain;
    }
    (0..ch)
        .map(|c| {
            if c == a {
                plain[c]
            } else {
                texels.iter().map(|t| t[c] * t[a]).sum::<f32>() / wsum
            }
        })
        .collect()
}

/// The vertical strip of six faces (`n × 6n`, +X, −X, +Y, −Y, +Z, −Z
/// from the top): [`faces_from_strip`]'s inverse.
pub fn strip_from_faces(faces: &[&Texture]) -> Result<Texture> {
    let Some(first) = faces.first() else {
        return Err(Error::InvalidOption(
            "a cube map has six faces, got none".into(),
        ));
    };
    let (n, fmt) = (first.width(), first.format());
    if faces.len() != 6
        || faces
            .iter()
            .any(|f| (f.width(), f.height(), f.format()) != (n, n, fmt))
    {
        return Err(Error::InvalidOption(format!(
            "a cube map has six square faces of one size and format, got {} faces",
            faces.len()
        )));
    }
    fn join<T: Clone>(parts: impl Iterator<Item = Vec<T>>) -> Vec<T> {
        parts.flatten().collect()
    }
    let texels = match first.texels() {
        Texels::U8(_) => Texels::U8(join(faces.iter().map(|f| match f.texels() {
            Texels::U8(v) => v.clone(),
            _ => unreachable!("one format"),
        }))),
        Texels::U16(_) => Texels::U16(join(faces.iter().map(|f| match f.texels() {
            Texels::U16(v) => v.clone(),
            _ => unreachable!("one format"),
        }))),
        Texels::F16(_) => Texels::F16(join(faces.iter().map(|f| match f.texels() {
            Texels::F16(v) => v.clone(),
            _ => unreachable!("one format"),
        }))),
        Texels::F32(_) => Texels::F32(join(faces.iter().map(|f| match f.texels() {
            Texels::F32(v) => v.clone(),
            _ => unreachable!("one format"),
        }))),
    };
    Texture::from_texels(n, 6 * n, fmt, texels)
}

/// A mip chain per face, each face filtered on its own with clamped
/// edges (`options.wrap` is replaced by clamp-to-edge). With the box
/// filter and power-of-two faces every coarser texel is the mean of the
/// finer texels it covers, which is the direction-space box average too,
/// so no texel straddles an edge; the seams between faces are then
/// removed at lookup by [`CubeSampler`]'s seamless filtering.
pub fn build_faces(faces: Vec<Texture>, options: &MipOptions) -> Result<Vec<MipChain>> {
    let o = MipOptions {
        wrap: Wrap::both(WrapMode::ClampToEdge),
        ..*options
    };
    faces
        .into_iter()
        .map(|f| crate::mip::build(f, &o))
        .collect()
}
