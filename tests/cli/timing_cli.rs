//! `texsim cycles` and `texsim sweep --cycles` as users see them.

use crate::cli_common::{texsim, text, tmp};

#[test]
fn cycles_prints_the_report_and_writes_json() {
    let d = tmp("cycles");
    for hw in ["texram16", "d3d11"] {
        let o = texsim(
            &[
                "cycles", "--scene", "demo", "--width", "128", "--height", "96", "--hw", hw,
                "--out", hw,
            ],
            &d,
        );
        let t = text(&o);
        assert!(o.status.success(), "{t}");
        for needle in [
            "total cycles",
            "cycles/pixel",
            "utilization",
            "stall cause",
            "cache hit rate",
            "bank conflicts",
            "bottleneck",
        ] {
            assert!(t.contains(needle), "missing '{needle}' in:\n{t}");
        }
        let j: serde_json::Value = serde_json::from_slice(
            &std::fs::read(d.join(hw).join("cycles.json")).expect("cycles.json"),
        )
        .expect("json");
        let tot = j["timing"]["total_cycles"].as_u64().expect("total");
        assert!(tot > 0);
        assert_eq!(j["timing"]["hw"], hw);
        assert!(j["timing"]["units"].as_array().is_some_and(|u| u.len() > 4));
    }
}

#[test]
fn cycles_rejects_bad_input_with_a_named_error() {
    let d = tmp("bad");
    let o = texsim(&["cycles", "--scene", "demo", "--hw", "nope"], &d);
    assert!(!o.status.success());
    assert!(text(&o).contains("nope"));
    std::fs::write(d.join("hw.toml"), "[timing]\nbanks = 3\n").expect("write");
    let o = texsim(&["cycles", "--scene", "demo", "--hw", "hw.toml"], &d);
    assert!(!o.status.success());
    assert!(text(&o).contains("timing.banks"), "{}", text(&o));
}

#[test]
fn sweep_with_cycles_adds_the_timing_column() {
    let d = tmp("sweep");
    let o = texsim(
        &[
            "sweep",
            "--scene",
            "w1-plane",
            "--width",
            "64",
            "--height",
            "64",
            "--vary",
            "aniso_probes=1,4",
            "--cycles",
            "--out",
            "s",
        ],
        &d,
    );
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(t.contains("timing_cycles"), "{t}");
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("s").join("sweep.json")).expect("json"))
            .expect("parse");
    let rows = j.as_array().expect("rows");
    let c: Vec<u64> = rows
        .iter()
        .map(|r| r["timing_cycles"].as_u64().expect("cycles"))
        .collect();
    assert_eq!(c.len(), 2);
    assert!(c[1] > c[0], "4 probes cost more than 1: {c:?}");
    // Without --cycles the column is absent.
    let o = texsim(
        &[
            "sweep",
            "--scene",
            "w1-plane",
            "--width",
            "32",
            "--height",
            "32",
            "--vary",
            "aniso_probes=1",
            "--out",
            "s2",
        ],
        &d,
    );
    assert!(o.status.success());
    assert!(!text(&o).contains("timing_cycles"));
}
