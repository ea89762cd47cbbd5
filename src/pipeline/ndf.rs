//! What the NDF-mapping stages share (Olano and North 1997, "Normal Distribution Mapping",
//! sections 5-6): their plan, fragment signals, unit and ground truth. The stages are one file
//! each: [`super::ndf_fetch`] (LOD against the moment maps' size, then three trilinear lookups
//! of the moment maps A, B, C through the unchanged trilinear unit, a fourth of the
//! normalization map when `ndf_norm = map`) and [`super::ndf_shade`] (per light: `h` in the
//! local frame, then `hw_model::ndf::NdfUnit`, times `ks` and the light; plus Lambert diffuse
//! on the interpolated normal and the ambient term).
//!
//! An NDF material is a bump material (its `bump` texture is the normal or height map the
//! moment maps are built from) whose plan runs `bary`, `texcoord`, `normal`, `frame` of the
//! bump path, then `ndf-fetch` and `ndf-shade` instead of `bump-fetch`, `perturb`, `phong`.
//! The frame's directions `t_u`, `t_v`, `n` are the basis of the moment maps' tangent space (the
//! offsets `(f_u, f_v)` of the bump path give the texel normal `normalize(f_u, f_v, 1)`); the
//! natural frame's lengths are not used. `h` is renormalized after the change of basis.
//!
//! The specular term is `ks light D 2 pi / s` with `s` the base shininess: `2 pi / s` is the
//! inverse peak of the normalized base lobe (von Mises-Fisher, `crate::shading::ndf::base_lobe`),
//! so a flat texel has a highlight of peak `ks` under the exact normalization; the other options
//! show their normalization error as brightness. `ndf_norm = exact` has no fixed twin: `render`
//! runs `ndf-shade` in float and says so.

use super::{Plan, StageKind};
use glam::DVec3;
use hw_model::config::HwConfig;
use hw_model::ndf::{NdfNorm, NdfUnit};

/// What the NDF stages of one material need.
#[derive(Clone, Debug, PartialEq)]
pub struct NdfPlan {
    /// Index of moment map A in the prepared maps; B, C and the normalization map follow.
    pub maps: usize,
    /// Base shininess of the moment maps.
    pub shininess: u32,
    /// The normalization map stores `(1/Z) / 2^norm_exp`.
    pub norm_exp: u32,
}

/// Per-fragment signals of the NDF stages.
#[derive(Clone, Copy, Debug, Default)]
pub struct NdfFrag {
    /// Filtered maps A, B, C, normalization: raw (`moment_bits` unorm) and carriers (0..1).
    pub texel_x: [[u16; 4]; 4],
    pub texel: [[f64; 4]; 4],
}

/// The fixed NDF unit of `hw` (`None` for `ndf_norm = exact` or an invalid config).
#[must_use]
pub fn ndf_unit(hw: &HwConfig) -> Option<NdfUnit> {
    NdfUnit::new(&hw.ndf, &hw.reciprocal, &hw.shading.rsqrt).ok()
}

/// Turns the plan of an NDF material (planned as a bump material) into the NDF plan: the
/// bump path's `bump-fetch`, `perturb`, `phong` are replaced by `ndf-fetch`, `ndf-shade`.
#[must_use]
pub fn with_ndf(mut plan: Plan, maps: usize, shininess: u32, norm_exp: u32) -> Plan {
    if plan.bump.is_none() {
        return plan;
    }
    plan.stages.retain(|k| {
        !matches!(
            k,
            StageKind::BumpFetch | StageKind::Perturb | StageKind::Phong
        )
    });
    plan.stages
        .extend([StageKind::NdfFetch, StageKind::NdfShade]);
    plan.ndf = Some(NdfPlan {
        maps,
        shininess,
        norm_exp,
    });
    plan
}

/// The ground truth of one set of moment maps: the finest unit normals (tangent space), their
/// size, the base shininess and the requested sub-samples per axis. The truth of a pixel is
/// [`crate::shading::ndf::ground_truth`]: the exactly normalized base lobes of the finest
/// normals averaged over the pixel's footprint parallelogram in texture space (the texture
/// coordinates' derivatives), `samples x samples` sub-samples at least and at least one per
/// texel the footprint crosses.
#[derive(Clone, Debug)]
pub struct NdfTruth {
    /// Index of moment map A of the set (as in [`NdfPlan::maps`]).
    pub maps: usize,
    pub width: u32,
    pub height: u32,
    pub normals: Vec<DVec3>,
    pub shininess: f64,
    /// Sub-samples per footprint axis at least (`--truth N`).
    pub samples: u32,
}

/// The truth data of every NDF plan in `plans` from the maps' finest offsets, with at least
/// `samples x samples` sub-samples per pixel.
#[must_use]
pub fn truth_maps(
    maps: &crate::maps::Maps,
    scene: &crate::scene::Scene,
    plans: &[Plan],
    samples: u32,
) -> Vec<NdfTruth> {
    let first = scene.textures.len() + maps.bump_offsets.len();
    let mut out: Vec<NdfTruth> = Vec::new();
    for np in plans.iter().filter_map(|p| p.ndf.as_ref()) {
        if out.iter().any(|t| t.maps == np.maps) || np.maps < first {
            continue;
        }
        let Some(&(k, s)) = maps.ndf.get((np.maps - first) / 4) else {
            continue;
        };
        let Some((w, h, _, offs)) = maps.bump_offsets.get(k) else {
            continue;
        };
        out.push(NdfTruth {
            maps: np.maps,
            width: *w,
            height: *h,
            normals: offs
                .iter()
                .map(|o| {
                    let n = DVec3::new(f64::from(o[0]), f64::from(o[1]), 1.0).normalize();
                    if n.is_finite() {
                        n
                    } else {
                        DVec3::Z
                    }
                })
                .collect(),
            shininess: f64::from(s),
            samples: samples.max(1),
        });
    }
    out
}

/// True when the fixed `ndf-shade` cannot run on `hw` (`ndf_norm = exact`: float only).
#[must_use]
pub fn shade_is_float_only(hw: &HwConfig) -> bool {
    hw.ndf.ndf_norm == NdfNorm::Exact
}

/// Why a render with `ndf_norm = exact` has no cycle count (`IssueCycles::not_modelled`).
pub const EXACT_NOT_MODELLED: &str =
    "ndf-shade with ndf_norm = exact is float only: no hardware cost model";
