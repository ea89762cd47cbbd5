//! Side-by-side sheet (e.g. hardware | reference | error): each panel is scaled down to at most
//! [`SHEET_MAX_PANEL_W`] pixels wide with an exact integer box (area-average) filter in
//! premultiplied space, composited over a dark checkerboard (so transparent backgrounds read
//! as such), and topped with a title bar in the bitmap font.
//!
//! Size arithmetic: panel `i` of scaled size `(w_i, h_i)` ([`sheet_panel_size`]) sits at
//! `x = PAD + sum_{j<i} (w_j + PAD)`, `y = PAD + TITLE_H`; the sheet is
//! `PAD + sum_i (w_i + PAD)` wide and `PAD + TITLE_H + max_i h_i + PAD` tall.

use tiny_skia::Pixmap;

use super::draw::{blit_over_checker, box_downscale, draw_text, fill_rect, new_pixmap};

/// Largest panel width in the sheet; wider panels are scaled down (aspect kept).
pub const SHEET_MAX_PANEL_W: u32 = 512;
/// Border around and between panels.
pub const SHEET_PAD: u32 = 4;
/// Height of the title bar above each panel (font scale 2: 14 px glyphs, 4 px margins).
pub const SHEET_TITLE_H: u32 = 22;

const SHEET_BG: [u8; 3] = [16, 16, 16];
const TITLE_BG: [u8; 3] = [48, 48, 48];
const TITLE_RGB: [u8; 3] = [240, 240, 240];
const CHECKER: ([u8; 3], [u8; 3]) = ([40, 40, 40], [64, 64, 64]);
const CHECKER_CELL: u32 = 8;

/// The size a `width` x `height` panel is shown at: unchanged if at most
/// [`SHEET_MAX_PANEL_W`] wide, else `SHEET_MAX_PANEL_W` x `round(height * 512 / width)` (>= 1).
#[must_use]
pub fn sheet_panel_size(width: u32, height: u32) -> (u32, u32) {
    if width <= SHEET_MAX_PANEL_W {
        return (width, height);
    }
    let m = u64::from(SHEET_MAX_PANEL_W);
    let (w, h) = (u64::from(width), u64::from(height));
    let nh = ((h * m + w / 2) / w).max(1);
    (SHEET_MAX_PANEL_W, u32::try_from(nh).unwrap_or(u32::MAX))
}

/// Panels side by side, each under a title bar (see the module docs for the layout).
#[must_use]
pub fn sheet(panels: &[(&str, &Pixmap)]) -> Pixmap {
    let sizes: Vec<(u32, u32)> = panels
        .iter()
        .map(|(_, p)| sheet_panel_size(p.width(), p.height()))
        .collect();
    let width = sizes
        .iter()
        .fold(SHEET_PAD, |acc, &(w, _)| acc.saturating_add(w + SHEET_PAD));
    let max_h = sizes.iter().map(|&(_, h)| h).max().unwrap_or(0);
    let height = (2 * SHEET_PAD + SHEET_TITLE_H).saturating_add(max_h);
    let mut out = new_pixmap(width, height);
    if out.width() != width || out.height() != height {
        return out;
    }
    fill_rect(
        &mut out,
        0,
        0,
        i64::from(width),
        i64::from(height),
        SHEET_BG,
    );
    let mut x = SHEET_PAD;
    for ((title, p), &(w, h)) in panels.iter().zip(&sizes) {
        let (xi, yi) = (i64::from(x), i64::from(SHEET_PAD));
        fill_rect(
            &mut out,
            xi,
            yi,
            i64::from(w),
            i64::from(SHEET_TITLE_H),
            TITLE_BG,
        );
        draw_text(
            &mut out,
            xi + 4,
            yi + 4,
            title,
            2,
            TITLE_RGB,
            xi + i64::from(w),
        );
        let scaled = box_downscale(p, w, h);
        let (c0, c1) = CHECKER;
        blit_over_checker(
            &mut out,
            &scaled,
            x,
            SHEET_PAD + SHEET_TITLE_H,
            CHECKER_CELL,
            c0,
            c1,
        );
        x += w + SHEET_PAD;
    }
    out
}
