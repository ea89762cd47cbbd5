//! Reciprocal unit: LUT seed plus Newton-Raphson refinement `y' = y (2 - m y)` (the classic
//! scheme of e.g. Flynn 1970 / Oberman & Flynn 1997), as used for 1/w and 1/area.
//!
//! Datapath (M = `recip_mantissa_bits`, L = `recip_lut_bits`, N = `recip_iterations`,
//! G = [`GUARD_BITS`], P = M + G working fraction bits):
//! 1. Normalize: `x = m * 2^n`, `m` in [1, 2), by a leading-zero count. `m` is rounded to P
//!    fraction bits by `recip_rounding` (exact when `x` has at most P + 1 significant bits);
//!    a carry to 2.0 renormalizes.
//! 2. Seed: the top L fraction bits of `m` index a table whose entry i is
//!    `2^(L+1) / (2^(L+1) + 2i + 1)` (the reciprocal of the interval midpoint, which minimizes
//!    `max |1 - m y|` over the interval) rounded to P fraction bits, computed in integers at
//!    [`Reciprocal::new`].
//! 3. N steps `t = m*y`, `d = 2 - t`, `y = y*d`, each product rounded to P fraction bits by
//!    `recip_rounding`.
//! 4. `y` is rounded to M + 1 significant bits by `recip_rounding` into [`Recip`].
//!
//! ERROR BOUND (relative, `e` = |1/x - result| * x): let `e_0 = 2^-(L+1) + 2^-P` and
//! `e_{k+1} = e_k^2 + 4 * 2^-P`; then `e <= e_N + 2^-M` (in result ulps, where one ulp is
//! `2^-shift`: at most `2^(M+1) e_N + 1`, or `+ 0.5` for the round-to-nearest modes;
//! `tests/units/unit_reciprocal.rs` asserts `2^(M+1) (e_N + 2^-P) 1.001` plus those, a margin
//! of one working ulp and 0.1% for evaluating the bound in floating point). The seed
//! error halves per LUT bit and squares per iteration: with L = 8 and M = 24, one iteration is
//! limited by the seed (~2^-18, 128 ulps), so texram16 (L=8, N=2, M=24) uses two, which reach
//! the rounding floor (<= 1 ulp). Measured max error (ulps, M = 24, HalfEven;
//! `cargo test --test units unit_reciprocal:: -- --nocapture`): (L,N) = (8,0) 65352, (8,1) 128.0 and
//! (8,2) 0.75 (both exhaustive over all 24-bit x), (10,1) 8.3, (12,1) 1.16, (6,2) 0.82,
//! (4,3) 0.74, (16,0) 256.

use crate::config::ReciprocalConfig;
use crate::cost::UnitCost;
use crate::datapath::{ceil_log2, Component, Datapath, Stage};
use crate::fixed::{
    round_shift_right_lane, round_shift_right_mid, round_shift_right_small, round_shift_right_wide,
    round_shift_right_wide_small, ConstRounding, Rounding, SatCounter,
};
use std::marker::PhantomData;

#[cfg(test)]
pub(crate) mod previous;

/// Guard bits carried by the working precision beyond `recip_mantissa_bits`.
pub const GUARD_BITS: u32 = 3;

/// A reciprocal `mant * 2^-shift`; `mant` has exactly `recip_mantissa_bits + 1` bits (top bit set).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Recip {
    /// Normalized mantissa in `[2^M, 2^(M+1))`.
    pub mant: u64,
    /// Binary exponent: the value is `mant * 2^-shift`.
    pub shift: i32,
}

/// The reciprocal unit: its config and the seed table built from it.
#[derive(Clone, Debug)]
pub struct Reciprocal {
    cfg: ReciprocalConfig,
    /// Seed entries with P fraction bits, values in (1/2, 1).
    lut: Vec<u64>,
    /// Working fraction bits P.
    p: u32,
}

impl Reciprocal {
    /// Builds the unit and its seed table (integer arithmetic only). Widths outside the ranges
    /// of `HwConfig::validate` are clamped to them.
    #[must_use]
    pub fn new(cfg: &ReciprocalConfig) -> Self {
        let mut cfg = cfg.clone();
        cfg.recip_lut_bits = cfg.recip_lut_bits.clamp(1, 16);
        cfg.recip_iterations = cfg.recip_iterations.min(4);
        cfg.recip_mantissa_bits = cfg.recip_mantissa_bits.clamp(8, 30);
        let l = cfg.recip_lut_bits;
        let p = cfg.recip_mantissa_bits + GUARD_BITS;
        let lut = (0..(1u64 << l))
            .map(|i| {
                // 2^P * 2^(L+1) / (2^(L+1) + 2i + 1), rounded to nearest (ties cannot occur:
                // the denominator is odd).
                let num = 1i128 << (p + l + 1);
                let den = i128::from((1u64 << (l + 1)) + 2 * i + 1);
                crate::fixed::round_div_i128(num, den, crate::fixed::Rounding::HalfUp) as u64
            })
            .collect();
        Self { cfg, lut, p }
    }

    /// The (range-clamped) config the unit was built from.
    #[must_use]
    pub fn config(&self) -> &ReciprocalConfig {
        &self.cfg
    }

    /// `1/x` for an integer mantissa `x` (the caller tracks its binary point). `x == 0`
    /// returns the largest value `(2^(M+1) - 1) * 2^0` (at least 1/x for every x >= 1) and
    /// counts a saturation.
    #[inline]
    #[must_use]
    pub fn eval(&self, x: u64, sat: &mut SatCounter) -> Recip {
        crate::with_rounding!(self.cfg.recip_rounding, R => self.lane::<R>().eval(x, sat))
    }

    /// The unit resolved for many evaluations: `R` must be the type of `recip_rounding`
    /// (resolve it once with [`crate::with_rounding!`]).
    #[inline(always)]
    #[must_use]
    pub fn lane<R: ConstRounding>(&self) -> RecipLane<'_, R> {
        debug_assert_eq!(R::MODE, self.cfg.recip_rounding);
        RecipLane {
            lut: &self.lut,
            p: self.p,
            idx_up: self.cfg.recip_lut_bits.saturating_sub(self.p),
            idx_down: self.p.saturating_sub(self.cfg.recip_lut_bits),
            idx_mask: (1i64 << self.cfg.recip_lut_bits) - 1,
            iterations: self.cfg.recip_iterations,
            m_bits: self.cfg.recip_mantissa_bits,
            mode: PhantomData,
        }
    }

    /// Cost of one evaluation: normalize, LUT, 3 ops per iteration, final round; cycles from
    /// [`datapath`] at `gate_levels_per_cycle`.
    #[must_use]
    pub fn cost(&self, gate_levels_per_cycle: u32) -> UnitCost {
        UnitCost {
            ops: 3 + 3 * self.cfg.recip_iterations,
            cycles: datapath(&self.cfg).latency(gate_levels_per_cycle),
            texels: 0,
        }
    }
}

/// A [`Reciprocal`] with its rounding mode as the type `R` and its widths and seed table
/// loaded once ([`Reciprocal::lane`]): a span evaluates it per lane without dispatching on the
/// mode or reloading the config. [`RecipLane::eval`] is [`Reciprocal::eval`]'s datapath
/// (checked against the previous routine and `eval` in the tests below).
#[derive(Clone, Copy, Debug)]
pub struct RecipLane<'a, R> {
    /// Seed entries with P fraction bits.
    lut: &'a [u64],
    /// Working fraction bits P.
    p: u32,
    /// The seed index of `m` (P fraction bits, below 2^(P+1)) is its top L fraction bits:
    /// `(m << idx_up) >> idx_down` (`L - P` and `P - L`, whichever is positive; a wider index
    /// sees zeros below `m`'s bits) masked by `idx_mask` (`2^L - 1`).
    idx_up: u32,
    /// See `idx_up`.
    idx_down: u32,
    /// See `idx_up`.
    idx_mask: i64,
    /// `recip_iterations` N.
    iterations: u32,
    /// `recip_mantissa_bits` M.
    m_bits: u32,
    /// The rounding mode `R` (`recip_rounding`).
    mode: PhantomData<R>,
}

impl<R: ConstRounding> RecipLane<'_, R> {
    /// [`Reciprocal::eval`]: `1/x`, `x == 0` saturated and counted.
    #[inline(always)]
    #[must_use]
    pub fn eval(&self, x: u64, sat: &mut SatCounter) -> Recip {
        let m_bits = self.m_bits;
        if x == 0 {
            sat.saturated += 1;
            return Recip {
                mant: (1u64 << (m_bits + 1)) - 1,
                shift: 0,
            };
        }
        let p = self.p;
        let rnd = R::MODE;
        let n = 63 - x.leading_zeros();
        // m with P fraction bits, in [2^P, 2^(P+1)] (a rounding up reaches 2^(P+1)).
        let m: i64 = if n <= p {
            (x << (p - n)) as i64
        } else if n < 62 {
            // `x` below 2^62, `n - p` in 1..=60.
            round_shift_right_small::<R>(x as i64, n - p)
        } else if n < 63 {
            // `n - p` in 1..=62.
            round_shift_right_mid::<R>(x as i64, n - p)
        } else {
            round_shift_right_wide(i128::from(x), n - p, rnd)
        };
        let (m, n, mut y) = self.seed(m, n);
        if (1..=29).contains(&p) {
            y = self.steps_narrow(m, y, self.iterations);
        } else {
            let two = 2i64 << p;
            for _ in 0..self.iterations {
                y = nr_step(m, y, two, p, rnd);
            }
        }
        // Normalize y (positive, about 2^P / m) to M + 1 significant bits.
        self.normalized(y, p + n)
    }
}

impl<R: ConstRounding> RecipLane<'_, R> {
    /// The `recip_iterations` N when the working width P is in 1..=29 (where
    /// [`RecipLane::eval_narrow`] applies), else `None`.
    #[inline(always)]
    #[must_use]
    pub fn narrow_iterations(&self) -> Option<u32> {
        (1..=29).contains(&self.p).then_some(self.iterations)
    }

    /// [`RecipLane::eval`] of an `x` in 1..2^62 when P is in 1..=29 and `recip_iterations`
    /// is `N` ([`RecipLane::narrow_iterations`]): the same steps without the tests those bounds
    /// settle (checked against `eval` in `eval_narrow_matches_eval`).
    #[inline(always)]
    #[must_use]
    pub fn eval_narrow<const N: u32>(&self, x: u64) -> Recip {
        debug_assert!(x != 0 && x >> 62 == 0 && (1..=29).contains(&self.p));
        debug_assert_eq!(N, self.iterations);
        let p = self.p;
        let n = 63 - x.leading_zeros();
        // m with P fraction bits, in [2^P, 2^(P+1)]; `x` below 2^62, `n - p` in 1..=60.
        let m: i64 = if n <= p {
            (x << (p - n)) as i64
        } else {
            round_shift_right_small::<R>(x as i64, n - p)
        };
        let (m, n, y) = self.seed(m, n);
        self.normalized(self.steps_narrow(m, y, N), p + n)
    }

    /// `m` (P fraction bits, below 2^(P+2)) brought into [2^P, 2^(P+1)) with its exponent `n`,
    /// and its seed from the table: `(m, n, y)`.
    #[inline(always)]
    fn seed(&self, mut m: i64, mut n: u32) -> (i64, u32, i64) {
        if m >> (self.p + 1) != 0 {
            m >>= 1;
            n += 1;
        }
        // Top L fraction bits of m (m has only P; a wider index sees zeros below them); m is
        // below 2^34 and L - P at most 5, so the left shift is exact.
        let idx = (((m << self.idx_up) >> self.idx_down) & self.idx_mask) as usize;
        (m, n, self.lut[idx] as i64)
    }

    /// `iterations` Newton-Raphson steps from the seed `y` when P is in 1..=29: `nr_step`'s
    /// 64-bit products without its tests on P. With `m` in [1, 2) and the seed in (1/2, 1],
    /// `y` stays at most 1/m + 2^(1-p) (`y (2 - m y) <= 1/m`), so `t` is in [0, 2] and both
    /// products are below 2^(2p+2) <= 2^60.
    #[inline(always)]
    fn steps_narrow(&self, m: i64, mut y: i64, iterations: u32) -> i64 {
        let p = self.p;
        let two = 2i64 << p;
        for _ in 0..iterations {
            let t = round_shift_right_small::<R>(m * y, p);
            y = round_shift_right_small::<R>(y * (two - t), p);
        }
        y
    }

    /// The last step of [`RecipLane::eval`]: `y` (positive, below 2^(P+2)) rounded to M + 1
    /// significant bits, the result `y * 2^-(p + n)`.
    #[inline(always)]
    fn normalized(&self, y: i64, pn: u32) -> Recip {
        let m_bits = self.m_bits;
        let b = 64 - (y as u64).leading_zeros();
        let drop = b - (m_bits + 1);
        let mut mant = if (1..64).contains(&drop) {
            // `y` is below 2^(P+2) <= 2^35.
            round_shift_right_small::<R>(y, drop)
        } else {
            crate::fixed::round_shift_right(y, drop, R::MODE)
        } as u64;
        let mut shift = pn as i32 - drop as i32;
        if mant >> (m_bits + 1) != 0 {
            mant >>= 1;
            shift -= 1;
        }
        Recip { mant, shift }
    }
}

/// 64-bit lanes in one AVX-512 register: a batch of [`RecipLane::eval_square_lanes`] is a
/// multiple of it.
pub(crate) const RECIP_LANES: usize = 8;

impl<R: ConstRounding> RecipLane<'_, R> {
    /// [`RecipLane::eval_narrow`] of each `x[j]` (in 1..2^62; P in 1..=29 and `N` the
    /// iteration count, as there) with its [`square`] rounded by `S`: the same bits, written
    /// lane by lane with every per-lane choice a select (the normalizing shifts through
    /// [`round_shift_right_lane`]), so that its loops over the lanes vectorize (several
    /// registers of lanes each step: independent chains the core overlaps). Checked against
    /// `eval_narrow` and `square` in `eval_square_lanes_match_eval_narrow`.
    #[inline(always)]
    pub(crate) fn eval_square_lanes<const N: u32, S: ConstRounding, const L: usize>(
        &self,
        x: &[u64; L],
        out: &mut RecipLanes<L>,
    ) {
        debug_assert!((1..=29).contains(&self.p) && N == self.iterations);
        let (p, m_bits) = (u64::from(self.p), u64::from(self.m_bits));
        // 2^recip_lut_bits entries: every masked index is in range, with no test per lane.
        let lut = &self.lut[..=self.idx_mask as usize];
        let (mut m, mut n, mut y) = ([0i64; L], [0u64; L], [0i64; L]);
        for j in 0..L {
            debug_assert!(x[j] != 0 && x[j] >> 62 == 0, "{}", x[j]);
            // m with P fraction bits in [2^P, 2^(P+1)]: `x` moved up, or rounded down.
            let nj = 63 - u64::from(x[j].leading_zeros());
            let (up, down) = (p.saturating_sub(nj), nj.saturating_sub(p));
            let mj = round_shift_right_lane::<R>((x[j] << up) as i64, down as u32);
            // The seed: m brought below 2^(P+1), its top `recip_lut_bits` fraction bits the
            // index.
            let carry = (mj >> (p + 1)) as u64;
            let mj = mj >> carry;
            let idx = ((mj << self.idx_up) >> self.idx_down) & self.idx_mask;
            (m[j], n[j], y[j]) = (mj, nj + carry, lut[idx as usize] as i64);
        }
        let two = 2i64 << p;
        for _ in 0..N {
            for j in 0..L {
                let t = round_shift_right_small::<R>(m[j] * y[j], p as u32);
                y[j] = round_shift_right_small::<R>(y[j] * (two - t), p as u32);
            }
        }
        for j in 0..L {
            // [`RecipLane::normalized`]: `y` to M + 1 significant bits (a drop of 1 to 3).
            let b = 64 - u64::from((y[j] as u64).leading_zeros());
            let drop = b - (m_bits + 1);
            debug_assert!(drop < 64, "{drop}");
            let mant = round_shift_right_lane::<R>(y[j], drop as u32) as u64;
            let over = mant >> (m_bits + 1);
            let (mant, shift) = (mant >> over, (p + n[j]) as i64 - (drop + over) as i64);
            // [`square`]: a mantissa below 2^31, its square below 2^62.
            let sq = (mant * mant) as i64;
            let drop2 = (64 - u64::from(sq.leading_zeros())).saturating_sub(m_bits + 1);
            let mant2 = round_shift_right_lane::<S>(sq, drop2 as u32) as u64;
            let over2 = mant2 >> (m_bits + 1);
            out.mant[j] = mant;
            out.shift[j] = shift;
            out.mant2[j] = mant2 >> over2;
            out.shift2[j] = 2 * shift - (drop2 + over2) as i64;
        }
    }
}

/// The results of one [`RecipLane::eval_square_lanes`] batch, lane by lane: `1/x` and its
/// square as mantissas and shifts ([`Recip`]'s fields), in arrays (what the vector unit writes).
#[derive(Clone, Copy, Debug)]
pub(crate) struct RecipLanes<const L: usize> {
    mant: [u64; L],
    shift: [i64; L],
    mant2: [u64; L],
    shift2: [i64; L],
}

impl<const L: usize> Default for RecipLanes<L> {
    fn default() -> Self {
        Self {
            mant: [0; L],
            shift: [0; L],
            mant2: [0; L],
            shift2: [0; L],
        }
    }
}

impl<const L: usize> RecipLanes<L> {
    /// Lane `j`'s `1/x` and its square.
    #[inline(always)]
    #[must_use]
    pub(crate) fn get(&self, j: usize) -> (Recip, Recip) {
        (
            Recip {
                mant: self.mant[j],
                shift: self.shift[j] as i32,
            },
            Recip {
                mant: self.mant2[j],
                shift: self.shift2[j] as i32,
            },
        )
    }
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
#[inline(always)]
#[must_use]
pub fn square(r: Recip, m_bits: u32, mode: Rounding) -> Recip {
    let (drop, mut mant) = if r.mant >> 31 == 0 {
        // A mantissa of at most 31 bits (every `Reciprocal` result): the square fits `i64`.
        let sq = (r.mant * r.mant) as i64;
        let drop = (64 - sq.leading_zeros()).saturating_sub(m_bits + 1);
        // `sq` is below 2^62.
        let v = if drop == 0 {
            sq
        } else {
            crate::with_rounding!(mode, M => round_shift_right_small::<M>(sq, drop))
        };
        (drop, v as u64)
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
    let sh = r.shift - frac_bits as i32;
    // |x| < 2^96 and a mantissa below 2^31 (at most 30 bits + 1, every `Reciprocal` result
    // and its `square`): the product is exact below 2^127, then the one rounding.
    if sh >= 0 && x.unsigned_abs() >> 96 == 0 && r.mant >> 31 == 0 {
        return round_shift_right_wide(x * i128::from(r.mant), sh as u32, M::MODE);
    }
    apply_general::<M>(r, x, sh)
}

/// [`apply_in`] of an `x` that fits `i64` (the barycentrics' `q_i`): the same bits, the
/// product a single 64x64 -> 128-bit multiply.
#[inline(always)]
#[must_use]
pub fn apply_i64_in<M: ConstRounding>(r: Recip, x: i64, frac_bits: u32) -> i64 {
    let sh = r.shift - frac_bits as i32;
    if sh >= 0 && r.mant >> 31 == 0 {
        let prod = i128::from(x) * i128::from(r.mant as i64);
        return round_shift_right_wide(prod, sh as u32, M::MODE);
    }
    apply_general::<M>(r, i128::from(x), sh)
}

/// [`apply_i64_in`] for `|x| < 2^62` and a mantissa below 2^29 (the product below 2^91)
/// when `r.shift - frac_bits` is in 1..=63: the one rounding is
/// [`round_shift_right_wide_small`]'s. `None` outside that shift range or when the result
/// leaves `i64` (where [`apply_i64_in`] saturates).
#[inline(always)]
#[must_use]
pub fn apply_i64_small_in<M: ConstRounding>(r: Recip, x: i64, frac_bits: u32) -> Option<i64> {
    debug_assert!(x.unsigned_abs() >> 62 == 0 && r.mant >> 29 == 0);
    let sh = r.shift - frac_bits as i32;
    if !(1..64).contains(&sh) {
        return None;
    }
    round_shift_right_wide_small::<M>(i128::from(x) * i128::from(r.mant as u32), sh as u32)
}

/// [`apply_in`] for any operands, `sh` = `r.shift - frac_bits`: the product saturated to
/// `i128`, then rounded (`sh >= 0`) or scaled up and saturated (`sh < 0`).
#[inline(never)]
fn apply_general<M: ConstRounding>(r: Recip, x: i128, sh: i32) -> i64 {
    let mode = M::MODE;
    let prod = x.saturating_mul(i128::from(r.mant));
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

/// The unit's datapath (P = M + G working bits): normalize (leading-zero count and shift of
/// the P + 1-bit mantissa), the seed ROM (`recip_lut_cycles`), N Newton-Raphson steps
/// (`m y`, `2 - t`, `y d`, each product rounded; `recip_iteration_cycles` each) and the final
/// rounding to M + 1 bits.
#[must_use]
pub fn datapath(cfg: &ReciprocalConfig) -> Datapath {
    let m = cfg.recip_mantissa_bits;
    let p = m + GUARD_BITS;
    let w = p + 1;
    Datapath::new()
        .stage(
            Stage::new("normalize")
                .then(Component::LeadingZeros { width: 64 })
                .then(Component::Shifter {
                    width: w,
                    shift_bits: 6,
                })
                .then(Component::Adder { width: w }),
        )
        .stage(
            Stage::new("seed ROM")
                .then(Component::Rom {
                    addr_bits: cfg.recip_lut_bits,
                    data_bits: w,
                })
                .cycles(cfg.recip_lut_cycles),
        )
        .stage(
            Stage::new("Newton-Raphson step")
                .then(Component::Multiplier { a: w, b: w })
                .then(Component::Adder { width: w + 1 })
                .then(Component::Multiplier { a: w, b: w + 1 })
                .then(Component::Adder { width: w })
                .times(cfg.recip_iterations)
                .cycles(cfg.recip_iteration_cycles),
        )
        .stage(
            Stage::new("round")
                .then(Component::LeadingZeros { width: w + 1 })
                .then(Component::Shifter {
                    width: w + 1,
                    shift_bits: ceil_log2(w + 1),
                })
                .then(Component::Adder { width: m + 1 })
                .then(Component::Register { bits: m + 1 + 8 }),
        )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::HwConfig;
    use crate::fixed::round_shift_right;

    const MODES: [Rounding; 3] = [Rounding::Truncate, Rounding::HalfUp, Rounding::HalfEven];

    use crate::test_rng::splitmix64 as next;

    /// `eval` as it was before it was compiled per rounding mode (the mode read from the
    /// config at every reduction): the oracle.
    fn eval_before(u: &Reciprocal, x: u64, sat: &mut SatCounter) -> Recip {
        let m_bits = u.cfg.recip_mantissa_bits;
        if x == 0 {
            sat.saturated += 1;
            return Recip {
                mant: (1u64 << (m_bits + 1)) - 1,
                shift: 0,
            };
        }
        let (p, rnd) = (u.p, u.cfg.recip_rounding);
        let mut n = 63 - x.leading_zeros();
        let mut m: i64 = if n <= p {
            (x << (p - n)) as i64
        } else if n < 63 {
            round_shift_right(x as i64, n - p, rnd)
        } else {
            round_shift_right_wide(i128::from(x), n - p, rnd)
        };
        if m >> (p + 1) != 0 {
            m >>= 1;
            n += 1;
        }
        let l = u.cfg.recip_lut_bits;
        let top = if l <= p { m >> (p - l) } else { m << (l - p) };
        let mut y = u.lut[(top & ((1i64 << l) - 1)) as usize] as i64;
        for _ in 0..u.cfg.recip_iterations {
            y = nr_step(m, y, 2i64 << p, p, rnd);
        }
        let b = 64 - (y as u64).leading_zeros();
        let drop = b - (m_bits + 1);
        let mut mant = round_shift_right(y, drop, rnd) as u64;
        let mut shift = (p + n) as i32 - drop as i32;
        if mant >> (m_bits + 1) != 0 {
            mant >>= 1;
            shift -= 1;
        }
        Recip { mant, shift }
    }

    /// `apply` as it was before the mode became a type and the unchecked product: the oracle.
    fn apply_before(r: Recip, x: i128, frac_bits: u32, mode: Rounding) -> i64 {
        let sh = r.shift - frac_bits as i32;
        if sh >= 0 {
            if let (Ok(x64), Ok(m64)) = (i64::try_from(x), i64::try_from(r.mant)) {
                if let Some(prod) = x64.checked_mul(m64) {
                    return round_shift_right(prod, sh as u32, mode);
                }
            }
        }
        let prod = x.saturating_mul(i128::from(r.mant));
        if sh >= 0 {
            round_shift_right_wide(prod, sh as u32, mode)
        } else {
            let up = (-sh) as u32;
            if up >= 64 {
                match prod.signum() {
                    0 => 0,
                    1 => i64::MAX,
                    _ => i64::MIN,
                }
            } else {
                round_shift_right_wide(prod.saturating_mul(1i128 << up), 0, mode)
            }
        }
    }

    /// `base` with the seed table's index bits `l`, `n` Newton-Raphson steps, `mb` mantissa
    /// bits and the rounding `mode`.
    fn config(
        base: &ReciprocalConfig,
        (l, n, mb): (u32, u32, u32),
        mode: Rounding,
    ) -> ReciprocalConfig {
        ReciprocalConfig {
            recip_lut_bits: l,
            recip_iterations: n,
            recip_mantissa_bits: mb,
            recip_rounding: mode,
            ..base.clone()
        }
    }

    /// 3M seeded arguments over 15 configurations (every mode; LUT, iteration and mantissa
    /// widths varied; arguments of 1 to 64 bits and 0): `eval` and `apply` give the old bits, `apply`
    /// across the 64-bit path, the unchecked 128-bit product (|x| < 2^96) and the saturating
    /// one beyond it, with positive and negative scale.
    #[test]
    fn eval_and_apply_match_the_previous_datapath() {
        let mut s = 0x5eed_0005;
        let base = HwConfig::texram16().reciprocal;
        for mode in MODES {
            for (l, n, mb) in [(8, 2, 24), (8, 1, 24), (4, 3, 30), (12, 1, 16), (16, 0, 8)] {
                let cfg = config(&base, (l, n, mb), mode);
                let u = Reciprocal::new(&cfg);
                for i in 0..200_000u32 {
                    let x = if i == 0 { 0 } else { next(&mut s) >> (i % 64) };
                    let (mut sa, mut sb) = (SatCounter::default(), SatCounter::default());
                    let r = u.eval(x, &mut sa);
                    assert_eq!(r, eval_before(&u, x, &mut sb), "1/{x} {cfg:?}");
                    assert_eq!(sa, sb);
                    let xb = [20, 62, 63, 90, 95, 96, 100, 126][(i % 8) as usize];
                    let v =
                        (i128::from(next(&mut s)) << 64 | i128::from(next(&mut s))) >> (127 - xb);
                    let fb = (next(&mut s) % 100) as u32;
                    for m2 in MODES {
                        assert_eq!(apply(r, v, fb, m2), apply_before(r, v, fb, m2), "{v} {r:?}");
                    }
                }
            }
        }
    }

    /// 3.6M seeded cases over 18 configurations (every mode; LUT, iteration and mantissa widths
    /// varied, the 30-bit mantissa's 128-bit Newton-Raphson products included; arguments 0, 1,
    /// 2^63, 2^64 - 1 and of 1 to 64 bits): `eval`, the span's `RecipLane::eval`, `apply` and
    /// `apply_i64_in` give the previous routines' bits and counts, `apply` on both its
    /// one-multiply path and the general one (a mantissa of 31 or more bits, `|x| >= 2^96`, a
    /// negative scale).
    #[test]
    fn eval_and_apply_match_the_previous_routines() {
        let mut s = 0x5eed_0006;
        let base = HwConfig::texram16().reciprocal;
        let (mut fast, mut general) = (0u64, 0u64);
        for mode in MODES {
            for (l, n, mb) in [
                (8, 2, 24),
                (8, 1, 24),
                (4, 3, 30),
                (12, 1, 16),
                (16, 0, 8),
                (10, 1, 20),
            ] {
                let cfg = config(&base, (l, n, mb), mode);
                let u = Reciprocal::new(&cfg);
                for i in 0..200_000u32 {
                    let x = match [0, 1, 1 << 63, u64::MAX].get(i as usize) {
                        Some(&e) => e,
                        None => next(&mut s) >> (i % 64),
                    };
                    let (mut sa, mut sb) = (SatCounter::default(), SatCounter::default());
                    let r = u.eval(x, &mut sa);
                    let want = previous::eval(&u, x, &mut sb);
                    assert_eq!((r, sa), (want, sb), "1/{x} {cfg:?}");
                    let mut sl = SatCounter::default();
                    let rl = crate::with_rounding!(mode, R => u.lane::<R>().eval(x, &mut sl));
                    assert_eq!((rl, sl), (want, sb), "lane 1/{x} {cfg:?}");
                    let r = if i % 16 == 1 {
                        Recip {
                            mant: next(&mut s) >> (next(&mut s) % 40),
                            shift: r.shift,
                        }
                    } else {
                        r
                    };
                    let xb = [20, 62, 63, 90, 95, 96, 100, 126][(i % 8) as usize];
                    let v =
                        (i128::from(next(&mut s)) << 64 | i128::from(next(&mut s))) >> (127 - xb);
                    let fb = (next(&mut s) % 140) as u32;
                    let v64 = v as i64;
                    for m2 in MODES {
                        let want = previous::apply(r, v, fb, m2);
                        assert_eq!(apply(r, v, fb, m2), want, "{v} {r:?} {fb}");
                        let got = crate::with_rounding!(m2, M => apply_i64_in::<M>(r, v64, fb));
                        let want = previous::apply(r, i128::from(v64), fb, m2);
                        assert_eq!(got, want, "{v64} {r:?} {fb}");
                    }
                    if r.shift >= fb as i32 && v.unsigned_abs() >> 96 == 0 && r.mant >> 31 == 0 {
                        fast += 1;
                    } else {
                        general += 1;
                    }
                }
            }
        }
        assert!(fast > 500_000 && general > 500_000, "{fast} {general}");
    }

    /// `eval_square_lanes` of `x` into `out` (one vector batch).
    fn eval_square_batch<R: ConstRounding, const N: u32, S: ConstRounding>(
        lane: &RecipLane<'_, R>,
        x: &[u64; 2 * RECIP_LANES],
        out: &mut RecipLanes<{ 2 * RECIP_LANES }>,
    ) {
        lane.eval_square_lanes::<N, S, { 2 * RECIP_LANES }>(x, out);
    }

    crate::isa_kernel! {
        /// [`eval_square_batch`] built for the vector instruction set in force.
        vector fn eval_square_vector[R: ConstRounding, const N: u32, S: ConstRounding](
            lane: &RecipLane<'_, R>,
            x: &[u64; 2 * RECIP_LANES],
            out: &mut RecipLanes<{ 2 * RECIP_LANES }>,
        ) = eval_square_batch::<R, N, S>;
    }

    /// `eval_square_lanes` built for the vector instruction set in force (as the vector
    /// batches of `interpolator::derivs_span_held` are) where that is not the portable one.
    fn eval_square_lanes_wide<R: ConstRounding, const N: u32, S: ConstRounding>(
        lane: &RecipLane<'_, R>,
        x: &[u64; 2 * RECIP_LANES],
    ) -> Option<RecipLanes<{ 2 * RECIP_LANES }>> {
        let mut out = RecipLanes::default();
        eval_square_vector::<R, N, S>(lane, x, &mut out).then_some(out)
    }

    /// `eval_square_lanes::<N, S>` of the batch `x` (the portable build and, on a CPU with
    /// AVX2 or AVX-512, `eval_square_lanes_wide`), each lane against `eval_narrow` and `square`.
    fn check_lanes<R: ConstRounding, S: ConstRounding, const N: u32>(
        lane: &RecipLane<'_, R>,
        x: &[u64; 2 * RECIP_LANES],
    ) -> u64 {
        let mut lanes = RecipLanes::default();
        lane.eval_square_lanes::<N, S, { 2 * RECIP_LANES }>(x, &mut lanes);
        let wide = eval_square_lanes_wide::<R, N, S>(lane, x);
        for (j, &xj) in x.iter().enumerate() {
            let r = lane.eval_narrow::<N>(xj);
            let want = (r, square(r, lane.m_bits, S::MODE));
            assert_eq!(
                lanes.get(j),
                want,
                "1/{xj} lane {j} {:?} {:?}",
                R::MODE,
                S::MODE
            );
            if let Some(w) = &wide {
                assert_eq!(
                    w.get(j),
                    want,
                    "1/{xj} lane {j} {:?} {:?}",
                    R::MODE,
                    S::MODE
                );
            }
        }
        2 * RECIP_LANES as u64
    }

    /// 4.3M seeded lanes in 1..2^62 (every bit length; 1, 2^62 - 1 and runs of steps along a
    /// span included) over every pair of rounding modes of the reciprocal and of the square,
    /// LUT widths 1..=16, iteration counts 0..=4 and the mantissa widths 8..=26: each lane of
    /// `eval_square_lanes` (portable, and built for AVX2 or AVX-512 where the CPU has it) gives
    /// `eval_narrow` and its `square`.
    #[test]
    fn eval_square_lanes_match_eval_narrow() {
        let mut s = 0x5eed_0018;
        let base = HwConfig::texram16().reciprocal;
        let mut cases = 0u64;
        for mode in MODES {
            for sq_mode in MODES {
                for l in [1, 3, 6, 8, 11, 16] {
                    for n in 0..=4 {
                        for mb in [8, 13, 16, 21, 24, 26] {
                            let u = Reciprocal::new(&config(&base, (l, n, mb), mode));
                            for i in 0..165u32 {
                                let x: [u64; 2 * RECIP_LANES] = match i {
                                    0 => std::array::from_fn(|c| {
                                        [1u64, (1 << 62) - 1, 2, 3, 1 << 61, 7, 255, 256][c % 8]
                                            .saturating_sub(c as u64 / 8)
                                            .max(1)
                                    }),
                                    1..=29 => std::array::from_fn(|_| {
                                        (next(&mut s) >> 2 >> (next(&mut s) % 62)).max(1)
                                    }),
                                    _ => {
                                        // A span: `D` stepping by `S` (either sign).
                                        let d = (next(&mut s) >> 2 >> (i % 40)).max(1 << 9);
                                        let st =
                                            (next(&mut s) >> (i % 60 + 4)) as i64 - (d >> 4) as i64;
                                        std::array::from_fn(|c| {
                                            let x = i128::from(d) + c as i128 * i128::from(st);
                                            x.clamp(1, (1 << 62) - 1) as u64
                                        })
                                    }
                                };
                                crate::with_rounding!(mode, R => {
                                    crate::with_rounding!(sq_mode, S => {
                                        let lane = u.lane::<R>();
                                        cases += match n {
                                            0 => check_lanes::<R, S, 0>(&lane, &x),
                                            1 => check_lanes::<R, S, 1>(&lane, &x),
                                            2 => check_lanes::<R, S, 2>(&lane, &x),
                                            3 => check_lanes::<R, S, 3>(&lane, &x),
                                            _ => check_lanes::<R, S, 4>(&lane, &x),
                                        };
                                    })
                                });
                            }
                        }
                    }
                }
            }
        }
        assert!(cases > 4_000_000, "{cases}");
    }

    /// 4.6M seeded arguments in 1..2^62 (every bit length, 1 and 2^62 - 1 included) over every
    /// rounding mode, LUT width 1..=16, iteration count 0..=4 and the mantissa widths 8..=26
    /// (working width P <= 29, where `narrow_iterations` is `Some`): `eval_narrow::<N>` gives
    /// `eval`'s bits; wider mantissas have no narrow form.
    #[test]
    fn eval_narrow_matches_eval() {
        let mut s = 0x5eed_0008;
        let base = HwConfig::texram16().reciprocal;
        let mut cases = 0u64;
        for mode in MODES {
            for l in 1..=16 {
                for n in 0..=4 {
                    for mb in [8, 12, 16, 20, 23, 24, 25, 26, 27, 30] {
                        let cfg = config(&base, (l, n, mb), mode);
                        let u = Reciprocal::new(&cfg);
                        crate::with_rounding!(mode, R => {
                            let lane = u.lane::<R>();
                            let Some(it) = lane.narrow_iterations() else {
                                assert!(mb + GUARD_BITS > 29, "{cfg:?}");
                                continue;
                            };
                            assert_eq!(it, n);
                            for i in 0..2_400u32 {
                                let x = match i {
                                    0 => 1,
                                    1 => (1 << 62) - 1,
                                    _ => (next(&mut s) >> 2 >> (i % 62)).max(1),
                                };
                                let want = u.eval(x, &mut SatCounter::default());
                                let got = match n {
                                    0 => lane.eval_narrow::<0>(x),
                                    1 => lane.eval_narrow::<1>(x),
                                    2 => lane.eval_narrow::<2>(x),
                                    3 => lane.eval_narrow::<3>(x),
                                    _ => lane.eval_narrow::<4>(x),
                                };
                                assert_eq!(got, want, "1/{x} {cfg:?}");
                                cases += 1;
                            }
                        });
                    }
                }
            }
        }
        assert!(cases > 4_000_000, "{cases}");
    }
}
