//! Integration tests of what goes in and what comes out (`texsim::scene`, `texsim::report`):
//! scene loading (TOML, OBJ + MTL, the built-in catalogue, textures, MIP chains, the Mesa
//! anchors), bad input and validation, and the reports (PNG, metrics, output sets).
//!
//! One file per module below; run one with `cargo test --test scenes scene_load::`.

#[path = "../rng_common/mod.rs"]
mod rng_common;
#[path = "../tmp_common/mod.rs"]
mod tmp_common;

mod bad_input_files;
mod bad_input_validate;
mod bump_scene;
mod env_scene;
mod float_passes;
mod report_flip;
mod report_images;
mod report_metrics;
mod report_output;
mod report_pareto;
mod scene_anchor_coverage;
mod scene_load;
mod scene_mip;
