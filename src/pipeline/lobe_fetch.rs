//! `lobe-fetch`: the fitted Fournier lobes of the pixel's texel (Fournier 1992, sec. 3.2;
//! plan and maps in [`super::lobe_fit`]): the LOD unit on the texture-coordinate derivatives,
//! the nearest MIP level and the nearest texel, one single-level lookup of the trilinear unit
//! per lobe at the texel's centre (weights 0, so the stored lobe passes exactly; traced). With
//! `multi_lobe.lobe_level_mix = "blend"`: the two levels around the LOD (as the trilinear unit
//! picks them: one level when magnified or at the top), the nearest texel of each, 2K lookups,
//! and the coarser level's weight (the LOD fraction) for `lobe-shade`'s blend.

use super::lobe_fit::fitted_of;
use super::stages::{texel_derivs, Counters, Machine};
use super::trace::{hardware_uv, trilinear_traced, Lookup};
use super::{Frag, Plan, Px, StageKind};
use crate::reference::lod_f64;
use hw_model::config::HwConfig;
use hw_model::lod::{lod, lod_cost};
use hw_model::multi_lobe::{LevelMix, MAX_LOBES};
use hw_model::trilinear::trilinear_cost;
use hw_model::wrap::WrapMode;
use hw_model::UnitCost;

/// Lobes one invocation fetches: the material's K, at most the unit's `lobe_max_lobes`.
fn fetched(k: u32, hw: &HwConfig) -> usize {
    k.min(hw.multi_lobe.lobe_max_lobes).min(MAX_LOBES) as usize
}

/// The nearest level of a raw LOD (`frac` fraction bits) in a chain of `n` levels.
fn nearest_level(l: i64, frac: u32, n: usize) -> usize {
    let half = if frac == 0 { 0 } else { 1i64 << (frac - 1) };
    ((l + half) >> frac).clamp(0, n.saturating_sub(1) as i64) as usize
}

/// The centre of the texel under raw coordinate `u` (`frac` fraction bits) of a level `size`
/// texels wide (exact when `size` divides `2^(frac - 1)`, else within one raw LSB).
fn texel_centre(u: i64, frac: u32, size: u32) -> i64 {
    let s = i64::from(size.max(1));
    let x = (u * s) >> frac;
    ((2 * x + 1) << frac).div_euclid(2 * s)
}

/// The level pair of a raw LOD (`frac` fraction bits) in a chain of `n` levels, blended: the
/// finer level, the coarser one and the coarser one's weight (`frac` bits); magnification and
/// the top level use one level (weight 0), as the trilinear unit does.
fn level_pair(l: i64, frac: u32, n: usize) -> (usize, usize, u32) {
    let top = n.saturating_sub(1);
    if l <= 0 {
        return (0, 0, 0);
    }
    let lo = (l >> frac) as usize;
    if lo >= top {
        return (top, top, 0);
    }
    (lo, lo + 1, (l & ((1i64 << frac) - 1)) as u32)
}

/// K traced single-level lookups of the lobe maps at the centre of level `level`'s texel
/// under `uv`, lookup numbers from `first`.
#[allow(clippy::too_many_arguments)]
fn fetch_level(
    px: &Px,
    fl: &super::lobe_fit::FittedLobes,
    uv: [i64; 2],
    level: usize,
    first: u32,
    out: &mut [[u16; 4]; MAX_LOBES as usize],
    trace: &mut super::trace::Trace,
) {
    let m = px.m;
    let fb = m.uv_fmt.frac_bits;
    let lf = m.hw.lod.lod_frac_bits.min(30);
    let Some(lv) = m.tex_fixed.get(fl.map).and_then(|c| c.get(level)) else {
        return;
    };
    let u = texel_centre(uv[0], fb, lv.width);
    let v = texel_centre(uv[1], fb, lv.height);
    for (j, texel) in out.iter_mut().enumerate().take(fetched(fl.lobes, m.hw)) {
        let Some(levels) = m.tex_fixed.get(fl.map + j) else {
            break;
        };
        let at = Lookup {
            stage: StageKind::LobeFetch,
            lookup: first + j as u32,
            tex: fl.map + j,
        };
        *texel = trilinear_traced(
            levels,
            u,
            v,
            fb,
            (level as i64) << lf,
            lf,
            px.plan.wrap,
            &m.hw.trilinear,
            trace,
            at,
        );
    }
}

/// The hardware lookups: writes the raw lobe texels and their number (and, blended, the
/// coarser level's texels and weight).
fn hardware_fetch(px: &Px, frag: &mut Frag, sat: &mut hw_model::SatCounter) {
    let Some((_, fl)) = fitted_of(px) else {
        return;
    };
    let m = px.m;
    let hw = m.hw;
    let Some(chain) = m.tex_fixed.get(fl.map) else {
        return;
    };
    let Some(l0) = chain.first() else {
        return;
    };
    let fb = m.uv_fmt.frac_bits;
    let uv = hardware_uv(m, frag, px.fixed(StageKind::Texcoord), sat);
    let d = texel_derivs(&uv, l0.width, l0.height);
    let l = lod(d, fb, &hw.lod, sat);
    let lf = hw.lod.lod_frac_bits.min(30);
    let k = fetched(fl.lobes, hw);
    let lobe = &mut frag.lobe;
    let trace = &mut frag.trace;
    match hw.multi_lobe.lobe_level_mix {
        LevelMix::Nearest => {
            let level = nearest_level(l, lf, chain.len());
            fetch_level(px, fl, uv[0], level, 0, &mut lobe.texel_x, trace);
            lobe.blend = false;
        }
        LevelMix::Blend => {
            let (fine, coarse, w) = level_pair(l, lf, chain.len());
            fetch_level(px, fl, uv[0], fine, 0, &mut lobe.texel_x, trace);
            fetch_level(px, fl, uv[0], coarse, k as u32, &mut lobe.coarse_x, trace);
            lobe.blend = true;
            lobe.weight_x = w;
        }
    }
    lobe.count = k as u8;
}

/// Fixed twin: the LOD unit, the nearest level and texel, K traced lookups.
pub fn fixed(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let sat = &mut c.sat[StageKind::LobeFetch.index()];
    hardware_fetch(px, frag, sat);
}

/// The texel index under float coordinate `u` of a level `size` texels wide, wrapped.
fn texel_index(u: f64, size: u32, wrap: WrapMode) -> usize {
    let s = i64::from(size.max(1));
    let x = (u * s as f64).floor();
    let x = if x.is_finite() { x as i64 } else { 0 };
    (match wrap {
        WrapMode::Repeat => x.rem_euclid(s),
        WrapMode::ClampToEdge => x.clamp(0, s - 1),
        WrapMode::Mirror => {
            let p = x.rem_euclid(2 * s);
            if p < s {
                p
            } else {
                2 * s - 1 - p
            }
        }
    }) as usize
}

/// Float twin: exact LOD, its nearest level (blend: the two levels around it and the LOD
/// fraction) and texel of the float lobe maps (the unquantized fit); under timing, the
/// hardware lookups' footprints.
pub fn float(px: &Px, frag: &mut Frag, _: &mut Counters) {
    let Some((_, fl)) = fitted_of(px) else {
        return;
    };
    let m = px.m;
    let Some(chain) = m.tex_float.get(fl.map) else {
        return;
    };
    let Some(l0) = chain.first() else {
        return;
    };
    let uv = &frag.uv;
    let (wf, hf) = (f64::from(l0.width), f64::from(l0.height));
    let l = lod_f64([
        (uv[1][0] - uv[0][0]) * wf,
        (uv[1][1] - uv[0][1]) * hf,
        (uv[2][0] - uv[0][0]) * wf,
        (uv[2][1] - uv[0][1]) * hf,
    ]);
    let top = chain.len().saturating_sub(1);
    let k = fetched(fl.lobes, m.hw);
    let wrap = px.plan.wrap;
    let read = |level: usize, out: &mut [[f32; 4]; MAX_LOBES as usize]| {
        let Some(lv) = chain.get(level) else {
            return;
        };
        let x = texel_index(uv[0][0], lv.width, wrap[0]);
        let y = texel_index(uv[0][1], lv.height, wrap[1]);
        for (j, o) in out.iter_mut().enumerate().take(k) {
            let t = m
                .tex_float
                .get(fl.map + j)
                .and_then(|c| c.get(level))
                .and_then(|lv| lv.texels.get(y * lv.width as usize + x));
            *o = t.copied().unwrap_or([0.0; 4]);
        }
    };
    let mut texel = [[0.0f32; 4]; MAX_LOBES as usize];
    let mut coarse = [[0.0f32; 4]; MAX_LOBES as usize];
    let (blend, weight) = match m.hw.multi_lobe.lobe_level_mix {
        LevelMix::Nearest => {
            let level = if l.is_nan() {
                0.0
            } else {
                l.round().clamp(0.0, top as f64)
            } as usize;
            read(level, &mut texel);
            (false, 0.0)
        }
        LevelMix::Blend => {
            let (fine, w) = if l.is_nan() || l <= 0.0 {
                (0, 0.0)
            } else if l.floor() >= top as f64 {
                (top, 0.0)
            } else {
                (l.floor() as usize, l - l.floor())
            };
            read(fine, &mut texel);
            read((fine + 1).min(top), &mut coarse);
            (true, w)
        }
    };
    let lobe = &mut frag.lobe;
    lobe.texel = texel;
    lobe.coarse = coarse;
    lobe.blend = blend;
    lobe.weight = weight;
    lobe.count = k as u8;
    if frag.trace.on {
        let mut scratch = hw_model::SatCounter::default();
        hardware_fetch(px, frag, &mut scratch);
    }
}

/// One invocation: the LOD unit and K single-level trilinear lookups.
#[must_use]
pub fn cost(m: &Machine, plan: &Plan) -> UnitCost {
    let (Some(_), Some(fl)) = (
        &plan.bump,
        plan.lobes.as_ref().and_then(|l| l.fitted.as_ref()),
    ) else {
        return UnitCost::default();
    };
    let g = m.hw.timing.gate_levels_per_cycle;
    let one = trilinear_cost(&m.hw.trilinear, 1, g);
    let mut c = lod_cost(&m.hw.lod, g);
    for _ in 0..fetched(fl.lobes, m.hw) * levels(m.hw) {
        c = c.plus(one);
    }
    c
}

/// Levels fetched per lobe: 1 (nearest) or 2 (blend).
#[must_use]
pub fn levels(hw: &HwConfig) -> usize {
    match hw.multi_lobe.lobe_level_mix {
        LevelMix::Nearest => 1,
        LevelMix::Blend => 2,
    }
}

/// Lookups per invocation, at most: the unit's `lobe_max_lobes`, twice when blending levels.
#[must_use]
pub fn lookups(hw: &HwConfig) -> u32 {
    hw.multi_lobe.lobe_max_lobes.min(MAX_LOBES) * levels(hw) as u32
}
