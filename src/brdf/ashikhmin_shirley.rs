//! Float (f64) reference of the Ashikhmin-Shirley anisotropic Phong BRDF (Ashikhmin & Shirley
//! 2000): specular lobe eq. 10 in the trigonometry-free form of eq. 18, Schlick Fresnel eq. 11,
//! the coupled non-Lambertian diffuse term eq. 16, the half-vector sampler of eqs. 19-22 with its
//! density eqs. 5 and 20, and deterministic / Monte Carlo directional albedo (eq. 6).
//!
//! Everything is in the LOCAL shading frame: `n = +z`, `u = +x`, `v = +y`. Directions point
//! away from the surface (`k1` toward the light, `k2` toward the viewer) and are unit vectors.
//!
//! Notes on the equations (checked against the paper text and verified by the tests):
//! - Eq. 18 divides by `1 - (h.n)^2`; for a unit `h` that equals `s = (h.u)^2 + (h.v)^2`, which
//!   we use instead: it has no cancellation as `h -> n`, and it makes the exponent a weighted
//!   average of `nu` and `nv`, so the `0/0` at `h = n` has the limit "any value in
//!   `[min(nu,nv), max(nu,nv)]`", and `(n.h)^E = 1` there whichever value is taken. Likewise
//!   the power is evaluated as `(n.h)^E = (1 - s)^(E/2)` (identical for a unit `h`), which keeps
//!   full relative precision for narrow lobes and is what the fixed unit computes.
//! - Eq. 5 is the EXACT density of the sampler of eqs. 21-22 (not only an approximation): the
//!   Jacobian of eq. 21 gives `p(phi) = sqrt((nu+1)(nv+1)) / (2 pi ((nu+1)cos^2 + (nv+1)sin^2))`
//!   and eq. 22 gives `(E+1) cos^E theta` in `cos theta`; their product cancels `E + 1`.
//!   `tests/shading/brdf_sampling.rs` verifies it by quadrature (integral = 1) and by chi-square.
//! - The quadrant mapping of the text ("phi(1 - 4(0.5 - xi1))" then flip about pi/2) is
//!   implemented in the monotone form `phi = pi - phi'(4(0.5 - xi1))` for `xi1 in [0.25, 0.5)`
//!   (and likewise for the other quadrants), so that `phi(xi1)` is continuous and increasing:
//!   the density is the same either way, but stratification of `xi1` is preserved.
//! - Eq. 16's constant: `integral_0^1 mu (1 - (1 - mu/2)^5) dmu = 23/56`, so `28/(23 pi)` makes
//!   the diffuse albedo exactly `Rd (1 - Rs) (1 - (1 - (n.k1)/2)^5)`; verified by quadrature.
//!
//! Guards: directions at or below the horizon give 0; `k1 = -k2` (no halfway vector) gives 0;
//! the specular denominator `(h.k) max(n.k1, n.k2)` is floored at [`DENOM_FLOOR`] so the value
//! stays finite at grazing (the true lobe is unbounded there only for exponents below 1).
//!
//! Bounds (asserted by `tests/shading/brdf_props.rs` over random and boundary inputs, and reached: the
//! floor is hit at grazing with `h = k1 = k2`): for every input, including the dot-product form
//! [`AshikhminShirley::eval_from_dots`] with any dots,
//! - `0 <= rho_s <= sqrt((nu+1)(nv+1)) / (8 pi DENOM_FLOOR)` (power and Fresnel are in
//!   `[0, 1]`), at most `3.98e16` for exponents up to [`EXPONENT_MAX`];
//! - `0 <= rho_d <= 28 Rd (1 - Rs) / (23 pi) <= 0.388`;
//! - `0 <= pdf(k1, k2) <= sqrt((nu+1)(nv+1)) / (4 pi |k1 + k2|)` (eq. 20 with
//!   `k1.h = |k1 + k2| / 2`; finite because a halfway vector needs `|k1 + k2| > 1e-300`), and
//!   `0 <= pdf_h <= sqrt((nu+1)(nv+1)) / (2 pi)`.
//!
//! [`BRDF_MAX`] is the largest of these bounds on `rho`.

// `!(x > 0.0)` is used on purpose: it is true for NaN, which must take the guarded path.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use crate::error::{Error, Result};
pub use crate::rng::SplitMix64;
use glam::DVec3;
use std::f64::consts::PI;

/// Floor of the specular denominator `(h.k) max(n.k1, n.k2)`: keeps every value finite at
/// grazing. Only directions within ~1e-12 rad of the horizon are affected.
pub const DENOM_FLOOR: f64 = 1.0e-12;

/// Largest accepted Phong exponent.
pub const EXPONENT_MAX: f64 = 1.0e6;

impl AshikhminShirley {
    /// Upper bound of [`AshikhminShirley::specular`] (and of the specular part of
    /// [`AshikhminShirley::eval_from_dots`]) for these parameters: the denominator floor with
    /// power and Fresnel at 1 (module doc, "Bounds").
    #[must_use]
    pub fn specular_max(&self) -> f64 {
        ((self.nu + 1.0) * (self.nv + 1.0)).sqrt() / (8.0 * PI * DENOM_FLOOR)
    }

    /// Upper bound of [`AshikhminShirley::diffuse`]: `28 Rd (1 - Rs) / (23 pi)` (eq. 16 with
    /// both `n.k` at 1).
    #[must_use]
    pub fn diffuse_max(&self) -> f64 {
        28.0 * self.rd * (1.0 - self.rs) / (23.0 * PI)
    }
}

/// Largest value of `rho` for any valid parameters and directions: the specular bound at
/// `nu = nv = EXPONENT_MAX` plus the largest diffuse value (about `3.98e16`).
pub const BRDF_MAX: f64 = (EXPONENT_MAX + 1.0) / (8.0 * PI * DENOM_FLOOR) + 28.0 / (23.0 * PI);

/// Parameters of the model: Phong exponents along `u` and `v`, normal-incidence specular
/// reflectance `Rs` (eq. 11) and diffuse albedo `Rd` (eq. 16).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AshikhminShirley {
    /// Exponent along the tangent `u` (x).
    pub nu: f64,
    /// Exponent along the bitangent `v` (y).
    pub nv: f64,
    /// Specular reflectance at normal incidence, in [0, 1].
    pub rs: f64,
    /// Diffuse albedo of the substrate, in [0, 1].
    pub rd: f64,
}

/// The dot products one BRDF evaluation needs: `h.n, h.u, h.v, k.h, n.k1, n.k2`.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Dots {
    /// `h . n` (cosine of the half-vector with the normal).
    pub hn: f64,
    /// `h . u`.
    pub hu: f64,
    /// `h . v`.
    pub hv: f64,
    /// `k . h` (= `k1.h` = `k2.h`).
    pub kh: f64,
    /// `n . k1`.
    pub nk1: f64,
    /// `n . k2`.
    pub nk2: f64,
}

impl Dots {
    /// The dot products of a direction pair in the local frame; `None` when there is no
    /// halfway vector (`k1 = -k2`) or a direction is at or below the horizon.
    #[must_use]
    pub fn from_dirs(k1: DVec3, k2: DVec3) -> Option<Dots> {
        if k1.z <= 0.0 || k2.z <= 0.0 {
            return None;
        }
        let h = halfway(k1, k2)?;
        Some(Dots {
            hn: h.z,
            hu: h.x,
            hv: h.y,
            kh: k1.dot(h),
            nk1: k1.z,
            nk2: k2.z,
        })
    }
}

/// Monte Carlo albedo estimate with its standard error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct McAlbedo {
    /// Sample mean of `rho cos / pdf`.
    pub albedo: f64,
    /// Standard error of the mean.
    pub std_error: f64,
    /// Fraction of samples that produced a direction above the horizon.
    pub valid_fraction: f64,
}

/// Unit direction from polar angle `theta_deg` (from `n`) and azimuth `phi_deg` (from `u`).
#[must_use]
pub fn dir_from_angles(theta_deg: f64, phi_deg: f64) -> DVec3 {
    let (st, ct) = theta_deg.to_radians().sin_cos();
    let (sp, cp) = phi_deg.to_radians().sin_cos();
    DVec3::new(st * cp, st * sp, ct)
}

/// Normalized `k1 + k2`, or `None` when it vanishes (`k1 = -k2`).
#[must_use]
fn halfway(k1: DVec3, k2: DVec3) -> Option<DVec3> {
    let s = k1 + k2;
    let len = s.length();
    if !(len > 1.0e-300) || !len.is_finite() {
        return None;
    }
    Some(s / len)
}

/// `(1 - x)^5`.
#[must_use]
fn pow5_one_minus(x: f64) -> f64 {
    let y = 1.0 - x;
    let y2 = y * y;
    y2 * y2 * y
}

/// Nodes and weights of 4-point Gauss-Legendre on [0, 1].
const GL4: [(f64, f64); 4] = [
    (0.069_431_844_202_973_71, 0.173_927_422_568_726_93),
    (0.330_009_478_207_571_9, 0.326_072_577_431_273_07),
    (0.669_990_521_792_428_1, 0.326_072_577_431_273_07),
    (0.930_568_155_797_026_3, 0.173_927_422_568_726_93),
];

impl AshikhminShirley {
    /// Validated parameters: exponents finite in `[0, 1e6]`, `Rs` and `Rd` in `[0, 1]`.
    pub fn new(nu: f64, nv: f64, rs: f64, rd: f64) -> Result<Self> {
        for (name, v, hi) in [
            ("nu", nu, EXPONENT_MAX),
            ("nv", nv, EXPONENT_MAX),
            ("rs", rs, 1.0),
            ("rd", rd, 1.0),
        ] {
            if !v.is_finite() || v < 0.0 || v > hi {
                return Err(Error::field(name, format!("{v} is not in [0, {hi}]")));
            }
        }
        Ok(Self { nu, nv, rs, rd })
    }

    /// Normalization of eq. 5: `sqrt((nu+1)(nv+1)) / (2 pi)`.
    #[must_use]
    pub fn ph_norm(&self) -> f64 {
        ((self.nu + 1.0) * (self.nv + 1.0)).sqrt() / (2.0 * PI)
    }

    /// Exponent `(nu hu^2 + nv hv^2) / (hu^2 + hv^2)` (eq. 18; see the module notes). At
    /// `h = n` (0/0) returns `(nu + nv) / 2`; the power is 1 there whatever the exponent.
    #[must_use]
    pub fn exponent(&self, hu: f64, hv: f64) -> f64 {
        let (a, b) = (hu * hu, hv * hv);
        let s = a + b;
        if !(s > 0.0) {
            return 0.5 * (self.nu + self.nv);
        }
        let t = (a / s).clamp(0.0, 1.0);
        self.nv + (self.nu - self.nv) * t
    }

    /// `(n.h)^E`, evaluated as `(1 - s)^(E/2)` with `s = hu^2 + hv^2` (equal for a unit `h`;
    /// this is also the fixed unit's formula, so the twin sees the same function of the
    /// quantized dot products). 1 at `h = n` and for `E = 0` (`0^0 = 1`); 0 for `h.n <= 0`
    /// unless `E = 0`.
    #[must_use]
    pub fn lobe_power(&self, hn: f64, hu: f64, hv: f64) -> f64 {
        let e = self.exponent(hu, hv);
        if e == 0.0 {
            return 1.0;
        }
        if !(hn > 0.0) {
            return 0.0;
        }
        let s = hu * hu + hv * hv;
        if !(s > 0.0) {
            return 1.0;
        }
        if s >= 1.0 {
            return 0.0;
        }
        (0.5 * e * (-s).ln_1p()).exp()
    }

    /// Half-vector density of eq. 5 (per steradian of `h`); 0 below the horizon.
    #[must_use]
    pub fn pdf_h(&self, h: DVec3) -> f64 {
        if !(h.z > 0.0) {
            return 0.0;
        }
        self.ph_norm() * self.lobe_power(h.z, h.x, h.y)
    }

    /// Schlick's Fresnel approximation, eq. 11: `Rs + (1 - Rs)(1 - cos)^5`, `cos` clamped to
    /// `[0, 1]`.
    #[must_use]
    pub fn fresnel_schlick(&self, cos: f64) -> f64 {
        let c = if cos.is_nan() {
            0.0
        } else {
            cos.clamp(0.0, 1.0)
        };
        self.rs + (1.0 - self.rs) * pow5_one_minus(c)
    }

    /// Specular term from dot products (eq. 18), without the hemisphere checks.
    #[must_use]
    fn specular_dots(&self, d: &Dots) -> f64 {
        let p = self.lobe_power(d.hn, d.hu, d.hv);
        let m = d.nk1.max(d.nk2);
        let denom = (d.kh * m).max(DENOM_FLOOR);
        let c = ((self.nu + 1.0) * (self.nv + 1.0)).sqrt() / (8.0 * PI);
        c * p * self.fresnel_schlick(d.kh) / denom
    }

    /// Diffuse term from `n.k1`, `n.k2` (eq. 16), without the hemisphere checks.
    #[must_use]
    fn diffuse_dots(&self, nk1: f64, nk2: f64) -> f64 {
        let f = |c: f64| 1.0 - pow5_one_minus(0.5 * c.clamp(0.0, 1.0));
        28.0 * self.rd / (23.0 * PI) * (1.0 - self.rs) * f(nk1) * f(nk2)
    }

    /// Specular BRDF `rho_s(k1, k2)`, eq. 10/18 (per steradian). 0 unless both directions are
    /// strictly above the horizon.
    #[must_use]
    pub fn specular(&self, k1: DVec3, k2: DVec3) -> f64 {
        Dots::from_dirs(k1, k2).map_or(0.0, |d| self.specular_dots(&d))
    }

    /// Diffuse BRDF `rho_d(k1, k2)`, eq. 16. 0 unless both directions are above the horizon.
    #[must_use]
    pub fn diffuse(&self, k1: DVec3, k2: DVec3) -> f64 {
        if !(k1.z > 0.0 && k2.z > 0.0) {
            return 0.0;
        }
        self.diffuse_dots(k1.z, k2.z)
    }

    /// Full BRDF, eq. 17: specular + diffuse.
    #[must_use]
    pub fn eval(&self, k1: DVec3, k2: DVec3) -> f64 {
        self.specular(k1, k2) + self.diffuse(k1, k2)
    }

    /// The BRDF from precomputed dot products (the float twin of `hw_model::aniso_phong`):
    /// returns `(specular, diffuse)`. Zero when `h.n <= 0`, `k.h <= 0`, or `n.k1`/`n.k2 <= 0`.
    #[must_use]
    pub fn eval_from_dots(&self, d: &Dots) -> (f64, f64) {
        if !(d.hn > 0.0 && d.kh > 0.0 && d.nk1 > 0.0 && d.nk2 > 0.0) {
            return (0.0, 0.0);
        }
        (self.specular_dots(d), self.diffuse_dots(d.nk1, d.nk2))
    }

    /// Azimuth of eq. 21 for `x in [0, 1]` (first quadrant), computed without `tan(pi/2)`.
    #[must_use]
    fn phi_first_quadrant(&self, x: f64) -> f64 {
        let a = ((self.nu + 1.0) / (self.nv + 1.0)).sqrt();
        let (s, c) = (0.5 * PI * x).sin_cos();
        (a * s).atan2(c)
    }

    /// Half vector from two uniforms (eqs. 21-22 with the four-quadrant mapping of `xi1`).
    #[must_use]
    pub fn sample_h(&self, xi1: f64, xi2: f64) -> DVec3 {
        let xi1 = if xi1.is_nan() {
            0.0
        } else {
            xi1.clamp(0.0, 1.0)
        };
        let xi2 = if xi2.is_nan() {
            0.0
        } else {
            xi2.clamp(0.0, 1.0)
        };
        let x = 4.0 * xi1;
        let q = (x.floor() as u32).min(3);
        let t = x - f64::from(q);
        let phi = match q {
            0 => self.phi_first_quadrant(t),
            1 => PI - self.phi_first_quadrant(1.0 - t),
            2 => PI + self.phi_first_quadrant(t),
            _ => 2.0 * PI - self.phi_first_quadrant(1.0 - t),
        };
        let (sp, cp) = phi.sin_cos();
        let e = self.nu * cp * cp + self.nv * sp * sp;
        // cos(theta) = (1 - xi2)^(1/(e+1)) via logs, so sin(theta) keeps full precision.
        let l = (-xi2).ln_1p() / (e + 1.0);
        let (cos_t, sin_t) = if l == f64::NEG_INFINITY {
            (0.0, 1.0)
        } else {
            (l.exp(), (-(2.0 * l).exp_m1()).max(0.0).sqrt())
        };
        DVec3::new(sin_t * cp, sin_t * sp, cos_t)
    }

    /// Samples `k2` by reflecting `k1` about a sampled half vector (eq. 19). Returns the
    /// direction and its density [`Self::pdf`], or `None` when `k2` falls at or below the
    /// horizon (the paper's zero-weight sample) or `k1` is not above it.
    #[must_use]
    pub fn sample(&self, k1: DVec3, xi: [f64; 2]) -> Option<(DVec3, f64)> {
        self.sample_sphere(k1, xi).filter(|(k2, _)| k2.z > 0.0)
    }

    /// Like [`Self::sample`] but keeps directions below the horizon: the reflected direction
    /// over the whole sphere with its density [`Self::pdf`] (`None` only if `k1` is not above
    /// the horizon or the density is 0 or not finite).
    #[must_use]
    pub fn sample_sphere(&self, k1: DVec3, xi: [f64; 2]) -> Option<(DVec3, f64)> {
        if !(k1.z > 0.0) {
            return None;
        }
        let h = self.sample_h(xi[0], xi[1]);
        let kh = k1.dot(h);
        let k2 = (2.0 * kh * h - k1).normalize_or_zero();
        // Eq. 20 at the sampled h (equal to `self.pdf(k1, k2)`, which re-derives h from k2).
        let pdf = if kh.abs() > 0.0 {
            self.pdf_h(h) / (4.0 * kh.abs())
        } else {
            0.0
        };
        if pdf > 0.0 && pdf.is_finite() {
            Some((k2, pdf))
        } else {
            None
        }
    }

    /// Density of the reflected direction `k2` over the WHOLE sphere (eq. 20): `p_h(h) /
    /// (4 |k1.h|)` with `h = +-normalize(k1 + k2)` taken in the upper hemisphere. It integrates
    /// to 1 over the sphere; the part below the horizon is the probability of `sample`
    /// returning `None`. 0 for `k2 = -k1` (a measure-zero point) and when `k1` is below.
    #[must_use]
    pub fn pdf(&self, k1: DVec3, k2: DVec3) -> f64 {
        if !(k1.z > 0.0) {
            return 0.0;
        }
        let Some(mut h) = halfway(k1, k2) else {
            return 0.0;
        };
        if h.z < 0.0 {
            h = -h;
        }
        let kh = k1.dot(h).abs();
        if !(kh > 0.0) {
            return 0.0;
        }
        self.pdf_h(h) / (4.0 * kh)
    }

    /// Directional albedo `R(k1)` (eq. 6) by deterministic quadrature; also returns its
    /// specular and diffuse parts as `(total, specular, diffuse)`.
    ///
    /// Specular part: the integrand is importance-transformed to the sampler's unit square,
    /// where it is `F(k.h) (n.k2) / max(n.k1, n.k2)` (bounded by 1, continuous, kinks at the
    /// horizon and at `n.k2 = n.k1`), and integrated by 4x4-point Gauss-Legendre on a
    /// `4 res x res` grid of cells aligned with the quadrants of `xi1`. Diffuse part: eq. 16 is
    /// a degree-6 polynomial in `n.k2` and independent of azimuth, so Gauss-Legendre in `n.k2`
    /// is exact. Accuracy (measured in `tests/shading/brdf_albedo.rs` against `res = 64` and against the
    /// closed form at normal incidence), for exponents 0..1e5, anisotropy up to 1e4 and
    /// `theta <= 89` deg: |error| < 3e-4 at `res = 32` (worst measured 1.2e-4), < 5e-3 at
    /// `res = 6` (worst 3.5e-3, only at 89 deg with exponents <= 1). Cost: `64 res^2` BRDF
    /// evaluations.
    #[must_use]
    pub fn albedo_quadrature_parts(&self, k1: DVec3, res: usize) -> (f64, f64, f64) {
        let (s, d) =
            self.albedo_quadrature_with(k1, res, &mut |k2| self.specular(k1, k2), &mut |k2| {
                self.diffuse(k1, k2)
            });
        (s + d, s, d)
    }

    /// The quadrature of [`Self::albedo_quadrature_parts`] applied to any specular and diffuse
    /// BRDF pair (e.g. a fixed-point unit): returns `(specular albedo, diffuse albedo)`. The
    /// specular integrand is `spec(k2) cos / pdf` on this model's sampler grid; the diffuse one
    /// must be azimuth-independent and is integrated by `res` Gauss-Legendre cells in `n.k2`.
    pub fn albedo_quadrature_with(
        &self,
        k1: DVec3,
        res: usize,
        spec: &mut dyn FnMut(DVec3) -> f64,
        diffuse: &mut dyn FnMut(DVec3) -> f64,
    ) -> (f64, f64) {
        if !(k1.z > 0.0) {
            return (0.0, 0.0);
        }
        let res = res.max(1);
        let cell = 1.0 / (4 * res) as f64;
        let cell2 = 1.0 / res as f64;
        let mut s = 0.0;
        for i in 0..4 * res {
            let x0 = i as f64 * cell;
            let mut col = 0.0;
            for j in 0..res {
                let y0 = j as f64 * cell2;
                for (gx, wx) in GL4 {
                    for (gy, wy) in GL4 {
                        if let Some((k2, pdf)) = self.sample(k1, [x0 + gx * cell, y0 + gy * cell2])
                        {
                            col += wx * wy * spec(k2) * k2.z / pdf;
                        }
                    }
                }
            }
            s += col;
        }
        s *= cell * cell2;
        let mut d = 0.0;
        for j in 0..res {
            for (g, w) in GL4 {
                // Azimuth-independent: integral = 2 pi * integral_0^1 rho_d(mu) mu dmu.
                let mu = (j as f64 + g) * cell2;
                let k2 = DVec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
                d += w * cell2 * diffuse(k2) * mu;
            }
        }
        (s, 2.0 * PI * d)
    }

    /// Total directional albedo by quadrature (see [`Self::albedo_quadrature_parts`]).
    #[must_use]
    pub fn albedo_quadrature(&self, k1: DVec3, res: usize) -> f64 {
        self.albedo_quadrature_parts(k1, res).0
    }

    /// Probability of choosing the specular lobe in [`Self::albedo_mc`]'s mixture sampler.
    #[must_use]
    fn lobe_choice(&self, k1: DVec3) -> f64 {
        let r = self.rs + (1.0 - self.rs) * pow5_one_minus(0.5 * k1.z.clamp(0.0, 1.0));
        let d = self.rd * (1.0 - r);
        if d <= 0.0 {
            1.0
        } else {
            (r / (r + d)).clamp(0.1, 0.9)
        }
    }

    /// Density of the mixture sampler used by [`Self::albedo_mc`]: specular lobe (eq. 20) with
    /// probability `a`, cosine-weighted hemisphere otherwise (the paper's Section 4 choice).
    #[must_use]
    pub fn pdf_mixture(&self, k1: DVec3, k2: DVec3) -> f64 {
        let a = self.lobe_choice(k1);
        let cosine = if k2.z > 0.0 { k2.z / PI } else { 0.0 };
        a * self.pdf(k1, k2) + (1.0 - a) * cosine
    }

    /// Directional albedo by importance-sampled Monte Carlo (mixture of the specular sampler
    /// and cosine sampling, weighted by [`Self::pdf_mixture`]); deterministic for a seed.
    #[must_use]
    pub fn albedo_mc(&self, k1: DVec3, samples: usize, seed: u64) -> McAlbedo {
        let mut rng = SplitMix64(seed);
        let a = self.lobe_choice(k1);
        let (mut sum, mut sum2, mut valid) = (0.0, 0.0, 0usize);
        let n = samples.max(1);
        for _ in 0..n {
            let (c, x1, x2) = (rng.next_f64(), rng.next_f64(), rng.next_f64());
            let k2 = if c < a {
                self.sample(k1, [x1, x2]).map(|s| s.0)
            } else {
                let r = x2.sqrt();
                let (s, co) = (2.0 * PI * x1).sin_cos();
                let z = (1.0 - x2).max(0.0).sqrt();
                (z > 0.0).then_some(DVec3::new(r * co, r * s, z))
            };
            let w = match k2 {
                Some(k2) => {
                    let p = self.pdf_mixture(k1, k2);
                    if p > 0.0 {
                        valid += 1;
                        self.eval(k1, k2) * k2.z / p
                    } else {
                        0.0
                    }
                }
                None => 0.0,
            };
            sum += w;
            sum2 += w * w;
        }
        let nf = n as f64;
        let mean = sum / nf;
        let var = (sum2 / nf - mean * mean).max(0.0);
        McAlbedo {
            albedo: mean,
            std_error: (var / (nf - 1.0).max(1.0)).sqrt(),
            valid_fraction: valid as f64 / nf,
        }
    }
}
