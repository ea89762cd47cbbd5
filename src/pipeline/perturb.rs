//! `perturb`: the bump material's normal `n' = normalize(n + f_u s_u + f_v s_v)` from the
//! fetched offsets and the local frame (Schilling 1997, equation 2; `hw_model::frame`).

use super::bump::{bump_of, d3, raw3, val3};
use super::stages::{Counters, Machine};
use super::{Frag, Plan, Px, StageKind};
use crate::fixedpoint::{to_raw, to_unorm};
use crate::shading::reference as fref;
use hw_model::frame::{perturb_cost, perturb_normal, Frame};
use hw_model::vector::offset_from_texel;
use hw_model::UnitCost;

/// Fixed twin: offsets decoded from the texel, the perturbation unit.
pub fn fixed(px: &Px, frag: &mut Frag, c: &mut Counters) {
    if bump_of(px).is_none() {
        return;
    }
    let m = px.m;
    let units = &m.units;
    let vc = &units.cfg.vector;
    let tb = m.hw.trilinear.texel_bits;
    let sat = &mut c.sat[StageKind::Perturb.index()];
    let bf = &mut frag.bump;
    let tex = if px.fixed(StageKind::BumpFetch) {
        bf.texel_x
    } else {
        bf.texel.map(|x| to_unorm(x, tb))
    };
    let f_u = offset_from_texel(u64::from(tex[0]), tb, vc, sat);
    let f_v = offset_from_texel(u64::from(tex[1]), tb, vc, sat);
    let fr = if px.fixed(StageKind::Frame) {
        Frame {
            n: bf.fr_n_x,
            t_u: bf.fr_t_u_x,
            t_v: bf.fr_t_v_x,
            len_u: bf.fr_len_x[0],
            len_v: bf.fr_len_x[1],
            fallback: false,
            zero_normal: false,
        }
    } else {
        Frame {
            n: raw3(&bf.fr_n, &m.vec_fmt, sat),
            t_u: raw3(&bf.fr_t_u, &m.vec_fmt, sat),
            t_v: raw3(&bf.fr_t_v, &m.vec_fmt, sat),
            len_u: to_raw(bf.fr_len[0], &m.len_fmt, sat),
            len_v: to_raw(bf.fr_len[1], &m.len_fmt, sat),
            fallback: false,
            zero_normal: false,
        }
    };
    bf.normal_x = perturb_normal(&fr, f_u, f_v, units, sat).v;
    bf.normal = val3(&bf.normal_x, vc.vector_frac_bits);
}

/// Float twin: `shading::reference::perturb_normal` on the decoded float offsets.
pub fn float(px: &Px, frag: &mut Frag, _: &mut Counters) {
    if bump_of(px).is_none() {
        return;
    }
    let vc = &px.m.units.cfg.vector;
    let bf = &mut frag.bump;
    let range = f64::from(vc.offset_int_bits.min(30)).exp2();
    let off = bf.texel.map(|t| (t - 0.5) * 2.0 * range);
    let fr = fref::FrameF {
        n: d3(&bf.fr_n),
        t_u: d3(&bf.fr_t_u),
        t_v: d3(&bf.fr_t_v),
        len_u: bf.fr_len[0],
        len_v: bf.fr_len[1],
        fallback: false,
        zero_normal: false,
    };
    bf.normal = fref::perturb_normal(&fr, off[0], off[1]).to_array();
}

/// One invocation of the perturbation unit.
#[must_use]
pub fn cost(m: &Machine, plan: &Plan) -> UnitCost {
    if plan.bump.is_none() {
        return UnitCost::default();
    }
    perturb_cost(&m.units, m.hw.timing.gate_levels_per_cycle)
}
