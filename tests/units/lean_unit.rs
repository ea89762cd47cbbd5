//! The LEAN unit (`hw_model::lean`, Olano and Baker 2010) against its float twin
//! (`texsim::shading::lean::lean_f`) on the same quantized inputs: 10^7 seeded cases (random
//! filtered slope moments, half vectors out to grazing), the hard cases (a flat map is the base
//! lobe exactly, singular Sigma from one-dimensional bumps, quantized `M - B B^T` below zero,
//! the half vector at and below the horizon, garbage texels) and the cost.

use crate::rng_common::Rng;
use glam::DVec3;
use hw_model::fixed::SatCounter;
use hw_model::lean::{datapath, lean, lean_cost, LeanConfig, LeanInput};
use hw_model::ndf::{NdfConfig, NdfDensity, NdfNorm, NdfUnit};
use hw_model::HwConfig;
use texsim::shading::lean::{decode_moments, lean_f};

const TB: u32 = 16;
const R: u32 = 3;
const F: u32 = 14;
const P: u32 = 16;

fn density() -> NdfUnit {
    let hw = HwConfig::texram16();
    let cfg = NdfConfig {
        ndf_density: NdfDensity::Gauss,
        ndf_norm: NdfNorm::Partial,
        ..hw.ndf.clone()
    };
    NdfUnit::new(&cfg, &hw.reciprocal, &hw.shading.rsqrt).expect("unit")
}

fn unorm(x: f64) -> u32 {
    (x.clamp(0.0, 1.0) * 65535.0).round() as u32
}

/// Encoded texels of slope moments `b`, `m` (the maps' encodings).
fn texels(b: [f64; 2], m: [f64; 3], e: u32) -> ([u32; 2], [u32; 3]) {
    let r = f64::from(R).exp2();
    let s = f64::from(e).exp2();
    (
        b.map(|x| unorm(x / (2.0 * r) + 0.5)),
        [unorm(m[0] / s), unorm(m[1] / s), unorm(0.5 + m[2] / s)],
    )
}

fn h_raw(h: DVec3) -> [i64; 3] {
    [h.x, h.y, h.z].map(|c| (c * f64::from(1u32 << F)).round() as i64)
}

/// Fixed and float `D` on the same quantized inputs.
fn pair(
    bt: [u32; 2],
    mt: [u32; 3],
    h: [i64; 3],
    s: u32,
    cfg: &LeanConfig,
    d: &NdfUnit,
) -> (f64, f64, SatCounter) {
    let mut sat = SatCounter::default();
    let inp = LeanInput {
        b: bt,
        m: mt,
        texel_bits: TB,
        offset_int_bits: R,
        h,
        h_frac_bits: F,
        shininess: s,
    };
    let o = lean(&inp, cfg, d, P, &mut sat);
    assert!(o.d >= 0 && o.d <= 1 << P, "{o:?}");
    let rr = f64::from(R).exp2();
    let b = bt.map(|t| (f64::from(t) / 65535.0 - 0.5) * 2.0 * rr);
    let m = decode_moments(mt.map(|t| f64::from(t) / 65535.0), cfg.lean_moment_exp);
    let hf = DVec3::new(h[0] as f64, h[1] as f64, h[2] as f64) / f64::from(1u32 << F);
    (o.d as f64 / f64::from(1u32 << P), lean_f(b, m, hf, s), sat)
}

#[test]
fn seeded_against_the_float_twin() {
    let cfg = LeanConfig::texram16();
    let d = density();
    let mut rng = Rng(0x1ea2_0010);
    let mut worst = 0.0f64;
    for _ in 0..10_000_000u32 {
        let s = 1 + rng.below(4096) as u32;
        // A mixture of two slopes with weights: a filtered texel's moments.
        let (a, c) = (
            [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)],
            [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)],
        );
        let w = rng.unit();
        let b = [w * a[0] + (1.0 - w) * c[0], w * a[1] + (1.0 - w) * c[1]];
        let m = [
            w * a[0] * a[0] + (1.0 - w) * c[0] * c[0],
            w * a[1] * a[1] + (1.0 - w) * c[1] * c[1],
            w * a[0] * a[1] + (1.0 - w) * c[0] * c[1],
        ];
        let (bt, mt) = texels(b, m, cfg.lean_moment_exp);
        // Half vectors around the mean normal, out to grazing.
        let hz = rng.range(0.02, 1.0);
        let ph = rng.range(0.0, std::f64::consts::TAU);
        let hr = (1.0 - hz * hz).sqrt();
        let h = DVec3::new(hr * ph.cos(), hr * ph.sin(), hz);
        let (fx, fl, _) = pair(bt, mt, h_raw(h), s, &cfg, &d);
        let e = (fx - fl).abs();
        worst = worst.max(e);
        assert!(
            e <= 2f64.powi(-12),
            "s {s} b {b:?} m {m:?} h {h}: fixed {fx} float {fl}"
        );
    }
    eprintln!("lean seeded (10^7): worst |D - D_f| {worst:.3e} (bound 2^-12 = 2.44e-4)");
}

#[test]
fn flat_map_is_the_base_lobe() {
    let cfg = LeanConfig::texram16();
    let d = density();
    let (bt, mt) = texels([0.0, 0.0], [0.0, 0.0, 0.0], cfg.lean_moment_exp);
    for s in [1u32, 16, 64, 256, 1024, 4096] {
        // At the normal: the peak, 1.
        let (fx, fl, sat) = pair(bt, mt, [0, 0, 1 << F], s, &cfg, &d);
        assert!(
            (fl - 1.0).abs() < 1e-4 && (fx - 1.0).abs() < 1e-3,
            "s {s}: {fx} {fl}"
        );
        // The unorm centre code of M_uv is half an LSB off zero (Sigma_uv = 2^-16, not 0), so
        // the normalization may reach 1 + 2^-20: clamped to 1, counted.
        assert!(sat.saturated <= 1, "s {s}");
        // Off the normal: exp(-s tan^2 / 2), the Blinn-Phong-like base lobe.
        let t: f64 = 0.5 / f64::from(s).sqrt();
        let h = DVec3::new(t, 0.0, 1.0).normalize();
        let (fx, fl, _) = pair(bt, mt, h_raw(h), s, &cfg, &d);
        let want = (-0.5 * f64::from(s) * t * t).exp();
        assert!(
            (fl - want).abs() < 0.02 && (fx - fl).abs() < 2e-3,
            "s {s}: {fx} {fl} {want}"
        );
    }
}

#[test]
fn hard_cases_stay_finite_and_bounded() {
    let cfg = LeanConfig::texram16();
    let d = density();
    // One-dimensional bumps (corrugation): Sigma_vv = 1/s only, Sigma singular without the base.
    let (bt, mt) = texels([0.0, 0.0], [0.5, 0.0, 0.0], cfg.lean_moment_exp);
    let (fx, fl, _) = pair(bt, mt, [0, 0, 1 << F], 256, &cfg, &d);
    assert!(fx > 0.0 && fx <= 1.0 && (fx - fl).abs() < 1e-3, "{fx} {fl}");
    // M - B B^T below zero (inconsistent texels): clamped and counted, still finite.
    let (bt, mt) = texels([0.8, 0.8], [0.0, 0.0, 0.0], cfg.lean_moment_exp);
    let (fx, _, sat) = pair(bt, mt, [0, 0, 1 << F], 64, &cfg, &d);
    assert!(sat.saturated >= 2 && (0.0..=1.0).contains(&fx));
    // An off-diagonal that makes det <= 0: dropped and counted.
    let (bt, mt) = texels([0.0, 0.0], [0.1, 0.1, 0.2], cfg.lean_moment_exp);
    let (_, _, sat) = pair(bt, mt, [0, 0, 1 << F], 4096, &cfg, &d);
    assert!(sat.saturated >= 1);
    // Half vector on and below the horizon: 0; grazing: the slope is clamped, finite.
    let (bt, mt) = texels([0.0, 0.0], [0.0, 0.0, 0.0], cfg.lean_moment_exp);
    for h in [[1 << F, 0, 0], [1 << F, 0, -5]] {
        assert_eq!(pair(bt, mt, h, 64, &cfg, &d).0, 0.0);
    }
    let (fx, fl, sat) = pair(bt, mt, [1 << F, 0, 1], 1, &cfg, &d);
    assert!(sat.saturated >= 1 && fx == 0.0 && fl < 1e-6, "{fx} {fl}");
    // Garbage texels and vectors: never out of [0, 1].
    let mut rng = Rng(7);
    for _ in 0..200_000 {
        let bt = [0, 1].map(|_| rng.below(65536) as u32);
        let mt = [0, 1, 2].map(|_| rng.below(65536) as u32);
        let h = [0, 1, 2].map(|_| rng.below(1 << 16) as i64 - (1 << 15));
        let s = rng.below(70000) as u32;
        let (fx, fl, _) = pair(bt, mt, h, s, &cfg, &d);
        assert!(fl.is_finite() && (0.0..=1.0).contains(&fl) && (0.0..=1.0).contains(&fx));
    }
}

#[test]
fn cost_follows_the_datapath() {
    let cfg = LeanConfig::texram16();
    let c = lean_cost(&cfg, 32);
    assert_eq!(c.cycles, datapath(&cfg).latency(32));
    let narrow = LeanConfig {
        lean_frac_bits: 16,
        ..cfg.clone()
    };
    assert!(datapath(&narrow).area() < datapath(&cfg).area());
    let bad = LeanConfig {
        lean_moment_exp: 9,
        ..cfg
    };
    assert!(bad
        .validate()
        .unwrap_err()
        .field
        .contains("lean_moment_exp"));
}
