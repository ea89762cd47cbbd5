//! Power unit (log-exp tables and repeated squaring) against f64 powf, exponents 1..=2047 (all
//! that texram16's 11 exponent bits hold), every rounding mode.

use crate::rng_common::Rng;
use hw_model::fixed::Rounding;
use hw_model::pow::{pow_cost, Pow, PowConfig, PowMethod};
use hw_model::SatCounter;

/// The documented absolute bound for `x^n` (x, result in [0, 1]).
pub(crate) fn bound(cfg: &PowConfig, x: f64, n: u32) -> f64 {
    let p = f64::from(cfg.pow_frac_bits);
    let g = -(p + f64::from(cfg.pow_guard_bits));
    let h2 = (-2.0 * f64::from(cfg.pow_lut_bits)).exp2();
    // The output's rounding: half an ulp, a whole one when truncating.
    let half = if cfg.pow_rounding == Rounding::Truncate {
        (-p).exp2()
    } else {
        (-(p + 1.0)).exp2()
    };
    let xn = x.powf(f64::from(n));
    match cfg.pow_method {
        PowMethod::LogExp => {
            let el = 0.1803 * h2 + g.exp2();
            let ee = 0.0601 * h2 + g.exp2();
            xn * ((f64::from(n) * el).exp2() - 1.0 + ee) + half
        }
        PowMethod::Squaring => 2.0 * f64::from(n) * g.exp2() + half,
    }
}

/// Inputs: edges, values near 1 (where x^n stays large) and uniform ones.
fn inputs(p: u32, s: &mut Rng, count: usize) -> Vec<u64> {
    let one = 1u64 << p;
    let mut v = vec![0, 1, 2, one / 2, one - 1, one];
    while v.len() < count {
        let r = s.next();
        let x = if r & 1 == 0 {
            one - (r >> 1) % (one / 64 + 1)
        } else {
            (r >> 1) % (one + 1)
        };
        v.push(x);
    }
    v
}

/// (max abs error, max error/bound) over the exponents `exps` with `per_n` inputs each.
fn measure(cfg: &PowConfig, per_n: usize, exps: &[u32]) -> (f64, f64) {
    let u = Pow::new(cfg);
    let p = cfg.pow_frac_bits;
    let scale = (-f64::from(p)).exp2();
    let mut s = Rng(99);
    let mut sat = SatCounter::default();
    let (mut worst, mut ratio) = (0.0f64, 0.0f64);
    for &n in exps {
        for x in inputs(p, &mut s, per_n) {
            let xf = x as f64 * scale;
            let got = u.pow(x, n, &mut sat) as f64 * scale;
            let e = (got - xf.powf(f64::from(n))).abs();
            worst = worst.max(e);
            ratio = ratio.max(e / bound(cfg, xf, n));
        }
    }
    assert_eq!(sat.saturated, 0);
    (worst, ratio)
}

/// Every exponent texram16 holds (1..=2047), 600 inputs each (1.2M cases) per rounding mode.
fn within_bound_every_exponent_and_mode(method: PowMethod, name: &str) {
    let exps: Vec<u32> = (1..=2047).collect();
    for mode in [Rounding::HalfEven, Rounding::HalfUp, Rounding::Truncate] {
        let cfg = PowConfig {
            pow_method: method,
            pow_rounding: mode,
            ..PowConfig::texram16()
        };
        let (w, r) = measure(&cfg, 600, &exps);
        println!(
            "pow {name} texram16 {mode:?}: max abs err {:.2} ulp(2^-16), max err/bound {r:.3}",
            w * 65536.0
        );
        assert!(r <= 1.0, "{name} {mode:?}: {r}");
    }
}

#[test]
fn log_exp_within_bound_all_exponents() {
    within_bound_every_exponent_and_mode(PowMethod::LogExp, "log-exp");
}

#[test]
fn squaring_within_bound_all_exponents() {
    within_bound_every_exponent_and_mode(PowMethod::Squaring, "squaring");
}

#[test]
fn pow_edges_and_saturation() {
    for method in [PowMethod::LogExp, PowMethod::Squaring] {
        let cfg = PowConfig {
            pow_method: method,
            ..PowConfig::texram16()
        };
        let u = Pow::new(&cfg);
        let one = 1u64 << 16;
        let mut sat = SatCounter::default();
        assert_eq!(u.pow(0, 0, &mut sat), one);
        assert_eq!(u.pow(0, 5, &mut sat), 0);
        assert_eq!(u.pow(one, 1000, &mut sat), one);
        assert_eq!(u.pow(12345, 1, &mut sat), 12345);
        assert_eq!(sat.saturated, 0);
        assert_eq!(u.pow(one + 5, 2, &mut sat), one);
        assert_eq!(sat.saturated, 1, "input above 1.0 counted");
        let _ = u.pow(one / 2, 1 << 11, &mut sat);
        assert_eq!(
            sat.saturated, 2,
            "exponent beyond pow_exponent_bits counted"
        );
    }
}

#[test]
fn pow_error_table() {
    let exps: Vec<u32> = [
        1u32, 2, 3, 5, 8, 13, 20, 32, 50, 64, 100, 128, 200, 256, 500, 512, 1000, 1024,
    ]
    .to_vec();
    println!("pow max abs error in ulp of 2^-16 (P=16, guard 8), exponents 1..1024 sampled");
    println!("pow_lut_bits | log-exp err | err/bound | cycles");
    for l in [4u32, 6, 8, 10, 12] {
        let cfg = PowConfig {
            pow_lut_bits: l,
            ..PowConfig::texram16()
        };
        let (w, r) = measure(&cfg, 3000, &exps);
        assert!(r <= 1.0, "L={l}: {r}");
        println!(
            "{l:12} | {:11.2} | {r:9.3} | {}",
            w * 65536.0,
            pow_cost(&cfg, hw_model::timing_config::DEFAULT_GATE_LEVELS_PER_CYCLE).cycles
        );
    }
    println!("pow_guard_bits | squaring err | err/bound | cycles");
    for gb in [0u32, 4, 8, 12] {
        let cfg = PowConfig {
            pow_method: PowMethod::Squaring,
            pow_guard_bits: gb,
            ..PowConfig::texram16()
        };
        let (w, r) = measure(&cfg, 3000, &exps);
        assert!(r <= 1.0, "guard={gb}: {r}");
        println!(
            "{gb:14} | {:12.2} | {r:9.3} | {}",
            w * 65536.0,
            pow_cost(&cfg, hw_model::timing_config::DEFAULT_GATE_LEVELS_PER_CYCLE).cycles
        );
    }
}
