//! LDR-FLIP (Andersson, Nilsson, Akenine-Möller, Oskarsson, Åström, Fairchild 2020, "FLIP: A
//! Difference Evaluator for Alternating Images", HPG 2020): the perceptual difference between
//! a test image (the hardware's) and a reference, per pixel in [0, 1], computed by NVIDIA's
//! reference C++ implementation through the `nv-flip` crate (BSD-3-Clause).
//!
//! The images are compared as sRGB 8-bit RGB (alpha dropped), at the paper's default viewing
//! condition ([`PIXELS_PER_DEGREE`]: a 0.7 m distance from a 24" 4K monitor). The statistics
//! pool the covered pixels only (the mask of the LSB metrics), so the FLIP mean and the LSB
//! mean describe the same pixels; the filters still see the whole image (computed in bands of
//! rows in parallel, the same map bit for bit).

use image::ImageEncoder as _;
use rayon::prelude::*;
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

/// The image as sRGB 8-bit RGB rows (alpha dropped).
fn rgb8(img: &Image) -> Vec<u8> {
    img.to_rgba8()
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect()
}

/// Rows of context a band of the error map needs on each side: a FLIP pixel depends on the
/// pixels within the larger of its two filter radii (at [`PIXELS_PER_DEGREE`]: the spatial
/// filter's `ceil(3 sqrt(b_max / (2 pi^2)) ppd)` = 10 with `b_max` = 0.04, the feature
/// filter's `ceil(3 * 0.5 * 0.082 * ppd)` = 9), both separable and clamped at the image's
/// edges; 16 leaves a margin.
const BAND_CONTEXT: usize = 16;

/// The fewest rows of the error map in a band computed apart.
const MIN_BAND_ROWS: usize = 64;

/// FLIP's per-pixel error map of `test` against `reference` (RGB8 rows of a `w` x `h`
/// image): on one thread one call on the whole image, else in two bands per thread (at least
/// [`MIN_BAND_ROWS`] rows each) computed in parallel ([`banded_error_map`]).
fn error_map(reference: &[u8], test: &[u8], w: usize, h: usize) -> Vec<f32> {
    let threads = rayon::current_num_threads();
    if threads == 1 {
        return flip_rows(reference, test, w, h);
    }
    let rows = h.div_ceil(2 * threads).max(MIN_BAND_ROWS);
    banded_error_map(reference, test, w, h, rows)
}

/// One call of NVIDIA's FLIP on `rows` rows of RGB8 pixels.
fn flip_rows(reference: &[u8], test: &[u8], w: usize, rows: usize) -> Vec<f32> {
    let img = |d: &[u8]| nv_flip::FlipImageRgb8::with_data(w as u32, rows as u32, d);
    nv_flip::flip(img(reference), img(test), PIXELS_PER_DEGREE).to_vec()
}

/// [`error_map`] in bands of `rows` rows computed in parallel, each from its rows and
/// [`BAND_CONTEXT`] rows of context on each side: a band's pixels read only rows within the
/// filters' radii, which the context holds, and the image's own first and last rows clamp as
/// in one call on the whole image, so the map is the same bit for bit whatever `rows`
/// (`banded_flip_is_the_whole_image_flip`).
fn banded_error_map(reference: &[u8], test: &[u8], w: usize, h: usize, rows: usize) -> Vec<f32> {
    if h <= rows + 2 * BAND_CONTEXT {
        return flip_rows(reference, test, w, h);
    }
    let mut map = vec![0.0f32; w * h];
    map.par_chunks_mut(rows * w)
        .enumerate()
        .for_each(|(k, out)| {
            let y0 = k * rows;
            let y1 = y0 + out.len() / w;
            let (c0, c1) = (y0.saturating_sub(BAND_CONTEXT), (y1 + BAND_CONTEXT).min(h));
            let (a, b) = (c0 * w * 3, c1 * w * 3);
            let band = flip_rows(&reference[a..b], &test[a..b], w, c1 - c0);
            out.copy_from_slice(&band[(y0 - c0) * w..(y1 - c0) * w]);
        });
    map
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
    let map = error_map(&rgb8(reference), &rgb8(test), w as usize, h as usize);
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

#[cfg(test)]
mod tests {
    use super::*;

    /// An image with structure at every scale: smooth gradients, hard edges and noise.
    fn pattern(w: usize, h: usize, seed: u64) -> Vec<u8> {
        let mut rng = crate::rng::SplitMix64(seed);
        (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .flat_map(|(x, y)| {
                let edge = if (x / 7 + y / 5) % 2 == 0 { 200 } else { 30 };
                [(x * 255 / w) as u8, edge, ((y * 3) % 256) as u8]
            })
            .map(|c| c.wrapping_add((rng.next_u64() % 9) as u8))
            .collect()
    }

    #[test]
    fn banded_flip_is_the_whole_image_flip() {
        let cases = [
            (37, 161, 64),
            (64, 300, 40),
            (23, 417, 100),
            (96, 321, 17),
            (50, 96, 1),
        ];
        for (w, h, rows) in cases {
            let (a, b) = (pattern(w, h, 1), pattern(w, h, 2));
            let whole = flip_rows(&a, &b, w, h);
            assert!(
                whole.iter().any(|&v| v > 0.05),
                "{w}x{h}: the images differ"
            );
            for banded in [
                banded_error_map(&a, &b, w, h, rows),
                error_map(&a, &b, w, h),
            ] {
                let same = whole
                    .iter()
                    .zip(&banded)
                    .all(|(x, y)| x.to_bits() == y.to_bits());
                assert!(
                    same && banded.len() == w * h,
                    "{w}x{h} in bands of {rows}: differs"
                );
            }
        }
    }
}
