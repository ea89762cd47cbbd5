//! What the fitted-lobe stages share (Fournier 1992, sec. 3.2: the NDF under a texel as a sum
//! of Phong peaks, fitted to a bump map): their plan, the lobe maps and the ground-truth plans.
//! The stages are one file each: [`super::lobe_fetch`] reads the fitted lobes of the pixel's
//! texel through the trilinear unit, [`super::lobe_shade`] shades them with the multi-lobe
//! unit (`hw_model::multi_lobe`) instead of `phong`.
//!
//! A bump material with `fournier_lobes = K` (or `"hw"`: the hardware's
//! `multi_lobe.fournier_lobes`; and no roughness map, NDF, environment map, Toksvig or LEAN
//! filter, or Ashikhmin-Shirley BRDF) gets these stages; any other costs nothing extra.
//!
//! - Fit: per texel and MIP level, K lobes fitted to the finest offsets under the texel
//!   (`shading::fournier_fit::fit_pyramid`, every level from the finest map; through the
//!   in-process cache `fit_pyramid_cached`, so a sweep fits each map once), as normals
//!   `normalize(f_u, f_v, 1)` of the offset space (the frame the perturbation decodes offsets
//!   in; exact where the frame is orthonormal with unit lengths), under the material's Phong
//!   exponent.
//! - Storage: lobe `j` of every texel is map `map + j`, one texel `[p, q, c, n]` per lobe
//!   (`quantize_fit`: slopes `p = x / z`, `q = y / z` in the slope format stored offset-binary,
//!   the lobe's weight `alpha` as amplitude, exponent `n`; the multi-lobe unit's specular
//!   weight is `alpha n / s`), four 16-bit channels; a texel with fewer lobes has zero
//!   amplitudes.
//!   The amplitude channel holds at most `2^16 - 1`: at `lobe_amp_bits = 16` an amplitude of
//!   exactly 1.0 (a flat texel) is stored `1 - 2^-16`. The float chains hold the unquantized
//!   `[p, q, c, n]` (the float reference's lobes).
//! - Between MIP levels (`multi_lobe.lobe_level_mix`): the nearest level and the nearest texel
//!   (lobes do not average linearly, so no bilinear or trilinear blend of lobe parameters): one
//!   single-level lookup per lobe at the texel's centre (weights 0), whose footprint the timing
//!   model sees; or `blend`: the two levels around the LOD, each its nearest texel, both shaded
//!   and the colours blended by the LOD fraction (2K lookups, two shadings).
//! - Ground truth: the roughness stages' (supersampled plain Blinn-Phong of the finest
//!   offsets, `rough-shade` in truth mode), as for Toksvig and LEAN.

use super::rough::{decoded_offsets, RoughPlan};
use super::{BumpPlan, Plan, Px, StageKind};
use crate::maps::Maps;
use crate::maps::{FixedLevel, FixedMipChain, MipChain, MipLevel, TexelFormat};
use crate::scene::{BumpFilter, LobeCount, Material};
use crate::shading::fournier_fit::{fit_pyramid_cached, quantize_fit, FitConfig, LevelFit};
use crate::shading::multi_lobe::LobeF;
use glam::DVec3;
use hw_model::config::HwConfig;
use hw_model::multi_lobe::{Lobe, MAX_LOBES};
use hw_model::roughness::RoughVariant;
use std::sync::Arc;

/// What the fitted-lobe stages of one material need.
#[derive(Clone, Debug, PartialEq)]
pub struct FittedLobes {
    /// The material's lobe count.
    pub count: LobeCount,
    /// Lobes per texel on this machine (set by [`resolve_plans`]).
    pub lobes: u32,
    /// Index of the map of lobe 0 (lobe `j` is `map + j`; set by [`resolve_plans`]).
    pub map: usize,
    /// The plan's stages before the lobe stages replaced `bump-fetch`, `perturb` and `phong`
    /// (the ground truth shades them).
    pub plain_stages: Vec<StageKind>,
}

/// Per-fragment signals of `lobe-fetch`: the fetched lobe texels (raw and float) and their
/// number; with `lobe_level_mix = "blend"` also the coarser level's texels and its weight.
#[derive(Clone, Copy, Debug, Default)]
pub struct LobeFrag {
    pub texel_x: [[u16; 4]; MAX_LOBES as usize],
    pub texel: [[f32; 4]; MAX_LOBES as usize],
    pub count: u8,
    /// Blend: the coarser level's texels were fetched (`coarse_x` fixed, `coarse` float).
    pub blend: bool,
    pub coarse_x: [[u16; 4]; MAX_LOBES as usize],
    pub coarse: [[f32; 4]; MAX_LOBES as usize],
    /// Weight of the coarser level: raw (`lod_frac_bits` fraction bits) and float.
    pub weight_x: u32,
    pub weight: f64,
}

/// Marks the bump plan of a `fournier_lobes` material (after the other bump planners: a plan
/// that no longer shades with `phong`, or has another filter, is left alone).
pub fn mark_plan(plan: &mut Plan, material: &Material) {
    let Some(count) = material.fournier_lobes else {
        return;
    };
    if material.bump_filter != BumpFilter::Plain
        || plan.bump.is_none()
        || plan.aniso.is_some()
        || plan.rough.is_some()
        || plan.ndf.is_some()
        || plan.env.is_some()
        || plan.toksvig.is_some()
        || plan.lean.is_some()
        || plan.lobes.is_some()
        || !plan.stages.contains(&StageKind::Phong)
    {
        return;
    }
    plan.lobes = Some(super::lobe_shade::LobePlan {
        lobes: Vec::new(),
        fitted: Some(FittedLobes {
            count,
            lobes: 0,
            map: usize::MAX,
            plain_stages: plan.stages.clone(),
        }),
    });
}

/// The bump plan and the fitted lobes of the pixel's material; `None` without either.
#[inline]
pub(super) fn fitted_of<'a>(px: &Px<'a>) -> Option<(&'a BumpPlan, &'a FittedLobes)> {
    Some((
        px.plan.bump.as_ref()?,
        px.plan.lobes.as_ref()?.fitted.as_ref()?,
    ))
}

/// One fitted lobe map set to build: the offset map, K and the Phong exponent of the fit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LobeSource {
    pub offset_map: usize,
    pub lobes: u32,
    pub shininess: u32,
}

/// Numbers the lobe maps from `first_map` (K maps per distinct source, in the order of the
/// returned sources) and sets the stages: `bump-fetch` and `perturb` dropped (the lobes
/// replace the offsets), `phong` replaced by `lobe-fetch`, `lobe-shade`.
pub fn resolve_plans(plans: &mut [Plan], hw: &HwConfig, first_map: usize) -> Vec<LobeSource> {
    let mut sources: Vec<LobeSource> = Vec::new();
    for plan in plans.iter_mut() {
        let Some(bp) = &plan.bump else { continue };
        let (offset_map, shininess) = (bp.map, bp.shininess);
        let Some(fl) = plan.lobes.as_mut().and_then(|l| l.fitted.as_mut()) else {
            continue;
        };
        let src = LobeSource {
            offset_map,
            lobes: fl.count.resolve(hw).clamp(1, MAX_LOBES),
            shininess,
        };
        let k = sources.iter().position(|&s| s == src).unwrap_or_else(|| {
            sources.push(src);
            sources.len() - 1
        });
        fl.lobes = src.lobes;
        fl.map = first_map + sources[..k].iter().map(|s| s.lobes as usize).sum::<usize>();
        let mut stages = Vec::with_capacity(fl.plain_stages.len() + 1);
        for &s in &fl.plain_stages {
            match s {
                StageKind::BumpFetch | StageKind::Perturb => {}
                StageKind::Phong => stages.extend([StageKind::LobeFetch, StageKind::LobeShade]),
                _ => stages.push(s),
            }
        }
        plan.stages = stages;
    }
    sources
}

/// The stored texel of one lobe: slopes offset-binary, amplitude (at most `2^16 - 1`),
/// exponent.
#[must_use]
pub fn encode_lobe(l: &Lobe) -> [u16; 4] {
    let s = |x: i64| (x + (1 << 15)).clamp(0, 0xFFFF) as u16;
    [
        s(l.slope[0]),
        s(l.slope[1]),
        l.amp.min(0xFFFF) as u16,
        l.exponent.min(0xFFFF) as u16,
    ]
}

/// The lobe of a stored texel ([`encode_lobe`]'s inverse).
#[must_use]
pub fn decode_lobe(t: [u16; 4]) -> Lobe {
    Lobe {
        slope: [i64::from(t[0]) - (1 << 15), i64::from(t[1]) - (1 << 15)],
        amp: u64::from(t[2]),
        exponent: u32::from(t[3]),
    }
}

/// The float lobe of a float texel `[p, q, c, n]` (the exponent rounded: the float unit takes
/// integer exponents).
#[must_use]
pub fn float_lobe(t: [f32; 4]) -> LobeF {
    LobeF {
        slope: [f64::from(t[0]), f64::from(t[1])],
        amp: f64::from(t[2]),
        exponent: f64::from(t[3]).round().clamp(0.0, f64::from(u32::MAX)) as u32,
    }
}

/// What fitting one source cost and left (per level).
#[derive(Clone, Debug)]
pub struct LobeMapStats {
    pub source: LobeSource,
    pub levels: Arc<Vec<LevelFit>>,
    /// The fit came from the in-process cache (`fournier_fit::fit_pyramid_cached`).
    pub cached: bool,
}

/// `maps` with the lobe maps of `sources` appended (K float chains and their stored
/// quantization per source), and the fits' per-level statistics.
pub fn lobe_maps(
    maps: &Maps,
    sources: &[LobeSource],
    hw: &HwConfig,
) -> crate::Result<(Maps, Vec<LobeMapStats>)> {
    let cfg = &hw.multi_lobe;
    if 1 + cfg.lobe_slope_int_bits + cfg.lobe_slope_frac_bits > 16 {
        return Err(crate::Error::field(
            "multi_lobe.lobe_slope_frac_bits",
            "fitted lobe slopes are stored in 16-bit channels: 1 + lobe_slope_int_bits + lobe_slope_frac_bits must be <= 16",
        ));
    }
    let mut out = maps.clone();
    let mut stats = Vec::with_capacity(sources.len());
    for &src in sources {
        let Some(chain) = maps.float.get(src.offset_map) else {
            return Err(crate::Error::msg(format!(
                "fournier_lobes: offset map {} does not exist",
                src.offset_map
            )));
        };
        let (w, h, offs) = decoded_offsets(chain, maps.offset_int_bits);
        let normals: Vec<DVec3> = offs
            .iter()
            .map(|o| DVec3::new(f64::from(o[0]), f64::from(o[1]), 1.0).normalize())
            .collect();
        let fc = FitConfig {
            lobes: src.lobes as usize,
            shininess: f64::from(src.shininess.max(1)),
            ..FitConfig::default()
        };
        let (levels, cached) = fit_pyramid_cached(&normals, w, h, &fc)?;
        let s = fc.shininess;
        for j in 0..src.lobes as usize {
            let mut float = Vec::with_capacity(levels.len());
            let mut fixed = Vec::with_capacity(levels.len());
            for lv in levels.iter() {
                let mut ft = Vec::with_capacity(lv.texels.len());
                let mut xt = Vec::with_capacity(lv.texels.len());
                for t in &lv.texels {
                    let mut sat = hw_model::SatCounter::default();
                    let stored = quantize_fit(t, s, cfg, &mut sat);
                    match (t.lobes.get(j), stored.get(j)) {
                        (Some(l), Some(q)) => {
                            let p = l.to_stored(s);
                            let z = p.direction.z.max(1e-9);
                            ft.push([
                                (p.direction.x / z) as f32,
                                (p.direction.y / z) as f32,
                                p.amplitude as f32,
                                p.exponent as f32,
                            ]);
                            xt.push(encode_lobe(q));
                        }
                        _ => {
                            ft.push([0.0; 4]);
                            xt.push(encode_lobe(&Lobe::default()));
                        }
                    }
                }
                float.push(MipLevel {
                    width: lv.width,
                    height: lv.height,
                    texels: ft,
                });
                fixed.push(FixedLevel {
                    width: lv.width,
                    height: lv.height,
                    texels: xt,
                });
            }
            out.float.push(MipChain { levels: float });
            out.fixed.push(FixedMipChain {
                texel_bits: 16,
                format: TexelFormat {
                    channels: 4,
                    bits: 16,
                },
                levels: fixed,
            });
        }
        stats.push(LobeMapStats {
            source: src,
            levels,
            cached,
        });
    }
    Ok((out, stats))
}

/// The ground-truth plans: every fitted-lobe plan goes back to its plain bump stages with
/// `phong` as a roughness plan of variant `none` in truth mode (`rough-shade` supersampling
/// plain Blinn-Phong, `k` sub-samples per axis).
#[must_use]
pub fn truth_plans(plans: Vec<Plan>, k: u32) -> Vec<Plan> {
    plans
        .into_iter()
        .map(|mut p| {
            let fitted = p.lobes.as_ref().and_then(|l| l.fitted.clone());
            if let Some(fl) = fitted {
                p.lobes = None;
                p.rough = Some(RoughPlan {
                    choice: crate::scene::RoughChoice::Variant(RoughVariant::None),
                    variant: RoughVariant::None,
                    map: usize::MAX,
                    truth_samples: k.max(1),
                });
                p.stages = fl
                    .plain_stages
                    .iter()
                    .map(|&s| {
                        if s == StageKind::Phong {
                            StageKind::RoughShade
                        } else {
                            s
                        }
                    })
                    .collect();
            }
            p
        })
        .collect()
}
