//! What `texsim tune` shows and writes: the trial lines, the closing summary, tune.csv and
//! report.html, the argument parsing. The command itself (which prints) is `cli::tune_cmd`.

use crate::scene::{self, Scene};
use crate::tune::{Budget, Trial, TuneResult};
use crate::{hwconfig, Error, Result};
use std::fmt::Write;
use std::path::Path;

/// Parses `WxH`.
pub fn parse_size(s: &str) -> Result<(u32, u32)> {
    let bad = || Error::field("--size", format!("'{s}' is not WxH (e.g. 320x240)"));
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
    if w == 0 || h == 0 {
        return Err(bad());
    }
    Ok((w, h))
}

/// A built-in scene by name, else a scene file.
pub fn load_scene(name: &str, size: Option<(u32, u32)>) -> Result<Scene> {
    let p = Path::new(name);
    let mut sc = if p.is_file() {
        scene::load(p)?
    } else {
        scene::builtin(name).map_err(|e| e.context("--scene"))?
    };
    if let Some((w, h)) = size {
        sc.width = w;
        sc.height = h;
    }
    scene::validate(&sc)?;
    Ok(sc)
}

/// The knobs of `values` that differ from `from`, as `field=value`.
fn changed(knobs: &[crate::tune::Knob], values: &[u32], from: &[u32]) -> String {
    let v: Vec<String> = knobs
        .iter()
        .zip(values.iter().zip(from))
        .filter(|(_, (v, f))| v != f)
        .map(|(k, (v, _))| format!("{}={v}", leaf(&k.field)))
        .collect();
    if v.is_empty() {
        "-".into()
    } else {
        v.join(" ")
    }
}

fn leaf(path: &str) -> &str {
    path.rsplit('.').next().unwrap_or(path)
}

/// One trial: phase, verdict, area, budget load, errors per scene, then the knobs that
/// differ from `from` (the previous trial's values; the base for the first).
pub fn trial_line(knobs: &[crate::tune::Knob], t: &Trial, from: &[u32]) -> String {
    let errs: Vec<String> = t
        .scenes
        .iter()
        .map(|e| {
            format!(
                "{} max8 {} mean8 {:.4} within1 {:.2}%",
                e.scene, e.max8, e.mean8, e.within1_pct
            )
        })
        .collect();
    format!(
        "#{:<4} {:<8} {:<4} area {:>8} GE  load {:>7.3}  {}  | {}",
        t.index,
        t.phase,
        if t.meets { "ok" } else { "miss" },
        t.area_ge,
        t.load(),
        errs.join("; "),
        changed(knobs, &t.values, from)
    )
}

/// The trials as CSV: index, phase, meets, complete, area, total bits, every knob's value,
/// then per scene its metrics and budget load.
pub fn tune_csv(r: &TuneResult) -> Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let err = |e: csv::Error| Error::msg(format!("tune.csv: {e}"));
    let mut head: Vec<String> = [
        "index",
        "phase",
        "meets",
        "complete",
        "area_ge",
        "total_bits",
    ]
    .iter()
    .map(|s| (*s).to_string())
    .collect();
    head.extend(r.knobs.iter().map(|k| k.field.clone()));
    for sc in &r.scenes {
        for m in ["max8", "mean8", "within1_pct", "psnr8_db", "load"] {
            head.push(format!("{sc}.{m}"));
        }
    }
    w.write_record(&head).map_err(err)?;
    for t in &r.trials {
        let mut rec = vec![
            t.index.to_string(),
            t.phase.to_string(),
            t.meets.to_string(),
            t.complete.to_string(),
            t.area_ge.to_string(),
            t.total_bits.to_string(),
        ];
        rec.extend(t.values.iter().map(ToString::to_string));
        for sc in &r.scenes {
            match t.scenes.iter().find(|e| &e.scene == sc) {
                Some(e) => rec.extend([
                    e.max8.to_string(),
                    e.mean8.to_string(),
                    e.within1_pct.to_string(),
                    e.psnr8_db.map_or_else(String::new, |p| p.to_string()),
                    e.load.to_string(),
                ]),
                None => rec.extend(std::iter::repeat_n(String::new(), 5)),
            }
        }
        w.write_record(&rec).map_err(err)?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| Error::msg(format!("tune.csv: {e}")))?;
    String::from_utf8(bytes).map_err(|e| Error::msg(format!("tune.csv: {e}")))
}

/// The closing report: renders against the grid, the verified row, the found widths.
pub fn summary_text(r: &TuneResult, texram16_area: u64) -> String {
    let mut o = String::new();
    let best = r.best_trial();
    let budgets: Vec<String> = r.budgets.iter().map(Budget::label).collect();
    let _ = writeln!(
        o,
        "budget {} (hardware vs {}) on {}",
        budgets.join(", "),
        if r.against == "truth" {
            "ground truth"
        } else {
            "float reference"
        },
        r.scenes.join(", ")
    );
    let _ = writeln!(
        o,
        "renders: {} used for {} trials; the full grid of {} knobs is {} points = {} renders",
        r.renders,
        r.trials.len(),
        r.knobs.len(),
        big(r.grid_points),
        big(r.grid_renders)
    );
    let hi: Vec<u32> = r.knobs.iter().map(|k| k.hi).collect();
    let _ = writeln!(
        o,
        "verified (knobs vs base): {}",
        trial_line(&r.knobs, best, &hi)
    );
    let pct = |a: u64, b: u64| 100.0 * a as f64 / b.max(1) as f64;
    let _ = writeln!(
        o,
        "area {} GE = {:.1}% of the base machine ({} GE), {:.1}% of texram16 ({} GE)",
        best.area_ge,
        pct(best.area_ge, r.base_area_ge),
        r.base_area_ge,
        pct(best.area_ge, texram16_area),
        texram16_area
    );
    let _ = writeln!(
        o,
        "{:<34} {:>6} {:>6} {:>6} {:>9}",
        "knob", "found", "base", "least", "exercised"
    );
    for (i, (k, v)) in r.knobs.iter().zip(&best.values).enumerate() {
        let exercised = r.exercised.get(i).copied().unwrap_or(true);
        let _ = writeln!(
            o,
            "{:<34} {:>6} {:>6} {:>6} {:>9}{}",
            k.field,
            v,
            k.hi,
            k.lo,
            if exercised { "yes" } else { "no" },
            if *v == k.hi { "" } else { "  *" }
        );
    }
    let _ = writeln!(
        o,
        "*: found differs from base; exercised no: the knob's least value moved no metric of \
         any scene (its unit is unused there): add a scene that uses it before trusting that width"
    );
    o
}

/// report.html of a tune run: every complete trial as a setting (the knobs that differ from
/// the base machine, its worst mean and max 8-bit error over the scenes, its area), the Pareto
/// front of error against area, the summary and the found machine.
pub fn tune_report(r: &TuneResult, summary: &str) -> Result<String> {
    use crate::report::html::{html, HtmlReport, ReportRow};
    let hi: Vec<u32> = r.knobs.iter().map(|k| k.hi).collect();
    // Only the knobs some trial moved: the others would each be a chart of one value.
    let moved: Vec<usize> = (0..r.knobs.len())
        .filter(|&i| r.trials.iter().any(|t| t.values[i] != hi[i]))
        .collect();
    let trials: Vec<&Trial> = r.trials.iter().filter(|t| t.complete).collect();
    let worst = |t: &Trial, f: fn(&crate::tune::SceneError) -> f64| {
        t.scenes.iter().map(f).fold(f64::NAN, f64::max)
    };
    let points: Vec<(f64, f64)> = trials
        .iter()
        .map(|t| (worst(t, |e| e.mean8), t.area_ge as f64))
        .collect();
    let front = crate::pareto::front(&points);
    let rows = trials
        .iter()
        .zip(front)
        .map(|(t, on_front)| ReportRow {
            settings: moved
                .iter()
                .map(|&i| (leaf(&r.knobs[i].field).to_string(), t.values[i].to_string()))
                .collect(),
            error: Some(worst(t, |e| e.mean8)).filter(|e| e.is_finite()),
            metrics: vec![
                ("max8".into(), Some(worst(t, |e| f64::from(e.max8)))),
                (
                    "within1_pct".into(),
                    Some(
                        t.scenes
                            .iter()
                            .map(|e| e.within1_pct)
                            .fold(f64::NAN, f64::min),
                    ),
                ),
                ("load".into(), Some(t.load())),
                ("meets".into(), Some(if t.meets { 1.0 } else { 0.0 })),
            ],
            area_ge: Some(t.area_ge as f64),
            cycles: None,
            pareto_area: on_front,
            pareto_cycles: None,
            strip: Vec::new(),
        })
        .collect();
    let budgets: Vec<String> = r.budgets.iter().map(Budget::label).collect();
    html(&HtmlReport {
        title: format!(
            "texsim tune: {} on {}",
            budgets.join(", "),
            r.scenes.join(", ")
        ),
        subtitle: format!(
            "{} trials, {} renders (full grid: {} renders); error = the worst scene's mean 8-bit \
             error vs the {}",
            r.trials.len(),
            r.renders,
            big(r.grid_renders),
            r.against
        ),
        rows,
        tables: vec![("Tune result".into(), summary.to_string())],
        ranges: None,
        hw_config: hwconfig::to_toml(&r.machine),
    })
}

/// A count, in scientific notation when large.
fn big(n: f64) -> String {
    if n >= 1e9 {
        format!("{n:.2e}")
    } else {
        format!("{n:.0}")
    }
}
