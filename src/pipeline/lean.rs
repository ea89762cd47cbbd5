//! What the LEAN stages share (Olano and Baker 2010, "LEAN Mapping"): their plan, the moment
//! maps and the ground-truth plans. The stages are one file each: [`super::lean_fetch`]
//! filters the second-moment map (`M_uu, M_vv, M_uv` of the bump slopes) with the ordinary
//! trilinear unit at the LOD of the bump fetch (the first moments `B` are the filtered offset
//! map `bump-fetch` already read); [`super::lean_shade`] replaces `phong`: the LEAN unit
//! (`hw_model::lean`) evaluates the slope Gaussian at the half vector for every light.
//!
//! A bump material with `bump_filter = "lean"` (and no roughness map, NDF or Ashikhmin-Shirley
//! BRDF) gets these stages; any other costs nothing extra. Its ground truth is the roughness
//! stages' (the box-filtered mean of plain Blinn-Phong over sub-samples of the finest offsets).

use super::rough::{decoded_offsets, resolve_extra_map, truth_as_rough, ExtraMapStages};
use super::{BumpPlan, Plan, Px, StageKind};
use crate::maps::Maps;
use crate::scene::{BumpFilter, Material};
use crate::shading::lean::{lean_mip_chain, quantize_lean_chain};
use hw_model::config::HwConfig;

/// The LEAN stages: the fetch after `bump-fetch`, the shade instead of `phong`.
const STAGES: ExtraMapStages = ExtraMapStages {
    fetch: StageKind::LeanFetch,
    shade: StageKind::LeanShade,
};

/// What the LEAN stages of one material need.
#[derive(Clone, Debug, PartialEq)]
pub struct LeanPlan {
    /// Index of the moment map in the render's maps (set by [`resolve_plans`]).
    pub map: usize,
}

/// Per-fragment signals of `lean-fetch`: the filtered moment channels (unorm), raw texels.
#[derive(Clone, Copy, Debug, Default)]
pub struct LeanFrag {
    pub texel: [f64; 3],
    pub texel_x: [u32; 3],
}

/// Marks the bump plan of a `bump_filter = "lean"` material (after the roughness and NDF
/// planners: a plan that no longer shades with `phong`, or has a roughness map, is left alone).
pub fn mark_plan(plan: &mut Plan, material: &Material) {
    if material.bump_filter != BumpFilter::Lean
        || plan.aniso.is_some()
        || plan.rough.is_some()
        || plan.ndf.is_some()
        || plan.bump.is_none()
        || !plan.stages.contains(&StageKind::Phong)
    {
        return;
    }
    plan.lean = Some(LeanPlan { map: usize::MAX });
}

/// The bump and LEAN plans of the pixel's material; `None` (the stage does nothing)
/// without either.
#[inline]
pub(super) fn lean_of<'a>(px: &Px<'a>) -> Option<(&'a BumpPlan, &'a LeanPlan)> {
    Some((px.plan.bump.as_ref()?, px.plan.lean.as_ref()?))
}

/// Numbers the moment maps from `first_map` (one per distinct offset map, in the order of the
/// returned offset-map indices) and sets the stages: `lean-fetch` after `bump-fetch`,
/// `lean-shade` instead of `phong`.
pub fn resolve_plans(plans: &mut [Plan], first_map: usize) -> Vec<usize> {
    resolve_extra_map(plans, first_map, STAGES, |p| {
        p.lean.as_mut().map(|t| &mut t.map)
    })
}

/// `maps` with the moment maps of offset maps `sources` appended (float chains and their
/// quantization to `texel_bits`, three channels stored), and the moment values clamped by
/// the encoding.
pub fn lean_maps(maps: &Maps, sources: &[usize], hw: &HwConfig) -> crate::Result<(Maps, u64)> {
    let mut out = maps.clone();
    let mut clamped = 0;
    for &s in sources {
        let Some(chain) = maps.float.get(s) else {
            return Err(crate::Error::msg(format!(
                "lean: offset map {s} does not exist"
            )));
        };
        let (w, h, offs) = decoded_offsets(chain, maps.offset_int_bits);
        let (c, cl) = lean_mip_chain(&offs, w, h, hw.lean.lean_moment_exp);
        clamped += cl;
        out.fixed
            .push(quantize_lean_chain(&c, hw.trilinear.texel_bits));
        out.float.push(c);
    }
    Ok((out, clamped))
}

/// The ground-truth plans: every LEAN plan becomes a roughness plan of variant `none` in
/// truth mode (`rough-shade` supersampling plain Blinn-Phong, `k` sub-samples per axis).
#[must_use]
pub fn truth_plans(plans: Vec<Plan>, k: u32) -> Vec<Plan> {
    truth_as_rough(plans, k, STAGES, |p| p.lean.take().is_some())
}
