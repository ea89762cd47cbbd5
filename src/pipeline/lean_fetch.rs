//! `lean-fetch`: one trilinear lookup of the LEAN second-moment map (`M_uu, M_vv, M_uv` of the
//! bump slopes, Olano and Baker 2010) at the LOD of the bump fetch (`hw_model::lod`,
//! `hw_model::trilinear`). The plan and the maps are in [`super::lean`].

use super::lean::lean_of;
use super::stages::{Counters, Machine};
use super::trace::{trace_float_fetch, trilinear_traced, Lookup};
use super::{Frag, Plan, Px, StageKind};
use crate::fixedpoint::{from_unorm, to_raw};
use crate::reference::{lod_f64, trilinear_f64};
use hw_model::lod::lod;
use hw_model::trilinear::trilinear_cost;
use hw_model::UnitCost;

/// Fixed twin: the LOD unit on the texture-coordinate derivatives, the trilinear unit (traced).
pub fn fixed(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let Some((_, tp)) = lean_of(px) else {
        return;
    };
    let m = px.m;
    let hw = m.hw;
    let t = tp.map;
    let Some(l0) = m.tex_float.get(t).and_then(|l| l.first()) else {
        return;
    };
    let sat = &mut c.sat[StageKind::LeanFetch.index()];
    let (w, h) = (l0.width, l0.height);
    let fb = m.uv_fmt.frac_bits;
    let uv = if px.fixed(StageKind::Texcoord) {
        frag.uv_x
    } else {
        frag.uv.map(|s| s.map(|x| to_raw(x, &m.uv_fmt, sat)))
    };
    let d = [
        (uv[1][0] - uv[0][0]) * i64::from(w),
        (uv[1][1] - uv[0][1]) * i64::from(h),
        (uv[2][0] - uv[0][0]) * i64::from(w),
        (uv[2][1] - uv[0][1]) * i64::from(h),
    ];
    let l = lod(d, fb, &hw.lod, sat);
    let [u, v] = uv[0];
    let at = Lookup {
        stage: StageKind::LeanFetch,
        lookup: 0,
        tex: t,
    };
    let r = trilinear_traced(
        &m.tex_fixed[t],
        u,
        v,
        fb,
        l,
        hw.lod.lod_frac_bits,
        px.plan.wrap,
        &hw.trilinear,
        &mut frag.trace,
        at,
    );
    let tb = hw.trilinear.texel_bits;
    frag.lean.texel_x = [0, 1, 2].map(|i| u32::from(r[i]));
    frag.lean.texel = frag.lean.texel_x.map(|x| from_unorm(x, tb));
}

/// Float twin: exact LOD and trilinear filter of the float moment map.
pub fn float(px: &Px, frag: &mut Frag, _: &mut Counters) {
    let Some((_, tp)) = lean_of(px) else {
        return;
    };
    let m = px.m;
    let t = tp.map;
    let Some(l0) = m.tex_float.get(t).and_then(|l| l.first()) else {
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
    let r = trilinear_f64(&m.tex_float[t], uv[0][0], uv[0][1], l, px.plan.wrap);
    frag.lean.texel = [r[0], r[1], r[2]];
    let at = Lookup {
        stage: StageKind::LeanFetch,
        lookup: 0,
        tex: t,
    };
    trace_float_fetch(m, frag, px.fixed(StageKind::Texcoord), px.plan.wrap, at, 1);
}

/// One invocation: one trilinear lookup (the LOD unit's share is counted as in `rough-fetch`:
/// the bump fetch's LOD is reused).
#[must_use]
pub fn cost(m: &Machine, plan: &Plan) -> UnitCost {
    if plan.bump.is_none() || plan.lean.is_none() {
        return UnitCost::default();
    }
    trilinear_cost(&m.hw.trilinear, 2, m.hw.timing.gate_levels_per_cycle)
}
