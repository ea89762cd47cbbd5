//! NDF shading unit (`hw_model::ndf`) against its float twin (`texsim::shading::ndf`):
//! 1M+ random texels and halfway vectors, the Pearson II limit, the hard cases, the cost.

use crate::ndf_common::{random_moments, texels, unit, Rng};
use glam::DVec3;
use hw_model::fixed::SatCounter;
use hw_model::ndf::{ndf_cost, ndf_lookups, NdfConfig, NdfDensity, NdfNorm, NdfTexels, D_MAX_RAW};
use hw_model::rsqrt::RsqrtConfig;
use hw_model::HwConfig;
use texsim::shading::ndf::{
    decode_texels, density, eval_float, h_from_fixed, h_to_fixed, raw_to_f64, Moments,
};

fn cfg(norm: NdfNorm, dens: NdfDensity) -> NdfConfig {
    NdfConfig {
        ndf_norm: norm,
        ndf_density: dens,
        ..NdfConfig::texram16()
    }
}

/// Worst errors of one configuration over `n` random cases.
#[derive(Default, Debug)]
struct Worst {
    d_rel: f64,
    g_abs_lsb: f64,
    g_unit_lsb: f64,
    g_excess_lsb: f64,
    val_rel: f64,
    branch_mismatch: u64,
    cases: u64,
}

fn run(c: &NdfConfig, n: u64, seed: u64) -> Worst {
    let u = unit(c);
    let f = c.ndf_frac_bits;
    let lsb = (-f64::from(f)).exp2();
    let mut r = Rng(seed);
    let mut w = Worst::default();
    for _ in 0..n {
        let m = random_moments(&mut r);
        let inv_z = r.unit() * 64.0;
        let t = texels(&m, c, inv_z, 6);
        let dm = decode_texels(&t, c);
        let spread = (m.covariance()[0] + m.covariance()[1] + m.covariance()[2])
            .max(0.0)
            .sqrt();
        let dir = m.mu.normalize();
        let hv = (dir + DVec3::new(r.normal(), r.normal(), r.normal()) * spread * 1.5).normalize();
        let hf = h_to_fixed(hv);
        let h = h_from_fixed(&hf);
        let mut sat = SatCounter::default();
        let out = u.eval(&t, &hf, &mut sat);
        let inv_z_dec = f64::from(t.norm[0]) / f64::from((1u32 << c.moment_bits) - 1) * 64.0;
        let fl = eval_float(&dm, h, inv_z_dec, c);
        assert!(out.d_value >= 0 && out.d_value <= D_MAX_RAW);
        assert!(fl.d_value.is_finite() && fl.g.is_finite() && fl.dist.is_finite());
        w.cases += 1;
        // Regularization branch decided differently (quantization at the PD boundary).
        if out.fallback != fl.fallback {
            w.branch_mismatch += 1;
            continue;
        }
        let dist = raw_to_f64(out.dist, f);
        let dmax = 128.0 - lsb;
        if fl.dist < dmax * 0.99 && fl.dist > 1e-3 {
            w.d_rel = w.d_rel.max((dist - fl.dist).abs() / fl.dist);
        }
        let g = raw_to_f64(out.g, f);
        w.g_abs_lsb = w.g_abs_lsb.max((g - fl.g).abs() / lsb);
        if h.z > 0.0 && out.dist > 0 {
            w.g_unit_lsb = w.g_unit_lsb.max((g - density(dist, c)).abs() / lsb);
        }
        // |g'| <= 1/2 for both densities: the d error explains g's error beyond the unit's own.
        w.g_excess_lsb = w
            .g_excess_lsb
            .max(((g - fl.g).abs() - 0.5 * (dist - fl.dist).abs()) / lsb);
        let v = raw_to_f64(out.d_value, f);
        if fl.g > 1e-3 {
            // Error relative to the texel's peak value D / g (the value at g = 1).
            let peak = fl.d_value / fl.g;
            w.val_rel = w.val_rel.max((v - fl.d_value).abs() / peak);
        }
    }
    w
}

/// 1.02M random cases over every fixed option and both densities (texram16 widths), on
/// mixtures of up to four lobes of shininess up to 2^12 (condition numbers of Sigma up to ~2^13).
/// Bounds (F = 24, ndf_inverse_bits = 24): relative error of d <= 1e-4 (the adjugate rounded to
/// 24 significant bits errs by up to cond(Sigma) 2^-24 relative; measured 4.8e-5); the density
/// unit's own error <= 8 LSB of 2^-F (Pearson m = 8: one rounding per squaring, doubled by each
/// later squaring; Gauss: table and lerp, measured 1.5); g's error beyond `|g'| |d error|`
/// (|g'| <= 1/2) <= 8 LSB; D within 5e-5 of the texel's peak value `D/g` where g > 1e-3 (rsqrt
/// 5.7e-6 relative plus g). Regularization branch mismatches below 1 in 10^4.
#[test]
fn fixed_matches_float_1m() {
    let mut total = 0;
    for (i, (norm, dens)) in [
        (NdfNorm::Partial, NdfDensity::Pearson),
        (NdfNorm::Partial, NdfDensity::Gauss),
        (NdfNorm::Map, NdfDensity::Pearson),
        (NdfNorm::Map, NdfDensity::Gauss),
        (NdfNorm::Projected, NdfDensity::Pearson),
        (NdfNorm::Projected, NdfDensity::Gauss),
    ]
    .into_iter()
    .enumerate()
    {
        let c = cfg(norm, dens);
        let w = run(&c, 170_000, 0x5EED + i as u64);
        println!("{norm:?} {dens:?}: {w:?}");
        total += w.cases;
        assert!(w.d_rel <= 1e-4, "{norm:?} {dens:?} d {w:?}");
        assert!(w.g_unit_lsb <= 8.0, "{norm:?} {dens:?} g {w:?}");
        assert!(w.g_excess_lsb <= 8.0, "{norm:?} {dens:?} g {w:?}");
        assert!(w.val_rel <= 5e-5, "{norm:?} {dens:?} D {w:?}");
        assert!(w.branch_mismatch * 10_000 <= w.cases, "{w:?}");
    }
    assert!(total >= 1_000_000);
}

/// Narrower widths (10-bit moments, 16-bit adjugate, F = 16, 64-entry exp table): the density
/// unit stays within 8 LSB, D within 5% of the peak; d itself can err by cond(Sigma) 2^-16
/// (measured 0.33 relative on the shiniest mixtures, where g is then ~0).
#[test]
fn narrow_widths_track_float() {
    let c = NdfConfig {
        moment_bits: 10,
        ndf_inverse_bits: 16,
        ndf_frac_bits: 16,
        ndf_exp_lut_bits: 6,
        ..NdfConfig::texram16()
    };
    let w = run(&c, 50_000, 77);
    println!("narrow: {w:?}");
    assert!(w.g_unit_lsb <= 8.0, "{w:?}");
    assert!(w.g_excess_lsb <= 8.0, "{w:?}");
    assert!(w.val_rel <= 5e-2, "{w:?}");
}

/// `(1 - t/(2m))^m` tends to `exp(-t/2)`; the seed's printed `(1 - t/2^m)^m` does not.
#[test]
fn pearson_limit_is_two_m_not_two_to_the_m() {
    let mut prev = f64::INFINITY;
    for m in [2u32, 4, 8, 16, 64] {
        let c = NdfConfig {
            pearson_m: m,
            ..NdfConfig::texram16()
        };
        let worst = (0..=200)
            .map(|i| f64::from(i) * 0.05)
            .map(|t| (density(t, &c) - (-0.5 * t).exp()).abs())
            .fold(0.0, f64::max);
        println!("m = {m}: max |g - exp(-t/2)| on [0, 10] = {worst:.5}");
        assert!(worst < prev);
        prev = worst;
    }
    assert!(prev < 0.01);
    // The printed form with m = 8 at t = 8: (1 - 8/256)^8 = 0.776 vs exp(-4) = 0.018.
    let printed = (1.0f64 - 8.0 / 256.0).powi(8);
    let c = NdfConfig::texram16();
    assert!((density(8.0, &c) - (-4.0f64).exp()).abs() < 0.02);
    assert!((printed - (-4.0f64).exp()).abs() > 0.5);
    // The printed form behaves like exp(-t m / 2^m) (exp(-t/32) for m = 8), not like
    // exp(-t m / 2^(m+1)): over t in [0, 2^m) it stays within 0.1 of the former (measured
    // 0.074 for m = 4, 0.035 for m = 8) and is more than 0.2 off the latter.
    for m in [4i32, 8] {
        let den = f64::from(1u32 << m);
        let (mut near, mut half) = (0.0f64, 0.0f64);
        for i in 0..1000 {
            let t = f64::from(i) / 1000.0 * den;
            let p = (1.0 - t / den).powi(m);
            near = near.max((p - (-t * f64::from(m) / den).exp()).abs());
            half = half.max((p - (-t * f64::from(m) / (2.0 * den)).exp()).abs());
        }
        println!(
            "m = {m}: printed form vs exp(-t m/2^m) {near:.4}, vs exp(-t m/2^(m+1)) {half:.4}"
        );
        assert!(
            near < 0.1 && half > 0.2 && near < half / 3.0,
            "m = {m}: {near} {half}"
        );
    }
}

fn finite_checks(t: &NdfTexels, h: DVec3, c: &NdfConfig) -> (i64, SatCounter) {
    let u = unit(c);
    let mut sat = SatCounter::default();
    let out = u.eval(t, &h_to_fixed(h), &mut sat);
    assert!(out.d_value >= 0 && out.d_value <= D_MAX_RAW, "{out:?}");
    assert!(out.g >= 0 && out.g <= 1i64 << c.ndf_frac_bits, "{out:?}");
    assert!(out.dist >= 0);
    let fl = eval_float(&decode_texels(t, c), h, 1.0, c);
    assert!(fl.d_value.is_finite() && fl.d_value >= 0.0, "{fl:?}");
    (out.d_value, sat)
}

fn all_cfgs() -> Vec<NdfConfig> {
    let mut v = Vec::new();
    for norm in [NdfNorm::Partial, NdfNorm::Map, NdfNorm::Projected] {
        for dens in [NdfDensity::Pearson, NdfDensity::Gauss] {
            for bits in [8, 16] {
                v.push(NdfConfig {
                    moment_bits: bits,
                    ..cfg(norm, dens)
                });
            }
        }
    }
    v
}

/// The default minimum variance `2^(3-B)` covers the quantization noise of `Sigma`'s diagonal:
/// over 200k random mixtures per width, the unit's diagonal from stored (rounded) moments errs
/// by at most half the budget `(2^k + 4) 2^-B / 2` (storage rounding; the filter's output
/// rounding takes the other half), and the budget is at most the floor.
#[test]
fn min_variance_floor_covers_quantization_noise() {
    let mut r = Rng(0xF100);
    for bits in [8u32, 12, 16] {
        for k in [0u32, 1, 2] {
            let c = NdfConfig {
                moment_bits: bits,
                moment_scale_bits: k,
                ..NdfConfig::texram16()
            };
            let u = unit(&c);
            let lsb = (-f64::from(bits)).exp2();
            let budget = f64::from((1u32 << k) + 4) * lsb;
            assert!(budget <= (-f64::from(c.min_variance_bits())).exp2());
            let mut worst = 0.0f64;
            for _ in 0..200_000 {
                let m = random_moments(&mut r);
                let enc = texsim::shading::ndf::encode_texel(&m, k);
                if enc.iter().flatten().any(|v| !(0.0..=1.0).contains(v)) {
                    continue; // clamped by the encoding (k = 0, low shininess): counted there
                }
                let (mu, e) = u.decode(&texels(&m, &c, 0.0, 0));
                let sig = u.covariance(&mu, &e);
                let want = m.covariance();
                for i in 0..3 {
                    worst = worst.max((raw_to_f64(sig[i], 32) - want[i]).abs());
                }
            }
            println!(
                "B = {bits}, k = {k}: worst diagonal error {:.3} LSB, half budget {:.1}",
                worst / lsb,
                budget / lsb / 2.0
            );
            assert!(worst <= budget / 2.0, "B = {bits} k = {k}: {worst}");
        }
    }
}

/// Half-width (angle) of the true base lobe of shininess `s`: `g(d) = 1/2` with
/// `d = |h - n|^2 s = 2 (1 - cos theta) s`.
fn true_half_width(s: f64, c: &NdfConfig) -> f64 {
    let d_half = match c.ndf_density {
        NdfDensity::Gauss => 2.0 * std::f64::consts::LN_2,
        NdfDensity::Pearson => {
            let m = f64::from(c.pearson_m);
            2.0 * m * (1.0 - 0.5f64.powf(1.0 / m))
        }
    };
    (1.0 - d_half / (2.0 * s)).acos()
}

/// Singular Sigma (all normals equal, extreme shininess): the quantized covariance is zero or
/// indefinite. GRACEFUL DEGRADATION: the unit clamps each diagonal to the minimum variance
/// `2^-(B-3)` (counted), stays finite, peaks at the mean with a peak no higher than that of a
/// lobe at the floor (x1.5), and beyond the width's breaking point (table [`BREAKS`]) the lobe
/// is at least as wide as the true one (at the true half-width the fixed `D` is still above
/// half its peak, along two tangent directions): broader, not sharper.
#[test]
fn hard_singular_and_shiny() {
    for c in all_cfgs() {
        let v = c.min_variance_bits();
        assert_eq!(v, c.moment_bits - 3);
        let brk = BREAKS
            .iter()
            .find(|b| b.0 == c.moment_bits)
            .map(|b| b.1)
            .expect("breaking point of the width");
        let n = DVec3::new(0.3, -0.2, 0.93).normalize();
        let t1 = n.any_orthonormal_vector();
        let t2 = n.cross(t1);
        // The peak of a single lobe at the floor (float twin, exact moments, no clamp).
        let floor = Moments::from_normal(n, f64::from(v).exp2());
        let floor_peak = eval_float(&floor, n, 1.0, &c).d_value;
        let f = c.ndf_frac_bits;
        for s in [1e3, 1e5, 1e9] {
            let m = Moments::from_normal(n, s);
            let t = texels(&m, &c, 1.0, 0);
            let (peak, sat) = finite_checks(&t, n, &c);
            let (off, _) = finite_checks(&t, DVec3::new(-0.3, 0.2, 0.93).normalize(), &c);
            let pk = raw_to_f64(peak, f);
            assert!(
                peak > 0 && peak >= off,
                "{c:?} s={s}: peak {peak} off {off}"
            );
            assert!(
                pk <= 1.5 * floor_peak,
                "{c:?} s={s}: peak {pk} > 1.5 x {floor_peak}"
            );
            if s > f64::from(v).exp2() {
                assert!(
                    sat.saturated >= 1,
                    "{c:?} s={s}: variance clamps not counted"
                );
            }
            if s > brk {
                let th = true_half_width(s, &c);
                for dir in [t1, t2] {
                    let h = n * th.cos() + dir * th.sin();
                    let (at, _) = finite_checks(&t, h, &c);
                    assert!(
                        2 * at >= peak,
                        "{c:?} s={s}: sharper than the true lobe: D {at} at the true half-width, peak {peak}"
                    );
                }
            }
        }
    }
}

/// Grooves: two normal directions averaged (rank-deficient spread) and mu near 0 (opposite
/// normals), h at and below the horizon, d far outside the support, random garbage texels.
#[test]
fn hard_grooves_mu_zero_horizon_garbage() {
    let mut r = Rng(42);
    for c in all_cfgs() {
        let a = Moments::from_normal(DVec3::new(0.6, 0.0, 0.8), 1e6);
        let b = Moments::from_normal(DVec3::new(-0.6, 0.0, 0.8), 1e6);
        let mut g = a;
        g.mu = (a.mu + b.mu) * 0.5;
        for i in 0..6 {
            g.e[i] = 0.5 * (a.e[i] + b.e[i]);
        }
        let t = texels(&g, &c, 1.0, 0);
        finite_checks(&t, DVec3::Z, &c);
        finite_checks(&t, DVec3::new(0.6, 0.0, 0.8), &c);
        // mu = 0: x and -x normals (both hemispheres, a coarse level of a closed surface).
        let mut z = a;
        z.mu = DVec3::ZERO;
        z.e = [0.5, 0.5, 0.0, 0.0, 0.0, 0.0];
        let t0 = texels(&z, &c, 1.0, 0);
        finite_checks(&t0, DVec3::Z, &c);
        finite_checks(&t0, DVec3::new(1.0, 0.0, 1e-9).normalize(), &c);
        // Horizon: h_z = 0 and below give exactly 0.
        let (v0, _) = finite_checks(&t, DVec3::X, &c);
        let (v1, _) = finite_checks(&t, DVec3::new(0.0, 0.6, -0.8), &c);
        assert_eq!((v0, v1), (0, 0));
        // Far outside the support: h 82 degrees off a lobe of shininess 10^4 (whose variance
        // the 8-bit floor 2^-5 raises: d >= 31 there): Pearson (support d < 16) gives 0, the
        // Gaussian less than 10^-5 of the peak.
        let sharp = texels(&Moments::from_normal(DVec3::Z, 1e4), &c, 1.0, 0);
        let (far, _) = finite_checks(&sharp, DVec3::new(0.99, 0.0, 0.14).normalize(), &c);
        let (top, _) = finite_checks(&sharp, DVec3::Z, &c);
        match c.ndf_density {
            NdfDensity::Pearson => assert_eq!(far, 0, "{c:?}"),
            NdfDensity::Gauss => assert!(far as f64 * 1e5 < top as f64, "{c:?}: {far} {top}"),
        }
        for _ in 0..2000 {
            let q = || 0u16;
            let mut t = NdfTexels::default();
            let mask = ((1u32 << c.moment_bits) - 1) as u64;
            for ch in 0..3 {
                t.mean[ch] = (r.next() & mask) as u16;
                t.diag[ch] = (r.next() & mask) as u16;
                t.off[ch] = (r.next() & mask) as u16;
            }
            t.norm[0] = (r.next() & mask) as u16;
            t.norm[3] = q();
            t.norm_exp = (r.next() % 41) as u32;
            let h = r.tilted(1.5);
            finite_checks(&t, h, &c);
        }
    }
}

/// Garbage at the maximum widths (16-bit moments with scale 2^2, 30-bit adjugate, F = 28,
/// 30-bit reciprocal and rsqrt mantissas, m = 64, 4096-entry exp table): random texels
/// (non-normalized means, indefinite moments) and random halfway vectors, also far from unit
/// length, never overflow (this test runs with overflow checks in the test profile) and stay
/// in range, for every fixed option and both densities.
#[test]
fn garbage_at_max_widths_never_overflows() {
    let mut hw = HwConfig::texram16();
    hw.reciprocal.recip_mantissa_bits = 30;
    let rs = RsqrtConfig {
        rsqrt_mantissa_bits: 30,
        ..RsqrtConfig::texram16()
    };
    let mut r = Rng(0xBAD);
    for norm in [NdfNorm::Partial, NdfNorm::Map, NdfNorm::Projected] {
        for dens in [NdfDensity::Pearson, NdfDensity::Gauss] {
            let c = NdfConfig {
                moment_bits: 16,
                moment_scale_bits: 2,
                ndf_inverse_bits: 30,
                ndf_frac_bits: 28,
                ndf_exp_lut_bits: 12,
                pearson_m: 64,
                ndf_min_variance_bits: 30,
                ..cfg(norm, dens)
            };
            let u = hw_model::ndf::NdfUnit::new(&c, &hw.reciprocal, &rs).expect("max widths");
            let mut sat = SatCounter::default();
            for i in 0..100_000 {
                let mut t = NdfTexels::default();
                for ch in 0..3 {
                    t.mean[ch] = r.next() as u16;
                    t.diag[ch] = r.next() as u16;
                    t.off[ch] = r.next() as u16;
                }
                // Extremes: all-zero and all-one channels, mean at a corner of the cube.
                if i % 7 == 0 {
                    t.mean = [0, 0, 0, 0];
                    t.diag = [u16::MAX; 4];
                }
                if i % 11 == 0 {
                    t.off = [if i % 2 == 0 { 0 } else { u16::MAX }; 4];
                }
                t.norm[0] = r.next() as u16;
                t.norm_exp = (r.next() % 41) as u32;
                let h = if i % 5 == 0 {
                    [r.next() as i64, r.next() as i64, (r.next() >> 1) as i64]
                } else {
                    h_to_fixed(r.tilted(1.5))
                };
                let out = u.eval(&t, &h, &mut sat);
                assert!(out.d_value >= 0 && out.d_value <= D_MAX_RAW, "{out:?}");
                assert!(out.g >= 0 && out.g <= 1i64 << c.ndf_frac_bits, "{out:?}");
                assert!(
                    out.dist >= 0 && out.dist < 128i64 << c.ndf_frac_bits,
                    "{out:?}"
                );
            }
            assert!(sat.saturated > 0);
        }
    }
}

/// Saturation is counted when the regularization falls back.
#[test]
fn fallback_is_counted() {
    let c = NdfConfig::texram16();
    // E = 0 with mu = (1, 0, 0): Sigma = -mu mu^T is negative: clamps, then diagonal.
    let t = texels(
        &Moments {
            mu: DVec3::new(0.7, 0.0, 0.7),
            e: [0.0; 6],
        },
        &c,
        1.0,
        0,
    );
    let (_, sat) = finite_checks(&t, DVec3::Z, &c);
    assert!(sat.saturated >= 1);
}

#[test]
fn exact_is_rejected_by_fixed_unit() {
    let c = cfg(NdfNorm::Exact, NdfDensity::Pearson);
    let e = hw_model::ndf::NdfUnit::new(
        &c,
        &HwConfig::texram16().reciprocal,
        &RsqrtConfig::texram16(),
    )
    .expect_err("exact is float only");
    assert_eq!(e.field, "ndf.ndf_norm");
    let bad = NdfConfig {
        pearson_m: 0,
        ..NdfConfig::texram16()
    };
    assert_eq!(bad.validate().expect_err("m = 0").field, "ndf.pearson_m");
}

/// Lookups and cycles per option (the table in docs/NDF.md); `exact` has none (float only).
#[test]
fn cost_per_option() {
    let hw = HwConfig::texram16();
    let recip =
        hw_model::reciprocal::Reciprocal::new(&hw.reciprocal).cost(hw.timing.gate_levels_per_cycle);
    let rs = RsqrtConfig::texram16();
    println!("norm       density  lookups  texels  ops  cycles");
    let mut partial = 0;
    let mut projected = 0;
    for norm in [
        NdfNorm::Partial,
        NdfNorm::Map,
        NdfNorm::Projected,
        NdfNorm::Exact,
    ] {
        for dens in [NdfDensity::Pearson, NdfDensity::Gauss] {
            let c = cfg(norm, dens);
            let Some(k) = ndf_cost(&c, &recip, &rs, hw.timing.gate_levels_per_cycle) else {
                // `exact` is float only: no cost to report.
                assert_eq!(norm, NdfNorm::Exact);
                println!(
                    "{:<10} {:<8} {:>7} {:>7} {:>4} {:>7}",
                    "Exact",
                    format!("{dens:?}"),
                    "-",
                    "-",
                    "-",
                    "-"
                );
                continue;
            };
            assert_ne!(norm, NdfNorm::Exact);
            println!(
                "{:<10} {:<8} {:>7} {:>7} {:>4} {:>7}",
                format!("{norm:?}"),
                format!("{dens:?}"),
                ndf_lookups(&c),
                k.texels,
                k.ops,
                k.cycles
            );
            assert_eq!(k.texels, 8 * ndf_lookups(&c));
            if norm == NdfNorm::Partial && dens == NdfDensity::Pearson {
                partial = k.cycles;
            }
            if norm == NdfNorm::Projected && dens == NdfDensity::Pearson {
                projected = k.cycles;
            }
        }
    }
    assert!(projected > partial && partial > 0);
    assert_eq!(ndf_lookups(&cfg(NdfNorm::Map, NdfDensity::Gauss)), 4);
}

/// Exhaustive over every `d` the unit can produce at F = 16 (`[0, 2^23)` raw): the density unit
/// against `density` in f64, both densities, within 8 LSB (Pearson m = 8: the base rounded to
/// 1/2 LSB times the slope m = 8, plus the squarings) and 2 LSB (Gauss,
/// 1024-entry table).
#[test]
fn density_exhaustive_f16() {
    for (dens, bound) in [(NdfDensity::Pearson, 8.0), (NdfDensity::Gauss, 2.0)] {
        let c = NdfConfig {
            ndf_frac_bits: 16,
            ..cfg(NdfNorm::Partial, dens)
        };
        let u = unit(&c);
        let mut worst = 0.0f64;
        for raw in 0..(1i64 << (hw_model::ndf::DMAX_INT_BITS + 16)) {
            let g = u.density(raw);
            let want = density(raw_to_f64(raw, 16), &c) * 65536.0;
            worst = worst.max((g as f64 - want).abs());
        }
        println!("{dens:?}: worst {worst:.3} LSB of 2^-16 over 2^23 inputs");
        assert!(worst <= bound, "{dens:?} {worst}");
    }
}

/// Breaking points (`breaking_shininess`, threshold 10% of the peak) per moment width,
/// texram16 otherwise: the table in README.md and docs/NDF.md.
const BREAKS: [(u32, f64); 5] = [
    (8, 22.6),
    (10, 90.5),
    (12, 512.0),
    (14, 1722.2),
    (16, 5792.6),
];

/// The shininess at which each moment width breaks: the first `s` on the grid `2^(i/4)` where
/// a quantized base lobe errs by more than 10% of its peak, `h` at the peak and 0.5, 1 and 2
/// standard deviations `1/sqrt(s)` off it along two tangent directions, five tilted normals
/// (`lobe_error`). The measured grid points are pinned (each is `2^(i/4)`, printed to 0.1);
/// wider moments hold to higher shininess.
#[test]
fn shininess_breaking_point_per_moment_width() {
    let mut prev = 0.0;
    println!("moment_bits  breaks at shininess");
    for (bits, want) in BREAKS {
        let c = NdfConfig {
            moment_bits: bits,
            ..NdfConfig::texram16()
        };
        let s = texsim::shading::ndf::breaking_shininess(&unit(&c), 0.1).unwrap_or(f64::INFINITY);
        println!("{bits:>11}  {s:.1}");
        assert!(
            (s - want).abs() < 0.05,
            "{bits} bits: breaks at {s}, table {want}"
        );
        assert!(s > prev, "{bits}: {s} <= {prev}");
        prev = s;
    }
}
