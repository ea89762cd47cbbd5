//! Vector unit (dot, cross, normalize, madd, offset decode) against an f64 model, seeded random.
#![allow(clippy::needless_range_loop)]

use crate::rng_common::Rng;
use hw_model::rsqrt::{Rsqrt, RsqrtConfig};
use hw_model::vector::{
    cross3, dot3, madd, normalize3, offset_format, offset_from_texel, vector_format, wide_format,
    VectorConfig,
};
use hw_model::SatCounter;

fn ulp(f: u32) -> f64 {
    (-f64::from(f)).exp2()
}

#[test]
fn dot_and_cross_half_ulp() {
    let cfg = VectorConfig::texram16();
    let f = cfg.vector_frac_bits;
    let fmt = vector_format(&cfg);
    let (lo, hi) = (fmt.min_raw(), fmt.max_raw());
    let mut s = Rng(1);
    let mut sat = SatCounter::default();
    let mut n_sat = 0u64;
    for _ in 0..1_000_000 {
        let a = [0; 3].map(|_: i64| s.int_in(lo, hi));
        let b = [0; 3].map(|_: i64| s.int_in(lo, hi) / 2);
        let exact: f64 = (0..3).map(|i| (a[i] * b[i]) as f64).sum::<f64>() * ulp(2 * f);
        let before = sat.saturated;
        let d = dot3(&a, &b, &cfg, &mut sat) as f64 * ulp(f);
        if sat.saturated > before {
            n_sat += 1;
            assert!(
                exact >= 2.0 - ulp(f) || exact < -2.0,
                "spurious saturation {exact}"
            );
            assert_eq!(d, exact.clamp(-2.0, 2.0 - ulp(f)));
        } else {
            assert!((d - exact).abs() <= 0.5 * ulp(f), "dot {d} vs {exact}");
        }
        let before = sat.saturated;
        let c = cross3(&a, &b, &cfg, &mut sat);
        let ex = [
            (a[1] * b[2] - a[2] * b[1]) as f64,
            (a[2] * b[0] - a[0] * b[2]) as f64,
            (a[0] * b[1] - a[1] * b[0]) as f64,
        ];
        for i in 0..3 {
            let e = ex[i] * ulp(2 * f);
            let g = c[i] as f64 * ulp(f);
            if (-2.0..2.0 - ulp(f)).contains(&e) {
                assert!((g - e).abs() <= 0.5 * ulp(f), "cross {g} vs {e}");
            } else {
                assert_eq!(g, e.clamp(-2.0, 2.0 - ulp(f)));
            }
        }
        n_sat += sat.saturated - before;
    }
    assert_eq!(sat.saturated, n_sat);
    assert_eq!(sat.wrapped, 0);
    assert!(n_sat > 0, "the saturation path was exercised");
}

/// Normalize: per-component error <= rsqrt bound + 1/2 ulp, for inputs of any scale.
#[test]
fn normalize_error_bound() {
    let cfg = VectorConfig::texram16();
    let f = cfg.vector_frac_bits;
    let rs = Rsqrt::new(&RsqrtConfig::texram16());
    let bound = 6.53e-6 + 0.5 * ulp(f);
    let mut s = Rng(3);
    let mut worst = 0.0f64;
    let mut sat = SatCounter::default();
    for i in 0..1_000_000u32 {
        let k = 1 + (i % 40) as i64;
        let lim = 1i64 << k;
        let v = [0; 3].map(|_: i64| s.int_in(-lim, lim));
        if v == [0; 3] {
            continue;
        }
        let out = normalize3(&v, [0; 3], &rs, &cfg, &mut sat);
        assert!(!out.zero);
        let len = v
            .iter()
            .map(|&c| (c as f64) * (c as f64))
            .sum::<f64>()
            .sqrt();
        for j in 0..3 {
            let e = (out.v[j] as f64 * ulp(f) - v[j] as f64 / len).abs();
            worst = worst.max(e);
        }
    }
    println!(
        "normalize max component error {:.3} ulp (bound {:.3})",
        worst / ulp(f),
        bound / ulp(f)
    );
    assert!(worst <= bound, "{worst} > {bound}");
    assert_eq!(sat.saturated, 0);
    let z = normalize3(&[0; 3], [0, 0, 1 << f], &rs, &cfg, &mut sat);
    assert!(z.zero);
    assert_eq!(z.v, [0, 0, 1 << f]);
    assert_eq!(sat.saturated, 1, "zero length is counted");
}

#[test]
fn madd_half_ulp_and_saturation_counted() {
    let cfg = VectorConfig::texram16();
    let (f, o) = (cfg.vector_frac_bits, cfg.offset_frac_bits);
    let vf = vector_format(&cfg);
    let of = offset_format(&cfg);
    let wf = wide_format(&cfg);
    let mut s = Rng(5);
    let mut sat = SatCounter::default();
    let mut expected_sat = 0;
    for _ in 0..1_000_000 {
        let n = [0; 3].map(|_: i64| s.int_in(-(1 << f), 1 << f));
        let tu = [0; 3].map(|_: i64| s.int_in(-(1 << f), 1 << f));
        let tv = [0; 3].map(|_: i64| s.int_in(-(1 << f), 1 << f));
        let gu = s.int_in(of.min_raw(), of.max_raw());
        let gv = s.int_in(of.min_raw(), of.max_raw());
        let w = madd(&n, &tu, &tv, gu, gv, &cfg, &mut sat);
        for i in 0..3 {
            let e = n[i] as f64 * ulp(f)
                + (gu * tu[i]) as f64 * ulp(f + o)
                + (gv * tv[i]) as f64 * ulp(f + o);
            let lo = wf.min_raw() as f64 * ulp(f);
            let hi = wf.max_raw() as f64 * ulp(f);
            let g = w[i] as f64 * ulp(f);
            if e < lo || e > hi {
                expected_sat += 1;
                assert_eq!(g, e.clamp(lo, hi));
            } else {
                assert!((g - e).abs() <= 0.5 * ulp(f), "madd {g} vs {e}");
            }
        }
        let _ = vf;
    }
    assert_eq!(sat.saturated, expected_sat);
}

#[test]
fn offset_decode_texram16_is_exact_bias() {
    let cfg = VectorConfig::texram16();
    let mut sat = SatCounter::default();
    for t in 0..65536u64 {
        assert_eq!(offset_from_texel(t, 16, &cfg, &mut sat), t as i64 - 32768);
    }
    assert_eq!(sat.saturated, 0);
    // 8-bit texels: f = (t/256 - 1/2) * 16 exactly representable in s3.12.
    for t in 0..256u64 {
        let f = offset_from_texel(t, 8, &cfg, &mut sat) as f64 / 4096.0;
        assert_eq!(f, (t as f64 / 256.0 - 0.5) * 16.0);
    }
}
