//! Shared helpers of the NDF tests: a seeded PRNG and random moment texels.
#![allow(dead_code)]

use glam::DVec3;
use hw_model::config::HwConfig;
use hw_model::ndf::{NdfConfig, NdfTexels, NdfUnit};
use hw_model::rsqrt::RsqrtConfig;
use texsim::shading::ndf::{quantize_texel, Moments};

pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    pub fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn normal(&mut self) -> f64 {
        let u = self.unit().max(1e-300);
        let v = self.unit();
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    }
    /// A unit vector within `max_tilt` radians of +z.
    pub fn tilted(&mut self, max_tilt: f64) -> DVec3 {
        let c = 1.0 - self.unit() * (1.0 - max_tilt.cos());
        let s = (1.0 - c * c).max(0.0).sqrt();
        let p = 2.0 * std::f64::consts::PI * self.unit();
        DVec3::new(s * p.cos(), s * p.sin(), c)
    }
}

pub fn unit(cfg: &NdfConfig) -> NdfUnit {
    NdfUnit::new(
        cfg,
        &HwConfig::texram16().reciprocal,
        &RsqrtConfig::texram16(),
    )
    .expect("valid config")
}

/// Quantizes moments into the unit's texels (norm channel from `inv_z`, `norm_exp`).
pub fn texels(m: &Moments, cfg: &NdfConfig, inv_z: f64, norm_exp: u32) -> NdfTexels {
    quantize_texel(m, cfg, inv_z, norm_exp)
}

/// A random mixture of 1..=4 base lobes: tilts up to 60 degrees, shininess 2^(0..12).
pub fn random_moments(r: &mut Rng) -> Moments {
    let k = 1 + (r.next() % 4) as usize;
    let s = (r.unit() * 12.0).exp2();
    let mut acc = Moments::default();
    for _ in 0..k {
        let m = Moments::from_normal(r.tilted(1.05), s);
        acc.mu += m.mu / k as f64;
        for i in 0..6 {
            acc.e[i] += m.e[i] / k as f64;
        }
    }
    acc
}
