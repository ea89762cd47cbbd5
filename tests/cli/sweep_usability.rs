//! Sweep usability (issue 14 item 6): axes that would overwrite each other, `--isolate`,
//! render's `--truth-samples` spelling, the worst pixel, `--shard K/N` and `texsim merge`.

use crate::cli_common::{texsim, text, tmp};
use std::path::Path;

const SMALL: [&str; 6] = ["--width", "48", "--height", "36", "--no-cycles", "--scene"];

fn sweep(d: &Path, extra: &[&str]) -> std::process::Output {
    let mut a = vec!["sweep"];
    a.extend(SMALL);
    a.push("demo");
    a.extend(extra);
    texsim(&a, d)
}

fn json(p: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display())))
        .expect("json")
}

#[test]
fn an_axis_that_would_overwrite_another_is_refused() {
    let d = tmp("overwrite");
    let o = sweep(&d, &["--vary", "weight_bits=2,3", "--vary", "hw=d3d11"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        text(&o).contains("give --vary hw=... first"),
        "{}",
        text(&o)
    );
    let o = sweep(
        &d,
        &[
            "--vary",
            "weight_bits=2,3",
            "--vary",
            "trilinear.weight_bits=4",
        ],
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(text(&o).contains("would overwrite"), "{}", text(&o));
    // hw first, then a field: allowed.
    let o = sweep(
        &d,
        &[
            "--vary",
            "hw=d3d11",
            "--vary",
            "weight_bits=2",
            "--out",
            "ok",
        ],
    );
    assert!(o.status.success(), "{}", text(&o));
}

#[test]
fn isolate_truth_samples_and_the_worst_pixel() {
    let d = tmp("isolate");
    // Only `color` fixed: the filter's weight width changes nothing.
    let o = sweep(
        &d,
        &[
            "--vary",
            "weight_bits=2,8",
            "--isolate",
            "color",
            "--out",
            "c",
        ],
    );
    assert!(o.status.success(), "{}", text(&o));
    let rows = json(&d.join("c/sweep.json"));
    assert_eq!(rows[0]["error_8bit"], rows[1]["error_8bit"]);
    // Only `trilinear` fixed: it does.
    let o = sweep(
        &d,
        &[
            "--vary",
            "weight_bits=2,8",
            "--isolate",
            "trilinear",
            "--out",
            "t",
        ],
    );
    assert!(o.status.success(), "{}", text(&o));
    let rows = json(&d.join("t/sweep.json"));
    let max = |r: &serde_json::Value| r["error_8bit"]["max_abs_lsb"].as_u64().unwrap();
    assert!(max(&rows[0]) > max(&rows[1]), "{rows}");
    for r in rows.as_array().unwrap() {
        let w = &r["worst_pixel"];
        assert_eq!(w["error_lsb"].as_u64(), Some(max(r)));
        assert!(w["x"].as_u64().unwrap() < 48 && w["y"].as_u64().unwrap() < 36);
    }
    let o = sweep(&d, &["--vary", "weight_bits=4", "--truth-samples", "2"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(text(&o).contains("--truth-samples"), "{}", text(&o));
    let o = texsim(
        &[
            "sweep",
            "--scene",
            "lake",
            "--width",
            "48",
            "--height",
            "32",
            "--no-cycles",
            "--vary",
            "weight_bits=4",
            "--truth",
            "--truth-samples",
            "2",
            "--out",
            "tr",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", text(&o));
    assert!(json(&d.join("tr/sweep.json"))[0]["model_error"].is_object());
}

#[test]
fn shards_merge_into_the_unsharded_table() {
    let d = tmp("shards");
    let axes = ["--vary", "weight_bits=2..4", "--vary", "texel_bits=6,8"];
    let mut a = axes.to_vec();
    a.extend(["--out", "full"]);
    assert!(sweep(&d, &a).status.success());
    for k in ["1/3", "2/3"] {
        let mut a = axes.to_vec();
        a.extend(["--shard", k, "--out", "sh"]);
        let o = sweep(&d, &a);
        assert!(o.status.success(), "{}", text(&o));
    }
    // Not all shards yet.
    let o = texsim(&["merge", "sh"], &d);
    assert_eq!(o.status.code(), Some(1));
    assert!(text(&o).contains("shard(s) 3 of 3 missing"), "{}", text(&o));
    // The third from a Slurm array task (ids 4..6 here).
    let mut a = vec!["sweep"];
    a.extend(SMALL);
    a.push("demo");
    a.extend(axes);
    a.extend(["--shard", "3", "--out", "sh"]);
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_texsim"))
        .args(&a)
        .current_dir(&d)
        .env("SLURM_ARRAY_TASK_ID", "6")
        .env("SLURM_ARRAY_TASK_MIN", "4")
        .output()
        .expect("run");
    assert!(o.status.success(), "{}", text(&o));
    assert!(d.join("sh/sweep-shard-3-of-3.json").is_file());
    let o = texsim(&["merge", "sh", "--out", "merged"], &d);
    assert!(o.status.success(), "{}", text(&o));
    let full = json(&d.join("full/sweep.json"));
    let merged = json(&d.join("merged/sweep.json"));
    let strip = |v: &serde_json::Value| -> Vec<serde_json::Value> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|r| {
                let mut r = r.clone();
                for k in ["hw_ms", "ref_ms", "provenance"] {
                    r.as_object_mut().unwrap().remove(k);
                }
                r
            })
            .collect()
    };
    assert_eq!(strip(&full).len(), 6);
    assert_eq!(strip(&full), strip(&merged));
    let csv = |p: &str| -> Vec<String> {
        std::fs::read_to_string(d.join(p))
            .unwrap()
            .lines()
            .map(|l| l.split(',').take(20).collect::<Vec<_>>().join(","))
            .collect()
    };
    assert_eq!(csv("full/sweep.csv"), csv("merged/sweep.csv"));
    for bad in ["0/3", "4/3", "x/3", "3"] {
        let mut a = axes.to_vec();
        a.extend(["--shard", bad]);
        let o = sweep(&d, &a);
        assert_eq!(o.status.code(), Some(1), "{bad}");
        assert!(text(&o).contains("--shard"), "{bad}: {}", text(&o));
    }
}

#[test]
fn a_sweep_plan_file_runs_and_the_command_line_adds_to_it() {
    let d = tmp("plan");
    std::fs::write(
        d.join("plan.toml"),
        "scene = \"demo\"\nwidth = 48\nheight = 36\nvary = [\"weight_bits=2..3\"]\nno_cycles = true\nout = \"p\"\n",
    )
    .unwrap();
    let o = texsim(&["sweep", "plan.toml", "--vary", "texel_bits=6,8"], &d);
    assert!(o.status.success(), "{}", text(&o));
    let rows = json(&d.join("p/sweep.json"));
    let rows = rows.as_array().unwrap();
    assert_eq!(rows.len(), 4);
    assert_eq!(rows[1]["settings"][0][0], "weight_bits");
    assert_eq!(
        rows[1]["settings"][1],
        serde_json::json!(["texel_bits", "8"])
    );
    assert!(rows[0]["cycles"].is_null(), "no_cycles from the plan");
    std::fs::write(
        d.join("bad.toml"),
        "vary = [\"weight_bits=2\"]\nbogus = 1\n",
    )
    .unwrap();
    let o = texsim(&["sweep", "bad.toml"], &d);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        text(&o).contains("bad.toml") && text(&o).contains("bogus"),
        "{}",
        text(&o)
    );
    let o = texsim(&["sweep", "--scene", "demo"], &d);
    assert_eq!(o.status.code(), Some(1));
    assert!(text(&o).contains("--vary"), "{}", text(&o));
}

/// Rows that share the float passes (a blind axis, `weight_bits`, beside one that reaches
/// them, `subpixel_bits`, alternating keys) measure what each row measures alone.
#[test]
fn rows_sharing_float_passes_equal_rows_rendered_alone() {
    let d = tmp("float-passes");
    let axes = ["--vary", "weight_bits=2,8", "--vary", "subpixel_bits=1,8"];
    let mut extra = axes.to_vec();
    extra.extend(["--out", "all"]);
    let o = sweep(&d, &extra);
    assert!(o.status.success(), "{}", text(&o));
    let rows = json(&d.join("all/sweep.json"));
    let rows = rows.as_array().unwrap();
    assert_eq!(rows.len(), 4);
    for (i, r) in rows.iter().enumerate() {
        let (w, s) = (["2", "8"][i / 2], ["1", "8"][i % 2]);
        let (wv, sv) = (format!("weight_bits={w}"), format!("subpixel_bits={s}"));
        let out = format!("one{i}");
        let o = sweep(&d, &["--vary", &wv, "--vary", &sv, "--out", &out]);
        assert!(o.status.success(), "{}", text(&o));
        let alone = &json(&d.join(format!("{out}/sweep.json")))[0];
        for k in ["error_8bit", "error_16bit", "worst_pixel"] {
            assert_eq!(r[k], alone[k], "row {i} {k}");
        }
    }
}
