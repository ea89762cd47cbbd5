//! Modulate unit (GL_MODULATE, colour x texel) and unsigned-normalized width conversion.
//!
//! A `n`-bit unorm raw value `x` means `x / (2^n - 1)`. Both functions compute the exact
//! rational result with ONE integer division and round it by the given mode; a hardware
//! divide-by-constant (multiply by a precomputed reciprocal of `2^n - 1` with enough bits, or
//! the `(x + (x >> n) + 1) >> n` identity at equal widths) produces the same integer, so the
//! ERROR BOUND is the rounding alone: <= 1/2 LSB of the output (< 1 LSB for Truncate).

use crate::config::ColorConfig;
use crate::cost::UnitCost;
use crate::datapath::{Component, Datapath, Stage};
use crate::fixed::{round_div_wide, DivRound, Rounding};

#[inline]
fn unorm_max(bits: u32) -> u64 {
    (1u64 << bits.min(32)) - 1
}

/// Unorm product `round(a b (2^o - 1) / ((2^a_bits - 1)(2^b_bits - 1)))`; widths 1..=16
/// (a zero width gives 0; wider widths are clamped to 16). Inputs above their maximum are
/// clamped to it.
#[inline]
#[must_use]
pub fn modulate(
    a: u32,
    a_bits: u32,
    b: u32,
    b_bits: u32,
    out_bits: u32,
    rounding: Rounding,
) -> u32 {
    if a_bits == 0 || b_bits == 0 || out_bits == 0 {
        return 0;
    }
    let (ma, mb, mo) = (
        unorm_max(a_bits.min(16)),
        unorm_max(b_bits.min(16)),
        unorm_max(out_bits.min(16)),
    );
    let num = u64::from(a).min(ma) * u64::from(b).min(mb) * mo;
    round_div_wide(i128::from(num), i128::from(ma * mb), rounding) as u32
}

/// [`modulate`] of the four channels of each lane `(a, b, out)`: `out[ch] = modulate(a[ch],
/// a_bits, b[ch], b_bits, out_bits, rounding)`, with the widths' maxima, the divisor and the
/// rounding mode resolved once for the lanes ([`DivRound`]). Bit-identical to [`modulate`]
/// (`modulate_span_matches_modulate`: every input pair at widths up to 6 bits, 4M seeded lanes
/// at 1..=16 bits and beyond).
pub fn modulate_span<'a>(
    lanes: impl Iterator<Item = ([u32; 4], [u32; 4], &'a mut [u32; 4])>,
    a_bits: u32,
    b_bits: u32,
    out_bits: u32,
    rounding: Rounding,
) {
    if a_bits == 0 || b_bits == 0 || out_bits == 0 {
        for (_, _, out) in lanes {
            *out = [0; 4];
        }
        return;
    }
    let (ma, mb, mo) = (
        unorm_max(a_bits.min(16)),
        unorm_max(b_bits.min(16)),
        unorm_max(out_bits.min(16)),
    );
    // `ma mb` is in 1..2^32 and every numerator below 2^48: in `DivRound`'s range.
    let Some(div) = DivRound::new(ma * mb, rounding) else {
        return;
    };
    for (a, b, out) in lanes {
        let channel =
            |ch: usize| div.apply(u64::from(a[ch]).min(ma) * u64::from(b[ch]).min(mb) * mo) as u32;
        *out = [channel(0), channel(1), channel(2), channel(3)];
    }
}

/// Unorm width conversion `round(x (2^to - 1) / (2^from - 1))`; widths 1..=32 (a zero width
/// gives 0). `x` above its maximum is clamped to it.
#[inline]
#[must_use]
pub fn unorm_convert(x: u32, from_bits: u32, to_bits: u32, rounding: Rounding) -> u32 {
    if from_bits == 0 || to_bits == 0 {
        return 0;
    }
    let (mf, mt) = (unorm_max(from_bits), unorm_max(to_bits));
    if mf == mt {
        return u64::from(x).min(mf) as u32;
    }
    round_div_wide(
        i128::from(u64::from(x).min(mf) * mt),
        i128::from(mf),
        rounding,
    ) as u32
}

/// Cost of one modulate (4 channels in parallel): per channel a multiply and a
/// divide-by-constant (multiply + shift); cycles from [`datapath`].
#[must_use]
pub fn modulate_cost(cfg: &ColorConfig, gate_levels_per_cycle: u32) -> UnitCost {
    UnitCost {
        ops: 4 * 3,
        cycles: datapath(cfg).latency(gate_levels_per_cycle),
        texels: 0,
    }
}

/// The modulate unit (C = `color_bits`, `modulate_cycles`): per channel, side by side, the
/// `C x C` product, the divide by `2^C - 1` as a multiply by its reciprocal and the rounding
/// add, the result register.
#[must_use]
pub fn datapath(cfg: &ColorConfig) -> Datapath {
    let c = cfg.color_bits;
    Datapath::new().stage(
        Stage::new("modulate")
            .then_n(4, Component::Multiplier { a: c, b: c })
            .then_n(4, Component::Multiplier { a: 2 * c, b: c + 1 })
            .then_n(4, Component::Adder { width: c + 1 })
            .then(Component::Register { bits: 4 * c })
            .cycles(cfg.modulate_cycles),
    )
}
