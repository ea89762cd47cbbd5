//! Reflection-vector unit: `r = 2 (n . v) n - v` for the (perturbed) unit normal `n` and the
//! unit vector `v` towards the eye (Blinn & Newell 1976; the environment-map lookup of
//! Schilling 1997, "balanced system"; OpenGL 4.6 eq. 12.6 with `v = -u`).
//!
//! Datapath (F = `vector_frac_bits`, R = `reflect_bits`): `n . v` exact (2F fraction bits),
//! then per component `2 (n . v) n_i - v_i 2^(2F)` exact (3F fraction bits), one rounding to
//! signed 1.R (`env_rounding`, saturating, counted). No normalization: for unit inputs
//! `|r| = 1` up to the inputs' quantization, and the cube-face unit divides by the major axis,
//! so the scale of `r` does not matter.
//!
//! ERROR BOUND per component, against the exact `2 (n . v) n - v` of the given raw inputs:
//! at most 1/2 ulp of 1.R (`2^-(R+1)`; < 1 ulp for `Truncate`), unless saturated (possible
//! only when `|r_i| >= 2`, i.e. for inputs far from unit length). Tested in
//! `tests/units/env_units.rs` over 10^7 seeded random pairs and the hard cases (normal
//! parallel to the view, grazing views).

use crate::cost::UnitCost;
use crate::datapath::{Component, Datapath, Stage};
use crate::env_config::EnvConfig;
use crate::fixed::{round_shift_right_wide, Format, SatCounter};
use crate::vector::{dot3_exact, Vec3x, VectorConfig};

/// The reflection-vector format: signed 1.R, saturating.
#[must_use]
pub fn reflect_format(cfg: &EnvConfig) -> Format {
    Format::signed(1, cfg.reflect_bits, cfg.env_rounding)
}

/// `2 (n . v) n - v` of vector-format `n`, `v` (s1.F), in reflect format (s1.R).
#[must_use]
pub fn reflect(
    n: &Vec3x,
    v: &Vec3x,
    vcfg: &VectorConfig,
    cfg: &EnvConfig,
    sat: &mut SatCounter,
) -> Vec3x {
    let f = vcfg.vector_frac_bits;
    let r = cfg.reflect_bits;
    let d = dot3_exact(n, v);
    let fmt = reflect_format(cfg);
    let mut out = [0i64; 3];
    for i in 0..3 {
        let acc = 2 * d * i128::from(n[i]) - (i128::from(v[i]) << (2 * f));
        let q = if 3 * f >= r {
            round_shift_right_wide(acc, 3 * f - r, cfg.env_rounding)
        } else {
            i64::try_from(acc << (r - 3 * f)).unwrap_or(i64::MAX)
        };
        out[i] = fmt.fit(q, sat);
    }
    out
}

/// Cost of one reflection: 6 multiplies, 5 adds; cycles from [`datapath`].
#[must_use]
pub fn reflect_cost(vcfg: &VectorConfig, cfg: &EnvConfig, gate_levels_per_cycle: u32) -> UnitCost {
    UnitCost {
        ops: 11,
        cycles: datapath(vcfg, cfg).latency(gate_levels_per_cycle),
        texels: 0,
    }
}

/// The reflection unit (`reflect_cycles`; V = F + 2 bits per vector component): the dot
/// product's three products and two adds, then three products `(n . v) n_i` side by side,
/// three subtracts of `v_i` and the rounding to 1.R.
#[must_use]
pub fn datapath(vcfg: &VectorConfig, cfg: &EnvConfig) -> Datapath {
    let v = vcfg.vector_frac_bits + 2;
    let d = 2 * v + 2;
    Datapath::new().stage(
        Stage::new("reflect")
            .then_n(3, Component::Multiplier { a: v, b: v })
            .then(Component::Adder { width: 2 * v + 1 })
            .then(Component::Adder { width: d })
            .then_n(3, Component::Multiplier { a: d, b: v })
            .then_n(3, Component::Adder { width: d + v + 1 })
            .then_n(
                3,
                Component::Adder {
                    width: cfg.reflect_bits + 2,
                },
            )
            .cycles(cfg.reflect_cycles),
    )
}
