//! IEEE 754 binary32 multiplication, bit-exact (0 ulp) against x86 SSE `mulss` (the host's
//! binary32 `*`) for every operand pair, NaNs included (policy in [`crate::f32_pack`]). Float
//! twin: the host's binary32 multiplication. Tested on 10^7 seeded pairs plus boundary cases,
//! `tests/units/f32_units.rs`.

use crate::cost::UnitCost;
use crate::datapath::{Component, Datapath, Stage};
use crate::f32_pack::{classify, inf, quiet, round_pack, zero, Class, DEFAULT_NAN};

/// `a x b`, encodings in and out.
#[must_use]
pub fn mul(a: u32, b: u32) -> u32 {
    let neg = (a ^ b) >> 31 != 0;
    match (classify(a), classify(b)) {
        (Class::Nan(x), _) => quiet(x),
        (_, Class::Nan(y)) => quiet(y),
        (Class::Inf(_), Class::Zero(_)) | (Class::Zero(_), Class::Inf(_)) => DEFAULT_NAN,
        (Class::Inf(_), _) | (_, Class::Inf(_)) => inf(neg),
        (Class::Zero(_), _) | (_, Class::Zero(_)) => zero(neg),
        (Class::Finite(x), Class::Finite(y)) => {
            // The exact 48-bit product, one rounding.
            round_pack(neg, x.exp + y.exp, u128::from(x.sig * y.sig), false)
        }
    }
}

/// One multiplication.
#[must_use]
pub fn mul_cost(gate_levels_per_cycle: u32) -> UnitCost {
    crate::f32_pack::one_op_cost(&datapath(), gate_levels_per_cycle)
}

/// The float32 multiplier: the 24 x 24-bit significand product beside the exponent adder,
/// then [`crate::f32_pack::pack_stage`] over the 48-bit product.
#[must_use]
pub fn datapath() -> Datapath {
    Datapath::new()
        .stage(
            Stage::new("binary32-mul.product")
                .then(Component::Multiplier { a: 24, b: 24 })
                .beside(1, Component::Adder { width: 9 }),
        )
        .stage(crate::f32_pack::pack_stage("binary32-mul.pack", 48))
}
