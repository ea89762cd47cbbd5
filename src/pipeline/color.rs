//! `color`: interpolation of the vertex colour (the Gouraud lighting result) at the pixel
//! (`hw_model::interpolator::interpolate`, unorm `color_bits`).

use super::stages::{column, column_f, each_fragment, unorm, Counters, Machine};
use super::{Frag, Plan, Px, StageKind};
use crate::fixedpoint::to_raw;
use crate::reference::interpolate_f64;
use hw_model::interpolator::{interpolate, interpolate_cost, interpolate_span, SPAN_LANES};
use hw_model::UnitCost;

/// Fixed twin: three channels through the interpolator, alpha one.
pub fn fixed(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let m = px.m;
    let cb = m.hw.color.color_bits;
    let bb = m.hw.interp.bary_bits;
    let sat = &mut c.sat[StageKind::Color.index()];
    let b = if px.fixed(StageKind::Bary) {
        frag.bary_x[0]
    } else {
        frag.bary[0].map(|x| to_raw(x, &m.bary_fmt, sat))
    };
    for ch in 0..3 {
        let r = interpolate(b, bb, column(&px.a.color_x, ch), &m.color_fmt, sat) as u32;
        frag.color_x[ch] = r;
        if px.carriers {
            frag.color[ch] = unorm(r, cb);
        }
    }
    frag.color_x[3] = ((1u64 << cb) - 1) as u32;
    frag.out_x = frag.color_x;
    frag.out_bits = cb;
    if px.carriers {
        frag.color[3] = 1.0;
        frag.out = frag.color;
    }
}

/// Fixed twin over a span: after a Fixed `bary`, the three channels of up to [`SPAN_LANES`]
/// fragments at a time through `interpolate_span` (the triangle's terms and the rounding
/// resolved once), bit-identical to [`fixed`] on each fragment; otherwise [`fixed`] per
/// fragment.
pub fn fixed_span(px: &Px, frags: &mut [Frag], c: &mut Counters) {
    if !px.fixed(StageKind::Bary) {
        return each_fragment(fixed, px, frags, c);
    }
    let m = px.m;
    let (cb, bb) = (m.hw.color.color_bits, m.hw.interp.bary_bits);
    let attr = px.a.color_x.map(|v| v.map(i64::from));
    let alpha = ((1u64 << cb) - 1) as u32;
    let sat = &mut c.sat[StageKind::Color.index()];
    let mut rgb = [[[0i64; 3]; 1]; SPAN_LANES];
    for chunk in frags.chunks_mut(SPAN_LANES) {
        let lanes = chunk
            .iter()
            .zip(rgb.iter_mut())
            .map(|(f, r)| (&f.bary_x[..1], &mut r[..]));
        interpolate_span(lanes, bb, attr, &m.color_fmt, sat);
        for (f, [r]) in chunk.iter_mut().zip(&rgb) {
            f.color_x = [r[0] as u32, r[1] as u32, r[2] as u32, alpha];
            f.out_x = f.color_x;
            f.out_bits = cb;
            if px.carriers {
                f.color = f.color_x.map(|x| unorm(x, cb));
                f.color[3] = 1.0;
                f.out = f.color;
            }
        }
    }
}

/// Float twin.
pub fn float(px: &Px, frag: &mut Frag, _: &mut Counters) {
    for ch in 0..3 {
        frag.color[ch] = interpolate_f64(frag.bary[0], column_f(&px.af.color, ch));
    }
    frag.out_bits = 0;
    frag.color[3] = 1.0;
    frag.out = frag.color;
}

/// One invocation: three interpolations.
#[must_use]
pub fn cost(m: &Machine, _: &Plan) -> UnitCost {
    interpolate_cost(&m.hw.interp, m.hw.timing.gate_levels_per_cycle).times(3)
}
