//! Integration tests of whole frames (`texsim::raster`, `texsim::pipeline`, `texsim::render`,
//! `texsim::timing`): rasterization (fill rule, watertightness, robustness, thread counts),
//! each effect through the pipeline (plain, bumps, roughness, NDF, Ashikhmin-Shirley) fixed
//! against float, their hard cases, determinism, and the golden cycle counts.
//!
//! One file per module below; run one with `cargo test --test pipeline timing_golden::`.

#[path = "../rng_common/mod.rs"]
mod rng_common;
#[path = "../tmp_common/mod.rs"]
mod tmp_common;

mod raster_common;

mod as_hard_cases;
mod as_pipeline;
mod bary_edges;
mod bump_hard_cases;
mod bump_pipeline;
mod coord_f32_path;
mod determinism;
mod env_scene;
mod lobe_fit_pipeline;
mod lobe_pipeline;
mod ndf_pipeline;
mod range_instrumentation;
mod raster_parallel;
mod raster_robust;
mod raster_rules;
mod raster_watertight;
mod render_pipeline;
mod roughness_scene;
mod span_stages;
mod timing_golden;
mod toksvig_pipeline;
mod tune_search;
