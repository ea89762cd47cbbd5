//! The roughness shading unit end to end (`hw_model::roughness::rough_blinn_phong`, Schilling
//! 1997 Appendix A) against its float twin (`texsim::shading::roughness::rough_blinn_phong_f`)
//! on the same quantized vectors, colours and D texels, over random frames (orthonormal and
//! not), frame lengths, range exponents, vector widths `F`, power widths `P`, variants, modes
//! and the energy normalization; the D scaling unit `scale_d` against its twin; and the
//! saturations (`D_RAW_LIMIT`, `Q >= 2^Q_CAP_BITS`) counted.

use crate::rng_common::Rng;
use glam::DVec3;
use hw_model::blinn_phong::{BlinnPhongInput, ShadingConfig, ShadingUnits};
use hw_model::fixed::SatCounter;
use hw_model::roughness::{
    decode_d, rough_blinn_phong, rough_cos_d, scale_d, RoughExponentMode, RoughShadeInput,
    RoughVariant, RoughnessConfig, D_RAW_LIMIT, Q_CAP_BITS,
};
use hw_model::rsqrt::RsqrtConfig;
use texsim::shading::reference as r;
use texsim::shading::roughness::{
    d_and_cos, decode_d_texels, normalize_factor, rough_blinn_phong_f, rough_cos_twin, scale_d_f,
};

/// `(1 + u^2)^(-1/2)`, the twin's `cos a'` as a function of `u = tan a'` (0 at infinity).
fn cos_of_u(u: f64) -> f64 {
    if u.is_finite() {
        1.0 / (1.0 + u * u).sqrt()
    } else {
        0.0
    }
}

/// Smallest singular value of the upper triangular `[[d1, d2], [0, d3]]`.
fn sigma_min(dv: [f64; 3]) -> f64 {
    let (a, b, c) = (dv[0], dv[1], dv[2]);
    let fro2 = a * a + b * b + c * c;
    let det = (a * c).abs();
    let disc = (fro2 * fro2 - 4.0 * det * det).max(0.0).sqrt();
    (2.0 * det * det / (fro2 + disc)).max(0.0).sqrt()
}

/// The `E_in` term of the `rough_blinn_phong` bound: the range of the twin's `cos a'` when
/// `c` moves by `dc`, each `d` component by `dd` and each D entry by `dd_d`.
fn e_in(v: RoughVariant, c: f64, d: [f64; 2], dv: [f64; 3], dc: f64, dd: f64, dd_d: f64) -> f64 {
    if v == RoughVariant::None {
        return dc;
    }
    let dn = d[0].hypot(d[1]);
    let ddv = std::f64::consts::SQRT_2 * dd;
    let eta = 3f64.sqrt() * dd_d;
    let [d1, d2, d3] = dv;
    let (w_lo, w_hi) = match v {
        RoughVariant::Published | RoughVariant::Directional => {
            let m = if v == RoughVariant::Published {
                (d1 * d[0] + d2 * d[1]).hypot(d3 * d[1])
            } else {
                (d1 * d[0]).hypot(d2 * d[0] + d3 * d[1])
            };
            let norm = (d1 * d1 + d2 * d2 + d3 * d3).sqrt();
            let dm = norm * ddv + eta * (dn + ddv);
            let lo = (dn - ddv).max(0.0).powi(2) / (m + dm);
            let hi = if m > dm {
                (dn + ddv).powi(2) / (m - dm)
            } else {
                f64::INFINITY
            };
            (lo, hi)
        }
        RoughVariant::Mahalanobis => {
            let s = sigma_min(dv);
            if d1 <= 0.0 || d3 <= 0.0 || s <= eta {
                (0.0, f64::INFINITY)
            } else {
                // |D^-1 d| with D^-1 = [[1/d1, -d2/(d1 d3)], [0, 1/d3]].
                let w = (d[0] / d1 - d2 * d[1] / (d1 * d3)).hypot(d[1] / d3);
                let dw = (ddv + eta * dn / s) / (s - eta);
                ((w - dw).max(0.0), w + dw)
            }
        }
        RoughVariant::Isotropic | RoughVariant::None => {
            let lo = (dn - ddv).max(0.0) / (d1 + dd_d);
            let hi = if d1 > dd_d {
                (dn + ddv) / (d1 - dd_d)
            } else {
                f64::INFINITY
            };
            (lo, hi)
        }
    };
    let u_lo = w_lo / (c + dc);
    let u_hi = if c > dc {
        w_hi / (c - dc)
    } else {
        f64::INFINITY
    };
    cos_of_u(u_lo) - cos_of_u(u_hi)
}

/// One case of the end-to-end comparison.
struct Case {
    n: DVec3,
    l: DVec3,
    v: DVec3,
    t: [DVec3; 2],
    tex: [u64; 3],
    len: [i64; 2],
    shininess: u32,
    colors: [[u64; 3]; 3],
}

const C: u32 = 16;

/// Checks one case against the bound of the `rough_blinn_phong` doc comment; returns the
/// worst error / bound over the channels where the bound exceeds 8 LSB (0 if none).
#[allow(clippy::too_many_lines)]
fn check(case: &Case, cfg: &RoughnessConfig, units: &ShadingUnits, sat: &mut SatCounter) -> f64 {
    let vc = &units.cfg.vector;
    let f = vc.vector_frac_bits;
    let p = units.cfg.pow.pow_frac_bits.clamp(8, 24);
    let lfb = units.cfg.frame.frame_len_frac_bits;
    let iso = cfg.rough_variant == RoughVariant::Isotropic;
    let (nq, lq, vq) = (
        r::to_vec3x(case.n, f),
        r::to_vec3x(case.l, f),
        r::to_vec3x(case.v, f),
    );
    let tq = case.t.map(|t| r::to_vec3x(t, f));
    let (dvx, t) = decode_d(case.tex, 16, cfg);
    let mut scale_sat = SatCounter::default();
    let dvs = scale_d(dvx, case.len, lfb, iso, &mut scale_sat);
    // Lengths below 16 keep D below D_RAW_LIMIT: the bound's precondition.
    assert_eq!(scale_sat.saturated, 0);
    let [kd, ks, light] = case.colors;
    let inp = BlinnPhongInput {
        n: nq,
        l: lq,
        v: vq,
        shininess: case.shininess,
        kd,
        ks,
        light,
    };
    let ri = RoughShadeInput {
        t_u: tq[0],
        t_v: tq[1],
        dv: dvs,
        t,
    };
    let (out, _) = rough_blinn_phong(&inp, &ri, cfg, units, sat);
    // The twin on the same quantized inputs; D decoded from the same texels, scaled in float.
    let fv = |x: &[i64; 3]| r::from_vec3x(x, f);
    let (n, l, v) = (fv(&nq), fv(&lq), fv(&vq));
    let (tu, tv) = (fv(&tq[0]), fv(&tq[1]));
    let lens = case.len.map(|x| x as f64 * (-f64::from(lfb)).exp2());
    let dv = scale_d_f(
        decode_d_texels(case.tex, 16, cfg.rough_range_exp),
        lens,
        iso,
    );
    let e = cfg.exponent(case.shininess);
    let norm_on = cfg.rough_normalize && cfg.rough_variant != RoughVariant::None;
    let norm = if norm_on {
        normalize_factor(dv, cfg.rough_variant, e, case.shininess)
    } else {
        1.0
    };
    // Unorm colours: raw x means x / (2^C - 1).
    let cu = 1.0 / ((1u64 << C) - 1) as f64;
    let col = |c: [u64; 3]| c.map(|x| x as f64 * cu);
    let (kdf, ksf, lf) = (col(kd), col(ks), col(light));
    let (want, hz) = rough_blinn_phong_f(
        n,
        l,
        v,
        [tu, tv],
        dv,
        cfg.rough_variant,
        e,
        norm,
        [kdf, ksf, lf],
    );
    assert_eq!(hz, out.h_zero);
    // The bound of the rough_blinn_phong doc comment.
    let ulp = (-f64::from(f)).exp2();
    let dd_d = (-f64::from(t + 1)).exp2();
    let ndl = n.dot(l).clamp(0.0, 1.0);
    let (x_t, spec_t, dx) = if hz || ndl == 0.0 {
        (0.0, 0.0, 0.0)
    } else {
        let h = (l + v).normalize();
        let (d, c) = d_and_cos(n, h, tu, tv);
        let x = rough_cos_twin(cfg.rough_variant, c, d, dv);
        let eps_h = RSQRT_REL * (1u64 << f) as f64 + 0.5;
        let s3 = 3f64.sqrt();
        let dc = (s3 * eps_h * n.length() + 0.5) * ulp;
        let nt = n.dot(tu).abs().max(n.dot(tv).abs());
        let tl = tu.length().max(tv.length());
        let dd = (s3 * eps_h * (tl + n.length() * nt) + 0.5 * nt + 1.5) * ulp + dc * ulp;
        let e_rough = if cfg.rough_variant == RoughVariant::None {
            (-f64::from(p + 1)).exp2()
        } else {
            1.5 * (-f64::from(cfg.rough_div_bits)).exp2()
                + (-f64::from(cfg.rough_sqrt_bits)).exp2()
                + (-f64::from(p + 1)).exp2()
                + (-20f64).exp2()
        };
        let dx = e_rough
            + e_in(
                cfg.rough_variant,
                c.clamp(0.0, 1.0),
                [d[0].clamp(-1.0, 1.0), d[1].clamp(-1.0, 1.0)],
                dv,
                dc,
                dd,
                dd_d,
            );
        (x, r::pow(x, e), dx)
    };
    let ef = f64::from(e);
    let x_hi = (x_t + dx).min(1.0);
    let (lb, gb) = (
        f64::from(units.cfg.pow.pow_lut_bits),
        f64::from(p + units.cfg.pow.pow_guard_bits),
    );
    let xe = x_hi.powf(ef);
    let e_pow = xe * ef * std::f64::consts::LN_2 * (0.1803 * (-2.0 * lb).exp2() + (-gb).exp2())
        + xe * (0.0601 * (-2.0 * lb).exp2() + (-gb).exp2())
        + (-f64::from(p + 1)).exp2();
    let mut d_spec = e_pow + ef * x_hi.powf(ef - 1.0) * dx;
    if norm_on && spec_t + d_spec > 0.0 {
        // min(1, r), r = (e / s) / (d1 d3): the divider's 2^-div and the D rounding.
        let d1 = dv[0];
        let d3 = if iso { dv[0] } else { dv[2] };
        let q = (-f64::from(cfg.rough_div_bits)).exp2();
        let rt = ef / f64::from(case.shininess.max(1)) / (d1 * d3);
        let (f_lo, f_hi) = if d1 > dd_d && d3 > dd_d {
            let rho_hi = (1.0 + dd_d / d1) * (1.0 + dd_d / d3);
            let rho_lo = (1.0 - dd_d / d1) * (1.0 - dd_d / d3);
            (
                (rt * (1.0 - q) / rho_hi).min(1.0),
                (rt * (1.0 + q) / rho_lo).min(1.0),
            )
        } else {
            (0.0, 1.0)
        };
        d_spec = f_hi * d_spec + spec_t * (f_hi - f_lo) + (-f64::from(p + 1)).exp2();
    }
    let switch = if ndl <= ulp { spec_t * norm } else { 0.0 };
    let mut worst = 0.0f64;
    for k in 0..3 {
        let got = out.color[k] as f64 * cu;
        let b = lf[k] * (ksf[k] * (d_spec + switch) + kdf[k] * 0.5 * ulp) + cu;
        let err = (got - want[k]).abs();
        assert!(
            err <= b,
            "{:?} F {f} P {p} e {} ch {k}: {got} vs {} (bound {b}, x {x_t}, dx {dx})",
            cfg.rough_variant,
            cfg.rough_range_exp,
            want[k]
        );
        if switch == 0.0 && b > 8.0 * cu {
            worst = worst.max(err / b);
        }
    }
    worst
}

/// The reciprocal square root unit's relative error bound (texram16, `hw_model::rsqrt`).
const RSQRT_REL: f64 = 6.53e-6;

fn random_case(rng: &mut Rng) -> Case {
    let n = rng.dir();
    // Tangents: orthonormal to n (the main frame), or a sheared, non-orthogonal pair.
    let a = n.any_orthonormal_vector();
    let b = n.cross(a);
    let phi = rng.unit() * std::f64::consts::TAU;
    let (tu0, tv0) = (
        a * phi.cos() + b * phi.sin(),
        -a * phi.sin() + b * phi.cos(),
    );
    let t = match rng.below(3) {
        0 => [tu0, tv0],
        1 => [
            (tu0 + n * (rng.unit() - 0.5)).normalize(),
            (tv0 + tu0 * (rng.unit() - 0.5) + n * (rng.unit() - 0.5)).normalize(),
        ],
        _ => [rng.dir(), rng.dir()],
    };
    let v = rng.dir();
    let v = if v.dot(n) < 0.0 && rng.below(4) != 0 {
        -v
    } else {
        v
    };
    // Light: near the mirror direction of v (h near n: the highlight), random, grazing,
    // or exactly opposite to the eye.
    let mirror = 2.0 * n.dot(v) * n - v;
    let l = match rng.below(8) {
        0..=3 => (mirror + rng.dir() * (0.3 * rng.unit())).normalize(),
        4 | 5 => rng.dir(),
        6 => {
            let tt = (mirror - n * n.dot(mirror)).normalize_or(a);
            (tt + n * (2e-3 * rng.unit() - 1e-3)).normalize()
        }
        _ => -v,
    };
    let lim = 1u64 << 16;
    let ch = |rng: &mut Rng, centre: bool| match rng.below(8) {
        0 => 0,
        1 => lim,
        2 => rng.below(16),
        3 if centre => 1 << 15,
        _ => rng.below(lim + 1),
    };
    let tex = [ch(rng, false), ch(rng, true), ch(rng, false)];
    let lenv = |rng: &mut Rng| match rng.below(6) {
        0 => rng.unit() * 16.0,
        1 => rng.unit() * 0.25,
        2 => 1.0,
        _ => 0.25 + rng.unit() * 3.75,
    };
    let len = [lenv(rng), lenv(rng)];
    let shininess = 1 + rng.below(1024) as u32;
    let colors = [0; 3].map(|_| [0; 3].map(|_| rng.below(1 << C)));
    Case {
        n,
        l,
        v,
        t,
        tex,
        len: [0, 1].map(|i| (len[i] * 256.0).round() as i64),
        shininess,
        colors,
    }
}

#[test]
fn rough_blinn_phong_matches_its_twin_within_the_stated_bound() {
    let mut rng = Rng(41);
    let mut sat = SatCounter::default();
    let variants = RoughVariant::ALL;
    let mut worst = [0.0f64; 5];
    let mut cases = 0u64;
    for f in [8u32, 10, 12, 14, 15] {
        for p in [12u32, 16, 24] {
            let mut sc = ShadingConfig::texram16();
            sc.vector.vector_frac_bits = f;
            sc.pow.pow_frac_bits = p;
            assert_eq!(sc.rsqrt, RsqrtConfig::texram16());
            let units = ShadingUnits::new(&sc);
            for _ in 0..80_000 {
                let vi = rng.below(5) as usize;
                let bits = [10u32, 12, 16, 24];
                let cfg = RoughnessConfig {
                    rough_variant: variants[vi],
                    rough_range_exp: rng.below(9) as i32 - 4,
                    rough_div_bits: bits[rng.below(4) as usize],
                    rough_sqrt_bits: bits[rng.below(4) as usize],
                    rough_exponent_mode: if rng.below(4) == 0 {
                        RoughExponentMode::Constant
                    } else {
                        RoughExponentMode::Material
                    },
                    rough_const_exponent: 1 + rng.below(64) as u32,
                    rough_normalize: rng.below(2) == 0,
                    ..RoughnessConfig::texram16()
                };
                let case = random_case(&mut rng);
                worst[vi] = worst[vi].max(check(&case, &cfg, &units, &mut sat));
                cases += 1;
            }
        }
    }
    for (v, w) in variants.iter().zip(worst) {
        println!("{:<12} worst error / bound {w:.3}", v.name());
    }
    println!("{cases} cases");
    assert!(worst.iter().all(|&w| w > 0.0 && w <= 1.0));
}

#[test]
fn scale_d_matches_its_twin_within_half_an_lsb_and_counts_saturations() {
    let mut rng = Rng(42);
    let lim = D_RAW_LIMIT as f64;
    let mut saturated = 0u64;
    for _ in 0..2_000_000 {
        let range_exp = rng.below(9) as i32 - 4;
        let cfg = RoughnessConfig {
            rough_range_exp: range_exp,
            ..RoughnessConfig::texram16()
        };
        let tex = [0; 3].map(|_| rng.below((1 << 16) + 1));
        let lfb = 4 + rng.below(13) as u32;
        let len = [0; 2].map(|_| (rng.next() >> (rng.below(40) + 24)) as i64);
        let iso = rng.below(4) == 0;
        let (dv, t) = decode_d(tex, 16, &cfg);
        let mut sat = SatCounter::default();
        let got = scale_d(dv, len, lfb, iso, &mut sat);
        let lens = len.map(|x| x as f64 * (-f64::from(lfb)).exp2());
        let want = scale_d_f(decode_d_texels(tex, 16, range_exp), lens, iso);
        let scale = f64::from(t).exp2();
        let mut n_sat = 0;
        for i in 0..3 {
            let w = want[i] * scale;
            if w.abs() > lim {
                n_sat += 1;
                assert_eq!(got[i] as f64, lim.copysign(w), "{tex:?} {len:?}");
            } else {
                assert!((got[i] as f64 - w).abs() <= 0.5, "{tex:?} {len:?} {i}");
            }
        }
        assert_eq!(sat.saturated, n_sat);
        saturated += n_sat;
    }
    println!("scale_d: {saturated} saturated entries");
    assert!(saturated > 0);
}

#[test]
fn d_raw_limit_and_q_cap_saturate_to_zero_or_clamp_and_are_counted() {
    let cfg = RoughnessConfig::texram16();
    let lim = D_RAW_LIMIT;
    // scale_d: D = 4 (t = 14) times length 255 (u8.8) is 1020 > 2^20 / 2^14 = 64.
    let mut sat = SatCounter::default();
    let (dv, t) = decode_d([1 << 16, 0, 1 << 16], 16, &cfg);
    assert_eq!(t, 14);
    let out = scale_d(dv, [255 << 8, 255 << 8], 8, false, &mut sat);
    assert_eq!(out, [lim, -lim, lim]);
    assert_eq!(sat.saturated, 3);
    // rough_cos_d: D beyond the limit is clamped (counted once) and evaluated clamped.
    let f = 14u32;
    let one = 1i64 << f;
    let (c, d) = (one / 2, [one / 2, one / 3]);
    let mut sat = SatCounter::default();
    let big = rough_cos_d(
        c,
        d,
        [4 * lim, -3 * lim, 2 * lim],
        14,
        &cfg,
        f,
        16,
        &mut sat,
    );
    assert_eq!(sat.saturated, 1);
    let mut sat2 = SatCounter::default();
    let clamped = rough_cos_d(c, d, [lim, -lim, lim], 14, &cfg, f, 16, &mut sat2);
    assert_eq!(sat2.saturated, 0);
    assert_eq!(big, clamped);
    // Q >= 2^40: directional with sigma = 2^-20 (range_exp -4: t = 20, one raw LSB) and
    // |d| = 1 gives Q = 2^40; Mahalanobis with a huge shear over tiny d1, d3 gives 2^68.
    for (variant, e, dv, dvec) in [
        (RoughVariant::Directional, -4, [1i64, 0, 1], [one, 0]),
        (RoughVariant::Published, -4, [1, 0, 1], [0, one]),
        (RoughVariant::Mahalanobis, 2, [1, lim, 1], [0, one]),
        (RoughVariant::Isotropic, -4, [1, 0, 0], [one, 0]),
    ] {
        let cfg = RoughnessConfig {
            rough_variant: variant,
            rough_range_exp: e,
            ..RoughnessConfig::texram16()
        };
        let t = (16 - e) as u32;
        let mut sat = SatCounter::default();
        let o = rough_cos_d(one, dvec, dv, t, &cfg, f, 16, &mut sat);
        assert!(o.degenerate && o.cos_mod == 0, "{variant:?} {o:?}");
        assert_eq!(sat.saturated, 1, "{variant:?}");
        let s = (-f64::from(t)).exp2();
        let twin = rough_cos_twin(
            variant,
            1.0,
            dvec.map(|x| x as f64 / one as f64),
            dv.map(|x| x as f64 * s),
        );
        assert_eq!(
            twin, 0.0,
            "{variant:?}: the twin caps at 2^{Q_CAP_BITS} too"
        );
        // One step inside the cap: finite, positive, no saturation.
        let mut sat = SatCounter::default();
        let o = rough_cos_d(one, dvec, dv.map(|x| x * 2), t, &cfg, f, 24, &mut sat);
        if variant != RoughVariant::Mahalanobis {
            assert!(!o.degenerate && o.cos_mod > 0, "{variant:?} {o:?}");
            assert_eq!(sat.saturated, 0);
        }
    }
    // Through the shading unit: a Q-capped pixel has no specular term and counts.
    let units = ShadingUnits::new(&ShadingConfig::texram16());
    let cfg = RoughnessConfig {
        rough_range_exp: -4,
        ..RoughnessConfig::texram16()
    };
    let n = [0, 0, one];
    let l = r::to_vec3x(DVec3::new(0.6, 0.0, 0.8), f);
    let v = r::to_vec3x(DVec3::new(-0.6, 0.0, 0.8), f);
    let inp = BlinnPhongInput {
        n,
        l,
        v,
        shininess: 1,
        kd: [0; 3],
        ks: [65535; 3],
        light: [65535; 3],
    };
    let ri = RoughShadeInput {
        t_u: [0, one, 0],
        t_v: [0, 0, 0],
        dv: [1, 0, 1],
        t: 20,
    };
    // h = n exactly: d = 0, cos a' = 1 (no saturation).
    let mut sat = SatCounter::default();
    let (o, ro) = rough_blinn_phong(&inp, &ri, &cfg, &units, &mut sat);
    assert!(ro.d_zero && o.color[0] > 60_000, "{o:?} {ro:?}");
    // Unorm colour ending: a white light on a white surface lit head-on is white, exactly.
    let head_on = BlinnPhongInput {
        l: n,
        v: n,
        kd: [65535; 3],
        ks: [0; 3],
        ..inp
    };
    let (o, _) = rough_blinn_phong(&head_on, &ri, &cfg, &units, &mut sat);
    assert_eq!(o.color, [65535; 3], "white x white must be white");
    // Mahalanobis with a huge shear over tiny d1, d3 and h tilted along t_v: Q far above
    // 2^40, so no specular term, and the saturation is counted.
    let cfg = RoughnessConfig {
        rough_variant: RoughVariant::Mahalanobis,
        ..RoughnessConfig::texram16()
    };
    let ri = RoughShadeInput {
        t_u: [one, 0, 0],
        t_v: [0, one, 0],
        dv: [1, lim, 1],
        t: 14,
    };
    let inp = BlinnPhongInput {
        l: r::to_vec3x(DVec3::new(0.0, 0.6, 0.8), f),
        v: [0, 0, one],
        ..inp
    };
    let mut sat = SatCounter::default();
    let (o, ro) = rough_blinn_phong(&inp, &ri, &cfg, &units, &mut sat);
    assert!(ro.degenerate, "{ro:?}");
    assert_eq!(o.color, [0; 3]);
    assert_eq!(sat.saturated, 1);
}

#[test]
fn flat_texels_shade_as_plain_blinn_phong_only_in_an_orthonormal_frame() {
    // A flat texel (K = 0) stores K' = s (0 + s0^2 I) = I with s0 = 1/sqrt(s) (material
    // mode), so the modified Blinn-Phong is the plain one: tan a' = tan a. That needs
    // |d| = sin a, i.e. t_u, t_v an orthonormal basis of the tangent plane of the shading
    // normal (the main frame with an unperturbed normal, lengths 1). A normal tilted off the
    // frame (a constant nonzero offset) or a natural frame breaks it.
    use texsim::shading::roughness::{d_factor, RoughParams};
    let mut rng = Rng(43);
    let (mut worst_main, mut worst_tilt, mut worst_natural) = (0.0f64, 0.0f64, 0.0f64);
    for _ in 0..200_000 {
        let s = 1 + rng.below(1024) as u32;
        let dv = d_factor(RoughParams::for_material(s, s, false).stored_cov([0.0; 3]));
        let n = rng.dir();
        let a = n.any_orthonormal_vector();
        let phi = rng.unit() * std::f64::consts::TAU;
        let tu = a * phi.cos() + n.cross(a) * phi.sin();
        let tv = n.cross(tu);
        let v = rng.dir();
        let v = if v.dot(n) < 0.0 { -v } else { v };
        let l = ((2.0 * n.dot(v) * n - v) + rng.dir() * (0.5 * rng.unit())).normalize();
        let white = [1.0; 3];
        let cols = [[0.0; 3], white, white];
        let plain = |nn: DVec3| r::blinn_phong(nn, l, v, s, [0.0; 3], white, white).0[0];
        for variant in [
            RoughVariant::Published,
            RoughVariant::Directional,
            RoughVariant::Mahalanobis,
            RoughVariant::Isotropic,
        ] {
            let d = if variant == RoughVariant::Isotropic {
                [dv[0], 0.0, 0.0]
            } else {
                dv
            };
            let main = rough_blinn_phong_f(n, l, v, [tu, tv], d, variant, s, 1.0, cols).0[0];
            worst_main = worst_main.max((main - plain(n)).abs());
            // The shading normal tilted by a constant offset 0.3 along t_u (flat, K = 0).
            let nt = (n + 0.3 * tu).normalize();
            let tilt = rough_blinn_phong_f(nt, l, v, [tu, tv], d, variant, s, 1.0, cols).0[0];
            worst_tilt = worst_tilt.max((tilt - plain(nt)).abs());
            // A natural frame: sheared tangents, lengths 2 and 1/2 (D scaled by them).
            let tvn = (tv + 0.5 * tu).normalize();
            let dn = scale_d_f(d, [2.0, 0.5], variant == RoughVariant::Isotropic);
            let nat = rough_blinn_phong_f(n, l, v, [tu, tvn], dn, variant, s, 1.0, cols).0[0];
            worst_natural = worst_natural.max((nat - plain(n)).abs());
        }
    }
    println!(
        "flat texel vs plain Blinn-Phong, max |difference| of the specular term: main frame \
         {worst_main:.2e}, normal tilted 0.3 off the frame {worst_tilt:.3}, natural frame \
         {worst_natural:.3}"
    );
    assert!(worst_main < 1e-12, "{worst_main}");
    assert!(worst_tilt > 0.01 && worst_natural > 0.1);
}
