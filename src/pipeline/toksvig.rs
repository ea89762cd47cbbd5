//! What the Toksvig stages share (Toksvig 2005, "Mipmapping Normal Maps"): their plan, the
//! Toksvig maps and the ground-truth plans. The stages are one file each:
//! [`super::toksvig_fetch`] filters the Toksvig map (the MIP-mapped average unit normal, RGB)
//! with the ordinary trilinear unit at the LOD of the bump fetch; [`super::toksvig_shade`]
//! replaces `phong`: the Toksvig unit (`hw_model::toksvig`) turns `|Na|` into the adjusted
//! exponent and specular scale, then the Blinn-Phong unit shades the perturbed normal with
//! them for every light.
//!
//! A bump material with `bump_filter = "toksvig"` (and no roughness map, NDF or
//! Ashikhmin-Shirley BRDF, which bring their own lobes) gets these stages; any other costs
//! nothing extra. Its ground truth is the roughness stages' (the box-filtered mean of plain
//! Blinn-Phong over sub-samples of the finest offsets, `rough-shade` in truth mode), so
//! Toksvig, the plain bump map and the roughness pyramid are measured against one truth.

use super::rough::{decoded_offsets, resolve_extra_map, truth_as_rough, ExtraMapStages};
use super::{BumpPlan, Plan, Px, StageKind};
use crate::maps::Maps;
use crate::scene::{BumpFilter, Material};
use crate::shading::toksvig::{quantize_toksvig_chain, toksvig_mip_chain};
use hw_model::config::HwConfig;

/// The Toksvig stages: the fetch after `bump-fetch`, the shade instead of `phong`.
const STAGES: ExtraMapStages = ExtraMapStages {
    fetch: StageKind::ToksvigFetch,
    shade: StageKind::ToksvigShade,
};

/// What the Toksvig stages of one material need.
#[derive(Clone, Debug, PartialEq)]
pub struct ToksvigPlan {
    /// Index of the Toksvig map in the render's maps (set by [`resolve_plans`]).
    pub map: usize,
}

/// Per-fragment signals of `toksvig-fetch`: the filtered channels (unorm) and their raw texels.
#[derive(Clone, Copy, Debug, Default)]
pub struct ToksvigFrag {
    pub texel: [f64; 3],
    pub texel_x: [u32; 3],
}

/// Marks the bump plan of a `bump_filter = "toksvig"` material (after the roughness and NDF
/// planners: a plan that no longer shades with `phong`, or has a roughness map, is left alone).
pub fn mark_plan(plan: &mut Plan, material: &Material) {
    if material.bump_filter != BumpFilter::Toksvig
        || plan.aniso.is_some()
        || plan.rough.is_some()
        || plan.ndf.is_some()
        || plan.bump.is_none()
        || !plan.stages.contains(&StageKind::Phong)
    {
        return;
    }
    plan.toksvig = Some(ToksvigPlan { map: usize::MAX });
}

/// The bump and Toksvig plans of the pixel's material; `None` (the stage does nothing)
/// without either.
#[inline]
pub(super) fn toksvig_of<'a>(px: &Px<'a>) -> Option<(&'a BumpPlan, &'a ToksvigPlan)> {
    Some((px.plan.bump.as_ref()?, px.plan.toksvig.as_ref()?))
}

/// Numbers the Toksvig maps from `first_map` (one per distinct offset map, in the order of the
/// returned offset-map indices) and sets the stages: `toksvig-fetch` after `bump-fetch`,
/// `toksvig-shade` instead of `phong`.
pub fn resolve_plans(plans: &mut [Plan], first_map: usize) -> Vec<usize> {
    resolve_extra_map(plans, first_map, STAGES, |p| {
        p.toksvig.as_mut().map(|t| &mut t.map)
    })
}

/// `maps` with the Toksvig maps of offset maps `sources` appended (float chains and their
/// quantization to `texel_bits`, three channels stored).
pub fn toksvig_maps(maps: &Maps, sources: &[usize], hw: &HwConfig) -> crate::Result<Maps> {
    let mut out = maps.clone();
    for &s in sources {
        let Some(chain) = maps.float.get(s) else {
            return Err(crate::Error::msg(format!(
                "toksvig: offset map {s} does not exist"
            )));
        };
        let (w, h, offs) = decoded_offsets(chain, maps.offset_int_bits);
        let c = toksvig_mip_chain(&offs, w, h);
        out.fixed
            .push(quantize_toksvig_chain(&c, hw.trilinear.texel_bits));
        out.float.push(c);
    }
    Ok(out)
}

/// The ground-truth plans: every Toksvig plan becomes a roughness plan of variant `none` in
/// truth mode (`rough-shade` supersampling plain Blinn-Phong, `k` sub-samples per axis).
#[must_use]
pub fn truth_plans(plans: Vec<Plan>, k: u32) -> Vec<Plan> {
    truth_as_rough(plans, k, STAGES, |p| p.toksvig.take().is_some())
}
