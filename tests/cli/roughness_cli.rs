//! The roughness command line: `texsim render --scene lake --truth` (truth.png, baseline.png,
//! model/quantization/baseline error in summary.json) and the `roughness` sweep with `--truth`.

use crate::cli_common::{texsim, text, tmp};

#[test]
fn render_truth_writes_the_truth_and_the_three_errors() {
    let d = tmp("render");
    let o = texsim(&["scenes"], &d);
    for s in ["lake", "corrugated", "brushed", "scratches"] {
        assert!(text(&o).contains(s), "{s}");
    }
    let o = texsim(
        &[
            "render",
            "--scene",
            "lake",
            "--width",
            "160",
            "--height",
            "100",
            "--truth",
            "--truth-samples",
            "6",
            "--out",
            "o",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("rough-shade"));
    for f in ["truth.png", "baseline.png", "hw.png", "ref.png"] {
        assert!(d.join("o").join(f).exists(), "{f}");
    }
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("o/summary.json")).expect("summary"))
            .expect("json");
    let r = &j["stats"]["roughness"];
    assert_eq!(r["truth_samples"], 6);
    for k in ["model_error", "quantization_error", "baseline_error"] {
        assert!(r[k]["rmse_lsb"].as_f64().is_some(), "{k}: {r}");
    }
    // A scene without roughness materials: a warning, no truth, still a success.
    let o = texsim(
        &[
            "render", "--scene", "bumps", "--width", "64", "--height", "48", "--truth", "--out",
            "b",
        ],
        &d,
    );
    assert!(o.status.success());
    assert!(text(&o).contains("no roughness or NDF material"));
    assert!(!d.join("b/truth.png").exists());
}

#[test]
fn sweep_reports_model_error_and_cost_per_variant() {
    let d = tmp("sweep");
    let o = texsim(
        &[
            "sweep",
            "--scene",
            "lake",
            "--width",
            "96",
            "--height",
            "64",
            "--truth",
            "4",
            "--vary",
            "roughness=none,published,directional,mahalanobis,isotropic",
            "--out",
            "o",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", text(&o));
    let rows: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("o/sweep.json")).expect("sweep"))
            .expect("json");
    let rows = rows.as_array().expect("rows");
    assert_eq!(rows.len(), 5);
    for r in rows {
        assert!(r["model_error"]["mean_abs_lsb"].as_f64().is_some(), "{r}");
        assert!(r["cycles_per_pixel"].as_f64().expect("cost") > 0.0);
    }
    let bad = texsim(
        &[
            "sweep",
            "--scene",
            "lake",
            "--vary",
            "roughness=shiny",
            "--out",
            "o",
        ],
        &d,
    );
    assert!(!bad.status.success());
    assert!(text(&bad).contains("rough_variant"), "{}", text(&bad));
}
