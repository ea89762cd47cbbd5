//! `texsim fit` (Fournier lobe fit per level) and the Fournier scenes on the command line.

use crate::cli_common::{texsim, text, tmp};

/// The fit prints one row per K and level with its residual and time; on the two-slope
/// `grooves` map the coarse levels' residual drops from K = 1 to K = 2 (one lobe cannot hold
/// two slopes, two can); bad parameters fail naming the flag.
#[test]
fn fit_prints_residual_and_time_per_level() {
    let d = tmp("fit");
    let o = texsim(&["fit", "--size", "32", "--lobes", "1,2"], &d);
    assert!(o.status.success(), "{}", text(&o));
    let out = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(out.contains("residual") && out.contains("time_ms"), "{out}");
    let rows: Vec<Vec<f64>> = out
        .lines()
        .skip(2)
        .map(|l| l.split_whitespace().map(|c| c.parse().expect(c)).collect())
        .collect();
    assert_eq!(rows.len(), 2 * 6, "K = 1, 2 over levels 0..=5");
    let top = |k: f64| rows.iter().find(|r| r[0] == k && r[1] == 5.0).expect("row")[6];
    assert!(
        top(1.0) > 0.1 && top(2.0) < 1e-9,
        "{} {}",
        top(1.0),
        top(2.0)
    );
    for (args, flag) in [
        (vec!["fit", "--size", "30"], "--size"),
        (vec!["fit", "--lobes", "0"], "fournier_lobes"),
        (vec!["fit", "--normals", "nope"], "nope"),
    ] {
        let o = texsim(&args, &d);
        assert!(!o.status.success());
        assert!(text(&o).contains(flag), "{}", text(&o));
    }
}

/// The Fournier scenes render from the command line with the `lobe-shade` stage in the
/// summary.
#[test]
fn fournier_scene_renders() {
    let d = tmp("render");
    let o = texsim(
        &[
            "render",
            "--scene",
            "fournier-fig2",
            "--width",
            "120",
            "--height",
            "32",
            "--out",
            "o",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", text(&o));
    let t = text(&o);
    assert!(t.contains("lobe-shade    fixed"), "{t}");
    assert!(d.join("o/hw.png").exists() && d.join("o/ref.png").exists());
}

/// The command: `texsim sweep --scene two-slope --truth --vary fournier_lobes=1,2,4,8`
/// (at 96 x 64) gives the model error against the supersampled truth falling with K (K = 4 and
/// 8 agree: no texel of the V-grooves has more than four distinct normals) and the cost rising.
#[test]
fn two_slope_sweep_model_error_falls_with_k() {
    let d = tmp("two-slope");
    let o = texsim(
        &[
            "sweep",
            "--scene",
            "two-slope",
            "--truth",
            "--vary",
            "fournier_lobes=1,2,4,8",
            "--width",
            "96",
            "--height",
            "64",
            "--out",
            "s",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", text(&o));
    let csv = std::fs::read_to_string(d.join("s/sweep.csv")).expect("csv");
    let mut lines = csv.lines();
    let head: Vec<&str> = lines.next().expect("header").split(',').collect();
    let col = |name: &str| head.iter().position(|h| *h == name).expect(name);
    let (k, model, cyc) = (
        col("fournier_lobes"),
        col("model_error.mean_abs_lsb"),
        col("cycles"),
    );
    let rows: Vec<[f64; 3]> = lines
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            [k, model, cyc].map(|i| c[i].parse::<f64>().expect(c[i]))
        })
        .collect();
    assert_eq!(rows.len(), 4, "{csv}");
    assert_eq!(
        rows.iter().map(|r| r[0]).collect::<Vec<_>>(),
        [1.0, 2.0, 4.0, 8.0]
    );
    assert!(rows[1][1] < 0.8 * rows[0][1], "{csv}");
    assert!(
        rows[2][1] < rows[1][1] && rows[3][1] <= rows[2][1] + 1e-9,
        "{csv}"
    );
    assert!(
        rows.windows(2).all(|w| w[1][2] > w[0][2]),
        "cycles rise with K: {csv}"
    );
}
