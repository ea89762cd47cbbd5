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
//! floor-rounded.
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
#[inline]
#[must_use]
pub fn lod(d: [i64; 4], frac: u32, cfg: &LodConfig, sat: &mut SatCounter) -> i64 {
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
