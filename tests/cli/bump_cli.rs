//! The bump-mapping command line: `texsim render --scene bumps`, the frame sweep with its
//! `frame` alias, the knobs of the shading units, and the real mesh's TOML scene.

use crate::cli_common::{texsim, text, tmp};
use std::path::Path;

#[test]
fn scenes_lists_bumps_and_render_reports_bump_stages() {
    let d = tmp("render");
    let o = texsim(&["scenes"], &d);
    assert!(o.status.success());
    assert!(text(&o).contains("bumps"));
    let o = texsim(
        &[
            "render", "--scene", "bumps", "--width", "160", "--height", "120", "--out", "o",
        ],
        &d,
    );
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    for stage in ["normal", "bump-fetch", "frame", "perturb", "phong"] {
        assert!(t.contains(stage), "{stage} missing in {t}");
    }
    let json = std::fs::read_to_string(d.join("o/summary.json")).expect("summary");
    let v: serde_json::Value = serde_json::from_str(&json).expect("json");
    assert_eq!(v["stats"]["bump"]["frame"].as_str(), Some("main"), "{json}");
    assert_eq!(v["stats"]["bump"]["ref_nonfinite"].as_u64(), Some(0));
    assert!(t.contains("bump mapping: frame main"), "{t}");
}

/// The rows of a sweep CSV as (column name -> cell) maps.
fn csv_rows(csv: &str) -> Vec<std::collections::HashMap<String, String>> {
    let mut lines = csv.lines();
    let head: Vec<String> = lines
        .next()
        .expect("header")
        .split(',')
        .map(str::to_string)
        .collect();
    lines
        .map(|l| {
            head.iter()
                .cloned()
                .zip(l.split(',').map(str::to_string))
                .collect()
        })
        .collect()
}

fn num(row: &std::collections::HashMap<String, String>, col: &str) -> f64 {
    row.get(col)
        .and_then(|c| c.parse().ok())
        .unwrap_or_else(|| panic!("column {col} in {row:?}"))
}

/// Each frame row reports the frame it really used, and the frames differ in cost (the
/// interpolated attributes and the frame unit differ) and in error.
#[test]
fn sweep_over_frames_reports_each() {
    let d = tmp("sweep");
    let o = texsim(
        &[
            "sweep",
            "--scene",
            "bumps",
            "--width",
            "160",
            "--height",
            "120",
            "--vary",
            "frame=natural,unit,main",
            "--out",
            "s",
        ],
        &d,
    );
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(!t.contains("has no effect"), "{t}");
    let csv = std::fs::read_to_string(d.join("s/sweep.csv")).expect("csv");
    let rows = csv_rows(&csv);
    assert_eq!(rows.len(), 3, "{csv}");
    for (r, f) in rows.iter().zip(["natural", "unit", "main"]) {
        assert_eq!(r["frame"], f, "{csv}");
        assert_eq!(r["frame_used"], f, "{csv}");
        assert_eq!(num(r, "frame_fallback"), 0.0);
        assert_eq!(num(r, "zero_normal"), 0.0);
    }
    let cycles: Vec<f64> = rows.iter().map(|r| num(r, "issue_cycles")).collect();
    let rmse: Vec<f64> = rows
        .iter()
        .map(|r| num(r, "error_16bit.rmse_lsb"))
        .collect();
    assert!(
        cycles[0] != cycles[1] && cycles[1] != cycles[2] && cycles[0] != cycles[2],
        "{cycles:?}"
    );
    assert!(rmse[0] != rmse[1] && rmse[0] != rmse[2], "{rmse:?}");
    let json = std::fs::read_to_string(d.join("s/sweep.json")).expect("json");
    let v: serde_json::Value = serde_json::from_str(&json).expect("json");
    assert_eq!(v[2]["frame_used"].as_str(), Some("main"), "{json}");
    // A bad value is an error naming the field.
    let o = texsim(
        &[
            "sweep",
            "--scene",
            "bumps",
            "--vary",
            "frame=diagonal",
            "--out",
            "x",
        ],
        &d,
    );
    assert!(!o.status.success());
    assert!(text(&o).contains("frame_kind"), "{}", text(&o));
}

/// A frame sweep over a scene whose every bump material pins its own `frame` cannot change
/// the frame: the rows say which frame was used and the command warns.
#[test]
fn frame_sweep_over_pinned_materials_warns() {
    let d = tmp("pinned");
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let src = std::fs::read_to_string(dir.join("bump_column.toml")).expect("toml");
    let abs = |f: &str| dir.join(f).to_str().expect("utf8").replace('\\', "/");
    let pinned = src
        .replace(
            "bump = \"bump_height.png\"",
            &format!("bump = \"{}\"\nframe = \"natural\"", abs("bump_height.png")),
        )
        .replace(
            "obj = \"bump_column.obj\"",
            &format!("obj = \"{}\"", abs("bump_column.obj")),
        );
    assert!(pinned.contains("frame = \"natural\""));
    std::fs::write(d.join("pinned.toml"), pinned).expect("write");
    let o = texsim(
        &[
            "sweep",
            "pinned.toml",
            "--width",
            "80",
            "--height",
            "96",
            "--vary",
            "frame=unit,main",
            "--out",
            "p",
        ],
        &d,
    );
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(t.contains("warning: frame_kind=unit has no effect"), "{t}");
    assert!(t.contains("warning: frame_kind=main has no effect"), "{t}");
    let csv = std::fs::read_to_string(d.join("p/sweep.csv")).expect("csv");
    for r in csv_rows(&csv) {
        assert_eq!(r["frame_used"], "natural", "{csv}");
    }
}

/// The shading units' knobs change the error at coarse settings (fixed vs float, 16-bit RMSE):
/// no Newton step after a 4-bit rsqrt seed, 6-bit vector components, 4-bit offset fractions
/// and a 3-bit pow table each are clearly worse than the fine setting.
#[test]
fn knob_sweeps_change_the_error() {
    let d = tmp("knobs");
    for (i, (fix, vary)) in [
        (Some("rsqrt_lut_bits=4"), "rsqrt_iterations=0,1"),
        (None, "vector_frac_bits=6,14"),
        (None, "offset_frac_bits=4,12"),
        (None, "pow_lut_bits=3,8"),
    ]
    .into_iter()
    .enumerate()
    {
        let out = format!("k{i}");
        let mut args = vec![
            "sweep", "--scene", "bumps", "--width", "160", "--height", "120",
        ];
        if let Some(f) = fix {
            args.extend(["--vary", f]);
        }
        args.extend(["--vary", vary, "--out", &out]);
        let o = texsim(&args, &d);
        assert!(o.status.success(), "{vary}: {}", text(&o));
        let csv = std::fs::read_to_string(d.join(&out).join("sweep.csv")).expect("csv");
        let rows = csv_rows(&csv);
        assert_eq!(rows.len(), 2, "{csv}");
        let (coarse, fine) = (
            num(&rows[0], "error_16bit.rmse_lsb"),
            num(&rows[1], "error_16bit.rmse_lsb"),
        );
        eprintln!("{vary}: rmse16 {coarse} -> {fine}");
        assert!(coarse > 1.5 * fine, "{vary}: {coarse} vs {fine}\n{csv}");
    }
}

#[test]
fn real_mesh_toml_renders() {
    let d = tmp("toml");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/bump_column.toml");
    let o = texsim(
        &[
            "render",
            scene.to_str().expect("utf8"),
            "--width",
            "120",
            "--height",
            "144",
            "--out",
            "c",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", text(&o));
    assert!(d.join("c/sheet.png").exists());
}
