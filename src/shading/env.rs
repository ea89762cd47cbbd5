//! Environment maps, host side: the float twins of the environment units
//! (`hw_model::{reflect, cube_face, env_lod}`) and the procedural sky of the built-in scenes
//! (Schilling 1997, "balanced system"; `docs/ENVMAP.md`).

use crate::footprint_ref::{footprint_f64, FootprintF};
use glam::DVec3;
use hw_model::env_config::EnvFilter;

/// Float twin of `hw_model::reflect::reflect`: `2 (n . v) n - v`.
#[must_use]
pub fn reflect_f(n: DVec3, v: DVec3) -> DVec3 {
    2.0 * n.dot(v) * n - v
}

/// Float twin of `hw_model::cube_face::select_face` (ties to the lower axis).
#[must_use]
pub fn select_face_f(r: DVec3) -> u8 {
    let a = r.abs();
    let axis = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    2 * axis + u8::from(r[usize::from(axis)] < 0.0)
}

/// `(sc, tc, ma)` of `r` on `face` (OpenGL 4.6 Table 8.19).
#[must_use]
pub fn face_axes_f(r: DVec3, face: u8) -> (f64, f64, f64) {
    let (x, y, z) = (r.x, r.y, r.z);
    match face {
        0 => (-z, -y, x),
        1 => (z, -y, -x),
        2 => (x, z, y),
        3 => (x, -z, -y),
        4 => (x, -y, z),
        _ => (-x, -y, -z),
    }
}

/// Float twin of `hw_model::cube_face::cube_face`: face and `[s, t]` in `[0, 1]`; the zero
/// (or non-finite) vector takes face +Z at its centre.
#[must_use]
pub fn cube_face_f(r: DVec3) -> (u8, [f64; 2]) {
    if !r.is_finite() || r == DVec3::ZERO {
        return (4, [0.5, 0.5]);
    }
    let face = select_face_f(r);
    let (sc, tc, ma) = face_axes_f(r, face);
    let m = ma.abs();
    (
        face,
        [sc, tc].map(|c| ((c / m + 1.0) * 0.5).clamp(0.0, 1.0)),
    )
}

/// Float twin of `hw_model::cube_face::project`: `r` on a given face, unclamped, limited to
/// `+-256`; `ma <= 0` returns the limit.
#[must_use]
pub fn project_f(r: DVec3, face: u8) -> [f64; 2] {
    let (sc, tc, ma) = face_axes_f(r, face);
    if ma <= 0.0 || !ma.is_finite() {
        return [sc, tc].map(|c| if c < 0.0 { -256.0 } else { 256.0 });
    }
    [sc, tc].map(|c| ((c / ma + 1.0) * 0.5).clamp(-256.0, 256.0))
}

/// The roughness on the face in float: the ellipse's two axes (face units).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FaceRoughnessF {
    pub axes: [[f64; 2]; 2],
}

/// Float twin of `hw_model::env_lod::env_lod`.
#[must_use]
pub fn env_lod_f(
    st: &[[f64; 2]; 3],
    face_size: u32,
    rough: &FaceRoughnessF,
    filter: EnvFilter,
    probes: u32,
    adaptive: bool,
) -> FootprintF {
    let n = (face_size, face_size);
    match filter {
        EnvFilter::None => footprint_f64(st, n, probes, adaptive),
        EnvFilter::Lambda1 => {
            let mut fp = footprint_f64(st, n, probes, adaptive);
            let [a, b] = rough.axes;
            let w = a[0].hypot(a[1]).max(b[0].hypot(b[1])) * f64::from(face_size);
            let lw = if w > 0.0 { w.log2().max(-32.0) } else { -32.0 };
            fp.lod = fp.lod.max(lw);
            fp
        }
        EnvFilter::Ellipse => {
            let dx = [st[1][0] - st[0][0], st[1][1] - st[0][1]];
            let dy = [st[2][0] - st[0][0], st[2][1] - st[0][1]];
            let cand = [dx, dy, rough.axes[0], rough.axes[1]];
            let l2 = |d: [f64; 2]| d[0] * d[0] + d[1] * d[1];
            let mut major = 0;
            for (i, c) in cand.iter().enumerate() {
                if l2(*c) > l2(cand[major]) {
                    major = i;
                }
            }
            let a = cand[major];
            let lm = cand
                .iter()
                .enumerate()
                .filter(|(i, _)| *i != major)
                .map(|(_, c)| l2(*c))
                .fold(0.0, f64::max)
                .sqrt();
            let la = l2(a).sqrt();
            let minor = if la > 0.0 {
                [-a[1] * lm / la, a[0] * lm / la]
            } else {
                [0.0, 0.0]
            };
            let tri = [
                st[0],
                [st[0][0] + a[0], st[0][1] + a[1]],
                [st[0][0] + minor[0], st[0][1] + minor[1]],
            ];
            footprint_f64(&tri, n, probes, adaptive)
        }
    }
}

/// The Jacobian of the face coordinates `(s, t)` with respect to the direction `r` on
/// `face` (rows `ds/dr`, `dt/dr`): `d(c/ma)/dr = (dc ma - c dma) / ma^2`, halved.
#[must_use]
pub fn face_jacobian_f(r: DVec3, face: u8) -> [DVec3; 2] {
    let axes = |v: DVec3| face_axes_f(v, face);
    let (sc, tc, ma) = axes(r);
    let basis = [DVec3::X, DVec3::Y, DVec3::Z];
    let mut js = DVec3::ZERO;
    let mut jt = DVec3::ZERO;
    if ma.abs() < 1e-300 {
        return [js, jt];
    }
    for (i, e) in basis.iter().enumerate() {
        let (dsc, dtc, dma) = axes(*e);
        js[i] = 0.5 * (dsc * ma - sc * dma) / (ma * ma);
        jt[i] = 0.5 * (dtc * ma - tc * dma) / (ma * ma);
    }
    [js, jt]
}

/// The roughness ellipse carried from the tangent plane to the face (float; the carry is
/// first order): a slope `(du, dv)` of the surface tilts the normal by `dn = du t_u + dv t_v`,
/// which turns the reflection by `dr = 2 ((dn . v) n + (n . v) dn)`, which moves the face
/// coordinates by `J dr` ([`face_jacobian_f`]). The ellipse's axes are the columns of `D`
/// (`[[d1, d2], [0, d3]]`, slopes) mapped so. (The stage uses the finite difference of the
/// exact map instead, `env_fetch`; this first-order form is its small-roughness limit.)
#[must_use]
pub fn rough_on_face_f(n: DVec3, v: DVec3, t: [DVec3; 2], d: [f64; 3], face: u8) -> FaceRoughnessF {
    let r = reflect_f(n, v);
    let j = face_jacobian_f(r, face);
    let nv = n.dot(v);
    let turn = |dn: DVec3| 2.0 * (dn.dot(v) * n + nv * dn);
    let to_face = |dr: DVec3| [j[0].dot(dr), j[1].dot(dr)];
    let col0 = t[0] * d[0];
    let col1 = t[0] * d[1] + t[1] * d[2];
    FaceRoughnessF {
        axes: [to_face(turn(col0)), to_face(turn(col1))],
    }
}

/// The procedural sky of the built-in scenes (linear RGB in `[0, 1]`, deterministic): a
/// horizon-to-zenith gradient, a sun disc with a halo, a band of high-frequency cloud stripes
/// (so that under-filtering aliases visibly far away) and a dark checkered ground below the
/// horizon. `+Y` is up.
#[must_use]
pub fn sky_f(dir: DVec3) -> [f64; 3] {
    let d = dir.normalize_or_zero();
    if d == DVec3::ZERO {
        return [0.0; 3];
    }
    let up = d.y;
    if up < 0.0 {
        let az = d.z.atan2(d.x);
        let checker = ((az * 16.0 / std::f64::consts::PI).floor() as i64
            + ((-up) * 12.0).floor() as i64)
            .rem_euclid(2);
        let g = if checker == 0 { 0.10 } else { 0.22 };
        return [g, g * 0.9, g * 0.8];
    }
    let horizon = [0.85, 0.88, 0.92];
    let zenith = [0.15, 0.35, 0.80];
    let k = up.sqrt();
    let mut c = [0, 1, 2].map(|i| horizon[i] * (1.0 - k) + zenith[i] * k);
    let sun = DVec3::new(0.3, 0.5, -0.8).normalize();
    let cs = d.dot(sun);
    let disc = if cs > 0.9990 { 1.0 } else { 0.0 };
    let halo = cs.max(0.0).powi(64) * 0.4;
    let az = d.z.atan2(d.x);
    let stripes = 0.5 + 0.5 * (az * 48.0).sin() * (up * 40.0).cos();
    let band = (1.0 - (up * 4.0 - 1.0).abs()).clamp(0.0, 1.0);
    for ch in &mut c {
        *ch = (*ch * (1.0 - 0.45 * band * stripes) + halo + disc).clamp(0.0, 1.0);
    }
    c
}
