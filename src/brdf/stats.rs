//! Chi-square goodness-of-fit tests of the Ashikhmin-Shirley sampler (eqs. 19-22) against its
//! densities, with Wilson-Hilferty critical values (Wilson & Hilferty 1931:
//! `chi2_p(k) ~ k (1 - 2/(9k) + z_p sqrt(2/(9k)))^3`).
//!
//! - [`chi2_h`]: sampled half vectors (eqs. 21-22) against eq. 5, valid at ANY anisotropy:
//!   `32` azimuth bins whose edges follow the lobe (`phi = atan(a tan(psi))`, `psi` uniform per
//!   quadrant, `a = sqrt((nu+1)/(nv+1))`) times `16` bins in `cos(theta)` with edges
//!   `mu_k = (k/16)^(1/(E_j+1))` (`E_j` the exponent at the azimuth bin's centre), so every bin
//!   holds a comparable share of the lobe however narrow or anisotropic it is. The expected
//!   probability of a bin is eq. 5 integrated in closed form over `mu` and by 8 cells of
//!   4-point Gauss-Legendre over `psi`.
//! - [`chi2_k2`]: reflected directions `k2` (eq. 19) against eq. 20, over the whole sphere, in
//!   a frame centred on the mirror direction `r` of `k1`: `24` bins in `t` where
//!   `1 - cos(angle to r) = 2 (e^(lambda t) - 1)/(e^lambda - 1)` (fine near the lobe,
//!   `lambda = ln(1 + 2 sqrt((nu+1)(nv+1)))`) times `16` bins of the azimuth around `r`; expected
//!   probabilities by 8x8 sub-cells of 4x4 Gauss-Legendre nodes. This binning is round around
//!   `r`, so it resolves lobes whose anisotropy ratio ([`anisotropy_ratio`]) is at most
//!   [`K2_MAX_ANISOTROPY`]; beyond that use [`chi2_h`].
//!
//! Bins expecting fewer than 5 samples are merged in index order ([`chi2_merged`]). A sample
//! the sampler could not place (`None`: a density of 0 or not finite) has probability 0 under
//! the density, so any such "lost" sample makes the statistic infinite: it is never merged into
//! a bin that expects samples.

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
    /// Samples the sampler could not place (probability 0 under the density; any makes the
    /// statistic infinite).
    pub lost: usize,
    /// `statistic < critical_999`.
    pub passed: bool,
}

/// Largest anisotropy ratio [`chi2_k2`] is valid for (its binning is round around the mirror
/// direction; `tests/shading/brdf_sampling.rs` checks it up to a ratio of 9.2).
pub const K2_MAX_ANISOTROPY: f64 = 10.0;

/// Anisotropy ratio of the lobe: `max(nu+1, nv+1) / min(nu+1, nv+1)`.
#[must_use]
pub fn anisotropy_ratio(p: &AshikhminShirley) -> f64 {
    let (a, b) = (p.nu + 1.0, p.nv + 1.0);
    a.max(b) / a.min(b)
}

/// The result of a statistic over `groups` merged bins.
#[must_use]
fn result(statistic: f64, groups: usize, total_probability: f64, lost: usize) -> Chi2Result {
    let dof = groups.saturating_sub(1).max(1);
    let critical_999 = wilson_hilferty(dof as f64, Z_999);
    Chi2Result {
        statistic,
        dof,
        critical_95: wilson_hilferty(dof as f64, Z_95),
        critical_999,
        total_probability,
        lost,
        passed: statistic < critical_999,
    }
}

/// The chi-square result of `samples` binned into `observed` against the bin probabilities
/// `expected` (bins expecting fewer than 5 merged); `lost` samples make it infinite.
fn binned_result(
    observed: &[f64],
    expected: &[f64],
    samples: usize,
    total_probability: f64,
    lost: usize,
) -> Chi2Result {
    let n = samples as f64;
    let pairs: Vec<(f64, f64)> = observed
        .iter()
        .zip(expected)
        .map(|(&o, &e)| (o, e * n))
        .collect();
    let (statistic, groups) = chi2_merged(&pairs, 5.0);
    let statistic = if lost > 0 { f64::INFINITY } else { statistic };
    result(statistic, groups, total_probability, lost)
}

/// Wilson-Hilferty approximation of the chi-square quantile for `dof` degrees of freedom and
/// standard normal quantile `z`.
#[must_use]
pub fn wilson_hilferty(dof: f64, z: f64) -> f64 {
    let a = 2.0 / (9.0 * dof);
    dof * (1.0 - a + z * a.sqrt()).powi(3)
}

/// Chi-square statistic over `(observed, expected)` pairs after merging bins expecting fewer
/// than `min_expected`, in order (the remainder joins the last group). A bin that expects
/// exactly 0 but holds samples is an impossible event under the density: the statistic is
/// infinite (it is not diluted by merging). Returns `(statistic, merged bin count)`.
#[must_use]
pub fn chi2_merged(pairs: &[(f64, f64)], min_expected: f64) -> (f64, usize) {
    if pairs
        .iter()
        .any(|&(o, e)| (e <= 0.0 || e.is_nan()) && o > 0.0)
    {
        return (f64::INFINITY, pairs.len());
    }
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

/// Azimuth and `cos(theta)` bins of [`chi2_h`].
const NP: usize = 32;
const NC: usize = 16;
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
/// for a fixed `k1` (must be above the horizon), with `samples` samples from `seed`. Valid for
/// an [`anisotropy_ratio`] up to [`K2_MAX_ANISOTROPY`].
#[must_use]
pub fn chi2_k2(p: &AshikhminShirley, k1: DVec3, samples: usize, seed: u64) -> Chi2Result {
    chi2_k2_of(p, k1, &mut |xi| p.sample_sphere(k1, xi), samples, seed)
}

/// [`chi2_k2`] of any sampler of reflected directions (`None`: a lost sample) against the
/// density of `p`: the negative controls of the tests feed it a wrong sampler.
#[must_use]
pub fn chi2_k2_of(
    p: &AshikhminShirley,
    k1: DVec3,
    sampler: &mut dyn FnMut([f64; 2]) -> Option<(DVec3, f64)>,
    samples: usize,
    seed: u64,
) -> Chi2Result {
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
    let mut lost = 0usize;
    for _ in 0..samples {
        let xi = [rng.next_f64(), rng.next_f64()];
        match sampler(xi) {
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
            None => lost += 1,
        }
    }
    binned_result(&observed, &expected, samples, total_probability, lost)
}

/// Chi-square test of the half-vector sampler [`AshikhminShirley::sample_h`] (eqs. 21-22)
/// against its density [`AshikhminShirley::pdf_h`] (eq. 5) with `samples` samples from
/// `seed`; valid at any anisotropy (module doc).
#[must_use]
pub fn chi2_h(p: &AshikhminShirley, samples: usize, seed: u64) -> Chi2Result {
    chi2_h_of(p, &mut |x1, x2| p.sample_h(x1, x2), samples, seed)
}

/// [`chi2_h`] of any half-vector sampler against the density of `p` (negative controls).
#[must_use]
pub fn chi2_h_of(
    p: &AshikhminShirley,
    sampler: &mut dyn FnMut(f64, f64) -> DVec3,
    samples: usize,
    seed: u64,
) -> Chi2Result {
    let (nu, nv) = (p.nu, p.nv);
    let a = ((nu + 1.0) / (nv + 1.0)).sqrt();
    let q = NP / 4;
    // phi(psi) per quadrant, increasing in psi, mirrored in odd quadrants so that the lobe
    // (symmetric about both axes) is followed in every quadrant; and dphi/dpsi.
    let first = |psi: f64| (a * psi.sin()).atan2(psi.cos());
    let jac = |psi: f64| a / (psi.cos().powi(2) + a * a * psi.sin().powi(2));
    let phi_of = |quad: usize, psi: f64| {
        if quad & 1 == 0 {
            0.5 * PI * quad as f64 + first(psi)
        } else {
            0.5 * PI * (quad + 1) as f64 - first(0.5 * PI - psi)
        }
    };
    let dphi = |quad: usize, psi: f64| {
        if quad & 1 == 0 {
            jac(psi)
        } else {
            jac(0.5 * PI - psi)
        }
    };
    let mut edges = Vec::with_capacity(NP + 1);
    for quad in 0..4 {
        for i in 0..q {
            edges.push(phi_of(quad, 0.5 * PI * i as f64 / q as f64));
        }
    }
    edges.push(2.0 * PI);
    let e_of = |phi: f64| nu * phi.cos().powi(2) + nv * phi.sin().powi(2);
    let ej: Vec<f64> = (0..NP)
        .map(|j| e_of(0.5 * (edges[j] + edges[j + 1])))
        .collect();
    let mu_edge = |j: usize, k: usize| (k as f64 / NC as f64).powf(1.0 / (ej[j] + 1.0));
    let norm = ((nu + 1.0) * (nv + 1.0)).sqrt() / (2.0 * PI);
    let mut expected = vec![0.0; NP * NC];
    for j in 0..NP {
        // Integrate in psi: a smooth change of variables that follows the lobe.
        let (quad, i) = (j / q, j % q);
        let (lo_psi, hi_psi) = (
            0.5 * PI * i as f64 / q as f64,
            0.5 * PI * (i + 1) as f64 / q as f64,
        );
        let cell = (hi_psi - lo_psi) / SUB as f64;
        for k in 0..NC {
            let (lo, hi) = (mu_edge(j, k), mu_edge(j, k + 1));
            let mut acc = 0.0;
            for c in 0..SUB {
                for (g, w) in GL4 {
                    let psi = lo_psi + (c as f64 + g) * cell;
                    let e1 = e_of(phi_of(quad, psi)) + 1.0;
                    acc += w * cell * norm * (hi.powf(e1) - lo.powf(e1)) / e1 * dphi(quad, psi);
                }
            }
            expected[j * NC + k] = acc;
        }
    }
    let total_probability: f64 = expected.iter().sum();
    let mut observed = vec![0.0; NP * NC];
    let mut rng = SplitMix64(seed);
    for _ in 0..samples {
        let (x1, x2) = (rng.next_f64(), rng.next_f64());
        let h = sampler(x1, x2);
        let mut phi = h.y.atan2(h.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        let j = edges.partition_point(|&e| e <= phi).clamp(1, NP) - 1;
        let t = h.z.clamp(0.0, 1.0).powf(ej[j] + 1.0);
        let k = ((t * NC as f64) as usize).min(NC - 1);
        observed[j * NC + k] += 1.0;
    }
    binned_result(&observed, &expected, samples, total_probability, 0)
}
