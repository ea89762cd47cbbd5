//! The Toksvig exponent unit (`hw_model::toksvig`, Toksvig 2005) against its float twin
//! (`texsim::shading::toksvig::toksvig_f`) on the same quantized texels: exhaustive over every
//! 8-bit texel triple (2^24 cases, the exponent cycling through 1..4096), 10^7 seeded 16-bit
//! cases, the hard cases (flat texel, zero mean, |Na| above 1, s = 0, huge s), monotonicity and
//! the cost.

use crate::rng_common::Rng;
use hw_model::fixed::SatCounter;
use hw_model::toksvig::{datapath, toksvig, toksvig_cost, ToksvigConfig};
use texsim::shading::toksvig::toksvig_f;

const EXPONENTS: [u32; 7] = [1, 8, 32, 64, 256, 1024, 4096];

/// `|Na|` of raw texels as the float path decodes them.
fn length(t: [u32; 3], tb: u32) -> f64 {
    let m = f64::from((1u32 << tb) - 1);
    t.iter()
        .map(|&x| {
            let c = (2.0 * f64::from(x) - m) / m;
            c * c
        })
        .sum::<f64>()
        .sqrt()
}

/// Checks one case against the documented bound; returns (exponent error, bound) ratio.
fn check(t: [u32; 3], tb: u32, s: u32, cfg: &ToksvigConfig, sat: &mut SatCounter) -> f64 {
    let cb = 16;
    let cmax = f64::from((1u32 << cb) - 1);
    let ks = [65535, 40000, 1];
    let o = toksvig(t, tb, s, ks, cb, cfg, sat);
    let l = length(t, tb).min(1.0);
    let (sp, scale) = toksvig_f(l, s);
    let b = 2f64.powi(-(cfg.toksvig_sqrt_bits as i32));
    let slope = if l > 0.0 { sp * sp / l } else { 0.0 };
    let bound = 0.5 + slope * b * (1.0 + 2.0 * b) + 1e-9;
    let e = (f64::from(o.exponent) - sp).abs();
    assert!(
        e <= bound,
        "t {t:?} tb {tb} s {s}: n' {} s' {sp} bound {bound}",
        o.exponent
    );
    assert!(o.exponent <= s);
    for (k, &kf) in o.ks.iter().zip(&ks) {
        let want = f64::from(kf) * scale;
        let kb = f64::from(kf) / cmax * cmax * bound / (1.0 + f64::from(s)) + 0.5 + 1e-9;
        assert!(
            (f64::from(*k) - want).abs() <= kb,
            "t {t:?} s {s}: ks {k} want {want} bound {kb}"
        );
    }
    e / bound
}

#[test]
fn exhaustive_8_bit_texels() {
    let cfg = ToksvigConfig::texram16();
    let mut sat = SatCounter::default();
    let mut worst = 0.0f64;
    let mut i = 0usize;
    for a in 0..256u32 {
        for b in 0..256u32 {
            for c in 0..256u32 {
                let s = EXPONENTS[i % EXPONENTS.len()];
                i += 1;
                worst = worst.max(check([a, b, c], 8, s, &cfg, &mut sat));
            }
        }
    }
    assert_eq!(i, 1 << 24);
    assert!(sat.saturated > 0, "|Na| > 1 codes exist and are clamped");
    eprintln!("toksvig exhaustive 8-bit: worst error / bound {worst:.3}");
}

#[test]
fn seeded_16_bit_texels() {
    let mut rng = Rng(0x70c5_5716);
    let mut worst = 0.0f64;
    let mut sat = SatCounter::default();
    for bits in [16u32, 12] {
        let cfg = ToksvigConfig {
            toksvig_sqrt_bits: bits,
            ..ToksvigConfig::texram16()
        };
        for _ in 0..5_000_000 {
            // Mostly plausible filtered normals (length 0.3..1), some garbage texels.
            let t = if rng.below(8) == 0 {
                [0, 1, 2].map(|_| rng.below(65536) as u32)
            } else {
                let z = rng.range(0.0, 1.0);
                let r = (1.0 - z * z).sqrt();
                let ph = rng.range(0.0, std::f64::consts::TAU);
                let len = rng.range(0.3, 1.0);
                [r * ph.cos(), r * ph.sin(), z]
                    .map(|c| ((c * len + 1.0) * 0.5 * 65535.0).round() as u32)
            };
            let s = 1 + rng.below(8192) as u32;
            worst = worst.max(check(t, 16, s, &cfg, &mut sat));
        }
    }
    eprintln!("toksvig seeded 16-bit (10^7): worst error / bound {worst:.3}");
}

#[test]
fn hard_cases() {
    let cfg = ToksvigConfig::texram16();
    let mut sat = SatCounter::default();
    let m = 65535u32;
    let half = 32768u32;
    let ks = [60000, 30000, 0];
    // A flat texel: |Na| = 1 to within the encoding, the exponent and ks stay.
    for s in EXPONENTS {
        let o = toksvig([half, half, m], 16, s, ks, 16, &cfg, &mut sat);
        assert_eq!(o.exponent, s, "flat, s {s}");
        assert_eq!(o.ks, ks, "flat, s {s}");
    }
    assert_eq!(sat.saturated, 0);
    // A zero mean (opposite normals cancel): exponent 0, ks / (1 + s).
    let o = toksvig([half, half, half], 16, 64, ks, 16, &cfg, &mut sat);
    assert!(o.exponent == 0, "{o:?}");
    assert_eq!(o.ks, [923, 462, 0]);
    // |Na| above 1 (texels that no average of unit normals makes): clamped and counted.
    let o = toksvig([m, m, m], 16, 100, ks, 16, &cfg, &mut sat);
    assert_eq!(o.exponent, 100);
    assert_eq!(sat.saturated, 1);
    // s = 0: nothing to adjust.
    let o = toksvig([half, half, m], 16, 0, ks, 16, &cfg, &mut sat);
    assert_eq!((o.exponent, o.ks), (0, ks));
    // A huge exponent: L = 0.999 still broadens it by orders of magnitude.
    let z = ((0.999f64 + 1.0) * 0.5 * 65535.0).round() as u32;
    let o = toksvig([half, half, z], 16, 65535, ks, 16, &cfg, &mut sat);
    let (sp, _) = toksvig_f(length([half, half, z], 16), 65535);
    assert!(
        (f64::from(o.exponent) - sp).abs() < 2.0 && sp < 1100.0,
        "{o:?} {sp}"
    );
}

#[test]
fn exponent_grows_with_the_mean_length() {
    let cfg = ToksvigConfig::texram16();
    let mut sat = SatCounter::default();
    for s in EXPONENTS {
        let mut last = 0;
        for z in 32768..=65535u32 {
            let o = toksvig([32768, 32768, z], 16, s, [65535; 3], 16, &cfg, &mut sat);
            assert!(o.exponent >= last, "s {s} z {z}");
            last = o.exponent;
        }
        assert_eq!(last, s);
    }
}

#[test]
fn float_twin_limits() {
    assert_eq!(toksvig_f(1.0, 64), (64.0, 1.0));
    assert_eq!(toksvig_f(0.0, 64).0, 0.0);
    let (sp, sc) = toksvig_f(0.9, 100);
    assert!((sp - 0.9 * 100.0 / (0.9 + 10.0)).abs() < 1e-12);
    assert!((sc - (1.0 + sp) / 101.0).abs() < 1e-12);
    assert!(toksvig_f(f64::NAN, 8).0.is_finite());
}

#[test]
fn cost_follows_the_datapath() {
    let cfg = ToksvigConfig::texram16();
    let c = toksvig_cost(&cfg, 16, 32);
    assert_eq!(c.cycles, datapath(&cfg, 16).latency(32));
    assert!(c.ops > 0 && c.texels == 0);
    let narrow = ToksvigConfig {
        toksvig_sqrt_bits: 8,
        ..cfg.clone()
    };
    assert!(datapath(&narrow, 8).area() < datapath(&cfg, 16).area());
    assert!(toksvig_cost(&narrow, 8, 32).cycles < c.cycles);
    let bad = ToksvigConfig {
        toksvig_sqrt_bits: 3,
        ..cfg
    };
    let e = bad.validate().unwrap_err();
    assert!(e.field.contains("toksvig_sqrt_bits"), "{e:?}");
}
