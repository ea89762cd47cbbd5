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
//! floor-rounded. The simulator takes the loop's bits from a quadratic per segment of the
//! mantissa range ([`table_log2_bits`], a 4 KiB table), the loop itself only where that
//! value lies near an integer (about 1 in 500 mantissas). The loop's result is monotone in
//! `m` (squaring with truncation and the conditional halving keep the order) and its
//! thresholds lie within a few mantissas of the exact ones (the unit tests check all 2^15,
//! their neighbourhoods and 10^7 mantissas; all 2^31 mantissas were also compared once, in
//! 47 s on two threads, when the quadratics replaced the 192 KiB threshold tables).
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
use crate::fixed::{round_shift_right_mid, SatCounter, TruncateMode};

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
    lod_with(&LodSetup::new(frac, cfg), d, sat)
}

/// The constants of [`lod`] for one configuration and coordinate format, resolved once for a
/// run of LODs (e.g. a span) by [`lod_with`].
#[derive(Clone, Copy, Debug)]
pub struct LodSetup {
    /// Coordinate fraction bits.
    frac: u32,
    /// `lod_frac_bits`, at most 16.
    f: u32,
    /// [`lod_zero`] of `f`: the result for a zero footprint and the lower clamp.
    floor_val: i64,
    /// `cfg.lod_log2` is PiecewiseLinear.
    piecewise: bool,
    /// Fraction bits of log2(L) the Exact mode takes from the table: `f - 1` (0 for `f` = 0).
    steps: u32,
    /// The floor halving of the Exact mode for `f` = 0: 1, else 0.
    halve: u32,
}

impl LodSetup {
    /// The constants for `cfg` and coordinates with `frac` fraction bits.
    #[inline(always)]
    #[must_use]
    pub fn new(frac: u32, cfg: &LodConfig) -> Self {
        let f = cfg.lod_frac_bits.min(16);
        Self {
            frac,
            f,
            floor_val: lod_zero(f),
            piecewise: cfg.lod_log2 == LodLog2::PiecewiseLinear,
            steps: f.saturating_sub(1),
            halve: u32::from(f == 0),
        }
    }
}

/// [`lod`] with its constants resolved in `k`: the same value and count.
#[inline(always)]
#[must_use]
pub fn lod_with(k: &LodSetup, d: [i64; 4], sat: &mut SatCounter) -> i64 {
    let (frac, f, floor_val) = (k.frac, k.f, k.floor_val);
    // The squared lengths in u64 when every d is in [-2^31, 2^31) (each sum <= 2^63), else in
    // u128: one test of the four offsets `d + 2^31`.
    let offsets = d.map(|x| (x as u64).wrapping_add(1 << 31));
    let small = (offsets[0] | offsets[1] | offsets[2] | offsets[3]) < 1 << 32;
    let (e, mant, l) = if small {
        // Each square at most 2^62 in `i64`.
        let sq = d.map(|x| (x * x) as u64);
        let l = (sq[0] + sq[1]).max(sq[2] + sq[3]);
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
    if k.piecewise {
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
    let steps = k.steps;
    let bits = i64::from(table_log2_bits(mant) >> (SERIAL_STEPS - steps));
    // floor(log2(L) * 2^steps); L has 2*frac fraction bits.
    let int_part = i64::from(e) - 2 * i64::from(frac);
    let t = (int_part << steps) + bits;
    let v = t >> k.halve;
    if v < floor_val {
        sat.saturated += 1;
        return floor_val;
    }
    v
}

/// [`lod_with`] of each lane `j` of `lanes` into `out[j]`, its derivatives those of the
/// texture coordinates of three samples `uv[sample][axis][j]` (the pixel, its neighbour one
/// step in x and one in y) on a `w` x `h` level 0: `d = ((u1 - u0) w, (v1 - v0) h, (u2 - u0) w,
/// (v2 - v0) h)`. The same values and saturation counts as one [`lod_with`] call per lane
/// (`lod_lanes_matches_lod_with`): in the Exact mode every lane is computed without a branch on
/// its data (as vector lanes where the CPU has AVX2 or AVX-512: the table's quadratic by
/// gathers), and a lane whose derivatives leave `[-2^31, 2^31)`, whose quadratic lies within
/// [`LOG2_MARGIN`] of an integer, or whose result takes the clamp is computed again by
/// [`lod_with`]; the piecewise-linear mode takes [`lod_with`] on every lane. `lanes.end` must
/// not exceed `L`.
pub fn lod_lanes<const L: usize>(
    k: &LodSetup,
    uv: &[[[i64; L]; 2]; 3],
    lanes: std::ops::Range<usize>,
    (w, h): (u32, u32),
    sat: &mut SatCounter,
    out: &mut [i64; L],
) {
    assert!(lanes.end <= L, "lanes {lanes:?} beyond {L}");
    let size = (i64::from(w), i64::from(h));
    let mut redo = [true; L];
    if !k.piecewise {
        redo = [false; L];
        exact_lanes_vector(k, uv, lanes.clone(), size, out, &mut redo);
    }
    for j in lanes.filter(|&j| redo[j]) {
        out[j] = lod_with(k, lane_derivs(uv, j, size), sat);
    }
}

/// The derivatives of lane `j` of [`lod_lanes`] (wrapping, as a release build's `i64`).
#[inline(always)]
fn lane_derivs<const L: usize>(uv: &[[[i64; L]; 2]; 3], j: usize, (w, h): (i64, i64)) -> [i64; 4] {
    let diff =
        |s: usize, ax: usize, size: i64| uv[s][ax][j].wrapping_sub(uv[0][ax][j]).wrapping_mul(size);
    [diff(1, 0, w), diff(1, 1, h), diff(2, 0, w), diff(2, 1, h)]
}

/// [`lod_with`]'s Exact mode on each lane of `lanes` without a branch on a lane's data (so
/// the loop runs as vector lanes): the value in `out`, and in `redo` whether the lane is one
/// [`lod_lanes`] computes again (its value here is not read).
#[inline(always)]
fn exact_lanes<const L: usize>(
    k: &LodSetup,
    uv: &[[[i64; L]; 2]; 3],
    lanes: std::ops::Range<usize>,
    size: (i64, i64),
    out: &mut [i64; L],
    redo: &mut [bool; L],
) {
    let (frac2, steps, drop) = (2 * i64::from(k.frac), k.steps, SERIAL_STEPS - k.steps);
    for j in lanes {
        let d = lane_derivs(uv, j, size);
        let offsets = d.map(|x| (x as u64).wrapping_add(1 << 31));
        let small = (offsets[0] | offsets[1] | offsets[2] | offsets[3]) < 1 << 32;
        let sq = d.map(|x| x.wrapping_mul(x) as u64);
        let l = sq[0].wrapping_add(sq[1]).max(sq[2].wrapping_add(sq[3]));
        // The MSB index (-1 for `l` = 0, whose lane returns `floor_val`).
        let e = 63 - i64::from(l.leading_zeros());
        let m = if e >= i64::from(MANT_BITS) {
            l.wrapping_shr((e - i64::from(MANT_BITS)) as u32)
        } else {
            l.wrapping_shl((i64::from(MANT_BITS) - e) as u32)
        };
        let (bits, direct) = quadratic_bits(m);
        let v = (((e - frac2) << steps) + i64::from(bits >> drop)) >> k.halve;
        let zero = l == 0;
        out[j] = if zero { k.floor_val } else { v };
        redo[j] = !small | (!zero & (!direct | (v < k.floor_val)));
    }
}

crate::isa_kernel! {
    /// [`exact_lanes`] built for the vector instruction set in force.
    fn exact_lanes_vector[const L: usize](
        k: &LodSetup,
        uv: &[[[i64; L]; 2]; 3],
        lanes: std::ops::Range<usize>,
        size: (i64, i64),
        out: &mut [i64; L],
        redo: &mut [bool; L],
    ) = exact_lanes::<L>;
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

/// Segments of the mantissa range in [`LOG2_QUAD`] (`2^SEG_BITS`).
const SEG_BITS: u32 = 8;
/// Mantissa offsets per segment: `2^SHIFT`.
const SEG_SHIFT: u32 = MANT_BITS - SEG_BITS;
/// Distance (in units of `2^-16` of a result) that the quadratic's value must keep from an
/// integer for [`table_log2_bits`] to take its floor: the floor differs from the loop's
/// result only within 4 units of an integer (all 2^31 mantissas, measured), so 16 times that.
pub const LOG2_MARGIN: u32 = 64;

/// `floor(2^31 log2(1 + x / 2^31))` for `x` in `[0, 2^31]`: the first 31 bits of the exact
/// log2 by the bit-serial squaring of [`serial_log2_bits`] on 62 fraction bits (each
/// truncation lowers the state by less than `2^-61` relative, far below the last bit kept;
/// `x = 2^31` gives `2^31`).
const fn log2_q31(x: u64) -> u64 {
    if x >= 1 << MANT_BITS {
        return 1 << 31;
    }
    let mut m: u128 = ((1u128 << MANT_BITS) + x as u128) << 31; // Q1.62
    let mut bits = 0u64;
    let mut i = 0;
    while i < 31 {
        m = (m * m) >> 62;
        let b = (m >> 63) as u64;
        bits = (bits << 1) | b;
        m >>= b;
        i += 1;
    }
    bits
}

/// Per segment `j` of `2^SEG_SHIFT` mantissa offsets, the quadratic through
/// `z(t) = 2^31 log2(1 + (j 2^SEG_SHIFT + t) / 2^31)` at `t` = 0, half and the whole segment
/// (each to `2^-31`): `[z0, a, b]` with `z(t) ~= z0 + a tau + b tau^2`, `tau = t / 2^SEG_SHIFT`
/// (`a = 4 z_mid - 3 z0 - z1`, `b = 2 (z0 + z1 - 2 z_mid)`).
static LOG2_QUAD: [[i32; 4]; 1 << SEG_BITS] = quadratics();

const fn quadratics() -> [[i32; 4]; 1 << SEG_BITS] {
    let mut q = [[0i32; 4]; 1 << SEG_BITS];
    let mut j = 0;
    while j < q.len() {
        let at = (j as u64) << SEG_SHIFT;
        let z0 = log2_q31(at) as i64;
        let zm = log2_q31(at + (1 << (SEG_SHIFT - 1))) as i64;
        let z1 = log2_q31(at + (1 << SEG_SHIFT)) as i64;
        q[j] = [
            z0 as i32,
            (4 * zm - 3 * z0 - z1) as i32,
            (2 * (z0 + z1 - 2 * zm)) as i32,
            0,
        ];
        j += 1;
    }
    q
}

/// [`serial_log2_bits`] with [`SERIAL_STEPS`] steps of `m` in `[2^31, 2^32)`, the same bits,
/// mostly without the loop. The bit-serial log2 is a nondecreasing function of `m` (a larger
/// `m` squares to a larger or equal state; while the bits agree the states stay ordered, and
/// the first bit that differs is 1 for the larger), so its result is `k` for `T_k <= m <
/// T_(k+1)`, `T_k` the least mantissa with a result `>= k`; truncation only lowers the
/// result, so `T_k` is at or a few mantissas above the exact `2^31 2^(k/2^15)` (checked for
/// every `k` by the tests). So where the exact `2^15 log2(m / 2^31)` lies farther than those
/// few mantissas from an integer, the result is its floor. That value comes, to 16 fraction
/// bits, from a quadratic per segment of `2^23` mantissas ([`LOG2_QUAD`], 4 KiB); when it
/// lies within [`LOG2_MARGIN`] of an integer (about 1 in 500 mantissas) the loop runs.
/// Checked against the loop for all 2^31 mantissas once (when it was built) and, in the unit
/// tests, for the neighbourhood of every threshold and 10^7 seeded mantissas.
#[inline(always)]
#[must_use]
pub fn table_log2_bits(m: u64) -> u32 {
    debug_assert!(m >> MANT_BITS == 1, "mantissa {m:#x} outside [2^31, 2^32)");
    match log2_quadratic(m) {
        Some(bits) => bits,
        None => serial_log2_bits(m, SERIAL_STEPS),
    }
}

/// The quadratic's floor of `2^15 log2(m / 2^31)` for `m` in `[2^31, 2^32)` ([`LOG2_QUAD`],
/// 16 fraction bits), or `None` where its value lies within [`LOG2_MARGIN`] of an integer
/// (there [`table_log2_bits`] runs the loop).
#[inline(always)]
fn log2_quadratic(m: u64) -> Option<u32> {
    let (bits, direct) = quadratic_bits(m);
    direct.then_some(bits)
}

/// [`log2_quadratic`] without the branch: the quadratic's floor, and whether it lies at least
/// [`LOG2_MARGIN`] from an integer (any `m`: only its low 32 bits are read).
#[inline(always)]
fn quadratic_bits(m: u64) -> (u32, bool) {
    let off = (m as u32) ^ (1 << MANT_BITS);
    // `off < 2^31`: the mask only drops the bounds check.
    let [z0, a, b, _] = LOG2_QUAD[(off >> SEG_SHIFT) as usize & (LOG2_QUAD.len() - 1)];
    let t = i64::from(off & ((1 << SEG_SHIFT) - 1));
    let tb = round_shift_right_mid::<TruncateMode>(t * i64::from(b), SEG_SHIFT);
    let z =
        i64::from(z0) + round_shift_right_mid::<TruncateMode>(t * (i64::from(a) + tb), SEG_SHIFT);
    // z (16 fraction bits) within `[0, 2^31)`: the floor and the distance to an integer.
    let f = (z as u32) & 0xffff;
    let direct = f.wrapping_sub(LOG2_MARGIN) <= 0x1_0000 - 2 * LOG2_MARGIN;
    ((z >> 16) as u32, direct)
}

/// Whether [`table_log2_bits`] takes the quadratic's value for `m` (else it runs the loop).
#[must_use]
pub fn table_log2_is_direct(m: u64) -> bool {
    log2_quadratic(m).is_some()
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

    /// Number of 15-bit results of the bit-serial log2.
    const RESULTS: usize = 1 << SERIAL_STEPS;
    /// How far (in mantissas) a threshold of the bit-serial log2 may lie from the ideal one.
    const THRESHOLD_SLACK: u64 = 4;

    /// `ceil(2^31 2^(k / 2^15)) - 2^31` for k = 1..2^15 (within one: the powers are formed by
    /// repeated multiplication by `2^(2^-15)` on 32 fraction bits, `(2^(2^-15) - 1) 2^64` =
    /// 390211300099399.33): where the exact log2 of the mantissa reaches `k / 2^15`.
    fn ideal_thresholds() -> Vec<u64> {
        let mut t = vec![0u64; RESULTS];
        let mut x: u128 = 1 << 63; // 2^31 with 32 fraction bits
        for t in t.iter_mut().skip(1) {
            x += (x * 390_211_300_099_399) >> 64;
            *t = (((x + (1 << 32) - 1) >> 32) - (1 << MANT_BITS)) as u64;
        }
        t
    }

    /// The premise of [`table_log2_bits`] for every result `k`: the bit-serial threshold
    /// `T_k` lies within the slack of the ideal one (the result is `>= k` at `ideal + slack`
    /// and `< k` one below `ideal - slack`). Then the neighbourhood (+-8) of every threshold,
    /// the ends and 10^7 seeded mantissas give the bit-serial result for every step count 0
    /// to 15, with both the quadratic's value and the loop taken (counted).
    #[test]
    fn log2_table_matches_the_serial_log2() {
        let top = 1u64 << MANT_BITS;
        let slack = THRESHOLD_SLACK;
        let ideal = ideal_thresholds();
        for (k, &t) in ideal.iter().enumerate().skip(1) {
            let at = top + t;
            assert!(
                serial_log2_bits(at + slack, SERIAL_STEPS) >= k as u32,
                "{k}"
            );
            assert!(
                serial_log2_bits(at - slack - 1, SERIAL_STEPS) < k as u32,
                "{k}"
            );
        }
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
        for &t in &ideal[1..] {
            for m in top + t - slack - 8..=top + t + slack + 8 {
                check(m);
            }
        }
        for j in 0..=1u64 << SEG_BITS {
            let at = top + (j << SEG_SHIFT);
            for m in at.saturating_sub(2).max(top)..(at + 3).min(2 * top) {
                check(m);
            }
        }
        let mut s = 0x5eed_0013;
        for _ in 0..10_000_000 {
            check(top | (next(&mut s) & (top - 1)));
        }
        assert!(direct > 9_900_000 && looped > 500_000, "{direct} {looped}");
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
                let ends = [i64::MIN, i64::MAX, 0, 1 << 31, -(1 << 31), (1 << 31) - 1];
                d[(i / 97 % 4) as usize] = ends[(i / 388 % 6) as usize];
                if i % 3 == 0 {
                    // Every derivative at or just beyond the ends of the `u64` squares.
                    let ends = [
                        -(1 << 31),
                        (1 << 31) - 1,
                        1 << 31,
                        -(1 << 31) - 1,
                        u32::MAX.into(),
                    ];
                    d = [0; 4].map(|_| ends[(next(&mut s) % 5) as usize]);
                }
            }
            if i % 89 == 0 {
                d = [0; 4];
            }
            match d.iter().map(|x| x.unsigned_abs()).max() {
                Some(0) => zero += 1,
                Some(x) if x <= 1 << 31 => narrow += 1,
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
