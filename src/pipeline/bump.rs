//! What the bump-mapping stages share (Schilling 1997, "Bump mapping with Precalculated
//! Derivatives" and "The Local Coordinate System"; Blinn-Phong): the per-triangle data, the
//! small conversions, and the ends of a shading stage (also used by `rough-shade`, `ndf-shade`
//! and `as-shade`). The stages are one file each: [`super::normal`], [`super::bump_fetch`],
//! [`super::frame`], [`super::perturb`] and [`super::phong`]. Fixed twins call the `hw_model`
//! units (vector format s1.F, offsets in offset format, lengths in len format, colours
//! `shade_color_bits` unorm); Float twins call `crate::shading::reference`. As in
//! [`super::stages`], a Fixed stage reads raw values of a Fixed producer and quantizes the
//! carriers of a Float one.
//!
//! Per-triangle data ([`BumpAttrs`]): vertex normal, unit directions of `s_u`, `s_v`, their
//! relative lengths (natural frame), the main direction (when `m = p_u` or `p_v`), and the
//! vectors towards the eye and each point light. Those last vectors are affine in the world
//! position, so interpolating them is interpolating the position; each is divided by its
//! largest vertex length per triangle (the normalization removes any common scale), so they
//! fit the vector format with full precision.

use super::stages::{Counters, Machine, ShadeLight};
use super::{BumpFrag, BumpPlan, Frag, Px, MAX_POINT_LIGHTS};
use crate::fixedpoint::{from_raw, to_raw, to_unorm};
use crate::scene::MainDirection;
use crate::shading::reference as fref;
use glam::DVec3;
use hw_model::fixed::{Format, SatCounter};
use hw_model::frame::MainRole;
use hw_model::modulate::modulate;
use hw_model::vector::{normalize3, Vec3x};

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
pub(super) fn main_role(bp: &BumpPlan, ba: &BumpAttrs) -> MainRole {
    MainRole {
        m_is_u: bp.main == MainDirection::Pu,
        mirrored: ba.mirrored,
    }
}

#[inline]
pub(super) fn raw3(v: &[f64; 3], fmt: &Format, sat: &mut SatCounter) -> Vec3x {
    v.map(|c| to_raw(c, fmt, sat))
}

#[inline]
pub(super) fn val3(v: &Vec3x, f: u32) -> [f64; 3] {
    v.map(|c| from_raw(c, f))
}

#[inline]
pub(super) fn d3(v: &[f64; 3]) -> DVec3 {
    DVec3::from(*v)
}

/// The constant main direction of `bp`, unit (zero for `p_u`/`p_v`).
pub(super) fn constant_m(bp: &BumpPlan) -> [f64; 3] {
    match bp.main {
        MainDirection::Constant(d) => fref::normalize_or(d3(&d.map(f64::from)), DVec3::ZERO)
            .0
            .to_array(),
        MainDirection::Pu | MainDirection::Pv => [0.0; 3],
    }
}

/// The bump plan of the pixel's material and its triangle's bump data; `None` (the stage
/// does nothing) for a material without a bump plan or a triangle without bump data.
#[inline]
pub(super) fn bump_of<'a>(px: &Px<'a>) -> Option<(&'a BumpPlan, &'a BumpAttrs)> {
    let bp = px.plan.bump.as_ref()?;
    let ba = px.m.bump_attrs.get(px.a.bump as usize)?;
    Some((bp, ba))
}

/// Number of point lights shaded per pixel.
#[must_use]
pub fn point_lights(m: &Machine) -> usize {
    m.lights.iter().filter(|l| l.point.is_some()).count()
}

/// The unit vector towards the eye of a fixed shading stage (vector format): the `normal`
/// stage's raw vector when it ran fixed (`raw`), its quantized carrier otherwise, normalized.
pub(super) fn fixed_eye(m: &Machine, bf: &BumpFrag, raw: bool, sat: &mut SatCounter) -> Vec3x {
    let eye = if raw {
        bf.to_eye_x
    } else {
        raw3(&bf.to_eye, &m.vec_fmt, sat)
    };
    unit_vec(m, &eye, sat)
}

/// The unit vector towards `light` of a fixed shading stage: a point light's interpolated
/// vector (raw when `normal` ran fixed) normalized, a directional light's direction.
pub(super) fn fixed_light(
    m: &Machine,
    bf: &BumpFrag,
    light: &ShadeLight,
    raw: bool,
    sat: &mut SatCounter,
) -> Vec3x {
    match light.point {
        Some(pi) => {
            let lv = if raw {
                bf.to_light_x[pi]
            } else {
                raw3(&bf.to_light[pi], &m.vec_fmt, sat)
            };
            unit_vec(m, &lv, sat)
        }
        None => light.l_x,
    }
}

/// `v` normalized by the vector unit (`+z` for a zero vector).
fn unit_vec(m: &Machine, v: &Vec3x, sat: &mut SatCounter) -> Vec3x {
    let vc = &m.units.cfg.vector;
    normalize3(
        v,
        [0, 0, 1i64 << vc.vector_frac_bits],
        &m.units.rsqrt,
        vc,
        sat,
    )
    .v
}

/// The unit vector towards the eye of a float shading stage.
pub(super) fn float_eye(bf: &BumpFrag) -> DVec3 {
    fref::normalize_or(d3(&bf.to_eye), DVec3::Z).0
}

/// The unit vector towards `light` of a float shading stage.
pub(super) fn float_light(bf: &BumpFrag, light: &ShadeLight) -> DVec3 {
    match light.point {
        Some(pi) => fref::normalize_or(d3(&bf.to_light[pi]), DVec3::Z).0,
        None => d3(&light.l_f),
    }
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
