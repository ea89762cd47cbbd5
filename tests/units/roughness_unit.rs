//! The fixed-point modified Blinn-Phong unit (`hw_model::roughness`, Schilling 1997 Appendix A)
//! against its float twin (`texsim::shading::roughness::rough_cos_twin`) on the same quantized
//! inputs: seeded random millions of cases, an exhaustive sweep of `d` over the F = 10 grid
//! (2^22 points per variant, 78.5% of them inside the unit disc), the hard cases of issue 4,
//! the meaning of each variant, and the cost function.

#![allow(clippy::needless_range_loop)]

use crate::rng_common::Rng;
use hw_model::fixed::SatCounter;
use hw_model::pow::{Pow, PowConfig, PowMethod};
use hw_model::roughness::{
    decode_d, div_round, rough_cos, rough_cost, rough_specular, sqrt_round, RoughExponentMode,
    RoughInput, RoughVariant, RoughnessConfig,
};
use texsim::shading::roughness::{d_factor, decode_d_texels, rough_cos_twin};

const VARIANTS: [RoughVariant; 4] = [
    RoughVariant::Published,
    RoughVariant::Directional,
    RoughVariant::Mahalanobis,
    RoughVariant::Isotropic,
];

/// The documented bound (module doc of `hw_model::roughness`).
fn bound(cfg: &RoughnessConfig, p: u32) -> f64 {
    1.5 * (-f64::from(cfg.rough_div_bits)).exp2()
        + (-f64::from(cfg.rough_sqrt_bits)).exp2()
        + (-f64::from(p + 1)).exp2()
        + (-20f64).exp2()
}

/// Fixed result minus twin on the same quantized inputs.
fn err(inp: &RoughInput, cfg: &RoughnessConfig, f: u32, p: u32, sat: &mut SatCounter) -> f64 {
    let o = rough_cos(inp, cfg, f, p, sat);
    assert!(o.cos_mod <= 1u64 << p, "{inp:?}");
    let s = (-f64::from(f)).exp2();
    let dv = decode_d_texels(inp.dch, inp.texel_bits, cfg.rough_range_exp);
    let t = rough_cos_twin(
        cfg.rough_variant,
        inp.cos_a as f64 * s,
        [inp.d[0] as f64 * s, inp.d[1] as f64 * s],
        dv,
    );
    assert!(t.is_finite() && (0.0..=1.0).contains(&t), "{inp:?} {t}");
    (o.cos_mod as f64 * (-f64::from(p)).exp2() - t).abs()
}

/// A random unit `h`-relative configuration: `cos a` and `d` with `|d|^2 = 1 - cos^2 a`.
fn random_input(r: &mut Rng, f: u32, bits: u32) -> RoughInput {
    let one = f64::from(1u32 << f);
    let a = r.unit() * std::f64::consts::FRAC_PI_2;
    let phi = r.unit() * std::f64::consts::TAU;
    let s = a.sin();
    let lim = 1u64 << bits;
    let ch = |r: &mut Rng| match r.next() % 8 {
        0 => 0,
        1 => lim,
        2 => r.next() % 16,
        _ => r.next() % (lim + 1),
    };
    RoughInput {
        cos_a: (a.cos() * one).round() as i64,
        d: [
            (s * phi.cos() * one).round() as i64,
            (s * phi.sin() * one).round() as i64,
        ],
        dch: [ch(r), ch(r), ch(r)],
        texel_bits: bits,
    }
}

#[test]
fn random_cases_meet_the_bound_for_every_variant_and_width() {
    let mut r = Rng(11);
    let mut sat = SatCounter::default();
    for (div, sq, p) in [
        (16u32, 16u32, 16u32),
        (10, 12, 12),
        (24, 24, 24),
        (8, 8, 10),
    ] {
        for v in VARIANTS {
            let cfg = RoughnessConfig {
                rough_variant: v,
                rough_div_bits: div,
                rough_sqrt_bits: sq,
                ..RoughnessConfig::texram16()
            };
            let b = bound(&cfg, p);
            let mut worst = 0.0f64;
            for _ in 0..125_000 {
                let inp = random_input(&mut r, 14, 16);
                let e = err(&inp, &cfg, 14, p, &mut sat);
                worst = worst.max(e);
                assert!(
                    e <= b,
                    "{v:?} div {div} sqrt {sq} P {p}: {inp:?} err {e} > {b}"
                );
            }
            println!(
                "{:<12} div {div:2} sqrt {sq:2} P {p:2}: worst {worst:.3e} bound {b:.3e}",
                v.name()
            );
        }
    }
}

#[test]
fn exhaustive_d_sweep_meets_the_bound() {
    // F = 10: every d = (x, y) in [-2^10, 2^10)^2 (2^22 grid points) per variant, with a
    // fixed anisotropic D and cos a = sqrt(1 - |d|^2) rounded. Outside the unit disc (21.5%)
    // cos a is 0, which only exercises the `cos a = 0` guard; the count inside is asserted.
    let f = 10u32;
    let one = 1i64 << f;
    let mut sat = SatCounter::default();
    for v in VARIANTS {
        let cfg = RoughnessConfig {
            rough_variant: v,
            ..RoughnessConfig::texram16()
        };
        let b = bound(&cfg, 16);
        let mut worst = 0.0f64;
        let mut inside = 0u64;
        for x in -one..one {
            for y in -one..one {
                let dd = (x * x + y * y) as f64 / (one * one) as f64;
                let c = ((1.0 - dd).max(0.0).sqrt() * one as f64).round() as i64;
                inside += u64::from(c > 0);
                let inp = RoughInput {
                    cos_a: c,
                    d: [x, y],
                    dch: [40_000, 20_000, 3_000],
                    texel_bits: 16,
                };
                let e = err(&inp, &cfg, f, 16, &mut sat);
                worst = worst.max(e);
                assert!(e <= b, "{v:?} {inp:?} {e}");
            }
        }
        println!(
            "{:<12} exhaustive d: {inside} cases with cos a > 0, worst {worst:.3e}",
            v.name()
        );
        assert!(inside > 3_290_000 && inside < 3_300_000, "{inside}");
    }
}

#[test]
fn hard_cases_are_finite_and_bounded() {
    let mut sat = SatCounter::default();
    let f = 14u32;
    let one = 1i64 << f;
    let lim = 1u64 << 16;
    let ds: [[u64; 3]; 8] = [
        [0, 1 << 15, 0],   // D = 0: every texel a mirror
        [lim, lim, lim],   // saturation, all channels
        [lim, 0, lim],     // d2 at its negative end
        [0, 1 << 15, lim], // d1 = 0: K singular (offsets on a line)
        [lim, 1 << 15, 0], // d3 = 0 (c -> 0)
        [lim, 1 << 15, 1], // huge anisotropy
        [1, 1 << 15, lim], // huge anisotropy, other axis
        [lim, lim - 1, 1], // nearly singular, sheared
    ];
    let dvecs: [[i64; 2]; 7] = [
        [0, 0], // h = n
        [1, 0], // d -> 0
        [0, 1],
        [1, 1],
        [one, 0],
        [0, -one],
        [-one / 2, one / 3],
    ];
    for v in VARIANTS {
        let cfg = RoughnessConfig {
            rough_variant: v,
            ..RoughnessConfig::texram16()
        };
        let b = bound(&cfg, 16);
        for dch in ds {
            for d in dvecs {
                for c in [0, 1, one / 2, one - 1, one, one + 5, -3] {
                    let inp = RoughInput {
                        cos_a: c,
                        d,
                        dch,
                        texel_bits: 16,
                    };
                    let e = err(&inp, &cfg, f, 16, &mut sat);
                    assert!(e <= b, "{v:?} {inp:?} {e}");
                    let o = rough_cos(&inp, &cfg, f, 16, &mut sat);
                    if d == [0, 0] && c > 0 {
                        assert!(o.d_zero && o.cos_mod == 1 << 16);
                    }
                    if c <= 0 {
                        assert_eq!(o.cos_mod, 0);
                    }
                }
            }
        }
    }
    // d -> 0 with a non-singular D: the result tends to 1 (the limit of |d|^4/|Dd|^2 is 0).
    let cfg = RoughnessConfig::texram16();
    let o = rough_cos(
        &RoughInput {
            cos_a: one,
            d: [1, 0],
            dch: [30_000, 1 << 15, 30_000],
            texel_bits: 16,
        },
        &cfg,
        f,
        16,
        &mut sat,
    );
    assert!(o.cos_mod >= (1 << 16) - 1, "{o:?}");
}

#[test]
fn degenerate_d_counts_a_saturation() {
    let mut sat = SatCounter::default();
    let cfg = RoughnessConfig::texram16();
    let o = rough_cos(
        &RoughInput {
            cos_a: 1 << 13,
            d: [1 << 13, 0],
            dch: [0, 1 << 15, 0],
            texel_bits: 16,
        },
        &cfg,
        14,
        16,
        &mut sat,
    );
    assert!(o.degenerate);
    assert_eq!(o.cos_mod, 0);
    assert!(sat.saturated >= 1);
}

#[test]
fn none_is_the_plain_cosine() {
    let mut sat = SatCounter::default();
    let cfg = RoughnessConfig {
        rough_variant: RoughVariant::None,
        ..RoughnessConfig::texram16()
    };
    for c in [0i64, 1, 1000, 1 << 14] {
        let o = rough_cos(
            &RoughInput {
                cos_a: c,
                d: [5, 5],
                dch: [0; 3],
                texel_bits: 16,
            },
            &cfg,
            14,
            16,
            &mut sat,
        );
        assert_eq!(o.cos_mod, (c as u64) << 2);
    }
}

/// `K = D D^T` as `[a, b, c]`.
fn k_of(d: [f64; 3]) -> [f64; 3] {
    [d[0] * d[0] + d[1] * d[1], d[1] * d[2], d[2] * d[2]]
}

#[test]
fn variants_mean_what_the_docs_say() {
    // tan a' = tan a / sigma(u) (directional, sigma^2 = u^T K u), tan a * sqrt(u^T K^-1 u)
    // (Mahalanobis), tan a / lambda1 (isotropic), tan a |d| / |D d| (published).
    let mut r = Rng(12);
    for _ in 0..200_000 {
        let a = r.unit() * 1.5;
        let phi = r.unit() * std::f64::consts::TAU;
        let (u, c) = ([phi.cos(), phi.sin()], a.cos());
        let d = [u[0] * a.sin(), u[1] * a.sin()];
        let k = [0.01 + r.unit(), r.unit() - 0.5, 0.01 + r.unit()];
        let k = [k[0] + k[1].abs(), k[1], k[2] + k[1].abs()];
        let dv = d_factor(k);
        let kk = k_of(dv);
        let det = kk[0] * kk[2] - kk[1] * kk[1];
        let var = kk[0] * u[0] * u[0] + 2.0 * kk[1] * u[0] * u[1] + kk[2] * u[1] * u[1];
        let inv = (kk[2] * u[0] * u[0] - 2.0 * kk[1] * u[0] * u[1] + kk[0] * u[1] * u[1]) / det;
        let dd = [dv[0] * u[0] + dv[1] * u[1], dv[2] * u[1]];
        let pubv = dd[0] * dd[0] + dd[1] * dd[1];
        let tan = a.tan();
        let lam = texsim::shading::roughness::lambda1(kk);
        for (v, want) in [
            (RoughVariant::Directional, tan / var.sqrt()),
            (RoughVariant::Mahalanobis, tan * inv.sqrt()),
            (RoughVariant::Published, tan / pubv.sqrt()),
        ] {
            let got = rough_cos_twin(v, c, d, dv);
            let want_cos = 1.0 / (1.0 + want * want).sqrt();
            assert!((got - want_cos).abs() < 1e-9, "{v:?} {got} {want_cos}");
        }
        let got = rough_cos_twin(RoughVariant::Isotropic, c, d, [lam, 0.0, 0.0]);
        let want = tan / lam;
        assert!((got - 1.0 / (1.0 + want * want).sqrt()).abs() < 1e-9);
        // Isotropic K: all four variants agree.
        let s = 0.1 + r.unit();
        let iso = [
            rough_cos_twin(RoughVariant::Published, c, d, [s, 0.0, s]),
            rough_cos_twin(RoughVariant::Directional, c, d, [s, 0.0, s]),
            rough_cos_twin(RoughVariant::Isotropic, c, d, [s, 0.0, 0.0]),
        ];
        for x in iso {
            assert!((x - iso[0]).abs() < 1e-12);
        }
        let m = rough_cos_twin(RoughVariant::Mahalanobis, c, d, [s, 0.0, s]);
        assert!((m - iso[0]).abs() < 1e-12);
    }
}

#[test]
fn decoder_matches_its_float_twin_exhaustively_per_channel() {
    let cfg = RoughnessConfig::texram16();
    for t in 0..=(1u64 << 16) {
        let (raw, frac) = decode_d([t, t, t], 16, &cfg);
        let f = decode_d_texels([t, t, t], 16, cfg.rough_range_exp);
        for i in 0..3 {
            assert_eq!(raw[i] as f64 * (-f64::from(frac)).exp2(), f[i]);
        }
    }
}

#[test]
fn divider_and_root_are_correctly_rounded() {
    let mut r = Rng(13);
    for _ in 0..1_000_000 {
        let n = u128::from(r.next() >> (r.next() % 60)) + 1;
        let m = u128::from(r.next() >> (r.next() % 60)) + 1;
        let b = 8 + (r.next() % 23) as u32;
        let (q, e) = div_round(n, m, b);
        assert!(q >> (b - 1) == 1, "{n} {m} {b}");
        let want = n as f64 / m as f64;
        let got = q as f64 * f64::from(e).exp2();
        assert!((got - want).abs() <= want * (-f64::from(b)).exp2() * 1.0001);
        let (s, se) = sqrt_round(n, b);
        assert!(s >> (b - 1) == 1);
        let want = (n as f64).sqrt();
        let got = s as f64 * f64::from(se).exp2();
        assert!((got - want).abs() <= want * (-f64::from(b)).exp2() * 1.0001);
    }
}

#[test]
fn specular_applies_the_exponent_mode() {
    let pow = Pow::new(&PowConfig::texram16());
    let mut sat = SatCounter::default();
    let inp = RoughInput {
        cos_a: 15_000,
        d: [6_000, 2_000],
        dch: [30_000, 33_000, 20_000],
        texel_bits: 16,
    };
    let constant = RoughnessConfig {
        rough_const_exponent: 4,
        rough_exponent_mode: RoughExponentMode::Constant,
        ..RoughnessConfig::texram16()
    };
    let material = RoughnessConfig {
        rough_exponent_mode: RoughExponentMode::Material,
        ..constant.clone()
    };
    let (a, o) = rough_specular(&inp, &constant, 14, 64, &pow, &mut sat);
    let (b, _) = rough_specular(&inp, &material, 14, 4, &pow, &mut sat);
    assert_eq!(a, b);
    assert_eq!(a, pow.pow(o.cos_mod, 4, &mut sat));
    assert_eq!(constant.exponent(64), 4);
    assert_eq!(material.exponent(64), 64);
}

/// 1M seeded cases (every variant, both power methods, exponents 1 to 2047 with the small
/// ones weighted, the inputs of `random_cases_meet_the_bound_for_every_variant_and_width`):
/// `rough_specular` against the twin's `cos a'` raised to the exponent in f64 stays within its
/// documented bound, the power unit's own bound at the unit's `cos a'` plus the cosine's bound
/// carried through `x^n`.
#[test]
fn specular_meets_the_composed_bound() {
    let mut r = Rng(47);
    let mut sat = SatCounter::default();
    let f = 14;
    let mut worst = 0.0f64;
    for method in [PowMethod::LogExp, PowMethod::Squaring] {
        let pcfg = PowConfig {
            pow_method: method,
            ..PowConfig::texram16()
        };
        let pow = Pow::new(&pcfg);
        let p = pcfg.pow_frac_bits;
        let scale = (-f64::from(p)).exp2();
        for v in VARIANTS {
            let cfg = RoughnessConfig {
                rough_variant: v,
                rough_exponent_mode: RoughExponentMode::Material,
                ..RoughnessConfig::texram16()
            };
            let b_cos = bound(&cfg, p);
            for i in 0..125_000u32 {
                let n = match i % 4 {
                    0 => 1 + (r.next() % 16) as u32,
                    1 => 1 + (r.next() % 128) as u32,
                    _ => 1 + (r.next() % 2047) as u32,
                };
                let inp = random_input(&mut r, f, 16);
                let (y, o) = rough_specular(&inp, &cfg, f, n, &pow, &mut sat);
                let s = (-f64::from(f)).exp2();
                let dv = decode_d_texels(inp.dch, inp.texel_bits, cfg.rough_range_exp);
                let c = rough_cos_twin(
                    v,
                    inp.cos_a as f64 * s,
                    [inp.d[0] as f64 * s, inp.d[1] as f64 * s],
                    dv,
                );
                let c_fixed = o.cos_mod as f64 * scale;
                let nf = f64::from(n);
                let carried = nf * b_cos * c.max(c_fixed).min(1.0).powf(nf - 1.0);
                let b = crate::frames_pow::bound(&pcfg, c_fixed, n) + carried;
                let e = (y as f64 * scale - c.powf(nf)).abs();
                assert!(e <= b, "{v:?} {method:?} n {n}: {inp:?} err {e} > {b}");
                worst = worst.max(e / b);
            }
        }
    }
    println!("rough_specular: worst error / bound {worst:.3}");
}

#[test]
fn cost_grows_with_precision_and_none_is_free() {
    let base = RoughnessConfig::texram16();
    for v in VARIANTS {
        let c = RoughnessConfig {
            rough_variant: v,
            ..base.clone()
        };
        let wide = RoughnessConfig {
            rough_div_bits: 24,
            rough_sqrt_bits: 24,
            ..c.clone()
        };
        assert!(
            rough_cost(
                &wide,
                hw_model::timing_config::DEFAULT_GATE_LEVELS_PER_CYCLE
            )
            .cycles
                > rough_cost(&c, hw_model::timing_config::DEFAULT_GATE_LEVELS_PER_CYCLE).cycles
        );
        assert!(rough_cost(&c, hw_model::timing_config::DEFAULT_GATE_LEVELS_PER_CYCLE).ops > 0);
    }
    let iso = RoughnessConfig {
        rough_variant: RoughVariant::Isotropic,
        ..base.clone()
    };
    assert!(
        rough_cost(&iso, hw_model::timing_config::DEFAULT_GATE_LEVELS_PER_CYCLE).cycles
            < rough_cost(
                &base,
                hw_model::timing_config::DEFAULT_GATE_LEVELS_PER_CYCLE
            )
            .cycles
    );
    let none = RoughnessConfig {
        rough_variant: RoughVariant::None,
        ..base
    };
    assert_eq!(
        rough_cost(
            &none,
            hw_model::timing_config::DEFAULT_GATE_LEVELS_PER_CYCLE
        )
        .cycles,
        0
    );
    assert_eq!(
        rough_cost(
            &none,
            hw_model::timing_config::DEFAULT_GATE_LEVELS_PER_CYCLE
        )
        .ops,
        0
    );
}

#[test]
fn config_validation_names_the_field() {
    let mut c = RoughnessConfig::texram16();
    c.rough_d_bits = 1;
    let e = c.validate().expect_err("too narrow");
    assert!(e.to_string().contains("roughness.rough_d_bits"), "{e}");
    let mut c = RoughnessConfig::texram16();
    c.rough_range_exp = 9;
    let e = c.validate().expect_err("range");
    assert!(e.to_string().contains("roughness.rough_range_exp"), "{e}");
    let mut h = hw_model::HwConfig::texram16();
    h.roughness.rough_sqrt_bits = 40;
    assert!(h.validate().is_err());
    // Old files without a [roughness] section still parse, with the default.
    let mut t = toml::Value::try_from(hw_model::HwConfig::texram16()).expect("ser");
    t.as_table_mut().expect("table").remove("roughness");
    let back: hw_model::HwConfig = t.try_into().expect("old file parses");
    assert_eq!(back.roughness, RoughnessConfig::texram16());
}

#[test]
fn sweep_knobs_set_the_roughness_fields() {
    let c = hw_model::HwConfig::texram16();
    for v in [
        "none",
        "published",
        "directional",
        "mahalanobis",
        "isotropic",
    ] {
        let n = texsim::hwconfig::set_field(&c, "roughness", v).expect("variant");
        assert_eq!(n.roughness.rough_variant.name(), v);
    }
    let n = texsim::hwconfig::set_field(&c, "rough_d_bits", "8").expect("bits");
    assert_eq!(n.roughness.rough_d_bits, 8);
    let n = texsim::hwconfig::set_field(&c, "rough_exponent_mode", "constant").expect("mode");
    assert_eq!(n.roughness.rough_exponent_mode, RoughExponentMode::Constant);
    let e = texsim::hwconfig::set_field(&c, "roughness", "shiny").expect_err("bad");
    assert!(e.to_string().contains("rough_variant"), "{e}");
    let e = texsim::hwconfig::set_field(&c, "rough_div_bits", "99").expect_err("bad");
    assert!(e.to_string().contains("rough_div_bits"), "{e}");
}

#[test]
fn normalization_matches_its_float_twin() {
    use hw_model::roughness::{normalize_spec, RoughShadeInput};
    use texsim::shading::roughness::normalize_factor;
    let mut r = Rng(14);
    for v in VARIANTS {
        let cfg = RoughnessConfig {
            rough_variant: v,
            rough_normalize: true,
            ..RoughnessConfig::texram16()
        };
        for _ in 0..200_000 {
            let t = 14u32;
            let dv = [
                (r.next() % (1 << 17)) as i64,
                (r.next() % (1 << 17)) as i64 - (1 << 16),
                (r.next() % (1 << 17)) as i64,
            ];
            let ri = RoughShadeInput {
                t_u: [0; 3],
                t_v: [0; 3],
                dv,
                t,
            };
            let spec = r.next() % (1 << 16 | 1);
            let (e, s) = (1 + (r.next() % 256) as u32, 1 + (r.next() % 256) as u32);
            let got = normalize_spec(spec, e, s, &ri, &cfg) as f64;
            let scale = (-f64::from(t)).exp2();
            let want = spec as f64 * normalize_factor(dv.map(|x| x as f64 * scale), v, e, s);
            let tol = want * (-f64::from(cfg.rough_div_bits)).exp2() + 0.5 + 1e-9;
            assert!(
                (got - want).abs() <= tol,
                "{v:?} {dv:?} {spec} {e} {s}: {got} {want}"
            );
            assert!(got <= spec as f64);
        }
    }
}
