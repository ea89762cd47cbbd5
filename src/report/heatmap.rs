//! Error heatmap: per-pixel max RGB channel error in LSBs of a `bits`-bit output, black for
//! exact pixels, otherwise a viridis-like ramp (matplotlib "viridis" stops, linearly
//! interpolated) on a log scale from 1 LSB (dark purple) to the image's max error (yellow):
//! `t = ln(e) / ln(max)`. Error distributions of fixed-point units are heavy-tailed, and the log
//! scale keeps 1-2 LSB errors visible next to rare large ones. A colour-bar legend on the
//! right is labelled in LSBs (bitmap font) at the max and at powers of two, with a black box
//! labelled 0.

use tiny_skia::Pixmap;

use super::draw::{draw_text, fill_rect, new_pixmap, opaque};
use super::font;
use super::metrics::{row, selected, ChannelErrors};
use super::Image;

/// Colour of pixels outside the mask (or outside the second image).
pub const MASKED_RGB: [u8; 3] = [64, 64, 64];
/// Legend background.
const BG_RGB: [u8; 3] = [28, 28, 28];
/// Legend text and tick colour.
const TEXT_RGB: [u8; 3] = [235, 235, 235];
/// Outline around the colour bar and the zero box.
const FRAME_RGB: [u8; 3] = [140, 140, 140];

/// Viridis colour-map stops at t = 0, 1/8, ..., 1.
const VIRIDIS: [[u8; 3]; 9] = [
    [68, 1, 84],
    [71, 44, 122],
    [59, 82, 139],
    [44, 113, 142],
    [33, 145, 140],
    [39, 173, 129],
    [92, 200, 99],
    [170, 220, 50],
    [253, 231, 37],
];

/// The ramp at `t` in [0, 1].
fn ramp(t: f64) -> [u8; 3] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let x = t * (VIRIDIS.len() - 1) as f64;
    let i = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let f = x - i as f64;
    let (c0, c1) = (VIRIDIS[i], VIRIDIS[i + 1]);
    [0, 1, 2].map(|k| (f64::from(c0[k]) + (f64::from(c1[k]) - f64::from(c0[k])) * f).round() as u8)
}

/// Ramp position of error `e` (>= 1) when the largest error is `max`.
fn ramp_pos(e: u32, max: u32) -> f64 {
    if max <= 1 {
        1.0
    } else {
        f64::from(e.clamp(1, max)).ln() / f64::from(max).ln()
    }
}

/// The heatmap colour of a max-channel error `err` when the largest error shown is `max`:
/// black for 0, else the ramp at `ln(err) / ln(max)` (the top colour when `max <= 1`).
#[must_use]
pub fn heatmap_colour(err: u32, max: u32) -> [u8; 3] {
    if err == 0 {
        [0, 0, 0]
    } else {
        ramp(ramp_pos(err, max))
    }
}

/// Where [`heatmap`] puts things. The image occupies `[0, image_width) x [0, image_height)`;
/// rows `[grad_top, grad_bottom)` of the bar columns `[bar_x, bar_x + bar_w)` hold the ramp
/// (max at the top, 1 LSB at the bottom); `[zero_top, zero_bottom)` is the black 0 box.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HeatmapLayout {
    pub width: u32,
    pub height: u32,
    pub image_width: u32,
    pub image_height: u32,
    /// Font and legend scale (1..=3).
    pub scale: u32,
    pub bar_x: u32,
    pub bar_w: u32,
    pub grad_top: u32,
    pub grad_bottom: u32,
    pub zero_top: u32,
    pub zero_bottom: u32,
    /// Left edge of the numeric labels.
    pub label_x: u32,
}

fn titles(bits: u32) -> [String; 2] {
    ["LSB".to_string(), format!("{}-BIT", bits.clamp(1, 16))]
}

/// The layout of a heatmap of a `width` x `height` image whose largest error is `max_err`.
#[must_use]
pub fn heatmap_layout(width: u32, height: u32, bits: u32, max_err: u32) -> HeatmapLayout {
    let s = (height / 320).clamp(1, 3);
    let bar_x = width.saturating_add(8 * s);
    let bar_w = 12 * s;
    let label_x = bar_x.saturating_add(bar_w + 5 * s);
    let label_w = font::text_width(&max_err.to_string(), s);
    let title_w = titles(bits)
        .iter()
        .map(|t| font::text_width(t, s))
        .max()
        .unwrap_or(0);
    let legend_w = (bar_w + 5 * s + label_w).max(title_w);
    let total_w = bar_x.saturating_add(legend_w + 6 * s);
    let total_h = height.max(100 * s);
    let zero_bottom = total_h - 6 * s;
    let zero_top = zero_bottom - 8 * s;
    HeatmapLayout {
        width: total_w,
        height: total_h,
        image_width: width,
        image_height: height,
        scale: s,
        bar_x,
        bar_w,
        grad_top: 30 * s,
        grad_bottom: zero_top - 6 * s,
        zero_top,
        zero_bottom,
        label_x,
    }
}

/// Per-pixel max RGB channel |a - b| in LSBs of `bits` bits (both reduced first, as
/// [`super::compare`]) as colours (see the module docs); pixels outside `mask` (row-major in
/// `a`'s layout) or outside `b` are [`MASKED_RGB`]. The pixmap is `a`'s size plus a legend on
/// the right (and at least tall enough for the legend: see [`heatmap_layout`]); it is opaque.
#[must_use]
pub fn heatmap(a: &Image, b: &Image, bits: u32, mask: Option<&[bool]>) -> Pixmap {
    let bits = bits.clamp(1, 16);
    let errors = ChannelErrors::new(bits);
    // Every pixel of `a`'s area, row by row: its max-channel error, `NONE` outside the mask
    // or outside either image.
    const NONE: u32 = u32::MAX;
    let mut errs = vec![NONE; a.width as usize * a.height as usize];
    let mut max_err = 0u32;
    if a.width > 0 {
        for (y, out) in (0..a.height).zip(errs.chunks_exact_mut(a.width as usize)) {
            let first = y as usize * a.width as usize;
            let b_row = if y < b.height {
                row(b, y, b.width.min(a.width))
            } else {
                &[]
            };
            let pairs = row(a, y, a.width).iter().zip(b_row);
            for (x, ((&pa, &pb), e)) in pairs.zip(out.iter_mut()).enumerate() {
                if selected(mask, first + x) {
                    *e = errors.max_of(pa, pb);
                    max_err = max_err.max(*e);
                }
            }
        }
    }
    let lay = heatmap_layout(a.width, a.height, bits, max_err);
    let mut p = new_pixmap(lay.width, lay.height);
    if p.width() != lay.width || p.height() != lay.height {
        return p;
    }
    let lut: Vec<_> = (0..=max_err)
        .map(|e| opaque(heatmap_colour(e, max_err)))
        .collect();
    let masked = opaque(MASKED_RGB);
    fill_rect(
        &mut p,
        0,
        0,
        i64::from(lay.width),
        i64::from(lay.height),
        BG_RGB,
    );
    let stride = lay.width as usize;
    let px = p.pixels_mut();
    if a.width > 0 {
        for (out, e_row) in px
            .chunks_mut(stride)
            .zip(errs.chunks_exact(a.width as usize))
        {
            for (o, &e) in out.iter_mut().zip(e_row) {
                *o = if e == NONE { masked } else { lut[e as usize] };
            }
        }
    }
    draw_legend(&mut p, &lay, bits, max_err, &lut);
    p
}

fn draw_legend(
    p: &mut Pixmap,
    lay: &HeatmapLayout,
    bits: u32,
    max_err: u32,
    lut: &[tiny_skia::PremultipliedColorU8],
) {
    let s = i64::from(lay.scale);
    let bar_x = i64::from(lay.bar_x);
    let bar_w = i64::from(lay.bar_w);
    let (g0, g1) = (i64::from(lay.grad_top), i64::from(lay.grad_bottom));
    let (z0, z1) = (i64::from(lay.zero_top), i64::from(lay.zero_bottom));
    let right = i64::from(lay.width);
    for (k, t) in titles(bits).iter().enumerate() {
        draw_text(
            p,
            bar_x,
            6 * s + k as i64 * 9 * s,
            t,
            lay.scale,
            TEXT_RGB,
            right,
        );
    }
    // Frames, then the zero box and the ramp rows (each row's colour is the LUT colour of the
    // error value at that height, so the bar shows exactly what the pixels use).
    fill_rect(p, bar_x - 1, g0 - 1, bar_w + 2, g1 - g0 + 2, FRAME_RGB);
    fill_rect(p, bar_x - 1, z0 - 1, bar_w + 2, z1 - z0 + 2, FRAME_RGB);
    fill_rect(p, bar_x, z0, bar_w, z1 - z0, [0, 0, 0]);
    let n = g1 - g0;
    let row_value = |r: i64| -> u32 {
        if max_err <= 1 || n <= 1 {
            return max_err;
        }
        let t = 1.0 - r as f64 / (n - 1) as f64;
        (f64::from(max_err).powf(t).round() as u32).clamp(1, max_err)
    };
    let stride = p.width() as usize;
    let px = p.pixels_mut();
    for r in 0..n {
        let c = lut[row_value(r) as usize];
        let row = (g0 + r) as usize * stride;
        px[row + bar_x as usize..row + (bar_x + bar_w) as usize].fill(c);
    }
    // Labels: "0" at the zero box, the max at the top, powers of two below while they fit.
    let label = |p: &mut Pixmap, yc: i64, v: u32| {
        fill_rect(p, bar_x + bar_w, yc - s / 2, 3 * s, s, TEXT_RGB);
        let top = yc - 3 * s - s / 2;
        draw_text(
            p,
            i64::from(lay.label_x),
            top,
            &v.to_string(),
            lay.scale,
            TEXT_RGB,
            right,
        );
    };
    label(p, (z0 + z1) / 2, 0);
    if max_err == 0 {
        return;
    }
    let y_of = |v: u32| g0 + ((1.0 - ramp_pos(v, max_err)) * (n - 1) as f64).round() as i64;
    let mut last = y_of(max_err);
    label(p, last, max_err);
    let mut v = 1u32 << (31 - max_err.leading_zeros());
    if v == max_err {
        v >>= 1;
    }
    while v >= 1 {
        let y = y_of(v);
        if y - last >= 9 * s {
            label(p, y, v);
            last = y;
        }
        v >>= 1;
    }
}
