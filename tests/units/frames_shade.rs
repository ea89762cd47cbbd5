//! Blinn-Phong fixed unit against its f64 twin, including grazing light/view and l = -v.
#![allow(clippy::needless_range_loop)]

use crate::rng_common::Rng;
use glam::DVec3;
use hw_model::blinn_phong::{
    blinn_phong, blinn_phong_cost, BlinnPhongInput, ShadingConfig, ShadingUnits,
};
use hw_model::pow::PowMethod;
use hw_model::SatCounter;
use texsim::shading::reference as r;

const F: u32 = 14;
const C: u32 = 16;

fn run(method: PowMethod, cases: u32) -> f64 {
    let mut cfg = ShadingConfig::texram16();
    cfg.pow.pow_method = method;
    let u = ShadingUnits::new(&cfg);
    let mut s = Rng(77);
    let mut sat = SatCounter::default();
    let mut worst_ratio = 0.0f64;
    // Colours are unorm: raw x means x / (2^C - 1), as in the pipeline.
    let cu = 1.0 / ((1u64 << C) - 1) as f64;
    let ulp = (-f64::from(F)).exp2();
    for i in 0..cases {
        let n = s.dir();
        let mut l = s.dir();
        let mut v = s.dir();
        match i % 4 {
            // Grazing light: n.l in [-1e-3, 1e-3].
            1 => {
                let t = (l - n * n.dot(l)).normalize();
                l = (t + n * (2e-3 * s.unit() - 1e-3)).normalize();
            }
            // Grazing view.
            2 => {
                let t = (v - n * n.dot(v)).normalize();
                v = (t + n * (2e-3 * s.unit() - 1e-3)).normalize();
            }
            // l = -v exactly (after quantization).
            3 if i % 8 == 3 => v = -l,
            _ => {}
        }
        let (nq, lq, vq) = (r::to_vec3x(n, F), r::to_vec3x(l, F), r::to_vec3x(v, F));
        let shininess = 1 + (s.next() % 2047) as u32;
        let col = |s: &mut Rng| [0; 3].map(|_: u64| s.next() % (1 << C));
        let (kd, ks, light) = (col(&mut s), col(&mut s), col(&mut s));
        let inp = BlinnPhongInput {
            n: nq,
            l: lq,
            v: vq,
            shininess,
            kd,
            ks,
            light,
        };
        let out = blinn_phong(&inp, &u, &mut sat);
        let f = |c: [u64; 3]| c.map(|x| x as f64 * cu);
        let (nd, ld, vd) = (
            r::from_vec3x(&nq, F),
            r::from_vec3x(&lq, F),
            r::from_vec3x(&vq, F),
        );
        let (want, hz) = r::blinn_phong(nd, ld, vd, shininess, f(kd), f(ks), f(light));
        assert_eq!(hz, out.h_zero, "case {i}");
        if i % 8 == 3 {
            assert!(out.h_zero);
        }
        // Bound: ks * (pow bound at x + s x^(s-1) * 2.5 ulp (n.h error)) + kd * 1 ulp (n.l,
        // plus the twin's exact normalization of the quantized inputs) + 1 colour ulp.
        let ndl = nd.dot(ld).max(0.0);
        let x = if hz || ndl == 0.0 {
            0.0
        } else {
            nd.dot((ld + vd).normalize()).clamp(0.0, 1.0)
        };
        let sf = f64::from(shininess);
        let pow_b = x.powf(sf) * ((sf * (0.1803 * 2f64.powi(-16) + 2f64.powi(-24))).exp2() - 1.0)
            + 2.0 * sf * 2f64.powi(-24)
            + 2f64.powi(-17);
        let sens = sf * x.powf(sf - 1.0) * 2.5 * ulp;
        for k in 0..3 {
            let got = out.color[k] as f64 * cu;
            let lt = f(light)[k];
            // Near a boundary (n.l ~ 0) the spec term may switch on/off: allow the full term.
            let switch = if ndl < 1.5 * ulp {
                f(ks)[k] * x.powf(sf)
            } else {
                0.0
            };
            let b = lt * (f(ks)[k] * (pow_b + sens) + f(kd)[k] * ulp + switch) + cu;
            let e = (got - want[k]).abs();
            worst_ratio = worst_ratio.max(e / b);
            assert!(e <= b, "case {i} ch {k}: {got} vs {} (bound {b})", want[k]);
        }
    }
    worst_ratio
}

#[test]
fn blinn_phong_log_exp_matches_twin() {
    let w = run(PowMethod::LogExp, 1_000_000);
    println!("blinn-phong log-exp: max err/bound {w:.3}");
}

#[test]
fn blinn_phong_squaring_matches_twin() {
    let w = run(PowMethod::Squaring, 1_000_000);
    println!("blinn-phong squaring: max err/bound {w:.3}");
}

#[test]
fn point_and_directional_light_vectors() {
    let p = DVec3::new(1.0, 2.0, 3.0);
    let l = r::light_dir_point(DVec3::new(1.0, 2.0, 5.0), p);
    assert!((l - DVec3::Z).length() < 1e-12);
    let d = r::light_dir_directional(DVec3::new(0.0, -2.0, 0.0));
    assert!((d - DVec3::Y).length() < 1e-12);
    let u = ShadingUnits::new(&ShadingConfig::texram16());
    assert!(
        blinn_phong_cost(&u, hw_model::timing_config::DEFAULT_GATE_LEVELS_PER_CYCLE).cycles > 0
    );
    assert!(ShadingConfig::texram16().validate().is_ok());
}

/// Colours are unorm (`x / (2^C - 1)`): white light on a white diffuse surface facing it is
/// exactly white at every colour width, half-grey light on white is half-grey within 1/2 LSB,
/// and the fixed colour of random inputs has no systematic bias against the twin.
#[test]
fn unorm_products_at_every_colour_width() {
    let mut s = Rng(5);
    for c in 4..=16u32 {
        let mut cfg = ShadingConfig::texram16();
        cfg.shade.shade_color_bits = c;
        let u = ShadingUnits::new(&cfg);
        let mut sat = SatCounter::default();
        let max = (1u64 << c) - 1;
        let z = r::to_vec3x(DVec3::Z, F);
        let mut inp = BlinnPhongInput {
            n: z,
            l: z,
            v: z,
            shininess: 8,
            kd: [max; 3],
            ks: [0; 3],
            light: [max; 3],
        };
        assert_eq!(blinn_phong(&inp, &u, &mut sat).color, [max; 3], "C = {c}");
        inp.light = [max / 2; 3];
        assert_eq!(
            blinn_phong(&inp, &u, &mut sat).color,
            [max / 2; 3],
            "C = {c}"
        );
        assert_eq!(sat.saturated, 0);
        // Mean signed error over random lit inputs, in LSBs: rounding only (|mean| < 0.05).
        let cu = 1.0 / max as f64;
        let (mut sum, mut k) = (0.0f64, 0u32);
        for _ in 0..20_000 {
            let n = s.dir();
            let l = (n + 0.8 * s.dir()).normalize();
            let (nq, lq) = (r::to_vec3x(n, F), r::to_vec3x(l, F));
            let col = |s: &mut Rng| [0; 3].map(|_: u64| s.next() % (max + 1));
            let (kd, light) = (col(&mut s), col(&mut s));
            let inp = BlinnPhongInput {
                n: nq,
                l: lq,
                v: lq,
                shininess: 8,
                kd,
                ks: [0; 3],
                light,
            };
            let out = blinn_phong(&inp, &u, &mut sat);
            let f = |c: [u64; 3]| c.map(|x| x as f64 * cu);
            let (nd, ld) = (r::from_vec3x(&nq, F), r::from_vec3x(&lq, F));
            let (want, _) = r::blinn_phong(nd, ld, ld, 8, f(kd), [0.0; 3], f(light));
            for ch in 0..3 {
                sum += out.color[ch] as f64 - want[ch] * max as f64;
                k += 1;
            }
        }
        let bias = sum / f64::from(k);
        assert!(bias.abs() < 0.05, "C = {c}: mean signed error {bias} LSB");
    }
}
