//! Roughness stages (Schilling 1997, "Antialiasing of Bump-Maps": "The roughness pyramid",
//! Appendix A): `rough-fetch` filters the D map (three channels `d1, d2, d3`, or lambda1) with
//! the ordinary trilinear unit at the LOD of the bump fetch (same map size, same derivatives);
//! `rough-shade` replaces `phong` and evaluates Blinn-Phong with the modified specular term
//! `cos^2 a' = cos^2 a / (|d|^4 / |D d|^2 + cos^2 a)` (or a variant) for every light.
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

use super::bump_stages::point_lights;
use super::stages::{Counters, Machine};
use super::trace::{trace_float_fetch, trilinear_traced, Lookup};
use super::{Frag, Impl, Plan, Px, StageImpls, StageKind};
use crate::fixedpoint::{from_unorm, to_raw, to_unorm};
use crate::maps::Maps;
use crate::maps::MipChain;
use crate::reference::{lod_f64, trilinear_f64};
use crate::scene::{Material, RoughChoice};
use crate::shading::reference as fref;
use crate::shading::roughness::{
    build_rough_pyramid, normalize_factor, quantize_rough_chain, rough_blinn_phong_f,
    rough_mip_chain, scale_d_f, RoughParams, RoughnessEncoding,
};
use glam::DVec3;
use hw_model::blinn_phong::BlinnPhongInput;
use hw_model::config::HwConfig;
use hw_model::fixed::SatCounter;
use hw_model::lod::lod;
use hw_model::roughness::{
    decode_d, rough_blinn_phong, rough_blinn_phong_cost, scale_d, RoughShadeInput, RoughVariant,
};
use hw_model::rsqrt::rsqrt_cost;
use hw_model::trilinear::trilinear_cost;
use hw_model::vector::{normalize3, normalize_cost, Vec3x};
use hw_model::UnitCost;

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
fn decoded_offsets(chain: &MipChain, offset_int_bits: u32) -> (u32, u32, Vec<[f32; 2]>) {
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

/// Cost of one invocation of `kind` (`rough-fetch`: one trilinear lookup, the LOD is the bump
/// fetch's; `rough-shade`: `phong` with the modified specular term).
#[must_use]
pub fn rough_stage_cost(m: &Machine, kind: StageKind, plan: &Plan) -> UnitCost {
    let (Some(_), Some(rp)) = (&plan.bump, &plan.rough) else {
        return UnitCost::default();
    };
    let u = &m.units;
    let g = m.hw.timing.gate_levels_per_cycle;
    let cfg = hw_model::roughness::RoughnessConfig {
        rough_variant: rp.variant,
        ..m.hw.roughness.clone()
    };
    match kind {
        StageKind::RoughFetch => trilinear_cost(&m.hw.trilinear, 2, g),
        StageKind::RoughShade => {
            let np = point_lights(m) as u32;
            let lights = m.lights.len() as u32;
            let nz = normalize_cost(&u.cfg.vector, rsqrt_cost(&u.cfg.rsqrt, g), g);
            let mac = hw_model::blinn_phong::mac_cost(&u.cfg, g);
            let mut c = rough_blinn_phong_cost(&cfg, u, g)
                .times(lights)
                .plus(nz.times(1 + np))
                .plus(mac.times(1 + lights));
            if plan.texture.is_some() {
                c = c.plus(mac);
            }
            c
        }
        _ => UnitCost::default(),
    }
}

#[inline]
fn raw3(v: &[f64; 3], m: &Machine, sat: &mut SatCounter) -> Vec3x {
    v.map(|c| to_raw(c, &m.vec_fmt, sat))
}

/// Bilinear, wrapping sample of the two offset channels of a float level at `(u, v)`,
/// decoded with range `2^offset_int_bits`.
fn sample_offsets(l0: &crate::reference::LevelF, u: f64, v: f64, range: f64) -> [f64; 2] {
    let (w, h) = (f64::from(l0.width), f64::from(l0.height));
    let fix = |x: f64| if x.is_finite() { x } else { 0.0 };
    let (x, y) = (fix(u) * w - 0.5, fix(v) * h - 0.5);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let wrap = |i: f64, n: u32| (i.rem_euclid(f64::from(n)) as u32).min(n - 1) as usize;
    let (xa, xb) = (wrap(x0, l0.width), wrap(x0 + 1.0, l0.width));
    let (ya, yb) = (wrap(y0, l0.height), wrap(y0 + 1.0, l0.height));
    let at = |xi: usize, yi: usize, c: usize| {
        l0.texels
            .get(yi * l0.width as usize + xi)
            .map_or(0.5, |t| f64::from(t[c]))
    };
    [0, 1].map(|c| {
        let top = at(xa, ya, c) * (1.0 - fx) + at(xb, ya, c) * fx;
        let bot = at(xa, yb, c) * (1.0 - fx) + at(xb, yb, c) * fx;
        ((top * (1.0 - fy) + bot * fy) - 0.5) * 2.0 * range
    })
}

/// Runs roughness stage `kind` of `plan` on `frag`.
#[allow(clippy::too_many_lines, clippy::needless_range_loop)]
#[inline]
pub fn run_rough_stage(
    kind: StageKind,
    plan: &Plan,
    impls: &StageImpls,
    m: &Machine,
    frag: &mut Frag,
    c: &mut Counters,
) {
    let (Some(bp), Some(rp)) = (&plan.bump, &plan.rough) else {
        return;
    };
    let fixed_in = |k: StageKind| impls.of(k) == Impl::Fixed;
    let fixed = fixed_in(kind) && rp.truth_samples == 0;
    let hw = m.hw;
    let units = &m.units;
    let vc = &units.cfg.vector;
    let f = vc.vector_frac_bits;
    let lfb = units.cfg.frame.frame_len_frac_bits;
    let tb = hw.trilinear.texel_bits;
    let k = kind.index();
    let mut sat = c.sat[k];
    let iso = rp.variant == RoughVariant::Isotropic;
    let rcfg = hw_model::roughness::RoughnessConfig {
        rough_variant: rp.variant,
        ..hw.roughness.clone()
    };
    match kind {
        StageKind::RoughFetch => {
            let t = rp.map;
            let Some(l0) = m.tex_float.get(t).and_then(|l| l.first()) else {
                c.sat[k] = sat;
                return;
            };
            let (w, h) = (l0.width, l0.height);
            let fb = m.uv_fmt.frac_bits;
            if fixed {
                let uv = if fixed_in(StageKind::Texcoord) {
                    frag.uv_x
                } else {
                    frag.uv.map(|s| s.map(|x| to_raw(x, &m.uv_fmt, &mut sat)))
                };
                let d = [
                    (uv[1][0] - uv[0][0]) * i64::from(w),
                    (uv[1][1] - uv[0][1]) * i64::from(h),
                    (uv[2][0] - uv[0][0]) * i64::from(w),
                    (uv[2][1] - uv[0][1]) * i64::from(h),
                ];
                let l = lod(d, fb, &hw.lod, &mut sat);
                let [u, v] = uv[0];
                let at = Lookup {
                    stage: kind,
                    lookup: 0,
                    tex: t,
                };
                let r = trilinear_traced(
                    &m.tex_fixed[t],
                    u,
                    v,
                    fb,
                    l,
                    hw.lod.lod_frac_bits,
                    plan.wrap,
                    &hw.trilinear,
                    &mut frag.trace,
                    at,
                );
                frag.rough_x = [0, 1, 2].map(|i| u32::from(r[i]));
                frag.rough = frag.rough_x.map(|x| from_unorm(x, tb));
            } else {
                let uv = &frag.uv;
                let (wf, hf) = (f64::from(w), f64::from(h));
                let l = lod_f64([
                    (uv[1][0] - uv[0][0]) * wf,
                    (uv[1][1] - uv[0][1]) * hf,
                    (uv[2][0] - uv[0][0]) * wf,
                    (uv[2][1] - uv[0][1]) * hf,
                ]);
                let r = trilinear_f64(&m.tex_float[t], uv[0][0], uv[0][1], l, plan.wrap);
                frag.rough = [r[0], r[1], r[2]];
                let at = Lookup {
                    stage: kind,
                    lookup: 0,
                    tex: t,
                };
                trace_float_fetch(m, frag, fixed_in(StageKind::Texcoord), plan.wrap, at, 1);
            }
        }
        StageKind::RoughShade => {
            let bf = &frag.bump;
            let cb = units.cfg.shade.shade_color_bits;
            if fixed {
                let rnd = units.cfg.shade.shade_rounding;
                let n = if fixed_in(StageKind::Perturb) {
                    bf.normal_x
                } else {
                    raw3(&bf.normal, m, &mut sat)
                };
                let eye = if fixed_in(StageKind::Normal) {
                    bf.to_eye_x
                } else {
                    raw3(&bf.to_eye, m, &mut sat)
                };
                let v = normalize3(&eye, [0, 0, 1i64 << f], &units.rsqrt, vc, &mut sat).v;
                let fr_fixed = fixed_in(StageKind::Frame);
                let (t_u, t_v, len) = if fr_fixed {
                    (bf.fr_t_u_x, bf.fr_t_v_x, bf.fr_len_x)
                } else {
                    (
                        raw3(&bf.fr_t_u, m, &mut sat),
                        raw3(&bf.fr_t_v, m, &mut sat),
                        bf.fr_len.map(|x| to_raw(x, &m.len_fmt, &mut sat)),
                    )
                };
                let tex = if fixed_in(StageKind::RoughFetch) {
                    frag.rough_x
                } else {
                    frag.rough.map(|x| to_unorm(x, tb))
                };
                let (dv, t) = decode_d(tex.map(u64::from), tb, &rcfg);
                let ri = RoughShadeInput {
                    t_u,
                    t_v,
                    dv: scale_d(dv, len, lfb, iso, &mut sat),
                    t,
                };
                let (kd, ks, mut acc) = super::bump_stages::fixed_material(
                    bp,
                    m,
                    plan.texture.is_some(),
                    fixed_in(StageKind::Trilinear),
                    frag.texel_x,
                    frag.texel,
                    cb,
                    rnd,
                );
                for light in &m.lights {
                    let l = match light.point {
                        Some(pi) => {
                            let lv = if fixed_in(StageKind::Normal) {
                                bf.to_light_x[pi]
                            } else {
                                raw3(&bf.to_light[pi], m, &mut sat)
                            };
                            normalize3(&lv, [0, 0, 1i64 << f], &units.rsqrt, vc, &mut sat).v
                        }
                        None => light.l_x,
                    };
                    let inp = BlinnPhongInput {
                        n,
                        l,
                        v,
                        shininess: bp.shininess,
                        kd,
                        ks,
                        light: light.color_x,
                    };
                    let (r, _) = rough_blinn_phong(&inp, &ri, &rcfg, units, &mut sat);
                    c.h_zero += u64::from(r.h_zero);
                    for ch in 0..3 {
                        acc[ch] += r.color[ch];
                    }
                }
                super::bump_stages::fixed_output(acc, frag, &mut sat, cb);
            } else {
                let v = fref::normalize_or(DVec3::from(bf.to_eye), DVec3::Z).0;
                let mut kd = bp.kd;
                if plan.texture.is_some() {
                    for ch in 0..3 {
                        kd[ch] *= frag.texel[ch];
                    }
                }
                let fr = fref::FrameF {
                    n: DVec3::from(bf.fr_n),
                    t_u: DVec3::from(bf.fr_t_u),
                    t_v: DVec3::from(bf.fr_t_v),
                    len_u: bf.fr_len[0],
                    len_v: bf.fr_len[1],
                    fallback: false,
                    zero_normal: false,
                };
                let mut acc = [0.0f64; 3];
                for ch in 0..3 {
                    acc[ch] = m.ambient[ch] * kd[ch];
                }
                let rexp = rcfg.exponent(bp.shininess);
                let enc = RoughnessEncoding::for_range_exp(rcfg.rough_range_exp);
                let dv = scale_d_f(enc.decode(frag.rough), bf.fr_len, iso);
                let norm = if rcfg.rough_normalize && rp.variant != RoughVariant::None {
                    normalize_factor(dv, rp.variant, rexp, bp.shininess)
                } else {
                    1.0
                };
                let n = DVec3::from(bf.normal);
                let kk = rp.truth_samples;
                let range = f64::from(vc.offset_int_bits.min(30)).exp2();
                let l0 = m.tex_float.get(bp.map).and_then(|l| l.first());
                for light in &m.lights {
                    let l = match light.point {
                        Some(pi) => fref::normalize_or(DVec3::from(bf.to_light[pi]), DVec3::Z).0,
                        None => DVec3::from(light.l_f),
                    };
                    let (col, hz) = match (kk, l0) {
                        (0, _) | (_, None) => rough_blinn_phong_f(
                            n,
                            l,
                            v,
                            [fr.t_u, fr.t_v],
                            dv,
                            rp.variant,
                            rexp,
                            norm,
                            [kd, bp.ks, light.color_f],
                        ),
                        (kk, Some(l0)) => {
                            let uv = &frag.uv;
                            let dx = [uv[1][0] - uv[0][0], uv[1][1] - uv[0][1]];
                            let dy = [uv[2][0] - uv[0][0], uv[2][1] - uv[0][1]];
                            let inv = 1.0 / f64::from(kk);
                            let mut sum = [0.0; 3];
                            let mut hz = false;
                            for j in 0..kk {
                                let tt = (f64::from(j) + 0.5) * inv - 0.5;
                                for i in 0..kk {
                                    let ss = (f64::from(i) + 0.5) * inv - 0.5;
                                    let su = uv[0][0] + ss * dx[0] + tt * dy[0];
                                    let sv = uv[0][1] + ss * dx[1] + tt * dy[1];
                                    let o = sample_offsets(l0, su, sv, range);
                                    let ns = fref::perturb_normal(&fr, o[0], o[1]);
                                    let (cs, h) = fref::blinn_phong(
                                        ns,
                                        l,
                                        v,
                                        bp.shininess,
                                        kd,
                                        bp.ks,
                                        light.color_f,
                                    );
                                    hz |= h;
                                    for ch in 0..3 {
                                        sum[ch] += cs[ch];
                                    }
                                }
                            }
                            (sum.map(|s| s * inv * inv), hz)
                        }
                    };
                    c.h_zero += u64::from(hz);
                    for ch in 0..3 {
                        acc[ch] += col[ch];
                    }
                }
                super::bump_stages::float_output(acc, frag, c);
            }
        }
        _ => {}
    }
    c.sat[k] = sat;
}

/// Stage-table entry of rough stage `K` (`StageKind::index`); it runs the twin `px.impls`
/// names for it.
pub fn row<const K: usize>(px: &Px, frag: &mut Frag, c: &mut Counters) {
    run_rough_stage(StageKind::ALL[K], px.plan, px.impls, px.m, frag, c);
}

/// Stage-table cost of rough stage `K`.
#[must_use]
pub fn row_cost<const K: usize>(m: &Machine, plan: &Plan) -> UnitCost {
    rough_stage_cost(m, StageKind::ALL[K], plan)
}
