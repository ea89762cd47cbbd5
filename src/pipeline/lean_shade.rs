//! `lean-shade`: LEAN mapping's specular term (Olano and Baker 2010; `hw_model::lean`) for
//! every light, with the Blinn-Phong unit's colour ending, in place of `phong`: diffuse
//! `kd max(0, n.l)` of the perturbed normal, specular `ks D` with `D` the slope Gaussian of the
//! filtered moments at the half vector's projected slope (peak 1 on a flat texel), zero where
//! `n.l <= 0`.

use super::bump::{
    d3, fixed_eye, fixed_light, fixed_material, fixed_output, float_eye, float_light, float_output,
    point_lights, raw3,
};
use super::lean::lean_of;
use super::stages::{Counters, Machine};
use super::{Frag, Plan, Px, StageKind};
use crate::fixedpoint::to_unorm;
use crate::shading::lean::{decode_moments, lean_f};
use glam::DVec3;
use hw_model::blinn_phong::{lit_color, mac_cost, BlinnPhongInput};
use hw_model::lean::{lean, lean_cost, LeanInput};
use hw_model::rsqrt::rsqrt_cost;
use hw_model::vector::{dot3, dot_cost, normalize3, normalize_cost};
use hw_model::UnitCost;

/// Fixed twin: per light `n.l`, the half vector (vector unit), its frame components (three
/// dots), the LEAN unit, the colour ending; summed saturating into `shade_color_bits`.
/// Without a fixed density unit (`ndf_norm = exact` makes none) it runs the float twin.
#[allow(clippy::needless_range_loop)]
pub fn fixed(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let Some((bp, _)) = lean_of(px) else {
        return;
    };
    let m = px.m;
    let Some(density) = m.lean_density() else {
        return float(px, frag, c);
    };
    let units = &m.units;
    let vc = &units.cfg.vector;
    let f = vc.vector_frac_bits;
    let p = units.cfg.pow.pow_frac_bits.clamp(8, 24);
    let cb = units.cfg.shade.shade_color_bits;
    let rnd = units.cfg.shade.shade_rounding;
    let tb = m.hw.trilinear.texel_bits;
    let mut sat = c.sat[StageKind::LeanShade.index()];
    let bf = &frag.bump;
    let vf = &m.vec_fmt;
    let n = if px.fixed(StageKind::Perturb) {
        bf.normal_x
    } else {
        raw3(&bf.normal, vf, &mut sat)
    };
    let (t_u, t_v, fr_n) = if px.fixed(StageKind::Frame) {
        (bf.fr_t_u_x, bf.fr_t_v_x, bf.fr_n_x)
    } else {
        (
            raw3(&bf.fr_t_u, vf, &mut sat),
            raw3(&bf.fr_t_v, vf, &mut sat),
            raw3(&bf.fr_n, vf, &mut sat),
        )
    };
    let b = if px.fixed(StageKind::BumpFetch) {
        bf.texel_x
    } else {
        bf.texel.map(|x| to_unorm(x, tb))
    };
    let mtex = if px.fixed(StageKind::LeanFetch) {
        frag.lean.texel_x
    } else {
        frag.lean.texel.map(|x| to_unorm(x, tb))
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
    let one_f = 1i64 << f;
    for light in &m.lights {
        let l = fixed_light(m, bf, light, px.fixed(StageKind::Normal), &mut sat);
        let ndl = dot3(&n, &l, vc, &mut sat).clamp(0, one_f);
        let sum = [l[0] + v[0], l[1] + v[1], l[2] + v[2]];
        let h_zero = sum == [0; 3];
        c.h_zero += u64::from(h_zero);
        let spec = if h_zero || ndl == 0 {
            0
        } else {
            let h = normalize3(&sum, [0; 3], &units.rsqrt, vc, &mut sat).v;
            let hf = [
                dot3(&h, &t_u, vc, &mut sat),
                dot3(&h, &t_v, vc, &mut sat),
                dot3(&h, &fr_n, vc, &mut sat),
            ];
            let inp = LeanInput {
                b,
                m: mtex,
                texel_bits: tb,
                offset_int_bits: vc.offset_int_bits,
                h: hf,
                h_frac_bits: f,
                shininess: bp.shininess,
            };
            lean(&inp, &m.hw.lean, density, p, &mut sat).d
        };
        let inp = BlinnPhongInput {
            n,
            l,
            v,
            shininess: 0,
            kd,
            ks,
            light: light.color_x,
        };
        let col = lit_color(&inp, ndl, spec, units, &mut sat);
        for ch in 0..3 {
            acc[ch] += col[ch];
        }
    }
    fixed_output(acc, frag, &mut sat, cb);
    c.sat[StageKind::LeanShade.index()] = sat;
}

/// Float twin: `shading::lean::lean_f` on the decoded filtered offsets and moments per light.
#[allow(clippy::needless_range_loop)]
pub fn float(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let Some((bp, _)) = lean_of(px) else {
        return;
    };
    let m = px.m;
    let bf = &frag.bump;
    let n = d3(&bf.normal);
    let v = float_eye(bf);
    let (t_u, t_v, fr_n) = (d3(&bf.fr_t_u), d3(&bf.fr_t_v), d3(&bf.fr_n));
    let range = f64::from(m.units.cfg.vector.offset_int_bits.min(30)).exp2();
    let b = bf.texel.map(|t| (t - 0.5) * 2.0 * range);
    let mm = decode_moments(frag.lean.texel, m.hw.lean.lean_moment_exp);
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
    for light in &m.lights {
        let l = float_light(bf, light);
        let ndl = n.dot(l).clamp(0.0, 1.0);
        let sum = l + v;
        let h_zero = sum == DVec3::ZERO;
        c.h_zero += u64::from(h_zero);
        let spec = if h_zero || ndl == 0.0 {
            0.0
        } else {
            let h = sum.normalize();
            lean_f(
                b,
                mm,
                DVec3::new(h.dot(t_u), h.dot(t_v), h.dot(fr_n)),
                bp.shininess,
            )
        };
        for ch in 0..3 {
            acc[ch] += (light.color_f[ch] * (kd[ch] * ndl + bp.ks[ch] * spec)).clamp(0.0, 1.0);
        }
    }
    float_output(acc, frag, c);
}

/// One invocation: per light the LEAN unit, four dots, the half-vector normalization and the
/// colour multiply-accumulate; the eye and point light normalizations, the ambient (+1 for the
/// texture).
#[must_use]
pub fn cost(m: &Machine, plan: &Plan) -> UnitCost {
    if plan.bump.is_none() || plan.lean.is_none() {
        return UnitCost::default();
    }
    let u = &m.units;
    let g = m.hw.timing.gate_levels_per_cycle;
    let np = point_lights(m) as u32;
    let nz = normalize_cost(&u.cfg.vector, rsqrt_cost(&u.cfg.rsqrt, g), g);
    let mac = mac_cost(&u.cfg, g);
    let lights = m.lights.len() as u32;
    let per_light = lean_cost(&m.hw.lean, g)
        .plus(dot_cost(&u.cfg.vector, g).times(4))
        .plus(nz)
        .plus(mac);
    let mut c = per_light.times(lights).plus(nz.times(1 + np)).plus(mac);
    if plan.texture.is_some() {
        c = c.plus(mac);
    }
    c
}
