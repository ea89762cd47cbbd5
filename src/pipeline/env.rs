//! What the environment stage shares (Schilling 1997, "balanced system"; issue 16): its plan,
//! its resolution against the hardware, and the sky cube maps in texture memory. The stage
//! is [`super::env_fetch`]: reflection vector, cube face, footprint (filtered by the
//! roughness when `env_filter` says so), footprint-assembly lookup on the face, and the
//! reflection weighted by `ks` added to the shading result (`docs/ENVMAP.md`).
//!
//! Only bump materials with `env` get the stage, appended after their shading stage
//! (`phong` or `rough-shade`); every other material's plan is unchanged.

use super::{Plan, StageKind};
use crate::maps::cube::cube_chains;
use crate::maps::cube::env_sampler;
use crate::maps::{quantize_chain, Maps};
use crate::scene::{EnvSource, Material, TextureImage};
use hw_model::config::HwConfig;
use hw_model::env_config::EnvFilter;

/// What the environment stage of one material needs.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvPlan {
    /// The material's filter (`None`: the hardware's `env_filter`).
    pub choice: Option<EnvFilter>,
    /// The resolved filter.
    pub filter: EnvFilter,
    /// Face size of the cube.
    pub size: u32,
    /// Where its texels come from.
    pub source: EnvSource,
    /// Index of the cube's first face chain (+X; the six faces are consecutive).
    pub map: usize,
    /// Ground-truth sub-samples per axis; 0 = the model.
    pub truth_samples: u32,
    /// The D map stores `sqrt(m) D` (`m` the roughness exponent, `shading::roughness`): the
    /// stage scales D by `1/sqrt(m)`, a per-material constant with 16 fraction bits.
    pub d_scale_q16: i64,
}

/// Marks a bump plan of a material with an environment map (the stage is appended by
/// [`resolve_plans`]). Ashikhmin-Shirley and NDF plans are left alone.
pub fn mark_plan(plan: &mut Plan, material: &Material) {
    let shaded = plan.has(StageKind::Phong) || plan.has(StageKind::RoughShade);
    if plan.aniso.is_some() || plan.ndf.is_some() || plan.bump.is_none() || !shaded {
        return;
    }
    if let Some(e) = material.env {
        plan.env = Some(EnvPlan {
            choice: e.filter,
            filter: EnvFilter::None,
            size: e.size,
            source: e.source,
            map: usize::MAX,
            truth_samples: 0,
            d_scale_q16: 1 << 16,
        });
    }
}

/// Resolves every environment plan's filter against `hw`, numbers its cube (one per distinct
/// face size and source, from `first_map`) and appends `env-fetch` as the plan's last stage.
/// Returns the cubes to build (face size, source), in order.
pub fn resolve_plans(plans: &mut [Plan], hw: &HwConfig, first_map: usize) -> Vec<(u32, EnvSource)> {
    let mut sizes: Vec<(u32, EnvSource)> = Vec::new();
    for plan in plans.iter_mut() {
        let Some(ep) = plan.env.as_mut() else {
            continue;
        };
        ep.filter = ep.choice.unwrap_or(hw.env.env_filter);
        let exponent = plan
            .bump
            .as_ref()
            .map_or(1, |b| hw.roughness.exponent(b.shininess).max(1));
        ep.d_scale_q16 = crate::fixedpoint::to_raw_nearest(1.0 / f64::from(exponent).sqrt(), 16);
        let key = (ep.size, ep.source);
        let k = sizes.iter().position(|&s| s == key).unwrap_or_else(|| {
            sizes.push(key);
            sizes.len() - 1
        });
        ep.map = first_map + 6 * k;
        plan.stages.retain(|&s| s != StageKind::EnvFetch);
        plan.stages.push(StageKind::EnvFetch);
    }
    sizes
}

/// `maps` with the cubes of `cubes` appended (six float chains each and their quantization
/// to `texel_bits`); image sources are the scene's `textures`.
#[must_use]
pub fn env_maps(
    maps: &Maps,
    cubes: &[(u32, EnvSource)],
    hw: &HwConfig,
    textures: &[TextureImage],
) -> Maps {
    let mut out = maps.clone();
    for &(n, source) in cubes {
        for c in cube_chains(n, &*env_sampler(source, textures)) {
            out.fixed.push(quantize_chain(&c, hw.trilinear.texel_bits));
            out.float.push(c);
        }
    }
    out
}

/// The ground-truth plans: every environment plan looks up the level-0 cube per sub-sample.
#[must_use]
pub fn truth_plans(plans: &[Plan], k: u32) -> Vec<Plan> {
    plans
        .iter()
        .map(|p| {
            let mut p = p.clone();
            if let Some(ep) = p.env.as_mut() {
                ep.truth_samples = k.max(1);
            }
            p
        })
        .collect()
}
