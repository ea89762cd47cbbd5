//! Shared helpers of the NDF tests: a seeded PRNG and random moment texels.
#![allow(dead_code)]

use hw_model::config::HwConfig;
use hw_model::ndf::{NdfConfig, NdfTexels, NdfUnit};
use hw_model::rsqrt::RsqrtConfig;
use texsim::shading::ndf::{quantize_texel, Moments};

pub use crate::rng_common::Rng;

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
