//! Integration tests of the `texsim` binary as users and scripts run it: every subcommand's
//! exit codes, files and messages (render, scenes, sweep, cycles, brdf, the bump, roughness and
//! NDF options, vectors and the SystemVerilog lerp, compare).
//!
//! One file per module below; run one with `cargo test --test cli timing_cli::`.

mod cli_common;
#[path = "../tmp_common/mod.rs"]
mod tmp_common;

mod as_cli;
mod budget_cli;
mod bump_cli;
mod cli;
mod filters_cli;
mod fournier_cli;
mod ndf_cli;
mod report_cli;
mod roughness_cli;
mod sweep_usability;
mod timing_cli;
mod tune_cli;
mod vectors_cli;
