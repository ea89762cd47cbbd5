//! texsim: a simulator of fixed-function texture and shading hardware.
//!
//! The bit-accurate units live in the integer-only crate [`hw_model`]; this crate holds
//! everything around them: scenes, host-side float map preparation, the scanline rasterizer,
//! the per-material stage pipeline with its fixed and float twins, reports and the CLI.
//!
//! Frame flow: scene -> geometry (float) -> raster (fixed setup + scanline traversal into a
//! visibility buffer) -> per-pixel planned stages (each Fixed or Float) -> images + metrics.
//!
//! # Using texsim from Rust
//!
//! Load or build a [`scene::Scene`], resolve a [`hw_model::HwConfig`] (a preset, a file, or a
//! preset with edited fields), prepare the texture maps and [`render::render`]: the result holds
//! the hardware image, the float reference and every statistic `summary.json` shows.
//!
//! ```
//! use texsim::render::{render, Maps, RenderOptions};
//!
//! let mut sc = texsim::scene::builtin("sphere")?;
//! sc.width = 64;
//! sc.height = 48;
//! texsim::scene::validate(&sc)?;
//! let hw = texsim::hwconfig::resolve("texram16")?;
//! let coarse = texsim::hwconfig::set_field(&hw, "weight_bits", "4")?;
//! let maps = Maps::new(&sc, hw.trilinear.texel_bits);
//! let fine = render(&sc, &maps, &hw, &RenderOptions::default())?;
//! let rough = render(&sc, &maps, &coarse, &RenderOptions::default())?;
//! let rmse = |r: &texsim::render::Rendered| r.stats.error_8bit.as_ref().unwrap().rmse_lsb;
//! assert!(fine.stats.covered_pixels > 0);
//! assert!(rmse(&rough) >= rmse(&fine));
//! # Ok::<(), texsim::Error>(())
//! ```
//!
//! Memory is budgeted ([`budget`]): [`render::render`] refuses a run whose estimate exceeds
//! the limit before it allocates; raise it with [`budget::set_max_memory`]. Library code never
//! prints; warnings about results come back in `RenderStats::warnings`.

pub mod brdf;
pub mod budget;
pub mod cli;
pub mod compare;
pub mod error;
pub mod filters;
pub mod fit_cmd;
pub mod fixedpoint;
pub mod flip;
pub mod footprint_ref;
pub mod hwconfig;
pub mod maps;
pub mod pareto;
pub mod pipeline;
mod prefetch;
pub mod probe;
pub mod provenance;
pub mod raster;
pub mod reference;
pub mod render;
pub mod report;
pub mod rng;
pub mod scene;
pub mod shading;
pub mod summary;
pub mod sweep_plan;
pub mod sweep_shard;
pub mod timing;
pub mod tune;
pub mod tune_cli;
pub mod vectors;
pub mod warnings;

/// The tests' shared seeded generator (splitmix64), the one the test binaries use.
#[cfg(test)]
#[path = "../tests/rng_common/mod.rs"]
mod rng_common;

pub use error::{Error, Result};
