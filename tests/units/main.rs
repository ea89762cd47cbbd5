//! Integration tests of the bit-accurate units (`hw_model`) against exact integer models and
//! their float twins: fixed-point rounding and conversion, reciprocal, interpolator, LOD, wrap,
//! filter, modulate, the shading units (vector, rsqrt, pow, frames, Blinn-Phong,
//! Ashikhmin-Shirley, roughness, NDF, Toksvig, LEAN), footprint assembly, the timing model's parts, and the
//! hardware configurations.
//!
//! One file per module below; run one with `cargo test --test units unit_lod::`.

#[path = "../rng_common/mod.rs"]
mod rng_common;
#[path = "../tmp_common/mod.rs"]
mod tmp_common;

mod ndf_common;

mod as_power;
mod brdf_fixed;
mod env_units;
mod f32_units;
mod frames_config;
mod frames_frame;
mod frames_pixel;
mod frames_pow;
mod frames_rsqrt;
mod frames_shade;
mod frames_vector;
mod hw_config;
mod lean_unit;
mod lobe_unit;
mod ndf_unit;
mod roughness_shade;
mod roughness_unit;
mod timing_footprint;
mod timing_units;
mod toksvig_unit;
mod unit_bary_derivs;
mod unit_bary_span;
mod unit_cost;
mod unit_fixed;
mod unit_fixedpoint;
mod unit_interpolator;
mod unit_lod;
mod unit_modulate;
mod unit_reciprocal;
mod unit_trilinear;
mod unit_wrap;
