//! Float <-> fixed bridge for `hw_model::aniso_phong` (Ashikhmin-Shirley eqs. 11, 16, 18):
//! quantizes dot products and material parameters into the unit's declared formats, runs the
//! unit, and gives the float twin (the f64 reference evaluated from the SAME quantized values).

use super::ashikhmin_shirley::{AshikhminShirley, Dots};
use crate::error::{Error, Result};
use glam::DVec3;
use hw_model::aniso_phong::{
    aniso_phong, AnisoPhongConfig, AnisoPhongInputs, AnisoPhongOut, PseudoFloat,
};
use hw_model::{Rounding, SatCounter};
use std::f64::consts::PI;

/// Value of a pseudo-float.
#[must_use]
pub fn pf_to_f64(x: PseudoFloat) -> f64 {
    x.mant as f64 * 2f64.powi(x.exp)
}

/// Rounds `x` to a raw with `frac` fraction bits (nearest, ties away), clamped to `[-lim, lim]`.
#[must_use]
fn to_raw(x: f64, frac: u32, lim: i64) -> i64 {
    let v = (x * (1u64 << frac) as f64).round();
    if v.is_nan() {
        return 0;
    }
    (v.clamp(-(lim as f64), lim as f64)) as i64
}

/// Checks the model's parameters against the unit's formats (exponents must be integers below
/// `2^exponent_max_bits`); the error names the field.
pub fn check_params(p: &AshikhminShirley, cfg: &AnisoPhongConfig) -> Result<()> {
    cfg.validate().map_err(Error::from)?;
    let emax = ((1u64 << cfg.exponent_max_bits) - 1) as f64;
    for (name, v) in [("nu", p.nu), ("nv", p.nv)] {
        if !(v >= 0.0 && v <= emax && v.fract() == 0.0) {
            return Err(Error::field(
                name,
                format!("{v} is not an integer in 0..={emax} (exponent_max_bits)"),
            ));
        }
    }
    for (name, v) in [("rs", p.rs), ("rd", p.rd)] {
        if !(0.0..=1.0).contains(&v) {
            return Err(Error::field(name, format!("{v} is not in [0, 1]")));
        }
    }
    Ok(())
}

/// Quantized unit inputs for a parameter set and dot products (call [`check_params`] first for
/// error reporting; out-of-range values are clamped here).
#[must_use]
pub fn quantize(p: &AshikhminShirley, d: &Dots, cfg: &AnisoPhongConfig) -> AnisoPhongInputs {
    let df = cfg.aniso_dot_frac_bits;
    let one = 1i64 << df;
    let q = |x: f64| to_raw(x, df, one) as i32;
    let fone = 1i64 << cfg.fresnel_bits;
    let emax = ((1u64 << cfg.exponent_max_bits) - 1) as f64;
    AnisoPhongInputs {
        hn: q(d.hn),
        hu: q(d.hu),
        hv: q(d.hv),
        kh: q(d.kh),
        nk1: q(d.nk1),
        nk2: q(d.nk2),
        nu: p.nu.round().clamp(0.0, emax) as u32,
        nv: p.nv.round().clamp(0.0, emax) as u32,
        rs: to_raw(p.rs, cfg.fresnel_bits, fone) as u32,
        rd: to_raw(p.rd, cfg.fresnel_bits, fone) as u32,
    }
}

/// The float twin's inputs: the parameters and dot products exactly as the unit sees them.
#[must_use]
pub fn dequantize(inp: &AnisoPhongInputs, cfg: &AnisoPhongConfig) -> (AshikhminShirley, Dots) {
    let s = 1.0 / (1u64 << cfg.aniso_dot_frac_bits) as f64;
    let f = 1.0 / (1u64 << cfg.fresnel_bits) as f64;
    let p = AshikhminShirley {
        nu: f64::from(inp.nu),
        nv: f64::from(inp.nv),
        rs: f64::from(inp.rs) * f,
        rd: f64::from(inp.rd) * f,
    };
    let d = Dots {
        hn: f64::from(inp.hn) * s,
        hu: f64::from(inp.hu) * s,
        hv: f64::from(inp.hv) * s,
        kh: f64::from(inp.kh) * s,
        nk1: f64::from(inp.nk1) * s,
        nk2: f64::from(inp.nk2) * s,
    };
    (p, d)
}

/// Float twin of the unit output: `pi * (specular, diffuse)` from the quantized inputs.
#[must_use]
pub fn twin_pi_rho(inp: &AnisoPhongInputs, cfg: &AnisoPhongConfig) -> (f64, f64) {
    let (p, d) = dequantize(inp, cfg);
    let (s, df) = p.eval_from_dots(&d);
    (PI * s, PI * df)
}

/// The fixed unit's BRDF parts `(rho_s, rho_d)` (not times pi) for a direction pair; zeros
/// below the horizon or for `k1 = -k2`.
#[must_use]
pub fn eval_fixed_parts(
    p: &AshikhminShirley,
    k1: DVec3,
    k2: DVec3,
    cfg: &AnisoPhongConfig,
    sat: &mut SatCounter,
) -> (f64, f64) {
    match Dots::from_dirs(k1, k2) {
        Some(d) => {
            let out: AnisoPhongOut = aniso_phong(&quantize(p, &d, cfg), cfg, sat);
            (pf_to_f64(out.spec) / PI, pf_to_f64(out.diffuse) / PI)
        }
        None => (0.0, 0.0),
    }
}

/// The fixed unit's total BRDF `rho(k1, k2)` (rounded sum of its parts, not times pi).
#[must_use]
pub fn eval_fixed(
    p: &AshikhminShirley,
    k1: DVec3,
    k2: DVec3,
    cfg: &AnisoPhongConfig,
    sat: &mut SatCounter,
) -> f64 {
    match Dots::from_dirs(k1, k2) {
        Some(d) => pf_to_f64(aniso_phong(&quantize(p, &d, cfg), cfg, sat).total) / PI,
        None => 0.0,
    }
}

/// Directional albedo `(total, specular, diffuse)` of the fixed unit by the quadrature of
/// [`AshikhminShirley::albedo_quadrature_with`].
pub fn albedo_fixed(
    p: &AshikhminShirley,
    k1: DVec3,
    res: usize,
    cfg: &AnisoPhongConfig,
    sat: &mut SatCounter,
) -> Result<(f64, f64, f64)> {
    check_params(p, cfg)?;
    let mut sat_d = SatCounter::default();
    let (s, d) = p.albedo_quadrature_with(
        k1,
        res,
        &mut |k2| eval_fixed_parts(p, k1, k2, cfg, sat).0,
        &mut |k2| eval_fixed_parts(p, k1, k2, cfg, &mut sat_d).1,
    );
    sat.add(&sat_d);
    Ok((s + d, s, d))
}

/// Terms of the declared error bound of the power stage `hw_model::aniso_phong::aniso_power`
/// (its doc derives them) at `X = E L / 2`, `L = -log2(1 - s)`, when the `E` the stage is fed
/// is within `e_err` of the exact one (0 for an exact `aniso_ratio_bits` value, `2^-(r+1)`
/// after the exponent divider): `(dX, dE)`, the bound on `|X_fixed - X|` and the relative error
/// of the exp2 step.
#[must_use]
pub fn power_error_terms(cfg: &AnisoPhongConfig, x: f64, l: f64, e_err: f64) -> (f64, f64) {
    let u = if cfg.aniso_rounding == Rounding::Truncate {
        1.0
    } else {
        0.5
    };
    let f = 2f64.powi(-(cfg.aniso_pow_frac_bits as i32));
    let h2 = 2f64.powi(-2 * cfg.aniso_pow_lut_bits as i32 - 3);
    let eps = 2.0 * u * f + 2f64.powi(-40);
    let ln2 = std::f64::consts::LN_2;
    let dl = eps + h2 / ln2;
    let dx = x * dl + u * f + 0.5 * l * (1.0 + dl) * e_err;
    let de = 2.0 * (eps + ln2 * ln2 * h2);
    (dx, de)
}

/// The declared relative error bound `2^dX (1 + dE) - 1` of `aniso_power` at `X`, `L` and
/// `e_err` (see [`power_error_terms`]); it holds for every non-zero output.
#[must_use]
pub fn power_rel_bound(cfg: &AnisoPhongConfig, x: f64, l: f64, e_err: f64) -> f64 {
    let (dx, de) = power_error_terms(cfg, x, l, e_err);
    2f64.powf(dx) * (1.0 + de) - 1.0
}
