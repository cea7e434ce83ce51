//! The environment scenes (`sky`, `sphere`) against independent geometry:
//! the sky's centre ray points where its yaw and pitch say and its frame
//! edges sit at the field of view; the sphere's lookups follow the mirror
//! law, checked with a ray-sphere hit found by bisection; every difference
//! across the lat-long seam takes the short way.

use parvo::env::latlong::{direction_to_st, st_to_direction};
use parvo::scene::{Frame, Scene, Sky, Sphere};

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let l = dot(a, a).sqrt();
    a.map(|c| c / l)
}

/// Distance between two (s, t) with s periodic.
fn st_dist(a: (f64, f64), b: (f64, f64)) -> f64 {
    let ds = (a.0 - b.0).rem_euclid(1.0);
    ds.min(1.0 - ds).max((a.1 - b.1).abs())
}

#[test]
fn the_sky_looks_where_its_yaw_and_pitch_say() {
    for (w, h) in [(64u32, 48u32), (33, 17), (200, 100)] {
        for (yaw, pitch, fov) in [(0.0, 0.0, 90.0), (20.0, 35.0, 100.0), (-130.0, 60.0, 45.0)] {
            let k = Sky {
                fov_y: f64::to_radians(fov),
                pitch: f64::to_radians(pitch),
                yaw: f64::to_radians(yaw),
            };
            let s = Scene::Sky(k);
            let f = Frame::new(w, h);
            let tex = (512, 256);
            // The frame's centre: longitude yaw, elevation pitch.
            let c = s.uv(f, tex, w as f64 / 2.0, h as f64 / 2.0).unwrap();
            let want = ((0.5 + yaw / 360.0).rem_euclid(1.0), 0.5 - pitch / 180.0);
            assert!(
                st_dist(c, want) < 1e-12,
                "{w}x{h} {yaw} {pitch}: {c:?} {want:?}"
            );
            // The middle of the top edge: fov/2 above the centre, in the
            // same vertical plane (same longitude unless past the pole).
            let top = s.uv(f, tex, w as f64 / 2.0, 0.0).unwrap();
            let elev = pitch + fov / 2.0;
            if elev < 90.0 {
                let want = ((0.5 + yaw / 360.0).rem_euclid(1.0), 0.5 - elev / 180.0);
                assert!(st_dist(top, want) < 1e-12, "{top:?} {want:?}");
            }
            // The middle of the left and right edges: the horizontal field
            // of view, atan(tan(fov/2)·aspect), from the centre ray, and the
            // right edge at the larger s.
            let half = (f64::to_radians(fov) / 2.0).tan() * w as f64 / h as f64;
            let d = |p: (f64, f64)| st_to_direction(p.0, p.1);
            for x in [0.0, w as f64] {
                let e = s.uv(f, tex, x, h as f64 / 2.0).unwrap();
                let angle = dot(d(c), d(e)).clamp(-1.0, 1.0).acos();
                assert!(
                    (angle - half.atan()).abs() < 1e-9,
                    "{angle} {}",
                    half.atan()
                );
            }
            let (l, r) = (
                s.uv(f, tex, w as f64 / 2.0 - 1.0, h as f64 / 2.0).unwrap(),
                s.uv(f, tex, w as f64 / 2.0 + 1.0, h as f64 / 2.0).unwrap(),
            );
            let ds = (r.0 - l.0 + 0.5).rem_euclid(1.0) - 0.5;
            assert!(ds > 0.0, "moving right turns towards larger s: {l:?} {r:?}");
        }
    }
}

/// The reflection seen at screen position (x, y) of the default sphere,
/// found independently: the pinhole ray from (0, 0, d) down −z (+x to the
/// right, +y up), its first hit on the unit sphere by bisection along the
/// ray, the mirror law about the normal there.
fn reflection(k: &Sphere, f: Frame, x: f64, y: f64) -> Option<[f64; 3]> {
    let (w, h) = (f.width as f64, f.height as f64);
    let tan = (k.fov_y / 2.0).tan();
    let nx = (2.0 * x / w - 1.0) * tan * w / h;
    let ny = (1.0 - 2.0 * y / h) * tan;
    let d = unit([nx, ny, -1.0]);
    let o = [0.0, 0.0, k.distance];
    let at = |t: f64| [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]];
    // Closest approach to the centre; a miss if it is outside the sphere.
    let tc = -dot(o, d);
    if dot(at(tc), at(tc)) > 1.0 {
        return None;
    }
    let (mut lo, mut hi) = (0.0, tc);
    for _ in 0..200 {
        let m = 0.5 * (lo + hi);
        if dot(at(m), at(m)) > 1.0 {
            lo = m;
        } else {
            hi = m;
        }
    }
    let n = unit(at(0.5 * (lo + hi)));
    let dn = dot(d, n);
    Some([0, 1, 2].map(|i| d[i] - 2.0 * dn * n[i]))
}

#[test]
fn the_sphere_reflects_by_the_mirror_law() {
    let k = Sphere::default();
    let s = Scene::Sphere(k);
    for (w, h) in [(97u32, 61u32), (64, 64)] {
        let f = Frame::new(w, h);
        let mut hits = 0;
        for j in 0..h {
            for i in 0..w {
                let (x, y) = (i as f64 + 0.37, j as f64 + 0.61);
                let got = s.uv(f, (512, 256), x, y);
                match (got, reflection(&k, f, x, y)) {
                    (Some(g), Some(r)) => {
                        hits += 1;
                        // Near the silhouette the reflection turns fast:
                        // compare directions, not (s, t) (s is loose at the
                        // poles).
                        let a = st_to_direction(g.0, g.1);
                        let angle = dot(a, unit(r)).clamp(-1.0, 1.0).acos();
                        assert!(angle < 1e-6, "({x}, {y}): {angle}");
                    }
                    (None, None) => {}
                    (g, r) => {
                        // Only a ray that grazes the sphere may disagree.
                        let tan = (k.fov_y / 2.0).tan();
                        let nx = (2.0 * x / w as f64 - 1.0) * tan * w as f64 / h as f64;
                        let ny = (1.0 - 2.0 * y / h as f64) * tan;
                        let d = unit([nx, ny, -1.0]);
                        let miss = k.distance * k.distance * (1.0 - d[2] * d[2]);
                        assert!((miss - 1.0).abs() < 1e-9, "({x}, {y}): {g:?} vs {r:?}");
                    }
                }
            }
        }
        // The sphere covers π(0.85/2)² of the frame's height squared.
        let want = std::f64::consts::PI * (0.425 * h as f64).powi(2);
        assert!(
            (hits as f64 / want - 1.0).abs() < 0.05,
            "{hits} pixels on the sphere, {want} expected"
        );
        // The centre reflects straight back at the camera: s = t = 1/2.
        let c = s.uv(f, (512, 256), w as f64 / 2.0, h as f64 / 2.0).unwrap();
        assert!(st_dist(c, (0.5, 0.5)) < 1e-12, "{c:?}");
        assert_eq!(direction_to_st([0.0, 0.0, 1.0]), (0.5, 0.5));
    }
}

#[test]
fn differences_cross_the_lat_long_seam_the_short_way() {
    for (scene, f) in [
        (Scene::Sky(Sky::default()), Frame::new(96, 64)),
        (
            Scene::Sky(Sky {
                yaw: std::f64::consts::PI,
                ..Sky::default()
            }),
            Frame::new(96, 64),
        ),
        (Scene::Sphere(Sphere::default()), Frame::new(96, 96)),
    ] {
        let tex = (1024, 512);
        let mut seen = 0;
        for py in 0..f.height {
            for px in 0..f.width {
                let Some(q) = scene.query(f, tex, px, py) else {
                    continue;
                };
                seen += 1;
                for d in [q.dudx, q.dudy] {
                    assert!(d.abs() <= 0.5, "{scene} ({px}, {py}): {q:?}");
                }
                // And they are the differences of the mapping.
                let (x, y) = (px as f64 + 0.5, py as f64 + 0.5);
                let (l, r) = (
                    scene.uv(f, tex, x - 0.5, y).unwrap(),
                    scene.uv(f, tex, x + 0.5, y).unwrap(),
                );
                let du = (r.0 - l.0 + 0.5).rem_euclid(1.0) - 0.5;
                assert!((du - q.dudx as f64).abs() < 1e-6, "{du} {}", q.dudx);
                assert!(((r.1 - l.1) - q.dvdx as f64).abs() < 1e-6);
            }
        }
        if let Scene::Sky(_) = scene {
            assert_eq!(seen, f.pixels(), "the sky fills the frame");
        } else {
            assert!(seen > 0);
        }
    }
}

#[test]
fn environment_scenes_repeat_in_s_and_clamp_in_t() {
    use parvo::wrap::WrapMode;
    for s in ["sky", "sphere"] {
        let scene: Scene = s.parse().unwrap();
        assert!(scene.is_environment());
        let w = scene.wrap().unwrap();
        assert_eq!((w.u, w.v), (WrapMode::Repeat, WrapMode::ClampToEdge));
    }
    let plane: Scene = "plane".parse().unwrap();
    assert!(!plane.is_environment() && plane.wrap().is_none());
}
