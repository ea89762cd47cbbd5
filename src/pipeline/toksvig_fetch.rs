//! `toksvig-fetch`: one trilinear lookup of the Toksvig map (the MIP-mapped average unit
//! normal, Toksvig 2005) at the LOD of the bump fetch (`hw_model::lod`, `hw_model::trilinear`).
//! The plan and the maps are in [`super::toksvig`].

use super::stages::{Counters, Machine};
use super::toksvig::toksvig_of;
use super::trace::{fetch_at_uv_lod, fetch_at_uv_lod_f64};
use super::{Frag, Plan, Px, StageKind};
use crate::fixedpoint::from_unorm;
use hw_model::trilinear::trilinear_cost;
use hw_model::UnitCost;

/// Fixed twin: the LOD unit on the texture-coordinate derivatives, the trilinear unit (traced).
pub fn fixed(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let Some((_, tp)) = toksvig_of(px) else {
        return;
    };
    let Some(r) = fetch_at_uv_lod(px, frag, c, StageKind::ToksvigFetch, tp.map) else {
        return;
    };
    let tb = px.m.hw.trilinear.texel_bits;
    frag.toksvig.texel_x = [0, 1, 2].map(|i| u32::from(r[i]));
    frag.toksvig.texel = frag.toksvig.texel_x.map(|x| from_unorm(x, tb));
}

/// Float twin: exact LOD and trilinear filter of the float Toksvig map.
pub fn float(px: &Px, frag: &mut Frag, _: &mut Counters) {
    let Some((_, tp)) = toksvig_of(px) else {
        return;
    };
    let Some(r) = fetch_at_uv_lod_f64(px, frag, StageKind::ToksvigFetch, tp.map) else {
        return;
    };
    frag.toksvig.texel = [r[0], r[1], r[2]];
}

/// One invocation: one trilinear lookup (the LOD unit's share is counted as in `rough-fetch`:
/// the bump fetch's LOD is reused).
#[must_use]
pub fn cost(m: &Machine, plan: &Plan) -> UnitCost {
    if plan.bump.is_none() || plan.toksvig.is_none() {
        return UnitCost::default();
    }
    trilinear_cost(&m.hw.trilinear, 2, m.hw.timing.gate_levels_per_cycle)
}
