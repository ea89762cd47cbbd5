//! The power stage of the Ashikhmin-Shirley unit, `hw_model::aniso_phong::aniso_power`
//! (`(n.h)^E = (1 - s)^(E/2)`, eq. 18's lobe), against `(1 - s)^(E/2)` in f64 with its
//! declared error bound (`texsim::brdf::fixed_twin::power_rel_bound`, derived in the unit's
//! doc from `aniso_pow_lut_bits`, `aniso_pow_frac_bits` and `aniso_ratio_bits`): every ROM
//! entry exhaustively, texram16 over millions of seeded cases with `s in (0, 1)` and
//! `E in [0, 1e5]`, and small configurations exhaustively over all `(s, E)` inputs.

use hw_model::aniso_phong::{
    aniso_power, rom_exp2, rom_g, rom_log2, AnisoPhongConfig, AnisoPhongRoms, POW_FLUSH_X,
};
use hw_model::Rounding;
use rayon::prelude::*;
use texsim::brdf::fixed_twin::{pf_to_f64, power_error_terms, power_rel_bound};

/// Exact `(L, X)` of an input: `L = -log2(1 - s)`, `X = E L / 2`.
fn exact_lx(s: f64, e: f64) -> (f64, f64) {
    let l = -(-s).ln_1p() / std::f64::consts::LN_2;
    (l, 0.5 * e * l)
}

/// Worst case of a batch: largest `error / bound` and the largest relative error.
#[derive(Clone, Copy, Default, Debug)]
struct Worst {
    ratio: f64,
    rel: f64,
    flushed: u64,
    cases: u64,
}

impl Worst {
    fn merge(self, o: Worst) -> Worst {
        Worst {
            ratio: self.ratio.max(o.ratio),
            rel: self.rel.max(o.rel),
            flushed: self.flushed + o.flushed,
            cases: self.cases + o.cases,
        }
    }
}

/// Checks one input against the declared bound (`e` is the exact exponent the output is
/// compared with; the stage sees `e_raw`, within `e_err` of it) and returns its statistics.
fn check(roms: &AnisoPhongRoms, s_raw: u64, e_raw: u64, e: f64, e_err: f64) -> Worst {
    let cfg = roms.config();
    let s = s_raw as f64 / 2f64.powi(2 * cfg.aniso_dot_frac_bits as i32);
    let p = pf_to_f64(aniso_power(s_raw, e_raw, roms));
    let (l, x) = exact_lx(s, e);
    let (dx, _) = power_error_terms(cfg, x, l, e_err);
    let mut w = Worst {
        cases: 1,
        ..Worst::default()
    };
    if e_raw == 0 {
        assert_eq!(p, 1.0, "s {s_raw}: E = 0 must give exactly 1");
        return w;
    }
    if p == 0.0 {
        // Flushed: X_fixed >= 100, so the exact X is at least 100 - dX.
        assert!(
            x >= POW_FLUSH_X as f64 - dx,
            "s {s_raw} e_raw {e_raw}: flushed at X = {x} (dX {dx})"
        );
        w.flushed = 1;
        return w;
    }
    let exact = (-x).exp2();
    let rel = (p / exact - 1.0).abs();
    let bound = power_rel_bound(cfg, x, l, e_err);
    assert!(
        rel <= bound,
        "s {s_raw} e_raw {e_raw} (X {x}): fixed {p:e} exact {exact:e}, rel {rel:e} > bound {bound:e}"
    );
    w.ratio = rel / bound;
    w.rel = rel;
    w
}

/// Every entry of the three ROMs, for every index width and every rounding, is within
/// `u 2^-f + 2^-40` of its function (the premise of the derived bound; `f = 30`, the widest
/// entries, so the `2^-40` computation term is what is checked).
#[test]
fn rom_entries_within_declared_error() {
    for rnd in [Rounding::HalfEven, Rounding::HalfUp, Rounding::Truncate] {
        for b in 2..=16u32 {
            let cfg = AnisoPhongConfig {
                aniso_pow_lut_bits: b,
                aniso_pow_frac_bits: 30,
                aniso_dot_frac_bits: 15,
                aniso_rounding: rnd,
                ..AnisoPhongConfig::texram16()
            };
            assert!(cfg.validate().is_ok());
            let one = 2f64.powi(30);
            let u = if rnd == Rounding::Truncate { 1.0 } else { 0.5 };
            let tol = u / one + 2f64.powi(-40);
            let n = 1u32 << b;
            for i in 0..=n {
                let t = f64::from(i) / f64::from(n);
                let s = 0.5 * t;
                let g = if i == 0 {
                    1.0 / std::f64::consts::LN_2
                } else {
                    exact_lx(s, 2.0).0 / s
                };
                for (what, rom, exact) in [
                    ("g", rom_g(i, &cfg), g),
                    ("log2", rom_log2(i, &cfg), (1.0 + t).log2()),
                    ("exp2", rom_exp2(i, &cfg), (-t).exp2()),
                ] {
                    let e = (rom as f64 / one - exact).abs();
                    assert!(
                        e <= tol,
                        "{what} b {b} i {i} {rnd:?}: error {e:e} > {tol:e}"
                    );
                }
            }
        }
    }
}

/// A random `s_raw` in `(0, 2^sb)`: uniform, log-uniform (narrow lobes), near 1, or at the
/// `s = 1/2` branch point.
fn random_s(r: &mut texsim::brdf::SplitMix64, sb: u32) -> u64 {
    let top = 1u64 << sb;
    let v = match r.next_u64() % 4 {
        0 => r.next_u64() % top,
        1 => (f64::from(sb) * r.next_f64()).exp2() as u64,
        2 => top - 1 - (f64::from(sb) * r.next_f64()).exp2() as u64 % top,
        _ => (top / 2).wrapping_add(r.next_u64() % 64).wrapping_sub(32),
    };
    v.clamp(1, top - 1)
}

/// A random exponent in `[0, e_max]`: uniform, log-uniform, or aimed at `X in [0, 110]` so
/// that most cases are neither flushed nor trivial.
fn random_e(r: &mut texsim::brdf::SplitMix64, s: f64, e_max: f64) -> f64 {
    match r.next_u64() % 4 {
        0 => e_max * r.next_f64(),
        1 => (e_max.log2() * r.next_f64()).exp2() - 1.0,
        _ => {
            let l = exact_lx(s, 2.0).0;
            (2.0 * 110.0 * r.next_f64() / l).min(e_max)
        }
    }
}

/// texram16 over 2^22 seeded cases, `s in (0, 1)`, `E in [0, 1e5]`: with `E` exactly the
/// stage's `aniso_ratio_bits` input, and with `E` real and rounded to it as the divider does
/// (the bound then includes the `L 2^-(r+2)` term). Measured figures are printed.
#[test]
fn texram16_power_within_declared_bound() {
    let cfg = AnisoPhongConfig::texram16();
    let roms = AnisoPhongRoms::new(&cfg);
    let sb = 2 * cfg.aniso_dot_frac_bits;
    let scale = 2f64.powi(cfg.aniso_ratio_bits as i32);
    let e_err = 0.5 / scale;
    let (exact_e, real_e) = (0..64u64)
        .into_par_iter()
        .map(|chunk| {
            let mut r = texsim::brdf::SplitMix64(0xA5_0000 + chunk);
            let (mut a, mut b) = (Worst::default(), Worst::default());
            for _ in 0..(1 << 22) / 64 {
                let s_raw = random_s(&mut r, sb);
                let s = s_raw as f64 / 2f64.powi(sb as i32);
                let e = random_e(&mut r, s, 1e5);
                let e_raw = (e * scale).floor() as u64;
                a = a.merge(check(&roms, s_raw, e_raw, e_raw as f64 / scale, 0.0));
                let e_raw = (e * scale).round() as u64;
                b = b.merge(check(&roms, s_raw, e_raw, e, e_err));
            }
            (a, b)
        })
        .reduce(
            || (Worst::default(), Worst::default()),
            |x, y| (x.0.merge(y.0), x.1.merge(y.1)),
        );
    println!("texram16 power, E exact: {exact_e:?}");
    println!("texram16 power, E rounded to 2^-16: {real_e:?}");
    for w in [exact_e, real_e] {
        assert_eq!(w.cases, 1 << 22);
        assert!(w.flushed < w.cases / 2, "{w:?}");
    }
    // The declared bound is not vacuous: the measured error uses a sizeable part of it.
    assert!(exact_e.ratio > 0.05, "{exact_e:?}");
}

/// Boundary inputs: `s` at its smallest and largest values and at the branch point, `E` at 0,
/// one LSB and its largest value, and a pow input beyond the divider's range (clamped).
#[test]
fn texram16_power_boundaries() {
    let cfg = AnisoPhongConfig::texram16();
    let roms = AnisoPhongRoms::new(&cfg);
    let sb = 2 * cfg.aniso_dot_frac_bits;
    let scale = 2f64.powi(cfg.aniso_ratio_bits as i32);
    let e_top = (1u64 << (cfg.exponent_max_bits + cfg.aniso_ratio_bits)) - 1;
    for s_raw in [
        1,
        2,
        3,
        (1 << (sb - 1)) - 1,
        1 << (sb - 1),
        (1 << (sb - 1)) + 1,
        (1 << sb) - 2,
        (1 << sb) - 1,
    ] {
        for e_raw in [0, 1, 2, 1 << 16, 1 << 20, 100_000 << 16, e_top] {
            let _ = check(&roms, s_raw, e_raw, e_raw as f64 / scale, 0.0);
        }
        // Inputs above the divider's range are clamped to it.
        assert_eq!(
            aniso_power(s_raw, u64::MAX, &roms),
            aniso_power(s_raw, e_top, &roms)
        );
    }
    // s = 0 (h = n) gives exactly 1, s >= 1 gives 0.
    assert_eq!(pf_to_f64(aniso_power(0, 12345 << 16, &roms)), 1.0);
    assert_eq!(pf_to_f64(aniso_power(1 << sb, 1 << 16, &roms)), 0.0);
    assert_eq!(pf_to_f64(aniso_power(u64::MAX, 1 << 16, &roms)), 0.0);
}

/// Exhaustive over every `(s, E)` of small configurations (`2^(2D) - 1` values of `s`,
/// `2^(exponent_max_bits + r)` of `E`): the coarse 4-bit ROMs and 12-bit mantissas, in every
/// rounding mode, are within the same derived bound.
#[test]
fn small_configs_exhaustive() {
    for (d, emb, r, b, f, rnd) in [
        (6u32, 8u32, 4u32, 4u32, 12u32, Rounding::HalfEven),
        (6, 6, 4, 3, 10, Rounding::Truncate),
        (6, 6, 4, 6, 8, Rounding::HalfUp),
    ] {
        let cfg = AnisoPhongConfig {
            aniso_dot_frac_bits: d,
            exponent_max_bits: emb,
            aniso_ratio_bits: r,
            aniso_pow_lut_bits: b,
            aniso_pow_frac_bits: f,
            aniso_rounding: rnd,
            ..AnisoPhongConfig::texram16()
        };
        assert!(cfg.validate().is_ok(), "{cfg:?}");
        let roms = AnisoPhongRoms::new(&cfg);
        let scale = 2f64.powi(r as i32);
        let w = (1u64..1 << (2 * d))
            .into_par_iter()
            .map(|s_raw| {
                (0..1u64 << (emb + r)).fold(Worst::default(), |w, e_raw| {
                    w.merge(check(&roms, s_raw, e_raw, e_raw as f64 / scale, 0.0))
                })
            })
            .reduce(Worst::default, Worst::merge);
        println!("D {d} emb {emb} r {r} lut {b} frac {f} {rnd:?}: {w:?}");
        assert_eq!(w.cases, ((1 << (2 * d)) - 1) << (emb + r));
        assert!(w.ratio > 0.05, "{w:?}");
    }
}

/// `aniso_ratio_bits` matters as declared: with 4 fraction bits the divider's rounding of `E`
/// alone exceeds what the bound allows without its `L 2^-(r+2)` term, and stays within the bound
/// with it.
#[test]
fn ratio_bits_term_is_needed_and_sufficient() {
    let cfg = AnisoPhongConfig {
        aniso_ratio_bits: 4,
        ..AnisoPhongConfig::texram16()
    };
    let roms = AnisoPhongRoms::new(&cfg);
    let sb = 2 * cfg.aniso_dot_frac_bits;
    let scale = 2f64.powi(4);
    let mut r = texsim::brdf::SplitMix64(77);
    let mut beyond = 0u64;
    for _ in 0..1 << 20 {
        let s_raw = random_s(&mut r, sb);
        let s = s_raw as f64 / 2f64.powi(sb as i32);
        let e = random_e(&mut r, s, 1e5);
        let e_raw = (e * scale).round() as u64;
        let _ = check(&roms, s_raw, e_raw, e, 0.5 / scale);
        let p = pf_to_f64(aniso_power(s_raw, e_raw, &roms));
        let (l, x) = exact_lx(s, e);
        if p > 0.0 && (p / (-x).exp2() - 1.0).abs() > power_rel_bound(&cfg, x, l, 0.0) {
            beyond += 1;
        }
    }
    println!("ratio bits 4: {beyond} of 2^20 cases need the L 2^-(r+2) term");
    assert!(beyond > 1000, "{beyond}");
}
