//! `toksvig-shade`: Blinn-Phong of the perturbed normal with Toksvig's adjusted exponent and
//! specular scale (Toksvig 2005, eq. 6 and the `(1 + s') / (1 + s)` factor;
//! `hw_model::toksvig`, `hw_model::blinn_phong`) over every light, in place of `phong`.

use super::bump::{
    d3, fixed_eye, fixed_light, fixed_material, fixed_output, float_eye, float_light, float_output,
    point_lights, raw3,
};
use super::stages::{Counters, Machine};
use super::toksvig::toksvig_of;
use super::{Frag, Plan, Px, StageKind};
use crate::fixedpoint::to_unorm;
use crate::shading::toksvig::{blinn_phong_real, mean_length, toksvig_f};
use hw_model::blinn_phong::{blinn_phong, blinn_phong_cost, mac_cost, BlinnPhongInput};
use hw_model::rsqrt::rsqrt_cost;
use hw_model::toksvig::{toksvig, toksvig_cost};
use hw_model::vector::normalize_cost;
use hw_model::UnitCost;

/// Fixed twin: the Toksvig unit on the filtered texel (once per pixel), then the Blinn-Phong
/// unit per light with the adjusted integer exponent and scaled `ks`, summed saturating into
/// `shade_color_bits`.
#[allow(clippy::needless_range_loop)]
pub fn fixed(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let Some((bp, _)) = toksvig_of(px) else {
        return;
    };
    let m = px.m;
    let units = &m.units;
    let cb = units.cfg.shade.shade_color_bits;
    let rnd = units.cfg.shade.shade_rounding;
    let tb = m.hw.trilinear.texel_bits;
    let mut sat = c.sat[StageKind::ToksvigShade.index()];
    let bf = &frag.bump;
    let n = if px.fixed(StageKind::Perturb) {
        bf.normal_x
    } else {
        raw3(&bf.normal, &m.vec_fmt, &mut sat)
    };
    let tex = if px.fixed(StageKind::ToksvigFetch) {
        frag.toksvig.texel_x
    } else {
        frag.toksvig.texel.map(|x| to_unorm(x, tb))
    };
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
    let t = toksvig(
        tex,
        tb,
        bp.shininess,
        ks.map(|k| k as u32),
        cb,
        &m.hw.toksvig,
        &mut sat,
    );
    let ks = t.ks.map(u64::from);
    for light in &m.lights {
        let l = fixed_light(m, bf, light, px.fixed(StageKind::Normal), &mut sat);
        let inp = BlinnPhongInput {
            n,
            l,
            v,
            shininess: t.exponent,
            kd,
            ks,
            light: light.color_x,
        };
        let r = blinn_phong(&inp, units, &mut sat);
        c.h_zero += u64::from(r.h_zero);
        for ch in 0..3 {
            acc[ch] += r.color[ch];
        }
    }
    fixed_output(acc, frag, &mut sat, cb);
    c.sat[StageKind::ToksvigShade.index()] = sat;
}

/// Float twin: `|Na|` of the filtered texel, the real exponent and scale
/// (`shading::toksvig::toksvig_f`), Blinn-Phong with the real exponent per light.
#[allow(clippy::needless_range_loop)]
pub fn float(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let Some((bp, _)) = toksvig_of(px) else {
        return;
    };
    let m = px.m;
    let bf = &frag.bump;
    let n = d3(&bf.normal);
    let v = float_eye(bf);
    let mut kd = bp.kd;
    if px.plan.texture.is_some() {
        for ch in 0..3 {
            kd[ch] *= frag.texel[ch];
        }
    }
    let (sp, scale) = toksvig_f(mean_length(frag.toksvig.texel), bp.shininess);
    let ks = bp.ks.map(|k| k * scale);
    let mut acc = [0.0f64; 3];
    for ch in 0..3 {
        acc[ch] = m.ambient[ch] * kd[ch];
    }
    for light in &m.lights {
        let l = float_light(bf, light);
        let (col, hz) = blinn_phong_real(n, l, v, sp, kd, ks, light.color_f);
        c.h_zero += u64::from(hz);
        for ch in 0..3 {
            acc[ch] += col[ch];
        }
    }
    float_output(acc, frag, c);
}

/// One invocation: the Toksvig unit, the Blinn-Phong unit per light, the normalizations of the
/// eye and point light vectors, the ambient and per-light multiply-accumulates (+1 for the
/// texture).
#[must_use]
pub fn cost(m: &Machine, plan: &Plan) -> UnitCost {
    if plan.bump.is_none() || plan.toksvig.is_none() {
        return UnitCost::default();
    }
    let u = &m.units;
    let g = m.hw.timing.gate_levels_per_cycle;
    let np = point_lights(m) as u32;
    let nz = normalize_cost(&u.cfg.vector, rsqrt_cost(&u.cfg.rsqrt, g), g);
    let mac = mac_cost(&u.cfg, g);
    let lights = m.lights.len() as u32;
    let mut c = toksvig_cost(&m.hw.toksvig, m.hw.trilinear.texel_bits, g)
        .plus(blinn_phong_cost(u, g).times(lights))
        .plus(nz.times(1 + np))
        .plus(mac.times(1 + lights));
    if plan.texture.is_some() {
        c = c.plus(mac);
    }
    c
}
