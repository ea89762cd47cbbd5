//! One frame, end to end: host geometry (float) -> raster setup and traversal (fixed) ->
//! the planned stages per visible fragment, once with the hardware's twins and once with the
//! float reference -> images, error metrics, per-stage counts and a first cycle estimate.
//!
//! The simulated machine textures visible fragments only (a visibility buffer resolves depth
//! first, then each covered pixel runs its material's stages once), so stage counts and cycles
//! do not depend on triangle order, and the hardware and reference passes see the same
//! fragments by default (shared coverage).
//!
//! The phases, one file each, dependencies one way (the stages never import this module):
//! [`geometry`] (host transforms, lighting, plans), [`shading`] (per-triangle attributes,
//! the compiled programs over every covered pixel, timing events), [`stats`] (what the render
//! measured), [`float_passes`] (the reference and truth kept for the next render on a machine
//! they do not see: sweeps and `texsim tune`); maps come prepared from [`crate::maps`],
//! visibility from [`crate::raster`].

mod float_passes;
mod geometry;
pub mod ranges;
mod shading;
mod stats;

pub use float_passes::{float_blind, float_pass_budget, FloatPassCache, FloatPasses};
pub use geometry::Geometry;
use shading::{bump_attrs, f32_tris, shade, tri_attrs, ShadeInput};
use stats::bump_frames;
pub use stats::{
    BumpStats, DatapathCost, IssueCycles, RenderStats, Rendered, RoughStats, StageStats, Timings,
    UnitCostRow,
};

use crate::fixedpoint::to_unorm;
pub use crate::maps::{bump_sources, ndf_sources, BumpSource, Maps};
use crate::pipeline::stages::{reads_tri_floats, Machine};
use crate::pipeline::{Impl, StageImpls, StageKind, MAX_POINT_LIGHTS};
use crate::raster::{self, Coverage, NO_TRI};
use crate::report::compare;
use crate::scene::Scene;
use crate::timing::events::{PlanTiming, TextureLayout};
use hw_model::HwConfig;
use serde::Serialize;
use std::sync::Arc;
use std::time::Instant;

/// How the reference pass chooses its fragments.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum CoverageMode {
    /// The reference shades exactly the fragments the hardware rasterizer produced.
    Shared,
    /// The reference rasterizes with unsnapped float coverage and float depth.
    Independent,
}

/// What to run.
#[derive(Clone, Debug)]
pub struct RenderOptions {
    /// Twins of the "hardware" image (all Fixed = the machine; one Fixed = that stage alone).
    pub hw_impls: StageImpls,
    /// Also render the all-float reference and compare.
    pub reference: bool,
    pub coverage: CoverageMode,
    /// Run the timing model on the hardware pass (`RenderStats::timing`). Off by default: a
    /// render without it allocates no event buffer and does no extra work per pixel.
    pub timing: bool,
    /// With `timing`, also keep the frame's event stream in `Rendered::events` (for a caller
    /// that replays it, e.g. `timing::simulate`). On by default; a caller that only needs the
    /// cycle counts turns it off and the rows' events are dropped once the model has read them.
    pub keep_events: bool,
    /// Also render the ground truth, with this many sub-samples per pixel axis (0 = off):
    /// roughness materials supersample their full-resolution bump map
    /// (`pipeline::rough`), NDF materials their finest normal map
    /// (`pipeline::ndf::NdfTruth`); the stats gain `model_error` (float vs truth) and
    /// `quantization_error` (hardware vs float).
    pub truth: u32,
    /// Called once per finished phase (setup, raster, hardware shading, reference shading,
    /// ground truth) with its name and wall time in ms (`texsim render` prints them).
    pub progress: Option<fn(&str, f64)>,
    /// Also run the range-instrumented float pass ([`ranges`]): `RenderStats::ranges`.
    pub ranges: bool,
    /// Shade one fragment at a time through every stage (the reference of the default, which
    /// runs each stage over spans of consecutive pixels of one triangle): the same frame.
    pub per_fragment: bool,
    /// The float passes of an earlier render of the same scene ([`FloatPasses`]): used
    /// instead of running them again when they match this render's options.
    pub float_passes: Option<Arc<FloatPasses>>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            hw_impls: StageImpls::FIXED,
            reference: true,
            coverage: CoverageMode::Shared,
            timing: false,
            keep_events: true,
            truth: 0,
            progress: None,
            ranges: false,
            per_fragment: false,
            float_passes: None,
        }
    }
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// Renders `scene` on the machine `hw` (and, if asked, the float reference) and measures both.
pub fn render(
    scene: &Scene,
    maps: &Maps,
    hw: &HwConfig,
    opts: &RenderOptions,
) -> crate::Result<Rendered> {
    hw.validate()?;
    crate::budget::check_run(scene, hw, opts.reference || opts.truth > 0, opts.timing)?;
    let progress = |phase: &str, ms: f64| {
        if let Some(report) = opts.progress {
            report(phase, ms);
        }
    };
    let t_start = Instant::now();
    let mut tm = Timings::default();
    let t = Instant::now();
    let mut geo = Geometry::new(scene);
    tm.geometry_ms = ms(t);
    let bumped = geo.plans.iter().any(|p| p.bump.is_some());
    if bumped && geo.point_lights.len() > MAX_POINT_LIGHTS {
        return Err(crate::Error::field(
            "lights",
            format!(
                "{} point lights; bump-mapped materials shade at most {MAX_POINT_LIGHTS} per pixel",
                geo.point_lights.len()
            ),
        ));
    }
    let offset_bits = hw.shading.vector.offset_int_bits;
    let reencoded;
    let maps = if maps.offset_int_bits == offset_bits || maps.bump_offsets.is_empty() {
        maps
    } else {
        let mut mm = maps.clone();
        mm.ensure_offset_bits(offset_bits);
        reencoded = mm;
        &reencoded
    };
    // NDF chains first: `ensure_ndf` replaces the chains at the end of the list, and the
    // roughness maps of this render are appended after them.
    let ndf_rebuilt;
    let maps = if maps.ndf_stale(&hw.ndf) {
        let mut mm = maps.clone();
        mm.ensure_ndf(&hw.ndf);
        ndf_rebuilt = mm;
        &ndf_rebuilt
    } else {
        maps
    };
    let rough_sources = crate::pipeline::rough::resolve_plans(&mut geo.plans, hw, maps.float.len());
    let has_rough = geo.plans.iter().any(|p| p.rough.is_some());
    let mut d_clamped = 0;
    let rough_owned;
    let maps = if rough_sources.is_empty() {
        maps
    } else {
        let (mm, cl) = crate::pipeline::rough::rough_maps(maps, &rough_sources, hw)?;
        d_clamped = cl;
        rough_owned = mm;
        &rough_owned
    };
    let env_sizes = crate::pipeline::env::resolve_plans(&mut geo.plans, hw, maps.float.len());
    let env_owned;
    let maps = if env_sizes.is_empty() {
        maps
    } else {
        env_owned = crate::pipeline::env::env_maps(maps, &env_sizes, hw, &scene.textures);
        &env_owned
    };
    let toksvig_sources = crate::pipeline::toksvig::resolve_plans(&mut geo.plans, maps.float.len());
    let has_toksvig = !toksvig_sources.is_empty();
    let toksvig_owned;
    let maps = if has_toksvig {
        toksvig_owned = crate::pipeline::toksvig::toksvig_maps(maps, &toksvig_sources, hw)?;
        &toksvig_owned
    } else {
        maps
    };
    let lean_sources = crate::pipeline::lean::resolve_plans(&mut geo.plans, maps.float.len());
    let has_lean = !lean_sources.is_empty();
    let lean_owned;
    let maps = if has_lean {
        lean_owned = crate::pipeline::lean::lean_maps(maps, &lean_sources, hw)?.0;
        &lean_owned
    } else {
        maps
    };
    let lobe_sources =
        crate::pipeline::lobe_fit::resolve_plans(&mut geo.plans, hw, maps.float.len());
    let has_fitted_lobes = !lobe_sources.is_empty();
    let lobes_owned;
    let maps = if has_fitted_lobes {
        lobes_owned = crate::pipeline::lobe_fit::lobe_maps(maps, &lobe_sources, hw)?.0;
        &lobes_owned
    } else {
        maps
    };

    let mut warnings: Vec<String> = Vec::new();
    let mut opts = opts.clone();
    if crate::pipeline::ndf::shade_is_float_only(hw)
        && geo.plans.iter().any(|p| p.ndf.is_some())
        && opts.hw_impls.of(StageKind::NdfShade) == Impl::Fixed
    {
        warnings.push("field 'ndf.ndf_norm': exact is float only: ndf-shade runs in float".into());
        opts.hw_impls = opts.hw_impls.with(StageKind::NdfShade, Impl::Float);
    }
    let opts = &opts;

    // The reference and the truth of an earlier render whose machine differs only in widths
    // they do not read; without them, and for the signal ranges, this render runs its own.
    let kept = opts
        .float_passes
        .as_deref()
        .filter(|fp| fp.fits(scene, opts));
    let float_pass = opts.ranges || (kept.is_none() && (opts.reference || opts.truth > 0));
    let t = Instant::now();
    let setup = raster::setup(&geo.clip, &geo.draws, scene.width, scene.height, &hw.raster);
    let m0 = Machine::new(hw, &maps.float, &maps.fixed).with_lights(&scene.lights, scene.ambient);
    let floats = float_pass || reads_tri_floats(&opts.hw_impls, hw);
    tm.setup_ms = ms(t);
    progress("setup", ms(t_start));

    let t = Instant::now();
    let (vis, raster_stats) = raster::rasterize(&setup, Coverage::Fixed, true);
    tm.raster_ms = ms(t);
    progress("raster", tm.raster_ms);
    // The float passes of Shared coverage shade the hardware's fragments with the depth test
    // at full precision, the depth buffer's float twin: `Some` when that picks other surfaces.
    let t = Instant::now();
    let runs_exact_depth = runs_exact_depth(opts, kept.is_some(), hw);
    let exact_vis = runs_exact_depth
        .then(|| exact_depth_vis(&geo, scene, hw, &setup, &vis))
        .flatten();
    let exact_ms = ms(t);
    if runs_exact_depth {
        progress("exact depth test", exact_ms);
    }
    let float_vis = exact_vis.as_ref().unwrap_or(&vis);

    // The attributes (part of the setup's time) after the raster, which needs only the screen
    // triangles: when the hardware pass is the frame's only shading pass, the triangles it
    // leaves hidden need none converted.
    let t = Instant::now();
    let only_pass = (!floats).then_some(&vis);
    let (mut attrs, floats, mut input_sat) = tri_attrs(&setup, &geo, &m0, floats, only_pass);
    let (battrs, bsat) = bump_attrs(&setup, &geo, &m0, &mut attrs);
    input_sat.add(&bsat);
    let ftris = f32_tris(&setup, &geo, &m0, &mut attrs);
    let m = m0.with_bump_attrs(&battrs).with_f32_tris(&ftris);
    tm.setup_ms += ms(t);
    progress("attributes", ms(t));

    let bg = scene.background.map(|c| to_unorm(f64::from(c), 16) as u16);
    let t = Instant::now();
    let inp = ShadeInput {
        vis: &vis,
        setup: &setup,
        attrs: &attrs,
        floats: &floats,
        geo: &geo,
        m: &m,
        per_fragment: opts.per_fragment,
    };
    let plans: Vec<PlanTiming> = geo
        .plans
        .iter()
        .map(|p| PlanTiming {
            stages: p.stages.iter().map(|&k| (k, m.stage_cost(k, p))).collect(),
        })
        .collect();
    let textures: Vec<TextureLayout> = maps
        .fixed
        .iter()
        .map(|ch| TextureLayout {
            levels: ch.levels.iter().map(|l| (l.width, l.height)).collect(),
            texel_bytes: ch.format.bytes(),
        })
        .collect();
    let sim = opts
        .timing
        .then(|| crate::timing::Simulator::new(&plans, &textures, hw));
    let (hw_image, counters, timed) = shade(&inp, &opts.hw_impls, bg, sim, opts.keep_events);
    let (events, sim) = match timed {
        Some((mut fe, sim)) => {
            fe.triangles = setup.tris.len() as u64;
            fe.spans = raster_stats.spans;
            fe.fragments = raster_stats.fragments;
            fe.plans = plans;
            fe.textures = textures;
            let counts = fe.counts();
            (opts.keep_events.then_some(fe), Some((sim, counts)))
        }
        None => (None, None),
    };
    tm.shade_hw_ms = ms(t);
    progress("hardware shading", tm.shade_hw_ms);
    tm.hw_total_ms = tm.setup_ms + tm.raster_ms + tm.shade_hw_ms;

    // The compared pixels: those the hardware or the float passes cover.
    let mut mask: Vec<bool> = vis
        .tri
        .iter()
        .zip(&float_vis.tri)
        .map(|(&h, &f)| h != NO_TRI || f != NO_TRI)
        .collect();
    if let Some(fp) = kept {
        for (mk, &k) in mask.iter_mut().zip(&fp.mask) {
            *mk |= k;
        }
    }
    let mut ref_image = None;
    let mut ref_nonfinite = 0;
    let (mut e8, mut e16) = (None, None);
    if let Some((img, nonfinite)) = kept.and_then(|fp| fp.reference.as_ref()) {
        ref_nonfinite = *nonfinite;
        e8 = Some(compare(&hw_image, img, 8, Some(&mask)));
        e16 = Some(compare(&hw_image, img, 16, Some(&mask)));
        ref_image = Some(img.clone());
    } else if opts.reference {
        let t_ref = Instant::now();
        let ref_vis;
        let rv = match opts.coverage {
            CoverageMode::Shared => {
                tm.raster_ref_ms = tm.raster_ms + exact_ms;
                float_vis
            }
            CoverageMode::Independent => {
                let t = Instant::now();
                ref_vis = raster::rasterize(&setup, Coverage::Float, true).0;
                tm.raster_ref_ms = ms(t);
                for (mk, &t) in mask.iter_mut().zip(&ref_vis.tri) {
                    *mk |= t != NO_TRI;
                }
                &ref_vis
            }
        };
        let t = Instant::now();
        let rinp = ShadeInput { vis: rv, ..inp };
        let (img, rc, _) = shade(&rinp, &StageImpls::FLOAT, bg, None, false);
        ref_nonfinite = rc.nonfinite;
        tm.shade_ref_ms = ms(t);
        progress("reference", ms(t_ref));
        tm.ref_total_ms = tm.setup_ms + tm.raster_ref_ms + tm.shade_ref_ms;
        e8 = Some(compare(&hw_image, &img, 8, Some(&mask)));
        e16 = Some(compare(&hw_image, &img, 16, Some(&mask)));
        ref_image = Some(img);
    }
    let ranges = opts.ranges.then(|| ranges::measure(&inp));
    let mut truth_image = None;
    let has_ndf = geo.plans.iter().any(|p| p.ndf.is_some());
    let has_env = geo.plans.iter().any(|p| p.env.is_some());
    if let Some(fp) = kept {
        truth_image.clone_from(&fp.truth);
    } else if opts.truth > 0
        && (has_rough || has_ndf || has_env || has_toksvig || has_lean || has_fitted_lobes)
    {
        let t_truth = Instant::now();
        // One float pass over every material: roughness materials shade their supersampled
        // bump map (`rough::truth_plans`), NDF materials their supersampled finest normal
        // map (`ndf::NdfTruth`), all others are their own float reference.
        let tp = crate::pipeline::rough::truth_plans(&geo.plans, opts.truth);
        let tp = crate::pipeline::env::truth_plans(&tp, opts.truth);
        let tp = crate::pipeline::toksvig::truth_plans(tp, opts.truth);
        let tp = crate::pipeline::lean::truth_plans(tp, opts.truth);
        let tp = crate::pipeline::lobe_fit::truth_plans(tp, opts.truth);
        let saved = std::mem::replace(&mut geo.plans, tp);
        let ndf_truth = crate::pipeline::ndf::truth_maps(maps, scene, &geo.plans, opts.truth);
        let mt = Machine::new(hw, &maps.float, &maps.fixed)
            .with_lights(&scene.lights, scene.ambient)
            .with_bump_attrs(&battrs)
            .with_f32_tris(&ftris)
            .with_ndf_truth(&ndf_truth);
        let tin = ShadeInput {
            vis: float_vis,
            setup: &setup,
            attrs: &attrs,
            floats: &floats,
            geo: &geo,
            m: &mt,
            per_fragment: opts.per_fragment,
        };
        let (img, _, _) = shade(&tin, &StageImpls::FLOAT, bg, None, false);
        geo.plans = saved;
        truth_image = Some(img);
        progress("ground truth", ms(t_truth));
    }
    let model_error = match (&ref_image, &truth_image) {
        (Some(r), Some(t)) => Some(compare(r, t, 8, Some(&mask))),
        _ => None,
    };
    let roughness = has_rough.then(|| RoughStats {
        d_clamped,
        truth_samples: if truth_image.is_some() { opts.truth } else { 0 },
        model_error: model_error.clone(),
        quantization_error: e8.clone(),
        baseline_error: None,
    });

    let mut stages = Vec::with_capacity(StageKind::COUNT);
    let mut stage_issue = 0u64;
    for kind in StageKind::ALL {
        let k = kind.index();
        let inv = counters.invocations[k];
        let [ops, cyc, texels] = counters.cost[k];
        let s = StageStats {
            stage: kind,
            imp: opts.hw_impls.of(kind),
            invocations: inv,
            saturated: counters.sat[k].saturated,
            wrapped: counters.sat[k].wrapped,
            ops,
            issue_cycles: cyc,
            texels,
        };
        stage_issue += s.issue_cycles;
        stages.push(s);
    }
    let covered = vis.tri.iter().filter(|&&t| t != NO_TRI).count() as u64;
    let rc = &hw.raster;
    let mut issue_cycles = IssueCycles {
        setup: setup.tris.len() as u64 * u64::from(rc.setup_cycles),
        spans: raster_stats.spans * u64::from(rc.span_cycles),
        stages: stage_issue,
        ..Default::default()
    };
    issue_cycles.total = issue_cycles.setup + issue_cycles.spans + issue_cycles.stages;
    issue_cycles.per_covered_pixel = issue_cycles.total as f64 / covered.max(1) as f64;
    if crate::pipeline::ndf::shade_is_float_only(hw)
        && counters.invocations[StageKind::NdfShade.index()] > 0
    {
        issue_cycles.not_modelled = Some(crate::pipeline::ndf::EXACT_NOT_MODELLED);
    }
    // The frame's cycles: the timing model, fed the hardware pass's pixels while it shaded
    // (none for a stage without a hardware cost model).
    let timing = match (sim, issue_cycles.not_modelled) {
        (Some((sim, counts)), None) => {
            let t = Instant::now();
            let rep = sim.finish(&counts, &scene.name);
            tm.timing_ms = ms(t);
            progress("timing model", tm.timing_ms);
            Some(rep)
        }
        _ => None,
    };

    Ok(Rendered {
        hw_image,
        ref_image,
        truth_image,
        mask,
        events,
        stats: RenderStats {
            scene: scene.name.clone(),
            hw: hw.name.clone(),
            width: scene.width,
            height: scene.height,
            triangles: scene.triangle_count() as u64,
            coverage: opts.coverage,
            setup: setup.stats,
            raster: raster_stats,
            covered_pixels: covered,
            input_saturated: input_sat.saturated,
            input_wrapped: input_sat.wrapped,
            bump: BumpStats {
                frame_fallback: counters.frame_fallback,
                zero_normal: counters.zero_normal,
                h_zero: counters.h_zero,
                nonfinite: counters.nonfinite,
                ref_nonfinite,
                offset_clamped: if bumped { maps.bump_clamped } else { 0 },
                ndf_clamped: maps.ndf_clamped,
                frame: bump_frames(&geo, hw),
            },
            stages,
            issue_cycles,
            timing,
            datapath: DatapathCost::of(hw),
            timings: tm,
            quantization_error: if model_error.is_some() {
                e8.clone()
            } else {
                None
            },
            model_error,
            error_8bit: e8,
            error_16bit: e16,
            roughness,
            ranges,
            warnings: {
                warnings.extend(crate::warnings::depth_warning(
                    scene,
                    setup.depth_bits,
                    &raster_stats,
                ));
                warnings
            },
        },
    })
}

/// Whether a render runs [`exact_depth_vis`]: its own float passes (none `kept`) with shared
/// coverage, on a depth buffer narrower than [`raster::MAX_DEPTH_BITS`].
fn runs_exact_depth(opts: &RenderOptions, kept: bool, hw: &HwConfig) -> bool {
    !kept
        && (opts.reference || opts.truth > 0)
        && opts.coverage == CoverageMode::Shared
        && hw.raster.depth_bits < raster::MAX_DEPTH_BITS
}

/// The visibility of `vis`'s fragments with the depth test at full precision (the depth
/// buffer's float twin): the triangles of `setup` set up again with
/// [`raster::MAX_DEPTH_BITS`]-bit vertex depths and rasterized (the same triangles in the same
/// order, the same edges, hence the same fragments). `None` when it picks the surface `vis`
/// shows at every pixel (at 24 bits on every built-in scene).
fn exact_depth_vis(
    geo: &Geometry,
    scene: &Scene,
    hw: &HwConfig,
    setup: &raster::Setup,
    vis: &raster::VisBuffer,
) -> Option<raster::VisBuffer> {
    let cfg = hw_model::config::RasterConfig {
        depth_bits: raster::MAX_DEPTH_BITS,
        ..hw.raster.clone()
    };
    let exact = raster::setup(&geo.clip, &geo.draws, scene.width, scene.height, &cfg);
    debug_assert_eq!(exact.tris.len(), setup.tris.len());
    let exact = raster::rasterize(&exact, Coverage::Fixed, true).0;
    (exact.tri != vis.tri).then_some(exact)
}
