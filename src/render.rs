//! One frame, end to end: host geometry (float) -> raster setup and traversal (fixed) ->
//! the planned stages per visible fragment, once with the hardware's twins and once with the
//! float reference -> images, error metrics, per-stage counts and a first cycle estimate.
//!
//! The simulated machine textures visible fragments only (a visibility buffer resolves depth
//! first, then each covered pixel runs its material's stages once), so stage counts and cycles
//! do not depend on triangle order, and the hardware and reference passes see the same
//! fragments by default (shared coverage).

use crate::fixedpoint::to_unorm;
pub use crate::maps::{bump_sources, ndf_sources, BumpSource, Maps};
use crate::pipeline::bump_stages::{BumpAttrs, BumpVertex};
use crate::pipeline::stages::{output16, run, Counters, Machine, TriAttrs};
use crate::pipeline::{
    plan_with_bump, BumpPlan, Frag, Impl, Plan, Program, StageImpls, StageKind, MAX_POINT_LIGHTS,
};
use crate::raster::{self, Coverage, DrawTri, RasterStats, Setup, SetupStats, VisBuffer, NO_TRI};
use crate::report::{compare, ErrorMetrics, Image};
use crate::scene::{Light, Scene};
use crate::scene::{MainDirection, Mesh};
use crate::shading::reference as fref;
use crate::shading::tangents::{generate_tangents, generate_uv_derivatives};
use crate::timing::events::{record_pixel, FrameEvents, PlanTiming, RowEvents};
use glam::DVec3;
use hw_model::fixed::SatCounter;
use hw_model::{HwConfig, UnitCost};
use rayon::prelude::*;
use serde::Serialize;
use std::time::Instant;

/// Host-side geometry: clip-space vertices, Gouraud vertex colours, texture coordinates, the
/// triangles to draw and the plan of each mesh.
pub struct Geometry {
    pub clip: Vec<[f64; 4]>,
    pub color: Vec<[f64; 3]>,
    pub uv: Vec<[f64; 2]>,
    /// Per-vertex bump data: empty unless some plan is bump mapped (then one per vertex;
    /// default for vertices of other meshes).
    pub bump: Vec<BumpVertex>,
    /// World-space eye position and point-light positions (bump shading).
    pub eye: [f64; 3],
    pub point_lights: Vec<[f64; 3]>,
    pub draws: Vec<DrawTri>,
    /// Plan index of each draw.
    pub draw_plan: Vec<u32>,
    /// One plan per mesh.
    pub plans: Vec<Plan>,
}

impl Geometry {
    /// Transforms, lights (per vertex, float) and plans every mesh of `scene`.
    #[must_use]
    pub fn new(scene: &Scene) -> Self {
        let aspect = f64::from(scene.width) / f64::from(scene.height.max(1));
        let vp = scene.camera.projection(aspect) * scene.camera.view();
        let n: usize = scene.meshes.iter().map(|m| m.positions.len()).sum();
        let mut g = Geometry {
            clip: Vec::with_capacity(n),
            color: Vec::with_capacity(n),
            uv: Vec::with_capacity(n),
            draws: Vec::with_capacity(scene.triangle_count()),
            draw_plan: Vec::with_capacity(scene.triangle_count()),
            plans: Vec::with_capacity(scene.meshes.len()),
            bump: Vec::new(),
            eye: scene
                .camera
                .view()
                .inverse()
                .transform_point3(DVec3::ZERO)
                .to_array(),
            point_lights: scene
                .lights
                .iter()
                .filter_map(|l| match l {
                    Light::Point { position, .. } => Some(position.map(f64::from)),
                    Light::Directional { .. } => None,
                })
                .collect(),
        };
        let sources = bump_sources(scene);
        let ndf_srcs = ndf_sources(scene);
        for (mi, mesh) in scene.meshes.iter().enumerate() {
            let mat = &scene.materials[mesh.material];
            let base = g.clip.len() as u32;
            let kd = DVec3::from(mat.kd.map(f64::from));
            for (vi, p) in mesh.positions.iter().enumerate() {
                let p = DVec3::from(p.map(f64::from));
                g.clip.push((vp * p.extend(1.0)).to_array());
                let c = if mat.lit {
                    let nrm = mesh
                        .normals
                        .get(vi)
                        .map_or(DVec3::Z, |n| DVec3::from(n.map(f64::from)));
                    kd * lighting(scene, p, nrm.normalize_or_zero())
                } else {
                    kd
                };
                g.color.push(c.clamp(DVec3::ZERO, DVec3::ONE).to_array());
                g.uv.push(mesh.uvs.get(vi).map_or([0.0; 2], |t| t.map(f64::from)));
            }
            let bump_map = BumpSource::of(mat).and_then(|b| {
                sources
                    .iter()
                    .position(|o| o.same(&b))
                    .map(|k| scene.textures.len() + k)
            });
            let mut p = plan_with_bump(mat, !mesh.uvs.is_empty(), bump_map);
            crate::pipeline::rough_stages::mark_plan(&mut p, mat);
            if mat.ndf {
                let first = scene.textures.len() + sources.len();
                if let Some(j) = bump_map.and_then(|b| {
                    ndf_srcs
                        .iter()
                        .position(|&s| s == (b - scene.textures.len(), mat.shininess))
                }) {
                    let ne = crate::shading::ndf::norm_exp_for(f64::from(mat.shininess));
                    p = crate::pipeline::ndf_stages::with_ndf(p, first + 4 * j, mat.shininess, ne);
                }
            }
            if let Some(bp) = &p.bump {
                g.bump.resize(base as usize, BumpVertex::default());
                g.bump.extend(bump_vertices(mesh, bp));
            }
            g.plans.push(p);
            for t in &mesh.indices {
                g.draws.push(DrawTri {
                    v: t.map(|i| base + i),
                    cull_back: mat.cull_back,
                });
                g.draw_plan.push(mi as u32);
            }
        }
        g
    }
}

/// Per-vertex bump data of `mesh` (Schilling 1997 frame 1 via `reference::natural_vertex`,
/// with per-object reference lengths: the mean `|p_u x p_v| / |p_v|` and `/ |p_u|`). Where the
/// natural frame is undefined (UV-degenerate vertex), the directions come from the fallback
/// tangent of `tangents::generate_tangents` (`d_u = -T`, `d_v = -B`) with length 1.
fn bump_vertices(mesh: &Mesh, bp: &BumpPlan) -> Vec<BumpVertex> {
    let (pos, nor, uvs, idx) = (&mesh.positions, &mesh.normals, &mesh.uvs, &mesh.indices);
    let der = generate_uv_derivatives(pos, nor, uvs, idx);
    let tan = generate_tangents(pos, nor, uvs, idx);
    let v3 = |a: [f32; 3]| DVec3::from(a.map(f64::from));
    let (mut ru, mut rv, mut cnt) = (0.0, 0.0, 0.0);
    for d in &der {
        let (pu, pv) = (v3(d[0]), v3(d[1]));
        let g = pu.cross(pv).length();
        if g > 0.0 && g.is_finite() {
            ru += g / pv.length();
            rv += g / pu.length();
            cnt += 1.0;
        }
    }
    let (ref_u, ref_v) = if cnt > 0.0 {
        (ru / cnt, rv / cnt)
    } else {
        (1.0, 1.0)
    };
    pos.iter()
        .enumerate()
        .map(|(i, p)| {
            let n = nor.get(i).map_or(DVec3::Z, |&n| v3(n));
            let n = fref::normalize_or(n, DVec3::Z).0;
            let t = tan.get(i).copied().unwrap_or([1.0, 0.0, 0.0, 1.0]);
            let tt = DVec3::new(f64::from(t[0]), f64::from(t[1]), f64::from(t[2]));
            let bb = f64::from(t[3]) * n.cross(tt);
            let d = der.get(i).copied().unwrap_or([[0.0; 3]; 2]);
            let (pu, pv) = (v3(d[0]), v3(d[1]));
            let (du, dv, len) = match fref::natural_vertex(n, pu, pv, ref_u, ref_v) {
                Some(nv) => (nv.dir_u, nv.dir_v, [nv.len_u, nv.len_v]),
                None => (-tt, -bb, [1.0, 1.0]),
            };
            let m = match bp.main {
                MainDirection::Pu => fref::normalize_or(pu, tt).0,
                MainDirection::Pv => fref::normalize_or(pv, bb).0,
                MainDirection::Constant(_) => DVec3::ZERO,
            };
            let fin = |v: DVec3| {
                if v.is_finite() {
                    v.to_array()
                } else {
                    [0.0; 3]
                }
            };
            BumpVertex {
                n: fin(n),
                du: fin(du),
                dv: fin(dv),
                len: len.map(|l| if l.is_finite() { l } else { 1.0 }),
                m: fin(m),
                p: p.map(f64::from),
            }
        })
        .collect()
}

/// Lambert irradiance at `p` with unit normal `n` (ambient + each light's n.l).
fn lighting(scene: &Scene, p: DVec3, n: DVec3) -> DVec3 {
    let mut e = DVec3::from(scene.ambient.map(f64::from));
    for l in &scene.lights {
        let (dir, col) = match l {
            Light::Directional { direction, color } => (
                -DVec3::from(direction.map(f64::from)).normalize_or_zero(),
                color,
            ),
            Light::Point { position, color } => (
                (DVec3::from(position.map(f64::from)) - p).normalize_or_zero(),
                color,
            ),
        };
        e += DVec3::from(col.map(f64::from)) * n.dot(dir).max(0.0);
    }
    e
}

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
    /// Collect the timing model's event stream (`Rendered::events`). Off by default: a render
    /// without it allocates no event buffer and does no extra work per pixel.
    pub timing: bool,
    /// Also render the ground truth, with this many sub-samples per pixel axis (0 = off):
    /// roughness materials supersample their full-resolution bump map
    /// (`pipeline::rough_stages`), NDF materials their finest normal map
    /// (`pipeline::ndf_stages::NdfTruth`); the stats gain `model_error` (float vs truth) and
    /// `quantization_error` (hardware vs float).
    pub truth: u32,
    /// Called once per finished phase (setup, raster, hardware shading, reference shading,
    /// ground truth) with its name and wall time in ms (`texsim render` prints them).
    pub progress: Option<fn(&str, f64)>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            hw_impls: StageImpls::FIXED,
            reference: true,
            coverage: CoverageMode::Shared,
            timing: false,
            truth: 0,
            progress: None,
        }
    }
}

/// Per-stage statistics of the hardware pass.
#[derive(Clone, Debug, Serialize)]
pub struct StageStats {
    pub stage: StageKind,
    #[serde(rename = "impl")]
    pub imp: Impl,
    pub invocations: u64,
    pub saturated: u64,
    pub wrapped: u64,
    pub ops: u64,
    pub cycles: u64,
    pub texels: u64,
}

/// Bump-mapping events: frames from a fallback, zero interpolated normals, `l + v = 0`,
/// non-finite float carriers (hardware and reference pass), offsets clamped by the map
/// encoding (including normal-map texels whose `n_z` was clamped, [`Maps::bump_clamped`]).
/// Format saturations are in the per-stage `saturated` counts.
#[derive(Clone, Debug, Default, Serialize)]
pub struct BumpStats {
    pub frame_fallback: u64,
    pub zero_normal: u64,
    pub h_zero: u64,
    pub nonfinite: u64,
    pub ref_nonfinite: u64,
    pub offset_clamped: u64,
    /// NDF moment-map channels clamped by their encoding (all moment maps of the scene).
    pub ndf_clamped: u64,
    /// The frames the bump materials used (`natural`, `unit`, `main`), empty without bumps.
    pub frame: String,
}

fn bump_frames(geo: &Geometry, hw: &HwConfig) -> String {
    let mut kinds: Vec<&str> = geo
        .plans
        .iter()
        .filter_map(|p| p.bump.as_ref())
        .map(|b| b.frame.unwrap_or(hw.shading.frame.frame_kind).name())
        .collect();
    kinds.sort_unstable();
    kinds.dedup();
    kinds.join("+")
}

/// Wall times in milliseconds.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Timings {
    pub geometry_ms: f64,
    pub setup_ms: f64,
    pub raster_ms: f64,
    pub shade_hw_ms: f64,
    pub raster_ref_ms: f64,
    pub shade_ref_ms: f64,
    /// Setup + raster + hardware shading.
    pub hw_total_ms: f64,
    /// Setup + (shared or float) raster + reference shading.
    pub ref_total_ms: f64,
}

/// First cycle estimate: each unit's invocations x its cycles from HwConfig (no overlap, no
/// memory effects; the detailed timing model is separate).
#[derive(Clone, Debug, Default, Serialize)]
pub struct CycleEstimate {
    pub setup: u64,
    pub spans: u64,
    pub stages: u64,
    pub total: u64,
    pub per_covered_pixel: f64,
    /// Set when a stage ran without a hardware cost model (`ndf_norm = exact`): the totals
    /// leave its unit out and are no machine's cost; sweeps print `-`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub not_modelled: Option<&'static str>,
}

/// Everything one render produced.
pub struct Rendered {
    pub hw_image: Image,
    pub ref_image: Option<Image>,
    /// The ground truth image (`RenderOptions::truth`).
    pub truth_image: Option<Image>,
    /// Pixels covered by the hardware or the reference pass (the compared set).
    pub mask: Vec<bool>,
    pub stats: RenderStats,
    /// The timing model's events of the hardware pass, when `RenderOptions::timing` was set.
    pub events: Option<FrameEvents>,
}

/// The numbers of one render (serialized into summary.json).
#[derive(Clone, Debug, Serialize)]
pub struct RenderStats {
    pub scene: String,
    pub hw: String,
    pub width: u32,
    pub height: u32,
    pub triangles: u64,
    pub coverage: CoverageMode,
    pub setup: SetupStats,
    pub raster: RasterStats,
    pub covered_pixels: u64,
    /// Host-to-hardware conversions that saturated (vertex attributes out of format range).
    pub input_saturated: u64,
    /// Host-to-hardware conversions that wrapped (formats whose overflow rule is `wrap`).
    pub input_wrapped: u64,
    /// Bump-mapping events of the hardware pass (all zero without bump materials).
    pub bump: BumpStats,
    pub stages: Vec<StageStats>,
    pub cycles: CycleEstimate,
    /// Wall times: not part of the results (they differ between two runs), so not serialized
    /// with them; `texsim render` writes them into `timings.json`.
    #[serde(skip)]
    pub timings: Timings,
    /// Error of the hardware image against the reference, in 8-bit and 16-bit LSBs.
    pub error_8bit: Option<ErrorMetrics>,
    pub error_16bit: Option<ErrorMetrics>,
    /// Roughness materials (issue 4): D maps, ground truth and the two errors.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub roughness: Option<RoughStats>,
    /// With `--truth`: the float reference against the ground truth (the model's error) and
    /// the hardware against the float reference (quantization), 8-bit LSBs.
    pub model_error: Option<ErrorMetrics>,
    pub quantization_error: Option<ErrorMetrics>,
    /// Results that are valid but probably not what was meant (`crate::warnings`).
    pub warnings: Vec<String>,
}

/// Roughness statistics of one render (8-bit LSB metrics over the covered pixels).
#[derive(Clone, Debug, Serialize)]
pub struct RoughStats {
    /// D channel values clamped by the encoding.
    pub d_clamped: u64,
    /// Ground-truth sub-samples per pixel axis (0: no truth rendered).
    pub truth_samples: u32,
    /// Float model vs ground truth.
    pub model_error: Option<ErrorMetrics>,
    /// Fixed vs float of the same model (= `error_8bit`).
    pub quantization_error: Option<ErrorMetrics>,
    /// Plain filtered bump map (variant `none`, float) vs ground truth; filled by the CLI.
    pub baseline_error: Option<ErrorMetrics>,
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// Bump data of every screen triangle of a bump plan (clipped vertices blended from their
/// source vertices); sets `TriAttrs::bump`.
fn bump_attrs(
    setup: &Setup,
    geo: &Geometry,
    m: &Machine,
    attrs: &mut [TriAttrs],
) -> (Vec<BumpAttrs>, SatCounter) {
    let mut out = Vec::new();
    let mut sat = SatCounter::default();
    if geo.bump.is_empty() {
        return (out, sat);
    }
    for (t, a) in setup.tris.iter().zip(attrs.iter_mut()) {
        let plan = &geo.plans[a.plan as usize];
        if plan.bump.is_none() {
            continue;
        }
        let d = &geo.draws[t.src as usize];
        let blend = |k: usize| -> BumpVertex {
            let w = t.src_bary[k];
            let mut r = BumpVertex::default();
            for (&wj, &vi) in w.iter().zip(&d.v) {
                let Some(b) = geo.bump.get(vi as usize) else {
                    continue;
                };
                for c in 0..3 {
                    r.n[c] += wj * b.n[c];
                    r.du[c] += wj * b.du[c];
                    r.dv[c] += wj * b.dv[c];
                    r.m[c] += wj * b.m[c];
                    r.p[c] += wj * b.p[c];
                }
                for c in 0..2 {
                    r.len[c] += wj * b.len[c];
                }
            }
            r
        };
        let verts = [blend(0), blend(1), blend(2)];
        a.bump = out.len() as u32;
        out.push(BumpAttrs::new(
            m,
            &verts,
            geo.eye,
            &geo.point_lights,
            &mut sat,
        ));
    }
    (out, sat)
}

/// Per-triangle attributes of every screen triangle, in the machine's formats.
fn tri_attrs(setup: &Setup, geo: &Geometry, m: &Machine) -> (Vec<TriAttrs>, SatCounter) {
    let out: Vec<(TriAttrs, SatCounter)> = setup
        .tris
        .par_iter()
        .map(|t| {
            let d = &geo.draws[t.src as usize];
            let blend = |k: usize| -> ([f64; 3], [f64; 2]) {
                let w = t.src_bary[k];
                let mut c = [0.0; 3];
                let mut uv = [0.0; 2];
                for (&wj, &vi) in w.iter().zip(&d.v) {
                    let vi = vi as usize;
                    for (acc, &x) in c.iter_mut().zip(&geo.color[vi]) {
                        *acc += wj * x;
                    }
                    for (acc, &x) in uv.iter_mut().zip(&geo.uv[vi]) {
                        *acc += wj * x;
                    }
                }
                (c, uv)
            };
            let (c0, t0) = blend(0);
            let (c1, t1) = blend(1);
            let (c2, t2) = blend(2);
            let mut sat = SatCounter::default();
            let plan = geo.draw_plan[t.src as usize];
            let wrap = geo.plans[plan as usize].wrap;
            let a = TriAttrs::new(m, plan, t.inv_w, [c0, c1, c2], [t0, t1, t2], wrap, &mut sat);
            (a, sat)
        })
        .collect();
    let mut sat = SatCounter::default();
    let attrs = out
        .into_iter()
        .map(|(a, s)| {
            sat.add(&s);
            a
        })
        .collect();
    (attrs, sat)
}

/// What the shading pass reads: the visible triangles and everything prepared for them.
struct ShadeInput<'a> {
    vis: &'a VisBuffer,
    setup: &'a Setup,
    attrs: &'a [TriAttrs],
    geo: &'a Geometry,
    m: &'a Machine<'a>,
}

/// Shades row `y` into `row` with the plans compiled as `progs`, adding to `c`; `on_pixel(plan index, triangle, frag)` sees every
/// shaded fragment (a no-op closure compiles to the plain loop; the timing model records its
/// events through it, from the footprints the stages traced when `trace`).
#[allow(clippy::too_many_arguments)]
fn shade_row(
    inp: &ShadeInput,
    progs: &[Program],
    y: usize,
    row: &mut [[u16; 4]],
    c: &mut Counters,
    trace: bool,
    mut on_pixel: impl FnMut(u32, u32, &Frag),
) {
    let w = inp.vis.width as usize;
    let mut frag = Frag::default();
    frag.trace.on = trace;
    let tris = &inp.vis.tri[y * w..(y + 1) * w];
    for (x, (&t, out)) in tris.iter().zip(row.iter_mut()).enumerate() {
        if t == NO_TRI {
            continue;
        }
        let a = &inp.attrs[t as usize];
        let pi = a.plan as usize;
        let tri = &inp.setup.tris[t as usize];
        let plan = &inp.geo.plans[pi];
        run(
            &progs[pi], plan, inp.m, tri, a, x as i64, y as i64, &mut frag, c,
        );
        *out = output16(&frag);
        on_pixel(a.plan, t, &frag);
    }
}

/// Shades every covered pixel with `impls`; returns the image, the counters and, when
/// `timing`, the event stream (rows concatenated in row order).
fn shade(
    inp: &ShadeInput,
    impls: &StageImpls,
    background: [u16; 4],
    timing: bool,
) -> (Image, Counters, Option<FrameEvents>) {
    let vis = inp.vis;
    let w = vis.width as usize;
    let mut img = Image::new(vis.width, vis.height, background);
    let progs: Vec<Program> = inp
        .geo
        .plans
        .iter()
        .map(|p| Program::new(p, impls, inp.m))
        .collect();
    let progs = &progs[..];
    if !timing {
        let counters = img
            .px
            .par_chunks_mut(w.max(1))
            .enumerate()
            .map(|(y, row)| {
                let mut c = Counters::default();
                shade_row(inp, progs, y, row, &mut c, false, |_, _, _| {});
                c
            })
            .reduce(Counters::default, |mut a, b| {
                a.add(&b);
                a
            });
        return (img, counters, None);
    }
    let lookups = StageKind::ALL
        .iter()
        .map(|&k| crate::timing::events::lookups(k, inp.m.hw) as usize)
        .sum::<usize>();
    let rows: Vec<(Counters, RowEvents)> = img
        .px
        .par_chunks_mut(w.max(1))
        .enumerate()
        .map(|(y, row)| {
            let mut c = Counters::default();
            let mut ev = RowEvents::with_capacity(w, lookups);
            shade_row(inp, progs, y, row, &mut c, true, |pi, t, frag| {
                record_pixel(pi, t, frag, &mut ev);
            });
            (c, ev)
        })
        .collect();
    let mut counters = Counters::default();
    let mut fe = FrameEvents {
        width: vis.width,
        height: vis.height,
        ..FrameEvents::default()
    };
    // Sized once: the rows are copied in without reallocating the frame's lists.
    fe.pixels
        .reserve_exact(rows.iter().map(|r| r.1.pixels.len()).sum());
    fe.footprints
        .reserve_exact(rows.iter().map(|r| r.1.footprints.len()).sum());
    for (c, ev) in rows {
        counters.add(&c);
        fe.append_row(ev);
    }
    (img, counters, Some(fe))
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
    let rough_sources =
        crate::pipeline::rough_stages::resolve_plans(&mut geo.plans, hw, maps.float.len());
    let has_rough = geo.plans.iter().any(|p| p.rough.is_some());
    let mut d_clamped = 0;
    let rough_owned;
    let maps = if rough_sources.is_empty() {
        maps
    } else {
        let (mm, cl) = crate::pipeline::rough_stages::rough_maps(maps, &rough_sources, hw)?;
        d_clamped = cl;
        rough_owned = mm;
        &rough_owned
    };

    let mut warnings: Vec<String> = Vec::new();
    let mut opts = opts.clone();
    if crate::pipeline::ndf_stages::shade_is_float_only(hw)
        && geo.plans.iter().any(|p| p.ndf.is_some())
        && opts.hw_impls.of(StageKind::NdfShade) == Impl::Fixed
    {
        warnings.push("field 'ndf.ndf_norm': exact is float only: ndf-shade runs in float".into());
        opts.hw_impls = opts.hw_impls.with(StageKind::NdfShade, Impl::Float);
    }
    let opts = &opts;

    let t = Instant::now();
    let setup = raster::setup(&geo.clip, &geo.draws, scene.width, scene.height, &hw.raster);
    let m0 = Machine::new(hw, &maps.float, &maps.fixed).with_lights(&scene.lights, scene.ambient);
    let (mut attrs, mut input_sat) = tri_attrs(&setup, &geo, &m0);
    let (battrs, bsat) = bump_attrs(&setup, &geo, &m0, &mut attrs);
    input_sat.add(&bsat);
    let m = m0.with_bump_attrs(&battrs);
    let costs: Vec<[UnitCost; StageKind::COUNT]> =
        geo.plans.iter().map(|p| m.plan_costs(p)).collect();
    tm.setup_ms = ms(t);
    progress("setup", ms(t_start));

    let t = Instant::now();
    let (vis, raster_stats) = raster::rasterize(&setup, Coverage::Fixed, true);
    tm.raster_ms = ms(t);
    progress("raster", tm.raster_ms);

    let bg = scene.background.map(|c| to_unorm(f64::from(c), 16) as u16);
    let t = Instant::now();
    let inp = ShadeInput {
        vis: &vis,
        setup: &setup,
        attrs: &attrs,
        geo: &geo,
        m: &m,
    };
    let (hw_image, counters, mut events) = shade(&inp, &opts.hw_impls, bg, opts.timing);
    if let Some(fe) = events.as_mut() {
        fe.triangles = setup.tris.len() as u64;
        fe.spans = raster_stats.spans;
        fe.fragments = raster_stats.fragments;
        fe.plans = geo
            .plans
            .iter()
            .zip(&costs)
            .map(|(p, c)| PlanTiming {
                stages: p.stages.iter().map(|&k| (k, c[k.index()])).collect(),
            })
            .collect();
        fe.textures = maps
            .fixed
            .iter()
            .map(|ch| ch.levels.iter().map(|l| (l.width, l.height)).collect())
            .collect();
    }
    tm.shade_hw_ms = ms(t);
    progress("hardware shading", tm.shade_hw_ms);
    tm.hw_total_ms = tm.setup_ms + tm.raster_ms + tm.shade_hw_ms;

    let mut mask: Vec<bool> = vis.tri.iter().map(|&t| t != NO_TRI).collect();
    let mut ref_image = None;
    let mut ref_nonfinite = 0;
    let (mut e8, mut e16) = (None, None);
    if opts.reference {
        let t_ref = Instant::now();
        let ref_vis;
        let rv = match opts.coverage {
            CoverageMode::Shared => {
                tm.raster_ref_ms = tm.raster_ms;
                &vis
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
        let (img, rc, _) = shade(
            &ShadeInput { vis: rv, ..inp },
            &StageImpls::FLOAT,
            bg,
            false,
        );
        ref_nonfinite = rc.nonfinite;
        tm.shade_ref_ms = ms(t);
        progress("reference", ms(t_ref));
        tm.ref_total_ms = tm.setup_ms + tm.raster_ref_ms + tm.shade_ref_ms;
        e8 = Some(compare(&hw_image, &img, 8, Some(&mask)));
        e16 = Some(compare(&hw_image, &img, 16, Some(&mask)));
        ref_image = Some(img);
    }
    let mut truth_image = None;
    let has_ndf = geo.plans.iter().any(|p| p.ndf.is_some());
    if opts.truth > 0 && (has_rough || has_ndf) {
        let t_truth = Instant::now();
        // One float pass over every material: roughness materials shade their supersampled
        // bump map (`rough_stages::truth_plans`), NDF materials their supersampled finest normal
        // map (`ndf_stages::NdfTruth`), all others are their own float reference.
        let tp = crate::pipeline::rough_stages::truth_plans(&geo.plans, opts.truth);
        let saved = std::mem::replace(&mut geo.plans, tp);
        let ndf_truth =
            crate::pipeline::ndf_stages::truth_maps(maps, scene, &geo.plans, opts.truth);
        let mt = Machine::new(hw, &maps.float, &maps.fixed)
            .with_lights(&scene.lights, scene.ambient)
            .with_bump_attrs(&battrs)
            .with_ndf_truth(&ndf_truth);
        let tin = ShadeInput {
            vis: &vis,
            setup: &setup,
            attrs: &attrs,
            geo: &geo,
            m: &mt,
        };
        let (img, _, _) = shade(&tin, &StageImpls::FLOAT, bg, false);
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
    let mut stage_cycles = 0u64;
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
            cycles: cyc,
            texels,
        };
        stage_cycles += s.cycles;
        stages.push(s);
    }
    let covered = vis.tri.iter().filter(|&&t| t != NO_TRI).count() as u64;
    let rc = &hw.raster;
    let mut cycles = CycleEstimate {
        setup: setup.tris.len() as u64 * u64::from(rc.setup_cycles),
        spans: raster_stats.spans * u64::from(rc.span_cycles),
        stages: stage_cycles,
        ..Default::default()
    };
    cycles.total = cycles.setup + cycles.spans + cycles.stages;
    cycles.per_covered_pixel = cycles.total as f64 / covered.max(1) as f64;
    if crate::pipeline::ndf_stages::shade_is_float_only(hw)
        && counters.invocations[StageKind::NdfShade.index()] > 0
    {
        cycles.not_modelled = Some(crate::pipeline::ndf_stages::EXACT_NOT_MODELLED);
    }

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
            cycles,
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
