//! The tests' scratch directories: under Cargo's `CARGO_TARGET_TMPDIR` (inside `target/`, so
//! a test run leaves nothing in the system's temporary directory and `cargo clean` clears
//! it), one per test, removed when the test passes and kept, its path printed, when it fails.
#![allow(dead_code)]

use std::ops::Deref;
use std::path::{Path, PathBuf};

/// A fresh, empty directory, removed on drop unless the thread is panicking (a failed test
/// keeps its files for inspection).
#[derive(Debug)]
pub struct TmpDir(PathBuf);

impl TmpDir {
    /// A fresh, empty directory private to this test binary, process, calling file and `name`
    /// (the test files of one binary share a process: `render` in `cli.rs` and in
    /// `bump_cli.rs` are two directories).
    #[track_caller]
    pub fn new(name: &str) -> Self {
        let caller = Path::new(std::panic::Location::caller().file());
        let file = caller
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("tests");
        let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!(
            "{}-{file}-{}-{name}",
            env!("CARGO_CRATE_NAME"),
            std::process::id()
        ));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).expect("scratch dir");
        Self(d)
    }
}

impl Deref for TmpDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for TmpDir {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for TmpDir {
    fn drop(&mut self) {
        if std::thread::panicking() {
            eprintln!("the failed test's files are kept in {}", self.0.display());
        } else {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

/// A file in a [`TmpDir`] of its own, which lives as long as the file's handle.
#[derive(Debug)]
pub struct TmpFile {
    path: PathBuf,
    dir: TmpDir,
}

impl TmpFile {
    /// `contents` written as `file` in a fresh [`TmpDir`] named after `name`.
    #[track_caller]
    pub fn new(name: &str, file: &str, contents: impl AsRef<[u8]>) -> Self {
        let dir = TmpDir::new(name);
        let path = dir.join(file);
        std::fs::write(&path, contents).expect("write scratch file");
        Self { path, dir }
    }

    /// The file's directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }
}

impl Deref for TmpFile {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.path
    }
}

impl AsRef<Path> for TmpFile {
    fn as_ref(&self) -> &Path {
        &self.path
    }
}
