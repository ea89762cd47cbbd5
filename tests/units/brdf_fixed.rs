//! The bit-accurate unit `hw_model::aniso_phong` against its float twin (the f64 reference
//! evaluated from the same quantized dot products and parameters), its guards, saturation
//! counting, cost, and a precision sweep (printed with `--nocapture`).

use crate::rng_common::Rng;
use glam::DVec3;
use hw_model::aniso_phong::{aniso_phong, aniso_phong_cost, AnisoPhongConfig, AnisoPhongInputs};
use hw_model::SatCounter;
use rayon::prelude::*;
use std::f64::consts::PI;
use texsim::brdf::fixed_twin::{pf_to_f64, quantize, twin_pi_rho};
use texsim::brdf::{dir_from_angles, AshikhminShirley, Dots};

/// Draws of this file's cases from the tests' shared generator.
trait Draws {
    fn upper(&mut self) -> DVec3;
    fn pair(&mut self, p: &AshikhminShirley) -> (DVec3, DVec3);
    fn model(&mut self) -> AshikhminShirley;
}

impl Draws for Rng {
    fn upper(&mut self) -> DVec3 {
        match self.next() % 8 {
            0 => dir_from_angles(85.0 + 5.0 * self.unit(), 360.0 * self.unit()),
            1 => dir_from_angles(0.5 * self.unit(), 360.0 * self.unit()),
            _ => dir_from_angles((self.unit()).acos().to_degrees(), 360.0 * self.unit()),
        }
    }
    /// A pair biased toward the specular lobe (k2 near the mirror of k1) half of the time.
    fn pair(&mut self, p: &AshikhminShirley) -> (DVec3, DVec3) {
        let k1 = self.upper();
        if self.next() & 1 == 0 {
            if let Some((k2, _)) = p.sample(k1, [self.unit(), self.unit()]) {
                return (k1, k2);
            }
        }
        (k1, self.upper())
    }
    fn model(&mut self) -> AshikhminShirley {
        let e = |r: &mut Rng| match r.next() % 4 {
            0 => [0.0, 1.0, 10.0, 100_000.0][(r.next() % 4) as usize],
            _ => (10f64.powf(5.0 * r.unit())).round(),
        };
        let (nu, nv) = (e(self), e(self));
        AshikhminShirley::new(nu, nv, self.unit(), self.unit()).expect("valid")
    }
}

/// Values below this (in units of pi rho) may be flushed to zero by the unit (the power is
/// flushed below 2^-100, and sqrt((nu+1)(nv+1))/8 / den < 2^42): only an absolute bound applies.
const FLOOR: f64 = 1e-15;

/// Error statistics of one configuration over `n` random cases.
#[derive(Default, Clone)]
struct Stats {
    /// Max |fixed - twin| / twin over non-saturated cases with twin >= FLOOR.
    max_rel: f64,
    /// Max |fixed - twin| where twin < FLOOR.
    max_abs_floor: f64,
    /// End-to-end relative errors (fixed from quantized dots vs exact f64 from the unquantized
    /// directions) where the exact value is above 1e-3.
    e2e: Vec<f64>,
    /// Cases that saturated (excluded from the error figures).
    saturated: u64,
    /// (twin, fixed) of the worst relative case.
    worst: (f64, f64),
}

fn run(cfg: &AnisoPhongConfig, n: usize, seed: u64) -> Stats {
    let chunks = 64;
    let mut all: Vec<Stats> = (0..chunks)
        .into_par_iter()
        .map(|c| {
            let mut r = Rng(seed ^ (c as u64).wrapping_mul(0xD1B5_4A32_D192_ED03));
            let mut st = Stats::default();
            for _ in 0..n / chunks {
                let p = r.model();
                let (k1, k2) = r.pair(&p);
                let Some(d) = Dots::from_dirs(k1, k2) else {
                    continue;
                };
                let inp = quantize(&p, &d, cfg);
                let mut sat = SatCounter::default();
                let out = aniso_phong(&inp, cfg, &mut sat);
                if sat.saturated > 0 {
                    st.saturated += 1;
                    continue;
                }
                let (ts, td) = twin_pi_rho(&inp, cfg);
                let tw = ts + td;
                let fx = pf_to_f64(out.total);
                let err = (fx - tw).abs();
                if tw >= FLOOR {
                    if err / tw > st.max_rel {
                        st.max_rel = err / tw;
                        st.worst = (tw, fx);
                    }
                } else {
                    st.max_abs_floor = st.max_abs_floor.max(err);
                }
                let exact = PI * p.eval(k1, k2);
                if exact > 1e-3 {
                    st.e2e.push((fx - exact).abs() / exact);
                }
            }
            st
        })
        .collect();
    let mut tot = Stats::default();
    for st in all.iter_mut() {
        if st.max_rel > tot.max_rel {
            tot.max_rel = st.max_rel;
            tot.worst = st.worst;
        }
        tot.max_abs_floor = tot.max_abs_floor.max(st.max_abs_floor);
        tot.saturated += st.saturated;
        tot.e2e.append(&mut st.e2e);
    }
    tot.e2e.sort_by(f64::total_cmp);
    tot
}

fn quantile(v: &[f64], q: f64) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v[((v.len() - 1) as f64 * q) as usize]
}

/// texram16 over 2^21 random cases (exponents 0..1e5 integer, Rs, Rd uniform, directions
/// uniform-cosine plus grazing and near-normal ones, half of them sampled from the lobe):
/// the bound stated in `hw_model::aniso_phong`'s module doc, `|fixed - twin| <= 2e-4 twin`
/// for twin >= 1e-15 (pi rho units; below that only `|fixed - twin| <= 1e-15`), excluding
/// inputs that saturate (output >= 2^24, extreme grazing; counted, < 0.1%).
#[test]
fn texram16_matches_twin() {
    let cfg = AnisoPhongConfig::texram16();
    let st = run(&cfg, 1 << 21, 42);
    println!(
        "texram16: max rel {:.3e} (twin {:.4e} fixed {:.4e}), max abs below floor {:.3e}, end-to-end rel p50 {:.2e} p99 {:.2e}, saturated {}",
        st.max_rel,
        st.worst.0,
        st.worst.1,
        st.max_abs_floor,
        quantile(&st.e2e, 0.5),
        quantile(&st.e2e, 0.99),
        st.saturated
    );
    assert!(st.max_rel <= 2e-4, "relative error {}", st.max_rel);
    assert!(
        st.max_abs_floor <= FLOOR,
        "absolute error {}",
        st.max_abs_floor
    );
    assert!(st.saturated < (1 << 21) / 1000, "{}", st.saturated);
}

/// Precision sweep (printed): datapath error vs aniso_pow_lut_bits and aniso_pow_frac_bits,
/// fresnel_bits and aniso_ratio_bits, saturations and cycles vs exponent_max_bits, and the
/// end-to-end error vs the dot-product width. Asserts each knob has an effect: a 4-bit ROM is
/// measurably worse than the 8-bit one, 8 Fresnel bits worse than 16, a 4-bit exponent fraction
/// worse than 16 bits, 8 and 12 exponent bits clamp more of the exponents (up to 1e5) than 17
/// and cost fewer cycles, and 6 dot bits are worse end-to-end than 14.
#[test]
fn precision_sweep() {
    let n = 1 << 15;
    println!("aniso_pow_lut_bits aniso_pow_frac_bits | max rel err vs twin");
    let mut by_lut = Vec::new();
    for lut in [4u32, 6, 8, 10, 12] {
        for frac in [16u32, 20, 24, 28] {
            let mut cfg = AnisoPhongConfig::texram16();
            cfg.aniso_pow_lut_bits = lut;
            cfg.aniso_pow_frac_bits = frac;
            assert!(cfg.validate().is_ok());
            let st = run(&cfg, n, 7);
            println!("{lut:>12} {frac:>13} | {:.3e}", st.max_rel);
            if frac == 24 {
                by_lut.push(st.max_rel);
            }
        }
    }
    assert!(by_lut[0] > 2.0 * by_lut[2], "{by_lut:?}");
    println!("fresnel_bits | max rel err vs twin");
    let mut by_fresnel = Vec::new();
    for fb in [8u32, 12, 16, 20] {
        let mut cfg = AnisoPhongConfig::texram16();
        cfg.fresnel_bits = fb;
        let e = run(&cfg, n, 8).max_rel;
        println!("{fb:>12} | {e:.3e}");
        by_fresnel.push(e);
    }
    assert!(
        by_fresnel[0] > SWEEP_FRESNEL * by_fresnel[2],
        "{by_fresnel:?}"
    );
    println!("aniso_ratio_bits | max rel err vs twin");
    let mut by_ratio = Vec::new();
    for r in [4u32, 8, 12, 16] {
        let mut cfg = AnisoPhongConfig::texram16();
        cfg.aniso_ratio_bits = r;
        let e = run(&cfg, n, 10).max_rel;
        println!("{r:>16} | {e:.3e}");
        by_ratio.push(e);
    }
    assert!(by_ratio[0] > SWEEP_RATIO * by_ratio[3], "{by_ratio:?}");
    // The exponents of `run` go up to 1e5: narrower exponent inputs clamp them (in `quantize`,
    // so the twin sees the clamped value too), which shows in the end-to-end error against the
    // exact model; the divider gets shorter.
    println!("exponent_max_bits | end-to-end rel err p90 p99, cycles");
    let mut by_emax = Vec::new();
    for eb in [8u32, 12, 17] {
        let mut cfg = AnisoPhongConfig::texram16();
        cfg.exponent_max_bits = eb;
        let st = run(&cfg, n, 11);
        let (p90, p99) = (quantile(&st.e2e, 0.9), quantile(&st.e2e, 0.99));
        let cycles =
            aniso_phong_cost(&cfg, hw_model::timing_config::DEFAULT_GATE_LEVELS_PER_CYCLE).cycles;
        println!("{eb:>17} | {p90:.2e} {p99:.2e} {cycles}");
        by_emax.push((p99, cycles));
    }
    assert!(
        by_emax[0].0 > by_emax[1].0 && by_emax[1].0 > SWEEP_EMAX * by_emax[2].0,
        "{by_emax:?}"
    );
    assert!(by_emax[0].1 < by_emax[2].1, "{by_emax:?}");
    println!(
        "aniso_dot_frac_bits | end-to-end rel err vs exact directions (values > 1e-3): p50 p90 p99"
    );
    let mut e2e = Vec::new();
    for dot in [6u32, 8, 10, 12, 14, 15] {
        let mut cfg = AnisoPhongConfig::texram16();
        cfg.aniso_dot_frac_bits = dot;
        let st = run(&cfg, n, 9);
        let (a, b, c) = (
            quantile(&st.e2e, 0.5),
            quantile(&st.e2e, 0.9),
            quantile(&st.e2e, 0.99),
        );
        println!("{dot:>19} | {a:.2e} {b:.2e} {c:.2e}");
        e2e.push(a);
    }
    assert!(e2e[0] > 4.0 * e2e[4], "{e2e:?}");
}

// Measured (2^15 cases per setting): max rel err 2.0e-2 at 8 Fresnel bits vs 5.4e-5 at 16
// (x368); 1.1e-1 at 4 exponent fraction bits vs 5.7e-5 at 16 (x1900); end-to-end p99 1.12 at
// 12 exponent bits vs 9.3e-3 at 17 (x120). Asserted with a wide margin.
const SWEEP_FRESNEL: f64 = 100.0;
const SWEEP_RATIO: f64 = 100.0;
const SWEEP_EMAX: f64 = 20.0;

fn cfg16() -> AnisoPhongConfig {
    AnisoPhongConfig::texram16()
}

/// Unit inputs from float dots `[h.n, h.u, h.v, k.h, n.k1, n.k2]` (1.14) and exponents, with
/// Rs = 0.5 and Rd = 1.
fn inputs(d: [f64; 6], nu: u32, nv: u32) -> AnisoPhongInputs {
    let q = |x: f64| (x * 16384.0).round() as i32;
    AnisoPhongInputs {
        hn: q(d[0]),
        hu: q(d[1]),
        hv: q(d[2]),
        kh: q(d[3]),
        nk1: q(d[4]),
        nk2: q(d[5]),
        nu,
        nv,
        rs: 1 << 15,
        rd: 1 << 16,
    }
}

/// Guards: h = n gives power exactly 1 (spec = sqrt((nu+1)(nv+1))/8 F/den); any of h.n, k.h,
/// n.k1, n.k2 <= 0 gives zero (how the caller encodes k1 = -k2 and below-horizon directions);
/// nu = nv = 0 gives a power of 1 even for horizontal h.
#[test]
fn guards() {
    let cfg = cfg16();
    let mut sat = SatCounter::default();
    let at_n = aniso_phong(
        &inputs([1.0, 0.0, 0.0, 1.0, 1.0, 1.0], 100, 10000),
        &cfg,
        &mut sat,
    );
    let expect = (101.0f64 * 10001.0).sqrt() / 8.0 * 0.5;
    assert!(
        (pf_to_f64(at_n.spec) - expect).abs() < 1e-4 * expect,
        "{} {expect}",
        pf_to_f64(at_n.spec)
    );
    for bad in [
        inputs([0.0, 1.0, 0.0, 0.5, 0.5, 0.5], 10, 10),
        inputs([1.0, 0.0, 0.0, 0.0, 0.0, 0.0], 10, 10),
        inputs([0.9, 0.1, 0.0, 0.5, -0.1, 0.5], 10, 10),
        inputs([0.9, 0.1, 0.0, 0.5, 0.5, 0.0], 10, 10),
        AnisoPhongInputs::default(),
    ] {
        let o = aniso_phong(&bad, &cfg, &mut sat);
        assert_eq!(
            (o.total.mant, o.spec.mant, o.diffuse.mant),
            (0, 0, 0),
            "{bad:?}"
        );
    }
    let flat = aniso_phong(
        &inputs([1e-4, 1.0, 0.0, 0.5, 0.5, 0.5], 0, 0),
        &cfg,
        &mut sat,
    );
    // nu = nv = 0: rho_s pi = 1/8 F / (k.h max) with F = 0.5 + 0.5 (0.5)^5.
    let f = 0.5 + 0.5 * 0.5f64.powi(5);
    let expect = 0.125 * f / 0.25;
    assert!(
        (pf_to_f64(flat.spec) - expect).abs() < 1e-3 * expect,
        "{} {expect}",
        pf_to_f64(flat.spec)
    );
    assert_eq!(sat.saturated, 0);
}

/// Saturation is counted: out-of-range dot products, exponents above exponent_max_bits, and an
/// output at or above 2^aniso_out_exp_max (a huge exponent at extreme grazing).
#[test]
fn saturation_is_counted() {
    let cfg = cfg16();
    let mut sat = SatCounter::default();
    let mut i = inputs([1.0, 0.0, 0.0, 1.0, 1.0, 1.0], 10, 10);
    i.hn = 20000;
    let _ = aniso_phong(&i, &cfg, &mut sat);
    assert_eq!(sat.saturated, 1);
    let mut sat = SatCounter::default();
    let _ = aniso_phong(
        &inputs([1.0, 0.0, 0.0, 0.5, 0.5, 0.5], 1 << 17, 5),
        &cfg,
        &mut sat,
    );
    assert_eq!(sat.saturated, 1);
    let mut sat = SatCounter::default();
    let g = AnisoPhongInputs {
        hn: 16384,
        hu: 0,
        hv: 0,
        kh: 1,
        nk1: 1,
        nk2: 1,
        nu: 100_000,
        nv: 100_000,
        rs: 65536,
        rd: 0,
    };
    let o = aniso_phong(&g, &cfg, &mut sat);
    assert!(sat.saturated >= 1, "{sat:?}");
    assert_eq!(pf_to_f64(o.spec), (65535.0) * 2f64.powi(24 - 16));
}

/// Cost: positive, and slower dividers cost more cycles.
#[test]
fn cost_model() {
    let c = aniso_phong_cost(
        &cfg16(),
        hw_model::timing_config::DEFAULT_GATE_LEVELS_PER_CYCLE,
    );
    assert!(c.ops > 20 && c.cycles > 20 && c.texels == 0, "{c:?}");
    let mut slow = cfg16();
    slow.aniso_div_bits_per_cycle = 1;
    assert!(
        aniso_phong_cost(
            &slow,
            hw_model::timing_config::DEFAULT_GATE_LEVELS_PER_CYCLE
        )
        .cycles
            > c.cycles
    );
    let mut bad = cfg16();
    bad.aniso_pow_lut_bits = 40;
    assert!(bad
        .validate()
        .err()
        .is_some_and(|e| e.field == "aniso_phong.aniso_pow_lut_bits"));
}

/// `albedo_report` with the fixed unit: its last line is the fixed albedo, close to the float
/// one (the unit's relative error is <= 2e-4, so the albedo differs by < 1e-3 incl. rounding
/// of the printed value); non-integer exponents are rejected naming the field.
#[test]
fn albedo_report_with_fixed_unit() {
    let cfg = cfg16();
    let p = AshikhminShirley::new(100.0, 400.0, 0.05, 0.8).expect("valid");
    let rep = texsim::brdf::albedo_report(&p, 30.0, Some(&cfg)).expect("report");
    let last: f64 = rep
        .lines()
        .last()
        .and_then(|l| l.trim().parse().ok())
        .expect("number");
    let float = p.albedo_quadrature(dir_from_angles(30.0, 0.0), 32);
    assert!((last - float).abs() < 1e-3, "{rep}");
    let bad = AshikhminShirley::new(10.5, 400.0, 0.05, 0.8).expect("valid float model");
    assert!(texsim::brdf::albedo_report(&bad, 30.0, Some(&cfg))
        .err()
        .is_some_and(|e| e.message().contains("'nu'")));
}

/// Reciprocity of the unit (eqs. 10 and 16 are symmetric in `k1, k2`): swapping `n.k1` and
/// `n.k2` of the same quantized inputs (`h` and `k.h` are shared by both directions) changes
/// only the order of the diffuse product's roundings, so both outputs are within the unit's
/// declared `2e-4` of the same (symmetric) twin value, hence within `4e-4` of each other
/// (`1e-15` absolute below the floor). End to end, the unit fed `Dots::from_dirs(k2, k1)`
/// (whose `k.h` is computed as `k2.h` and may round to another LSB) differs from it fed
/// `(k1, k2)` by at most the twin's own difference plus `4e-4` (the same triangle inequality).
/// 2^18 seeded cases, saturated outputs excluded. Measured: 83% bit-identical, worst 6.0e-5
/// in both checks.
#[test]
fn unit_is_reciprocal_within_its_bound() {
    let cfg = cfg16();
    let mut r = Rng(99);
    let (mut worst, mut worst_e2e, mut exact, mut n) = (0.0f64, 0.0f64, 0u64, 0u64);
    for _ in 0..1 << 18 {
        let p = r.model();
        let (k1, k2) = r.pair(&p);
        let (Some(d12), Some(d21)) = (Dots::from_dirs(k1, k2), Dots::from_dirs(k2, k1)) else {
            continue;
        };
        let a = quantize(&p, &d12, &cfg);
        let swapped = AnisoPhongInputs {
            nk1: a.nk2,
            nk2: a.nk1,
            ..a
        };
        let b = quantize(&p, &d21, &cfg);
        let mut sat = SatCounter::default();
        let (oa, os, ob) = (
            pf_to_f64(aniso_phong(&a, &cfg, &mut sat).total),
            pf_to_f64(aniso_phong(&swapped, &cfg, &mut sat).total),
            pf_to_f64(aniso_phong(&b, &cfg, &mut sat).total),
        );
        if sat.saturated > 0 {
            continue;
        }
        n += 1;
        exact += u64::from(oa == os);
        let big = oa.max(os);
        if big >= FLOOR {
            worst = worst.max((oa - os).abs() / big);
        } else {
            assert!((oa - os).abs() <= FLOOR, "{a:?}: {oa} {os}");
        }
        let (ts_a, td_a) = twin_pi_rho(&a, &cfg);
        let (ts_b, td_b) = twin_pi_rho(&b, &cfg);
        let (ta, tb) = (ts_a + td_a, ts_b + td_b);
        if ta.max(tb) >= FLOOR {
            let e2e = (oa - ob).abs() - (ta - tb).abs();
            worst_e2e = worst_e2e.max(e2e / ta.max(tb));
        }
    }
    println!(
        "unit reciprocity over {n} cases: {exact} bit-identical, worst rel {worst:.2e}, end to end beyond the twin's own change {worst_e2e:.2e}"
    );
    assert!(n > 200_000, "{n}");
    assert!(worst <= 4e-4, "{worst}");
    assert!(worst_e2e <= 4e-4, "{worst_e2e}");
}
