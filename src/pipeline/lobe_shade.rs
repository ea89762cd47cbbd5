//! `lobe-shade`: a multiple surface (Fournier 1992, "Normal Distribution Functions and
//! Multiple Surfaces", eqs. 11-12 and sec. 4) shaded per pixel as the sum of its lobes' Phong
//! shadings, fixed (`hw_model::multi_lobe`) and float (`shading::multi_lobe::shade`).
//!
//! A made-up multiple-surface material (sec. 3.4: `[[materials.lobes]]` in a scene file, or
//! the built-in `fournier-*` scenes) runs `bary` (+ `texcoord`, `lod`, `trilinear` when
//! textured), `normal`, `frame` and `lobe-shade`: the bump stages' interpolation and the
//! material's local frame supply `n`, `t_u`, `t_v` ("the normal vectors are defined in the
//! surface local frame", sec. 4), and each lobe's direction `(x, y, z)` in that frame enters
//! as the slopes `(x / z, y / z)`, decoded by the frame unit like a bump offset. Colour:
//! `ambient kd + sum_lights light (kd D + ks S)` (the unit's `D`, `S`), saturating.
//!
//! Fitted lobes (`lobe-fetch`): the stored amplitude is the lobe's weight `alpha`, its
//! specular weight `alpha n / s` (the unit's `spec_recip`, `s` the material's exponent).
//!
//! The fixed twin quantizes the material's lobes into the unit's formats (`multi_lobe` config:
//! slopes, amplitudes, exponents); the float twin uses them unquantized, so the stage's error
//! includes the lobes' storage.

use super::bump::{
    bump_of, d3, fixed_eye, fixed_light, fixed_material, fixed_output, float_eye, float_light,
    float_output, point_lights, raw3,
};
use super::lobe_fit::{decode_lobe, float_lobe};
use super::stages::{Counters, Machine};
use super::{BumpPlan, Frag, Plan, Px, StageKind};
use crate::fixedpoint::to_raw;
use crate::scene::{MadeUpLobe, Material};
use crate::shading::multi_lobe::{shade, LobeF};
use crate::shading::reference::FrameF;
use glam::DVec3;
use hw_model::blinn_phong::mac_cost;
use hw_model::datapath::{Component, Datapath, Stage};
use hw_model::fixed::Format;
use hw_model::frame::Frame;
use hw_model::multi_lobe::{
    amp_format, fitted_weight_cost, max_exponent, multi_lobe_cost, multi_lobe_shade,
    shininess_recip, slope_format, LevelMix, Lobe, LobeLight, MultiLobeInput, MAX_LOBES,
};
use hw_model::rsqrt::rsqrt_cost;
use hw_model::trilinear::lerp;
use hw_model::vector::normalize_cost;
use hw_model::UnitCost;

/// What the `lobe-shade` stage of one material needs.
#[derive(Clone, Debug, PartialEq)]
pub struct LobePlan {
    /// The made-up lobes (at most [`MAX_LOBES`]).
    pub lobes: Vec<MadeUpLobe>,
    /// Lobes fitted to the bump map (`pipeline::lobe_fit`), fetched per pixel by `lobe-fetch`
    /// (then `lobes` is empty).
    pub fitted: Option<super::lobe_fit::FittedLobes>,
}

/// The plan of a made-up multiple-surface material (`None` for other materials): `bary`, the
/// texture stages when textured, `normal`, `frame` (the material's frame kind, or the
/// hardware's) and `lobe-shade`.
#[must_use]
pub fn plan_lobes(material: &Material, has_uvs: bool) -> Option<Plan> {
    if material.lobes.is_empty() {
        return None;
    }
    let textured = material.texture.is_some() && has_uvs;
    let mut stages = vec![StageKind::Bary];
    if textured {
        stages.extend([StageKind::Texcoord, StageKind::Lod, StageKind::Trilinear]);
    }
    stages.extend([StageKind::Normal, StageKind::Frame, StageKind::LobeShade]);
    let kd = material.kd.map(f64::from);
    Some(Plan {
        stages,
        texture: if textured { material.texture } else { None },
        const_color: [kd[0], kd[1], kd[2], 1.0],
        derivatives: textured,
        wrap: [material.wrap_s, material.wrap_t],
        bump: Some(BumpPlan {
            map: usize::MAX,
            frame: material.frame,
            main: material.main_direction,
            kd,
            ks: material.ks.map(f64::from),
            shininess: material.shininess,
        }),
        aniso: None,
        rough: None,
        ndf: None,
        env: None,
        toksvig: None,
        lean: None,
        lobes: Some(LobePlan {
            lobes: material
                .lobes
                .iter()
                .take(MAX_LOBES as usize)
                .copied()
                .collect(),
            fitted: None,
        }),
    })
}

/// Most lights passed to the unit at once (more are shaded in groups).
const LIGHT_GROUP: usize = 8;

/// Fixed twin: the frame (raw when `frame` ran fixed), the lobes quantized into the unit's
/// formats, the multi-lobe unit over the lights, plus the ambient term, saturating.
#[allow(clippy::needless_range_loop)]
pub fn fixed(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let (Some((bp, _)), Some(lp)) = (bump_of(px), &px.plan.lobes) else {
        return;
    };
    let m = px.m;
    let units = &m.units;
    let cfg = &m.hw.multi_lobe;
    let cb = units.cfg.shade.shade_color_bits;
    let rnd = units.cfg.shade.shade_rounding;
    let k = StageKind::LobeShade.index();
    let mut sat = c.sat[k];
    let bf = &frag.bump;
    let (n, t_u, t_v, len) = if px.fixed(StageKind::Frame) {
        (bf.fr_n_x, bf.fr_t_u_x, bf.fr_t_v_x, bf.fr_len_x)
    } else {
        (
            raw3(&bf.fr_n, &m.vec_fmt, &mut sat),
            raw3(&bf.fr_t_u, &m.vec_fmt, &mut sat),
            raw3(&bf.fr_t_v, &m.vec_fmt, &mut sat),
            bf.fr_len.map(|x| to_raw(x, &m.len_fmt, &mut sat)),
        )
    };
    let frame = Frame {
        n,
        t_u,
        t_v,
        len_u: len[0],
        len_v: len[1],
        fallback: false,
        zero_normal: false,
    };
    let sf = slope_format(cfg);
    let af = amp_format(cfg);
    let fetched_fixed = px.fixed(StageKind::LobeFetch);
    let lf = &frag.lobe;
    let wb = m.hw.lod.lod_frac_bits.min(30);
    // The lobes of one fetched level (fixed texels, or the float ones quantized).
    let fitted_lobes = |tx: &[[u16; 4]; MAX_LOBES as usize],
                        tf: &[[f32; 4]; MAX_LOBES as usize],
                        sat: &mut hw_model::SatCounter| {
        let mut lobes = [Lobe::default(); MAX_LOBES as usize];
        for j in 0..usize::from(lf.count).min(MAX_LOBES as usize) {
            lobes[j] = if fetched_fixed {
                decode_lobe(tx[j])
            } else {
                let t = tf[j].map(f64::from);
                Lobe {
                    slope: [to_raw(t[0], &sf, sat), to_raw(t[1], &sf, sat)],
                    amp: to_raw(t[2], &af, sat) as u64,
                    exponent: t[3].round().clamp(0.0, f64::from(max_exponent(cfg))) as u32,
                }
            };
        }
        lobes
    };
    let mut lobes = [Lobe::default(); MAX_LOBES as usize];
    let mut coarse = None;
    let nl = if lp.fitted.is_some() {
        lobes = fitted_lobes(&lf.texel_x, &lf.texel, &mut sat);
        if lf.blend {
            let w = if fetched_fixed {
                lf.weight_x
            } else {
                to_raw(lf.weight, &Format::unsigned(1, wb, rnd), &mut sat) as u32
            };
            coarse = Some((fitted_lobes(&lf.coarse_x, &lf.coarse, &mut sat), w));
        }
        usize::from(lf.count).min(MAX_LOBES as usize)
    } else {
        for (q, l) in lobes.iter_mut().zip(&lp.lobes) {
            let s = l.slopes();
            *q = Lobe {
                slope: [to_raw(s[0], &sf, &mut sat), to_raw(s[1], &sf, &mut sat)],
                amp: to_raw(f64::from(l.amplitude), &af, &mut sat) as u64,
                exponent: l.exponent,
            };
        }
        lp.lobes.len().min(MAX_LOBES as usize)
    };
    let spec_recip = lp
        .fitted
        .as_ref()
        .map(|_| shininess_recip(bp.shininess, cfg, &units.cfg));
    let v = fixed_eye(m, bf, px.fixed(StageKind::Normal), &mut sat);
    let (kd, ks, mut acc) = fixed_material(
        bp,
        m,
        px.plan.texture.is_some(),
        px.fixed(StageKind::Trilinear),
        frag.texel_x,
        frag.texel,
        cb,
        rnd,
    );
    let mut acc_coarse = acc;
    for group in m.lights.chunks(LIGHT_GROUP) {
        let mut ls = [LobeLight {
            l: [0; 3],
            color: [0; 3],
        }; LIGHT_GROUP];
        for (q, light) in ls.iter_mut().zip(group) {
            *q = LobeLight {
                l: fixed_light(m, bf, light, px.fixed(StageKind::Normal), &mut sat),
                color: light.color_x,
            };
        }
        let mut inp = MultiLobeInput {
            frame: &frame,
            lobes: &lobes[..nl],
            lights: &ls[..group.len()],
            v,
            kd,
            ks,
            spec_recip,
        };
        let out = multi_lobe_shade(&inp, cfg, units, &mut sat);
        c.h_zero += u64::from(out.h_zero);
        for ch in 0..3 {
            acc[ch] += out.sum[ch];
        }
        if let Some((cl, _)) = &coarse {
            inp.lobes = &cl[..nl];
            let out = multi_lobe_shade(&inp, cfg, units, &mut sat);
            for ch in 0..3 {
                acc_coarse[ch] += out.sum[ch];
            }
        }
    }
    if let Some((_, w)) = coarse {
        // Both levels' colours (saturated, counted), blended by the LOD fraction.
        let max = (1u64 << cb) - 1;
        for ch in 0..3 {
            let (a, b) = (acc[ch], acc_coarse[ch]);
            sat.saturated += u64::from(a > max) + u64::from(b > max);
            acc[ch] = u64::from(lerp(a.min(max) as u32, b.min(max) as u32, w, wb, rnd));
        }
    }
    fixed_output(acc, frag, &mut sat, cb);
    c.sat[k] = sat;
}

/// Float twin: `shading::multi_lobe::shade` with the material's unquantized lobes.
#[allow(clippy::needless_range_loop)]
pub fn float(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let (Some((bp, _)), Some(lp)) = (bump_of(px), &px.plan.lobes) else {
        return;
    };
    let m = px.m;
    let bf = &frag.bump;
    let fr = FrameF {
        n: d3(&bf.fr_n),
        t_u: d3(&bf.fr_t_u),
        t_v: d3(&bf.fr_t_v),
        len_u: bf.fr_len[0],
        len_v: bf.fr_len[1],
        fallback: false,
        zero_normal: false,
    };
    let lf = &frag.lobe;
    let cfg = &m.hw.multi_lobe;
    let fetched_fixed = px.fixed(StageKind::LobeFetch);
    // The lobes of one fetched level (float texels, or the fixed ones decoded).
    let fitted_lobes = |tx: &[[u16; 4]; MAX_LOBES as usize],
                        tf: &[[f32; 4]; MAX_LOBES as usize]| {
        let mut lobes = [LobeF::default(); MAX_LOBES as usize];
        for j in 0..usize::from(lf.count).min(MAX_LOBES as usize) {
            lobes[j] = if fetched_fixed {
                let q = decode_lobe(tx[j]);
                let sf = slope_format(cfg).frac_bits;
                let af = amp_format(cfg).frac_bits;
                LobeF {
                    slope: q.slope.map(|x| x as f64 / f64::from(sf).exp2()),
                    amp: q.amp as f64 / f64::from(af).exp2(),
                    exponent: q.exponent,
                }
            } else {
                float_lobe(tf[j])
            };
        }
        lobes
    };
    let mut lobes = [LobeF::default(); MAX_LOBES as usize];
    let mut coarse = None;
    let nl = if lp.fitted.is_some() {
        lobes = fitted_lobes(&lf.texel_x, &lf.texel);
        if lf.blend {
            let w = if fetched_fixed {
                f64::from(lf.weight_x) / f64::from(m.hw.lod.lod_frac_bits.min(30)).exp2()
            } else {
                lf.weight
            };
            coarse = Some((fitted_lobes(&lf.coarse_x, &lf.coarse), w));
        }
        usize::from(lf.count).min(MAX_LOBES as usize)
    } else {
        for (q, l) in lobes.iter_mut().zip(&lp.lobes) {
            *q = LobeF {
                slope: l.slopes(),
                amp: f64::from(l.amplitude),
                exponent: l.exponent,
            };
        }
        lp.lobes.len().min(MAX_LOBES as usize)
    };
    let fitted_shininess = lp.fitted.as_ref().map(|_| f64::from(bp.shininess.max(1)));
    let v = float_eye(bf);
    let mut kd = bp.kd;
    if px.plan.texture.is_some() {
        for ch in 0..3 {
            kd[ch] *= frag.texel[ch];
        }
    }
    let mut acc = [0.0f64; 3];
    for ch in 0..3 {
        acc[ch] = m.ambient[ch] * kd[ch];
    }
    let mut acc_coarse = acc;
    for group in m.lights.chunks(LIGHT_GROUP) {
        let mut ls = [(DVec3::ZERO, [0.0; 3]); LIGHT_GROUP];
        for (q, light) in ls.iter_mut().zip(group) {
            *q = (float_light(bf, light), light.color_f);
        }
        let lights = &ls[..group.len()];
        let out = shade(
            &fr,
            &lobes[..nl],
            nl,
            lights,
            v,
            kd,
            bp.ks,
            fitted_shininess,
        );
        c.h_zero += u64::from(out.h_zero);
        for ch in 0..3 {
            acc[ch] += out.sum[ch];
        }
        if let Some((cl, _)) = &coarse {
            let out = shade(&fr, &cl[..nl], nl, lights, v, kd, bp.ks, fitted_shininess);
            for ch in 0..3 {
                acc_coarse[ch] += out.sum[ch];
            }
        }
    }
    if let Some((_, w)) = coarse {
        for ch in 0..3 {
            let (a, b) = (acc[ch].clamp(0.0, 1.0), acc_coarse[ch].clamp(0.0, 1.0));
            acc[ch] = a + (b - a) * w;
        }
    }
    float_output(acc, frag, c);
}

/// The colour blend of two levels: one lerp per channel (`trilinear::lerp`: a multiply by
/// the LOD fraction and an add).
fn level_blend_cost(m: &Machine) -> UnitCost {
    let g = m.hw.timing.gate_levels_per_cycle;
    let cb = m.units.cfg.shade.shade_color_bits;
    let wb = m.hw.lod.lod_frac_bits.min(30);
    let d = Datapath::new().stage(
        Stage::new("level blend")
            .then(Component::Multiplier {
                a: cb + 1,
                b: wb + 1,
            })
            .then(Component::Adder { width: cb + wb + 1 }),
    );
    UnitCost {
        ops: 3,
        cycles: d.latency(g),
        texels: 0,
    }
}

/// One invocation: the multi-lobe unit for the plan's K lobes and the scene's lights, the
/// eye and point-light normalizations, the ambient multiply-add (+1 for the texture).
#[must_use]
pub fn cost(m: &Machine, plan: &Plan) -> UnitCost {
    let (Some(_), Some(lp)) = (&plan.bump, &plan.lobes) else {
        return UnitCost::default();
    };
    let u = &m.units;
    let g = m.hw.timing.gate_levels_per_cycle;
    let np = point_lights(m) as u32;
    let nz = normalize_cost(&u.cfg.vector, rsqrt_cost(&u.cfg.rsqrt, g), g);
    let mac = mac_cost(&u.cfg, g);
    let lights = m.lights.len() as u32;
    let k = lp
        .fitted
        .as_ref()
        .map_or(lp.lobes.len() as u32, |f| f.lobes);
    let mut c = multi_lobe_cost(&m.hw.multi_lobe, u, k, lights, g)
        .plus(nz.times(1 + np))
        .plus(mac);
    if lp.fitted.is_some() {
        c = c.plus(fitted_weight_cost(&m.hw.multi_lobe, &u.cfg, k, lights, g));
        if m.hw.multi_lobe.lobe_level_mix == LevelMix::Blend {
            // The coarser level's shading and the colour blend.
            let second = multi_lobe_cost(&m.hw.multi_lobe, u, k, lights, g)
                .plus(fitted_weight_cost(&m.hw.multi_lobe, &u.cfg, k, lights, g));
            c = c.plus(second).plus(level_blend_cost(m));
        }
    }
    if plan.texture.is_some() {
        c = c.plus(mac);
    }
    c
}
