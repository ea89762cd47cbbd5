//! `ndf-fetch`: the LOD against the moment maps' size, then three trilinear lookups of the
//! moment maps A, B, C through the unchanged trilinear unit, a fourth of the normalization map
//! when `ndf_norm = map` (Olano and North 1997, "Normal Distribution Mapping", section 5;
//! `hw_model::lod`, `hw_model::trilinear`). The plan is [`super::ndf::NdfPlan`].

use super::stages::{Counters, Machine};
use super::trace::{trace_float_fetch, trilinear_traced, Lookup};
use super::{Frag, Plan, Px, StageKind};
use crate::fixedpoint::{from_unorm, to_raw};
use crate::reference::{lod_f64, trilinear_f64};
use hw_model::config::HwConfig;
use hw_model::lod::{lod, lod_cost};
use hw_model::ndf::ndf_lookups;
use hw_model::trilinear::trilinear_cost;
use hw_model::UnitCost;

/// Fixed twin: the LOD unit on the texture-coordinate derivatives scaled to the moment maps,
/// the trilinear unit per map (traced).
pub fn fixed(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let (Some(np), Some(_)) = (&px.plan.ndf, &px.plan.bump) else {
        return;
    };
    let m = px.m;
    let hw = m.hw;
    let Some(l0) = m.tex_float.get(np.maps).and_then(|l| l.first()) else {
        return;
    };
    let sat = &mut c.sat[StageKind::NdfFetch.index()];
    let (w, h) = (l0.width, l0.height);
    let mb = hw.ndf.moment_bits;
    if !px.fixed(StageKind::Texcoord) {
        for s in 0..3 {
            for ax in 0..2 {
                frag.uv_x[s][ax] = to_raw(frag.uv[s][ax], &m.uv_fmt, sat);
            }
        }
    }
    let uv = &frag.uv_x;
    let d = [
        (uv[1][0] - uv[0][0]) * i64::from(w),
        (uv[1][1] - uv[0][1]) * i64::from(h),
        (uv[2][0] - uv[0][0]) * i64::from(w),
        (uv[2][1] - uv[0][1]) * i64::from(h),
    ];
    frag.lod_x = lod(d, m.uv_fmt.frac_bits, &hw.lod, sat);
    let [u, v] = frag.uv_x[0];
    for i in 0..lookups(hw) as usize {
        let Some(levels) = m.tex_fixed.get(np.maps + i) else {
            continue;
        };
        let at = Lookup {
            stage: StageKind::NdfFetch,
            lookup: i as u32,
            tex: np.maps + i,
        };
        let r = trilinear_traced(
            levels,
            u,
            v,
            m.uv_fmt.frac_bits,
            frag.lod_x,
            hw.lod.lod_frac_bits,
            px.plan.wrap,
            &hw.trilinear,
            &mut frag.trace,
            at,
        );
        frag.ndf.texel_x[i] = r;
        frag.ndf.texel[i] = r.map(|x| from_unorm(u32::from(x), mb));
    }
}

/// Float twin: exact LOD and trilinear filter of the float moment maps.
pub fn float(px: &Px, frag: &mut Frag, _: &mut Counters) {
    let (Some(np), Some(_)) = (&px.plan.ndf, &px.plan.bump) else {
        return;
    };
    let m = px.m;
    let Some(l0) = m.tex_float.get(np.maps).and_then(|l| l.first()) else {
        return;
    };
    let n_maps = lookups(m.hw);
    let uv = &frag.uv;
    let (wf, hf) = (f64::from(l0.width), f64::from(l0.height));
    frag.lod = lod_f64([
        (uv[1][0] - uv[0][0]) * wf,
        (uv[1][1] - uv[0][1]) * hf,
        (uv[2][0] - uv[0][0]) * wf,
        (uv[2][1] - uv[0][1]) * hf,
    ]);
    let [u, v] = frag.uv[0];
    for i in 0..n_maps as usize {
        let Some(levels) = m.tex_float.get(np.maps + i) else {
            continue;
        };
        frag.ndf.texel[i] = trilinear_f64(levels, u, v, frag.lod, px.plan.wrap);
    }
    let at = Lookup {
        stage: StageKind::NdfFetch,
        lookup: 0,
        tex: np.maps,
    };
    let raw_uv = px.fixed(StageKind::Texcoord);
    trace_float_fetch(m, frag, raw_uv, px.plan.wrap, at, n_maps);
}

/// Lookups of one `ndf-fetch` (3, 4 with the normalization map).
#[must_use]
pub fn lookups(hw: &HwConfig) -> u32 {
    ndf_lookups(&hw.ndf)
}

/// One invocation: the LOD unit and a trilinear lookup per map.
#[must_use]
pub fn cost(m: &Machine, plan: &Plan) -> UnitCost {
    if plan.ndf.is_none() {
        return UnitCost::default();
    }
    let hw = m.hw;
    let g = hw.timing.gate_levels_per_cycle;
    lod_cost(&hw.lod, g).plus(trilinear_cost(&hw.trilinear, 2, g).times(lookups(hw)))
}
