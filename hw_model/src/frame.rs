//! Local coordinate systems for bump mapping in fixed point (Schilling 1997, "The Local
//! Coordinate System"), and the perturbed normal `n' = n + f_u s_u + f_v s_v`, normalized.
//!
//! All three frames are returned as a [`Frame`]: unit normal `n`, unit tangents `t_u`, `t_v`
//! (the vectors multiplied by `f_u`, `f_v`) and lengths `len_u`, `len_v` (len format, unsigned
//! `frame_len_int_bits`.`frame_len_frac_bits`; 1.0 for frames 2 and 3):
//!
//! 1. Natural: `s_u = n x p_v`, `s_v = p_u x n` (paper: `s_u = n/|n| x p_v`). The pipeline
//!    interpolates the vertex directions and the vertex lengths separately, perspective
//!    correctly, as the paper prescribes; here `t_u = d_u/|d_u|` and `f_u s_u = (f_u len_u) t_u`,
//!    so the lengths scale the two scalar offsets instead of three vector components.
//!    The vertex lengths are relative: `|s_u| / |n|` times a reference, see
//!    `texsim::shading::reference::natural_vertex`.
//! 2. Unit: the same directions, lengths 1 (scale-invariant bumps).
//! 3. Main direction: `n = n_I/|n_I|`, `e1 = m x n / |m x n|`, `e2 = n x e1` (paper, Fig. 5).
//!    `e1` is perpendicular to the plane of `n` and `m`, `e2` lies in it. (The converted paper
//!    text also says the opposite in one sentence, "e2 is perpendicular to m and e1 is in the
//!    plane of n and m"; the formula, the bullet list after it and the earth example, where
//!    `e1` points east, agree with each other, so the formula is implemented.)
//!
//!    Which of `e1`, `e2` carries `f_u` and which `f_v` depends on what `m` stands for
//!    ([`MainRole`]); the assignment makes frame 3 equal frame 2 wherever `p_u`, `p_v` and `n` are
//!    mutually perpendicular, so one offset map gives the same bumps in every frame:
//!    - `m = p_v`, or a constant `m` (which stands for the v direction, as the paper's earth
//!      axis: `e1` east = u, `e2` north = v): `t_u = -e1` (`-e1 = n x p_v / |n x p_v|`, exactly
//!      the direction of `s_u`), `t_v = -e2`;
//!    - `m = p_u`: `t_v = e1` (`e1 = p_u x n / |p_u x n|`, exactly the direction of `s_v`),
//!      `t_u = -e2`.
//!
//!    The vector along `m` (`-e2`) is `s_u` or `s_v` only when `(p_u, p_v, n)` is
//!    right-handed; with mirrored texture coordinates (`n . (p_u x p_v) < 0`, a flag per
//!    triangle, [`MainRole::mirrored`]) frames 1 and 2 flip that axis, so frame 3 uses `+e2`
//!    there. A sign select: no arithmetic, no cost.
//!
//! Near-parallel main direction: if `|m^ x n|^2 < 2^(-2 t)` (`t = frame_min_sin_bits`, i.e.
//! the angle between `m` and `n` is below `asin(2^-t)`, 0.9 degrees for t = 6), or `m` is zero,
//! `m` is replaced by the coordinate axis least aligned with `n` (smallest `|n_i|`, lowest index
//! on ties), for which `|a x n| >= sqrt(2/3)`. The frame therefore JUMPS on the cone
//! `angle(m, n) = asin(2^-t)` and, inside it, on the planes `|n_i| = |n_j|`; everywhere else it
//! is a continuous function of `n_I` and `m`. A zero interpolated normal (opposite vertex
//! normals) becomes +z; zero natural/unit tangent directions fall back to the main-direction
//! frame with the fallback axis. Both are flagged in the returned [`Frame`] and counted as one
//! saturation event each by the normalizer.
//!
//! ERROR BOUNDS (texram16, s1.14, ulp = 2^-14; stated bound / measured max over 1M random
//! cases each in `tests/units/frames_frame.rs`): main frame orthonormality (| |x| - 1 | and pairwise
//! dot products) <= 3 ulp / 1.95 ulp; main frame components against the float twin on the
//! same quantized inputs <= 4 ulp + 2.5 ulp / sin(m, n) / 0.47 of that; unit and natural frame
//! components <= 0.61 ulp / 0.59 ulp; perturbed normal ([`perturb_normal`]) <= 2.5 ulp /
//! 1.10 ulp (unit lengths), <= 8 ulp / 3.38 ulp (natural lengths in [0.25, 2.25], offsets in
//! [-2, 2]). Main frame of every [`MainRole`] against the unit frame on mutually perpendicular
//! `p_u`, `p_v`, `n` (200k cases): frame components <= 6.5 ulp / 3.0 ulp, perturbed normals
//! <= 9 ulp / 3.0 ulp.

use crate::blinn_phong::ShadingConfig;
use crate::config::ConfigError;
use crate::cost::UnitCost;
use crate::datapath::{Component, Cycles, Datapath, Stage};
use crate::fixed::{round_shift_right_wide, Format, Rounding, SatCounter};
use crate::rsqrt::range;
use crate::vector::{
    cross3, cross3_exact, madd, normalize3, offset_format, vector_format, Normalized, Vec3x,
};
use crate::vector::{cross_cost, dot_cost, madd_cost, normalize_cost};
use crate::vector::{cross_datapath, dot_datapath, madd_datapath, normalize_datapath};
use serde::{Deserialize, Serialize};

use crate::blinn_phong::ShadingUnits;

/// Which local coordinate system perturbs the normal.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FrameKind {
    /// `s_u = n x p_v`, `s_v = p_u x n` with separately interpolated lengths.
    Natural,
    /// The natural directions with unit length.
    Unit,
    /// Orthonormal frame from the normal and a main direction `m`.
    Main,
}

impl FrameKind {
    /// The name used in configs, scenes and reports.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            FrameKind::Natural => "natural",
            FrameKind::Unit => "unit",
            FrameKind::Main => "main",
        }
    }
}

/// What the main direction `m` of frame 3 stands for, and the orientation of the texture
/// coordinates: together they select which of `e1`, `e2` (and with which sign) carries `f_u`
/// and which `f_v` (module doc, frame 3). The default is a constant `m` (or `m = p_v`) on
/// right-handed texture coordinates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct MainRole {
    /// `m` is `p_u` (interpolated per pixel). `false`: `m` is `p_v`, or a constant per object,
    /// which stands for the v direction.
    pub m_is_u: bool,
    /// `(p_u, p_v, n)` is left-handed (mirrored texture coordinates), per triangle.
    pub mirrored: bool,
}

/// Frame unit configuration.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrameConfig {
    /// Which frame the pipeline builds.
    pub frame_kind: FrameKind,
    /// Integer bits of the natural frame's interpolated lengths (unsigned). 0..=12.
    pub frame_len_int_bits: u32,
    /// Fraction bits of the natural frame's interpolated lengths. 4..=16.
    pub frame_len_frac_bits: u32,
    /// Main-direction fallback threshold: fall back when `sin(angle(m, n)) < 2^-bits`. 1..=12.
    pub frame_min_sin_bits: u32,
    /// Cycles of the length scaling (two scalar multiplies) in the natural frame.
    pub frame_len_cycles: Cycles,
}

impl FrameConfig {
    /// Texram-style default: main-direction frame, lengths u8.8, fallback below 2^-6.
    #[must_use]
    pub fn texram16() -> Self {
        Self {
            frame_kind: FrameKind::Main,
            frame_len_int_bits: 8,
            frame_len_frac_bits: 8,
            frame_min_sin_bits: 6,
            frame_len_cycles: Cycles::Derived,
        }
    }

    /// Checks the widths; the error names the field.
    pub fn validate(&self) -> Result<(), ConfigError> {
        range("frame.frame_len_int_bits", self.frame_len_int_bits, 0, 12)?;
        range("frame.frame_len_frac_bits", self.frame_len_frac_bits, 4, 16)?;
        range("frame.frame_min_sin_bits", self.frame_min_sin_bits, 1, 12)?;
        Ok(())
    }
}

/// The natural-frame length format: unsigned `frame_len_int_bits`.`frame_len_frac_bits`.
#[must_use]
pub fn len_format(cfg: &FrameConfig, rounding: Rounding) -> Format {
    Format::unsigned(cfg.frame_len_int_bits, cfg.frame_len_frac_bits, rounding)
}

/// A local frame ready for [`perturb_normal`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Frame {
    /// Unit normal (vector format).
    pub n: Vec3x,
    /// Unit vector multiplied by `f_u` (vector format).
    pub t_u: Vec3x,
    /// Unit vector multiplied by `f_v` (vector format).
    pub t_v: Vec3x,
    /// Length of `s_u` (len format; 1.0 for the unit and main frames).
    pub len_u: i64,
    /// Length of `s_v` (len format; 1.0 for the unit and main frames).
    pub len_v: i64,
    /// The tangents came from a fallback (main-direction threshold or zero direction).
    pub fallback: bool,
    /// The interpolated normal had zero length; `n` is +z.
    pub zero_normal: bool,
}

/// The orthonormal main-direction frame `(n, e1, e2)` of the paper.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MainFrame {
    /// `n = n_I / |n_I|`.
    pub n: Vec3x,
    /// `e1 = m x n / |m x n|`.
    pub e1: Vec3x,
    /// `e2 = n x e1`.
    pub e2: Vec3x,
    /// `m` was replaced by the least aligned axis.
    pub fallback: bool,
    /// `n_I` was zero; `n` is +z.
    pub zero_normal: bool,
}

fn unit_z(f: u32) -> Vec3x {
    [0, 0, 1i64 << f]
}

/// The coordinate axis least aligned with `n` (smallest `|n_i|`, lowest index on ties).
#[must_use]
pub fn least_aligned_axis(n: &Vec3x, frac_bits: u32) -> Vec3x {
    let a = n.map(i64::abs);
    let i = if a[0] <= a[1] && a[0] <= a[2] {
        0
    } else if a[1] <= a[2] {
        1
    } else {
        2
    };
    let mut out = [0i64; 3];
    out[i] = 1i64 << frac_bits;
    out
}

/// Paper frame 3: `n = n_I/|n_I|`, `e1 = m x n/|m x n|`, `e2 = n x e1`, with the documented
/// near-parallel fallback. `n_i` and `m` may have any binary scale (vector format typical).
#[must_use]
pub fn main_direction_frame(
    n_i: &Vec3x,
    m: &Vec3x,
    units: &ShadingUnits,
    sat: &mut SatCounter,
) -> MainFrame {
    let vc = &units.cfg.vector;
    let f = vc.vector_frac_bits;
    let rs = &units.rsqrt;
    let nn = normalize3(n_i, unit_z(f), rs, vc, sat);
    let n = nn.v;
    let mn = normalize3(m, [0; 3], rs, vc, sat);
    // |m^ x n|^2 (4F fraction bits) against 2^(4F - 2t).
    let mut c = cross3_exact(&mn.v, &n);
    let s2: u128 = c.iter().map(|&x| (x * x) as u128).sum();
    let t = units.cfg.frame.frame_min_sin_bits.min(2 * f);
    let fallback = mn.zero || s2 < (1u128 << (4 * f - 2 * t));
    if fallback {
        c = cross3_exact(&least_aligned_axis(&n, f), &n);
    }
    // c has 2F fraction bits and |c| < 2^(2F+2): it fits i64 exactly.
    let c64 = c.map(|x| x as i64);
    let e1 = normalize3(&c64, [1i64 << f, 0, 0], rs, vc, sat).v;
    let e2 = cross3(&n, &e1, vc, sat);
    MainFrame {
        n,
        e1,
        e2,
        fallback,
        zero_normal: nn.zero,
    }
}

fn neg(v: &Vec3x, fmt: &Format, sat: &mut SatCounter) -> Vec3x {
    v.map(|x| fmt.fit(-x, sat))
}

/// Frame 3 as a [`Frame`], lengths 1: `t_u = -e1`, `t_v = -e2` for `m = p_v` or a constant
/// `m`; `t_u = -e2`, `t_v = e1` for `m = p_u`; `e2` instead of `-e2` when mirrored (module doc).
#[must_use]
pub fn main_frame(
    n_i: &Vec3x,
    m: &Vec3x,
    role: MainRole,
    units: &ShadingUnits,
    sat: &mut SatCounter,
) -> Frame {
    let mf = main_direction_frame(n_i, m, units, sat);
    let fmt = vector_format(&units.cfg.vector);
    let one = 1i64 << units.cfg.frame.frame_len_frac_bits;
    let along_m = if role.mirrored {
        mf.e2
    } else {
        neg(&mf.e2, &fmt, sat)
    };
    let (t_u, t_v) = if role.m_is_u {
        (along_m, mf.e1)
    } else {
        (neg(&mf.e1, &fmt, sat), along_m)
    };
    Frame {
        n: mf.n,
        t_u,
        t_v,
        len_u: one,
        len_v: one,
        fallback: mf.fallback,
        zero_normal: mf.zero_normal,
    }
}

/// Frame 1: interpolated normal `n_i`, interpolated directions `d_u`, `d_v` of `s_u`, `s_v`
/// (any common scale) and separately interpolated lengths `len_u`, `len_v` (len format raw,
/// saturated into it). Zero `d_u` or `d_v` falls back to the main frame of the fallback axis.
#[must_use]
#[allow(clippy::too_many_arguments)]
pub fn natural_frame(
    n_i: &Vec3x,
    d_u: &Vec3x,
    d_v: &Vec3x,
    len_u: i64,
    len_v: i64,
    units: &ShadingUnits,
    sat: &mut SatCounter,
) -> Frame {
    let lf = len_format(&units.cfg.frame, units.cfg.vector.vector_rounding);
    let mut fr = unit_frame(n_i, d_u, d_v, units, sat);
    fr.len_u = lf.fit(len_u, sat);
    fr.len_v = lf.fit(len_v, sat);
    fr
}

/// Frame 2: `n = n_i/|n_i|`, `t_u = d_u/|d_u|`, `t_v = d_v/|d_v|`, lengths 1.
#[must_use]
pub fn unit_frame(
    n_i: &Vec3x,
    d_u: &Vec3x,
    d_v: &Vec3x,
    units: &ShadingUnits,
    sat: &mut SatCounter,
) -> Frame {
    let vc = &units.cfg.vector;
    let f = vc.vector_frac_bits;
    let rs = &units.rsqrt;
    let nn = normalize3(n_i, unit_z(f), rs, vc, sat);
    let su = normalize3(d_u, [0; 3], rs, vc, sat);
    let sv = normalize3(d_v, [0; 3], rs, vc, sat);
    let one = 1i64 << units.cfg.frame.frame_len_frac_bits;
    if su.zero || sv.zero {
        let axis = least_aligned_axis(&nn.v, f);
        let mut fr = main_frame(&nn.v, &axis, MainRole::default(), units, sat);
        fr.fallback = true;
        fr.zero_normal = nn.zero;
        return fr;
    }
    Frame {
        n: nn.v,
        t_u: su.v,
        t_v: sv.v,
        len_u: one,
        len_v: one,
        fallback: false,
        zero_normal: nn.zero,
    }
}

/// The frame of `units.cfg.frame.frame_kind` from all per-pixel inputs (`m` and `role` are
/// used by the main frame only; `d_u`, `d_v`, lengths by the other two).
#[must_use]
#[allow(clippy::too_many_arguments)]
pub fn build_frame(
    n_i: &Vec3x,
    d_u: &Vec3x,
    d_v: &Vec3x,
    len_u: i64,
    len_v: i64,
    m: &Vec3x,
    role: MainRole,
    units: &ShadingUnits,
    sat: &mut SatCounter,
) -> Frame {
    match units.cfg.frame.frame_kind {
        FrameKind::Natural => natural_frame(n_i, d_u, d_v, len_u, len_v, units, sat),
        FrameKind::Unit => unit_frame(n_i, d_u, d_v, units, sat),
        FrameKind::Main => main_frame(n_i, m, role, units, sat),
    }
}

/// Perturbed normal `normalize(n + (f_u len_u) t_u + (f_v len_v) t_v)`; `f_u`, `f_v` raw in
/// offset format. Each `f len` is rounded once into offset format (saturating, counted), the
/// multiply-add is exact with one rounding into wide format, then normalized (a zero result
/// falls back to the frame normal).
/// ERROR BOUND per component against the float twin on the same frame and offsets (texram16,
/// ulp = 2^-14, offsets in [-2, 2]; asserted in `tests/units/frames_frame.rs`, 1M cases): 2.5 ulp
/// with lengths 1 (madd rounding, at most sqrt(3)/2 ulp relative to `|n'|`, plus the
/// normalize bound 0.61 ulp), 8 ulp with natural lengths in [0.25, 2.25] (adds the rounding
/// of each `f len` to the offset format, 1/2 ulp of s3.12 = 2 ulp of s1.14 per offset);
/// measured 1.10 and 3.38 ulp.
#[must_use]
pub fn perturb_normal(
    fr: &Frame,
    f_u: i64,
    f_v: i64,
    units: &ShadingUnits,
    sat: &mut SatCounter,
) -> Normalized {
    let vc = &units.cfg.vector;
    let of = offset_format(vc);
    let lfb = units.cfg.frame.frame_len_frac_bits;
    let g = |f: i64, l: i64, sat: &mut SatCounter| {
        of.fit(
            round_shift_right_wide(i128::from(f) * i128::from(l), lfb, vc.vector_rounding),
            sat,
        )
    };
    let g_u = g(f_u, fr.len_u, sat);
    let g_v = g(f_v, fr.len_v, sat);
    let w = madd(&fr.n, &fr.t_u, &fr.t_v, g_u, g_v, vc, sat);
    normalize3(&w, fr.n, &units.rsqrt, vc, sat)
}

/// Cost of building one frame of `kind` (normalizer costs include the rsqrt). The natural
/// frame includes its length scaling: the two scalar multiplies `f_u len_u`, `f_v len_v`
/// (`frame_len_cycles`), which [`perturb_normal`] performs but only the natural frame needs
/// (the unit and main frames have lengths 1), so they are charged here, once. Cycles are
/// those of [`datapath`].
#[must_use]
pub fn frame_cost(kind: FrameKind, units: &ShadingUnits, gate_levels_per_cycle: u32) -> UnitCost {
    let g = gate_levels_per_cycle;
    let c = &units.cfg;
    let nz = normalize_cost(&c.vector, crate::rsqrt::rsqrt_cost(&c.rsqrt, g), g);
    match kind {
        FrameKind::Unit => nz.times(3),
        FrameKind::Natural => nz.times(3).plus(UnitCost {
            ops: 2,
            cycles: len_datapath(c).latency(g),
            texels: 0,
        }),
        FrameKind::Main => nz
            .times(3)
            .plus(cross_cost(&c.vector, g).times(2))
            .plus(dot_cost(&c.vector, g)),
    }
}

/// Cost of one [`perturb_normal`] of any frame: the multiply-add and a normalize (the natural
/// frame's length multiplies are in [`frame_cost`]); cycles those of [`perturb_datapath`].
#[must_use]
pub fn perturb_cost(units: &ShadingUnits, gate_levels_per_cycle: u32) -> UnitCost {
    let g = gate_levels_per_cycle;
    let c = &units.cfg;
    let nz = normalize_cost(&c.vector, crate::rsqrt::rsqrt_cost(&c.rsqrt, g), g);
    madd_cost(&c.vector, g).plus(nz)
}

/// The natural frame's length scaling (`frame_len_cycles`): two products of a vector by its
/// `frame_len_int_bits.frame_len_frac_bits` length, side by side, rounded.
#[must_use]
pub fn len_datapath(c: &ShadingConfig) -> Datapath {
    let v = c.vector.vector_frac_bits + 2;
    let l = c.frame.frame_len_int_bits + c.frame.frame_len_frac_bits;
    Datapath::new().stage(
        Stage::new("length scaling")
            .then_n(6, Component::Multiplier { a: v, b: l })
            .then_n(6, Component::Adder { width: v + 1 })
            .cycles(c.frame.frame_len_cycles),
    )
}

/// Building a frame of `kind`: three normalizes; the natural frame adds its length scaling,
/// the main frame two cross products and a dot.
#[must_use]
pub fn datapath(kind: FrameKind, c: &ShadingConfig) -> Datapath {
    let nz = normalize_datapath(&c.vector, &c.rsqrt).times(3);
    match kind {
        FrameKind::Unit => nz,
        FrameKind::Natural => nz.then(len_datapath(c)),
        FrameKind::Main => nz
            .then(cross_datapath(&c.vector).times(2))
            .then(dot_datapath(&c.vector)),
    }
}

/// [`perturb_normal`]: the multiply-add, then a normalize.
#[must_use]
pub fn perturb_datapath(c: &ShadingConfig) -> Datapath {
    madd_datapath(&c.vector).then(normalize_datapath(&c.vector, &c.rsqrt))
}
