//! The reciprocal's routines as they were before the fast paths of the barycentric stage,
//! verbatim but for `eval` as a free function of the unit: the oracles of the tests.

use super::{Recip, Reciprocal};
use crate::fixed::{round_shift_right_wide, ConstRounding, Rounding, SatCounter};

/// `Reciprocal::eval` as it was.
pub fn eval(u: &Reciprocal, x: u64, sat: &mut SatCounter) -> Recip {
    crate::with_rounding!(u.cfg.recip_rounding, M => eval_in::<M>(u, x, sat))
}

/// `Reciprocal::eval_in` as it was.
#[inline(always)]
pub fn eval_in<M: ConstRounding>(u: &Reciprocal, x: u64, sat: &mut SatCounter) -> Recip {
    let m_bits = u.cfg.recip_mantissa_bits;
    if x == 0 {
        sat.saturated += 1;
        return Recip {
            mant: (1u64 << (m_bits + 1)) - 1,
            shift: 0,
        };
    }
    let p = u.p;
    let rnd = M::MODE;
    let mut n = 63 - x.leading_zeros();
    // m with P fraction bits, in [2^P, 2^(P+1)).
    let mut m: i64 = if n <= p {
        (x << (p - n)) as i64
    } else if n < 63 {
        crate::fixed::round_shift_right(x as i64, n - p, rnd)
    } else {
        round_shift_right_wide(i128::from(x), n - p, rnd)
    };
    if m >> (p + 1) != 0 {
        m >>= 1;
        n += 1;
    }
    let l = u.cfg.recip_lut_bits;
    // Top L fraction bits of m (m has only P; a wider index sees zeros below them).
    let top = if l <= p { m >> (p - l) } else { m << (l - p) };
    let idx = (top & ((1i64 << l) - 1)) as usize;
    let mut y = u.lut[idx] as i64;
    let two = 2i64 << p;
    for _ in 0..u.cfg.recip_iterations {
        y = nr_step(m, y, two, p, rnd);
    }
    // Normalize y (positive, about 2^P / m) to M + 1 significant bits.
    let b = 64 - (y as u64).leading_zeros();
    let drop = b - (m_bits + 1);
    let mut mant = crate::fixed::round_shift_right(y, drop, rnd) as u64;
    let mut shift = (p + n) as i32 - drop as i32;
    if mant >> (m_bits + 1) != 0 {
        mant >>= 1;
        shift -= 1;
    }
    Recip { mant, shift }
}

/// One Newton-Raphson step `y (2 - m y)` with each product rounded to `p` fraction bits.
/// Operands are below 2^(p+2), so for p <= 29 the products fit `i64` (same bits as `i128`).
#[inline(always)]
fn nr_step(m: i64, y: i64, two: i64, p: u32, rnd: Rounding) -> i64 {
    if p <= 29 {
        let t = crate::fixed::round_shift_right(m * y, p, rnd);
        crate::fixed::round_shift_right(y * (two - t), p, rnd)
    } else {
        let t = round_shift_right_wide(i128::from(m) * i128::from(y), p, rnd);
        round_shift_right_wide(i128::from(y) * i128::from(two - t), p, rnd)
    }
}

/// `r * r` with its mantissa rounded once back to `m_bits + 1` significant bits (relative
/// error of the square: `2 e_r + 2^-(m_bits+1)`).
#[inline]
#[must_use]
pub fn square(r: Recip, m_bits: u32, mode: Rounding) -> Recip {
    let (drop, mut mant) = if r.mant >> 31 == 0 {
        // A mantissa of at most 31 bits (every `Reciprocal` result): the square fits `i64`.
        let sq = (r.mant * r.mant) as i64;
        let drop = (64 - sq.leading_zeros()).saturating_sub(m_bits + 1);
        (drop, crate::fixed::round_shift_right(sq, drop, mode) as u64)
    } else {
        let sq = i128::from(r.mant) * i128::from(r.mant);
        let drop = (128 - sq.leading_zeros()).saturating_sub(m_bits + 1);
        (drop, round_shift_right_wide(sq, drop, mode) as u64)
    };
    let mut shift = 2 * r.shift - drop as i32;
    if mant >> (m_bits + 1) != 0 {
        mant >>= 1;
        shift -= 1;
    }
    Recip { mant, shift }
}

/// `x * r` reduced to `frac_bits` fraction bits with ONE rounding by `mode` (x is an integer,
/// the product is exact in `i128` for |x| < 2^96); results beyond `i64` saturate.
#[inline]
#[must_use]
pub fn apply(r: Recip, x: i128, frac_bits: u32, mode: Rounding) -> i64 {
    crate::with_rounding!(mode, M => apply_in::<M>(r, x, frac_bits))
}

/// [`apply`] compiled for the rounding mode `M`.
#[inline(always)]
#[must_use]
pub fn apply_in<M: ConstRounding>(r: Recip, x: i128, frac_bits: u32) -> i64 {
    let mode = M::MODE;
    let sh = r.shift - frac_bits as i32;
    // Exact i64 fast path: same product, same single rounding.
    if sh >= 0 {
        if let (Ok(x64), Ok(m64)) = (i64::try_from(x), i64::try_from(r.mant)) {
            if let Some(prod) = x64.checked_mul(m64) {
                return crate::fixed::round_shift_right(prod, sh as u32, mode);
            }
        }
    }
    // |x| < 2^96 and a mantissa below 2^31 (at most 30 bits + 1): the product is below 2^127
    // and the saturating multiply's overflow check can be skipped (same value).
    let prod = if x.unsigned_abs() >> 96 == 0 && r.mant >> 31 == 0 {
        x * i128::from(r.mant)
    } else {
        x.saturating_mul(i128::from(r.mant))
    };
    if sh >= 0 {
        round_shift_right_wide(prod, sh as u32, mode)
    } else {
        let up = (-sh) as u32;
        if up >= 64 {
            if prod == 0 {
                0
            } else if prod > 0 {
                i64::MAX
            } else {
                i64::MIN
            }
        } else {
            round_shift_right_wide(prod.saturating_mul(1i128 << up), 0, mode)
        }
    }
}
