//! Directional albedo of the Ashikhmin-Shirley BRDF (eq. 6): quadrature accuracy, energy
//! conservation over a parameter grid, the observations of the paper's furnace figures 2 and 4,
//! and Monte Carlo agreement.

use rayon::prelude::*;
use texsim::brdf::{dir_from_angles, AshikhminShirley};

const EXPS: [f64; 5] = [1.0, 10.0, 100.0, 1000.0, 10000.0];
/// Error bound of the res-6 quadrature (`quadrature_convergence`).
const RES6_ERROR: f64 = 5e-3;
/// Tolerance above 1 of the res-32 refinement of `energy_conservation_grid` (3x the res-32
/// error measured on its cases).
const RES32_TOL: f64 = 1e-5;

fn model(nu: f64, nv: f64, rs: f64, rd: f64) -> AshikhminShirley {
    AshikhminShirley::new(nu, nv, rs, rd).expect("valid parameters")
}

/// Normal incidence, isotropic n, Rs = 1, Rd = 0 has a closed form: with k1 = n, k2 is the
/// mirror of n about h, n.k2 = cos(2 theta_h), max(n.k1, n.k2) = 1, so
/// R = integral_{theta_h < pi/4} p_h(h) cos(2 theta_h) d omega_h
///   = (n+1) [2 (1 - a^(n+3))/(n+3) - (1 - a^(n+1))/(n+1)],  a = 1/sqrt(2).
/// The quadrature (res 32) must match it to 1e-4 (its documented accuracy is 3e-4 worst case;
/// normal incidence is a smooth case).
#[test]
fn quadrature_matches_closed_form_at_normal_incidence() {
    let a = std::f64::consts::FRAC_1_SQRT_2;
    for n in [0.0, 1.0, 10.0, 100.0, 1000.0, 10000.0, 100000.0] {
        let closed = (n + 1.0)
            * (2.0 * (1.0 - a.powf(n + 3.0)) / (n + 3.0) - (1.0 - a.powf(n + 1.0)) / (n + 1.0));
        let q = model(n, n, 1.0, 0.0).albedo_quadrature(dir_from_angles(0.0, 0.0), 32);
        assert!(
            (q - closed).abs() < 1e-4,
            "n {n}: quadrature {q} closed {closed}"
        );
    }
}

/// Convergence: res 32 (used by reports) and res 6 (used by the grid test below) against
/// res 64, over exponents 0..1e5, anisotropy up to 1e4 and angles up to 89 deg. Bounds: 3e-4
/// for res 32 (the documented accuracy; res 64 differs from res 128 by < 1e-4 on these cases),
/// 5e-3 for res 6 (the grid test's tolerance; reached only at 89 deg with n <= 1).
#[test]
fn quadrature_convergence() {
    let cases: Vec<(f64, f64, f64)> = [
        (0.0, 0.0),
        (1.0, 1.0),
        (10.0, 10.0),
        (1.0, 10000.0),
        (1000.0, 1000.0),
        (100000.0, 100000.0),
    ]
    .iter()
    .flat_map(|&(u, v)| [0.0, 30.0, 60.0, 80.0, 85.0, 89.0].map(move |t| (u, v, t)))
    .collect();
    let worst = cases
        .par_iter()
        .map(|&(nu, nv, t)| {
            let p = model(nu, nv, 0.3, 0.7);
            let k1 = dir_from_angles(t, 20.0);
            let fine = p.albedo_quadrature(k1, 64);
            let e32 = (p.albedo_quadrature(k1, 32) - fine).abs();
            let e8 = (p.albedo_quadrature(k1, 6) - fine).abs();
            assert!(e32 < 3e-4, "res 32 nu {nu} nv {nv} theta {t}: {e32}");
            assert!(e8 < 5e-3, "res 6 nu {nu} nv {nv} theta {t}: {e8}");
            (e32, e8)
        })
        .reduce(|| (0.0, 0.0), |a, b| (a.0.max(b.0), a.1.max(b.1)));
    println!(
        "worst quadrature error vs res 64: res32 {:.2e} res6 {:.2e}",
        worst.0, worst.1
    );
}

/// Energy conservation: directional albedo <= 1 for nu, nv in {1..1e4}, Rs, Rd in {0, .5, 1},
/// theta 0..89 deg (azimuth 0; plus azimuth 45 deg every 5 deg for the anisotropic pairs).
/// The albedo is affine in Rs for the specular part and Rd (1 - Rs) times a fixed integral for
/// the diffuse part, so per direction we integrate A1 (Rs = 1), A0 (Rs = 0, Fresnel only) and
/// D (Rd = 1, Rs = 0) once and combine; the combination is checked against direct quadrature of
/// the combined model on a subset.
///
/// Two passes. The whole grid at res 6, whose error is < 5e-3 (`quadrature_convergence`):
/// every case below `1 - 5e-3` there is below 1. Every direction with a case at or above
/// `1 - 5e-3` (79 of 2610, measured) is recomputed at res 32 and must be `<= 1 + 1e-5`: on
/// these cases res 32 is within 3e-6 of res 128 (measured; res 64 within 1e-6), and the test
/// checks the three largest against res 64 within 5e-6. In theory the albedo is < 1 (the
/// specular albedo is <= r(k1) of eq. 15, the diffuse one Rd (1 - r(k1))). The largest is
/// 0.99960 at nu = nv = 1e4, Rs = 1, Rd = 0, normal incidence, where the closed form of
/// `quadrature_matches_closed_form_at_normal_incidence` gives 9999/10003 = 0.9996001; asserted.
#[test]
fn energy_conservation_grid() {
    let mut dirs: Vec<(f64, f64, f64, f64)> = Vec::new();
    for nu in EXPS {
        for nv in EXPS {
            for t in 0..90 {
                dirs.push((nu, nv, f64::from(t), 0.0));
                if nu != nv && t % 5 == 0 {
                    dirs.push((nu, nv, f64::from(t), 45.0));
                }
            }
        }
    }
    let rows: Vec<(f64, f64, f64, f64, f64, f64, f64)> = dirs
        .par_iter()
        .map(|&(nu, nv, t, phi)| {
            let k1 = dir_from_angles(t, phi);
            let a1 = model(nu, nv, 1.0, 0.0).albedo_quadrature_parts(k1, 6).1;
            let (_, a0, d) = model(nu, nv, 0.0, 1.0).albedo_quadrature_parts(k1, 6);
            (nu, nv, t, phi, a1, a0, d)
        })
        .collect();
    let combos = |a1: f64, a0: f64, d: f64| {
        [0.0, 0.5, 1.0].into_iter().flat_map(move |rs| {
            [0.0, 0.5, 1.0]
                .into_iter()
                .map(move |rd| (rs, rd, rs * a1 + (1.0 - rs) * a0 + rd * (1.0 - rs) * d))
        })
    };
    let mut near_one = Vec::new();
    for &(nu, nv, t, phi, a1, a0, d) in &rows {
        let mut top = 0.0f64;
        for (rs, rd, a) in combos(a1, a0, d) {
            assert!(
                a >= 0.0,
                "nu {nu} nv {nv} rs {rs} rd {rd} theta {t} phi {phi}: {a}"
            );
            top = top.max(a);
        }
        if top >= 1.0 - RES6_ERROR {
            near_one.push((nu, nv, t, phi));
        }
    }
    // Refinement of the directions the res-6 bound cannot settle.
    let mut refined: Vec<(f64, f64, f64, f64, f64, f64, f64)> = near_one
        .par_iter()
        .map(|&(nu, nv, t, phi)| {
            let k1 = dir_from_angles(t, phi);
            let a1 = model(nu, nv, 1.0, 0.0).albedo_quadrature_parts(k1, 32).1;
            let (_, a0, d) = model(nu, nv, 0.0, 1.0).albedo_quadrature_parts(k1, 32);
            (nu, nv, t, phi, a1, a0, d)
        })
        .collect();
    let mut max = (0.0, String::new());
    for &(nu, nv, t, phi, a1, a0, d) in &refined {
        for (rs, rd, a) in combos(a1, a0, d) {
            let at = format!("nu {nu} nv {nv} rs {rs} rd {rd} theta {t} phi {phi}");
            assert!(a <= 1.0 + RES32_TOL, "{at}: {a}");
            if a > max.0 {
                max = (a, at);
            }
        }
    }
    println!(
        "largest albedo {:.6} at {} ({} directions refined at res 32)",
        max.0,
        max.1,
        refined.len()
    );
    assert!(refined.len() > 10 && refined.len() < rows.len() / 10);
    assert_eq!(max.1, "nu 10000 nv 10000 rs 1 rd 0 theta 0 phi 0");
    assert!((max.0 - 9999.0 / 10003.0).abs() < 1e-6, "{}", max.0);
    // The res-32 tolerance: the three largest refined directions against res 64.
    refined.sort_by(|x, y| y.4.total_cmp(&x.4));
    for &(nu, nv, t, phi, a1, _, _) in refined.iter().take(3) {
        let fine = model(nu, nv, 1.0, 0.0).albedo_quadrature(dir_from_angles(t, phi), 64);
        assert!((a1 - fine).abs() < 5e-6, "{nu} {nv} {t}: {a1} vs {fine}");
    }
    // The affine decomposition equals direct quadrature of the combined model.
    for &(nu, nv, t, phi, a1, a0, d) in rows.iter().step_by(97) {
        for (rs, rd) in [(0.5, 0.5), (0.5, 1.0), (1.0, 1.0), (0.0, 0.5)] {
            let direct = model(nu, nv, rs, rd).albedo_quadrature(dir_from_angles(t, phi), 6);
            let comb = rs * a1 + (1.0 - rs) * a0 + rd * (1.0 - rs) * d;
            assert!((direct - comb).abs() < 1e-12, "{direct} {comb}");
        }
    }
    // Grid excerpt for the report (Rs = 1, Rd = 0 and Rs = 0.05, Rd = 1; azimuth 0).
    println!("albedo excerpt: nu nv theta | Rs=1,Rd=0 | Rs=.05,Rd=1");
    for &(nu, nv, t, phi, a1, a0, d) in &rows {
        if phi == 0.0 && nu == nv && [0.0, 45.0, 75.0, 89.0].contains(&t) {
            println!(
                "{nu:>6} {nv:>6} {t:>3} | {a1:.4} | {:.4}",
                0.05 * a1 + 0.95 * a0 + 0.95 * d
            );
        }
    }
}

/// Figure 2 (spheres in a furnace, specular only, taken as Rs = 1, Rd = 0): "as the exponents
/// get larger, less energy is lost" (albedo increases with n at every angle); "for the centre of
/// the darkest sphere, nu = nv = 10, the luminance is about 68%" (exact value 0.6957; the
/// paper's figure was read from an image, so +-0.03); perfect mirrors (n -> inf) reflect
/// everything but at grazing incidence, where half of the lobe falls below the horizon and the
/// albedo drops toward 1/2.
#[test]
fn figure2_furnace_specular() {
    let centre = model(10.0, 10.0, 1.0, 0.0).albedo_quadrature(dir_from_angles(0.0, 0.0), 32);
    assert!((centre - 0.68).abs() < 0.03, "{centre}");
    for t in [0.0, 30.0, 60.0, 75.0, 85.0, 89.0] {
        let mut prev = 0.0;
        for n in EXPS {
            let a = model(n, n, 1.0, 0.0).albedo_quadrature(dir_from_angles(t, 0.0), 16);
            assert!(a > prev && a < 1.0, "theta {t} n {n}: {a} after {prev}");
            prev = a;
        }
    }
    // Near-mirror: close to but below 1 away from grazing.
    for t in [0.0, 30.0, 60.0, 80.0] {
        let a = model(10000.0, 10000.0, 1.0, 0.0).albedo_quadrature(dir_from_angles(t, 0.0), 16);
        assert!(a > 0.95 && a < 1.0, "theta {t}: {a}");
    }
    // Grazing: the albedo falls toward 1/2 for every exponent (half the lobe is cut off).
    for n in [1.0, 10.0, 100.0, 1000.0] {
        let p = model(n, n, 1.0, 0.0);
        let g = p.albedo_quadrature(dir_from_angles(89.99, 0.0), 32);
        let mid = p.albedo_quadrature(dir_from_angles(45.0, 0.0), 32);
        assert!((g - 0.5).abs() < 0.03, "n {n}: grazing {g}");
        assert!(g < mid || n < 10.0, "n {n}: grazing {g} vs 45 deg {mid}");
    }
}

/// Figure 4 (Rs = 0.05, Rd = 1, diffusely lit; large exponent): "the lowest values are near the
/// edge of the sphere and are approximately 74% of the background". With n = 10000 the minimum
/// over the visible disk (theta <= 85 deg; beyond that is the outer 0.4% of the radius) must
/// be 0.74 +- 0.02, at theta in [60, 85] deg. In the large-n limit the albedo is
/// F(cos) + 0.95 (1 - (1 - cos/2)^5), whose minimum 0.737 is at cos = 0.27 (74 deg). The
/// centre is Rs + (1 - Rs)(31/32) = 0.970; the specular loss is small (Rs = 1 albedo > 0.95
/// up to 80 deg), so "any darkening is due to the diffuse component".
#[test]
fn figure4_coupled_diffuse() {
    let p = model(10000.0, 10000.0, 0.05, 1.0);
    let curve: Vec<(f64, f64)> = (0..=170)
        .into_par_iter()
        .map(|i| {
            let t = 0.5 * f64::from(i);
            (t, p.albedo_quadrature(dir_from_angles(t, 0.0), 16))
        })
        .collect();
    let (tmin, amin) = curve
        .iter()
        .copied()
        .fold((0.0, 2.0), |m, c| if c.1 < m.1 { c } else { m });
    println!("figure 4: minimum {amin:.4} at theta {tmin}");
    assert!(
        (amin - 0.74).abs() < 0.02 && (60.0..=85.0).contains(&tmin),
        "{amin} at {tmin}"
    );
    assert!((curve[0].1 - 0.970).abs() < 0.005, "centre {}", curve[0].1);
    assert!(curve.iter().all(|&(_, a)| a <= 1.0));
    for t in [0.0, 40.0, 80.0] {
        let s = model(10000.0, 10000.0, 1.0, 0.0).albedo_quadrature(dir_from_angles(t, 0.0), 16);
        assert!(s > 0.95, "{s}");
    }
}

/// Monte Carlo (importance-sampled mixture) agrees with quadrature within 4 standard errors
/// (plus the res 32 quadrature bound 3e-4), for varied parameters and angles.
#[test]
fn monte_carlo_matches_quadrature() {
    let cases = [
        (1.0, 1.0, 0.5, 0.5, 0.0),
        (10.0, 10.0, 1.0, 0.0, 45.0),
        (10.0, 1000.0, 0.05, 1.0, 30.0),
        (1000.0, 10.0, 0.05, 1.0, 70.0),
        (100.0, 100.0, 0.0, 0.0, 85.0),
        (10000.0, 10000.0, 0.3, 0.8, 60.0),
        (0.0, 0.0, 0.2, 0.2, 20.0),
        (1.0, 10000.0, 1.0, 0.0, 80.0),
    ];
    for (i, &(nu, nv, rs, rd, t)) in cases.iter().enumerate() {
        let p = model(nu, nv, rs, rd);
        let k1 = dir_from_angles(t, 17.0);
        let q = p.albedo_quadrature(k1, 32);
        let mc = p.albedo_mc(k1, 200_000, 1000 + i as u64);
        assert!(
            (mc.albedo - q).abs() < 4.0 * mc.std_error + 3e-4,
            "{nu} {nv} {rs} {rd} {t}: mc {mc:?} quad {q}"
        );
    }
}
