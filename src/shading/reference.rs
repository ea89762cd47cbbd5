//! Float (f64) twins of the fixed-point bump/shading units in `hw_model::{rsqrt, vector, frame,
//! pow, blinn_phong}` (Schilling 1997, "The Local Coordinate System"; Blinn-Phong), same
//! algorithms and the same fallbacks, plus float<->fixed conversion helpers.
//!
//! All functions take already-interpolated per-pixel quantities, so the pipeline can call the
//! fixed unit or its twin at the same place. Natural frame (paper, frame 1): at the vertices
//! compute [`natural_vertex`] (unit directions of `s_u = n x p_v`, `s_v = p_u x n` and their
//! relative lengths); interpolate directions and lengths separately with the
//! perspective-correct barycentrics ([`interpolate3`], [`interpolate1`]); per pixel
//! [`natural_frame`] normalizes the directions and keeps the lengths. Perspective division only
//! scales the interpolated direction, which the normalization removes (the paper's remark).

use glam::DVec3;
use hw_model::frame::{FrameKind, MainRole};
use hw_model::vector::Vec3x;

/// A frame in float: the twin of `hw_model::frame::Frame`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameF {
    pub n: DVec3,
    pub t_u: DVec3,
    pub t_v: DVec3,
    pub len_u: f64,
    pub len_v: f64,
    pub fallback: bool,
    pub zero_normal: bool,
}

/// Per-vertex data of the natural frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NaturalVertex {
    /// Unit direction of `s_u = n x p_v`.
    pub dir_u: DVec3,
    /// `|s_u| / |n_geo| * ref_u`, where `|n_geo| = |p_u x p_v|`, i.e. `ref_u / (|p_u| sin)`.
    pub len_u: f64,
    /// Unit direction of `s_v = p_u x n`.
    pub dir_v: DVec3,
    /// `|s_v| / |n_geo| * ref_v`.
    pub len_v: f64,
}

/// Value of a raw fixed number with `frac` fraction bits.
#[must_use]
pub fn from_fixed(r: i64, frac: u32) -> f64 {
    r as f64 * (-f64::from(frac)).exp2()
}

/// A float vector into vector format (s1.F), rounded to nearest (ties up) and clamped to the
/// format (a non-finite component gives 0).
#[must_use]
pub fn to_vec3x(v: DVec3, frac: u32) -> Vec3x {
    let lim = (1i64 << (frac + 1)) - 1;
    [v.x, v.y, v.z].map(|c| crate::fixedpoint::to_raw_nearest(c, frac).clamp(-lim - 1, lim))
}

/// A raw vector with `frac` fraction bits as float.
#[must_use]
pub fn from_vec3x(v: &Vec3x, frac: u32) -> DVec3 {
    DVec3::new(
        from_fixed(v[0], frac),
        from_fixed(v[1], frac),
        from_fixed(v[2], frac),
    )
}

/// `v/|v|`, or `fallback` (and `true`) for a zero or non-finite length.
#[must_use]
pub fn normalize_or(v: DVec3, fallback: DVec3) -> (DVec3, bool) {
    let l2 = v.length_squared();
    if l2 > 0.0 && l2.is_finite() {
        (v / l2.sqrt(), false)
    } else {
        (fallback, true)
    }
}

/// The coordinate axis least aligned with `n` (smallest `|n_i|`, lowest index on ties).
#[must_use]
pub fn least_aligned_axis(n: DVec3) -> DVec3 {
    let a = n.abs();
    if a.x <= a.y && a.x <= a.z {
        DVec3::X
    } else if a.y <= a.z {
        DVec3::Y
    } else {
        DVec3::Z
    }
}

/// Paper frame 3 `(n, e1, e2)` with the fallback of `hw_model::frame` (threshold
/// `sin(angle(m, n)) < 2^-min_sin_bits`). Returns `(n, e1, e2, fallback, zero_normal)`.
#[must_use]
pub fn main_direction_frame(
    n_i: DVec3,
    m: DVec3,
    min_sin_bits: u32,
) -> (DVec3, DVec3, DVec3, bool, bool) {
    let (n, zero) = normalize_or(n_i, DVec3::Z);
    let (mh, mzero) = normalize_or(m, DVec3::ZERO);
    let mut c = mh.cross(n);
    let thr = (-2.0 * f64::from(min_sin_bits)).exp2();
    let fallback = mzero || c.length_squared() < thr;
    if fallback {
        c = least_aligned_axis(n).cross(n);
    }
    let (e1, _) = normalize_or(c, DVec3::X);
    let e2 = n.cross(e1);
    (n, e1, e2, fallback, zero)
}

/// Frame 3 as [`FrameF`], lengths 1, with the axis assignment of `hw_model::frame`
/// (`role`): `t_u = -e1`, `t_v = -e2` for `m = p_v` or a constant `m`; `t_u = -e2`,
/// `t_v = e1` for `m = p_u`; `e2` instead of `-e2` on mirrored texture coordinates.
#[must_use]
pub fn main_frame(n_i: DVec3, m: DVec3, role: MainRole, min_sin_bits: u32) -> FrameF {
    let (n, e1, e2, fallback, zero_normal) = main_direction_frame(n_i, m, min_sin_bits);
    let along_m = if role.mirrored { e2 } else { -e2 };
    let (t_u, t_v) = if role.m_is_u {
        (along_m, e1)
    } else {
        (-e1, along_m)
    };
    FrameF {
        n,
        t_u,
        t_v,
        len_u: 1.0,
        len_v: 1.0,
        fallback,
        zero_normal,
    }
}

/// Frame 2: normalized interpolated normal and directions, lengths 1; zero directions fall
/// back to the main frame of the least aligned axis.
#[must_use]
pub fn unit_frame(n_i: DVec3, d_u: DVec3, d_v: DVec3, min_sin_bits: u32) -> FrameF {
    let (n, zero_normal) = normalize_or(n_i, DVec3::Z);
    let (su, zu) = normalize_or(d_u, DVec3::ZERO);
    let (sv, zv) = normalize_or(d_v, DVec3::ZERO);
    if zu || zv {
        let mut f = main_frame(n, least_aligned_axis(n), MainRole::default(), min_sin_bits);
        f.fallback = true;
        f.zero_normal = zero_normal;
        return f;
    }
    FrameF {
        n,
        t_u: su,
        t_v: sv,
        len_u: 1.0,
        len_v: 1.0,
        fallback: false,
        zero_normal,
    }
}

/// Frame 1: as [`unit_frame`] with the separately interpolated lengths.
#[must_use]
pub fn natural_frame(
    n_i: DVec3,
    d_u: DVec3,
    d_v: DVec3,
    len_u: f64,
    len_v: f64,
    min_sin_bits: u32,
) -> FrameF {
    let mut f = unit_frame(n_i, d_u, d_v, min_sin_bits);
    f.len_u = len_u;
    f.len_v = len_v;
    f
}

/// The frame of `kind` (twin of `hw_model::frame::build_frame`).
#[must_use]
#[allow(clippy::too_many_arguments)]
pub fn build_frame(
    kind: FrameKind,
    n_i: DVec3,
    d_u: DVec3,
    d_v: DVec3,
    len_u: f64,
    len_v: f64,
    m: DVec3,
    role: MainRole,
    min_sin_bits: u32,
) -> FrameF {
    match kind {
        FrameKind::Natural => natural_frame(n_i, d_u, d_v, len_u, len_v, min_sin_bits),
        FrameKind::Unit => unit_frame(n_i, d_u, d_v, min_sin_bits),
        FrameKind::Main => main_frame(n_i, m, role, min_sin_bits),
    }
}

/// `normalize(n + f_u len_u t_u + f_v len_v t_v)`, falling back to `n` if that is zero.
#[must_use]
pub fn perturb_normal(fr: &FrameF, f_u: f64, f_v: f64) -> DVec3 {
    let w = fr.n + f_u * fr.len_u * fr.t_u + f_v * fr.len_v * fr.t_v;
    normalize_or(w, fr.n).0
}

/// Natural-frame vertex data from the vertex normal `n` and the surface derivatives `p_u`,
/// `p_v` (e.g. from `tangents::generate_uv_derivatives`). `ref_u`, `ref_v` are per-object
/// reference lengths (e.g. the mean `|p_u| sin`, `|p_v| sin`) so that the relative lengths
/// stay near 1 and fit the fixed length format; bump heights are then in units of them.
/// `None` if `p_u x p_v` is zero (no natural frame: use the fallback).
#[must_use]
pub fn natural_vertex(
    n: DVec3,
    p_u: DVec3,
    p_v: DVec3,
    ref_u: f64,
    ref_v: f64,
) -> Option<NaturalVertex> {
    let (nh, z) = normalize_or(n, DVec3::ZERO);
    let geo = p_u.cross(p_v).length();
    if z || !geo.is_finite() || geo <= 0.0 {
        return None;
    }
    let su = nh.cross(p_v);
    let sv = p_u.cross(nh);
    let (du, zu) = normalize_or(su, DVec3::ZERO);
    let (dv, zv) = normalize_or(sv, DVec3::ZERO);
    if zu || zv {
        return None;
    }
    Some(NaturalVertex {
        dir_u: du,
        len_u: su.length() / geo * ref_u,
        dir_v: dv,
        len_v: sv.length() / geo * ref_v,
    })
}

/// `b0 a0 + b1 a1 + b2 a2` (perspective-correct barycentrics `b`).
#[must_use]
pub fn interpolate3(b: [f64; 3], a: [DVec3; 3]) -> DVec3 {
    b[0] * a[0] + b[1] * a[1] + b[2] * a[2]
}

/// Scalar version of [`interpolate3`].
#[must_use]
pub fn interpolate1(b: [f64; 3], a: [f64; 3]) -> f64 {
    b[0] * a[0] + b[1] * a[1] + b[2] * a[2]
}

/// `x^n` for `x` in `[0, 1]` (twin of `hw_model::pow::Pow::pow`; `x^0 = 1`).
#[must_use]
pub fn pow(x: f64, n: u32) -> f64 {
    if n == 0 {
        1.0
    } else {
        x.clamp(0.0, 1.0).powi(i32::try_from(n).unwrap_or(i32::MAX))
    }
}

/// Unit vector towards a directional light travelling along `direction`.
#[must_use]
pub fn light_dir_directional(direction: DVec3) -> DVec3 {
    normalize_or(-direction, DVec3::Z).0
}

/// Unit vector from surface point `p` towards a point light at `pos`.
#[must_use]
pub fn light_dir_point(pos: DVec3, p: DVec3) -> DVec3 {
    normalize_or(pos - p, DVec3::Z).0
}

/// Blinn-Phong twin: `light * (kd max(0, n.l) + ks max(0, n.h)^s)`, no specular where
/// `n.l <= 0` or `l + v = 0`, saturated at 1 per channel. Returns `(colour, h_zero)`.
#[must_use]
#[allow(clippy::too_many_arguments)]
pub fn blinn_phong(
    n: DVec3,
    l: DVec3,
    v: DVec3,
    shininess: u32,
    kd: [f64; 3],
    ks: [f64; 3],
    light: [f64; 3],
) -> ([f64; 3], bool) {
    let ndl = n.dot(l).clamp(0.0, 1.0);
    let sum = l + v;
    let h_zero = sum == DVec3::ZERO;
    let spec = if h_zero || ndl == 0.0 {
        0.0
    } else {
        pow(n.dot(sum.normalize()).clamp(0.0, 1.0), shininess)
    };
    let mut c = [0.0; 3];
    for i in 0..3 {
        c[i] = (light[i] * (kd[i] * ndl + ks[i] * spec)).clamp(0.0, 1.0);
    }
    (c, h_zero)
}

/// Float twin of `hw_model::blinn_phong::bump_shade`: offsets `f_u`, `f_v` already decoded
/// (`bump::OffsetEncoding::decode`), frame of `kind`, perturb, Blinn-Phong.
/// Returns `(colour, perturbed normal, frame fallback, h_zero)`.
#[must_use]
#[allow(clippy::too_many_arguments)]
pub fn bump_shade(
    kind: FrameKind,
    n_i: DVec3,
    d_u: DVec3,
    d_v: DVec3,
    lens: [f64; 2],
    m: DVec3,
    role: MainRole,
    offsets: [f64; 2],
    min_sin_bits: u32,
    l: DVec3,
    v: DVec3,
    shininess: u32,
    colors: [[f64; 3]; 3],
) -> ([f64; 3], DVec3, bool, bool) {
    let fr = build_frame(kind, n_i, d_u, d_v, lens[0], lens[1], m, role, min_sin_bits);
    let n = perturb_normal(&fr, offsets[0], offsets[1]);
    let (c, hz) = blinn_phong(n, l, v, shininess, colors[0], colors[1], colors[2]);
    (c, n, fr.fallback, hz)
}
