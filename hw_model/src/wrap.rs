//! Texel address and wrap unit.

use crate::config::TrilinearConfig;
use crate::datapath::{Component, Datapath, Stage};
use serde::{Deserialize, Serialize};

/// Texture addressing mode of one axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum WrapMode {
    /// Coordinates repeat with period 1 (GL_REPEAT).
    Repeat,
    /// Texel indices clamp to [0, size-1] (GL_CLAMP_TO_EDGE).
    ClampToEdge,
    /// Coordinates reflect every period (GL_MIRRORED_REPEAT).
    Mirror,
}

/// Output of the address unit for one axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct WrapOut {
    /// Wrapped index of the first texel, in `[0, size-1]`.
    pub i0: u32,
    /// Wrapped index of the second texel (`i0 + 1` before wrapping), in `[0, size-1]`.
    pub i1: u32,
    /// Weight of `i1` with `weight_bits` fraction bits, in `[0, 2^weight_bits - 1]`.
    pub weight: u32,
}

/// Texel address of one axis (texel centres at half-integers, see `trilinear`).
///
/// `coord` is a normalized coordinate with `frac` fraction bits (1.0 = the full texture).
/// `s = coord * size - 1/2` is formed exactly (`frac + 1` fraction bits; `i64` when
/// [`fits_i64`], else `i128`; `frac` is clamped to 62);
/// `i0 = floor(s)`, and the fraction of `s` is reduced to `weight_bits` by `weight_rounding`
/// (exact when `frac + 1 <= weight_bits`). If rounding carries to `2^weight_bits`, then
/// `i0 += 1` and `weight = 0` (the same filtered value), so `weight < 2^weight_bits` always;
/// with `weight_bits = 0` the weight is always 0 (HalfUp/HalfEven then select the nearest texel
/// `round(s)`, Truncate selects `floor(s)`). `i1 = i0 + 1`; both are then wrapped by `mode`:
/// Repeat = Euclidean `mod size`; ClampToEdge = clamp to `[0, size-1]`; Mirror =
/// GL_MIRRORED_REPEAT on indices (`m = i mod 2 size; if m >= size { 2 size - 1 - m }`).
/// `size == 0` is treated as 1. Error of `weight` vs the exact fraction: < 2^-weight_bits for
/// Truncate, <= 2^-(weight_bits+1) for the nearest modes (modulo the carry, which moves both).
#[inline]
#[must_use]
pub fn wrap(
    coord: i64,
    frac: u32,
    size: u32,
    mode: WrapMode,
    cfg: &crate::config::TrilinearConfig,
) -> WrapOut {
    crate::with_rounding!(cfg.weight_rounding, W => wrap_in::<W>(coord, frac, size, mode, cfg))
}

/// [`wrap`] compiled for the weight rounding `W` (`weight_rounding`).
#[inline(always)]
#[must_use]
pub fn wrap_in<W: crate::fixed::ConstRounding>(
    coord: i64,
    frac: u32,
    size: u32,
    mode: WrapMode,
    cfg: &crate::config::TrilinearConfig,
) -> WrapOut {
    if fits_i64(coord, frac, size) {
        wrap_i64_in::<W>(coord, frac, size, mode, cfg.weight_bits.min(16))
    } else {
        wrap_wide_in::<W>(coord, frac, size, mode, cfg)
    }
}

/// Whether [`wrap`] of `coord` on an axis of `size` texels takes its 64-bit path: `frac <= 30`
/// and [`fits_i64_on`] `size`.
#[inline(always)]
#[must_use]
pub fn fits_i64(coord: i64, frac: u32, size: u32) -> bool {
    frac <= 30 && fits_i64_on(coord, size)
}

/// Whether `|coord| size.max(1) < 2^61`: then `|2 coord size| < 2^62`, so with `frac <= 30`
/// the address `s` of [`wrap`] and its index stay below 2^63 (any `coord` in `[-2^29, 2^29]`
/// for the widest `u32` size, `|coord| < 2^53` for 256 texels).
#[inline(always)]
#[must_use]
pub fn fits_i64_on(coord: i64, size: u32) -> bool {
    coord.unsigned_abs().saturating_mul(u64::from(size.max(1))) < 1 << 61
}

/// [`wrap_in`] of a coordinate that [`fits_i64`], `wb` = `weight_bits.min(16)`.
#[inline(always)]
#[must_use]
pub fn wrap_i64_in<W: crate::fixed::ConstRounding>(
    coord: i64,
    frac: u32,
    size: u32,
    mode: WrapMode,
    wb: u32,
) -> WrapOut {
    wrap_i64_with::<W>(coord, size, mode, &WrapShifts::new(frac, wb))
}

/// The shifts of [`wrap_i64_in`] for one coordinate format (`frac <= 30`) and weight width
/// (`wb <= 16`), resolved once for a run of wraps ([`wrap_i64_with`]).
#[derive(Clone, Copy, Debug)]
pub struct WrapShifts {
    /// One half in the fraction bits of `s` (`2^frac`).
    half: i64,
    /// Fraction bits of `s`: `frac + 1`.
    sf: u32,
    /// The fraction bits of `s`: `2^sf - 1`.
    fmask: i64,
    /// Weight width.
    wb: u32,
    /// Dropped fraction bits of `s` (`sf - wb`, or 0).
    down: u32,
    /// Bits the fraction is widened by (`wb - sf`, or 0).
    up: u32,
}

impl WrapShifts {
    /// The shifts for coordinates with `frac` fraction bits and weights of `wb` bits.
    #[inline(always)]
    #[must_use]
    pub fn new(frac: u32, wb: u32) -> Self {
        let sf = frac.saturating_add(1);
        // Only a `frac <= 30` is used; larger ones are kept in range.
        let f = frac.min(62);
        Self {
            half: 1 << f,
            sf,
            fmask: ((1u64 << (f + 1)) - 1) as i64,
            wb,
            down: sf.saturating_sub(wb),
            up: wb.saturating_sub(sf),
        }
    }
}

/// [`wrap_i64_in`] with its shifts resolved in `k` (what [`wrap_i64_in`] runs): a coordinate
/// that [`fits_i64`].
#[inline(always)]
#[must_use]
pub fn wrap_i64_with<W: crate::fixed::ConstRounding>(
    coord: i64,
    size: u32,
    mode: WrapMode,
    k: &WrapShifts,
) -> WrapOut {
    let size = size.max(1);
    let (i0, w) = address::<W>(coord, size, k);
    finish_narrow(i0, w, size, mode)
}

/// [`wrap_i64_with`] of an axis with Repeat on a level whose `size` is a power of two (the
/// caller's test, once per span): both indices masked, no test of the mode or the size.
#[inline(always)]
#[must_use]
pub fn wrap_pow2_repeat<W: crate::fixed::ConstRounding>(
    coord: i64,
    size: u32,
    k: &WrapShifts,
) -> WrapOut {
    debug_assert!(size.is_power_of_two(), "{size}");
    let (i0, weight) = address::<W>(coord, size, k);
    let mask = i64::from(size) - 1;
    WrapOut {
        i0: (i0 & mask) as u32,
        i1: ((i0 + 1) & mask) as u32,
        weight,
    }
}

/// [`wrap_pow2_repeat`] of one lane of a batch on an axis of `2^log2_size` texels, `(i0, i1,
/// weight)`, without a branch (a loop over lanes vectorizes): [`address`] with the size's
/// multiply as a shift and the carry as a select, for shifts `k` of a `frac <= 30`. The same
/// triple for a coordinate in `[-2^29, 2^29)` (the batch's test; any other wraps, in range,
/// to a value the batch discards).
#[inline(always)]
#[must_use]
pub fn wrap_pow2_repeat_lane<W: crate::fixed::ConstRounding>(
    coord: i64,
    log2_size: u32,
    k: &WrapShifts,
) -> (u32, u32, u32) {
    let s = coord.wrapping_shl(log2_size + 1).wrapping_sub(k.half);
    let i0 = s >> k.sf;
    // In [0, 2^sf), `sf <= 31`: the rounding's input range.
    let fr = s & k.fmask;
    let truncate = W::MODE == crate::fixed::Rounding::Truncate;
    let w = if truncate {
        (fr >> k.down) << k.up
    } else {
        crate::fixed::round_shift_right_lane::<W>(fr, k.down) << k.up
    };
    let carry = !truncate && w >> k.wb != 0;
    let i0 = i0.wrapping_add(i64::from(carry));
    let mask = (1i64 << log2_size) - 1;
    (
        (i0 & mask) as u32,
        (i0.wrapping_add(1) & mask) as u32,
        if carry { 0 } else { w as u32 },
    )
}

/// The unwrapped first index `floor(s)` and the weight of a coordinate that [`fits_i64`] on
/// an axis of `size >= 1` texels ([`wrap`]'s rule, the rounding carry applied).
#[inline(always)]
fn address<W: crate::fixed::ConstRounding>(coord: i64, size: u32, k: &WrapShifts) -> (i64, u32) {
    let s = 2 * coord * i64::from(size) - k.half;
    let i0 = s >> k.sf;
    // `s - i0 2^sf`, in [0, 2^sf).
    let fr = s & k.fmask;
    // Reduced to `wb` fraction bits when `sf > wb`, else widened (exact). Truncate is the
    // floor either way (one of `down`, `up` is 0): two shifts, no branch.
    let w = if W::MODE == crate::fixed::Rounding::Truncate {
        (fr >> k.down) << k.up
    } else if k.down == 0 {
        fr << k.up
    } else {
        crate::fixed::round_shift_right_mid::<W>(fr, k.down)
    };
    // Truncation cannot carry (`fr < 2^sf`, so `w < 2^wb`).
    let carry = W::MODE != crate::fixed::Rounding::Truncate && w >> k.wb != 0;
    if carry {
        (i0 + 1, 0)
    } else {
        (i0, w as u32)
    }
}

/// [`finish`] of an index `|i0| < 2^62` (that of a coordinate that [`fits_i64`]): the same
/// pair without the test for `i64::MAX`.
#[inline(always)]
fn finish_narrow(i0: i64, weight: u32, size: u32, mode: WrapMode) -> WrapOut {
    debug_assert!(i0.unsigned_abs() < 1 << 62, "{i0}");
    if mode == WrapMode::Repeat && size & (size - 1) == 0 {
        let mask = i64::from(size) - 1;
        return WrapOut {
            i0: (i0 & mask) as u32,
            i1: ((i0 + 1) & mask) as u32,
            weight,
        };
    }
    finish(i0, weight, size, mode)
}

/// [`wrap_in`] in `i128` (any coordinate).
#[inline(never)]
#[must_use]
pub fn wrap_wide_in<W: crate::fixed::ConstRounding>(
    coord: i64,
    frac: u32,
    size: u32,
    mode: WrapMode,
    cfg: &crate::config::TrilinearConfig,
) -> WrapOut {
    let size = size.max(1);
    let wb = cfg.weight_bits.min(16);
    let rnd = W::MODE;
    let frac = frac.min(62);
    let sf = frac + 1;
    let s = 2 * i128::from(coord) * i128::from(size) - (1i128 << frac);
    let mut i0 = s >> sf;
    let fr = s - (i0 << sf); // in [0, 2^sf)
    let mut w = if sf >= wb {
        crate::fixed::round_shift_right_wide(fr, sf - wb, rnd)
    } else {
        (fr << (wb - sf)) as i64
    };
    if w >> wb != 0 {
        i0 += 1;
        w = 0;
    }
    // Bring huge indices into i64 without changing the wrapped result.
    let i0 = match i64::try_from(i0) {
        Ok(v) => v,
        Err(_) => match mode {
            WrapMode::ClampToEdge => {
                if i0 < 0 {
                    i64::MIN
                } else {
                    i64::MAX - 1
                }
            }
            _ => i0.rem_euclid(2 * i128::from(size)) as i64,
        },
    };
    finish(i0, w as u32, size, mode)
}

/// The wrapped indices `i0` and `i0 + 1` (saturating) of a level of `size >= 1` texels: both
/// inside the level (the common case) need no wrap; with Repeat the second is the first's
/// successor modulo the size (both masked for a power-of-two size, inside the level or not);
/// with ClampToEdge each is clamped.
#[inline(always)]
fn finish(i0: i64, weight: u32, size: u32, mode: WrapMode) -> WrapOut {
    let n = i64::from(size);
    let (a, b) = if mode == WrapMode::Repeat && size & (size - 1) == 0 && i0 < i64::MAX {
        // A power-of-two size reduces both by a mask, inside the level or not (two's
        // complement `&` is the Euclidean remainder; `i0 + 1` does not overflow).
        let mask = n - 1;
        ((i0 & mask) as u32, ((i0 + 1) & mask) as u32)
    } else if (i0 as u64) < (n - 1) as u64 {
        (i0 as u32, i0 as u32 + 1)
    } else {
        match mode {
            WrapMode::Repeat if i0 < i64::MAX => {
                let a = wrap_index(i0, size, mode);
                (a, if a + 1 == size { 0 } else { a + 1 })
            }
            WrapMode::ClampToEdge => (
                i0.clamp(0, n - 1) as u32,
                i0.saturating_add(1).clamp(0, n - 1) as u32,
            ),
            _ => (
                wrap_index(i0, size, mode),
                wrap_index(i0.saturating_add(1), size, mode),
            ),
        }
    };
    WrapOut {
        i0: a,
        i1: b,
        weight,
    }
}

/// Wraps a texel index into `[0, size-1]` by `mode` (`size >= 1`).
#[inline(always)]
#[must_use]
pub fn wrap_index(i: i64, size: u32, mode: WrapMode) -> u32 {
    let n = i64::from(size.max(1));
    if i >= 0 && i < n {
        return i as u32;
    }
    // Power-of-two sizes reduce by masking (two's complement `&` is the Euclidean remainder).
    let pow2 = n & (n - 1) == 0;
    match mode {
        WrapMode::Repeat if pow2 => (i & (n - 1)) as u32,
        WrapMode::Repeat => i.rem_euclid(n) as u32,
        WrapMode::ClampToEdge => i.clamp(0, n - 1) as u32,
        WrapMode::Mirror => {
            let m = if pow2 {
                i & (2 * n - 1)
            } else {
                i.rem_euclid(2 * n)
            };
            (if m >= n { 2 * n - 1 - m } else { m }) as u32
        }
    }
}

/// Cost of the address unit for one axis of one level: multiply, subtract, round, 2 wraps
/// (its cycles are part of the bilinear stage of [`crate::trilinear::bilinear_datapath`]).
#[must_use]
pub fn wrap_cost(_cfg: &crate::config::TrilinearConfig) -> crate::cost::UnitCost {
    crate::cost::UnitCost {
        ops: 5,
        cycles: 0,
        texels: 0,
    }
}

/// Width of the normalized texture coordinate entering the address unit.
pub const COORD_BITS: u32 = 32;
/// Width of a texel index and level size (levels up to 2^16 texels a side).
pub const INDEX_BITS: u32 = 17;

/// Appends the address unit of `axes` axes side by side to `s` (W = `weight_bits`): the
/// coordinate times the level size, the `- 1/2` and rounding to W fraction bits, and for the
/// two texel indices the compare against the size, the wrap subtract and the mode select.
#[must_use]
pub fn address_steps(s: Stage, cfg: &TrilinearConfig, axes: u32) -> Stage {
    let w = cfg.weight_bits;
    s.then_n(
        axes,
        Component::Multiplier {
            a: COORD_BITS,
            b: INDEX_BITS,
        },
    )
    .then_n(
        axes,
        Component::Adder {
            width: INDEX_BITS + w + 1,
        },
    )
    .then_n(2 * axes, Component::Comparator { width: INDEX_BITS })
    .beside(2 * axes, Component::Adder { width: INDEX_BITS })
    .then_n(
        2 * axes,
        Component::Mux {
            width: INDEX_BITS,
            inputs: 3,
        },
    )
}

/// The address/wrap unit of one level (both axes side by side).
#[must_use]
pub fn datapath(cfg: &TrilinearConfig) -> Datapath {
    Datapath::new().stage(address_steps(Stage::new("address and wrap"), cfg, 2))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::config::HwConfig;
    use crate::fixed::{round_shift_right, round_shift_right_wide, Rounding};

    use crate::test_rng::splitmix64 as next;

    /// The wrap of both indices as it was before the in-level and Repeat shortcuts.
    fn finish_before(i0: i64, weight: u32, size: u32, mode: WrapMode) -> WrapOut {
        WrapOut {
            i0: wrap_index(i0, size, mode),
            i1: wrap_index(i0.saturating_add(1), size, mode),
            weight,
        }
    }

    /// `wrap` as it was before it was compiled per rounding mode: the oracle (also of the
    /// trilinear unit's tests).
    pub(crate) fn wrap_before(
        coord: i64,
        frac: u32,
        size: u32,
        mode: WrapMode,
        rnd: Rounding,
        wb: u32,
    ) -> WrapOut {
        let size = size.max(1);
        let wb = wb.min(16);
        if frac <= 30 && coord.unsigned_abs() < (1u64 << 29) {
            let sf = frac + 1;
            let s = 2 * coord * i64::from(size) - (1i64 << frac);
            let i0 = s >> sf;
            let fr = s - (i0 << sf);
            let w = if sf >= wb {
                round_shift_right(fr, sf - wb, rnd)
            } else {
                fr << (wb - sf)
            };
            return if w >> wb != 0 {
                finish_before(i0 + 1, 0, size, mode)
            } else {
                finish_before(i0, w as u32, size, mode)
            };
        }
        let frac = frac.min(62);
        let sf = frac + 1;
        let s = 2 * i128::from(coord) * i128::from(size) - (1i128 << frac);
        let mut i0 = s >> sf;
        let fr = s - (i0 << sf);
        let mut w = if sf >= wb {
            round_shift_right_wide(fr, sf - wb, rnd)
        } else {
            (fr << (wb - sf)) as i64
        };
        if w >> wb != 0 {
            i0 += 1;
            w = 0;
        }
        let i0 = match i64::try_from(i0) {
            Ok(v) => v,
            Err(_) => match mode {
                WrapMode::ClampToEdge => {
                    if i0 < 0 {
                        i64::MIN
                    } else {
                        i64::MAX - 1
                    }
                }
                _ => i0.rem_euclid(2 * i128::from(size)) as i64,
            },
        };
        finish_before(i0, w as u32, size, mode)
    }

    /// 3M seeded cases (every rounding and wrap mode, weight widths 0 to 16, the 64-bit and
    /// 128-bit paths): the per-mode `wrap` gives the old result.
    #[test]
    fn compiled_modes_match_the_previous_wrap() {
        let mut s = 0x5eed_0007;
        let mut cfg = HwConfig::texram16().trilinear;
        for i in 0..3_000_000u32 {
            let rnd = [Rounding::Truncate, Rounding::HalfUp, Rounding::HalfEven][(i % 3) as usize];
            let mode =
                [WrapMode::Repeat, WrapMode::ClampToEdge, WrapMode::Mirror][(i / 3 % 3) as usize];
            cfg.weight_rounding = rnd;
            cfg.weight_bits = i / 9 % 17;
            let frac = (next(&mut s) % 64) as u32;
            let coord = (next(&mut s) as i64) >> (next(&mut s) % 64);
            let size = (next(&mut s) % 5000) as u32;
            assert_eq!(
                wrap(coord, frac, size, mode, &cfg),
                wrap_before(coord, frac, size, mode, rnd, cfg.weight_bits),
                "{coord} {frac} {size} {mode:?} {cfg:?}"
            );
        }
        // The ends of the 64-bit path ([-2^29, 2^29)) and the largest sizes.
        for i in 0..200_000u32 {
            let rnd = [Rounding::Truncate, Rounding::HalfUp, Rounding::HalfEven][(i % 3) as usize];
            let mode =
                [WrapMode::Repeat, WrapMode::ClampToEdge, WrapMode::Mirror][(i / 3 % 3) as usize];
            cfg.weight_rounding = rnd;
            cfg.weight_bits = i / 9 % 17;
            let frac = (next(&mut s) % 32) as u32;
            let edge = [-(1i64 << 29), 1 << 29][(i / 153 % 2) as usize];
            let coord = edge + (next(&mut s) % 5) as i64 - 2;
            let size = [u32::MAX, 1 << 31, 65_536, 3, 1][(next(&mut s) % 5) as usize];
            assert_eq!(
                wrap(coord, frac, size, mode, &cfg),
                wrap_before(coord, frac, size, mode, rnd, cfg.weight_bits),
                "{coord} {frac} {size} {mode:?} {cfg:?}"
            );
        }
    }

    /// 3M seeded texture-space cases (every rounding and wrap mode, weight widths 0 to 16,
    /// level sizes 1, 2, 3, powers of two and others up to 70,000, coordinates mostly in
    /// [-2, 3) and some far outside or at the ends of `i64`): `wrap` gives the previous
    /// result through each of its paths (counted); and `finish` gives the previous pair of
    /// wrapped indices for 3M seeded indices including the ends of `i64` (`finish_narrow`
    /// for those below 2^62).
    #[test]
    fn shortcuts_match_the_previous_wrap() {
        let mut s = 0x5eed_0015;
        let mut cfg = HwConfig::texram16().trilinear;
        let modes = [WrapMode::Repeat, WrapMode::ClampToEdge, WrapMode::Mirror];
        let mut paths = [0u32; 4]; // inside, outside (64-bit), wide, i64 ends
        for i in 0..3_000_000u32 {
            let rnd = [Rounding::Truncate, Rounding::HalfUp, Rounding::HalfEven][(i % 3) as usize];
            let mode = modes[(i / 3 % 3) as usize];
            cfg.weight_rounding = rnd;
            cfg.weight_bits = i / 9 % 17;
            let frac = if i % 10 == 0 {
                31 + (next(&mut s) % 32) as u32
            } else {
                4 + (next(&mut s) % 27) as u32
            };
            let size = match i / 153 % 4 {
                0 => [1, 2, 3][(i / 612 % 3) as usize],
                1 => 1 << (i / 612 % 17),
                _ => (next(&mut s) % 70_000) as u32,
            };
            let coord = match i % 7 {
                0 => (next(&mut s) as i64) >> (next(&mut s) % 64),
                1 => [i64::MIN, i64::MAX, i64::MIN + 1, i64::MAX - 1][(i / 7 % 4) as usize],
                _ => {
                    let one = 1i128 << frac.min(62);
                    let r = i128::from(next(&mut s)) % (5 * one) - 2 * one;
                    r.clamp(i128::from(i64::MIN), i128::from(i64::MAX)) as i64
                }
            };
            let want = wrap_before(coord, frac, size, mode, rnd, cfg.weight_bits);
            assert_eq!(
                wrap(coord, frac, size, mode, &cfg),
                want,
                "{coord} {frac} {size} {mode:?} {cfg:?}"
            );
            let fast = frac <= 30 && coord.unsigned_abs() < (1u64 << 29);
            let inside = want.i1 == want.i0 + 1;
            paths[match (fast, inside) {
                _ if i % 7 == 1 => 3,
                (true, true) => 0,
                (true, false) => 1,
                (false, _) => 2,
            }] += 1;
        }
        assert!(paths.iter().all(|&n| n > 100_000), "{paths:?}");
        for i in 0..3_000_000u32 {
            let mode = modes[(i % 3) as usize];
            let size = [1, 2, 3, 4, 5, 64, 1000, 65_536][(i / 3 % 8) as usize];
            let i0 = match i / 24 % 4 {
                0 => [i64::MIN, i64::MIN + 1, -1, 0, i64::MAX - 1, i64::MAX][(i / 96 % 6) as usize],
                1 => (next(&mut s) as i64) >> (next(&mut s) % 64),
                _ => (next(&mut s) % 200_000) as i64 - 100_000,
            };
            assert_eq!(
                finish(i0, 7, size, mode),
                finish_before(i0, 7, size, mode),
                "{i0} {size} {mode:?}"
            );
            if i0.unsigned_abs() < 1 << 62 {
                assert_eq!(
                    finish_narrow(i0, 7, size, mode),
                    finish_before(i0, 7, size, mode),
                    "{i0} {size} {mode:?}"
                );
            }
        }
    }
}
