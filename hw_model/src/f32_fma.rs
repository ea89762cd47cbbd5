//! IEEE 754 binary32 fused multiply-add `a x b + c` with one rounding, bit-exact (0 ulp)
//! against the host's binary32 `mul_add` (x86 `vfmadd`) for every finite and infinite operand
//! triple; NaN results are NaN (which operand's payload an x86 FMA propagates depends on the
//! instruction form LLVM picks; this unit returns the first NaN of `a`, `b`, `c` quieted).
//! It models LLVM's `llvm.fmuladd`, which `lp_build_fmuladd` emits and the x86 backend fuses
//! on a CPU with FMA (llvmpipe's attribute interpolation `a0 + dadx x + dady y`). Float twin:
//! the host's binary32 `mul_add`. Tested on 10^7 seeded triples plus boundary cases (cancellation, zeros,
//! subnormals, overflow), `tests/units/f32_units.rs`.

use crate::cost::UnitCost;
use crate::datapath::{Component, Datapath, Stage};
use crate::f32_pack::{
    classify, inf, quiet, round_pack, round_sum, zero, Class, Unpacked, DEFAULT_NAN,
};

/// Beyond this exponent difference the smaller addend lies entirely below the larger one's
/// rounding bits (the exact product has at most 48 bits).
const FAR: i32 = 72;

/// `a x b + c` rounded once, encodings in and out.
#[must_use]
pub fn fma(a: u32, b: u32, c: u32) -> u32 {
    let pneg = (a ^ b) >> 31 != 0;
    let (ca, cb, cc) = (classify(a), classify(b), classify(c));
    for (cl, x) in [(ca, a), (cb, b), (cc, c)] {
        if let Class::Nan(_) = cl {
            return quiet(x);
        }
    }
    let product = match (ca, cb) {
        (Class::Inf(_), Class::Zero(_)) | (Class::Zero(_), Class::Inf(_)) => return DEFAULT_NAN,
        (Class::Inf(_), _) | (_, Class::Inf(_)) => {
            return match cc {
                Class::Inf(nc) if nc != pneg => DEFAULT_NAN,
                _ => inf(pneg),
            };
        }
        (Class::Zero(_), _) | (_, Class::Zero(_)) => None,
        (Class::Finite(x), Class::Finite(y)) => Some(Unpacked {
            neg: pneg,
            exp: x.exp + y.exp,
            sig: x.sig * y.sig,
        }),
        _ => unreachable!("NaN operands returned above"),
    };
    match (product, cc) {
        (_, Class::Inf(_)) => c,
        (None, Class::Zero(nc)) => zero(pneg && nc),
        (None, _) => c,
        (Some(p), Class::Zero(_)) => round_pack(p.neg, p.exp, u128::from(p.sig), false),
        (Some(p), Class::Finite(z)) => round_sum(p, z, FAR),
        (Some(_), Class::Nan(_)) => unreachable!("NaN operands returned above"),
    }
}

/// One fused multiply-add.
#[must_use]
pub fn fma_cost(gate_levels_per_cycle: u32) -> UnitCost {
    crate::f32_pack::one_op_cost(&datapath(), gate_levels_per_cycle)
}

/// The float32 FMA: the 24 x 24 product beside the addend's alignment shift over 74 bits,
/// the 74-bit adder, then [`crate::f32_pack::pack_stage`].
#[must_use]
pub fn datapath() -> Datapath {
    Datapath::new()
        .stage(
            Stage::new("binary32-fma.product")
                .then(Component::Multiplier { a: 24, b: 24 })
                .beside(1, Component::Adder { width: 9 })
                .beside(
                    1,
                    Component::Shifter {
                        width: 74,
                        shift_bits: 7,
                    },
                ),
        )
        .stage(Stage::new("binary32-fma.add").then(Component::Adder { width: 74 }))
        .stage(crate::f32_pack::pack_stage("binary32-fma.pack", 74))
}
