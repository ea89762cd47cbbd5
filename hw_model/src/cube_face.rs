//! Cube-face unit: the face a direction `r` points at and its face coordinates `s, t`
//! (OpenGL 4.6 section 8.13, Table 8.19: `s = (sc / |ma| + 1) / 2`, `t = (tc / |ma| + 1) / 2`),
//! the divide by the major axis through the [`Reciprocal`] unit.
//!
//! Faces are numbered as OpenGL's: +X, -X, +Y, -Y, +Z, -Z = 0..5; `(sc, tc, ma)` per face:
//! +X `(-rz, -ry, rx)`, -X `(rz, -ry, rx)`, +Y `(rx, rz, ry)`, -Y `(rx, -rz, ry)`,
//! +Z `(rx, -ry, rz)`, -Z `(-rx, -ry, rz)`.
//!
//! Edges and corners (declared behaviour): the major axis is the component of largest
//! magnitude, exact integer compares; ties go to the lower axis (x before y before z), so a
//! direction on an edge or corner has exactly one face, and on it `|s - 1/2|` or `|t - 1/2|`
//! is exactly 1/2. Coordinates are clamped to `[0, 1]` (the reciprocal's rounding can only
//! push them past by a few ulps; each clamp is counted). The filter then reads the face with
//! clamp-to-edge addressing: a footprint that crosses an edge is clamped per face, it does
//! not fetch across faces. The zero vector (only from a saturated or zero input) takes face
//! +Z at its centre and counts a saturation.
//!
//! Datapath (R = input fraction bits, any scale: the result does not depend on it; C =
//! `face_coord_bits`; M = `recip_mantissa_bits`): three magnitude compares and the select of
//! `(sc, tc, |ma|)`; `1/|ma| = mant 2^-shift` from the reciprocal unit; `s = (sc mant +
//! 2^shift) 2^(C - 1 - shift)` exact, one rounding by `env_rounding`.
//!
//! ERROR BOUND (each of `s, t`, against the exact `(sc/|ma| + 1)/2` of the given raw `r`):
//! `1/2 ulp of 0.C` (rounding, `< 1` for `Truncate`) plus `e_recip / 2` relative to
//! `|sc/ma| <= 1`, where `e_recip` is the reciprocal unit's relative error (texram16,
//! `M = 24`: `e_recip <= 2^-24`, so `< 0.502 ulp` at `C = 16`). Tested in
//! `tests/units/env_units.rs` (4M seeded random directions over three widths, every
//! direction of components in 1.6, edges, corners, axes).
//! [`project`] on a given face has the same bound before its clamp.

use crate::cost::UnitCost;
use crate::datapath::{Component, Datapath, Stage};
use crate::env_config::EnvConfig;
use crate::fixed::{round_shift_right_wide, SatCounter};
use crate::reciprocal::Reciprocal;

/// A cube-map address: the face (0..5: +X, -X, +Y, -Y, +Z, -Z) and `s, t` with
/// `face_coord_bits` fraction bits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CubeCoord {
    pub face: u8,
    pub s: i64,
    pub t: i64,
}

/// The face of `r`: the axis of largest magnitude (ties to the lower axis) and its sign.
#[must_use]
pub fn select_face(r: &[i64; 3]) -> u8 {
    let a = r.map(i64::unsigned_abs);
    let axis = if a[0] >= a[1] && a[0] >= a[2] {
        0
    } else if a[1] >= a[2] {
        1
    } else {
        2
    };
    2 * axis + u8::from(r[usize::from(axis)] < 0)
}

/// `(sc, tc, ma)` of `r` on `face` (OpenGL Table 8.19; `ma` signed: positive on the face's
/// own side).
#[must_use]
pub fn face_axes(r: &[i64; 3], face: u8) -> (i64, i64, i64) {
    let [x, y, z] = *r;
    match face {
        0 => (-z, -y, x),
        1 => (z, -y, -x),
        2 => (x, z, y),
        3 => (x, -z, -y),
        4 => (x, -y, z),
        _ => (-x, -y, -z),
    }
}

/// `(c / ma + 1) / 2` with `c_frac` = C fraction bits, from `1/ma = mant 2^-shift`.
fn scaled(c: i64, mant: u64, shift: i32, cbits: u32, cfg: &EnvConfig) -> i64 {
    let q = i128::from(c) * i128::from(mant) + (1i128 << shift.clamp(0, 120));
    let sh = shift + 1 - cbits as i32;
    if sh >= 0 {
        round_shift_right_wide(q, sh as u32, cfg.env_rounding)
    } else {
        i64::try_from(q << (-sh).min(60) as u32).unwrap_or(i64::MAX)
    }
}

/// Face and coordinates of direction `r` (raw components of any common scale, magnitude below
/// 2^40), `s, t` in `[0, 2^C]`.
#[must_use]
pub fn cube_face(
    r: &[i64; 3],
    recip: &Reciprocal,
    cfg: &EnvConfig,
    sat: &mut SatCounter,
) -> CubeCoord {
    let cb = cfg.face_coord_bits;
    let face = select_face(r);
    let (sc, tc, ma) = face_axes(r, face);
    if ma == 0 {
        sat.saturated += 1;
        return CubeCoord {
            face: 4,
            s: 1 << (cb - 1),
            t: 1 << (cb - 1),
        };
    }
    let rc = recip.eval(ma.unsigned_abs(), sat);
    let one = 1i64 << cb;
    let mut fit = |x: i64| {
        if x < 0 || x > one {
            sat.saturated += 1;
        }
        x.clamp(0, one)
    };
    let s = fit(scaled(sc, rc.mant, rc.shift, cb, cfg));
    let t = fit(scaled(tc, rc.mant, rc.shift, cb, cfg));
    CubeCoord { face, s, t }
}

/// Coordinates of `r` projected on a given `face` (for the LOD's helper samples, which stay
/// on the pixel's face), not clamped: `s, t` outside `[0, 2^C]` when `r` leaves the face,
/// limited to `+-2^(C+8)`; `ma <= 0` (r on the far side) returns the limit, counted.
#[must_use]
pub fn project(
    r: &[i64; 3],
    face: u8,
    recip: &Reciprocal,
    cfg: &EnvConfig,
    sat: &mut SatCounter,
) -> [i64; 2] {
    let cb = cfg.face_coord_bits;
    let lim = 1i64 << (cb + 8);
    let (sc, tc, ma) = face_axes(r, face);
    if ma <= 0 {
        sat.saturated += 1;
        return [sc, tc].map(|c| if c < 0 { -lim } else { lim });
    }
    let rc = recip.eval(ma.unsigned_abs(), sat);
    [sc, tc].map(|c| {
        let x = scaled(c, rc.mant, rc.shift, cb, cfg);
        if x.abs() > lim {
            sat.saturated += 1;
        }
        x.clamp(-lim, lim)
    })
}

/// Cost of one face selection and scaling (compares, select, reciprocal, 2 multiply-adds).
#[must_use]
pub fn cube_face_cost(cfg: &EnvConfig, recip: &Reciprocal, gate_levels_per_cycle: u32) -> UnitCost {
    UnitCost {
        ops: 3 + 2 + recip.cost(gate_levels_per_cycle).ops,
        cycles: datapath(cfg, recip.config()).latency(gate_levels_per_cycle),
        texels: 0,
    }
}

/// The face unit (R = `reflect_bits` + 2 bits per component, M = `recip_mantissa_bits`):
/// "major axis" (three magnitude compares, the 3:1 selects of `sc`, `tc`, `ma`,
/// `face_cycles`), the reciprocal unit, "face scale" (two `R x (M+1)` products, the `+1`, the
/// rounding to 0.C, the clamp).
#[must_use]
pub fn datapath(cfg: &EnvConfig, rc: &crate::config::ReciprocalConfig) -> Datapath {
    let r = cfg.reflect_bits + 2;
    let m = rc.recip_mantissa_bits + 1;
    Datapath::new()
        .stage(
            Stage::new("major axis")
                .then_n(3, Component::Comparator { width: r })
                .then_n(
                    3,
                    Component::Mux {
                        width: r,
                        inputs: 3,
                    },
                )
                .cycles(cfg.face_cycles),
        )
        .then(crate::reciprocal::datapath(rc))
        .stage(
            Stage::new("face scale")
                .then_n(2, Component::Multiplier { a: r, b: m })
                .then_n(2, Component::Adder { width: r + m + 1 })
                .then_n(
                    2,
                    Component::Comparator {
                        width: cfg.face_coord_bits + 2,
                    },
                )
                .then(Component::Register {
                    bits: 2 * cfg.face_coord_bits + 5,
                })
                .cycles(cfg.face_cycles),
        )
}
