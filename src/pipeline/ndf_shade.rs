//! `ndf-shade`: per light, `h` in the local frame, then `hw_model::ndf::NdfUnit` (Sigma, its
//! inverse, Mahalanobis distance, density, normalization), times `ks` and the light; plus
//! Lambert diffuse on the interpolated normal and the ambient term (Olano and North 1997,
//! "Normal Distribution Mapping", sections 5-6). The specular term is `ks light D 2 pi / s`
//! ([`super::ndf`]). `ndf_norm = exact` has no fixed unit: the fixed twin runs the float one.

use super::bump::{
    fixed_eye, fixed_light, fixed_output, float_eye, float_light, float_output, point_lights,
};
use super::ndf::NdfPlan;
use super::stages::{Counters, Machine};
use super::{BumpPlan, Frag, Plan, Px, StageKind};
use crate::fixedpoint::{from_unorm, to_raw, to_unorm};
use crate::shading::ndf::{eval_float, ground_truth, Moments};
use crate::shading::reference as fref;
use glam::DVec3;
use hw_model::blinn_phong::mac_cost;
use hw_model::config::HwConfig;
use hw_model::fixed::{round_shift_right_wide, SatCounter};
use hw_model::modulate::modulate;
use hw_model::ndf::{ndf_cost, NdfTexels, NDF_FRAC};
use hw_model::rsqrt::rsqrt_cost;
use hw_model::vector::{dot3, normalize3, normalize_cost, Vec3x};
use hw_model::UnitCost;

/// The NDF and bump plans of the pixel's material; `None` (the stage does nothing) without
/// either.
fn plans<'a>(px: &Px<'a>) -> Option<(&'a NdfPlan, &'a BumpPlan)> {
    Some((px.plan.ndf.as_ref()?, px.plan.bump.as_ref()?))
}

/// The inverse peak `2 pi / s` of the normalized base lobe of shininess `s`.
fn spec_scale(np: &NdfPlan) -> f64 {
    2.0 * std::f64::consts::PI / f64::from(np.shininess.max(1))
}

/// Fixed twin: the frame, eye and light vectors in vector format, the NDF unit per light, the
/// diffuse and specular products rounded into `shade_color_bits` and summed saturating.
#[allow(clippy::needless_range_loop)]
pub fn fixed(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let Some((np, bp)) = plans(px) else { return };
    let m = px.m;
    let Some(unit) = m.ndf() else {
        return float(px, frag, c);
    };
    let hw = m.hw;
    let mb = hw.ndf.moment_bits;
    let bf = &frag.bump;
    let units = &m.units;
    let vc = &units.cfg.vector;
    let f = vc.vector_frac_bits;
    let cb = units.cfg.shade.shade_color_bits;
    let spec_scale = spec_scale(np);
    let mut sat = c.sat[StageKind::NdfShade.index()];
    let rnd = units.cfg.shade.shade_rounding;
    let raw_frame = px.fixed(StageKind::Frame);
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
    let texels = if px.fixed(StageKind::NdfFetch) {
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
    let one = [0, 0, 1i64 << f];
    let v = fixed_eye(m, bf, px.fixed(StageKind::Normal), &mut sat);
    let kd = bp.kd.map(|x| to_unorm(x, cb));
    let ks = bp.ks.map(|x| to_unorm(x, cb));
    let ndf_f = hw.ndf.ndf_frac_bits;
    let scale_q = crate::fixedpoint::to_raw_nearest(spec_scale, 30);
    let mut acc = [0u64; 3];
    for ch in 0..3 {
        acc[ch] = u64::from(modulate(m.ambient_x[ch] as u32, cb, kd[ch], cb, cb, rnd));
    }
    for light in &m.lights {
        let l = fixed_light(m, bf, light, px.fixed(StageKind::Normal), &mut sat);
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
            let diff = round_shift_right_wide(i128::from(kdl) * i128::from(ndl), f, rnd);
            let sp = round_shift_right_wide(i128::from(ksl) * i128::from(spec), ndf_f, rnd);
            acc[ch] = acc[ch]
                .saturating_add(diff.max(0) as u64)
                .saturating_add(sp.max(0) as u64);
        }
    }
    fixed_output(acc, frag, &mut sat, cb);
    c.sat[StageKind::NdfShade.index()] = sat;
}

/// Float twin: the decoded moments and `shading::ndf::eval_float` per light, or the ground
/// truth of the finest normals when the run has it ([`super::ndf::NdfTruth`]).
#[allow(clippy::needless_range_loop)]
pub fn float(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let Some((np, bp)) = plans(px) else { return };
    let m = px.m;
    let hw = m.hw;
    let mb = hw.ndf.moment_bits;
    let bf = &frag.bump;
    let spec_scale = spec_scale(np);
    let texel = if px.fixed(StageKind::NdfFetch) {
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
    let v = float_eye(bf);
    let mut acc = [0.0f64; 3];
    for ch in 0..3 {
        acc[ch] = m.ambient[ch] * bp.kd[ch];
    }
    for light in &m.lights {
        let l = float_light(bf, light);
        let ndl = n.dot(l).max(0.0);
        if ndl <= 0.0 {
            continue;
        }
        let hv = fref::normalize_or(l + v, n).0;
        let ht = fref::normalize_or(DVec3::new(hv.dot(tu), hv.dot(tv), hv.dot(n)), DVec3::Z).0;
        let d = match truth {
            Some(tr) => {
                let (wf, hf) = (f64::from(tr.width), f64::from(tr.height));
                let uv = &frag.uv;
                let d = |k: usize| [(uv[k][0] - uv[0][0]) * wf, (uv[k][1] - uv[0][1]) * hf];
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
    float_output(acc, frag, c);
}

/// One invocation: the NDF unit per light (its texels are the fetch's), the normalizations of
/// the eye, point light, `h` and `h` in the frame, the ambient and four MACs per light.
#[must_use]
pub fn cost(m: &Machine, plan: &Plan) -> UnitCost {
    if plan.ndf.is_none() {
        return UnitCost::default();
    }
    let hw = m.hw;
    let g = hw.timing.gate_levels_per_cycle;
    let u = &m.units;
    let lights = m.lights.len() as u32;
    let np = point_lights(m) as u32;
    let nz = normalize_cost(&u.cfg.vector, rsqrt_cost(&u.cfg.rsqrt, g), g);
    let mac = mac_cost(&u.cfg, g);
    // `exact` has no unit cost (float only): the stage's cost is then incomplete and
    // `render` marks the cycle estimate as not modelled ([`super::ndf::EXACT_NOT_MODELLED`]).
    let mut unit = ndf_cost(&hw.ndf, &m.recip.cost(g), &hw.shading.rsqrt, g).unwrap_or_default();
    unit.texels = 0;
    // Per light: l (point lights), h, h in the frame (3 dots), n.l, D, two MACs.
    unit.times(lights)
        .plus(nz.times(1 + np + 2 * lights))
        .plus(mac.times(1 + 4 * lights))
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
