//! The all-or-nothing output writer: everything a run writes is encoded first and written last,
//! and the set of outputs in the directory is all old or all new.
//!
//! Protocol (directory swap): validate every name; write every file into a fresh sibling
//! directory `.<DIR>.texsim-new-<pid>` and mark it complete (`.texsim-complete`); move the
//! entries of `DIR` that are not this kind of run's outputs (other files, subdirectories) into
//! it; rename `DIR` to `.<DIR>.texsim-old-<pid>`, the new directory to `DIR`, and remove the
//! old one. The set's files and the other entries are in place at once; the earlier run's
//! outputs of the family ([`OutputSet::family`]) that this run does not write are gone with the
//! old directory. A failure while writing removes the new directory and touches nothing else.
//!
//! Before it writes, a run finishes what a killed run left behind (any process id that is no
//! longer running): a complete new directory is swapped in (the killed run had finished
//! writing), an incomplete one is removed, a left-over old directory is removed (or renamed back
//! when `DIR` is missing), and `NAME.tmp-<pid>` files of earlier texsim versions are removed.
//!
//! When `DIR` cannot be renamed (a symbolic link, the file system root, a mount point), the
//! files are moved into `DIR` one by one from the complete new directory instead (each rename
//! atomic, the set not), and the stale files of the family are removed after the last one.

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

    /// Writes every file into `dir` (created if missing, with its parents), removes the stale
    /// files of the family, and returns the written paths in insertion order. Errors name the
    /// directory or file at fault; see the module docs for the protocol.
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
        let finals: Vec<PathBuf> = self.files.iter().map(|(n, _)| dir.join(n)).collect();
        for path in &finals {
            if path.is_dir() {
                return Err(Error::file(
                    path,
                    "is a directory; cannot write an output file over it",
                ));
            }
        }
        let mut abs = std::path::absolute(dir).unwrap_or_else(|_| dir.to_path_buf());
        if abs.file_name().is_none() {
            // `out/..` and the like: the directory's real name.
            if let Ok(real) = fs::canonicalize(dir) {
                abs = real;
            }
        }
        let (Some(parent), Some(base)) = (abs.parent(), abs.file_name()) else {
            return Err(Error::file(
                dir,
                "cannot be an output directory (it has no parent directory)",
            ));
        };
        let base = base.to_string_lossy().into_owned();
        fs::create_dir_all(parent)
            .map_err(|e| Error::file(dir, format!("cannot create output directory: {e}")))?;
        recover(parent, &base, &abs);
        let pid = std::process::id();
        let new = parent.join(format!(".{base}.texsim-new-{pid}"));
        let old = parent.join(format!(".{base}.texsim-old-{pid}"));
        let _ = fs::remove_dir_all(&new);
        fs::create_dir(&new).map_err(|e| {
            Error::file(
                dir,
                format!(
                    "cannot create the new output directory {}: {e}",
                    new.display()
                ),
            )
        })?;
        for (name, bytes) in &self.files {
            if let Err(e) = fs::write(new.join(name), bytes) {
                let _ = fs::remove_dir_all(&new);
                return Err(Error::file(&dir.join(name), format!("cannot write: {e}")));
            }
        }
        if let Err(e) = fs::write(new.join(COMPLETE), b"") {
            let _ = fs::remove_dir_all(&new);
            return Err(Error::file(dir, format!("cannot write: {e}")));
        }
        let ours =
            |n: &str| self.files.iter().any(|(f, _)| f == n) || self.family.iter().any(|f| f == n);
        commit(&new, &abs, &old, &ours).map_err(|e| Error::file(dir, e))?;
        Ok(finals)
    }
}

/// Marks a new output directory as completely written.
const COMPLETE: &str = ".texsim-complete";

/// Whether process `pid` is running (where `/proc` exists; elsewhere every other process id
/// counts as running, so nothing of a run in progress is ever touched).
fn alive(pid: u32) -> bool {
    if pid == std::process::id() {
        return true;
    }
    let proc_fs = Path::new("/proc/self");
    !proc_fs.exists() || Path::new(&format!("/proc/{pid}")).exists()
}

/// `NAME.tmp-<pid>` of a process that is no longer running (the per-file temp files of earlier
/// texsim versions).
fn stale_temp(name: &str) -> bool {
    name.rsplit_once(".tmp-")
        .and_then(|(_, p)| p.parse::<u32>().ok())
        .is_some_and(|p| !alive(p))
}

/// Finishes or removes what killed runs left beside `dir` (module docs).
fn recover(parent: &Path, base: &str, dir: &Path) {
    let Ok(entries) = fs::read_dir(parent) else {
        return;
    };
    let mut news = Vec::new();
    let mut olds = Vec::new();
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        for (tag, list) in [("new", &mut news), ("old", &mut olds)] {
            let prefix = format!(".{base}.texsim-{tag}-");
            if let Some(pid) = name
                .strip_prefix(&prefix)
                .and_then(|p| p.parse::<u32>().ok())
            {
                if !alive(pid) {
                    list.push((pid, e.path()));
                }
            }
        }
    }
    for (pid, new) in news {
        if new.join(COMPLETE).is_file() {
            let old = parent.join(format!(".{base}.texsim-old-{pid}"));
            let _ = commit(&new, dir, &old, &|_| false);
        } else {
            let _ = fs::remove_dir_all(&new);
        }
    }
    for (_, old) in olds {
        if !old.exists() {
            continue;
        }
        if dir.exists() {
            let _ = fs::remove_dir_all(&old);
        } else {
            let _ = fs::rename(&old, dir);
        }
    }
}

/// Swaps the complete directory `new` in as `dir` (module docs): entries of `dir` for which
/// `ours` is false (and that are not in `new`) move into `new` first; `old` is the name `dir`
/// takes until it is removed.
fn commit(
    new: &Path,
    dir: &Path,
    old: &Path,
    ours: &dyn Fn(&str) -> bool,
) -> std::result::Result<(), String> {
    let is_link = fs::symlink_metadata(dir).is_ok_and(|m| m.file_type().is_symlink());
    if is_link {
        return commit_per_file(new, dir, ours);
    }
    let mut moved = Vec::new();
    if dir.exists() {
        let entries = fs::read_dir(dir).map_err(|e| format!("cannot list: {e}"))?;
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if name == COMPLETE || ours(&name) || new.join(&name).exists() {
                continue;
            }
            if stale_temp(&name) {
                let _ = fs::remove_file(e.path());
                continue;
            }
            if fs::rename(e.path(), new.join(&name)).is_ok() {
                moved.push(name);
            }
        }
        if fs::rename(dir, old).is_err() {
            // Not renamable (mount point, permissions): put the moved entries back and fall
            // back to moving the files in one by one.
            for name in &moved {
                let _ = fs::rename(new.join(name), dir.join(name));
            }
            return commit_per_file(new, dir, ours);
        }
    }
    if let Err(e) = fs::rename(new, dir) {
        // Put the earlier directory back as it was.
        let _ = fs::rename(old, dir);
        for name in &moved {
            let _ = fs::rename(new.join(name), dir.join(name));
        }
        let _ = fs::remove_dir_all(new);
        return Err(format!("cannot move the new outputs into place: {e}"));
    }
    let _ = fs::remove_file(dir.join(COMPLETE));
    let _ = fs::remove_dir_all(old);
    Ok(())
}

/// The fallback of [`commit`]: each file of `new` renamed into `dir`, then the family files
/// (`ours`) of `dir` that `new` did not hold removed, then `new`.
fn commit_per_file(
    new: &Path,
    dir: &Path,
    ours: &dyn Fn(&str) -> bool,
) -> std::result::Result<(), String> {
    fs::create_dir_all(dir).map_err(|e| format!("cannot create output directory: {e}"))?;
    let mut names: Vec<String> = fs::read_dir(new)
        .map_err(|e| format!("cannot list {}: {e}", new.display()))?
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n != COMPLETE)
        .collect();
    names.sort();
    for n in &names {
        fs::rename(new.join(n), dir.join(n))
            .map_err(|e| format!("{n}: cannot rename into place: {e}"))?;
    }
    if let Ok(entries) = fs::read_dir(dir) {
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            let stale =
                (ours(&name) && !names.contains(&name) && e.path().is_file()) || stale_temp(&name);
            if stale {
                let _ = fs::remove_file(e.path());
            }
        }
    }
    let _ = fs::remove_dir_all(new);
    Ok(())
}
