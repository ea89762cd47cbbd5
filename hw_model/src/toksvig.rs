//! Toksvig's adjusted specular exponent (Toksvig 2005, "Mipmapping Normal Maps", eqs. 4-6):
//! the length `|Na|` of the MIP-mapped (trilinearly filtered, not renormalized) average unit
//! normal measures how much the normals under the footprint spread, and the Blinn-Phong
//! exponent `s` becomes
//!
//! `s' = |Na| s / (|Na| + s (1 - |Na|))`,
//!
//! with the specular colour scaled by `(1 + s') / (1 + s)` (the energy-conserving factor of the
//! paper's normalized Blinn-Phong lobe, applied to the un-normalized lobe the pipeline shades:
//! a wider lobe gets a lower peak). `s' = s` where `|Na| = 1` (a flat footprint), `s' -> 0` as
//! `|Na| -> 0`.
//!
//! Input: the three filtered channels `t_i` of the Toksvig map (raw unorm of `texel_bits`
//! `T`, `M = 2^T - 1`), each encoding `(n_i + 1) / 2`, so `2 t_i - M = M n_i` exactly.
//! The unit forms `Q = sum (2 t_i - M)^2 = M^2 |Na|^2` exactly, its square root `R ~ M |Na|`
//! correctly rounded to `toksvig_sqrt_bits` significant bits ([`crate::roughness::sqrt_round`],
//! the roughness unit's root), clamps `R <= M` (quantization can make `|Na|` exceed 1; each
//! clamp is counted), and divides once, exactly, rounding half even to an integer exponent
//! (the power unit takes integer exponents):
//!
//! `n' = round(R s / (R + s (M - R)))`, `ks' = round(ks (1 + n') / (1 + s))` (colour unorm).
//!
//! ERROR BOUND (against the float twin `texsim::shading::toksvig::toksvig_f` on the same
//! quantized texels, asserted in `tests/units/toksvig_unit.rs`): with `L = |Na|` and `s'` the exact
//! exponent, `ds'/dL = (s'/L)^2` and the root errs by at most `L 2^-B` (`B` =
//! `toksvig_sqrt_bits`, half an ulp of a `B`-bit mantissa), so
//! `|n' - s'| <= 1/2 + (s'/L)^2 L 2^-B (1 + 2^(1-B))` (plus the effect of the clamp where `R`
//! rounds above `M`), and the scale errs by at most `|n' - s'| / (1 + s)` plus half an LSB.

use crate::config::ConfigError;
use crate::cost::UnitCost;
use crate::datapath::{Component, Cycles, Datapath, Stage};
use crate::fixed::{round_div_wide, Rounding, SatCounter};
use crate::roughness::sqrt_round;
use crate::rsqrt::range;
use serde::{Deserialize, Serialize};

/// Toksvig unit configuration.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ToksvigConfig {
    /// Significant bits of the root `R ~ M |Na|`. 4..=30.
    pub toksvig_sqrt_bits: u32,
    /// Quotient bits the exponent divider produces per cycle. 1..=8.
    pub toksvig_div_bits_per_cycle: u32,
    /// Cycles of the multiplier stages.
    pub toksvig_mul_cycles: Cycles,
}

impl ToksvigConfig {
    /// Texram-style default: a 16-bit root, radix-4 divider, derived cycles.
    #[must_use]
    pub fn texram16() -> Self {
        Self {
            toksvig_sqrt_bits: 16,
            toksvig_div_bits_per_cycle: 2,
            toksvig_mul_cycles: Cycles::Derived,
        }
    }

    /// Checks the ranges; the error names the field.
    pub fn validate(&self) -> Result<(), ConfigError> {
        range("toksvig.toksvig_sqrt_bits", self.toksvig_sqrt_bits, 4, 30)?;
        range(
            "toksvig.toksvig_div_bits_per_cycle",
            self.toksvig_div_bits_per_cycle,
            1,
            8,
        )?;
        Ok(())
    }
}

impl Default for ToksvigConfig {
    fn default() -> Self {
        Self::texram16()
    }
}

/// What the unit produces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ToksvigOut {
    /// The adjusted integer exponent `n'` (at most `s`).
    pub exponent: u32,
    /// The scaled specular colour `ks (1 + n') / (1 + s)` (unorm, the input's width).
    pub ks: [u32; 3],
    /// `M |Na|` as the unit saw it: the rounded root `mant * 2^exp`, clamped to `M`.
    pub root_mant: u64,
    pub root_exp: i32,
}

/// The unit: `texels` the filtered Toksvig map (unorm, `texel_bits`), `shininess` the base
/// exponent `s`, `ks` the specular colour (unorm, `color_bits`). A clamp of `|Na|` to 1 is
/// counted in `sat`. `s = 0` gives `n' = 0` and `ks` unchanged.
#[must_use]
pub fn toksvig(
    texels: [u32; 3],
    texel_bits: u32,
    shininess: u32,
    ks: [u32; 3],
    color_bits: u32,
    cfg: &ToksvigConfig,
    sat: &mut SatCounter,
) -> ToksvigOut {
    let tb = texel_bits.clamp(1, 16);
    let m = (1i64 << tb) - 1;
    let q: u128 = texels
        .iter()
        .map(|&t| {
            let c = 2 * i64::from(t).min(m) - m;
            (c * c) as u128
        })
        .sum();
    let s = i128::from(shininess);
    if shininess == 0 {
        return ToksvigOut {
            exponent: 0,
            ks,
            root_mant: 0,
            root_exp: 0,
        };
    }
    // R = mant 2^e (0 for a zero mean), clamped to M.
    let (mut mant, mut e) = if q == 0 {
        (0u64, 0i32)
    } else {
        sqrt_round(q, cfg.toksvig_sqrt_bits)
    };
    let above = if e >= 0 {
        i128::from(mant) << e as u32 > i128::from(m)
    } else {
        i128::from(mant) > i128::from(m) << (-e) as u32
    };
    if above {
        sat.saturated += 1;
        mant = m as u64;
        e = 0;
    }
    // n' = R s / (R + s (M - R)); with R = mant 2^e, scale numerator and denominator by
    // 2^-e when e < 0 so both are integers.
    let (r, mm) = if e >= 0 {
        (i128::from(mant) << e as u32, i128::from(m))
    } else {
        (i128::from(mant), i128::from(m) << (-e) as u32)
    };
    let num = r * s;
    let den = r + s * (mm - r);
    let exponent = if den <= 0 {
        shininess
    } else {
        (round_div_wide(num, den, Rounding::HalfEven).clamp(0, i64::from(shininess))) as u32
    };
    let cmax = (1i128 << color_bits.clamp(1, 16)) - 1;
    let ks = ks.map(|k| {
        let k = i128::from(k).min(cmax);
        round_div_wide(k * (1 + i128::from(exponent)), 1 + s, Rounding::HalfEven) as u32
    });
    ToksvigOut {
        exponent,
        ks,
        root_mant: mant,
        root_exp: e,
    }
}

/// Cost of one evaluation: three squares and their sum, the root, the two multiplies and the
/// divide of the exponent, three colour multiplies and divides; cycles from [`datapath`].
#[must_use]
pub fn toksvig_cost(cfg: &ToksvigConfig, texel_bits: u32, gate_levels_per_cycle: u32) -> UnitCost {
    UnitCost {
        ops: 3 + 2 + 1 + 3 + 1 + 6,
        cycles: datapath(cfg, texel_bits).latency(gate_levels_per_cycle),
        texels: 0,
    }
}

/// The unit's datapath: squares of the three centred channels and their sum; the digit-serial
/// root (`toksvig_sqrt_bits / 2` steps of a radix-4 root, as the roughness unit's); the
/// exponent's numerator and denominator (two multiplies, an adder), its divide (digit-serial,
/// `16 / toksvig_div_bits_per_cycle` steps for a 16-bit exponent); the three colour scalings.
#[must_use]
pub fn datapath(cfg: &ToksvigConfig, texel_bits: u32) -> Datapath {
    let t = texel_bits.clamp(1, 16) + 1;
    let b = cfg.toksvig_sqrt_bits;
    let w = 2 * t + 2;
    let div_steps = 16u32.div_ceil(cfg.toksvig_div_bits_per_cycle.max(1));
    Datapath::new()
        .stage(
            Stage::new("squares")
                .then_n(3, Component::Multiplier { a: t, b: t })
                .then(Component::Adder { width: w })
                .then(Component::Register { bits: w })
                .cycles(cfg.toksvig_mul_cycles),
        )
        .stage(
            Stage::new("square-root step")
                .then(Component::Adder { width: b + 2 })
                .then(Component::Mux {
                    width: b + 2,
                    inputs: 2,
                })
                .then(Component::Register { bits: b + 2 })
                .times(b.div_ceil(2)),
        )
        .stage(
            Stage::new("exponent terms")
                .then_n(2, Component::Multiplier { a: b + 1, b: 16 })
                .then(Component::Adder { width: b + 17 })
                .then(Component::Register { bits: 2 * (b + 17) })
                .cycles(cfg.toksvig_mul_cycles),
        )
        .stage(
            Stage::new("exponent divide step")
                .then(Component::Adder { width: b + 17 })
                .then(Component::Mux {
                    width: b + 17,
                    inputs: 3,
                })
                .then(Component::Register { bits: b + 17 })
                .times(div_steps),
        )
        .stage(
            Stage::new("specular scale")
                .then_n(3, Component::Multiplier { a: 16, b: 17 })
                .then_n(3, Component::Multiplier { a: 33, b: 17 })
                .then(Component::Register { bits: 48 })
                .cycles(cfg.toksvig_mul_cycles),
        )
}
