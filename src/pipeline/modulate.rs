//! `modulate`: colour x texel, rounded to `color_bits` (`hw_model::modulate`).

use super::stages::{unorm, Counters, Machine};
use super::{Frag, Plan, Px, StageKind};
use crate::fixedpoint::to_unorm;
use hw_model::modulate::{modulate, modulate_cost, modulate_span};
use hw_model::UnitCost;

/// Fixed twin: four unorm products.
pub fn fixed(px: &Px, frag: &mut Frag, _: &mut Counters) {
    let hw = px.m.hw;
    let cb = hw.color.color_bits;
    let tb = hw.trilinear.texel_bits;
    let rnd = hw.color.color_rounding;
    let col = if px.color_raw {
        frag.color_x
    } else {
        frag.color.map(|x| to_unorm(x, cb))
    };
    let tex = if px.fixed(StageKind::Trilinear) {
        frag.texel_x
    } else {
        frag.texel.map(|x| to_unorm(x, tb))
    };
    for ch in 0..4 {
        frag.out_x[ch] = modulate(col[ch], cb, tex[ch], tb, cb, rnd);
        if px.carriers {
            frag.out[ch] = unorm(frag.out_x[ch], cb);
        }
    }
    frag.out_bits = cb;
}

/// Fixed twin over a span: [`fixed`] on each fragment, with the widths and the rounding
/// resolved once for the span (`modulate_span`, bit-identical to `modulate`).
pub fn fixed_span(px: &Px, frags: &mut [Frag], _: &mut Counters) {
    let hw = px.m.hw;
    let cb = hw.color.color_bits;
    let tb = hw.trilinear.texel_bits;
    let (color_raw, texel_raw) = (px.color_raw, px.fixed(StageKind::Trilinear));
    let lanes = frags.iter_mut().map(|f| {
        let col = if color_raw {
            f.color_x
        } else {
            f.color.map(|x| to_unorm(x, cb))
        };
        let tex = if texel_raw {
            f.texel_x
        } else {
            f.texel.map(|x| to_unorm(x, tb))
        };
        (col, tex, &mut f.out_x)
    });
    modulate_span(lanes, cb, tb, cb, hw.color.color_rounding);
    for f in frags.iter_mut() {
        if px.carriers {
            f.out = f.out_x.map(|x| unorm(x, cb));
        }
        f.out_bits = cb;
    }
}

/// Float twin.
pub fn float(_: &Px, frag: &mut Frag, _: &mut Counters) {
    for ch in 0..4 {
        frag.out[ch] = frag.color[ch] * frag.texel[ch];
    }
    frag.out_bits = 0;
}

/// One invocation of the modulate unit.
#[must_use]
pub fn cost(m: &Machine, _: &Plan) -> UnitCost {
    modulate_cost(&m.hw.color, m.hw.timing.gate_levels_per_cycle)
}
