//! The NDF sweep as users run it (docs/NDF.md): `texsim sweep --scene ripple-sphere --vary
//! ndf_norm=partial,map,projected,exact --truth --cycles` reports, per option, lookups per pixel,
//! model and quantization errors, ALU ops and cycles; `exact` (float only) has no cost.

use crate::cli_common::{texsim, text, tmp};

#[test]
fn ndf_norm_sweep_reports_errors_lookups_and_costs() {
    let d = tmp("ndf-sweep");
    let o = texsim(
        &[
            "sweep",
            "--scene",
            "ripple-sphere",
            "--width",
            "96",
            "--height",
            "64",
            "--vary",
            "ndf_norm=partial,map,projected,exact",
            "--truth",
            "--cycles",
            "--out",
            "s",
        ],
        &d,
    );
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    for col in ["lookups/px", "ops/px", "cyc/px", "model_mean8", "tex_bytes"] {
        assert!(t.contains(col), "column {col} missing: {t}");
    }
    assert!(t.contains("no hardware cost model"), "{t}");
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("s/sweep.json")).expect("json"))
            .expect("parse");
    let rows = j.as_array().expect("rows");
    let names: Vec<&str> = rows
        .iter()
        .map(|r| r["settings"][0][1].as_str().expect("setting"))
        .collect();
    assert_eq!(names, ["partial", "map", "projected", "exact"]);
    let lookups: Vec<f64> = rows
        .iter()
        .map(|r| r["lookups_per_pixel"].as_f64().expect("lookups"))
        .collect();
    assert_eq!(lookups, [3.0, 4.0, 3.0, 3.0]);
    for r in rows {
        let model = r["model_error"]["mean_abs_lsb"]
            .as_f64()
            .expect("model error");
        let quant = r["error_8bit"]["mean_abs_lsb"]
            .as_f64()
            .expect("quantization error");
        assert!(model > 0.0 && quant >= 0.0 && model > quant, "{r}");
        assert!(r["ndf_clamped"].as_u64().is_some(), "{r}");
    }
    for r in &rows[..3] {
        assert!(r["cycles"].as_u64().expect("timing cycles") > 0, "{r}");
        assert!(r["cycles_per_pixel"].as_f64().expect("cycles") > 0.0, "{r}");
        assert!(
            r["issue_cycles_per_pixel"].as_f64().expect("issue") > 0.0,
            "{r}"
        );
        assert!(r["ops_per_pixel"].as_f64().expect("ops") > 0.0, "{r}");
    }
    // Exact normalization is float only: no cycles, ops or timing, not a fake number.
    let exact = &rows[3];
    for k in [
        "cycles",
        "cycles_per_pixel",
        "ops_per_pixel",
        "issue_cycles",
        "texture_bytes",
    ] {
        assert!(exact[k].is_null(), "exact {k}: {exact}");
    }
    let csv = std::fs::read_to_string(d.join("s/sweep.csv")).expect("csv");
    let head: Vec<&str> = csv.lines().next().expect("header").split(',').collect();
    let last: Vec<&str> = csv.lines().last().expect("exact row").split(',').collect();
    assert_eq!(last[0], "exact");
    for k in [
        "cycles",
        "cycles_per_pixel",
        "ops_per_pixel",
        "issue_cycles",
        "texture_bytes",
    ] {
        let i = head.iter().position(|h| *h == k).expect("column");
        assert_eq!(last[i], "", "exact {k} in {csv}");
    }
    // The options differ in cost: map pays a lookup, projected more arithmetic.
    let cpp = |i: usize| rows[i]["issue_cycles_per_pixel"].as_f64().expect("issue");
    assert!(
        cpp(2) > cpp(0),
        "projected costs more arithmetic than partial"
    );
    let tc = |i: usize| rows[i]["cycles"].as_u64().expect("timing");
    assert!(
        tc(1) > tc(0),
        "map's fourth lookup shows in the timing model"
    );
}
