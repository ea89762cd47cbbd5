//! LDR-FLIP (Andersson, Nilsson, Akenine-Möller, Oskarsson, Åström, Fairchild 2020, "FLIP: A
//! Difference Evaluator for Alternating Images", HPG 2020): the perceptual difference between
//! a test image (the hardware's) and a reference, per pixel in [0, 1], computed by NVIDIA's
//! reference C++ implementation through the `nv-flip` crate (BSD-3-Clause).
//!
//! The images are compared as sRGB 8-bit RGB (alpha dropped), at the paper's default viewing
//! condition ([`PIXELS_PER_DEGREE`]: a 0.7 m distance from a 24" 4K monitor). The statistics
//! pool the covered pixels only (the mask of the LSB metrics), so the FLIP mean and the LSB
//! mean describe the same pixels; the filters still see the whole image.

use image::ImageEncoder as _;
use serde::Serialize;

use crate::report::Image;

/// Pixels per degree of visual angle of the comparison (FLIP's default, 67.0).
pub const PIXELS_PER_DEGREE: f32 = nv_flip::DEFAULT_PIXELS_PER_DEGREE;

/// FLIP statistics over the pooled pixels.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct FlipStats {
    /// Mean per-pixel FLIP, in [0, 1] (the paper's recommended single number).
    pub mean: f64,
    /// 99th percentile of the per-pixel FLIP (nearest rank over the pooled pixels).
    pub p99: f64,
    /// Largest per-pixel FLIP.
    pub max: f64,
    /// Pixels pooled (the covered pixels).
    pub pixels: u64,
    /// Viewing condition of the comparison.
    pub pixels_per_degree: f64,
}

/// A FLIP comparison: the statistics and the per-pixel error map (row-major, top row first).
#[derive(Clone, Debug)]
pub struct Flip {
    pub stats: FlipStats,
    pub width: u32,
    pub height: u32,
    pub map: Vec<f32>,
}

fn rgb8(img: &Image) -> nv_flip::FlipImageRgb8 {
    let rgb: Vec<u8> = img
        .to_rgba8()
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    nv_flip::FlipImageRgb8::with_data(img.width, img.height, &rgb)
}

/// LDR-FLIP of `test` against `reference`, pooled over the pixels `mask` selects (all when
/// `None`). `None` when the sizes differ or no pixel is selected.
#[must_use]
pub fn flip(test: &Image, reference: &Image, mask: Option<&[bool]>) -> Option<Flip> {
    let (w, h) = (test.width, test.height);
    if w == 0 || h == 0 || reference.width != w || reference.height != h {
        return None;
    }
    if !test.is_consistent() || !reference.is_consistent() {
        return None;
    }
    let map = nv_flip::flip(rgb8(reference), rgb8(test), PIXELS_PER_DEGREE).to_vec();
    let mut pooled: Vec<f32> = map
        .iter()
        .enumerate()
        .filter(|(i, _)| mask.is_none_or(|m| m.get(*i).copied().unwrap_or(false)))
        .map(|(_, &v)| if v.is_finite() { v } else { 1.0 })
        .collect();
    if pooled.is_empty() {
        return None;
    }
    let n = pooled.len();
    let mean = pooled.iter().map(|&v| f64::from(v)).sum::<f64>() / n as f64;
    pooled.sort_by(f32::total_cmp);
    // Nearest rank: the smallest value with at least 99% of the pixels at or below it.
    let rank = (n * 99).div_ceil(100).max(1);
    let p99 = f64::from(pooled[rank - 1]);
    let max = f64::from(pooled[n - 1]);
    Some(Flip {
        stats: FlipStats {
            mean,
            p99,
            max,
            pixels: n as u64,
            pixels_per_degree: f64::from(PIXELS_PER_DEGREE),
        },
        width: w,
        height: h,
        map,
    })
}

/// The error map coloured with FLIP's magma colour map (0 black, 1 light yellow), as RGBA8
/// pixels; uncovered pixels (outside `mask`) are grey.
#[must_use]
pub fn error_map_rgba8(f: &Flip, mask: Option<&[bool]>) -> Vec<u8> {
    let img = nv_flip::FlipImageFloat::with_data(f.width, f.height, &f.map);
    let rgb = img.apply_color_lut(&nv_flip::magma_lut()).to_vec();
    rgb.chunks_exact(3)
        .enumerate()
        .flat_map(|(i, p)| {
            if mask.is_none_or(|m| m.get(i).copied().unwrap_or(false)) {
                [p[0], p[1], p[2], 255]
            } else {
                let [r, g, b] = crate::report::MASKED_RGB;
                [r, g, b, 255]
            }
        })
        .collect()
}

/// The coloured error map as a PNG file.
pub fn error_map_png(f: &Flip, mask: Option<&[bool]>) -> crate::Result<Vec<u8>> {
    let rgba = error_map_rgba8(f, mask);
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(&rgba, f.width, f.height, image::ExtendedColorType::Rgba8)
        .map_err(|e| crate::Error::msg(format!("flip.png: {e}")))?;
    Ok(out)
}
