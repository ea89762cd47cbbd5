//! LEAN mapping (Olano and Baker 2010, "LEAN Mapping", sec. 3-4): the bump slopes' first and
//! second moments, linearly filtered, give per pixel a 2D Gaussian of the slopes
//! `N(B, Sigma)`, `Sigma = M - B B^T + I/s` (the base roughness of a Blinn-Phong exponent `s`,
//! slope variance `1/s`), and the specular term is that Gaussian at the half vector's projected
//! slope `h~ = (h_u / h_n, h_v / h_n)` (the Beckmann-style lobe of eq. 5-6, without the
//! `1/h_n^4` Jacobian, as the paper's shader listing), normalized to peak 1 for a flat texel:
//!
//! `D = (1/s) / sqrt(det Sigma) exp(-(h~ - B)^T Sigma^-1 (h~ - B) / 2)`.
//!
//! The same maths as the Olano-North unit (`crate::ndf`), in 2D: where it differs, the moments
//! are of slopes (not of unit normals), `B` is the ordinary filtered offset map (`f_u, f_v`, the
//! texel normal being `normalize(f_u, f_v, 1)` as in the NDF maps), one map holds `M_uu, M_vv,
//! M_uv`, the base variance is added in the unit (so `Sigma >= I/s` in exact arithmetic, and a
//! flat map gives `Sigma = I/s` exactly), and the inverse is the exact 2x2 adjugate. The
//! density `exp(-d/2)` is the NDF unit's ([`crate::ndf::NdfUnit::density`], its `gauss`
//! table); the root and the normalizing divide are the roughness unit's
//! ([`crate::roughness::sqrt_round`]).
//!
//! Inputs: the two filtered offset channels (raw unorm `T = texel_bits`, `M_T = 2^T - 1`,
//! `f = (2t - M_T)/M_T 2^R`, `R = offset_int_bits`), the three moment channels (`M_ii =
//! t/M_T 2^E`, `M_uv = (2t - M_T)/M_T 2^(E-1)`, `E = lean_moment_exp`), the half vector in the
//! frame (`h_u, h_v, h_n`, vector format with `F` fraction bits), the exponent `s`. Everything
//! is decoded to `G = lean_frac_bits` fraction bits (one rounded division per channel).
//!
//! Hard cases: a quantized `M_ii - B_i^2` below zero is clamped to 0 (counted) before `1/s` is
//! added, so the diagonal is at least `round(2^G / s) > 0`; an off-diagonal that makes
//! `det <= 0` is dropped (counted); `h_n <= 0` (half vector at or below the horizon) gives 0;
//! the slope `h~` is clamped to `|h~| <= 2^8` (grazing angles, counted); the distance is
//! clamped below 128 as in the NDF unit. Integers only: no NaN or infinity can arise.
//!
//! ERROR BOUND (against the float twin `texsim::shading::lean::lean_f` on the same quantized
//! inputs, asserted in `tests/units/lean_unit.rs`): `|D - D_f| <= 2^-12` at texram16 widths
//! (`G = 24`, `E = 2`, 16-bit texels, `F = 14` half vectors, `P = 16`) for `s <= 4096`. The
//! terms: the decoded moments err by `2^-(G+1)`; `M - B B^T` cancels to an error of about
//! `2^(2R - G + 1)` against a variance of at least `1/s`; the slope `h~` errs by the half
//! vector's `2^-F` over `h_n`; the density by the NDF unit's Gauss bound; the normalization by
//! `2^-29` relative. Measured over 10^7 seeded cases: 2.07e-4.

use crate::config::ConfigError;
use crate::cost::UnitCost;
use crate::datapath::{Component, Cycles, Datapath, Stage};
use crate::fixed::{round_div_i128, round_div_wide, round_shift_right_wide, Rounding, SatCounter};
use crate::ndf::NdfUnit;
use crate::roughness::sqrt_round;
use crate::rsqrt::range;
use serde::{Deserialize, Serialize};

/// LEAN unit configuration.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LeanConfig {
    /// Range exponent `E` of the second moments: `M_ii` in `[0, 2^E)`, `M_uv` in
    /// `[-2^(E-1), 2^(E-1))`. 0..=8.
    pub lean_moment_exp: u32,
    /// Fraction bits `G` of the decoded moments and of Sigma. 16..=30.
    pub lean_frac_bits: u32,
    /// Cycles of the multiplier stages.
    pub lean_mul_cycles: Cycles,
}

impl LeanConfig {
    /// Texram-style default: moments in `[0, 4)` (slopes up to 2), 24 fraction bits.
    #[must_use]
    pub fn texram16() -> Self {
        Self {
            lean_moment_exp: 2,
            lean_frac_bits: 24,
            lean_mul_cycles: Cycles::Derived,
        }
    }

    /// Checks the ranges; the error names the field.
    pub fn validate(&self) -> Result<(), ConfigError> {
        range("lean.lean_moment_exp", self.lean_moment_exp, 0, 8)?;
        range("lean.lean_frac_bits", self.lean_frac_bits, 16, 30)?;
        Ok(())
    }
}

impl Default for LeanConfig {
    fn default() -> Self {
        Self::texram16()
    }
}

/// Inputs of one LEAN evaluation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LeanInput {
    /// Filtered offset channels `(f_u, f_v)` and moment channels `(M_uu, M_vv, M_uv)`, raw
    /// unorm of `texel_bits`.
    pub b: [u32; 2],
    pub m: [u32; 3],
    pub texel_bits: u32,
    /// Offset range exponent `R` (`hw.shading.vector.offset_int_bits`).
    pub offset_int_bits: u32,
    /// The unit half vector in the frame `(h . t_u, h . t_v, h . n)`, `h_frac_bits` fraction bits.
    pub h: [i64; 3],
    pub h_frac_bits: u32,
    /// The base Blinn-Phong exponent (slope variance `1/s`); 0 is taken as 1.
    pub shininess: u32,
}

/// Decoded moments and the covariance the unit used (`G` fraction bits), for tests.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LeanOut {
    /// `D` with `p` fraction bits (the caller's), in `[0, 2^p]`.
    pub d: i64,
    /// `Sigma_uu, Sigma_vv, Sigma_uv`.
    pub sigma: [i64; 3],
    /// The half vector was at or below the horizon.
    pub below: bool,
}

/// One LEAN evaluation: `D` with `p` fraction bits (2..=30). `density` is the NDF unit whose
/// `gauss` density evaluates `exp(-d/2)`.
#[must_use]
pub fn lean(
    inp: &LeanInput,
    cfg: &LeanConfig,
    density: &NdfUnit,
    p: u32,
    sat: &mut SatCounter,
) -> LeanOut {
    let rnd = Rounding::HalfEven;
    let g = cfg.lean_frac_bits.clamp(16, 30);
    let e = cfg.lean_moment_exp.min(8);
    let tb = inp.texel_bits.clamp(1, 16);
    let mt = (1i128 << tb) - 1;
    let r = inp.offset_int_bits.min(8);
    let s = i128::from(inp.shininess.max(1));
    let c = |t: u32| 2 * i128::from(t).min(mt) - mt;
    let b = inp
        .b
        .map(|t| round_div_wide(c(t) << (g + r), mt, rnd) as i128);
    let muu = round_div_wide(i128::from(inp.m[0]).min(mt) << (g + e), mt, rnd) as i128;
    let mvv = round_div_wide(i128::from(inp.m[1]).min(mt) << (g + e), mt, rnd) as i128;
    let muv = if e == 0 {
        round_div_wide(c(inp.m[2]) << g, 2 * mt, rnd) as i128
    } else {
        round_div_wide(c(inp.m[2]) << (g + e - 1), mt, rnd) as i128
    };
    let base = round_div_wide(1i128 << g, s, rnd) as i128;
    let sq = |x: i128, y: i128| i128::from(round_shift_right_wide(x * y, g, rnd));
    let mut diag = [muu - sq(b[0], b[0]), mvv - sq(b[1], b[1])];
    for d in &mut diag {
        if *d < 0 {
            sat.saturated += 1;
            *d = 0;
        }
        *d += base;
    }
    let mut suv = muv - sq(b[0], b[1]);
    let mut det = diag[0] * diag[1] - suv * suv;
    if det <= 0 {
        sat.saturated += 1;
        suv = 0;
        det = diag[0] * diag[1];
    }
    let sigma = [diag[0] as i64, diag[1] as i64, suv as i64];
    let zero = LeanOut {
        d: 0,
        sigma,
        below: true,
    };
    if inp.h[2] <= 0 {
        return zero;
    }
    // The projected slope of h with G fraction bits, clamped to |h~| <= 2^8.
    let lim = 1i128 << (g + 8);
    let hn = i128::from(inp.h[2]);
    let x = [0, 1].map(|i| {
        let mut t = round_div_i128(i128::from(inp.h[i]) << g, hn, rnd);
        if t.abs() > lim {
            sat.saturated += 1;
            t = t.clamp(-lim, lim);
        }
        t - b[i]
    });
    // d = x^T adj(Sigma) x / det: the squares and product of x rounded to G fraction bits
    // (|x| < 2^(G+9)), times Sigma's entries (G bits): the numerator has 2G fraction bits, as
    // det; d with the density's F fraction bits, clamped below 128.
    let sq_x = |a: i128, b: i128| i128::from(round_shift_right_wide(a * b, g, rnd));
    let q = sq_x(x[0], x[0]) * diag[1] - 2 * sq_x(x[0], x[1]) * suv + sq_x(x[1], x[1]) * diag[0];
    let f = density.config().ndf_frac_bits;
    let dmax = 128i128 << f;
    let dist = round_div_i128(q.max(0) << f, det, rnd).clamp(0, dmax) as i64;
    let gv = i128::from(density.density(dist));
    // k = (1/s) / sqrt(det value) with P fraction bits: sqrt(det raw) = mant 2^ex, the value
    // is that over 2^G, so k = 2^(G + P) / (s mant 2^ex).
    let p = p.clamp(2, 30);
    let (mant, ex) = sqrt_round(det as u128, 30);
    let (mut num, mut den) = (1i128 << (g + p), s * i128::from(mant));
    if ex >= 0 {
        den <<= ex as u32;
    } else {
        num <<= (-ex) as u32;
    }
    let one = 1i128 << p;
    let mut k = i128::from(round_div_wide(num, den, rnd));
    if k > one {
        sat.saturated += 1;
        k = one;
    }
    let d = round_shift_right_wide(gv * k, f, rnd).clamp(0, 1i64 << p);
    LeanOut {
        d,
        sigma,
        below: false,
    }
}

/// Cost of one evaluation: the decode (five constant multiplies), `B B^T` (three multiplies),
/// the determinant (two), the slope divide, the quadratic form (six), its divide, the density
/// (the NDF unit's exp table: two lookups and an interpolation), the root, the normalizing
/// divide and the product; cycles from [`datapath`].
#[must_use]
pub fn lean_cost(cfg: &LeanConfig, gate_levels_per_cycle: u32) -> UnitCost {
    UnitCost {
        ops: 5 + 3 + 3 + 2 + 2 + 6 + 1 + 3 + 1 + 1 + 1,
        cycles: datapath(cfg).latency(gate_levels_per_cycle),
        texels: 0,
    }
}

/// The unit's datapath (`G = lean_frac_bits`): decode and `B B^T`, the determinant, the slope
/// divide (digit-serial, radix 4, `G + 8` quotient bits), the quadratic form, the distance
/// divide (radix 4), the exp table with interpolation, the root (radix 4, 30 bits), the
/// normalizing divide (radix 4) and the final product.
#[must_use]
pub fn datapath(cfg: &LeanConfig) -> Datapath {
    let g = cfg.lean_frac_bits.clamp(16, 30);
    let w = g + 12;
    let step = |name: &'static str, width: u32, n: u32| {
        Stage::new(name)
            .then(Component::Adder { width })
            .then(Component::Mux { width, inputs: 3 })
            .then(Component::Register { bits: width })
            .times(n)
    };
    Datapath::new()
        .stage(
            Stage::new("decode and B B^T")
                .then_n(5, Component::Multiplier { a: 17, b: w })
                .then_n(3, Component::Multiplier { a: w, b: w })
                .then(Component::Adder { width: 2 * w })
                .then(Component::Register { bits: 5 * w })
                .cycles(cfg.lean_mul_cycles),
        )
        .stage(
            Stage::new("determinant")
                .then_n(2, Component::Multiplier { a: w, b: w })
                .then(Component::Adder { width: 2 * w })
                .then(Component::Register { bits: 2 * w })
                .cycles(cfg.lean_mul_cycles),
        )
        .stage(step("slope divide step", w, (g + 8).div_ceil(2)))
        .stage(
            Stage::new("quadratic form")
                .then_n(3, Component::Multiplier { a: w, b: w })
                .then_n(3, Component::Multiplier { a: w, b: w })
                .then(Component::Adder { width: 3 * w })
                .then(Component::Register { bits: 3 * w })
                .cycles(cfg.lean_mul_cycles),
        )
        .stage(step("distance divide step", w, w.div_ceil(2)))
        .stage(
            Stage::new("exp table")
                .then(Component::Rom {
                    addr_bits: 8,
                    data_bits: 30,
                })
                .then(Component::Multiplier { a: 30, b: 22 })
                .then(Component::Adder { width: 52 })
                .then(Component::Register { bits: 30 })
                .cycles(cfg.lean_mul_cycles),
        )
        .stage(step("square-root step", 32, 15))
        .stage(step("normalize divide step", 32, 16))
        .stage(
            Stage::new("specular product")
                .then(Component::Multiplier { a: 30, b: 30 })
                .then(Component::Register { bits: 30 })
                .cycles(cfg.lean_mul_cycles),
        )
}
