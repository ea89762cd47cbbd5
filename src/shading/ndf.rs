//! NDF mapping, host side and float twin (Olano and North 1997, "Normal Distribution Mapping",
//! sections 5-6; background Fournier 1992, NDFs normalized over the sphere, his eq. 1):
//! moment maps from a normal map, their encoding into three RGB unorm MIP chains (plus the
//! normalization map), the float twin of `hw_model::ndf`, the exact numerical normalization and
//! the supersampled ground truth.
//!
//! Per finest texel with unit normal `n` and base shininess `s` the moments are those of the
//! 3D Gaussian `N(n, sigma0^2 I)` with `sigma0^2 = 1/s`: `mu = n`, `E[x x^T] = n n^T + I/s`.
//! Restricted to the sphere and normalized exactly this base lobe is the von Mises-Fisher
//! density `kappa e^(kappa (h.n - 1)) / (2 pi (1 - e^(-2 kappa)))` with `kappa = s` (since
//! `|h - n|^2 = 2 - 2 h.n`), which behaves like `cos^s` near the peak: [`base_lobe`].
//! MIP levels average the nine numbers (box filter of `crate::maps`), which is exact for
//! moments (paper: mixture mean and second moments combine linearly). The paper prints the
//! mixture covariance as `EX^2 - mu^T mu`; the covariance is `E[x x^T] - mu mu^T` (outer
//! product), as used here and tested in `tests/shading/ndf_maps.rs`.
//!
//! Encoding (`k` = `moment_scale_bits`, all channels unorm `moment_bits`): map A holds
//! `(mu + 1)/2`, map B `E_ii / 2^k`, map C `1/2 + E_ij / 2^k`; the normalization map holds
//! `(1/Z) / 2^norm_exp` in channel 0 with `norm_exp = ceil(log2(s/2))` fixed by the base
//! shininess ([`norm_exp_for`]: a bound on the largest `1/Z` of any chain of that shininess,
//! not the chain's own maximum, so the plan knows it before the maps are built). For a single lobe `E_ii = n_i^2 + 1/s <= 1 + 1/s` and
//! `|E_ij| = |n_i n_j| <= 1/2`, so `k = 1` covers every shininess >= 1 (values above are
//! clamped and counted in [`NdfMaps::clamped`]).

use crate::error::{Error, Result};
use crate::maps::{chain_sizes, quantize_chain, quantize_unorm, FixedMipChain, MipChain, MipLevel};
use glam::{DMat3, DVec3};
use hw_model::fixed::SatCounter;
use hw_model::ndf::{NdfConfig, NdfDensity, NdfNorm, NdfTexels, NdfUnit, NDF_FRAC};
use std::f64::consts::PI;

/// The nine moments of one texel: mean and `[Exx, Eyy, Ezz, Exy, Exz, Eyz]`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Moments {
    pub mu: DVec3,
    pub e: [f64; 6],
}

impl Moments {
    /// The base lobe of a unit normal `n` at shininess `s`: `mu = n`, `E = n n^T + I/s`.
    #[must_use]
    pub fn from_normal(n: DVec3, shininess: f64) -> Self {
        let v = 1.0 / shininess;
        Self {
            mu: n,
            e: [
                n.x * n.x + v,
                n.y * n.y + v,
                n.z * n.z + v,
                n.x * n.y,
                n.x * n.z,
                n.y * n.z,
            ],
        }
    }

    /// `Sigma = E - mu mu^T`, symmetric order.
    #[must_use]
    pub fn covariance(&self) -> [f64; 6] {
        let m = self.mu;
        [
            self.e[0] - m.x * m.x,
            self.e[1] - m.y * m.y,
            self.e[2] - m.z * m.z,
            self.e[3] - m.x * m.y,
            self.e[4] - m.x * m.z,
            self.e[5] - m.y * m.z,
        ]
    }
}

/// Symmetric order to a matrix.
#[must_use]
pub fn sym(s: &[f64; 6]) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(s[0], s[3], s[4]),
        DVec3::new(s[3], s[1], s[5]),
        DVec3::new(s[4], s[5], s[2]),
    )
}

/// Moment pyramid (f64) and the encoded unorm chains.
#[derive(Clone, Debug)]
pub struct NdfMaps {
    /// Float moments per level (`crate::maps` down-filter convention), level 0 finest.
    pub levels: Vec<(u32, u32, Vec<Moments>)>,
    /// The encoded float chains (channels in 0..1): A, B, C, normalization.
    pub float: [MipChain; 4],
    /// Maps A (mean), B (diagonal), C (off-diagonal), D (normalization, channel 0).
    pub mean: FixedMipChain,
    pub diag: FixedMipChain,
    pub off: FixedMipChain,
    pub norm: FixedMipChain,
    /// Float `1/Z` per level and texel (the normalization map before encoding).
    pub inv_z: Vec<Vec<f64>>,
    /// `1/Z = channel * 2^norm_exp`.
    pub norm_exp: u32,
    /// Channel values outside `[0, 1]` before quantization (clamped).
    pub clamped: u64,
}

fn downsample_moments(w: u32, h: u32, src: &[Moments]) -> (u32, u32, Vec<Moments>) {
    let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
    let par = |i: u32, n: u32, cn: u32| -> (u32, u32) {
        if n == 1 {
            (0, 1)
        } else {
            (2 * i, if i + 1 == cn && n % 2 == 1 { 3 } else { 2 })
        }
    };
    let mut out = Vec::with_capacity((nw * nh) as usize);
    for y in 0..nh {
        let (y0, cy) = par(y, h, nh);
        for x in 0..nw {
            let (x0, cx) = par(x, w, nw);
            let mut acc = Moments::default();
            for py in y0..y0 + cy {
                for px in x0..x0 + cx {
                    let t = &src[(py * w + px) as usize];
                    acc.mu += t.mu;
                    for k in 0..6 {
                        acc.e[k] += t.e[k];
                    }
                }
            }
            let inv = 1.0 / f64::from(cx * cy);
            acc.mu *= inv;
            acc.e = acc.e.map(|v| v * inv);
            out.push(acc);
        }
    }
    (nw, nh, out)
}

/// Encodes one texel into the three channel triples (unclamped).
#[must_use]
pub fn encode_texel(m: &Moments, scale_bits: u32) -> [[f64; 3]; 3] {
    let r = f64::from(1u32 << scale_bits);
    [
        [
            0.5 * (m.mu.x + 1.0),
            0.5 * (m.mu.y + 1.0),
            0.5 * (m.mu.z + 1.0),
        ],
        [m.e[0] / r, m.e[1] / r, m.e[2] / r],
        [0.5 + m.e[3] / r, 0.5 + m.e[4] / r, 0.5 + m.e[5] / r],
    ]
}

/// Exact decode of unorm channels (what the fixed unit approximates to 2^-32).
#[must_use]
pub fn decode_texels(t: &NdfTexels, cfg: &NdfConfig) -> Moments {
    let den = f64::from((1u32 << cfg.moment_bits) - 1);
    let r = f64::from(1u32 << cfg.moment_scale_bits);
    let c = |q: u16| f64::from(q) / den;
    Moments {
        mu: DVec3::new(
            2.0 * c(t.mean[0]) - 1.0,
            2.0 * c(t.mean[1]) - 1.0,
            2.0 * c(t.mean[2]) - 1.0,
        ),
        e: [
            r * c(t.diag[0]),
            r * c(t.diag[1]),
            r * c(t.diag[2]),
            r * (c(t.off[0]) - 0.5),
            r * (c(t.off[1]) - 0.5),
            r * (c(t.off[2]) - 0.5),
        ],
    }
}

/// Builds the moment pyramid and encoded chains from a unit normal map (`w x h`, row-major) at
/// base shininess `shininess`; the normalization map integrates `cfg`'s density.
pub fn build_ndf_maps(
    normals: &[DVec3],
    w: u32,
    h: u32,
    shininess: f64,
    cfg: &NdfConfig,
) -> Result<NdfMaps> {
    cfg.validate()?;
    if w == 0 || h == 0 || normals.len() != (w as usize) * (h as usize) {
        return Err(Error::field(
            "normals",
            "size does not match width x height",
        ));
    }
    if !(shininess.is_finite() && shininess >= 1.0) {
        return Err(Error::field("shininess", "must be finite and >= 1"));
    }
    let mut levels = vec![(
        w,
        h,
        normals
            .iter()
            .map(|n| {
                let n = if n.is_finite() && n.length() > 0.0 {
                    n.normalize()
                } else {
                    DVec3::Z
                };
                Moments::from_normal(n, shininess)
            })
            .collect::<Vec<_>>(),
    )];
    for _ in 1..chain_sizes(w, h).len() {
        let (lw, lh, t) = levels
            .last()
            .map(|l| (l.0, l.1, &l.2))
            .unwrap_or((1, 1, &levels[0].2));
        let next = downsample_moments(lw, lh, t);
        levels.push(next);
    }
    let mut clamped = 0u64;
    let mut chains: [Vec<MipLevel>; 3] = [Vec::new(), Vec::new(), Vec::new()];
    let mut inv_z = Vec::with_capacity(levels.len());
    for (lw, lh, t) in &levels {
        let mut tex: [Vec<[f32; 4]>; 3] = [Vec::new(), Vec::new(), Vec::new()];
        let mut iz = Vec::with_capacity(t.len());
        for m in t {
            let enc = encode_texel(m, cfg.moment_scale_bits);
            for (k, triple) in enc.iter().enumerate() {
                let mut px = [0.0f32; 4];
                for c in 0..3 {
                    let v = triple[c];
                    if !(0.0..=1.0).contains(&v) {
                        clamped += 1;
                    }
                    px[c] = v.clamp(0.0, 1.0) as f32;
                }
                tex[k].push(px);
            }
            if cfg.ndf_norm == NdfNorm::Map {
                let (mu, s) = regularize_float(m, cfg);
                iz.push(1.0 / sphere_integral(mu, &s, cfg));
            } else {
                iz.push(0.0);
            }
        }
        for k in 0..3 {
            chains[k].push(MipLevel {
                width: *lw,
                height: *lh,
                texels: std::mem::take(&mut tex[k]),
            });
        }
        inv_z.push(iz);
    }
    let norm_exp = norm_exp_for(shininess);
    let scale = f64::from(norm_exp).exp2();
    for v in inv_z.iter().flatten() {
        if *v > scale {
            clamped += 1;
        }
    }
    let norm_chain = MipChain {
        levels: levels
            .iter()
            .zip(&inv_z)
            .map(|((lw, lh, _), iz)| MipLevel {
                width: *lw,
                height: *lh,
                texels: iz
                    .iter()
                    .map(|v| [(v / scale).clamp(0.0, 1.0) as f32, 0.0, 0.0, 0.0])
                    .collect(),
            })
            .collect(),
    };
    let [a, b, c] = chains.map(|levels| MipChain { levels });
    // Stored formats: three moments per map, the normalization map its one channel.
    let q = |ch: &MipChain, channels: u32| {
        let f = quantize_chain(ch, cfg.moment_bits);
        let bits = f.texel_bits;
        f.stored_as(channels, bits)
    };
    Ok(NdfMaps {
        levels,
        mean: q(&a, 3),
        diag: q(&b, 3),
        off: q(&c, 3),
        norm: q(&norm_chain, 1),
        float: [a, b, c, norm_chain],
        inv_z,
        norm_exp,
        clamped,
    })
}

/// Power-of-two scale of the normalization map for base shininess `s`: `1/Z` is at most
/// about `s (m+1) / (2 pi m)` (the sharpest texel is a single base lobe, whose projected 2D
/// Pearson or Gaussian has that peak; mixtures only widen it), so `2^ceil(log2(s/2))` covers it
/// with margin (`s/2 >= 1.1 s/(2 pi) (m+1)/m` for m >= 1). Larger values are clamped (counted).
#[must_use]
pub fn norm_exp_for(shininess: f64) -> u32 {
    (0.5 * shininess.max(2.0)).log2().ceil().clamp(0.0, 40.0) as u32
}

/// Float twin of step 2 of `hw_model::ndf`: minimum variance on the diagonal; off-diagonals
/// dropped when a leading minor is not positive. Returns `(mu, Sigma)`.
#[must_use]
pub fn regularize_float(m: &Moments, cfg: &NdfConfig) -> (DVec3, [f64; 6]) {
    (m.mu, regularize_sigma(&m.covariance(), cfg).0)
}

/// Regularizes `Sigma` (minimum variance `2^-cfg.min_variance_bits()` on the diagonal); the
/// flag says the off-diagonals were dropped.
#[must_use]
pub fn regularize_sigma(s: &[f64; 6], cfg: &NdfConfig) -> ([f64; 6], bool) {
    let vmin = (-f64::from(cfg.min_variance_bits())).exp2();
    let mut r = *s;
    for v in r.iter_mut().take(3) {
        *v = v.max(vmin);
    }
    let m2 = r[0] * r[1] - r[3] * r[3];
    let det = sym(&r).determinant();
    if m2 <= 0.0 || det <= 0.0 || !det.is_finite() {
        r[3] = 0.0;
        r[4] = 0.0;
        r[5] = 0.0;
        return (r, true);
    }
    (r, false)
}

/// `g(t)` of the configured density (exact).
#[must_use]
pub fn density(t: f64, cfg: &NdfConfig) -> f64 {
    match cfg.ndf_density {
        NdfDensity::Gauss => (-0.5 * t).exp(),
        NdfDensity::Pearson => {
            let m = f64::from(cfg.pearson_m);
            // (1 - t/(2m))^m -> exp(-t/2). The paper's printed `2^m` denominator gives
            // (1 - t/2^m)^m = exp(m ln(1 - t/2^m)) ~ exp(-t m / 2^m) instead (ln(1 - x) ~ -x
            // for the small x = t/2^m): exp(-t/32) for m = 8 (tested in tests/units/ndf_unit.rs).
            let b = 1.0 - t / (2.0 * m);
            if b <= 0.0 {
                0.0
            } else {
                b.powi(cfg.pearson_m as i32)
            }
        }
    }
}

/// Mahalanobis distance `v^T S^-1 v` (exact inverse).
#[must_use]
pub fn mahalanobis(s: &[f64; 6], v: DVec3) -> f64 {
    let m = sym(s);
    let det = m.determinant();
    if det <= 0.0 || !det.is_finite() {
        return f64::from(1u32 << hw_model::ndf::DMAX_INT_BITS);
    }
    let d = v.dot(m.inverse() * v);
    d.clamp(0.0, f64::from(1u32 << hw_model::ndf::DMAX_INT_BITS))
}

/// `Z = integral over the unit sphere of g(d(x))` by product quadrature around the mean
/// direction: 8-point Gauss-Legendre panels in theta of geometrically growing width (first
/// width a quarter of the lobe's angular spread), 96-point trapezoid in phi.
#[must_use]
pub fn sphere_integral(mu: DVec3, s: &[f64; 6], cfg: &NdfConfig) -> f64 {
    const GL_X: [f64; 4] = [
        0.183_434_642_495_649_8,
        0.525_532_409_916_329,
        0.796_666_477_413_626_7,
        0.960_289_856_497_536_3,
    ];
    const GL_W: [f64; 4] = [
        0.362_683_783_378_362,
        0.313_706_645_877_887_3,
        0.222_381_034_453_374_5,
        0.101_228_536_290_376_3,
    ];
    const NPHI: usize = 96;
    let axis = if mu.length() > 1e-6 {
        mu.normalize()
    } else {
        DVec3::Z
    };
    let t1 = axis.any_orthonormal_vector();
    let t2 = axis.cross(t1);
    let spread = (s[0] + s[1] + s[2]).max(0.0).sqrt() / mu.length().max(0.05);
    let mut width = (0.25 * spread).clamp(1e-4, 0.25);
    let det = sym(s).determinant();
    if det <= 0.0 || !det.is_finite() {
        return f64::MIN_POSITIVE;
    }
    let inv = sym(s).inverse();
    let dmax = f64::from(1u32 << hw_model::ndf::DMAX_INT_BITS);
    let mut a = 0.0;
    let mut z = 0.0;
    let dphi = 2.0 * PI / NPHI as f64;
    let mut cphi = [0.0f64; NPHI];
    let mut sphi = [0.0f64; NPHI];
    for (k, (s, c)) in sphi.iter_mut().zip(cphi.iter_mut()).enumerate() {
        (*s, *c) = ((k as f64 + 0.5) * dphi).sin_cos();
    }
    while a < PI {
        let b = (a + width).min(PI);
        let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
        for i in 0..8 {
            let (x, wgt) = if i < 4 {
                (-GL_X[i], GL_W[i])
            } else {
                (GL_X[i - 4], GL_W[i - 4])
            };
            let th = mid + half * x;
            let (st, ct) = th.sin_cos();
            let mut ring = 0.0;
            for k in 0..NPHI {
                let dir = axis * ct + (t1 * cphi[k] + t2 * sphi[k]) * st;
                let v = dir - mu;
                ring += density(v.dot(inv * v).clamp(0.0, dmax), cfg);
            }
            z += wgt * half * st * ring * dphi;
        }
        a = b;
        width *= 2.0;
    }
    z
}

/// Float twin output.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NdfFloat {
    pub d_value: f64,
    pub g: f64,
    pub dist: f64,
    /// The regularization dropped the off-diagonals.
    pub fallback: bool,
}

/// Float twin of `NdfUnit::eval` on decoded moments. `inv_z` is the (filtered) normalization
/// map value for `map`; `exact` integrates numerically here.
#[must_use]
pub fn eval_float(m: &Moments, h: DVec3, inv_z: f64, cfg: &NdfConfig) -> NdfFloat {
    if h.z <= 0.0 {
        return NdfFloat::default();
    }
    let (s, fallback) = regularize_sigma(&m.covariance(), cfg);
    let k3 = (2.0 * PI).powf(-1.5);
    match cfg.ndf_norm {
        NdfNorm::Partial | NdfNorm::Map | NdfNorm::Exact => {
            let dist = mahalanobis(&s, h - m.mu);
            let g = density(dist, cfg);
            let d_value = match cfg.ndf_norm {
                NdfNorm::Partial => g * k3 / sym(&s).determinant().sqrt(),
                NdfNorm::Map => g * inv_z,
                _ => g / sphere_integral(m.mu, &s, cfg),
            };
            NdfFloat {
                d_value,
                g,
                dist,
                fallback,
            }
        }
        NdfNorm::Projected => {
            let n = if m.mu.length_squared() > 0.0 {
                m.mu.normalize()
            } else {
                DVec3::Z
            };
            let hn = h.dot(n);
            if hn <= 0.0 {
                return NdfFloat::default();
            }
            let p = DMat3::IDENTITY - DMat3::from_cols(n * n.x, n * n.y, n * n.z);
            let sp = p * sym(&s) * p + DMat3::from_cols(n * n.x, n * n.y, n * n.z);
            let sp6 = [
                sp.x_axis.x,
                sp.y_axis.y,
                sp.z_axis.z,
                sp.y_axis.x,
                sp.z_axis.x,
                sp.z_axis.y,
            ];
            let (sp6, fb2) = regularize_sigma(&sp6, cfg);
            let dist = mahalanobis(&sp6, h - n * hn);
            let g = density(dist, cfg);
            let k2 = match cfg.ndf_density {
                NdfDensity::Gauss => 1.0 / (2.0 * PI),
                NdfDensity::Pearson => {
                    let mm = f64::from(cfg.pearson_m);
                    (mm + 1.0) / (2.0 * PI * mm)
                }
            };
            NdfFloat {
                d_value: g * k2 / sym(&sp6).determinant().sqrt(),
                g,
                dist,
                fallback: fallback || fb2,
            }
        }
    }
}

/// The base lobe (von Mises-Fisher, `kappa = shininess`), normalized over the sphere.
#[must_use]
pub fn base_lobe(h: DVec3, n: DVec3, shininess: f64) -> f64 {
    let k = shininess;
    k * (k * (h.dot(n) - 1.0)).exp() / (2.0 * PI * (1.0 - (-2.0 * k).exp()))
}

/// Sub-samples per footprint axis of [`ground_truth`] for an axis `len` texels long (after its
/// clamp to `[1, size]`) and the requested `n`: `max(n, ceil(len))`, so that every texel the
/// axis crosses gets at least one sample.
#[must_use]
pub fn truth_samples_per_axis(len: f64, n: u32) -> u32 {
    (len.ceil() as u32).max(n).max(1)
}

/// Ground truth of one pixel: the exactly normalized base lobes ([`base_lobe`]) of the finest
/// unit normals (`w x h`, nearest texel, repeat wrap) averaged over the pixel's footprint in
/// texel space, the parallelogram `c + s a + t b`, `s, t` in `[-1/2, 1/2]` (`c` the pixel's
/// texel coordinates, texel centres at `i + 0.5`; `a`, `b` the texel-space derivatives of the
/// texture coordinates along x and y: the footprint of the roughness truth,
/// `pipeline::rough`). Each axis is clamped to `[1, max(w, h)]` texels (a one-texel box
/// over the nearest-texel lobes interpolates them linearly between texel centres, as the
/// bilinear filter does with the moments; a footprint larger than the map covers all of it)
/// and sampled at the centres of [`truth_samples_per_axis`]`(len, n)` equal steps: `n x n`
/// samples at least, one per crossed texel at least. Degenerate or non-finite axes count as
/// one texel along u (a) or v (b).
#[must_use]
#[allow(clippy::too_many_arguments)]
pub fn ground_truth(
    normals: &[DVec3],
    w: u32,
    h: u32,
    shininess: f64,
    c: [f64; 2],
    axes: [[f64; 2]; 2],
    n: u32,
    hv: DVec3,
) -> f64 {
    if normals.len() != (w as usize) * (h as usize) || normals.is_empty() {
        return 0.0;
    }
    let size = f64::from(w.max(h));
    let axis = |a: [f64; 2], unit: [f64; 2]| -> ([f64; 2], u32) {
        let len = (a[0] * a[0] + a[1] * a[1]).sqrt();
        if !(len.is_finite() && len > 0.0) {
            return (unit, truth_samples_per_axis(1.0, n));
        }
        let l = len.clamp(1.0, size);
        (
            [a[0] * l / len, a[1] * l / len],
            truth_samples_per_axis(l, n),
        )
    };
    let (a, ka) = axis(axes[0], [1.0, 0.0]);
    let (b, kb) = axis(axes[1], [0.0, 1.0]);
    let k = shininess;
    let scale = k / (2.0 * PI * (1.0 - (-2.0 * k).exp()));
    let mut acc = 0.0;
    for j in 0..kb {
        let t = (f64::from(j) + 0.5) / f64::from(kb) - 0.5;
        for i in 0..ka {
            let s = (f64::from(i) + 0.5) / f64::from(ka) - 0.5;
            let u = c[0] + s * a[0] + t * b[0];
            let v = c[1] + s * a[1] + t * b[1];
            let x = (u.floor() as i64).rem_euclid(i64::from(w)) as usize;
            let y = (v.floor() as i64).rem_euclid(i64::from(h)) as usize;
            acc += (k * (hv.dot(normals[y * w as usize + x]) - 1.0)).exp();
        }
    }
    scale * acc / (f64::from(ka) * f64::from(kb))
}

/// `h` (unit) to the fixed unit's W = `NDF_FRAC` fraction bits.
#[must_use]
pub fn h_to_fixed(h: DVec3) -> [i64; 3] {
    [h.x, h.y, h.z].map(|c| crate::fixedpoint::to_raw_nearest(c, NDF_FRAC))
}

/// The fixed unit's `h` back to float (exact).
#[must_use]
pub fn h_from_fixed(h: &[i64; 3]) -> DVec3 {
    let s = (-f64::from(NDF_FRAC)).exp2();
    DVec3::new(h[0] as f64 * s, h[1] as f64 * s, h[2] as f64 * s)
}

/// A raw fixed value with `frac` fraction bits to float.
#[must_use]
pub fn raw_to_f64(x: i64, frac: u32) -> f64 {
    x as f64 * (-f64::from(frac)).exp2()
}

/// Procedural normal maps for the NDF scenes: `ripple` (concentric sine ripples), `foil`
/// (hashed random facets, crumpled-and-flattened foil), `grooves` (parallel V-grooves along
/// x: rank-deficient coarse levels), `waves` ([`WAVES`] sine waves along u, slope
/// [`wave_slope`]). `amplitude` is the largest slope.
pub fn procedural_normals(kind: &str, w: u32, h: u32, amplitude: f64) -> Result<Vec<DVec3>> {
    let mut out = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let u = (f64::from(x) + 0.5) / f64::from(w);
            let v = (f64::from(y) + 0.5) / f64::from(h);
            let (dx, dy) = match kind {
                "ripple" => {
                    let (cx, cy) = (u - 0.5, v - 0.5);
                    let r = (cx * cx + cy * cy).sqrt().max(1e-9);
                    let s = amplitude * (r * 2.0 * PI * 8.0).cos();
                    (s * cx / r, s * cy / r)
                }
                "waves" => (wave_slope(u, amplitude), 0.0),
                "grooves" => {
                    let ph = (u * 16.0).fract();
                    (if ph < 0.5 { amplitude } else { -amplitude }, 0.0)
                }
                "foil" => {
                    let mut z = u64::from(x / 2).wrapping_mul(0x9E37_79B9_7F4A_7C15)
                        ^ u64::from(y / 2).wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
                    z ^= z >> 31;
                    z = z.wrapping_mul(0xBF58_476D_1CE4_E5B9);
                    z ^= z >> 29;
                    let a = (z & 0xFFFF) as f64 / 65535.0 * 2.0 * PI;
                    let r = ((z >> 16) & 0xFFFF) as f64 / 65535.0;
                    (amplitude * r * a.cos(), amplitude * r * a.sin())
                }
                _ => {
                    return Err(Error::field(
                        "normal_map",
                        format!("unknown procedural map '{kind}'"),
                    ))
                }
            };
            out.push(DVec3::new(-dx, -dy, 1.0).normalize());
        }
    }
    Ok(out)
}

/// Sine waves across u of the `waves` normal map.
pub const WAVES: f64 = 8.0;

/// Slope `dh/du` (in the tangent frame, per unit length) of the `waves` map at `u`: the
/// tangent-space normal is `normalize(-slope, 0, 1)`.
#[must_use]
pub fn wave_slope(u: f64, amplitude: f64) -> f64 {
    amplitude * (2.0 * PI * WAVES * u).cos()
}

/// Quantizes moments into the unit's texels as the maps store them (`inv_z` into the
/// normalization channel with `norm_exp`).
#[must_use]
pub fn quantize_texel(m: &Moments, cfg: &NdfConfig, inv_z: f64, norm_exp: u32) -> NdfTexels {
    let enc = encode_texel(m, cfg.moment_scale_bits);
    let q = |v: f64| quantize_unorm(v.clamp(0.0, 1.0) as f32, cfg.moment_bits);
    let tri = |k: usize| [q(enc[k][0]), q(enc[k][1]), q(enc[k][2]), 0];
    NdfTexels {
        mean: tri(0),
        diag: tri(1),
        off: tri(2),
        norm: [q(inv_z / f64::from(norm_exp).exp2()), 0, 0, 0],
        norm_exp,
    }
}

/// Worst error of the fixed unit on one quantized base lobe of shininess `s` against the float
/// twin on the unquantized moments, relative to the true peak, over `h` at the peak and at
/// 0.5, 1 and 2 standard deviations along two axes, for five tilted normals.
#[must_use]
pub fn lobe_error(unit: &NdfUnit, s: f64) -> f64 {
    let cfg = unit.config();
    let f = cfg.ndf_frac_bits;
    let sd = s.recip().sqrt();
    let mut worst = 0.0f64;
    for n in [
        DVec3::Z,
        DVec3::new(0.3, 0.0, 1.0),
        DVec3::new(-0.4, 0.5, 1.0),
        DVec3::new(0.05, -0.7, 0.8),
        DVec3::new(0.9, 0.1, 0.6),
    ] {
        let n = n.normalize();
        let m = Moments::from_normal(n, s);
        let t1 = n.any_orthonormal_vector();
        let t2 = n.cross(t1);
        let peak = eval_float(&m, n, 0.0, cfg).d_value;
        if !(peak.is_finite() && peak > 0.0) {
            continue;
        }
        let t = quantize_texel(&m, cfg, 0.0, 0);
        for k in [0.0, 0.5, 1.0, 2.0] {
            for dir in [t1, t2] {
                let h = (n + dir * (k * sd)).normalize();
                let hf = h_to_fixed(h);
                let want = eval_float(&m, h_from_fixed(&hf), 0.0, cfg).d_value;
                let mut sat = SatCounter::default();
                let got = raw_to_f64(unit.eval(&t, &hf, &mut sat).d_value, f);
                worst = worst.max((got - want).abs() / peak);
            }
        }
    }
    worst
}

/// The smallest shininess on the grid `2^(i/4)`, `i = 0..=96`, at which [`lobe_error`] exceeds
/// `threshold` (`None`: the width holds up to `2^24`). The fixed unit's config is used as is
/// (its `ndf_norm` must be `partial` or `projected`).
#[must_use]
pub fn breaking_shininess(unit: &NdfUnit, threshold: f64) -> Option<f64> {
    (0..=96)
        .map(|i| (f64::from(i) / 4.0).exp2())
        .find(|&s| lobe_error(unit, s) > threshold)
}
