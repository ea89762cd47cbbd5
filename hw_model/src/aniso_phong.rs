//! Ashikhmin-Shirley anisotropic Phong BRDF unit (Ashikhmin & Shirley 2000, eqs. 11, 16, 18),
//! integer only. Output is `pi * rho` (so a white Lambertian surface would give 1.0) as a
//! pseudo-float, split into specular and diffuse parts and their sum.
//!
//! Datapath (every width from [`AnisoPhongConfig`]; `D = aniso_dot_frac_bits`):
//! 1. Inputs: the dot products `h.n, h.u, h.v, k.h, n.k1, n.k2` as signed raws with `D` fraction
//!    bits (`1.0 = 2^D`, so 1.0 is exact; `|x| > 1` saturates and is counted). `nu, nv` unsigned
//!    integers below `2^exponent_max_bits`; `Rs, Rd` unorm raws with `fresnel_bits` fraction bits
//!    (`1.0 = 2^fresnel_bits`).
//! 2. `a = hu^2`, `b = hv^2`, `s = a + b` exactly (`2D` fraction bits). For a unit `h`,
//!    `s = 1 - (h.n)^2`; using `s` instead of `1 - (h.n)^2` (eq. 18) avoids the cancellation as
//!    `h -> n`. Exponent `E = (nu a + nv b) / s` by a restoring divider to `aniso_ratio_bits`
//!    fraction bits plus a guard bit, rounded to nearest (a weighted average of nu, nv, so it
//!    never overflows). `h.n` itself is only checked for `> 0`.
//! 3. Power `(n.h)^E = (1 - s)^(E/2) = 2^-X` with `X = E L / 2`, `L = -log2(1 - s)`:
//!    for `s < 1/2`, `L = s g(s)` with `g(s) = -log2(1-s)/s` from a `2^aniso_pow_lut_bits + 1` entry
//!    ROM with linear interpolation (keeps relative precision as `s -> 0`); for `s >= 1/2`,
//!    `L = k - log2(m)` after normalizing `1 - s = 2^-k m` with a log2 ROM on `m in [1, 2)`.
//!    `X` is rounded to `aniso_pow_frac_bits`, then `2^-X = 2^-floor(X) 2^-frac(X)` with an exp2 ROM
//!    (pseudo-float, so the tail keeps relative precision; `X >= 100` flushes to 0).
//!    ROM entries are `aniso_pow_frac_bits`-bit roundings of values computed here in integer
//!    arithmetic to ~2^-55 (the ROM contents are a pure function of the index). The stage is
//!    [`aniso_power`]; its doc derives its error bound from `aniso_pow_lut_bits`,
//!    `aniso_pow_frac_bits` and `aniso_ratio_bits`.
//! 4. Schlick Fresnel `Rs + (1 - Rs)(1 - k.h)^5` (eq. 11): `1 - k.h` exact, three multiplies, a
//!    multiply and an add, each rounded to a `fresnel_bits` mantissa (pseudo-float: `F` keeps
//!    relative precision when small, e.g. low `Rs` with `k.h -> 1`).
//! 5. `1 / ((k.h) max(n.k1, n.k2))`: the exact `2D`-bit product is normalized and its mantissa
//!    inverted by a restoring divider to `aniso_recip_bits` bits (pseudo-float).
//! 6. Specular `sqrt((nu+1)(nv+1))/8 * P * F / den`, a chain of pseudo-float multiplies with
//!    `aniso_pow_frac_bits`-bit mantissas (the square root is an exact integer square root, a
//!    per-material constant: see [`aniso_phong_material_cost`]).
//! 7. Diffuse `28/23 Rd (1 - Rs) D(n.k1) D(n.k2)` (eq. 16 times pi) with
//!    `D(c) = 1 - (1 - c/2)^5` expanded as `x (5 - 10x + 10x^2 - 5x^3 + x^4)`, `x = c/2`
//!    (Horner, `fresnel_bits` fraction bits; no cancellation as `c -> 0`), then pseudo-float
//!    multiplies with `fresnel_bits` mantissas.
//! 8. Sum, rounded to `aniso_out_mant_bits`; values `>= 2^aniso_out_exp_max` saturate (counted).
//!
//! Guards: if `h.n <= 0`, `k.h <= 0`, `n.k1 <= 0` or `n.k2 <= 0` the output is zero: the caller
//! passes zeros for `k1 = -k2` (no halfway vector) and for directions below the horizon. At
//! `h = n` (`s = 0`, eq. 18's 0/0) the power is exactly 1. `0^0 = 1` (`nu = nv = 0`).
//!
//! Accuracy (texram16; `tests/units/brdf_fixed.rs`, 2^21 random unit-vector inputs with integer
//! exponents 0..1e5, against the reference evaluated from the SAME quantized dot products):
//! `|fixed - ref| <= 2e-4 ref` for `ref >= 1e-15` in units of `pi rho` (measured worst 6.7e-5),
//! excluding saturated outputs (`>= 2^24`, only at extreme grazing, < 0.1% of those inputs).

use crate::config::ConfigError;
use crate::cost::UnitCost;
use crate::datapath::{Component, Cycles, Datapath, Stage};
use crate::fixed::{round_shift_right, round_shift_right_wide, Rounding, SatCounter};
use serde::{Deserialize, Serialize};

/// Widths and per-op cycles of the anisotropic Phong unit.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnisoPhongConfig {
    /// Fraction bits of the input dot products (signed, `1.0 = 2^bits`).
    pub aniso_dot_frac_bits: u32,
    /// Bits of the unsigned integer exponents `nu`, `nv`.
    pub exponent_max_bits: u32,
    /// Fraction bits of the exponent `E` produced by the divider.
    pub aniso_ratio_bits: u32,
    /// Index bits of the log2 / g / exp2 ROMs (each has `2^bits + 1` entries).
    pub aniso_pow_lut_bits: u32,
    /// Fraction bits of ROM entries, of `X`, and of the internal pseudo-float mantissas.
    pub aniso_pow_frac_bits: u32,
    /// Fraction bits of Fresnel, the diffuse polynomial and `Rs`, `Rd`.
    pub fresnel_bits: u32,
    /// Mantissa bits of the reciprocal of `(k.h) max(n.k1, n.k2)`.
    pub aniso_recip_bits: u32,
    /// Mantissa bits of the output pseudo-floats.
    pub aniso_out_mant_bits: u32,
    /// Output values at or above `2^aniso_out_exp_max` saturate (counted).
    pub aniso_out_exp_max: u32,
    /// Rounding of every reduction inside the unit.
    pub aniso_rounding: Rounding,
    /// Cycles per multiply.
    pub aniso_mul_cycles: Cycles,
    /// Cycles per ROM lookup.
    pub aniso_lut_cycles: Cycles,
    /// Quotient bits a restoring divider retires per cycle.
    pub aniso_div_bits_per_cycle: u32,
}

fn check(field: &str, v: u32, lo: u32, hi: u32) -> Result<(), ConfigError> {
    if v < lo || v > hi {
        return Err(ConfigError {
            field: format!("aniso_phong.{field}"),
            what: format!("{v} is out of range {lo}..={hi}"),
        });
    }
    Ok(())
}

impl AnisoPhongConfig {
    /// Texram-style 16-bit unit: 1.14 dot products (16 bits with sign), 17-bit exponents
    /// (up to 131071), 16-bit Fresnel/diffuse and output mantissa, 24-bit internal mantissas.
    #[must_use]
    pub fn texram16() -> Self {
        Self {
            aniso_dot_frac_bits: 14,
            exponent_max_bits: 17,
            aniso_ratio_bits: 16,
            aniso_pow_lut_bits: 8,
            aniso_pow_frac_bits: 24,
            fresnel_bits: 16,
            aniso_recip_bits: 20,
            aniso_out_mant_bits: 16,
            aniso_out_exp_max: 24,
            aniso_rounding: Rounding::HalfEven,
            aniso_mul_cycles: Cycles::Derived,
            aniso_lut_cycles: Cycles::Derived,
            aniso_div_bits_per_cycle: 4,
        }
    }

    /// Checks every width against the range the model supports; the error names the field.
    pub fn validate(&self) -> Result<(), ConfigError> {
        check("aniso_dot_frac_bits", self.aniso_dot_frac_bits, 6, 15)?;
        check("exponent_max_bits", self.exponent_max_bits, 1, 20)?;
        check("aniso_ratio_bits", self.aniso_ratio_bits, 4, 24)?;
        check(
            "aniso_pow_lut_bits",
            self.aniso_pow_lut_bits,
            2,
            (2 * self.aniso_dot_frac_bits - 1).min(16),
        )?;
        check(
            "aniso_pow_frac_bits",
            self.aniso_pow_frac_bits,
            self.aniso_pow_lut_bits.max(8),
            30,
        )?;
        check("fresnel_bits", self.fresnel_bits, 4, 24)?;
        check("aniso_recip_bits", self.aniso_recip_bits, 4, 30)?;
        check("aniso_out_mant_bits", self.aniso_out_mant_bits, 2, 30)?;
        check("aniso_out_exp_max", self.aniso_out_exp_max, 1, 60)?;
        check(
            "aniso_div_bits_per_cycle",
            self.aniso_div_bits_per_cycle,
            1,
            64,
        )?;
        Ok(())
    }
}

impl Default for AnisoPhongConfig {
    fn default() -> Self {
        Self::texram16()
    }
}

/// Inputs of one evaluation (see the module doc for the formats).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AnisoPhongInputs {
    /// `h.n`, signed, `aniso_dot_frac_bits` fraction bits.
    pub hn: i32,
    /// `h.u`.
    pub hu: i32,
    /// `h.v`.
    pub hv: i32,
    /// `k.h`.
    pub kh: i32,
    /// `n.k1`.
    pub nk1: i32,
    /// `n.k2`.
    pub nk2: i32,
    /// Exponent along `u`.
    pub nu: u32,
    /// Exponent along `v`.
    pub nv: u32,
    /// `Rs`, unorm with `fresnel_bits` fraction bits.
    pub rs: u32,
    /// `Rd`, unorm with `fresnel_bits` fraction bits.
    pub rd: u32,
}

/// A non-negative pseudo-float `mant * 2^exp`; `mant` is normalized (top bit of its width set)
/// or zero.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PseudoFloat {
    /// Mantissa.
    pub mant: u64,
    /// Power-of-two exponent of the mantissa's least significant bit.
    pub exp: i32,
}

/// Output of one evaluation, in units of `pi * rho`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AnisoPhongOut {
    /// Specular part (eq. 18 times pi).
    pub spec: PseudoFloat,
    /// Diffuse part (eq. 16 times pi).
    pub diffuse: PseudoFloat,
    /// `spec + diffuse`.
    pub total: PseudoFloat,
}

/// The power `2^-X` is flushed to zero for `X >= POW_FLUSH_X`. A constant, not a knob: a
/// flushed power is below `2^-99.9`, and the largest factor the specular chain applies to it is
/// `sqrt((nu+1)(nv+1))/8 / ((k.h) max(n.k1, n.k2)) < 2^(exponent_max_bits - 3) 2^(2
/// aniso_dot_frac_bits) <= 2^47` (20-bit exponents, 15-bit dot products; `2^42` for texram16),
/// so a flushed term is below `2^-52` of `pi rho` in every valid configuration, far below any
/// output or colour LSB. Raising it only widens the pseudo-float exponents; lowering it to a
/// few tens would clip visible lobe tails (`E = 1e5` reaches `X = 100` at `1 - h.n = 6.9e-4`).
pub const POW_FLUSH_X: i64 = 100;

/// `2^62 / ln 2`, rounded.
const LOG2E_Q62: u128 = 6_653_256_548_922_161_246;
/// `2^62 ln 2`, rounded.
const LN2_Q62: u128 = 3_196_577_161_300_663_915;
const Q: u32 = 62;

/// Normalizes `m * 2^e` to a `bits`-bit mantissa (rounded by `rnd`).
#[must_use]
fn pf_norm(m: u128, e: i32, bits: u32, rnd: Rounding) -> PseudoFloat {
    if m == 0 {
        return PseudoFloat { mant: 0, exp: 0 };
    }
    let len = 128 - m.leading_zeros();
    if len > bits {
        let sh = len - bits;
        let mut r = round_shift_right_wide(m as i128, sh, rnd) as u128;
        let mut e2 = e + sh as i32;
        if r >> bits != 0 {
            r >>= 1;
            e2 += 1;
        }
        PseudoFloat {
            mant: r as u64,
            exp: e2,
        }
    } else {
        let sh = bits - len;
        PseudoFloat {
            mant: (m << sh) as u64,
            exp: e - sh as i32,
        }
    }
}

#[must_use]
fn pf_mul(a: PseudoFloat, b: PseudoFloat, bits: u32, rnd: Rounding) -> PseudoFloat {
    pf_norm(
        u128::from(a.mant) * u128::from(b.mant),
        a.exp + b.exp,
        bits,
        rnd,
    )
}

#[must_use]
fn pf_add(a: PseudoFloat, b: PseudoFloat, bits: u32, rnd: Rounding) -> PseudoFloat {
    if a.mant == 0 {
        return pf_norm(u128::from(b.mant), b.exp, bits, rnd);
    }
    if b.mant == 0 {
        return pf_norm(u128::from(a.mant), a.exp, bits, rnd);
    }
    // Normalize both, align to the smaller exponent, but never shift by more than bits + 4:
    // beyond that the smaller operand only acts as a sticky bit below the rounding position.
    let a = pf_norm(u128::from(a.mant), a.exp, bits, rnd);
    let b = pf_norm(u128::from(b.mant), b.exp, bits, rnd);
    let (hi, lo) = if a.exp >= b.exp { (a, b) } else { (b, a) };
    let d = (hi.exp - lo.exp) as u32;
    let cap = bits + 4;
    if d > cap {
        let m = (u128::from(hi.mant) << cap) | 1;
        return pf_norm(m, hi.exp - cap as i32, bits, rnd);
    }
    let m = (u128::from(hi.mant) << d) + u128::from(lo.mant);
    pf_norm(m, lo.exp, bits, rnd)
}

/// Restoring divider: `floor(num / den)` one quotient bit per step, for a quotient known to be
/// below `2^qbits`. Returns 0 for `den = 0`.
#[must_use]
pub fn restoring_div(num: u128, den: u128, qbits: u32) -> u128 {
    if den == 0 {
        return 0;
    }
    let mut r = num;
    let mut q = 0u128;
    for i in (0..qbits).rev() {
        if den.leading_zeros() < i {
            continue;
        }
        let d = den << i;
        if r >= d {
            r -= d;
            q |= 1u128 << i;
        }
    }
    q
}

/// Exact integer square root `floor(sqrt(x))`, bit by bit.
#[must_use]
pub fn isqrt(x: u128) -> u128 {
    let mut res = 0u128;
    let mut rem = x;
    let mut bit = 1u128 << 126;
    while bit > x {
        bit >>= 2;
    }
    while bit != 0 {
        if rem >= res + bit {
            rem -= res + bit;
            res = (res >> 1) + bit;
        } else {
            res >>= 1;
        }
        bit >>= 2;
    }
    res
}

/// `log2(m)` in Q62 for `m` in Q62 within `[1, 2)`, by repeated squaring (error ~2^-56).
#[must_use]
fn log2_q62(m: u128) -> u128 {
    let one = 1u128 << Q;
    let mut z = m;
    let mut y = 0u128;
    for i in 1..=Q {
        z = (z * z) >> Q;
        if z >= 2 * one {
            z >>= 1;
            y |= 1u128 << (Q - i);
        }
    }
    y
}

/// Rounds a Q62 value to `f` fraction bits.
#[must_use]
fn q62_to(v: u128, f: u32, rnd: Rounding) -> i64 {
    round_shift_right_wide(v as i128, Q - f, rnd)
}

/// ROM `g(s) = -log2(1 - s) / s` at `s = i / 2^(lut_bits + 1)`, `i in 0..=2^lut_bits`.
#[must_use]
pub fn rom_g(i: u32, cfg: &AnisoPhongConfig) -> i64 {
    let b = cfg.aniso_pow_lut_bits;
    let f = cfg.aniso_pow_frac_bits;
    if i == 0 {
        return q62_to(LOG2E_Q62, f, cfg.aniso_rounding);
    }
    // 1 - s = m / 2 with m = (2^(b+1) - i) / 2^b in [1, 2].
    let m = u128::from((1u32 << (b + 1)) - i) << (Q - b);
    let neg_log = (1u128 << Q) - log2_q62(m);
    // g = neg_log / s = neg_log * 2^(b+1) / i.
    let g = (neg_log << (b + 1)) / u128::from(i);
    q62_to(g, f, cfg.aniso_rounding)
}

/// ROM `log2(1 + i / 2^lut_bits)`, `i in 0..=2^lut_bits`.
#[must_use]
pub fn rom_log2(i: u32, cfg: &AnisoPhongConfig) -> i64 {
    let b = cfg.aniso_pow_lut_bits;
    if i >= 1u32 << b {
        return 1i64 << cfg.aniso_pow_frac_bits;
    }
    let m = u128::from((1u32 << b) + i) << (Q - b);
    q62_to(log2_q62(m), cfg.aniso_pow_frac_bits, cfg.aniso_rounding)
}

/// ROM `2^(-i / 2^lut_bits)`, `i in 0..=2^lut_bits`, by the Taylor series of `e^-x`.
#[must_use]
pub fn rom_exp2(i: u32, cfg: &AnisoPhongConfig) -> i64 {
    let b = cfg.aniso_pow_lut_bits;
    let x = (LN2_Q62 * u128::from(i)) >> b;
    let one = 1i128 << Q;
    let (mut term, mut sum) = (one, one);
    for k in 1..=30i128 {
        term = -((term * x as i128) >> Q) / k;
        sum += term;
    }
    q62_to(
        sum.max(0) as u128,
        cfg.aniso_pow_frac_bits,
        cfg.aniso_rounding,
    )
}

/// Linear interpolation between two ROM entries with a `fb`-bit fraction.
#[must_use]
fn interp(a: i64, b: i64, frac: i64, fb: u32, rnd: Rounding) -> i64 {
    a + round_shift_right((b - a) * frac, fb, rnd)
}

/// The power stage (module doc, step 3) on its own: `(n.h)^E = (1 - s)^(E/2)` as a
/// pseudo-float with an `aniso_pow_frac_bits`-bit mantissa, from `s = (h.u)^2 + (h.v)^2` with
/// `2 aniso_dot_frac_bits` fraction bits and `E = e_raw 2^-aniso_ratio_bits`. `s = 0` or
/// `E = 0` give exactly 1, `s >= 1` gives 0. `e_raw` above the divider's range
/// `2^(exponent_max_bits + aniso_ratio_bits) - 1` is clamped to it (the unit never produces
/// more: `E` is a weighted average of `nu, nv`). ROMs are read from `roms` (built for a valid
/// configuration).
///
/// Declared precision (derived here, checked by `tests/units/as_power.rs` against `(1 - s)^(E/2)` in
/// double precision). Let `f = aniso_pow_frac_bits`, `b = aniso_pow_lut_bits`, `r = aniso_ratio_bits`,
/// `u = 1/2` for the round-to-nearest modes and `u = 1` for `Truncate`, `L = -log2(1 - s)`
/// and `X = E L / 2`, so the exact power is `P = 2^-X`.
/// - Every ROM entry is its function computed to ~2^-55 and rounded once: within
///   `u 2^-f + 2^-40` of it. Reading between two entries adds the rounding of the interpolated
///   value (`u 2^-f`) and the linear-interpolation error `h^2 max|y''| / 8`. Write
///   `eps = 2u 2^-f + 2^-40`.
/// - `L` for `s < 1/2` is `s g(s)` (exact product) with `g in [1/ln 2, 2]`, `h = 2^-(b+1)`,
///   `g'' <= g''(1/2) = 16 - 8/ln 2`: relative error `<= ln 2 (eps + (16 - 8/ln 2) 2^(-2b-5))`.
///   For `s >= 1/2`, `L = k - log2(m) >= 1` with `h = 2^-b`, `|log2''| <= 1/ln 2`: relative
///   error `<= eps + 2^(-2b-3)/ln 2`, the larger of the two. So
///   `dL = eps + 2^(-2b-3) / ln 2` bounds the relative error of `L`.
/// - `X` rounded to `f` fraction bits: `|X_fixed - X| <= dX = X dL + u 2^-f`.
/// - `2^-frac(X)` in `(1/2, 1]` from the exp2 ROM (`h = 2^-b`, `(2^-t)'' <= ln^2 2`):
///   relative error `<= dE = 2 (eps + ln^2(2) 2^(-2b-3))`; the final normalization is exact.
///
/// Hence, for every non-zero output, `|P_fixed / P - 1| <= 2^dX (1 + dE) - 1`. An output of 0
/// (flush, [`POW_FLUSH_X`]) means `X_fixed >= 100`, so `P < 2^-(100 - dX)`. When `E` comes from
/// the exponent divider (rounded to nearest: `|E_raw 2^-r - E| <= 2^-(r+1)`), `dX` gains
/// `L (1 + dL) 2^-(r+2)`. texram16 (`f = 24, b = 8, r = 16`, half-even): `dL = 2.8e-6`,
/// `dE = 2.0e-6`; relative error `<= 3.9e-6` at `X = 1`, `2.1e-5` at `X = 10`, `2.0e-4` at
/// `X = 100` (`P = 7.9e-31`). Measured over 2^22 seeded texram16 cases with `E in [0, 1e5]`:
/// worst relative error 9.6e-5, 0.49 of the bound at its `X`; exhaustive runs of 4-bit-ROM
/// configurations use up to 0.71 of it.
#[must_use]
pub fn aniso_power(s: u64, e_raw: u64, roms: &AnisoPhongRoms) -> PseudoFloat {
    let cfg = &roms.cfg;
    let e_max = (1u64 << (cfg.exponent_max_bits + cfg.aniso_ratio_bits).min(63)) - 1;
    power(s, e_raw.min(e_max), cfg, roms)
}

/// `(n.h)^E = (1 - s)^(E/2)` as a pseudo-float; `s` has `2D` fraction bits, `e_raw` has
/// `aniso_ratio_bits` fraction bits (see [`aniso_power`] for its precision).
#[must_use]
fn power(s: u64, e_raw: u64, cfg: &AnisoPhongConfig, rom: &impl RomSource) -> PseudoFloat {
    let f = cfg.aniso_pow_frac_bits;
    let rnd = cfg.aniso_rounding;
    let b = cfg.aniso_pow_lut_bits;
    let sb = 2 * cfg.aniso_dot_frac_bits;
    let one_pf = PseudoFloat {
        mant: 1u64 << f,
        exp: -(f as i32),
    };
    if e_raw == 0 || s == 0 {
        return one_pf;
    }
    if s >= 1u64 << sb {
        return PseudoFloat::default();
    }
    // L with sb + f fraction bits.
    let l_wide: u128 = if s < 1u64 << (sb - 1) {
        let fb = sb - b - 1;
        let idx = (s >> fb) as u32;
        let fr = (s & ((1u64 << fb) - 1)) as i64;
        let g = interp(rom.g(idx), rom.g(idx + 1), fr, fb, rnd);
        u128::from(s) * g.max(0) as u128
    } else {
        let y = (1u64 << sb) - s;
        let bl = 64 - y.leading_zeros();
        let mf = bl - 1;
        let mfrac = y - (1u64 << mf);
        let (idx, fr, fb) = if mf >= b {
            let fb = mf - b;
            (
                (mfrac >> fb) as u32,
                (mfrac & ((1u64 << fb) - 1)) as i64,
                fb,
            )
        } else {
            ((mfrac << (b - mf)) as u32, 0, 0)
        };
        let lg = interp(rom.log2(idx), rom.log2(idx + 1), fr, fb, rnd);
        let k = i64::from(sb + 1 - bl);
        (((k << f) - lg).max(0) as u128) << sb
    };
    // X = E * L / 2, rounded to f fraction bits.
    let x = round_shift_right_wide(
        (u128::from(e_raw) * l_wide) as i128,
        cfg.aniso_ratio_bits + sb + 1,
        rnd,
    );
    let xi = x >> f;
    if xi >= POW_FLUSH_X {
        return PseudoFloat::default();
    }
    let xf = x & ((1i64 << f) - 1);
    let fb = f - b;
    let idx = (xf >> fb) as u32;
    let fr = xf & ((1i64 << fb) - 1);
    let pm = interp(rom.exp2(idx), rom.exp2(idx + 1), fr, fb, rnd);
    pf_norm(pm.max(0) as u128, -(xi as i32) - f as i32, f, rnd)
}

/// Schlick Fresnel `Rs + (1 - Rs)(1 - k.h)^5` (eq. 11) as a pseudo-float with `fb`-bit
/// mantissas: `1 - k.h` is exact, each of the four multiplies and the add round to `fb` bits,
/// so `F` keeps relative precision even when it is small (low `Rs`, `k.h -> 1`).
#[must_use]
fn fresnel(kh: i64, d: u32, rs: i64, fb: u32, rnd: Rounding) -> PseudoFloat {
    let y = PseudoFloat {
        mant: ((1i64 << d) - kh).max(0) as u64,
        exp: -(d as i32),
    };
    let y2 = pf_mul(y, y, fb, rnd);
    let y4 = pf_mul(y2, y2, fb, rnd);
    let y5 = pf_mul(y4, y, fb, rnd);
    let one_minus_rs = PseudoFloat {
        mant: ((1i64 << fb) - rs).max(0) as u64,
        exp: -(fb as i32),
    };
    let t = pf_mul(one_minus_rs, y5, fb, rnd);
    pf_add(
        PseudoFloat {
            mant: rs.max(0) as u64,
            exp: -(fb as i32),
        },
        t,
        fb,
        rnd,
    )
}

/// `1 - (1 - x)^5` for `x = n.k / 2` (eq. 16) as a pseudo-float with `fb`-bit mantissa, by the
/// expanded form `x (5 - 10x + 10x^2 - 5x^3 + x^4)` in Horner order with `fb` fraction bits
/// (the polynomial is in [1.9, 5] on [0, 1/2], so the result keeps relative precision as
/// `n.k -> 0`, where `1 - (1 - x)^5` would cancel).
#[must_use]
fn diffuse_factor(nk: i64, d: u32, fb: u32, rnd: Rounding) -> PseudoFloat {
    // x = nk / 2 has d + 1 fraction bits exactly; bring it to fb fraction bits.
    let xf = d + 1;
    let x = if xf >= fb {
        round_shift_right(nk, xf - fb, rnd)
    } else {
        nk << (fb - xf)
    };
    let one = 1i64 << fb;
    let mut q = x - 5 * one;
    for c in [10i64, -10, 5] {
        q = round_shift_right(q * x, fb, rnd) + c * one;
    }
    pf_mul(
        PseudoFloat {
            mant: nk.max(0) as u64,
            exp: -(xf as i32),
        },
        PseudoFloat {
            mant: q.max(0) as u64,
            exp: -(fb as i32),
        },
        fb,
        rnd,
    )
}

/// Per-material constant `sqrt((nu+1)(nv+1))` with `aniso_pow_frac_bits` fraction bits (exact floor).
#[must_use]
pub fn norm_sqrt(nu: u32, nv: u32, cfg: &AnisoPhongConfig) -> u64 {
    let p = (u128::from(nu) + 1) * (u128::from(nv) + 1);
    isqrt(p << (2 * cfg.aniso_pow_frac_bits)) as u64
}

/// Clamps a dot product to `[-1, 1]` (`2^D`), counting saturation.
#[must_use]
fn clamp_dot(x: i32, d: u32, sat: &mut SatCounter) -> i64 {
    let one = 1i64 << d;
    let v = i64::from(x);
    if v > one || v < -one {
        sat.saturated += 1;
        return v.clamp(-one, one);
    }
    v
}

/// Where the datapath reads its ROM entries: computed on demand ([`aniso_phong`]) or from
/// tables built once ([`AnisoPhongRoms`]); both give the same entries.
trait RomSource {
    fn g(&self, i: u32) -> i64;
    fn log2(&self, i: u32) -> i64;
    fn exp2(&self, i: u32) -> i64;
}

/// ROM entries computed per lookup from their defining functions.
struct DirectRoms<'a>(&'a AnisoPhongConfig);

impl RomSource for DirectRoms<'_> {
    fn g(&self, i: u32) -> i64 {
        rom_g(i, self.0)
    }
    fn log2(&self, i: u32) -> i64 {
        rom_log2(i, self.0)
    }
    fn exp2(&self, i: u32) -> i64 {
        rom_exp2(i, self.0)
    }
}

/// The three ROMs of one configuration, built once (`3 (2^aniso_pow_lut_bits + 1)` entries):
/// [`aniso_phong_prepared`] with these tables is bit-identical to [`aniso_phong`], which
/// recomputes each entry it reads.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AnisoPhongRoms {
    cfg: AnisoPhongConfig,
    g: Vec<i64>,
    log2: Vec<i64>,
    exp2: Vec<i64>,
}

impl AnisoPhongRoms {
    /// Tables of [`rom_g`], [`rom_log2`] and [`rom_exp2`] for `cfg` (which should be valid).
    #[must_use]
    pub fn new(cfg: &AnisoPhongConfig) -> Self {
        let n = (1u32 << cfg.aniso_pow_lut_bits.min(16)) + 1;
        Self {
            cfg: cfg.clone(),
            g: (0..n).map(|i| rom_g(i, cfg)).collect(),
            log2: (0..n).map(|i| rom_log2(i, cfg)).collect(),
            exp2: (0..n).map(|i| rom_exp2(i, cfg)).collect(),
        }
    }

    /// The configuration the tables were built for.
    #[must_use]
    pub fn config(&self) -> &AnisoPhongConfig {
        &self.cfg
    }
}

impl RomSource for AnisoPhongRoms {
    fn g(&self, i: u32) -> i64 {
        self.g.get(i as usize).copied().unwrap_or(0)
    }
    fn log2(&self, i: u32) -> i64 {
        self.log2.get(i as usize).copied().unwrap_or(0)
    }
    fn exp2(&self, i: u32) -> i64 {
        self.exp2.get(i as usize).copied().unwrap_or(0)
    }
}

/// Evaluates the BRDF (times pi) from dot products. See the module doc for formats and guards.
/// Recomputes every ROM entry it reads; for many evaluations use [`aniso_phong_prepared`].
#[must_use]
pub fn aniso_phong(
    inp: &AnisoPhongInputs,
    cfg: &AnisoPhongConfig,
    sat: &mut SatCounter,
) -> AnisoPhongOut {
    aniso_phong_core(inp, cfg, &DirectRoms(cfg), sat)
}

/// [`aniso_phong`] reading its ROMs from tables built once by [`AnisoPhongRoms::new`] (for the
/// configuration `roms.config()`); bit-identical to [`aniso_phong`] with that configuration.
#[must_use]
pub fn aniso_phong_prepared(
    inp: &AnisoPhongInputs,
    roms: &AnisoPhongRoms,
    sat: &mut SatCounter,
) -> AnisoPhongOut {
    aniso_phong_core(inp, &roms.cfg, roms, sat)
}

#[must_use]
fn aniso_phong_core(
    inp: &AnisoPhongInputs,
    cfg: &AnisoPhongConfig,
    rom: &impl RomSource,
    sat: &mut SatCounter,
) -> AnisoPhongOut {
    let d = cfg.aniso_dot_frac_bits;
    let f = cfg.aniso_pow_frac_bits;
    let fb = cfg.fresnel_bits;
    let rnd = cfg.aniso_rounding;
    let hn = clamp_dot(inp.hn, d, sat);
    let hu = clamp_dot(inp.hu, d, sat);
    let hv = clamp_dot(inp.hv, d, sat);
    let kh = clamp_dot(inp.kh, d, sat);
    let nk1 = clamp_dot(inp.nk1, d, sat);
    let nk2 = clamp_dot(inp.nk2, d, sat);
    if hn <= 0 || kh <= 0 || nk1 <= 0 || nk2 <= 0 {
        return AnisoPhongOut::default();
    }
    let emax = (1u64 << cfg.exponent_max_bits) - 1;
    let clamp_e = |e: u32, sat: &mut SatCounter| -> u64 {
        if u64::from(e) > emax {
            sat.saturated += 1;
            emax
        } else {
            u64::from(e)
        }
    };
    let nu = clamp_e(inp.nu, sat);
    let nv = clamp_e(inp.nv, sat);
    let one_f = 1i64 << fb;
    let clamp_u = |x: u32, sat: &mut SatCounter| -> i64 {
        if i64::from(x) > one_f {
            sat.saturated += 1;
            one_f
        } else {
            i64::from(x)
        }
    };
    let rs = clamp_u(inp.rs, sat);
    let rd = clamp_u(inp.rd, sat);

    // Exponent: E = (nu a + nv b) / s.
    let a = (hu * hu) as u64;
    let b = (hv * hv) as u64;
    let s = a + b;
    let r = cfg.aniso_ratio_bits;
    let e_raw = if s == 0 {
        0
    } else {
        // One guard bit, then round to nearest (ties up): |E error| <= 2^-(r+1).
        let num = (u128::from(nu) * u128::from(a) + u128::from(nv) * u128::from(b)) << (r + 1);
        let q = restoring_div(num, u128::from(s), cfg.exponent_max_bits + r + 2) as i64;
        round_shift_right(q, 1, Rounding::HalfUp) as u64
    };
    let p = power(s, e_raw, cfg, rom);

    // Fresnel, eq. 11.
    let fpf = fresnel(kh, d, rs, fb, rnd);

    // 1 / (k.h max(n.k1, n.k2)) as a pseudo-float.
    let den = (kh * nk1.max(nk2)) as u64;
    let w = cfg.aniso_recip_bits;
    let bl = 64 - den.leading_zeros();
    let md = if bl > w {
        round_shift_right(den as i64, bl - w, rnd) as u64
    } else {
        den << (w - bl)
    };
    let q = restoring_div(1u128 << (2 * w - 1), u128::from(md), w + 2);
    let recip = PseudoFloat {
        mant: q as u64,
        exp: (2 * d) as i32 - bl as i32 - w as i32 + 1,
    };

    // Specular: sqrt((nu+1)(nv+1))/8 * P * F * recip.
    let c = PseudoFloat {
        mant: norm_sqrt(nu as u32, nv as u32, cfg),
        exp: -(f as i32) - 3,
    };
    let spec = if p.mant == 0 || fpf.mant == 0 {
        PseudoFloat::default()
    } else {
        let t = pf_mul(c, p, f, rnd);
        let t = pf_mul(t, fpf, f, rnd);
        pf_mul(t, recip, f, rnd)
    };

    // Diffuse, eq. 16 times pi: 28/23 Rd (1 - Rs) D(n.k1) D(n.k2), pseudo-floats of fb bits.
    let k = PseudoFloat {
        // 28/23 rounded to nearest: a hard-wired constant, not a datapath rounding.
        mant: ((28u64 << fb) + 11) / 23,
        exp: -(fb as i32),
    };
    let rd_pf = PseudoFloat {
        mant: rd.max(0) as u64,
        exp: -(fb as i32),
    };
    let one_minus_rs = PseudoFloat {
        mant: (one_f - rs).max(0) as u64,
        exp: -(fb as i32),
    };
    let diffuse = if rd == 0 || rs == one_f {
        PseudoFloat::default()
    } else {
        let t = pf_mul(rd_pf, one_minus_rs, fb, rnd);
        let t = pf_mul(t, diffuse_factor(nk1, d, fb, rnd), fb, rnd);
        let t = pf_mul(t, diffuse_factor(nk2, d, fb, rnd), fb, rnd);
        pf_mul(t, k, fb, rnd)
    };

    let total = pf_add(spec, diffuse, f, rnd);
    let ob = cfg.aniso_out_mant_bits;
    let out = |x: PseudoFloat, sat: &mut SatCounter| -> PseudoFloat {
        let y = pf_norm(u128::from(x.mant), x.exp, ob, rnd);
        if y.mant != 0 && y.exp + ob as i32 > cfg.aniso_out_exp_max as i32 {
            sat.saturated += 1;
            return PseudoFloat {
                mant: (1u64 << ob) - 1,
                exp: cfg.aniso_out_exp_max as i32 - ob as i32,
            };
        }
        y
    };
    AnisoPhongOut {
        spec: out(spec, sat),
        diffuse: out(diffuse, sat),
        total: out(total, sat),
    }
}

/// Cycles of a restoring divider producing `qbits` quotient bits.
#[must_use]
/// A digit-recurrence divider of `qbits` quotient bits, `aniso_div_bits_per_cycle` bits per
/// step (each step that many subtract-and-select slices of `qbits + 2` bits).
fn divider(name: &'static str, qbits: u32, cfg: &AnisoPhongConfig) -> Stage {
    let k = cfg.aniso_div_bits_per_cycle.max(1);
    let mut s = Stage::new(name);
    for _ in 0..k {
        s = s
            .then(Component::Adder { width: qbits + 2 })
            .then(Component::Mux {
                width: qbits + 2,
                inputs: 2,
            });
    }
    s.times(qbits.div_ceil(k))
}

/// The unit's per-pixel datapath (D = `aniso_dot_frac_bits + 2`): 30 multiplies in series
/// (`aniso_mul_cycles` each), 17 of them fused with the following add, the 4 ROM reads of
/// the power (`aniso_lut_cycles`; `aniso_pow_lut_bits` x `aniso_pow_frac_bits`), and the
/// exponent and reciprocal dividers at `aniso_div_bits_per_cycle`.
#[must_use]
pub fn datapath(cfg: &AnisoPhongConfig) -> Datapath {
    let d = cfg.aniso_dot_frac_bits + 2;
    let e_div = cfg.exponent_max_bits + cfg.aniso_ratio_bits + 1;
    let r_div = cfg.aniso_recip_bits + 2;
    Datapath::new()
        .stage(
            Stage::new("multiply-add")
                .then(Component::Multiplier { a: d, b: d })
                .then(Component::Adder { width: 2 * d + 1 })
                .times(17)
                .cycles(cfg.aniso_mul_cycles),
        )
        .stage(
            Stage::new("multiply")
                .then(Component::Multiplier { a: d, b: d })
                .times(13)
                .cycles(cfg.aniso_mul_cycles),
        )
        .stage(
            Stage::new("power ROM")
                .then(Component::Rom {
                    addr_bits: cfg.aniso_pow_lut_bits,
                    data_bits: cfg.aniso_pow_frac_bits,
                })
                .times(4)
                .cycles(cfg.aniso_lut_cycles),
        )
        .stage(divider("exponent divide step", e_div, cfg))
        .stage(divider("reciprocal divide step", r_div, cfg))
}

/// Cost of one per-pixel evaluation on a single non-pipelined datapath (one multiplier, one
/// ROM port, one divider used in sequence; adds and compares fold into the multiplier stages).
/// Excludes the per-material square root ([`aniso_phong_material_cost`]).
#[must_use]
pub fn aniso_phong_cost(cfg: &AnisoPhongConfig, gate_levels_per_cycle: u32) -> UnitCost {
    // Multiplies: exponent 4 (hu^2, hv^2, nu a, nv b); power 4 (two ROM interpolations, s g,
    // E L); Fresnel 4; k.h max 1; specular chain 3; diffuse 2 x 5 (Horner + x q) + 4 (chain).
    let muls = 4 + 4 + 4 + 1 + 3 + 10 + 4;
    let luts = 4; // two entries for each of the log ROM and the exp2 ROM
                  // Adds/compares: exponent 2, power 2, Fresnel 2, max 1, diffuse Horner 8 + (1 - Rs) 1, sum 1.
    let adds = 17;
    UnitCost {
        ops: muls + luts + adds + 2,
        cycles: datapath(cfg).latency(gate_levels_per_cycle),
        texels: 0,
    }
}

/// Cost of the per-material setup: the integer square root `sqrt((nu+1)(nv+1))`, one result bit
/// per divider step.
#[must_use]
pub fn aniso_phong_material_cost(cfg: &AnisoPhongConfig, gate_levels_per_cycle: u32) -> UnitCost {
    let bits = cfg.exponent_max_bits + 1 + cfg.aniso_pow_frac_bits;
    UnitCost {
        ops: bits,
        cycles: Datapath::new()
            .stage(divider("material divide step", bits, cfg))
            .latency(gate_levels_per_cycle),
        texels: 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn restoring_div_matches_integer_division() {
        let mut x = 0x1234_5678_9abc_def0u64;
        for _ in 0..10_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let den = u128::from(x >> 40) + 1;
            let num = u128::from(x) & ((1u128 << 40) - 1);
            assert_eq!(restoring_div(num, den, 41), num / den);
        }
    }

    #[test]
    fn isqrt_is_floor_sqrt() {
        for v in [
            0u128,
            1,
            2,
            3,
            4,
            15,
            16,
            17,
            1 << 40,
            (1 << 80) + 12345,
            u128::from(u64::MAX),
        ] {
            let r = isqrt(v);
            assert!(r * r <= v && (r + 1) * (r + 1) > v, "{v}");
        }
    }

    #[test]
    fn prepared_is_bit_identical_to_direct() {
        let mut cfgs = vec![AnisoPhongConfig::texram16()];
        let mut small = AnisoPhongConfig::texram16();
        small.aniso_dot_frac_bits = 10;
        small.aniso_pow_lut_bits = 5;
        small.aniso_pow_frac_bits = 12;
        small.aniso_rounding = Rounding::HalfUp;
        cfgs.push(small);
        fn next(x: &mut u64) -> u64 {
            *x ^= *x << 13;
            *x ^= *x >> 7;
            *x ^= *x << 17;
            *x
        }
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        for cfg in &cfgs {
            assert!(cfg.validate().is_ok());
            let roms = AnisoPhongRoms::new(cfg);
            let one = 1i64 << cfg.aniso_dot_frac_bits;
            // Dot products over [-1.1, 1.1] (some saturate), biased to h near n half the time.
            let dot = |x: &mut u64, near_one: bool| -> i32 {
                let r = (next(x) % (2 * one as u64 + one as u64 / 5)) as i64 - one - one / 10;
                if near_one {
                    (one - (r.abs() >> 6)) as i32
                } else {
                    r as i32
                }
            };
            for k in 0..20_000 {
                let near = k % 2 == 0;
                let hn = dot(&mut x, near);
                let (hu, hv) = if near {
                    (dot(&mut x, false) >> 5, dot(&mut x, false) >> 5)
                } else {
                    (dot(&mut x, false), dot(&mut x, false))
                };
                let inp = AnisoPhongInputs {
                    hn,
                    hu,
                    hv,
                    kh: dot(&mut x, near),
                    nk1: dot(&mut x, false),
                    nk2: dot(&mut x, false),
                    nu: (next(&mut x) % 200_000) as u32,
                    nv: (next(&mut x) % 2_000) as u32,
                    rs: (next(&mut x) % (1 << cfg.fresnel_bits)) as u32,
                    rd: (next(&mut x) % (1 << cfg.fresnel_bits)) as u32,
                };
                let (mut s1, mut s2) = (SatCounter::default(), SatCounter::default());
                let a = aniso_phong(&inp, cfg, &mut s1);
                let b = aniso_phong_prepared(&inp, &roms, &mut s2);
                assert_eq!(a, b, "{inp:?}");
                assert_eq!(s1, s2);
            }
        }
    }

    #[test]
    fn rom_endpoints() {
        let cfg = AnisoPhongConfig::texram16();
        let one = 1i64 << cfg.aniso_pow_frac_bits;
        assert_eq!(rom_log2(0, &cfg), 0);
        assert_eq!(rom_log2(1 << cfg.aniso_pow_lut_bits, &cfg), one);
        assert_eq!(rom_exp2(0, &cfg), one);
        assert!((rom_exp2(1 << cfg.aniso_pow_lut_bits, &cfg) - one / 2).abs() <= 1);
        // g(1/2) = -log2(1/2) / (1/2) = 2.
        assert!((rom_g(1 << cfg.aniso_pow_lut_bits, &cfg) - 2 * one).abs() <= 1);
        assert!(cfg.validate().is_ok());
    }
}
