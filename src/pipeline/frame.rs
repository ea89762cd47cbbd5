//! `frame`: the bump material's local frame, natural, unit or main direction (Schilling 1997,
//! "The Local Coordinate System"; `hw_model::frame`).

use super::bump::{bump_of, d3, main_role, raw3, val3};
use super::stages::{Counters, Machine};
use super::{Frag, Plan, Px, StageKind};
use crate::fixedpoint::{from_raw, to_raw};
use crate::scene::FrameKind;
use crate::shading::reference as fref;
use hw_model::frame::{frame_cost, main_frame, natural_frame, unit_frame};
use hw_model::vector::Vec3x;
use hw_model::UnitCost;

/// Fixed twin: the frame unit on the interpolated vectors (quantized when `normal` ran float).
pub fn fixed(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let Some((bp, ba)) = bump_of(px) else { return };
    let m = px.m;
    let units = &m.units;
    let f = units.cfg.vector.vector_frac_bits;
    let lfb = units.cfg.frame.frame_len_frac_bits;
    let sat = &mut c.sat[StageKind::Frame.index()];
    let bf = &mut frag.bump;
    let raw = px.fixed(StageKind::Normal);
    let mut q = |x: &Vec3x, v: &[f64; 3]| {
        if raw {
            *x
        } else {
            raw3(v, &m.vec_fmt, sat)
        }
    };
    let n = q(&bf.n_i_x, &bf.n_i);
    let du = q(&bf.d_u_x, &bf.d_u);
    let dv = q(&bf.d_v_x, &bf.d_v);
    let mm = q(&bf.m_x, &bf.m);
    let len = if raw {
        bf.len_x
    } else {
        bf.len.map(|x| to_raw(x, &m.len_fmt, sat))
    };
    let fr = match m.frame_of(bp) {
        FrameKind::Natural => natural_frame(&n, &du, &dv, len[0], len[1], units, sat),
        FrameKind::Unit => unit_frame(&n, &du, &dv, units, sat),
        FrameKind::Main => main_frame(&n, &mm, main_role(bp, ba), units, sat),
    };
    c.frame_fallback += u64::from(fr.fallback);
    c.zero_normal += u64::from(fr.zero_normal);
    bf.fr_n_x = fr.n;
    bf.fr_t_u_x = fr.t_u;
    bf.fr_t_v_x = fr.t_v;
    bf.fr_len_x = [fr.len_u, fr.len_v];
    bf.fr_n = val3(&fr.n, f);
    bf.fr_t_u = val3(&fr.t_u, f);
    bf.fr_t_v = val3(&fr.t_v, f);
    bf.fr_len = bf.fr_len_x.map(|x| from_raw(x, lfb));
}

/// Float twin: `shading::reference::build_frame`.
pub fn float(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let Some((bp, ba)) = bump_of(px) else { return };
    let m = px.m;
    let bf = &mut frag.bump;
    let fr = fref::build_frame(
        m.frame_of(bp),
        d3(&bf.n_i),
        d3(&bf.d_u),
        d3(&bf.d_v),
        bf.len[0],
        bf.len[1],
        d3(&bf.m),
        main_role(bp, ba),
        m.units.cfg.frame.frame_min_sin_bits,
    );
    c.frame_fallback += u64::from(fr.fallback);
    c.zero_normal += u64::from(fr.zero_normal);
    bf.fr_n = fr.n.to_array();
    bf.fr_t_u = fr.t_u.to_array();
    bf.fr_t_v = fr.t_v.to_array();
    bf.fr_len = [fr.len_u, fr.len_v];
}

/// One invocation of the frame unit of the plan's frame kind.
#[must_use]
pub fn cost(m: &Machine, plan: &Plan) -> UnitCost {
    let Some(bp) = &plan.bump else {
        return UnitCost::default();
    };
    frame_cost(m.frame_of(bp), &m.units, m.hw.timing.gate_levels_per_cycle)
}
