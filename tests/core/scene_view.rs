//! A scene set up once per frame (`Scene::view`) gives the same texture
//! coordinates and queries, to the last bit, as the per-pixel formulas it
//! replaced: those formulas are restated here as they were (a tangent and
//! a sine and cosine per call) and every pixel of several frames, odd
//! sizes among them, is compared, for every scene, through both the
//! per-frame view and the per-call `Scene` methods.

use parvo::sample::Query;
use parvo::scene::{Frame, Plane, RasterOrder, Scene};

/// The ground plane as `Plane::uv` computed it per call.
fn plane_uv(p: &Plane, frame: Frame, sx: f64, sy: f64) -> Option<(f64, f64)> {
    let (w, h) = (frame.width as f64, frame.height as f64);
    let t = (p.fov_y * 0.5).tan();
    let nx = (sx / w * 2.0 - 1.0) * t * (w / h);
    let ny = (1.0 - sy / h * 2.0) * t;
    let (sp, cp) = p.pitch.sin_cos();
    let dx = nx;
    let dy = -sp + ny * cp;
    let dz = cp + ny * sp;
    if dy >= -1e-9 {
        return None;
    }
    let k = p.camera_height / -dy;
    let (x, z) = (dx * k, dz * k);
    if (x * x + z * z).sqrt() > p.max_distance {
        return None;
    }
    Some((0.5 + x * p.uv_per_unit, z * p.uv_per_unit))
}

/// `Scene::uv` as it was: the set-up of every scene repeated per call.
fn old_uv(scene: &Scene, frame: Frame, tex: (u32, u32), x: f64, y: f64) -> Option<(f64, f64)> {
    let (w, h) = (frame.width as f64, frame.height as f64);
    let (tw, th) = (tex.0.max(1) as f64, tex.1.max(1) as f64);
    match scene {
        Scene::Plane(p) => plane_uv(p, frame, x, y),
        Scene::Tunnel(t) => {
            let tan = (t.fov_y * 0.5).tan();
            let nx = (x / w * 2.0 - 1.0) * tan * (w / h);
            let ny = (1.0 - y / h * 2.0) * tan;
            let r = (nx * nx + ny * ny).sqrt();
            if r < 1e-12 {
                return None;
            }
            let z = 1.0 / r;
            if z > t.max_distance {
                return None;
            }
            let angle = ny.atan2(nx) / std::f64::consts::TAU + 0.5;
            Some((angle * t.repeats_around, z * t.v_per_unit))
        }
        Scene::Zoom(z) => {
            let k = (z.lod_right - z.lod_left) / w;
            let s = (z.lod_left + k * x).exp2();
            let u = if k.abs() < 1e-15 {
                s * x
            } else {
                (s - z.lod_left.exp2()) / (k * std::f64::consts::LN_2)
            };
            Some((u / tw, 0.5 + (y - h * 0.5) * s / th))
        }
        Scene::Rotate(r) => {
            let (sn, cs) = r.degrees.to_radians().sin_cos();
            let (dx, dy) = (x - w * 0.5, y - h * 0.5);
            Some((
                0.5 + (cs * dx - sn * dy) * r.scale / tw,
                0.5 + (sn * dx + cs * dy) * r.scale / th,
            ))
        }
        // The environment scenes came with the per-frame view; their
        // geometry is checked against ray tracing in tests/core/scene_env.rs.
        Scene::Sky(_) | Scene::Sphere(_) => unreachable!("not in scenes()"),
    }
}

/// `Scene::query_at` as it was.
fn old_query(scene: &Scene, frame: Frame, tex: (u32, u32), x: f64, y: f64) -> Option<Query> {
    let at = |x: f64, y: f64| old_uv(scene, frame, tex, x, y);
    let c = at(x, y)?;
    let (l, r) = (at(x - 0.5, y)?, at(x + 0.5, y)?);
    let (t, b) = (at(x, y - 0.5)?, at(x, y + 0.5)?);
    let period = match scene {
        Scene::Tunnel(t) => Some(t.repeats_around),
        _ => None,
    };
    let d = |a: f64, b: f64| match period {
        Some(p) => {
            let mut v = b - a;
            v -= (v / p).round() * p;
            v
        }
        None => b - a,
    };
    Some(Query::new(
        c.0 as f32,
        c.1 as f32,
        d(l.0, r.0) as f32,
        (r.1 - l.1) as f32,
        d(t.0, b.0) as f32,
        (b.1 - t.1) as f32,
    ))
}

fn bits(q: Option<Query>) -> Option<[u32; 6]> {
    q.map(|q| [q.u, q.v, q.dudx, q.dvdx, q.dudy, q.dvdy].map(f32::to_bits))
}

fn uv_bits(p: Option<(f64, f64)>) -> Option<(u64, u64)> {
    p.map(|(u, v)| (u.to_bits(), v.to_bits()))
}

fn scenes() -> Vec<Scene> {
    let mut s: Vec<Scene> = ["plane", "tunnel", "zoom", "rotate:30", "rotate:-17.5:3.7"]
        .iter()
        .map(|n| n.parse().unwrap())
        .collect();
    // A camera that sees the horizon inside the frame and far hits.
    s.push(Scene::Plane(Plane {
        camera_height: 0.37,
        pitch: 3f64.to_radians(),
        fov_y: 71f64.to_radians(),
        uv_per_unit: 1.3,
        max_distance: 40.0,
    }));
    s
}

#[test]
fn every_pixel_of_a_view_equals_the_per_pixel_formula_to_the_bit() {
    let tex = (1000, 333);
    for scene in scenes() {
        for frame in [Frame::new(33, 17), Frame::new(1, 1), Frame::new(257, 129)] {
            let view = scene.view(frame, tex);
            let mut shown = 0;
            for py in 0..frame.height {
                for px in 0..frame.width {
                    let (x, y) = (px as f64 + 0.5, py as f64 + 0.5);
                    let want = bits(old_query(&scene, frame, tex, x, y));
                    shown += want.is_some() as u32;
                    let what = format!("{scene} {frame} ({px}, {py})");
                    assert_eq!(bits(view.query(px, py)), want, "{what}: view");
                    assert_eq!(bits(view.query_at(x, y)), want, "{what}: view at");
                    assert_eq!(bits(scene.query(frame, tex, px, py)), want, "{what}: scene");
                    // Off the pixel grid (the flicker metric's offsets, the
                    // reference image's subsamples).
                    let (ox, oy) = (x + 0.3125, y - 0.2703);
                    let want = uv_bits(old_uv(&scene, frame, tex, ox, oy));
                    assert_eq!(uv_bits(view.uv(ox, oy)), want, "{what}: uv");
                    assert_eq!(
                        uv_bits(scene.uv(frame, tex, ox, oy)),
                        want,
                        "{what}: scene uv"
                    );
                    assert_eq!(
                        bits(view.query_at(ox, oy)),
                        bits(old_query(&scene, frame, tex, ox, oy)),
                        "{what}: offset query"
                    );
                }
            }
            if frame.pixels() > 1 {
                assert!(shown > 0, "{scene} {frame} shows nothing");
            }
        }
    }
}

/// The frame of the benchmark, every pixel of it.
#[test]
fn the_1080p_plane_frame_is_unchanged() {
    let scene = Scene::default();
    let frame = Frame::new(1920, 1080);
    let tex = (4096, 4096);
    let view = scene.view(frame, tex);
    let mut shown = 0u64;
    for py in 0..frame.height {
        for px in 0..frame.width {
            let want = bits(old_query(
                &scene,
                frame,
                tex,
                px as f64 + 0.5,
                py as f64 + 0.5,
            ));
            shown += want.is_some() as u64;
            assert_eq!(bits(view.query(px, py)), want, "({px}, {py})");
        }
    }
    assert_eq!(shown, 1_547_572, "the pixels the issue's run reports");
}

/// The collected orders are the iterators' orders; quads cover every
/// pixel once, in tiles of the same pixel size.
#[test]
fn pixel_lists_and_quads_cover_the_frame_once() {
    for frame in [Frame::new(13, 7), Frame::new(16, 16), Frame::new(1, 5)] {
        for order in [
            "scanline", "tiled:1", "tiled:4", "tiled:5", "morton", "hilbert",
        ] {
            let order: RasterOrder = order.parse().unwrap();
            let list = order.pixel_list(frame);
            assert_eq!(list, order.pixels(frame).collect::<Vec<_>>(), "{order}");
            let mut seen = vec![0u32; frame.pixels() as usize];
            for (qx, qy) in order.quads(frame) {
                for (x, y) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let (x, y) = (2 * qx + x, 2 * qy + y);
                    if x < frame.width && y < frame.height {
                        seen[(y * frame.width + x) as usize] += 1;
                    }
                }
            }
            assert!(seen.iter().all(|&n| n == 1), "{order} {frame}: {seen:?}");
        }
    }
    // tiled:8 visits 8x8-pixel tiles: the first 16 quads are the top-left
    // tile's 4x4.
    let q = RasterOrder::Tiled(8).quads(Frame::new(64, 64));
    assert!(q[..16].iter().all(|&(x, y)| x < 4 && y < 4));
}
