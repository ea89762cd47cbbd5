//! `rough-shade`: Blinn-Phong with the modified specular term `cos^2 a' = cos^2 a / (|d|^4 /
//! |D d|^2 + cos^2 a)` (or a variant) for every light, in place of `phong` (Schilling 1997,
//! "Antialiasing of Bump-Maps", Appendix A; `hw_model::roughness`). A ground-truth plan
//! ([`super::rough::RoughPlan::truth_samples`]) shades the box-filtered mean of `k x k`
//! sub-samples of the finest offsets in float.

use super::bump::{
    fixed_eye, fixed_light, fixed_material, fixed_output, float_eye, float_light, float_output,
    point_lights, raw3,
};
use super::rough::{rough_config, rough_of};
use super::stages::{Counters, Machine};
use super::{Frag, Plan, Px, StageKind};
use crate::fixedpoint::{floor_exact, to_raw, to_unorm};
use crate::reference::wrap_index_f64;
use crate::shading::reference as fref;
use crate::shading::roughness::{
    normalize_factor, rough_blinn_phong_f, scale_d_f, RoughnessEncoding,
};
use glam::DVec3;
use hw_model::blinn_phong::{mac_cost, BlinnPhongInput};
use hw_model::roughness::{
    decode_d, rough_blinn_phong, rough_blinn_phong_cost, scale_d, RoughShadeInput, RoughVariant,
};
use hw_model::rsqrt::rsqrt_cost;
use hw_model::vector::normalize_cost;
use hw_model::wrap::WrapMode;
use hw_model::UnitCost;

/// Fixed twin: the eye and light vectors normalized, the D texel decoded and scaled by the
/// frame lengths, the modified Blinn-Phong unit per light, summed saturating into
/// `shade_color_bits`. A ground-truth plan runs the float twin.
#[allow(clippy::needless_range_loop)]
pub fn fixed(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let Some((bp, rp)) = rough_of(px) else { return };
    if rp.truth_samples != 0 {
        return float(px, frag, c);
    }
    let m = px.m;
    let units = &m.units;
    let lfb = units.cfg.frame.frame_len_frac_bits;
    let tb = m.hw.trilinear.texel_bits;
    let cb = units.cfg.shade.shade_color_bits;
    let rnd = units.cfg.shade.shade_rounding;
    let iso = rp.variant == RoughVariant::Isotropic;
    let rcfg = rough_config(m.hw, rp);
    let mut sat = c.sat[StageKind::RoughShade.index()];
    let bf = &frag.bump;
    let vf = &m.vec_fmt;
    let n = if px.fixed(StageKind::Perturb) {
        bf.normal_x
    } else {
        raw3(&bf.normal, vf, &mut sat)
    };
    let v = fixed_eye(m, bf, px.fixed(StageKind::Normal), &mut sat);
    let (t_u, t_v, len) = if px.fixed(StageKind::Frame) {
        (bf.fr_t_u_x, bf.fr_t_v_x, bf.fr_len_x)
    } else {
        (
            raw3(&bf.fr_t_u, vf, &mut sat),
            raw3(&bf.fr_t_v, vf, &mut sat),
            bf.fr_len.map(|x| to_raw(x, &m.len_fmt, &mut sat)),
        )
    };
    let tex = if px.fixed(StageKind::RoughFetch) {
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
    for light in &m.lights {
        let l = fixed_light(m, bf, light, px.fixed(StageKind::Normal), &mut sat);
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
    fixed_output(acc, frag, &mut sat, cb);
    c.sat[StageKind::RoughShade.index()] = sat;
}

/// Float twin: `shading::roughness::rough_blinn_phong_f` per light, or with ground truth the
/// mean of plain Blinn-Phong over `k x k` sub-sample normals of the finest offsets.
#[allow(clippy::needless_range_loop)]
pub fn float(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let Some((bp, rp)) = rough_of(px) else { return };
    let m = px.m;
    let vc = &m.units.cfg.vector;
    let iso = rp.variant == RoughVariant::Isotropic;
    let rcfg = rough_config(m.hw, rp);
    let bf = &frag.bump;
    let v = float_eye(bf);
    let mut kd = bp.kd;
    if px.plan.texture.is_some() {
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
        let l = float_light(bf, light);
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
                        let (cs, h) =
                            fref::blinn_phong(ns, l, v, bp.shininess, kd, bp.ks, light.color_f);
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
    float_output(acc, frag, c);
}

/// One invocation: the modified Blinn-Phong unit per light, the normalizations of the eye and
/// point light vectors, the ambient and per-light multiply-accumulates (+1 for the texture).
#[must_use]
pub fn cost(m: &Machine, plan: &Plan) -> UnitCost {
    let (Some(_), Some(rp)) = (&plan.bump, &plan.rough) else {
        return UnitCost::default();
    };
    let u = &m.units;
    let g = m.hw.timing.gate_levels_per_cycle;
    let cfg = rough_config(m.hw, rp);
    let np = point_lights(m) as u32;
    let lights = m.lights.len() as u32;
    let nz = normalize_cost(&u.cfg.vector, rsqrt_cost(&u.cfg.rsqrt, g), g);
    let mac = mac_cost(&u.cfg, g);
    let mut c = rough_blinn_phong_cost(&cfg, u, g)
        .times(lights)
        .plus(nz.times(1 + np))
        .plus(mac.times(1 + lights));
    if plan.texture.is_some() {
        c = c.plus(mac);
    }
    c
}

/// Bilinear, wrapping sample of the two offset channels of a float level at `(u, v)`,
/// decoded with range `2^offset_int_bits`.
pub(super) fn sample_offsets(
    l0: &crate::reference::LevelF,
    u: f64,
    v: f64,
    range: f64,
) -> [f64; 2] {
    let (w, h) = (f64::from(l0.width), f64::from(l0.height));
    let fix = |x: f64| if x.is_finite() { x } else { 0.0 };
    let (x, y) = (fix(u) * w - 0.5, fix(v) * h - 0.5);
    let (x0, y0) = (floor_exact(x), floor_exact(y));
    let (fx, fy) = (x - x0, y - y0);
    let wrap = |i: f64, n: u32| wrap_index_f64(i, n, WrapMode::Repeat).min(n - 1) as usize;
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
