//! Integration tests of the float shading models and the maps they read (`texsim::brdf`,
//! `texsim::shading`, `texsim::maps`): the Ashikhmin-Shirley reference (properties, albedo,
//! sampler, sphere grids), NDF moment maps, the roughness pyramid, bump-map preparation and
//! tangent generation.
//!
//! One file per module below; run one with `cargo test --test shading brdf_props::`.

#[path = "../rng_common/mod.rs"]
mod rng_common;
#[path = "../tmp_common/mod.rs"]
mod tmp_common;

mod brdf_albedo;
mod brdf_props;
mod brdf_sampling;
mod brdf_spheres;
mod fournier_fit;
mod frames_bump;
mod frames_tangents;
mod ndf_maps;
mod roughness_pyramid;
