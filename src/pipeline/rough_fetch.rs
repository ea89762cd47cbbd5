//! `rough-fetch`: one trilinear lookup of the D map at the LOD of the bump fetch (Schilling
//! 1997, "Antialiasing of Bump-Maps", Appendix A; `hw_model::trilinear`). The plan and the D
//! maps are in [`super::rough`].

use super::rough::rough_of;
use super::stages::{Counters, Machine};
use super::trace::{fetch_at_uv_lod, fetch_at_uv_lod_f64};
use super::{Frag, Plan, Px, StageKind};
use crate::fixedpoint::from_unorm;
use hw_model::trilinear::trilinear_cost;
use hw_model::UnitCost;

/// Fixed twin: the LOD unit on the texture-coordinate derivatives, the trilinear unit
/// (traced). A ground-truth plan runs the float twin.
pub fn fixed(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let Some((_, rp)) = rough_of(px) else { return };
    if rp.truth_samples != 0 {
        return float(px, frag, c);
    }
    let Some(r) = fetch_at_uv_lod(px, frag, c, StageKind::RoughFetch, rp.map) else {
        return;
    };
    let tb = px.m.hw.trilinear.texel_bits;
    frag.rough_x = [0, 1, 2].map(|i| u32::from(r[i]));
    frag.rough = frag.rough_x.map(|x| from_unorm(x, tb));
}

/// Float twin: exact LOD and trilinear filter of the float D map.
pub fn float(px: &Px, frag: &mut Frag, _: &mut Counters) {
    let Some((_, rp)) = rough_of(px) else { return };
    let Some(r) = fetch_at_uv_lod_f64(px, frag, StageKind::RoughFetch, rp.map) else {
        return;
    };
    frag.rough = [r[0], r[1], r[2]];
}

/// One invocation: one trilinear lookup (the LOD is the bump fetch's).
#[must_use]
pub fn cost(m: &Machine, plan: &Plan) -> UnitCost {
    if plan.bump.is_none() || plan.rough.is_none() {
        return UnitCost::default();
    }
    trilinear_cost(&m.hw.trilinear, 2, m.hw.timing.gate_levels_per_cycle)
}
