//! Sweeps in pieces and their worst pixels: `texsim sweep --shard K/N` renders every N-th
//! row of the grid into `sweep-shard-K-of-N.json` / `.csv`, `texsim merge` joins the shards
//! into one `sweep.json`, `sweep.csv` and table; [`worst_pixel`] is a row's worst pixel.

use crate::report::{quantize, Image};
use crate::summary::SweepRow;
use crate::{Error, Result};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// One shard of a grid: `index` in `1..=count`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: u64,
    pub count: u64,
}

impl Shard {
    /// Parses `K/N` (`1 <= K <= N`), or `N` alone with K from the Slurm array task
    /// (`slurm_task` = `SLURM_ARRAY_TASK_ID`, `slurm_min` = `SLURM_ARRAY_TASK_MIN`, default 0:
    /// K = task - min + 1).
    pub fn parse(s: &str, slurm_task: Option<&str>, slurm_min: Option<&str>) -> Result<Self> {
        let num = |x: &str, what: &str| -> Result<u64> {
            x.trim().parse::<u64>().map_err(|_| {
                Error::field(
                    "--shard",
                    format!("{what} '{x}' in '{s}' is not a whole number"),
                )
            })
        };
        let (index, count) = match s.split_once('/') {
            Some((k, n)) => (num(k, "K")?, num(n, "N")?),
            None => {
                let n = num(s, "N")?;
                let task = slurm_task.ok_or_else(|| {
                    Error::field(
                        "--shard",
                        format!("'{s}' gives no K and SLURM_ARRAY_TASK_ID is not set: give K/N"),
                    )
                })?;
                let t = task.trim().parse::<u64>().map_err(|_| {
                    Error::field(
                        "SLURM_ARRAY_TASK_ID",
                        format!("'{task}' is not a whole number"),
                    )
                })?;
                let m = match slurm_min {
                    Some(m) => m.trim().parse::<u64>().map_err(|_| {
                        Error::field(
                            "SLURM_ARRAY_TASK_MIN",
                            format!("'{m}' is not a whole number"),
                        )
                    })?,
                    None => 0,
                };
                if t < m {
                    return Err(Error::field(
                        "SLURM_ARRAY_TASK_ID",
                        format!("{t} is below SLURM_ARRAY_TASK_MIN {m}"),
                    ));
                }
                (t - m + 1, n)
            }
        };
        if count == 0 || index == 0 || index > count {
            return Err(Error::field(
                "--shard",
                format!("shard {index} of {count}: K must be in 1..=N and N at least 1"),
            ));
        }
        Ok(Self { index, count })
    }

    /// True when grid row `row` (0-based) belongs to this shard.
    #[must_use]
    pub fn owns(&self, row: u64) -> bool {
        row % self.count == self.index - 1
    }

    /// The shard's file name with `ext` (`sweep-shard-2-of-8.json`).
    #[must_use]
    pub fn file(&self, ext: &str) -> String {
        format!("sweep-shard-{}-of-{}.{ext}", self.index, self.count)
    }
}

/// The pixel whose largest 8-bit channel error is largest (the first in raster order on a tie).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct WorstPixel {
    pub x: u32,
    pub y: u32,
    /// Largest channel error in 8-bit LSBs.
    pub error_lsb: u32,
    /// The two images' 8-bit RGBA there.
    pub hw: [u32; 4],
    pub reference: [u32; 4],
}

/// The worst pixel of `hw` against `reference` over `mask` (`None`: no pixel compared).
#[must_use]
pub fn worst_pixel(hw: &Image, reference: &Image, mask: &[bool]) -> Option<WorstPixel> {
    let mut best: Option<(usize, u32)> = None;
    let errors = crate::report::ChannelErrors::new(8);
    for (i, (&a, &b)) in hw.px.iter().zip(&reference.px).enumerate() {
        if !mask.get(i).copied().unwrap_or(false) {
            continue;
        }
        let e = errors.max_of(a, b);
        if best.is_none_or(|(_, b)| e > b) {
            best = Some((i, e));
        }
    }
    let (i, e) = best?;
    let q = |p: &[u16; 4]| p.map(|c| quantize(c, 8));
    let w = hw.width.max(1) as usize;
    Some(WorstPixel {
        x: (i % w) as u32,
        y: (i / w) as u32,
        error_lsb: e,
        hw: q(&hw.px[i]),
        reference: q(&reference.px[i]),
    })
}

/// The shard files among `inputs` (files, or directories whose `sweep-shard-*-of-*.json`
/// are taken), sorted by name.
pub fn shard_files(inputs: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for p in inputs {
        if p.is_dir() {
            let rd = std::fs::read_dir(p).map_err(|e| Error::file(p, e))?;
            for e in rd {
                let e = e.map_err(|e| Error::file(p, e))?;
                let name = e.file_name().to_string_lossy().into_owned();
                if name.starts_with("sweep-shard-") && name.ends_with(".json") {
                    out.push(e.path());
                }
            }
        } else if p.is_file() {
            out.push(p.clone());
        } else {
            return Err(Error::file(p, "no such file or directory"));
        }
    }
    out.sort();
    out.dedup();
    if out.is_empty() {
        return Err(Error::msg(
            "merge: no sweep-shard-*-of-*.json among the inputs (write them with sweep --shard K/N)",
        ));
    }
    Ok(out)
}

/// The merged sweep: its JSON rows (grid order, without the shard keys) and table rows.
pub struct Merged {
    pub json_rows: Vec<serde_json::Value>,
    pub rows: Vec<SweepRow>,
}

/// Joins shard files: every shard of one grid present once, every grid row once.
pub fn merge(files: &[PathBuf]) -> Result<Merged> {
    let mut all: Vec<(u64, serde_json::Value)> = Vec::new();
    let mut grid: Option<(u64, u64)> = None;
    let mut seen_shards: Vec<u64> = Vec::new();
    for f in files {
        let text = std::fs::read(f).map_err(|e| Error::file(f, e))?;
        let v: serde_json::Value = serde_json::from_slice(&text).map_err(|e| Error::file(f, e))?;
        let get = |k: &str| -> Result<u64> {
            v.get(k)
                .and_then(serde_json::Value::as_u64)
                .ok_or_else(|| Error::file(f, format!("no '{k}': not a sweep shard file")))
        };
        let (k, n, rows) = (get("shard")?, get("shards")?, get("grid_rows")?);
        match grid {
            None => grid = Some((n, rows)),
            Some(g) if g != (n, rows) => {
                return Err(Error::file(
                    f,
                    format!(
                        "shard of a grid of {rows} rows in {n} shards, the others: {} rows in {} shards",
                        g.1, g.0
                    ),
                ))
            }
            Some(_) => {}
        }
        if seen_shards.contains(&k) {
            return Err(Error::file(f, format!("shard {k} of {n} given twice")));
        }
        seen_shards.push(k);
        let rows_v = v
            .get("rows")
            .and_then(serde_json::Value::as_array)
            .ok_or_else(|| Error::file(f, "no 'rows' array"))?;
        for r in rows_v {
            let i = r
                .get("grid_index")
                .and_then(serde_json::Value::as_u64)
                .ok_or_else(|| Error::file(f, "a row without 'grid_index'"))?;
            let mut r = r.clone();
            if let Some(o) = r.as_object_mut() {
                o.remove("grid_index");
            }
            all.push((i, r));
        }
    }
    let (n, rows) = grid.unwrap_or((0, 0));
    let missing: Vec<String> = (1..=n)
        .filter(|k| !seen_shards.contains(k))
        .map(|k| k.to_string())
        .collect();
    if !missing.is_empty() {
        return Err(Error::msg(format!(
            "merge: shard(s) {} of {n} missing",
            missing.join(", ")
        )));
    }
    all.sort_by_key(|(i, _)| *i);
    let indices: Vec<u64> = all.iter().map(|(i, _)| *i).collect();
    if indices != (0..rows).collect::<Vec<_>>() {
        return Err(Error::msg(format!(
            "merge: the shards hold {} rows, not the grid's {rows} rows 0..{rows} once each",
            indices.len()
        )));
    }
    let mut table = Vec::with_capacity(all.len());
    for (i, r) in &all {
        let mut row: SweepRow = serde_json::from_value(r.clone())
            .map_err(|e| Error::msg(format!("merge: grid row {i}: {e}")))?;
        let cfg: hw_model::HwConfig = serde_json::from_value(r["hw_config"].clone())
            .map_err(|e| Error::msg(format!("merge: grid row {i}: hw_config: {e}")))?;
        row.unit_order = crate::render::DatapathCost::of(&cfg)
            .units
            .iter()
            .map(|u| u.unit.clone())
            .collect();
        table.push(row);
    }
    // A shard's Pareto marks are over its own rows: the front is recomputed over the grid.
    crate::pareto::mark_sweep(&mut table);
    let json_rows = all
        .into_iter()
        .zip(&table)
        .map(|((_, mut r), row)| {
            if let Some(o) = r.as_object_mut() {
                o.insert("pareto_area".into(), row.pareto_area.into());
                o.insert("pareto_cycles".into(), row.pareto_cycles.into());
            }
            r
        })
        .collect();
    Ok(Merged {
        json_rows,
        rows: table,
    })
}

/// The output directory of `merge` when none is given: the first input's directory.
#[must_use]
pub fn default_out(files: &[PathBuf]) -> PathBuf {
    files
        .first()
        .and_then(|f| f.parent())
        .map_or_else(|| Path::new(".").to_path_buf(), Path::to_path_buf)
}
