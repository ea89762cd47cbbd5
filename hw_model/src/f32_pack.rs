//! IEEE 754 binary32 encoding shared by the float32 units (`f32_add`, `f32_mul`, `f32_div`,
//! `f32_fma`, `f32_convert`): unpacking an encoding into sign, exponent and integer
//! significand, and the one round-and-pack exit every float32 result leaves through
//! ([`round_pack`], round to nearest, ties to even, by [`crate::fixed::round_shift_right_sticky`]).
//!
//! Policy (that of x86 SSE with MXCSR's DAZ and FTZ clear, the host's binary32): gradual
//! underflow (subnormal operands and results are exact IEEE), overflow to infinity, and NaN
//! results as SSE produces them: an operation with a NaN operand returns its first NaN
//! operand quieted, an invalid operation (inf - inf, 0 x inf, 0/0, inf/inf) the default NaN
//! `0xFFC0_0000` (the tests check NaN-ness only: the host compiler may commute operands).
//! Mesa llvmpipe runs its setup and shaders with DAZ and FTZ set
//! (`util_fpstate_set_denorms_to_zero`); that differs from this policy only when an operand
//! or a result is below 2^-126 in magnitude.

use crate::cost::UnitCost;
use crate::datapath::{Component, Datapath, Stage};
use crate::fixed::{round_shift_right_mid, round_shift_right_sticky, HalfEvenMode, Rounding};

/// Sign bit of an encoding.
pub const SIGN: u32 = 0x8000_0000;
/// The default NaN of x86 SSE (an invalid operation's result).
pub const DEFAULT_NAN: u32 = 0xFFC0_0000;
/// Positive infinity.
pub const INF: u32 = 0x7F80_0000;
/// Fraction bits of binary32.
pub const FRAC_BITS: u32 = 23;
/// The exponent of the least significant bit of a subnormal (2^-149).
pub const MIN_LSB_EXP: i32 = -149;

/// An unpacked finite operand: value = (-1)^`neg` x `sig` x 2^`exp`, `sig` < 2^24.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Unpacked {
    pub neg: bool,
    pub exp: i32,
    pub sig: u64,
}

/// What an encoding holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Class {
    /// A NaN (its bits).
    Nan(u32),
    /// An infinity (true if negative).
    Inf(bool),
    /// A zero (true if negative).
    Zero(bool),
    /// A normal or subnormal number.
    Finite(Unpacked),
}

/// Unpacks encoding `x`.
#[inline]
#[must_use]
pub fn classify(x: u32) -> Class {
    let neg = x & SIGN != 0;
    let e = (x >> FRAC_BITS) & 0xFF;
    let f = x & 0x007F_FFFF;
    match (e, f) {
        (0xFF, 0) => Class::Inf(neg),
        (0xFF, _) => Class::Nan(x),
        (0, 0) => Class::Zero(neg),
        (0, _) => Class::Finite(Unpacked {
            neg,
            exp: MIN_LSB_EXP,
            sig: u64::from(f),
        }),
        _ => Class::Finite(Unpacked {
            neg,
            exp: e as i32 - 150,
            sig: u64::from(f | 0x0080_0000),
        }),
    }
}

/// `x` with its quiet bit set (SSE's propagation of a signalling NaN).
#[inline]
#[must_use]
pub const fn quiet(x: u32) -> u32 {
    x | 0x0040_0000
}

/// A signed zero.
#[inline]
#[must_use]
pub const fn zero(neg: bool) -> u32 {
    if neg {
        SIGN
    } else {
        0
    }
}

/// Signed infinity.
#[inline]
#[must_use]
pub const fn inf(neg: bool) -> u32 {
    zero(neg) | INF
}

/// Bit length of `x` (0 for 0).
#[inline]
fn bit_len(x: u128) -> i32 {
    128 - x.leading_zeros() as i32
}

/// The one exit of every float32 unit: the binary32 encoding nearest (ties to even) to
/// (-1)^`neg` x (`sig` + f) x 2^`exp`, where f in [0, 1) is what an earlier step dropped
/// (f > 0 iff `sticky`). `sig` = 0 with `sticky` clear is an exact zero of sign `neg`.
/// Overflow gives infinity; results below 2^-126 are subnormal (gradual underflow).
#[must_use]
pub fn round_pack(neg: bool, exp: i32, sig: u128, sticky: bool) -> u32 {
    if sig == 0 && !sticky {
        return zero(neg);
    }
    // Keep a sticky bit of our own below the significand, so a dropped f is never lost.
    let (sig, exp) = (sig << 1 | u128::from(sticky), exp - 1);
    if let Ok(narrow) = i64::try_from(sig) {
        if let Some(r) = pack_narrow(neg, exp, narrow) {
            return r;
        }
    }
    pack_wide(neg, exp, sig)
}

/// [`pack_wide`] in 64 bits (a positive significand below 2^63, the multiplier's always),
/// rounded by the one 64-bit rounding routine: `None` when the rounding would drop 64 bits or
/// more (results far below 2^-149), left to [`pack_wide`].
#[inline]
fn pack_narrow(neg: bool, exp: i32, sig: i64) -> Option<u32> {
    let top = exp + (64 - sig.leading_zeros() as i32) - 1;
    let mut lsb = (top - FRAC_BITS as i32).max(MIN_LSB_EXP);
    let mut q = if lsb > exp {
        let shift = (lsb - exp) as u32;
        if shift >= 64 {
            return None;
        }
        round_shift_right_mid::<HalfEvenMode>(sig, shift)
    } else {
        // At most 24 significant bits after the shift: no overflow.
        sig << (exp - lsb)
    };
    if q >> (FRAC_BITS + 1) != 0 {
        q >>= 1;
        lsb += 1;
    }
    if q >> FRAC_BITS == 0 {
        return Some(zero(neg) | q as u32);
    }
    let biased = lsb + 150;
    if biased >= 0xFF {
        return Some(inf(neg));
    }
    Some(zero(neg) | (biased as u32) << FRAC_BITS | (q as u32 & 0x007F_FFFF))
}

/// [`round_pack`]'s rounding of `sig` x 2^`exp` (not 0, its own sticky bit already at the
/// bottom) in `u128`.
fn pack_wide(neg: bool, exp: i32, sig: u128) -> u32 {
    let top = exp + bit_len(sig) - 1;
    // The exponent of the result's least significant bit: 24 significant bits, or 2^-149.
    let lsb = (top - FRAC_BITS as i32).max(MIN_LSB_EXP);
    let mut q = if lsb > exp {
        let shift = (lsb - exp).min(127) as u32;
        round_shift_right_sticky(sig, shift, false, Rounding::HalfEven)
    } else {
        sig << (exp - lsb)
    };
    let mut lsb = lsb;
    if q >> (FRAC_BITS + 1) != 0 {
        // Rounding carried into a 25th bit: exact halving (the low bit is 0).
        q >>= 1;
        lsb += 1;
    }
    if q >> FRAC_BITS == 0 {
        // Subnormal (lsb = -149) or zero after rounding.
        return zero(neg) | q as u32;
    }
    let biased = lsb + 150;
    if biased >= 0xFF {
        return inf(neg);
    }
    zero(neg) | (biased as u32) << FRAC_BITS | (q as u32 & 0x007F_FFFF)
}

/// The packing stage beside each float32 unit: leading-zero count over `width` bits, the
/// normalizing shift, the 24-bit rounding increment and the exponent adjust.
#[must_use]
pub fn pack_stage(name: &'static str, width: u32) -> Stage {
    Stage::new(name)
        .then(Component::LeadingZeros { width })
        .then(Component::Shifter {
            width,
            shift_bits: crate::datapath::ceil_log2(width),
        })
        .then(Component::Adder { width: 24 })
        .beside(1, Component::Adder { width: 10 })
}

/// The cost of one float32 operation on the unit whose datapath is `datapath`: one op, its
/// latency at `gate_levels_per_cycle`.
#[must_use]
pub fn one_op_cost(datapath: &Datapath, gate_levels_per_cycle: u32) -> UnitCost {
    UnitCost {
        ops: 1,
        cycles: datapath.latency(gate_levels_per_cycle),
        texels: 0,
    }
}

/// The exact sum of two unpacked finite values, rounded once (the adder's and the fused
/// multiply-add's last step). Beyond an exponent difference of `far` the smaller operand lies
/// entirely below the larger one's rounding bits and enters only as a sticky bit of its sign;
/// `far` must keep `sig << far` within 128 bits.
#[must_use]
pub fn round_sum(p: Unpacked, z: Unpacked, far: i32) -> u32 {
    let (x, y) = if p.exp >= z.exp { (p, z) } else { (z, p) };
    let diff = x.exp - y.exp;
    if diff > far && y.sig != 0 {
        let big = u128::from(x.sig) << 3;
        let exp = x.exp - 3;
        return if x.neg == y.neg {
            round_pack(x.neg, exp, big, true)
        } else {
            round_pack(x.neg, exp, big - 1, true)
        };
    }
    let big = u128::from(x.sig) << diff;
    let small = u128::from(y.sig);
    if x.neg == y.neg {
        round_pack(x.neg, y.exp, big + small, false)
    } else if big >= small {
        // An exact zero difference is +0 under round to nearest.
        let d = big - small;
        round_pack(x.neg && d != 0, y.exp, d, false)
    } else {
        round_pack(y.neg, y.exp, small - big, false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::splitmix64 as next;

    /// A uniform integer in `lo..=hi`.
    fn range(s: &mut u64, lo: i64, hi: i64) -> i64 {
        lo + (next(s) % (hi - lo + 1) as u64) as i64
    }

    /// [`round_pack`] (its `u64` path when the significand fits) equals [`pack_wide`] on 10^6
    /// seeded significands of 1 to 110 bits, exponents from far below 2^-149 to overflow, with
    /// and without the sticky bit.
    #[test]
    fn narrow_pack_matches_wide_pack() {
        let mut s = 0x9AC4;
        let mut narrow = 0;
        for _ in 0..1_000_000 {
            let bits = range(&mut s, 1, 110) as u32;
            let sig = (u128::from(next(&mut s)) << 64 | u128::from(next(&mut s))) >> (128 - bits);
            let sig = sig | 1u128 << (bits - 1);
            let exp = range(&mut s, -300, 160) as i32 - bits as i32;
            let sticky = next(&mut s) & 1 == 1;
            let neg = next(&mut s) & 1 == 1;
            let want = pack_wide(neg, exp - 1, sig << 1 | u128::from(sticky));
            assert_eq!(
                round_pack(neg, exp, sig, sticky),
                want,
                "{neg} {exp} {sig} {sticky}"
            );
            narrow += usize::from(bits < 62);
        }
        assert!(narrow > 400_000, "{narrow}");
    }
}
