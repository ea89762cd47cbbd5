//! Watertightness: closed meshes, needle fans/strips, random triangulations of a square, and
//! meshes cut by the near plane and the guard band, for both coverage models.

use crate::raster_common::*;
use glam::{DMat4, DVec3};
use texsim::raster::{coverage_count, setup, Coverage, DrawTri};

const BOTH: [Coverage; 2] = [Coverage::Fixed, Coverage::Float];

fn reversed(t: &[[u32; 3]]) -> Vec<[u32; 3]> {
    t.iter().map(|&[a, b, c]| [a, c, b]).collect()
}

/// Front count f, back count b, total c: f == b, c == f + b, f <= 1 (convex), f == 1 inside
/// `r_in` and 0 outside `r_out` of `centre` (pixels).
#[allow(clippy::too_many_arguments)]
fn check_convex_closed(
    clip: &[[f64; 4]],
    tris: &[[u32; 3]],
    w: u32,
    h: u32,
    sp: u32,
    centre: [f64; 2],
    r_in: f64,
    r_out: f64,
    min_sp_single: u32,
) {
    let c = cfg(sp, 24);
    let suspect = float_suspect_mask(clip, tris, &setup(clip, &draws(tris, false), w, h, &c));
    let n_suspect = suspect.iter().filter(|&&m| m).count();
    let limit = if sp >= min_sp_single { 40 } else { 8 };
    eprintln!("sp={sp}: {n_suspect} float-suspect pixels");
    assert!(
        n_suspect * limit < (w * h) as usize,
        "too many suspect pixels: {n_suspect}"
    );
    for cov in BOTH {
        let front = coverage_count(&setup(clip, &draws(tris, true), w, h, &c), cov);
        let back = coverage_count(&setup(clip, &draws(&reversed(tris), true), w, h, &c), cov);
        let all = coverage_count(&setup(clip, &draws(tris, false), w, h, &c), cov);
        let mut inside = 0u64;
        for py in 0..h {
            for px in 0..w {
                let i = (py * w + px) as usize;
                let at = format!("{cov:?} sp={sp} pixel ({px},{py})");
                let d = ((f64::from(px) + 0.5 - centre[0]).powi(2)
                    + (f64::from(py) + 0.5 - centre[1]).powi(2))
                .sqrt();
                // Exact for any closed mesh: the front and back layers cancel.
                assert_eq!(all[i], front[i] + back[i], "{at}: culled vs unculled");
                // Orientation and degeneracy are decided on snapped positions; where the
                // float twin disagrees (slivers), only the fixed model is exact.
                let exact = cov == Coverage::Fixed || !suspect[i];
                if exact {
                    assert_eq!(front[i], back[i], "{at}: front vs back layers");
                }
                // Snapping can fold the front layer at the silhouette (coarse grids only).
                if exact && (sp >= min_sp_single || d < r_in || d > r_out) {
                    assert!(front[i] <= 1, "{at}: front covered {} times", front[i]);
                }
                if d < r_in && exact {
                    assert_eq!(front[i], 1, "{at}: hole inside the silhouette");
                    inside += 1;
                }
                if d > r_out {
                    assert_eq!(front[i], 0, "{at}: covered outside the silhouette");
                }
            }
        }
        assert!(inside > 1000, "test disc too small: {inside}");
    }
}

#[test]
fn sphere_orthographic_watertight() {
    let (p, t) = uv_sphere(64, 32);
    let (w, h) = (256u32, 192u32);
    for (k, sp) in [1u32, 4, 8, 12].into_iter().enumerate() {
        let rot =
            DMat4::from_rotation_x(0.3 + 0.2 * k as f64) * DMat4::from_rotation_y(0.7 * k as f64);
        // Orthographic: x, y scaled to a radius of 80 pixels, z into [-0.5, 0.5].
        let scale = DMat4::from_scale(DVec3::new(
            80.0 * 2.0 / f64::from(w),
            80.0 * 2.0 / f64::from(h),
            -0.5,
        ));
        let off = DMat4::from_translation(DVec3::new(0.013, -0.021, 0.0));
        let clip = transform(&(off * scale * rot), &p);
        let centre = [
            (0.013 + 1.0) * 0.5 * f64::from(w),
            (1.0 + 0.021) * 0.5 * f64::from(h),
        ];
        // The inscribed polyhedron's silhouette lies between 0.99 R and R.
        check_convex_closed(
            &clip,
            &t,
            w,
            h,
            sp,
            centre,
            80.0 * 0.98 - 1.0,
            80.0 + 1.0,
            4,
        );
    }
}

#[test]
fn sphere_perspective_watertight() {
    let (p, t) = uv_sphere(64, 32);
    let (w, h) = (240u32, 240u32);
    let fovy: f64 = 50f64.to_radians();
    let dist = 3.0;
    let view = DMat4::look_at_rh(DVec3::new(0.0, 0.0, dist), DVec3::ZERO, DVec3::Y);
    let proj = DMat4::perspective_rh_gl(fovy, 1.0, 0.5, 10.0);
    let model = DMat4::from_rotation_z(0.4) * DMat4::from_rotation_x(1.1);
    let clip = transform(&(proj * view * model), &p);
    // Silhouette of the unit sphere: a circle of radius tan(asin(1/d)) / tan(fovy/2) * h/2.
    let r = (1.0f64 / dist).asin().tan() / (fovy / 2.0).tan() * f64::from(h) / 2.0;
    for sp in [4u32, 8] {
        check_convex_closed(
            &clip,
            &t,
            w,
            h,
            sp,
            [120.0, 120.0],
            r * 0.98 - 1.0,
            r + 1.0,
            4,
        );
    }
}

/// A disc as a fan of `n` needle triangles around its centre, each vertex with a random w.
fn needle_fan(
    n: u32,
    centre: [f64; 2],
    r: f64,
    w: u32,
    h: u32,
    rng: &mut Rng,
) -> (Vec<[f64; 4]>, Vec<[u32; 3]>) {
    let mut v = vec![px_to_clip(centre[0], centre[1], 0.1, w, h)];
    for i in 0..n {
        let a = 2.0 * std::f64::consts::PI * f64::from(i) / f64::from(n);
        v.push(px_to_clip(
            centre[0] + r * a.cos(),
            centre[1] + r * a.sin(),
            0.2,
            w,
            h,
        ));
    }
    for c in &mut v {
        let s = rng.range(0.5, 3.0);
        *c = c.map(|x| x * s);
    }
    let t = (0..n).map(|i| [0, 1 + i, 1 + (i + 1) % n]).collect();
    (v, t)
}

#[test]
fn needle_fan_watertight() {
    let mut rng = Rng(7);
    let (w, h) = (256u32, 256u32);
    for sp in [2u32, 8, 12] {
        let n = 3000;
        let r = 110.0;
        let centre = [128.3, 127.9];
        let (v, t) = needle_fan(n, centre, r, w, h, &mut rng);
        let c = cfg(sp, 16);
        for cov in BOTH {
            let s = setup(&v, &draws(&t, false), w, h, &c);
            assert_eq!(
                s.stats.output + s.stats.degenerate,
                u64::from(n),
                "{:?}",
                s.stats
            );
            assert!(
                s.stats.output > 2000,
                "too many needles lost: {:?}",
                s.stats
            );
            let cnt = coverage_count(&s, cov);
            // Needles dropped as degenerate after snapping cover nothing in fixed (their
            // snapped area is zero) but leave float holes: excluded for the float model.
            let suspect = float_suspect_mask(&v, &t, &s);
            let dropped: Vec<bool> = suspect
                .iter()
                .map(|&m| m && cov == Coverage::Float)
                .collect();
            let r_in = r * (std::f64::consts::PI / f64::from(n)).cos() - 1.0;
            for py in 0..h {
                for px in 0..w {
                    let d = ((f64::from(px) + 0.5 - centre[0]).powi(2)
                        + (f64::from(py) + 0.5 - centre[1]).powi(2))
                    .sqrt();
                    let k = cnt[(py * w + px) as usize];
                    assert!(k <= 1, "{cov:?} sp={sp} ({px},{py}) covered {k} times");
                    if d < r_in && !dropped[(py * w + px) as usize] {
                        assert_eq!(k, 1, "{cov:?} sp={sp} hole at ({px},{py})");
                    }
                    if d > r + 1.0 {
                        assert_eq!(k, 0, "{cov:?} sp={sp} outside at ({px},{py})");
                    }
                }
            }
        }
    }
}

#[test]
fn needle_strip_watertight() {
    // Parallelogram strip of slanted needles 0.3 px wide and 150 px tall.
    let (w, h) = (256u32, 200u32);
    let (n, dx, y0, y1, slant) = (600u32, 0.3, 20.0, 170.0, 13.7);
    let mut v = Vec::new();
    for i in 0..=n {
        let x = 20.0 + dx * f64::from(i);
        v.push(px_to_clip(x + slant, y0, 0.0, w, h));
        v.push(px_to_clip(x, y1, 0.0, w, h));
    }
    let mut t = Vec::new();
    for i in 0..n {
        let (a, b, c, d) = (2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3);
        t.push([a, b, c]);
        t.push([b, d, c]);
    }
    for sp in [4u32, 8] {
        for cov in BOTH {
            let s = setup(&v, &draws(&t, false), w, h, &cfg(sp, 16));
            assert_eq!(s.stats.output, 2 * u64::from(n));
            let cnt = coverage_count(&s, cov);
            for py in 0..h {
                for px in 0..w {
                    let (x, y) = (f64::from(px) + 0.5, f64::from(py) + 0.5);
                    // Left/right sides of the parallelogram at this y.
                    let f = (y - y0) / (y1 - y0);
                    let xl = 20.0 + slant * (1.0 - f);
                    let xr = xl + dx * f64::from(n);
                    let k = cnt[(py * w + px) as usize];
                    assert!(k <= 1, "{cov:?} ({px},{py}) covered {k} times");
                    let inside = y > y0 + 0.01 && y < y1 - 0.01 && x > xl + 0.01 && x < xr - 0.01;
                    let outside = y < y0 || y > y1 || x < xl - 0.01 || x > xr + 0.01;
                    if inside {
                        assert_eq!(k, 1, "{cov:?} sp={sp} hole at ({px},{py})");
                    }
                    if outside {
                        assert_eq!(k, 0, "{cov:?} sp={sp} outside at ({px},{py})");
                    }
                }
            }
        }
    }
}

/// Random triangulation of the square [x0, x1) x [y0, y1) (pixels, exactly representable):
/// an n x m grid with jittered interior vertices (boundary vertices slide along the boundary),
/// random diagonals, random w on interior vertices. Expected coverage is exact, fill rule
/// included: a centre on the left/top side is in, on the right/bottom side out.
#[test]
fn random_square_triangulations_cover_once() {
    let mut rng = Rng(0x5eed);
    let (w, h) = (128u32, 128u32);
    for case in 0..40 {
        let x0 = 3.0 + rng.below(40) as f64 * 0.25;
        let y0 = 2.0 + rng.below(40) as f64 * 0.5;
        let x1 = 80.0 + rng.below(160) as f64 * 0.25;
        let y1 = 70.0 + rng.below(100) as f64 * 0.5;
        let n = 1 + rng.below(if case % 2 == 0 { 12 } else { 90 }) as u32;
        let m = 1 + rng.below(if case % 2 == 0 { 12 } else { 90 }) as u32;
        let jitter = if case % 5 == 4 { 0.0 } else { 0.2 };
        let mut v = Vec::new();
        for j in 0..=m {
            for i in 0..=n {
                let fx = f64::from(i) / f64::from(n);
                let fy = f64::from(j) / f64::from(m);
                let mut x = x0 + (x1 - x0) * fx;
                let mut y = y0 + (y1 - y0) * fy;
                let (cx, cy) = ((x1 - x0) / f64::from(n), (y1 - y0) / f64::from(m));
                if i == 0 {
                    x = x0;
                } else if i == n {
                    x = x1;
                } else {
                    x += rng.range(-jitter, jitter) * cx;
                }
                if j == 0 {
                    y = y0;
                } else if j == m {
                    y = y1;
                } else {
                    y += rng.range(-jitter, jitter) * cy;
                }
                let mut c = px_to_clip(x, y, rng.range(-0.9, 0.9), w, h);
                let interior = i > 0 && i < n && j > 0 && j < m;
                if interior && case % 3 != 0 {
                    let s = rng.range(0.25, 4.0);
                    c = c.map(|q| q * s);
                }
                v.push(c);
            }
        }
        let id = |i: u32, j: u32| j * (n + 1) + i;
        let mut t = Vec::new();
        for j in 0..m {
            for i in 0..n {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                if rng.below(2) == 0 {
                    t.push([a, b, c]);
                    t.push([a, c, d]);
                } else {
                    t.push([a, b, d]);
                    t.push([b, c, d]);
                }
            }
        }
        let sp = [1u32, 2, 4, 8, 12][case % 5];
        let s = setup(&v, &draws(&t, false), w, h, &cfg(sp, 24));
        for cov in BOTH {
            let cnt = coverage_count(&s, cov);
            for py in 0..h {
                for px in 0..w {
                    let (x, y) = (f64::from(px) + 0.5, f64::from(py) + 0.5);
                    let expect = u32::from(x >= x0 && x < x1 && y >= y0 && y < y1);
                    assert_eq!(
                        cnt[(py * w + px) as usize],
                        expect,
                        "case {case} {cov:?} sp={sp} n={n} m={m} pixel ({px},{py})"
                    );
                }
            }
        }
    }
}

/// Camera inside a closed sphere: every pixel is covered exactly once without culling, even
/// though many triangles cross the near plane and the guard band.
#[test]
fn camera_inside_sphere_near_and_guard_clipping() {
    let (w, h) = (160u32, 120u32);
    let mut clipped = 0;
    for (k, fov) in [60.0f64, 120.0, 170.0, 90.0].into_iter().enumerate() {
        // Coarse spheres have triangles that cross the near plane and the guard band.
        let (p, t) = if k % 2 == 0 {
            uv_sphere(48, 24)
        } else {
            uv_sphere(7, 4)
        };
        let view = DMat4::look_at_rh(
            DVec3::new(0.1, -0.05 * k as f64, 0.2),
            DVec3::new(1.0, 0.3, -0.2),
            DVec3::Y,
        );
        let proj = DMat4::perspective_rh_gl(fov.to_radians(), 4.0 / 3.0, 0.05, 10.0);
        let model = DMat4::from_scale(DVec3::splat(3.0));
        let clip = transform(&(proj * view * model), &p);
        for cov in BOTH {
            let s = setup(&clip, &draws(&t, false), w, h, &cfg(8, 24));
            clipped += s.stats.clipped;
            let cnt = coverage_count(&s, cov);
            assert!(
                cnt.iter().all(|&c| c == 1),
                "fov {fov} {cov:?}: counts {:?}",
                (0..=3)
                    .map(|v| cnt.iter().filter(|&&c| c == v).count())
                    .collect::<Vec<_>>()
            );
            // Seen from inside, outward-wound faces are back faces.
            let culled = setup(&clip, &draws(&t, true), w, h, &cfg(8, 24));
            assert!(coverage_count(&culled, cov).iter().all(|&c| c == 0));
            let inner = setup(&clip, &draws(&reversed(&t), true), w, h, &cfg(8, 24));
            assert!(coverage_count(&inner, cov).iter().all(|&c| c == 1));
        }
    }
    assert!(clipped > 0, "expected clipping");
}

/// A large ground plane, cut by the near plane and extending far beyond the guard band:
/// pixels whose ray hits the plane well inside it and beyond the near plane are covered once.
#[test]
fn ground_plane_near_and_guard_clipping() {
    let mut rng = Rng(99);
    let (w, h) = (200u32, 150u32);
    let n = 40u32;
    let half = 500.0;
    let mut pos = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let cell = 2.0 * half / f64::from(n);
            let mut x = -half + cell * f64::from(i);
            let mut z = -half + cell * f64::from(j);
            if i > 0 && i < n && j > 0 && j < n {
                x += rng.range(-0.2, 0.2) * cell;
                z += rng.range(-0.2, 0.2) * cell;
            }
            pos.push(DVec3::new(x, -1.0, z));
        }
    }
    let mut t = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let id = |i: u32, j: u32| j * (n + 1) + i;
            t.push([id(i, j), id(i, j + 1), id(i + 1, j + 1)]);
            t.push([id(i, j), id(i + 1, j + 1), id(i + 1, j)]);
        }
    }
    let eye = DVec3::new(3.0, 0.0, 7.0);
    let target = DVec3::new(2.0, -0.6, 0.0);
    let view = DMat4::look_at_rh(eye, target, DVec3::Y);
    let (near, far, fovy) = (0.1, 2000.0, 70f64.to_radians());
    let proj = DMat4::perspective_rh_gl(fovy, f64::from(w) / f64::from(h), near, far);
    let clip = transform(&(proj * view), &pos);
    let inv_vp = (proj * view).inverse();
    for cov in BOTH {
        let s = setup(&clip, &draws(&t, false), w, h, &cfg(8, 24));
        assert!(s.stats.clipped > 0);
        let cnt = coverage_count(&s, cov);
        let mut hits = 0;
        for py in 0..h {
            for px in 0..w {
                let k = cnt[(py * w + px) as usize];
                assert!(k <= 1, "{cov:?} ({px},{py}) covered {k} times");
                // Independent model: intersect the pixel-centre ray with y = -1.
                let xn = (f64::from(px) + 0.5) / f64::from(w) * 2.0 - 1.0;
                let yn = 1.0 - (f64::from(py) + 0.5) / f64::from(h) * 2.0;
                let a = inv_vp.project_point3(DVec3::new(xn, yn, -1.0));
                let b = inv_vp.project_point3(DVec3::new(xn, yn, 1.0));
                let d = b - a;
                if d.y >= 0.0 {
                    continue;
                }
                let hit = a + d * ((-1.0 - a.y) / d.y);
                let depth = (hit - eye).dot((target - eye).normalize());
                if hit.x.abs() < half * 0.95
                    && hit.z.abs() < half * 0.95
                    && depth > near * 1.5
                    && depth < far * 0.9
                {
                    assert_eq!(k, 1, "{cov:?} hole at ({px},{py})");
                    hits += 1;
                }
            }
        }
        assert!(hits > 5000, "too few ground pixels checked: {hits}");
    }
}

/// The random-square check against the brute-force model, with vertices on pixel centres.
#[test]
fn grid_on_pixel_centres_matches_brute_force() {
    let (w, h) = (64u32, 64u32);
    let mut v = Vec::new();
    let n = 8u32;
    for j in 0..=n {
        for i in 0..=n {
            v.push(px_to_clip(
                2.5 + 4.0 * f64::from(i),
                1.5 + 4.0 * f64::from(j),
                0.0,
                w,
                h,
            ));
        }
    }
    let mut t = Vec::new();
    let id = |i: u32, j: u32| j * (n + 1) + i;
    for j in 0..n {
        for i in 0..n {
            if (i + j) % 2 == 0 {
                t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            } else {
                t.push([id(i, j), id(i + 1, j), id(i, j + 1)]);
                t.push([id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
    }
    let d: Vec<DrawTri> = draws(&t, false);
    for sp in [1u32, 3, 8] {
        let s = setup(&v, &d, w, h, &cfg(sp, 16));
        for (cov, float) in [(Coverage::Fixed, false), (Coverage::Float, true)] {
            let cnt = coverage_count(&s, cov);
            assert_eq!(cnt, brute_count(&s, float), "{cov:?} sp={sp}");
            for py in 0..h {
                for px in 0..w {
                    let (x, y) = (f64::from(px) + 0.5, f64::from(py) + 0.5);
                    let inside = (2.5..34.5).contains(&x) && (1.5..33.5).contains(&y);
                    assert_eq!(
                        cnt[(py * w + px) as usize],
                        u32::from(inside),
                        "{cov:?} ({px},{py})"
                    );
                }
            }
        }
    }
}
