//! What the roughness stages share (Schilling 1997, "Antialiasing of Bump-Maps": "The
//! roughness pyramid", Appendix A): their plan, its resolution and the D maps. The stages are
//! one file each: [`super::rough_fetch`] filters the D map (three channels `d1, d2, d3`, or
//! lambda1) with the ordinary trilinear unit at the LOD of the bump fetch (same map size, same
//! derivatives); [`super::rough_shade`] replaces `phong` and evaluates Blinn-Phong with the
//! modified specular term `cos^2 a' = cos^2 a / (|d|^4 / |D d|^2 + cos^2 a)` (or a variant)
//! for every light.
//!
//! A material with `roughness` set gets these stages when its resolved variant is not `none`;
//! with `none` it keeps the plain `phong` (the filtered bump map, the paper's baseline) and
//! costs nothing extra. The D maps are built per render ([`rough_maps`]) from the offset
//! map's level 0 as the trilinear unit sees it (decoded 16-bit offsets), with the material's
//! base roughness and the exponent of the configured mode (`shading::roughness`).
//!
//! Ground truth (the paper's "expensive alternative"): a plan whose [`RoughPlan::truth_samples`]
//! is set evaluates `rough-shade` as the box-filtered mean of `k x k` sub-samples over the
//! pixel's footprint in texture space (`uv + s du/dx + t du/dy`, `s, t` in `[-1/2, 1/2]`),
//! each with its own normal perturbed by the bilinearly sampled finest offsets, shaded with
//! the material's plain Blinn-Phong in float.

use super::{BumpPlan, Plan, Px, StageKind};
use crate::maps::Maps;
use crate::maps::MipChain;
use crate::scene::{Material, RoughChoice};
use crate::shading::roughness::{
    build_rough_pyramid, quantize_rough_chain, rough_mip_chain, RoughParams, RoughnessEncoding,
};
use hw_model::config::HwConfig;
use hw_model::roughness::RoughVariant;

/// What the roughness stages of one material need.
#[derive(Clone, Debug, PartialEq)]
pub struct RoughPlan {
    /// The material's choice (resolved into `variant` by [`resolve_plans`]).
    pub choice: RoughChoice,
    /// The variant evaluated (`None` until resolved; `none` keeps plain `phong`).
    pub variant: RoughVariant,
    /// Index of the D map in the render's maps (set by [`resolve_plans`]).
    pub map: usize,
    /// Ground-truth sub-samples per axis; 0 = the model.
    pub truth_samples: u32,
}

/// Marks a bump plan of a roughness material (called by the planner of `render`; the stages
/// are set by [`resolve_plans`] once the hardware is known). Ashikhmin-Shirley plans (which
/// also carry a bump plan) are left alone: they have no Blinn-Phong to modify.
pub fn mark_plan(plan: &mut Plan, material: &Material) {
    if plan.aniso.is_some() || !plan.stages.contains(&StageKind::Phong) {
        return;
    }
    if let (Some(choice), Some(_)) = (material.roughness, &plan.bump) {
        plan.rough = Some(RoughPlan {
            choice,
            variant: RoughVariant::None,
            map: usize::MAX,
            truth_samples: 0,
        });
    }
}

/// The bump and roughness plans of the pixel's material; `None` (the stage does nothing)
/// without either.
#[inline]
pub(super) fn rough_of<'a>(px: &Px<'a>) -> Option<(&'a BumpPlan, &'a RoughPlan)> {
    Some((px.plan.bump.as_ref()?, px.plan.rough.as_ref()?))
}

/// The machine's roughness configuration with the plan's resolved variant.
pub(super) fn rough_config(hw: &HwConfig, rp: &RoughPlan) -> hw_model::roughness::RoughnessConfig {
    hw_model::roughness::RoughnessConfig {
        rough_variant: rp.variant,
        ..hw.roughness.clone()
    }
}

/// One D map to build: offset map, material shininess, isotropic representation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RoughSource {
    pub offset_map: usize,
    pub shininess: u32,
    pub isotropic: bool,
}

/// Resolves every roughness plan's variant against `hw` and sets its stages: `rough-fetch`
/// after `bump-fetch` and `rough-shade` instead of `phong` (variant `none`: plain `phong`).
/// D maps are numbered from `first_map` in the order of the returned sources.
pub fn resolve_plans(plans: &mut [Plan], hw: &HwConfig, first_map: usize) -> Vec<RoughSource> {
    let mut sources: Vec<RoughSource> = Vec::new();
    for plan in plans.iter_mut() {
        let Some(bp) = &plan.bump else { continue };
        let (offset_map, shininess) = (bp.map, bp.shininess);
        let Some(rp) = plan.rough.as_mut() else {
            continue;
        };
        rp.variant = match rp.choice {
            RoughChoice::Hw => hw.roughness.rough_variant,
            RoughChoice::Variant(v) => v,
        };
        plan.stages
            .retain(|k| !matches!(k, StageKind::RoughFetch | StageKind::RoughShade));
        if !plan.stages.contains(&StageKind::Phong) {
            plan.stages.push(StageKind::Phong);
        }
        if rp.variant == RoughVariant::None {
            rp.map = usize::MAX;
            continue;
        }
        let src = RoughSource {
            offset_map,
            shininess,
            isotropic: rp.variant == RoughVariant::Isotropic,
        };
        let k = sources.iter().position(|s| *s == src).unwrap_or_else(|| {
            sources.push(src);
            sources.len() - 1
        });
        rp.map = first_map + k;
        let mut stages = Vec::with_capacity(plan.stages.len() + 1);
        for &s in &plan.stages {
            match s {
                StageKind::BumpFetch => stages.extend([s, StageKind::RoughFetch]),
                StageKind::Phong => stages.push(StageKind::RoughShade),
                _ => stages.push(s),
            }
        }
        plan.stages = stages;
    }
    sources
}

/// The ground-truth plans: every roughness plan shades with `rough-shade` in truth mode
/// (`k` sub-samples per axis) and skips the D fetch.
#[must_use]
pub fn truth_plans(plans: &[Plan], k: u32) -> Vec<Plan> {
    plans
        .iter()
        .map(|p| {
            let mut p = p.clone();
            if let Some(rp) = p.rough.as_mut() {
                rp.truth_samples = k.max(1);
                p.stages.retain(|&s| s != StageKind::RoughFetch);
                for s in &mut p.stages {
                    if *s == StageKind::Phong {
                        *s = StageKind::RoughShade;
                    }
                }
            }
            p
        })
        .collect()
}

/// Level-0 offsets of offset map `map` as the trilinear unit sees them (decoded texels).
pub(crate) fn decoded_offsets(chain: &MipChain, offset_int_bits: u32) -> (u32, u32, Vec<[f32; 2]>) {
    let Some(l0) = chain.levels.first() else {
        return (1, 1, vec![[0.0; 2]]);
    };
    let range = f64::from(offset_int_bits.min(30)).exp2();
    let offs = l0
        .texels
        .iter()
        .map(|t| [0, 1].map(|c| ((f64::from(t[c]) - 0.5) * 2.0 * range) as f32))
        .collect();
    (l0.width, l0.height, offs)
}

/// `maps` with the D maps of `sources` appended (float chains and their `rough_d_bits`
/// quantization widened to the texel width), and the number of clamped D channel values.
pub fn rough_maps(
    maps: &Maps,
    sources: &[RoughSource],
    hw: &HwConfig,
) -> crate::Result<(Maps, u64)> {
    let mut out = maps.clone();
    let rc = &hw.roughness;
    let enc = RoughnessEncoding::for_range_exp(rc.rough_range_exp);
    let tb = hw.trilinear.texel_bits;
    let mut clamped = 0;
    for s in sources {
        let Some(chain) = maps.float.get(s.offset_map) else {
            return Err(crate::Error::msg(format!(
                "roughness: offset map {} does not exist",
                s.offset_map
            )));
        };
        let (w, h, offs) = decoded_offsets(chain, maps.offset_int_bits);
        let pyr = build_rough_pyramid(&offs, w, h)?;
        let params =
            RoughParams::for_material(s.shininess, rc.exponent(s.shininess), rc.rough_uniform);
        let (c, cl) = rough_mip_chain(&pyr, &params, &enc, s.isotropic);
        clamped += cl;
        let q = quantize_rough_chain(&c, rc.rough_d_bits, tb);
        let stored = if s.isotropic { 1 } else { q.format.channels };
        let bits = q.format.bits;
        out.fixed.push(q.stored_as(stored, bits));
        out.float.push(c);
    }
    Ok((out, clamped))
}

/// The two stages of a bump-map filter that reads one more map per offset map (Toksvig,
/// LEAN): its fetch runs after `bump-fetch`, its shade instead of `phong`.
#[derive(Clone, Copy)]
pub(super) struct ExtraMapStages {
    pub fetch: StageKind,
    pub shade: StageKind,
}

/// Numbers the extra maps of the plans whose `slot` is set (the map index it holds) from
/// `first_map`, one per distinct offset map, and sets their stages. Returns the offset maps,
/// in the order of the extra maps.
pub(super) fn resolve_extra_map(
    plans: &mut [Plan],
    first_map: usize,
    st: ExtraMapStages,
    slot: fn(&mut Plan) -> Option<&mut usize>,
) -> Vec<usize> {
    let mut sources: Vec<usize> = Vec::new();
    for plan in plans.iter_mut() {
        let Some(offset_map) = plan.bump.as_ref().map(|b| b.map) else {
            continue;
        };
        let Some(map) = slot(plan) else { continue };
        let k = sources
            .iter()
            .position(|&s| s == offset_map)
            .unwrap_or_else(|| {
                sources.push(offset_map);
                sources.len() - 1
            });
        *map = first_map + k;
        let mut stages = Vec::with_capacity(plan.stages.len() + 1);
        for &s in &plan.stages {
            match s {
                StageKind::BumpFetch => stages.extend([s, st.fetch]),
                StageKind::Phong => stages.push(st.shade),
                s if s == st.fetch || s == st.shade => {}
                _ => stages.push(s),
            }
        }
        plan.stages = stages;
    }
    sources
}

/// The ground truth of such a filter's plans (`take` clears the filter's plan and says whether
/// there was one): a roughness plan of variant `none` in truth mode (`rough-shade`
/// supersampling plain Blinn-Phong, `k` sub-samples per axis), so the filter, the plain bump
/// map and the roughness pyramid are measured against one truth.
pub(super) fn truth_as_rough(
    plans: Vec<Plan>,
    k: u32,
    st: ExtraMapStages,
    take: fn(&mut Plan) -> bool,
) -> Vec<Plan> {
    plans
        .into_iter()
        .map(|mut p| {
            if take(&mut p) {
                p.rough = Some(RoughPlan {
                    choice: RoughChoice::Variant(RoughVariant::None),
                    variant: RoughVariant::None,
                    map: usize::MAX,
                    truth_samples: k.max(1),
                });
                p.stages.retain(|&s| s != st.fetch);
                for s in &mut p.stages {
                    if *s == st.shade {
                        *s = StageKind::RoughShade;
                    }
                }
            }
            p
        })
        .collect()
}
