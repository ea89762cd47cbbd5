//! Bump mapping and per-pixel shading, host side: the float twins of the fixed-point units in
//! `hw_model::{rsqrt, vector, frame, pow, blinn_phong}` (Schilling 1997, "Antialiasing of
//! Bump-Maps", local coordinate systems; Blinn-Phong), bump-map preparation and tangent
//! generation.

pub mod bump;
pub mod env;
pub mod fournier_fit;
pub mod lean;
pub mod multi_lobe;
pub mod ndf;
pub mod reference;
pub mod roughness;
pub mod tangents;
pub mod toksvig;
