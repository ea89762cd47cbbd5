//! The sampler of eqs. 19-22 against its densities, eqs. 5 and 20: both densities integrate to
//! 1 (numerically, independently of the sampler's mapping), and chi-square goodness of fit of
//! the half vectors (binned in (phi, cos theta), own implementation here) and of the reflected
//! directions (library `chi2_k2`).

use glam::DVec3;
use std::f64::consts::PI;
use texsim::brdf::stats::{chi2_k2, wilson_hilferty, Z_95, Z_999};
use texsim::brdf::{dir_from_angles, AshikhminShirley};

struct Rng(u64);
impl Rng {
    fn f(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

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

/// Chi-square of sampled half vectors against eq. 5. Bins: 32 in phi with edges
/// phi = atan(a tan(psi)) for psi uniform per quadrant (a = sqrt((nu+1)/(nv+1)); any fixed edges
/// are valid, these follow the lobe), times 16 in cos(theta) with edges mu_k = (k/16)^(1/(E_j+1))
/// where E_j is the exponent at the phi-bin centre. Expected probability of a bin = integral over
/// its phi range of integral of eq. 5 over mu, i.e. sqrt((nu+1)(nv+1))/(2 pi) (mu_hi^(E+1) -
/// mu_lo^(E+1)) / (E+1) with E = E(phi), by 32-node Gauss-Legendre in phi. Bins expecting < 5
/// are merged. The statistic must stay below the 99.9% Wilson-Hilferty value (a false alarm
/// rate of 1e-3 per case; the seeds are fixed, so the outcome is deterministic).
#[test]
fn half_vector_chi_square() {
    const NP: usize = 32;
    const NC: usize = 16;
    const N: usize = 200_000;
    let mut rng = Rng(11);
    for (nu, nv) in CASES {
        let p = AshikhminShirley::new(nu, nv, 1.0, 0.0).expect("valid");
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
            let sub = uniform_edges(
                0.5 * PI * i as f64 / q as f64,
                0.5 * PI * (i + 1) as f64 / q as f64,
                8,
            );
            for k in 0..NC {
                let (lo, hi) = (mu_edge(j, k), mu_edge(j, k + 1));
                expected[j * NC + k] = gl(&sub, |psi| {
                    let e1 = e_of(phi_of(quad, psi)) + 1.0;
                    norm * (hi.powf(e1) - lo.powf(e1)) / e1 * dphi(quad, psi)
                }) * N as f64;
            }
        }
        let total: f64 = expected.iter().sum::<f64>() / N as f64;
        assert!(
            (total - 1.0).abs() < 1e-6,
            "expected probabilities sum {total}"
        );
        let mut observed = vec![0.0; NP * NC];
        for _ in 0..N {
            let h = p.sample_h(rng.f(), rng.f());
            let mut phi = h.y.atan2(h.x);
            if phi < 0.0 {
                phi += 2.0 * PI;
            }
            let j = edges.partition_point(|&e| e <= phi).clamp(1, NP) - 1;
            let t = h.z.clamp(0.0, 1.0).powf(ej[j] + 1.0);
            let k = ((t * NC as f64) as usize).min(NC - 1);
            observed[j * NC + k] += 1.0;
        }
        let (stat, groups) = merged_chi2(&observed, &expected);
        let dof = (groups - 1) as f64;
        let (c95, c999) = (wilson_hilferty(dof, Z_95), wilson_hilferty(dof, Z_999));
        println!("h chi2 nu {nu} nv {nv}: {stat:.1} dof {dof} crit95 {c95:.1} crit99.9 {c999:.1}");
        assert!(
            stat < c999,
            "nu {nu} nv {nv}: chi2 {stat} >= {c999} (dof {dof})"
        );
    }
}

fn merged_chi2(obs: &[f64], exp: &[f64]) -> (f64, usize) {
    let mut groups = Vec::new();
    let (mut o, mut e) = (0.0, 0.0);
    for (&ob, &ex) in obs.iter().zip(exp) {
        o += ob;
        e += ex;
        if e >= 5.0 {
            groups.push((o, e));
            (o, e) = (0.0, 0.0);
        }
    }
    if let Some(l) = groups.last_mut() {
        l.0 += o;
        l.1 += e;
    }
    (
        groups.iter().map(|&(o, e)| (o - e) * (o - e) / e).sum(),
        groups.len(),
    )
}

/// A sampler with a wrong exponent must be rejected by the same test: sanity that the
/// half-vector chi-square has power (E off by 5% at nu = nv = 100 is detected).
#[test]
fn chi_square_detects_a_wrong_sampler() {
    let truth = AshikhminShirley::new(100.0, 100.0, 1.0, 0.0).expect("valid");
    let wrong = AshikhminShirley::new(105.0, 105.0, 1.0, 0.0).expect("valid");
    let mut rng = Rng(5);
    let nc = 32;
    let n = 200_000usize;
    let mut observed = vec![0.0; nc];
    for _ in 0..n {
        let h = wrong.sample_h(rng.f(), rng.f());
        let t = h.z.powf(101.0);
        observed[((t * nc as f64) as usize).min(nc - 1)] += 1.0;
    }
    // Under the truth, t = mu^101 is uniform: every bin expects n / nc.
    let expected = vec![n as f64 / nc as f64; nc];
    let (stat, groups) = merged_chi2(&observed, &expected);
    assert!(stat > wilson_hilferty((groups - 1) as f64, Z_999), "{stat}");
    let _ = truth;
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
            let k1 = dir_from_angles(89.0 * rng.f(), 360.0 * rng.f());
            if let Some((k2, pdf)) = p.sample(k1, [rng.f(), rng.f()]) {
                let q = p.pdf(k1, k2);
                assert!(
                    (pdf - q).abs() <= 1e-6 * pdf,
                    "{nu} {nv} {k1} {k2}: {pdf} vs {q}"
                );
            }
        }
    }
}
