//! Footprint assembly: Texram's anisotropic filter (Schilling, Knittel and Strasser, "Texram: a
//! smart memory for texturing", IEEE CG&A 16(3), 1996), as a fixed-point unit.
//!
//! The pixel footprint in texel space is the parallelogram spanned by the derivatives
//! `(du/dx, dv/dx)` and `(du/dy, dv/dy)`. Footprint assembly approximates it by `N` trilinear
//! probes placed along its major axis and averages them:
//!
//! - Major axis: the derivative vector with the larger squared texel-space length (`x` on a
//!   tie), exact in `u128`; the minor length is that of the other vector.
//! - Probes: `N` = `aniso_probes` (a power of two <= 16; every pixel takes all `N`, so a
//!   lookup's cost is fixed), or with `aniso_adaptive` the smallest power of two `N <=
//!   aniso_probes` with `|major|^2 <= N^2 |minor|^2`: the anisotropy rounded up to a power of
//!   two, as Texram picks it (an isotropic footprint takes one probe, plain trilinear; the
//!   cost then varies per pixel and is counted per pixel). Probe `i` (0-based) is at `uv + axis * (2i + 1 - N) / (2N)`: the
//!   centres of `N` equal segments of the major axis, centred on the pixel. Each offset is the
//!   exact product rounded once (half-even) to the texture-coordinate format.
//! - Per-probe LOD: `log2(max(minor, major / N))`, the practice of
//!   `EXT_texture_filter_anisotropic` (and EWA-style filters): the probes cover the major axis
//!   when it needs more than `N` probes, otherwise the minor axis sets the level. In integers:
//!   if `|major|^2 > N^2 |minor|^2`, `lod(major) - log2(N)`, else `lod(minor)`, where `lod` is
//!   the LOD unit ([`crate::lod::lod`], floor-rounded); clamped below at [`lod_zero`].
//!   With `N = 1` this is exactly the isotropic LOD of the LOD unit.
//! - Average: the per-channel sum of the `N` trilinear results shifted right by `log2(N)` with
//!   one rounding (`filter_rounding`).
//!
//! ERROR BOUND vs the exact-arithmetic twin (`texsim::footprint_ref`) on the same (fixed)
//! texture coordinates: the axis choice and the `N^2` comparison are exact integer decisions,
//! so both pick the same candidate; each offset is within 1/2 LSB of the texture-coordinate
//! format; the LOD is `floor(lambda * 2^F)` of the chosen candidate (subtracting `log2(N) << F`
//! is exact), i.e. within 1 LSB below the exact value, plus the LOD unit's own rare extra LSB
//! (see [`crate::lod`]): at most 2 LSB below, never above (before the lower clamp). The
//! average adds one rounding (<= 1/2 LSB, < 1 for Truncate) to the mean of the probes'
//! trilinear errors ([`crate::trilinear`]).

use crate::config::{LodConfig, TrilinearConfig};
use crate::cost::UnitCost;
use crate::datapath::{ceil_log2, Component, Datapath, Stage};
use crate::fixed::{round_shift_right, Rounding, SatCounter};
use crate::lod::{lod, lod_cost, lod_zero};
use crate::trilinear::{trilinear, trilinear_cost, Level, TrilinearTrace};
use crate::wrap::WrapMode;

/// Largest number of probes.
pub const MAX_PROBES: usize = 16;

/// The assembled footprint of one pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Footprint {
    /// Number of probes `N` (a power of two, 1..=16).
    pub probes: u32,
    /// Major-axis vector in normalized texture coordinates (`frac` fraction bits).
    pub axis: [i64; 2],
    /// Per-probe LOD, `lod_frac_bits` fraction bits.
    pub lod: i64,
}

/// Squared texel-space length of `(du, dv)` (normalized differences scaled by the level-0 size).
#[inline]
fn len2(du: i64, dv: i64, w: u32, h: u32) -> u128 {
    let a = u128::from(du.unsigned_abs()) * u128::from(w);
    let b = u128::from(dv.unsigned_abs()) * u128::from(h);
    a * a + b * b
}

/// Assembles the footprint of a pixel from its texture coordinates `uv` at the sample and the
/// helper samples (x+1, y) and (x, y+1) (`frac` fraction bits, normalized), the level-0 size
/// `(w, h)` and `probes` (clamped to a power of two in 1..=16). With `adaptive` the probe
/// count is the smallest power of two `N <= probes` with `|major|^2 <= N^2 |minor|^2` (the
/// anisotropy rounded up to a power of two, as Texram chooses it), else `probes`.
#[inline]
#[must_use]
pub fn footprint(
    uv: &[[i64; 2]; 3],
    size: (u32, u32),
    frac: u32,
    probes: u32,
    adaptive: bool,
    cfg: &LodConfig,
    sat: &mut SatCounter,
) -> Footprint {
    let cap = probes.clamp(1, MAX_PROBES as u32);
    let cap = if cap.is_power_of_two() {
        cap
    } else {
        cap.next_power_of_two() >> 1
    };
    let (w, h) = size;
    let dx = [uv[1][0] - uv[0][0], uv[1][1] - uv[0][1]];
    let dy = [uv[2][0] - uv[0][0], uv[2][1] - uv[0][1]];
    let lx = len2(dx[0], dx[1], w, h);
    let ly = len2(dy[0], dy[1], w, h);
    let (maj, min, lmaj, lmin) = if lx >= ly {
        (dx, dy, lx, ly)
    } else {
        (dy, dx, ly, lx)
    };
    let mut n = if adaptive { 1 } else { cap };
    while n < cap && lmaj > lmin.saturating_mul(u128::from(n) * u128::from(n)) {
        n *= 2;
    }
    let texel = |d: [i64; 2]| [d[0] * i64::from(w), d[1] * i64::from(h), 0, 0];
    let f = cfg.lod_frac_bits.min(16);
    let log2n = n.trailing_zeros();
    let n2 = u128::from(n) * u128::from(n);
    let l = if n == 1 {
        lod(
            [
                dx[0] * i64::from(w),
                dx[1] * i64::from(h),
                dy[0] * i64::from(w),
                dy[1] * i64::from(h),
            ],
            frac,
            cfg,
            sat,
        )
    } else if lmaj > lmin.saturating_mul(n2) {
        lod(texel(maj), frac, cfg, sat) - (i64::from(log2n) << f)
    } else {
        lod(texel(min), frac, cfg, sat)
    };
    Footprint {
        probes: n,
        axis: maj,
        lod: l.max(lod_zero(f)),
    }
}

/// Offset of probe `i` from the pixel's texture coordinate: `axis * (2i + 1 - N) / (2N)`,
/// rounded once (half-even) to the coordinate format.
#[inline]
#[must_use]
pub fn probe_offset(fp: &Footprint, i: u32) -> [i64; 2] {
    let n = i64::from(fp.probes.max(1));
    let k = 2 * i64::from(i) + 1 - n;
    let shift = fp.probes.max(1).trailing_zeros() + 1;
    fp.axis
        .map(|a| round_shift_right(a.saturating_mul(k), shift, Rounding::HalfEven))
}

/// Footprint-assembly filter: the average of the trilinear probes of `fp` around `(u, v)`
/// (one rounding by `cfg.filter_rounding`). `traces`, when given, receives each probe's trace
/// (the first `fp.probes` entries).
#[allow(clippy::too_many_arguments)]
#[inline]
#[must_use]
pub fn footprint_filter(
    levels: &[Level],
    u: i64,
    v: i64,
    frac: u32,
    fp: &Footprint,
    lod_frac_bits: u32,
    wrap_mode: [WrapMode; 2],
    cfg: &TrilinearConfig,
    mut traces: Option<&mut [TrilinearTrace; MAX_PROBES]>,
) -> [u16; 4] {
    let n = fp.probes.clamp(1, MAX_PROBES as u32);
    let mut sum = [0i64; 4];
    for i in 0..n {
        let o = probe_offset(fp, i);
        let tr = traces.as_deref_mut().map(|t| &mut t[i as usize]);
        let r = trilinear(
            levels,
            u.saturating_add(o[0]),
            v.saturating_add(o[1]),
            frac,
            fp.lod,
            lod_frac_bits,
            wrap_mode,
            cfg,
            tr,
        );
        for c in 0..4 {
            sum[c] += i64::from(r[c]);
        }
    }
    let s = n.trailing_zeros();
    sum.map(|x| round_shift_right(x, s, cfg.filter_rounding) as u16)
}

/// Cost of one footprint-assembly lookup with `probes` probes: `probes` two-level trilinear
/// samples; with more than one probe, plus the axis selection (4 squares, 2 adds, a compare),
/// one extra LOD evaluation, the offsets (2 multiplies per probe) and the average (4 adds per
/// probe, 4 shifts). Cycles from [`datapath`].
#[must_use]
pub fn footprint_cost(
    cfg: &TrilinearConfig,
    lod_cfg: &LodConfig,
    probes: u32,
    gate_levels_per_cycle: u32,
) -> UnitCost {
    let n = probes.clamp(1, MAX_PROBES as u32);
    let mut tri = trilinear_cost(cfg, 2, gate_levels_per_cycle).times(n);
    if n > 1 {
        let l = lod_cost(lod_cfg, gate_levels_per_cycle);
        tri = tri.plus(UnitCost {
            ops: 7 + l.ops + 2 * n + 4 * n + 4,
            cycles: 0,
            texels: 0,
        });
    }
    tri.cycles = datapath(cfg, lod_cfg, n).latency(gate_levels_per_cycle);
    tri
}

/// Footprint assembly with `probes` probes: the probes' two-level trilinear samples in series
/// (one filter unit); with more than one probe first the second LOD evaluation and one stage
/// for the axis selection (compare of the squared lengths, select), the probe offsets (two
/// multiplies per probe, side by side) and the average (an adder tree of `log2 probes` levels
/// per channel).
#[must_use]
pub fn datapath(cfg: &TrilinearConfig, lod_cfg: &LodConfig, probes: u32) -> Datapath {
    let n = probes.clamp(1, MAX_PROBES as u32);
    let tri = crate::trilinear::datapath(cfg, 2).times(n);
    if n == 1 {
        return tri;
    }
    let sq = 2 * crate::lod::DERIV_BITS + 1;
    let t = cfg.texel_bits;
    let mut avg = Stage::new("axis select, offsets, average")
        .then(Component::Comparator { width: sq })
        .then(Component::Mux {
            width: 2 * crate::lod::DERIV_BITS,
            inputs: 2,
        })
        .then_n(
            2 * n,
            Component::Multiplier {
                a: crate::lod::DERIV_BITS,
                b: ceil_log2(n) + 1,
            },
        );
    for level in 1..=ceil_log2(n) {
        avg = avg.then_n(4 * (n >> level), Component::Adder { width: t + level });
    }
    crate::lod::datapath(lod_cfg).stage(avg).then(tri)
}
