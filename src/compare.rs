//! `texsim compare`: one image against another (a texsim render against Mesa, a GPU capture or
//! another simulator): match percentage, per-channel max and mean absolute difference, the
//! histogram of per-pixel differences, an error map and the pixels that differ most.
//!
//! Differences are in LSBs of a `bits`-bit output (8 by default: what PNG8 files hold); a
//! pixel's difference is its largest RGB channel difference, as in [`crate::report::compare`]
//! and the Mesa anchor's `RESULTS.md`; alpha has its own per-channel line. The compared pixels
//! are all pixels, those a mask image selects (not black in RGB), or the covered ones: pixels
//! whose 8-bit RGBA differs from a clear colour, counted as the Mesa anchor counts coverage
//! (`mesa_anchor.c`: read-back pixels that differ from the clear colour (0,0,0,0)).

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::path::Path;

use image::ImageReader;
use serde::Serialize;

use crate::provenance::Provenance;
use crate::report::{self, ErrorMetrics, Image, OutputSet};
use crate::{Error, Result};

/// Largest accepted image side.
pub const MAX_SIDE: u32 = 16384;

/// Largest `--top`: how many of the most different pixels a report lists.
pub const MAX_TOP: usize = 100_000;

/// Decodes a PNG or JPEG (8 or 16 bits; gray, gray+alpha, RGB, RGBA) to RGBA16 (8-bit channels
/// as `x * 257`, exactly). Errors name the file.
pub fn load_image(path: &Path) -> Result<Image> {
    let file = crate::budget::open_regular(
        path,
        "a PNG or JPEG image",
        crate::budget::max_binary_file_bytes(),
    )?;
    let mut reader = ImageReader::new(std::io::BufReader::new(file))
        .with_guessed_format()
        .map_err(|e| Error::file(path, format!("cannot read image: {e}")))?;
    if reader.format().is_none() {
        return Err(Error::file(path, "not a PNG or JPEG image"));
    }
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_SIDE);
    limits.max_image_height = Some(MAX_SIDE);
    limits.max_alloc = Some(crate::budget::max_memory() / 4);
    reader.limits(limits);
    let img = reader
        .decode()
        .map_err(|e| Error::file(path, format!("cannot decode image: {e}")))?;
    let (width, height) = (img.width(), img.height());
    if width == 0 || height == 0 {
        return Err(Error::file(path, "image has no pixels"));
    }
    let px = img.to_rgba16().pixels().map(|p| p.0).collect();
    Ok(Image { width, height, px })
}

/// Which pixels are compared.
#[derive(Clone, Debug, PartialEq)]
pub enum Selection {
    /// Every pixel.
    All,
    /// Pixels where this mask (same size) is not black in RGB.
    Mask(Image),
    /// Covered pixels: 8-bit RGBA differs from `clear` in A, in B, in either or in both.
    Coverage { from: CoverageFrom, clear: [u8; 4] },
}

/// The image(s) whose coverage selects the compared pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum CoverageFrom {
    A,
    B,
    Either,
    Both,
}

/// Largest and mean absolute difference of one channel over the compared pixels.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct ChannelStats {
    pub channel: &'static str,
    pub max_abs_lsb: u32,
    pub mean_abs_lsb: f64,
}

/// One of the pixels that differ most.
#[derive(Clone, Debug, Serialize, PartialEq, Eq)]
pub struct WorstPixel {
    pub x: u32,
    pub y: u32,
    /// Largest RGB channel difference, LSBs.
    pub diff: u32,
    /// A's and B's pixel, RGBA in `bits`-bit values.
    pub a: [u32; 4],
    pub b: [u32; 4],
}

/// Order of the worst pixels: larger difference first, then the top row, then the left column.
type WorstKey = (u32, Reverse<(u32, u32)>);

/// Everything `compare.json` holds (beside the provenance).
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    pub a: String,
    pub b: String,
    pub width: u32,
    pub height: u32,
    /// `all`, `mask FILE`, or `coverage from a|b|either|both, clear R,G,B,A`.
    pub selection: String,
    /// Pixels of A and of B that differ from the clear colour (with a coverage selection).
    pub covered_a: Option<u64>,
    pub covered_b: Option<u64>,
    /// Pixels covered in exactly one of the two (with a coverage selection).
    pub covered_only_one: Option<u64>,
    /// Pixels compared, max/mean/RMSE/PSNR over RGB, % exact (the match %), % within 1 LSB
    /// and the histogram of per-pixel differences.
    pub metrics: ErrorMetrics,
    /// R, G, B, A.
    pub channels: Vec<ChannelStats>,
    /// The pixels with the largest differences, largest first (then top row, left column).
    pub worst: Vec<WorstPixel>,
}

fn covered(p: [u16; 4], clear: [u8; 4]) -> bool {
    (0..4).any(|c| report::quantize(p[c], 8) != u32::from(clear[c]))
}

/// The compared pixels (`true`), row-major; `None` for all pixels.
fn selection_mask(a: &Image, b: &Image, sel: &Selection) -> Option<Vec<bool>> {
    match sel {
        Selection::All => None,
        Selection::Mask(m) => Some(
            m.px.iter()
                .map(|p| p[0] > 0 || p[1] > 0 || p[2] > 0)
                .collect(),
        ),
        Selection::Coverage { from, clear } => Some(
            a.px.iter()
                .zip(&b.px)
                .map(|(&pa, &pb)| {
                    let (ca, cb) = (covered(pa, *clear), covered(pb, *clear));
                    match from {
                        CoverageFrom::A => ca,
                        CoverageFrom::B => cb,
                        CoverageFrom::Either => ca || cb,
                        CoverageFrom::Both => ca && cb,
                    }
                })
                .collect(),
        ),
    }
}

/// Compares `a` and `b` (same size; the names are for messages and the report) over the
/// pixels `sel` selects, in LSBs of `bits` (1..=16), keeping the `top` pixels that differ most.
#[allow(clippy::too_many_arguments)]
pub fn compare(
    a: &Image,
    a_name: &str,
    b: &Image,
    b_name: &str,
    sel: &Selection,
    bits: u32,
    top: usize,
) -> Result<(Comparison, Vec<bool>)> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(Error::msg(format!(
            "images differ in size: {a_name} is {}x{}, {b_name} is {}x{}",
            a.width, a.height, b.width, b.height
        )));
    }
    if top > MAX_TOP {
        return Err(Error::field(
            "--top",
            format!("{top} is over the limit of {MAX_TOP} pixels"),
        ));
    }
    if !(1..=16).contains(&bits) {
        return Err(Error::field(
            "--bits",
            format!("{bits} is out of range 1..=16"),
        ));
    }
    let mut selection = "all".to_string();
    if let Selection::Mask(m) = sel {
        if (m.width, m.height) != (a.width, a.height) {
            return Err(Error::msg(format!(
                "the mask is {}x{}, the images are {}x{}",
                m.width, m.height, a.width, a.height
            )));
        }
        selection = "mask".into();
    }
    let (mut covered_a, mut covered_b, mut only_one) = (None, None, None);
    if let Selection::Coverage { from, clear } = sel {
        let (mut na, mut nb, mut n1) = (0u64, 0u64, 0u64);
        for (&pa, &pb) in a.px.iter().zip(&b.px) {
            let (ca, cb) = (covered(pa, *clear), covered(pb, *clear));
            na += u64::from(ca);
            nb += u64::from(cb);
            n1 += u64::from(ca != cb);
        }
        (covered_a, covered_b, only_one) = (Some(na), Some(nb), Some(n1));
        let from = match from {
            CoverageFrom::A => "a",
            CoverageFrom::B => "b",
            CoverageFrom::Either => "either",
            CoverageFrom::Both => "both",
        };
        selection = format!(
            "coverage from {from}, clear {},{},{},{}",
            clear[0], clear[1], clear[2], clear[3]
        );
    }
    let mask = selection_mask(a, b, sel);
    let metrics = report::compare(a, b, bits, mask.as_deref());
    let mut sum = [0u64; 4];
    let mut max = [0u32; 4];
    // The `top` largest (difference, then top row, then left column) in a bounded min-heap.
    let mut worst: BinaryHeap<Reverse<WorstKey>> = BinaryHeap::new();
    let q = |p: [u16; 4]| p.map(|c| report::quantize(c, bits));
    for (i, (&pa, &pb)) in a.px.iter().zip(&b.px).enumerate() {
        if mask.as_ref().is_some_and(|m| !m[i]) {
            continue;
        }
        let (qa, qb) = (q(pa), q(pb));
        let mut d = 0;
        for c in 0..4 {
            let e = qa[c].abs_diff(qb[c]);
            sum[c] += u64::from(e);
            max[c] = max[c].max(e);
            if c < 3 {
                d = d.max(e);
            }
        }
        if d > 0 && top > 0 {
            let (x, y) = ((i % a.width as usize) as u32, (i / a.width as usize) as u32);
            worst.push(Reverse((d, Reverse((y, x)))));
            if worst.len() > top {
                worst.pop();
            }
        }
    }
    let mut worst: Vec<(u32, u32, u32)> = worst
        .into_iter()
        .map(|Reverse((d, Reverse((y, x))))| (d, y, x))
        .collect();
    worst.sort_unstable_by(|p, o| o.0.cmp(&p.0).then((p.1, p.2).cmp(&(o.1, o.2))));
    let n = metrics.pixels.max(1) as f64;
    let channels = ["r", "g", "b", "a"]
        .iter()
        .enumerate()
        .map(|(c, &channel)| ChannelStats {
            channel,
            max_abs_lsb: max[c],
            mean_abs_lsb: sum[c] as f64 / n,
        })
        .collect();
    let at = |x: u32, y: u32, img: &Image| q(img.get(x, y).unwrap_or([0; 4]));
    let worst = worst
        .into_iter()
        .map(|(diff, y, x)| WorstPixel {
            x,
            y,
            diff,
            a: at(x, y, a),
            b: at(x, y, b),
        })
        .collect();
    let c = Comparison {
        a: a_name.to_string(),
        b: b_name.to_string(),
        width: a.width,
        height: a.height,
        selection,
        covered_a,
        covered_b,
        covered_only_one: only_one,
        metrics,
        channels,
        worst,
    };
    let mask = mask.unwrap_or_else(|| vec![true; a.px.len()]);
    Ok((c, mask))
}

/// The output files: `compare.json` (the comparison and its provenance) and `compare_error.png`
/// (per-pixel largest RGB difference on a logarithmic ramp from the smallest non-zero
/// difference, which gets a colour distinct from black, to the largest; not compared pixels
/// grey; the colour bar on the right).
pub fn output_set(
    c: &Comparison,
    a: &Image,
    b: &Image,
    mask: &[bool],
    provenance: &Provenance,
) -> Result<OutputSet> {
    #[derive(Serialize)]
    struct File<'a> {
        #[serde(flatten)]
        comparison: &'a Comparison,
        provenance: &'a Provenance,
    }
    let json = serde_json::to_string_pretty(&File {
        comparison: c,
        provenance,
    })
    .map_err(|e| Error::msg(format!("cannot encode compare.json: {e}")))?;
    let mut out = OutputSet::new();
    out.add("compare.json", format!("{json}\n").into_bytes());
    let map = report::heatmap(a, b, c.metrics.bits, Some(mask));
    out.add("compare_error.png", report::encode_pixmap(&map)?);
    out.family(&["compare.json", "compare_error.png"]);
    Ok(out)
}

/// The terminal report: pixels, match %, per-channel differences, histogram, worst pixels.
#[must_use]
pub fn format_report(c: &Comparison) -> String {
    let m = &c.metrics;
    let mut s = format!(
        "compare {} vs {} ({}x{}), pixels: {} ({})\n",
        c.a, c.b, c.width, c.height, m.pixels, c.selection
    );
    if let (Some(ca), Some(cb), Some(o)) = (c.covered_a, c.covered_b, c.covered_only_one) {
        s += &format!("covered: {ca} in A, {cb} in B, {o} in only one of them\n");
    }
    s += &format!(
        "match: {:.3}% exact, {:.3}% within 1 LSB ({}-bit); max {}, mean {:.4}, rmse {:.4}\n",
        m.pct_exact, m.pct_within_1lsb, m.bits, m.max_abs_lsb, m.mean_abs_lsb, m.rmse_lsb
    );
    s += "channel  max   mean\n";
    for ch in &c.channels {
        s += &format!(
            "{:<7} {:>4} {:>8.4}\n",
            ch.channel, ch.max_abs_lsb, ch.mean_abs_lsb
        );
    }
    s += "difference histogram (pixels by largest RGB difference):";
    for (label, n) in &m.histogram {
        s += &format!(" {label}: {n}");
    }
    s.push('\n');
    if !c.worst.is_empty() {
        s += "largest differences (x, y: diff, A rgba, B rgba):\n";
        for w in &c.worst {
            s += &format!(
                "  {:>5}, {:>5}: {:>3}  {:?}  {:?}\n",
                w.x, w.y, w.diff, w.a, w.b
            );
        }
    }
    s
}

/// Parses `R,G,B,A` (8-bit values).
pub fn parse_clear(s: &str) -> Result<[u8; 4]> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let bad = || {
        Error::field(
            "--clear",
            format!("'{s}' is not R,G,B,A with four values in 0..=255"),
        )
    };
    if parts.len() != 4 {
        return Err(bad());
    }
    let mut c = [0u8; 4];
    for (v, p) in c.iter_mut().zip(parts) {
        *v = p.parse().map_err(|_| bad())?;
    }
    Ok(c)
}
