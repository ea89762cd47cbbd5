//! `lod`: the level of detail of the material texture from the texture-coordinate derivatives
//! (the OpenGL isotropic rule; `hw_model::lod`).

use super::lanes::{Lanes, LANES};
use super::stages::{each_fragment, texel_derivs, texel_derivs_f64, Counters, Machine};
use super::texcoord::quantize_uv;
use super::{Frag, Plan, Px, StageKind};
use crate::fixedpoint::from_raw;
use crate::reference::lod_mode_f64;
use hw_model::config::CoordArith;
use hw_model::fixed::SatCounter;
use hw_model::lod::{lod_cost, lod_lanes, lod_with, LodSetup};
use hw_model::UnitCost;

/// Fixed twin: squared lengths, bit-serial log2.
pub fn fixed(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let m = px.m;
    if m.hw.interp.coord_arith == CoordArith::Float32 && px.fixed(StageKind::Texcoord) {
        return super::coord_f32::lod(px, frag, c);
    }
    let Some(l0) = px.plan.texture.and_then(|t| m.tex_float[t].first()) else {
        return;
    };
    let sat = &mut c.sat[StageKind::Lod.index()];
    if !px.fixed(StageKind::Texcoord) {
        quantize_uv(frag, m, px.samples(), sat);
    }
    let d = texel_derivs(&frag.uv_x, l0.width, l0.height);
    let fb = m.uv_fmt.frac_bits;
    frag.lod_x = hw_model::lod::lod(d, fb, &m.hw.lod, sat);
    if px.carriers {
        frag.lod = from_raw(frag.lod_x, m.hw.lod.lod_frac_bits);
    }
}

/// Fixed twin over a span: the texture's level-0 size and the LOD unit's constants
/// ([`LodSetup`]) resolved once, then the squared lengths and log2 per fragment. The float32 coordinate
/// path and a Float `texcoord` producer take [`fixed`] on each fragment.
pub fn fixed_span(px: &Px, frags: &mut [Frag], c: &mut Counters) {
    let m = px.m;
    if m.hw.interp.coord_arith == CoordArith::Float32 || !px.fixed(StageKind::Texcoord) {
        return each_fragment(fixed, px, frags, c);
    }
    let Some(l0) = px.plan.texture.and_then(|t| m.tex_float[t].first()) else {
        return;
    };
    let sat = &mut c.sat[StageKind::Lod.index()];
    let (w, h) = (l0.width, l0.height);
    let cfg = &m.hw.lod;
    let k = LodSetup::new(m.uv_fmt.frac_bits, cfg);
    if let Some(lanes) = px.lanes {
        from_lanes(&lanes.borrow(), px.base, (&k, w, h), frags, sat);
    } else {
        for frag in frags.iter_mut() {
            let d = texel_derivs(&frag.uv_x, w, h);
            frag.lod_x = lod_with(&k, d, sat);
        }
    }
    if px.carriers {
        let lfb = cfg.lod_frac_bits;
        for frag in frags.iter_mut() {
            frag.lod = from_raw(frag.lod_x, lfb);
        }
    }
}

/// [`fixed_span`]'s LOD of each fragment from the texture coordinates in the run's lanes
/// ([`super::lanes`], the span's first fragment at lane `base`), for a `w` x `h` level 0: one
/// call of the LOD unit's lanes datapath ([`lod_lanes`]).
#[inline(never)]
fn from_lanes(
    lanes: &Lanes,
    base: usize,
    (k, w, h): (&LodSetup, u32, u32),
    frags: &mut [Frag],
    sat: &mut SatCounter,
) {
    let mut lod = [0i64; LANES];
    lod_lanes(
        k,
        &lanes.uv,
        base..base + frags.len(),
        (w, h),
        sat,
        &mut lod,
    );
    for (frag, &l) in frags.iter_mut().zip(&lod[base..]) {
        frag.lod_x = l;
    }
}

/// Whether the fixed twins may take several triangles' spans at once
/// ([`super::table::AcrossFn`]): not on the float32 coordinate path, whose quad reads the
/// pixel's position ([`super::coord_f32::lod`]).
#[must_use]
pub fn across(m: &Machine, _: &Plan) -> bool {
    m.hw.interp.coord_arith != CoordArith::Float32
}

/// Whether the fixed twins may run with the chain's signals in lanes
/// ([`super::table::LanesFn`]): off the float32 coordinate path, as `texcoord`'s.
#[must_use]
pub fn lanes(m: &Machine, plan: &Plan) -> bool {
    super::texcoord::lanes(m, plan)
}

/// Float twin.
pub fn float(px: &Px, frag: &mut Frag, _: &mut Counters) {
    let Some(l0) = px.plan.texture.and_then(|t| px.m.tex_float[t].first()) else {
        return;
    };
    let d = texel_derivs_f64(&frag.uv, l0.width, l0.height);
    frag.lod = lod_mode_f64(d, px.m.hw.lod.lod_log2);
}

/// One invocation of the LOD unit.
#[must_use]
pub fn cost(m: &Machine, _: &Plan) -> UnitCost {
    lod_cost(&m.hw.lod, m.hw.timing.gate_levels_per_cycle)
}
