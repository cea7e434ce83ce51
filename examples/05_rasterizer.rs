//! A small software rasterizer that takes parvo as its texture unit, as a
//! renderer would: a perspective camera over a ground plane whose brick
//! texture repeats across UVs −30…30, a rotated cube with a photo on each
//! face, 2×2 pixel quads that give every pixel its derivatives (as GPUs
//! take them), a depth buffer, and a shadow map of the cube sampled with a
//! depth comparison (percentage-closer filtering by the bilinear filter).
//!
//! ```text
//! cargo run --release --example 05_rasterizer                 # writes target/rasterizer.png
//! cargo run --release --example 05_rasterizer -- --json       # the speed table as JSON
//! cargo run --release --example 05_rasterizer -- --out f.png --filter aniso16
//! ```
//!
//! With `--json` it times the lookups of the frame on one thread for
//! nearest, bilinear, trilinear, aniso16 and ewa, in M pixels/s:
//! `single` (one `Sampler::sample` call per pixel, as a forward renderer
//! shades while rasterizing), `quad` (one `sample_quad` per 2×2 quad),
//! `slice` (all the frame's queries in one `sample_slice`), and the
//! ground's queries alone in one slice with their UVs as the rasterizer
//! made them, −30…30 (`wrapped`), and wrapped into [0, 1) by hand
//! (`unit`). Each figure is the median of 9 timed runs, the columns
//! interleaved (one run of each per round).
//! `portable_slice` is the slice with the AVX-512 paths off
//! (`Sampler::set_simd(false)`): the per-lookup code a single call runs.
//! `--only NAME` times that filter alone.

use std::hint::black_box;
use std::time::Instant;

use parvo::mip::{self, MipFilter, MipOptions};
use parvo::sample::{CompareOp, MipMode, Query, Sampler, SamplerOptions, TexelFilter};
use parvo::{ChannelType, ColorSpace, Format, Texture, Wrap, WrapMode};

const W: usize = 640;
const H: usize = 480;
/// Shadow map side.
const SHADOW: usize = 1024;

type V3 = [f32; 3];

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: V3, b: V3) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn norm(a: V3) -> V3 {
    let l = dot(a, a).sqrt();
    [a[0] / l, a[1] / l, a[2] / l]
}

/// A 4×4 matrix, row-major, acting on column vectors.
#[derive(Clone, Copy)]
struct M4([[f32; 4]; 4]);

impl M4 {
    fn mul(&self, o: &M4) -> M4 {
        let mut r = [[0.0; 4]; 4];
        for (i, row) in r.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                *x = (0..4).map(|k| self.0[i][k] * o.0[k][j]).sum();
            }
        }
        M4(r)
    }
    fn apply(&self, p: V3) -> [f32; 4] {
        let v = [p[0], p[1], p[2], 1.0];
        let mut r = [0.0; 4];
        for (i, x) in r.iter_mut().enumerate() {
            *x = (0..4).map(|k| self.0[i][k] * v[k]).sum();
        }
        r
    }
    fn look_at(eye: V3, at: V3, up: V3) -> M4 {
        let f = norm(sub(at, eye));
        let s = norm(cross(f, up));
        let u = cross(s, f);
        M4([
            [s[0], s[1], s[2], -dot(s, eye)],
            [u[0], u[1], u[2], -dot(u, eye)],
            [-f[0], -f[1], -f[2], dot(f, eye)],
            [0.0, 0.0, 0.0, 1.0],
        ])
    }
    /// OpenGL-style perspective: depth −1…1 from near to far.
    fn perspective(fovy: f32, aspect: f32, near: f32, far: f32) -> M4 {
        let t = 1.0 / (fovy / 2.0).tan();
        M4([
            [t / aspect, 0.0, 0.0, 0.0],
            [0.0, t, 0.0, 0.0],
            [
                0.0,
                0.0,
                (far + near) / (near - far),
                2.0 * far * near / (near - far),
            ],
            [0.0, 0.0, -1.0, 0.0],
        ])
    }
    fn ortho(half: f32, near: f32, far: f32) -> M4 {
        M4([
            [1.0 / half, 0.0, 0.0, 0.0],
            [0.0, 1.0 / half, 0.0, 0.0],
            [0.0, 0.0, -2.0 / (far - near), -(far + near) / (far - near)],
            [0.0, 0.0, 0.0, 1.0],
        ])
    }
}

/// A vertex after the vertex stage: clip position, texture coordinate,
/// world position (for the shadow lookup).
#[derive(Clone, Copy)]
struct Vert {
    clip: [f32; 4],
    uv: [f32; 2],
    world: V3,
}

fn lerp_vert(a: &Vert, b: &Vert, t: f32) -> Vert {
    let l = |x: f32, y: f32| x + (y - x) * t;
    Vert {
        clip: [
            l(a.clip[0], b.clip[0]),
            l(a.clip[1], b.clip[1]),
            l(a.clip[2], b.clip[2]),
            l(a.clip[3], b.clip[3]),
        ],
        uv: [l(a.uv[0], b.uv[0]), l(a.uv[1], b.uv[1])],
        world: [
            l(a.world[0], b.world[0]),
            l(a.world[1], b.world[1]),
            l(a.world[2], b.world[2]),
        ],
    }
}

/// Clip a polygon against the near plane (z > −w), Sutherland–Hodgman.
fn clip_near(poly: &[Vert]) -> Vec<Vert> {
    let d = |v: &Vert| v.clip[2] + v.clip[3];
    let mut out = Vec::new();
    for i in 0..poly.len() {
        let (a, b) = (&poly[i], &poly[(i + 1) % poly.len()]);
        let (da, db) = (d(a), d(b));
        if da >= 0.0 {
            out.push(*a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            out.push(lerp_vert(a, b, da / (da - db)));
        }
    }
    out
}

/// A textured triangle list and the texture it uses.
struct Mesh {
    tris: Vec<[(V3, [f32; 2]); 3]>,
    texture: usize,
}

fn ground() -> Mesh {
    let (a, b, c, d) = (
        ([-30.0, 0.0, -30.0], [-30.0, -30.0]),
        ([30.0, 0.0, -30.0], [30.0, -30.0]),
        ([30.0, 0.0, 30.0], [30.0, 30.0]),
        ([-30.0, 0.0, 30.0], [-30.0, 30.0]),
    );
    Mesh {
        tris: vec![[a, b, c], [a, c, d]],
        texture: 0,
    }
}

fn cube(angle: f32) -> Mesh {
    let (s, c) = angle.sin_cos();
    let place = |p: V3| -> V3 {
        let (x, y, z) = (p[0] * 0.75, p[1] * 0.75 + 0.75, p[2] * 0.75);
        [c * x + s * z, y, -s * x + c * z]
    };
    let mut tris = Vec::new();
    // Each face: a corner and its two edge directions (outward winding).
    let faces: [(V3, V3, V3); 6] = [
        ([-1.0, -1.0, 1.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]),
        ([1.0, -1.0, -1.0], [-2.0, 0.0, 0.0], [0.0, 2.0, 0.0]),
        ([1.0, -1.0, 1.0], [0.0, 0.0, -2.0], [0.0, 2.0, 0.0]),
        ([-1.0, -1.0, -1.0], [0.0, 0.0, 2.0], [0.0, 2.0, 0.0]),
        ([-1.0, 1.0, 1.0], [2.0, 0.0, 0.0], [0.0, 0.0, -2.0]),
        ([-1.0, -1.0, -1.0], [2.0, 0.0, 0.0], [0.0, 0.0, 2.0]),
    ];
    for (o, e1, e2) in faces {
        let p = |a: f32, b: f32| {
            place([
                o[0] + a * e1[0] + b * e2[0],
                o[1] + a * e1[1] + b * e2[1],
                o[2] + a * e1[2] + b * e2[2],
            ])
        };
        let (v00, v10, v11, v01) = (
            (p(0.0, 0.0), [0.0, 1.0]),
            (p(1.0, 0.0), [1.0, 1.0]),
            (p(1.0, 1.0), [1.0, 0.0]),
            (p(0.0, 1.0), [0.0, 0.0]),
        );
        tris.push([v00, v10, v11]);
        tris.push([v00, v11, v01]);
    }
    Mesh { tris, texture: 1 }
}

/// One textured pixel the raster loop produced: where, its query (the
/// derivatives from its quad), which texture, and the light-space
/// position for the shadow test.
#[derive(Clone, Copy)]
struct Frag {
    x: usize,
    y: usize,
    query: Query,
    texture: usize,
    light: [f32; 3],
}

/// Rasterize `meshes` seen through `view_proj` into `depth`, calling
/// `emit` per covered pixel of every 2×2 quad with its query (coarse
/// derivatives from the quad, helper pixels included as GPUs run them).
/// `light` maps a world position to light space (u, v, depth).
fn raster(
    meshes: &[Mesh],
    view_proj: &M4,
    (w, h): (usize, usize),
    depth: &mut [f32],
    light: &dyn Fn(V3) -> [f32; 3],
    emit: &mut dyn FnMut(&[Option<Frag>; 4]),
) {
    for m in meshes {
        for t in &m.tris {
            let verts: Vec<Vert> = t
                .iter()
                .map(|&(p, uv)| Vert {
                    clip: view_proj.apply(p),
                    uv,
                    world: p,
                })
                .collect();
            let poly = clip_near(&verts);
            for k in 1..poly.len().saturating_sub(1) {
                triangle(
                    [&poly[0], &poly[k], &poly[k + 1]],
                    m.texture,
                    (w, h),
                    depth,
                    light,
                    emit,
                );
            }
        }
    }
}

fn triangle(
    v: [&Vert; 3],
    texture: usize,
    (w, h): (usize, usize),
    depth: &mut [f32],
    light: &dyn Fn(V3) -> [f32; 3],
    emit: &mut dyn FnMut(&[Option<Frag>; 4]),
) {
    // Screen positions; attributes divided by w for perspective-correct
    // interpolation.
    let s: Vec<[f32; 4]> = v
        .iter()
        .map(|v| {
            let iw = 1.0 / v.clip[3];
            [
                (v.clip[0] * iw * 0.5 + 0.5) * w as f32,
                (0.5 - v.clip[1] * iw * 0.5) * h as f32,
                v.clip[2] * iw,
                iw,
            ]
        })
        .collect();
    let area =
        (s[1][0] - s[0][0]) * (s[2][1] - s[0][1]) - (s[2][0] - s[0][0]) * (s[1][1] - s[0][1]);
    if area.abs() < 1e-9 {
        return;
    }
    let min_x = s.iter().map(|p| p[0]).fold(f32::MAX, f32::min).max(0.0) as usize & !1;
    let min_y = s.iter().map(|p| p[1]).fold(f32::MAX, f32::min).max(0.0) as usize & !1;
    let max_x = (s.iter().map(|p| p[0]).fold(f32::MIN, f32::max).ceil() as usize).min(w);
    let max_y = (s.iter().map(|p| p[1]).fold(f32::MIN, f32::max).ceil() as usize).min(h);
    let bary = |px: f32, py: f32| {
        let e =
            |a: &[f32; 4], b: &[f32; 4]| (b[0] - a[0]) * (py - a[1]) - (b[1] - a[1]) * (px - a[0]);
        [
            e(&s[1], &s[2]) / area,
            e(&s[2], &s[0]) / area,
            e(&s[0], &s[1]) / area,
        ]
    };
    for qy in (min_y..max_y).step_by(2) {
        for qx in (min_x..max_x).step_by(2) {
            let mut b = [[0.0f32; 3]; 4];
            let mut covered = [false; 4];
            for (k, (dx, dy)) in [(0, 0), (1, 0), (0, 1), (1, 1)].into_iter().enumerate() {
                let (px, py) = (qx + dx, qy + dy);
                b[k] = bary(px as f32 + 0.5, py as f32 + 0.5);
                covered[k] = px < w && py < h && b[k].iter().all(|&x| x >= 0.0);
            }
            if !covered.iter().any(|&c| c) {
                continue;
            }
            // Perspective-correct attributes at the four pixel centres
            // (helpers outside the triangle extrapolate, as on a GPU).
            let attr = |b: &[f32; 3]| {
                let iw: f32 = (0..3).map(|i| b[i] * s[i][3]).sum();
                let get = |f: &dyn Fn(&Vert) -> f32| -> f32 {
                    (0..3).map(|i| b[i] * s[i][3] * f(v[i])).sum::<f32>() / iw
                };
                (
                    [get(&|v| v.uv[0]), get(&|v| v.uv[1])],
                    [
                        get(&|v| v.world[0]),
                        get(&|v| v.world[1]),
                        get(&|v| v.world[2]),
                    ],
                    (0..3).map(|i| b[i] * s[i][2]).sum::<f32>(),
                )
            };
            let a: Vec<_> = b.iter().map(attr).collect();
            let uv = [a[0].0, a[1].0, a[2].0, a[3].0];
            let queries = parvo::sample::quad_queries(&uv);
            let mut frags = [None; 4];
            for k in 0..4 {
                let (px, py) = (qx + (k & 1), qy + (k >> 1));
                if !covered[k] {
                    continue;
                }
                let z = a[k].2;
                let d = &mut depth[py * w + px];
                if z < *d {
                    *d = z;
                    frags[k] = Some(Frag {
                        x: px,
                        y: py,
                        query: queries[k],
                        texture,
                        light: light(a[k].1),
                    });
                }
            }
            emit(&frags);
        }
    }
}

/// A brick wall texture, RGBA8 sRGB, 256², seamless.
fn bricks() -> Texture {
    let n = 256u32;
    let mut v = Vec::with_capacity((n * n * 4) as usize);
    let mut seed = 0x1234_5678u32;
    for y in 0..n {
        for x in 0..n {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            let row = y / 32;
            let xs = (x + if row % 2 == 1 { 32 } else { 0 }) % n;
            let mortar = y % 32 < 3 || xs % 64 < 3;
            let grain = (seed % 24) as u8;
            let px = if mortar {
                [190 + grain / 2, 185 + grain / 2, 170 + grain / 2, 255]
            } else {
                let tone = ((xs / 64 + row * 7) % 5) as u8 * 8;
                [150 + tone + grain, 60 + grain / 2, 45 + grain / 3, 255]
            };
            v.extend_from_slice(&px);
        }
    }
    Texture::from_u8(n, n, Format::new(4, ChannelType::U8, ColorSpace::Srgb), v).unwrap()
}

struct Scene {
    meshes: Vec<Mesh>,
    view_proj: M4,
    light_vp: M4,
    light_dir: V3,
}

fn scene() -> Scene {
    let view = M4::look_at([0.0, 2.2, 5.5], [0.0, 0.6, 0.0], [0.0, 1.0, 0.0]);
    let proj = M4::perspective(60f32.to_radians(), W as f32 / H as f32, 0.1, 100.0);
    let light_dir = norm([-0.6, 1.0, 0.45]);
    let lv = M4::look_at(
        [
            light_dir[0] * 10.0,
            light_dir[1] * 10.0,
            light_dir[2] * 10.0,
        ],
        [0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
    );
    Scene {
        meshes: vec![ground(), cube(0.55)],
        view_proj: proj.mul(&view),
        light_vp: M4::ortho(3.5, 1.0, 60.0).mul(&lv),
        light_dir,
    }
}

/// World position to light space: shadow-map (u, v) and depth in [0, 1].
fn to_light(light_vp: &M4, p: V3) -> [f32; 3] {
    let c = light_vp.apply(p);
    [c[0] * 0.5 + 0.5, 0.5 - c[1] * 0.5, c[2] * 0.5 + 0.5]
}

/// The shadow map: the cube's depth seen from the light, 1-channel f32.
fn shadow_map(s: &Scene) -> Texture {
    let mut depth = vec![1.0f32; SHADOW * SHADOW];
    let id = |_: V3| [0.0; 3];
    let mut frags = Vec::new();
    raster(
        &s.meshes[1..],
        &s.light_vp,
        (SHADOW, SHADOW),
        &mut depth,
        &id,
        &mut |f| frags.extend(f.iter().flatten().copied()),
    );
    // NDC depth −1…1 to 0…1.
    let d: Vec<f32> = depth
        .iter()
        .map(|&z| if z >= 1.0 { 1.0 } else { z * 0.5 + 0.5 })
        .collect();
    Texture::from_f32(
        SHADOW as u32,
        SHADOW as u32,
        Format::new(1, ChannelType::F32, ColorSpace::Linear),
        d,
    )
    .unwrap()
}

fn samplers(textures: &[parvo::MipChain; 2], o: SamplerOptions) -> [Sampler; 2] {
    [
        Sampler::new(&textures[0], o).unwrap(),
        Sampler::new(&textures[1], o).unwrap(),
    ]
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

/// Timed rounds per column ([`rates`]).
const ROUNDS: usize = 9;

/// M lookups/s of each column `(n, f)` (`f` does `n` lookups): every
/// column run once to warm up, then [`ROUNDS`] rounds that each run every
/// column once, each round starting at the next column; the median of
/// each column's rounds. Interleaved so that a column's neighbours in
/// the table were timed seconds apart, not a whole column apart: on a
/// VM whose speed drifts over seconds, ratios of columns timed one after
/// the other drift with it.
fn rates(cols: &mut [(usize, &mut dyn FnMut())]) -> Vec<f64> {
    cols.iter_mut().for_each(|(_, f)| f());
    let mut runs = vec![Vec::with_capacity(ROUNDS); cols.len()];
    for round in 0..ROUNDS {
        for k in 0..cols.len() {
            let c = (round + k) % cols.len();
            let (n, f) = &mut cols[c];
            let t = Instant::now();
            f();
            runs[c].push(*n as f64 / t.elapsed().as_secs_f64() / 1e6);
        }
    }
    runs.into_iter().map(median).collect()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let json = args.iter().any(|a| a == "--json");
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1).cloned())
    };
    let out = value("--out").unwrap_or_else(|| "target/rasterizer.png".into());
    let filter = value("--filter").unwrap_or_else(|| "trilinear".into());

    let s = scene();
    let opts = MipOptions::with_filter(MipFilter::Kaiser);
    let textures = [
        mip::build(bricks(), &opts)?,
        mip::build(parvo::builtin::load("builtin:photo:512")?, &opts)?,
    ];
    let shadow = parvo::MipChain::from_levels(vec![shadow_map(&s)], MipOptions::default())?;
    let shadow = Sampler::new(
        &shadow,
        SamplerOptions {
            mag: TexelFilter::Linear,
            min: TexelFilter::Linear,
            mip: MipMode::None,
            wrap: Wrap::both(WrapMode::ClampToBorder),
            border: [1.0; 4],
            ..Default::default()
        },
    )?;

    // The frame's fragments, in raster order, grouped by quad.
    let mut depth = vec![f32::INFINITY; W * H];
    let mut quads: Vec<[Option<Frag>; 4]> = Vec::new();
    let light = |p: V3| to_light(&s.light_vp, p);
    raster(
        &s.meshes,
        &s.view_proj,
        (W, H),
        &mut depth,
        &light,
        &mut |f| quads.push(*f),
    );
    // Later quads may hide earlier fragments: keep each pixel's last.
    let mut last = vec![usize::MAX; W * H];
    for (i, q) in quads.iter().enumerate() {
        for f in q.iter().flatten() {
            last[f.y * W + f.x] = i;
        }
    }
    let frags: Vec<Frag> = quads
        .iter()
        .enumerate()
        .flat_map(|(i, q)| {
            let last = &last;
            q.iter().flatten().filter(move |f| last[f.y * W + f.x] == i)
        })
        .copied()
        .collect();

    // Shade: texture × (ambient + diffuse × shadow).
    let sam = samplers(&textures, SamplerOptions::from_name(&filter)?);
    let mut rgb = vec![[0.55f32, 0.7, 0.9]; W * H];
    for f in &frags {
        let c = sam[f.texture].sample(&f.query);
        let lit = shadow.sample_compare_level(
            f.light[0],
            f.light[1],
            0.0,
            f.light[2] - 0.004,
            CompareOp::LessEqual,
        );
        let n_dot_l = if f.texture == 0 { s.light_dir[1] } else { 0.8 };
        let k = 0.3 + 0.7 * n_dot_l * lit;
        rgb[f.y * W + f.x] = [c[0] * k, c[1] * k, c[2] * k];
    }
    let bytes: Vec<u8> = rgb
        .iter()
        .flat_map(|c| c.map(parvo::texel::srgb::encode_u8))
        .collect();
    image::RgbImage::from_raw(W as u32, H as u32, bytes)
        .ok_or("frame buffer size")?
        .save(&out)?;

    if !json {
        println!(
            "{out}: {W}x{H}, {} textured pixels ({} on the ground), filter {filter}",
            frags.len(),
            frags.iter().filter(|f| f.texture == 0).count()
        );
        return Ok(());
    }
    // Timing: the frame's lookups on one thread, per filter.
    let queries: Vec<Query> = frags.iter().map(|f| f.query).collect();
    let ground: Vec<Query> = frags
        .iter()
        .filter(|f| f.texture == 0)
        .map(|f| f.query)
        .collect();
    let unit: Vec<Query> = ground
        .iter()
        .map(|q| q.at(q.u - q.u.floor(), q.v - q.v.floor()))
        .collect();
    let quad_uv: Vec<(usize, [[f32; 2]; 4])> = quads
        .iter()
        .filter_map(|q| {
            let f = q.iter().flatten().next()?;
            // The quad's four positions from any fragment's query and its
            // derivatives (the coarse rule makes them exact).
            let k = q.iter().position(|x| x.is_some())?;
            let (dx, dy) = ((k & 1) as f32, (k >> 1) as f32);
            let (u0, v0) = (
                f.query.u - dx * f.query.dudx - dy * f.query.dudy,
                f.query.v - dx * f.query.dvdx - dy * f.query.dvdy,
            );
            let at = |x: f32, y: f32| {
                [
                    u0 + x * f.query.dudx + y * f.query.dudy,
                    v0 + x * f.query.dvdx + y * f.query.dvdy,
                ]
            };
            Some((
                f.texture,
                [at(0.0, 0.0), at(1.0, 0.0), at(0.0, 1.0), at(1.0, 1.0)],
            ))
        })
        .collect();
    // The frame's queries with their textures, as a deferred renderer
    // batches them: one slice per texture.
    let per_texture: [Vec<Query>; 2] = [0, 1].map(|t| {
        frags
            .iter()
            .filter(|f| f.texture == t)
            .map(|f| f.query)
            .collect()
    });
    let mut rows = Vec::new();
    // `--only NAME` times one filter (for a profiler's run).
    let only = value("--only");
    for name in ["nearest", "bilinear", "trilinear", "aniso16", "ewa"] {
        if only.as_deref().is_some_and(|o| o != name) {
            continue;
        }
        let sam = samplers(&textures, SamplerOptions::from_name(name)?);
        // The same slices with the AVX-512 paths off: the per-lookup code
        // a single call runs, batched (single / this is what a call costs
        // beyond the lookup itself).
        let mut plain = samplers(&textures, SamplerOptions::from_name(name)?);
        plain.iter_mut().for_each(|s| s.set_simd(false));
        // One output buffer per column: the columns' closures live
        // together.
        let mut buffers: [Vec<[f32; 4]>; 4] =
            std::array::from_fn(|_| vec![[0f32; 4]; queries.len()]);
        let [b_slice, b_wrapped, b_unit, b_portable] = &mut buffers;
        let by_texture = |sam: &[Sampler; 2], out: &mut [[f32; 4]]| {
            for (t, qs) in per_texture.iter().enumerate() {
                sam[t].sample_slice(qs, &mut out[..qs.len()]).unwrap();
            }
            black_box(&out);
        };
        let mut single = || {
            for f in &frags {
                black_box(sam[f.texture].sample(black_box(&f.query)));
            }
        };
        let mut quad = || {
            for (t, uv) in &quad_uv {
                black_box(sam[*t].sample_quad(black_box(uv)));
            }
        };
        let mut slice = || by_texture(&sam, b_slice);
        let mut wrapped = || {
            sam[0]
                .sample_slice(&ground, &mut b_wrapped[..ground.len()])
                .unwrap();
            black_box(&b_wrapped);
        };
        let mut unit_slice = || {
            sam[0]
                .sample_slice(&unit, &mut b_unit[..unit.len()])
                .unwrap();
            black_box(&b_unit);
        };
        let mut portable_slice = || by_texture(&plain, b_portable);
        let r = rates(&mut [
            (frags.len(), &mut single),
            (quad_uv.len() * 4, &mut quad),
            (queries.len(), &mut slice),
            (ground.len(), &mut wrapped),
            (unit.len(), &mut unit_slice),
            (queries.len(), &mut portable_slice),
        ]);
        let [single, quad, slice, wrapped, unit_rate, portable] =
            [r[0], r[1], r[2], r[3], r[4], r[5]];
        rows.push(format!(
            "{{\"name\": \"{name}\", \"single_mps\": {single:.2}, \"quad_mps\": {quad:.2}, \
             \"slice_mps\": {slice:.2}, \"portable_slice_mps\": {portable:.2}, \
             \"wrapped_mps\": {wrapped:.2}, \"unit_mps\": {unit_rate:.2}}}"
        ));
    }
    println!(
        "{{\"pixels\": {}, \"ground_pixels\": {}, \"filters\": [{}]}}",
        frags.len(),
        ground.len(),
        rows.join(", ")
    );
    Ok(())
}
