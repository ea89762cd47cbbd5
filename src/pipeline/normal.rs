//! `normal`: interpolation of the bump material's normal, its frame vectors and lengths and the
//! vectors towards the eye and each point light (Schilling 1997, "The Local Coordinate System";
//! `hw_model::interpolator`). The per-triangle data is [`super::bump::BumpAttrs`].

use super::bump::{bump_of, constant_m, point_lights, raw3, val3};
use super::stages::{column, column_f, each_fragment, Counters, Machine};
use super::{BumpFrag, BumpPlan, Frag, Plan, Px, StageKind};
use crate::fixedpoint::{from_raw, to_raw};
use crate::reference::interpolate_f64;
use crate::scene::{FrameKind, MainDirection};
use hw_model::fixed::{Format, SatCounter};
use hw_model::interpolator::{interpolate, interpolate_cost, interpolate_span};
use hw_model::vector::Vec3x;
use hw_model::UnitCost;

/// Fixed twin: the interpolator on the vertex data in vector and len formats.
pub fn fixed(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let Some((bp, ba)) = bump_of(px) else { return };
    let m = px.m;
    let hw = m.hw;
    let f = m.units.cfg.vector.vector_frac_bits;
    let lfb = m.units.cfg.frame.frame_len_frac_bits;
    let fk = m.frame_of(bp);
    let np = point_lights(m);
    let sat = &mut c.sat[StageKind::Normal.index()];
    let bf = &mut frag.bump;
    let bb = hw.interp.bary_bits;
    let b = if px.fixed(StageKind::Bary) {
        frag.bary_x[0]
    } else {
        frag.bary[0].map(|x| to_raw(x, &m.bary_fmt, sat))
    };
    let mut ip = |attr: &[[i64; 3]; 3], fmt: &Format| -> Vec3x {
        [0, 1, 2].map(|ch| interpolate(b, bb, column(attr, ch), fmt, sat))
    };
    bf.n_i_x = ip(&ba.n_x, &m.vec_fmt);
    bf.to_eye_x = ip(&ba.eye_x, &m.vec_fmt);
    for l in 0..np {
        bf.to_light_x[l] = ip(&ba.light_x[l], &m.vec_fmt);
    }
    if fk == FrameKind::Main {
        bf.m_x = match bp.main {
            MainDirection::Constant(_) => raw3(&constant_m(bp), &m.vec_fmt, sat),
            _ => ip(&ba.m_x, &m.vec_fmt),
        };
    } else {
        bf.d_u_x = ip(&ba.du_x, &m.vec_fmt);
        bf.d_v_x = ip(&ba.dv_x, &m.vec_fmt);
    }
    if fk == FrameKind::Natural {
        bf.len_x = [0, 1].map(|ax| interpolate(b, bb, column(&ba.len_x, ax), &m.len_fmt, sat));
    }
    lengths_and_carriers(bf, fk, lfb, f, np);
}

/// Fixed twin over a span: after a Fixed `bary`, each attribute of every fragment through
/// `interpolate_span` (the triangle's terms and the rounding resolved once per attribute and
/// span) and the constant main direction quantized once, bit-identical to [`fixed`] on each
/// fragment (`normal_span_twin_matches_the_per_fragment_twin`); otherwise [`fixed`] per
/// fragment.
pub fn fixed_span(px: &Px, frags: &mut [Frag], c: &mut Counters) {
    let Some((bp, ba)) = bump_of(px) else { return };
    if !px.fixed(StageKind::Bary) {
        return each_fragment(fixed, px, frags, c);
    }
    let m = px.m;
    let f = m.units.cfg.vector.vector_frac_bits;
    let lfb = m.units.cfg.frame.frame_len_frac_bits;
    let fk = m.frame_of(bp);
    let np = point_lights(m);
    let sat = &mut c.sat[StageKind::Normal.index()];
    let bb = m.hw.interp.bary_bits;
    let vec_fmt = &m.vec_fmt;
    interpolate_into(frags, bb, ba.n_x, vec_fmt, sat, |b| &mut b.n_i_x);
    interpolate_into(frags, bb, ba.eye_x, vec_fmt, sat, |b| &mut b.to_eye_x);
    for l in 0..np {
        interpolate_into(frags, bb, ba.light_x[l], vec_fmt, sat, |b| {
            &mut b.to_light_x[l]
        });
    }
    if fk == FrameKind::Main {
        match bp.main {
            MainDirection::Constant(_) => {
                // Quantized once: every fragment's quantization counts its saturations.
                let mut once = SatCounter::default();
                let m_x = raw3(&constant_m(bp), vec_fmt, &mut once);
                sat.saturated += once.saturated * frags.len() as u64;
                sat.wrapped += once.wrapped * frags.len() as u64;
                for fr in frags.iter_mut() {
                    fr.bump.m_x = m_x;
                }
            }
            _ => interpolate_into(frags, bb, ba.m_x, vec_fmt, sat, |b| &mut b.m_x),
        }
    } else {
        interpolate_into(frags, bb, ba.du_x, vec_fmt, sat, |b| &mut b.d_u_x);
        interpolate_into(frags, bb, ba.dv_x, vec_fmt, sat, |b| &mut b.d_v_x);
    }
    if fk == FrameKind::Natural {
        interpolate_into(frags, bb, ba.len_x, &m.len_fmt, sat, |b| &mut b.len_x);
    }
    for fr in frags.iter_mut() {
        lengths_and_carriers(&mut fr.bump, fk, lfb, f, np);
    }
}

/// The frame's lengths (a natural frame's from its interpolated `len_x`, `lfb` fraction bits;
/// another frame's unit lengths) and the float carriers of the stage's signals.
fn lengths_and_carriers(bf: &mut BumpFrag, fk: FrameKind, lfb: u32, f: u32, np: usize) {
    if fk == FrameKind::Natural {
        bf.len = bf.len_x.map(|x| from_raw(x, lfb));
    } else {
        bf.len_x = [1i64 << lfb; 2];
        bf.len = [1.0; 2];
    }
    carriers(bf, f, np);
}

/// `interpolate_span` of one per-vertex attribute (`N` channels) at every fragment's first
/// sample into the slot `at` picks in its bump signals.
fn interpolate_into<const N: usize>(
    frags: &mut [Frag],
    bary_bits: u32,
    attr: [[i64; N]; 3],
    fmt: &Format,
    sat: &mut SatCounter,
    at: impl Fn(&mut BumpFrag) -> &mut [i64; N],
) {
    let lanes = frags.iter_mut().map(|fr| {
        let Frag { bary_x, bump, .. } = fr;
        (&bary_x[..1], std::slice::from_mut(at(bump)))
    });
    interpolate_span(lanes, bary_bits, attr, fmt, sat);
}

/// The float carriers of the fixed twins' raw vectors (`f` fraction bits, `np` point lights).
fn carriers(bf: &mut BumpFrag, f: u32, np: usize) {
    bf.n_i = val3(&bf.n_i_x, f);
    bf.to_eye = val3(&bf.to_eye_x, f);
    for l in 0..np {
        bf.to_light[l] = val3(&bf.to_light_x[l], f);
    }
    bf.d_u = val3(&bf.d_u_x, f);
    bf.d_v = val3(&bf.d_v_x, f);
    bf.m = val3(&bf.m_x, f);
}

/// Float twin: the same interpolation of the float vertex data.
pub fn float(px: &Px, frag: &mut Frag, _: &mut Counters) {
    let Some((bp, ba)) = bump_of(px) else { return };
    let m = px.m;
    let fk = m.frame_of(bp);
    let np = point_lights(m);
    let bf = &mut frag.bump;
    let b = frag.bary[0];
    let ip = |attr: &[[f64; 3]; 3]| -> [f64; 3] {
        [0, 1, 2].map(|ch| interpolate_f64(b, column_f(attr, ch)))
    };
    bf.n_i = ip(&ba.n_f);
    bf.to_eye = ip(&ba.eye_f);
    for l in 0..np {
        bf.to_light[l] = ip(&ba.light_f[l]);
    }
    bf.d_u = ip(&ba.du_f);
    bf.d_v = ip(&ba.dv_f);
    bf.m = match bp.main {
        MainDirection::Constant(_) => constant_m(bp),
        _ => ip(&ba.m_f),
    };
    bf.len = if fk == FrameKind::Natural {
        [0, 1].map(|ax| interpolate_f64(b, column_f(&ba.len_f, ax)))
    } else {
        [1.0; 2]
    };
}

/// One invocation: one interpolation per scalar attribute ([`normal_attr_count`]).
#[must_use]
pub fn cost(m: &Machine, plan: &Plan) -> UnitCost {
    let Some(bp) = &plan.bump else {
        return UnitCost::default();
    };
    let g = m.hw.timing.gate_levels_per_cycle;
    interpolate_cost(&m.hw.interp, g).times(normal_attr_count(m, bp, m.frame_of(bp)))
}

/// Scalar attributes interpolated by the `normal` stage of `bp` with frame `kind`.
#[must_use]
pub fn normal_attr_count(m: &Machine, bp: &BumpPlan, kind: FrameKind) -> u32 {
    let frame = match kind {
        FrameKind::Natural => 8,
        FrameKind::Unit => 6,
        FrameKind::Main => match bp.main {
            MainDirection::Constant(_) => 0,
            MainDirection::Pu | MainDirection::Pv => 3,
        },
    };
    3 + 3 + 3 * point_lights(m) as u32 + frame
}
