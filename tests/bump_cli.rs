//! The bump-mapping command line: `texsim render --scene bumps`, the frame sweep with its
//! `frame` alias, the knobs of the shading units, and the real mesh's TOML scene.

mod cli_common;

use cli_common::{texsim, text, tmp};
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

#[test]
fn sweep_over_frames_reports_each() {
    let d = tmp("sweep");
    let o = texsim(
        &[
            "sweep",
            "--scene",
            "bumps",
            "--vary",
            "frame=natural,unit,main",
            "--out",
            "s",
        ],
        &d,
    );
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    let csv = std::fs::read_to_string(d.join("s/sweep.csv")).expect("csv");
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 4, "{csv}");
    for (l, f) in lines[1..].iter().zip(["natural", "unit", "main"]) {
        assert!(l.starts_with(f), "{l}");
    }
    // Knobs of the shading units sweep too (and a bad value is an error naming the field).
    let o = texsim(
        &[
            "sweep",
            "--scene",
            "bumps",
            "--vary",
            "rsqrt_lut_bits=4,8",
            "--vary",
            "offset_int_bits=2,3",
            "--out",
            "k",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", text(&o));
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
