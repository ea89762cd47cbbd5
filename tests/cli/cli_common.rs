//! Shared helpers of the command-line tests: run the binary, a fresh temp dir, its output.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the `texsim` binary with `args` in `cwd`.
pub fn texsim(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_texsim"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("run texsim")
}

/// A fresh, empty directory private to this test binary, process, calling file and `name`
/// (the test files of one binary share a process: `render` in `cli.rs` and in `bump_cli.rs`
/// are two directories).
#[track_caller]
pub fn tmp(name: &str) -> PathBuf {
    let caller = Path::new(std::panic::Location::caller().file());
    let file = caller
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("tests");
    let d = std::env::temp_dir().join(format!(
        "texsim-{}-{file}-{}-{name}",
        env!("CARGO_CRATE_NAME"),
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("tmp dir");
    d
}

/// Standard output followed by standard error.
pub fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}
