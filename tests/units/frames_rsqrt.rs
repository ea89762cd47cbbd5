//! rsqrt unit against an f64 model: exhaustive over all mantissas (texram16) and seeded random
//! 64-bit inputs, plus the error table over LUT bits and iterations.

use crate::rng_common::Rng;
use hw_model::rsqrt::{rsqrt_cost, Rsqrt, RsqrtConfig};
use hw_model::Rounding;

/// Documented bound: e0 = 1.06 * 2^-(L+1), e' = 1.5 e^2 + 0.5 e^3 + 3 * 2^-(B+4), plus output
/// rounding 2^-B and input rounding 2^-(B+1).
fn bound(cfg: &RsqrtConfig) -> f64 {
    let b = f64::from(cfg.rsqrt_mantissa_bits);
    let mut e = 1.06 * (-(f64::from(cfg.rsqrt_lut_bits) + 1.0)).exp2();
    for _ in 0..cfg.rsqrt_iterations {
        e = 1.5 * e * e + 0.5 * e * e * e + 3.0 * (-(b + 4.0)).exp2();
    }
    e + (-b).exp2() + (-(b + 1.0)).exp2()
}

/// Max relative error over mantissas m = 2^(B-1) + i*stride, both parities.
fn max_err_mantissas(cfg: &RsqrtConfig, stride: u64) -> f64 {
    let u = Rsqrt::new(cfg);
    let b = cfg.rsqrt_mantissa_bits;
    let mut worst = 0.0f64;
    for p in 0..2i32 {
        let mut m = 1u64 << (b - 1);
        while m < 1u64 << b {
            let r = u.eval_mantissa(m, p);
            let got = r.mant as f64 * (-f64::from(r.shift)).exp2();
            let x = m as f64 * (f64::from(p) - f64::from(b - 1)).exp2();
            let exact = 1.0 / x.sqrt();
            let e = (got / exact - 1.0).abs();
            worst = worst.max(e);
            m += stride;
        }
    }
    worst
}

#[test]
fn rsqrt_exhaustive_texram16() {
    let cfg = RsqrtConfig::texram16();
    let worst = max_err_mantissas(&cfg, 1);
    println!(
        "rsqrt texram16 exhaustive max rel err {worst:.3e} bound {:.3e}",
        bound(&cfg)
    );
    assert!(worst <= bound(&cfg), "{worst} > {}", bound(&cfg));
    assert!(worst < 6.0e-6);
}

#[test]
fn rsqrt_random_inputs_all_roundings() {
    let mut s = Rng(7);
    for rounding in [Rounding::HalfEven, Rounding::HalfUp, Rounding::Truncate] {
        let mut cfg = RsqrtConfig::texram16();
        cfg.rsqrt_rounding = rounding;
        let u = Rsqrt::new(&cfg);
        assert!(u.eval(0).is_none());
        // Truncation rounds the input and every product down: allow the one-sided extra.
        let bnd = bound(&cfg)
            * if rounding == Rounding::Truncate {
                1.5
            } else {
                1.0
            };
        let mut worst = 0.0f64;
        for i in 0..400_000u32 {
            let r = s.next();
            let x = (r >> (i % 64)).max(1);
            let o = u.eval(x).expect("nonzero");
            let got = o.mant as f64 * (-f64::from(o.shift)).exp2();
            let exact = 1.0 / (x as f64).sqrt();
            worst = worst.max((got / exact - 1.0).abs());
        }
        println!("rsqrt {rounding:?} random max rel err {worst:.3e}");
        assert!(worst <= bnd, "{rounding:?}: {worst} > {bnd}");
    }
}

#[test]
fn rsqrt_exact_powers_of_four() {
    let u = Rsqrt::new(&RsqrtConfig {
        rsqrt_iterations: 3,
        ..RsqrtConfig::texram16()
    });
    for k in 0..32 {
        let o = u.eval(1u64 << (2 * k)).expect("nonzero");
        let got = o.mant as f64 * (-f64::from(o.shift)).exp2();
        assert!(
            (got * f64::from(1u32 << k) - 1.0).abs() < 1e-7,
            "k={k} got {got}"
        );
    }
}

#[test]
fn rsqrt_error_table() {
    println!("rsqrt max rel error (B=24, sampled 2^17 mantissas per parity)");
    println!("lut_bits | it=0      | it=1      | it=2      | cost(it=1)");
    for l in [4u32, 6, 8, 10, 12] {
        let mut row = format!("{l:8} |");
        for it in 0..3 {
            let cfg = RsqrtConfig {
                rsqrt_lut_bits: l,
                rsqrt_iterations: it,
                ..RsqrtConfig::texram16()
            };
            let w = max_err_mantissas(&cfg, 64);
            assert!(w <= bound(&cfg), "L={l} it={it}: {w} > {}", bound(&cfg));
            row.push_str(&format!(" {w:.3e} |"));
        }
        let c = rsqrt_cost(
            &RsqrtConfig {
                rsqrt_lut_bits: l,
                ..RsqrtConfig::texram16()
            },
            hw_model::timing_config::DEFAULT_GATE_LEVELS_PER_CYCLE,
        );
        row.push_str(&format!(" {} cyc", c.cycles));
        println!("{row}");
    }
}

#[test]
fn rsqrt_config_validation_names_field() {
    let cfg = RsqrtConfig {
        rsqrt_lut_bits: 0,
        ..RsqrtConfig::texram16()
    };
    let e = cfg.validate().expect_err("lut bits 0");
    assert!(e.field.contains("rsqrt_lut_bits"));
    assert!(RsqrtConfig::texram16().validate().is_ok());
}
