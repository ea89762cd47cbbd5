//! The multi-lobe (Fournier multiple-surface) unit `hw_model::multi_lobe` against its float
//! twin `texsim::shading::multi_lobe::shade`: the lobe sum exhaustively at 8 amplitude bits,
//! 10^7 seeded evaluations against the stated bound, and the hard cases (exponent 0 and
//! saturated, coincident lobes, lobes at the horizon, K above the limit, no lobes).
#![allow(clippy::needless_range_loop)]

use crate::rng_common::Rng;
use glam::DVec3;
use hw_model::blinn_phong::{ShadingConfig, ShadingUnits};
use hw_model::frame::Frame;
use hw_model::multi_lobe::{
    fitted_spec_sum, lobe_direction, lobe_sum, multi_lobe_cost, multi_lobe_shade, recip_frac_bits,
    shininess_recip, Lobe, LobeLight, MultiLobeConfig, MultiLobeInput,
};
use hw_model::{Rounding, SatCounter};
use rayon::prelude::*;
use texsim::shading::multi_lobe::{shade, LobeF};
use texsim::shading::reference::{self as r, FrameF};

const F: u32 = 14;
const C: u32 = 16;

fn units() -> ShadingUnits {
    ShadingUnits::new(&ShadingConfig::texram16())
}

/// A random orthonormal frame, quantized, with lengths 1 (len format raw `2^8`).
fn random_frame(g: &mut Rng, lf: u32) -> (Frame, FrameF) {
    let n = g.dir();
    let a = if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    let t_u = n.cross(a).normalize();
    let t_v = n.cross(t_u);
    let (nq, uq, vq) = (r::to_vec3x(n, F), r::to_vec3x(t_u, F), r::to_vec3x(t_v, F));
    let fx = Frame {
        n: nq,
        t_u: uq,
        t_v: vq,
        len_u: 1 << lf,
        len_v: 1 << lf,
        fallback: false,
        zero_normal: false,
    };
    let ff = FrameF {
        n: r::from_vec3x(&nq, F),
        t_u: r::from_vec3x(&uq, F),
        t_v: r::from_vec3x(&vq, F),
        len_u: 1.0,
        len_v: 1.0,
        fallback: false,
        zero_normal: false,
    };
    (fx, ff)
}

/// The lobe sum is the exact sum rounded once: every amplitude of 1.8 against every `N . l`
/// of s1.14 in [0, 1] (2^8 + 1 times 2^14 + 1 cases, each mode).
#[test]
fn lobe_sum_exhaustive_at_8_amplitude_bits() {
    for mode in [Rounding::HalfEven, Rounding::HalfUp, Rounding::Truncate] {
        let bad = (0u64..=256)
            .into_par_iter()
            .map(|c| {
                (0i64..=1 << F)
                    .filter(|&t| {
                        let got = lobe_sum(&[(c, t)], 8, mode);
                        let exact = i128::from(c) * i128::from(t);
                        let diff = i128::from(got) * 256 - exact;
                        match mode {
                            Rounding::Truncate => !(-255..=0).contains(&diff),
                            _ => diff.abs() > 128,
                        }
                    })
                    .count()
            })
            .sum::<usize>();
        assert_eq!(bad, 0, "{mode:?}");
    }
    // Two terms: the sum is rounded once, not each product.
    assert_eq!(lobe_sum(&[(1, 1), (1, 1)], 2, Rounding::HalfEven), 0);
    assert_eq!(lobe_sum(&[(1, 1), (1, 1)], 1, Rounding::HalfEven), 1);
}

/// The power unit's bound (`pow.rs`, texram16 log-exp: L = 8, G = 24, P = 16) at `x`.
fn pow_bound(x: f64, s: f64) -> f64 {
    x.powf(s) * ((s * (0.1803 * 2f64.powi(-16) + 2f64.powi(-24))).exp2() - 1.0)
        + x.powf(s) * (0.0601 * 2f64.powi(-16) + 2f64.powi(-24))
        + 2f64.powi(-17)
}

struct Case {
    frame: (Frame, FrameF),
    lobes: Vec<Lobe>,
    lights: Vec<LobeLight>,
    v: [i64; 3],
    kd: [u64; 3],
    ks: [u64; 3],
    /// Fitted lobes: the material's exponent `s` (specular weights `c_i n_i / s`).
    fitted: Option<u32>,
}

fn random_case(g: &mut Rng, lf: u32) -> Case {
    let frame = random_frame(g, lf);
    let n = frame.1.n;
    let k = 1 + g.below(8) as usize;
    // One case in two: fitted lobes under an exponent s in 1..=2047, lobe exponents <= s.
    let fitted = (g.below(2) == 0).then(|| (g.range(0.0, 11.0).exp2() as u32).clamp(1, 2047));
    let lobes = (0..k)
        .map(|_| Lobe {
            slope: [0; 2].map(|_: i64| (g.range(-2.0, 2.0) * 4096.0).round() as i64),
            amp: g.below(1 << 14),
            exponent: match fitted {
                Some(s) => g.below(u64::from(s) + 1) as u32,
                None if g.below(8) == 0 => g.below(4) as u32,
                None => g.range(0.0, 10.0).exp2() as u32,
            },
        })
        .collect();
    let col = |g: &mut Rng| [0; 3].map(|_: u64| g.below(1 << C));
    let nl = 1 + g.below(3) as usize;
    let mut lights: Vec<LobeLight> = (0..nl)
        .map(|_| {
            let mut l = g.dir();
            if l.dot(n) < 0.0 && g.below(2) == 0 {
                l = -l;
            }
            LobeLight {
                l: r::to_vec3x(l, F),
                color: col(g),
            }
        })
        .collect();
    let mut v = g.dir();
    if v.dot(n) < 0.0 {
        v = -v;
    }
    let vq = r::to_vec3x(v, F);
    if g.below(64) == 0 {
        lights[0].l = vq.map(|c| -c);
    }
    Case {
        frame,
        lobes,
        lights,
        v: vq,
        kd: col(g),
        ks: col(g),
        fitted,
    }
}

/// Error / bound of one case (panics if above 1).
fn check(c: &Case, u: &ShadingUnits, cfg: &MultiLobeConfig, idx: u64) -> f64 {
    let mut sat = SatCounter::default();
    let inp = MultiLobeInput {
        frame: &c.frame.0,
        lobes: &c.lobes,
        lights: &c.lights,
        v: c.v,
        kd: c.kd,
        ks: c.ks,
        spec_recip: c.fitted.map(|s| shininess_recip(s, cfg, &u.cfg)),
    };
    let out = multi_lobe_shade(&inp, cfg, u, &mut sat);
    let cu = 1.0 / ((1u64 << C) - 1) as f64;
    let fc = |x: [u64; 3]| x.map(|y| y as f64 * cu);
    let lf: Vec<LobeF> = c
        .lobes
        .iter()
        .map(|l| LobeF {
            slope: l.slope.map(|s| s as f64 / 4096.0),
            amp: l.amp as f64 / 65536.0,
            exponent: l.exponent,
        })
        .collect();
    let lights: Vec<(DVec3, [f64; 3])> = c
        .lights
        .iter()
        .map(|l| (r::from_vec3x(&l.l, F), fc(l.color)))
        .collect();
    let vd = r::from_vec3x(&c.v, F);
    let fs = c.fitted.map(f64::from);
    let want = shade(&c.frame.1, &lf, 8, &lights, vd, fc(c.kd), fc(c.ks), fs);
    let r_ulp = (-f64::from(recip_frac_bits(cfg, &u.cfg))).exp2();
    assert_eq!(want.h_zero, out.h_zero, "case {idx}");
    let ulp = (-f64::from(F)).exp2();
    let e_n = 2.5 * ulp;
    let d_l = ulp + 3f64.sqrt() * e_n;
    let d_h = 2.5 * ulp + 3f64.sqrt() * e_n;
    let mut bound = [cu; 3].map(|b| b * lights.len() as f64);
    for &(l, light) in &lights {
        let hz = l + vd == DVec3::ZERO;
        let h = r::normalize_or(l + vd, DVec3::ZERO).0;
        let (mut bd, mut bs) = (ulp / 2.0, 2f64.powi(-17));
        for lobe in &lf {
            let nn = texsim::shading::multi_lobe::lobe_direction(&c.frame.1, lobe);
            let ndl = nn.dot(l);
            bd += lobe.amp * d_l;
            if hz || ndl < -d_l {
                continue;
            }
            let s = f64::from(lobe.exponent);
            let x = nn.dot(h).clamp(0.0, 1.0);
            let hi = (x + d_h).min(1.0);
            let lo = (x - d_h).max(0.0);
            let w = hi.powf(s) - lo.powf(s);
            let t = if ndl < d_l { hi.powf(s) } else { 0.0 };
            let (weight, q) = match fs {
                Some(sh) => (lobe.amp * s / sh, lobe.amp * s * r_ulp / 2.0),
                None => (lobe.amp, 0.0),
            };
            bs += weight * (pow_bound(hi, s) + w + t) + q;
        }
        for ch in 0..3 {
            bound[ch] += light[ch] * (fc(c.kd)[ch] * bd + fc(c.ks)[ch] * bs);
        }
    }
    let mut worst = 0.0f64;
    for ch in 0..3 {
        let got = out.color[ch] as f64 * cu;
        let e = (got - want.color[ch]).abs();
        assert!(
            e <= bound[ch],
            "case {idx} ch {ch}: {got} vs {} (bound {})",
            want.color[ch],
            bound[ch]
        );
        worst = worst.max(e / bound[ch]);
    }
    worst
}

/// 10^7 seeded evaluations (K = 1..8 lobes, 1..3 lights, exponents 0..1024, slopes in
/// [-2, 2], `l = -v` once in 64; one case in two fitted lobes, specular weights `c_i n_i / s`
/// for an exponent `s` in 1..=2047) within the module's bound; chunks are seeded by index, so
/// the result does not depend on the thread count.
#[test]
fn multi_lobe_matches_twin_within_bound() {
    let u = units();
    let cfg = MultiLobeConfig::texram16();
    let lf = u.cfg.frame.frame_len_frac_bits;
    const CHUNKS: u64 = 1000;
    const PER: u64 = 10_000;
    let worst = (0..CHUNKS)
        .into_par_iter()
        .map(|ch| {
            let mut g = Rng(0xF0_0000 + ch);
            (0..PER)
                .map(|i| check(&random_case(&mut g, lf), &u, &cfg, ch * PER + i))
                .fold(0.0f64, f64::max)
        })
        .reduce(|| 0.0, f64::max);
    println!(
        "multi-lobe: max err/bound {worst:.3} over {} cases",
        CHUNKS * PER
    );
    assert!(worst > 0.0);
}

fn one_light_case(lobes: Vec<Lobe>) -> (Frame, Vec<Lobe>, Vec<LobeLight>, [i64; 3]) {
    let one = 1i64 << F;
    let frame = Frame {
        n: [0, 0, one],
        t_u: [one, 0, 0],
        t_v: [0, one, 0],
        len_u: 1 << 8,
        len_v: 1 << 8,
        fallback: false,
        zero_normal: false,
    };
    let l = r::to_vec3x(DVec3::new(0.3, 0.2, 1.0).normalize(), F);
    let v = r::to_vec3x(DVec3::new(-0.2, 0.1, 1.0).normalize(), F);
    let lights = vec![LobeLight {
        l,
        color: [65535; 3],
    }];
    (frame, lobes, lights, v)
}

fn eval(
    frame: &Frame,
    lobes: &[Lobe],
    lights: &[LobeLight],
    v: [i64; 3],
    cfg: &MultiLobeConfig,
    sat: &mut SatCounter,
) -> hw_model::multi_lobe::MultiLobeOut {
    let inp = MultiLobeInput {
        frame,
        lobes,
        lights,
        v,
        kd: [20000; 3],
        ks: [40000; 3],
        spec_recip: None,
    };
    multi_lobe_shade(&inp, cfg, &units(), sat)
}

/// Two coincident lobes of amplitudes a and b shade bit-identically to one lobe of a + b (the
/// sums are exact and rounded once).
#[test]
fn coincident_lobes_add_exactly() {
    let cfg = MultiLobeConfig::texram16();
    let mut g = Rng(5);
    for _ in 0..2000 {
        let slope = [0; 2].map(|_: i64| g.below(8192) as i64 - 4096);
        let exponent = g.below(600) as u32;
        let a = g.below(1 << 15);
        let b = g.below(1 << 15);
        let lobe = |amp| Lobe {
            slope,
            amp,
            exponent,
        };
        let (fr, _, lights, v) = one_light_case(vec![]);
        let mut sat = SatCounter::default();
        let two = eval(&fr, &[lobe(a), lobe(b)], &lights, v, &cfg, &mut sat);
        let one = eval(&fr, &[lobe(a + b)], &lights, v, &cfg, &mut sat);
        assert_eq!(two, one);
    }
}

/// Exponent 0: each lobe is a constant amplitude where it faces the light; exponents above
/// `2^lobe_exp_bits - 1` saturate (counted) and equal the largest one; a huge exponent off the
/// peak gives no specular term.
#[test]
fn exponent_zero_and_saturated() {
    let mut cfg = MultiLobeConfig::texram16();
    let (fr, _, lights, v) = one_light_case(vec![]);
    let mut sat = SatCounter::default();
    let lobe = |exponent, amp| Lobe {
        slope: [0, 0],
        amp,
        exponent,
    };
    // ks only, light white, exponent 0: colour = ks * c.
    let inp = MultiLobeInput {
        frame: &fr,
        lobes: &[lobe(0, 1 << 15)],
        lights: &lights,
        v,
        kd: [0; 3],
        ks: [65535; 3],
        spec_recip: None,
    };
    let out = multi_lobe_shade(&inp, &cfg, &units(), &mut sat);
    assert!(out.color.iter().all(|&c| c.abs_diff(32768) <= 1), "{out:?}");
    cfg.lobe_exp_bits = 6;
    let before = sat.saturated;
    let big = eval(&fr, &[lobe(1000, 1 << 16)], &lights, v, &cfg, &mut sat);
    assert!(sat.saturated > before, "saturation counted");
    let max = eval(&fr, &[lobe(63, 1 << 16)], &lights, v, &cfg, &mut sat);
    assert_eq!(big.color, max.color);
    // Far off the peak, exponent 2047: only the diffuse term remains.
    cfg = MultiLobeConfig::texram16();
    let tilted = Lobe {
        slope: [-4000, 3000],
        amp: 1 << 16,
        exponent: 2047,
    };
    let spec_off = eval(&fr, &[tilted], &lights, v, &cfg, &mut sat);
    let diffuse_only = {
        let inp = MultiLobeInput {
            frame: &fr,
            lobes: &[tilted],
            lights: &lights,
            v,
            kd: [20000; 3],
            ks: [0; 3],
            spec_recip: None,
        };
        multi_lobe_shade(&inp, &cfg, &units(), &mut sat)
    };
    assert_eq!(spec_off.color, diffuse_only.color);
}

/// Lobes at (or "below") the horizon: the largest stored slope (about 83 degrees at s3.12)
/// is in range, larger ones saturate to it (counted); the decoded
/// direction stays unit and above the horizon, the colour is finite and within [0, 1].
#[test]
fn lobes_at_the_horizon_stay_above_it() {
    let cfg = MultiLobeConfig::texram16();
    let u = units();
    let (fr, _, lights, v) = one_light_case(vec![]);
    let mut sat = SatCounter::default();
    for (slope, out_of_range) in [
        ([i64::MAX, 0], true),
        ([i64::MIN, i64::MIN], true),
        ([32767, -32768], false),
        ([1 << 20, 5], true),
    ] {
        let lobe = Lobe {
            slope,
            amp: 1 << 16,
            exponent: 8,
        };
        let before = sat.saturated;
        let d = lobe_direction(&fr, &lobe, &cfg, &u, &mut sat);
        assert_eq!(
            sat.saturated > before,
            out_of_range,
            "{slope:?}: saturation counted"
        );
        let dv = r::from_vec3x(&d, F);
        assert!((dv.length() - 1.0).abs() < 1e-3, "{dv}");
        assert!(dv.z > 0.0, "{dv} above the horizon");
        let out = eval(&fr, &[lobe], &lights, v, &cfg, &mut sat);
        assert!(out.color.iter().all(|&c| c <= 65535));
    }
}

/// More lobes than `lobe_max_lobes`: the extra ones are dropped (flagged) and the result is the
/// first `lobe_max_lobes` lobes'; no lobes shade black; the cost grows with K and stops at the
/// limit.
#[test]
fn lobe_limit_and_no_lobes() {
    let mut cfg = MultiLobeConfig::texram16();
    cfg.lobe_max_lobes = 3;
    let (fr, _, lights, v) = one_light_case(vec![]);
    let mut sat = SatCounter::default();
    let lobes: Vec<Lobe> = (0..6)
        .map(|i| Lobe {
            slope: [i * 300 - 800, 200 - i * 100],
            amp: 9000,
            exponent: 10 + 7 * i as u32,
        })
        .collect();
    let six = eval(&fr, &lobes, &lights, v, &cfg, &mut sat);
    let three = eval(&fr, &lobes[..3], &lights, v, &cfg, &mut sat);
    assert!(six.dropped && !three.dropped);
    assert_eq!(six.color, three.color);
    let none = eval(&fr, &[], &lights, v, &cfg, &mut sat);
    assert_eq!(none.color, [0; 3]);
    let u = units();
    let cfg8 = MultiLobeConfig::texram16();
    let costs: Vec<_> = [1, 2, 4, 8, 16]
        .iter()
        .map(|&k| multi_lobe_cost(&cfg8, &u, k, 2, 32))
        .collect();
    for w in costs.windows(2).take(3) {
        assert!(
            w[1].ops > w[0].ops && w[1].cycles > w[0].cycles,
            "{costs:?}"
        );
    }
    assert_eq!(costs[3], costs[4], "K is capped at lobe_max_lobes");
}

/// Out-of-range widths are refused naming the field.
#[test]
fn config_validation_names_the_field() {
    let mut c = MultiLobeConfig::texram16();
    c.lobe_max_lobes = 9;
    let e = c.validate().unwrap_err();
    assert_eq!(e.field, "multi_lobe.lobe_max_lobes");
    c = MultiLobeConfig::texram16();
    c.lobe_amp_bits = 1;
    assert_eq!(c.validate().unwrap_err().field, "multi_lobe.lobe_amp_bits");
}

/// Fitted lobes: a lobe at the material's own exponent (`n = s`: a von Mises-Fisher lobe of
/// coincident normals) has specular weight `c` exactly, so with `s` a power of two (an exact
/// reciprocal) it shades bit-identically to the made-up lobe; at `n < s` its specular term
/// falls as `n / s` while the diffuse term keeps the weight `c`. The scaled sum is rounded once.
#[test]
fn fitted_lobe_weights() {
    let cfg = MultiLobeConfig::texram16();
    let u = units();
    let (fr, _, lights, v) = one_light_case(vec![]);
    let mut sat = SatCounter::default();
    let run = |lobes: &[Lobe], recip: Option<u64>, kd, ks, sat: &mut SatCounter| {
        let inp = MultiLobeInput {
            frame: &fr,
            lobes,
            lights: &lights,
            v,
            kd,
            ks,
            spec_recip: recip,
        };
        multi_lobe_shade(&inp, &cfg, &u, sat).color
    };
    let mut g = Rng(77);
    for _ in 0..2000 {
        let s = 1u32 << g.below(11);
        let lobe = Lobe {
            slope: [0; 2].map(|_: i64| g.below(4096) as i64 - 2048),
            amp: g.below(1 << 16),
            exponent: s,
        };
        let recip = Some(shininess_recip(s, &cfg, &u.cfg));
        let (kd, ks) = ([30000; 3], [50000; 3]);
        assert_eq!(
            run(&[lobe], recip, kd, ks, &mut sat),
            run(&[lobe], None, kd, ks, &mut sat)
        );
    }
    let lobe = |exponent| Lobe {
        slope: [0, 0],
        amp: 1 << 15,
        exponent,
    };
    let recip = Some(shininess_recip(64, &cfg, &u.cfg));
    let diffuse = |n| {
        run(
            &[lobe(n)],
            recip,
            [65535; 3],
            [0; 3],
            &mut SatCounter::default(),
        )
    };
    assert_eq!(
        diffuse(64),
        diffuse(4),
        "the diffuse weight is c at every n"
    );
    let spec = |n| {
        run(
            &[lobe(n)],
            recip,
            [0; 3],
            [65535; 3],
            &mut SatCounter::default(),
        )[0]
    };
    assert!(
        spec(4) < spec(16) && spec(16) < spec(64),
        "specular weight c n / s"
    );
    // One rounding of the scaled sum: 3 x 1 x 1 / 2^2 = 0.75 -> 1; per term 0.25 -> 0 each.
    assert_eq!(fitted_spec_sum(&[(1, 1); 3], 1, 2, Rounding::HalfEven), 1);
    assert_eq!(fitted_spec_sum(&[(1, 1)], 1, 2, Rounding::HalfEven), 0);
}
