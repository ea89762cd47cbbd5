//! Environment LOD unit: the footprint of an environment lookup on its cube face from the
//! reflection vector's screen derivatives, widened by the roughness (Schilling 1997,
//! "balanced system": the roughness ellipse `D`, or `lambda_1`, anti-aliases the
//! environment lookup instead of a plain MIP level).
//!
//! Inputs: the face coordinates (`face_coord_bits` = C fraction bits) of the pixel's
//! reflection vector and of its helper samples (x+1, y), (x, y+1) projected on the pixel's
//! face ([`crate::cube_face::project`]), the face size `N` (level-0 texels), and the
//! roughness on the face: `axes`, the two axes of the ellipse `D` carried to the face
//! (face-coordinate units, C fraction bits).
//!
//! - `none`: footprint assembly ([`crate::footprint::footprint`]) on the derivatives only
//!   (with one probe: the isotropic LOD unit).
//! - `lambda1`: the same footprint, its LOD raised to that of the longer ellipse axis when
//!   that is larger: `max(log2 rho, log2 max(|a_1|, |a_2|))` (one more evaluation of the LOD
//!   unit, which takes the longer of two vectors, and a compare). The longer axis is within
//!   `[lambda_1 / sqrt 2, lambda_1]` of the mapped ellipse's `lambda_1`: an isotropic width.
//! - `ellipse`: the footprint of the union of the pixel's parallelogram and the ellipse,
//!   bounded by two vectors: the major axis is the longest of the four (`dx`, `dy`, `axes`;
//!   exact squared lengths, ties to the earlier), the minor has the largest length of the
//!   other three (along the perpendicular of the major, so the probe count sees the true
//!   aspect); footprint assembly then places its probes along that major axis.
//!
//! ERROR BOUND: the axis decisions are exact integer compares, so the fixed unit picks the
//! same vectors as its float twin (`texsim::shading::env::env_lod_f`) on the same inputs; the
//! LOD is the footprint unit's (at most 2 LSB below the exact value, never above, see
//! [`crate::footprint`]); the perpendicular minor is exact (a swap and a negation) scaled by
//! `|minor| / |major|` through one rounding (1/2 LSB of C per component), which moves the
//! minor's LOD by at most `-2^F log2(1 - 2^-(C+1/2) / |minor|)` LSB either way (F =
//! `lod_frac_bits`; e.g. 67 LSB for a minor of 1000 face ulps at F = 16). The two lengths are
//! floored square roots with 16 fraction bits, which moves the scaled minor's length by less
//! than `2^-15` face ulp more (the test's term uses 0.71 ulp for the rounding's `2^-1/2`). In all:
//! within `[-3, +1]` LSB of the float twin, plus that term for `ellipse`. Tested in
//! `tests/units/env_units.rs` (1M seeded footprints, every filter).

use crate::config::LodConfig;
use crate::cost::UnitCost;
use crate::datapath::{Component, Datapath, Stage};
use crate::env_config::{EnvConfig, EnvFilter};
use crate::fixed::{round_div_wide, SatCounter};
use crate::footprint::{footprint, Footprint};
use crate::lod::{lod, lod_cost};

/// The roughness on the face: the ellipse's two axes (C fraction bits).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FaceRoughness {
    pub axes: [[i64; 2]; 2],
}

fn len2(d: [i64; 2]) -> u128 {
    let a = u128::from(d[0].unsigned_abs());
    let b = u128::from(d[1].unsigned_abs());
    a * a + b * b
}

/// Integer square root (floor) of a `u128`: Newton's iteration from `2^ceil(bits/2)`, an
/// upper bound, so the iterates decrease to the floor.
fn isqrt(x: u128) -> u128 {
    if x < 2 {
        return x;
    }
    let mut r = 1u128 << (128 - x.leading_zeros()).div_ceil(2);
    loop {
        let nr = (r + x / r) / 2;
        if nr >= r {
            return r;
        }
        r = nr;
    }
}

/// The footprint of one environment lookup on a face of `face_size` texels.
#[allow(clippy::too_many_arguments)]
#[must_use]
pub fn env_lod(
    st: &[[i64; 2]; 3],
    face_size: u32,
    rough: &FaceRoughness,
    filter: EnvFilter,
    probes: u32,
    adaptive: bool,
    cfg: &EnvConfig,
    lcfg: &LodConfig,
    sat: &mut SatCounter,
) -> Footprint {
    let cb = cfg.face_coord_bits;
    let n = (face_size, face_size);
    match filter {
        EnvFilter::None => footprint(st, n, cb, probes, adaptive, lcfg, sat),
        EnvFilter::Lambda1 => {
            let mut fp = footprint(st, n, cb, probes, adaptive, lcfg, sat);
            let n = i64::from(face_size);
            let [a, b] = rough.axes;
            let d = [a[0], a[1], b[0], b[1]].map(|x| x.saturating_mul(n));
            let lw = lod(d, cb, lcfg, sat);
            fp.lod = fp.lod.max(lw);
            fp
        }
        EnvFilter::Ellipse => {
            let dx = [st[1][0] - st[0][0], st[1][1] - st[0][1]];
            let dy = [st[2][0] - st[0][0], st[2][1] - st[0][1]];
            let cand = [dx, dy, rough.axes[0], rough.axes[1]];
            let mut major = 0;
            for (i, c) in cand.iter().enumerate() {
                if len2(*c) > len2(cand[major]) {
                    major = i;
                }
            }
            let a = cand[major];
            let minor_l2 = cand
                .iter()
                .enumerate()
                .filter(|(i, _)| *i != major)
                .map(|(_, c)| len2(*c))
                .max()
                .unwrap_or(0);
            let la = isqrt(len2(a) << 32);
            let lm = isqrt(minor_l2 << 32);
            // minor = perp(a) * |minor| / |a|, one rounding per component.
            let perp = [-a[1], a[0]];
            let minor = if la == 0 {
                [0, 0]
            } else {
                perp.map(|p| {
                    round_div_wide(
                        i128::from(p) * i128::try_from(lm).unwrap_or(i128::MAX),
                        i128::try_from(la).unwrap_or(i128::MAX),
                        cfg.env_rounding,
                    )
                })
            };
            let tri = [
                st[0],
                [st[0][0] + a[0], st[0][1] + a[1]],
                [st[0][0] + minor[0], st[0][1] + minor[1]],
            ];
            footprint(&tri, n, cb, probes, adaptive, lcfg, sat)
        }
    }
}

/// Cost of the footprint choice beyond footprint assembly itself: `lambda1` one LOD
/// evaluation and a compare; `ellipse` four squared lengths, three compares, two square
/// roots and the minor's scaling (2 multiplies, 2 divides).
#[must_use]
pub fn env_lod_cost(filter: EnvFilter, lcfg: &LodConfig, cfg: &EnvConfig, g: u32) -> UnitCost {
    match filter {
        EnvFilter::None => UnitCost::default(),
        EnvFilter::Lambda1 => UnitCost {
            ops: lod_cost(lcfg, g).ops + 1,
            cycles: lambda1_datapath(lcfg).latency(g),
            texels: 0,
        },
        EnvFilter::Ellipse => UnitCost {
            ops: 8 + 3 + 2 + 4,
            cycles: datapath(cfg).latency(g),
            texels: 0,
        },
    }
}

/// `lambda1`'s widening: the LOD unit on the width, the compare and select of the larger LOD.
#[must_use]
pub fn lambda1_datapath(lcfg: &LodConfig) -> Datapath {
    crate::lod::datapath(lcfg).stage(
        Stage::new("larger lod")
            .then(Component::Comparator { width: 24 })
            .then(Component::Mux {
                width: 24,
                inputs: 2,
            }),
    )
}

/// The ellipse's axis choice (C = `face_coord_bits`, W = C + 8 bits per difference): four
/// squared lengths side by side, three compares and the selects, two square roots (a
/// digit-recurrence of `W + 16` steps, modelled as one adder per bit), the minor's two
/// products and divides (modelled as a multiplier and `W` subtract steps each).
#[must_use]
pub fn datapath(cfg: &EnvConfig) -> Datapath {
    let w = cfg.face_coord_bits + 9;
    let sq = 2 * w + 1;
    Datapath::new()
        .stage(
            Stage::new("axis choice")
                .then_n(8, Component::Multiplier { a: w, b: w })
                .then_n(4, Component::Adder { width: sq })
                .then(Component::Comparator { width: sq })
                .then(Component::Comparator { width: sq })
                .then(Component::Comparator { width: sq })
                .then_n(
                    2,
                    Component::Mux {
                        width: 2 * w,
                        inputs: 4,
                    },
                ),
        )
        .stage(
            Stage::new("square-root step")
                .then_n(2, Component::Adder { width: sq + 32 })
                .times(w + 16),
        )
        .stage(Stage::new("minor scale").then_n(2, Component::Multiplier { a: w, b: w + 16 }))
        .stage(
            Stage::new("minor divide step")
                .then_n(2, Component::Adder { width: 2 * w + 16 })
                .times(w),
        )
}
