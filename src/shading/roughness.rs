//! Bump and roughness pyramids (Schilling 1997, "Antialiasing of Bump-Maps": "The roughness
//! pyramid", "Isotropic roughness representation", Appendix A), host side in float: the
//! pyramid of mean offsets and offset covariances, its D factorization and unorm encoding, the
//! float twin of `hw_model::roughness` and of its shading (the supersampled ground truth is
//! in `crate::pipeline::rough`).
//!
//! Recursive rule. The converted paper text garbles it (a sum over `n = 0..3` of `K_{l-1,n}`
//! runs into the scatter matrix with no operator between them). The form implemented, the law
//! of total covariance for the 2x2 box filter, is
//! `K_l = 1/4 sum_n K_{l-1,n} + 1/4 sum_n (f_n - f_bar)(f_n - f_bar)^T`, `f_n` the four child
//! means (the bump pyramid level `l - 1`) and `f_bar` their mean (level `l`). It is what the
//! paper says it is equivalent to: the covariance of all finest offsets under the texel
//! (`tests/shading/roughness_pyramid.rs` checks it against that direct covariance, bit-exactly for
//! dyadic offsets and within 1e-12 for random ones). For non-power-of-two sizes the parents of
//! `maps::downsample` (2 or 3 per axis, equal weights) are used, so the mean stays the bump MIP
//! and K is the covariance under the weights that MIP implies.
//!
//! Stored matrix: `K' = m (c K + s0^2 I)`, `c` the correction factor (1, or
//! [`UNIFORM_CORRECTION`] = 3 for uniformly distributed offsets: a uniform distribution of
//! half-width `w` has standard deviation `w / sqrt(3)`, so scaling K by 3 makes the ellipse
//! `x^T K^-1 x = 1` reach the edge of the distribution), `s0` the material's base roughness
//! (no texel is a mirror; `s0 = 1/sqrt(shininess)` reproduces Blinn-Phong of that shininess
//! on flat areas, since `cos^m a` has slope variance about `1/m`, when the frame's tangents
//! are an orthonormal basis of the shading normal's tangent plane: docs/ROUGHNESS.md) and
//! `m` the exponent the
//! shading uses (with exponent `m`, `cos^m a'` has slope variance `sigma^2 / m`).
//!
//! D factor: `d3 = sqrt(c)`, `d2 = b / d3` (clamped to `|d2| <= sqrt(a)`, which Cauchy-Schwarz
//! guarantees for a PSD matrix, and 0 when `c = 0`), `d1 = sqrt(max(0, a - d2^2))`; the paper
//! gives `d1 = sqrt(a - b^2/c)`, the same when `c > 0`. Then `D D^T = K` exactly in exact
//! arithmetic, also for `c -> 0` (then `b -> 0`, `d1 -> sqrt(a)`). lambda1, the largest
//! standard deviation: `sqrt((a + c)/2 + sqrt(((a - c)/2)^2 + b^2))`.
//!
//! Encoding ([`RoughnessEncoding`], range `R = 2^rough_range_exp`): channels
//! `(d1 / R, 1/2 + d2 / (2R), d3 / R, 1)`, clamped to `[0, 1]` and counted; isotropic:
//! `(lambda1 / R, 1/2, 0, 1)`. The channels are then quantized to `rough_d_bits` and widened
//! to the texel width ([`quantize_rough_chain`]: `d1`, `d3` unorm with bit replication, `d2`
//! offset-binary with zero padding, so `d2 = 0` stays exactly 0 at every width); the
//! trilinear unit filters them like any texture, and `hw_model::roughness::decode_d` decodes
//! them.

use crate::error::{Error, Result};
use crate::maps::{next_level_size, quantize_unorm, FixedLevel, FixedMipChain, MipChain, MipLevel};
use glam::DVec3;
use hw_model::roughness::{widen_d_channel, RoughVariant, D2_CHANNEL, Q_CAP_BITS};

/// Correction factor on K for uniformly distributed offsets (module doc).
pub const UNIFORM_CORRECTION: f64 = 3.0;

/// One pyramid level: per texel the mean offset `(f_u, f_v)` and the covariance `[a, b, c]`
/// (`K = [[a, b], [b, c]]`), top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct RoughLevel {
    pub width: u32,
    pub height: u32,
    pub mean: Vec<[f64; 2]>,
    pub cov: Vec<[f64; 3]>,
}

/// The bump (mean) and roughness (covariance) pyramids, level 0 = finest, last = 1x1.
#[derive(Clone, Debug, PartialEq)]
pub struct RoughPyramid {
    pub levels: Vec<RoughLevel>,
}

impl RoughPyramid {
    /// Level `l`, clamped to the last level (LOD past the coarsest level).
    #[must_use]
    pub fn level(&self, l: usize) -> &RoughLevel {
        &self.levels[l.min(self.levels.len() - 1)]
    }
}

/// Parent range of child `i` along an axis of parent size `n` (the `maps` convention).
fn parents(i: u32, n: u32, child_n: u32) -> (u32, u32) {
    if n == 1 {
        return (0, 1);
    }
    let count = if i + 1 == child_n && n % 2 == 1 { 3 } else { 2 };
    (2 * i, count)
}

/// Builds both pyramids from the finest offsets (`w * h`, top row first) with the recursive
/// rule of the module doc. Errors name the offending input.
pub fn build_rough_pyramid(offsets: &[[f32; 2]], w: u32, h: u32) -> Result<RoughPyramid> {
    if w == 0 || h == 0 || (w as usize).checked_mul(h as usize) != Some(offsets.len()) {
        return Err(Error::field(
            "bump offsets",
            format!("{} offsets for a {w}x{h} map", offsets.len()),
        ));
    }
    if let Some(i) = offsets
        .iter()
        .position(|o| !o[0].is_finite() || !o[1].is_finite())
    {
        return Err(Error::field(
            "bump offsets",
            format!("texel {i} is not finite"),
        ));
    }
    let mut levels = vec![RoughLevel {
        width: w,
        height: h,
        mean: offsets
            .iter()
            .map(|o| [f64::from(o[0]), f64::from(o[1])])
            .collect(),
        cov: vec![[0.0; 3]; offsets.len()],
    }];
    loop {
        let src = &levels[levels.len() - 1];
        let (pw, ph) = (src.width, src.height);
        if pw == 1 && ph == 1 {
            break;
        }
        let (nw, nh) = (next_level_size(pw), next_level_size(ph));
        let mut mean = Vec::with_capacity(nw as usize * nh as usize);
        let mut cov = Vec::with_capacity(nw as usize * nh as usize);
        for y in 0..nh {
            let (y0, cy) = parents(y, ph, nh);
            for x in 0..nw {
                let (x0, cx) = parents(x, pw, nw);
                let inv = 1.0 / f64::from(cx * cy);
                let idx = |px: u32, py: u32| py as usize * pw as usize + px as usize;
                let mut m = [0.0; 2];
                let mut k = [0.0; 3];
                for py in y0..y0 + cy {
                    for px in x0..x0 + cx {
                        let i = idx(px, py);
                        for (acc, v) in m.iter_mut().zip(src.mean[i]) {
                            *acc += v;
                        }
                        for (acc, v) in k.iter_mut().zip(src.cov[i]) {
                            *acc += v;
                        }
                    }
                }
                let m = m.map(|v| v * inv);
                for py in y0..y0 + cy {
                    for px in x0..x0 + cx {
                        let c = src.mean[idx(px, py)];
                        let (du, dv) = (c[0] - m[0], c[1] - m[1]);
                        k[0] += du * du;
                        k[1] += du * dv;
                        k[2] += dv * dv;
                    }
                }
                mean.push(m);
                cov.push(k.map(|v| v * inv));
            }
        }
        levels.push(RoughLevel {
            width: nw,
            height: nh,
            mean,
            cov,
        });
    }
    Ok(RoughPyramid { levels })
}

/// How the stored K' is formed from K (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughParams {
    /// Base roughness `s0` (a standard deviation in offset units).
    pub base_sigma: f64,
    /// The shading exponent `m` the stored K' is scaled for.
    pub exponent: f64,
    /// Correction factor `c` (1 or [`UNIFORM_CORRECTION`]).
    pub correction: f64,
}

impl RoughParams {
    /// Constant-exponent mode for a material of `shininess` shaded with exponent `m`.
    #[must_use]
    pub fn for_material(shininess: u32, exponent: u32, uniform: bool) -> Self {
        Self {
            base_sigma: base_sigma_for_shininess(shininess),
            exponent: f64::from(exponent.max(1)),
            correction: if uniform { UNIFORM_CORRECTION } else { 1.0 },
        }
    }

    /// `K' = m (c K + s0^2 I)`.
    #[must_use]
    pub fn stored_cov(&self, k: [f64; 3]) -> [f64; 3] {
        let s2 = self.base_sigma * self.base_sigma;
        let m = self.exponent;
        let c = self.correction;
        [m * (c * k[0] + s2), m * c * k[1], m * (c * k[2] + s2)]
    }
}

/// `1/sqrt(shininess)` (1 for shininess 0): the slope standard deviation of `cos^s`.
#[must_use]
pub fn base_sigma_for_shininess(shininess: u32) -> f64 {
    1.0 / f64::from(shininess.max(1)).sqrt()
}

/// `[d1, d2, d3]` with `D D^T = K` (module doc, with the `c -> 0` guard). Negative or
/// non-finite diagonal entries count as 0.
#[must_use]
pub fn d_factor(k: [f64; 3]) -> [f64; 3] {
    let clean = |v: f64| if v.is_finite() { v.max(0.0) } else { 0.0 };
    let (a, c) = (clean(k[0]), clean(k[2]));
    let b = if k[1].is_finite() { k[1] } else { 0.0 };
    let d3 = c.sqrt();
    let sa = a.sqrt();
    let d2 = if d3 > 0.0 {
        (b / d3).clamp(-sa, sa)
    } else {
        0.0
    };
    let d1 = (a - d2 * d2).max(0.0).sqrt();
    [d1, d2, d3]
}

/// `D D^T` as `[a, b, c]`.
#[must_use]
pub fn d_product(d: [f64; 3]) -> [f64; 3] {
    [d[0] * d[0] + d[1] * d[1], d[1] * d[2], d[2] * d[2]]
}

/// lambda1: the largest standard deviation of K (the square root of its largest eigenvalue).
#[must_use]
pub fn lambda1(k: [f64; 3]) -> f64 {
    let (a, b, c) = (k[0], k[1], k[2]);
    let h = 0.5 * (a - c);
    (0.5 * (a + c) + (h * h + b * b).sqrt()).max(0.0).sqrt()
}

/// The unorm encoding of D (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughnessEncoding {
    /// `R = 2^rough_range_exp`.
    pub range: f64,
}

impl RoughnessEncoding {
    /// `R = 2^e`, matching `hw_model::roughness::decode_d`.
    #[must_use]
    pub fn for_range_exp(e: i32) -> Self {
        Self {
            range: f64::from(e.clamp(-4, 4)).exp2(),
        }
    }

    /// Channels of `[d1, d2, d3]` and how many were clamped.
    #[must_use]
    pub fn encode(&self, d: [f64; 3]) -> ([f32; 3], u32) {
        let r = self.range;
        let raw = [d[0] / r, 0.5 + d[1] / (2.0 * r), d[2] / r];
        let mut clamped = 0;
        let ch = raw.map(|c| {
            let cl = if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) };
            clamped += u32::from(cl != c);
            cl as f32
        });
        (ch, clamped)
    }

    /// Channels of the isotropic representation `lambda1`.
    #[must_use]
    pub fn encode_isotropic(&self, lambda: f64) -> ([f32; 3], u32) {
        let c = lambda / self.range;
        let cl = if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) };
        ([cl as f32, 0.5, 0.0], u32::from(cl != c))
    }

    /// Decodes (filtered) channels into `[d1, d2, d3]`.
    #[must_use]
    pub fn decode(&self, ch: [f64; 3]) -> [f64; 3] {
        let r = self.range;
        [ch[0] * r, (ch[1] - 0.5) * 2.0 * r, ch[2] * r]
    }
}

/// The D (or lambda1) channel pyramid as a float MIP chain for the trilinear unit, from the
/// covariance pyramid. Returns the chain and the number of clamped channel values.
#[must_use]
pub fn rough_mip_chain(
    pyr: &RoughPyramid,
    params: &RoughParams,
    enc: &RoughnessEncoding,
    isotropic: bool,
) -> (MipChain, u64) {
    let mut clamped = 0u64;
    let levels = pyr
        .levels
        .iter()
        .map(|l| MipLevel {
            width: l.width,
            height: l.height,
            texels: l
                .cov
                .iter()
                .map(|&k| {
                    let ks = params.stored_cov(k);
                    let (ch, n) = if isotropic {
                        enc.encode_isotropic(lambda1(ks))
                    } else {
                        enc.encode(d_factor(ks))
                    };
                    clamped += u64::from(n);
                    [ch[0], ch[1], ch[2], 1.0]
                })
                .collect(),
        })
        .collect();
    (MipChain { levels }, clamped)
}

/// Quantizes a D channel value to its stored `d_bits` code: `d1`, `d3` (and lambda1, alpha)
/// unorm ([`quantize_unorm`]); `d2` (channel `hw_model::roughness::D2_CHANNEL`, value
/// `c = 1/2 + d2 / (2R)`) offset-binary, `2^(d-1) + round((c - 1/2) 2^d)` (ties to even, so
/// `+x` and `-x` quantize symmetrically and `d2 = 0` to the centre code exactly), clamped to
/// `[0, 2^d - 1]` (the top code is `d2 = R (1 - 2^(1-d))`); NaN gives the centre.
#[must_use]
pub fn quantize_d_channel(c: f32, channel: usize, d_bits: u32) -> u64 {
    let db = d_bits.clamp(2, 16);
    if channel != D2_CHANNEL {
        return u64::from(quantize_unorm(c, db));
    }
    let half = 1i64 << (db - 1);
    if c.is_nan() {
        return half as u64;
    }
    let off = ((f64::from(c) - 0.5) * f64::from(1u32 << db)).round_ties_even();
    (off.clamp(-(half as f64), (half - 1) as f64) as i64 + half) as u64
}

/// Quantizes D channels to `d_bits` ([`quantize_d_channel`]) and widens them to `texel_bits`
/// (`hw_model::roughness::widen_d_channel`: bit replication for the unorm channels, zero
/// padding for the offset-binary `d2`): what the trilinear unit reads. Texture memory holds
/// the codes before widening (the widening is wiring): three channels of `min(d_bits,
/// texel_bits)` bits (the isotropic map's one channel is set by its builder).
#[must_use]
pub fn quantize_rough_chain(chain: &MipChain, d_bits: u32, texel_bits: u32) -> FixedMipChain {
    let db = d_bits.clamp(2, 16);
    let tb = texel_bits.clamp(1, 16);
    FixedMipChain {
        texel_bits: tb,
        format: crate::maps::TexelFormat {
            channels: 3,
            bits: db.min(tb),
        },
        levels: chain
            .levels
            .iter()
            .map(|l| FixedLevel {
                width: l.width,
                height: l.height,
                texels: l
                    .texels
                    .iter()
                    .map(|t| {
                        let mut out = [0u16; 4];
                        for (i, (o, &c)) in out.iter_mut().zip(t).enumerate() {
                            *o = widen_d_channel(quantize_d_channel(c, i, db), i, db, tb) as u16;
                        }
                        out
                    })
                    .collect(),
            })
            .collect(),
    }
}

/// Exact float value of filtered D texels (twin of `hw_model::roughness::decode_d`).
#[must_use]
pub fn decode_d_texels(t: [u64; 3], texel_bits: u32, range_exp: i32) -> [f64; 3] {
    let bits = texel_bits.clamp(1, 16);
    let lim = 1u64 << bits;
    let scale = f64::from(range_exp.clamp(-4, 4) - bits as i32).exp2();
    let t = t.map(|x| x.min(lim) as f64);
    [
        t[0] * scale,
        2.0 * (t[1] - f64::from(1u32 << (bits - 1))) * scale,
        t[2] * scale,
    ]
}

/// Float twin of `hw_model::roughness::rough_cos`: `cos a'` from `cos a`, `d` (offset
/// coordinates) and D (`[lambda1, -, -]` for the isotropic variant), same guards.
#[must_use]
pub fn rough_cos_twin(variant: RoughVariant, cos_a: f64, d: [f64; 2], dv: [f64; 3]) -> f64 {
    let c = cos_a.clamp(0.0, 1.0);
    if variant == RoughVariant::None {
        return c;
    }
    if c <= 0.0 {
        return 0.0;
    }
    let (x, y) = (d[0].clamp(-1.0, 1.0), d[1].clamp(-1.0, 1.0));
    let dd = x * x + y * y;
    if dd <= 0.0 {
        return 1.0;
    }
    let [d1, d2, d3] = dv;
    let sq = |v: f64| v * v;
    let (n, m) = match variant {
        RoughVariant::Published => (dd, sq(d1 * x + d2 * y) + sq(d3 * y)),
        RoughVariant::Directional => (dd, sq(d1 * x) + sq(d2 * x + d3 * y)),
        RoughVariant::Mahalanobis => (sq(d3 * x - d2 * y) + sq(d1 * y), sq(d1 * d3)),
        RoughVariant::Isotropic | RoughVariant::None => (1.0, sq(d1)),
    };
    if m <= 0.0 || !m.is_finite() {
        return 0.0;
    }
    let q = if variant == RoughVariant::Mahalanobis {
        n / m
    } else {
        dd * n / m
    };
    if q.is_nan() || q >= f64::from(Q_CAP_BITS).exp2() {
        return 0.0;
    }
    c / (q + c * c).sqrt()
}

/// Float twin of `hw_model::roughness::scale_d`: `L D`, `L = diag(len_u, len_v)` (isotropic:
/// lambda1 times `max(len_u, len_v)`).
#[must_use]
pub fn scale_d_f(dv: [f64; 3], len: [f64; 2], isotropic: bool) -> [f64; 3] {
    let (lu, lv) = (len[0].max(0.0), len[1].max(0.0));
    if isotropic {
        [dv[0] * lu.max(lv), dv[1] * lu, dv[2] * lv]
    } else {
        [dv[0] * lu, dv[1] * lu, dv[2] * lv]
    }
}

/// `d = (h_t . t_u, h_t . t_v)` with `h_t = h - (n.h) n`, and `cos a = n.h` (the inputs of the
/// modified Blinn-Phong; twin of the projection in `hw_model::roughness::rough_blinn_phong`).
#[must_use]
pub fn d_and_cos(n: DVec3, h: DVec3, t_u: DVec3, t_v: DVec3) -> ([f64; 2], f64) {
    let c = n.dot(h);
    let ht = h - c * n;
    ([ht.dot(t_u), ht.dot(t_v)], c)
}

/// Float twin of `hw_model::roughness::normalize_spec`: `min(1, (e / s) / (d1 d3))`
/// (isotropic `d1^2`); 1 when `d1 d3 = 0`.
#[must_use]
pub fn normalize_factor(dv: [f64; 3], variant: RoughVariant, exponent: u32, shininess: u32) -> f64 {
    let d1 = dv[0].max(0.0);
    let d3 = if variant == RoughVariant::Isotropic {
        d1
    } else {
        dv[2].max(0.0)
    };
    let det = d1 * d3;
    if det <= 0.0 || !det.is_finite() {
        return 1.0;
    }
    (f64::from(exponent.max(1)) / f64::from(shininess.max(1)) / det).min(1.0)
}

/// Float twin of `hw_model::roughness::rough_blinn_phong` for one light: colour and `l + v = 0`.
/// `dv` is D in tangent-plane units ([`scale_d_f`]); `exponent` the mode's exponent; `norm`
/// the specular scale ([`normalize_factor`], or 1).
#[allow(clippy::too_many_arguments)]
#[must_use]
pub fn rough_blinn_phong_f(
    n: DVec3,
    l: DVec3,
    v: DVec3,
    t: [DVec3; 2],
    dv: [f64; 3],
    variant: RoughVariant,
    exponent: u32,
    norm: f64,
    colors: [[f64; 3]; 3],
) -> ([f64; 3], bool) {
    let ndl = n.dot(l).clamp(0.0, 1.0);
    let sum = l + v;
    let h_zero = sum == DVec3::ZERO;
    let spec = if h_zero || ndl == 0.0 {
        0.0
    } else {
        let h = sum.normalize();
        let (d, c) = d_and_cos(n, h, t[0], t[1]);
        crate::shading::reference::pow(rough_cos_twin(variant, c, d, dv), exponent) * norm
    };
    let [kd, ks, light] = colors;
    (
        [0, 1, 2].map(|i| (light[i] * (kd[i] * ndl + ks[i] * spec)).clamp(0.0, 1.0)),
        h_zero,
    )
}
