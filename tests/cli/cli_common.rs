//! Shared helpers of the command-line tests: run the binary, a scratch directory, its output.
#![allow(dead_code)]

use crate::tmp_common::TmpDir;
use std::path::Path;
use std::process::{Command, Output};

/// Runs the `texsim` binary with `args` in `cwd`.
pub fn texsim(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_texsim"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("run texsim")
}

/// A fresh, empty scratch directory of the calling test ([`TmpDir`]), named after `name`.
#[track_caller]
pub fn tmp(name: &str) -> TmpDir {
    TmpDir::new(name)
}

/// Standard output followed by standard error.
pub fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}
