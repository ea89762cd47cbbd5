//! `env-fetch`: the environment-map lookup of a bump material (Schilling 1997, "balanced
//! system"; `hw_model::{reflect, cube_face, env_lod, footprint}`), appended after its shading
//! stage. Per pixel:
//!
//! 1. `r = 2 (n . v) n - v` from the perturbed normal and the unit eye vector (reflect unit).
//! 2. Its face and face coordinates (cube-face unit, the reciprocal unit for `1/|ma|`).
//! 3. The screen derivatives: at the helper samples (x+1, y), (x, y+1) the interpolated
//!    normal and eye vector (interpolator, normalized) give `r_h = r + R(n_i(h), v(h)) -
//!    R(n_i, v)`: the change of the unperturbed reflection, added to the perturbed one (the
//!    bump map's variation inside the pixel is what the roughness stands for). Each is
//!    projected on the pixel's face.
//! 4. With `env_filter = lambda1 | ellipse` and a roughness map (`rough-fetch` ran): the
//!    ellipse `D` (scaled by the frame lengths as `rough-shade` does) is carried to the face
//!    (and by `1/sqrt(m)`, which undoes the D map's exponent scaling) is carried to the face
//!    by tilting the normal one standard deviation along each column of `D`
//!    (`normalize(n + d_1 t_u)`, `normalize(n + d_2 t_u + d_3 t_v)`, the bump multiply-add
//!    and normalize units), reflecting each and projecting it on the face: the two face
//!    vectors from the pixel's coordinates are the ellipse's axes on the face (a finite
//!    difference of the exact map, not a Jacobian). The isotropic map's lambda1 tilts along
//!    `t_u` and `t_v` by lambda1.
//! 5. The footprint (`env_lod`) and footprint assembly on the face (`aniso_probes`, clamp to
//!    edge: a footprint crossing a cube edge is clamped per face).
//! 6. `out = shade + ks * env` per channel (modulate unit, saturating add, counted).
//!
//! A ground-truth plan (`env::EnvPlan::truth_samples`) averages `k x k` sub-samples over the
//! pixel's texture-space footprint, each with its normal perturbed by the bilinearly sampled
//! finest offsets, reflected, and looked up bilinearly in the level-0 face.

use super::bump::{bump_of, raw3};
use super::rough_shade::sample_offsets;
use super::stages::{column, column_f, Counters, Machine};
use super::trace::{Lookup, Trace};
use super::{Frag, Plan, Px, StageKind};
use crate::fixedpoint::{to_raw, to_unorm};
use crate::footprint_ref::footprint_filter_f64;
use crate::reference::{bilinear_f64, interpolate_f64};
use crate::shading::env::{cube_face_f, env_lod_f, project_f, reflect_f, FaceRoughnessF};
use crate::shading::reference as fref;
use crate::shading::roughness::{scale_d_f, RoughnessEncoding};
use glam::DVec3;
use hw_model::cube_face::{cube_face, cube_face_cost, project};
use hw_model::env_config::EnvFilter;
use hw_model::env_lod::{env_lod, env_lod_cost, FaceRoughness};
use hw_model::fixed::SatCounter;
use hw_model::footprint::{footprint_cost, footprint_filter, MAX_PROBES};
use hw_model::interpolator::{interpolate, interpolate_cost};
use hw_model::modulate::{modulate, modulate_cost};
use hw_model::reflect::{reflect, reflect_cost, reflect_format};
use hw_model::roughness::{decode_d, scale_d, RoughVariant};
use hw_model::rsqrt::rsqrt_cost;
use hw_model::trilinear::TrilinearTrace;
use hw_model::vector::{madd, madd_cost, normalize3, normalize_cost, offset_format, Vec3x};
use hw_model::wrap::WrapMode;
use hw_model::{HwConfig, UnitCost};

const KIND: StageKind = StageKind::EnvFetch;
const CLAMP: [WrapMode; 2] = [WrapMode::ClampToEdge; 2];

/// Fixed twin (module doc). A ground-truth plan runs the float twin.
#[allow(clippy::too_many_lines, clippy::needless_range_loop)]
pub fn fixed(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let (Some(ep), Some((_, ba))) = (px.plan.env.as_ref(), bump_of(px)) else {
        return;
    };
    if ep.truth_samples != 0 {
        return float(px, frag, c);
    }
    let m = px.m;
    let hw = m.hw;
    let vc = &m.units.cfg.vector;
    let ec = &hw.env;
    let mut sat = c.sat[KIND.index()];
    let bf = &frag.bump;
    let vf = &m.vec_fmt;
    let unit = |v: &Vec3x, sat: &mut SatCounter| {
        normalize3(
            v,
            [0, 0, 1i64 << vc.vector_frac_bits],
            &m.units.rsqrt,
            vc,
            sat,
        )
        .v
    };
    let n = if px.fixed(StageKind::Perturb) {
        bf.normal_x
    } else {
        raw3(&bf.normal, vf, &mut sat)
    };
    let raw_normal = px.fixed(StageKind::Normal);
    let eye0 = if raw_normal {
        bf.to_eye_x
    } else {
        raw3(&bf.to_eye, vf, &mut sat)
    };
    let ni0 = if raw_normal {
        bf.n_i_x
    } else {
        raw3(&bf.n_i, vf, &mut sat)
    };
    let v = unit(&eye0, &mut sat);
    let r0 = reflect(&n, &v, vc, ec, &mut sat);
    let c0 = cube_face(&r0, &m.recip, ec, &mut sat);
    // Helper reflections (interpolated normal and eye at the helper samples).
    let ri0 = reflect(&unit(&ni0, &mut sat), &v, vc, ec, &mut sat);
    let rfmt = reflect_format(ec);
    let bb = hw.interp.bary_bits;
    let mut st = [[c0.s, c0.t]; 3];
    for h in 1..3 {
        let b = if px.fixed(StageKind::Bary) {
            frag.bary_x[h]
        } else {
            frag.bary[h].map(|x| to_raw(x, &m.bary_fmt, &mut sat))
        };
        let ip = |attr: &[[i64; 3]; 3], sat: &mut SatCounter| -> Vec3x {
            [0, 1, 2].map(|ch| interpolate(b, bb, column(attr, ch), vf, sat))
        };
        let nh = unit(&ip(&ba.n_x, &mut sat), &mut sat);
        let vh = unit(&ip(&ba.eye_x, &mut sat), &mut sat);
        let rih = reflect(&nh, &vh, vc, ec, &mut sat);
        let rh: Vec3x = std::array::from_fn(|i| rfmt.fit(r0[i] + rih[i] - ri0[i], &mut sat));
        st[h] = project(&rh, c0.face, &m.recip, ec, &mut sat);
    }
    // The roughness ellipse on the face.
    let mut fr = FaceRoughness::default();
    if let (true, Some(rp)) = (ep.filter != EnvFilter::None, px.plan.rough.as_ref()) {
        let tb = hw.trilinear.texel_bits;
        let rcfg = super::rough::rough_config(hw, rp);
        let iso = rp.variant == RoughVariant::Isotropic;
        let tex = if px.fixed(StageKind::RoughFetch) {
            frag.rough_x
        } else {
            frag.rough.map(|x| to_unorm(x, tb))
        };
        let (t_u, t_v, len) = if px.fixed(StageKind::Frame) {
            (bf.fr_t_u_x, bf.fr_t_v_x, bf.fr_len_x)
        } else {
            (
                raw3(&bf.fr_t_u, vf, &mut sat),
                raw3(&bf.fr_t_v, vf, &mut sat),
                bf.fr_len.map(|x| to_raw(x, &m.len_fmt, &mut sat)),
            )
        };
        let (dv, t) = decode_d(tex.map(u64::from), tb, &rcfg);
        let lfb = m.units.cfg.frame.frame_len_frac_bits;
        let d = scale_d(dv, len, lfb, iso, &mut sat).map(|x| {
            hw_model::fixed::round_shift_right(x * ep.d_scale_q16, 16, vc.vector_rounding)
        });
        let ofmt = offset_format(vc);
        let g = |x: i64, sat: &mut SatCounter| ofmt.requantize(x, t, sat);
        let cols = if iso {
            [(d[0], 0), (0, d[0])]
        } else {
            [(d[0], 0), (d[1], d[2])]
        };
        for (k, (gu, gv)) in cols.into_iter().enumerate() {
            let (gu, gv) = (g(gu, &mut sat), g(gv, &mut sat));
            let tilted = madd(&n, &t_u, &t_v, gu, gv, vc, &mut sat);
            let nk = unit(&tilted, &mut sat);
            let rk = reflect(&nk, &v, vc, ec, &mut sat);
            let p = project(&rk, c0.face, &m.recip, ec, &mut sat);
            fr.axes[k] = [p[0] - c0.s, p[1] - c0.t];
        }
    }
    let t = ep.map + usize::from(c0.face);
    let levels = &m.tex_fixed[t];
    let size = levels.first().map_or(1, |l0| l0.width);
    let tr = &hw.trilinear;
    let fb = ec.face_coord_bits;
    let fp = env_lod(
        &st,
        size,
        &fr,
        ep.filter,
        tr.aniso_probes,
        tr.aniso_adaptive,
        ec,
        &hw.lod,
        &mut sat,
    );
    let lfb = hw.lod.lod_frac_bits;
    let texel = filter_traced(m, t, levels, c0.s, c0.t, fb, &fp, lfb, &mut frag.trace);
    // out = shade + ks * env.
    let cb = m.units.cfg.shade.shade_color_bits;
    let rnd = m.units.cfg.shade.shade_rounding;
    let max = (1u64 << cb) - 1;
    let base = if frag.out_bits == cb {
        frag.out_x
    } else {
        frag.out.map(|x| to_unorm(x, cb))
    };
    let ks = px.plan.bump.as_ref().map_or([0.0; 3], |b| b.ks);
    for ch in 0..3 {
        let k = to_unorm(ks[ch], cb);
        let e = modulate(u32::from(texel[ch]), tr.texel_bits, k, cb, cb, rnd);
        let sum = u64::from(base[ch]) + u64::from(e);
        if sum > max {
            sat.saturated += 1;
        }
        frag.out_x[ch] = sum.min(max) as u32;
        frag.out[ch] = frag.out_x[ch] as f64 / max as f64;
    }
    frag.out_x[3] = max as u32;
    frag.out[3] = 1.0;
    frag.out_bits = cb;
    c.sat[KIND.index()] = sat;
}

/// Footprint assembly on face chain `t`, its probes recorded into `trace` when it is on.
#[allow(clippy::too_many_arguments)]
fn filter_traced(
    m: &Machine,
    t: usize,
    levels: &[hw_model::trilinear::Level],
    s: i64,
    tc: i64,
    fb: u32,
    fp: &hw_model::footprint::Footprint,
    lfb: u32,
    trace: &mut Trace,
) -> [u16; 4] {
    let tr = &m.hw.trilinear;
    if !trace.on {
        return footprint_filter(levels, s, tc, fb, fp, lfb, CLAMP, tr, None);
    }
    let mut traces = [TrilinearTrace::default(); MAX_PROBES];
    let r = footprint_filter(levels, s, tc, fb, fp, lfb, CLAMP, tr, Some(&mut traces));
    for (i, tt) in traces.iter().take(fp.probes as usize).enumerate() {
        let at = Lookup {
            stage: KIND,
            lookup: i as u32,
            tex: t,
        };
        trace.record(at.stage, at.lookup, at.tex, tt);
    }
    r
}

/// Float twin (module doc), or the ground truth.
#[allow(clippy::needless_range_loop)]
pub fn float(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let (Some(ep), Some((bp, ba))) = (px.plan.env.as_ref(), bump_of(px)) else {
        return;
    };
    let m = px.m;
    let bf = &frag.bump;
    let d3 = |a: &[f64; 3]| DVec3::from(*a);
    let unit = |v: DVec3| fref::normalize_or(v, DVec3::Z).0;
    let n = d3(&bf.normal);
    let v = unit(d3(&bf.to_eye));
    let env = if ep.truth_samples != 0 {
        truth(px, frag, ep, n, v)
    } else {
        let r0 = reflect_f(n, v);
        let (face, st0) = cube_face_f(r0);
        let ri0 = reflect_f(unit(d3(&bf.n_i)), v);
        let mut st = [st0; 3];
        for h in 1..3 {
            let b = frag.bary[h];
            let ip = |attr: &[[f64; 3]; 3]| {
                DVec3::from([0, 1, 2].map(|ch| interpolate_f64(b, column_f(attr, ch))))
            };
            let rh = r0 + reflect_f(unit(ip(&ba.n_f)), unit(ip(&ba.eye_f))) - ri0;
            st[h] = project_f(rh, face);
        }
        let mut fr = FaceRoughnessF::default();
        if let (true, Some(rp)) = (ep.filter != EnvFilter::None, px.plan.rough.as_ref()) {
            let rcfg = super::rough::rough_config(m.hw, rp);
            let iso = rp.variant == RoughVariant::Isotropic;
            let enc = RoughnessEncoding::for_range_exp(rcfg.rough_range_exp);
            let ds = ep.d_scale_q16 as f64 / 65536.0;
            let d = scale_d_f(enc.decode(frag.rough), bf.fr_len, iso).map(|x| x * ds);
            let cols = if iso {
                [(d[0], 0.0), (0.0, d[0])]
            } else {
                [(d[0], 0.0), (d[1], d[2])]
            };
            let (t_u, t_v) = (d3(&bf.fr_t_u), d3(&bf.fr_t_v));
            for (k, (gu, gv)) in cols.into_iter().enumerate() {
                let nk = unit(n + gu * t_u + gv * t_v);
                let p = project_f(reflect_f(nk, v), face);
                fr.axes[k] = [p[0] - st0[0], p[1] - st0[1]];
            }
        }
        let levels = &m.tex_float[ep.map + usize::from(face)];
        let size = levels.first().map_or(1, |l0| l0.width);
        let tr = &m.hw.trilinear;
        let fp = env_lod_f(
            &st,
            size,
            &fr,
            ep.filter,
            tr.aniso_probes,
            tr.aniso_adaptive,
        );
        let e = footprint_filter_f64(levels, st0[0], st0[1], &fp, CLAMP);
        if frag.trace.on {
            // The footprints the hardware fetches for this footprint in its formats.
            let ec = &m.hw.env;
            let q = |x: f64| crate::fixedpoint::to_raw_nearest(x, ec.face_coord_bits);
            let fx = hw_model::footprint::Footprint {
                probes: fp.probes,
                axis: fp.axis.map(q),
                lod: to_raw(fp.lod, &m.lod_fmt, &mut SatCounter::default()),
            };
            let t = ep.map + usize::from(face);
            let (s0, t0) = (q(st0[0]), q(st0[1]));
            let lfb = m.hw.lod.lod_frac_bits;
            let _ = filter_traced(
                m,
                t,
                &m.tex_fixed[t],
                s0,
                t0,
                ec.face_coord_bits,
                &fx,
                lfb,
                &mut frag.trace,
            );
        }
        [e[0], e[1], e[2]]
    };
    for ch in 0..3 {
        let o = frag.out[ch] + bp.ks[ch] * env[ch];
        frag.out[ch] = if o.is_finite() {
            o.clamp(0.0, 1.0)
        } else {
            c.nonfinite += 1;
            0.0
        };
    }
    frag.out[3] = 1.0;
    frag.out_bits = 0;
}

/// Ground truth: the mean over `k x k` sub-samples of the level-0 face texel (bilinear) seen
/// along the reflection of the finest perturbed normal.
#[allow(clippy::needless_range_loop)]
fn truth(px: &Px, frag: &Frag, ep: &super::env::EnvPlan, n: DVec3, v: DVec3) -> [f64; 3] {
    let m = px.m;
    let Some(bp) = px.plan.bump.as_ref() else {
        return [0.0; 3];
    };
    let bf = &frag.bump;
    let fr = fref::FrameF {
        n: DVec3::from(bf.fr_n),
        t_u: DVec3::from(bf.fr_t_u),
        t_v: DVec3::from(bf.fr_t_v),
        len_u: bf.fr_len[0],
        len_v: bf.fr_len[1],
        fallback: false,
        zero_normal: false,
    };
    let kk = ep.truth_samples;
    let range = f64::from(m.units.cfg.vector.offset_int_bits.min(30)).exp2();
    let Some(l0) = m.tex_float.get(bp.map).and_then(|l| l.first()) else {
        let (face, st) = cube_face_f(reflect_f(n, v));
        let e = bilinear_f64(
            &m.tex_float[ep.map + usize::from(face)][0],
            st[0],
            st[1],
            CLAMP,
        );
        return [e[0], e[1], e[2]];
    };
    let uv = &frag.uv;
    let dx = [uv[1][0] - uv[0][0], uv[1][1] - uv[0][1]];
    let dy = [uv[2][0] - uv[0][0], uv[2][1] - uv[0][1]];
    let inv = 1.0 / f64::from(kk);
    let mut sum = [0.0; 3];
    for j in 0..kk {
        let tt = (f64::from(j) + 0.5) * inv - 0.5;
        for i in 0..kk {
            let ss = (f64::from(i) + 0.5) * inv - 0.5;
            let su = uv[0][0] + ss * dx[0] + tt * dy[0];
            let sv = uv[0][1] + ss * dx[1] + tt * dy[1];
            let o = sample_offsets(l0, su, sv, range);
            let ns = fref::perturb_normal(&fr, o[0], o[1]);
            let (face, st) = cube_face_f(reflect_f(ns, v));
            let e = bilinear_f64(
                &m.tex_float[ep.map + usize::from(face)][0],
                st[0],
                st[1],
                CLAMP,
            );
            for ch in 0..3 {
                sum[ch] += e[ch];
            }
        }
    }
    sum.map(|s| s * inv * inv)
}

/// One invocation: the eye and three normalizations per helper, four interpolations of 3
/// components, three reflections, the face unit and two projections, with a filter the two
/// tilts (multiply-add, normalize, reflect, project each) and the footprint choice,
/// footprint assembly on the face, and three modulates.
#[must_use]
pub fn cost(m: &Machine, plan: &Plan) -> UnitCost {
    let Some(ep) = &plan.env else {
        return UnitCost::default();
    };
    let hw = m.hw;
    let g = hw.timing.gate_levels_per_cycle;
    let vc = &m.units.cfg.vector;
    let nz = normalize_cost(vc, rsqrt_cost(&m.units.cfg.rsqrt, g), g);
    let refl = reflect_cost(vc, &hw.env, g);
    let face = cube_face_cost(&hw.env, &m.recip, g);
    let mut c = nz
        .times(6)
        .plus(interpolate_cost(&hw.interp, g).times(12))
        .plus(refl.times(3))
        .plus(face.times(3))
        .plus(footprint_cost(
            &hw.trilinear,
            &hw.lod,
            hw.trilinear.aniso_probes,
            g,
        ))
        .plus(modulate_cost(&hw.color, g).times(3));
    if ep.filter != EnvFilter::None && plan.rough.is_some() {
        c = c
            .plus(madd_cost(vc, g).plus(nz).plus(refl).plus(face).times(2))
            .plus(env_lod_cost(ep.filter, &hw.lod, &hw.env, g));
    }
    c
}

/// Lookups per invocation: one per footprint-assembly probe.
#[must_use]
pub fn lookups(hw: &HwConfig) -> u32 {
    hw.trilinear.aniso_probes.max(1)
}
