//! The bump-mapping stage twins (Schilling 1997, "Bump mapping with Precalculated
//! Derivatives" and "The Local Coordinate System"; Blinn-Phong): `normal`, `bump-fetch`,
//! `frame`, `perturb` and `phong`. Fixed twins call the `hw_model` units (vector format s1.F,
//! offsets in offset format, lengths in len format, colours `shade_color_bits` unorm); Float
//! twins call `crate::shading::reference`. As in [`super::stages`], a Fixed stage reads raw
//! values of a Fixed producer and quantizes the carriers of a Float one.
//!
//! Per-triangle data ([`BumpAttrs`]): vertex normal, unit directions of `s_u`, `s_v`, their
//! relative lengths (natural frame), the main direction (when `m = p_u` or `p_v`), and the
//! vectors towards the eye and each point light. Those last vectors are affine in the world
//! position, so interpolating them is interpolating the position; each is divided by its
//! largest vertex length per triangle (the normalization removes any common scale), so they
//! fit the vector format with full precision.

use super::stages::{column, column_f, Counters, Machine, TriAttrs};
use super::trace::{trace_float_fetch, trilinear_traced, Lookup};
use super::{BumpPlan, Frag, Impl, Plan, Px, StageImpls, StageKind, MAX_POINT_LIGHTS};
use crate::fixedpoint::{from_raw, to_raw, to_unorm};
use crate::reference::{interpolate_f64, lod_f64, trilinear_f64};
use crate::scene::{FrameKind, MainDirection};
use crate::shading::reference as fref;
use glam::DVec3;
use hw_model::blinn_phong::{blinn_phong, blinn_phong_cost, BlinnPhongInput};
use hw_model::fixed::{Format, SatCounter};
use hw_model::frame::{
    frame_cost, main_frame, natural_frame, perturb_cost, perturb_normal, unit_frame, Frame,
    MainRole,
};
use hw_model::interpolator::{interpolate, interpolate_cost};
use hw_model::lod::{lod, lod_cost};
use hw_model::modulate::modulate;
use hw_model::rsqrt::rsqrt_cost;
use hw_model::trilinear::trilinear_cost;
use hw_model::vector::{normalize3, normalize_cost, offset_from_texel, Vec3x};
use hw_model::UnitCost;

/// One screen triangle's bump vertex data, in float and in the machine's formats.
#[derive(Clone, Copy, Debug, Default)]
pub struct BumpAttrs {
    pub n_f: [[f64; 3]; 3],
    pub n_x: [[i64; 3]; 3],
    pub du_f: [[f64; 3]; 3],
    pub du_x: [[i64; 3]; 3],
    pub dv_f: [[f64; 3]; 3],
    pub dv_x: [[i64; 3]; 3],
    pub m_f: [[f64; 3]; 3],
    pub m_x: [[i64; 3]; 3],
    /// Relative lengths of `s_u`, `s_v` per vertex (len format when raw).
    pub len_f: [[f64; 2]; 3],
    pub len_x: [[i64; 2]; 3],
    /// Scaled vectors towards the eye and each point light, per vertex.
    pub eye_f: [[f64; 3]; 3],
    pub eye_x: [[i64; 3]; 3],
    pub light_f: [[[f64; 3]; 3]; MAX_POINT_LIGHTS],
    pub light_x: [[[i64; 3]; 3]; MAX_POINT_LIGHTS],
    /// The triangle's texture coordinates are mirrored (`n . (p_u x p_v) < 0`, the sign of
    /// `(d_u x d_v) . n` at two or three of its vertices); selects the main frame's sign along
    /// `m` (`hw_model::frame::MainRole`).
    pub mirrored: bool,
}

/// Float per-vertex bump data of one (possibly clipped) vertex.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BumpVertex {
    /// Vertex normal.
    pub n: [f64; 3],
    /// Unit directions of `s_u = n x p_v` and `s_v = p_u x n`.
    pub du: [f64; 3],
    pub dv: [f64; 3],
    /// Relative lengths of `s_u`, `s_v` (`reference::natural_vertex`).
    pub len: [f64; 2],
    /// Main direction when it is `p_u` or `p_v` (unit), zero otherwise.
    pub m: [f64; 3],
    /// World position.
    pub p: [f64; 3],
}

fn scaled(v: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let s = v
        .iter()
        .map(|x| DVec3::from(*x).length())
        .fold(0.0f64, f64::max);
    if s > 0.0 && s.is_finite() {
        v.map(|x| x.map(|c| c / s))
    } else {
        [[0.0; 3]; 3]
    }
}

impl BumpAttrs {
    /// Converts three (post-clip) vertices into the machine's formats: vectors in vector
    /// format, lengths in len format (overflows counted in `sat`); `eye` and `lights` are
    /// world positions.
    #[must_use]
    pub fn new(
        m: &Machine,
        v: &[BumpVertex; 3],
        eye: [f64; 3],
        lights: &[[f64; 3]],
        sat: &mut SatCounter,
    ) -> Self {
        let vf = &m.vec_fmt;
        let q3 = |a: [[f64; 3]; 3], sat: &mut SatCounter| a.map(|x| x.map(|c| to_raw(c, vf, sat)));
        let rel = |to: [f64; 3]| {
            scaled(v.map(|x| {
                let d = DVec3::from(to) - DVec3::from(x.p);
                d.to_array()
            }))
        };
        let mut b = BumpAttrs {
            n_f: v.map(|x| x.n),
            du_f: v.map(|x| x.du),
            dv_f: v.map(|x| x.dv),
            m_f: v.map(|x| x.m),
            len_f: v.map(|x| x.len),
            eye_f: rel(eye),
            mirrored: mirrored(v),
            ..Default::default()
        };
        for (k, &lp) in lights.iter().take(MAX_POINT_LIGHTS).enumerate() {
            b.light_f[k] = rel(lp);
            b.light_x[k] = q3(b.light_f[k], sat);
        }
        b.n_x = q3(b.n_f, sat);
        b.du_x = q3(b.du_f, sat);
        b.dv_x = q3(b.dv_f, sat);
        b.m_x = q3(b.m_f, sat);
        b.eye_x = q3(b.eye_f, sat);
        b.len_x = b.len_f.map(|x| x.map(|c| to_raw(c, &m.len_fmt, sat)));
        b
    }
}

/// Two or three of the vertices have left-handed `(s_u, s_v, n)`: `s_u x s_v = n (n . (p_u x
/// p_v))` for a unit `n` (and `-T x -B = w n` for the tangent fallback), so the sign of
/// `(d_u x d_v) . n` is the handedness of the texture coordinates.
fn mirrored(v: &[BumpVertex; 3]) -> bool {
    v.iter()
        .filter(|x| d3(&x.du).cross(d3(&x.dv)).dot(d3(&x.n)) < 0.0)
        .count()
        >= 2
}

/// The main frame's role of `bp`'s main direction on a triangle of `ba`.
fn main_role(bp: &BumpPlan, ba: &BumpAttrs) -> MainRole {
    MainRole {
        m_is_u: bp.main == MainDirection::Pu,
        mirrored: ba.mirrored,
    }
}

#[inline]
fn raw3(v: &[f64; 3], fmt: &Format, sat: &mut SatCounter) -> Vec3x {
    v.map(|c| to_raw(c, fmt, sat))
}

#[inline]
fn val3(v: &Vec3x, f: u32) -> [f64; 3] {
    v.map(|c| from_raw(c, f))
}

#[inline]
fn d3(v: &[f64; 3]) -> DVec3 {
    DVec3::from(*v)
}

/// The constant main direction of `bp`, unit (zero for `p_u`/`p_v`).
fn constant_m(bp: &BumpPlan) -> [f64; 3] {
    match bp.main {
        MainDirection::Constant(d) => fref::normalize_or(d3(&d.map(f64::from)), DVec3::ZERO)
            .0
            .to_array(),
        MainDirection::Pu | MainDirection::Pv => [0.0; 3],
    }
}

/// Number of point lights shaded per pixel.
#[must_use]
pub fn point_lights(m: &Machine) -> usize {
    m.lights.iter().filter(|l| l.point.is_some()).count()
}

/// Scalar attributes interpolated by the `normal` stage of `bp` with frame `kind`.
#[must_use]
pub fn normal_attr_count(m: &Machine, bp: &BumpPlan, kind: FrameKind) -> u32 {
    let frame = match kind {
        FrameKind::Natural => 8,
        FrameKind::Unit => 6,
        FrameKind::Main => match bp.main {
            MainDirection::Constant(_) => 0,
            MainDirection::Pu | MainDirection::Pv => 3,
        },
    };
    3 + 3 + 3 * point_lights(m) as u32 + frame
}

/// Runs bump stage `kind` (one of the five) of `plan` on `frag`.
#[allow(clippy::too_many_arguments, clippy::needless_range_loop)]
#[inline]
pub fn run_bump_stage(
    kind: StageKind,
    plan: &Plan,
    impls: &StageImpls,
    m: &Machine,
    a: &TriAttrs,
    frag: &mut Frag,
    c: &mut Counters,
) {
    let Some(bp) = &plan.bump else { return };
    let Some(ba) = m.bump_attrs.get(a.bump as usize) else {
        return;
    };
    let fixed_in = |k: StageKind| impls.of(k) == Impl::Fixed;
    let fixed = fixed_in(kind);
    let hw = m.hw;
    let units = &m.units;
    let vc = &units.cfg.vector;
    let f = vc.vector_frac_bits;
    let lfb = units.cfg.frame.frame_len_frac_bits;
    let fk = m.frame_of(bp);
    let np = point_lights(m);
    let k = kind.index();
    let mut sat = c.sat[k];
    let bf = &mut frag.bump;
    match kind {
        StageKind::Normal => {
            if fixed {
                let bb = hw.interp.bary_bits;
                let b = if fixed_in(StageKind::Bary) {
                    frag.bary_x[0]
                } else {
                    frag.bary[0].map(|x| to_raw(x, &m.bary_fmt, &mut sat))
                };
                let mut ip = |attr: &[[i64; 3]; 3], fmt: &Format| -> Vec3x {
                    [0, 1, 2].map(|ch| interpolate(b, bb, column(attr, ch), fmt, &mut sat))
                };
                bf.n_i_x = ip(&ba.n_x, &m.vec_fmt);
                bf.to_eye_x = ip(&ba.eye_x, &m.vec_fmt);
                for l in 0..np {
                    bf.to_light_x[l] = ip(&ba.light_x[l], &m.vec_fmt);
                }
                if fk != FrameKind::Main {
                    bf.d_u_x = ip(&ba.du_x, &m.vec_fmt);
                    bf.d_v_x = ip(&ba.dv_x, &m.vec_fmt);
                }
                if fk == FrameKind::Main {
                    bf.m_x = match bp.main {
                        MainDirection::Constant(_) => raw3(&constant_m(bp), &m.vec_fmt, &mut sat),
                        _ => ip(&ba.m_x, &m.vec_fmt),
                    };
                }
                if fk == FrameKind::Natural {
                    for ax in 0..2 {
                        bf.len_x[ax] =
                            interpolate(b, bb, column(&ba.len_x, ax), &m.len_fmt, &mut sat);
                        bf.len[ax] = from_raw(bf.len_x[ax], lfb);
                    }
                } else {
                    bf.len_x = [1i64 << lfb; 2];
                    bf.len = [1.0; 2];
                }
                bf.n_i = val3(&bf.n_i_x, f);
                bf.to_eye = val3(&bf.to_eye_x, f);
                for l in 0..np {
                    bf.to_light[l] = val3(&bf.to_light_x[l], f);
                }
                bf.d_u = val3(&bf.d_u_x, f);
                bf.d_v = val3(&bf.d_v_x, f);
                bf.m = val3(&bf.m_x, f);
            } else {
                let b = frag.bary[0];
                let ip = |attr: &[[f64; 3]; 3]| -> [f64; 3] {
                    [0, 1, 2].map(|ch| interpolate_f64(b, column_f(attr, ch)))
                };
                bf.n_i = ip(&ba.n_f);
                bf.to_eye = ip(&ba.eye_f);
                for l in 0..np {
                    bf.to_light[l] = ip(&ba.light_f[l]);
                }
                bf.d_u = ip(&ba.du_f);
                bf.d_v = ip(&ba.dv_f);
                bf.m = match bp.main {
                    MainDirection::Constant(_) => constant_m(bp),
                    _ => ip(&ba.m_f),
                };
                bf.len = if fk == FrameKind::Natural {
                    [0, 1].map(|ax| interpolate_f64(b, column_f(&ba.len_f, ax)))
                } else {
                    [1.0; 2]
                };
            }
        }
        StageKind::BumpFetch => {
            let t = bp.map;
            let Some(l0) = m.tex_float.get(t).and_then(|l| l.first()) else {
                c.sat[k] = sat;
                return;
            };
            let (w, h) = (l0.width, l0.height);
            let fb = m.uv_fmt.frac_bits;
            let lfb_lod = hw.lod.lod_frac_bits;
            if fixed {
                if !fixed_in(StageKind::Texcoord) {
                    for s in 0..3 {
                        for ax in 0..2 {
                            frag.uv_x[s][ax] = to_raw(frag.uv[s][ax], &m.uv_fmt, &mut sat);
                        }
                    }
                }
                let d = super::stages::texel_derivs(&frag.uv_x, w, h);
                let l = lod(d, fb, &hw.lod, &mut sat);
                let [u, v] = frag.uv_x[0];
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
                    lfb_lod,
                    plan.wrap,
                    &hw.trilinear,
                    &mut frag.trace,
                    at,
                );
                let tb = hw.trilinear.texel_bits;
                bf.texel_x = [u32::from(r[0]), u32::from(r[1])];
                bf.texel = bf.texel_x.map(|x| crate::fixedpoint::from_unorm(x, tb));
            } else {
                let l = lod_f64(super::stages::texel_derivs_f64(&frag.uv, w, h));
                let uv = &frag.uv;
                let [u, v] = uv[0];
                let r = trilinear_f64(&m.tex_float[t], u, v, l, plan.wrap);
                bf.texel = [r[0], r[1]];
                let at = Lookup {
                    stage: kind,
                    lookup: 0,
                    tex: t,
                };
                trace_float_fetch(m, frag, fixed_in(StageKind::Texcoord), plan.wrap, at, 1);
            }
        }
        StageKind::Frame => {
            if fixed {
                let raw = fixed_in(StageKind::Normal);
                let mut q = |x: &Vec3x, v: &[f64; 3]| {
                    if raw {
                        *x
                    } else {
                        raw3(v, &m.vec_fmt, &mut sat)
                    }
                };
                let n = q(&bf.n_i_x, &bf.n_i);
                let du = q(&bf.d_u_x, &bf.d_u);
                let dv = q(&bf.d_v_x, &bf.d_v);
                let mm = q(&bf.m_x, &bf.m);
                let len = if raw {
                    bf.len_x
                } else {
                    bf.len.map(|x| to_raw(x, &m.len_fmt, &mut sat))
                };
                let fr = match fk {
                    FrameKind::Natural => {
                        natural_frame(&n, &du, &dv, len[0], len[1], units, &mut sat)
                    }
                    FrameKind::Unit => unit_frame(&n, &du, &dv, units, &mut sat),
                    FrameKind::Main => main_frame(&n, &mm, main_role(bp, ba), units, &mut sat),
                };
                c.frame_fallback += u64::from(fr.fallback);
                c.zero_normal += u64::from(fr.zero_normal);
                bf.fr_n_x = fr.n;
                bf.fr_t_u_x = fr.t_u;
                bf.fr_t_v_x = fr.t_v;
                bf.fr_len_x = [fr.len_u, fr.len_v];
                bf.fr_n = val3(&fr.n, f);
                bf.fr_t_u = val3(&fr.t_u, f);
                bf.fr_t_v = val3(&fr.t_v, f);
                bf.fr_len = bf.fr_len_x.map(|x| from_raw(x, lfb));
            } else {
                let fr = fref::build_frame(
                    fk,
                    d3(&bf.n_i),
                    d3(&bf.d_u),
                    d3(&bf.d_v),
                    bf.len[0],
                    bf.len[1],
                    d3(&bf.m),
                    main_role(bp, ba),
                    units.cfg.frame.frame_min_sin_bits,
                );
                c.frame_fallback += u64::from(fr.fallback);
                c.zero_normal += u64::from(fr.zero_normal);
                bf.fr_n = fr.n.to_array();
                bf.fr_t_u = fr.t_u.to_array();
                bf.fr_t_v = fr.t_v.to_array();
                bf.fr_len = [fr.len_u, fr.len_v];
            }
        }
        StageKind::Perturb => {
            let tb = hw.trilinear.texel_bits;
            if fixed {
                let tex = if fixed_in(StageKind::BumpFetch) {
                    bf.texel_x
                } else {
                    bf.texel.map(|x| to_unorm(x, tb))
                };
                let f_u = offset_from_texel(u64::from(tex[0]), tb, vc, &mut sat);
                let f_v = offset_from_texel(u64::from(tex[1]), tb, vc, &mut sat);
                let fr = if fixed_in(StageKind::Frame) {
                    Frame {
                        n: bf.fr_n_x,
                        t_u: bf.fr_t_u_x,
                        t_v: bf.fr_t_v_x,
                        len_u: bf.fr_len_x[0],
                        len_v: bf.fr_len_x[1],
                        fallback: false,
                        zero_normal: false,
                    }
                } else {
                    Frame {
                        n: raw3(&bf.fr_n, &m.vec_fmt, &mut sat),
                        t_u: raw3(&bf.fr_t_u, &m.vec_fmt, &mut sat),
                        t_v: raw3(&bf.fr_t_v, &m.vec_fmt, &mut sat),
                        len_u: to_raw(bf.fr_len[0], &m.len_fmt, &mut sat),
                        len_v: to_raw(bf.fr_len[1], &m.len_fmt, &mut sat),
                        fallback: false,
                        zero_normal: false,
                    }
                };
                bf.normal_x = perturb_normal(&fr, f_u, f_v, units, &mut sat).v;
                bf.normal = val3(&bf.normal_x, f);
            } else {
                let range = f64::from(vc.offset_int_bits.min(30)).exp2();
                let off = bf.texel.map(|t| (t - 0.5) * 2.0 * range);
                let fr = fref::FrameF {
                    n: d3(&bf.fr_n),
                    t_u: d3(&bf.fr_t_u),
                    t_v: d3(&bf.fr_t_v),
                    len_u: bf.fr_len[0],
                    len_v: bf.fr_len[1],
                    fallback: false,
                    zero_normal: false,
                };
                bf.normal = fref::perturb_normal(&fr, off[0], off[1]).to_array();
            }
        }
        StageKind::Phong => {
            let cb = units.cfg.shade.shade_color_bits;
            if fixed {
                let rnd = units.cfg.shade.shade_rounding;
                let n = if fixed_in(StageKind::Perturb) {
                    bf.normal_x
                } else {
                    raw3(&bf.normal, &m.vec_fmt, &mut sat)
                };
                let eye = if fixed_in(StageKind::Normal) {
                    bf.to_eye_x
                } else {
                    raw3(&bf.to_eye, &m.vec_fmt, &mut sat)
                };
                let v = normalize3(&eye, [0, 0, 1i64 << f], &units.rsqrt, vc, &mut sat).v;
                let (kd, ks, mut acc) = fixed_material(
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
                                raw3(&bf.to_light[pi], &m.vec_fmt, &mut sat)
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
                    let r = blinn_phong(&inp, units, &mut sat);
                    c.h_zero += u64::from(r.h_zero);
                    for ch in 0..3 {
                        acc[ch] += r.color[ch];
                    }
                }
                fixed_output(acc, frag, &mut sat, cb);
            } else {
                let n = d3(&bf.normal);
                let v = fref::normalize_or(d3(&bf.to_eye), DVec3::Z).0;
                let mut kd = bp.kd;
                if plan.texture.is_some() {
                    for ch in 0..3 {
                        kd[ch] *= frag.texel[ch];
                    }
                }
                let mut acc = [0.0f64; 3];
                for ch in 0..3 {
                    acc[ch] = m.ambient[ch] * kd[ch];
                }
                for light in &m.lights {
                    let l = match light.point {
                        Some(pi) => fref::normalize_or(d3(&bf.to_light[pi]), DVec3::Z).0,
                        None => d3(&light.l_f),
                    };
                    let (col, hz) =
                        fref::blinn_phong(n, l, v, bp.shininess, kd, bp.ks, light.color_f);
                    c.h_zero += u64::from(hz);
                    for ch in 0..3 {
                        acc[ch] += col[ch];
                    }
                }
                float_output(acc, frag, c);
            }
        }
        _ => {}
    }
    c.sat[k] = sat;
}

/// Ends a float shading stage: the RGB sum `acc` (a non-finite channel becomes 0 and is
/// counted) clamped to [0, 1] into `frag.out`, alpha 1, as a float carrier.
pub(super) fn float_output(acc: [f64; 3], frag: &mut Frag, c: &mut Counters) {
    for (out, a) in frag.out.iter_mut().zip(acc) {
        *out = if a.is_finite() {
            a.clamp(0.0, 1.0)
        } else {
            c.nonfinite += 1;
            0.0
        };
    }
    frag.out[3] = 1.0;
    frag.out_bits = 0;
}

/// The material of a fixed Blinn-Phong-type stage, `cb`-bit unorm: `kd` (times the texel
/// when `textured`: `texel_x` if the trilinear stage ran fixed, else the quantized float
/// `texel`), `ks`, and the ambient term `ambient x kd` that starts the light sum.
#[allow(clippy::too_many_arguments)]
pub(super) fn fixed_material(
    bp: &BumpPlan,
    m: &Machine,
    textured: bool,
    texel_fixed: bool,
    texel_x: [u32; 4],
    texel: [f64; 4],
    cb: u32,
    rnd: hw_model::fixed::Rounding,
) -> ([u64; 3], [u64; 3], [u64; 3]) {
    let mut kd = bp.kd.map(|x| u64::from(to_unorm(x, cb)));
    if textured {
        let tb = m.hw.trilinear.texel_bits;
        let tex = if texel_fixed {
            texel_x
        } else {
            texel.map(|x| to_unorm(x, tb))
        };
        for ch in 0..3 {
            kd[ch] = u64::from(modulate(kd[ch] as u32, cb, tex[ch], tb, cb, rnd));
        }
    }
    let ks = bp.ks.map(|x| u64::from(to_unorm(x, cb)));
    let ambient = std::array::from_fn(|ch| {
        u64::from(modulate(
            m.ambient_x[ch] as u32,
            cb,
            kd[ch] as u32,
            cb,
            cb,
            rnd,
        ))
    });
    (kd, ks, ambient)
}

/// Ends a fixed shading stage: the `cb`-bit unorm sums `acc` saturated (counted) into
/// `frag.out_x`, alpha 1, with their float carriers.
pub(super) fn fixed_output(acc: [u64; 3], frag: &mut Frag, sat: &mut SatCounter, cb: u32) {
    let max = (1u64 << cb) - 1;
    for (ch, a) in acc.into_iter().enumerate() {
        if a > max {
            sat.saturated += 1;
        }
        let a = a.min(max);
        frag.out_x[ch] = a as u32;
        frag.out[ch] = a as f64 / max as f64;
    }
    frag.out_x[3] = max as u32;
    frag.out[3] = 1.0;
    frag.out_bits = cb;
}

/// Cost of one invocation of a bump stage of `plan` (zero without a bump plan).
pub fn bump_stage_cost(m: &Machine, kind: StageKind, plan: &Plan) -> UnitCost {
    let Some(bp) = &plan.bump else {
        return UnitCost::default();
    };
    let u = &m.units;
    let fk = m.frame_of(bp);
    let np = point_lights(m) as u32;
    let g = m.hw.timing.gate_levels_per_cycle;
    let nz = normalize_cost(&u.cfg.vector, rsqrt_cost(&u.cfg.rsqrt, g), g);
    let mac = hw_model::blinn_phong::mac_cost(&u.cfg, g);
    match kind {
        StageKind::Normal => interpolate_cost(&m.hw.interp, g).times(normal_attr_count(m, bp, fk)),
        StageKind::BumpFetch => lod_cost(&m.hw.lod, g).plus(trilinear_cost(&m.hw.trilinear, 2, g)),
        StageKind::Frame => frame_cost(fk, u, g),
        StageKind::Perturb => perturb_cost(u, g),
        StageKind::Phong => {
            let lights = m.lights.len() as u32;
            let mut c = blinn_phong_cost(u, g)
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

/// Stage-table entry of bump stage `K` (`StageKind::index`); it runs the twin `px.impls`
/// names for it.
pub fn row<const K: usize>(px: &Px, frag: &mut Frag, c: &mut Counters) {
    run_bump_stage(StageKind::ALL[K], px.plan, px.impls, px.m, px.a, frag, c);
}

/// Stage-table cost of bump stage `K`.
#[must_use]
pub fn row_cost<const K: usize>(m: &Machine, plan: &Plan) -> UnitCost {
    bump_stage_cost(m, StageKind::ALL[K], plan)
}
