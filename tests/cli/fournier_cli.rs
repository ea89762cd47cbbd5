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
