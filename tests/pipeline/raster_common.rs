//! Shared helpers for the raster tests: PRNG, meshes, an independent brute-force coverage model.
#![allow(dead_code)]

use glam::{DMat4, DVec3, DVec4};
use hw_model::config::RasterConfig;
use texsim::raster::{DrawTri, ScreenTri, Setup};

pub use crate::rng_common::Rng;

pub fn cfg(subpixel_bits: u32, depth_bits: u32) -> RasterConfig {
    RasterConfig {
        subpixel_bits,
        depth_bits,
        setup_cycles: 16,
        span_cycles: 2,
    }
}

/// Clip coordinates (w = 1) of a point given in pixels (y down) and NDC depth.
pub fn px_to_clip(x: f64, y: f64, z: f64, width: u32, height: u32) -> [f64; 4] {
    [
        x / f64::from(width) * 2.0 - 1.0,
        1.0 - y / f64::from(height) * 2.0,
        z,
        1.0,
    ]
}

pub fn draws(tris: &[[u32; 3]], cull_back: bool) -> Vec<DrawTri> {
    tris.iter().map(|&v| DrawTri { v, cull_back }).collect()
}

/// Closed UV sphere (unit radius) with outward counter-clockwise winding; poles are single
/// vertices with triangle fans.
pub fn uv_sphere(nu: u32, nv: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut p = vec![DVec3::new(0.0, 1.0, 0.0)];
    for j in 1..nv {
        let th = std::f64::consts::PI * f64::from(j) / f64::from(nv);
        for i in 0..nu {
            let ph = 2.0 * std::f64::consts::PI * f64::from(i) / f64::from(nu);
            p.push(DVec3::new(
                th.sin() * ph.cos(),
                th.cos(),
                th.sin() * ph.sin(),
            ));
        }
    }
    p.push(DVec3::new(0.0, -1.0, 0.0));
    let south = (p.len() - 1) as u32;
    let ring = |j: u32, i: u32| 1 + (j - 1) * nu + (i % nu);
    let mut t = Vec::new();
    for i in 0..nu {
        t.push([0, ring(1, i), ring(1, i + 1)]);
        t.push([south, ring(nv - 1, i), ring(nv - 1, i + 1)]);
    }
    for j in 1..nv - 1 {
        for i in 0..nu {
            t.push([ring(j, i), ring(j + 1, i), ring(j + 1, i + 1)]);
            t.push([ring(j, i), ring(j + 1, i + 1), ring(j, i + 1)]);
        }
    }
    // Make every triangle wind counter-clockwise seen from outside.
    for tri in &mut t {
        let [a, b, c] = tri.map(|i| p[i as usize]);
        if (b - a).cross(c - a).dot(a + b + c) < 0.0 {
            tri.swap(1, 2);
        }
    }
    (p, t)
}

pub fn transform(m: &DMat4, p: &[DVec3]) -> Vec<[f64; 4]> {
    p.iter()
        .map(|v| {
            let c: DVec4 = *m * v.extend(1.0);
            c.to_array()
        })
        .collect()
}

/// Independent fixed coverage model: sample exactly, resolve E == 0 by sampling at
/// p + (eps, eps^2) symbolically.
pub fn covers_fixed(t: &ScreenTri, px: i64, py: i64, s: u32) -> bool {
    let h = 1i128 << (s - 1);
    let p = [(i128::from(px) << s) + h, (i128::from(py) << s) + h];
    (0..3).all(|i| {
        let a = t.xy[(i + 1) % 3].map(i128::from);
        let b = t.xy[(i + 2) % 3].map(i128::from);
        let e = (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
        let d_eps = -(b[1] - a[1]);
        let d_eps2 = b[0] - a[0];
        e > 0 || (e == 0 && (d_eps > 0 || (d_eps == 0 && d_eps2 > 0)))
    })
}

/// Independent float coverage model from `edges_float` and the same perturbation rule.
pub fn covers_float(t: &ScreenTri, px: i64, py: i64) -> bool {
    if t.area2_f == 0.0 || t.area2_f.is_nan() {
        return false;
    }
    // A flipped sliver is drawn with its own (float) orientation.
    let sg = t.area2_f.signum();
    let e = t.edges_float(px as f64, py as f64).map(|v| v * sg);
    (0..3).all(|i| {
        let a = t.xy_f[(i + 1) % 3].map(|v| v * sg);
        let b = t.xy_f[(i + 2) % 3].map(|v| v * sg);
        let d_eps = -(b[1] - a[1]);
        let d_eps2 = b[0] - a[0];
        e[i] > 0.0 || (e[i] == 0.0 && (d_eps > 0.0 || (d_eps == 0.0 && d_eps2 > 0.0)))
    })
}

/// Brute-force coverage counts over the whole viewport.
pub fn brute_count(s: &Setup, float: bool) -> Vec<u32> {
    let (w, h) = (s.width as i64, s.height as i64);
    let mut c = vec![0u32; (w * h) as usize];
    for t in &s.tris {
        for py in 0..h {
            for px in 0..w {
                let hit = if float {
                    covers_float(t, px, py)
                } else {
                    covers_fixed(t, px, py, s.subpixel_bits)
                };
                if hit {
                    c[(py * w + px) as usize] += 1;
                }
            }
        }
    }
    c
}

/// Pixels (within one pixel of the float footprint) of the input triangles where the float
/// model legitimately departs from a watertight float rendering: triangles that fixed setup
/// dropped as degenerate after snapping, and outputs whose snapped orientation differs from
/// the unsnapped one (`area2_f <= 0`). Setup must have been run without culling.
pub fn float_suspect_mask(clip: &[[f64; 4]], tris: &[[u32; 3]], s: &Setup) -> Vec<bool> {
    let (w, h) = (s.width, s.height);
    let mut suspect = vec![true; tris.len()];
    for st in &s.tris {
        suspect[st.src as usize] = false;
    }
    for st in &s.tris {
        if st.area2_f <= 0.0 || st.area2_f.is_nan() {
            suspect[st.src as usize] = true;
        }
    }
    let mut mask = vec![false; (w * h) as usize];
    for (ti, tri) in tris.iter().enumerate() {
        if !suspect[ti] {
            continue;
        }
        let pts = tri.map(|i| {
            let c = clip[i as usize];
            [
                (c[0] / c[3] + 1.0) * 0.5 * f64::from(w),
                (1.0 - c[1] / c[3]) * 0.5 * f64::from(h),
            ]
        });
        let x0 = pts.iter().map(|p| p[0]).fold(f64::MAX, f64::min).floor() as i64 - 1;
        let x1 = pts.iter().map(|p| p[0]).fold(f64::MIN, f64::max).ceil() as i64 + 1;
        let y0 = pts.iter().map(|p| p[1]).fold(f64::MAX, f64::min).floor() as i64 - 1;
        let y1 = pts.iter().map(|p| p[1]).fold(f64::MIN, f64::max).ceil() as i64 + 1;
        for y in y0.max(0)..y1.min(i64::from(h)) {
            for x in x0.max(0)..x1.min(i64::from(w)) {
                mask[(y * i64::from(w) + x) as usize] = true;
            }
        }
    }
    mask
}
