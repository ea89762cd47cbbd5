//! Fitting multiple-surface lobes to bump-map normals, host side, in float (Fournier 1992,
//! sec. 3.2: the NDF under a texel's footprint as a sum of Phong peaks).
//!
//! Method: per texel, an EM fit of a mixture of K von Mises-Fisher lobes to the finest normals
//! under the texel (Banerjee et al. 2005, "Clustering on the unit hypersphere using von
//! Mises-Fisher distributions"; per texel as in Han et al. 2007, "Frequency domain normal map
//! filtering"), each level fitted from the finest map (lobes do not average linearly), then
//! each lobe converted to a Phong peak: a vMF lobe `alpha C(kappa) exp(kappa mu.n)` of the NDF
//! seen through the Phong specular `(n.h)^s` is, for large `kappa` and `s`,
//! `alpha kappa / (kappa + s) (mu.h)^(kappa s / (kappa + s))` (the product of two vMF
//! exponentials integrated over the sphere; `exp(k (x - 1)) ~ x^k` near the peak): amplitude
//! `c = alpha kappa / (kappa + s)`, exponent `n = kappa s / (kappa + s)`. A lobe is stored
//! as `alpha` and `n` ([`VmfLobe::to_stored`]): `alpha` weights its diffuse term and the
//! multi-lobe unit forms the specular weight `c = alpha n / s`. Fournier's own fit
//! is a non-linear least-squares one; this is the EM form, which the issue accepts.
//!
//! - Initialization (seeded, deterministic): the first centre is the normal at index
//!   `splitmix64(seed ^ texel) % N`, each next one the normal farthest from the centres so far
//!   (largest minimum angle); no more centres once every normal is within `1e-12` of one (so
//!   K never exceeds the number of distinct normals). `kappa = 10`, equal weights.
//! - EM: responsibilities in log space, `kappa` by Banerjee's approximation
//!   `rbar (3 - rbar^2) / (1 - rbar^2)` (infinite when all of a lobe's normals coincide).
//! - Convergence rule: the mean log-likelihood changes by less than `tolerance` (relative,
//!   with an absolute floor of `tolerance`) between two iterations, within `max_iterations`.
//! - Fallback (counted): a fit that does not converge, or gives a non-finite value, is replaced
//!   by one lobe from the moments (`mu` the mean normal normalized, `kappa` from its length).
//! - Residual of a texel: the RMS over probe directions (the texel's normals, at most 64 of
//!   them, and 32 fixed directions of the upper hemisphere) of the difference between the
//!   texel's mean Phong specular `mean_i (n_i.h)^s` and the fitted lobes' `sum_j c_j
//!   (mu_j.h)^(n_j)`.
//!
//! Deterministic: every texel is fitted on its own, in texel order, with its own seed, so the
//! result is bit-identical at any thread count.

use glam::DVec3;
use rayon::prelude::*;
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// Most lobes per texel.
pub const MAX_FIT_LOBES: usize = 8;

/// Fitting parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FitConfig {
    /// Lobes per texel (K), 1..=8.
    pub lobes: usize,
    /// EM iterations at most.
    pub max_iterations: u32,
    /// Convergence threshold of the mean log-likelihood change.
    pub tolerance: f64,
    /// Seed of the initialization.
    pub seed: u64,
    /// The material's Phong exponent `s` (the conversion to Phong peaks and the residual).
    pub shininess: f64,
}

impl Default for FitConfig {
    fn default() -> Self {
        Self {
            lobes: 2,
            max_iterations: 200,
            tolerance: 1e-6,
            seed: 0x5EED_F0E5,
            shininess: 32.0,
        }
    }
}

impl FitConfig {
    /// Checks the parameters; the error names the field.
    pub fn validate(&self) -> crate::Result<()> {
        if !(1..=MAX_FIT_LOBES).contains(&self.lobes) {
            return Err(crate::Error::field(
                "fournier_lobes",
                format!("{} is out of range 1..={MAX_FIT_LOBES}", self.lobes),
            ));
        }
        if !(self.shininess.is_finite() && self.shininess > 0.0) {
            return Err(crate::Error::field(
                "shininess",
                format!("{} is not a positive exponent", self.shininess),
            ));
        }
        if !(self.tolerance.is_finite() && self.tolerance >= 0.0) {
            return Err(crate::Error::field(
                "tolerance",
                format!("{} is not a finite non-negative number", self.tolerance),
            ));
        }
        Ok(())
    }
}

/// One von Mises-Fisher lobe of a texel's NDF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VmfLobe {
    /// Unit mean direction (tangent space, `z` the geometric normal).
    pub mu: DVec3,
    /// Concentration (infinite for a lobe of coincident normals).
    pub kappa: f64,
    /// Mixture weight (the lobes' weights sum to 1).
    pub weight: f64,
}

/// One Phong peak `c (N.h)^n` (Fournier eq. 11).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhongLobe {
    pub direction: DVec3,
    pub amplitude: f64,
    pub exponent: f64,
}

impl VmfLobe {
    /// The Phong peak of this lobe under the specular exponent `s` (module doc).
    #[must_use]
    pub fn to_phong(&self, s: f64) -> PhongLobe {
        let (amplitude, exponent) = if self.kappa.is_finite() {
            (
                self.weight * self.kappa / (self.kappa + s),
                self.kappa * s / (self.kappa + s),
            )
        } else {
            (self.weight, s)
        };
        PhongLobe {
            direction: self.mu,
            amplitude,
            exponent,
        }
    }

    /// The stored form under the specular exponent `s`: direction, the mixture weight `alpha`
    /// as amplitude (the diffuse weight) and the Phong exponent `n` of [`Self::to_phong`]; the
    /// specular weight `alpha kappa / (kappa + s)` is `alpha n / s`, which the multi-lobe unit
    /// forms from the stored `alpha` and `n` (`hw_model::multi_lobe`, fitted lobes).
    #[must_use]
    pub fn to_stored(&self, s: f64) -> PhongLobe {
        PhongLobe {
            amplitude: self.weight,
            ..self.to_phong(s)
        }
    }
}

/// The fit of one texel.
#[derive(Clone, Debug, PartialEq)]
pub struct TexelFit {
    /// At most K lobes (fewer when the texel has fewer distinct normals).
    pub lobes: Vec<VmfLobe>,
    /// EM iterations run.
    pub iterations: u32,
    /// The EM fit failed and `lobes` is the one-lobe moments fallback.
    pub fallback: bool,
    /// RMS shading residual (module doc).
    pub residual: f64,
}

/// The fits of one MIP level.
#[derive(Clone, Debug, PartialEq)]
pub struct LevelFit {
    pub level: u32,
    pub width: u32,
    pub height: u32,
    /// Row-major texel fits.
    pub texels: Vec<TexelFit>,
    /// Texels whose fit fell back to the moments lobe.
    pub fallbacks: u64,
    /// Mean of the texels' residuals.
    pub mean_residual: f64,
    /// Wall time of the level's fit (seconds; not part of the bit-identical result).
    pub seconds: f64,
}

/// `log C(kappa)` of the vMF density on the 2-sphere, `C = kappa / (4 pi sinh kappa)`.
fn log_norm(kappa: f64) -> f64 {
    if kappa < 1e-6 {
        -(4.0 * std::f64::consts::PI).ln()
    } else {
        // log sinh k = k + log(1 - e^-2k) - log 2
        kappa.ln()
            - (4.0 * std::f64::consts::PI).ln()
            - (kappa + (-(-2.0 * kappa).exp()).ln_1p() - std::f64::consts::LN_2)
    }
}

/// Banerjee's concentration from the mean resultant length.
fn kappa_of(rbar: f64) -> f64 {
    if rbar >= 1.0 - 1e-12 {
        f64::INFINITY
    } else {
        let r = rbar.max(0.0);
        r * (3.0 - r * r) / (1.0 - r * r)
    }
}

/// The one-lobe fit from the moments (the fallback, and the K = 1 seed).
#[must_use]
pub fn moments_lobe(normals: &[DVec3]) -> VmfLobe {
    let sum: DVec3 = normals.iter().copied().sum();
    let len = sum.length();
    let n = normals.len().max(1) as f64;
    if len > 0.0 && len.is_finite() {
        VmfLobe {
            mu: sum / len,
            kappa: kappa_of(len / n),
            weight: 1.0,
        }
    } else {
        VmfLobe {
            mu: DVec3::Z,
            kappa: 0.0,
            weight: 1.0,
        }
    }
}

const SAME: f64 = 1e-12;

/// Deterministic centres: a seeded first normal, then farthest points.
fn initial_centres(normals: &[DVec3], k: usize, seed: u64) -> Vec<DVec3> {
    let mut c =
        vec![normals[(crate::rng::SplitMix64(seed).next_u64() % normals.len() as u64) as usize]];
    while c.len() < k {
        let (best, cos) = normals
            .iter()
            .enumerate()
            .map(|(i, n)| (i, c.iter().map(|m| m.dot(*n)).fold(f64::MIN, f64::max)))
            .fold((0, f64::MAX), |a, b| if b.1 < a.1 { b } else { a });
        if cos >= 1.0 - SAME {
            break;
        }
        c.push(normals[best]);
    }
    c
}

/// EM of `k` lobes; `None` when it does not converge or goes non-finite.
fn em(normals: &[DVec3], k: usize, cfg: &FitConfig, seed: u64) -> Option<(Vec<VmfLobe>, u32)> {
    let centres = initial_centres(normals, k, seed);
    let k = centres.len();
    let mut lobes: Vec<VmfLobe> = centres
        .into_iter()
        .map(|mu| VmfLobe {
            mu,
            kappa: 10.0,
            weight: 1.0 / k as f64,
        })
        .collect();
    let n = normals.len() as f64;
    let mut last = f64::NEG_INFINITY;
    let mut resp = vec![0.0f64; normals.len() * k];
    for it in 1..=cfg.max_iterations {
        // E step (log space; an infinite kappa is a point mass: normals on it take it all).
        let mut ll = 0.0;
        for (i, x) in normals.iter().enumerate() {
            let r = &mut resp[i * k..(i + 1) * k];
            let mut top = f64::NEG_INFINITY;
            for (j, l) in lobes.iter().enumerate() {
                r[j] = if l.weight <= 0.0 {
                    f64::NEG_INFINITY
                } else if l.kappa.is_finite() {
                    l.weight.ln() + log_norm(l.kappa) + l.kappa * (l.mu.dot(*x) - 1.0) + l.kappa
                } else if l.mu.dot(*x) >= 1.0 - SAME {
                    f64::MAX.ln()
                } else {
                    f64::NEG_INFINITY
                };
                top = top.max(r[j]);
            }
            if top == f64::NEG_INFINITY {
                // A normal no lobe can explain: the fit failed.
                return None;
            }
            let s: f64 = r.iter().map(|v| (v - top).exp()).sum();
            for v in r.iter_mut() {
                *v = (*v - top).exp() / s;
            }
            ll += top + s.ln();
        }
        ll /= n;
        // M step.
        for (j, l) in lobes.iter_mut().enumerate() {
            let mut w = 0.0;
            let mut sum = DVec3::ZERO;
            for (i, x) in normals.iter().enumerate() {
                let r = resp[i * k + j];
                w += r;
                sum += r * *x;
            }
            let len = sum.length();
            l.weight = w / n;
            if w > 0.0 && len > 0.0 {
                l.mu = sum / len;
                l.kappa = kappa_of(len / w);
            }
        }
        if !ll.is_finite() {
            return None;
        }
        if (ll - last).abs() <= cfg.tolerance * ll.abs().max(1.0) {
            lobes.retain(|l| l.weight > 0.0);
            return lobes
                .iter()
                .all(|l| l.mu.is_finite() && l.weight.is_finite() && !l.kappa.is_nan())
                .then_some((lobes, it));
        }
        last = ll;
    }
    None
}

/// 32 fixed directions of the upper hemisphere (a Fibonacci spiral).
fn hemisphere_probes() -> [DVec3; 32] {
    std::array::from_fn(|i| {
        let z = 1.0 - (i as f64 + 0.5) / 32.0;
        let r = (1.0 - z * z).sqrt();
        let phi = i as f64 * 2.399_963_229_728_653;
        DVec3::new(r * phi.cos(), r * phi.sin(), z)
    })
}

/// RMS difference of the mean Phong specular of `normals` and of `lobes` (module doc).
#[must_use]
pub fn residual(normals: &[DVec3], lobes: &[VmfLobe], s: f64) -> f64 {
    let step = normals.len().div_ceil(64).max(1);
    let probes: Vec<DVec3> = normals
        .iter()
        .step_by(step)
        .copied()
        .chain(hemisphere_probes())
        .collect();
    let peaks: Vec<PhongLobe> = lobes.iter().map(|l| l.to_phong(s)).collect();
    let n = normals.len() as f64;
    let sq: f64 = probes
        .iter()
        .map(|h| {
            let want: f64 = normals
                .iter()
                .map(|x| x.dot(*h).max(0.0).powf(s))
                .sum::<f64>()
                / n;
            let got: f64 = peaks
                .iter()
                .map(|p| p.amplitude * p.direction.dot(*h).max(0.0).powf(p.exponent))
                .sum();
            (want - got).powi(2)
        })
        .sum();
    (sq / probes.len() as f64).sqrt()
}

/// Fits the normals of one texel (`texel` seeds the initialization).
#[must_use]
pub fn fit_texel(normals: &[DVec3], cfg: &FitConfig, texel: u64) -> TexelFit {
    if normals.is_empty() {
        return TexelFit {
            lobes: vec![moments_lobe(normals)],
            iterations: 0,
            fallback: true,
            residual: 0.0,
        };
    }
    let k = cfg.lobes.clamp(1, MAX_FIT_LOBES);
    let (lobes, iterations, fallback) = match em(normals, k, cfg, cfg.seed ^ texel) {
        Some((l, it)) => (l, it, false),
        None => (vec![moments_lobe(normals)], cfg.max_iterations, true),
    };
    TexelFit {
        residual: residual(normals, &lobes, cfg.shininess),
        lobes,
        iterations,
        fallback,
    }
}

/// The finest normals under texel `(x, y)` of level `level` of a `w x h` map (a footprint of
/// `2^level` texels per axis, clipped to the map).
fn footprint(normals: &[DVec3], w: u32, h: u32, level: u32, x: u32, y: u32) -> Vec<DVec3> {
    let f = 1u32 << level;
    let (x0, y0) = (x * f, y * f);
    let (x1, y1) = ((x0 + f).min(w), (y0 + f).min(h));
    (y0..y1)
        .flat_map(|yy| (x0..x1).map(move |xx| normals[(yy * w + xx) as usize]))
        .collect()
}

/// Fits every level of the MIP pyramid of a `w x h` normal map (unit tangent-space normals,
/// row-major), each level from the finest normals; level `l` has `ceil(w / 2^l) x ceil(h /
/// 2^l)` texels, down to 1 x 1.
pub fn fit_pyramid(
    normals: &[DVec3],
    w: u32,
    h: u32,
    cfg: &FitConfig,
) -> crate::Result<Vec<LevelFit>> {
    cfg.validate()?;
    if w == 0 || h == 0 || normals.len() != (w as usize) * (h as usize) {
        return Err(crate::Error::msg(format!(
            "normal map of {} normals is not {w} x {h}",
            normals.len()
        )));
    }
    if normals.iter().any(|n| !n.is_finite()) {
        return Err(crate::Error::msg("normal map has a non-finite normal"));
    }
    let mut levels = Vec::new();
    let mut level = 0u32;
    loop {
        let f = 1u32 << level;
        let (lw, lh) = (w.div_ceil(f), h.div_ceil(f));
        let start = Instant::now();
        let texels: Vec<TexelFit> = (0..lw * lh)
            .into_par_iter()
            .map(|t| {
                let (x, y) = (t % lw, t / lw);
                let under = footprint(normals, w, h, level, x, y);
                fit_texel(&under, cfg, u64::from(level) << 32 | u64::from(t))
            })
            .collect();
        let fallbacks = texels.iter().filter(|t| t.fallback).count() as u64;
        let mean_residual = texels.iter().map(|t| t.residual).sum::<f64>() / texels.len() as f64;
        levels.push(LevelFit {
            level,
            width: lw,
            height: lh,
            texels,
            fallbacks,
            mean_residual,
            seconds: start.elapsed().as_secs_f64(),
        });
        if lw == 1 && lh == 1 {
            break;
        }
        level += 1;
    }
    Ok(levels)
}

/// One cached fit: its key (the map's normals bit for bit, its size, every fit parameter) and
/// the levels.
struct CachedFit {
    normals: Vec<[u64; 3]>,
    size: (u32, u32),
    cfg: [u64; 5],
    levels: Arc<Vec<LevelFit>>,
    bytes: u64,
}

/// The fits kept in this process, oldest first, and their bytes.
static FIT_CACHE: Mutex<(Vec<CachedFit>, u64)> = Mutex::new((Vec::new(), 0));

/// The fit parameters as bits (the cache key's part).
fn cfg_key(cfg: &FitConfig) -> [u64; 5] {
    [
        cfg.lobes as u64,
        u64::from(cfg.max_iterations),
        cfg.tolerance.to_bits(),
        cfg.seed,
        cfg.shininess.to_bits(),
    ]
}

/// Bytes held by a cached fit of `normals` (its key and its levels' texel fits and lobes).
fn fit_bytes(normals: usize, levels: &[LevelFit]) -> u64 {
    let texels: usize = levels
        .iter()
        .flat_map(|l| &l.texels)
        .map(|t| {
            std::mem::size_of::<TexelFit>() + t.lobes.capacity() * std::mem::size_of::<VmfLobe>()
        })
        .sum();
    (normals * std::mem::size_of::<[u64; 3]>() + std::mem::size_of_val(levels) + texels) as u64
}

/// The fit cache's capacity: an eighth of the run's memory limit (`crate::budget`); a fit
/// larger than that is not kept.
#[must_use]
pub fn fit_cache_capacity() -> u64 {
    crate::budget::max_memory() / 8
}

/// [`fit_pyramid`] through an in-process cache: a fit of the same normals (bit for bit), size
/// and parameters is returned from the cache (`true`) instead of being redone, so a sweep that
/// varies no fit input fits once. The fit is deterministic, so a cached result equals a new
/// one (but for the levels' wall times, those of the first fit). The cache holds at most
/// [`fit_cache_capacity`] bytes, dropping the oldest fits first.
pub fn fit_pyramid_cached(
    normals: &[DVec3],
    w: u32,
    h: u32,
    cfg: &FitConfig,
) -> crate::Result<(Arc<Vec<LevelFit>>, bool)> {
    let key: Vec<[u64; 3]> = normals
        .iter()
        .map(|n| [n.x.to_bits(), n.y.to_bits(), n.z.to_bits()])
        .collect();
    let ck = cfg_key(cfg);
    {
        let cache = FIT_CACHE
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        if let Some(c) = cache
            .0
            .iter()
            .find(|c| c.size == (w, h) && c.cfg == ck && c.normals == key)
        {
            return Ok((Arc::clone(&c.levels), true));
        }
    }
    let levels = Arc::new(fit_pyramid(normals, w, h, cfg)?);
    let bytes = fit_bytes(key.len(), &levels);
    let cap = fit_cache_capacity();
    if bytes <= cap {
        let mut cache = FIT_CACHE
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let (entries, held) = &mut *cache;
        while *held + bytes > cap && !entries.is_empty() {
            *held -= entries.remove(0).bytes;
        }
        if !entries
            .iter()
            .any(|c| c.size == (w, h) && c.cfg == ck && c.normals == key)
        {
            entries.push(CachedFit {
                normals: key,
                size: (w, h),
                cfg: ck,
                levels: Arc::clone(&levels),
                bytes,
            });
            *held += bytes;
        }
    }
    Ok((levels, false))
}

/// The stored lobes of a texel fit in the multi-lobe unit's formats (`hw_model::multi_lobe`):
/// per lobe ([`VmfLobe::to_stored`]) its slopes `(x / z, y / z)` in the slope format, its
/// weight `alpha` in the amplitude format and its exponent rounded to an integer, saturating at `2^lobe_exp_bits - 1` (every
/// saturation counted in `sat`); `s` is the material's Phong exponent of the conversion.
#[must_use]
pub fn quantize_fit(
    fit: &TexelFit,
    s: f64,
    cfg: &hw_model::multi_lobe::MultiLobeConfig,
    sat: &mut hw_model::SatCounter,
) -> Vec<hw_model::multi_lobe::Lobe> {
    use crate::fixedpoint::to_raw;
    use hw_model::multi_lobe::{amp_format, max_exponent, slope_format, Lobe};
    let sf = slope_format(cfg);
    let af = amp_format(cfg);
    let n_max = f64::from(max_exponent(cfg));
    fit.lobes
        .iter()
        .map(|l| {
            let p = l.to_stored(s);
            let d = p.direction;
            let z = d.z.max(1e-9);
            let e = p.exponent.round();
            if e > n_max {
                sat.saturated += 1;
            }
            Lobe {
                slope: [to_raw(d.x / z, &sf, sat), to_raw(d.y / z, &sf, sat)],
                amp: to_raw(p.amplitude, &af, sat) as u64,
                exponent: e.clamp(0.0, n_max) as u32,
            }
        })
        .collect()
}

/// Bytes per texel of K stored lobes (two slopes, amplitude, exponent per lobe), rounded up.
#[must_use]
pub fn bytes_per_texel(k: usize, cfg: &hw_model::multi_lobe::MultiLobeConfig) -> u32 {
    let slope = 1 + cfg.lobe_slope_int_bits + cfg.lobe_slope_frac_bits;
    let bits = 2 * slope + 1 + cfg.lobe_amp_bits + cfg.lobe_exp_bits;
    (k as u32 * bits).div_ceil(8)
}
