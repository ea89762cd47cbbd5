//! Bilinear and trilinear MIP filter unit (Williams 1983, "Pyramidal parametrics"; the
//! OpenGL 4.6 section 8.14 LINEAR_MIPMAP_LINEAR rule).
//!
//! Conventions (written down once):
//! - Texel centres: texel `i` of a level of `size` texels covers normalized coordinates
//!   `[i/size, (i+1)/size)`; its centre is at `(i + 1/2)/size`. A coordinate `c` maps to
//!   texel space `s = c * size - 1/2`; the footprint is texels `floor(s)` and `floor(s) + 1`.
//! - Weights: a weight is the weight of the SECOND operand (`i1`, the next level), with
//!   `weight_bits` fraction bits: `lerp(a, b, w) = a + (b - a) w / 2^weight_bits`.
//! - Levels are row-major, top row first: texel (x, y) is `texels[y * width + x]`; `u` runs
//!   along x, `v` along y. Channel values are `texel_bits`-wide unsigned normalized raw values.
//! - Bilinear order: lerp along x on row `y0` and on row `y1`, then along y between the two.
//!   Each lerp rounds ONCE (by `filter_rounding`) back to texel precision.
//! - Trilinear: `lod <= 0` -> level 0 only; `lod >= (levels - 1)` -> last level only; else
//!   levels `floor(lod)` and `floor(lod) + 1` blended with the `lod_frac_bits` LOD fraction as
//!   the weight of the finer-to-coarser lerp (a zero fraction uses one level: same result).
//!
//! ERROR BOUND vs the exact-arithmetic filter with the same coordinates and LOD
//! ([`trilinear_error_bound_q8`]): per lerp the weight error `dw` (< 2^-wb for Truncate,
//! <= 2^-(wb+1) for the nearest modes; 0 when the coordinate has at most `wb - 1` fraction
//! bits) costs `dw * (2^texel_bits - 1)` LSBs and the rounding `h` (1/2, or < 1 for Truncate).
//! Lerps are convex, so errors do not grow through later lerps: bilinear `<= (dw_x + dw_y)
//! (2^T - 1) + 2h`, trilinear `<=` that `+ h`. If the reference uses an unquantized LOD, add
//! `2^-lod_frac_bits * (2^T - 1)` (the LOD is floor-rounded).

use crate::config::TrilinearConfig;
use crate::cost::UnitCost;
use crate::datapath::{Component, Datapath, Stage};
use crate::fixed::{round_shift_right, ConstRounding, Rounding};
use crate::wrap::{wrap_in, WrapMode};

/// One MIP level (borrowed texels).
#[derive(Clone, Copy, Debug)]
pub struct Level<'a> {
    pub width: u32,
    pub height: u32,
    /// Row-major, top row first, at least `width * height` texels.
    pub texels: &'a [[u16; 4]],
}

/// What one bilinear footprint did (for `texsim probe`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BilinearTrace {
    /// Level index (set by `trilinear`; 0 when `bilinear` is called directly).
    pub level: u32,
    /// Texel coordinates (x, y) in the order (x0,y0), (x1,y0), (x0,y1), (x1,y1).
    pub coords: [(u32, u32); 4],
    /// The four texels, same order.
    pub texels: [[u16; 4]; 4],
    /// Horizontal and vertical weights (of x1 and y1), `weight_bits` fraction bits.
    pub weights: [u32; 2],
    /// The filtered value.
    pub result: [u32; 4],
}

/// What one trilinear sample did (for `texsim probe`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TrilinearTrace {
    /// 1 or 2.
    pub levels_used: u32,
    /// Footprints of the used levels (finer first); only `levels_used` entries are valid.
    pub level: [BilinearTrace; 2],
    /// Weight of the coarser level, `lod_frac_bits` fraction bits (0 with one level).
    pub level_weight: u32,
    /// The filtered value.
    pub result: [u16; 4],
}

/// `a + (b - a) w / 2^weight_bits` with exactly one rounding (`w` in `[0, 2^weight_bits]`,
/// `weight_bits <= 30`). The result lies between `a` and `b`; exact for `w` = 0 or 2^wb.
#[inline(always)]
#[must_use]
pub fn lerp(a: u32, b: u32, w: u32, weight_bits: u32, rounding: Rounding) -> u32 {
    let num = (i64::from(a) << weight_bits) + (i64::from(b) - i64::from(a)) * i64::from(w);
    round_shift_right(num, weight_bits, rounding) as u32
}

#[inline(always)]
fn fetch(level: &Level, x: u32, y: u32) -> [u16; 4] {
    let idx = y as usize * level.width as usize + x as usize;
    level.texels.get(idx).copied().unwrap_or([0; 4])
}

/// Bilinear filter of one level at normalized (u, v) with `frac` fraction bits. A level with
/// too few texels reads zeros for the missing ones.
#[inline]
#[must_use]
pub fn bilinear(
    level: &Level,
    u: i64,
    v: i64,
    frac: u32,
    wrap_mode: [WrapMode; 2],
    cfg: &TrilinearConfig,
    trace: Option<&mut BilinearTrace>,
) -> [u32; 4] {
    crate::with_rounding!(cfg.filter_rounding, F => {
        crate::with_rounding!(cfg.weight_rounding, W => {
            bilinear_in::<F, W>(level, u, v, frac, wrap_mode, cfg, trace)
        })
    })
}

/// [`bilinear`] compiled for the filter rounding `F` (`filter_rounding`) and the weight
/// rounding `W` (`weight_rounding`).
#[inline(always)]
fn bilinear_in<F: ConstRounding, W: ConstRounding>(
    level: &Level,
    u: i64,
    v: i64,
    frac: u32,
    wrap_mode: [WrapMode; 2],
    cfg: &TrilinearConfig,
    trace: Option<&mut BilinearTrace>,
) -> [u32; 4] {
    let wx = wrap_in::<W>(u, frac, level.width, wrap_mode[0], cfg);
    let wy = wrap_in::<W>(v, frac, level.height, wrap_mode[1], cfg);
    let t00 = fetch(level, wx.i0, wy.i0);
    let t10 = fetch(level, wx.i1, wy.i0);
    let t01 = fetch(level, wx.i0, wy.i1);
    let t11 = fetch(level, wx.i1, wy.i1);
    let wb = cfg.weight_bits.min(16);
    let r = F::MODE;
    let mut out = [0u32; 4];
    for c in 0..4 {
        let top = lerp(u32::from(t00[c]), u32::from(t10[c]), wx.weight, wb, r);
        let bot = lerp(u32::from(t01[c]), u32::from(t11[c]), wx.weight, wb, r);
        out[c] = lerp(top, bot, wy.weight, wb, r);
    }
    if let Some(t) = trace {
        t.coords = [
            (wx.i0, wy.i0),
            (wx.i1, wy.i0),
            (wx.i0, wy.i1),
            (wx.i1, wy.i1),
        ];
        t.texels = [t00, t10, t01, t11];
        t.weights = [wx.weight, wy.weight];
        t.result = out;
    }
    out
}

/// Trilinear filter: the LOD rule and conventions of the module doc. `lod` has
/// `lod_frac_bits` fraction bits. No levels gives zeros.
#[allow(clippy::too_many_arguments)]
#[inline]
#[must_use]
pub fn trilinear(
    levels: &[Level],
    u: i64,
    v: i64,
    frac: u32,
    lod: i64,
    lod_frac_bits: u32,
    wrap_mode: [WrapMode; 2],
    cfg: &TrilinearConfig,
    trace: Option<&mut TrilinearTrace>,
) -> [u16; 4] {
    crate::with_rounding!(cfg.filter_rounding, F => {
        crate::with_rounding!(cfg.weight_rounding, W => {
            trilinear_in::<F, W>(levels, u, v, frac, lod, lod_frac_bits, wrap_mode, cfg, trace)
        })
    })
}

/// [`trilinear`] compiled for the filter rounding `F` and the weight rounding `W`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn trilinear_in<F: ConstRounding, W: ConstRounding>(
    levels: &[Level],
    u: i64,
    v: i64,
    frac: u32,
    lod: i64,
    lod_frac_bits: u32,
    wrap_mode: [WrapMode; 2],
    cfg: &TrilinearConfig,
    mut trace: Option<&mut TrilinearTrace>,
) -> [u16; 4] {
    let n = levels.len();
    if n == 0 {
        return [0; 4];
    }
    let lf = lod_frac_bits.min(30);
    let last = (n - 1) as i64;
    let (l0, lw) = if lod <= 0 {
        (0usize, 0u32)
    } else if (lod >> lf) >= last {
        (n - 1, 0)
    } else {
        ((lod >> lf) as usize, (lod & ((1i64 << lf) - 1)) as u32)
    };
    let mut bt0 = BilinearTrace {
        level: l0 as u32,
        ..BilinearTrace::default()
    };
    let c0 = bilinear_in::<F, W>(
        &levels[l0],
        u,
        v,
        frac,
        wrap_mode,
        cfg,
        trace.as_ref().map(|_| &mut bt0),
    );
    let mut out = [0u16; 4];
    if lw == 0 {
        for c in 0..4 {
            out[c] = c0[c] as u16;
        }
        if let Some(t) = trace.as_deref_mut() {
            *t = TrilinearTrace {
                levels_used: 1,
                level: [bt0, BilinearTrace::default()],
                level_weight: 0,
                result: out,
            };
        }
        return out;
    }
    let mut bt1 = BilinearTrace {
        level: l0 as u32 + 1,
        ..BilinearTrace::default()
    };
    let c1 = bilinear_in::<F, W>(
        &levels[l0 + 1],
        u,
        v,
        frac,
        wrap_mode,
        cfg,
        trace.as_ref().map(|_| &mut bt1),
    );
    for c in 0..4 {
        out[c] = lerp(c0[c], c1[c], lw, lf, F::MODE) as u16;
    }
    if let Some(t) = trace {
        *t = TrilinearTrace {
            levels_used: 2,
            level: [bt0, bt1],
            level_weight: lw,
            result: out,
        };
    }
    out
}

/// Cost of one trilinear sample using `levels_used` (1 or 2) levels: per level the two wraps,
/// 4 fetches and 3 lerps per channel; plus the level blend (4 lerps) when two levels are used.
/// Cycles from [`datapath`] at `gate_levels_per_cycle`.
#[must_use]
pub fn trilinear_cost(
    cfg: &TrilinearConfig,
    levels_used: u32,
    gate_levels_per_cycle: u32,
) -> UnitCost {
    let per_level = UnitCost {
        ops: 2 * 5 + 12,
        cycles: 0,
        texels: 4,
    };
    let blend = if levels_used > 1 {
        UnitCost {
            ops: 4,
            cycles: 0,
            texels: 0,
        }
    } else {
        UnitCost::default()
    };
    let mut c = per_level.times(levels_used).plus(blend);
    c.cycles = datapath(cfg, levels_used).latency(gate_levels_per_cycle);
    c
}

/// Appends `n` lerps side by side (T = `texel_bits`, W = `weight_bits`): the difference
/// `b - a`, its product with the `W + 1`-bit weight, the add of `a 2^W` with the rounding.
fn lerp_steps(s: Stage, cfg: &TrilinearConfig, n: u32) -> Stage {
    let (t, w) = (cfg.texel_bits, cfg.weight_bits);
    s.then_n(n, Component::Adder { width: t + 1 })
        .then_n(n, Component::Multiplier { a: t + 1, b: w + 1 })
        .then_n(n, Component::Adder { width: t + w + 2 })
}

/// One bilinear footprint (`bilinear_cycles`): the address unit of both axes, the 4-channel
/// lerps along x on both rows side by side, the lerps along y, the result register.
#[must_use]
pub fn bilinear_datapath(cfg: &TrilinearConfig) -> Datapath {
    let s = crate::wrap::address_steps(Stage::new("bilinear footprint"), cfg, 2);
    let s = lerp_steps(lerp_steps(s, cfg, 8), cfg, 4)
        .then(Component::Register {
            bits: 4 * cfg.texel_bits,
        })
        .cycles(cfg.bilinear_cycles);
    Datapath::new().stage(s)
}

/// The trilinear unit with `levels_used` levels: a bilinear footprint per level, then
/// (two levels) the 4-channel level blend (`level_lerp_cycles`).
#[must_use]
pub fn datapath(cfg: &TrilinearConfig, levels_used: u32) -> Datapath {
    let blend = lerp_steps(Stage::new("level blend"), cfg, 4)
        .then(Component::Register {
            bits: 4 * cfg.texel_bits,
        })
        .cycles(cfg.level_lerp_cycles)
        .times(u32::from(levels_used > 1));
    bilinear_datapath(cfg).times(levels_used).stage(blend)
}

/// The module's error bound vs exact arithmetic (same coordinates, same quantized LOD), in
/// 1/256 LSBs of the `texel_bits` output, for coordinates with `coord_frac` fraction bits.
#[must_use]
pub fn trilinear_error_bound_q8(cfg: &TrilinearConfig, coord_frac: u32, two_levels: bool) -> u64 {
    let wb = cfg.weight_bits.min(16);
    let range = (1u64 << cfg.texel_bits.min(16)) - 1;
    // dw in units of 2^-(wb+1): 2 for Truncate (< 2^-wb), 1 for nearest, 0 if exact.
    let dw_units: u64 = if coord_frac < wb {
        0
    } else {
        match cfg.weight_rounding {
            Rounding::Truncate => 2,
            Rounding::HalfUp | Rounding::HalfEven => 1,
        }
    };
    // h in 1/256 LSB: 128 for nearest, 256 for Truncate.
    let h: u64 = match cfg.filter_rounding {
        Rounding::Truncate => 256,
        Rounding::HalfUp | Rounding::HalfEven => 128,
    };
    let weight_term = (2 * dw_units * range * 256) >> (wb + 1);
    let weight_term = weight_term + 1; // round the shifted term up
    weight_term + h * if two_levels { 3 } else { 2 }
}

/// Cycles of one bilinear footprint and of the level blend at `gate_levels_per_cycle` (the
/// timing model's filter latency: footprints x the first + the second when two levels).
#[must_use]
pub fn filter_latencies(cfg: &TrilinearConfig, gate_levels_per_cycle: u32) -> (u32, u32) {
    let bilinear = bilinear_datapath(cfg).latency(gate_levels_per_cycle);
    let both = datapath(cfg, 2).latency(gate_levels_per_cycle);
    (bilinear, both - 2 * bilinear)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::HwConfig;
    use crate::wrap::wrap;

    const MODES: [Rounding; 3] = [Rounding::Truncate, Rounding::HalfUp, Rounding::HalfEven];

    use crate::test_rng::splitmix64 as next;

    /// The bilinear footprint as it was composed before the unit was compiled per rounding
    /// mode (each reduction reading its mode from the config): the oracle.
    fn bilinear_before(
        level: &Level,
        u: i64,
        v: i64,
        frac: u32,
        wm: [WrapMode; 2],
        cfg: &TrilinearConfig,
    ) -> [u32; 4] {
        let wx = wrap(u, frac, level.width, wm[0], cfg);
        let wy = wrap(v, frac, level.height, wm[1], cfg);
        let t = |x: u32, y: u32| fetch(level, x, y);
        let (t00, t10, t01, t11) = (
            t(wx.i0, wy.i0),
            t(wx.i1, wy.i0),
            t(wx.i0, wy.i1),
            t(wx.i1, wy.i1),
        );
        let (wb, r) = (cfg.weight_bits.min(16), cfg.filter_rounding);
        std::array::from_fn(|c| {
            let top = lerp(u32::from(t00[c]), u32::from(t10[c]), wx.weight, wb, r);
            let bot = lerp(u32::from(t01[c]), u32::from(t11[c]), wx.weight, wb, r);
            lerp(top, bot, wy.weight, wb, r)
        })
    }

    /// 1.8M seeded samples over the nine (filter, weight) rounding pairs, three wrap modes,
    /// weight widths 0 to 16 and coordinates in and far outside [0, 1]: `bilinear` and
    /// `trilinear` give the bits of the composition from `wrap` and `lerp`.
    #[test]
    fn compiled_modes_match_the_composed_filter() {
        let mut s = 0x5eed_0006;
        let (w, h) = (13u32, 8u32);
        let texels: Vec<[u16; 4]> = (0..w * h * 2)
            .map(|_| [0; 4].map(|_| next(&mut s) as u16))
            .collect();
        let l0 = Level {
            width: w,
            height: h,
            texels: &texels[..(w * h) as usize],
        };
        let l1 = Level {
            width: 7,
            height: 4,
            texels: &texels[(w * h) as usize..],
        };
        let modes = [WrapMode::Repeat, WrapMode::ClampToEdge, WrapMode::Mirror];
        for f in MODES {
            for wr in MODES {
                let mut cfg = HwConfig::texram16().trilinear;
                cfg.filter_rounding = f;
                cfg.weight_rounding = wr;
                for i in 0..200_000u32 {
                    cfg.weight_bits = [16, 8, 4, 0, 12][(i % 5) as usize];
                    let frac = [24, 16, 8, 30][(i / 5 % 4) as usize];
                    let sh = [34, 30, 10][(i % 3) as usize];
                    let u = (next(&mut s) as i64) >> sh;
                    let v = (next(&mut s) as i64) >> sh;
                    let wm = [modes[(i % 3) as usize], modes[(i / 3 % 3) as usize]];
                    let want = bilinear_before(&l0, u, v, frac, wm, &cfg);
                    assert_eq!(bilinear(&l0, u, v, frac, wm, &cfg, None), want);
                    let lod = (next(&mut s) % (3 << 16)) as i64 - (1 << 16);
                    let lw = (lod.clamp(0, 1 << 16) & 0xffff) as u32;
                    let want = if lod <= 0 {
                        want.map(|c| c as u16)
                    } else if lod >> 16 >= 1 {
                        bilinear_before(&l1, u, v, frac, wm, &cfg).map(|c| c as u16)
                    } else {
                        let c1 = bilinear_before(&l1, u, v, frac, wm, &cfg);
                        std::array::from_fn(|c| lerp(want[c], c1[c], lw, 16, f) as u16)
                    };
                    let got = trilinear(&[l0, l1], u, v, frac, lod, 16, wm, &cfg, None);
                    assert_eq!(got, want, "{u} {v} {lod} {cfg:?}");
                }
            }
        }
    }
}
