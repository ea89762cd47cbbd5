//! IEEE 754 binary32 division, bit-exact (0 ulp) against x86 SSE `divss` (the host's binary32 `/`)
//! for every operand pair, NaNs included (policy in [`crate::f32_pack`]): a 26-bit quotient
//! by restoring division, its remainder as the sticky bit, one rounding. Float twin: the
//! host's binary32 division. Tested on 10^7 seeded pairs plus boundary cases, and `1/x` over a
//! 2^24 slice of `x`, `tests/units/f32_units.rs`.

use crate::cost::UnitCost;
use crate::datapath::{Component, Datapath, Stage};
use crate::f32_pack::{classify, inf, quiet, round_pack, zero, Class, DEFAULT_NAN};

/// Quotient bits beyond the significand's 24: one guard bit and one round bit, after
/// normalizing both significands to 24 bits.
const EXTRA: u32 = 2;

/// `a / b`, encodings in and out.
#[must_use]
pub fn div(a: u32, b: u32) -> u32 {
    let neg = (a ^ b) >> 31 != 0;
    match (classify(a), classify(b)) {
        (Class::Nan(x), _) => quiet(x),
        (_, Class::Nan(y)) => quiet(y),
        (Class::Inf(_), Class::Inf(_)) | (Class::Zero(_), Class::Zero(_)) => DEFAULT_NAN,
        (Class::Inf(_), _) | (_, Class::Zero(_)) => inf(neg),
        (Class::Zero(_), _) | (_, Class::Inf(_)) => zero(neg),
        (Class::Finite(x), Class::Finite(y)) => {
            // Normalize both significands to exactly 24 bits (subnormals shift up).
            let nx = x.sig.leading_zeros() - 40;
            let ny = y.sig.leading_zeros() - 40;
            let (xs, ys) = (x.sig << nx, y.sig << ny);
            let (xe, ye) = (x.exp - nx as i32, y.exp - ny as i32);
            // xs / ys in (1/2, 2): shifted by 24 + EXTRA the quotient has 25 or 26 bits.
            let num = u128::from(xs) << (24 + EXTRA);
            let den = u128::from(ys);
            let q = num / den;
            let r = num % den;
            round_pack(neg, xe - ye - (24 + EXTRA) as i32, q, r != 0)
        }
    }
}

/// One division (`lp_build_rcp` is `1.0 / x` as a true division).
#[must_use]
pub fn div_cost(gate_levels_per_cycle: u32) -> UnitCost {
    crate::f32_pack::one_op_cost(&datapath(), gate_levels_per_cycle)
}

/// The float32 divider: 26 restoring steps (a 25-bit subtractor each) beside the exponent
/// subtractor, then [`crate::f32_pack::pack_stage`].
#[must_use]
pub fn datapath() -> Datapath {
    Datapath::new()
        .stage(
            Stage::new("binary32-div.steps")
                .then(Component::Adder { width: 25 })
                .then(Component::Mux {
                    width: 25,
                    inputs: 2,
                })
                .times(24 + EXTRA),
        )
        .stage(
            Stage::new("binary32-div.exp")
                .then(Component::Adder { width: 9 })
                .then(Component::Comparator { width: 25 }),
        )
        .stage(crate::f32_pack::pack_stage("binary32-div.pack", 27))
}
