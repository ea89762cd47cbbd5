//! Reciprocal unit vs exact integer arithmetic: exhaustive over all 24-bit mantissas for
//! texram16, seeded random for other configs; asserts the documented ulp bound.
//! Run `cargo test --test units unit_reciprocal:: -- --nocapture` to see the error table.

use crate::rng_common::Rng;
use hw_model::config::{HwConfig, ReciprocalConfig};
use hw_model::fixed::{Rounding, SatCounter};
use hw_model::reciprocal::{Recip, Reciprocal, GUARD_BITS};

/// Signed error of `r` vs 1/x in ulps of the result (ulp = 2^-shift), exact in i128.
fn err_ulps(x: u64, r: Recip) -> f64 {
    assert!(r.shift >= 0 && r.shift < 126, "shift {}", r.shift);
    let num = i128::from(r.mant) * i128::from(x) - (1i128 << r.shift);
    num as f64 / x as f64
}

/// The documented bound in ulps.
fn bound_ulps(cfg: &ReciprocalConfig) -> f64 {
    let m = cfg.recip_mantissa_bits;
    let p = m + GUARD_BITS;
    let tp = 2f64.powi(-(p as i32));
    let mut e = 2f64.powi(-(cfg.recip_lut_bits as i32 + 1)) + tp;
    for _ in 0..cfg.recip_iterations {
        e = e * e + 4.0 * tp;
    }
    let h = if cfg.recip_rounding == Rounding::Truncate {
        1.0
    } else {
        0.5
    };
    2f64.powi(m as i32 + 1) * (e + tp) * 1.001 + h
}

fn cfg_with(l: u32, n: u32, m: u32, r: Rounding) -> ReciprocalConfig {
    let mut c = HwConfig::texram16().reciprocal;
    c.recip_lut_bits = l;
    c.recip_iterations = n;
    c.recip_mantissa_bits = m;
    c.recip_rounding = r;
    c
}

fn check(unit: &Reciprocal, cfg: &ReciprocalConfig, x: u64, bound: f64, max: &mut f64) {
    let mut sat = SatCounter::default();
    let r = unit.eval(x, &mut sat);
    assert_eq!(sat, SatCounter::default());
    assert_eq!(
        r.mant >> cfg.recip_mantissa_bits,
        1,
        "mantissa not normalized for x={x}"
    );
    let e = err_ulps(x, r).abs();
    assert!(e <= bound, "x={x} err {e} ulps > bound {bound} ({cfg:?})");
    if e > *max {
        *max = e;
    }
}

#[test]
fn texram16_exhaustive_24_bit() {
    let cfg = HwConfig::texram16().reciprocal;
    let unit = Reciprocal::new(&cfg);
    let bound = bound_ulps(&cfg);
    let mut max = 0.0;
    for x in 1u64..(1 << 24) {
        check(&unit, &cfg, x, bound, &mut max);
    }
    println!("texram16 (L=8,N=2,M=24) exhaustive 2^24: max err {max:.3} ulps (bound {bound:.3})");
    assert!(
        max <= 1.0,
        "two iterations from an 8-bit seed should be within 1 ulp"
    );
}

#[test]
fn one_iteration_exhaustive_24_bit_is_seed_limited() {
    let mut cfg = HwConfig::texram16().reciprocal;
    cfg.recip_iterations = 1;
    let unit = Reciprocal::new(&cfg);
    let bound = bound_ulps(&cfg);
    let mut max = 0.0;
    for x in 1u64..(1 << 24) {
        check(&unit, &cfg, x, bound, &mut max);
    }
    println!("(L=8,N=1,M=24) exhaustive 2^24: max err {max:.3} ulps (bound {bound:.3})");
    assert!(max > 1.0, "seed-limited config should show > 1 ulp error");
}

#[test]
fn lut_iteration_table() {
    let mut rng = Rng(0x5eed_0001);
    let combos = [
        (8, 0),
        (8, 1),
        (6, 2),
        (12, 1),
        (8, 2),
        (16, 0),
        (4, 3),
        (10, 1),
    ];
    for (l, n) in combos {
        let cfg = cfg_with(l, n, 24, Rounding::HalfEven);
        let unit = Reciprocal::new(&cfg);
        let bound = bound_ulps(&cfg);
        let mut max = 0.0;
        for _ in 0..400_000 {
            let x = (rng.next() >> 40) | (1 << 23);
            check(&unit, &cfg, x, bound, &mut max);
        }
        println!("M=24 L={l:2} N={n}: max err {max:12.3} ulps (bound {bound:12.3})");
    }
}

#[test]
fn random_configs_and_widths() {
    let mut rng = Rng(0x5eed_0002);
    let modes = [Rounding::Truncate, Rounding::HalfUp, Rounding::HalfEven];
    for k in 0..48u32 {
        let cfg = cfg_with(
            1 + (rng.next() % 16) as u32,
            (rng.next() % 5) as u32,
            [8, 12, 16, 20, 24, 30][(k % 6) as usize],
            modes[(k / 6 % 3) as usize],
        );
        let unit = Reciprocal::new(&cfg);
        let bound = bound_ulps(&cfg);
        let mut max = 0.0;
        for _ in 0..25_000 {
            let bits = 1 + (rng.next() % 64) as u32;
            let x = (rng.next() >> (64 - bits)) | (1u64 << (bits - 1));
            check(&unit, &cfg, x, bound, &mut max);
        }
    }
}

#[test]
fn converged_config_is_within_one_ulp() {
    let mut rng = Rng(0x5eed_0003);
    for mode in [Rounding::HalfEven, Rounding::HalfUp, Rounding::Truncate] {
        let cfg = cfg_with(8, 2, 24, mode);
        let unit = Reciprocal::new(&cfg);
        let mut max = 0.0;
        for _ in 0..200_000 {
            let x = (rng.next() >> 40) | (1 << 23);
            check(&unit, &cfg, x, bound_ulps(&cfg), &mut max);
        }
        let lim = if mode == Rounding::Truncate { 1.6 } else { 1.1 };
        assert!(max < lim, "{mode:?}: {max}");
    }
}

#[test]
fn zero_saturates() {
    let cfg = HwConfig::texram16().reciprocal;
    let unit = Reciprocal::new(&cfg);
    let mut sat = SatCounter::default();
    let r = unit.eval(0, &mut sat);
    assert_eq!(sat.saturated, 1);
    assert_eq!(r.mant, (1 << 25) - 1);
    assert_eq!(r.shift, 0);
    let big = unit.eval(u64::MAX, &mut sat);
    assert_eq!(sat.saturated, 1);
    assert!(err_ulps(u64::MAX, big).abs() <= bound_ulps(&cfg));
}
