//! Reports: the framebuffer [`Image`], error metrics between two images (in LSBs of a chosen
//! output bit depth), PNG encoding (8/16-bit), an error heatmap with a colour-bar legend, a
//! side-by-side sheet, and the all-or-nothing [`OutputSet`] writer.
//!
//! Conventions: images are RGBA, 16-bit unsigned normalized per channel, straight (not
//! premultiplied) alpha, top row first. Reducing to `b` bits rounds half up:
//! `q = (x * (2^b - 1) + 32767) / 65535` (for 8 bits this is [`Image::to_rgba8`]; for 16 bits
//! it is the identity). tiny-skia pixmaps hold premultiplied RGBA8.

mod draw;
pub mod font;
mod heatmap;
pub mod html;
mod metrics;
mod output;
mod png;
mod sheet;

pub use heatmap::{heatmap, heatmap_colour, heatmap_layout, HeatmapLayout, MASKED_RGB};
pub(crate) use metrics::ChannelErrors;
pub use metrics::{compare, format_metrics_table, quantize, ErrorMetrics, HISTOGRAM_BUCKETS};
pub use output::OutputSet;
pub use png::{encode_pixmap, encode_png16, encode_png8, image_to_pixmap};
pub use sheet::{sheet, sheet_panel_size, SHEET_MAX_PANEL_W, SHEET_PAD, SHEET_TITLE_H};

/// The framebuffer: RGBA, 16-bit unsigned normalized per channel, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    /// `width * height` pixels, row-major, top row first.
    pub px: Vec<[u16; 4]>,
}

impl Image {
    /// A `width` x `height` image filled with `fill`.
    #[must_use]
    pub fn new(width: u32, height: u32, fill: [u16; 4]) -> Self {
        let n = width as usize * height as usize;
        Self {
            width,
            height,
            px: vec![fill; n],
        }
    }

    /// The pixel at (x, y), if inside the image.
    #[must_use]
    pub fn get(&self, x: u32, y: u32) -> Option<[u16; 4]> {
        if x >= self.width || y >= self.height {
            return None;
        }
        self.px
            .get(y as usize * self.width as usize + x as usize)
            .copied()
    }

    /// Interleaved RGBA8 bytes (straight alpha), each channel reduced with round half up:
    /// `(x * 255 + 32767) / 65535`.
    #[must_use]
    pub fn to_rgba8(&self) -> Vec<u8> {
        self.px
            .as_flattened()
            .iter()
            .map(|&c| unorm16_to_unorm8(c))
            .collect()
    }

    /// Whether `px` holds exactly `width * height` pixels.
    #[must_use]
    pub fn is_consistent(&self) -> bool {
        u64::from(self.width) * u64::from(self.height) == self.px.len() as u64
    }
}

/// [`quantize`]`(c, 8)`, `(c * 255 + 32767) / 65535`, as a multiply, an add and a shift,
/// `(c * 255 + 32895) >> 16`: equal for every 16-bit `c` (checked exhaustively by
/// `unorm8_matches_quantize`), and with no division the loop of [`Image::to_rgba8`]
/// vectorizes wherever the compiler places it.
#[inline]
fn unorm16_to_unorm8(c: u16) -> u8 {
    ((u32::from(c) * 255 + 32895) >> 16) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unorm8_matches_quantize() {
        for c in 0..=u16::MAX {
            assert_eq!(u32::from(unorm16_to_unorm8(c)), quantize(c, 8), "c = {c}");
        }
    }
}
