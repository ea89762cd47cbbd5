//! Human-readable summaries of a render and the sweep table (terminal, CSV, JSON rows).

use crate::render::RenderStats;
use crate::report::{format_metrics_table, ErrorMetrics};
use serde::Serialize;
use std::fmt::Write;

/// The terminal summary of one render.
#[must_use]
pub fn text(s: &RenderStats) -> String {
    let mut o = String::new();
    let _ = writeln!(
        o,
        "scene '{}' {}x{}, {} triangles ({} after setup: {} culled, {} degenerate, {} non-finite, {} clipped away), hw '{}'",
        s.scene,
        s.width,
        s.height,
        s.triangles,
        s.setup.output,
        s.setup.culled,
        s.setup.degenerate,
        s.setup.non_finite,
        s.setup.clipped_away,
        s.hw
    );
    let _ = writeln!(
        o,
        "fragments: {} rasterized, {} failed depth, {} pixels covered; {} spans",
        s.raster.fragments, s.raster.depth_fails, s.covered_pixels, s.raster.spans
    );
    if let (Some(e8), Some(e16)) = (&s.error_8bit, &s.error_16bit) {
        let _ = writeln!(
            o,
            "error, hardware vs float reference ({:?} coverage):",
            s.coverage
        );
        o.push_str(&format_metrics_table(&[("8-bit", e8), ("16-bit", e16)]));
    }
    let _ = writeln!(
        o,
        "{:<13} {:<6} {:>12} {:>10} {:>8} {:>12} {:>13} {:>12} {:>12}  {:<24} {:>7} {:>9}",
        "stage",
        "impl",
        "invocations",
        "saturated",
        "wrapped",
        "busy_cycles",
        "issue_cycles",
        "texels",
        "tex_bytes",
        "unit",
        "latency",
        "area_ge"
    );
    for st in &s.stages {
        let unit = s
            .timing
            .as_ref()
            .and_then(|t| t.units.iter().find(|u| u.unit == st.stage.name()));
        let uname = stage_unit(st.stage.name());
        let cost = s.datapath.unit(uname);
        let _ = writeln!(
            o,
            "{:<13} {:<6} {:>12} {:>10} {:>8} {:>12} {:>13} {:>12} {:>12}  {:<24} {:>7} {:>9}",
            st.stage.name(),
            if st.invocations == 0 {
                "-"
            } else {
                imp_name(st.imp)
            },
            st.invocations,
            st.saturated,
            st.wrapped,
            unit.map_or_else(|| "-".into(), |u| u.busy_cycles.to_string()),
            st.issue_cycles,
            st.texels,
            unit.map_or_else(|| "-".into(), |u| u.texture_bytes.to_string()),
            if cost.is_some() { uname } else { "-" },
            cost.map_or_else(|| "-".into(), |c| c.latency.to_string()),
            cost.map_or_else(|| "-".into(), |c| c.area_ge.to_string()),
        );
    }
    if s.input_saturated > 0 {
        let _ = writeln!(
            o,
            "vertex attributes saturated on input: {}",
            s.input_saturated
        );
    }
    if s.input_wrapped > 0 {
        let _ = writeln!(o, "vertex attributes wrapped on input: {}", s.input_wrapped);
    }
    let b = &s.bump;
    if !b.frame.is_empty() {
        let _ = writeln!(
            o,
            "bump mapping: frame {}; {} frame fallbacks, {} zero normals, {} l+v=0, {} offsets clamped by the map encoding, {}/{} non-finite float carriers (hw/ref)",
            b.frame, b.frame_fallback, b.zero_normal, b.h_zero, b.offset_clamped, b.nonfinite, b.ref_nonfinite
        );
    }
    o.push_str(&cycles_line(s));
    let d = &s.datapath;
    let _ = writeln!(
        o,
        "datapath: area {} GE (gate equivalents, a proxy; top-level units), longest unit latency {} cycles ({}); `texsim hw cost` lists every unit",
        d.area_ge, d.max_latency, d.max_latency_unit
    );
    let c = &s.issue_cycles;
    let _ = writeln!(
        o,
        "issue cycles (invocations x cycles/op, no overlap; not a frame time): {} = {} setup + {} spans + {} stages",
        c.total, c.setup, c.spans, c.stages
    );
    let t = &s.timings;
    let _ = writeln!(
        o,
        "wall time: hardware path {:.1} ms (setup {:.1}, raster {:.1}, shade {:.1}); reference path {:.1} ms (shade {:.1}); timing model {:.1} ms; vector batches {}",
        t.hw_total_ms, t.setup_ms, t.raster_ms, t.shade_hw_ms, t.ref_total_ms, t.shade_ref_ms, t.timing_ms, hw_model::vector_isa().name()
    );
    o
}

/// The frame's cycles as the timing model counted them (the one cycle figure; `texsim cycles`
/// prints the same total with its full report), or why there is none.
#[must_use]
pub fn cycles_line(s: &RenderStats) -> String {
    match (&s.timing, s.issue_cycles.not_modelled) {
        (Some(t), _) => format!(
            "cycles (timing model): {} = visibility pass {} + shading pass {}; {:.2} per covered pixel; bottleneck {}; texture bytes {}, DRAM bytes {}\n",
            t.total_cycles,
            t.visibility_pass_cycles,
            t.shading_pass_cycles,
            t.cycles_per_pixel,
            t.bottleneck,
            t.memory.texture_bytes,
            t.memory.dram_bytes
        ),
        (None, Some(why)) => format!("cycles: none ({why})\n"),
        (None, None) => "cycles: not counted (the timing model did not run)\n".into(),
    }
}

/// The `hw_model::datapath::units` name of the unit a stage instantiates (the stage table's
/// `unit` column; each stage kind is its own instance in the timing model).
#[must_use]
pub fn stage_unit(stage: &str) -> &'static str {
    match stage {
        "bary" => "interpolator.bary-derivs",
        "color" | "texcoord" | "normal" => "interpolator.attribute",
        "lod" => "lod",
        "trilinear" => "footprint",
        "bump-fetch" | "rough-fetch" | "ndf-fetch" => "trilinear",
        "toksvig-fetch" | "lean-fetch" => "trilinear",
        "toksvig-shade" => "toksvig",
        "lean-shade" => "lean",
        "modulate" => "modulate",
        "frame" => "frame",
        "perturb" => "perturb",
        "phong" => "blinn_phong",
        "as-shade" => "aniso_phong",
        "rough-shade" => "roughness.shade",
        "ndf-shade" => "ndf",
        "lobe-shade" => "multi_lobe",
        "env-fetch" => "cube_face",
        _ => "",
    }
}

fn imp_name(i: crate::pipeline::Impl) -> &'static str {
    match i {
        crate::pipeline::Impl::Fixed => "fixed",
        crate::pipeline::Impl::Float => "float",
    }
}

/// One unit's cost in a sweep row: critical path (gate levels), latency (cycles), area (GE).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct UnitCost {
    pub delay: u32,
    pub latency: u32,
    pub area_ge: u64,
}

/// One row of a sweep: the settings, the error against the reference, the cost.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct SweepRow {
    pub settings: Vec<(String, String)>,
    pub error_8bit: Option<ErrorMetrics>,
    pub error_16bit: Option<ErrorMetrics>,
    /// Saturations of the hardware pass (per stage, wrapped, vertex inputs) plus the NDF
    /// moment-map channels clamped by their encoding (`ndf_clamped`).
    pub saturated: u64,
    /// NDF moment-map channels clamped by their encoding.
    pub ndf_clamped: u64,
    pub texels: u64,
    /// The frame's cycles from the timing model; `None` when it did not run (`--no-cycles`)
    /// or a stage has no hardware cost model (`ndf_norm = exact`).
    pub cycles: Option<u64>,
    pub cycles_per_pixel: Option<f64>,
    /// Texel bytes read and bytes moved from DRAM, from the timing model (`None` as `cycles`).
    pub texture_bytes: Option<u64>,
    pub dram_bytes: Option<u64>,
    /// Issue cycles (`render::IssueCycles`: invocations x cycles per op, no overlap; not a
    /// frame time); `None` when a stage has no hardware cost model.
    pub issue_cycles: Option<u64>,
    pub issue_cycles_per_pixel: Option<f64>,
    /// Total area of the machine's top-level units in gate equivalents (a proxy) and its
    /// longest unit latency in cycles, with that unit.
    pub area_ge: u64,
    pub max_latency: u32,
    pub max_latency_unit: String,
    /// Delay, latency and area of every unit (`render::DatapathCost::units`).
    pub unit_cost: std::collections::BTreeMap<String, UnitCost>,
    /// The units in pipeline order (`hw_model::datapath::units`), for the tables.
    #[serde(skip)]
    pub unit_order: Vec<String>,
    /// ALU ops of the stages per covered pixel (`None` as `issue_cycles`).
    pub ops_per_pixel: Option<f64>,
    pub hw_ms: f64,
    pub ref_ms: f64,
    /// Trilinear texture lookups (8 texels each) per covered pixel.
    pub lookups_per_pixel: f64,
    /// `texsim sweep --truth`: float reference vs ground truth, 8-bit LSBs.
    pub model_error: Option<ErrorMetrics>,
    /// The frames the bump materials used (`natural`, `unit`, `main`, joined by `+`; empty
    /// without bump materials). A material's own `frame` overrides a swept `frame_kind`.
    pub frame_used: String,
    /// Bump events: frames from a fallback, zero interpolated normals, offsets clamped by the
    /// maps (`render::BumpStats`).
    pub frame_fallback: u64,
    pub zero_normal: u64,
    pub offset_clamped: u64,
    /// LDR-FLIP of the hardware image against the reference (`crate::flip`), set by the sweep.
    pub flip: Option<crate::flip::FlipStats>,
    /// On the Pareto front of mean 8-bit error vs `area_ge` (`crate::pareto::mark_sweep`).
    pub pareto_area: bool,
    /// On the Pareto front of mean 8-bit error vs `cycles` (`None` when a row has no cycles).
    pub pareto_cycles: Option<bool>,
}

impl SweepRow {
    /// The row of one render.
    #[must_use]
    pub fn new(settings: Vec<(String, String)>, s: &RenderStats) -> Self {
        let px = s.covered_pixels.max(1) as f64;
        let modelled = s.issue_cycles.not_modelled.is_none();
        let t = s.timing.as_ref();
        Self {
            settings,
            error_8bit: s.error_8bit.clone(),
            error_16bit: s.error_16bit.clone(),
            saturated: s
                .stages
                .iter()
                .map(|x| x.saturated + x.wrapped)
                .sum::<u64>()
                + s.input_saturated
                + s.input_wrapped
                + s.bump.ndf_clamped,
            ndf_clamped: s.bump.ndf_clamped,
            texels: s.stages.iter().map(|x| x.texels).sum(),
            cycles: t.map(|t| t.total_cycles),
            cycles_per_pixel: t.map(|t| t.cycles_per_pixel),
            texture_bytes: t.map(|t| t.memory.texture_bytes),
            dram_bytes: t.map(|t| t.memory.dram_bytes),
            issue_cycles: modelled.then_some(s.issue_cycles.total),
            issue_cycles_per_pixel: modelled.then_some(s.issue_cycles.per_covered_pixel),
            area_ge: s.datapath.area_ge,
            max_latency: s.datapath.max_latency,
            max_latency_unit: s.datapath.max_latency_unit.clone(),
            unit_cost: s
                .datapath
                .units
                .iter()
                .map(|u| {
                    let c = UnitCost {
                        delay: u.delay,
                        latency: u.latency,
                        area_ge: u.area_ge,
                    };
                    (u.unit.clone(), c)
                })
                .collect(),
            unit_order: s.datapath.units.iter().map(|u| u.unit.clone()).collect(),
            ops_per_pixel: modelled
                .then(|| s.stages.iter().map(|x| x.ops).sum::<u64>() as f64 / px),
            hw_ms: s.timings.hw_total_ms,
            ref_ms: s.timings.ref_total_ms,
            lookups_per_pixel: s.stages.iter().map(|x| x.texels).sum::<u64>() as f64 / 8.0 / px,
            model_error: s.model_error.clone(),
            frame_used: s.bump.frame.clone(),
            frame_fallback: s.bump.frame_fallback,
            zero_normal: s.bump.zero_normal,
            offset_clamped: s.bump.offset_clamped,
            flip: None,
            pareto_area: false,
            pareto_cycles: None,
        }
    }
}

/// Columns of the bump frame and events (present when any row has bump materials).
const BUMP_HEADER: [&str; 4] = [
    "frame_used",
    "frame_fallbacks",
    "zero_normals",
    "offsets_clamped",
];

fn bumped(rows: &[SweepRow]) -> bool {
    rows.iter().any(|r| !r.frame_used.is_empty())
}

fn bump_cells(r: &SweepRow) -> [String; 4] {
    let used = if r.frame_used.is_empty() {
        "-".into()
    } else {
        r.frame_used.clone()
    };
    [
        used,
        r.frame_fallback.to_string(),
        r.zero_normal.to_string(),
        r.offset_clamped.to_string(),
    ]
}

/// The terminal table's error columns: `quant_*` compare the hardware with the float
/// reference (quantization error; `error_8bit.*` / `error_16bit.*` in the CSV and JSON),
/// `model_*` the float reference with the ground truth (`model_error.*`).
const HEADER: [&str; 18] = [
    "quant_max8",
    "quant_mean8",
    "quant_rmse8",
    "quant_psnr8_db",
    "quant_exact8_%",
    "quant_max16",
    "quant_rmse16",
    "sat",
    "cycles",
    "cyc/px",
    "tex_bytes",
    "dram_bytes",
    "area_ge",
    "max_lat",
    "ops/px",
    "lookups/px",
    "model_mean8",
    "hw_ms",
];

fn cells(r: &SweepRow) -> Vec<String> {
    let e8 = r.error_8bit.as_ref();
    let e16 = r.error_16bit.as_ref();
    let psnr = |e: Option<&ErrorMetrics>| match e.and_then(|e| e.psnr_db) {
        Some(p) => format!("{p:.2}"),
        None => "inf".into(),
    };
    vec![
        e8.map_or("-".into(), |e| e.max_abs_lsb.to_string()),
        e8.map_or("-".into(), |e| format!("{:.4}", e.mean_abs_lsb)),
        e8.map_or("-".into(), |e| format!("{:.4}", e.rmse_lsb)),
        psnr(e8),
        e8.map_or("-".into(), |e| format!("{:.2}", e.pct_exact)),
        e16.map_or("-".into(), |e| e.max_abs_lsb.to_string()),
        e16.map_or("-".into(), |e| format!("{:.2}", e.rmse_lsb)),
        r.saturated.to_string(),
        r.cycles.map_or("-".into(), |c| c.to_string()),
        r.cycles_per_pixel.map_or("-".into(), |c| format!("{c:.2}")),
        r.texture_bytes.map_or("-".into(), |c| c.to_string()),
        r.dram_bytes.map_or("-".into(), |c| c.to_string()),
        r.area_ge.to_string(),
        r.max_latency.to_string(),
        r.ops_per_pixel.map_or("-".into(), |c| format!("{c:.2}")),
        format!("{:.2}", r.lookups_per_pixel),
        r.model_error
            .as_ref()
            .map_or("-".into(), |e| format!("{:.4}", e.mean_abs_lsb)),
        format!("{:.1}", r.hw_ms),
    ]
}

/// Columns of FLIP (present when any row has FLIP: `sweep --flip`).
const FLIP_HEADER: [&str; 2] = ["flip_mean", "flip_p99"];

fn flip_cells(r: &SweepRow) -> [String; 2] {
    let f = r.flip.as_ref();
    [
        f.map_or("-".into(), |f| format!("{:.4}", f.mean)),
        f.map_or("-".into(), |f| format!("{:.4}", f.p99)),
    ]
}

/// The terminal line of a render's FLIP statistics.
#[must_use]
pub fn flip_line(f: &crate::flip::FlipStats) -> String {
    format!(
        "FLIP (LDR, hardware vs reference, {:.0} px/degree, {} covered px): mean {:.4}  p99 {:.4}  max {:.4}",
        f.pixels_per_degree, f.pixels, f.mean, f.p99, f.max
    )
}

/// Units whose cost (delay, latency or area) differs from the first row's in some row, in
/// pipeline order (units a row lacks count as changed).
#[must_use]
pub fn changed_units(rows: &[SweepRow]) -> Vec<String> {
    let Some(first) = rows.first() else {
        return Vec::new();
    };
    let mut names: Vec<&String> = Vec::new();
    for r in rows {
        for k in &r.unit_order {
            if !names.contains(&k) {
                names.push(k);
            }
        }
    }
    names
        .into_iter()
        .filter(|n| {
            rows.iter()
                .any(|r| r.unit_cost.get(*n) != first.unit_cost.get(*n))
        })
        .cloned()
        .collect()
}

/// One field of a [`UnitCost`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum UnitField {
    Area,
    Delay,
    Latency,
}

impl UnitField {
    const ALL: [Self; 3] = [Self::Area, Self::Delay, Self::Latency];

    fn of(self, c: &UnitCost) -> u64 {
        match self {
            Self::Area => c.area_ge,
            Self::Delay => u64::from(c.delay),
            Self::Latency => u64::from(c.latency),
        }
    }

    /// The JSON/CSV name.
    fn name(self) -> &'static str {
        match self {
            Self::Area => "area_ge",
            Self::Delay => "delay",
            Self::Latency => "latency",
        }
    }

    /// The terminal column prefix.
    fn short(self) -> &'static str {
        match self {
            Self::Area => "area",
            Self::Delay => "delay",
            Self::Latency => "lat",
        }
    }
}

/// The changed unit costs the terminal table shows: of the units a stage instantiates
/// ([`stage_unit`]; sub-units such as `bilinear` inside `trilinear` are in the CSV and JSON),
/// without a unit whose costs equal an earlier one's in every row (`footprint` is `trilinear`
/// when `aniso_probes = 1`), each field (area, delay, latency) that differs from the first
/// row's in some row.
fn table_units(rows: &[SweepRow]) -> Vec<(String, UnitField)> {
    let staged = |u: &str| {
        crate::pipeline::StageKind::ALL
            .iter()
            .any(|k| stage_unit(k.name()) == u)
    };
    let mut out: Vec<String> = Vec::new();
    for u in changed_units(rows).into_iter().filter(|u| staged(u)) {
        let same = out.iter().any(|o| {
            rows.iter()
                .all(|r| r.unit_cost.get(o) == r.unit_cost.get(&u))
        });
        if !same {
            out.push(u);
        }
    }
    let Some(first) = rows.first() else {
        return Vec::new();
    };
    out.into_iter()
        .flat_map(|u| {
            UnitField::ALL
                .into_iter()
                .filter(|&f| {
                    let v = |r: &SweepRow| r.unit_cost.get(&u).map(|c| f.of(c));
                    rows.iter().any(|r| v(r) != v(first))
                })
                .map(|f| (u.clone(), f))
                .collect::<Vec<_>>()
        })
        .collect()
}

/// The sweep as an aligned terminal table: the swept fields, the error and cost columns, then
/// per unit whose cost changed against the first row ([`table_units`]) its area (GE) and delay
/// (gate levels).
#[must_use]
pub fn sweep_table(rows: &[SweepRow]) -> String {
    let mut grid: Vec<Vec<String>> = Vec::with_capacity(rows.len() + 1);
    let set_names: Vec<String> = rows.first().map_or(vec![], |r| {
        r.settings.iter().map(|(f, _)| f.clone()).collect()
    });
    let bump = bumped(rows);
    let changed = table_units(rows);
    let mut head = set_names.clone();
    head.extend(HEADER.iter().map(|s| s.to_string()));
    for (u, f) in &changed {
        head.push(format!("{}:{u}", f.short()));
    }
    let flipped = rows.iter().any(|r| r.flip.is_some());
    if flipped {
        head.extend(FLIP_HEADER.iter().map(|s| s.to_string()));
    }
    if bump {
        head.push(BUMP_HEADER[0].into());
    }
    head.push("pareto".into());
    grid.push(head);
    for r in rows {
        let mut line: Vec<String> = r.settings.iter().map(|(_, v)| v.clone()).collect();
        line.extend(cells(r));
        for (u, f) in &changed {
            let c = r.unit_cost.get(u);
            line.push(c.map_or_else(|| "-".into(), |c| f.of(c).to_string()));
        }
        if flipped {
            line.extend(flip_cells(r));
        }
        if bump {
            let [used, ..] = bump_cells(r);
            line.push(used);
        }
        line.push(crate::pareto::mark(r).into());
        grid.push(line);
    }
    let ncol = grid[0].len();
    let widths: Vec<usize> = (0..ncol)
        .map(|c| {
            grid.iter()
                .map(|l| l.get(c).map_or(0, |s| s.len()))
                .max()
                .unwrap_or(0)
        })
        .collect();
    let mut o = String::new();
    for l in &grid {
        let cols: Vec<String> = l
            .iter()
            .zip(&widths)
            .map(|(s, w)| format!("{s:>w$}"))
            .collect();
        let _ = writeln!(o, "{}", cols.join("  "));
    }
    o
}

/// Columns of `sweep.csv` after the swept fields: the names of `sweep.json`'s row fields
/// (nested metrics joined with a dot).
pub const CSV_COLUMNS: [&str; 32] = [
    "error_8bit.max_abs_lsb",
    "error_8bit.mean_abs_lsb",
    "error_8bit.rmse_lsb",
    "error_8bit.psnr_db",
    "error_8bit.pct_exact",
    "error_16bit.max_abs_lsb",
    "error_16bit.rmse_lsb",
    "saturated",
    "ndf_clamped",
    "texels",
    "cycles",
    "cycles_per_pixel",
    "texture_bytes",
    "dram_bytes",
    "issue_cycles",
    "issue_cycles_per_pixel",
    "area_ge",
    "max_latency",
    "max_latency_unit",
    "ops_per_pixel",
    "lookups_per_pixel",
    "model_error.mean_abs_lsb",
    "frame_used",
    "frame_fallback",
    "zero_normal",
    "offset_clamped",
    "hw_ms",
    "ref_ms",
    "flip.mean",
    "flip.p99",
    "pareto_area",
    "pareto_cycles",
];

/// The cells of [`CSV_COLUMNS`] for one row: full precision, empty where the JSON has `null`
/// (not applicable: no reference, no cost model, no timing run, no truth; a PSNR of identical
/// images), `frame_used` empty without bump materials.
fn csv_cells(r: &SweepRow) -> Vec<String> {
    fn opt<T: ToString>(v: Option<T>) -> String {
        v.map_or_else(String::new, |x| x.to_string())
    }
    let e8 = r.error_8bit.as_ref();
    let e16 = r.error_16bit.as_ref();
    vec![
        opt(e8.map(|e| e.max_abs_lsb)),
        opt(e8.map(|e| e.mean_abs_lsb)),
        opt(e8.map(|e| e.rmse_lsb)),
        opt(e8.and_then(|e| e.psnr_db)),
        opt(e8.map(|e| e.pct_exact)),
        opt(e16.map(|e| e.max_abs_lsb)),
        opt(e16.map(|e| e.rmse_lsb)),
        r.saturated.to_string(),
        r.ndf_clamped.to_string(),
        r.texels.to_string(),
        opt(r.cycles),
        opt(r.cycles_per_pixel),
        opt(r.texture_bytes),
        opt(r.dram_bytes),
        opt(r.issue_cycles),
        opt(r.issue_cycles_per_pixel),
        r.area_ge.to_string(),
        r.max_latency.to_string(),
        r.max_latency_unit.clone(),
        opt(r.ops_per_pixel),
        r.lookups_per_pixel.to_string(),
        opt(r.model_error.as_ref().map(|e| e.mean_abs_lsb)),
        r.frame_used.clone(),
        r.frame_fallback.to_string(),
        r.zero_normal.to_string(),
        r.offset_clamped.to_string(),
        r.hw_ms.to_string(),
        r.ref_ms.to_string(),
        opt(r.flip.as_ref().map(|f| f.mean)),
        opt(r.flip.as_ref().map(|f| f.p99)),
        r.pareto_area.to_string(),
        opt(r.pareto_cycles),
    ]
}

/// The sweep as CSV (RFC 4180, written by the `csv` crate): one column per swept field, then
/// [`CSV_COLUMNS`], named as in `sweep.json`, then `unit_cost.NAME.area_ge`, `.delay` and
/// `.latency` of every unit whose cost changed against the first row ([`changed_units`]; NAME
/// may itself contain a dot, the field does not).
pub fn sweep_csv(rows: &[SweepRow]) -> crate::Result<String> {
    let changed = changed_units(rows);
    let unit_cols: Vec<String> = changed
        .iter()
        .flat_map(|u| {
            UnitField::ALL
                .iter()
                .map(move |f| format!("unit_cost.{u}.{}", f.name()))
        })
        .collect();
    let mut w = csv::Writer::from_writer(Vec::new());
    let err = |e: csv::Error| crate::Error::msg(format!("sweep.csv: {e}"));
    let fields: Vec<String> = rows.first().map_or_else(Vec::new, |r| {
        r.settings.iter().map(|(f, _)| f.clone()).collect()
    });
    w.write_record(
        fields
            .iter()
            .map(String::as_str)
            .chain(CSV_COLUMNS)
            .chain(unit_cols.iter().map(String::as_str)),
    )
    .map_err(err)?;
    for r in rows {
        let mut rec: Vec<String> = r.settings.iter().map(|(_, v)| v.clone()).collect();
        rec.extend(csv_cells(r));
        for u in &changed {
            let c = r.unit_cost.get(u);
            for f in UnitField::ALL {
                rec.push(c.map_or_else(String::new, |c| f.of(c).to_string()));
            }
        }
        w.write_record(&rec).map_err(err)?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| crate::Error::msg(format!("sweep.csv: {e}")))?;
    String::from_utf8(bytes).map_err(|e| crate::Error::msg(format!("sweep.csv: {e}")))
}
