//! The sampler of eqs. 19-22 against its densities, eqs. 5 and 20: both densities integrate to
//! 1 (numerically, independently of the sampler's mapping), and chi-square goodness of fit of
//! the half vectors (library `chi2_h`, valid at any anisotropy) and of the reflected directions
//! (library `chi2_k2`, anisotropy up to 10), each with negative controls.

use crate::rng_common::Rng;
use glam::DVec3;
use std::f64::consts::PI;
use texsim::brdf::stats::{
    chi2_h, chi2_h_of, chi2_k2, chi2_k2_of, chi2_merged, wilson_hilferty, Z_999,
};
use texsim::brdf::{dir_from_angles, AshikhminShirley};

const GL4: [(f64, f64); 4] = [
    (0.069_431_844_202_973_71, 0.173_927_422_568_726_93),
    (0.330_009_478_207_571_9, 0.326_072_577_431_273_07),
    (0.669_990_521_792_428_1, 0.326_072_577_431_273_07),
    (0.930_568_155_797_026_3, 0.173_927_422_568_726_93),
];

/// Composite 4-point Gauss-Legendre of `f` over the cells between consecutive `edges`.
fn gl(edges: &[f64], mut f: impl FnMut(f64) -> f64) -> f64 {
    edges
        .windows(2)
        .map(|w| {
            GL4.iter()
                .map(|&(x, wt)| wt * (w[1] - w[0]) * f(w[0] + x * (w[1] - w[0])))
                .sum::<f64>()
        })
        .sum()
}

/// Polar-angle cell edges on [0, top]: geometric from 1e-6 (resolves lobes of any width up to
/// exponent 1e6), 160 cells.
fn geometric_edges(top: f64) -> Vec<f64> {
    let n = 160;
    let lo: f64 = 1e-6;
    let mut e = vec![0.0];
    e.extend((0..=n).map(|i| lo * (top / lo).powf(i as f64 / n as f64)));
    e
}

fn uniform_edges(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..=n).map(|i| a + (b - a) * i as f64 / n as f64).collect()
}

const CASES: [(f64, f64); 9] = [
    (0.0, 0.0),
    (1.0, 1.0),
    (10.0, 10.0),
    (10.0, 100.0),
    (100.0, 10.0),
    (1.0, 10000.0),
    (10000.0, 1.0),
    (1000.0, 1000.0),
    (100000.0, 10.0),
];

/// Eq. 5 integrates to 1 over the hemisphere: integral of p_h sin(theta) dtheta dphi by
/// composite Gauss-Legendre (geometric cells in theta, 2048 cells in phi so that the lobe of the
/// (1, 10000) case, ~0.01 rad wide in phi, spans many nodes). Tolerance 1e-5: the quadrature's
/// own error (measured <= 3.4e-7, in the (1, 10000) case; a wrong normalization is O(1)).
#[test]
fn half_vector_pdf_integrates_to_one() {
    let th = geometric_edges(PI / 2.0);
    let ph = uniform_edges(0.0, 2.0 * PI, 2048);
    for (nu, nv) in CASES {
        let p = AshikhminShirley::new(nu, nv, 1.0, 0.0).expect("valid");
        let total = gl(&ph, |phi| {
            gl(&th, |t| {
                p.pdf_h(dir_from_angles(t.to_degrees(), phi.to_degrees())) * t.sin()
            })
        });
        println!("p_h integral nu {nu} nv {nv}: 1 {:+.2e}", total - 1.0);
        assert!((total - 1.0).abs() < 1e-5, "nu {nu} nv {nv}: {total}");
    }
}

/// Eq. 20 integrates to 1 over the whole sphere of k2 (the part below the horizon is the
/// sampler's rejected mass): integral in a frame centred on the mirror direction, geometric
/// cells in the angle from it, 512 azimuth cells. Tolerance 2e-3: the density has an
/// integrable 1/|k2 + k1| singularity at k2 = -k1 (half vectors orthogonal to k1) that the
/// product rule resolves only to ~1e-3 when p_h is still large there (low exponents, oblique
/// k1); errors of the model (a wrong Jacobian factor) would be O(1). For exponents >= 100 the
/// singularity carries no mass and the bound is 1e-6 (measured <= 2e-8).
#[test]
fn direction_pdf_integrates_to_one_over_sphere() {
    let al = geometric_edges(PI);
    let be = uniform_edges(0.0, 2.0 * PI, 512);
    for (nu, nv) in [
        (1.0, 1.0),
        (10.0, 100.0),
        (1000.0, 1000.0),
        (100.0, 10000.0),
    ] {
        let p = AshikhminShirley::new(nu, nv, 1.0, 0.0).expect("valid");
        // (The strongly anisotropic case skips 80 deg: there the k2 = -k1 singularity carries
        // p_h ~ 0.2 and the product rule's error reaches 4e-3.)
        let thetas: &[f64] = if nv > 1000.0 {
            &[0.0, 30.0, 60.0]
        } else {
            &[0.0, 30.0, 60.0, 80.0]
        };
        for &theta in thetas {
            let k1 = dir_from_angles(theta, 20.0);
            let r = DVec3::new(-k1.x, -k1.y, k1.z);
            let t1 = if theta == 0.0 {
                DVec3::X
            } else {
                (DVec3::Z - r * r.z).normalize()
            };
            let t2 = r.cross(t1);
            let total = gl(&be, |b| {
                let (sb, cb) = b.sin_cos();
                gl(&al, |a| {
                    let (sa, ca) = a.sin_cos();
                    p.pdf(k1, sa * cb * t1 + sa * sb * t2 + ca * r) * sa
                })
            });
            println!(
                "pdf integral nu {nu} nv {nv} theta {theta}: 1 {:+.2e}",
                total - 1.0
            );
            assert!(
                (total - 1.0).abs() < if nu >= 100.0 { 1e-6 } else { 2e-3 },
                "nu {nu} nv {nv} theta {theta}: {total}"
            );
        }
    }
}

/// Chi-square of sampled half vectors against eq. 5 (library `chi2_h`, the test `texsim brdf
/// sample` reports; binning in its module doc): the expected probabilities sum to 1 within
/// 1e-6 and the statistic stays below the 99.9% Wilson-Hilferty value (a false alarm rate of
/// 1e-3 per case; the seeds are fixed, so the outcome is deterministic), for anisotropy up to
/// 1e4 and exponents up to 1e5.
#[test]
fn half_vector_chi_square() {
    for (i, (nu, nv)) in CASES.into_iter().enumerate() {
        let p = AshikhminShirley::new(nu, nv, 1.0, 0.0).expect("valid");
        let r = chi2_h(&p, 200_000, 11 + i as u64);
        println!(
            "h chi2 nu {nu} nv {nv}: {:.1} dof {} crit95 {:.1} crit99.9 {:.1}",
            r.statistic, r.dof, r.critical_95, r.critical_999
        );
        assert!(
            (r.total_probability - 1.0).abs() < 1e-6,
            "expected probabilities sum {}",
            r.total_probability
        );
        assert!(r.dof > 400 && r.lost == 0, "{r:?}");
        assert!(r.passed, "nu {nu} nv {nv}: {r:?}");
    }
}

/// Negative controls of `chi2_h` at the anisotropy `texsim brdf sample` advertises
/// (`nu = 1000, nv = 10`) and beyond: a sampler whose `nu` is 5% off, one with the axes
/// swapped, one for `(1e5, 10)` fed `(1e5, 12)` and an isotropic one 5% off are all rejected
/// at 99.9%, while the right sampler passes with the same seed.
#[test]
fn half_vector_chi_square_rejects_wrong_samplers() {
    for (truth, wrong) in [
        ((1000.0, 10.0), (1050.0, 10.0)),
        ((1000.0, 10.0), (10.0, 1000.0)),
        ((100_000.0, 10.0), (100_000.0, 12.0)),
        ((10.0, 10.0), (10.5, 10.5)),
    ] {
        let p = AshikhminShirley::new(truth.0, truth.1, 1.0, 0.0).expect("valid");
        let q = AshikhminShirley::new(wrong.0, wrong.1, 1.0, 0.0).expect("valid");
        let ok = chi2_h(&p, 200_000, 3);
        let bad = chi2_h_of(&p, &mut |a, b| q.sample_h(a, b), 200_000, 3);
        println!(
            "truth {truth:?}: {:.1}; sampler of {wrong:?}: {:.1} (crit99.9 {:.1})",
            ok.statistic, bad.statistic, bad.critical_999
        );
        assert!(ok.passed, "{truth:?}: {ok:?}");
        assert!(!bad.passed, "{truth:?} vs {wrong:?}: {bad:?}");
    }
}

/// Negative controls of `chi2_k2`: a sampler with a 5% wrong exponent (within its anisotropy
/// range) is rejected; a sampler that loses 0.1% of its samples (returns `None`, which the
/// density says has probability 0) is rejected with an infinite statistic; and `chi2_merged`
/// scores a bin that expects 0 but holds samples as infinite even where it would be merged
/// into a neighbour.
#[test]
fn reflected_direction_chi_square_rejects_wrong_samplers() {
    let k1 = dir_from_angles(30.0, 33.0);
    let p = AshikhminShirley::new(100.0, 100.0, 0.5, 0.5).expect("valid");
    let q = AshikhminShirley::new(105.0, 105.0, 0.5, 0.5).expect("valid");
    let ok = chi2_k2(&p, k1, 200_000, 3);
    let bad = chi2_k2_of(&p, k1, &mut |xi| q.sample_sphere(k1, xi), 200_000, 3);
    println!(
        "k2 chi2 (100, 100): {:.1}; sampler of (105, 105): {:.1} (crit99.9 {:.1})",
        ok.statistic, bad.statistic, bad.critical_999
    );
    assert!(ok.passed && ok.lost == 0, "{ok:?}");
    assert!(!bad.passed, "{bad:?}");
    let mut count = 0u64;
    let lossy = chi2_k2_of(
        &p,
        k1,
        &mut |xi| {
            count += 1;
            if count == 1000 {
                count = 0;
                None
            } else {
                p.sample_sphere(k1, xi)
            }
        },
        200_000,
        3,
    );
    assert_eq!(lossy.lost, 200);
    assert!(lossy.statistic.is_infinite() && !lossy.passed, "{lossy:?}");
    // (observed, expected): the last bin expects 0 but holds one sample.
    let (stat, _) = chi2_merged(&[(100.0, 100.0), (50.0, 50.0), (1.0, 0.0)], 5.0);
    assert!(stat.is_infinite(), "{stat}");
    let (stat, groups) = chi2_merged(&[(100.0, 100.0), (50.0, 50.0), (0.0, 0.0)], 5.0);
    assert_eq!((stat, groups), (0.0, 2));
}

/// An independent binning (not the library's): for `nu = nv = 100`, `t = (h.n)^101` is uniform
/// on [0, 1] under eq. 5, so 32 equal bins in `t` each expect `n / 32`. The right sampler
/// passes at 99.9% and a sampler with a 5% wrong exponent is rejected.
#[test]
fn chi_square_detects_a_wrong_sampler() {
    let truth = AshikhminShirley::new(100.0, 100.0, 1.0, 0.0).expect("valid");
    let wrong = AshikhminShirley::new(105.0, 105.0, 1.0, 0.0).expect("valid");
    let nc = 32;
    let n = 200_000usize;
    let stat_of = |p: &AshikhminShirley| {
        let mut rng = Rng(5);
        let mut observed = vec![0.0; nc];
        for _ in 0..n {
            let h = p.sample_h(rng.unit(), rng.unit());
            let t = h.z.powf(101.0);
            observed[((t * nc as f64) as usize).min(nc - 1)] += 1.0;
        }
        let pairs: Vec<(f64, f64)> = observed
            .into_iter()
            .map(|o| (o, n as f64 / nc as f64))
            .collect();
        let (stat, groups) = chi2_merged(&pairs, 5.0);
        (stat, wilson_hilferty((groups - 1) as f64, Z_999))
    };
    let (ok, crit) = stat_of(&truth);
    assert!(ok < crit, "{ok} {crit}");
    let (bad, crit) = stat_of(&wrong);
    assert!(bad > crit, "{bad} {crit}");
}

/// Chi-square of reflected directions k2 (eqs. 19-20) for moderate anisotropy, binned around
/// the mirror direction over the whole sphere (library implementation, see its module doc).
#[test]
fn reflected_direction_chi_square() {
    for (nu, nv, theta, seed) in [
        (10.0, 10.0, 30.0, 1u64),
        (10.0, 100.0, 45.0, 2),
        (100.0, 100.0, 70.0, 3),
        (1.0, 1.0, 60.0, 4),
        (1000.0, 300.0, 20.0, 5),
    ] {
        let p = AshikhminShirley::new(nu, nv, 0.5, 0.5).expect("valid");
        let r = chi2_k2(&p, dir_from_angles(theta, 33.0), 200_000, seed);
        println!(
            "k2 chi2 nu {nu} nv {nv} theta {theta}: {:.1} dof {} crit99.9 {:.1} total {:.6}",
            r.statistic, r.dof, r.critical_999, r.total_probability
        );
        assert!((r.total_probability - 1.0).abs() < 2e-3, "{r:?}");
        assert!(r.passed, "nu {nu} nv {nv} theta {theta}: {r:?}");
    }
}

/// The density returned with a sample equals `pdf(k1, k2)` recomputed from the direction.
#[test]
fn sample_pdf_matches_pdf() {
    let mut rng = Rng(9);
    for (nu, nv) in CASES {
        let p = AshikhminShirley::new(nu, nv, 1.0, 0.0).expect("valid");
        for _ in 0..20_000 {
            let k1 = dir_from_angles(89.0 * rng.unit(), 360.0 * rng.unit());
            if let Some((k2, pdf)) = p.sample(k1, [rng.unit(), rng.unit()]) {
                let q = p.pdf(k1, k2);
                assert!(
                    (pdf - q).abs() <= 1e-6 * pdf,
                    "{nu} {nv} {k1} {k2}: {pdf} vs {q}"
                );
            }
        }
    }
}
