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
//! (input rounding), for the nearest modes; `Truncate` rounds the input and every product
//! down, one-sided errors that add up to at most 1.5 times that bound. texram16 (L=8, 1
//! iteration, B=24): measured max 5.72e-6 (2^-17.4), bound 6.53e-6; exhaustive over all 2^23
//! mantissas x 2 parities, and 400k seeded inputs per rounding mode (`Truncate` against the 1.5
//! times), in `tests/units/frames_rsqrt.rs`.

use crate::config::ConfigError;
use crate::cost::UnitCost;
use crate::datapath::Cycles;
use crate::datapath::{Component, Datapath, Stage};
use crate::fixed::{
    round_shift_right_mid, round_shift_right_wide, ConstRounding, Rounding, ShiftRound,
};
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
                // `r2`, the root with one more fraction bit, is below 2^36 (w <= 34).
                let r2 = isqrt_u128(num) as i128;
                lut.push(round_shift_right_wide(r2, 1, Rounding::HalfUp) as u64);
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
        crate::with_rounding!(self.rounding, M => Some(self.eval_in::<M>(x)))
    }

    /// [`Rsqrt::eval`] of `x > 0` compiled for the rounding mode `M` (`rsqrt_rounding`).
    #[inline(always)]
    fn eval_in<M: ConstRounding>(&self, x: u64) -> RsqrtOut {
        let b = self.bits;
        let mut e = 63 - x.leading_zeros() as i32;
        let mut m = if e + 1 > b as i32 {
            let s = (e + 1 - b as i32) as u32;
            // Below 2^63 the 64-bit rounding is the 128-bit one of the same value.
            match i64::try_from(x) {
                Ok(x) => round_shift_right_mid::<M>(x, s) as u64,
                Err(_) => round_shift_right_wide(i128::from(x), s, M::MODE) as u64,
            }
        } else {
            x << (b as i32 - 1 - e)
        };
        if m >= 1u64 << b {
            m >>= 1;
            e += 1;
        }
        self.eval_mantissa_in::<M>(m, e)
    }

    /// Core: mantissa `m` in `[2^(B-1), 2^B)` (value `m / 2^(B-1)` in `[1, 2)`) times `2^e`.
    #[must_use]
    pub fn eval_mantissa(&self, m: u64, e: i32) -> RsqrtOut {
        crate::with_rounding!(self.rounding, M => self.eval_mantissa_in::<M>(m, e))
    }

    /// [`Rsqrt::eval_mantissa`] compiled for the rounding mode `M`. The iterate `y`, `y^2` and
    /// `M y^2` are reductions (saturated to `i64`), so only the products need more: each
    /// Newton-Raphson step runs in `i64` with the rounding resolved ([`ShiftRound`]) when its
    /// three products stay below 2^62 in magnitude (texram16's 28-bit datapath always does),
    /// else in `i128` ([`newton_step_wide`]); the same bits either way (checked against the
    /// all-`i128` step by `narrow_steps_match_the_wide_step`).
    #[inline(always)]
    fn eval_mantissa_in<M: ConstRounding>(&self, m: u64, e: i32) -> RsqrtOut {
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
        // Seeds are below 2^(w + 1), mantissas below 2^30 shifted by at most 6, and w <= 34.
        let mut y = self.lut[idx] as i64;
        let mw = (m as i64) << (RSQRT_GUARD_BITS + 1 + p);
        let three = 3i64 << w;
        let rounds = ShiftRound::<M>::new(w).zip(ShiftRound::<M>::new(w + 1));
        for _ in 0..self.iterations {
            y = rounds
                .as_ref()
                .and_then(|r| newton_step_narrow(y, mw, three, r))
                .unwrap_or_else(|| newton_step_wide(y, mw, three, w, M::MODE));
        }
        let out = round_shift_right_mid::<M>(y, RSQRT_GUARD_BITS).clamp(1, 1i64 << b);
        RsqrtOut {
            mant: out as u64,
            shift: b as i32 + k,
        }
    }
}

/// One Newton-Raphson step `y (3 - M y^2) / 2` of the unit's datapath (`w` fraction bits, each
/// product rounded by `mode`), with exact 128-bit products.
fn newton_step_wide(y: i64, mw: i64, three: i64, w: u32, mode: Rounding) -> i64 {
    let y2 = i128::from(round_shift_right_wide(
        i128::from(y) * i128::from(y),
        w,
        mode,
    ));
    let t = i128::from(round_shift_right_wide(i128::from(mw) * y2, w, mode));
    round_shift_right_wide(i128::from(y) * (i128::from(three) - t), w + 1, mode)
}

/// [`newton_step_wide`] in `i64` with the roundings by `w` and `w + 1` resolved, when every
/// product is below 2^62 in magnitude ([`ShiftRound::apply`]'s range); `None` otherwise.
#[inline(always)]
fn newton_step_narrow<M: ConstRounding>(
    y: i64,
    mw: i64,
    three: i64,
    (r_w, r_w1): &(ShiftRound<M>, ShiftRound<M>),
) -> Option<i64> {
    let small = |v: i64| (v.unsigned_abs() >> 62 == 0).then_some(v);
    let y2 = r_w.apply(small(y.checked_mul(y)?)?);
    let t = r_w.apply(small(mw.checked_mul(y2)?)?);
    Some(r_w1.apply(small(y.checked_mul(three.checked_sub(t)?)?)?))
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixed::{HalfEvenMode, HalfUpMode, TruncateMode};
    use crate::test_rng::splitmix64 as next;

    const MODES: [Rounding; 3] = [Rounding::Truncate, Rounding::HalfUp, Rounding::HalfEven];

    /// [`Rsqrt::eval_mantissa`] as first written, every product in `i128` and the mode
    /// branched at each rounding: the oracle.
    fn eval_mantissa_before(u: &Rsqrt, m: u64, e: i32) -> RsqrtOut {
        let b = u.bits;
        let w = b + RSQRT_GUARD_BITS;
        let k = e.div_euclid(2);
        let p = (e - 2 * k) as u32;
        let l = u.lut_bits;
        let frac_idx = if l > 1 {
            (m >> (b - l)) & ((1u64 << (l - 1)) - 1)
        } else {
            0
        };
        let idx = ((p as usize) << (l - 1)) | frac_idx as usize;
        let mut y = i128::from(u.lut[idx]);
        let mw = i128::from(m) << (RSQRT_GUARD_BITS + 1 + p);
        let three = 3i128 << w;
        for _ in 0..u.iterations {
            let y2 = i128::from(round_shift_right_wide(y * y, w, u.rounding));
            let t = i128::from(round_shift_right_wide(mw * y2, w, u.rounding));
            y = i128::from(round_shift_right_wide(y * (three - t), w + 1, u.rounding));
        }
        let out = round_shift_right_wide(y, RSQRT_GUARD_BITS, u.rounding).clamp(1, 1i64 << b);
        RsqrtOut {
            mant: out as u64,
            shift: b as i32 + k,
        }
    }

    fn unit(bits: u32, lut_bits: u32, iterations: u32, rounding: Rounding) -> Rsqrt {
        Rsqrt::new(&RsqrtConfig {
            rsqrt_lut_bits: lut_bits.min(bits),
            rsqrt_iterations: iterations,
            rsqrt_mantissa_bits: bits,
            rsqrt_rounding: rounding,
            ..RsqrtConfig::texram16()
        })
    }

    /// The unit with its steps in `i64` where they fit against [`eval_mantissa_before`]:
    /// every mantissa and parity of texram16 (2^24 cases) and of every mantissa width up to 12
    /// bits with seed widths 1, 4 and 8 and 0 to 4 iterations in every mode; 2M seeded
    /// mantissas of widths 13 to 30 (beyond 25 bits the products leave `i64` and the steps
    /// take the 128-bit path) over seed widths, iterations and modes.
    #[test]
    fn narrow_steps_match_the_wide_step() {
        let check = |u: &Rsqrt, m: u64, e: i32| {
            assert_eq!(
                u.eval_mantissa(m, e),
                eval_mantissa_before(u, m, e),
                "m {m} e {e} B {} L {} it {} {:?}",
                u.bits,
                u.lut_bits,
                u.iterations,
                u.rounding
            );
        };
        let texram = Rsqrt::new(&RsqrtConfig::texram16());
        for e in [0, 1] {
            for m in 1u64 << 23..1 << 24 {
                check(&texram, m, e);
            }
        }
        for bits in 8..=12 {
            for lut_bits in [1, 4, 8] {
                for iterations in 0..=4 {
                    for mode in MODES {
                        let u = unit(bits, lut_bits, iterations, mode);
                        for e in [-3, 0, 1, 6] {
                            for m in 1u64 << (bits - 1)..1 << bits {
                                check(&u, m, e);
                            }
                        }
                    }
                }
            }
        }
        let mut s = 0x5eed_0a51;
        for i in 0..1000u32 {
            let bits = 13 + (next(&mut s) % 18) as u32;
            let lut_bits = 1 + (next(&mut s) % 16) as u32;
            let u = unit(bits, lut_bits, i % 5, MODES[(i / 5 % 3) as usize]);
            for _ in 0..2000 {
                let m = (1u64 << (bits - 1)) | (next(&mut s) & ((1u64 << (bits - 1)) - 1));
                check(&u, m, (next(&mut s) % 64) as i32 - 32);
            }
        }
    }

    /// [`Rsqrt::eval`] (its mantissa rounded in 64 bits below 2^63) against the reduction as
    /// first written (in `i128`) followed by [`Rsqrt::eval_mantissa`]: 2M seeded inputs of
    /// every bit length 1 to 64 over mantissa widths, seed widths and modes, and the ends.
    #[test]
    fn eval_reduces_as_the_wide_rounding() {
        let before = |u: &Rsqrt, x: u64| {
            let b = u.bits;
            let mut e = 63 - x.leading_zeros() as i32;
            let mut m = if e + 1 > b as i32 {
                let s = (e + 1 - b as i32) as u32;
                round_shift_right_wide(i128::from(x), s, u.rounding) as u64
            } else {
                x << (b as i32 - 1 - e)
            };
            if m >= 1u64 << b {
                m >>= 1;
                e += 1;
            }
            u.eval_mantissa(m, e)
        };
        let mut s = 0x5eed_e7a1;
        for i in 0..400u32 {
            let bits = 8 + (next(&mut s) % 23) as u32;
            let lut_bits = 1 + (next(&mut s) % 8) as u32;
            let u = unit(bits, lut_bits, i % 5, MODES[(i / 5 % 3) as usize]);
            let ends = [
                1,
                2,
                3,
                (1 << 62) - 1,
                1 << 62,
                (1 << 63) - 1,
                1 << 63,
                u64::MAX,
            ];
            for x in ends {
                assert_eq!(u.eval(x), Some(before(&u, x)), "x {x} B {bits}");
            }
            for _ in 0..5000 {
                let len = 1 + next(&mut s) % 64;
                let x = (next(&mut s) >> (64 - len)) | 1 << (len - 1);
                assert_eq!(u.eval(x), Some(before(&u, x)), "x {x} B {bits}");
            }
        }
    }

    /// [`newton_step_narrow`] against [`newton_step_wide`] on 3M seeded iterates, mantissas
    /// and widths, from small to beyond `i64` (where it answers `None`): the same step
    /// whenever it answers, and an answer whenever the products are below 2^62.
    #[test]
    fn newton_step_narrow_matches_newton_step_wide() {
        fn case<M: ConstRounding>(y: i64, mw: i64, w: u32) -> bool {
            let three = 3i64 << w;
            let r = (
                ShiftRound::<M>::new(w).expect("w"),
                ShiftRound::<M>::new(w + 1).expect("w + 1"),
            );
            let wide = newton_step_wide(y, mw, three, w, M::MODE);
            match newton_step_narrow(y, mw, three, &r) {
                Some(v) => {
                    assert_eq!(v, wide, "y {y} mw {mw} w {w} {:?}", M::MODE);
                    true
                }
                None => {
                    let y = i128::from(y);
                    let y2 = i128::from(round_shift_right_wide(y * y, w, M::MODE));
                    let t = i128::from(round_shift_right_wide(i128::from(mw) * y2, w, M::MODE));
                    let widest = [y * y, i128::from(mw) * y2, y * (i128::from(three) - t)]
                        .map(i128::unsigned_abs)
                        .into_iter()
                        .max();
                    assert!(
                        widest >= Some(1 << 62),
                        "y {y} mw {mw} w {w}: refused with products below 2^62"
                    );
                    false
                }
            }
        }
        let mut s = 0x5eed_0a52;
        let (mut narrow, mut wide) = (0u32, 0u32);
        for i in 0..3_000_000u32 {
            let w = 12 + (next(&mut s) % 23) as u32;
            let y = (next(&mut s) >> (next(&mut s) % 64)) as i64 * if i % 2 == 0 { 1 } else { -1 };
            let y = y >> (i % 40);
            let mw = (next(&mut s) >> (28 + next(&mut s) % 36)) as i64;
            let took = match i % 3 {
                0 => case::<TruncateMode>(y, mw, w),
                1 => case::<HalfUpMode>(y, mw, w),
                _ => case::<HalfEvenMode>(y, mw, w),
            };
            if took {
                narrow += 1;
            } else {
                wide += 1;
            }
        }
        assert!(narrow > 500_000 && wide > 500_000, "{narrow} {wide}");
    }
}
