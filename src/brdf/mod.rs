//! The Ashikhmin-Shirley anisotropic Phong BRDF (Ashikhmin & Shirley, "An Anisotropic Phong
//! Light Reflection Model", 2000): the float reference with its sampler and albedo integrators
//! ([`ashikhmin_shirley`]), the float<->fixed bridge to the bit-accurate unit
//! `hw_model::aniso_phong` ([`fixed_twin`]) and the text reports behind `texsim brdf` ([`report`]).

pub mod ashikhmin_shirley;
pub mod fixed_twin;
pub mod report;
pub mod spheres;
pub mod stats;

pub use ashikhmin_shirley::{dir_from_angles, AshikhminShirley, Dots, McAlbedo, SplitMix64};
pub use report::{albedo_report, eval_report, sample_report};
