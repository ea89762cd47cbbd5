//! Specular exponentiation `x^n` for the Blinn-Phong term `(n . h)^n` (Blinn 1977), as fixed
//! hardware does it: log2/exp2 tables or repeated squaring.
//!
//! Input `x` and output: unsigned normalized with `P = pow_frac_bits` fraction bits (raw in
//! `[0, 2^P]`, 2^P = 1.0); exponent `n`: integer in `[0, 2^pow_exponent_bits)`.
//! Internally `G = P + pow_guard_bits` fraction bits.
//!
//! - `log-exp`: `x = mant * 2^e`, `log2(mant)` from a `2^L + 1` entry table (`L = pow_lut_bits`,
//!   entries rounded to G bits) with linear interpolation on the next `P` mantissa bits;
//!   `y = n * log2(x)` exactly; `2^frac(y)` from a second `2^L + 1` entry table with linear
//!   interpolation; the integer part of `y` is a shift, rounded once to P bits.
//!   ERROR BOUND (absolute): `x^n * (2^(n (0.1803 * 2^-2L + 2^-G)) - 1) + x^n * (0.0601 *
//!   2^-2L + 2^-G) + 2^-(P+1)` (to first order the first term is `x^n n ln2 (0.1803 2^-2L +
//!   2^-G)`; interpolation error of log2 is `h^2 / (8 ln2)`, of 2^x `h^2 ln2^2 / 8`).
//! - `squaring`: left-to-right binary exponentiation on G-bit values, each product rounded by
//!   `pow_rounding`; ERROR BOUND (absolute): `2 n 2^-G + 2^-(P+1)`.
//!
//! In both bounds the output's rounding `2^-(P+1)` is `2^-P` for `Truncate`. Both measured
//! against the exact power of the quantized input in `tests/units/frames_pow.rs` (every
//! exponent 1..=2047 that texram16's 11 bits hold, 600 inputs each, every rounding mode: 3.7M
//! cases per method): texram16 log-exp max 19.6 ulp of 2^-16 (21.5 truncating; L = 8),
//! squaring max 2.8 ulp (4.4 truncating; 8 guard bits); the test asserts exactly the bounds
//! above (ratio <= 1; the log-exp ratio reaches 1.000 where the final rounding dominates).
//! Exponents up to 1024 measured 15.6 and 1.7 ulp (2.1 ulp log-exp at L = 10).

use crate::config::ConfigError;
use crate::cost::UnitCost;
use crate::datapath::{Component, Cycles, Datapath, Stage};
use crate::fixed::{round_shift_right_wide, Rounding, SatCounter};
use crate::rsqrt::{isqrt_u128, range};
use serde::{Deserialize, Serialize};

/// Exponentiation method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PowMethod {
    /// log2 table, multiply, exp2 table (any exponent, constant time).
    LogExp,
    /// Repeated squaring (integer exponents, time grows with the exponent's bit count).
    Squaring,
}

/// Power unit configuration.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PowConfig {
    /// Which algorithm.
    pub pow_method: PowMethod,
    /// Index bits of the log2 and exp2 tables (2^bits + 1 entries each). 2..=14.
    pub pow_lut_bits: u32,
    /// Fraction bits of the input and output (unsigned normalized). 8..=24.
    pub pow_frac_bits: u32,
    /// Guard bits carried internally beyond `pow_frac_bits`. 0..=16.
    pub pow_guard_bits: u32,
    /// Exponent width: exponents are in `[0, 2^bits)`; larger ones saturate. 1..=16.
    pub pow_exponent_bits: u32,
    /// Rounding of every internal product and of the result.
    pub pow_rounding: Rounding,
    /// Cycles per table lookup-and-interpolate (log-exp: two of them).
    pub pow_lut_cycles: Cycles,
    /// Cycles per multiply (log-exp: one; squaring: up to 2 * exponent_bits - 1).
    pub pow_mul_cycles: Cycles,
}

impl PowConfig {
    /// Texram-style default: log-exp tables of 2^8 + 1 entries, 16-bit unorm, 8 guard bits,
    /// exponents up to 2047.
    #[must_use]
    pub fn texram16() -> Self {
        Self {
            pow_method: PowMethod::LogExp,
            pow_lut_bits: 8,
            pow_frac_bits: 16,
            pow_guard_bits: 8,
            pow_exponent_bits: 11,
            pow_rounding: Rounding::HalfEven,
            pow_lut_cycles: Cycles::Derived,
            pow_mul_cycles: Cycles::Derived,
        }
    }

    /// Checks the widths; the error names the field.
    pub fn validate(&self) -> Result<(), ConfigError> {
        range("pow.pow_lut_bits", self.pow_lut_bits, 2, 14)?;
        range("pow.pow_frac_bits", self.pow_frac_bits, 8, 24)?;
        range("pow.pow_guard_bits", self.pow_guard_bits, 0, 16)?;
        range("pow.pow_exponent_bits", self.pow_exponent_bits, 1, 16)?;
        if self.pow_lut_bits > self.pow_frac_bits + self.pow_guard_bits {
            return Err(ConfigError {
                field: "pow.pow_lut_bits".into(),
                what: "must not exceed pow_frac_bits + pow_guard_bits".into(),
            });
        }
        Ok(())
    }
}

const ONE62: u128 = 1u128 << 62;

/// `log2(v / 2^62)` for `v` in `[2^62, 2^63)`, as a 62-fraction-bit value (bit-serial squaring).
fn log2_frac62(v: u128) -> u128 {
    let mut m = v;
    let mut out = 0u128;
    for i in (0..62).rev() {
        m = (m * m) >> 62;
        if m >= 2 * ONE62 {
            m >>= 1;
            out |= 1u128 << i;
        }
    }
    out
}

/// The unit with its tables built (once, from the config).
#[derive(Clone, Debug)]
pub struct Pow {
    log_t: Vec<i64>,
    exp_t: Vec<i64>,
    cfg: PowConfig,
    g: u32,
}

impl Pow {
    /// Builds the log2 and exp2 tables. The config should have passed [`PowConfig::validate`];
    /// out-of-range fields are clamped.
    #[must_use]
    pub fn new(cfg: &PowConfig) -> Self {
        let mut cfg = cfg.clone();
        cfg.pow_lut_bits = cfg.pow_lut_bits.clamp(2, 14);
        cfg.pow_frac_bits = cfg.pow_frac_bits.clamp(8, 24);
        cfg.pow_guard_bits = cfg.pow_guard_bits.min(16);
        cfg.pow_exponent_bits = cfg.pow_exponent_bits.clamp(1, 16);
        cfg.pow_lut_bits = cfg.pow_lut_bits.min(cfg.pow_frac_bits + cfg.pow_guard_bits);
        let l = cfg.pow_lut_bits;
        let g = cfg.pow_frac_bits + cfg.pow_guard_bits;
        let n = 1usize << l;
        let rnd = |x: u128| round_shift_right_wide(x as i128, 62 - g, Rounding::HalfEven);
        let log_t = (0..=n)
            .map(|j| {
                if j == n {
                    1i64 << g
                } else {
                    rnd(log2_frac62(ONE62 + ((j as u128) << (62 - l))))
                }
            })
            .collect();
        // r[b] = 2^(2^b / 2^L) with 62 fraction bits, by repeated square roots of 2.
        let mut roots = vec![0u128; l as usize + 1];
        roots[l as usize] = 2 * ONE62;
        for b in (0..l as usize).rev() {
            roots[b] = isqrt_u128(roots[b + 1] << 62);
        }
        let exp_t = (0..=n)
            .map(|j| {
                let mut acc = ONE62;
                for (b, r) in roots.iter().enumerate().take(l as usize + 1) {
                    if (j >> b) & 1 == 1 {
                        acc = (acc * r) >> 62;
                    }
                }
                rnd(acc)
            })
            .collect();
        Self {
            log_t,
            exp_t,
            cfg,
            g,
        }
    }

    /// The (clamped) configuration in use.
    #[must_use]
    pub fn config(&self) -> &PowConfig {
        &self.cfg
    }

    /// `x^n`, `x` raw unorm with `pow_frac_bits` (values above 1.0 saturate to 1.0, counted),
    /// `n` below `2^pow_exponent_bits` (larger saturates, counted). `x^0 = 1` (also for x = 0).
    #[must_use]
    pub fn pow(&self, x: u64, n: u32, sat: &mut SatCounter) -> u64 {
        let p = self.cfg.pow_frac_bits;
        let one = 1u64 << p;
        let mut x = x;
        if x > one {
            sat.saturated += 1;
            x = one;
        }
        let mut n = n;
        let nmax = (1u64 << self.cfg.pow_exponent_bits) - 1;
        if u64::from(n) > nmax {
            sat.saturated += 1;
            n = nmax as u32;
        }
        if n == 0 {
            return one;
        }
        if x == 0 {
            return 0;
        }
        match self.cfg.pow_method {
            PowMethod::LogExp => self.log_exp(x, n),
            PowMethod::Squaring => self.squaring(x, n),
        }
    }

    fn lerp(&self, t: &[i64], idx: usize, w: i64, wbits: u32) -> i64 {
        let (a, b) = (t[idx], t[idx + 1]);
        a + round_shift_right_wide(
            i128::from(b - a) * i128::from(w),
            wbits,
            self.cfg.pow_rounding,
        )
    }

    fn log_exp(&self, x: u64, n: u32) -> u64 {
        let (p, g, l) = (self.cfg.pow_frac_bits, self.g, self.cfg.pow_lut_bits);
        let e = 63 - x.leading_zeros();
        // Mantissa fraction with 62 bits: x = (1 + mf/2^62) * 2^(e - P).
        let mf = (u128::from(x) << (62 - e)) & (ONE62 - 1);
        let idx = (mf >> (62 - l)) as usize;
        let w = ((mf >> (62 - l - p)) & ((1u128 << p) - 1)) as i64;
        let lg_frac = self.lerp(&self.log_t, idx, w, p);
        let lg = ((i64::from(e as i32) - i64::from(p)) << g) + lg_frac;
        let y = lg * i64::from(n);
        if y <= -((i64::from(p) + 2) << g) {
            return 0;
        }
        let q = y.div_euclid(1i64 << g);
        let r = y.rem_euclid(1i64 << g);
        let ridx = (r >> (g - l)) as usize;
        let rw = r & ((1i64 << (g - l)) - 1);
        let ex = self.lerp(&self.exp_t, ridx, rw, g - l);
        let sh = (i64::from(g) - i64::from(p) - q) as u32;
        let out = round_shift_right_wide(i128::from(ex), sh, self.cfg.pow_rounding);
        out.clamp(0, 1i64 << p) as u64
    }

    fn squaring(&self, x: u64, n: u32) -> u64 {
        let (p, g) = (self.cfg.pow_frac_bits, self.g);
        let rnd = self.cfg.pow_rounding;
        let b = i128::from(x) << (g - p);
        let mut acc: i128 = 1i128 << g;
        for i in (0..32 - n.leading_zeros()).rev() {
            acc = i128::from(round_shift_right_wide(acc * acc, g, rnd));
            if (n >> i) & 1 == 1 {
                acc = i128::from(round_shift_right_wide(acc * b, g, rnd));
            }
        }
        round_shift_right_wide(acc, g - p, rnd).clamp(0, 1i64 << p) as u64
    }
}

/// Cost of one `x^n` (worst case over exponents for squaring: `2 * exponent_bits - 1`
/// multiplies; log-exp: two interpolated lookups and one multiply); cycles from [`datapath`].
#[must_use]
pub fn pow_cost(cfg: &PowConfig, gate_levels_per_cycle: u32) -> UnitCost {
    let ops = match cfg.pow_method {
        PowMethod::LogExp => 2 * 3 + 1,
        PowMethod::Squaring => 2 * cfg.pow_exponent_bits - 1,
    };
    UnitCost {
        ops,
        cycles: datapath(cfg).latency(gate_levels_per_cycle),
        texels: 0,
    }
}

/// The power unit (F = `pow_frac_bits`, G = `pow_guard_bits`, L = `pow_lut_bits`, E =
/// `pow_exponent_bits`). Log-exp: the log2 table with its linear interpolation
/// (`pow_lut_cycles`), the product with the exponent (`pow_mul_cycles`), the exp2 table with
/// its interpolation and the shift by the integer part (`pow_lut_cycles`). Squaring:
/// `2 E - 1` multiplies in series (`pow_mul_cycles` each).
#[must_use]
pub fn datapath(cfg: &PowConfig) -> Datapath {
    let (f, g, l, e) = (
        cfg.pow_frac_bits,
        cfg.pow_guard_bits,
        cfg.pow_lut_bits,
        cfg.pow_exponent_bits,
    );
    let w = f + g;
    let rest = f.saturating_sub(l).max(1);
    match cfg.pow_method {
        PowMethod::LogExp => Datapath::new()
            .stage(
                Stage::new("log2 table")
                    .then(Component::LeadingZeros { width: f + 1 })
                    .then(Component::Rom {
                        addr_bits: l,
                        data_bits: w,
                    })
                    .then(Component::Multiplier { a: w, b: rest })
                    .then(Component::Adder { width: w })
                    .cycles(cfg.pow_lut_cycles),
            )
            .stage(
                Stage::new("times exponent")
                    .then(Component::Multiplier { a: w + 6, b: e })
                    .then(Component::Adder { width: w + 6 })
                    .cycles(cfg.pow_mul_cycles),
            )
            .stage(
                Stage::new("exp2 table")
                    .then(Component::Rom {
                        addr_bits: l,
                        data_bits: w,
                    })
                    .then(Component::Multiplier { a: w, b: rest })
                    .then(Component::Adder { width: w })
                    .then(Component::Shifter {
                        width: f + 1,
                        shift_bits: 6,
                    })
                    .cycles(cfg.pow_lut_cycles),
            ),
        PowMethod::Squaring => Datapath::new().stage(
            Stage::new("multiply")
                .then(Component::Multiplier { a: w + 1, b: w + 1 })
                .then(Component::Adder { width: w + 1 })
                .times(2 * e - 1)
                .cycles(cfg.pow_mul_cycles),
        ),
    }
}
