//! LOD unit: `lambda = log2(rho)`, `rho = max(|(du/dx, dv/dx)|, |(du/dy, dv/dy)|)` (the OpenGL
//! isotropic rule, OpenGL 4.6 section 8.14.1, eq. 8.7 with the exact scale factor).
//!
//! Datapath (F = `lod_frac_bits`): squared lengths exactly in `u128`, `L` = the larger,
//! `lambda = log2(L) / 2`, so `lambda * 2^F = log2(L) * 2^(F-1)`: the integer part of `log2(L)`
//! comes from a leading-zero count, its F - 1 fraction bits (the halving supplies the last
//! one; for F = 0 the integer part is halved by an arithmetic shift) from the bit-serial
//! repeated squaring of the normalized mantissa
//! `m` in [1, 2) (`m <- m^2`; a bit is 1 iff `m >= 2`, then `m <- m/2`), with `m` kept to
//! [`MANT_BITS`] fraction bits by truncation so each square fits a `u64`. The output is
//! floor-rounded. The simulator takes the loop's bits from a table ([`table_log2_bits`]), the
//! loop itself only within a few mantissas of a result's threshold. The loop's result is
//! monotone in `m` (squaring with truncation and the conditional halving keep the order), so
//! the table is exact wherever the tested premise holds: every threshold lies within the
//! table's slack of its ideal value (the unit tests check it for all 2^15 thresholds, with
//! their neighbourhoods and 10^7 mantissas; all 2^31 mantissas were also compared once, in
//! 73 s, when the table was built).
//!
//! ERROR BOUND: truncation only ever lowers `m`, and each squaring step's truncation error
//! (< 2^-31 relative) contributes < 2^-30 to `log2(L)`; so the result is `floor(lambda * 2^F)`
//! exactly unless `lambda * 2^F` lies less than `F * 2^(F-31)` LSB above an integer (<= 2^-11
//! LSB for F = 16), where it may be exactly 1 LSB low. It is never above the floor. Powers of
//! two are exact. Measured (`tests/units/unit_lod.rs`, all 2^24 pairs (du/dx, dv/dx) in 0..4096, F =
//! 16): 118 results 1 LSB low, all within 9e-6 LSB above an integer.
//!
//! With `lod_log2 = piecewise-linear` (Mesa llvmpipe's `lp_build_fast_log2`) the mantissa
//! fraction replaces the squaring loop: `log2(L) ~= e + (L - 2^e) / 2^e`, `e` = the MSB index,
//! and the result is `floor` of that times `2^(F-1)`, exactly (the fraction is cut to 16 bits
//! first, which cannot change a floor at F <= 16 fraction bits of lambda). ERROR BOUND vs
//! the exact `lambda`: `0 <= lambda - pwl <= 0.04305` (half the largest deficit of the chord,
//! `log2(1/ln 2) - 1/ln 2 + 1 = 0.08607`, at `m = 1/ln 2`), then floor-rounded.
//!
//! Range: `rho == 0` returns [`lod_zero`] = `-(32 << F)`; any smaller result is clamped to it
//! (rho < 2^-32, counted as a saturation unless rho == 0). The largest result is below
//! `64 << F`.

use crate::config::{LodConfig, LodLog2};
use crate::cost::UnitCost;
use crate::datapath::{ceil_log2, Component, Datapath, Stage};
use crate::fixed::SatCounter;

/// Fraction bits of the mantissa in the squaring loop.
pub const MANT_BITS: u32 = 31;

/// The value returned for `rho == 0`: `-(32 << lod_frac_bits)` (also the lower clamp).
#[inline]
#[must_use]
pub const fn lod_zero(lod_frac_bits: u32) -> i64 {
    -(32i64 << lod_frac_bits)
}

/// LOD with `cfg.lod_frac_bits` fraction bits (floor-rounded, signed) from the derivatives
/// `d = (du/dx, dv/dx, du/dy, dv/dy)` in level-0 texel units with `frac` fraction bits.
#[inline(always)]
#[must_use]
pub fn lod(d: [i64; 4], frac: u32, cfg: &LodConfig, sat: &mut SatCounter) -> i64 {
    let f = cfg.lod_frac_bits.min(16);
    let floor_val = lod_zero(f);
    // The squared lengths in u64 when every |d| < 2^31 (each sum < 2^63), else in u128.
    let a = d.map(i64::unsigned_abs);
    let small = (a[0] | a[1] | a[2] | a[3]) < 1 << 31;
    let (e, mant, l) = if small {
        let l = (a[0] * a[0] + a[1] * a[1]).max(a[2] * a[2] + a[3] * a[3]);
        if l == 0 {
            return floor_val;
        }
        let e = 63 - l.leading_zeros();
        let m = if e >= MANT_BITS {
            l >> (e - MANT_BITS)
        } else {
            l << (MANT_BITS - e)
        };
        (e, m, u128::from(l))
    } else {
        wide_squares(d)
    };
    if cfg.lod_log2 == LodLog2::PiecewiseLinear {
        // floor((e - 2 frac + (L - 2^e) / 2^e) 2^16), then floor(/ 2^(17 - F)) = floor(* 2^(F-1)).
        let mf = l - (1u128 << e);
        let t16 = if e >= 16 {
            (mf >> (e - 16)) as i64
        } else {
            (mf << (16 - e)) as i64
        };
        let t = ((i64::from(e) - 2 * i64::from(frac)) << 16) + t16;
        let v = t >> (17 - f);
        if v < floor_val {
            sat.saturated += 1;
            return floor_val;
        }
        return v;
    }
    // lambda * 2^F = log2(L) * 2^(F-1): F - 1 fraction bits of log2(L) give the floor exactly.
    let steps = f.saturating_sub(1);
    let bits = i64::from(table_log2_bits(mant) >> (SERIAL_STEPS - steps));
    // floor(log2(L) * 2^steps); L has 2*frac fraction bits.
    let int_part = i64::from(e) - 2 * i64::from(frac);
    let t = (int_part << steps) + bits;
    let v = if f == 0 { t >> 1 } else { t };
    if v < floor_val {
        sat.saturated += 1;
        return floor_val;
    }
    v
}

/// The larger squared length `L` of [`lod`] in `u128` (some `|d| >= 2^31`, so `L > 0`): its
/// MSB index and its mantissa with [`MANT_BITS`] fraction bits (truncated).
#[inline(never)]
fn wide_squares(d: [i64; 4]) -> (u32, u64, u128) {
    let sq = |a: i64| -> u128 {
        let u = u128::from(a.unsigned_abs());
        u * u
    };
    let l = (sq(d[0]) + sq(d[1])).max(sq(d[2]) + sq(d[3]));
    let e = 127 - l.leading_zeros(); // bit index of the MSB
    let m = if e >= MANT_BITS {
        (l >> (e - MANT_BITS)) as u64
    } else {
        (l << (MANT_BITS - e)) as u64
    };
    (e, m, l)
}

/// Squaring steps of the widest LOD (`lod_frac_bits` = 16).
pub const SERIAL_STEPS: u32 = 15;

/// The first `steps` bits of `log2(m / 2^MANT_BITS)` by the bit-serial repeated squaring of
/// the module doc (`m` in `[2^31, 2^32)`, truncated to [`MANT_BITS`] after every square).
#[must_use]
pub fn serial_log2_bits(mut m: u64, steps: u32) -> u32 {
    let mut bits = 0u32;
    for _ in 0..steps {
        m = (m * m) >> MANT_BITS;
        let b = m >> (MANT_BITS + 1);
        bits = (bits << 1) | b as u32;
        m >>= b;
    }
    bits
}

/// Number of 15-bit results of the bit-serial log2.
const RESULTS: usize = 1 << SERIAL_STEPS;
/// Bits per bucket of [`LOG2_BUCKET`].
const BUCKET_BITS: u32 = 16;
/// How far (in mantissas) a threshold of the bit-serial log2 may lie from [`LOG2_IDEAL`]'s.
const THRESHOLD_SLACK: u32 = 4;

/// `ceil(2^31 2^(k / 2^15)) - 2^31` for k = 0..=2^15 (within one: the powers are formed by
/// repeated multiplication by `2^(2^-15)` on 32 fraction bits, `(2^(2^-15) - 1) 2^64` =
/// 390211300099399.33), then `u32::MAX` (three times, so that a bucket's four candidates can
/// be read at once): where the exact log2 of the mantissa reaches `k / 2^15`.
pub static LOG2_IDEAL: [u32; RESULTS + 4] = ideal_thresholds();
/// For each bucket of 2^16 mantissa offsets, how many of `LOG2_IDEAL[1..]` are at or below
/// its first offset.
static LOG2_BUCKET: [u16; 1 << (MANT_BITS - BUCKET_BITS)] = buckets();

const fn ideal_thresholds() -> [u32; RESULTS + 4] {
    let mut t = [0u32; RESULTS + 4];
    let mut x: u128 = 1 << 63; // 2^31 with 32 fraction bits
    let mut k = 1;
    while k < RESULTS {
        x += (x * 390_211_300_099_399) >> 64;
        t[k] = (((x + (1 << 32) - 1) >> 32) - (1 << MANT_BITS)) as u32;
        k += 1;
    }
    t[RESULTS] = 1 << MANT_BITS;
    t[RESULTS + 1] = u32::MAX;
    t[RESULTS + 2] = u32::MAX;
    t[RESULTS + 3] = u32::MAX;
    t
}

const fn buckets() -> [u16; 1 << (MANT_BITS - BUCKET_BITS)] {
    let ideal = ideal_thresholds();
    let mut b = [0u16; 1 << (MANT_BITS - BUCKET_BITS)];
    let (mut i, mut k) = (0usize, 0usize);
    while i < b.len() {
        while ideal[k + 1] <= (i as u32) << BUCKET_BITS {
            k += 1;
        }
        b[i] = k as u16;
        i += 1;
    }
    b
}

/// [`serial_log2_bits`] with [`SERIAL_STEPS`] steps of `m` in `[2^31, 2^32)`, the same bits,
/// mostly without the loop. The bit-serial log2 is a nondecreasing function of `m` (a larger
/// `m` squares to a larger or equal state; while the bits agree the states stay ordered, and
/// the first bit that differs is 1 for the larger), so its result is `k` for `T_k <= m <
/// T_(k+1)`, `T_k` the least mantissa with a result `>= k`; truncation only lowers the
/// result, so `T_k` is at or a little above the exact `2^31 2^(k/2^15)`, within
/// [`THRESHOLD_SLACK`] of [`LOG2_IDEAL`] (checked for every `k` by the tests). `k` with
/// `LOG2_IDEAL[k] <= m - 2^31 < LOG2_IDEAL[k+1]` comes from the bucket of `m` and two
/// compares (the ideal thresholds are over 45,000 apart, at most two per bucket of 2^16);
/// when `m` lies farther than the slack from both, that is the result, otherwise (about 1 in
/// 5,000 mantissas) the loop runs.
#[inline(always)]
#[must_use]
pub fn table_log2_bits(m: u64) -> u32 {
    debug_assert!(m >> MANT_BITS == 1, "mantissa {m:#x} outside [2^31, 2^32)");
    let off = (m as u32) ^ (1 << MANT_BITS);
    // `off < 2^31`: the mask only drops the bounds check.
    let bucket = (off >> BUCKET_BITS) as usize & (LOG2_BUCKET.len() - 1);
    let k0 = usize::from(LOG2_BUCKET[bucket]);
    // The bucket's candidates read at once (not one after the other): the thresholds
    // increase, so `off >= t[2]` implies `off >= t[1]` and `k = k0 + both`.
    let Some(&[t0, t1, t2, t3]) = LOG2_IDEAL.get(k0..k0 + 4) else {
        return serial_log2_bits(m, SERIAL_STEPS);
    };
    let (a, b) = (off >= t1, off >= t2);
    let (lo, hi) = match (a, b) {
        (false, _) => (t0, t1),
        (true, false) => (t1, t2),
        (true, true) => (t2, t3),
    };
    if off - lo >= THRESHOLD_SLACK && hi - off > THRESHOLD_SLACK {
        (k0 + usize::from(a) + usize::from(b)) as u32
    } else {
        serial_log2_bits(m, SERIAL_STEPS)
    }
}

/// Whether [`table_log2_bits`] takes the table's value for `m` (else it runs the loop).
#[must_use]
pub fn table_log2_is_direct(m: u64) -> bool {
    let off = (m as u32) ^ (1 << MANT_BITS);
    let mut k = usize::from(LOG2_BUCKET[(off >> BUCKET_BITS) as usize]);
    k += usize::from(off >= LOG2_IDEAL[k + 1]);
    k += usize::from(off >= LOG2_IDEAL[k + 1]);
    off - LOG2_IDEAL[k] >= THRESHOLD_SLACK && LOG2_IDEAL[k + 1] - off > THRESHOLD_SLACK
}

/// Cost: cycles from [`datapath`] (`lod_cycles + lod_cycles_per_bit * lod_frac_bits` when both
/// are hand-set); ops = 4 squares, 2 adds, compare,
/// normalize, plus one square per squaring step.
#[must_use]
pub fn lod_cost(cfg: &LodConfig, gate_levels_per_cycle: u32) -> UnitCost {
    UnitCost {
        ops: 8 + cfg.lod_frac_bits.saturating_sub(1),
        cycles: datapath(cfg).latency(gate_levels_per_cycle),
        texels: 0,
    }
}

/// Width of the texture-coordinate derivatives entering the LOD unit's squarers.
pub const DERIV_BITS: u32 = 32;

/// The LOD unit's datapath (F = `lod_frac_bits`): the four squares of the derivatives, the
/// two sums, the larger (compare, select), the leading-zero count and normalizing shift
/// (`lod_cycles`), then one squaring step of the `MANT_BITS + 1`-bit mantissa per fraction
/// bit, each a multiplier and the select of `m` or `m / 2` (`lod_cycles_per_bit` each).
#[must_use]
pub fn datapath(cfg: &LodConfig) -> Datapath {
    let sq = 2 * DERIV_BITS + 1;
    let m = MANT_BITS + 1;
    Datapath::new()
        .stage(
            Stage::new("squared lengths")
                .then_n(
                    4,
                    Component::Multiplier {
                        a: DERIV_BITS,
                        b: DERIV_BITS,
                    },
                )
                .then_n(2, Component::Adder { width: sq })
                .then(Component::Comparator { width: sq })
                .then(Component::Mux {
                    width: sq,
                    inputs: 2,
                })
                .then(Component::LeadingZeros { width: sq })
                .then(Component::Shifter {
                    width: m,
                    shift_bits: ceil_log2(sq),
                })
                .cycles(cfg.lod_cycles),
        )
        .stage(
            Stage::new("log2 bit (squaring)")
                .then(Component::Multiplier { a: m, b: m })
                .then(Component::Mux {
                    width: m,
                    inputs: 2,
                })
                .then(Component::Register { bits: m + 16 })
                .times(cfg.lod_frac_bits)
                .cycles(cfg.lod_cycles_per_bit),
        )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::HwConfig;
    use crate::test_rng::splitmix64 as next;

    /// `lod` before its squares went to `u64` and its log2 to the table: the oracle.
    fn lod_before(d: [i64; 4], frac: u32, cfg: &LodConfig, sat: &mut SatCounter) -> i64 {
        let f = cfg.lod_frac_bits.min(16);
        let sq = |a: i64| -> u128 {
            let u = u128::from(a.unsigned_abs());
            u * u
        };
        let lx = sq(d[0]) + sq(d[1]);
        let ly = sq(d[2]) + sq(d[3]);
        let l = lx.max(ly);
        let floor_val = lod_zero(f);
        if l == 0 {
            return floor_val;
        }
        let e = 127 - l.leading_zeros(); // bit index of the MSB
        if cfg.lod_log2 == LodLog2::PiecewiseLinear {
            // floor((e - 2 frac + (L - 2^e) / 2^e) 2^16), then floor(/ 2^(17 - F)) = floor(* 2^(F-1)).
            let mf = l - (1u128 << e);
            let t16 = if e >= 16 {
                (mf >> (e - 16)) as i64
            } else {
                (mf << (16 - e)) as i64
            };
            let t = ((i64::from(e) - 2 * i64::from(frac)) << 16) + t16;
            let v = t >> (17 - f);
            if v < floor_val {
                sat.saturated += 1;
                return floor_val;
            }
            return v;
        }
        // Normalized mantissa with MANT_BITS fraction bits (truncated).
        let mut m: u64 = if e >= MANT_BITS {
            (l >> (e - MANT_BITS)) as u64
        } else {
            (l << (MANT_BITS - e)) as u64
        };
        // lambda * 2^F = log2(L) * 2^(F-1): F - 1 fraction bits of log2(L) give the floor exactly.
        let steps = f.saturating_sub(1);
        let mut bits: i64 = 0;
        for _ in 0..steps {
            m = (m * m) >> MANT_BITS;
            let b = m >> (MANT_BITS + 1);
            bits = (bits << 1) | b as i64;
            m >>= b;
        }
        // floor(log2(L) * 2^steps); L has 2*frac fraction bits.
        let int_part = i64::from(e) - 2 * i64::from(frac);
        let t = (int_part << steps) + bits;
        let v = if f == 0 { t >> 1 } else { t };
        if v < floor_val {
            sat.saturated += 1;
            return floor_val;
        }
        v
    }

    /// The table's premise for every result `k`: the bit-serial threshold `T_k` lies within
    /// the slack of `LOG2_IDEAL[k]` (the result is `>= k` at `ideal + slack` and `< k` one
    /// below `ideal - slack`); the ideal thresholds are more than 2^15 apart (at most two per
    /// bucket). Then 10^7 seeded mantissas and the neighbourhood of every threshold give the
    /// bit-serial result for every step count 0 to 15, with both the table's value and the
    /// loop taken (counted).
    #[test]
    fn log2_table_matches_the_serial_log2() {
        let top = 1u64 << MANT_BITS;
        let slack = u64::from(THRESHOLD_SLACK);
        let mut gap = u32::MAX;
        for k in 1..RESULTS {
            let ideal = top + u64::from(LOG2_IDEAL[k]);
            assert!(
                serial_log2_bits(ideal + slack, SERIAL_STEPS) >= k as u32,
                "{k}"
            );
            assert!(
                serial_log2_bits(ideal - slack - 1, SERIAL_STEPS) < k as u32,
                "{k}"
            );
            gap = gap.min(LOG2_IDEAL[k] - LOG2_IDEAL[k - 1]);
        }
        assert!(gap > 1 << SERIAL_STEPS, "{gap}");
        let (mut direct, mut looped) = (0u32, 0u32);
        let mut check = |m: u64| {
            let b = table_log2_bits(m);
            assert_eq!(b, serial_log2_bits(m, SERIAL_STEPS), "{m}");
            let steps = (m % 16) as u32;
            assert_eq!(
                b >> (SERIAL_STEPS - steps),
                serial_log2_bits(m, steps),
                "{m}"
            );
            if table_log2_is_direct(m) {
                direct += 1;
            } else {
                looped += 1;
            }
        };
        for &t in &LOG2_IDEAL[1..RESULTS] {
            let ideal = top + u64::from(t);
            for m in ideal - slack - 2..=ideal + slack + 2 {
                check(m);
            }
        }
        for m in [top, top + 1, 2 * top - 2, 2 * top - 1] {
            check(m);
        }
        let mut s = 0x5eed_0013;
        for _ in 0..10_000_000 {
            check(top | (next(&mut s) & (top - 1)));
        }
        assert!(direct > 9_000_000 && looped > 200_000, "{direct} {looped}");
    }

    /// 4M seeded derivative sets (every `lod_frac_bits` 0 to 16, both log2 modes, coordinate
    /// fractions 0 to 40, derivatives from 0 to the ends of `i64`: the `u64` and the `u128`
    /// squares) give the previous unit's LOD and saturation count.
    #[test]
    fn lod_matches_the_previous_unit() {
        let mut s = 0x5eed_0014;
        let mut cfg = HwConfig::texram16().lod;
        let (mut narrow, mut wide, mut zero) = (0u32, 0u32, 0u32);
        let (mut sat, mut sat_before) = (SatCounter::default(), SatCounter::default());
        for i in 0..4_000_000u32 {
            cfg.lod_frac_bits = i % 17;
            cfg.lod_log2 = if i / 17 % 4 == 0 {
                LodLog2::PiecewiseLinear
            } else {
                LodLog2::Exact
            };
            let frac = (next(&mut s) % 41) as u32;
            let sh = [1, 20, 33, 40, 50, 63][(i / 68 % 6) as usize];
            let mut d = [0; 4].map(|_| (next(&mut s) as i64) >> sh);
            if i % 97 == 0 {
                d[(i / 97 % 4) as usize] = [i64::MIN, i64::MAX, 0][(i / 388 % 3) as usize];
            }
            if i % 89 == 0 {
                d = [0; 4];
            }
            match d.iter().map(|x| x.unsigned_abs()).max() {
                Some(0) => zero += 1,
                Some(x) if x < 1 << 31 => narrow += 1,
                _ => wide += 1,
            }
            assert_eq!(
                lod(d, frac, &cfg, &mut sat),
                lod_before(d, frac, &cfg, &mut sat_before),
                "{d:?} {frac} {cfg:?}"
            );
        }
        assert_eq!(sat, sat_before);
        assert!(
            narrow > 1_000_000 && wide > 1_000_000 && zero > 40_000,
            "{narrow} {wide} {zero}"
        );
        assert!(sat.saturated > 1000, "{sat:?}");
    }
}
