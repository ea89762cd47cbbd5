//! `bump-fetch`: the LOD and one trilinear lookup of the offset map `(f_u, f_v)` (Schilling
//! 1997, "Bump mapping with Precalculated Derivatives"; `hw_model::lod`, `hw_model::trilinear`).

use super::bump::bump_of;
use super::stages::{texel_derivs, texel_derivs_f64, Counters, Machine};
use super::trace::{trace_float_fetch, trilinear_traced, Lookup};
use super::{Frag, Plan, Px, StageKind};
use crate::fixedpoint::{from_unorm, to_raw};
use crate::reference::{lod_f64, trilinear_f64};
use hw_model::lod::{lod, lod_cost};
use hw_model::trilinear::trilinear_cost;
use hw_model::UnitCost;

/// Fixed twin: the LOD unit on the texture-coordinate derivatives, the trilinear unit (traced).
pub fn fixed(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let Some((bp, _)) = bump_of(px) else { return };
    let m = px.m;
    let hw = m.hw;
    let t = bp.map;
    let Some(l0) = m.tex_float.get(t).and_then(|l| l.first()) else {
        return;
    };
    let sat = &mut c.sat[StageKind::BumpFetch.index()];
    let (w, h) = (l0.width, l0.height);
    let fb = m.uv_fmt.frac_bits;
    if !px.fixed(StageKind::Texcoord) {
        for s in 0..3 {
            for ax in 0..2 {
                frag.uv_x[s][ax] = to_raw(frag.uv[s][ax], &m.uv_fmt, sat);
            }
        }
    }
    let d = texel_derivs(&frag.uv_x, w, h);
    let l = lod(d, fb, &hw.lod, sat);
    let [u, v] = frag.uv_x[0];
    let at = Lookup {
        stage: StageKind::BumpFetch,
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
    let bf = &mut frag.bump;
    bf.texel_x = [u32::from(r[0]), u32::from(r[1])];
    bf.texel = bf.texel_x.map(|x| from_unorm(x, tb));
}

/// Float twin: exact LOD and trilinear filter of the float map.
pub fn float(px: &Px, frag: &mut Frag, _: &mut Counters) {
    let Some((bp, _)) = bump_of(px) else { return };
    let m = px.m;
    let t = bp.map;
    let Some(l0) = m.tex_float.get(t).and_then(|l| l.first()) else {
        return;
    };
    let l = lod_f64(texel_derivs_f64(&frag.uv, l0.width, l0.height));
    let [u, v] = frag.uv[0];
    let r = trilinear_f64(&m.tex_float[t], u, v, l, px.plan.wrap);
    frag.bump.texel = [r[0], r[1]];
    let at = Lookup {
        stage: StageKind::BumpFetch,
        lookup: 0,
        tex: t,
    };
    trace_float_fetch(m, frag, px.fixed(StageKind::Texcoord), px.plan.wrap, at, 1);
}

/// One invocation: the LOD unit and a two-channel trilinear lookup.
#[must_use]
pub fn cost(m: &Machine, plan: &Plan) -> UnitCost {
    if plan.bump.is_none() {
        return UnitCost::default();
    }
    let g = m.hw.timing.gate_levels_per_cycle;
    lod_cost(&m.hw.lod, g).plus(trilinear_cost(&m.hw.trilinear, 2, g))
}
