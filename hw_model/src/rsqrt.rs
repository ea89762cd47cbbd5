//! Reciprocal square root unit: seed LUT plus Newton-Raphson `y' = y (3 - M y^2) / 2`.
//!
//! Used by the vector normalizer (Schilling 1997, "The Local Coordinate System": every frame
//! vector is `v / |v|`). The input integer `x` is reduced to a mantissa of `B =
//! rsqrt_mantissa_bits` significant bits (rounded by `rsqrt_rounding`, renormalized on carry),
//! written as `x = M * 2^(2k)` with `M` in `[1, 4)` (odd exponents put `M` in `[2, 4)`), so
//! `1/sqrt(x) = (1/sqrt(M)) * 2^-k` with `1/sqrt(M)` in `(1/2, 1]`.
//!
//! The seed LUT has `2^L` entries (`L = rsqrt_lut_bits`): the exponent parity and the top `L-1`
//! fraction bits of the mantissa; each entry is `1/sqrt` of its interval midpoint, rounded to
//! `B + 4` fraction bits. Newton-Raphson runs with `B + 4` fraction bits (each product rounded
//! by `rsqrt_rounding`), the result is rounded once to `B` fraction bits.
//!
//! ERROR BOUND (relative, against the exact `1/sqrt(x)`): with `e0 = 1.06 * 2^-(L+1)` (seed) and
//! `e(i+1) = 1.5 e(i)^2 + 0.5 e(i)^3 + 3 * 2^-(B+4)` (NR is quadratic and undershoots), the
//! result is within `e(iterations) + 2^-B` (output rounding, mantissa >= 1/2) `+ 2^-(B+1)`
//! (input rounding). texram16 (L=8, 1 iteration, B=24): measured max 5.72e-6 (2^-17.4), bound
//! 6.53e-6; exhaustive over all 2^23 mantissas x 2 parities in `tests/units/frames_rsqrt.rs`.

use crate::config::ConfigError;
use crate::cost::UnitCost;
use crate::datapath::Cycles;
use crate::datapath::{Component, Datapath, Stage};
use crate::fixed::{round_shift_right_wide, Rounding};
use serde::{Deserialize, Serialize};

/// Guard fraction bits carried inside the Newton-Raphson datapath beyond the mantissa.
pub const RSQRT_GUARD_BITS: u32 = 4;

/// Reciprocal square root unit configuration.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RsqrtConfig {
    /// Index bits of the seed LUT (2^bits entries; one bit is the exponent parity). 1..=16.
    pub rsqrt_lut_bits: u32,
    /// Newton-Raphson iterations after the LUT. 0..=4.
    pub rsqrt_iterations: u32,
    /// Significant bits of the input mantissa and fraction bits of the result mantissa. 8..=30.
    pub rsqrt_mantissa_bits: u32,
    /// Rounding of the input mantissa, of each product and of the result.
    pub rsqrt_rounding: Rounding,
    /// Cycles of the LUT lookup.
    pub rsqrt_lut_cycles: Cycles,
    /// Cycles per Newton-Raphson iteration (three multiplies and a subtract).
    pub rsqrt_cycles_per_iteration: Cycles,
}

impl RsqrtConfig {
    /// Texram-style default: 8-bit seed, one iteration, 24-bit mantissa.
    #[must_use]
    pub fn texram16() -> Self {
        Self {
            rsqrt_lut_bits: 8,
            rsqrt_iterations: 1,
            rsqrt_mantissa_bits: 24,
            rsqrt_rounding: Rounding::HalfEven,
            rsqrt_lut_cycles: Cycles::Derived,
            rsqrt_cycles_per_iteration: Cycles::Derived,
        }
    }

    /// Checks the widths; the error names the field.
    pub fn validate(&self) -> Result<(), ConfigError> {
        range("rsqrt.rsqrt_mantissa_bits", self.rsqrt_mantissa_bits, 8, 30)?;
        range(
            "rsqrt.rsqrt_lut_bits",
            self.rsqrt_lut_bits,
            1,
            16.min(self.rsqrt_mantissa_bits),
        )?;
        range("rsqrt.rsqrt_iterations", self.rsqrt_iterations, 0, 4)?;
        Ok(())
    }
}

pub(crate) fn range(field: &str, v: u32, lo: u32, hi: u32) -> Result<(), ConfigError> {
    if v < lo || v > hi {
        return Err(ConfigError {
            field: field.to_string(),
            what: format!("{v} is out of range {lo}..={hi}"),
        });
    }
    Ok(())
}

/// `1/sqrt(x) ~= mant * 2^-shift`, `mant` in `[2^(B-1), 2^B]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RsqrtOut {
    /// Result mantissa with `B` fraction bits, in `(1/2, 1]`.
    pub mant: u64,
    /// Total power-of-two scale: `B + k` where `x ~= M * 2^(2k)`.
    pub shift: i32,
}

/// The unit with its seed LUT built (once, from the config).
#[derive(Clone, Debug)]
pub struct Rsqrt {
    lut: Vec<u64>,
    lut_bits: u32,
    iterations: u32,
    bits: u32,
    rounding: Rounding,
}

/// Integer square root, floor, of a u128.
#[must_use]
pub fn isqrt_u128(n: u128) -> u128 {
    if n < 2 {
        return n;
    }
    let mut bit: u128 = 1 << ((127 - n.leading_zeros()) & !1);
    let (mut x, mut r) = (n, 0u128);
    while bit != 0 {
        if x >= r + bit {
            x -= r + bit;
            r = (r >> 1) + bit;
        } else {
            r >>= 1;
        }
        bit >>= 2;
    }
    r
}

impl Rsqrt {
    /// Builds the seed LUT. The config must have passed [`RsqrtConfig::validate`]; out-of-range
    /// fields are clamped into the supported range.
    #[must_use]
    pub fn new(cfg: &RsqrtConfig) -> Self {
        let bits = cfg.rsqrt_mantissa_bits.clamp(8, 30);
        let lut_bits = cfg.rsqrt_lut_bits.clamp(1, 16.min(bits));
        let w = bits + RSQRT_GUARD_BITS;
        let half = 1u64 << (lut_bits - 1);
        let mut lut = Vec::with_capacity(1usize << lut_bits);
        for p in 0..2u32 {
            for j in 0..half {
                // M_mid = (2^L + 2j + 1) * 2^(p - L); y = sqrt(2^(2w) / M_mid), rounded.
                let a = u128::from((1u64 << lut_bits) + 2 * j + 1);
                let num = (1u128 << (2 * w + lut_bits - p + 2)) / a;
                let r2 = isqrt_u128(num);
                lut.push(((r2 + 1) >> 1) as u64);
            }
        }
        Self {
            lut,
            lut_bits,
            iterations: cfg.rsqrt_iterations.min(4),
            bits,
            rounding: cfg.rsqrt_rounding,
        }
    }

    /// Mantissa bits `B` of this unit.
    #[must_use]
    pub fn mantissa_bits(&self) -> u32 {
        self.bits
    }

    /// `1/sqrt(x)` for an integer `x > 0`; `None` for `x = 0` (the caller decides the fallback).
    #[must_use]
    pub fn eval(&self, x: u64) -> Option<RsqrtOut> {
        if x == 0 {
            return None;
        }
        let b = self.bits;
        let mut e = 63 - x.leading_zeros() as i32;
        let mut m = if e + 1 > b as i32 {
            let s = (e + 1 - b as i32) as u32;
            round_shift_right_wide(i128::from(x), s, self.rounding) as u64
        } else {
            x << (b as i32 - 1 - e)
        };
        if m >= 1u64 << b {
            m >>= 1;
            e += 1;
        }
        Some(self.eval_mantissa(m, e))
    }

    /// Core: mantissa `m` in `[2^(B-1), 2^B)` (value `m / 2^(B-1)` in `[1, 2)`) times `2^e`.
    #[must_use]
    pub fn eval_mantissa(&self, m: u64, e: i32) -> RsqrtOut {
        let b = self.bits;
        let w = b + RSQRT_GUARD_BITS;
        let k = e.div_euclid(2);
        let p = (e - 2 * k) as u32;
        let l = self.lut_bits;
        let frac_idx = if l > 1 {
            (m >> (b - l)) & ((1u64 << (l - 1)) - 1)
        } else {
            0
        };
        let idx = ((p as usize) << (l - 1)) | frac_idx as usize;
        let mut y = i128::from(self.lut[idx]);
        let mw = i128::from(m) << (RSQRT_GUARD_BITS + 1 + p);
        let three = 3i128 << w;
        for _ in 0..self.iterations {
            let y2 = i128::from(round_shift_right_wide(y * y, w, self.rounding));
            let t = i128::from(round_shift_right_wide(mw * y2, w, self.rounding));
            y = i128::from(round_shift_right_wide(
                y * (three - t),
                w + 1,
                self.rounding,
            ));
        }
        let out = round_shift_right_wide(y, RSQRT_GUARD_BITS, self.rounding).clamp(1, 1i64 << b);
        RsqrtOut {
            mant: out as u64,
            shift: b as i32 + k,
        }
    }
}

/// Cost of one `1/sqrt`: one LUT read, then three multiplies and a subtract per iteration;
/// cycles from [`datapath`] at `gate_levels_per_cycle`.
#[must_use]
pub fn rsqrt_cost(cfg: &RsqrtConfig, gate_levels_per_cycle: u32) -> UnitCost {
    UnitCost {
        ops: 1 + 4 * cfg.rsqrt_iterations,
        cycles: datapath(cfg).latency(gate_levels_per_cycle),
        texels: 0,
    }
}

/// The unit's datapath (P = B + 4 working bits): normalize the input (leading-zero count,
/// even shift), the seed ROM (`rsqrt_lut_cycles`), per iteration `y^2`, `M y^2`, `3 - .`,
/// `y (.) / 2` (`rsqrt_cycles_per_iteration`), the final rounding to B bits.
#[must_use]
pub fn datapath(cfg: &RsqrtConfig) -> Datapath {
    let b = cfg.rsqrt_mantissa_bits;
    let w = b + RSQRT_GUARD_BITS + 2;
    Datapath::new()
        .stage(
            Stage::new("normalize")
                .then(Component::LeadingZeros { width: 64 })
                .then(Component::Shifter {
                    width: b,
                    shift_bits: 6,
                })
                .then(Component::Adder { width: b }),
        )
        .stage(
            Stage::new("seed ROM")
                .then(Component::Rom {
                    addr_bits: cfg.rsqrt_lut_bits,
                    data_bits: w,
                })
                .cycles(cfg.rsqrt_lut_cycles),
        )
        .stage(
            Stage::new("Newton-Raphson step")
                .then(Component::Multiplier { a: w, b: w })
                .then(Component::Multiplier { a: w, b: w })
                .then(Component::Adder { width: w + 1 })
                .then(Component::Multiplier { a: w, b: w + 1 })
                .times(cfg.rsqrt_iterations)
                .cycles(cfg.rsqrt_cycles_per_iteration),
        )
        .stage(
            Stage::new("round")
                .then(Component::Adder { width: b + 1 })
                .then(Component::Register { bits: b + 1 + 8 }),
        )
}
