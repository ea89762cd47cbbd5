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
    assert!(t.contains("cyc/px") && t.contains("tex_bytes"), "{t}");
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("s").join("sweep.json")).expect("json"))
            .expect("parse");
    let rows = j.as_array().expect("rows");
    let c: Vec<u64> = rows
        .iter()
        .map(|r| r["cycles"].as_u64().expect("cycles"))
        .collect();
    assert_eq!(c.len(), 2);
    assert!(c[1] > c[0], "4 probes cost more than 1: {c:?}");
    // With --no-cycles the timing model does not run: no cycles, no bytes.
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
            "--no-cycles",
            "--out",
            "s2",
        ],
        &d,
    );
    assert!(o.status.success());
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("s2").join("sweep.json")).expect("json"))
            .expect("parse");
    let row = &j.as_array().expect("rows")[0];
    for k in ["cycles", "cycles_per_pixel", "texture_bytes", "dram_bytes"] {
        assert!(row[k].is_null(), "{k}: {row}");
    }
    assert!(row["issue_cycles"].as_u64().expect("issue cycles") > 0);
}

/// The total of a line `PREFIX N ...` of the output (the first number after the prefix).
fn total_after(t: &str, prefix: &str) -> u64 {
    let line = t
        .lines()
        .find(|l| l.starts_with(prefix))
        .unwrap_or_else(|| panic!("no line '{prefix}' in:\n{t}"));
    line[prefix.len()..]
        .split(|c: char| !c.is_ascii_digit())
        .find(|w| !w.is_empty())
        .and_then(|w| w.parse().ok())
        .unwrap_or_else(|| panic!("no number in '{line}'"))
}

/// One cycle figure: `render` prints the timing model's total, the same `cycles` prints, and
/// `summary.json` and `cycles.json` hold it; `--no-cycles` prints none.
#[test]
fn render_and_cycles_print_the_same_cycle_count() {
    let d = tmp("onecycle");
    for (scene, hw) in [
        ("demo", "texram16"),
        ("bumps", "d3d11"),
        ("lake", "texram16"),
    ] {
        let size = ["--width", "96", "--height", "72"];
        let mut args = vec!["render", "--scene", scene, "--hw", hw, "--out", "r"];
        args.extend(size);
        let r = texsim(&args, &d);
        let rt = text(&r);
        assert!(r.status.success(), "{rt}");
        let mut args = vec!["cycles", "--scene", scene, "--hw", hw, "--out", "c"];
        args.extend(size);
        let c = texsim(&args, &d);
        let ct = text(&c);
        assert!(c.status.success(), "{ct}");
        let from_render = total_after(&rt, "cycles (timing model): ");
        let from_cycles = total_after(&ct, "total cycles ");
        assert_eq!(from_render, from_cycles, "{scene} on {hw}:\n{rt}\n{ct}");
        let json = |p: &str| -> serde_json::Value {
            serde_json::from_slice(&std::fs::read(d.join(p)).expect("json")).expect("parse")
        };
        assert_eq!(
            json("r/summary.json")["stats"]["timing"]["total_cycles"],
            json("c/cycles.json")["timing"]["total_cycles"]
        );
        // No other line calls the per-op sum "cycles".
        for l in rt.lines().filter(|l| l.contains("cycles")) {
            assert!(
                l.starts_with("cycles (timing model)")
                    || l.starts_with("issue cycles")
                    || l.starts_with("stage ")
                    || l.starts_with("datapath: ")
                    || l.starts_with("wall time"),
                "a line calls something else cycles: {l}"
            );
        }
    }
    let o = texsim(
        &[
            "render",
            "--scene",
            "demo",
            "--width",
            "32",
            "--height",
            "24",
            "--no-cycles",
            "--out",
            "n",
        ],
        &d,
    );
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(
        t.contains("cycles: not counted") && !t.contains("cycles (timing model)"),
        "{t}"
    );
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("n/summary.json")).expect("json"))
            .expect("parse");
    assert!(j["stats"]["timing"].is_null());
}

/// Storage follows the format: halving `texel_bits` halves the texture bytes (every map of
/// demo is stored at `texel_bits`) and moves DRAM traffic and cycles; the error grows.
#[test]
fn sweep_texel_bits_moves_bytes_and_cycles() {
    let d = tmp("texelbits");
    for hw in ["texram16", "d3d11"] {
        let o = texsim(
            &[
                "sweep",
                "--scene",
                "demo",
                "--width",
                "128",
                "--height",
                "96",
                "--hw",
                hw,
                "--vary",
                "texel_bits=8,16",
                "--cycles",
                "--out",
                hw,
            ],
            &d,
        );
        let t = text(&o);
        assert!(o.status.success(), "{t}");
        let j: serde_json::Value =
            serde_json::from_slice(&std::fs::read(d.join(hw).join("sweep.json")).expect("json"))
                .expect("parse");
        let rows = j.as_array().expect("rows");
        let u = |i: usize, k: &str| rows[i][k].as_u64().unwrap_or_else(|| panic!("{k}"));
        assert_eq!(
            2 * u(0, "texture_bytes"),
            u(1, "texture_bytes"),
            "{hw}: {t}"
        );
        assert_ne!(u(0, "dram_bytes"), u(1, "dram_bytes"), "{hw}: {t}");
        assert!(
            u(0, "cycles") < u(1, "cycles"),
            "{hw}: narrower texels are cheaper: {t}"
        );
        let rmse = |i: usize| rows[i]["error_8bit"]["rmse_lsb"].as_f64().expect("rmse");
        assert!(rmse(0) > rmse(1), "{hw}: {t}");
    }
}

/// The sweep rows of `args` (run in `d`, output directory `out`).
fn sweep_rows(d: &std::path::Path, args: &[&str], out: &str) -> (String, Vec<serde_json::Value>) {
    let mut a = vec!["sweep"];
    a.extend(args);
    a.extend(["--out", out]);
    let o = texsim(&a, d);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join(out).join("sweep.json")).expect("json"))
            .expect("parse");
    (t, j.as_array().expect("rows").clone())
}

/// What accuracy costs: wider filter weights lower the error and raise the area and the
/// trilinear unit's delay, each row beside its cycles; the table shows the changed units.
#[test]
fn sweep_weight_bits_shows_error_falling_and_cost_rising() {
    let d = tmp("weightcost");
    let (t, rows) = sweep_rows(
        &d,
        &[
            "--scene",
            "demo",
            "--width",
            "96",
            "--height",
            "72",
            "--vary",
            "weight_bits=4,8,12,16",
            "--cycles",
        ],
        "s",
    );
    assert_eq!(rows.len(), 4);
    for col in [
        "area_ge",
        "max_lat",
        "area:trilinear",
        "delay:trilinear",
        "cycles",
    ] {
        assert!(t.contains(col), "column {col}: {t}");
    }
    let f = |i: usize, k: &str| rows[i][k].as_f64().unwrap_or_else(|| panic!("{k}"));
    let tri = |i: usize, k: &str| rows[i]["unit_cost"]["trilinear"][k].as_u64().expect(k);
    for (i, row) in rows.iter().enumerate().skip(1) {
        assert!(
            f(i, "area_ge") > f(i - 1, "area_ge"),
            "area rises with the width: {t}"
        );
        assert!(
            tri(i, "delay") > tri(i - 1, "delay"),
            "trilinear delay: {t}"
        );
        assert!(tri(i, "area_ge") > tri(i - 1, "area_ge"), "{t}");
        assert!(row["cycles"].as_u64().expect("cycles") > 0);
    }
    let rmse = |i: usize| rows[i]["error_8bit"]["rmse_lsb"].as_f64().expect("rmse");
    assert!(rmse(0) > rmse(1) && rmse(1) > rmse(3), "error falls: {t}");
}

/// The clock target: fewer gate levels per cycle pipeline every unit deeper, so latencies and
/// the frame's cycles rise; areas do not change.
#[test]
fn sweep_gate_levels_per_cycle_changes_latency_and_cycles() {
    let d = tmp("glpc");
    let (t, rows) = sweep_rows(
        &d,
        &[
            "--scene",
            "bumps",
            "--width",
            "64",
            "--height",
            "48",
            "--vary",
            "gate_levels_per_cycle=8,16,64",
        ],
        "s",
    );
    let u = |i: usize, k: &str| rows[i][k].as_u64().unwrap_or_else(|| panic!("{k}"));
    assert!(u(0, "max_latency") > u(1, "max_latency"), "{t}");
    assert!(u(1, "max_latency") > u(2, "max_latency"), "{t}");
    assert!(u(0, "issue_cycles") > u(2, "issue_cycles"), "{t}");
    assert_ne!(u(0, "cycles"), u(2, "cycles"), "{t}");
    assert_eq!(u(0, "area_ge"), u(2, "area_ge"), "{t}");
}
