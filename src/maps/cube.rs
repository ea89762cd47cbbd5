//! Cube environment maps in texture memory: six faces (OpenGL order +X, -X, +Y, -Y, +Z, -Z),
//! each an ordinary float MIP chain (box-filtered) that the trilinear unit reads with
//! clamp-to-edge addressing (`hw_model::cube_face`: a footprint is clamped per face). Built
//! host side, in float, deterministically from a direction -> colour function (the procedural
//! sky of `shading::env::sky_f`).

use super::{chain_sizes, downsample, MipChain, MipLevel};
use crate::scene::{EnvSource, TextureImage};
use glam::DVec3;
use std::f64::consts::PI;

/// Largest face size (texels per side) of a cube map.
pub const MAX_FACE_SIZE: u32 = 2048;

/// The direction through face coordinates `(s, t)` in `[0, 1]` of `face` (the inverse of
/// OpenGL 4.6 Table 8.19: `sc = 2 s - 1`, `tc = 2 t - 1`), not normalized.
#[must_use]
pub fn face_dir(face: u8, s: f64, t: f64) -> DVec3 {
    let (sc, tc) = (2.0 * s - 1.0, 2.0 * t - 1.0);
    match face {
        0 => DVec3::new(1.0, -tc, -sc),
        1 => DVec3::new(-1.0, -tc, sc),
        2 => DVec3::new(sc, 1.0, tc),
        3 => DVec3::new(sc, -1.0, -tc),
        4 => DVec3::new(sc, -tc, 1.0),
        _ => DVec3::new(-sc, -tc, -1.0),
    }
}

/// The direction -> colour function of an environment source. `textures` are the scene's:
/// an equirectangular image is sampled bilinearly (`+Y` up, the image's centre column looking
/// along `-Z`, its left edge along `+Z` through `-X`: `u = 1/2 + atan2(x, -z) / 2 pi`,
/// `v = acos(y) / pi`, wrapping in `u`, clamped in `v`); a face image at the texel its
/// direction falls in (a cube of the faces' own size reproduces them exactly). Host side,
/// float.
pub fn env_sampler<'a>(
    source: EnvSource,
    textures: &'a [TextureImage],
) -> Box<dyn Fn(DVec3) -> [f64; 3] + Sync + 'a> {
    let texel = |t: &TextureImage, x: u32, y: u32| -> [f64; 3] {
        let p = t.texels[y as usize * t.width as usize + x as usize];
        [0, 1, 2].map(|c| f64::from(p[c]) / 65535.0)
    };
    match source {
        EnvSource::Sky => Box::new(crate::shading::env::sky_f),
        EnvSource::Equirect(i) => {
            let t = &textures[i];
            Box::new(move |d: DVec3| {
                let d = d.normalize_or_zero();
                let u = 0.5 + d.x.atan2(-d.z) / (2.0 * PI);
                let v = d.y.clamp(-1.0, 1.0).acos() / PI;
                let (w, h) = (f64::from(t.width), f64::from(t.height));
                let (x, y) = (u * w - 0.5, (v * h - 0.5).clamp(0.0, h - 1.0));
                let (x0, y0) = (x.floor(), y.floor());
                let (fx, fy) = (x - x0, y - y0);
                let wrap = |x: f64| (x.rem_euclid(w)) as u32;
                let (xa, xb) = (wrap(x0), wrap(x0 + 1.0));
                let (ya, yb) = (y0 as u32, (y0 as u32 + 1).min(t.height - 1));
                let (a, b) = (texel(t, xa, ya), texel(t, xb, ya));
                let (c, e) = (texel(t, xa, yb), texel(t, xb, yb));
                [0, 1, 2].map(|k| {
                    let top = a[k] + (b[k] - a[k]) * fx;
                    let bot = c[k] + (e[k] - c[k]) * fx;
                    top + (bot - top) * fy
                })
            })
        }
        EnvSource::Faces(ix) => Box::new(move |d: DVec3| {
            let (face, [s, t]) = crate::shading::env::cube_face_f(d);
            let img = &textures[ix[usize::from(face).min(5)]];
            let n = f64::from(img.width);
            let x = ((s * n).floor().max(0.0) as u32).min(img.width - 1);
            let y = ((t * n).floor().max(0.0) as u32).min(img.height - 1);
            texel(img, x, y)
        }),
    }
}

/// The six face images of a horizontal-cross image (`4n x 3n`): row 0 holds `+Y` in column
/// 1; row 1 holds `-X`, `+Z`, `+X`, `-Z`; row 2 holds `-Y` in column 1. Cut without rotation,
/// each face is in OpenGL's orientation. Returned in OpenGL order (+X, -X, +Y, -Y, +Z, -Z).
#[must_use]
pub fn split_cross(img: &TextureImage) -> [TextureImage; 6] {
    let n = img.width / 4;
    let cell = [(2u32, 1u32), (0, 1), (1, 0), (1, 2), (1, 1), (3, 1)];
    let names = ["+x", "-x", "+y", "-y", "+z", "-z"];
    std::array::from_fn(|f| {
        let (cx, cy) = cell[f];
        let mut texels = Vec::with_capacity((n * n) as usize);
        for y in 0..n {
            let row = (cy * n + y) as usize * img.width as usize;
            let start = row + (cx * n) as usize;
            texels.extend_from_slice(&img.texels[start..start + n as usize]);
        }
        TextureImage {
            name: format!("{} {}", img.name, names[f]),
            width: n,
            height: n,
            texels,
            prebuilt_levels: None,
        }
    })
}

/// The six face chains of a `size x size` cube map whose level-0 texel centres sample
/// `f(direction)` (RGB in `[0, 1]`, alpha 1). `size` is clamped to `1..=MAX_FACE_SIZE`.
#[must_use]
pub fn cube_chains<F: Fn(DVec3) -> [f64; 3] + ?Sized>(size: u32, f: &F) -> Vec<MipChain> {
    let n = size.clamp(1, MAX_FACE_SIZE);
    (0..6u8)
        .map(|face| {
            let mut texels = Vec::with_capacity((n * n) as usize);
            for y in 0..n {
                for x in 0..n {
                    let s = (f64::from(x) + 0.5) / f64::from(n);
                    let t = (f64::from(y) + 0.5) / f64::from(n);
                    let c = f(face_dir(face, s, t).normalize());
                    texels.push([c[0] as f32, c[1] as f32, c[2] as f32, 1.0]);
                }
            }
            let mut levels = vec![MipLevel {
                width: n,
                height: n,
                texels,
            }];
            for _ in 1..chain_sizes(n, n).len() {
                let next = downsample(levels.last().expect("level 0"));
                levels.push(next);
            }
            MipChain { levels }
        })
        .collect()
}
