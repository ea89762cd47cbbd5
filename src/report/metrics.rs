//! Error metrics between two images in LSBs of a `bits`-bit output: max / mean absolute error,
//! RMSE and PSNR over the RGB channel samples (PSNR = 20 log10((2^bits - 1) / RMSE)), and the
//! per-pixel max-channel error distribution in the histogram buckets of the Mesa anchor
//! (`shared/anchors/mesa/RESULTS.md`): 0, 1, 2, 3, 4-7, 8-15, 16-31, 32+.

use std::fmt::Write as _;

use super::Image;

/// Histogram bucket labels and their lower bounds (a bucket runs to the next one's bound - 1).
pub const HISTOGRAM_BUCKETS: [(&str, u32); 8] = [
    ("0", 0),
    ("1", 1),
    ("2", 2),
    ("3", 3),
    ("4-7", 4),
    ("8-15", 8),
    ("16-31", 16),
    ("32+", 32),
];

/// Comparison of two images (see the module docs for definitions).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct ErrorMetrics {
    /// Pixels compared (inside the mask and inside both images).
    pub pixels: u64,
    /// LSB unit: errors are in LSBs of a `bits`-bit output (8 = what the PNG shows; 16 = full
    /// precision).
    pub bits: u32,
    /// Largest channel error.
    pub max_abs_lsb: u32,
    /// Mean absolute error over all compared RGB channel samples.
    pub mean_abs_lsb: f64,
    /// Root mean square error over all compared RGB channel samples.
    pub rmse_lsb: f64,
    /// `20 log10((2^bits - 1) / rmse)`; `None` when identical (infinite).
    pub psnr_db: Option<f64>,
    /// Percent of pixels whose max channel error is 0.
    pub pct_exact: f64,
    /// Percent of pixels whose max channel error is <= 1.
    pub pct_within_1lsb: f64,
    /// Pixel counts by max channel error, labelled as in [`HISTOGRAM_BUCKETS`].
    pub histogram: Vec<(String, u64)>,
}

/// Reduces a 16-bit channel to `bits` bits (clamped to 1..=16), rounding half up:
/// `(x * (2^bits - 1) + 32767) / 65535`.
#[must_use]
pub fn quantize(x: u16, bits: u32) -> u32 {
    let bits = bits.clamp(1, 16);
    let maxv = (1u64 << bits) - 1;
    ((u64::from(x) * maxv + 32767) / 65535) as u32
}

/// Index into [`HISTOGRAM_BUCKETS`] of a max channel error.
#[must_use]
#[inline]
pub(crate) fn bucket_of(err: u32) -> usize {
    // 0..=3 are their own buckets; from 4 on a bucket per power of two up to 32+.
    if err < 4 {
        err as usize
    } else {
        (2 + (31 - err.leading_zeros()) as usize).min(HISTOGRAM_BUCKETS.len() - 1)
    }
}

/// The RGB channel errors (alpha ignored) of two pixels after reducing both to one width:
/// [`quantize`] with `2^bits - 1` resolved once, in `u32` (`x (2^bits - 1) + 32767 < 2^32`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct ChannelErrors {
    maxv: u32,
}

impl ChannelErrors {
    /// For `bits` (clamped to 1..=16).
    pub(crate) fn new(bits: u32) -> Self {
        Self {
            maxv: (1u32 << bits.clamp(1, 16)) - 1,
        }
    }

    /// The three channel errors of `pa` against `pb`.
    #[inline]
    pub(crate) fn of(self, pa: [u16; 4], pb: [u16; 4]) -> [u32; 3] {
        let q = |x: u16| (u32::from(x) * self.maxv + 32767) / 65535;
        [
            q(pa[0]).abs_diff(q(pb[0])),
            q(pa[1]).abs_diff(q(pb[1])),
            q(pa[2]).abs_diff(q(pb[2])),
        ]
    }

    /// The largest of the three.
    #[inline]
    pub(crate) fn max_of(self, pa: [u16; 4], pb: [u16; 4]) -> u32 {
        let e = self.of(pa, pb);
        e[0].max(e[1]).max(e[2])
    }
}

/// The pixels of row `y` of `img` from column 0 to `w - 1` that its pixel vector holds (all
/// of them unless the vector is shorter than `width * height`).
#[inline]
pub(crate) fn row(img: &Image, y: u32, w: u32) -> &[[u16; 4]] {
    let n = img.px.len();
    let start = (y as usize * img.width as usize).min(n);
    &img.px[start..(start + w as usize).min(n)]
}

/// Whether pixel `i` (row-major in `a`'s layout) is selected by `mask` (missing entries are
/// excluded).
#[inline]
pub(crate) fn selected(mask: Option<&[bool]>, i: usize) -> bool {
    match mask {
        None => true,
        Some(m) => m.get(i).copied().unwrap_or(false),
    }
}

/// Compares the RGB channels of `a` and `b` (alpha ignored), both reduced to `bits` bits first
/// (`bits` is clamped to 1..=16). `mask` (row-major in `a`'s layout, `true` = compare) limits
/// the pixels; entries it lacks count as excluded. Images of different sizes are compared over
/// their common top-left area. With no pixels compared the result reads as identical.
#[must_use]
pub fn compare(a: &Image, b: &Image, bits: u32, mask: Option<&[bool]>) -> ErrorMetrics {
    let bits = bits.clamp(1, 16);
    let w = a.width.min(b.width);
    let h = a.height.min(b.height);
    let mut pixels = 0u64;
    let mut max_abs = 0u32;
    let mut sum_abs = 0u64;
    let mut sum_sq = 0u128;
    let mut hist = [0u64; HISTOGRAM_BUCKETS.len()];
    let errors = ChannelErrors::new(bits);
    for y in 0..h {
        let first = y as usize * a.width as usize;
        for (x, (&pa, &pb)) in row(a, y, w).iter().zip(row(b, y, w)).enumerate() {
            if !selected(mask, first + x) {
                continue;
            }
            let e = errors.of(pa, pb);
            let m = e[0].max(e[1]).max(e[2]);
            pixels += 1;
            max_abs = max_abs.max(m);
            sum_abs += u64::from(e[0]) + u64::from(e[1]) + u64::from(e[2]);
            // Three squares below 2^32: their sum fits `u64`.
            let sq = |v: u32| u64::from(v) * u64::from(v);
            sum_sq += u128::from(sq(e[0]) + sq(e[1]) + sq(e[2]));
            hist[bucket_of(m)] += 1;
        }
    }
    let samples = (pixels * 3) as f64;
    let (mean, rmse) = if pixels == 0 {
        (0.0, 0.0)
    } else {
        (sum_abs as f64 / samples, (sum_sq as f64 / samples).sqrt())
    };
    let peak = ((1u64 << bits) - 1) as f64;
    let psnr_db = (sum_sq > 0).then(|| 20.0 * (peak / rmse).log10());
    let pct = |n: u64| {
        if pixels == 0 {
            100.0
        } else {
            100.0 * n as f64 / pixels as f64
        }
    };
    ErrorMetrics {
        pixels,
        bits,
        max_abs_lsb: max_abs,
        mean_abs_lsb: mean,
        rmse_lsb: rmse,
        psnr_db,
        pct_exact: pct(hist[0]),
        pct_within_1lsb: pct(hist[0] + hist[1]),
        histogram: HISTOGRAM_BUCKETS
            .iter()
            .zip(hist)
            .map(|(&(label, _), n)| (label.to_string(), n))
            .collect(),
    }
}

/// An aligned terminal table, one row per `(name, metrics)`: pixels, bits, max, mean, RMSE,
/// PSNR (dB, `inf` when identical), % exact, % within 1 LSB, then the histogram counts.
#[must_use]
pub fn format_metrics_table(rows: &[(&str, &ErrorMetrics)]) -> String {
    let mut header: Vec<String> = [
        "run", "bits", "pixels", "max", "mean", "rmse", "psnr_db", "exact%", "<=1lsb%",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    header.extend(HISTOGRAM_BUCKETS.iter().map(|(l, _)| format!("e={l}")));
    let mut table = vec![header];
    for (name, m) in rows {
        let mut r = vec![
            name.to_string(),
            m.bits.to_string(),
            m.pixels.to_string(),
            m.max_abs_lsb.to_string(),
            format!("{:.4}", m.mean_abs_lsb),
            format!("{:.4}", m.rmse_lsb),
            m.psnr_db
                .map_or_else(|| "inf".to_string(), |p| format!("{p:.2}")),
            format!("{:.3}", m.pct_exact),
            format!("{:.3}", m.pct_within_1lsb),
        ];
        r.extend(HISTOGRAM_BUCKETS.iter().map(|(label, _)| {
            m.histogram
                .iter()
                .find(|(l, _)| l == label)
                .map_or_else(|| "-".to_string(), |(_, n)| n.to_string())
        }));
        table.push(r);
    }
    let ncol = table[0].len();
    let widths: Vec<usize> = (0..ncol)
        .map(|c| {
            table
                .iter()
                .map(|r| r[c].chars().count())
                .max()
                .unwrap_or(0)
        })
        .collect();
    let mut out = String::new();
    for (ri, r) in table.iter().enumerate() {
        let mut line = String::new();
        for (c, cell) in r.iter().enumerate() {
            if c > 0 {
                line.push_str("  ");
            }
            if c == 0 {
                let _ = write!(line, "{cell:<w$}", w = widths[c]);
            } else {
                let _ = write!(line, "{cell:>w$}", w = widths[c]);
            }
        }
        out.push_str(line.trim_end());
        out.push('\n');
        if ri == 0 {
            let total: usize = widths.iter().sum::<usize>() + 2 * (ncol - 1);
            out.push_str(&"-".repeat(total));
            out.push('\n');
        }
    }
    out
}
