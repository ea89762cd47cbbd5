//! Chi-square goodness-of-fit of the Ashikhmin-Shirley reflected-direction sampler (eqs. 19-22)
//! against its density (eq. 20), with Wilson-Hilferty critical values (Wilson & Hilferty 1931:
//! `chi2_p(k) ~ k (1 - 2/(9k) + z_p sqrt(2/(9k)))^3`).
//!
//! Bins cover the whole sphere of `k2` in a frame centred on the mirror direction `r` of `k1`:
//! `24` bins in `t` where `1 - cos(angle to r) = 2 (e^(lambda t) - 1)/(e^lambda - 1)` (fine near
//! the lobe, `lambda = ln(1 + 2 sqrt((nu+1)(nv+1)))`) times `16` bins of the azimuth around `r`. The
//! expected probability of a bin is the integral of [`AshikhminShirley::pdf`] over it, by 8x8
//! sub-cells of 4x4 Gauss-Legendre nodes. Bins expecting fewer than 5 samples are merged in
//! index order. The binning resolves lobes whose anisotropy ratio `max/min` of `(n+1)` is up
//! to about 10; stronger anisotropy needs the half-vector test of `tests/brdf_sampling.rs`.

use super::ashikhmin_shirley::{AshikhminShirley, SplitMix64};
use glam::DVec3;
use std::f64::consts::PI;

/// Standard normal quantile at 0.95.
pub const Z_95: f64 = 1.644_853_626_951_472;
/// Standard normal quantile at 0.999.
pub const Z_999: f64 = 3.090_232_306_167_813;

/// Result of a chi-square test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Chi2Result {
    /// The statistic `sum (obs - exp)^2 / exp` over merged bins.
    pub statistic: f64,
    /// Degrees of freedom (merged bins - 1).
    pub dof: usize,
    /// 95% critical value.
    pub critical_95: f64,
    /// 99.9% critical value.
    pub critical_999: f64,
    /// Integral of the density over all bins (should be 1).
    pub total_probability: f64,
    /// `statistic < critical_999`.
    pub passed: bool,
}

/// Wilson-Hilferty approximation of the chi-square quantile for `dof` degrees of freedom and
/// standard normal quantile `z`.
#[must_use]
pub fn wilson_hilferty(dof: f64, z: f64) -> f64 {
    let a = 2.0 / (9.0 * dof);
    dof * (1.0 - a + z * a.sqrt()).powi(3)
}

/// Chi-square statistic over `(observed, expected)` pairs after merging bins expecting fewer
/// than `min_expected`, in order. Returns `(statistic, merged bin count)`.
#[must_use]
pub fn chi2_merged(pairs: &[(f64, f64)], min_expected: f64) -> (f64, usize) {
    let mut groups: Vec<(f64, f64)> = Vec::new();
    let (mut o, mut e) = (0.0, 0.0);
    for &(ob, ex) in pairs {
        o += ob;
        e += ex;
        if e >= min_expected {
            groups.push((o, e));
            o = 0.0;
            e = 0.0;
        }
    }
    if e > 0.0 || o > 0.0 {
        match groups.last_mut() {
            Some(last) => {
                last.0 += o;
                last.1 += e;
            }
            None => groups.push((o, e)),
        }
    }
    let stat = groups
        .iter()
        .map(|&(o, e)| {
            if e > 0.0 {
                (o - e) * (o - e) / e
            } else if o > 0.0 {
                f64::INFINITY
            } else {
                0.0
            }
        })
        .sum();
    (stat, groups.len())
}

const NT: usize = 24;
const NB: usize = 16;
const SUB: usize = 8;
const GL4: [(f64, f64); 4] = [
    (0.069_431_844_202_973_71, 0.173_927_422_568_726_93),
    (0.330_009_478_207_571_9, 0.326_072_577_431_273_07),
    (0.669_990_521_792_428_1, 0.326_072_577_431_273_07),
    (0.930_568_155_797_026_3, 0.173_927_422_568_726_93),
];

/// Orthonormal frame `(t1, t2, r)` around the mirror direction of `k1`.
#[must_use]
fn frame(k1: DVec3) -> (DVec3, DVec3, DVec3) {
    let r = DVec3::new(-k1.x, -k1.y, k1.z).normalize_or(DVec3::Z);
    let a = if r.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    let t1 = (a - r * r.dot(a)).normalize();
    let t2 = r.cross(t1);
    (t1, t2, r)
}

/// Chi-square test of [`AshikhminShirley::sample_sphere`] against [`AshikhminShirley::pdf`]
/// for a fixed `k1` (must be above the horizon), with `samples` samples from `seed`.
#[must_use]
pub fn chi2_k2(p: &AshikhminShirley, k1: DVec3, samples: usize, seed: u64) -> Chi2Result {
    let em = ((p.nu + 1.0) * (p.nv + 1.0)).sqrt() - 1.0;
    let lambda = (1.0 + 2.0 * (em + 1.0)).ln().max(1.0);
    let el = lambda.exp_m1();
    let w_of_t = |t: f64| 2.0 * (lambda * t).exp_m1() / el;
    let dw_dt = |t: f64| 2.0 * lambda * (lambda * t).exp() / el;
    let (t1, t2, r) = frame(k1);
    let dir = |w: f64, beta: f64| {
        let c = (1.0 - w).clamp(-1.0, 1.0);
        let s = (1.0 - c * c).max(0.0).sqrt();
        let (sb, cb) = beta.sin_cos();
        s * cb * t1 + s * sb * t2 + c * r
    };
    // Expected probabilities.
    let mut expected = vec![0.0; NT * NB];
    for it in 0..NT {
        for ib in 0..NB {
            let mut acc = 0.0;
            for st in 0..SUB {
                for sb in 0..SUB {
                    let ht = 1.0 / (NT * SUB) as f64;
                    let hb = 2.0 * PI / (NB * SUB) as f64;
                    let t0 = (it * SUB + st) as f64 * ht;
                    let b0 = (ib * SUB + sb) as f64 * hb;
                    for (gt, wt) in GL4 {
                        for (gb, wb) in GL4 {
                            let t = t0 + gt * ht;
                            let k2 = dir(w_of_t(t), b0 + gb * hb);
                            // d omega = d(cos) d(beta) = dw d(beta).
                            acc += wt * wb * ht * hb * dw_dt(t) * p.pdf(k1, k2);
                        }
                    }
                }
            }
            expected[it * NB + ib] = acc;
        }
    }
    let total_probability: f64 = expected.iter().sum();
    // Observed counts.
    let mut observed = vec![0.0; NT * NB];
    let mut rng = SplitMix64(seed);
    let mut lost = 0.0;
    for _ in 0..samples {
        let xi = [rng.next_f64(), rng.next_f64()];
        match p.sample_sphere(k1, xi) {
            Some((k2, _)) => {
                let c = k2.dot(r).clamp(-1.0, 1.0);
                let w = 1.0 - c;
                let t = ((w * el / 2.0).ln_1p() / lambda).clamp(0.0, 1.0);
                let mut beta = k2.dot(t2).atan2(k2.dot(t1));
                if beta < 0.0 {
                    beta += 2.0 * PI;
                }
                let it = ((t * NT as f64) as usize).min(NT - 1);
                let ib = ((beta / (2.0 * PI) * NB as f64) as usize).min(NB - 1);
                observed[it * NB + ib] += 1.0;
            }
            None => lost += 1.0,
        }
    }
    let n = samples as f64;
    let mut pairs: Vec<(f64, f64)> = observed
        .iter()
        .zip(&expected)
        .map(|(&o, &e)| (o, e * n))
        .collect();
    // Samples the sampler could not place count against a bin of expectation 0.
    pairs.push((lost, 0.0));
    let (statistic, groups) = chi2_merged(&pairs, 5.0);
    let dof = groups.saturating_sub(1).max(1);
    let critical_999 = wilson_hilferty(dof as f64, Z_999);
    Chi2Result {
        statistic,
        dof,
        critical_95: wilson_hilferty(dof as f64, Z_95),
        critical_999,
        total_probability,
        passed: statistic < critical_999,
    }
}
