//! Opaque pixel drawing on tiny-skia pixmaps (premultiplied RGBA8): rectangles, bitmap text,
//! area-average (box filter) down-scaling and compositing over a checkerboard.

use tiny_skia::{ColorU8, Pixmap, PremultipliedColorU8};

use super::font;

/// An opaque premultiplied colour.
#[must_use]
pub(crate) fn opaque(rgb: [u8; 3]) -> PremultipliedColorU8 {
    ColorU8::from_rgba(rgb[0], rgb[1], rgb[2], 255).premultiply()
}

/// A transparent pixmap of `width` x `height`; sizes tiny-skia cannot hold (zero or too large)
/// give a 1x1 pixmap instead.
#[must_use]
pub(crate) fn new_pixmap(width: u32, height: u32) -> Pixmap {
    match Pixmap::new(width, height) {
        Some(p) => p,
        None => Pixmap::new(1, 1).expect("a 1x1 pixmap always fits"),
    }
}

/// Fills the rectangle `[x, x+w) x [y, y+h)` (clipped to the pixmap) with opaque `rgb`.
pub(crate) fn fill_rect(p: &mut Pixmap, x: i64, y: i64, w: i64, h: i64, rgb: [u8; 3]) {
    fill_rect_clipped(p, x, y, w, h, rgb, i64::MAX);
}

fn fill_rect_clipped(
    p: &mut Pixmap,
    x: i64,
    y: i64,
    w: i64,
    h: i64,
    rgb: [u8; 3],
    clip_right: i64,
) {
    let pw = i64::from(p.width());
    let ph = i64::from(p.height());
    let x0 = x.max(0);
    let y0 = y.max(0);
    let x1 = x.saturating_add(w).min(pw).min(clip_right);
    let y1 = y.saturating_add(h).min(ph);
    if x0 >= x1 || y0 >= y1 {
        return;
    }
    let c = opaque(rgb);
    let stride = pw as usize;
    let px = p.pixels_mut();
    for yy in y0 as usize..y1 as usize {
        px[yy * stride + x0 as usize..yy * stride + x1 as usize].fill(c);
    }
}

/// Draws `text` with its top-left corner at (x, y), each font pixel a `scale` x `scale` square;
/// nothing is drawn at or right of `clip_right`.
pub(crate) fn draw_text(
    p: &mut Pixmap,
    x: i64,
    y: i64,
    text: &str,
    scale: u32,
    rgb: [u8; 3],
    clip_right: i64,
) {
    let s = i64::from(scale.max(1));
    let mut cx = x;
    for ch in text.chars() {
        let rows = font::glyph(ch);
        for (ry, row) in rows.iter().enumerate() {
            for col in 0..font::GLYPH_W {
                if row & (1 << (font::GLYPH_W - 1 - col)) != 0 {
                    let gx = cx + i64::from(col) * s;
                    let gy = y + ry as i64 * s;
                    fill_rect_clipped(p, gx, gy, s, s, rgb, clip_right);
                }
            }
        }
        cx += i64::from(font::ADVANCE) * s;
        if cx >= clip_right {
            break;
        }
    }
}

/// Area-average weights for resampling `n` source pixels onto `m` (`m <= n`) destination pixels:
/// destination `i` covers source `[i n / m, (i + 1) n / m)`. Weights are in units of `1 / m`
/// source pixel, so each destination's weights sum to exactly `n`.
fn box_weights(n: u32, m: u32) -> Vec<Vec<(usize, u64)>> {
    let (n, m) = (u64::from(n), u64::from(m));
    (0..m)
        .map(|i| {
            let lo = i * n;
            let hi = (i + 1) * n;
            let j0 = lo / m;
            let j1 = hi.div_ceil(m);
            (j0..j1)
                .filter_map(|j| {
                    let a = lo.max(j * m);
                    let b = hi.min((j + 1) * m);
                    (b > a).then_some((j as usize, b - a))
                })
                .collect()
        })
        .collect()
}

/// Down-scales `src` to `dw` x `dh` (each at most the source size) with an exact integer box
/// (area-average) filter in premultiplied space, rounding half up.
#[must_use]
pub(crate) fn box_downscale(src: &Pixmap, dw: u32, dh: u32) -> Pixmap {
    let (sw, sh) = (src.width(), src.height());
    let dw = dw.clamp(1, sw);
    let dh = dh.clamp(1, sh);
    if dw == sw && dh == sh {
        return src.clone();
    }
    let wx = box_weights(sw, dw);
    let wy = box_weights(sh, dh);
    let spx = src.pixels();
    // Horizontal pass: sums in units of 1/dw.
    let mut tmp = vec![[0u64; 4]; dw as usize * sh as usize];
    for y in 0..sh as usize {
        let row = &spx[y * sw as usize..(y + 1) * sw as usize];
        for (x, weights) in wx.iter().enumerate() {
            let mut acc = [0u64; 4];
            for &(j, w) in weights {
                let c = row[j];
                acc[0] += w * u64::from(c.red());
                acc[1] += w * u64::from(c.green());
                acc[2] += w * u64::from(c.blue());
                acc[3] += w * u64::from(c.alpha());
            }
            tmp[y * dw as usize + x] = acc;
        }
    }
    let denom = u128::from(sw) * u128::from(sh);
    let mut out = new_pixmap(dw, dh);
    let opx = out.pixels_mut();
    for (y, weights) in wy.iter().enumerate() {
        for x in 0..dw as usize {
            let mut acc = [0u128; 4];
            for &(j, w) in weights {
                let t = tmp[j * dw as usize + x];
                for k in 0..4 {
                    acc[k] += u128::from(w) * u128::from(t[k]);
                }
            }
            let q = |v: u128| ((v + denom / 2) / denom).min(255) as u8;
            let (r, g, b, a) = (q(acc[0]), q(acc[1]), q(acc[2]), q(acc[3]));
            // Equal weights keep r, g, b <= a; the min() guards the invariant regardless.
            opx[y * dw as usize + x] =
                PremultipliedColorU8::from_rgba(r.min(a), g.min(a), b.min(a), a)
                    .unwrap_or(PremultipliedColorU8::TRANSPARENT);
        }
    }
    out
}

/// Composites `src` (premultiplied) over an opaque checkerboard of `cell`-pixel squares in
/// colours `c0` / `c1` into `dst` at (x, y).
pub(crate) fn blit_over_checker(
    dst: &mut Pixmap,
    src: &Pixmap,
    x: u32,
    y: u32,
    cell: u32,
    c0: [u8; 3],
    c1: [u8; 3],
) {
    let dw = dst.width() as usize;
    let dh = dst.height() as usize;
    let sw = src.width() as usize;
    let cell = cell.max(1) as usize;
    let spx = src.pixels();
    let dpx = dst.pixels_mut();
    for (sy, row) in spx.chunks_exact(sw).enumerate() {
        let ty = y as usize + sy;
        if ty >= dh {
            break;
        }
        for (sx, c) in row.iter().enumerate() {
            let tx = x as usize + sx;
            if tx >= dw {
                break;
            }
            let bg = if (sx / cell + sy / cell) & 1 == 0 {
                c0
            } else {
                c1
            };
            let inv = 255 - u32::from(c.alpha());
            let mix =
                |s: u8, d: u8| (u32::from(s) + (u32::from(d) * inv + 127) / 255).min(255) as u8;
            dpx[ty * dw + tx] = opaque([
                mix(c.red(), bg[0]),
                mix(c.green(), bg[1]),
                mix(c.blue(), bg[2]),
            ]);
        }
    }
}
