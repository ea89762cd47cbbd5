//! `texsim sweep plan.toml`: a sweep described in a TOML file.
//!
//! ```toml
//! scene = "demo"                 # a built-in scene, or a scene file (relative to the plan)
//! hw = "texram16"                # a preset or hw file (relative to the plan)
//! width = 160
//! height = 120
//! vary = ["weight_bits=2..8", "texel_bits=6,8"]
//! no_cycles = true
//! truth = 0                      # ground-truth sub-samples per axis, 0 = off
//! isolate = "trilinear"          # or float = ["lod"]
//! shard = "1/4"
//! out = "out/plan"               # relative to the directory texsim runs in
//! ```
//!
//! The command line wins over the plan: a flag given there replaces the plan's value, and
//! its `--vary` axes come after the plan's.

use crate::cli::SweepArgs;
use crate::{Error, Result};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The keys of a sweep plan (see the module docs).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Plan {
    pub scene: Option<String>,
    pub hw: Option<String>,
    pub width: Option<u32>,
    pub height: Option<u32>,
    #[serde(default)]
    pub vary: Vec<String>,
    #[serde(default)]
    pub no_cycles: bool,
    #[serde(default)]
    pub truth: u32,
    pub isolate: Option<String>,
    #[serde(default)]
    pub float: Vec<String>,
    pub shard: Option<String>,
    pub out: Option<PathBuf>,
}

/// True when `path` is a sweep plan: a TOML file with a top-level `vary` key (a scene file
/// has none).
#[must_use]
pub fn is_plan(path: &Path) -> bool {
    path.extension().is_some_and(|e| e == "toml")
        && std::fs::read_to_string(path)
            .ok()
            .and_then(|t| t.parse::<toml::Table>().ok())
            .is_some_and(|t| t.contains_key("vary"))
}

/// Reads the plan at `path`; errors name the file and, where known, the line.
pub fn load(path: &Path) -> Result<Plan> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::file(path, e))?;
    toml::from_str(&text).map_err(|e| Error::file(path, crate::error::toml_message(&text, &e)))
}

/// `a` with the plan at `a.scene.input` filled in under the command line's flags.
pub fn apply(a: &SweepArgs) -> Result<SweepArgs> {
    let Some(path) = a.scene.input.clone().filter(|p| is_plan(p)) else {
        return Ok(a.clone());
    };
    let plan = load(&path)?;
    let dir = path.parent().unwrap_or_else(|| Path::new("."));
    let rel = |s: &str| -> String {
        let p = dir.join(s);
        if p.is_file() {
            p.to_string_lossy().into_owned()
        } else {
            s.to_string()
        }
    };
    let mut b = a.clone();
    b.scene.input = None;
    if b.scene.scene.is_none() {
        if let Some(s) = &plan.scene {
            let p = dir.join(s);
            if p.is_file() {
                b.scene.input = Some(p);
            } else {
                b.scene.scene = Some(s.clone());
            }
        }
    }
    if b.scene.hw.is_none() {
        b.scene.hw = plan.hw.as_deref().map(rel);
    }
    b.scene.width = b.scene.width.or(plan.width);
    b.scene.height = b.scene.height.or(plan.height);
    if b.scene.out == Path::new("out") {
        if let Some(o) = &plan.out {
            b.scene.out.clone_from(o);
        }
    }
    let mut vary = plan.vary.clone();
    vary.extend(a.vary.iter().cloned());
    b.vary = vary;
    b.no_cycles |= plan.no_cycles && !a.cycles;
    if b.truth == 0 {
        b.truth = plan.truth;
    }
    if b.isolate.is_none() && b.float.is_empty() {
        b.isolate.clone_from(&plan.isolate);
        b.float.clone_from(&plan.float);
    }
    if b.shard.is_none() {
        b.shard.clone_from(&plan.shard);
    }
    if b.vary.is_empty() {
        return Err(Error::file(
            &path,
            "the plan has no axes: add vary = [\"FIELD=A..B\"]",
        ));
    }
    Ok(b)
}
