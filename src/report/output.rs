//! The all-or-nothing output writer: everything a run writes is encoded first and written last.
//!
//! Protocol: validate every name, make the directory, write every file to `NAME.tmp-<pid>`,
//! then rename each over `NAME` in insertion order. A failure while writing removes the temp
//! files written so far, so no output file is touched. Renames within one directory are atomic
//! per file; should one fail, the remaining temp files are removed and the error names it.
//! Only after every file is in place, the files of the set's family ([`OutputSet::family`]:
//! the names a run of this kind may write) that this set does not contain are removed, so an
//! earlier run's optional outputs (say `ref.png` before a `--no-reference` run) do not stay
//! beside the new ones. No other file is ever touched.

use std::fs;
use std::path::{Path, PathBuf};

use crate::{Error, Result};

/// Named file contents to be written together.
#[derive(Clone, Debug, Default)]
pub struct OutputSet {
    files: Vec<(String, Vec<u8>)>,
    family: Vec<String>,
}

/// Whether `name` is a plain file name: non-empty, no path separators, no `..`, no NUL.
fn check_name(name: &str) -> Result<()> {
    let bad = name.is_empty()
        || name == "."
        || name.contains("..")
        || name.contains('/')
        || name.contains('\\')
        || name.contains('\0');
    if bad {
        return Err(Error::field(
            "output file name",
            format!("'{name}' is not a plain file name (no '/', '\\' or '..')"),
        ));
    }
    Ok(())
}

impl OutputSet {
    /// An empty set.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a file; adding a name again replaces its contents (keeping its first position).
    pub fn add(&mut self, name: &str, bytes: Vec<u8>) {
        match self.files.iter_mut().find(|(n, _)| n == name) {
            Some(entry) => entry.1 = bytes,
            None => self.files.push((name.to_string(), bytes)),
        }
    }

    /// Declares the names a run of this kind may write: [`OutputSet::write_to`] removes those
    /// of them, left in the directory by an earlier run, that this set does not contain.
    pub fn family(&mut self, names: &[&str]) {
        self.family = names.iter().map(|n| (*n).to_string()).collect();
    }

    /// Files of the family in `dir` that this set does not contain: what
    /// [`OutputSet::write_to`] will remove.
    #[must_use]
    pub fn stale_in(&self, dir: &Path) -> Vec<PathBuf> {
        self.family
            .iter()
            .filter(|f| !self.files.iter().any(|(n, _)| n == *f))
            .map(|f| dir.join(f))
            .filter(|p| p.is_file())
            .collect()
    }

    /// File names in insertion order.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.files.iter().map(|(n, _)| n.as_str())
    }

    /// Number of files.
    #[must_use]
    pub fn len(&self) -> usize {
        self.files.len()
    }

    /// Whether no file was added.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.files.is_empty()
    }

    /// Writes every file into `dir` (created if missing), removes the stale files of the
    /// family, and returns the written paths in insertion order. Errors name the directory or
    /// file at fault; see the module docs for the protocol.
    pub fn write_to(&self, dir: &Path) -> Result<Vec<PathBuf>> {
        for name in self.files.iter().map(|(n, _)| n).chain(&self.family) {
            check_name(name)?;
        }
        if dir.exists() && !dir.is_dir() {
            return Err(Error::file(
                dir,
                "output directory exists and is not a directory",
            ));
        }
        fs::create_dir_all(dir)
            .map_err(|e| Error::file(dir, format!("cannot create output directory: {e}")))?;
        let finals: Vec<PathBuf> = self.files.iter().map(|(n, _)| dir.join(n)).collect();
        for path in &finals {
            if path.is_dir() {
                return Err(Error::file(
                    path,
                    "is a directory; cannot write an output file over it",
                ));
            }
        }
        let pid = std::process::id();
        let temps: Vec<PathBuf> = self
            .files
            .iter()
            .map(|(n, _)| dir.join(format!("{n}.tmp-{pid}")))
            .collect();
        for (i, (_, bytes)) in self.files.iter().enumerate() {
            if let Err(e) = fs::write(&temps[i], bytes) {
                remove_all(&temps[..=i]);
                return Err(Error::file(&finals[i], format!("cannot write: {e}")));
            }
        }
        for (i, (tmp, fin)) in temps.iter().zip(&finals).enumerate() {
            if let Err(e) = fs::rename(tmp, fin) {
                remove_all(&temps[i..]);
                return Err(Error::file(
                    fin,
                    format!("cannot rename temp file into place: {e}"),
                ));
            }
        }
        for stale in self.stale_in(dir) {
            fs::remove_file(&stale).map_err(|e| {
                Error::file(
                    &stale,
                    format!("cannot remove this output of an earlier run: {e}"),
                )
            })?;
        }
        Ok(finals)
    }
}

/// Best-effort removal of temp files (a file that was never created is not an error).
fn remove_all(paths: &[PathBuf]) {
    for p in paths {
        let _ = fs::remove_file(p);
    }
}
