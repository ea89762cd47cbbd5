//! texsim: a simulator of fixed-function texture and shading hardware.
//!
//! The bit-accurate units live in the integer-only crate [`hw_model`]; this crate holds
//! everything around them: scenes, host-side float map preparation, the scanline rasterizer,
//! the per-material stage pipeline with its fixed and float twins, reports and the CLI.
//!
//! Frame flow: scene -> geometry (float) -> raster (fixed setup + scanline traversal into a
//! visibility buffer) -> per-pixel planned stages (each Fixed or Float) -> images + metrics.

pub mod brdf;
pub mod cli;
pub mod error;
pub mod fixedpoint;
pub mod footprint_ref;
pub mod hwconfig;
pub mod maps;
pub mod pipeline;
pub mod probe;
pub mod raster;
pub mod reference;
pub mod render;
pub mod report;
pub mod scene;
pub mod shading;
pub mod summary;
pub mod timing;

pub use error::{Error, Result};
