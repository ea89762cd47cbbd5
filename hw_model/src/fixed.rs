//! Fixed-point formats, the one rounding routine, and saturation/wrap with event counting.
//!
//! A raw value `r` in a format with `frac_bits = f` means `r * 2^-f`. Formats are at most
//! 32 bits wide so that any product of two values fits an `i64` exactly; wider intermediates
//! (accumulators) are `i64`/`i128` and are reduced through [`round_shift_right`] and
//! [`Format::fit`]. Nothing in this module uses a std operator with build-dependent overflow.

use serde::{Deserialize, Serialize};

/// Rounding mode, always passed explicitly (never a global).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Rounding {
    /// Toward minus infinity (drop the bits).
    Truncate,
    /// To nearest, ties toward plus infinity.
    HalfUp,
    /// To nearest, ties to even.
    HalfEven,
}

/// A rounding mode fixed at compile time (a zero-sized type): a unit whose datapath is
/// generic over it is compiled once per mode, so its reductions (still [`round_shift_right`]
/// and its siblings, with `M::MODE`) carry no run-time branch on the mode. The unit picks its
/// instance from the configured [`Rounding`] once per call with [`with_rounding!`].
pub trait ConstRounding {
    /// The mode.
    const MODE: Rounding;
}

/// [`Rounding::Truncate`] as a type.
#[derive(Clone, Copy, Debug)]
pub struct TruncateMode;
/// [`Rounding::HalfUp`] as a type.
#[derive(Clone, Copy, Debug)]
pub struct HalfUpMode;
/// [`Rounding::HalfEven`] as a type.
#[derive(Clone, Copy, Debug)]
pub struct HalfEvenMode;

impl ConstRounding for TruncateMode {
    const MODE: Rounding = Rounding::Truncate;
}
impl ConstRounding for HalfUpMode {
    const MODE: Rounding = Rounding::HalfUp;
}
impl ConstRounding for HalfEvenMode {
    const MODE: Rounding = Rounding::HalfEven;
}

/// `with_rounding!(mode, M => expr)`: evaluates `expr` with the type `M` bound to the
/// [`ConstRounding`] type of the run-time [`Rounding`] `mode` (one branch, then a body
/// compiled for that mode).
#[macro_export]
macro_rules! with_rounding {
    ($mode:expr, $m:ident => $body:expr) => {
        match $mode {
            $crate::fixed::Rounding::Truncate => {
                type $m = $crate::fixed::TruncateMode;
                $body
            }
            $crate::fixed::Rounding::HalfUp => {
                type $m = $crate::fixed::HalfUpMode;
                $body
            }
            $crate::fixed::Rounding::HalfEven => {
                type $m = $crate::fixed::HalfEvenMode;
                $body
            }
        }
    };
}

/// What happens to a value outside a format's range.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Overflow {
    /// Clamp to the nearest representable value.
    Saturate,
    /// Keep the low bits (two's complement wrap).
    Wrap,
}

/// Counts of overflow events, so a stage can report "saturated N times".
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct SatCounter {
    /// Values clamped to the range of their format.
    pub saturated: u64,
    /// Values that wrapped.
    pub wrapped: u64,
}

impl SatCounter {
    /// Adds another counter into this one.
    pub fn add(&mut self, o: &SatCounter) {
        self.saturated = self.saturated.saturating_add(o.saturated);
        self.wrapped = self.wrapped.saturating_add(o.wrapped);
    }
}

/// A fixed-point format chosen at run time.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Format {
    /// Two's complement if true, unsigned otherwise.
    pub signed: bool,
    /// Integer bits, not counting the sign bit.
    pub int_bits: u32,
    /// Fraction bits.
    pub frac_bits: u32,
    /// Rounding when a wider value is reduced into this format.
    pub rounding: Rounding,
    /// Behaviour outside the range.
    pub overflow: Overflow,
}

impl Format {
    /// Unsigned normalized-style format with `frac` fraction bits and `int` integer bits.
    #[must_use]
    pub const fn unsigned(int_bits: u32, frac_bits: u32, rounding: Rounding) -> Self {
        Self {
            signed: false,
            int_bits,
            frac_bits,
            rounding,
            overflow: Overflow::Saturate,
        }
    }

    /// Signed format with `int` integer bits plus sign and `frac` fraction bits.
    #[must_use]
    pub const fn signed(int_bits: u32, frac_bits: u32, rounding: Rounding) -> Self {
        Self {
            signed: true,
            int_bits,
            frac_bits,
            rounding,
            overflow: Overflow::Saturate,
        }
    }

    /// This format with the overflow rule `overflow`.
    #[must_use]
    pub const fn with_overflow(self, overflow: Overflow) -> Self {
        Self { overflow, ..self }
    }

    /// Total storage bits (sign + integer + fraction).
    #[must_use]
    pub const fn total_bits(&self) -> u32 {
        self.int_bits + self.frac_bits + self.signed as u32
    }

    /// Largest raw value.
    #[inline(always)]
    #[must_use]
    pub const fn max_raw(&self) -> i64 {
        (1i64 << (self.int_bits + self.frac_bits)) - 1
    }

    /// Smallest raw value.
    #[inline(always)]
    #[must_use]
    pub const fn min_raw(&self) -> i64 {
        if self.signed {
            -(1i64 << (self.int_bits + self.frac_bits))
        } else {
            0
        }
    }

    /// Brings `raw` into range by this format's overflow rule, counting the event.
    #[inline(always)]
    #[must_use]
    pub fn fit(&self, raw: i64, sat: &mut SatCounter) -> i64 {
        let (lo, hi) = (self.min_raw(), self.max_raw());
        if raw >= lo && raw <= hi {
            return raw;
        }
        match self.overflow {
            Overflow::Saturate => {
                sat.saturated += 1;
                raw.clamp(lo, hi)
            }
            Overflow::Wrap => {
                sat.wrapped += 1;
                let bits = self.total_bits();
                let m = raw & ((1i64 << bits) - 1);
                if self.signed && m >= (1i64 << (bits - 1)) {
                    m - (1i64 << bits)
                } else {
                    m
                }
            }
        }
    }

    /// Reduces `raw` (which has `from_frac` fraction bits) into this format: rounds by this
    /// format's rounding mode, then fits by its overflow rule.
    #[inline(always)]
    #[must_use]
    pub fn requantize(&self, raw: i64, from_frac: u32, sat: &mut SatCounter) -> i64 {
        let v = if from_frac >= self.frac_bits {
            round_shift_right(raw, from_frac - self.frac_bits, self.rounding)
        } else {
            raw.saturating_mul(1i64 << (self.frac_bits - from_frac))
        };
        self.fit(v, sat)
    }
}

/// The one rounding routine: `x / 2^shift`, rounded by `mode`. Exact for every `i64` input
/// and every `shift` (no intermediate overflow); a shift of 64 or more yields 0 or -1 before
/// rounding, exactly as the infinite-precision quotient does. The decision is [`round_up`]'s,
/// taken as the carry of the dropped bits plus [`round_bias`] (no branch on the data).
#[inline(always)]
#[must_use]
pub fn round_shift_right(x: i64, shift: u32, mode: Rounding) -> i64 {
    if shift == 0 {
        return x;
    }
    if shift >= 64 {
        return round_shift_right_wide(i128::from(x), shift, mode);
    }
    round_shift_right_narrow(x, shift, mode)
}

/// [`round_shift_right`] with the mode `M` as a type, for a `shift` in 1..=63 that the caller
/// has checked once (e.g. per span): the same value without the tests for 0 and 64 or more.
#[inline(always)]
#[must_use]
pub fn round_shift_right_mid<M: ConstRounding>(x: i64, shift: u32) -> i64 {
    debug_assert!((1..64).contains(&shift), "shift {shift}");
    round_shift_right_narrow(x, shift, M::MODE)
}

/// [`round_shift_right`] in the mode `M` by a `shift` in 1..=63 that is fixed for a run of
/// values (e.g. per span), its rounding constants resolved once: [`ShiftRound::apply`] adds
/// [`round_bias`] moved below the cut (plus the floor's lowest bit where that bias takes it)
/// before one arithmetic shift, for inputs `|x| < 2^62` (no overflow).
#[derive(Debug)]
pub struct ShiftRound<M> {
    shift: u32,
    /// `round_bias(false, M::MODE) >> (64 - shift)`: below one half of the dropped part.
    bias: i64,
    /// `round_bias(true, M::MODE) - round_bias(false, M::MODE)`: 1 for HalfEven, else 0.
    odd: i64,
    mode: std::marker::PhantomData<M>,
}

// Written out: a derive would ask `M` (a mode marker) to be `Copy` too.
impl<M> Clone for ShiftRound<M> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<M> Copy for ShiftRound<M> {}

impl<M: ConstRounding> ShiftRound<M> {
    /// The rounding by `shift`; `None` unless `shift` is in 1..=63.
    #[inline(always)]
    #[must_use]
    pub fn new(shift: u32) -> Option<Self> {
        (1..64).contains(&shift).then(|| Self::at(shift))
    }

    /// [`ShiftRound::new`] for a `shift` the caller has checked to lie in 1..=63.
    #[inline(always)]
    pub(crate) fn at(shift: u32) -> Self {
        debug_assert!((1..64).contains(&shift), "shift {shift}");
        Self {
            shift,
            bias: (round_bias(false, M::MODE) >> (64 - shift)) as i64,
            odd: (round_bias(true, M::MODE) - round_bias(false, M::MODE)) as i64,
            mode: std::marker::PhantomData,
        }
    }

    /// `round_shift_right(x, shift, M::MODE)` for `|x| < 2^62`: with `q = floor(x / 2^s)` and
    /// the dropped part `r`, `x + bias + odd(q)` carries into `q + 1` iff `r + bias + odd(q)
    /// >= 2^s`, the carry [`round_shift_right`] takes from the left-aligned `r`.
    #[inline(always)]
    #[must_use]
    pub fn apply(&self, x: i64) -> i64 {
        debug_assert!(x.unsigned_abs() < 1 << 62, "{x}");
        self.apply_wrapping(x)
    }

    /// [`ShiftRound::apply`] with wrapping adds, so that it takes any `x` (a vector lane whose
    /// input is out of range computes a value nobody reads): the same result for `|x| < 2^62`.
    #[inline(always)]
    #[must_use]
    pub fn apply_wrapping(&self, x: i64) -> i64 {
        x.wrapping_add(self.bias)
            .wrapping_add((x >> self.shift) & self.odd)
            >> self.shift
    }
}

/// [`round_shift_right`] of the two 32-bit lanes of a `u64` at once (the trilinear filter's
/// packed channel pairs): each lane, non-negative and at most `2^32 - 2^shift`, becomes its
/// floor by `2^shift` plus the carry of [`round_shift_right`] (HalfUp: a bias of one half;
/// HalfEven: one half less one, plus the floor's lowest bit; Truncate: none), in the same lane.
/// `shift` at most 31; built once per configuration.
#[derive(Clone, Copy, Debug)]
pub struct LaneRound {
    shift: u32,
    /// The bias in both lanes.
    bias: u64,
    /// Each lane's lowest bit where the floor's lowest bit joins the bias (HalfEven), else 0.
    odd: u64,
    /// Each lane's result bits (`32 - shift`), which drops what the upper lane shifted into the
    /// lower.
    mask: u64,
}

impl LaneRound {
    /// The lowest bit of each 32-bit lane.
    pub const LANE_LSB: u64 = 0x0000_0001_0000_0001;

    /// The rounding by `shift` (at most 31) in `mode`.
    #[must_use]
    pub fn new(shift: u32, mode: Rounding) -> Self {
        debug_assert!(shift < 32, "shift {shift}");
        let half = (1u64 << shift) >> 1;
        let (bias, odd) = match mode {
            Rounding::Truncate => (0, 0),
            Rounding::HalfUp => (half * Self::LANE_LSB, 0),
            Rounding::HalfEven if shift > 0 => ((half - 1) * Self::LANE_LSB, Self::LANE_LSB),
            Rounding::HalfEven => (0, 0),
        };
        Self {
            shift,
            bias,
            odd,
            mask: ((1u64 << (32 - shift)) - 1) * Self::LANE_LSB,
        }
    }

    /// Both lanes of `x` rounded.
    #[inline(always)]
    #[must_use]
    pub fn apply(&self, x: u64) -> u64 {
        ((x + self.bias + ((x >> self.shift) & self.odd)) >> self.shift) & self.mask
    }
}

/// [`round_shift_right_mid`] for `|x| < 2^62` and a `shift` in 1..=63 checked by the caller:
/// one value through [`ShiftRound`] (the bias added before the shift; no overflow at these
/// magnitudes), the same value with fewer operations.
#[inline(always)]
#[must_use]
pub fn round_shift_right_small<M: ConstRounding>(x: i64, shift: u32) -> i64 {
    ShiftRound::<M>::at(shift).apply(x)
}

/// [`round_shift_right`] in the mode `M` for `|x| < 2^62` and a `shift` in 0..=63 that may
/// differ from one value to the next (the lanes of a batch): [`ShiftRound::apply`]'s bias and
/// lowest-bit carry, with a shift of 0 giving `x`, written without a branch so that a loop over
/// lanes vectorizes.
#[inline(always)]
#[must_use]
pub fn round_shift_right_lane<M: ConstRounding>(x: i64, shift: u32) -> i64 {
    debug_assert!(shift < 64 && x.unsigned_abs() < 1 << 62, "{x} >> {shift}");
    let half = ((1u64 << shift) >> 1) as i64;
    match M::MODE {
        Rounding::Truncate => x >> shift,
        Rounding::HalfUp => (x + half) >> shift,
        Rounding::HalfEven => {
            // One half less one, plus the floor's lowest bit; nothing for a shift of 0.
            let cut = i64::from(shift != 0);
            (x + half - cut + ((x >> shift) & cut)) >> shift
        }
    }
}

/// [`round_shift_right_wide`] for `|x| < 2^126` and a `shift` in 1..=63, the bias of
/// [`ShiftRound`] added before the shift (a 128-bit add of a 64-bit bias and a 64-bit funnel
/// shift); `None` when the result does not fit `i64` (where `round_shift_right_wide`
/// saturates).
#[inline(always)]
#[must_use]
pub fn round_shift_right_wide_small<M: ConstRounding>(x: i128, shift: u32) -> Option<i64> {
    debug_assert!(x.unsigned_abs() >> 126 == 0, "x {x}");
    // `shift` < 64: the floor's last bit and the bias are in the low word, and the result
    // is the low word of a 64-bit funnel shift, which fits when the high word's rest is its
    // sign.
    let r = ShiftRound::<M>::at(shift & 63);
    let s = r.shift;
    let bias = r.bias as u64 + ((x as u64) >> s & r.odd as u64);
    let v = x + i128::from(bias);
    let (hi, lo) = ((v >> 64) as i64, v as u64);
    let q = (lo >> s | (hi as u64) << (64 - s)) as i64;
    (hi >> s == q >> 63).then_some(q)
}

/// [`round_shift_right_wide_small`] of the 128-bit `x = hi 2^64 + lo` (`|x| < 2^126`) by a
/// `shift` in 1..=63 that may differ from one value to the next, written without a branch so
/// that a loop over lanes vectorizes: the value and whether it fits `i64` (where
/// `round_shift_right_wide_small` gives `None`, the value is not meaningful).
#[inline(always)]
#[must_use]
pub fn round_shift_right_wide_lane<M: ConstRounding>(hi: i64, lo: u64, shift: u32) -> (i64, bool) {
    debug_assert!((1..64).contains(&shift), "shift {shift}");
    let s = shift & 63;
    let half = 1u64 << ((s + 63) & 63);
    // [`ShiftRound`]'s bias and the floor's lowest bit (HalfEven), in the low word.
    let bias = match M::MODE {
        Rounding::Truncate => 0,
        Rounding::HalfUp => half,
        Rounding::HalfEven => half - 1 + ((lo >> s) & 1),
    };
    let low = lo.wrapping_add(bias);
    let high = hi.wrapping_add(i64::from(low < lo));
    let q = ((low >> s) | ((high as u64) << ((64 - s) & 63))) as i64;
    (q, high >> s == q >> 63)
}

/// [`round_shift_right`] for a `shift` in 1..=63: the floor plus the carry out of the dropped
/// bits, left-aligned in 64 bits (one half = 2^63), when [`round_bias`] is added to them.
#[inline(always)]
fn round_shift_right_narrow(x: i64, shift: u32, mode: Rounding) -> i64 {
    let floor = x >> shift;
    let rem = (x as u64) << (64 - shift);
    floor + i64::from(rem.overflowing_add(round_bias(floor & 1 == 1, mode)).1)
}

/// What [`round_shift_right`] adds to the dropped bits left-aligned in 64 bits (one half =
/// 2^63) so that their carry out is [`round_up`]'s decision: 0 for Truncate; 2^63 for HalfUp
/// (carry iff the dropped part >= half); 2^63 - 1 + odd for HalfEven (carry iff above half,
/// or exactly half and the floor is odd).
#[inline(always)]
const fn round_bias(odd: bool, mode: Rounding) -> u64 {
    match mode {
        Rounding::Truncate => 0,
        Rounding::HalfUp => 1 << 63,
        Rounding::HalfEven => (1 << 63) - 1 + odd as u64,
    }
}

/// The divide-by-constant sibling of [`round_shift_right_wide`]: `x / den` for a constant
/// `den > 0` (e.g. the `2^n - 1` of unsigned normalized products), rounded by `mode`, exact
/// for every `i128` input, result saturated to `i64`. Hardware multiplies by a precomputed
/// reciprocal with enough bits, which gives the same integer. A `den <= 0` gives 0.
#[inline]
#[must_use]
pub fn round_div_wide(x: i128, den: i128, mode: Rounding) -> i64 {
    round_div_i128(x, den, mode).clamp(i128::from(i64::MIN), i128::from(i64::MAX)) as i64
}

/// [`round_div_wide`] without the saturation: `x / den` rounded by `mode`, exact for every
/// `i128` input and `den > 0` (a `den <= 0` gives 0).
#[inline]
#[must_use]
pub fn round_div_i128(x: i128, den: i128, mode: Rounding) -> i128 {
    if den <= 0 {
        return 0;
    }
    // The same quotient and remainder in 64-bit arithmetic when both fit (the common case).
    if let (Ok(x64), Ok(d64)) = (i64::try_from(x), i64::try_from(den)) {
        let (q, r) = (x64.div_euclid(d64), x64.rem_euclid(d64));
        return i128::from(q + i64::from(round_up(r > d64 - r, r == d64 - r, q & 1 == 1, mode)));
    }
    let q = x.div_euclid(den);
    // Remainder r in [0, den) against the other part den - r: no overflow for any den.
    let r = x.rem_euclid(den);
    let rest = den - r;
    q + i128::from(round_up(r > rest, r == rest, q & 1 == 1, mode))
}

/// [`round_div_i128`] by a divisor `den` that is fixed for a run of values (e.g. the
/// `(2^a - 1)(2^b - 1)` of a unorm product per span), for non-negative numerators: one
/// unsigned 64-bit quotient `q` and remainder `r`, and the mode resolved into a threshold `t`
/// and a parity mask: `q + 1` iff `r + (q & odd) > t`. Truncate never rounds up (`t` =
/// `u64::MAX`); half-up rounds up iff `2r >= den`, i.e. `r > ceil(den / 2) - 1`; half-even
/// iff `2r > den`, i.e. `r > floor(den / 2)`, or at a tie (`2r = den`, only for an even `den`,
/// where `odd` = 1) with `q` odd. Checked against [`round_div_i128`] by
/// `div_round_matches_round_div_i128` (exhaustive over numerators and divisors below 2^8 in
/// every mode, 3M seeded cases up to 2^63).
#[derive(Clone, Copy, Debug)]
pub struct DivRound {
    den: u64,
    threshold: u64,
    odd: u64,
}

impl DivRound {
    /// The rounding by `den` in `mode`; `None` unless `den` is in 1..2^63.
    #[inline]
    #[must_use]
    pub fn new(den: u64, mode: Rounding) -> Option<Self> {
        if !(1..1 << 63).contains(&den) {
            return None;
        }
        let (threshold, odd) = match mode {
            Rounding::Truncate => (u64::MAX, 0),
            Rounding::HalfUp => (den.div_ceil(2) - 1, 0),
            Rounding::HalfEven => (den / 2, u64::from(den.is_multiple_of(2))),
        };
        Some(Self {
            den,
            threshold,
            odd,
        })
    }

    /// `round_div_i128(x, den, mode)` for `x < 2^63`.
    #[inline(always)]
    #[must_use]
    pub fn apply(&self, x: u64) -> u64 {
        debug_assert!(x >> 63 == 0, "{x}");
        let (q, r) = (x / self.den, x % self.den);
        q + u64::from(r + (q & self.odd) > self.threshold)
    }
}

/// Rounds the magnitude `x + f` to a multiple of `2^shift` (returned divided by it), where
/// `f` in [0, 1) is what an earlier truncating division or root dropped (`f > 0` iff
/// `sticky`): the rounding of a correctly rounded divider or square root. Unsaturated, exact
/// for every `x` and `shift` in 1..=127.
#[inline]
#[must_use]
pub fn round_shift_right_sticky(x: u128, shift: u32, sticky: bool, mode: Rounding) -> u128 {
    let shift = shift.clamp(1, 127);
    let floor = x >> shift;
    let rem = x & ((1u128 << shift) - 1);
    let half = 1u128 << (shift - 1);
    // Above half: a larger remainder, or exactly half plus the dropped fraction.
    let above = rem > half || (rem == half && sticky);
    let tie = rem == half && !sticky;
    floor + u128::from(round_up(above, tie, floor & 1 == 1, mode))
}

/// The rounding decision shared by every routine here: whether to add one to the floor,
/// given whether the dropped part is above one half, exactly one half, and the floor's parity.
#[inline(always)]
const fn round_up(above_half: bool, half: bool, odd: bool, mode: Rounding) -> bool {
    match mode {
        Rounding::Truncate => false,
        Rounding::HalfUp => above_half || half,
        Rounding::HalfEven => above_half || (half && odd),
    }
}

/// `round_shift_right` for `i128` accumulators, result saturated to `i64`. Exact for every
/// `i128` input and every `shift` (shifts of 128 or more behave as the exact quotient).
///
/// When the quotient fits `i64` with two bits to spare, the 64-bit routine decides: `x` is
/// shifted right by all but two of the dropped bits (by `shift - 2` below 64, by 62 from 64
/// to 125) and the bits shifted out are ORed, as one sticky bit, into the lowest bit left.
/// The floor, the half bit and whether anything below the half is set are unchanged, so is
/// the decision of every mode.
#[inline(always)]
#[must_use]
pub fn round_shift_right_wide(x: i128, shift: u32, mode: Rounding) -> i64 {
    if (2..64).contains(&shift) {
        let pre = shift - 2;
        let sticky = (x as u64) & ((1u64 << pre) - 1) != 0;
        // `pre` < 62: the shift is a 64-bit funnel shift.
        if let Ok(y) = i64::try_from(x >> (pre & 63)) {
            return round_shift_right_narrow(y | i64::from(sticky), 2, mode);
        }
    } else if (64..126).contains(&shift) {
        let sticky = (x as u64) << 2 != 0;
        if let Ok(y) = i64::try_from(x >> 62) {
            return round_shift_right_narrow(y | i64::from(sticky), shift - 62, mode);
        }
    }
    round_shift_right_wide_any(x, shift, mode)
}

/// [`round_shift_right_wide`] for every input: the floor and the carry of the dropped bits
/// in 128-bit arithmetic, then the saturation to `i64`.
#[inline(never)]
fn round_shift_right_wide_any(x: i128, shift: u32, mode: Rounding) -> i64 {
    let v = if shift == 0 {
        x
    } else if shift >= 128 {
        // |x| / 2^shift <= 1/2: the floor is 0 or -1 and rounding to nearest always gives 0
        // (the one exact tie, i128::MIN at shift 128, rounds up by HalfUp and to even 0).
        match mode {
            Rounding::Truncate => -i128::from(x < 0),
            Rounding::HalfUp | Rounding::HalfEven => 0,
        }
    } else {
        let floor = x >> shift;
        // As in `round_shift_right`: the dropped bits left-aligned in 128 bits (one half =
        // 2^127), the decision their carry out with the same bias scaled.
        let rem = (x as u128) << (128 - shift);
        let bias: u128 = match mode {
            Rounding::Truncate => 0,
            Rounding::HalfUp => 1 << 127,
            Rounding::HalfEven => (1 << 127) - 1 + u128::from(floor & 1 == 1),
        };
        floor + i128::from(rem.overflowing_add(bias).1)
    };
    v.clamp(i128::from(i64::MIN), i128::from(i64::MAX)) as i64
}

/// Count of leading zeros of a 64-bit value (64 for zero).
#[inline]
#[must_use]
pub const fn clz64(x: u64) -> u32 {
    x.leading_zeros()
}

#[cfg(test)]
mod tests {
    use super::*;

    const MODES: [Rounding; 3] = [Rounding::Truncate, Rounding::HalfUp, Rounding::HalfEven];

    use crate::test_rng::splitmix64 as next;

    /// Rounds `num / den` (den > 0) by comparing twice the remainder with the divisor in
    /// `i128` (independent of the routines under test; operands below 2^100).
    fn reference_div(num: i128, den: i128, mode: Rounding) -> i128 {
        let q = num.div_euclid(den);
        let twice = 2 * num.rem_euclid(den);
        q + i128::from(match mode {
            Rounding::Truncate => false,
            Rounding::HalfUp => twice >= den,
            Rounding::HalfEven => twice > den || (twice == den && q & 1 == 1),
        })
    }

    /// 1.9M seeded lane pairs (with 0, the largest lane values and exact halves) at every shift
    /// 0 to 31 and every mode: each lane of `LaneRound::apply` is `round_shift_right` of it.
    #[test]
    fn lane_round_matches_round_shift_right_per_lane() {
        let mut s = 0x1a2e_0001u64;
        let mut cases = 0u64;
        for mode in MODES {
            for shift in 0..32u32 {
                let r = LaneRound::new(shift, mode);
                let top = (1u64 << 32) - (1u64 << shift);
                let half = (1u64 << shift) >> 1;
                for i in 0..20_000u32 {
                    let lane = |v: u64| match i % 8 {
                        0 => 0,
                        1 => top,
                        2 => (v % (top >> shift)) << shift | half,
                        _ => v % (top + 1),
                    };
                    let (lo, hi) = (lane(next(&mut s)), lane(next(&mut s)));
                    let got = r.apply(hi << 32 | lo);
                    let want = |v: u64| round_shift_right(v as i64, shift, mode) as u64;
                    assert_eq!(got & 0xffff_ffff, want(lo), "{mode:?} >> {shift}: {lo}");
                    assert_eq!(got >> 32, want(hi), "{mode:?} >> {shift}: {hi}");
                    cases += 1;
                }
            }
        }
        assert!(cases > 1_900_000, "{cases}");
    }

    /// 300k seeded values (with the ends of `i64` and exact halves) at every shift 1 to 63 and
    /// every mode: `round_shift_right_mid` gives `round_shift_right`.
    #[test]
    fn mid_shift_matches_round_shift_right() {
        let mut s = 0x5eed_f1d0;
        for i in 0..300_000u32 {
            let shift = 1 + i % 63;
            let x = match i % 5 {
                0 => [i64::MIN, i64::MAX, -1, 0, 1][(i / 5 % 5) as usize],
                1 => ((next(&mut s) as i64) >> shift << shift) + (1i64 << (shift - 1)),
                _ => next(&mut s) as i64 >> (i % 64),
            };
            for mode in MODES {
                let got = crate::with_rounding!(mode, M => round_shift_right_mid::<M>(x, shift));
                assert_eq!(
                    got,
                    round_shift_right(x, shift, mode),
                    "{x} {shift} {mode:?}"
                );
            }
        }
    }

    /// 640k seeded values below 2^62 in magnitude (with the ends of that range, exact halves
    /// and their neighbours) at every shift 0 to 63 and every mode: `round_shift_right_lane`
    /// gives `round_shift_right` at each, and at 1 to 63 so do `ShiftRound::apply` and
    /// `round_shift_right_small`; shifts 0 and 64 have no `ShiftRound`.
    #[test]
    fn shift_round_matches_round_shift_right() {
        let mut s = 0x5eed_f1d8;
        const TOP: i64 = (1 << 62) - 1;
        for i in 0..640_000u32 {
            let shift = i % 64;
            let x = match i % 5 {
                0 => [-TOP, TOP, -1, 0, 1][(i / 5 % 5) as usize],
                1 | 2 => {
                    let half = ((next(&mut s) as i64 >> 2) >> shift << shift)
                        .wrapping_add((1i64 << shift) >> 1);
                    (half + (i % 3) as i64 - 1).clamp(-TOP, TOP)
                }
                _ => (next(&mut s) as i64 >> 2) >> (i % 62),
            };
            for mode in MODES {
                let lane = crate::with_rounding!(mode, M => round_shift_right_lane::<M>(x, shift));
                assert_eq!(
                    lane,
                    round_shift_right(x, shift, mode),
                    "{x} {shift} {mode:?}"
                );
                if shift == 0 {
                    continue;
                }
                let got = crate::with_rounding!(mode, M => ShiftRound::<M>::new(shift).map(|r| r.apply(x)));
                let small =
                    crate::with_rounding!(mode, M => round_shift_right_small::<M>(x, shift));
                assert_eq!(Some(small), got, "{x} {shift} {mode:?}");
                assert_eq!(
                    got,
                    Some(round_shift_right(x, shift, mode)),
                    "{x} {shift} {mode:?}"
                );
            }
        }
        assert!(ShiftRound::<HalfEvenMode>::new(0).is_none());
        assert!(ShiftRound::<HalfUpMode>::new(64).is_none());
    }

    /// 400k seeded values below 2^126 in magnitude (with the ends of that range, exact halves
    /// and results at the ends of `i64`) at every shift 1 to 63 and every mode:
    /// `round_shift_right_wide_small` gives `round_shift_right_wide` where it fits `i64`, and
    /// `None` where that saturates; `round_shift_right_wide_lane` gives the same value and says
    /// whether it fits.
    #[test]
    fn wide_small_shift_matches_round_shift_right_wide() {
        let mut s = 0x5eed_5a12;
        let end = (1i128 << 126) - 1;
        let (mut fit, mut over) = (0u32, 0u32);
        for i in 0..400_000u32 {
            let shift = 1 + i % 63;
            let wide = |s: &mut u64| i128::from(next(s)) << 64 | i128::from(next(s));
            let x = match i % 6 {
                0 => [-end, end, -1, 0, 1][(i / 6 % 5) as usize],
                1 => (wide(&mut s) >> 2 >> shift << shift).wrapping_add(1i128 << (shift - 1)),
                2 => (i128::from(next(&mut s) as i64) << shift) + i128::from(i % 7) - 3,
                _ => wide(&mut s) >> (2 + i % 126),
            };
            if x.unsigned_abs() >> 126 != 0 {
                continue;
            }
            for mode in MODES {
                let got =
                    crate::with_rounding!(mode, M => round_shift_right_wide_small::<M>(x, shift));
                let (hi, lo) = ((x >> 64) as i64, x as u64);
                let (lane, fits) = crate::with_rounding!(mode, M => round_shift_right_wide_lane::<M>(hi, lo, shift));
                assert_eq!(fits.then_some(lane), got, "{x} {shift} {mode:?}");
                let want = round_shift_right_wide(x, shift, mode);
                let exact = round_div_i128(x, 1i128 << shift, mode);
                match got {
                    Some(v) => {
                        fit += 1;
                        assert_eq!(v, want, "{x} {shift} {mode:?}");
                    }
                    None => {
                        over += 1;
                        assert!(i64::try_from(exact).is_err(), "{x} {shift} {mode:?}");
                    }
                }
            }
        }
        assert!(fit > 500_000 && over > 100_000, "{fit} {over}");
    }

    /// `round_shift_right` as it was before the carry formulation (the decision of
    /// `round_up` on the remainder against one half): the oracle.
    fn shift_before(x: i64, shift: u32, mode: Rounding) -> i64 {
        if shift == 0 {
            return x;
        }
        if shift >= 64 {
            return round_shift_right_wide(i128::from(x), shift, mode);
        }
        let floor = x >> shift;
        let rem = (x as u64) & ((1u64 << shift) - 1);
        let half = 1u64 << (shift - 1);
        floor + i64::from(round_up(rem > half, rem == half, floor & 1 == 1, mode))
    }

    /// `round_shift_right_wide` as it was before the carry formulation: the oracle.
    fn wide_before(x: i128, shift: u32, mode: Rounding) -> i64 {
        if shift == 0 || shift >= 128 {
            return round_shift_right_wide(x, shift, mode);
        }
        let floor = x >> shift;
        let rem = (x as u128) & ((1u128 << shift) - 1);
        let half = 1u128 << (shift - 1);
        let v = floor + i128::from(round_up(rem > half, rem == half, floor & 1 == 1, mode));
        v.clamp(i128::from(i64::MIN), i128::from(i64::MAX)) as i64
    }

    /// 4M seeded cases of every shift 1..=127 and mode against the previous formulation
    /// (ties, near ties, full remainders and the ends of the `i128` range included).
    #[test]
    fn round_shift_right_wide_matches_the_previous_decision() {
        let mut s = 0x5eed_0004;
        for shift in 1..128u32 {
            for x in [i128::MIN, i128::MIN + 1, -1, 0, 1, i128::MAX - 1, i128::MAX] {
                for mode in MODES {
                    assert_eq!(
                        round_shift_right_wide(x, shift, mode),
                        wide_before(x, shift, mode)
                    );
                }
            }
        }
        for i in 0..4_000_000u32 {
            let shift = i % 127 + 1;
            let mut x =
                (i128::from(next(&mut s)) << 64 | i128::from(next(&mut s))) >> (next(&mut s) % 128);
            let low = (1i128 << shift).wrapping_sub(1);
            match i / 127 % 4 {
                0 => x = (x & !low) | (1i128 << (shift - 1)),
                1 => x = (x & !low) | ((1i128 << (shift - 1)) + (i128::from(i % 3 == 0) * 2 - 1)),
                2 => x |= low,
                _ => {}
            }
            for mode in MODES {
                assert_eq!(
                    round_shift_right_wide(x, shift, mode),
                    wide_before(x, shift, mode),
                    "{x} >> {shift} {mode:?}"
                );
            }
        }
    }

    /// 4M seeded cases of every shift 0..=66 and mode against the previous formulation, a
    /// quarter of them exact ties and the rest near ties, the ends of the range and the
    /// largest remainders (where `rem + bias` is largest) included.
    #[test]
    fn round_shift_right_matches_the_previous_decision() {
        let mut s = 0x5eed_0003;
        let edges = [i64::MIN, i64::MIN + 1, -1, 0, 1, i64::MAX - 1, i64::MAX];
        for shift in 0..=66u32 {
            for &x in &edges {
                for mode in MODES {
                    assert_eq!(
                        round_shift_right(x, shift, mode),
                        shift_before(x, shift, mode)
                    );
                }
            }
        }
        for i in 0..4_000_000u32 {
            let shift = i % 67;
            let mut x = next(&mut s) as i64 >> (next(&mut s) % 64);
            if (1..64).contains(&shift) {
                let low = (1i64 << shift).wrapping_sub(1);
                match i / 67 % 4 {
                    0 => x = (x & !low) | (1i64 << (shift - 1)),
                    1 => x = (x & !low) | ((1i64 << (shift - 1)) + (i64::from(i % 3 == 0) * 2 - 1)),
                    2 => x |= low,
                    _ => {}
                }
            }
            for mode in MODES {
                assert_eq!(
                    round_shift_right(x, shift, mode),
                    shift_before(x, shift, mode),
                    "{x} >> {shift} {mode:?}"
                );
            }
        }
    }

    /// 2M seeded cases over the 64-bit fast path and the 128-bit path, every mode, with
    /// exact ties forced on a quarter of them.
    #[test]
    fn round_div_i128_matches_the_reference() {
        let mut s = 0x5eed_0001;
        for i in 0..2_000_000u32 {
            let wide = i % 2 == 1;
            let bits = if wide { 99 } else { 62 };
            let den = i128::from(next(&mut s) >> (64 - (next(&mut s) % 40 + 1))) + 1;
            let mut num = i128::from(next(&mut s)) << 36 | i128::from(next(&mut s) >> 28);
            num &= (1i128 << bits) - 1;
            if i % 4 == 2 {
                num = (num / den) * den + den / 2;
            }
            if next(&mut s) & 1 == 1 {
                num = -num;
            }
            for mode in MODES {
                assert_eq!(
                    round_div_i128(num, den, mode),
                    reference_div(num, den, mode),
                    "{num} / {den} {mode:?}"
                );
            }
        }
        assert_eq!(round_div_i128(7, 0, Rounding::HalfEven), 0);
    }

    /// [`DivRound::apply`] against [`round_div_i128`]: every numerator and divisor below 2^8
    /// (divisors from 1) in every mode, then 3M seeded cases with numerators up to 2^63 - 1,
    /// divisors up to 2^63 - 1 (a third of the numerators exact ties or one off a tie), and
    /// the divisors the constructor refuses.
    #[test]
    fn div_round_matches_round_div_i128() {
        fn every_mode(x: u64, den: u64) {
            for mode in MODES {
                let want = round_div_i128(i128::from(x), i128::from(den), mode);
                let got = DivRound::new(den, mode).expect("divisor in range").apply(x);
                assert_eq!(i128::from(got), want, "{x} / {den} {mode:?}");
            }
        }
        for den in 1..256u64 {
            for x in 0..256u64 {
                every_mode(x, den);
            }
        }
        let mut s = 0x5eed_0005;
        for i in 0..3_000_000u32 {
            let den = (next(&mut s) >> (next(&mut s) % 63 + 1)).max(1);
            let mut x = next(&mut s) >> (next(&mut s) % 63 + 1);
            if i % 3 == 0 {
                let q = x / den;
                let tie = q.checked_mul(den).and_then(|m| m.checked_add(den / 2));
                if let Some(t) = tie.filter(|t| t >> 63 == 0) {
                    x = t.saturating_sub(
                        u64::from(i % 2 == 0 && den.is_multiple_of(2)) * (i as u64 % 3),
                    );
                }
            }
            every_mode(x, den);
        }
        for den in [0, 1 << 63, u64::MAX] {
            assert!(DivRound::new(den, Rounding::HalfEven).is_none(), "{den}");
        }
    }

    /// `round_shift_right_sticky(x, s, sticky)` rounds `x + f` with `0 < f < 1` iff sticky:
    /// the same as rounding `2x + sticky` over `2^(s+1)` exactly (2M seeded cases, ties forced).
    #[test]
    fn round_shift_right_sticky_rounds_the_exact_value() {
        let mut s = 0x5eed_0002;
        for i in 0..2_000_000u32 {
            let shift = (next(&mut s) % 90) as u32 + 1;
            let mut x = u128::from(next(&mut s)) << 32 | u128::from(next(&mut s) >> 32);
            if i % 3 == 0 {
                x = (x >> shift << shift) | (1u128 << (shift - 1));
            }
            let sticky = next(&mut s) & 1 == 1;
            let num = 2 * x as i128 + i128::from(sticky);
            for mode in MODES {
                let want = reference_div(num, 1i128 << (shift + 1), mode);
                assert_eq!(
                    round_shift_right_sticky(x, shift, sticky, mode) as i128,
                    want,
                    "{x} >> {shift} sticky {sticky} {mode:?}"
                );
            }
        }
    }

    /// 4M seeded cases of every shift 0..=129 and mode: `round_shift_right_wide` (its two
    /// 64-bit paths with the sticky bit, and the 128-bit one) gives the exact 128-bit
    /// routine's result, around the paths' bounds (quotients near 2^61 and 2^63, shifts 1, 2,
    /// 63, 64, 125, 126), with ties, near ties and sticky bits far below the half; each
    /// 64-bit path is taken many times.
    #[test]
    fn round_shift_right_wide_fast_paths_match_the_exact_routine() {
        let mut s = 0x5eed_0007;
        let (mut below64, mut from64, mut exact) = (0u32, 0u32, 0u32);
        for i in 0..4_000_000u32 {
            let shift = match i % 10 {
                0 => [0, 1, 2, 63, 64, 65, 125, 126, 127, 128][(i / 10 % 10) as usize],
                _ => (next(&mut s) % 130) as u32,
            };
            // A quotient of about `qb` bits, then the dropped bits.
            let qb = [40, 60, 61, 62, 63, 64, 70][(i / 100 % 7) as usize];
            let q = (next(&mut s) >> (64 - qb.min(63))) as i128 * if qb > 63 { 2 } else { 1 };
            let low = i128::from(next(&mut s)) << 64 | i128::from(next(&mut s));
            let sh = shift.min(127);
            let mask = (1i128 << sh).wrapping_sub(1);
            let mut x = q.checked_shl(sh).unwrap_or(0) | (low & mask);
            if sh > 0 {
                match i / 700 % 4 {
                    0 => x = (x & !mask) | (1i128 << (sh - 1)),
                    1 => x = (x & !mask) | (1i128 << (sh - 1)) | 1,
                    2 => x = (x & !mask) | ((1i128 << (sh - 1)) - 1),
                    _ => {}
                }
            }
            if next(&mut s) & 1 == 1 {
                x = x.wrapping_neg();
            }
            for mode in MODES {
                assert_eq!(
                    round_shift_right_wide(x, shift, mode),
                    round_shift_right_wide_any(x, shift, mode),
                    "{x} >> {shift} {mode:?}"
                );
            }
            if (2..64).contains(&shift) && i64::try_from(x >> (shift - 2)).is_ok() {
                below64 += 1;
            } else if (64..126).contains(&shift) && i64::try_from(x >> 62).is_ok() {
                from64 += 1;
            } else {
                exact += 1;
            }
        }
        assert!(below64 > 500_000 && from64 > 500_000 && exact > 500_000);
    }
}
