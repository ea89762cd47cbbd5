//! Float twin of the footprint-assembly unit (`hw_model::footprint`, Texram's anisotropic
//! filter): the same axis choice, probe placement and LOD rule in f64, and the plain average
//! of the trilinear probes of `crate::reference::trilinear_f64`.

use crate::reference::{trilinear_f64, LevelF};
use hw_model::wrap::WrapMode;

/// The footprint of one pixel in float: probes, major axis (normalized coordinates) and LOD.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FootprintF {
    pub probes: u32,
    pub axis: [f64; 2],
    pub lod: f64,
}

/// Float twin of `hw_model::footprint::footprint`: `uv` at the sample and helper samples
/// (normalized), level-0 size, `probes` (a power of two), `adaptive` (the smallest power of
/// two `N <= probes` with `|major|^2 <= N^2 |minor|^2`). The LOD is
/// `log2(max(minor, major / N))` (`N = 1`: `log2(major)`), clamped below at -32.
#[must_use]
pub fn footprint_f64(
    uv: &[[f64; 2]; 3],
    size: (u32, u32),
    probes: u32,
    adaptive: bool,
) -> FootprintF {
    let cap = probes.clamp(1, 16);
    let (w, h) = (f64::from(size.0), f64::from(size.1));
    let dx = [uv[1][0] - uv[0][0], uv[1][1] - uv[0][1]];
    let dy = [uv[2][0] - uv[0][0], uv[2][1] - uv[0][1]];
    let l2 = |d: [f64; 2]| (d[0] * w).powi(2) + (d[1] * h).powi(2);
    let (lx, ly) = (l2(dx), l2(dy));
    let (maj, lmaj, lmin) = if lx >= ly { (dx, lx, ly) } else { (dy, ly, lx) };
    let mut n = if adaptive { 1 } else { cap };
    while n < cap && lmaj > lmin * f64::from(n * n) {
        n *= 2;
    }
    let nf = f64::from(n);
    let l = if n == 1 {
        lmaj
    } else {
        (lmaj / (nf * nf)).max(lmin)
    };
    let lod = if l.is_nan() || l <= 0.0 {
        -32.0
    } else {
        (0.5 * l.log2()).max(-32.0)
    };
    FootprintF {
        probes: n,
        axis: maj,
        lod,
    }
}

/// Offset of probe `i`: `axis * (2i + 1 - N) / (2N)`.
#[must_use]
pub fn probe_offset_f64(fp: &FootprintF, i: u32) -> [f64; 2] {
    let n = f64::from(fp.probes.max(1));
    let k = (2.0 * f64::from(i) + 1.0 - n) / (2.0 * n);
    fp.axis.map(|a| a * k)
}

/// The mean of the `fp.probes` trilinear probes around `(u, v)`.
#[must_use]
pub fn footprint_filter_f64(
    levels: &[LevelF],
    u: f64,
    v: f64,
    fp: &FootprintF,
    wrap: [WrapMode; 2],
) -> [f64; 4] {
    let n = fp.probes.max(1);
    let mut sum = [0.0; 4];
    for i in 0..n {
        let o = probe_offset_f64(fp, i);
        let r = trilinear_f64(levels, u + o[0], v + o[1], fp.lod, wrap);
        for c in 0..4 {
            sum[c] += r[c];
        }
    }
    sum.map(|s| s / f64::from(n))
}
