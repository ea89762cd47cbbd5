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

use crate::config::{InterpConfig, ReciprocalConfig};
use crate::cost::UnitCost;
use crate::datapath::{Component, Datapath, Stage};
use crate::fixed::{
    round_shift_right, round_shift_right_lane, round_shift_right_mid, round_shift_right_wide,
    round_shift_right_wide_lane, ConstRounding, Format, SatCounter, ShiftRound,
};
use crate::reciprocal::{apply_i64_in, apply_i64_small_in, apply_in, square, Recip, Reciprocal};

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
    if let Some(p) = perspective_bary_narrow::<M>(edge, inv_w, cfg, recip) {
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
    let r0 = recip.eval(dn, sat);
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
        _ => recip.eval(s.d as u64, sat),
    };
    let r2 = square(r, recip.config().recip_mantissa_bits, M::MODE);
    let ds = i128::from(s.d);
    for k in 0..2 {
        let ss = i128::from(s.sum[k]);
        for i in 0..2 {
            // N can reach 2^125.
            let n = i128::from(s.a[k][i]) * ds - i128::from(s.q[i]) * ss;
            out[k + 1][i + 1] = p[i + 1] + derivative::<M>(n, r2, cfg.bary_bits, sat);
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
    let (p, dn, r0) = bary_from_q::<M>(q, d, cfg, recip)?;
    // The bit length of the largest magnitude is that of their OR (d > 0).
    let mag = [q[1], q[2], ax[1], ax[2], sx, ay[1], ay[2], sy]
        .into_iter()
        .fold(d as u64, |m, v| m | v.unsigned_abs());
    let shift = (64 - mag.leading_zeros()).saturating_sub(62);
    let ds = d >> shift;
    if ds <= 0 {
        sat.saturated += 1;
        return Some([p, p, p]);
    }
    let r = if ds as u64 == dn {
        r0
    } else {
        recip.eval(ds as u64, sat)
    };
    let r2 = square(r, recip.config().recip_mantissa_bits, M::MODE);
    let scaled = ([q[1] >> shift, q[2] >> shift], ds, shift);
    let bx = axis_derivs::<M>(p, ax, sx, scaled, r2, cfg.bary_bits, sat);
    let by = axis_derivs::<M>(p, ay, sy, scaled, r2, cfg.bary_bits, sat);
    Some([p, bx, by])
}

/// The edge values over a row span of `lanes` samples `(x + j, y)`: at its first sample and
/// their constant steps along x and y (every lane's `edge + j dx` must fit `i64`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EdgeSpan {
    pub edge: [i64; 3],
    pub dx: [i64; 3],
    pub dy: [i64; 3],
    pub lanes: usize,
}

/// [`perspective_bary_derivs`] at the samples of a row span: `out(j, result)` gets lane `j`'s
/// result (the edges `edge + j dx`, the steps `dx`, `dy`), each lane once, in no promised
/// order. Bit-identical to one call per lane, with the same saturation counts.
///
/// Along the row the exact `q_i = E_i invw_i` step by `a_i = dE_i/dx invw_i` and `D` by
/// `S = sum a_j`. When the common scale shift is 0 (every operand below 2^62, the common
/// case) the x numerators `N_i = a_i D - q_i S` are the same at every lane and the y
/// numerators `b_i D - q_i T` step by `b_i S - a_i T`, so per lane only `1/D`, its square
/// and the roundings remain. A lane outside those preconditions (operands beyond `i64` or
/// 2^62, `D <= 0`, a clamped `p_i`) takes the per-sample datapath.
#[inline]
pub fn perspective_bary_derivs_span(
    span: &EdgeSpan,
    inv_w: [i64; 3],
    cfg: &InterpConfig,
    recip: &Reciprocal,
    sat: &mut SatCounter,
    out: impl DerivsOut,
) {
    crate::with_rounding!(cfg.interp_rounding, M => {
        crate::with_rounding!(recip.config().recip_rounding, R => {
            perspective_bary_derivs_span_in::<M, R>(span, inv_w, cfg, recip, sat, out)
        })
    })
}

/// One span of [`perspective_bary_derivs_spans`]: its edges and its triangle's `1/w`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DerivSpan {
    pub span: EdgeSpan,
    pub inv_w: [i64; 3],
}

/// [`perspective_bary_derivs_span`] of each span of `spans` (e.g. the spans of one row, each
/// of its own triangle): `out(i, j, result)` gets lane `j` of span `i`, each lane once, in no
/// promised order. Bit-identical to one call per lane, with the same saturation counts.
///
/// At a narrow width on a CPU with vector batches ([`crate::VectorIsa::Avx2`] or wider) the
/// lanes of every span of at most [`GATHER_MAX_LANES`] lanes in the held form
/// ([`derivs_span_held`]) are gathered across the spans into vector batches of [`HELD_LANES`]
/// lanes ([`Gather`]), so that the short spans of a mesh fill a batch as a long span does; each
/// lane carries its span's constants. The other spans, and every span elsewhere, take
/// [`perspective_bary_derivs_span`]'s forms span by span.
pub fn perspective_bary_derivs_spans(
    spans: &[DerivSpan],
    cfg: &InterpConfig,
    recip: &Reciprocal,
    sat: &mut SatCounter,
    out: impl FnMut(usize, usize, [[i64; 3]; 3]),
) {
    crate::with_rounding!(cfg.interp_rounding, M => {
        crate::with_rounding!(recip.config().recip_rounding, R => {
            spans_in::<M, R>(spans, cfg, recip, sat, out)
        })
    })
}

/// [`perspective_bary_derivs_spans`] compiled for the rounding modes `M` (`interp_rounding`)
/// and `R` (the reciprocal's `recip_rounding`).
#[inline(always)]
fn spans_in<M: ConstRounding, R: ConstRounding>(
    spans: &[DerivSpan],
    cfg: &InterpConfig,
    recip: &Reciprocal,
    sat: &mut SatCounter,
    mut out: impl FnMut(usize, usize, [[i64; 3]; 3]),
) {
    #[cfg(target_arch = "x86_64")]
    if crate::vector_batches() && recip.config().recip_mantissa_bits <= 28 {
        // The reciprocal's iteration count as a constant for the common widths.
        match recip.lane::<R>().narrow_iterations() {
            Some(1) => return spans_gathered::<M, R, 1>(spans, cfg, recip, sat, out),
            Some(2) => return spans_gathered::<M, R, 2>(spans, cfg, recip, sat, out),
            _ => {}
        }
    }
    for (i, ds) in spans.iter().enumerate() {
        let out = |j: usize, v| out(i, j, v);
        perspective_bary_derivs_span_in::<M, R>(&ds.span, ds.inv_w, cfg, recip, sat, out);
    }
}

/// [`spans_in`] with the held lanes of the short `spans` gathered into vector batches
/// (AVX2 or AVX-512, `1/D` by `eval_narrow::<N>`): each span of at most [`GATHER_MAX_LANES`]
/// lanes in the held form ([`held_form`]) pushes its lanes into the [`Gather`], which runs a batch
/// whenever it is full and once more at the end; any other span takes
/// [`perspective_bary_derivs_span_in`] at once.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn spans_gathered<M: ConstRounding, R: ConstRounding, const N: u32>(
    spans: &[DerivSpan],
    cfg: &InterpConfig,
    recip: &Reciprocal,
    sat: &mut SatCounter,
    mut out: impl FnMut(usize, usize, [[i64; 3]; 3]),
) {
    let bb = cfg.bary_bits;
    let m_bits = recip.config().recip_mantissa_bits;
    let lane_recip = recip.lane::<R>();
    let mut g = Gather::<HELD_LANES>::default();
    // The batches' lane results, zeroed once (each batch writes every lane).
    let mut lanes = HeldLanes::<HELD_LANES>::default();
    for (i, ds) in spans.iter().enumerate() {
        // A longer span fills its own batches ([`derivs_span_held`]).
        let held = (ds.span.lanes <= GATHER_MAX_LANES)
            .then(|| held_form(&ds.span, ds.inv_w, m_bits))
            .flatten();
        let Some((st, tops)) = held else {
            let out = |j: usize, v| out(i, j, v);
            perspective_bary_derivs_span_in::<M, R>(&ds.span, ds.inv_w, cfg, recip, sat, out);
            continue;
        };
        let k = LaneConsts::new(&tops, bb);
        let [mut q1, mut q2, mut d] = st.first;
        let mut ny = tops.ny;
        for j in 0..ds.span.lanes {
            g.push((i, j), d, [q1, q2], ny, &k);
            if g.n == HELD_LANES {
                g.run::<M, R, N>(&lane_recip, (spans, cfg, recip), &mut lanes, sat, &mut out);
            }
            ([q1, q2], ny) = st.next_lane([q1, q2], ny);
            d = d.wrapping_add(st.s);
        }
    }
    if g.n > 0 {
        g.run::<M, R, N>(&lane_recip, (spans, cfg, recip), &mut lanes, sat, &mut out);
    }
}

/// The edges of lane `j` of a span: `edge + j edge_dx`.
#[inline(always)]
fn lane_edges(edge: [i64; 3], edge_dx: [i64; 3], j: usize) -> [i64; 3] {
    let j = j as i64;
    [0, 1, 2].map(|i| edge[i].wrapping_add(j.wrapping_mul(edge_dx[i])))
}

/// `[q_1, q_2, D]` of a lane with the edges `e` when each product `q_i = E_i invw_i` and
/// their sum fit `i64` (the tests of [`perspective_bary_derivs_narrow`]), else `None`.
#[inline(always)]
fn lane_q(e: [i64; 3], inv_w: [i64; 3]) -> Option<[i64; 3]> {
    let q = [
        e[0].checked_mul(inv_w[0])?,
        e[1].checked_mul(inv_w[1])?,
        e[2].checked_mul(inv_w[2])?,
    ];
    let d = q[0].checked_add(q[1])?.checked_add(q[2])?;
    Some([q[1], q[2], d])
}

/// [`perspective_bary_derivs_in`] of lane `j` of `span` out of line: a span lane outside the
/// fast form.
#[inline(never)]
fn derivs_lane<M: ConstRounding>(
    span: &EdgeSpan,
    j: usize,
    inv_w: [i64; 3],
    cfg: &InterpConfig,
    recip: &Reciprocal,
    sat: &mut SatCounter,
) -> [[i64; 3]; 3] {
    let e = lane_edges(span.edge, span.dx, j);
    perspective_bary_derivs_in::<M>(e, span.dx, span.dy, inv_w, cfg, recip, sat)
}

/// A lane's barycentrics `[1 - p_1 - p_2, p_1, p_2]` and those of its neighbours along x and
/// y from `p` and the neighbours' `x`, `y` (`one` = 1 in the barycentrics' format).
#[inline(always)]
fn lane_result(one: i64, p: [i64; 2], x: [i64; 2], y: [i64; 2]) -> [[i64; 3]; 3] {
    [p, x, y].map(|[b1, b2]| [one - b1 - b2, b1, b2])
}

/// Where [`perspective_bary_derivs_span`] puts its results: lane by lane ([`DerivsOut::lane`];
/// every closure `FnMut(usize, [[i64; 3]; 3])` is one), or the lanes of a vector batch at once
/// when all of them took the fast form ([`DerivsOut::batch`], which a sink may decline).
pub trait DerivsOut {
    /// Lane `j`'s barycentrics at the pixel and one step in x and in y.
    fn lane(&mut self, j: usize, v: [[i64; 3]; 3]);

    /// Lanes `j0..j0 + n` of a batch, each `c` of them [`lane_result`] of `one`, `p[..][c]`
    /// and the steps `dp[..][c]` (x then y) added to `p`; whether the sink took them (else
    /// they come lane by lane).
    #[inline(always)]
    fn batch(&mut self, _: usize, _: usize, _: i64, _: &BatchLanes<HELD_LANES>) -> bool {
        false
    }
}

impl<F: FnMut(usize, [[i64; 3]; 3])> DerivsOut for F {
    #[inline(always)]
    fn lane(&mut self, j: usize, v: [[i64; 3]; 3]) {
        self(j, v);
    }
}

/// The fast-form results of a vector batch's lanes ([`DerivsOut::batch`]): the barycentrics
/// `p_1`, `p_2` at the pixel and the four steps to its neighbours (x then y), by lane.
pub struct BatchLanes<const L: usize> {
    pub p: [[i64; L]; 2],
    pub dp: [[i64; L]; 4],
}

/// A [`DerivsOut`] into lanes of a structure of arrays, `bary[sample][component][base + j]`
/// for lane `j`, that takes whole batches as vector stores.
pub struct DerivLanes<'a, const L: usize> {
    pub bary: &'a mut [[[i64; L]; 3]; 3],
    pub base: usize,
}

impl<const L: usize> DerivsOut for DerivLanes<'_, L> {
    #[inline(always)]
    fn lane(&mut self, j: usize, v: [[i64; 3]; 3]) {
        debug_assert!(self.base + j < L, "lane {j} from {} beyond {L}", self.base);
        // One mask rather than nine bounds checks where `L` is a power of two.
        let j = if L.is_power_of_two() {
            (self.base + j) & (L - 1)
        } else {
            self.base + j
        };
        for (lanes, bs) in self.bary.iter_mut().zip(v) {
            for (lane, b) in lanes.iter_mut().zip(bs) {
                lane[j] = b;
            }
        }
    }

    #[inline(always)]
    fn batch(&mut self, j0: usize, n: usize, one: i64, b: &BatchLanes<HELD_LANES>) -> bool {
        let at = self.base + j0;
        if at + n > L || n > HELD_LANES {
            return false;
        }
        batch_into_lanes_vector(self.bary, at, n, one, b);
        true
    }
}

/// [`DerivLanes::batch`]'s stores: lanes `at..at + n` of `bary` from the batch's first `n`
/// lanes (`at + n <= L`, `n <= HELD_LANES`), with no branch on the data.
#[inline(always)]
fn batch_into_lanes<const L: usize>(
    bary: &mut [[[i64; L]; 3]; 3],
    at: usize,
    n: usize,
    one: i64,
    b: &BatchLanes<HELD_LANES>,
) {
    let p = [&b.p[0][..n], &b.p[1][..n]];
    for (s, sample) in bary.iter_mut().enumerate() {
        // The sample's steps: none at the pixel, `dp[0..2]` one step in x, `dp[2..4]` in y.
        let step = |i: usize, c: usize| if s == 0 { 0 } else { b.dp[2 * (s - 1) + i][c] };
        let [c0, c1, c2] = sample;
        let (c0, c1, c2) = (
            &mut c0[at..at + n],
            &mut c1[at..at + n],
            &mut c2[at..at + n],
        );
        for c in 0..n {
            let (b1, b2) = (p[0][c] + step(0, c), p[1][c] + step(1, c));
            (c0[c], c1[c], c2[c]) = (one - b1 - b2, b1, b2);
        }
    }
}

crate::isa_kernel! {
    /// [`batch_into_lanes`] built for the vector instruction set in force.
    fn batch_into_lanes_vector[const L: usize](
        bary: &mut [[[i64; L]; 3]; 3],
        at: usize,
        n: usize,
        one: i64,
        b: &BatchLanes<HELD_LANES>,
    ) = batch_into_lanes::<L>;
}

/// A span length the span datapaths are tuned for (the row loop's spans have at most 32
/// fragments); they take any length.
pub const SPAN_LANES: usize = 32;

/// [`perspective_bary_derivs_span`] compiled for the rounding modes `M` (`interp_rounding`)
/// and `R` (the reciprocal's `recip_rounding`).
#[inline(always)]
fn perspective_bary_derivs_span_in<M: ConstRounding, R: ConstRounding>(
    span: &EdgeSpan,
    inv_w: [i64; 3],
    cfg: &InterpConfig,
    recip: &Reciprocal,
    sat: &mut SatCounter,
    mut out: impl DerivsOut,
) {
    let &EdgeSpan {
        edge,
        dx: edge_dx,
        lanes,
        ..
    } = span;
    let Some(steps) = span_steps(span, inv_w) else {
        for j in 0..lanes {
            out.lane(j, derivs_lane::<M>(span, j, inv_w, cfg, recip, sat));
        }
        return;
    };
    let (bb, one) = (cfg.bary_bits, 1i64 << cfg.bary_bits);
    let m_bits = recip.config().recip_mantissa_bits;
    let lane_recip = recip.lane::<R>();
    let wide = i128::from;
    if lanes == 0 {
        return;
    }
    let ends = span_ends(span, inv_w);
    if let Some(steady) = steps.steady(ends) {
        return derivs_span_steady::<M, R>(span, &steady, inv_w, cfg, recip, sat, out);
    }
    let SpanSteps {
        a,
        b,
        s,
        t,
        mag: steps_mag,
        y_step,
    } = steps;
    let mut stepped = ends.map(|(f, _)| f);
    // From the first fast lane on: the x numerators' top bits (the same at every fast lane)
    // and the y numerators at the current lane (exact at every fast lane, below 2^125: the
    // wrapping steps across the lanes between are exact modulo 2^128).
    let mut numerators: Option<([NumeratorTop; 2], [i128; 2])> = None;
    for j in 0..lanes {
        if let Some((_, ny)) = &mut numerators {
            *ny = [ny[0].wrapping_add(y_step[0]), ny[1].wrapping_add(y_step[1])];
        }
        // The lane's `q_1`, `q_2`, `D`; fast when the scale shift is 0 (`D`, positive, and
        // `q_1`, `q_2` below 2^62 as the steps are) and no `p_i` needs the clamp.
        let lane = match &mut stepped {
            Some(v) => {
                let here = *v;
                *v = [
                    v[0].wrapping_add(a[1]),
                    v[1].wrapping_add(a[2]),
                    v[2].wrapping_add(s),
                ];
                Some(here)
            }
            None => lane_q(lane_edges(edge, edge_dx, j), inv_w),
        };
        let fast = lane.and_then(|[q1, q2, d]| {
            let small = (d as u64 | q1.unsigned_abs() | q2.unsigned_abs() | steps_mag) >> 62 == 0;
            if !small || d <= 0 {
                return None;
            }
            // `D` < 2^62 is its own reduced argument; it is not 0, so nothing is counted.
            let r = lane_recip.eval(d as u64, &mut SatCounter::default());
            let p1 = apply_i64_in::<M>(r, q1, bb);
            let p2 = apply_i64_in::<M>(r, q2, bb);
            let limit = BARY_LIMIT as u64;
            // The reciprocal of the barycentrics is that of the derivatives: its square.
            (p1.unsigned_abs() <= limit && p2.unsigned_abs() <= limit).then(|| {
                (
                    [q1, q2, d],
                    [one - p1 - p2, p1, p2],
                    square(r, m_bits, M::MODE),
                )
            })
        });
        let Some(([q1, q2, d], pj, r2)) = fast else {
            out.lane(j, derivs_lane::<M>(span, j, inv_w, cfg, recip, sat));
            continue;
        };
        let (nx, ny) = *numerators.get_or_insert_with(|| {
            let dw = wide(d);
            (
                [
                    numerator_top(wide(a[1]) * dw - wide(q1) * wide(s)),
                    numerator_top(wide(a[2]) * dw - wide(q2) * wide(s)),
                ],
                [
                    wide(b[1]) * dw - wide(q1) * wide(t),
                    wide(b[2]) * dw - wide(q2) * wide(t),
                ],
            )
        });
        let x1 = pj[1] + derivative_of_top::<M>(nx[0], r2, bb, sat);
        let x2 = pj[2] + derivative_of_top::<M>(nx[1], r2, bb, sat);
        let y1 = pj[1] + derivative::<M>(ny[0], r2, bb, sat);
        let y2 = pj[2] + derivative::<M>(ny[1], r2, bb, sat);
        out.lane(j, lane_result(one, [pj[1], pj[2]], [x1, x2], [y1, y2]));
    }
}

/// The lane-independent operands of a span ([`perspective_bary_derivs_span_in`]): `a_i`, `b_i`
/// (the x and y steps of `q_i`), `S`, `T`, the OR of the magnitudes that enter the scale and
/// the y numerators' step (0 for a lone lane, which does not step).
struct SpanSteps {
    a: [i64; 3],
    b: [i64; 3],
    s: i64,
    t: i64,
    mag: u64,
    y_step: [i128; 2],
}

/// The [`SpanSteps`] of a span, when each is below 2^62 (the fast form); else `None`.
#[inline(always)]
fn span_steps(span: &EdgeSpan, inv_w: [i64; 3]) -> Option<SpanSteps> {
    let times_w = |e: [i64; 3]| -> Option<[i64; 3]> {
        Some([
            e[0].checked_mul(inv_w[0])?,
            e[1].checked_mul(inv_w[1])?,
            e[2].checked_mul(inv_w[2])?,
        ])
    };
    let sum = |v: [i64; 3]| v[0].checked_add(v[1])?.checked_add(v[2]);
    let (a, b) = (times_w(span.dx)?, times_w(span.dy)?);
    let (s, t) = (sum(a)?, sum(b)?);
    let mag = [a[1], a[2], s, b[1], b[2], t]
        .into_iter()
        .fold(0u64, |m, v| m | v.unsigned_abs());
    if mag >> 62 != 0 {
        return None;
    }
    let wide = i128::from;
    // Written out: an array `map` here is a call per span.
    let y_step = if span.lanes > 1 {
        [
            wide(b[1]) * wide(s) - wide(a[1]) * wide(t),
            wide(b[2]) * wide(s) - wide(a[2]) * wide(t),
        ]
    } else {
        [0; 2]
    };
    Some(SpanSteps {
        a,
        b,
        s,
        t,
        mag,
        y_step,
    })
}

impl SpanSteps {
    /// The [`Steady`] operands of the span with these steps whose `[q_1, q_2, D]` at its first
    /// and last lane are `ends` ([`span_ends`]), when both ends are in the fast form
    /// ([`small_end`]), hence every lane; else `None`.
    #[inline(always)]
    fn steady(&self, ends: Option<([i64; 3], [i64; 3])>) -> Option<Steady> {
        let (first, last) = ends?;
        (small_end(first, self.mag) && small_end(last, self.mag)).then_some(Steady {
            first,
            a: self.a,
            b: self.b,
            s: self.s,
            t: self.t,
            y_step: self.y_step,
        })
    }
}

/// `[q_1, q_2, D]` at the first and the last lane of a span of at least one lane, when each
/// lane's products and sums fit `i64` there ([`lane_q`]): they are linear in the lane, so
/// they do when they do at both ends, and then they step by `a_1`, `a_2` and `S` (wrapping
/// adds, exact). `None`: each lane tests its own.
#[inline(always)]
fn span_ends(span: &EdgeSpan, inv_w: [i64; 3]) -> Option<([i64; 3], [i64; 3])> {
    let first = lane_q(span.edge, inv_w)?;
    if span.lanes <= 1 {
        return Some((first, first));
    }
    let last = lane_q(lane_edges(span.edge, span.dx, span.lanes - 1), inv_w)?;
    Some((first, last))
}

/// Whether the lane `[q_1, q_2, D]` at an end of a span with steps of magnitude `mag` is in
/// the fast form: `D` positive and every operand below 2^62. Every lane of the span is when
/// both ends are: `q_1`, `q_2` and `D` are linear in the lane, so their magnitudes are at
/// most those at the ends and `D` is positive between two positive ends.
#[inline(always)]
fn small_end([q1, q2, d]: [i64; 3], mag: u64) -> bool {
    d > 0 && (d as u64 | q1.unsigned_abs() | q2.unsigned_abs() | mag) >> 62 == 0
}

/// The held form of a span ([`derivs_span_held`]), when it takes it: its [`Steady`]
/// operands and the [`Tops`] of its derivative numerators (with mantissas below 2^29,
/// `m_bits <= 28`). `None`: the span takes another form of
/// [`perspective_bary_derivs_span_in`].
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn held_form(span: &EdgeSpan, inv_w: [i64; 3], m_bits: u32) -> Option<(Steady, Tops)> {
    let st = span_steps(span, inv_w)?.steady(span_ends(span, inv_w))?;
    let (nx, ny) = st.numerators();
    let ns_y = held_drops(&st, ny, span.lanes, m_bits)?;
    Some((st, Tops { nx, ny, ns_y }))
}

/// The lane-independent operands of a span whose lanes all take the fast form
/// ([`derivs_span_steady`]): `q_1`, `q_2`, `D` at its first lane, `a_i` and `b_i` (the x and
/// y steps of `q_i`), `S`, `T`, and the y numerators' step.
struct Steady {
    first: [i64; 3],
    a: [i64; 3],
    b: [i64; 3],
    s: i64,
    t: i64,
    y_step: [i128; 2],
}

impl Steady {
    /// The derivative numerators at the first lane: the x numerators' tops (the same at every
    /// lane) and the y numerators (which step by `y_step`, exact at every lane, below 2^125;
    /// the wrapping steps are exact modulo 2^128).
    #[inline(always)]
    fn numerators(&self) -> ([NumeratorTop; 2], [i128; 2]) {
        let wide = i128::from;
        let (a, b, s, t) = (self.a, self.b, self.s, self.t);
        let [q1, q2, d] = self.first;
        let dw = wide(d);
        (
            [
                numerator_top(wide(a[1]) * dw - wide(q1) * wide(s)),
                numerator_top(wide(a[2]) * dw - wide(q2) * wide(s)),
            ],
            [
                wide(b[1]) * dw - wide(q1) * wide(t),
                wide(b[2]) * dw - wide(q2) * wide(t),
            ],
        )
    }

    /// `q_1`, `q_2` and the y numerators of the next lane from this lane's (wrapping steps,
    /// exact at every lane of the span).
    #[inline(always)]
    fn next_lane(&self, [q1, q2]: [i64; 2], ny: [i128; 2]) -> ([i64; 2], [i128; 2]) {
        (
            [q1.wrapping_add(self.a[1]), q2.wrapping_add(self.a[2])],
            [
                ny[0].wrapping_add(self.y_step[0]),
                ny[1].wrapping_add(self.y_step[1]),
            ],
        )
    }
}

/// [`perspective_bary_derivs_span_in`] for a span whose `q_1`, `q_2` and `D` are below 2^62
/// (and `D` positive) at both ends, hence at every lane: the lane loop without the per-lane
/// tests of the general form; a lane whose `p_i` needs the clamp takes the per-sample
/// datapath. Checked against one call per lane in `derivs_span_stepping_matches_per_lane_calls`.
#[inline(always)]
fn derivs_span_steady<M: ConstRounding, R: ConstRounding>(
    span: &EdgeSpan,
    st: &Steady,
    inv_w: [i64; 3],
    cfg: &InterpConfig,
    recip: &Reciprocal,
    sat: &mut SatCounter,
    mut out: impl DerivsOut,
) {
    let (bb, one) = (cfg.bary_bits, 1i64 << cfg.bary_bits);
    let m_bits = recip.config().recip_mantissa_bits;
    let lane_recip = recip.lane::<R>();
    let (a, s) = (st.a, st.s);
    let [mut q1, mut q2, mut d] = st.first;
    let (nx, mut ny) = st.numerators();
    if let Some(ns_y) = held_drops(st, ny, span.lanes, m_bits) {
        let tops = Tops { nx, ny, ns_y };
        // The reciprocal's iteration count as a constant for the common widths.
        return match recip.lane::<R>().narrow_iterations() {
            Some(1) => derivs_span_held::<M, R, 1>(span, st, &tops, inv_w, cfg, recip, sat, out),
            Some(2) => derivs_span_held::<M, R, 2>(span, st, &tops, inv_w, cfg, recip, sat, out),
            _ => derivs_span_held::<M, R, ANY_ITERATIONS>(
                span, st, &tops, inv_w, cfg, recip, sat, out,
            ),
        };
    }
    let limit = BARY_LIMIT as u64;
    for j in 0..span.lanes {
        // `D` < 2^62 is its own reduced argument; it is not 0, so nothing is counted.
        let r = lane_recip.eval(d as u64, &mut SatCounter::default());
        let p1 = apply_i64_in::<M>(r, q1, bb);
        let p2 = apply_i64_in::<M>(r, q2, bb);
        if p1.unsigned_abs() <= limit && p2.unsigned_abs() <= limit {
            // The reciprocal of the barycentrics is that of the derivatives: its square.
            let r2 = square(r, m_bits, M::MODE);
            let x1 = p1 + derivative_of_top::<M>(nx[0], r2, bb, sat);
            let x2 = p2 + derivative_of_top::<M>(nx[1], r2, bb, sat);
            let y1 = p1 + derivative::<M>(ny[0], r2, bb, sat);
            let y2 = p2 + derivative::<M>(ny[1], r2, bb, sat);
            out.lane(j, lane_result(one, [p1, p2], [x1, x2], [y1, y2]));
        } else {
            out.lane(j, derivs_lane::<M>(span, j, inv_w, cfg, recip, sat));
        }
        q1 = q1.wrapping_add(a[1]);
        q2 = q2.wrapping_add(a[2]);
        d = d.wrapping_add(s);
        ny = [
            ny[0].wrapping_add(st.y_step[0]),
            ny[1].wrapping_add(st.y_step[1]),
        ];
    }
}

/// The y numerators' drops of a span of `lanes` lanes whose y numerators at the first lane
/// are `ny`, when the span takes the held form: every mantissa below 2^29 (`m_bits <= 28`:
/// `Reciprocal` results and their squares have `recip_mantissa_bits + 1` bits) and each drop
/// the same along the span ([`held_drop`]).
#[inline(always)]
fn held_drops(st: &Steady, ny: [i128; 2], lanes: usize, m_bits: u32) -> Option<(u32, u32)> {
    if m_bits > 28 {
        return None;
    }
    let last = lanes.saturating_sub(1);
    Some((
        held_drop(ny[0], st.y_step[0], last)?,
        held_drop(ny[1], st.y_step[1], last)?,
    ))
}

/// The drop `ns` of [`numerator_top`] at every lane of a numerator `n + j step` (`j` up to
/// `last`, every value exact below 2^125) when it is the same at both ends and they have the
/// same sign: the numerator is linear in the lane, so its magnitude is monotonic between
/// them. `None` otherwise.
#[inline(always)]
fn held_drop(n: i128, step: i128, last: usize) -> Option<u32> {
    let ns = numerator_top(n).1;
    if last == 0 {
        return Some(ns);
    }
    let end = n.wrapping_add(step.wrapping_mul(last as i128));
    ((n < 0) == (end < 0) && numerator_top(end).1 == ns).then_some(ns)
}

/// The derivative numerators of a span in [`derivs_span_held`]: the x numerators' tops (the
/// same at every lane), the y numerators at the first lane and their drops (the same at
/// every lane).
struct Tops {
    nx: [NumeratorTop; 2],
    ny: [i128; 2],
    ns_y: (u32, u32),
}

impl Tops {
    /// The range of `1/D^2`'s exponent that keeps the derivatives' shifts
    /// `r2.shift - (bary_bits + ns)` in 64..126: they are for all four drops when they are
    /// for the largest and the smallest.
    #[inline(always)]
    fn r2_shifts(&self, bb: u32) -> (i32, i32) {
        let (nx, (ny1, ny2)) = (self.nx, self.ns_y);
        let ns_max = nx[0].1.max(nx[1].1).max(ny1.max(ny2));
        let ns_min = nx[0].1.min(nx[1].1).min(ny1.min(ny2));
        (64 + (bb + ns_max) as i32, 126 + (bb + ns_min) as i32)
    }
}

/// Lanes whose `1/D` and `1/D^2` [`derivs_span_held`] evaluates in one loop before their
/// barycentrics and derivatives. Each reciprocal is a chain of dependent steps (the seed's
/// table read, the Newton steps, the normalization, the square); in a loop of those alone the
/// core overlaps the chains of several lanes, which the whole lane's loop body is too long
/// for. Measured at one thread (the fastest of 15 frames, 6 runs): W1's frame 51.5-53.6 ->
/// 47.7-49.1 ms, W2's 90.7-94.5 -> 88.5-91.2 ms; batches of 4 and 32 lanes did as well on W1,
/// and 32 gained nothing on W2's short spans.
const RECIP_BATCH: usize = 8;

/// Lanes of one vector batch of held lanes ([`held_batch_lanes`]): two AVX-512 registers of
/// 64-bit lanes, so that each step has two independent chains.
pub const HELD_LANES: usize = 2 * crate::reciprocal::RECIP_LANES;

/// The most lanes of a span whose held lanes [`perspective_bary_derivs_spans`] gathers with
/// other spans' ([`Gather`]); a longer span fills its own vector batches.
pub const GATHER_MAX_LANES: usize = HELD_LANES - 1;

/// The fewest lanes [`derivs_span_held`] runs as a vector batch (the lanes past the span
/// repeat its last).
const HELD_MIN_LANES: usize = 8;

/// The `N` of [`derivs_span_held`] that evaluates each `1/D` with
/// [`crate::reciprocal::RecipLane::eval`] (any width and iteration count); another `N` takes
/// [`crate::reciprocal::RecipLane::eval_narrow`] with `N` iterations.
const ANY_ITERATIONS: u32 = u32::MAX;

/// [`derivs_span_steady`] when every mantissa is below 2^29 and the y numerators keep one
/// drop along the span ([`held_drop`]): per lane `1/D` takes `eval_narrow::<N>` (`N` the
/// iteration count, else [`ANY_ITERATIONS`]: `eval`), the barycentrics
/// [`apply_i64_small_in`] (else [`apply_i64_in`]), the y tops are a shift of the stepped
/// numerators, and one test of `1/D^2`'s exponent puts all four derivatives on
/// [`derivative_held`]'s 64-bit rounding, their four [`held_rounding`]s kept while that
/// exponent holds (else each takes [`derivative_of_top`]). Checked against one call per lane
/// in `derivs_span_stepping_matches_per_lane_calls`. At a narrow width with vector batches,
/// the next [`HELD_MIN_LANES`] to [`HELD_LANES`] lanes run as one batch of vector lanes
/// ([`held_batch_wide`]; a lane outside its fast form takes the scalar lane, [`held_lane`]);
/// other lanes run in batches of [`RECIP_BATCH`], each batch's reciprocals ahead of the rest
/// of its lanes. ([`perspective_bary_derivs_spans`] gathers the held lanes of short spans
/// across spans instead: [`Gather`].)
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn derivs_span_held<M: ConstRounding, R: ConstRounding, const N: u32>(
    span: &EdgeSpan,
    st: &Steady,
    tops: &Tops,
    inv_w: [i64; 3],
    cfg: &InterpConfig,
    recip: &Reciprocal,
    sat: &mut SatCounter,
    mut out: impl DerivsOut,
) {
    let (bb, one) = (cfg.bary_bits, 1i64 << cfg.bary_bits);
    let m_bits = recip.config().recip_mantissa_bits;
    let lane_recip = recip.lane::<R>();
    let s = st.s;
    let [mut q1, mut q2, mut d] = st.first;
    let (nx, mut ny, (ny1, ny2)) = (tops.nx, tops.ny, tops.ns_y);
    let (lo, hi) = tops.r2_shifts(bb);
    // The span's constants of the vector batches, when it has one.
    let consts =
        (N != ANY_ITERATIONS && span.lanes >= HELD_MIN_LANES).then(|| LaneConsts::new(tops, bb));
    let mut rounds: Option<(i32, [ShiftRound<M>; 4])> = None;
    let ctx = HeldLane {
        bb,
        one,
        r2_shifts: (lo, hi),
        nx,
        ns_y: (ny1, ny2),
    };
    let mut recips = [(Recip { mant: 0, shift: 0 }, Recip { mant: 0, shift: 0 }); RECIP_BATCH];
    let mut j0 = 0;
    // The vector batches (of at least [`HELD_MIN_LANES`] lanes, so all of them come first) at
    // a narrow width where the CPU has the vector unit for them. Their inputs and results are
    // made once per span and refilled in place by each batch (every lane of both is written):
    // no copy of the inputs, one zeroing of the results.
    if let Some(span_consts) = consts.as_ref() {
        let mut input = HeldBatch {
            n: 0,
            d,
            s,
            q: [q1, q2],
            a: [st.a[1], st.a[2]],
            ny: [(0, 0); 2],
            y_step: st.y_step.map(words),
            k: span_consts,
        };
        HELD_WIDE.with_borrow_mut(|wide| {
            while span.lanes - j0 >= HELD_MIN_LANES {
                let n = (span.lanes - j0).min(HELD_LANES);
                (input.n, input.d, input.q, input.ny) = (n, d, [q1, q2], ny.map(words));
                if !held_batch_wide::<M, R, N, HELD_LANES, _>(&lane_recip, &input, bb, wide) {
                    break;
                }
                let b = &*wide;
                let all = u64::MAX >> (64 - n);
                if b.ok & all == all && out.batch(j0, n, one, &b.fast) {
                    // Every lane took the fast form and the sink stored them: the next batch's
                    // first lane, `n` steps on (the same wrapping sums as lane by lane).
                    let n64 = n as i64;
                    q1 = q1.wrapping_add(n64.wrapping_mul(st.a[1]));
                    q2 = q2.wrapping_add(n64.wrapping_mul(st.a[2]));
                    let n128 = i128::from(n64);
                    ny = [0, 1].map(|k| ny[k].wrapping_add(n128.wrapping_mul(st.y_step[k])));
                    d = d.wrapping_add(n64.wrapping_mul(s));
                    j0 += n;
                    continue;
                }
                for c in 0..n {
                    let j = j0 + c;
                    if b.ok >> c & 1 == 1 {
                        let (p1, p2) = (b.fast.p[0][c], b.fast.p[1][c]);
                        let (x1, x2) = (p1 + b.fast.dp[0][c], p2 + b.fast.dp[1][c]);
                        let (y1, y2) = (p1 + b.fast.dp[2][c], p2 + b.fast.dp[3][c]);
                        out.lane(j, lane_result(one, [p1, p2], [x1, x2], [y1, y2]));
                    } else {
                        let rr = b.recips.get(c);
                        match held_lane::<M>(&ctx, &mut rounds, rr, [q1, q2], ny, sat) {
                            Some(v) => out.lane(j, v),
                            None => out.lane(j, derivs_lane::<M>(span, j, inv_w, cfg, recip, sat)),
                        }
                    }
                    ([q1, q2], ny) = st.next_lane([q1, q2], ny);
                }
                d = d.wrapping_add((n as i64).wrapping_mul(s));
                j0 += n;
            }
        });
    }
    // The other lanes, [`RECIP_BATCH`] reciprocals at a time.
    while j0 < span.lanes {
        let n = (span.lanes - j0).min(RECIP_BATCH);
        let mut dj = d;
        for lane in &mut recips[..n] {
            // `D` < 2^62 is its own reduced argument; it is not 0, so nothing is counted.
            let r = if N == ANY_ITERATIONS {
                lane_recip.eval(dj as u64, &mut SatCounter::default())
            } else {
                lane_recip.eval_narrow::<N>(dj as u64)
            };
            *lane = (r, square(r, m_bits, M::MODE));
            dj = dj.wrapping_add(s);
        }
        for (c, &rr) in recips[..n].iter().enumerate() {
            let j = j0 + c;
            match held_lane::<M>(&ctx, &mut rounds, rr, [q1, q2], ny, sat) {
                Some(v) => out.lane(j, v),
                None => out.lane(j, derivs_lane::<M>(span, j, inv_w, cfg, recip, sat)),
            }
            ([q1, q2], ny) = st.next_lane([q1, q2], ny);
        }
        d = dj;
        j0 += n;
    }
}

thread_local! {
    /// [`derivs_span_held`]'s vector results, reused span after span: each batch writes every
    /// lane, and building them zeroed in each call took 1.25% of W1's frame (a 1.3 KB
    /// `memset` per span of at most 32 pixels).
    static HELD_WIDE: std::cell::RefCell<HeldLanes<HELD_LANES>> =
        std::cell::RefCell::new(HeldLanes::default());
}

/// The span constants of [`held_lane`]: `bary_bits`, 1 in its format, the range of `1/D^2`'s
/// exponent that keeps the derivatives' shifts in 64..126, the x numerators' tops and the y
/// numerators' drops.
struct HeldLane {
    bb: u32,
    one: i64,
    r2_shifts: (i32, i32),
    nx: [NumeratorTop; 2],
    ns_y: (u32, u32),
}

/// One lane of [`derivs_span_held`] from its `1/D`, `1/D^2`, `q_1`, `q_2` and y numerators;
/// `None`: the lane's barycentrics need the clamp, and it takes the per-sample datapath
/// ([`derivs_lane`]). `rounds` keeps the derivatives' roundings ([`held_rounding`]) for the
/// last exponent of `1/D^2`: along a span `D` rarely crosses a power of two.
#[inline(always)]
fn held_lane<M: ConstRounding>(
    c: &HeldLane,
    rounds: &mut Option<(i32, [ShiftRound<M>; 4])>,
    (r, r2): (Recip, Recip),
    [q1, q2]: [i64; 2],
    ny: [i128; 2],
    sat: &mut SatCounter,
) -> Option<[[i64; 3]; 3]> {
    let (bb, nx, (ny1, ny2)) = (c.bb, c.nx, c.ns_y);
    // `q_1`, `q_2` below 2^62 and the mantissa below 2^29.
    let (p1, p2) = match (
        apply_i64_small_in::<M>(r, q1, bb),
        apply_i64_small_in::<M>(r, q2, bb),
    ) {
        (Some(p1), Some(p2)) => (p1, p2),
        _ => (apply_i64_in::<M>(r, q1, bb), apply_i64_in::<M>(r, q2, bb)),
    };
    // |p_1|, |p_2| <= 2^60 as one unsigned compare of the larger of `p_i + 2^60`.
    if bary_offset(p1).max(bary_offset(p2)) > 2 * BARY_LIMIT as u64 {
        return None;
    }
    let ty = [(ny[0] >> (ny1 & 63), ny1), (ny[1] >> (ny2 & 63), ny2)];
    let (x1, x2, y1, y2) = if (c.r2_shifts.0..c.r2_shifts.1).contains(&r2.shift) {
        // The four roundings of `1/D^2`'s exponent, kept while it holds.
        let rd = match *rounds {
            Some((at, rd)) if at == r2.shift => rd,
            _ => {
                let rd =
                    [nx[0].1, nx[1].1, ny1, ny2].map(|ns| held_rounding::<M>(r2.shift, bb, ns));
                *rounds = Some((r2.shift, rd));
                rd
            }
        };
        let dp = clamp_four(
            [
                derivative_held::<M>(nx[0].0, r2, &rd[0]),
                derivative_held::<M>(nx[1].0, r2, &rd[1]),
                derivative_held::<M>(ty[0].0, r2, &rd[2]),
                derivative_held::<M>(ty[1].0, r2, &rd[3]),
            ],
            sat,
        );
        (p1 + dp[0], p2 + dp[1], p1 + dp[2], p2 + dp[3])
    } else {
        (
            p1 + derivative_of_top::<M>(nx[0], r2, bb, sat),
            p2 + derivative_of_top::<M>(nx[1], r2, bb, sat),
            p1 + derivative_of_top::<M>(ty[0], r2, bb, sat),
            p2 + derivative_of_top::<M>(ty[1], r2, bb, sat),
        )
    };
    Some(lane_result(c.one, [p1, p2], [x1, x2], [y1, y2]))
}

/// The inputs of one vector batch ([`held_batch_lanes`]) lane by lane: `D`, `q_1` and `q_2`,
/// the four derivative tops (x then y) as high and low words (below 2^94), each derivative's
/// drop plus `bary_bits` and 62 (the shift of its top's product is `1/D^2`'s exponent less
/// it), and the range of `1/D^2`'s exponent that keeps the derivatives' shifts in 64..126.
trait HeldInputs<const L: usize> {
    fn x(&self) -> [u64; L];
    fn q(&self, i: usize, c: usize) -> i64;
    fn top(&self, k: usize, c: usize) -> (i64, u64);
    fn drop(&self, k: usize, c: usize) -> i64;
    fn r2_shifts(&self, c: usize) -> (i64, i64);
}

/// The inputs of one batch of a span's lanes in [`derivs_span_held`]: the lanes it takes
/// (`n`, 1 to `L`; the lanes past them repeat its last), `D`, `q_1`, `q_2` and the y
/// numerators (as high and low words) at its first lane and their steps, and the span's
/// constants `k` (the x numerators' tops, the drops and the range of `1/D^2`'s exponent:
/// [`HeldInputs`]).
struct HeldBatch<'k, const L: usize> {
    n: usize,
    d: i64,
    s: i64,
    q: [i64; 2],
    a: [i64; 2],
    ny: [(i64, u64); 2],
    y_step: [(i64, u64); 2],
    k: &'k LaneConsts,
}

impl<const L: usize> HeldBatch<'_, L> {
    /// The span's lane of batch lane `c` (the lanes past `n` repeat the last).
    #[inline(always)]
    fn lane(&self, c: usize) -> i64 {
        c.min(self.n - 1) as i64
    }
}

impl<const L: usize> HeldInputs<L> for HeldBatch<'_, L> {
    #[inline(always)]
    fn x(&self) -> [u64; L] {
        std::array::from_fn(|c| self.d.wrapping_add(self.lane(c).wrapping_mul(self.s)) as u64)
    }
    #[inline(always)]
    fn q(&self, i: usize, c: usize) -> i64 {
        self.q[i].wrapping_add(self.lane(c).wrapping_mul(self.a[i]))
    }
    #[inline(always)]
    fn top(&self, k: usize, c: usize) -> (i64, u64) {
        if k < 2 {
            self.k.nx[k]
        } else {
            let i = k - 2;
            y_top_lane(self.ny[i], self.y_step[i], self.k.ns_y[i], self.lane(c))
        }
    }
    #[inline(always)]
    fn drop(&self, k: usize, _: usize) -> i64 {
        self.k.drop[k]
    }
    #[inline(always)]
    fn r2_shifts(&self, _: usize) -> (i64, i64) {
        self.k.r2_shifts
    }
}

/// A span's constants as the vector batches take them (a span's own [`HeldBatch`]es, or
/// each lane of a [`Gather`]): the x numerators' tops as high and low words (below 2^94),
/// each derivative's drop plus `bary_bits` and 62 (x then y: the shift of its top's product
/// is `1/D^2`'s exponent less it), the range of `1/D^2`'s exponent that keeps the
/// derivatives' shifts in 64..126, and the y numerators' drops.
struct LaneConsts {
    nx: [(i64, u64); 2],
    drop: [i64; 4],
    r2_shifts: (i64, i64),
    ns_y: [u32; 2],
}

impl LaneConsts {
    #[inline(always)]
    fn new(tops: &Tops, bb: u32) -> Self {
        let (nx, (ny1, ny2)) = (tops.nx, tops.ns_y);
        let (lo, hi) = tops.r2_shifts(bb);
        Self {
            nx: [nx[0].0, nx[1].0].map(|x| ((x >> 64) as i64, x as u64)),
            drop: [nx[0].1, nx[1].1, ny1, ny2].map(|ns| i64::from(bb + ns) + 62),
            r2_shifts: (i64::from(lo), i64::from(hi)),
            ns_y: [ny1, ny2],
        }
    }

    /// The top of y numerator `i` (`ny`, of a lane) as high and low words: `ny` less its drop.
    #[inline(always)]
    fn y_top(&self, i: usize, ny: i128) -> (i64, u64) {
        words(ny >> (self.ns_y[i] & 63))
    }
}

/// `x` as its high (signed) and low words.
#[inline(always)]
fn words(x: i128) -> (i64, u64) {
    ((x >> 64) as i64, x as u64)
}

/// [`LaneConsts::y_top`] of the y numerator `ny + c step` (wrapping; `ny`, `step` as high and
/// low words, drop `ns`) for a lane `c` in 0..16, in 64-bit words with no branch (a vector
/// lane): `c step` from `c` times the step's high word and its low word's two 32-bit halves,
/// the sum's carry by compare, the drop a funnel shift. Bit-identical to the 128-bit form
/// (`derivs_span_stepping_matches_per_lane_calls`, `y_top_lane_matches_the_wide_form`).
#[inline(always)]
fn y_top_lane((nh, nl): (i64, u64), (sh, sl): (i64, u64), ns: u32, c: i64) -> (i64, u64) {
    let cu = c as u64;
    // `c sl` as 128 bits: its low word, and its high word from `c < 2^4` and 32-bit halves.
    let lo_off = cu.wrapping_mul(sl);
    let hi_off = (cu * (sl >> 32) + ((cu * (sl & 0xffff_ffff)) >> 32)) >> 32;
    let lo = nl.wrapping_add(lo_off);
    let hi = nh
        .wrapping_add(c.wrapping_mul(sh))
        .wrapping_add(hi_off as i64)
        .wrapping_add(i64::from(lo < lo_off));
    let ns = ns & 63;
    ((hi >> ns), (lo >> ns) | ((hi as u64) << 1 << (63 - ns)))
}

/// Held lanes ([`held_form`]) gathered across spans for one vector batch of `L` lanes
/// ([`held_batch_lanes`]), lane by lane: where it comes from (span, lane), `D`, `q_1`, `q_2`,
/// the four derivative tops as high and low words (x then y; the y tops are the lane's own),
/// and its span's [`LaneConsts`]; `n` lanes are filled.
#[cfg(target_arch = "x86_64")]
struct Gather<const L: usize> {
    n: usize,
    at: [(u32, u32); L],
    x: [u64; L],
    q: [[i64; L]; 2],
    top_hi: [[i64; L]; 4],
    top_lo: [[u64; L]; 4],
    drop: [[i64; L]; 4],
    r2_lo: [i64; L],
    r2_hi: [i64; L],
}

#[cfg(target_arch = "x86_64")]
impl<const L: usize> Default for Gather<L> {
    fn default() -> Self {
        Self {
            n: 0,
            at: [(0, 0); L],
            x: [0; L],
            q: [[0; L]; 2],
            top_hi: [[0; L]; 4],
            top_lo: [[0; L]; 4],
            drop: [[0; L]; 4],
            r2_lo: [0; L],
            r2_hi: [0; L],
        }
    }
}

#[cfg(target_arch = "x86_64")]
impl<const L: usize> HeldInputs<L> for Gather<L> {
    #[inline(always)]
    fn x(&self) -> [u64; L] {
        self.x
    }
    #[inline(always)]
    fn q(&self, i: usize, c: usize) -> i64 {
        self.q[i][c]
    }
    #[inline(always)]
    fn top(&self, k: usize, c: usize) -> (i64, u64) {
        (self.top_hi[k][c], self.top_lo[k][c])
    }
    #[inline(always)]
    fn drop(&self, k: usize, c: usize) -> i64 {
        self.drop[k][c]
    }
    #[inline(always)]
    fn r2_shifts(&self, c: usize) -> (i64, i64) {
        (self.r2_lo[c], self.r2_hi[c])
    }
}

#[cfg(target_arch = "x86_64")]
impl<const L: usize> Gather<L> {
    /// Adds lane `j` of span `i` (`at`), with its `D`, `q_1`, `q_2`, y numerators and its
    /// span's constants `k`; the gather must not be full.
    #[inline(always)]
    fn push(&mut self, at: (usize, usize), d: i64, q: [i64; 2], ny: [i128; 2], k: &LaneConsts) {
        let c = self.n;
        self.at[c] = (at.0 as u32, at.1 as u32);
        // `D` is positive (the held form).
        self.x[c] = d as u64;
        for i in 0..2 {
            self.q[i][c] = q[i];
            (self.top_hi[i][c], self.top_lo[i][c]) = k.nx[i];
            (self.top_hi[2 + i][c], self.top_lo[2 + i][c]) = k.y_top(i, ny[i]);
        }
        for i in 0..4 {
            self.drop[i][c] = k.drop[i];
        }
        (self.r2_lo[c], self.r2_hi[c]) = k.r2_shifts;
        self.n = c + 1;
    }

    /// Copies lane `from` into lane `to` (a lane past `n` repeats a filled one).
    #[inline(always)]
    fn repeat(&mut self, from: usize, to: usize) {
        self.x[to] = self.x[from];
        for i in 0..2 {
            self.q[i][to] = self.q[i][from];
        }
        for i in 0..4 {
            self.top_hi[i][to] = self.top_hi[i][from];
            self.top_lo[i][to] = self.top_lo[i][from];
            self.drop[i][to] = self.drop[i][from];
        }
        self.r2_lo[to] = self.r2_lo[from];
        self.r2_hi[to] = self.r2_hi[from];
    }

    /// Runs the batch of the `n` filled lanes (the lanes past them repeat the last) on the
    /// vector unit ([`held_batch_wide`]) into `b` and gives each lane's result to `out(span,
    /// lane, result)`: the batch's own where the lane took its fast form, else the per-sample
    /// datapath's ([`derivs_lane`], of `spans`); then empties the gather.
    #[inline(always)]
    fn run<M: ConstRounding, R: ConstRounding, const N: u32>(
        &mut self,
        lane: &crate::reciprocal::RecipLane<'_, R>,
        (spans, cfg, recip): (&[DerivSpan], &InterpConfig, &Reciprocal),
        b: &mut HeldLanes<L>,
        sat: &mut SatCounter,
        out: &mut impl FnMut(usize, usize, [[i64; 3]; 3]),
    ) {
        let n = self.n;
        for to in n..L {
            self.repeat(n - 1, to);
        }
        let (bb, one) = (cfg.bary_bits, 1i64 << cfg.bary_bits);
        if !held_batch_wide::<M, R, N, L, Self>(lane, self, bb, b) {
            // No vector batches since [`spans_in`] chose the gather: every lane by itself.
            b.ok = 0;
        }
        for c in 0..n {
            let (i, j) = (self.at[c].0 as usize, self.at[c].1 as usize);
            if b.ok >> c & 1 == 1 {
                let (p1, p2) = (b.fast.p[0][c], b.fast.p[1][c]);
                let (x1, x2) = (p1 + b.fast.dp[0][c], p2 + b.fast.dp[1][c]);
                let (y1, y2) = (p1 + b.fast.dp[2][c], p2 + b.fast.dp[3][c]);
                out(i, j, lane_result(one, [p1, p2], [x1, x2], [y1, y2]));
            } else {
                let ds = &spans[i];
                out(
                    i,
                    j,
                    derivs_lane::<M>(&ds.span, j, ds.inv_w, cfg, recip, sat),
                );
            }
        }
        self.n = 0;
    }
}

/// What [`held_batch_lanes`] gives per lane: `1/D` and `1/D^2`, the barycentrics `p_1`, `p_2`,
/// the four derivative steps (x then y), and in bit `c` of `ok` whether lane `c` took the fast
/// form (a lane that did not takes the scalar lane from its `1/D` and `1/D^2`).
struct HeldLanes<const L: usize> {
    recips: crate::reciprocal::RecipLanes<L>,
    fast: BatchLanes<L>,
    ok: u64,
}

impl<const L: usize> Default for HeldLanes<L> {
    fn default() -> Self {
        Self {
            recips: crate::reciprocal::RecipLanes::default(),
            fast: BatchLanes {
                p: [[0; L]; 2],
                dp: [[0; L]; 4],
            },
            ok: 0,
        }
    }
}

/// `q mant` for `|q| < 2^62` and a mantissa below 2^32 as the 128-bit `(high, low)` words: two
/// 32 x 32-bit products and a carry, with no branch (a vector lane).
#[inline(always)]
fn mul_wide_lane(q: i64, mant: u64) -> (i64, u64) {
    let high = (q >> 32) * mant as i64;
    let low = (q as u64 & 0xffff_ffff) * mant;
    let lo = (high as u64) << 32;
    let sum = lo.wrapping_add(low);
    ((high >> 32) + i64::from(sum < low), sum)
}

/// [`product_top`] of `x = hi 2^64 + lo` (below 2^94) and a mantissa below 2^29 with no
/// branch (a vector lane): three 32 x 32-bit products.
#[inline(always)]
fn product_top_lane((hi, lo): (i64, u64), mant: u64) -> i64 {
    let p0 = (lo & 0xffff_ffff) * mant;
    let p1 = (lo >> 32) * mant;
    let low = (p1 << 32).wrapping_add(p0);
    let high = hi * mant as i64 + (p1 >> 32) as i64 + i64::from(low < p0);
    (high << 2) | (low >> 62) as i64 | i64::from(low << 2 != 0)
}

/// One batch of held lanes ([`HeldInputs`]: a span's, [`HeldBatch`], or gathered across
/// spans, [`Gather`]) written lane by lane with every per-lane choice a select, so that its
/// loops vectorize: [`crate::reciprocal::RecipLane::eval_square_lanes`], the barycentrics
/// ([`apply_i64_small_in`]'s product and rounding as [`mul_wide_lane`] and
/// [`round_shift_right_wide_lane`]) and the four derivatives ([`derivative_held`] as
/// [`product_top_lane`] and [`round_shift_right_lane`]). A lane is fast (its bit of `ok`) when
/// the scalar lane ([`held_lane`]) would take those forms and clamp nothing; its values are
/// then the scalar lane's (checked in `derivs_span_stepping_matches_per_lane_calls` and
/// `gathered_spans_match_per_lane_calls`).
#[inline(always)]
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
fn held_batch_lanes<M, R, const N: u32, const L: usize, I>(
    lane: &crate::reciprocal::RecipLane<'_, R>,
    b: &I,
    bb: u32,
    out: &mut HeldLanes<L>,
) where
    M: ConstRounding,
    R: ConstRounding,
    I: HeldInputs<L>,
{
    lane.eval_square_lanes::<N, M, L>(&b.x(), &mut out.recips);
    let mut ok = 0u64;
    let limit = 2 * BARY_LIMIT as u64;
    for c in 0..L {
        let (r, r2) = out.recips.get(c);
        // The barycentrics: `q_i / D` at `bary_bits`, a shift in 1..=63 that fits `i64`.
        let sh = i64::from(r.shift) - i64::from(bb);
        let mut fast = (1..64).contains(&sh);
        for i in 0..2 {
            let (hi, lo) = mul_wide_lane(b.q(i, c), r.mant);
            let (v, fits) = round_shift_right_wide_lane::<M>(hi, lo, sh.clamp(1, 63) as u32);
            fast &= fits && bary_offset(v) <= limit;
            out.fast.p[i][c] = v;
        }
        // The derivatives: each top rounded by `1/D^2`'s exponent less its drop.
        let r2_shift = i64::from(r2.shift);
        let (lo, hi) = b.r2_shifts(c);
        fast &= (lo..hi).contains(&r2_shift);
        for k in 0..4 {
            let shift = r2_shift - b.drop(k, c);
            let v = round_shift_right_lane::<M>(
                product_top_lane(b.top(k, c), r2.mant),
                shift.clamp(2, 63) as u32,
            );
            fast &= bary_offset(v) <= limit;
            out.fast.dp[k][c] = v;
        }
        ok |= u64::from(fast) << c;
    }
    out.ok = ok;
}

crate::isa_kernel! {
    /// [`held_batch_lanes`] built for the vector instruction set in force into `out` (and
    /// `true`), or `false` where no vector batches run ([`crate::VectorIsa::Portable`]).
    vector fn held_batch_wide[M, R, const N: u32, const L: usize, I](
        lane: &crate::reciprocal::RecipLane<'_, R>,
        b: &I,
        bb: u32,
        out: &mut HeldLanes<L>,
    ) where[M: ConstRounding, R: ConstRounding, I: HeldInputs<L>]
        = held_batch_lanes::<M, R, N, L, I>;
}

/// [`perspective_bary`] at the samples of a row span: `out(j, result)` gets lane `j`'s result
/// (the edges `edge + j dx`; `dy` is not used), each lane once. Bit-identical to one call per
/// lane, with the same saturation counts, the rounding mode resolved once.
#[inline]
pub fn perspective_bary_span(
    span: &EdgeSpan,
    inv_w: [i64; 3],
    cfg: &InterpConfig,
    recip: &Reciprocal,
    sat: &mut SatCounter,
    mut out: impl FnMut(usize, [i64; 3]),
) {
    crate::with_rounding!(cfg.interp_rounding, M => {
        for j in 0..span.lanes {
            let e = lane_edges(span.edge, span.dx, j);
            out(j, perspective_bary_eval::<M>(e, inv_w, cfg, recip, sat).0);
        }
    })
}

/// The barycentrics of the neighbour along one screen axis, `p + dp`: the numerators
/// `N_i = a_i D - q_i S` of the per-axis `a_i` and `S = sum`, from the scaled `q_1`, `q_2`
/// and `D` (`scaled`, with their common `shift`), as exact 64x64 -> 128-bit products of
/// operands of at most 62 bits, each through [`derivative`].
#[inline(always)]
fn axis_derivs<M: ConstRounding>(
    p: [i64; 3],
    a: [i64; 3],
    sum: i64,
    (q, ds, shift): ([i64; 2], i64, u32),
    r2: Recip,
    bary_bits: u32,
    sat: &mut SatCounter,
) -> [i64; 3] {
    let (ss, wide_ds) = (i128::from(sum >> shift), i128::from(ds));
    let n1 = i128::from(a[1] >> shift) * wide_ds - i128::from(q[0]) * ss;
    let n2 = i128::from(a[2] >> shift) * wide_ds - i128::from(q[1]) * ss;
    let b1 = p[1] + derivative::<M>(n1, r2, bary_bits, sat);
    let b2 = p[2] + derivative::<M>(n2, r2, bary_bits, sat);
    [(1i64 << bary_bits) - b1 - b2, b1, b2]
}

/// One derivative `N / D^2` from the exact numerator `n` and `r2 = 1/D^2`: `N` keeps its top
/// 94 bits (`apply` is exact below 2^100 with this mantissa; relative error < 2^-93), the
/// dropped scale folded into the one rounding to `bary_bits`, then the clamp to
/// +-[`BARY_LIMIT`] (counted).
#[inline(always)]
fn derivative<M: ConstRounding>(n: i128, r2: Recip, bary_bits: u32, sat: &mut SatCounter) -> i64 {
    derivative_of_top::<M>(numerator_top(n), r2, bary_bits, sat)
}

/// A numerator of [`derivative`] kept to its top 94 bits, and the shift dropped: `(N >> ns, ns)`.
type NumeratorTop = (i128, u32);

/// The numerator of [`derivative`] kept to its top 94 bits ([`NumeratorTop`]).
#[inline(always)]
fn numerator_top(n: i128) -> NumeratorTop {
    // |N| < 2^126, so `ns` <= 32 and `n >> ns` is a 64-bit funnel shift. `ns` from the high
    // word of |N| alone: at or above 2^64 the bit length of |N| is 64 plus that of its high
    // word, below it `ns` is 0 either way.
    let high = (n.unsigned_abs() >> 64) as u64;
    let ns = (64 - high.leading_zeros()).saturating_sub(30) & 63;
    (n >> ns, ns)
}

/// [`derivative`] from the numerator's top bits `(x, ns)` ([`numerator_top`]).
#[inline(always)]
fn derivative_of_top<M: ConstRounding>(
    (x, ns): NumeratorTop,
    r2: Recip,
    bary_bits: u32,
    sat: &mut SatCounter,
) -> i64 {
    let sh = r2.shift - (bary_bits + ns) as i32;
    // `apply_in`'s exact product and rounding (|x| <= 2^94, a mantissa below 2^31).
    if r2.mant >> 31 == 0 && (64..126).contains(&sh) {
        return derivative_short::<M>((x, ns), r2, bary_bits, sat);
    }
    let v = if sh >= 0 && r2.mant >> 31 == 0 {
        round_shift_right_wide(x * i128::from(r2.mant as i64), sh as u32, M::MODE)
    } else {
        apply_in::<M>(r2, x, bary_bits + ns)
    };
    clamp_derivative(v, sat)
}

/// [`derivative_of_top`] when `r2`'s mantissa is below 2^31 and `sh = r2.shift - (bary_bits +
/// ns)` is in 64..126: the product is below 2^125, its top bits from bit 62 fit `i64`, and
/// the 62 below fold into a sticky bit under the rounding position (`sh - 62` >= 2), as
/// `round_shift_right_wide` does for these shifts; then the clamp.
#[inline(always)]
fn derivative_short<M: ConstRounding>(
    (x, ns): NumeratorTop,
    r2: Recip,
    bary_bits: u32,
    sat: &mut SatCounter,
) -> i64 {
    let sh = r2.shift - (bary_bits + ns) as i32;
    debug_assert!(r2.mant >> 31 == 0 && (64..126).contains(&sh));
    let v = round_shift_right_mid::<M>(product_top(x, r2), (sh - 62) as u32);
    clamp_derivative(v, sat)
}

/// `x * r2.mant` (|x| <= 2^94, a mantissa below 2^31) from bit 62 up, the 62 bits below
/// folded into a sticky bit: below 2^63 in magnitude, below 2^61 for a mantissa below 2^29.
#[inline(always)]
fn product_top(x: i128, r2: Recip) -> i64 {
    // The mantissa as `u32`: the product's high word is one multiply.
    let prod = x * i128::from(r2.mant as u32);
    (prod >> 62) as i64 | i64::from((prod as u64) << 2 != 0)
}

/// The rounding of [`derivative_held`] for `1/D^2`'s exponent `r2_shift` and a numerator's
/// drop `ns`: by `r2_shift - (bary_bits + ns) - 62`, which [`derivs_span_held`] has checked to
/// lie in 2..=63.
#[inline(always)]
fn held_rounding<M: ConstRounding>(r2_shift: i32, bary_bits: u32, ns: u32) -> ShiftRound<M> {
    let sh = r2_shift - (bary_bits + ns) as i32;
    debug_assert!((64..126).contains(&sh));
    ShiftRound::at((sh - 62) as u32)
}

/// [`derivative_short`] before its clamp ([`clamp_four`]), for a mantissa below 2^29 (the span
/// lanes of [`derivs_span_held`]) and a numerator's top `x` (below 2^94), rounded by `round`
/// ([`held_rounding`] of the numerator's drop, a shift of at least 2): the product is below
/// 2^123 and its top bits below 2^61, so the rounding is
/// [`crate::fixed::round_shift_right_small`]'s.
#[inline(always)]
fn derivative_held<M: ConstRounding>(x: i128, r2: Recip, round: &ShiftRound<M>) -> i64 {
    debug_assert!(r2.mant >> 29 == 0 && x.unsigned_abs() >> 94 == 0);
    let v = round.apply(product_top(x, r2));
    debug_assert!(v.unsigned_abs() <= 1 << 59, "{v}");
    v
}

/// The offset of `v` from `-BARY_LIMIT`: `|v| <= BARY_LIMIT` iff it is at most `2 BARY_LIMIT`
/// (one unsigned compare).
#[inline(always)]
fn bary_offset(v: i64) -> u64 {
    v.wrapping_add(BARY_LIMIT) as u64
}

/// The clamp of four [`derivative_held`] results to +-[`BARY_LIMIT`], each clamp counted: one
/// test of the largest offset. (Their bounds keep them within 2^59, so it never clamps; the
/// test, the per-sample datapath's clamp, also keeps the compiler from vectorizing the four
/// 128-bit products, which without it cost W1's bary stage 40% more instructions.)
#[inline(always)]
fn clamp_four(d: [i64; 4], sat: &mut SatCounter) -> [i64; 4] {
    let o = |k: usize| bary_offset(d[k]);
    if o(0).max(o(1)).max(o(2).max(o(3))) <= 2 * BARY_LIMIT as u64 {
        return d;
    }
    clamp_each(d, sat)
}

/// [`clamp_four`] when one derivative or more is beyond the limit.
#[cold]
#[inline(never)]
fn clamp_each(d: [i64; 4], sat: &mut SatCounter) -> [i64; 4] {
    d.map(|v| clamp_derivative(v, sat))
}

/// A derivative clamped to +-[`BARY_LIMIT`], the clamp counted ([`clamp_counted`]).
#[inline(always)]
fn clamp_derivative(v: i64, sat: &mut SatCounter) -> i64 {
    if v.unsigned_abs() > BARY_LIMIT as u64 {
        return clamp_counted(v, sat);
    }
    v
}

/// A derivative beyond +-[`BARY_LIMIT`]: the clamp, counted.
#[cold]
#[inline(never)]
fn clamp_counted(v: i64, sat: &mut SatCounter) -> i64 {
    sat.saturated += 1;
    v.clamp(-BARY_LIMIT, BARY_LIMIT)
}

/// The same datapath as [`perspective_bary`] when every `q_i` and their sum fit `i64`
/// (the common case): identical bits, without `i128` arithmetic. `None` when they do not fit.
#[inline(always)]
fn perspective_bary_narrow<M: ConstRounding>(
    edge: [i64; 3],
    inv_w: [i64; 3],
    cfg: &InterpConfig,
    recip: &Reciprocal,
) -> Option<([i64; 3], Evaluated)> {
    let q = [
        edge[0].checked_mul(inv_w[0])?,
        edge[1].checked_mul(inv_w[1])?,
        edge[2].checked_mul(inv_w[2])?,
    ];
    let d = q[0].checked_add(q[1])?.checked_add(q[2])?;
    let (p, dn, r0) = bary_from_q::<M>(q, d, cfg, recip)?;
    Some((p, Some((dn, r0))))
}

/// [`perspective_bary_narrow`] from the exact products `q_i = E_i invw_i` and their sum `d`
/// (all in `i64`): the barycentrics, the reciprocal's argument and its result. `None` when
/// `d <= 0` or a `p_i` needs the clamp; nothing is counted (the argument is not 0).
#[inline(always)]
fn bary_from_q<M: ConstRounding>(
    q: [i64; 3],
    d: i64,
    cfg: &InterpConfig,
    recip: &Reciprocal,
) -> Option<([i64; 3], u64, Recip)> {
    if d <= 0 {
        return None;
    }
    // d < 2^63 has at most 63 significant bits; the wide path keeps the top 62.
    let s = (64 - d.leading_zeros()).saturating_sub(62);
    let dn = (d >> s) as u64;
    let r0 = recip.eval(dn, &mut SatCounter::default());
    let r = Recip {
        mant: r0.mant,
        shift: r0.shift + s as i32,
    };
    let p1 = apply_i64_in::<M>(r, q[1], cfg.bary_bits);
    let p2 = apply_i64_in::<M>(r, q[2], cfg.bary_bits);
    if p1.unsigned_abs() > BARY_LIMIT as u64 || p2.unsigned_abs() > BARY_LIMIT as u64 {
        return None;
    }
    Some(([(1i64 << cfg.bary_bits) - p1 - p2, p1, p2], dn, r0))
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
    crate::with_rounding!(out.rounding, M => interpolate_in::<M>(bary, bary_bits, attr, out, sat))
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
    crate::with_rounding!(out.rounding, M => {
        interpolate_span_in::<M, 2>(std::iter::once((bary, result)), bary_bits, attr, out, sat)
    })
}

/// [`interpolate`] of the `N` attributes `attr` (per vertex: a colour's channels, a texture
/// coordinate's pair) at each sample of each lane of a span (one fragment's samples'
/// barycentrics and the slots of their results) into the same index of its results: the
/// per-triangle terms `a0 2^B`, `a1 - a0`, `a2 - a0`, the format's range and the rounding
/// mode resolved once for the span; the same bits and counts as one [`interpolate`] call per
/// sample and attribute, and for pairs as one [`interpolate_pairs`] call per fragment
/// (checked by `interpolate_span_matches_interpolate` and
/// `interpolate_span_of_pairs_matches_per_fragment_calls`).
#[inline]
pub fn interpolate_span<'a, const N: usize>(
    lanes: impl Iterator<Item = (&'a [[i64; 3]], &'a mut [[i64; N]])>,
    bary_bits: u32,
    attr: [[i64; N]; 3],
    out: &Format,
    sat: &mut SatCounter,
) {
    crate::with_rounding!(out.rounding, M => {
        interpolate_span_in::<M, N>(lanes, bary_bits, attr, out, sat)
    })
}

/// [`interpolate_pairs`] of three samples at each lane `j` of `lanes` in a structure of
/// arrays: the barycentrics `bary[sample][component][j]` in, the pair's values
/// `uv[sample][axis][j]` out. The same bits and counts as one [`interpolate_pairs`] call per
/// lane (`interpolate_lanes_matches_interpolate_pairs`): the per-triangle terms and the
/// rounding's constants resolved once, every lane's six values computed in `i64` (as vector
/// lanes where the CPU has AVX2 or AVX-512), and a lane whose barycentrics leave the window
/// where that accumulator is exact, or whose values leave the format's range, computed again by
/// the exact path. `lanes.end` must not exceed `L`.
pub fn interpolate_lanes<const L: usize>(
    bary: &[[[i64; L]; 3]; 3],
    lanes: std::ops::Range<usize>,
    bary_bits: u32,
    attr: [[i64; 2]; 3],
    out: &Format,
    sat: &mut SatCounter,
    uv: &mut [[[i64; L]; 2]; 3],
) {
    crate::with_rounding!(out.rounding, M => {
        interpolate_lanes_in::<M, L>(bary, lanes, bary_bits, attr, out, sat, uv)
    })
}

/// [`interpolate_lanes`] compiled for the rounding mode `M` (`out.rounding`).
#[inline(always)]
fn interpolate_lanes_in<M: ConstRounding, const L: usize>(
    bary: &[[[i64; L]; 3]; 3],
    lanes: std::ops::Range<usize>,
    bary_bits: u32,
    attr: [[i64; 2]; 3],
    out: &Format,
    sat: &mut SatCounter,
    uv: &mut [[[i64; L]; 2]; 3],
) {
    // Short spans, and every lane the vector loop cannot take, lane by lane.
    let mut redo = [true; L];
    if lanes.len() >= PAIR_LANES_MIN {
        if let Some(k) = PairLanes::<M>::new(attr, bary_bits, out) {
            redo = [false; L];
            pair_lanes_vector(&k, bary, lanes.clone(), uv, &mut redo);
            if !redo[lanes.clone()].contains(&true) {
                return;
            }
        }
    }
    for j in lanes.filter(|&j| redo[j]) {
        let b: [[i64; 3]; 3] = std::array::from_fn(|s| [0, 1, 2].map(|c| bary[s][c][j]));
        let mut r = [[0i64; 2]; 3];
        let one = std::iter::once((&b[..], &mut r[..]));
        interpolate_span_in::<M, 2>(one, bary_bits, attr, out, sat);
        for (us, [u, v]) in uv.iter_mut().zip(r) {
            (us[0][j], us[1][j]) = (u, v);
        }
    }
}

/// What [`pair_lanes`] needs of a triangle's pair of attributes: [`interpolate_span`]'s terms
/// (`a0 2^B`, `a1 - a0`, `a2 - a0`), the rounding, the window `[-lim, lim)` of barycentrics
/// for which the accumulator stays exact in `i64`, and the output format's range.
struct PairLanes<M> {
    terms: [(i64, i64, i64); 2],
    round: crate::fixed::ShiftRound<M>,
    lim: u64,
    range: (i64, i64),
}

impl<M: ConstRounding> PairLanes<M> {
    /// `None` where a term leaves `i64` or `bary_bits` is not a shift of 1..=63: then every
    /// lane takes the exact path.
    #[inline(always)]
    fn new(attr: [[i64; 2]; 3], bary_bits: u32, out: &Format) -> Option<Self> {
        let terms = [
            span_terms(&attr, bary_bits, 0)?,
            span_terms(&attr, bary_bits, 1)?,
        ];
        Some(Self {
            terms,
            round: crate::fixed::ShiftRound::new(bary_bits)?,
            lim: narrow_limit(&terms),
            range: (out.min_raw(), out.max_raw()),
        })
    }
}

/// Lanes from which [`interpolate_lanes`] runs a span as vector lanes.
const PAIR_LANES_MIN: usize = 8;

/// The six values of each lane of `lanes` in `i64`, and in `redo` whether any of them has a
/// barycentric outside the window or a value outside the range (those lanes' values are not
/// read). No branch on a lane's data, so the loop runs as vector lanes.
#[inline(always)]
fn pair_lanes<M: ConstRounding, const L: usize>(
    k: &PairLanes<M>,
    bary: &[[[i64; L]; 3]; 3],
    lanes: std::ops::Range<usize>,
    uv: &mut [[[i64; L]; 2]; 3],
    redo: &mut [bool; L],
) {
    let (window, (lo, hi)) = (k.lim.wrapping_mul(2), k.range);
    // Each lane's misses as a 64-bit lane (a `bool` lane beside `i64` ones took a pack and
    // an unpack at every one of the six passes), written to `redo` once.
    let mut miss = [0u64; L];
    for s in 0..3 {
        let (b1, b2) = (&bary[s][1][lanes.clone()], &bary[s][2][lanes.clone()]);
        for (ax, &(t0, d1, d2)) in k.terms.iter().enumerate() {
            let o = &mut uv[s][ax][lanes.clone()];
            let miss = &mut miss[lanes.clone()];
            for (((o, r), &p1), &p2) in o.iter_mut().zip(miss).zip(b1).zip(b2) {
                let inside =
                    ((p1 as u64).wrapping_add(k.lim) | (p2 as u64).wrapping_add(k.lim)) < window;
                let acc = t0
                    .wrapping_add(p1.wrapping_mul(d1))
                    .wrapping_add(p2.wrapping_mul(d2));
                let v = k.round.apply_wrapping(acc);
                *o = v;
                *r |= u64::from(!(inside & (v >= lo) & (v <= hi)));
            }
        }
    }
    for (r, &m) in redo[lanes.clone()].iter_mut().zip(&miss[lanes]) {
        *r |= m != 0;
    }
}

crate::isa_kernel! {
    /// [`pair_lanes`] built for the vector instruction set in force.
    fn pair_lanes_vector[M: ConstRounding, const L: usize](
        k: &PairLanes<M>,
        bary: &[[[i64; L]; 3]; 3],
        lanes: std::ops::Range<usize>,
        uv: &mut [[[i64; L]; 2]; 3],
        redo: &mut [bool; L],
    ) = pair_lanes::<M, L>;
}

/// The sample-independent terms of attribute `ax` of a triangle's `attr` for
/// [`interpolate_span`] and [`interpolate_lanes`]: `a0 2^B`, `a1 - a0`, `a2 - a0` (`B` =
/// `bary_bits`), or `None` where one leaves `i64` (then the exact wide path runs).
#[inline(always)]
fn span_terms<const N: usize>(
    attr: &[[i64; N]; 3],
    bary_bits: u32,
    ax: usize,
) -> Option<(i64, i64, i64)> {
    let a0 = attr[0][ax];
    Some((
        a0.checked_mul(1i64.checked_shl(bary_bits)?)?,
        attr[1][ax].checked_sub(a0)?,
        attr[2][ax].checked_sub(a0)?,
    ))
}

/// [`interpolate_span`] compiled for the rounding mode `M` (`out.rounding`).
#[inline(always)]
fn interpolate_span_in<'a, M: ConstRounding, const N: usize>(
    lanes: impl Iterator<Item = (&'a [[i64; 3]], &'a mut [[i64; N]])>,
    bary_bits: u32,
    attr: [[i64; N]; 3],
    out: &Format,
    sat: &mut SatCounter,
) {
    // The sample-independent terms `a0 2^B`, `a1 - a0`, `a2 - a0` once per attribute; an
    // accumulator that leaves `i64` takes `interpolate`'s exact wide path.
    let all: [Option<(i64, i64, i64)>; N] =
        std::array::from_fn(|ax| span_terms(&attr, bary_bits, ax));
    if all.iter().any(Option::is_none) {
        for (bary, result) in lanes {
            for (b, r) in bary.iter().zip(result.iter_mut()) {
                *r = std::array::from_fn(|ax| {
                    interpolate_cold::<M, N>(b, bary_bits, &attr, ax, out, sat)
                });
            }
        }
        return;
    }
    let terms = all.map(|t| t.unwrap_or_default());
    let range = (out.min_raw(), out.max_raw());
    let lim = narrow_limit(&terms);
    if let Some(round) = crate::fixed::ShiftRound::<M>::new(bary_bits) {
        // `-lim <= p < lim` for both barycentrics: one unsigned compare of their offsets.
        let window = lim.wrapping_mul(2);
        for (bary, result) in lanes {
            for (b, r) in bary.iter().zip(result.iter_mut()) {
                let (o1, o2) = (
                    (b[1] as u64).wrapping_add(lim),
                    (b[2] as u64).wrapping_add(lim),
                );
                if (o1 | o2) < window {
                    let acc = |(t0, d1, d2): (i64, i64, i64)| t0 + b[1] * d1 + b[2] * d2;
                    let fit = |v: i64, sat: &mut SatCounter| {
                        if v >= range.0 && v <= range.1 {
                            v
                        } else {
                            out.fit(v, sat)
                        }
                    };
                    for ax in 0..N {
                        r[ax] = fit(round.apply(acc(terms[ax])), sat);
                    }
                    continue;
                }
                for (ax, (r, &t)) in r.iter_mut().zip(&terms).enumerate() {
                    *r = interpolate_terms::<M, N>(b, t, bary_bits, range, (&attr, ax), out, sat);
                }
            }
        }
        return;
    }
    for (bary, result) in lanes {
        for (b, r) in bary.iter().zip(result.iter_mut()) {
            for (ax, (r, &t)) in r.iter_mut().zip(&terms).enumerate() {
                *r = interpolate_terms::<M, N>(b, t, bary_bits, range, (&attr, ax), out, sat);
            }
        }
    }
}

/// The bound `lim` on the barycentrics, `-lim <= p1, p2 < lim`, within which the accumulators
/// `t0 + p1 d1 + p2 d2` of every attribute's `terms` `(t0, d1, d2)` stay below 2^62 in
/// magnitude, the input range of [`crate::fixed::ShiftRound::apply`] (0 when none does): with
/// every `|t0| < 2^61` and every `|d| < 2^D`, `|p| <= 2^(60 - D)` gives `|p d| < 2^60` and the
/// sum below `2^61 + 2^61`. Checked against the 128-bit accumulator by
/// `interpolate_pairs_matches_interpolate`.
#[inline(always)]
fn narrow_limit(terms: &[(i64, i64, i64)]) -> u64 {
    let top = terms.iter().map(|t| t.0.unsigned_abs()).fold(0, u64::max);
    let dmax = terms
        .iter()
        .map(|t| t.1.unsigned_abs().max(t.2.unsigned_abs()))
        .fold(0, u64::max);
    let bits = 64 - dmax.leading_zeros();
    if top >= 1 << 61 || bits > 60 {
        0
    } else {
        1 << (60 - bits)
    }
}

/// One interpolation from the sample-independent terms `(a0 2^B, a1 - a0, a2 - a0)` of the
/// attribute `column`: the exact accumulator (64x64 -> 128-bit products) when it fits `i64`
/// (else [`interpolate_in`]), then `Format::requantize` from `frac_bits + bary_bits` with the
/// range `(min_raw, max_raw)` of `out` tested inline.
#[inline(always)]
fn interpolate_terms<M: ConstRounding, const N: usize>(
    b: &[i64; 3],
    (t0, d1, d2): (i64, i64, i64),
    bary_bits: u32,
    (lo, hi): (i64, i64),
    (attr, ax): (&[[i64; N]; 3], usize),
    out: &Format,
    sat: &mut SatCounter,
) -> i64 {
    let wide =
        i128::from(t0) + i128::from(b[1]) * i128::from(d1) + i128::from(b[2]) * i128::from(d2);
    let Ok(acc) = i64::try_from(wide) else {
        return interpolate_cold::<M, N>(b, bary_bits, attr, ax, out, sat);
    };
    let v = round_shift_right(acc, bary_bits, M::MODE);
    if v >= lo && v <= hi {
        v
    } else {
        out.fit(v, sat)
    }
}

/// [`interpolate_in`] of the attribute `ax` of `attr` out of line: the rare accumulators
/// beyond `i64`.
#[cold]
#[inline(never)]
fn interpolate_cold<M: ConstRounding, const N: usize>(
    bary: &[i64; 3],
    bary_bits: u32,
    attr: &[[i64; N]; 3],
    ax: usize,
    out: &Format,
    sat: &mut SatCounter,
) -> i64 {
    let column = [attr[0][ax], attr[1][ax], attr[2][ax]];
    interpolate_in::<M>(*bary, bary_bits, column, out, sat)
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

/// Cost of [`perspective_bary_derivs`]: the barycentrics, one more reciprocal and its square,
/// and per axis 3 multiplies, 2 adds, 4 multiplies and 2 subtracts for the numerators and 2
/// reciprocal applications; cycles from [`bary_derivs_datapath`].
#[must_use]
pub fn perspective_bary_derivs_cost(
    cfg: &InterpConfig,
    recip: &Reciprocal,
    gate_levels_per_cycle: u32,
) -> UnitCost {
    let base = perspective_bary_cost(cfg, recip, gate_levels_per_cycle);
    let rc = recip.cost(gate_levels_per_cycle);
    UnitCost {
        ops: base.ops + rc.ops + 1 + 2 * 13,
        cycles: bary_derivs_datapath(cfg, recip.config()).latency(gate_levels_per_cycle),
        texels: 0,
    }
}

/// Cost of one fragment's barycentrics: 3 multiplies, 2 adds, the reciprocal, 2 multiplies
/// and 2 subtracts; cycles from [`bary_datapath`].
#[must_use]
pub fn perspective_bary_cost(
    cfg: &InterpConfig,
    recip: &Reciprocal,
    gate_levels_per_cycle: u32,
) -> UnitCost {
    let rc = recip.cost(gate_levels_per_cycle);
    UnitCost {
        ops: 9 + rc.ops,
        cycles: bary_datapath(cfg, recip.config()).latency(gate_levels_per_cycle),
        texels: 0,
    }
}

/// Cost of one scalar attribute: 2 subtracts, 2 multiplies, 2 adds, 1 round; cycles from
/// [`attribute_datapath`].
#[must_use]
pub fn interpolate_cost(cfg: &InterpConfig, gate_levels_per_cycle: u32) -> UnitCost {
    UnitCost {
        ops: 7,
        cycles: attribute_datapath(cfg).latency(gate_levels_per_cycle),
        texels: 0,
    }
}

/// Width of the edge-function values entering the barycentric multipliers (the rasterizer's
/// snapped coordinates give at most 32 significant bits at the supported resolutions).
pub const EDGE_BITS: u32 = 32;

/// Datapath of [`perspective_bary`] (B = `bary_bits`, W = `inv_w_bits`): the reciprocal of
/// `D`, then (`bary_cycles`) the three `E_i invw_i` products, their sum, two `q_i / D`
/// products and the rounding to B bits.
#[must_use]
pub fn bary_datapath(cfg: &InterpConfig, recip: &ReciprocalConfig) -> Datapath {
    let (b, w) = (cfg.bary_bits, cfg.inv_w_bits);
    let q = EDGE_BITS + w + 1;
    let r = recip.recip_mantissa_bits + 1;
    crate::reciprocal::datapath(recip).stage(
        Stage::new("barycentrics")
            .then_n(
                3,
                Component::Multiplier {
                    a: EDGE_BITS,
                    b: w + 1,
                },
            )
            .then(Component::Adder { width: q + 1 })
            .then(Component::Adder { width: q + 2 })
            .then_n(2, Component::Multiplier { a: 62, b: r })
            .then_n(2, Component::Adder { width: b + 2 })
            .then(Component::Register { bits: 3 * (b + 2) })
            .cycles(cfg.bary_cycles),
    )
}

/// Datapath of [`perspective_bary_derivs`]: [`bary_datapath`], the second reciprocal (of
/// `D^2`), and per screen axis (`bary_cycles` each) the numerators `a D - q S` (3 multiplies,
/// the subtract) and their scaling by `1/D^2` (2 multiplies, rounding).
#[must_use]
pub fn bary_derivs_datapath(cfg: &InterpConfig, recip: &ReciprocalConfig) -> Datapath {
    let b = cfg.bary_bits;
    let r = recip.recip_mantissa_bits + 1;
    bary_datapath(cfg, recip)
        .then(crate::reciprocal::datapath(recip))
        .stage(
            Stage::new("derivatives")
                .then_n(
                    3,
                    Component::Multiplier {
                        a: EDGE_BITS,
                        b: 62,
                    },
                )
                .then_n(2, Component::Adder { width: 96 })
                .then_n(2, Component::Multiplier { a: 62, b: r })
                .then_n(2, Component::Adder { width: b + 2 })
                .then(Component::Register { bits: 2 * (b + 2) })
                .times(2)
                .cycles(cfg.bary_cycles),
        )
}

/// Datapath of [`interpolate`] (A = `texcoord_int_bits + texcoord_frac_bits + 1`): the two
/// differences, two products by the barycentrics, the sum and the rounding
/// (`attr_cycles`).
#[must_use]
pub fn attribute_datapath(cfg: &InterpConfig) -> Datapath {
    let a = cfg.texcoord_int_bits + cfg.texcoord_frac_bits + 1;
    let b = cfg.bary_bits + 2;
    Datapath::new().stage(
        Stage::new("attribute")
            .then_n(2, Component::Adder { width: a + 1 })
            .then_n(2, Component::Multiplier { a: a + 1, b })
            .then(Component::Adder { width: a + b + 1 })
            .then(Component::Adder { width: a + b + 2 })
            .then(Component::Register { bits: a })
            .cycles(cfg.attr_cycles),
    )
}

#[cfg(test)]
mod previous;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::HwConfig;
    use crate::fixed::Rounding;
    use crate::reciprocal::apply;

    use crate::test_rng::splitmix64 as next;

    /// A value of up to `bits` magnitude bits, either sign.
    /// A seeded span for the span tests: `n` lanes, edges of `eb` bits (made positive unless
    /// `i % 3 == 0`; edge `zero` then cleared), steps of `db` bits (x steps shifted right by
    /// `dsh`), `1/w` of `wb` bits with vertex `(i + c) % 3` at 1; `None` when the last lane's
    /// edges leave `i64`.
    fn random_span(
        s: &mut u64,
        (n, eb, db, dsh): (usize, u32, u32, u32),
        (i, c, wb): (usize, usize, u32),
        zero: Option<usize>,
    ) -> Option<(EdgeSpan, [i64; 3])> {
        let mut edge = [0; 3].map(|_| signed(s, eb));
        if i % 3 != 0 {
            edge = edge.map(i64::abs);
        }
        if let Some(k) = zero {
            edge[k] = 0;
        }
        let dx = [0; 3].map(|_| signed(s, db) >> dsh);
        let dy = [0; 3].map(|_| signed(s, db));
        let mut inv_w = [0; 3].map(|_| (next(s) >> (64 - wb)) as i64 + 1);
        inv_w[(i + c) % 3] = 1 << wb;
        let span = EdgeSpan {
            edge,
            dx,
            dy,
            lanes: n,
        };
        last_lane_fits(&span).then_some((span, inv_w))
    }

    /// Lane `j`'s edges `edge + j dx` of `span`, exactly.
    fn lane_at(span: &EdgeSpan, j: usize) -> [i128; 3] {
        [0, 1, 2].map(|k| i128::from(span.edge[k]) + j as i128 * i128::from(span.dx[k]))
    }

    /// `span` moved near the horizon: `E_0` and its x step changed so that `D` is small and
    /// positive along the span while `q_1`, `q_2` stay large (the barycentrics beyond the
    /// clamp); `None` when the moved edges leave `i64`.
    fn near_horizon(s: &mut u64, span: &EdgeSpan, inv_w: [i64; 3]) -> Option<EdgeSpan> {
        let w = inv_w.map(i128::from);
        let d0 = (0..3)
            .map(|k| i128::from(span.edge[k]) * w[k])
            .sum::<i128>();
        let sx = (0..3).map(|k| i128::from(span.dx[k]) * w[k]).sum::<i128>();
        let t = i128::from(next(s) % (1 << 20)) + 1;
        let e0 = i128::from(span.edge[0]) - (d0 - t).div_euclid(w[0]);
        let dx0 = i128::from(span.dx[0]) - sx.div_euclid(w[0]);
        let mut moved = *span;
        (moved.edge[0], moved.dx[0]) = (i64::try_from(e0).ok()?, i64::try_from(dx0).ok()?);
        last_lane_fits(&moved).then_some(moved)
    }

    /// Whether the last lane's edges of `span` fit `i64` (the first lane's do).
    fn last_lane_fits(span: &EdgeSpan) -> bool {
        lane_at(span, span.lanes.max(1) - 1)
            .iter()
            .all(|e| i64::try_from(*e).is_ok())
    }

    /// [`perspective_bary_derivs_span`] of `span` into `got` (lane `j` at `got[j]`); returns
    /// its saturation counts.
    fn span_derivs(
        span: &EdgeSpan,
        inv_w: [i64; 3],
        cfg: &InterpConfig,
        recip: &Reciprocal,
        got: &mut [[[i64; 3]; 3]],
    ) -> SatCounter {
        let mut sat = SatCounter::default();
        perspective_bary_derivs_span(span, inv_w, cfg, recip, &mut sat, |j, b| got[j] = b);
        sat
    }

    /// [`span_derivs`] into lanes ([`DerivLanes`], whose sink takes whole vector batches)
    /// from lane `base` of 32, read back into `got`; panics unless every other lane keeps the
    /// value it had.
    fn span_derivs_in_lanes(
        span: &EdgeSpan,
        inv_w: [i64; 3],
        (cfg, recip): (&InterpConfig, &Reciprocal),
        base: usize,
        got: &mut [[[i64; 3]; 3]],
    ) -> SatCounter {
        const UNTOUCHED: i64 = 0x5a5a_5a5a;
        let mut bary = [[[UNTOUCHED; 32]; 3]; 3];
        let mut sat = SatCounter::default();
        let out = DerivLanes {
            bary: &mut bary,
            base,
        };
        perspective_bary_derivs_span(span, inv_w, cfg, recip, &mut sat, out);
        for (j, lane) in bary[0][0].iter().enumerate() {
            let ours = (base..base + span.lanes).contains(&j);
            if ours {
                got[j - base] = std::array::from_fn(|s| std::array::from_fn(|c| bary[s][c][j]));
            } else {
                let kept = (0..9).all(|k| bary[k / 3][k % 3][j] == UNTOUCHED);
                assert!(
                    kept && *lane == UNTOUCHED,
                    "lane {j} outside {base}..+{}",
                    span.lanes
                );
            }
        }
        sat
    }

    fn signed(s: &mut u64, bits: u32) -> i64 {
        let v = (next(s) >> (64 - bits.clamp(1, 63))) as i64;
        if next(s) & 1 == 1 {
            -v
        } else {
            v
        }
    }

    /// The derivative datapath as it was before the reciprocal was shared with the
    /// barycentrics and the scaled products became 64x64-bit multiplies: the oracle.
    fn derivs_before(
        edge: [i64; 3],
        edge_dx: [i64; 3],
        edge_dy: [i64; 3],
        inv_w: [i64; 3],
        cfg: &InterpConfig,
        recip: &Reciprocal,
        sat: &mut SatCounter,
    ) -> [[i64; 3]; 3] {
        let p = perspective_bary(edge, inv_w, cfg, recip, sat);
        let q = [0, 1, 2].map(|i| i128::from(edge[i]) * i128::from(inv_w[i]));
        let d = q[0] + q[1] + q[2];
        if d <= 0 {
            return [p, p, p];
        }
        let a_of = |de: [i64; 3]| [0, 1, 2].map(|i| i128::from(de[i]) * i128::from(inv_w[i]));
        let (ax, ay) = (a_of(edge_dx), a_of(edge_dy));
        let (sx, sy) = (ax[0] + ax[1] + ax[2], ay[0] + ay[1] + ay[2]);
        let mag = [
            d,
            q[1].abs(),
            q[2].abs(),
            ax[1].abs(),
            ax[2].abs(),
            sx.abs(),
        ]
        .into_iter()
        .chain([ay[1].abs(), ay[2].abs(), sy.abs()])
        .max()
        .unwrap_or(d);
        let shift = (128 - mag.leading_zeros()).saturating_sub(62);
        let ds = d >> shift;
        let mut out = [p, p, p];
        if ds <= 0 {
            sat.saturated += 1;
            return out;
        }
        let r = recip.eval(ds as u64, sat);
        let r2 = square(r, recip.config().recip_mantissa_bits, cfg.interp_rounding);
        for (k, a, sum) in [(1usize, ax, sx), (2, ay, sy)] {
            let ss = sum >> shift;
            for i in 1..3 {
                let n = (a[i] >> shift) * ds - (q[i] >> shift) * ss;
                let ns = (128 - n.unsigned_abs().leading_zeros()).saturating_sub(94);
                let v = apply(r2, n >> ns, cfg.bary_bits + ns, cfg.interp_rounding);
                let dp = v.clamp(-BARY_LIMIT, BARY_LIMIT);
                if dp != v {
                    sat.saturated += 1;
                }
                out[k][i] = p[i] + dp;
            }
            out[k][0] = (1i64 << cfg.bary_bits) - out[k][1] - out[k][2];
        }
        out
    }

    /// 3M seeded cases: the shared-reciprocal datapath gives the old one's bits and counts,
    /// over small and huge edge values (the 64-bit and 128-bit barycentric paths, scale
    /// shifts of 0 and above, reciprocal arguments equal to the barycentrics' and not, D <= 0
    /// and scaled D <= 0), on three interpolator/reciprocal configurations.
    #[test]
    fn derivs_match_the_previous_datapath() {
        let mut cfgs = vec![HwConfig::texram16(), HwConfig::d3d11()];
        let mut c = HwConfig::texram16();
        c.reciprocal.recip_iterations = 1;
        c.reciprocal.recip_rounding = Rounding::HalfUp;
        c.interp.bary_bits = 16;
        c.interp.interp_rounding = Rounding::Truncate;
        cfgs.push(c);
        let mut s = 0x5eed_0b41;
        let (mut reused, mut fresh) = (0u64, 0u64);
        for hw in &cfgs {
            let recip = Reciprocal::new(&hw.reciprocal);
            for i in 0..1_000_000u32 {
                let eb = [20, 38, 40, 50, 62][(i % 5) as usize];
                let db = [4, 26, 40, 62][(i / 5 % 4) as usize];
                let mut edge = [0; 3].map(|_| signed(&mut s, eb));
                if i % 3 != 0 {
                    edge = edge.map(i64::abs);
                }
                let dx = [0; 3].map(|_| signed(&mut s, db));
                let dy = [0; 3].map(|_| signed(&mut s, db));
                let wb = hw.interp.inv_w_bits;
                let mut inv_w = [0; 3].map(|_| (next(&mut s) >> (64 - wb)) as i64 + 1);
                inv_w[(i % 3) as usize] = 1 << wb;
                let (mut sa, mut sb) = (SatCounter::default(), SatCounter::default());
                let got = perspective_bary_derivs(edge, dx, dy, inv_w, &hw.interp, &recip, &mut sa);
                let want = derivs_before(edge, dx, dy, inv_w, &hw.interp, &recip, &mut sb);
                assert_eq!(got, want, "{edge:?} {dx:?} {dy:?} {inv_w:?}");
                assert_eq!(sa, sb, "{edge:?} {dx:?} {dy:?} {inv_w:?}");
                // Whether the shared evaluation was reused: the scaled D (by the largest
                // magnitude among D, q_i, a_i and their sums) equals the barycentrics' argument.
                let (_, ev) = crate::with_rounding!(hw.interp.interp_rounding, M => {
                    perspective_bary_eval::<M>(edge, inv_w, &hw.interp, &recip, &mut sa)
                });
                let w = |e: [i64; 3]| [0, 1, 2].map(|k| i128::from(e[k]) * i128::from(inv_w[k]));
                let (q, ax, ay) = (w(edge), w(dx), w(dy));
                let d: i128 = q.iter().sum();
                let mag = [q[1], q[2], ax[1], ax[2], ay[1], ay[2]]
                    .into_iter()
                    .chain([ax.iter().sum::<i128>(), ay.iter().sum(), d])
                    .map(i128::unsigned_abs)
                    .max()
                    .unwrap_or(0);
                let ds = d >> (128 - mag.leading_zeros()).saturating_sub(62);
                match ev {
                    Some((x, _)) if d > 0 && i128::from(x) == ds => reused += 1,
                    _ => fresh += 1,
                }
            }
        }
        // Both branches of the reuse were exercised.
        assert!(reused > 100_000 && fresh > 100_000, "{reused} {fresh}");
    }

    /// [`perspective_bary_derivs`] as it was before its 64-bit operand path (every operand in
    /// `i128`, the scale from the largest magnitude by comparison): the oracle, verbatim but
    /// for the mode passed as a type.
    fn derivs_all_wide<M: ConstRounding>(
        edge: [i64; 3],
        edge_dx: [i64; 3],
        edge_dy: [i64; 3],
        inv_w: [i64; 3],
        cfg: &InterpConfig,
        recip: &Reciprocal,
        sat: &mut SatCounter,
    ) -> [[i64; 3]; 3] {
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
        let down = |v: i128| (v >> shift) as i64;
        let ds = down(d);
        let mut out = [p, p, p];
        if ds <= 0 {
            sat.saturated += 1;
            return out;
        }
        let r = match evaluated {
            Some((x, r)) if x == ds as u64 => r,
            _ => recip.eval(ds as u64, sat),
        };
        let r2 = square_before(r, recip.config().recip_mantissa_bits, M::MODE);
        let ds = i128::from(ds);
        for (k, a, sum) in [(1usize, ax, sx), (2, ay, sy)] {
            let ss = i128::from(down(sum));
            for i in 1..3 {
                let n = i128::from(down(a[i])) * ds - i128::from(down(q[i])) * ss;
                let ns = (128 - n.unsigned_abs().leading_zeros()).saturating_sub(94);
                let v = apply_in::<M>(r2, n >> ns, cfg.bary_bits + ns);
                let dp = v.clamp(-BARY_LIMIT, BARY_LIMIT);
                if dp != v {
                    sat.saturated += 1;
                }
                out[k][i] = p[i] + dp;
            }
            out[k][0] = (1i64 << cfg.bary_bits) - out[k][1] - out[k][2];
        }
        out
    }

    /// `reciprocal::square` as it was before its 64-bit path: the oracle.
    fn square_before(r: Recip, m_bits: u32, mode: Rounding) -> Recip {
        let sq = i128::from(r.mant) * i128::from(r.mant);
        let b = 128 - sq.leading_zeros();
        let drop = b.saturating_sub(m_bits + 1);
        let mut mant = round_shift_right_wide(sq, drop, mode) as u64;
        let mut shift = 2 * r.shift - drop as i32;
        if mant >> (m_bits + 1) != 0 {
            mant >>= 1;
            shift -= 1;
        }
        Recip { mant, shift }
    }

    /// 3M seeded cases around the 64-bit operand path's boundaries (products `E_i invw_i`
    /// and `dE_i invw_i` of 56 to 64 bits, so their sums and the common scale of 0, 1 and 2
    /// bits straddle `i64`), every rounding mode: the derivatives give the all-`i128`
    /// datapath's bits and counts, and both the 64-bit path and its fallback are taken.
    #[test]
    fn derivs_narrow_path_matches_the_all_wide_datapath() {
        let mut s = 0x5eed_0b42;
        let (mut narrow, mut wide) = (0u64, 0u64);
        for (j, mode) in [Rounding::HalfEven, Rounding::HalfUp, Rounding::Truncate]
            .into_iter()
            .enumerate()
        {
            let mut hw = if j == 1 {
                HwConfig::d3d11()
            } else {
                HwConfig::texram16()
            };
            hw.interp.interp_rounding = mode;
            let recip = Reciprocal::new(&hw.reciprocal);
            let wb = hw.interp.inv_w_bits;
            for i in 0..1_000_000u32 {
                let eb = 62 - wb - 1 + (i % 4);
                let db = [eb, eb - 1, eb - 4, 20][(i / 4 % 4) as usize];
                let mut edge = [0; 3].map(|_| signed(&mut s, eb));
                if i % 5 != 0 {
                    edge = edge.map(i64::abs);
                }
                let dx = [0; 3].map(|_| signed(&mut s, db));
                let dy = [0; 3].map(|_| signed(&mut s, db));
                let mut inv_w = [0; 3].map(|_| (next(&mut s) >> (64 - wb)) as i64 + 1);
                inv_w[(i % 3) as usize] = 1 << wb;
                let (mut sa, mut sb) = (SatCounter::default(), SatCounter::default());
                let got = perspective_bary_derivs(edge, dx, dy, inv_w, &hw.interp, &recip, &mut sa);
                let want = crate::with_rounding!(mode, M => {
                    derivs_all_wide::<M>(edge, dx, dy, inv_w, &hw.interp, &recip, &mut sb)
                });
                assert_eq!(got, want, "{edge:?} {dx:?} {dy:?} {inv_w:?}");
                assert_eq!(sa, sb, "{edge:?} {dx:?} {dy:?} {inv_w:?}");
                let mut scratch = SatCounter::default();
                let took = crate::with_rounding!(mode, M => {
                    perspective_bary_derivs_narrow::<M>(
                        edge, dx, dy, inv_w, &hw.interp, &recip, &mut scratch,
                    )
                });
                match took {
                    Some(v) => {
                        assert_eq!(v, want);
                        narrow += 1;
                    }
                    None => wide += 1,
                }
            }
        }
        assert!(narrow > 300_000 && wide > 300_000, "{narrow} {wide}");
    }

    /// 3M seeded mantissas over every mantissa width 8..=30 and mode (top and bottom of each
    /// width, ties of the dropped bits included) and 200k wider ones (the 128-bit fallback):
    /// `square` gives the previous routine's bits.
    #[test]
    fn square_matches_the_previous_routine() {
        let mut s = 0x5eed_0b43;
        for i in 0..3_200_000u32 {
            let mb = 8 + i % 23;
            let mant = match i % 8 {
                0 => 1u64 << mb,
                1 => (2u64 << mb) - 1,
                _ if i >= 3_000_000 => next(&mut s) >> (1 + next(&mut s) % 33),
                _ => (1u64 << mb) | (next(&mut s) >> (64 - mb)),
            };
            let r = Recip {
                mant,
                shift: (next(&mut s) % 200) as i32 - 60,
            };
            for mode in [Rounding::Truncate, Rounding::HalfUp, Rounding::HalfEven] {
                assert_eq!(
                    square(r, mb, mode),
                    square_before(r, mb, mode),
                    "{r:?} {mb}"
                );
            }
        }
    }

    /// 2M seeded cases, every mode and both overflow rules, attributes and barycentrics from
    /// small to near the `i64` boundaries of the accumulator (the sample-independent terms
    /// overflowing, the per-sample sum overflowing, both fitting): `interpolate_pairs` gives
    /// one `interpolate` call per sample and attribute, bits and counts, also with the
    /// barycentrics at and next to the ends of [`narrow_limit`]'s window; the 64-bit
    /// accumulators within it are taken by over 500k samples, the others by over 500k.
    #[test]
    fn interpolate_pairs_matches_interpolate() {
        let mut s = 0x5eed_0b44;
        let (mut narrow, mut wide) = (0u32, 0u32);
        for i in 0..2_000_000u32 {
            let mode = [Rounding::Truncate, Rounding::HalfUp, Rounding::HalfEven][(i % 3) as usize];
            let overflow = if i % 7 == 0 {
                crate::fixed::Overflow::Wrap
            } else {
                crate::fixed::Overflow::Saturate
            };
            let bb = [16, 24, 30][(i / 3 % 3) as usize];
            let out = Format::signed(8 + i % 9, [12, 24, 30][(i / 9 % 3) as usize], mode)
                .with_overflow(overflow);
            let ab = [20, 33, 40, 62][(i / 27 % 4) as usize];
            let attr = [0; 3].map(|_| [signed(&mut s, ab), signed(&mut s, ab)]);
            let n = 1 + (i % 3) as usize;
            let t0 = attr[0].map(|a| a.checked_mul(1 << bb).unwrap_or(i64::MAX));
            let d = [0, 1].map(|ax| [1, 2].map(|v| attr[v][ax].wrapping_sub(attr[0][ax])));
            let lim = narrow_limit(&[0, 1].map(|ax| (t0[ax], d[ax][0], d[ax][1]))) as i64;
            let pb = [bb + 1, 30, 45, 60][(i / 108 % 4) as usize];
            let mut bary =
                [0; 3].map(|_| [signed(&mut s, pb), signed(&mut s, pb), signed(&mut s, pb)]);
            if i % 5 == 0 {
                // Barycentrics at the ends of the window `-lim <= p < lim` and just outside.
                let edge = [-lim - 1, -lim, -lim + 1, lim - 1, lim, 0];
                for b in &mut bary {
                    b[1] = edge[(next(&mut s) % 6) as usize];
                    b[2] = edge[(next(&mut s) % 6) as usize];
                }
            }
            let (mut sa, mut sb) = (SatCounter::default(), SatCounter::default());
            let mut got = [[0i64; 2]; 3];
            interpolate_pairs(&bary[..n], bb, attr, &out, &mut sa, &mut got[..n]);
            for b in &bary[..n] {
                if (-lim..lim).contains(&b[1]) && (-lim..lim).contains(&b[2]) {
                    narrow += 1;
                } else {
                    wide += 1;
                }
            }
            for k in 0..3 {
                let want = if k < n {
                    [0, 1].map(|ax| {
                        let c = [attr[0][ax], attr[1][ax], attr[2][ax]];
                        interpolate(bary[k], bb, c, &out, &mut sb)
                    })
                } else {
                    [0, 0]
                };
                assert_eq!(got[k], want, "{bary:?} {attr:?} {out:?}");
            }
            assert_eq!(sa, sb, "{bary:?} {attr:?} {out:?}");
        }
        assert!(narrow > 500_000 && wide > 500_000, "{narrow} {wide}");
    }

    /// Interpolator and reciprocal configurations of the comparisons with the previous
    /// routines: the presets' (texram16, d3d11, vulkan-min) and variants that take every
    /// branch of the reciprocal (one iteration, a 4-bit LUT, 30-bit mantissa so that the
    /// Newton-Raphson products leave `i64`, 16-bit barycentrics, half-up reciprocal).
    fn previous_configs() -> Vec<HwConfig> {
        let mut cfgs = vec![
            HwConfig::texram16(),
            HwConfig::d3d11(),
            HwConfig::vulkan_min(),
        ];
        let mut c = HwConfig::texram16();
        c.reciprocal.recip_iterations = 1;
        c.reciprocal.recip_rounding = Rounding::HalfUp;
        c.interp.bary_bits = 16;
        cfgs.push(c);
        let mut c = HwConfig::texram16();
        c.reciprocal.recip_mantissa_bits = 30;
        c.reciprocal.recip_lut_bits = 4;
        c.reciprocal.recip_iterations = 3;
        c.reciprocal.recip_rounding = Rounding::Truncate;
        c.interp.bary_bits = 30;
        cfgs.push(c);
        cfgs
    }

    /// 3M seeded cases over 5 configurations x 3 interpolator roundings, edge values from 4 to
    /// 62 bits (inside and outside the triangle), steps from 4 to 62 bits: the barycentrics
    /// and their derivatives give the previous routines' bits and saturation counts, and both
    /// the 64-bit operand path and the `i128` fallback are taken many times.
    #[test]
    fn bary_and_derivs_match_the_previous_routines() {
        let mut s = 0x5eed_0b45;
        let (mut narrow, mut wide) = (0u64, 0u64);
        for hw0 in previous_configs() {
            for mode in [Rounding::HalfEven, Rounding::HalfUp, Rounding::Truncate] {
                let mut hw = hw0.clone();
                hw.interp.interp_rounding = mode;
                let recip = Reciprocal::new(&hw.reciprocal);
                let wb = hw.interp.inv_w_bits;
                for i in 0..200_000u32 {
                    let eb =
                        [4, 20, 38, 62 - wb - 1, 62 - wb, 62 - wb + 2, 50, 62][(i % 8) as usize];
                    let db = [4, 26, eb.saturating_sub(1).max(1), 40, 62][(i / 8 % 5) as usize];
                    let mut edge = [0; 3].map(|_| signed(&mut s, eb));
                    if i % 3 != 0 {
                        edge = edge.map(i64::abs);
                    }
                    let dx = [0; 3].map(|_| signed(&mut s, db));
                    let dy = [0; 3].map(|_| signed(&mut s, db));
                    let mut inv_w = [0; 3].map(|_| (next(&mut s) >> (64 - wb)) as i64 + 1);
                    inv_w[(i % 3) as usize] = 1 << wb;
                    let (cfg, why) = (&hw.interp, (edge, dx, dy, inv_w, mode));
                    let (mut sa, mut sb) = (SatCounter::default(), SatCounter::default());
                    let got = perspective_bary(edge, inv_w, cfg, &recip, &mut sa);
                    let want = previous::perspective_bary(edge, inv_w, cfg, &recip, &mut sb);
                    assert_eq!((got, sa), (want, sb), "{why:?}");
                    let got = perspective_bary_derivs(edge, dx, dy, inv_w, cfg, &recip, &mut sa);
                    let want = previous::perspective_bary_derivs(
                        edge, dx, dy, inv_w, cfg, &recip, &mut sb,
                    );
                    assert_eq!((got, sa), (want, sb), "{why:?}");
                    let took = crate::with_rounding!(mode, M => {
                        let mut scratch = SatCounter::default();
                        perspective_bary_derivs_narrow::<M>(
                            edge, dx, dy, inv_w, cfg, &recip, &mut scratch,
                        )
                    });
                    if took.is_some() {
                        narrow += 1;
                    } else {
                        wide += 1;
                    }
                }
            }
        }
        assert!(narrow > 500_000 && wide > 500_000, "{narrow} {wide}");
    }

    /// 3M seeded cases, every mode and both overflow rules, attributes and barycentrics from
    /// small to near the `i64` boundaries of the accumulator: `interpolate_pairs` gives the
    /// previous routine's bits and counts, with both its 64-bit accumulator and the exact
    /// wide fallback taken many times.
    #[test]
    fn interpolate_pairs_matches_the_previous_routine() {
        let mut s = 0x5eed_0b46;
        let (mut fast, mut fallback) = (0u64, 0u64);
        for i in 0..1_000_000u32 {
            let mode = [Rounding::Truncate, Rounding::HalfUp, Rounding::HalfEven][(i % 3) as usize];
            let overflow = if i % 7 == 0 {
                crate::fixed::Overflow::Wrap
            } else {
                crate::fixed::Overflow::Saturate
            };
            let bb = [16, 24, 30, 1][(i / 3 % 4) as usize];
            let out = Format::signed(8 + i % 9, [12, 24, 28][(i / 12 % 3) as usize], mode)
                .with_overflow(overflow);
            let ab = [20, 33, 40, 62][(i / 36 % 4) as usize];
            let attr = [0; 3].map(|_| [signed(&mut s, ab), signed(&mut s, ab)]);
            let pb = [bb + 1, 30, 45, 60][(i / 144 % 4) as usize];
            let bary = [0; 3].map(|_| [signed(&mut s, pb), signed(&mut s, pb), signed(&mut s, pb)]);
            for n in 1..=3 {
                let (mut sa, mut sb) = (SatCounter::default(), SatCounter::default());
                let (mut got, mut want) = ([[0i64; 2]; 3], [[0i64; 2]; 3]);
                interpolate_pairs(&bary[..n], bb, attr, &out, &mut sa, &mut got[..n]);
                previous::interpolate_pairs(&bary[..n], bb, attr, &out, &mut sb, &mut want[..n]);
                assert_eq!((got, sa), (want, sb), "{bary:?} {attr:?} {out:?}");
            }
            for (b, ax) in bary.iter().zip([0, 1, 0]) {
                let c = [attr[0][ax], attr[1][ax], attr[2][ax]];
                let acc = (|| {
                    c[0].checked_mul(1 << bb)?
                        .checked_add(b[1].checked_mul(c[1].checked_sub(c[0])?)?)?
                        .checked_add(b[2].checked_mul(c[2].checked_sub(c[0])?)?)
                })();
                if acc.is_some() {
                    fast += 1;
                } else {
                    fallback += 1;
                }
            }
        }
        assert!(fast > 500_000 && fallback > 500_000, "{fast} {fallback}");
    }

    /// `held_drop` against `numerator_top` at every lane: 200k seeded numerators below 2^125
    /// and steps (many crossing zero inside the span with large ends); when it holds a drop,
    /// every lane has that drop, and it holds one for many spans with a nonzero drop.
    #[test]
    fn held_drop_matches_every_lane() {
        let mut s = 0x5eed_0d40;
        let (mut held, mut nonzero) = (0u64, 0u64);
        for i in 0..200_000u32 {
            let last = (next(&mut s) % 24) as usize;
            let nb = 62 + (next(&mut s) % 63) as u32;
            let n = i128::from(signed(&mut s, 62)) << (nb - 62);
            // Steps that reach, cross or stay clear of zero across the span.
            let step = match i % 3 {
                0 => -n / (last.max(1) as i128) + i128::from(signed(&mut s, 20)),
                1 => i128::from(signed(&mut s, 62)) << (nb.saturating_sub(66)),
                _ => -2 * n / (last.max(1) as i128),
            };
            let lanes = (0..=last).map(|j| step.checked_mul(j as i128)?.checked_add(n));
            if lanes
                .clone()
                .any(|v| v.is_none_or(|v| v.unsigned_abs() >> 125 != 0))
            {
                continue;
            }
            let lanes = lanes.flatten();
            if let Some(ns) = held_drop(n, step, last) {
                held += 1;
                nonzero += u64::from(ns > 0);
                for v in lanes {
                    assert_eq!(numerator_top(v).1, ns, "{n} {step} {last}");
                }
            }
        }
        assert!(held > 50_000 && nonzero > 10_000, "{held} {nonzero}");
    }

    /// 2M seeded operands (magnitudes of every bit length up to the bounds, low words of
    /// zeros and of ones, so that the carries and the sticky bit are at their edges): the
    /// vector lanes' products give the 128-bit ones, `mul_wide_lane` the product of `q`
    /// (below 2^62) and a mantissa below 2^32, `product_top_lane` the `product_top` of a
    /// numerator top (below 2^94) and a mantissa below 2^29.
    #[test]
    fn lane_products_match_the_wide_products() {
        let mut s = 0x5eed_0b48;
        let mut sticky_edge = 0u32;
        for i in 0..1_000_000u32 {
            let low_bits = |s: &mut u64, k: u32| match k % 4 {
                0 => 0,
                1 => u64::MAX >> (k % 64),
                _ => next(s),
            };
            let q = ((next(&mut s) as i64 >> 2) >> (i % 62)) & !((1i64 << (i % 40)) - 1);
            let q = if i % 7 == 0 {
                q | low_bits(&mut s, i) as i64 >> 2
            } else {
                q
            };
            let mant = next(&mut s) >> (32 + i % 32);
            let (hi, lo) = mul_wide_lane(q, mant);
            let want = i128::from(q) * i128::from(mant);
            assert_eq!(i128::from(hi) << 64 | i128::from(lo), want, "{q} {mant}");
            // A top below 2^94: random, or a multiple of 2^62 with at most one bit below
            // (and a power-of-two mantissa), so that the product's low 62 bits are zero or one
            // bit at any place.
            let top = (next(&mut s) as i64 >> (32 + i % 31)) as i128;
            let (x, m2) = match i % 3 {
                0 => {
                    let x = (i128::from(next(&mut s) as i64) << 32)
                        | i128::from(low_bits(&mut s, i / 3) >> 32);
                    (x >> (i % 5), (next(&mut s) >> (35 + i % 29)).max(1))
                }
                1 => (top << 62, (next(&mut s) >> (35 + i % 29)).max(1)),
                _ => {
                    let k = (next(&mut s) % 62) as u32;
                    let sign = if i % 2 == 0 { 1 } else { -1 };
                    (
                        (top << 62) + sign * (1i128 << k),
                        1 << (next(&mut s) % (62 - u64::from(k)).min(29)),
                    )
                }
            };
            let r2 = Recip { mant: m2, shift: 0 };
            let got = product_top_lane(((x >> 64) as i64, x as u64), m2);
            assert_eq!(got, product_top(x, r2), "{x} {m2}");
            sticky_edge += u32::from(((x * i128::from(m2)) as u64) << 2 == 0);
        }
        assert!(sticky_edge > 100_000, "{sticky_edge}");
    }

    /// [`clamp_four`] clamps and counts each derivative beyond +-[`BARY_LIMIT`] and passes
    /// the others (the span datapath's derivatives never reach it).
    #[test]
    fn clamp_four_clamps_and_counts_each_derivative_beyond_the_limit() {
        let mut sat = SatCounter::default();
        let within = [BARY_LIMIT, -BARY_LIMIT, 0, -5];
        assert_eq!(clamp_four(within, &mut sat), within);
        assert_eq!(sat.saturated, 0);
        let d = [BARY_LIMIT + 1, -3, i64::MIN / 2, 7];
        assert_eq!(clamp_four(d, &mut sat), [BARY_LIMIT, -3, -BARY_LIMIT, 7]);
        assert_eq!(sat.saturated, 2);
    }

    /// `y_top_lane` against the 128-bit sum and shift it stands for: 4M seeded cases of
    /// numerators and steps of 1 to 127 bits either sign, every lane 0..16 and drop 0..64.
    #[test]
    fn y_top_lane_matches_the_wide_form() {
        let mut s = 0x0707_1e5e;
        let wide = |s: &mut u64| {
            let bits = 1 + (next(s) % 127) as u32;
            let x = (u128::from(next(s)) << 64 | u128::from(next(s))) as i128;
            x >> (128 - bits)
        };
        for _ in 0..1 << 18 {
            let (ny, step, ns) = (wide(&mut s), wide(&mut s), (next(&mut s) % 64) as u32);
            for c in 0..16i64 {
                let want = words(ny.wrapping_add(i128::from(c).wrapping_mul(step)) >> ns);
                assert_eq!(
                    y_top_lane(words(ny), words(step), ns, c),
                    want,
                    "{ny} {step} {ns} {c}"
                );
            }
        }
    }

    /// 480k seeded spans of 1 to 24 lanes over 6 configurations x 3 interpolator roundings,
    /// edges and steps from 4 to 62 bits, so that `q_i = E_i invw_i` and `D` at the span's
    /// ends straddle `i64` and 2^62: `perspective_bary_derivs_span` gives one
    /// `perspective_bary_derivs` call per lane, bits and counts, and lanes of the fast form
    /// are many in spans that take the steady loop (steps and both ends below 2^62), in other
    /// spans whose `q_1`, `q_2`, `D` step along the span (both ends fit `i64`) and in spans
    /// whose lanes test their own; a quarter of the spans are moved near the horizon (`D`
    /// small and positive), so that many lanes of the held loop need the clamp of `p_i`. Spans
    /// of 8 lanes or more run the held loop's vector batches where the CPU has AVX2 or AVX-512:
    /// many of their lanes take the batch's fast form, and many the scalar lane (the clamp). Every
    /// other span goes into lanes from a random base ([`DerivLanes`], which stores a batch
    /// whose lanes all took the fast form whole): the same bits, the other lanes untouched.
    #[test]
    fn derivs_span_stepping_matches_per_lane_calls() {
        let mut s = 0x5eed_0b47;
        let (mut held_lanes, mut steady_lanes) = (0u64, 0u64);
        let (mut stepped, mut tested, mut held_small) = (0u64, 0u64, 0u64);
        let (mut held_clamped, mut held_batched) = (0u64, [0u64; 2]);
        let mut got = [[[0i64; 3]; 3]; 24];
        // The widest mantissa of the held loop, with the reciprocal truncating.
        let mut widest = HwConfig::texram16();
        widest.reciprocal.recip_mantissa_bits = 28;
        widest.reciprocal.recip_lut_bits = 4;
        widest.reciprocal.recip_iterations = 3;
        widest.reciprocal.recip_rounding = Rounding::Truncate;
        widest.interp.bary_bits = 20;
        let mut cfgs = previous_configs();
        cfgs.push(widest);
        for (c, hw0) in cfgs.into_iter().enumerate() {
            for mode in [Rounding::HalfEven, Rounding::HalfUp, Rounding::Truncate] {
                let mut hw = hw0.clone();
                hw.interp.interp_rounding = mode;
                let (cfg, recip) = (&hw.interp, Reciprocal::new(&hw.reciprocal));
                let wb = cfg.inv_w_bits;
                for i in 0..(400_000 / 15) {
                    let n = 1 + (next(&mut s) % 24) as usize;
                    let eb = [20, 40, 62 - wb - 1, 62 - wb, 63 - wb, 62][(i % 6) as usize];
                    // The last: steps that carry a span from the fast form out of `i64`.
                    let (db, dsh) = [(4, 5), (30, 5), (eb.saturating_sub(3).max(1), 5), (eb, 5)]
                        .into_iter()
                        .chain([(60 - wb, 0)])
                        .nth((i / 6 % 5) as usize)
                        .unwrap_or((4, 5));
                    let Some((mut span, inv_w)) =
                        random_span(&mut s, (n, eb, db, dsh), (i as usize, c, wb), None)
                    else {
                        continue;
                    };
                    if i % 4 == 3 {
                        let Some(moved) = near_horizon(&mut s, &span, inv_w) else {
                            continue;
                        };
                        span = moved;
                    }
                    let EdgeSpan { edge, dx, dy, .. } = span;
                    let at = |j: usize| lane_at(&span, j);
                    // Every other span into lanes from a random base.
                    let sa = if i % 2 == 0 {
                        span_derivs(&span, inv_w, cfg, &recip, &mut got)
                    } else {
                        let base = (next(&mut s) % (33 - n as u64)) as usize;
                        span_derivs_in_lanes(&span, inv_w, (cfg, &recip), base, &mut got)
                    };
                    let mut sb = SatCounter::default();
                    // Whether the ends' products and sums fit `i64` (the span steps them).
                    let fits = |j: usize| {
                        let q = [0, 1, 2].map(|k| at(j)[k] * i128::from(inv_w[k]));
                        [q[0], q[1], q[2], q[0] + q[1], q[0] + q[1] + q[2]]
                            .iter()
                            .all(|v| i64::try_from(*v).is_ok())
                    };
                    let ends_fit = fits(0) && fits(n - 1);
                    // Whether the span takes the steady loop: its steps and both ends below 2^62.
                    let below = |v: &[i128]| v.iter().all(|x| x.unsigned_abs() >> 62 == 0);
                    let step_terms = |de: [i64; 3]| {
                        let v = [0, 1, 2].map(|k| i128::from(de[k]) * i128::from(inv_w[k]));
                        [v[1], v[2], v[0] + v[1] + v[2]]
                    };
                    let small_end = |j: usize| {
                        let q = [0, 1, 2].map(|k| at(j)[k] * i128::from(inv_w[k]));
                        let d = q[0] + q[1] + q[2];
                        d > 0 && below(&[q[1], q[2], d])
                    };
                    let steady = ends_fit
                        && below(&step_terms(dx))
                        && below(&step_terms(dy))
                        && small_end(0)
                        && small_end(n - 1);
                    // Whether a steady span holds its y numerators' drops: the numerators
                    // `b_i D - q_i T` have one sign and one drop at both ends.
                    let y_numerators = |j: usize| {
                        let q = [0, 1, 2].map(|k| at(j)[k] * i128::from(inv_w[k]));
                        let b = step_terms(dy);
                        let d = q[0] + q[1] + q[2];
                        [1, 2].map(|k| b[k - 1] * d - q[k] * b[2])
                    };
                    let held = steady && recip.config().recip_mantissa_bits <= 28 && {
                        let (f, l) = (y_numerators(0), y_numerators(n - 1));
                        (0..2).all(|k| {
                            (f[k] < 0) == (l[k] < 0)
                                && numerator_top(f[k]).1 == numerator_top(l[k]).1
                        })
                    };
                    for (j, lane) in got[..n].iter().enumerate() {
                        let e = at(j).map(|v| v as i64);
                        let want = perspective_bary_derivs(e, dx, dy, inv_w, cfg, &recip, &mut sb);
                        let why = (e, dx, dy, inv_w, mode, c, j, n);
                        assert_eq!(*lane, want, "{why:?}");
                        let q = [0, 1, 2].map(|k| i128::from(e[k]) * i128::from(inv_w[k]));
                        let d = q[0] + q[1] + q[2];
                        if d > 0
                            && (d.unsigned_abs() | q[1].unsigned_abs() | q[2].unsigned_abs()) >> 62
                                == 0
                        {
                            if held {
                                held_lanes += 1;
                                let clamped = want[0][1..].iter().any(|v| v.abs() == BARY_LIMIT);
                                held_clamped += u64::from(clamped);
                                // Lanes of the vector batches (on a CPU with AVX2 or AVX-512).
                                if n >= HELD_MIN_LANES {
                                    held_batched[usize::from(clamped)] += 1;
                                }
                                // The lanes whose barycentrics take `apply_i64_small_in`.
                                let r = recip.eval(d as u64, &mut SatCounter::default());
                                let sh = r.shift - cfg.bary_bits as i32;
                                held_small += u64::from((1..64).contains(&sh));
                            } else if steady {
                                steady_lanes += 1;
                            } else if ends_fit {
                                stepped += 1;
                            } else {
                                tested += 1;
                            }
                        }
                    }
                    assert_eq!(sa, sb, "{edge:?} {dx:?} {dy:?} {inv_w:?} {mode:?} {c} {n}");
                }
            }
        }
        println!(
            "held {held_lanes} (small apply {held_small}, clamped {held_clamped}) steady \
             {steady_lanes} stepped {stepped} tested {tested}"
        );
        assert!(held_clamped > 50_000, "{held_clamped}");
        // Batched lanes of both forms: the batch's own and the scalar lane's.
        assert!(
            held_batched[0] > 200_000 && held_batched[1] > 20_000,
            "{held_batched:?}"
        );
        assert!(
            held_lanes > 500_000 && steady_lanes > 100_000 && held_small > 200_000,
            "{held_lanes} {held_small} {steady_lanes}"
        );
        assert!(stepped > 100_000 && tested > 40_000, "{stepped} {tested}");
    }

    /// 40k seeded rows of 1 to 24 spans of 1 to 12 lanes (about 3.2M lanes; the rows of a
    /// mesh), each span with its own `1/w`, over 6 configurations x 3 interpolator roundings,
    /// edges and steps as in `derivs_span_stepping_matches_per_lane_calls` (a quarter of the
    /// spans near the horizon): one `perspective_bary_derivs_spans` call per row gives each
    /// lane once, with the bits of one [`perspective_bary_derivs`] call per lane and the
    /// row's saturation counts. Many lanes are in the held form (gathered across the spans
    /// into vector batches where the CPU has AVX2 or AVX-512), many of those need the clamp (the
    /// per-sample datapath from a batch), and many spans take the other forms.
    #[test]
    fn gathered_spans_match_per_lane_calls() {
        let mut s = 0x6a7e_42ed;
        let (mut lanes, mut held, mut held_clamped, mut other) = (0u64, 0u64, 0u64, 0u64);
        let mut widest = HwConfig::texram16();
        widest.reciprocal.recip_mantissa_bits = 28;
        widest.reciprocal.recip_lut_bits = 4;
        widest.reciprocal.recip_iterations = 2;
        widest.reciprocal.recip_rounding = Rounding::Truncate;
        widest.interp.bary_bits = 20;
        let mut cfgs = previous_configs();
        cfgs.push(widest);
        let mut rows = 0u64;
        for (c, hw0) in cfgs.into_iter().enumerate() {
            for mode in [Rounding::HalfEven, Rounding::HalfUp, Rounding::Truncate] {
                let mut hw = hw0.clone();
                hw.interp.interp_rounding = mode;
                let (cfg, recip) = (&hw.interp, Reciprocal::new(&hw.reciprocal));
                let (wb, m_bits) = (cfg.inv_w_bits, recip.config().recip_mantissa_bits);
                for r in 0..(40_000 / 18) {
                    let mut spans = Vec::new();
                    for i in 0..1 + next(&mut s) % 24 {
                        let i = (r * 24 + i) as usize;
                        let n = 1 + (next(&mut s) % 12) as usize;
                        let eb = [20, 40, 62 - wb - 1, 62 - wb, 20, 40][i % 6];
                        let (db, dsh) =
                            [(4, 5), (30, 5), (eb.saturating_sub(3).max(1), 5)][i / 6 % 3];
                        let Some((mut span, inv_w)) =
                            random_span(&mut s, (n, eb, db, dsh), (i, c, wb), None)
                        else {
                            continue;
                        };
                        if i % 4 == 3 {
                            let Some(moved) = near_horizon(&mut s, &span, inv_w) else {
                                continue;
                            };
                            span = moved;
                        }
                        spans.push(DerivSpan { span, inv_w });
                    }
                    let mut got = vec![vec![None; 12]; spans.len()];
                    let mut sa = SatCounter::default();
                    perspective_bary_derivs_spans(&spans, cfg, &recip, &mut sa, |i, j, v| {
                        assert!(got[i][j].replace(v).is_none(), "lane {j} of span {i} twice");
                    });
                    let mut sb = SatCounter::default();
                    for (ds, got) in spans.iter().zip(&got) {
                        let DerivSpan { span, inv_w } = *ds;
                        #[cfg(target_arch = "x86_64")]
                        let is_held = held_form(&span, inv_w, m_bits).is_some();
                        #[cfg(not(target_arch = "x86_64"))]
                        let is_held = false;
                        for (j, lane) in got.iter().enumerate() {
                            if j >= span.lanes {
                                assert_eq!(*lane, None);
                                continue;
                            }
                            let e = lane_at(&span, j).map(|v| v as i64);
                            let (dx, dy) = (span.dx, span.dy);
                            let want =
                                perspective_bary_derivs(e, dx, dy, inv_w, cfg, &recip, &mut sb);
                            assert_eq!(*lane, Some(want), "{:?}", (span, inv_w, mode, c, j));
                            lanes += 1;
                            if is_held {
                                held += 1;
                                let clamped = want[0][1..].iter().any(|v| v.abs() == BARY_LIMIT);
                                held_clamped += u64::from(clamped);
                            } else {
                                other += 1;
                            }
                        }
                    }
                    assert_eq!(sa, sb, "row {r} of configuration {c}, {mode:?}");
                    rows += 1;
                }
            }
        }
        println!("rows {rows} lanes {lanes}: held {held} (clamped {held_clamped}), other {other}");
        assert!(rows > 35_000 && lanes > 2_500_000, "{rows} {lanes}");
        assert!(
            held > 1_000_000 && held_clamped > 100_000,
            "{held} {held_clamped}"
        );
        assert!(other > 1_000_000, "{other}");
    }

    /// 270k seeded spans of 1 to 8 lanes (the short spans of a mesh) over 5 configurations x
    /// 3 interpolator roundings, edge values from 4 to 62 bits with zero edges and steps from
    /// 4 bits to the edges' size: every lane of the span datapaths gives
    /// the bits and saturation counts of one [`perspective_bary_derivs`] call per lane.
    #[test]
    fn short_spans_match_per_lane_calls() {
        let mut s = 0x5407_5fa2;
        let (mut short, mut spans) = (0u64, 0u64);
        let mut got = [[[0i64; 3]; 3]; 8];
        for (c, hw0) in previous_configs().into_iter().enumerate() {
            for mode in [Rounding::HalfEven, Rounding::HalfUp, Rounding::Truncate] {
                let mut hw = hw0.clone();
                hw.interp.interp_rounding = mode;
                let (cfg, recip) = (&hw.interp, Reciprocal::new(&hw.reciprocal));
                let wb = cfg.inv_w_bits;
                for i in 0..18_000u64 {
                    let n = 1 + (next(&mut s) % 8) as usize;
                    let eb = [4, 20, 40, 62 - wb - 1, 62 - wb, 63 - wb, 62][(i % 7) as usize];
                    let db = [4, 20, eb.saturating_sub(3).max(1), eb][(i / 7 % 4) as usize];
                    let zero = (i % 5 == 0).then_some((i / 5 % 3) as usize);
                    let dsh = (i % 2 * 5) as u32;
                    let Some((span, inv_w)) =
                        random_span(&mut s, (n, eb, db, dsh), (i as usize, c, wb), zero)
                    else {
                        continue;
                    };
                    let EdgeSpan { edge, dx, dy, .. } = span;
                    let at = |j: usize| lane_at(&span, j);
                    let sa = span_derivs(&span, inv_w, cfg, &recip, &mut got);
                    let mut sb = SatCounter::default();
                    for (j, lane) in got[..n].iter().enumerate() {
                        let e = at(j).map(|v| v as i64);
                        let want = perspective_bary_derivs(e, dx, dy, inv_w, cfg, &recip, &mut sb);
                        assert_eq!(*lane, want, "{:?}", (e, dx, dy, inv_w, mode, c, j, n));
                    }
                    assert_eq!(sa, sb, "{edge:?} {dx:?} {dy:?} {inv_w:?} {mode:?} {c} {n}");
                    spans += 1;
                    short += u64::from(n == 1);
                }
            }
        }
        assert!(spans > 200_000 && short > 20_000, "{spans} {short}");
    }
}
