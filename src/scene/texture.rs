//! Texture sources: PNG/JPEG decoding to RGBA16 (8-bit channels expanded exactly by x * 257)
//! and procedural generators, including a bit-exact copy of the Mesa anchor texture
//! (`/work/shared/anchors/mesa/mesa_anchor.c`: `hash2`, `make_texture`, `downsample`).

use std::path::Path;

use image::{DynamicImage, ImageReader};

use super::TextureImage;
use crate::{Error, Result};
use rayon::prelude::*;

/// Largest accepted texture side, texels.
pub const MAX_TEXTURE_SIDE: u32 = 16384;

/// Decodes a PNG or JPEG file (8 or 16 bit; gray, gray+alpha, RGB or RGBA) to RGBA16, top row
/// first. Gray replicates to RGB; a missing alpha is opaque. Errors name the file.
pub fn decode_texture(path: &Path) -> Result<TextureImage> {
    let file = crate::budget::open_regular(
        path,
        "a PNG or JPEG texture",
        crate::budget::max_binary_file_bytes(),
    )?;
    let mut reader = ImageReader::new(std::io::BufReader::new(file))
        .with_guessed_format()
        .map_err(|e| Error::file(path, format!("cannot read texture: {e}")))?;
    if reader.format().is_none() {
        return Err(Error::file(path, "not a PNG or JPEG image"));
    }
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_TEXTURE_SIDE);
    limits.max_image_height = Some(MAX_TEXTURE_SIDE);
    limits.max_alloc = Some(crate::budget::max_memory() / 4);
    reader.limits(limits);
    let img = reader
        .decode()
        .map_err(|e| Error::file(path, format!("cannot decode texture: {e}")))?;
    let (width, height) = (img.width(), img.height());
    if width == 0 || height == 0 || width > MAX_TEXTURE_SIDE || height > MAX_TEXTURE_SIDE {
        return Err(Error::file(
            path,
            format!("texture size {width}x{height} is outside 1..={MAX_TEXTURE_SIDE}"),
        ));
    }
    let texels = to_rgba16(&img);
    Ok(TextureImage {
        name: path.display().to_string(),
        width,
        height,
        texels,
        prebuilt_levels: None,
    })
}

fn to_rgba16(img: &DynamicImage) -> Vec<[u16; 4]> {
    let eight_bit = matches!(
        img,
        DynamicImage::ImageLuma8(_)
            | DynamicImage::ImageLumaA8(_)
            | DynamicImage::ImageRgb8(_)
            | DynamicImage::ImageRgba8(_)
    );
    if eight_bit {
        img.to_rgba8()
            .pixels()
            .map(|p| p.0.map(|c| u16::from(c) * 257))
            .collect()
    } else {
        img.to_rgba16().pixels().map(|p| p.0).collect()
    }
}

/// Integer hash of the Mesa anchor (`hash2` in `mesa_anchor.c`).
#[must_use]
pub fn hash2(x: u32, y: u32) -> u32 {
    let mut h = x.wrapping_mul(0x8da6_b343) ^ y.wrapping_mul(0xd816_3841) ^ 0x9e37_79b9;
    h ^= h >> 16;
    h = h.wrapping_mul(0x7feb_352d);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846c_a68b);
    h ^= h >> 16;
    h
}

/// 8x8-texel checks of `light`/`dark` plus per-texel per-channel hash noise in [-32, 31],
/// clamped; alpha 255. With the Mesa colours and size 1024 this is `make_texture` exactly.
#[must_use]
pub fn noise_checker_rgba8(size: u32, light: [i32; 3], dark: [i32; 3]) -> Vec<[u8; 4]> {
    let n = size as usize;
    let mut out = vec![[0u8; 4]; n * n];
    out.par_chunks_mut(n.max(1))
        .enumerate()
        .for_each(|(y, row)| {
            let y = y as u32;
            for (p, x) in row.iter_mut().zip(0u32..) {
                let check = ((x >> 3) ^ (y >> 3)) & 1;
                let c = if check == 1 { light } else { dark };
                let h = hash2(x, y);
                *p = [0, 0, 0, 255];
                for k in 0..3 {
                    let n = ((h >> (8 * k)) & 63) as i32 - 32;
                    p[k] = (c[k] + n).clamp(0, 255) as u8;
                }
            }
        });
    out
}

/// The Mesa anchor's next level: `(a+b+c+d+2) >> 2` per channel (`downsample` in the anchor).
#[must_use]
pub fn downsample_rgba8(src: &[[u8; 4]], w: u32, h: u32) -> (u32, u32, Vec<[u8; 4]>) {
    let nw = if w > 1 { w / 2 } else { 1 };
    let nh = if h > 1 { h / 2 } else { 1 };
    let avg = |a: [u8; 4], b: [u8; 4], c: [u8; 4], e: [u8; 4]| {
        let mut p = [0u8; 4];
        for k in 0..4 {
            let s = u32::from(a[k]) + u32::from(b[k]) + u32::from(c[k]) + u32::from(e[k]);
            p[k] = ((s + 2) >> 2) as u8;
        }
        p
    };
    let wu = w as usize;
    let mut d = vec![[0u8; 4]; nw as usize * nh as usize];
    d.par_chunks_mut(nw as usize)
        .enumerate()
        .for_each(|(y, row)| {
            let y0 = 2 * y;
            let y1 = if h > 1 { y0 + 1 } else { y0 };
            let (r0, r1) = (&src[y0 * wu..][..wu], &src[y1 * wu..][..wu]);
            if w > 1 {
                for ((p, a), c) in row
                    .iter_mut()
                    .zip(r0.chunks_exact(2))
                    .zip(r1.chunks_exact(2))
                {
                    *p = avg(a[0], a[1], c[0], c[1]);
                }
            } else {
                row[0] = avg(r0[0], r0[0], r1[0], r1[0]);
            }
        });
    (nw, nh, d)
}

/// Light and dark check colours of the Mesa anchor texture.
pub const MESA_LIGHT: [i32; 3] = [224, 200, 160];
/// See [`MESA_LIGHT`].
pub const MESA_DARK: [i32; 3] = [40, 64, 96];
/// Side of the Mesa anchor texture.
pub const MESA_TEX_SIZE: u32 = 1024;

/// All 8-bit levels (level 0 first, down to 1x1) of the Mesa anchor texture of side `size`.
#[must_use]
pub fn mesa_levels_rgba8(size: u32) -> Vec<(u32, u32, Vec<[u8; 4]>)> {
    let mut levels = vec![(size, size, noise_checker_rgba8(size, MESA_LIGHT, MESA_DARK))];
    loop {
        let (w, h, t) = &levels[levels.len() - 1];
        if *w <= 1 && *h <= 1 {
            break;
        }
        let next = downsample_rgba8(t, *w, *h);
        levels.push(next);
    }
    levels
}

fn expand(t: &[[u8; 4]]) -> Vec<[u16; 4]> {
    t.iter().map(|p| p.map(|c| u16::from(c) * 257)).collect()
}

/// A texture from 8-bit level 0 only (`maps` builds the chain).
#[must_use]
pub fn from_rgba8(name: &str, size: u32, t: &[[u8; 4]]) -> TextureImage {
    TextureImage {
        name: name.into(),
        width: size,
        height: size,
        texels: expand(t),
        prebuilt_levels: None,
    }
}

/// The Mesa anchor texture with its integer-filtered chain as `prebuilt_levels` (x257).
#[must_use]
pub fn mesa_texture(size: u32) -> TextureImage {
    let levels = mesa_levels_rgba8(size.max(1));
    let (w, h, t0) = &levels[0];
    TextureImage {
        name: format!("mesa-{size}"),
        width: *w,
        height: *h,
        texels: expand(t0),
        prebuilt_levels: Some(
            levels[1..]
                .iter()
                .map(|(w, h, t)| (*w, *h, expand(t)))
                .collect(),
        ),
    }
}

/// A plain two-colour checkerboard of side `size` with `checks` x `checks` squares, 8-bit
/// colours (alpha 255).
#[must_use]
pub fn checker(size: u32, checks: u32, a: [u8; 3], b: [u8; 3]) -> TextureImage {
    let cell = (size / checks.max(1)).max(1);
    let mut t = Vec::with_capacity(size as usize * size as usize);
    for y in 0..size {
        for x in 0..size {
            let c = if ((x / cell) ^ (y / cell)) & 1 == 0 {
                a
            } else {
                b
            };
            t.push([c[0], c[1], c[2], 255]);
        }
    }
    from_rgba8(&format!("checker-{size}"), size, &t)
}

/// Floor tiles of side `size`: 8 x 8 tiles in two stone colours with per-texel hash noise in
/// [-16, 15] and dark 2-texel grout lines (fine noise, then grout, then tiles fade out as the
/// MIP level rises, which makes level transitions easy to see).
#[must_use]
pub fn tiles(size: u32) -> TextureImage {
    let cell = (size / 8).max(1);
    let mut t = Vec::with_capacity(size as usize * size as usize);
    for y in 0..size {
        for x in 0..size {
            let h = hash2(x ^ 0x5555, y ^ 0x3333);
            let grout = x % cell < 2 || y % cell < 2;
            let base: [i32; 3] = if grout {
                [28, 28, 34]
            } else if ((x / cell) ^ (y / cell)) & 1 == 0 {
                [214, 188, 150]
            } else {
                [92, 112, 138]
            };
            let mut p = [0u8, 0, 0, 255];
            for k in 0..3 {
                let n = ((h >> (8 * k)) & 31) as i32 - 16;
                p[k] = (base[k] + n).clamp(0, 255) as u8;
            }
            t.push(p);
        }
    }
    from_rgba8(&format!("tiles-{size}"), size, &t)
}

/// Procedural texture by name (`checker`, `noise-checker`, `mesa`, `tiles`) and side `size`.
pub fn procedural(kind: &str, size: u32) -> Result<TextureImage> {
    if !(1..=MAX_TEXTURE_SIDE).contains(&size) {
        return Err(Error::msg(format!(
            "texture size {size} is outside 1..={MAX_TEXTURE_SIDE}"
        )));
    }
    match kind {
        "checker" => Ok(checker(size, 8, [230, 230, 230], [40, 40, 48])),
        "noise-checker" => {
            let t = noise_checker_rgba8(size, [210, 120, 60], [50, 90, 140]);
            Ok(from_rgba8(&format!("noise-checker-{size}"), size, &t))
        }
        "mesa" => Ok(mesa_texture(size)),
        "tiles" => Ok(tiles(size)),
        "bricks-height" => Ok(bricks_height(size)),
        "ripples-height" => Ok(ripples_height(size)),
        other => Err(Error::msg(format!(
            "unknown procedural texture '{other}' (known: checker, noise-checker, mesa, tiles, \
             bricks-height, ripples-height)"
        ))),
    }
}

pub(crate) fn height_image(name: String, size: u32, h: impl Fn(f64, f64) -> f64) -> TextureImage {
    let n = f64::from(size.max(1));
    let mut texels = Vec::with_capacity(size as usize * size as usize);
    for y in 0..size {
        for x in 0..size {
            let v = h((f64::from(x) + 0.5) / n, (f64::from(y) + 0.5) / n).clamp(0.0, 1.0);
            let c = (v * 65535.0).round() as u16;
            texels.push([c, c, c, 65535]);
        }
    }
    TextureImage {
        name,
        width: size,
        height: size,
        texels,
        prebuilt_levels: None,
    }
}

/// A brick height map (16-bit grey, tileable): 8 x 16 running-bond bricks at height 1 with
/// bevelled edges down to mortar at 0.
#[must_use]
pub fn bricks_height(size: u32) -> TextureImage {
    height_image(format!("bricks-height-{size}"), size, |s, t| {
        let (rows, cols) = (16.0, 8.0);
        let r = t * rows;
        let shift = if (r.floor() as i64) % 2 == 0 {
            0.0
        } else {
            0.5
        };
        let c = s * cols + shift;
        // Distance to the nearest joint in brick-height units (a brick is 1 x 2 of them).
        let dy = (r - r.floor()).min(r.ceil() - r);
        let dx = (c - c.floor()).min(c.ceil() - c) * rows / cols;
        let d = dy.min(dx);
        let mortar = 0.06;
        let bevel = 0.16;
        let x = ((d - mortar) / bevel).clamp(0.0, 1.0);
        x * x * (3.0 - 2.0 * x)
    })
}

/// A ripple height map (16-bit grey, tileable): `0.5 + 0.5 sin` of two crossed waves.
#[must_use]
pub fn ripples_height(size: u32) -> TextureImage {
    height_image(format!("ripples-height-{size}"), size, |s, t| {
        let tau = std::f64::consts::TAU;
        0.5 + 0.25 * (tau * 6.0 * s).sin() + 0.25 * (tau * 4.0 * (s + t)).sin()
    })
}
