//! Float <-> fixed-point conversion (host side; `hw_model` itself is integer-only).
//!
//! A raw value `r` with `f` fraction bits means `r * 2^-f`; an `n`-bit unorm value `x` means
//! `x / (2^n - 1)`.

use hw_model::fixed::{Format, Rounding, SatCounter};

/// `x` into `fmt`: scaled by `2^frac_bits` (exact), rounded by `fmt.rounding`, then fitted by
/// `fmt.overflow` (each out-of-range value counted). NaN gives 0 and counts a saturation;
/// +-infinity and values beyond `i64` saturate (counted) whatever the overflow rule.
#[inline]
#[must_use]
pub fn to_raw(x: f64, fmt: &Format, sat: &mut SatCounter) -> i64 {
    let y = x * pow2(fmt.frac_bits as i32);
    // Below 2^52 in magnitude (never NaN): the floor and the rounding in `i64`, the same
    // integers as the general path below (an exact truncation, an exact remainder, the
    // floor's parity from its lowest bit).
    if y.abs() < 4_503_599_627_370_496.0 {
        let t = y as i64;
        let fl = t - i64::from(t as f64 > y);
        let rem = y - fl as f64;
        // `|` and `&`, not `||` and `&&`: the fraction of a vertex attribute is as likely
        // above one half as below, and a branch on it was mispredicted half the time.
        let up = match fmt.rounding {
            Rounding::Truncate => false,
            Rounding::HalfUp => rem >= 0.5,
            Rounding::HalfEven => (rem > 0.5) | ((rem == 0.5) & (fl & 1 == 1)),
        };
        return fmt.fit(fl + i64::from(up), sat);
    }
    to_raw_wide(x, fmt, sat)
}

/// [`to_raw`] for `|x 2^frac_bits| >= 2^52`, infinite or NaN.
#[inline(never)]
fn to_raw_wide(x: f64, fmt: &Format, sat: &mut SatCounter) -> i64 {
    if x.is_nan() {
        sat.saturated += 1;
        return 0;
    }
    let y = x * pow2(fmt.frac_bits as i32);
    let fl = floor_exact(y);
    let rem = y - fl;
    let r = match fmt.rounding {
        Rounding::Truncate => fl,
        Rounding::HalfUp => fl + if rem >= 0.5 { 1.0 } else { 0.0 },
        Rounding::HalfEven => {
            let odd = floor_exact(fl * 0.5) != fl * 0.5;
            fl + if rem > 0.5 || (rem == 0.5 && odd) {
                1.0
            } else {
                0.0
            }
        }
    };
    // 2^63 is exactly representable; anything at or beyond it does not fit i64.
    const LIM: f64 = 9_223_372_036_854_775_808.0;
    if r >= LIM {
        sat.saturated += 1;
        return fmt.max_raw();
    }
    if r < -LIM {
        sat.saturated += 1;
        return fmt.min_raw();
    }
    fmt.fit(r as i64, sat)
}

/// `x` as a raw value with `frac` fraction bits (at most 62), rounded to nearest with ties up:
/// [`to_raw`] into the widest signed format (saturating at +-2^62), 0 for a non-finite `x`.
/// For values with no declared hardware format: the fixed parameters a plan quantizes once
/// (scales, light directions), the addresses a float twin traces, the inputs of unit tests.
#[must_use]
pub fn to_raw_nearest(x: f64, frac: u32) -> i64 {
    if !x.is_finite() {
        return 0;
    }
    let frac = frac.min(62);
    let widest = Format::signed(62 - frac, frac, Rounding::HalfUp);
    to_raw(x, &widest, &mut SatCounter::default())
}

/// `y.floor()`, bit for bit (signed zeros, infinities and NaN included), without the libm
/// call `floor` is on x86-64 without SSE4.1: below 2^52 in magnitude through `i64`
/// truncation, above it every double is already an integer.
#[inline]
#[must_use]
pub fn floor_exact(y: f64) -> f64 {
    const TWO_52: f64 = 4_503_599_627_370_496.0;
    if y.abs() < TWO_52 {
        let t = y as i64 as f64;
        if t > y {
            t - 1.0
        } else {
            t.copysign(y)
        }
    } else {
        y
    }
}

/// `raw * 2^-frac_bits` (exact for |raw| <= 2^53).
#[inline]
#[must_use]
pub fn from_raw(raw: i64, frac_bits: u32) -> f64 {
    raw as f64 * pow2(-(frac_bits as i32))
}

/// `2^e` exactly (`2f64.powi(e)`), built from its bit pattern (no libm or `powi` call in
/// per-pixel code).
#[inline]
#[must_use]
pub fn pow2(e: i32) -> f64 {
    if (-1022..=1023).contains(&e) {
        f64::from_bits(((1023 + e) as u64) << 52)
    } else if e > 1023 {
        f64::INFINITY
    } else if e == -1023 {
        // Subnormal; `powi` divides by `2^-e`, which overflows below.
        f64::from_bits(1u64 << 51)
    } else {
        0.0
    }
}

/// `y` rounded to the nearest integer, ties to even, for `0 <= y < 2^52` (exactly
/// `y.round_ties_even()` there): adding 2^52 leaves a unit ulp, so the add rounds in IEEE
/// round-to-nearest-even, the only mode Rust runs in. Unlike `round_ties_even` it needs no
/// libm call on x86-64 without SSE4.1 (the unorm conversions of every texel use it).
#[inline]
#[must_use]
pub fn round_ties_even_small(y: f64) -> f64 {
    const TWO_52: f64 = 4_503_599_627_370_496.0;
    debug_assert!((0.0..TWO_52).contains(&y), "{y} outside [0, 2^52)");
    (y + TWO_52) - TWO_52
}

/// `x` (clamped to [0, 1]; NaN gives 0) as a `bits`-wide unorm, rounded half to even.
#[inline]
#[must_use]
pub fn to_unorm(x: f64, bits: u32) -> u32 {
    let max = ((1u64 << bits.min(32)) - 1) as f64;
    let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
    round_ties_even_small(x * max) as u32
}

/// A `bits`-wide unorm raw value as a float in [0, 1] (0 for `bits == 0`).
#[must_use]
pub fn from_unorm(x: u32, bits: u32) -> f64 {
    if bits == 0 {
        return 0.0;
    }
    f64::from(x) / ((1u64 << bits.min(32)) - 1) as f64
}
