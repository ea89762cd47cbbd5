//! Attribute interpolator: perspective-correct barycentrics (Heckbert & Moreton 1991,
//! "Interpolation for polygon texture mapping and shading": p_i = (E_i/w_i) / sum_j (E_j/w_j))
//! and per-attribute interpolation `a0 + p1 (a1 - a0) + p2 (a2 - a0)`.
//!
//! Barycentric datapath (B = `bary_bits`):
//! 1. `q_i = E_i * invw_i` exactly (`i128`), `D = q_0 + q_1 + q_2` exactly.
//! 2. `D <= 0` (only possible for helper samples far outside the triangle): the result is
//!    `[1.0, 0, 0]` and one saturation is counted.
//! 3. `D` is truncated to its top 62 significant bits (relative error < 2^-61) and goes through
//!    ONE [`Reciprocal::eval`].
//! 4. `p_1`, `p_2` = `q_i * recip` rounded ONCE to B fraction bits by `interp_rounding`, then
//!    clamped to +-2^60 (counted). `p_0 = 2^B - p_1 - p_2`, so the three sum to exactly 1.0.
//!
//! ERROR BOUND (in LSBs of 2^-B, exact value `P_i = q_i / D`): for i = 1, 2,
//! `|p_i - P_i 2^B| <= |P_i| 2^B (e_r + 2^-61) + h`, where `e_r` is the reciprocal's relative
//! bound (see [`crate::reciprocal`]) and `h` = 1/2 for the nearest modes, 1 for Truncate;
//! `p_0`'s error is at most the sum of the two. Inside the triangle |P_i| <= 1.

use crate::config::InterpConfig;
use crate::cost::UnitCost;
use crate::fixed::{round_shift_right_wide, Format, SatCounter};
use crate::reciprocal::{apply, Recip, Reciprocal};

/// Clamp of `p_1`, `p_2` (raw), far beyond any sample near the triangle.
pub const BARY_LIMIT: i64 = 1 << 60;

/// Perspective-correct barycentrics with `cfg.bary_bits` fraction bits; see the module doc.
/// `edge` are the exact edge-function values at the sample (negative outside), `inv_w` the
/// per-vertex 1/w normalized so that the largest is `1 << inv_w_bits`.
#[inline]
#[must_use]
pub fn perspective_bary(
    edge: [i64; 3],
    inv_w: [i64; 3],
    cfg: &InterpConfig,
    recip: &Reciprocal,
    sat: &mut SatCounter,
) -> [i64; 3] {
    let one = 1i64 << cfg.bary_bits;
    if let Some(p) = perspective_bary_narrow(edge, inv_w, one, cfg, recip, sat) {
        return p;
    }
    let q = [
        i128::from(edge[0]) * i128::from(inv_w[0]),
        i128::from(edge[1]) * i128::from(inv_w[1]),
        i128::from(edge[2]) * i128::from(inv_w[2]),
    ];
    let d = q[0] + q[1] + q[2];
    if d <= 0 {
        sat.saturated += 1;
        return [one, 0, 0];
    }
    let bl = 128 - d.leading_zeros();
    let s = bl.saturating_sub(62);
    let dn = (d >> s) as u64;
    let r = recip.eval(dn, sat);
    let r = Recip {
        mant: r.mant,
        shift: r.shift + s as i32,
    };
    let mut p = [0i64; 3];
    for i in 1..3 {
        let v = apply(r, q[i], cfg.bary_bits, cfg.interp_rounding);
        p[i] = if v > BARY_LIMIT {
            sat.saturated += 1;
            BARY_LIMIT
        } else if v < -BARY_LIMIT {
            sat.saturated += 1;
            -BARY_LIMIT
        } else {
            v
        };
    }
    p[0] = one - p[1] - p[2];
    p
}

/// The same datapath as [`perspective_bary`] when every `q_i` and their sum fit `i64`
/// (the common case): identical bits, without `i128` arithmetic. `None` when they do not fit.
#[inline]
fn perspective_bary_narrow(
    edge: [i64; 3],
    inv_w: [i64; 3],
    one: i64,
    cfg: &InterpConfig,
    recip: &Reciprocal,
    sat: &mut SatCounter,
) -> Option<[i64; 3]> {
    let q0 = edge[0].checked_mul(inv_w[0])?;
    let q1 = edge[1].checked_mul(inv_w[1])?;
    let q2 = edge[2].checked_mul(inv_w[2])?;
    let d = q0.checked_add(q1)?.checked_add(q2)?;
    if d <= 0 {
        return None;
    }
    // d < 2^63 has at most 63 significant bits; the wide path keeps the top 62.
    let bl = 64 - d.leading_zeros();
    let s = bl.saturating_sub(62);
    let r = recip.eval((d >> s) as u64, sat);
    let r = Recip {
        mant: r.mant,
        shift: r.shift + s as i32,
    };
    let mut p = [0i64; 3];
    for (i, q) in [(1usize, q1), (2, q2)] {
        let v = apply(r, i128::from(q), cfg.bary_bits, cfg.interp_rounding);
        if !(-BARY_LIMIT..=BARY_LIMIT).contains(&v) {
            return None;
        }
        p[i] = v;
    }
    p[0] = one - p[1] - p[2];
    Some(p)
}

/// `a0 + p1 (a1 - a0) + p2 (a2 - a0)` accumulated exactly in `i128`, then ONE reduction
/// from `out.frac_bits + bary_bits` to `out` (round by `out.rounding`, fit by `out.overflow`,
/// as [`Format::requantize`]). `attr` and the result share `out.frac_bits`. Error: at most
/// 1/2 LSB of `out` (1 LSB for Truncate) relative to the exact value with these barycentrics.
#[inline]
#[must_use]
pub fn interpolate(
    bary: [i64; 3],
    bary_bits: u32,
    attr: [i64; 3],
    out: &Format,
    sat: &mut SatCounter,
) -> i64 {
    let from = out.frac_bits + bary_bits;
    // Exact i64 fast path (same accumulator value, same single reduction).
    let narrow = (|| {
        let a0 = attr[0];
        let t0 = a0.checked_mul(1i64.checked_shl(bary_bits)?)?;
        let t1 = bary[1].checked_mul(attr[1].checked_sub(a0)?)?;
        let t2 = bary[2].checked_mul(attr[2].checked_sub(a0)?)?;
        t0.checked_add(t1)?.checked_add(t2)
    })();
    if let Some(acc) = narrow {
        return out.requantize(acc, from, sat);
    }
    let a0 = i128::from(attr[0]);
    let acc = (a0 << bary_bits)
        + i128::from(bary[1]) * (i128::from(attr[1]) - a0)
        + i128::from(bary[2]) * (i128::from(attr[2]) - a0);
    if let Ok(narrow) = i64::try_from(acc) {
        out.requantize(narrow, from, sat)
    } else {
        let v = round_shift_right_wide(acc, bary_bits, out.rounding);
        out.fit(v, sat)
    }
}

/// Cost of one fragment's barycentrics: 3 multiplies, 2 adds, the reciprocal, 2 multiplies
/// and 2 subtracts.
#[must_use]
pub fn perspective_bary_cost(cfg: &InterpConfig, recip: &Reciprocal) -> UnitCost {
    let rc = recip.cost();
    UnitCost {
        ops: 9 + rc.ops,
        cycles: cfg.bary_cycles + rc.cycles,
        texels: 0,
    }
}

/// Cost of one scalar attribute: 2 subtracts, 2 multiplies, 2 adds, 1 round.
#[must_use]
pub fn interpolate_cost(cfg: &InterpConfig) -> UnitCost {
    UnitCost {
        ops: 7,
        cycles: cfg.attr_cycles,
        texels: 0,
    }
}
