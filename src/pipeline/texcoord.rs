//! `texcoord`: interpolation of the texture coordinates at the pixel and its helper samples
//! (`hw_model::interpolator::interpolate`, signed `texcoord_int_bits.texcoord_frac_bits`).

use super::stages::{column_f, each_fragment, Counters, Machine};
use super::{Frag, Plan, Px, StageKind};
use crate::fixedpoint::{from_raw, to_raw};
use crate::reference::interpolate_f64;
use hw_model::config::CoordArith;
use hw_model::fixed::SatCounter;
use hw_model::interpolator::{
    interpolate_cost, interpolate_lanes, interpolate_pairs, interpolate_span,
};
use hw_model::UnitCost;

/// Fixed twin: two interpolations per sample.
pub fn fixed(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let m = px.m;
    if m.hw.interp.coord_arith == CoordArith::Float32 {
        return super::coord_f32::texcoord(px, frag, c);
    }
    let bb = m.hw.interp.bary_bits;
    let fb = m.uv_fmt.frac_bits;
    let raw_bary = px.fixed(StageKind::Bary);
    let sat = &mut c.sat[StageKind::Texcoord.index()];
    let n = px.samples();
    let uv = &mut frag.uv_x[..n];
    if raw_bary {
        interpolate_pairs(&frag.bary_x[..n], bb, px.a.uv_x, &m.uv_fmt, sat, uv);
    } else {
        let mut raw = [[0; 3]; 3];
        for (raw, carrier) in raw.iter_mut().zip(&frag.bary).take(n) {
            *raw = carrier.map(|x| to_raw(x, &m.bary_fmt, sat));
        }
        interpolate_pairs(&raw[..n], bb, px.a.uv_x, &m.uv_fmt, sat, uv);
    }
    if px.carriers {
        for s in 0..n {
            frag.uv[s] = frag.uv_x[s].map(|r| from_raw(r, fb));
        }
    }
}

/// Fixed twin over a span: after a Fixed `bary`, the triangle's terms resolved once for the
/// span (`interpolate_span`), bit-identical to [`fixed`] on each fragment; otherwise
/// [`fixed`] per fragment.
pub fn fixed_span(px: &Px, frags: &mut [Frag], c: &mut Counters) {
    let m = px.m;
    if m.hw.interp.coord_arith == CoordArith::Float32 || !px.fixed(StageKind::Bary) {
        return each_fragment(fixed, px, frags, c);
    }
    if let Some(lanes) = px.lanes {
        // The span's lanes ([`super::lanes`]): all three samples (the program has derivatives).
        let l = &mut *lanes.borrow_mut();
        let sat = &mut c.sat[StageKind::Texcoord.index()];
        let (bb, span) = (m.hw.interp.bary_bits, px.base..px.base + frags.len());
        return interpolate_lanes(&l.bary, span, bb, px.a.uv_x, &m.uv_fmt, sat, &mut l.uv);
    }
    let n = px.samples();
    let lanes = frags.iter_mut().map(|f| {
        let Frag { bary_x, uv_x, .. } = f;
        (&bary_x[..n], &mut uv_x[..n])
    });
    let sat = &mut c.sat[StageKind::Texcoord.index()];
    let bb = m.hw.interp.bary_bits;
    interpolate_span(lanes, bb, px.a.uv_x, &m.uv_fmt, sat);
    if px.carriers {
        let fb = m.uv_fmt.frac_bits;
        for frag in frags.iter_mut() {
            for s in 0..n {
                frag.uv[s] = frag.uv_x[s].map(|r| from_raw(r, fb));
            }
        }
    }
}

/// Whether the fixed twins may run with the chain's signals in lanes
/// ([`super::table::LanesFn`]): not on the float32 coordinate path ([`super::coord_f32`]),
/// which keeps its coordinates in the fragments.
#[must_use]
pub fn lanes(m: &Machine, _: &Plan) -> bool {
    m.hw.interp.coord_arith != CoordArith::Float32
}

/// Float twin.
pub fn float(px: &Px, frag: &mut Frag, _: &mut Counters) {
    for s in 0..px.samples() {
        for ax in 0..2 {
            frag.uv[s][ax] = interpolate_f64(frag.bary[s], column_f(&px.af.uv, ax));
        }
    }
}

/// One invocation: two interpolations per sample.
#[must_use]
pub fn cost(m: &Machine, plan: &Plan) -> UnitCost {
    let samples = if plan.derivatives { 3 } else { 1 };
    interpolate_cost(&m.hw.interp, m.hw.timing.gate_levels_per_cycle).times(2 * samples)
}

/// Rounds the float texture coordinates of the first `samples` samples into the machine's
/// format (a Fixed consumer after a Float `texcoord`).
pub fn quantize_uv(frag: &mut Frag, m: &Machine, samples: usize, sat: &mut SatCounter) {
    for s in 0..samples {
        for ax in 0..2 {
            frag.uv_x[s][ax] = to_raw(frag.uv[s][ax], &m.uv_fmt, sat);
        }
    }
}
