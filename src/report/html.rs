//! `report.html`: one self-contained page (inline SVG charts, inline PNG data URIs, one inline
//! script, no network) for a render, a sweep or any caller with rows of settings, error and
//! cost ([`HtmlReport`], [`ReportRow`]; `texsim tune` builds the same rows).
//!
//! Contents: error vs value per knob, error vs area and vs cycles with the Pareto front
//! (`crate::pareto`), image strips per setting (hardware, reference, truth, error maps), the
//! text tables the run printed (stages, sweep), the range table when instrumented, the
//! hardware configuration, and the data points as JSON (`<script id="texsim-data">`). The
//! page's script checks that every chart holds one point per JSON row that has its
//! coordinates and writes the outcome into `#texsim-check`; script errors go into
//! `#texsim-errors`.

use std::fmt::Write as _;

use base64::Engine as _;
use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder};
use serde::Serialize;

use super::{heatmap, Image};
use crate::summary::SweepRow;
use crate::{Error, Result};

/// Widest thumbnail of an image strip (pixels); larger images are box-filtered down by an
/// integer factor.
pub const THUMB_MAX_W: u32 = 192;

/// Most settings with an image strip (the Pareto rows first, then the others in order).
pub const MAX_STRIPS: usize = 48;

/// One setting of the report.
#[derive(Clone, Debug, Default, Serialize)]
pub struct ReportRow {
    /// The knobs and their values (empty for a single render).
    pub settings: Vec<(String, String)>,
    /// The error the charts plot (mean absolute 8-bit LSB, hardware vs reference).
    pub error: Option<f64>,
    /// Further metrics shown in the tooltips and the JSON (name, value).
    pub metrics: Vec<(String, Option<f64>)>,
    pub area_ge: Option<f64>,
    pub cycles: Option<f64>,
    pub pareto_area: bool,
    pub pareto_cycles: Option<bool>,
    /// Thumbnails (caption, PNG bytes): hardware, reference, truth, error maps.
    #[serde(skip)]
    pub strip: Vec<(String, Vec<u8>)>,
}

/// A report: what ran, its rows and its tables.
#[derive(Clone, Debug, Default)]
pub struct HtmlReport {
    pub title: String,
    /// One line saying what ran (scene, machine, grid).
    pub subtitle: String,
    pub rows: Vec<ReportRow>,
    /// Preformatted tables (heading, text), e.g. the render summary or the sweep table.
    pub tables: Vec<(String, String)>,
    /// The range table (`render --ranges`), when instrumented.
    pub ranges: Option<String>,
    /// The hardware configuration as TOML (the base machine of a sweep).
    pub hw_config: String,
}

/// The error and metric columns of a sweep row as a report row (no strip).
#[must_use]
pub fn sweep_report_row(r: &SweepRow) -> ReportRow {
    let e8 = r.error_8bit.as_ref();
    let metrics = vec![
        ("max8".into(), e8.map(|e| f64::from(e.max_abs_lsb))),
        ("mean8".into(), e8.map(|e| e.mean_abs_lsb)),
        ("exact8_pct".into(), e8.map(|e| e.pct_exact)),
        ("psnr8_db".into(), e8.and_then(|e| e.psnr_db)),
        ("flip_mean".into(), r.flip.as_ref().map(|f| f.mean)),
        ("flip_p99".into(), r.flip.as_ref().map(|f| f.p99)),
        (
            "model_mean8".into(),
            r.model_error.as_ref().map(|e| e.mean_abs_lsb),
        ),
    ];
    ReportRow {
        settings: r.settings.clone(),
        error: crate::pareto::sweep_error(r),
        metrics,
        area_ge: Some(r.area_ge as f64),
        cycles: r.cycles.map(|c| c as f64),
        pareto_area: r.pareto_area,
        pareto_cycles: r.pareto_cycles,
        strip: Vec::new(),
    }
}

/// Box-filters interleaved RGBA8 `w` x `h` pixels down by the least integer factor that makes
/// the width at most [`THUMB_MAX_W`]; returns (pixels, width, height).
fn shrink(rgba: &[u8], w: u32, h: u32) -> (Vec<u8>, u32, u32) {
    let f = w.div_ceil(THUMB_MAX_W).max(1);
    let (tw, th) = ((w / f).max(1), (h / f).max(1));
    let mut out = Vec::with_capacity(tw as usize * th as usize * 4);
    for ty in 0..th {
        for tx in 0..tw {
            let mut sum = [0u32; 4];
            let mut n = 0u32;
            for y in ty * f..((ty + 1) * f).min(h) {
                for x in tx * f..((tx + 1) * f).min(w) {
                    let i = (y as usize * w as usize + x as usize) * 4;
                    for (s, &c) in sum.iter_mut().zip(&rgba[i..i + 4]) {
                        *s += u32::from(c);
                    }
                    n += 1;
                }
            }
            out.extend(sum.map(|s| ((s + n / 2) / n.max(1)) as u8));
        }
    }
    (out, tw, th)
}

/// A thumbnail PNG of interleaved RGBA8 pixels.
pub fn thumbnail(rgba: &[u8], w: u32, h: u32) -> Result<Vec<u8>> {
    if w == 0 || h == 0 || rgba.len() != w as usize * h as usize * 4 {
        return Err(Error::msg(format!(
            "report.html: a {w}x{h} thumbnail needs {} bytes, got {}",
            u64::from(w) * u64::from(h) * 4,
            rgba.len()
        )));
    }
    let (px, tw, th) = shrink(rgba, w, h);
    let mut out = Vec::new();
    PngEncoder::new(&mut out)
        .write_image(&px, tw, th, ExtendedColorType::Rgba8)
        .map_err(|e| Error::msg(format!("report.html thumbnail: {e}")))?;
    Ok(out)
}

/// The strip of one render: hardware, reference, truth (when rendered), the 8-bit LSB error
/// map (`error_map` when the caller has it, else computed: `heatmap(hw, reference, 8, mask)`)
/// and the FLIP map (when given).
pub fn render_strip(
    hw: &Image,
    reference: Option<&Image>,
    truth: Option<&Image>,
    mask: &[bool],
    error_map: Option<&tiny_skia::Pixmap>,
    flip: Option<&crate::flip::Flip>,
) -> Result<Vec<(String, Vec<u8>)>> {
    let mut s = vec![(
        "hardware".to_string(),
        thumbnail(&hw.to_rgba8(), hw.width, hw.height)?,
    )];
    if let Some(rf) = reference {
        s.push((
            "reference".into(),
            thumbnail(&rf.to_rgba8(), rf.width, rf.height)?,
        ));
    }
    if let Some(t) = truth {
        s.push(("truth".into(), thumbnail(&t.to_rgba8(), t.width, t.height)?));
    }
    if let Some(rf) = reference {
        let computed;
        let heat = match error_map {
            Some(m) => m,
            None => {
                computed = heatmap(hw, rf, 8, Some(mask));
                &computed
            }
        };
        let (w, h) = (heat.width(), heat.height());
        // The heatmap is opaque: its premultiplied bytes are its straight ones.
        s.push(("error (8-bit LSB)".into(), thumbnail(heat.data(), w, h)?));
    }
    if let Some(f) = flip {
        let rgba = crate::flip::error_map_rgba8(f, Some(mask));
        s.push(("FLIP".into(), thumbnail(&rgba, f.width, f.height)?));
    }
    Ok(s)
}

/// Escapes `&`, `<`, `>`, `"` and `'` for HTML text and attributes.
fn esc(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&#39;"),
            _ => o.push(c),
        }
    }
    o
}

/// A number for a chart label: up to 4 significant digits.
fn num(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if (1e-3..1e5).contains(&a) {
        let digits = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
        let s = format!("{v:.digits$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        format!("{v:.3e}")
    }
}

fn label(r: &ReportRow, i: usize) -> String {
    if r.settings.is_empty() {
        return format!("row {i}");
    }
    r.settings
        .iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// One point of a chart: coordinates, its row, whether it is on the front.
struct Pt {
    x: f64,
    y: f64,
    row: usize,
    front: bool,
}

const CW: f64 = 440.0;
const CH: f64 = 270.0;
const ML: f64 = 62.0;
const MR: f64 = 30.0;
const MT: f64 = 12.0;
const MB: f64 = 44.0;

fn span(vals: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in vals {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if hi - lo < 1e-12 * hi.abs().max(1.0) {
        let pad = (hi.abs() * 0.1).max(0.5);
        return (lo - pad, hi + pad);
    }
    let pad = (hi - lo) * 0.06;
    (lo - pad, hi + pad)
}

/// An SVG scatter chart; `categories` names the x positions 0, 1, ... instead of a numeric
/// axis; `front` draws the Pareto front through the points marked on it.
fn chart(
    id: &str,
    xlabel: &str,
    pts: &[Pt],
    rows: &[ReportRow],
    categories: Option<&[String]>,
    front: bool,
) -> String {
    let (x0, x1) = match categories {
        Some(c) => (-0.5, c.len() as f64 - 0.5),
        None => span(pts.iter().map(|p| p.x)),
    };
    let (y0, y1) = {
        let (lo, hi) = span(pts.iter().map(|p| p.y));
        let y0 = if pts.iter().all(|p| p.y >= 0.0) {
            0.0
        } else {
            lo
        };
        (y0, hi.max(y0 + 1e-9))
    };
    let sx = |x: f64| ML + (x - x0) / (x1 - x0) * (CW - ML - MR);
    let sy = |y: f64| CH - MB - (y - y0) / (y1 - y0) * (CH - MT - MB);
    let mut s = String::new();
    let _ = write!(
        s,
        r#"<svg class="chart" id="{id}" data-chart="{id}" width="{CW}" height="{CH}" viewBox="0 0 {CW} {CH}" xmlns="http://www.w3.org/2000/svg" role="img">"#
    );
    let _ = write!(
        s,
        r#"<rect x="{ML}" y="{MT}" width="{}" height="{}" class="plot"/>"#,
        CW - ML - MR,
        CH - MT - MB
    );
    for k in 0..=4 {
        let y = y0 + (y1 - y0) * f64::from(k) / 4.0;
        let py = sy(y);
        let _ = write!(
            s,
            r#"<line class="grid" x1="{ML}" x2="{}" y1="{py:.1}" y2="{py:.1}"/><text class="tick" x="{}" y="{:.1}" text-anchor="end">{}</text>"#,
            CW - MR,
            ML - 4.0,
            py + 4.0,
            num(y)
        );
    }
    match categories {
        Some(c) => {
            for (i, name) in c.iter().enumerate() {
                let _ = write!(
                    s,
                    r#"<text class="tick" x="{:.1}" y="{}" text-anchor="middle">{}</text>"#,
                    sx(i as f64),
                    CH - MB + 16.0,
                    esc(name)
                );
            }
        }
        None => {
            // A knob's own values when few (integers: its widths), else five even ticks.
            let mut xs: Vec<f64> = pts.iter().map(|p| p.x).collect();
            xs.sort_by(f64::total_cmp);
            xs.dedup();
            let own = !front && xs.len() <= 12 && xs.iter().all(|x| x.fract() == 0.0);
            if !own {
                xs = (0..=4)
                    .map(|k| x0 + (x1 - x0) * f64::from(k) / 4.0)
                    .collect();
            }
            for x in xs {
                let _ = write!(
                    s,
                    r#"<text class="tick" x="{:.1}" y="{}" text-anchor="middle">{}</text>"#,
                    sx(x),
                    CH - MB + 16.0,
                    num(x)
                );
            }
        }
    }
    let _ = write!(
        s,
        r#"<text class="axis" x="{:.1}" y="{}" text-anchor="middle">{}</text><text class="axis" x="14" y="{:.1}" text-anchor="middle" transform="rotate(-90 14 {:.1})">mean error (8-bit LSB)</text>"#,
        (ML + CW - MR) / 2.0,
        CH - 8.0,
        esc(xlabel),
        (MT + CH - MB) / 2.0,
        (MT + CH - MB) / 2.0
    );
    if front {
        let mut on: Vec<&Pt> = pts.iter().filter(|p| p.front).collect();
        on.sort_by(|a, b| a.x.total_cmp(&b.x).then(b.y.total_cmp(&a.y)));
        if on.len() > 1 {
            // The staircase of the front: from each point, right at its error, then down.
            let mut d = String::new();
            for (k, p) in on.iter().enumerate() {
                let (px, py) = (sx(p.x), sy(p.y));
                if k == 0 {
                    let _ = write!(d, "M{px:.1},{py:.1}");
                } else {
                    let _ = write!(d, " H{px:.1} V{py:.1}");
                }
            }
            let _ = write!(s, r#"<path class="front" d="{d}"/>"#);
        }
    }
    for p in pts {
        let r = &rows[p.row];
        let class = if p.front { "pt pareto" } else { "pt" };
        let _ = write!(
            s,
            r#"<circle class="{class}" data-row="{}" cx="{:.2}" cy="{:.2}" r="4"><title>{}: error {}, {xl} {}</title></circle>"#,
            p.row,
            sx(p.x),
            sy(p.y),
            esc(&label(r, p.row)),
            num(p.y),
            num(p.x),
            xl = esc(xlabel)
        );
    }
    s.push_str("</svg>");
    s
}

/// The knobs of the rows, in order of first appearance.
fn knobs(rows: &[ReportRow]) -> Vec<String> {
    let mut k: Vec<String> = Vec::new();
    for r in rows {
        for (f, _) in &r.settings {
            if !k.contains(f) {
                k.push(f.clone());
            }
        }
    }
    k
}

/// The charts: (id, heading, svg).
fn charts(rows: &[ReportRow]) -> Vec<(String, String, String)> {
    let mut out = Vec::new();
    for (ki, k) in knobs(rows).iter().enumerate() {
        let vals: Vec<Option<&String>> = rows
            .iter()
            .map(|r| r.settings.iter().find(|(f, _)| f == k).map(|(_, v)| v))
            .collect();
        let numeric = vals.iter().flatten().all(|v| v.parse::<f64>().is_ok());
        let mut cats: Vec<String> = Vec::new();
        if !numeric {
            for v in vals.iter().flatten() {
                if !cats.contains(v) {
                    cats.push((*v).clone());
                }
            }
        }
        let pts: Vec<Pt> = rows
            .iter()
            .zip(&vals)
            .enumerate()
            .filter_map(|(i, (r, v))| {
                let (v, y) = ((*v)?, r.error?);
                let x = if numeric {
                    v.parse::<f64>().ok()?
                } else {
                    cats.iter().position(|c| c == v)? as f64
                };
                Some(Pt {
                    x,
                    y,
                    row: i,
                    front: false,
                })
            })
            .collect();
        let id = format!("knob-{ki}");
        let svg = chart(&id, k, &pts, rows, (!numeric).then_some(&cats[..]), false);
        out.push((id, format!("error vs {k}"), svg));
    }
    type Cost = fn(&ReportRow) -> Option<f64>;
    type Front = fn(&ReportRow) -> bool;
    let costs: [(&str, &str, Cost, Front); 2] = [
        ("cost-area", "area (GE)", |r| r.area_ge, |r| r.pareto_area),
        (
            "cost-cycles",
            "frame cycles",
            |r| r.cycles,
            |r| r.pareto_cycles == Some(true),
        ),
    ];
    for (id, xl, cost, on) in costs {
        let pts: Vec<Pt> = rows
            .iter()
            .enumerate()
            .filter_map(|(i, r)| {
                Some(Pt {
                    x: cost(r)?,
                    y: r.error?,
                    row: i,
                    front: on(r),
                })
            })
            .collect();
        if pts.is_empty() {
            continue;
        }
        let svg = chart(id, xl, &pts, rows, None, true);
        out.push((id.into(), format!("error vs {xl}, Pareto front"), svg));
    }
    out
}

/// The page's script: records errors, then checks each chart's points against the JSON.
const SCRIPT: &str = r#"
(function () {
  var errs = [];
  function report() {
    var el = document.getElementById('texsim-errors');
    if (el) { el.textContent = errs.join('\n'); }
  }
  window.onerror = function (msg, src, line) { errs.push(msg + ' (' + line + ')'); report(); };
  window.addEventListener('unhandledrejection', function (e) { errs.push(String(e.reason)); report(); });
  var data = JSON.parse(document.getElementById('texsim-data').textContent);
  var rows = data.rows;
  function has(r, key) {
    if (r.error === null) { return false; }
    if (key.indexOf('knob:') === 0) {
      var k = key.slice(5);
      return r.settings.some(function (s) { return s[0] === k; });
    }
    return r[key] !== null;
  }
  var lines = [];
  var ok = true;
  data.charts.forEach(function (c) {
    var svg = document.getElementById(c.id);
    var got = svg ? svg.querySelectorAll('circle.pt').length : -1;
    var want = rows.filter(function (r) { return has(r, c.key); }).length;
    var front = svg ? svg.querySelectorAll('circle.pareto').length : -1;
    if (got !== want) { ok = false; }
    lines.push(c.id + ' ' + got + '/' + want + ' points, ' + front + ' on the front');
    if (svg) {
      svg.querySelectorAll('circle.pt').forEach(function (p) {
        p.addEventListener('click', function () {
          var row = document.getElementById('row-' + p.getAttribute('data-row'));
          if (row) { row.scrollIntoView(); row.classList.add('hit'); }
        });
      });
    }
  });
  var el = document.getElementById('texsim-check');
  el.textContent = (ok ? 'ok: ' : 'MISMATCH: ') + lines.join('; ');
  el.setAttribute('data-ok', ok ? 'true' : 'false');
  report();
})();
"#;

const STYLE: &str = "body{font-family:sans-serif;margin:1.5em;color:#222;max-width:1400px}\
h1{font-size:1.4em}h2{font-size:1.15em;margin-top:1.6em;border-bottom:1px solid #ccc}\
.charts{display:flex;flex-wrap:wrap;gap:1em}.charts figure{margin:0}\
.plot{fill:#fafafa;stroke:#999}.grid{stroke:#e2e2e2}.tick{font-size:10px;fill:#555}\
.axis{font-size:11px;fill:#222}.pt{fill:#3b6ea8;fill-opacity:.75;cursor:pointer}\
.pareto{fill:#d9480f;fill-opacity:1}.front{fill:none;stroke:#d9480f;stroke-width:1.5}\
pre{background:#f6f6f6;padding:.6em;overflow-x:auto;font-size:11px}\
.strip{display:flex;flex-wrap:wrap;gap:.5em;align-items:flex-start;margin:.4em 0 1em}\
.strip figure{margin:0;font-size:11px}.strip img{image-rendering:pixelated;border:1px solid #ccc}\
table{border-collapse:collapse;font-size:12px}td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}\
tr.front td{background:#fff1e6}tr.hit td{outline:2px solid #d9480f}\
#texsim-check{font-size:11px;color:#666}#texsim-errors{color:#b00;white-space:pre}";

/// The rows' table: settings, error, cost, front marks and metrics.
fn rows_table(rows: &[ReportRow]) -> String {
    let ks = knobs(rows);
    let metric_names: Vec<&String> = rows
        .first()
        .map(|r| r.metrics.iter().map(|(n, _)| n).collect())
        .unwrap_or_default();
    let mut s = String::from("<table><tr><th>#</th>");
    for k in &ks {
        let _ = write!(s, "<th>{}</th>", esc(k));
    }
    s.push_str("<th>error</th><th>area_ge</th><th>cycles</th><th>pareto</th>");
    for m in &metric_names {
        let _ = write!(s, "<th>{}</th>", esc(m));
    }
    s.push_str("</tr>");
    let opt = |v: Option<f64>| v.map_or_else(|| "-".into(), num);
    for (i, r) in rows.iter().enumerate() {
        let front = r.pareto_area || r.pareto_cycles == Some(true);
        let _ = write!(
            s,
            r#"<tr id="row-{i}"{}><td>{i}</td>"#,
            if front { r#" class="front""# } else { "" }
        );
        for k in &ks {
            let v = r
                .settings
                .iter()
                .find(|(f, _)| f == k)
                .map_or("-", |(_, v)| v.as_str());
            let _ = write!(s, "<td>{}</td>", esc(v));
        }
        let mark = match (r.pareto_area, r.pareto_cycles == Some(true)) {
            (true, true) => "area+cycles",
            (true, false) => "area",
            (false, true) => "cycles",
            (false, false) => "-",
        };
        let _ = write!(
            s,
            "<td>{}</td><td>{}</td><td>{}</td><td>{mark}</td>",
            opt(r.error),
            opt(r.area_ge),
            opt(r.cycles)
        );
        for m in &metric_names {
            let v = r
                .metrics
                .iter()
                .find(|(n, _)| n == *m)
                .and_then(|(_, v)| *v);
            let _ = write!(s, "<td>{}</td>", opt(v));
        }
        s.push_str("</tr>");
    }
    s.push_str("</table>");
    s
}

/// The page. Deterministic: the same report gives the same bytes.
pub fn html(rep: &HtmlReport) -> Result<String> {
    let charts = charts(&rep.rows);
    let chart_keys: Vec<serde_json::Value> = charts
        .iter()
        .map(|(id, _, _)| {
            let key = match id.as_str() {
                "cost-area" => "area_ge".to_string(),
                "cost-cycles" => "cycles".to_string(),
                _ => {
                    let ki: usize = id.trim_start_matches("knob-").parse().unwrap_or(0);
                    format!(
                        "knob:{}",
                        knobs(&rep.rows).get(ki).cloned().unwrap_or_default()
                    )
                }
            };
            serde_json::json!({ "id": id, "key": key })
        })
        .collect();
    let data = serde_json::json!({
        "title": &rep.title,
        "error": "mean absolute error, 8-bit LSB, hardware vs reference",
        "rows": &rep.rows,
        "charts": chart_keys,
    });
    let json = serde_json::to_string(&data)
        .map_err(|e| Error::msg(format!("report.html: {e}")))?
        // Inside <script>: no "</" may end the element early. `<` only occurs inside JSON
        // strings, where "\u003c" is the same character.
        .replace('<', "\\u003c");
    let mut s = String::new();
    let _ = write!(
        s,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{}</title><style>{STYLE}</style></head><body>\n",
        esc(&rep.title)
    );
    let _ = writeln!(
        s,
        "<h1>{}</h1><p>{}</p><p id=\"texsim-check\" data-ok=\"pending\">charts not checked (script did not run)</p><div id=\"texsim-errors\"></div>",
        esc(&rep.title),
        esc(&rep.subtitle)
    );
    s.push_str("<h2>Error and cost</h2><p>Error: mean absolute error in 8-bit LSBs, hardware vs float reference. Orange points and the staircase: the Pareto front (no other setting has both less error and less cost). Click a point for its row.</p><div class=\"charts\">");
    for (_, head, svg) in &charts {
        let _ = write!(
            s,
            "<figure><figcaption>{}</figcaption>{svg}</figure>",
            esc(head)
        );
    }
    s.push_str("</div>\n<h2>Settings</h2>");
    s.push_str(&rows_table(&rep.rows));
    s.push_str("\n<h2>Images</h2>");
    let on_front = |i: &usize| rep.rows[*i].pareto_area || rep.rows[*i].pareto_cycles == Some(true);
    let order: Vec<usize> = (0..rep.rows.len())
        .filter(on_front)
        .chain((0..rep.rows.len()).filter(|i| !on_front(i)))
        .collect();
    let with_strip: Vec<usize> = order
        .into_iter()
        .filter(|&i| !rep.rows[i].strip.is_empty())
        .take(MAX_STRIPS)
        .collect();
    let total = rep.rows.iter().filter(|r| !r.strip.is_empty()).count();
    if total > with_strip.len() {
        let _ = write!(
            s,
            "<p>{} of {total} settings shown (the Pareto front first).</p>",
            with_strip.len()
        );
    }
    for i in with_strip {
        let r = &rep.rows[i];
        let _ = write!(
            s,
            "<h3>#{i} {}</h3><div class=\"strip\">",
            esc(&label(r, i))
        );
        for (cap, png) in &r.strip {
            let b64 = base64::engine::general_purpose::STANDARD.encode(png);
            let _ = write!(
                s,
                "<figure><img alt=\"{0}\" src=\"data:image/png;base64,{b64}\"><figcaption>{0}</figcaption></figure>",
                esc(cap)
            );
        }
        s.push_str("</div>");
    }
    for (head, text) in &rep.tables {
        let _ = write!(s, "\n<h2>{}</h2><pre>{}</pre>", esc(head), esc(text));
    }
    s.push_str("\n<h2>Ranges</h2><div id=\"ranges\">");
    match &rep.ranges {
        Some(t) => {
            let _ = write!(s, "<pre>{}</pre>", esc(t));
        }
        None => s.push_str("<p>No range instrumentation in this run.</p>"),
    }
    let _ = write!(
        s,
        "</div>\n<h2>Hardware configuration</h2><pre>{}</pre>\n",
        esc(&rep.hw_config)
    );
    let _ = write!(
        s,
        "<script type=\"application/json\" id=\"texsim-data\">{json}</script>\n<script>{SCRIPT}</script>\n</body></html>\n"
    );
    Ok(s)
}
