//! The NDF-mapping stage twins (Olano and North 1997, "Normal Distribution Mapping", sections
//! 5-6): `ndf-fetch` (LOD against the moment maps' size, then three trilinear lookups of the
//! moment maps A, B, C through the unchanged trilinear unit, a fourth of the normalization map
//! when `ndf_norm = map`) and `ndf-shade` (per light: `h` in the local frame, then
//! `hw_model::ndf::NdfUnit`, times `ks` and the light; plus Lambert diffuse on the interpolated
//! normal and the ambient term).
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

use super::stages::{Counters, Machine};
use super::trace::{trace_float_fetch, trilinear_traced, Lookup};
use super::{Frag, Impl, Plan, Px, StageImpls, StageKind};
use crate::fixedpoint::{from_unorm, to_raw, to_unorm};
use crate::reference::{lod_f64, trilinear_f64};
use crate::shading::ndf::{eval_float, ground_truth, Moments};
use crate::shading::reference as fref;
use glam::DVec3;
use hw_model::config::HwConfig;
use hw_model::fixed::{round_shift_right_wide, SatCounter};
use hw_model::lod::{lod, lod_cost};
use hw_model::modulate::modulate;
use hw_model::ndf::{ndf_cost, ndf_lookups, NdfNorm, NdfTexels, NdfUnit, NDF_FRAC};
use hw_model::rsqrt::rsqrt_cost;
use hw_model::trilinear::trilinear_cost;
use hw_model::vector::{dot3, normalize3, normalize_cost, Vec3x};
use hw_model::UnitCost;

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

/// Lookups of one `ndf-fetch` (3, 4 with the normalization map).
#[must_use]
pub fn fetch_lookups(hw: &HwConfig) -> u32 {
    ndf_lookups(&hw.ndf)
}

/// Cost of one invocation of an NDF stage of `plan`.
#[must_use]
pub fn ndf_stage_cost(m: &Machine, kind: StageKind, plan: &Plan) -> UnitCost {
    if plan.ndf.is_none() {
        return UnitCost::default();
    }
    let hw = m.hw;
    let g = hw.timing.gate_levels_per_cycle;
    match kind {
        StageKind::NdfFetch => {
            lod_cost(&hw.lod, g).plus(trilinear_cost(&hw.trilinear, 2, g).times(fetch_lookups(hw)))
        }
        StageKind::NdfShade => {
            let u = &m.units;
            let lights = m.lights.len() as u32;
            let np = super::bump_stages::point_lights(m) as u32;
            let nz = normalize_cost(&u.cfg.vector, rsqrt_cost(&u.cfg.rsqrt, g), g);
            let mac = hw_model::blinn_phong::mac_cost(&u.cfg, g);
            // `exact` has no unit cost (float only): the stage's cost is then incomplete and
            // `render` marks the cycle estimate as not modelled ([`EXACT_NOT_MODELLED`]).
            let mut unit =
                ndf_cost(&hw.ndf, &m.recip.cost(g), &hw.shading.rsqrt, g).unwrap_or_default();
            unit.texels = 0;
            // Per light: l (point lights), h, h in the frame (3 dots), n.l, D, two MACs.
            unit.times(lights)
                .plus(nz.times(1 + np + 2 * lights))
                .plus(mac.times(1 + 4 * lights))
        }
        _ => UnitCost::default(),
    }
}

fn lod_for(m: &Machine, frag: &mut Frag, fixed: bool, w: u32, h: u32, sat: &mut SatCounter) {
    let fb = m.uv_fmt.frac_bits;
    if fixed {
        let uv = &frag.uv_x;
        let d = [
            (uv[1][0] - uv[0][0]) * i64::from(w),
            (uv[1][1] - uv[0][1]) * i64::from(h),
            (uv[2][0] - uv[0][0]) * i64::from(w),
            (uv[2][1] - uv[0][1]) * i64::from(h),
        ];
        frag.lod_x = lod(d, fb, &m.hw.lod, sat);
    } else {
        let uv = &frag.uv;
        let (wf, hf) = (f64::from(w), f64::from(h));
        frag.lod = lod_f64([
            (uv[1][0] - uv[0][0]) * wf,
            (uv[1][1] - uv[0][1]) * hf,
            (uv[2][0] - uv[0][0]) * wf,
            (uv[2][1] - uv[0][1]) * hf,
        ]);
    }
}

/// Decoded moments and `1/Z` of the float carriers (exact decode of the channel encoding).
fn moments_of(t: &[[f64; 4]; 4], hw: &HwConfig, norm_exp: u32) -> (Moments, f64) {
    let r = f64::from(1u32 << hw.ndf.moment_scale_bits);
    let m = Moments {
        mu: DVec3::new(
            2.0 * t[0][0] - 1.0,
            2.0 * t[0][1] - 1.0,
            2.0 * t[0][2] - 1.0,
        ),
        e: [
            r * t[1][0],
            r * t[1][1],
            r * t[1][2],
            r * (t[2][0] - 0.5),
            r * (t[2][1] - 0.5),
            r * (t[2][2] - 0.5),
        ],
    };
    (m, t[3][0] * f64::from(norm_exp).exp2())
}

/// Runs NDF stage `kind` of `plan` on `frag`.
#[allow(clippy::too_many_lines, clippy::needless_range_loop)]
#[inline]
pub fn run_ndf_stage(
    kind: StageKind,
    plan: &Plan,
    impls: &StageImpls,
    m: &Machine,
    frag: &mut Frag,
    c: &mut Counters,
) {
    let (Some(np), Some(bp)) = (&plan.ndf, &plan.bump) else {
        return;
    };
    let fixed_in = |k: StageKind| impls.of(k) == Impl::Fixed;
    let hw = m.hw;
    let k = kind.index();
    let mut sat = c.sat[k];
    let mb = hw.ndf.moment_bits;
    let n_maps = fetch_lookups(hw) as usize;
    match kind {
        StageKind::NdfFetch => {
            let Some(l0) = m.tex_float.get(np.maps).and_then(|l| l.first()) else {
                c.sat[k] = sat;
                return;
            };
            let (w, h) = (l0.width, l0.height);
            if fixed_in(kind) {
                if !fixed_in(StageKind::Texcoord) {
                    for s in 0..3 {
                        for ax in 0..2 {
                            frag.uv_x[s][ax] = to_raw(frag.uv[s][ax], &m.uv_fmt, &mut sat);
                        }
                    }
                }
                lod_for(m, frag, true, w, h, &mut sat);
                let [u, v] = frag.uv_x[0];
                for i in 0..n_maps {
                    let Some(levels) = m.tex_fixed.get(np.maps + i) else {
                        continue;
                    };
                    let at = Lookup {
                        stage: kind,
                        lookup: i as u32,
                        tex: np.maps + i,
                    };
                    let r = trilinear_traced(
                        levels,
                        u,
                        v,
                        m.uv_fmt.frac_bits,
                        frag.lod_x,
                        hw.lod.lod_frac_bits,
                        plan.wrap,
                        &hw.trilinear,
                        &mut frag.trace,
                        at,
                    );
                    frag.ndf.texel_x[i] = r;
                    frag.ndf.texel[i] = r.map(|x| from_unorm(u32::from(x), mb));
                }
            } else {
                lod_for(m, frag, false, w, h, &mut sat);
                let [u, v] = frag.uv[0];
                for i in 0..n_maps {
                    let Some(levels) = m.tex_float.get(np.maps + i) else {
                        continue;
                    };
                    frag.ndf.texel[i] = trilinear_f64(levels, u, v, frag.lod, plan.wrap);
                }
                let at = Lookup {
                    stage: kind,
                    lookup: 0,
                    tex: np.maps,
                };
                let raw_uv = fixed_in(StageKind::Texcoord);
                trace_float_fetch(m, frag, raw_uv, plan.wrap, at, n_maps as u32);
            }
        }
        StageKind::NdfShade => {
            let unit = m.ndf.as_ref().filter(|_| fixed_in(kind));
            let bf = &frag.bump;
            let units = &m.units;
            let vc = &units.cfg.vector;
            let f = vc.vector_frac_bits;
            let cb = units.cfg.shade.shade_color_bits;
            let spec_scale = 2.0 * std::f64::consts::PI / f64::from(np.shininess.max(1));
            if let Some(unit) = unit {
                let rnd = units.cfg.shade.shade_rounding;
                let raw_frame = fixed_in(StageKind::Frame);
                let q = |x: &Vec3x, v: &[f64; 3], sat: &mut SatCounter| {
                    if raw_frame {
                        *x
                    } else {
                        v.map(|c| to_raw(c, &m.vec_fmt, sat))
                    }
                };
                let n = q(&bf.fr_n_x, &bf.fr_n, &mut sat);
                let tu = q(&bf.fr_t_u_x, &bf.fr_t_u, &mut sat);
                let tv = q(&bf.fr_t_v_x, &bf.fr_t_v, &mut sat);
                let texels = if fixed_in(StageKind::NdfFetch) {
                    frag.ndf.texel_x
                } else {
                    frag.ndf.texel.map(|t| t.map(|x| to_unorm(x, mb) as u16))
                };
                let t = NdfTexels {
                    mean: texels[0],
                    diag: texels[1],
                    off: texels[2],
                    norm: texels[3],
                    norm_exp: np.norm_exp,
                };
                let eye = if fixed_in(StageKind::Normal) {
                    bf.to_eye_x
                } else {
                    bf.to_eye.map(|c| to_raw(c, &m.vec_fmt, &mut sat))
                };
                let one = [0, 0, 1i64 << f];
                let v = normalize3(&eye, one, &units.rsqrt, vc, &mut sat).v;
                let kd = bp.kd.map(|x| to_unorm(x, cb));
                let ks = bp.ks.map(|x| to_unorm(x, cb));
                let ndf_f = hw.ndf.ndf_frac_bits;
                let scale_q = (spec_scale * f64::from(1u32 << 30)).round() as i64;
                let mut acc = [0u64; 3];
                for ch in 0..3 {
                    acc[ch] = u64::from(modulate(m.ambient_x[ch] as u32, cb, kd[ch], cb, cb, rnd));
                }
                for light in &m.lights {
                    let l = match light.point {
                        Some(pi) => {
                            let lv = if fixed_in(StageKind::Normal) {
                                bf.to_light_x[pi]
                            } else {
                                bf.to_light[pi].map(|c| to_raw(c, &m.vec_fmt, &mut sat))
                            };
                            normalize3(&lv, one, &units.rsqrt, vc, &mut sat).v
                        }
                        None => light.l_x,
                    };
                    let ndl = dot3(&n, &l, vc, &mut sat).max(0);
                    if ndl == 0 {
                        continue;
                    }
                    // h = normalize((l + v) / 2), then in the frame: (h.t_u, h.t_v, h.n).
                    let half = [0, 1, 2].map(|i| (l[i] + v[i]) >> 1);
                    let hv = normalize3(&half, n, &units.rsqrt, vc, &mut sat).v;
                    let ht = [
                        dot3(&hv, &tu, vc, &mut sat),
                        dot3(&hv, &tv, vc, &mut sat),
                        dot3(&hv, &n, vc, &mut sat),
                    ];
                    let ht = normalize3(&ht, one, &units.rsqrt, vc, &mut sat).v;
                    let h32 = ht.map(|x| x << (NDF_FRAC - f));
                    let d = unit.eval(&t, &h32, &mut sat).d_value;
                    // spec = D 2pi/s with ndf_frac_bits fraction bits.
                    let spec = round_shift_right_wide(i128::from(d) * i128::from(scale_q), 30, rnd);
                    for ch in 0..3 {
                        let lc = light.color_x[ch] as u32;
                        let kdl = u64::from(modulate(kd[ch], cb, lc, cb, cb, rnd));
                        let ksl = u64::from(modulate(ks[ch], cb, lc, cb, cb, rnd));
                        let diff =
                            round_shift_right_wide(i128::from(kdl) * i128::from(ndl), f, rnd);
                        let sp =
                            round_shift_right_wide(i128::from(ksl) * i128::from(spec), ndf_f, rnd);
                        acc[ch] = acc[ch]
                            .saturating_add(diff.max(0) as u64)
                            .saturating_add(sp.max(0) as u64);
                    }
                }
                super::bump_stages::fixed_output(acc, frag, &mut sat, cb);
            } else {
                let texel = if fixed_in(StageKind::NdfFetch) {
                    frag.ndf
                        .texel_x
                        .map(|t| t.map(|x| from_unorm(u32::from(x), mb)))
                } else {
                    frag.ndf.texel
                };
                let (mom, inv_z) = moments_of(&texel, hw, np.norm_exp);
                let truth = m.ndf_truth.iter().find(|t| t.maps == np.maps);
                let n = DVec3::from(bf.fr_n);
                let tu = DVec3::from(bf.fr_t_u);
                let tv = DVec3::from(bf.fr_t_v);
                let v = fref::normalize_or(DVec3::from(bf.to_eye), DVec3::Z).0;
                let mut acc = [0.0f64; 3];
                for ch in 0..3 {
                    acc[ch] = m.ambient[ch] * bp.kd[ch];
                }
                for light in &m.lights {
                    let l = match light.point {
                        Some(pi) => fref::normalize_or(DVec3::from(bf.to_light[pi]), DVec3::Z).0,
                        None => DVec3::from(light.l_f),
                    };
                    let ndl = n.dot(l).max(0.0);
                    if ndl <= 0.0 {
                        continue;
                    }
                    let hv = fref::normalize_or(l + v, n).0;
                    let ht =
                        fref::normalize_or(DVec3::new(hv.dot(tu), hv.dot(tv), hv.dot(n)), DVec3::Z)
                            .0;
                    let d = match truth {
                        Some(tr) => {
                            let (wf, hf) = (f64::from(tr.width), f64::from(tr.height));
                            let uv = &frag.uv;
                            let d =
                                |k: usize| [(uv[k][0] - uv[0][0]) * wf, (uv[k][1] - uv[0][1]) * hf];
                            ground_truth(
                                &tr.normals,
                                tr.width,
                                tr.height,
                                tr.shininess,
                                [uv[0][0] * wf, uv[0][1] * hf],
                                [d(1), d(2)],
                                tr.samples,
                                ht,
                            )
                        }
                        None => eval_float(&mom, ht, inv_z, &hw.ndf).d_value,
                    };
                    let spec = d * spec_scale;
                    for ch in 0..3 {
                        acc[ch] += light.color_f[ch] * (bp.kd[ch] * ndl + bp.ks[ch] * spec);
                    }
                }
                super::bump_stages::float_output(acc, frag, c);
            }
        }
        _ => {}
    }
    c.sat[k] = sat;
}

/// True when the fixed `ndf-shade` cannot run on `hw` (`ndf_norm = exact`: float only).
#[must_use]
pub fn shade_is_float_only(hw: &HwConfig) -> bool {
    hw.ndf.ndf_norm == NdfNorm::Exact
}

/// Why a render with `ndf_norm = exact` has no cycle count (`IssueCycles::not_modelled`).
pub const EXACT_NOT_MODELLED: &str =
    "ndf-shade with ndf_norm = exact is float only: no hardware cost model";

/// Stage-table entry of ndf stage `K` (`StageKind::index`); it runs the twin `px.impls`
/// names for it.
pub fn row<const K: usize>(px: &Px, frag: &mut Frag, c: &mut Counters) {
    run_ndf_stage(StageKind::ALL[K], px.plan, px.impls, px.m, frag, c);
}

/// Stage-table cost of ndf stage `K`.
#[must_use]
pub fn row_cost<const K: usize>(m: &Machine, plan: &Plan) -> UnitCost {
    ndf_stage_cost(m, StageKind::ALL[K], plan)
}
