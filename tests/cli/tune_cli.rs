//! `texsim tune` and `texsim render --ranges` as users run them.

use crate::cli_common::{texsim, text, tmp};

#[test]
fn tune_writes_its_trials_and_a_machine_render_accepts() {
    let d = tmp("tune");
    let o = texsim(
        &[
            "tune",
            "--scene",
            "demo",
            "--budget",
            "max8=1",
            "--knob",
            "weight_bits,texel_bits,lod_frac_bits",
            "--size",
            "48x36",
            "--out",
            "t",
        ],
        &d,
    );
    let out = text(&o);
    assert!(o.status.success(), "{out}");
    let line = out
        .lines()
        .find(|l| l.starts_with("renders: "))
        .unwrap_or_else(|| panic!("no renders line: {out}"));
    // "renders: R used for T trials; the full grid of 3 knobs is P points = G renders"
    let num = |after: &str| -> f64 {
        let rest = &line[line.find(after).expect(after) + after.len()..];
        rest.split_whitespace().next().unwrap().parse().unwrap()
    };
    let renders = num("renders: ");
    let grid = num("points = ");
    // weight_bits 0..=16, texel_bits 1..=16, lod_frac_bits 0..=16.
    assert_eq!(grid, 17.0 * 16.0 * 17.0, "{line}");
    assert!(renders > 0.0 && renders < grid / 10.0, "{line}");
    assert!(out.contains("verified (knobs vs base): #"), "{out}");
    // The knob table: each knob's found, base and least value and whether the scene exercises it.
    assert!(
        out.lines()
            .any(|l| l.starts_with("knob ") && l.ends_with(" exercised")),
        "{out}"
    );
    for knob in ["weight_bits", "texel_bits", "lod_frac_bits"] {
        assert_eq!(knob_row(&out, knob)[4], "yes", "{knob}: {out}");
    }
    for f in ["tune.json", "tune.csv", "tuned.toml"] {
        assert!(d.join("t").join(f).is_file(), "{f}");
    }
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("t/tune.json")).unwrap()).unwrap();
    assert_eq!(json["renders"].as_f64(), Some(renders));
    let best = &json["trials"][json["best"].as_u64().unwrap() as usize];
    assert_eq!(best["phase"], "verify");
    assert_eq!(best["meets"], true);
    let csv = std::fs::read_to_string(d.join("t/tune.csv")).unwrap();
    assert_eq!(
        csv.lines().count(),
        json["trials"].as_array().unwrap().len() + 1
    );
    // The found machine renders within the budget.
    let r = texsim(
        &[
            "render",
            "--scene",
            "demo",
            "--width",
            "48",
            "--height",
            "36",
            "--hw",
            "t/tuned.toml",
            "--no-cycles",
            "--out",
            "r",
        ],
        &d,
    );
    assert!(r.status.success(), "{}", text(&r));
    let s: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("r/summary.json")).unwrap()).unwrap();
    assert_eq!(s["hw_config"]["name"], "tuned");
    assert!(s["stats"]["error_8bit"]["max_abs_lsb"].as_u64().unwrap() <= 1);
}

/// A depth buffer too narrow for the scene is an error the search sees (the float passes'
/// depth test is exact): at 8 bits the far part of the demo's ground plane rounds to the
/// cleared maximum and vanishes, so the search keeps more bits, and the found machine covers
/// every pixel texram16 covers.
#[test]
fn tune_keeps_the_depth_bits_the_scene_needs() {
    let d = tmp("tune-depth");
    let args = "tune --scene demo --budget max8=1 --knob depth_bits --size 160x120 --out t";
    let o = texsim(&args.split(' ').collect::<Vec<_>>(), &d);
    let out = text(&o);
    assert!(o.status.success(), "{out}");
    let cols = knob_row(&out, "depth_bits");
    let found: u32 = cols[1].parse().unwrap();
    assert!(found > 8 && found <= 24, "{cols:?}");
    assert_eq!(cols[4], "yes", "{cols:?}");
    let covered = |hw: &str, dir: &str| -> u64 {
        let args = "render --scene demo --width 160 --height 120 --no-cycles --no-flip";
        let mut args: Vec<&str> = args.split(' ').collect();
        args.extend(["--hw", hw, "--out", dir]);
        let r = texsim(&args, &d);
        assert!(r.status.success(), "{}", text(&r));
        let s: serde_json::Value =
            serde_json::from_slice(&std::fs::read(d.join(dir).join("summary.json")).unwrap())
                .unwrap();
        s["stats"]["raster"]["visible"].as_u64().unwrap()
    };
    assert_eq!(
        covered("t/tuned.toml", "found"),
        covered("texram16", "base")
    );
}

#[test]
fn tune_bad_budget_and_knob_fail_with_the_flag_named() {
    let d = tmp("tune-bad");
    for (args, want) in [
        (vec!["--budget", "max9=1"], "--budget"),
        (
            vec!["--budget", "max8=1", "--knob", "weight_bit"],
            "weight_bits",
        ),
        (vec!["--budget", "max8=1", "--size", "48"], "--size"),
        (
            vec!["--budget", "max8=1", "--size", "32x24", "--truth", "2"],
            "drop --truth",
        ),
    ] {
        let mut a = vec!["tune", "--scene", "demo"];
        a.extend(args);
        let o = texsim(&a, &d);
        assert!(!o.status.success());
        assert!(text(&o).contains(want), "{}", text(&o));
    }
}

#[test]
fn render_ranges_prints_and_writes_the_bits_needed() {
    let d = tmp("ranges");
    let o = texsim(
        &[
            "render",
            "--scene",
            "bumps",
            "--width",
            "64",
            "--height",
            "48",
            "--ranges",
            "--no-cycles",
            "--out",
            "o",
        ],
        &d,
    );
    let out = text(&o);
    assert!(o.status.success(), "{out}");
    assert!(out.contains("signal ranges"), "{out}");
    let s: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("o/summary.json")).unwrap()).unwrap();
    let rows = s["stats"]["ranges"].as_array().expect("stats.ranges");
    let perturb = rows
        .iter()
        .find(|r| r["signal"] == "normal")
        .expect("perturbed normal");
    assert!(perturb["int_bits_needed"].as_u64().unwrap() <= 1);
    assert!(perturb["max"].as_f64().unwrap() <= 1.0 + 1e-9);
}

/// The columns of `knob`'s row in tune's knob table (`field found base least exercised [*]`).
fn knob_row<'a>(out: &'a str, knob: &str) -> Vec<&'a str> {
    out.lines()
        .map(|l| l.split_whitespace().collect::<Vec<_>>())
        .find(|cols| cols.first().is_some_and(|f| f.ends_with(knob)) && cols.len() >= 5)
        .unwrap_or_else(|| panic!("no row of {knob}: {out}"))
}
