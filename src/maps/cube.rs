//! Cube environment maps in texture memory: six faces (OpenGL order +X, -X, +Y, -Y, +Z, -Z),
//! each an ordinary float MIP chain (box-filtered) that the trilinear unit reads with
//! clamp-to-edge addressing (`hw_model::cube_face`: a footprint is clamped per face). Built
//! host side, in float, deterministically from a direction -> colour function (the procedural
//! sky of `shading::env::sky_f`).

use super::{chain_sizes, downsample, MipChain, MipLevel};
use glam::DVec3;

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

/// The six face chains of a `size x size` cube map whose level-0 texel centres sample
/// `f(direction)` (RGB in `[0, 1]`, alpha 1). `size` is clamped to `1..=MAX_FACE_SIZE`.
#[must_use]
pub fn cube_chains(size: u32, f: impl Fn(DVec3) -> [f64; 3]) -> Vec<MipChain> {
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
