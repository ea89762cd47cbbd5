//! The interpolator's routines as they were before the fast paths of the barycentric and
//! texture-coordinate stages, verbatim but for the reciprocal's routines (their previous
//! versions too): the oracles of the tests.

use super::BARY_LIMIT;
use crate::config::InterpConfig;
use crate::fixed::{round_shift_right_wide, ConstRounding, Format, SatCounter};
use crate::reciprocal::previous::{apply_in, eval, square};
use crate::reciprocal::{Recip, Reciprocal};

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
    crate::with_rounding!(cfg.interp_rounding, M => {
        perspective_bary_eval::<M>(edge, inv_w, cfg, recip, sat).0
    })
}

/// The reciprocal evaluation the barycentrics made: its argument and result (`None` when
/// `D <= 0`).
type Evaluated = Option<(u64, Recip)>;

/// [`perspective_bary`], with the reciprocal evaluation it made: its argument and result
/// (`None` when `D <= 0`), so [`perspective_bary_derivs`] reuses it when it needs the
/// reciprocal of the same argument ([`Reciprocal::eval`] is a pure function of it).
#[inline(always)]
fn perspective_bary_eval<M: ConstRounding>(
    edge: [i64; 3],
    inv_w: [i64; 3],
    cfg: &InterpConfig,
    recip: &Reciprocal,
    sat: &mut SatCounter,
) -> ([i64; 3], Evaluated) {
    let one = 1i64 << cfg.bary_bits;
    if let Some(p) = perspective_bary_narrow::<M>(edge, inv_w, cfg, recip, sat) {
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
        return ([one, 0, 0], None);
    }
    let bl = 128 - d.leading_zeros();
    let s = bl.saturating_sub(62);
    let dn = (d >> s) as u64;
    let r0 = eval(recip, dn, sat);
    let r = Recip {
        mant: r0.mant,
        shift: r0.shift + s as i32,
    };
    let mut p = [0i64; 3];
    for i in 1..3 {
        let v = apply_in::<M>(r, q[i], cfg.bary_bits);
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
    (p, Some((dn, r0)))
}

/// Perspective-correct barycentrics and their screen-space derivatives from ONE reciprocal
/// (analytic derivatives of p_i = q_i / D, as a plane-equation interpolator computes them):
/// `dp_i/dx = (a_i D - q_i S) / D^2` with `a_i = (E_i(x+1) - E_i(x)) invw_i`, `S = sum a_j`
/// (likewise for y). Returns `[p, p + dp/dx, p + dp/dy]` — the barycentrics of the sample and
/// of its two first-order neighbours — so downstream interpolation yields texture-coordinate
/// derivatives as plain differences. Each triple sums to exactly 1.0 (`_0 = 1 - _1 - _2`).
///
/// Datapath: `p` exactly as [`perspective_bary`]. For the derivatives, `D`, `q_i`, `a_i`, `S`
/// are exact (`i64` when they fit, else `i128`: the same values), then all scaled by one
/// common right shift so the largest magnitude has at most 62 bits (a scale that cancels in
/// the ratio), `N_i = a_i D - q_i S` exactly, then
/// `N_i` times `1/D^2` (one reciprocal shared by both axes, squared once and rounded to the
/// reciprocal's mantissa width) rounded once to `bary_bits`. ERROR BOUND of each derivative,
/// in LSBs of 2^-B: `|dp| 2^B (2 e_r + 2^-(M+1) + 2^-61) + 1/2` (1 for Truncate), `e_r` as in
/// [`perspective_bary`], M = `recip_mantissa_bits`. `D <= 0` gives the saturated `p` of
/// [`perspective_bary`] and zero derivatives (counted once).
#[inline]
#[must_use]
pub fn perspective_bary_derivs(
    edge: [i64; 3],
    edge_dx: [i64; 3],
    edge_dy: [i64; 3],
    inv_w: [i64; 3],
    cfg: &InterpConfig,
    recip: &Reciprocal,
    sat: &mut SatCounter,
) -> [[i64; 3]; 3] {
    crate::with_rounding!(cfg.interp_rounding, M => {
        perspective_bary_derivs_in::<M>(edge, edge_dx, edge_dy, inv_w, cfg, recip, sat)
    })
}

/// [`perspective_bary_derivs`] compiled for the rounding mode `M` (`interp_rounding`).
#[inline(always)]
fn perspective_bary_derivs_in<M: ConstRounding>(
    edge: [i64; 3],
    edge_dx: [i64; 3],
    edge_dy: [i64; 3],
    inv_w: [i64; 3],
    cfg: &InterpConfig,
    recip: &Reciprocal,
    sat: &mut SatCounter,
) -> [[i64; 3]; 3] {
    if let Some(out) =
        perspective_bary_derivs_narrow::<M>(edge, edge_dx, edge_dy, inv_w, cfg, recip, sat)
    {
        return out;
    }
    let (p, evaluated) = perspective_bary_eval::<M>(edge, inv_w, cfg, recip, sat);
    let q = [0, 1, 2].map(|i| i128::from(edge[i]) * i128::from(inv_w[i]));
    let d = q[0] + q[1] + q[2];
    if d <= 0 {
        return [p, p, p];
    }
    let a_of = |de: [i64; 3]| [0, 1, 2].map(|i| i128::from(de[i]) * i128::from(inv_w[i]));
    let (ax, ay) = (a_of(edge_dx), a_of(edge_dy));
    let (sx, sy) = (ax[0] + ax[1] + ax[2], ay[0] + ay[1] + ay[2]);
    let mag = [
        q[1].unsigned_abs(),
        q[2].unsigned_abs(),
        ax[1].unsigned_abs(),
        ax[2].unsigned_abs(),
        sx.unsigned_abs(),
        ay[1].unsigned_abs(),
        ay[2].unsigned_abs(),
        sy.unsigned_abs(),
    ]
    .into_iter()
    .fold(d.unsigned_abs(), u128::max);
    let shift = (128 - mag.leading_zeros()).saturating_sub(62);
    // Every scaled operand has at most 62 significant bits: it fits `i64` exactly, and the
    // products below are single 64x64 -> 128-bit multiplies.
    let down = |v: i128| (v >> shift) as i64;
    let scaled = Scaled {
        d: down(d),
        q: [down(q[1]), down(q[2])],
        a: [[down(ax[1]), down(ax[2])], [down(ay[1]), down(ay[2])]],
        sum: [down(sx), down(sy)],
    };
    derivs_from_scaled::<M>(p, evaluated, &scaled, cfg, recip, sat)
}

/// The derivative operands after the common scale: `D`, `q_1`, `q_2`, per axis `a_1`, `a_2`
/// and `S` (each at most 62 significant bits).
struct Scaled {
    d: i64,
    q: [i64; 2],
    a: [[i64; 2]; 2],
    sum: [i64; 2],
}

/// The second half of [`perspective_bary_derivs`]: from the barycentrics `p`, the reciprocal
/// evaluation they made and the scaled operands, the numerators `N_i = a_i D - q_i S`
/// (exact 64x64 -> 128-bit products) times `1/D^2`, rounded once.
#[inline(always)]
fn derivs_from_scaled<M: ConstRounding>(
    p: [i64; 3],
    evaluated: Evaluated,
    s: &Scaled,
    cfg: &InterpConfig,
    recip: &Reciprocal,
    sat: &mut SatCounter,
) -> [[i64; 3]; 3] {
    let mut out = [p, p, p];
    if s.d <= 0 {
        sat.saturated += 1;
        return out;
    }
    let r = match evaluated {
        Some((x, r)) if x == s.d as u64 => r,
        _ => eval(recip, s.d as u64, sat),
    };
    let r2 = square(r, recip.config().recip_mantissa_bits, M::MODE);
    let ds = i128::from(s.d);
    for k in 0..2 {
        let ss = i128::from(s.sum[k]);
        for i in 0..2 {
            let n = i128::from(s.a[k][i]) * ds - i128::from(s.q[i]) * ss;
            // N can reach 2^125; `apply` is exact below 2^100 with this mantissa, so N keeps
            // its top 94 bits (relative error < 2^-93) and the dropped scale 2^ns is folded
            // into the one rounding.
            let ns = (128 - n.unsigned_abs().leading_zeros()).saturating_sub(94);
            let v = apply_in::<M>(r2, n >> ns, cfg.bary_bits + ns);
            let dp = v.clamp(-BARY_LIMIT, BARY_LIMIT);
            if dp != v {
                sat.saturated += 1;
            }
            out[k + 1][i + 1] = p[i + 1] + dp;
        }
        out[k + 1][0] = (1i64 << cfg.bary_bits) - out[k + 1][1] - out[k + 1][2];
    }
    out
}

/// [`perspective_bary_derivs_in`] when every `q_i`, `a_i`, `D` and `S` fits `i64` and `D > 0`
/// and the barycentrics take their narrow path (the common case): the same operands, scale
/// and products in 64-bit arithmetic, identical bits and counts. `None` (nothing counted)
/// otherwise.
#[inline(always)]
fn perspective_bary_derivs_narrow<M: ConstRounding>(
    edge: [i64; 3],
    edge_dx: [i64; 3],
    edge_dy: [i64; 3],
    inv_w: [i64; 3],
    cfg: &InterpConfig,
    recip: &Reciprocal,
    sat: &mut SatCounter,
) -> Option<[[i64; 3]; 3]> {
    let times_w = |e: [i64; 3]| -> Option<[i64; 3]> {
        Some([
            e[0].checked_mul(inv_w[0])?,
            e[1].checked_mul(inv_w[1])?,
            e[2].checked_mul(inv_w[2])?,
        ])
    };
    let sum = |v: [i64; 3]| v[0].checked_add(v[1])?.checked_add(v[2]);
    let (q, ax, ay) = (times_w(edge)?, times_w(edge_dx)?, times_w(edge_dy)?);
    let (d, sx, sy) = (sum(q)?, sum(ax)?, sum(ay)?);
    let (p, evaluated) = bary_from_q::<M>(q, d, cfg, recip, sat)?;
    // The bit length of the largest magnitude is that of their OR.
    let mag = [q[1], q[2], ax[1], ax[2], sx, ay[1], ay[2], sy]
        .into_iter()
        .fold(d.unsigned_abs(), |m, v| m | v.unsigned_abs());
    let shift = (64 - mag.leading_zeros()).saturating_sub(62);
    let down = |v: i64| v >> shift;
    let scaled = Scaled {
        d: down(d),
        q: [down(q[1]), down(q[2])],
        a: [[down(ax[1]), down(ax[2])], [down(ay[1]), down(ay[2])]],
        sum: [down(sx), down(sy)],
    };
    Some(derivs_from_scaled::<M>(
        p, evaluated, &scaled, cfg, recip, sat,
    ))
}

/// The same datapath as [`perspective_bary`] when every `q_i` and their sum fit `i64`
/// (the common case): identical bits, without `i128` arithmetic. `None` when they do not fit.
#[inline(always)]
fn perspective_bary_narrow<M: ConstRounding>(
    edge: [i64; 3],
    inv_w: [i64; 3],
    cfg: &InterpConfig,
    recip: &Reciprocal,
    sat: &mut SatCounter,
) -> Option<([i64; 3], Evaluated)> {
    let q = [
        edge[0].checked_mul(inv_w[0])?,
        edge[1].checked_mul(inv_w[1])?,
        edge[2].checked_mul(inv_w[2])?,
    ];
    let d = q[0].checked_add(q[1])?.checked_add(q[2])?;
    bary_from_q::<M>(q, d, cfg, recip, sat)
}

/// [`perspective_bary_narrow`] from the exact products `q_i = E_i invw_i` and their sum `d`
/// (all in `i64`). `None` (nothing counted) when `d <= 0` or a `p_i` needs the clamp.
#[inline(always)]
fn bary_from_q<M: ConstRounding>(
    q: [i64; 3],
    d: i64,
    cfg: &InterpConfig,
    recip: &Reciprocal,
    sat: &mut SatCounter,
) -> Option<([i64; 3], Evaluated)> {
    if d <= 0 {
        return None;
    }
    // d < 2^63 has at most 63 significant bits; the wide path keeps the top 62.
    let bl = 64 - d.leading_zeros();
    let s = bl.saturating_sub(62);
    let dn = (d >> s) as u64;
    let r0 = eval(recip, dn, sat);
    let r = Recip {
        mant: r0.mant,
        shift: r0.shift + s as i32,
    };
    let mut p = [0i64; 3];
    for i in 1..3 {
        let v = apply_in::<M>(r, i128::from(q[i]), cfg.bary_bits);
        if !(-BARY_LIMIT..=BARY_LIMIT).contains(&v) {
            return None;
        }
        p[i] = v;
    }
    p[0] = (1i64 << cfg.bary_bits) - p[1] - p[2];
    Some((p, Some((dn, r0))))
}

/// [`interpolate`] of the two attributes `attr` (per vertex, e.g. a texture coordinate pair)
/// at each sample of `bary` into the same index of `result`: the same bits and counts as one
/// [`interpolate`] call per sample and attribute, with the rounding mode resolved once.
#[inline]
pub fn interpolate_pairs(
    bary: &[[i64; 3]],
    bary_bits: u32,
    attr: [[i64; 2]; 3],
    out: &Format,
    sat: &mut SatCounter,
    result: &mut [[i64; 2]],
) {
    let from = out.frac_bits + bary_bits;
    crate::with_rounding!(out.rounding, M => {
        let fmt = Format {
            rounding: M::MODE,
            ..*out
        };
        for ax in 0..2 {
            let column = [attr[0][ax], attr[1][ax], attr[2][ax]];
            // The sample-independent terms `a0 2^B`, `a1 - a0`, `a2 - a0` once per attribute;
            // any accumulator that leaves `i64` takes `interpolate`'s exact wide path.
            let terms = (|| {
                let a0 = column[0];
                Some((
                    a0.checked_mul(1i64.checked_shl(bary_bits)?)?,
                    column[1].checked_sub(a0)?,
                    column[2].checked_sub(a0)?,
                ))
            })();
            for (b, r) in bary.iter().zip(result.iter_mut()) {
                let acc = terms.and_then(|(t0, d1, d2)| {
                    t0.checked_add(b[1].checked_mul(d1)?)?
                        .checked_add(b[2].checked_mul(d2)?)
                });
                r[ax] = match acc {
                    Some(acc) => fmt.requantize(acc, from, sat),
                    None => interpolate_in::<M>(*b, bary_bits, column, out, sat),
                };
            }
        }
    })
}

/// [`interpolate`] compiled for the rounding mode `M` (`out.rounding`).
#[inline(always)]
fn interpolate_in<M: ConstRounding>(
    bary: [i64; 3],
    bary_bits: u32,
    attr: [i64; 3],
    out: &Format,
    sat: &mut SatCounter,
) -> i64 {
    let out = &Format {
        rounding: M::MODE,
        ..*out
    };
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
