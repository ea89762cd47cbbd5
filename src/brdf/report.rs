//! Text reports behind `texsim brdf` for the Ashikhmin-Shirley BRDF (albedo eq. 6, evaluation
//! eqs. 16-18, sampler eqs. 19-22). Every report validates its inputs and names the bad one.

// `!(x > 0.0)` is used on purpose: it is true for NaN, which must take the guarded path.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::ashikhmin_shirley::{dir_from_angles, AshikhminShirley, Dots, SplitMix64};
use super::fixed_twin::{albedo_fixed, check_params, eval_fixed_parts};
use super::stats::{anisotropy_ratio, chi2_h, chi2_k2, Chi2Result, K2_MAX_ANISOTROPY};
use crate::error::{Error, Result};
use glam::DVec3;
use hw_model::aniso_phong::AnisoPhongConfig;
use hw_model::SatCounter;
use std::fmt::Write;

/// Quadrature resolution used by the reports (accuracy: see `albedo_quadrature_parts`).
pub const REPORT_RES: usize = 32;
/// Largest sample count `sample_report` accepts.
pub const MAX_SAMPLES: usize = 100_000_000;

fn check_model(p: &AshikhminShirley) -> Result<()> {
    AshikhminShirley::new(p.nu, p.nv, p.rs, p.rd).map(|_| ())
}

fn check_dir(name: &str, k: DVec3) -> Result<DVec3> {
    let len = k.length();
    if !k.is_finite() || !(len > 1.0e-12) {
        return Err(Error::field(
            name,
            format!("{k} is not a non-zero finite direction"),
        ));
    }
    Ok(k / len)
}

/// Directional albedo for `k1` at polar angle `theta_deg` in `[0, 90)` and azimuth 0 (along
/// `u`): quadrature parts, the diffuse closed form, a Monte Carlo check and, with `fixed`, the
/// fixed unit's albedo by the same quadrature. The LAST line is the albedo alone (the fixed
/// unit's when `fixed` is given, else the float model's).
pub fn albedo_report(
    p: &AshikhminShirley,
    theta_deg: f64,
    fixed: Option<&AnisoPhongConfig>,
) -> Result<String> {
    check_model(p)?;
    if !(0.0..90.0).contains(&theta_deg) {
        return Err(Error::field(
            "theta",
            format!("{theta_deg} is not in [0, 90) degrees"),
        ));
    }
    let k1 = dir_from_angles(theta_deg, 0.0);
    let (total, spec, diff) = p.albedo_quadrature_parts(k1, REPORT_RES);
    let closed = p.rd * (1.0 - p.rs) * (1.0 - (1.0 - 0.5 * k1.z).powi(5));
    let mc = p.albedo_mc(k1, 1 << 16, 1);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "ashikhmin-shirley nu={} nv={} rs={} rd={}",
        p.nu, p.nv, p.rs, p.rd
    );
    let _ = writeln!(s, "k1: theta={theta_deg} deg, phi=0 (along u)");
    let _ = writeln!(
        s,
        "quadrature (res {REPORT_RES}): specular {spec:.6} diffuse {diff:.6} total {total:.6}"
    );
    let _ = writeln!(
        s,
        "diffuse closed form Rd(1-Rs)(1-(1-cos/2)^5): {closed:.6}"
    );
    let _ = writeln!(
        s,
        "monte carlo (65536 samples): {:.6} +- {:.6}",
        mc.albedo, mc.std_error
    );
    let mut last = total;
    if let Some(cfg) = fixed {
        let mut sat = SatCounter::default();
        let (ft, fs, fd) = albedo_fixed(p, k1, REPORT_RES, cfg, &mut sat)?;
        let _ = writeln!(s, "fixed unit: specular {fs:.6} diffuse {fd:.6} total {ft:.6} (float - fixed {:.2e}, saturated {})", total - ft, sat.saturated);
        last = ft;
    }
    let _ = write!(s, "{last:.6}");
    Ok(s)
}

/// The BRDF at one direction pair (local frame, `n = z`; inputs are normalized): dot products,
/// exponent, Fresnel, parts and the sampling density; with `fixed`, also the fixed unit's parts
/// for the same directions (its dot products rounded to the unit's inputs). The last line is
/// `rho(k1, k2)`: the fixed unit's when `fixed` is given, else the float model's.
pub fn eval_report(
    p: &AshikhminShirley,
    k1: DVec3,
    k2: DVec3,
    fixed: Option<&AnisoPhongConfig>,
) -> Result<String> {
    check_model(p)?;
    if let Some(cfg) = fixed {
        check_params(p, cfg)?;
    }
    let k1 = check_dir("k1", k1)?;
    let k2 = check_dir("k2", k2)?;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "ashikhmin-shirley nu={} nv={} rs={} rd={}",
        p.nu, p.nv, p.rs, p.rd
    );
    let _ = writeln!(s, "k1 = {k1}, k2 = {k2}");
    match Dots::from_dirs(k1, k2) {
        Some(d) => {
            let _ = writeln!(
                s,
                "h.n={:.6} h.u={:.6} h.v={:.6} k.h={:.6} n.k1={:.6} n.k2={:.6}",
                d.hn, d.hu, d.hv, d.kh, d.nk1, d.nk2
            );
            let _ = writeln!(
                s,
                "exponent {:.6}  fresnel {:.6}",
                p.exponent(d.hu, d.hv),
                p.fresnel_schlick(d.kh)
            );
        }
        None => {
            let _ = writeln!(
                s,
                "no reflection: a direction is at or below the horizon, or k1 = -k2"
            );
        }
    }
    let (sp, df) = (p.specular(k1, k2), p.diffuse(k1, k2));
    let _ = writeln!(
        s,
        "specular {sp:.6e}  diffuse {df:.6e}  pdf(k2|k1) {:.6e}",
        p.pdf(k1, k2)
    );
    let mut last = sp + df;
    if let Some(cfg) = fixed {
        let mut sat = SatCounter::default();
        let (fs, fd) = eval_fixed_parts(p, k1, k2, cfg, &mut sat);
        let _ = writeln!(
            s,
            "fixed unit: specular {fs:.6e}  diffuse {fd:.6e}  (float - fixed {:.2e}, saturated {})",
            last - (fs + fd),
            sat.saturated
        );
        last = fs + fd;
    }
    let _ = write!(s, "{last:.6e}");
    Ok(s)
}

/// One line of a chi-square result.
fn chi2_line(what: &str, c: &Chi2Result) -> String {
    format!(
        "{what} chi-square {:.2} dof {} critical95 {:.2} critical99.9 {:.2} (bins hold {:.6} of the pdf, {} lost): {}",
        c.statistic,
        c.dof,
        c.critical_95,
        c.critical_999,
        c.total_probability,
        c.lost,
        if c.passed { "pass" } else { "FAIL" }
    )
}

/// Sampler statistics for `k1`: valid fraction, mean density of valid samples, the MC albedo,
/// the chi-square test of the half vectors (valid at any anisotropy) and, when the anisotropy
/// ratio is within [`K2_MAX_ANISOTROPY`], of the reflected directions (otherwise a line says it
/// was skipped and why). The last line is the verdict of the tests that ran.
pub fn sample_report(p: &AshikhminShirley, k1: DVec3, samples: usize, seed: u64) -> Result<String> {
    check_model(p)?;
    let k1 = check_dir("k1", k1)?;
    if !(k1.z > 0.0) {
        return Err(Error::field("k1", "must point above the surface (z > 0)"));
    }
    if !(100..=MAX_SAMPLES).contains(&samples) {
        return Err(Error::field(
            "samples",
            format!("{samples} is not in 100..={MAX_SAMPLES}"),
        ));
    }
    let mut rng = SplitMix64(seed);
    let (mut valid, mut pdf_sum) = (0usize, 0.0);
    for _ in 0..samples {
        if let Some((_, pdf)) = p.sample(k1, [rng.next_f64(), rng.next_f64()]) {
            valid += 1;
            pdf_sum += pdf;
        }
    }
    let mc = p.albedo_mc(k1, samples, seed ^ 0x5DEE_CE66);
    let chi_h = chi2_h(p, samples, seed ^ 0x3C3C_3C3C);
    let ratio = anisotropy_ratio(p);
    let chi_k2 = (ratio <= K2_MAX_ANISOTROPY).then(|| chi2_k2(p, k1, samples, seed ^ 0xA5A5_A5A5));
    let mut s = String::new();
    let _ = writeln!(
        s,
        "ashikhmin-shirley nu={} nv={} rs={} rd={}",
        p.nu, p.nv, p.rs, p.rd
    );
    let _ = writeln!(s, "k1 = {k1}, samples {samples}, seed {seed}");
    let _ = writeln!(
        s,
        "valid (above horizon) fraction {:.6}",
        valid as f64 / samples as f64
    );
    let _ = writeln!(
        s,
        "mean pdf of valid samples {:.6e}",
        if valid > 0 {
            pdf_sum / valid as f64
        } else {
            0.0
        }
    );
    let _ = writeln!(s, "mc albedo {:.6} +- {:.6}", mc.albedo, mc.std_error);
    let _ = writeln!(
        s,
        "{}",
        chi2_line("half-vector (eqs. 21-22 vs eq. 5)", &chi_h)
    );
    match &chi_k2 {
        Some(c) => {
            let _ = writeln!(
                s,
                "{}",
                chi2_line("reflected-direction (eq. 19 vs eq. 20)", c)
            );
        }
        None => {
            let _ = writeln!(
                s,
                "reflected-direction chi-square skipped: anisotropy ratio {ratio:.1} > {K2_MAX_ANISOTROPY} is beyond its binning (the half-vector test holds at any anisotropy)"
            );
        }
    }
    let passed = chi_h.passed && chi_k2.iter().all(|c| c.passed);
    let _ = write!(
        s,
        "chi-square ({} at the 99.9% level): {}",
        if chi_k2.is_some() {
            "half-vector and reflected-direction"
        } else {
            "half-vector"
        },
        if passed { "pass" } else { "FAIL" }
    );
    Ok(s)
}
