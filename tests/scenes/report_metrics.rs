//! Metrics: hand-computed values, masks, LSB units, histogram buckets, and a randomized check
//! against an independent float model.

use crate::rng_common::Rng;
use texsim::report::{compare, format_metrics_table, quantize, ErrorMetrics, Image};

/// 8-bit value expanded exactly to 16 bits.
fn e8(v: u8) -> u16 {
    u16::from(v) * 257
}

fn hist(m: &ErrorMetrics, label: &str) -> u64 {
    m.histogram
        .iter()
        .find(|(l, _)| l == label)
        .map(|(_, n)| *n)
        .expect("bucket")
}

/// a: 2x2 grey 100; b: errors per pixel (0,0,0) (1,0,0) (0,3,2) (10,5,40) in 8-bit LSBs.
fn hand_pair() -> (Image, Image) {
    let a = Image::new(2, 2, [e8(100), e8(100), e8(100), 65535]);
    let mut b = a.clone();
    b.px[0][3] = 0; // alpha differs: must be ignored
    b.px[1][0] = e8(101);
    b.px[2] = [e8(100), e8(103), e8(98), 65535];
    b.px[3] = [e8(110), e8(95), e8(140), 12345];
    (a, b)
}

#[test]
fn identical_images() {
    let (a, _) = hand_pair();
    let m = compare(&a, &a, 8, None);
    assert_eq!(m.pixels, 4);
    assert_eq!(m.max_abs_lsb, 0);
    assert_eq!(m.mean_abs_lsb, 0.0);
    assert_eq!(m.rmse_lsb, 0.0);
    assert!(m.psnr_db.is_none());
    assert_eq!(m.pct_exact, 100.0);
    assert_eq!(m.pct_within_1lsb, 100.0);
    assert_eq!(hist(&m, "0"), 4);
    assert_eq!(m.histogram.iter().map(|(_, n)| n).sum::<u64>(), 4);
}

#[test]
fn hand_computed_8bit() {
    let (a, b) = hand_pair();
    let m = compare(&a, &b, 8, None);
    // channel errors: 0 0 0 | 1 0 0 | 0 3 2 | 10 5 40 -> sum 61, sum sq 1739, 12 samples
    assert_eq!(m.bits, 8);
    assert_eq!(m.pixels, 4);
    assert_eq!(m.max_abs_lsb, 40);
    assert!(
        (m.mean_abs_lsb - 5.083_333_333).abs() < 1e-8,
        "{}",
        m.mean_abs_lsb
    );
    assert!((m.rmse_lsb - 12.038_133_853).abs() < 1e-8, "{}", m.rmse_lsb);
    let psnr = m.psnr_db.expect("finite");
    assert!((psnr - 26.519_620_249).abs() < 1e-8, "{psnr}");
    assert_eq!(m.pct_exact, 25.0);
    assert_eq!(m.pct_within_1lsb, 50.0);
    let labels: Vec<&str> = m.histogram.iter().map(|(l, _)| l.as_str()).collect();
    assert_eq!(labels, ["0", "1", "2", "3", "4-7", "8-15", "16-31", "32+"]);
    let counts: Vec<u64> = m.histogram.iter().map(|(_, n)| *n).collect();
    assert_eq!(counts, [1, 1, 0, 1, 0, 0, 0, 1]);
    // symmetric
    let r = compare(&b, &a, 8, None);
    assert_eq!(r.max_abs_lsb, 40);
    assert_eq!(r.rmse_lsb, m.rmse_lsb);
}

#[test]
fn hand_computed_16bit_units() {
    let (a, b) = hand_pair();
    let m8 = compare(&a, &b, 8, None);
    let m = compare(&a, &b, 16, None);
    // every 8-bit LSB is exactly 257 16-bit LSBs here
    assert_eq!(m.bits, 16);
    assert_eq!(m.max_abs_lsb, 40 * 257);
    assert!((m.mean_abs_lsb - 61.0 * 257.0 / 12.0).abs() < 1e-6);
    assert!((m.rmse_lsb - m8.rmse_lsb * 257.0).abs() < 1e-6);
    // 65535 / (257 rmse8) = 255 / rmse8: the same PSNR
    assert!((m.psnr_db.expect("finite") - m8.psnr_db.expect("finite")).abs() < 1e-9);
    let counts: Vec<u64> = m.histogram.iter().map(|(_, n)| *n).collect();
    assert_eq!(counts, [1, 0, 0, 0, 0, 0, 0, 3]);
}

#[test]
fn quantize_first_then_difference() {
    // 1000 and 1001 both round to 8-bit 4: exact at 8 bits, 1 LSB at 16.
    let a = Image::new(1, 1, [1000, 1000, 1000, 0]);
    let b = Image::new(1, 1, [1001, 1000, 1000, 0]);
    assert_eq!(compare(&a, &b, 8, None).max_abs_lsb, 0);
    assert_eq!(compare(&a, &b, 16, None).max_abs_lsb, 1);
    // 128 -> 0 and 129 -> 1 at 8 bits (the rounding boundary is 128.5)
    let a = Image::new(1, 1, [128, 0, 0, 0]);
    let b = Image::new(1, 1, [129, 0, 0, 0]);
    let m = compare(&a, &b, 8, None);
    assert_eq!(m.max_abs_lsb, 1);
    assert_eq!(m.pct_exact, 0.0);
    assert_eq!(m.pct_within_1lsb, 100.0);
    // 10-bit unit: (64 * 1023 + 32767) / 65535 = 1
    assert_eq!(quantize(64, 10), 1);
    assert_eq!(quantize(65535, 10), 1023);
    assert_eq!(quantize(0, 10), 0);
    // out-of-range bit counts are clamped, not a panic
    assert_eq!(compare(&a, &b, 0, None).bits, 1);
    assert_eq!(compare(&a, &b, 99, None).bits, 16);
}

/// Four different channel values made from `v`; each channel covers all 65,536 values over `v`.
fn channels(v: u16) -> [u16; 4] {
    [v, !v, v.rotate_left(5), v ^ 0x5a5a]
}

#[test]
fn quantize_8_matches_to_rgba8_exhaustively() {
    let img = Image {
        width: 65536,
        height: 1,
        px: (0..=u16::MAX).map(channels).collect(),
    };
    let b = img.to_rgba8();
    assert_eq!(b.len(), 65536 * 4);
    let rule = |v: u16| ((f64::from(v) * 255.0 / 65535.0) + 0.5).floor() as u8;
    for v in 0..=u16::MAX {
        let expect = rule(v);
        // Every channel of every pixel: each holds a different value, so a mixed-up channel
        // or pixel order fails too.
        for (c, x) in channels(v).into_iter().enumerate() {
            assert_eq!(b[usize::from(v) * 4 + c], rule(x), "v={v} channel {c}");
        }
        assert_eq!(quantize(v, 8), u32::from(expect));
        assert_eq!(quantize(v, 16), u32::from(v));
    }
}

#[test]
fn masks() {
    let (a, b) = hand_pair();
    let mask = [true, true, true, false];
    let m = compare(&a, &b, 8, Some(&mask));
    assert_eq!(m.pixels, 3);
    assert_eq!(m.max_abs_lsb, 3);
    // errors 0 0 0 | 1 0 0 | 0 3 2: sum 6, sum sq 14, 9 samples
    assert!((m.mean_abs_lsb - 6.0 / 9.0).abs() < 1e-12);
    assert!((m.rmse_lsb - (14.0f64 / 9.0).sqrt()).abs() < 1e-12);
    assert!((m.pct_exact - 100.0 / 3.0).abs() < 1e-9);
    assert!((m.pct_within_1lsb - 200.0 / 3.0).abs() < 1e-9);
    assert_eq!(hist(&m, "32+"), 0);
    // a short mask excludes the pixels it lacks
    let m = compare(&a, &b, 8, Some(&[false, true]));
    assert_eq!(m.pixels, 1);
    assert_eq!(m.max_abs_lsb, 1);
    // nothing selected: reads as identical, no panic
    let m = compare(&a, &b, 8, Some(&[false; 4]));
    assert_eq!(m.pixels, 0);
    assert!(m.psnr_db.is_none());
    assert_eq!(m.pct_exact, 100.0);
    assert!(m.mean_abs_lsb == 0.0 && m.rmse_lsb == 0.0);
}

#[test]
fn mismatched_sizes_compare_common_area() {
    let (a, b) = hand_pair();
    let small = Image::new(1, 2, [e8(100), e8(100), e8(100), 65535]);
    let m = compare(&small, &b, 8, None);
    assert_eq!(m.pixels, 2); // pixels (0,0) and (0,1) of b: errors 0 and (0,3,2)
    assert_eq!(m.max_abs_lsb, 3);
    // an inconsistent pixel vector must not panic; missing pixels are skipped
    let broken = Image {
        width: 2,
        height: 2,
        px: a.px[..3].to_vec(),
    };
    assert_eq!(compare(&broken, &b, 8, None).pixels, 3);
}

#[test]
fn histogram_buckets() {
    // one row with red errors 0..=40 at 8 bits
    let n = 41u32;
    let a = Image::new(n, 1, [0, 0, 0, 65535]);
    let mut b = a.clone();
    for (i, p) in b.px.iter_mut().enumerate() {
        p[0] = e8(i as u8);
    }
    let m = compare(&a, &b, 8, None);
    let counts: Vec<u64> = m.histogram.iter().map(|(_, n)| *n).collect();
    assert_eq!(counts, [1, 1, 1, 1, 4, 8, 16, 9]);
    assert_eq!(m.max_abs_lsb, 40);
    // bucket edges exactly: 3 | 4, 7 | 8, 15 | 16, 31 | 32
    let edges = [
        (3u8, "3"),
        (4, "4-7"),
        (7, "4-7"),
        (8, "8-15"),
        (15, "8-15"),
        (16, "16-31"),
        (31, "16-31"),
        (32, "32+"),
        (255, "32+"),
    ];
    for (e, label) in edges {
        let a = Image::new(1, 1, [0, 0, 0, 0]);
        let b = Image::new(1, 1, [0, 0, e8(e), 0]);
        assert_eq!(hist(&compare(&a, &b, 8, None), label), 1, "error {e}");
    }
}

type Model = (u64, u32, f64, f64, [u64; 8]);

/// Independent model: float rounding, per-sample sums.
fn model(a: &Image, b: &Image, bits: u32, mask: &[bool]) -> Model {
    let maxv = f64::from((1u32 << bits) - 1);
    let q = |x: u16| (f64::from(x) * maxv / 65535.0 + 0.5).floor() as i64;
    let (mut n, mut mx, mut s, mut s2, mut h) = (0u64, 0u32, 0f64, 0f64, [0u64; 8]);
    for (i, _) in mask.iter().enumerate().filter(|(_, &m)| m) {
        n += 1;
        let mut pm = 0u32;
        for c in 0..3 {
            let d = (q(a.px[i][c]) - q(b.px[i][c])).unsigned_abs() as u32;
            pm = pm.max(d);
            s += f64::from(d);
            s2 += f64::from(d) * f64::from(d);
        }
        mx = mx.max(pm);
        let k = match pm {
            0..=3 => pm as usize,
            4..=7 => 4,
            8..=15 => 5,
            16..=31 => 6,
            _ => 7,
        };
        h[k] += 1;
    }
    (n, mx, s, s2, h)
}

#[test]
fn random_against_model() {
    let mut rng = Rng(0x5EED_0001);
    for case in 0..400 {
        let w = 1 + rng.below(24) as u32;
        let h = 1 + rng.below(24) as u32;
        let bits = 1 + rng.below(16) as u32;
        let spread = [1i64, 4, 300, 5000, 65536][rng.below(5) as usize];
        let a = Image {
            width: w,
            height: h,
            px: (0..w * h)
                .map(|_| [0; 4].map(|_: u16| rng.below(65536) as u16))
                .collect(),
        };
        let px_b: Vec<[u16; 4]> =
            a.px.iter()
                .map(|p| {
                    p.map(|c| {
                        let d = rng.below(2 * spread as u64) as i64 - spread;
                        (i64::from(c) + d).clamp(0, 65535) as u16
                    })
                })
                .collect();
        let b = Image {
            width: w,
            height: h,
            px: px_b,
        };
        let mask: Vec<bool> = (0..w * h).map(|_| rng.below(4) != 0).collect();
        let m = compare(&a, &b, bits, Some(&mask));
        let (n, mx, s, s2, hist) = model(&a, &b, bits, &mask);
        assert_eq!(m.pixels, n, "case {case}");
        assert_eq!(m.max_abs_lsb, mx, "case {case}");
        if n > 0 {
            let k = 3.0 * n as f64;
            assert!(
                (m.mean_abs_lsb - s / k).abs() <= 1e-9 * (1.0 + s / k),
                "case {case}"
            );
            let rmse = (s2 / k).sqrt();
            assert!(
                (m.rmse_lsb - rmse).abs() <= 1e-9 * (1.0 + rmse),
                "case {case}"
            );
            match m.psnr_db {
                None => assert_eq!(s2, 0.0),
                Some(p) => {
                    let expect = 20.0 * (f64::from((1u32 << bits) - 1) / rmse).log10();
                    assert!((p - expect).abs() < 1e-9, "case {case}");
                }
            }
            assert!((m.pct_exact - 100.0 * hist[0] as f64 / n as f64).abs() < 1e-9);
            let within = 100.0 * (hist[0] + hist[1]) as f64 / n as f64;
            assert!((m.pct_within_1lsb - within).abs() < 1e-9);
        }
        let counts: Vec<u64> = m.histogram.iter().map(|(_, n)| *n).collect();
        assert_eq!(counts, hist, "case {case}");
    }
}

#[test]
fn table_and_json() {
    let (a, b) = hand_pair();
    let same = compare(&a, &a, 8, None);
    let diff = compare(&a, &b, 8, None);
    let t = format_metrics_table(&[("identical", &same), ("hw-vs-ref", &diff)]);
    let lines: Vec<&str> = t.lines().collect();
    assert_eq!(lines.len(), 4, "{t}"); // header, rule, 2 rows
    let width = lines[0].chars().count();
    assert!(lines.iter().all(|l| l.chars().count() == width), "{t}");
    assert!(
        lines[2].starts_with("identical") && lines[2].contains("inf"),
        "{t}"
    );
    assert!(
        lines[3].contains("26.52") && lines[3].contains(" 40 "),
        "{t}"
    );
    assert!(lines[0].contains("e=32+"), "{t}");
    let json = serde_json::to_value(&same).expect("json");
    assert!(json["psnr_db"].is_null());
    assert_eq!(json["histogram"][0], serde_json::json!(["0", 4]));
    let json = serde_json::to_value(&diff).expect("json");
    assert_eq!(json["max_abs_lsb"], 40);
}

/// `compare` against a per-pixel model (`Image::get`, `quantize`) on images of different
/// sizes whose pixel vectors may be shorter or longer than their size, with short masks.
#[test]
fn random_sizes_and_broken_images_against_model() {
    use texsim::report::quantize;
    let mut rng = Rng(0x5EED_0002);
    for case in 0..300 {
        let bits = 1 + rng.below(16) as u32;
        let img = |rng: &mut Rng| {
            let (w, h) = (rng.below(12) as u32, rng.below(12) as u32);
            let mut px: Vec<[u16; 4]> = (0..w * h)
                .map(|_| [0; 4].map(|_: u16| rng.below(65536) as u16))
                .collect();
            match rng.below(4) {
                0 => px.truncate(rng.below(px.len() as u64 + 1) as usize),
                1 => px.extend((0..rng.below(20)).map(|_| [9u16; 4])),
                _ => {}
            }
            Image {
                width: w,
                height: h,
                px,
            }
        };
        let (a, b) = (img(&mut rng), img(&mut rng));
        let n = u64::from(a.width * a.height);
        let mask: Option<Vec<bool>> =
            (rng.below(2) == 0).then(|| (0..rng.below(n + 5)).map(|_| rng.below(3) != 0).collect());
        let (mut pixels, mut max, mut sum) = (0u64, 0u32, 0u64);
        for y in 0..a.height.min(b.height) {
            for x in 0..a.width.min(b.width) {
                let i = (y * a.width + x) as usize;
                if mask
                    .as_ref()
                    .is_some_and(|m| !m.get(i).copied().unwrap_or(false))
                {
                    continue;
                }
                let (Some(pa), Some(pb)) = (a.get(x, y), b.get(x, y)) else {
                    continue;
                };
                pixels += 1;
                for c in 0..3 {
                    let e = quantize(pa[c], bits).abs_diff(quantize(pb[c], bits));
                    max = max.max(e);
                    sum += u64::from(e);
                }
            }
        }
        let m = compare(&a, &b, bits, mask.as_deref());
        assert_eq!((m.pixels, m.max_abs_lsb), (pixels, max), "case {case}");
        let mean = if pixels == 0 {
            0.0
        } else {
            sum as f64 / (3 * pixels) as f64
        };
        assert!(
            (m.mean_abs_lsb - mean).abs() <= 1e-12 * (1.0 + mean),
            "case {case}"
        );
    }
}
