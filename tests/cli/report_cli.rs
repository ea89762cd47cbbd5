//! `report.html` of render and sweep in a real headless Chromium (Debian's `chromium`): it
//! renders with no console message and no script error, and every chart holds one point per
//! JSON row that has its coordinates (counted in the DOM Chromium dumps after the page's script
//! ran, and against the JSON embedded in the page). Also: FLIP and the Pareto marks in
//! summary.json, sweep.json and sweep.csv.

use std::path::Path;
use std::process::Command;

use crate::cli_common::{texsim, text, tmp};

const CHROMIUM: &str = "/usr/bin/chromium";

/// Whether Chromium is installed. Where it is missing, the test fails with how to install it
/// when `CI` or `TEXSIM_REQUIRE_CHROMIUM` is set (`.ci/run` installs it), and is skipped with
/// that note otherwise, so that `cargo test --workspace` passes on a fresh machine.
fn chromium_installed() -> bool {
    if Path::new(CHROMIUM).is_file() {
        return true;
    }
    let note = "Chromium is not installed: the report.html test needs it. Install it with \
                `apt-get update && apt-get install -y chromium` (Debian package chromium); \
                .ci/run does";
    let required = ["CI", "TEXSIM_REQUIRE_CHROMIUM"]
        .iter()
        .any(|v| std::env::var_os(v).is_some_and(|x| !x.is_empty() && x != "0" && x != "false"));
    assert!(!required, "{note}");
    eprintln!("skipped: {note}");
    false
}

/// Loads `page` in headless Chromium (no network, a fresh profile); returns the DOM after the
/// page's scripts ran and Chromium's log (standard error).
fn chromium_dump(page: &Path, profile: &Path) -> (String, String) {
    let url = format!("file://{}", page.canonicalize().unwrap().display());
    let o = Command::new(CHROMIUM)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--enable-logging=stderr",
            "--v=0",
            "--dump-dom",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(&url)
        .output()
        .expect("run chromium");
    let log = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "chromium failed: {log}");
    (String::from_utf8_lossy(&o.stdout).into_owned(), log)
}

/// The console lines of Chromium's log (`console.*` calls and uncaught errors).
fn console_lines(log: &str) -> Vec<&str> {
    log.lines().filter(|l| l.contains(":CONSOLE")).collect()
}

/// The text of the element with `id` (up to its first child tag or end tag).
fn element_text<'a>(dom: &'a str, id: &str) -> &'a str {
    let start = dom
        .find(&format!("id=\"{id}\""))
        .unwrap_or_else(|| panic!("no #{id}"));
    let open_end = start + dom[start..].find('>').unwrap() + 1;
    let close = open_end + dom[open_end..].find('<').unwrap();
    &dom[open_end..close]
}

/// The JSON the page embeds (`<script id="texsim-data">`; `<` is escaped as `\u003c`).
fn page_json(html: &str) -> serde_json::Value {
    let t = element_text(html, "texsim-data");
    serde_json::from_str(t).expect("page JSON")
}

/// Points (circles of class `pt`) in the SVG chart `id` of the DOM.
fn chart_points(dom: &str, id: &str) -> usize {
    let start = dom
        .find(&format!("<svg class=\"chart\" id=\"{id}\""))
        .unwrap_or_else(|| panic!("no chart {id}"));
    let end = start + dom[start..].find("</svg>").unwrap();
    dom[start..end].matches("<circle class=\"pt").count()
}

/// Checks one report in Chromium: no console line, no recorded error, the page's own check
/// ok, and each chart's circles against the JSON rows (counted here, independently).
fn check_report(page: &Path, profile: &Path) -> serde_json::Value {
    let html = std::fs::read_to_string(page).unwrap();
    // Self-contained: no external resource.
    for bad in [
        "src=\"http",
        "href=\"http",
        "<link",
        "<script src",
        "@import",
        "url(http",
    ] {
        assert!(!html.contains(bad), "report.html refers outside: {bad}");
    }
    let json = page_json(&html);
    let (dom, log) = chromium_dump(page, profile);
    assert!(
        console_lines(&log).is_empty(),
        "console: {:?}",
        console_lines(&log)
    );
    assert_eq!(element_text(&dom, "texsim-errors"), "", "script errors");
    let check = element_text(&dom, "texsim-check");
    assert!(check.starts_with("ok: "), "page check: {check}");
    let rows = json["rows"].as_array().unwrap();
    let charts = json["charts"].as_array().unwrap();
    assert!(!charts.is_empty());
    for c in charts {
        let id = c["id"].as_str().unwrap();
        let key = c["key"].as_str().unwrap();
        let want = rows
            .iter()
            .filter(|r| {
                !r["error"].is_null()
                    && match key.strip_prefix("knob:") {
                        Some(k) => r["settings"].as_array().unwrap().iter().any(|s| s[0] == k),
                        None => !r[key].is_null(),
                    }
            })
            .count();
        assert!(want > 0, "{id}: no data");
        assert_eq!(chart_points(&dom, id), want, "{id}: points vs JSON rows");
        if key == "area_ge" {
            let front = rows.iter().filter(|r| r["pareto_area"] == true).count();
            let start = dom.find(&format!("id=\"{id}\"")).unwrap();
            let end = start + dom[start..].find("</svg>").unwrap();
            assert_eq!(
                dom[start..end].matches("class=\"pt pareto\"").count(),
                front,
                "{id}: front points"
            );
        }
    }
    json
}

#[test]
fn sweep_and_render_reports_render_in_chromium() {
    let d = tmp("chromium");
    let o = texsim(
        &[
            "sweep",
            "--scene",
            "sphere",
            "--width",
            "64",
            "--height",
            "48",
            "--vary",
            "weight_bits=2..5",
            "--vary",
            "texel_bits=6,8",
            "--flip",
            "--out",
            "s",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", text(&o));
    let o = texsim(
        &[
            "render", "--scene", "sphere", "--width", "64", "--height", "48", "--out", "r",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", text(&o));
    assert!(d.join("s/report.html").is_file() && d.join("r/report.html").is_file());
    if !chromium_installed() {
        return;
    }
    let json = check_report(&d.join("s/report.html"), &d.join("profile-s"));
    assert_eq!(json["rows"].as_array().unwrap().len(), 8);
    let charts: Vec<&str> = json["charts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["id"].as_str().unwrap())
        .collect();
    assert_eq!(charts, ["knob-0", "knob-1", "cost-area", "cost-cycles"]);
    let html = std::fs::read_to_string(d.join("s/report.html")).unwrap();
    assert_eq!(
        html.matches("data:image/png;base64,").count(),
        8 * 4,
        "strips"
    );
    check_report(&d.join("r/report.html"), &d.join("profile-r"));
    // A tune run's report: every complete trial a point, its charts per moved knob and the
    // area chart with the front.
    let o = texsim(
        &[
            "tune",
            "--scene",
            "sphere",
            "--size",
            "64x48",
            "--budget",
            "max8=2",
            "--knob",
            "weight_bits,texel_bits",
            "--out",
            "t",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", text(&o));
    let tj = check_report(&d.join("t/report.html"), &d.join("profile-t"));
    let tune: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("t/tune.json")).unwrap()).unwrap();
    let complete = tune["trials"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|t| t["complete"] == true)
        .count();
    assert_eq!(tj["rows"].as_array().unwrap().len(), complete);
    let tcharts: Vec<&str> = tj["charts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["id"].as_str().unwrap())
        .collect();
    assert!(tcharts.contains(&"cost-area"), "{tcharts:?}");

    // The harness sees a broken page: a console message and an uncaught error.
    let bad = html.replace(
        "</body>",
        "<script>console.log('x'); no_such_function();</script></body>",
    );
    std::fs::write(d.join("bad.html"), bad).unwrap();
    let (dom, log) = chromium_dump(&d.join("bad.html"), &d.join("profile-bad"));
    assert_eq!(console_lines(&log).len(), 2, "{log}");
    assert!(element_text(&dom, "texsim-errors").contains("no_such_function"));
}

/// FLIP in summary.json and sweep.json/csv; the Pareto marks agree with the definition.
#[test]
fn flip_and_pareto_in_the_outputs() {
    let d = tmp("flippareto");
    let o = texsim(
        &[
            "render", "--scene", "sphere", "--width", "64", "--height", "48", "--out", "r",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("FLIP (LDR"), "{}", text(&o));
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("r/summary.json")).unwrap()).unwrap();
    let mean = j["flip"]["mean"].as_f64().unwrap();
    let p99 = j["flip"]["p99"].as_f64().unwrap();
    assert!(mean > 0.0 && mean <= p99 && p99 <= 1.0, "{mean} {p99}");
    assert!(d.join("r/flip.png").is_file());
    let o = texsim(
        &[
            "render",
            "--scene",
            "sphere",
            "--width",
            "64",
            "--height",
            "48",
            "--no-flip",
            "--out",
            "n",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", text(&o));
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("n/summary.json")).unwrap()).unwrap();
    assert!(j["flip"].is_null());
    assert!(!d.join("n/flip.png").exists());

    let o = texsim(
        &[
            "sweep",
            "--scene",
            "sphere",
            "--width",
            "48",
            "--height",
            "36",
            "--vary",
            "weight_bits=2..6",
            "--flip",
            "--out",
            "s",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", text(&o));
    let table = String::from_utf8_lossy(&o.stdout);
    assert!(
        table.contains("flip_mean") && table.contains("pareto"),
        "{table}"
    );
    let rows: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("s/sweep.json")).unwrap()).unwrap();
    let rows = rows.as_array().unwrap();
    let pt = |r: &serde_json::Value| {
        (
            r["error_8bit"]["mean_abs_lsb"].as_f64().unwrap(),
            r["area_ge"].as_f64().unwrap(),
        )
    };
    for a in rows {
        assert!(a["flip"]["mean"].as_f64().unwrap() > 0.0);
        let (ea, ca) = pt(a);
        let dominated = rows.iter().any(|b| {
            let (eb, cb) = pt(b);
            eb <= ea && cb <= ca && (eb < ea || cb < ca)
        });
        assert_eq!(a["pareto_area"].as_bool().unwrap(), !dominated, "{a}");
    }
    // The most accurate setting is on the front.
    assert!(rows.iter().any(|r| r["pareto_area"] == true));
    let csv = std::fs::read_to_string(d.join("s/sweep.csv")).unwrap();
    let head = csv.lines().next().unwrap();
    assert!(
        head.contains("flip.mean") && head.contains("pareto_area"),
        "{head}"
    );
}

/// FLIP (summary.json's `flip`, flip.png) is bit-identical at 1 and 2 threads.
#[test]
fn flip_outputs_are_identical_at_any_thread_count() {
    let d = tmp("flipthreads");
    for n in ["1", "2"] {
        let out = format!("t{n}");
        let o = texsim(
            &[
                "--threads",
                n,
                "render",
                "--scene",
                "demo",
                "--width",
                "96",
                "--height",
                "72",
                "--out",
                &out,
            ],
            &d,
        );
        assert!(o.status.success(), "{}", text(&o));
    }
    let a = std::fs::read(d.join("t1/flip.png")).unwrap();
    let b = std::fs::read(d.join("t2/flip.png")).unwrap();
    assert!(a == b, "flip.png differs between 1 and 2 threads");
    // summary.json's provenance holds the command line: compare the measurements.
    let json = |dir: &str| -> serde_json::Value {
        serde_json::from_slice(&std::fs::read(d.join(dir).join("summary.json")).unwrap()).unwrap()
    };
    let (a, b) = (json("t1"), json("t2"));
    assert!(a["flip"]["mean"].as_f64().unwrap() > 0.0);
    assert_eq!(a["flip"], b["flip"]);
    assert_eq!(a["stats"], b["stats"]);
}
