//! Bit-accurate, integer-only models of texture and shading hardware units.
//!
//! Each unit is one file and a pure function of (inputs, unit config) -> outputs, with its cost
//! and its datapath ([`datapath`]: components, delay, latency, area) beside it. Every
//! intermediate lands in a declared [`fixed::Format`]; rounding goes through the one routine
//! [`fixed::round_shift_right`]; overflow is saturated or wrapped as the format says,
//! and each event is counted in a [`fixed::SatCounter`]. No floating point anywhere in this crate
//! (`clippy::float_arithmetic` is denied); conversions to and from float live in `texsim`.
#![deny(clippy::float_arithmetic)]

pub mod aniso_phong;
pub mod blinn_phong;
pub mod config;
pub mod cost;
pub mod cube_face;
pub mod datapath;
pub mod env_config;
pub mod env_lod;
pub mod f32_add;
pub mod f32_convert;
pub mod f32_div;
pub mod f32_fma;
pub mod f32_mul;
pub mod f32_pack;
pub mod fixed;
pub mod footprint;
pub mod frame;
pub mod interpolator;
pub mod isa;
pub mod lean;
pub mod lod;
pub mod modulate;
pub mod multi_lobe;
pub mod ndf;
pub mod pow;
pub mod reciprocal;
pub mod reflect;
pub mod roughness;
pub mod rsqrt;
pub mod timing_config;
pub mod toksvig;
pub mod trilinear;
pub mod vector;
pub mod wrap;

pub use config::{ConfigError, HwConfig};
pub use cost::UnitCost;
pub use fixed::{Format, Overflow, Rounding, SatCounter};
pub use isa::{vector_batches, vector_isa, VectorIsa};

/// The seeded generator of the unit tests (splitmix64, as `tests/rng_common`).
#[cfg(test)]
pub(crate) mod test_rng {
    /// Splitmix64: the next value of the sequence seeded by `*s`.
    pub fn splitmix64(s: &mut u64) -> u64 {
        *s = s.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = *s;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
}
