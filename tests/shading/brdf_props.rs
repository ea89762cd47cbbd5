//! Property tests of the Ashikhmin-Shirley reference (eqs. 10-22): reciprocity, finiteness,
//! non-negativity and the stated upper bounds over random and boundary inputs, agreement of the dot-product form with the
//! vector form, the eq. 16 constant, the h -> n limit, and the report functions.

use crate::rng_common::Rng;
use glam::DVec3;
use std::f64::consts::PI;
use texsim::brdf::ashikhmin_shirley::{BRDF_MAX, DENOM_FLOOR, EXPONENT_MAX};
use texsim::brdf::{
    albedo_report, dir_from_angles, eval_report, sample_report, AshikhminShirley, Dots,
};

/// Draws of this file's cases from the tests' shared generator.
trait Draws {
    fn sphere_dir(&mut self) -> DVec3;
    fn upper(&mut self) -> DVec3;
    fn exponent(&mut self) -> f64;
    fn model(&mut self) -> AshikhminShirley;
}

impl Draws for Rng {
    /// Uniform direction on the sphere.
    fn sphere_dir(&mut self) -> DVec3 {
        let z = 2.0 * self.unit() - 1.0;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let (s, c) = (2.0 * PI * self.unit()).sin_cos();
        DVec3::new(r * c, r * s, z)
    }
    /// Upper-hemisphere direction, often near the boundary cases.
    fn upper(&mut self) -> DVec3 {
        match self.next() % 6 {
            0 => DVec3::Z,
            1 => dir_from_angles(90.0 - 1e-9 * self.unit(), 360.0 * self.unit()),
            2 => dir_from_angles(89.0 + self.unit(), 360.0 * self.unit()),
            3 => dir_from_angles(1e-7 * self.unit(), 360.0 * self.unit()),
            _ => {
                let d = self.sphere_dir();
                DVec3::new(d.x, d.y, d.z.abs())
            }
        }
    }
    fn exponent(&mut self) -> f64 {
        const E: [f64; 10] = [0.0, 1e-3, 0.5, 1.0, 10.0, 100.0, 1000.0, 1e4, 1e5, 1e6];
        if self.next() & 1 == 0 {
            E[(self.next() % 10) as usize]
        } else {
            10f64.powf(6.0 * self.unit())
        }
    }
    fn model(&mut self) -> AshikhminShirley {
        let pick = |r: &mut Rng| match r.next() % 4 {
            0 => 0.0,
            1 => 1.0,
            _ => r.unit(),
        };
        let (nu, nv) = (self.exponent(), self.exponent());
        let (rs, rd) = (pick(self), pick(self));
        AshikhminShirley::new(nu, nv, rs, rd).expect("valid parameters")
    }
}

/// Reciprocity eval(k1,k2) == eval(k2,k1). Eq. 10 and 16 are symmetric by construction (F uses
/// k.h, and k1.h = k2.h); the only asymmetry is f64 rounding in forming h and k.h, so the bound
/// is relative 1e-9 (values reach `BRDF_MAX`, about 4e16, at the denominator floor).
#[test]
fn reciprocity() {
    let mut r = Rng(1);
    for _ in 0..200_000 {
        let p = r.model();
        let (k1, k2) = (r.upper(), r.upper());
        let (a, b) = (p.eval(k1, k2), p.eval(k2, k1));
        assert!(
            (a - b).abs() <= 1e-9 * a.abs().max(b.abs()) + 1e-300,
            "{p:?} {k1} {k2}: {a} vs {b}"
        );
    }
}

/// Finite, non-negative, never NaN, and within the bounds stated in the module doc of
/// `texsim::brdf::ashikhmin_shirley` (computed here from the formulas): eval, specular,
/// diffuse, the dot-product form, pdf, pdf_h, sample and sample_h over random and boundary
/// inputs including directions below the horizon, k1 = -k2, h = n, exponents 0 and 1e6.
#[test]
fn finite_non_negative_and_bounded_everywhere() {
    let mut r = Rng(2);
    // Relative slack for the f64 rounding of the products that form each value.
    let tol = 1.0 + 1e-12;
    let mut near_floor = 0;
    for i in 0..300_000 {
        let p = r.model();
        let k1 = if i % 3 == 0 {
            r.sphere_dir()
        } else {
            r.upper()
        };
        let k2 = match i % 5 {
            0 => -k1,
            1 => DVec3::new(-k1.x, -k1.y, k1.z),
            2 => r.sphere_dir(),
            _ => r.upper(),
        };
        let root = ((p.nu + 1.0) * (p.nv + 1.0)).sqrt();
        let spec_max = root / (8.0 * PI * DENOM_FLOOR);
        let diff_max = 28.0 * p.rd * (1.0 - p.rs) / (23.0 * PI);
        let pdf_max = root / (4.0 * PI * (k1 + k2).length());
        let mixture_max = pdf_max + 1.0 / PI;
        let (e, sp, df) = (p.eval(k1, k2), p.specular(k1, k2), p.diffuse(k1, k2));
        let (pd, pm) = (p.pdf(k1, k2), p.pdf_mixture(k1, k2));
        for (what, v, hi) in [
            ("eval", e, spec_max + diff_max),
            ("specular", sp, spec_max),
            ("diffuse", df, diff_max),
            ("pdf", pd, pdf_max),
            ("pdf_mixture", pm, mixture_max),
        ] {
            assert!(
                v.is_finite() && v >= 0.0 && v <= hi * tol,
                "{what} {p:?} {k1} {k2}: {v} (bound {hi})"
            );
        }
        assert!(e <= BRDF_MAX * tol, "{p:?} {k1} {k2}: {e}");
        assert!(sp <= p.specular_max() * tol && df <= p.diffuse_max() * tol);
        if sp > 1e-3 * spec_max {
            near_floor += 1;
        }
        // The dot-product form with arbitrary dots (the float twin's entry point).
        let d = Dots {
            hn: 2.0 * r.unit() - 0.5,
            hu: 2.0 * r.unit() - 1.0,
            hv: 2.0 * r.unit() - 1.0,
            kh: if i % 2 == 0 {
                1e-300 * r.unit()
            } else {
                r.unit()
            },
            nk1: if i % 3 == 0 {
                1e-200 * r.unit()
            } else {
                r.unit()
            },
            nk2: 1.5 * r.unit(),
        };
        let (ds, dd) = p.eval_from_dots(&d);
        assert!(
            ds.is_finite() && ds >= 0.0 && ds <= spec_max * tol,
            "{p:?} {d:?}: {ds}"
        );
        assert!(
            dd.is_finite() && dd >= 0.0 && dd <= diff_max * tol,
            "{p:?} {d:?}: {dd}"
        );
        let xi = [r.unit(), r.unit()];
        let xi = match i % 7 {
            0 => [0.0, 0.0],
            1 => [1.0, 1.0],
            2 => [0.25, 1.0 - 1e-16],
            _ => xi,
        };
        let h = p.sample_h(xi[0], xi[1]);
        assert!(
            h.is_finite() && (h.length() - 1.0).abs() < 1e-12 && h.z >= 0.0,
            "{p:?} {xi:?} {h}"
        );
        let ph = p.pdf_h(h);
        assert!(ph.is_finite() && ph >= 0.0 && ph <= root / (2.0 * PI) * tol);
        if let Some((k, pdf)) = p.sample(k1, xi) {
            assert!(
                k.z > 0.0 && pdf.is_finite() && pdf > 0.0,
                "{p:?} {k1} {k} {pdf}"
            );
        }
    }
    // Random grazing pairs get close to the floor (the bound is not vacuous).
    assert!(near_floor > 100, "{near_floor}");
    // The floor is reached: h = k1 = k2 at 1e-13 degrees above the horizon (k.h = 1,
    // n.k = 1.7e-15 < DENOM_FLOOR), exponents 0 (power 1), Rs = 1 (F = 1).
    let g = dir_from_angles(90.0 - 1e-13, 0.0);
    let p = AshikhminShirley::new(0.0, 0.0, 1.0, 0.0).expect("valid");
    let at = p.specular(g, g);
    assert!(
        (at - 1.0 / (8.0 * PI * DENOM_FLOOR)).abs() <= 1e-12 * at,
        "{at}"
    );
    let p = AshikhminShirley::new(EXPONENT_MAX, EXPONENT_MAX, 1.0, 0.0).expect("valid");
    assert!(
        p.specular_max() <= BRDF_MAX && BRDF_MAX < 4.0e16,
        "{BRDF_MAX}"
    );
    let p = AshikhminShirley::new(0.0, 0.0, 0.0, 1.0).expect("valid");
    assert_eq!(p.eval(DVec3::Z, -DVec3::Z), 0.0, "k1 = -k2");
    let g = dir_from_angles(90.0, 0.0);
    assert_eq!(p.eval(g, g), 0.0, "exactly grazing gives 0");
    assert!(p
        .eval(
            dir_from_angles(90.0 - 1e-14, 0.0),
            dir_from_angles(90.0 - 1e-14, 180.0 - 1e-9)
        )
        .is_finite());
}

/// The dot-product form (the fixed unit's twin) equals the vector form.
#[test]
fn eval_from_dots_matches_eval() {
    let mut r = Rng(3);
    for _ in 0..100_000 {
        let p = r.model();
        let (k1, k2) = (r.upper(), r.upper());
        let v = p.eval(k1, k2);
        let w = Dots::from_dirs(k1, k2).map_or(0.0, |d| {
            let (s, df) = p.eval_from_dots(&d);
            s + df
        });
        assert!((v - w).abs() <= 1e-12 * v, "{v} {w}"); // same formula, same rounding
    }
}

/// At h = n the exponent is 0/0; the limit along any path is a weighted average of nu and nv
/// and the power is exactly 1: the specular value is continuous there.
#[test]
fn h_equals_n_limit() {
    let p = AshikhminShirley::new(10.0, 1000.0, 1.0, 0.0).expect("valid");
    let at = p.eval(DVec3::Z, DVec3::Z);
    // rho_s(n, n) = sqrt(11 * 1001)/(8 pi) * 1 * F(1) / (1 * 1), F(1) = Rs = 1.
    let expect = (11.0f64 * 1001.0).sqrt() / (8.0 * PI);
    assert!((at - expect).abs() < 1e-12 * expect, "{at} {expect}");
    for phi in [0.0, 30.0, 90.0, 200.0] {
        let k = dir_from_angles(1e-6, phi);
        let near = p.eval(k, k);
        assert!((near - at).abs() < 1e-6 * at, "phi {phi}: {near} vs {at}");
        let e = p.exponent(k.x, k.y);
        assert!((10.0..=1000.0).contains(&e));
    }
}

/// Eq. 11 endpoints and eq. 16's constant: with the diffuse term alone, the cosine-weighted
/// integral of eq. 16 over k2 is Rd (1-Rs)(1-(1-n.k1/2)^5) because integral mu(1-(1-mu/2)^5)
/// over [0,1] is 23/56 (checked here by a 2000-point midpoint rule, error < 1e-6).
#[test]
fn fresnel_and_diffuse_constant() {
    let p = AshikhminShirley::new(5.0, 5.0, 0.04, 1.0).expect("valid");
    assert!((p.fresnel_schlick(1.0) - 0.04).abs() < 1e-15);
    assert!((p.fresnel_schlick(0.0) - 1.0).abs() < 1e-15);
    assert!((p.fresnel_schlick(-3.0) - 1.0).abs() < 1e-15);
    let n = 2000;
    let integral: f64 = (0..n)
        .map(|i| {
            let mu = (i as f64 + 0.5) / n as f64;
            mu * (1.0 - (1.0 - mu / 2.0).powi(5)) / n as f64
        })
        .sum();
    assert!((integral - 23.0 / 56.0).abs() < 1e-6, "{integral}");
    let k1 = dir_from_angles(40.0, 0.0);
    let (_, _, d) = p.albedo_quadrature_parts(k1, 4);
    let closed = 0.96 * (1.0 - (1.0 - k1.z / 2.0).powi(5));
    assert!((d - closed).abs() < 1e-12, "{d} {closed}");
}

/// Parameter validation names the field; reports validate and end with the number.
#[test]
fn validation_and_reports() {
    assert!(AshikhminShirley::new(-1.0, 1.0, 0.0, 0.0)
        .err()
        .is_some_and(|e| e.message().contains("'nu'")));
    assert!(AshikhminShirley::new(1.0, f64::NAN, 0.0, 0.0)
        .err()
        .is_some_and(|e| e.message().contains("'nv'")));
    assert!(AshikhminShirley::new(1.0, 1.0, 1.5, 0.0)
        .err()
        .is_some_and(|e| e.message().contains("'rs'")));
    let p = AshikhminShirley::new(100.0, 100.0, 1.0, 0.0).expect("valid");
    let rep = albedo_report(&p, 0.0, None).expect("report");
    let last: f64 = rep
        .lines()
        .last()
        .and_then(|l| l.trim().parse().ok())
        .expect("number on last line");
    assert!(
        (last - p.albedo_quadrature(DVec3::Z, 32)).abs() < 1e-6,
        "{rep}"
    );
    assert!(albedo_report(&p, 90.0, None).is_err());
    assert!(albedo_report(&p, f64::NAN, None).is_err());
    let e = eval_report(&p, DVec3::Z, dir_from_angles(10.0, 0.0), None).expect("report");
    let last: f64 = e
        .lines()
        .last()
        .and_then(|l| l.trim().parse().ok())
        .expect("number");
    assert!((last - p.eval(DVec3::Z, dir_from_angles(10.0, 0.0))).abs() < 1e-5 * last);
    assert!(eval_report(&p, DVec3::ZERO, DVec3::Z, None).is_err());
    let s = sample_report(&p, dir_from_angles(30.0, 0.0), 20_000, 5).expect("report");
    assert!(s.lines().last().is_some_and(|l| l.ends_with("pass")), "{s}");
    assert!(sample_report(&p, -DVec3::Z, 20_000, 5).is_err());
    assert!(sample_report(&p, DVec3::Z, 10, 5).is_err());
}
