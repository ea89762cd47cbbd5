//! IEEE 754 binary32 addition and subtraction, bit-exact (0 ulp) against x86 SSE `addss` /
//! `subss` (the host's binary32 `+` and `-`) for every operand pair, NaNs included (see
//! [`crate::f32_pack`] for the policy). Float twin: the host's binary32 addition. Tested against
//! it on 10^7 seeded pairs plus boundary cases (zeros, subnormals, the largest finite value,
//! ties, cancellation, overflow), `tests/units/f32_units.rs`.

use crate::cost::UnitCost;
use crate::datapath::{Component, Datapath, Stage};
use crate::f32_pack::{classify, quiet, round_sum, zero, Class, DEFAULT_NAN, SIGN};

/// Beyond this exponent difference the smaller operand lies entirely below the larger one's
/// rounding bits and only its sign and non-zeroness matter.
const FAR: i32 = 40;

/// `a + b`, encodings in and out.
#[must_use]
pub fn add(a: u32, b: u32) -> u32 {
    match (classify(a), classify(b)) {
        (Class::Nan(x), _) => quiet(x),
        (_, Class::Nan(y)) => quiet(y),
        (Class::Inf(na), Class::Inf(nb)) => {
            if na == nb {
                a
            } else {
                DEFAULT_NAN
            }
        }
        (Class::Inf(_), _) => a,
        (_, Class::Inf(_)) => b,
        (Class::Zero(na), Class::Zero(nb)) => zero(na && nb),
        (Class::Zero(_), _) => b,
        (_, Class::Zero(_)) => a,
        (Class::Finite(x), Class::Finite(y)) => round_sum(x, y, FAR),
    }
}

/// `a - b`: [`add`] of `b` with its sign flipped (a NaN `b` keeps its bits, as SSE does).
#[must_use]
pub fn sub(a: u32, b: u32) -> u32 {
    if let Class::Nan(_) = classify(b) {
        return add(a, b);
    }
    add(a, b ^ SIGN)
}

/// One addition: align, add, normalize, round.
#[must_use]
pub fn add_cost(gate_levels_per_cycle: u32) -> UnitCost {
    crate::f32_pack::one_op_cost(&datapath(), gate_levels_per_cycle)
}

/// The float32 adder: exponent compare, alignment shift of the smaller significand, the
/// 27-bit significand adder (guard, round, sticky), then [`crate::f32_pack::pack_stage`].
#[must_use]
pub fn datapath() -> Datapath {
    Datapath::new()
        .stage(
            Stage::new("binary32-add.align")
                .then(Component::Adder { width: 8 })
                .then(Component::Shifter {
                    width: 27,
                    shift_bits: 5,
                })
                .then(Component::Adder { width: 27 }),
        )
        .stage(crate::f32_pack::pack_stage("binary32-add.pack", 27))
}
