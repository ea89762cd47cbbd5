//! Conversions between binary32 and integers, bit-exact against x86 SSE: `cvtsi2ss` (an
//! `i32` to the nearest binary32, ties to even; the host's cast to binary32) and `cvttss2si`
//! (truncation toward zero; NaN and out-of-range give `i32::MIN`, the "integer indefinite",
//! where the host's saturating `as i32` differs). Float twins: the host's `as` casts. Tested
//! exhaustively over a 2^24 slice of each direction plus boundaries, `tests/units/f32_units.rs`.

use crate::cost::UnitCost;
use crate::datapath::{Component, Datapath, Stage};
use crate::f32_pack::{classify, round_pack, Class};

/// `x` converted to binary32, rounded to nearest, ties to even.
#[must_use]
pub fn from_i32(x: i32) -> u32 {
    round_pack(x < 0, 0, u128::from(x.unsigned_abs()), false)
}

/// `cvttss2si`: `x` truncated toward zero; `i32::MIN` for NaN, infinities and values outside
/// the `i32` range.
#[must_use]
pub fn to_i32_trunc(x: u32) -> i32 {
    match classify(x) {
        Class::Zero(_) => 0,
        Class::Nan(_) | Class::Inf(_) => i32::MIN,
        Class::Finite(u) => {
            let mag: u64 = if u.exp >= 0 {
                if u.exp > 31 {
                    return i32::MIN;
                }
                u.sig << u.exp
            } else if u.exp <= -64 {
                0
            } else {
                u.sig >> (-u.exp)
            };
            let v = if u.neg { -(mag as i64) } else { mag as i64 };
            i32::try_from(v).unwrap_or(i32::MIN)
        }
    }
}

/// One conversion.
#[must_use]
pub fn convert_cost(gate_levels_per_cycle: u32) -> UnitCost {
    crate::f32_pack::one_op_cost(&datapath(), gate_levels_per_cycle)
}

/// The integer-to-float converter: negate, [`crate::f32_pack::pack_stage`] over 32 bits.
#[must_use]
pub fn datapath() -> Datapath {
    Datapath::new()
        .stage(Stage::new("binary32-convert.abs").then(Component::Adder { width: 32 }))
        .stage(crate::f32_pack::pack_stage("binary32-convert.pack", 32))
}
