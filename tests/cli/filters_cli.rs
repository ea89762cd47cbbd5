//! `texsim filters`: the filtering-method comparison at small size: the table's shape (one
//! row per scene and method, every column in the terminal table, CSV, JSON and Markdown), its
//! sanity (finite errors, costs that grow with the maps a method reads) and the point of the
//! comparison (a method that models the normals under the footprint beats the plain bump map
//! on model error on at least one scene).

use crate::cli_common::{texsim, text, tmp};

const METHODS: [&str; 12] = [
    "plain",
    "toksvig",
    "lean",
    "schilling",
    "ndf-partial",
    "ndf-map",
    "ndf-projected",
    "ndf-exact",
    "fournier-1",
    "fournier-2",
    "fournier-4",
    "fournier-8",
];

#[test]
fn filters_table_shape_and_sanity() {
    let d = tmp("filters");
    let o = texsim(
        &[
            "filters",
            "--scene",
            "lake",
            "--scene",
            "ripple-sphere",
            "--width",
            "120",
            "--height",
            "80",
            "--truth",
            "4",
            "--no-cycles",
            "--out",
            "out",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", text(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    for h in [
        "model mean",
        "quant max / mean",
        "bytes/texel",
        "texels/px",
        "issue cyc/px",
    ] {
        assert!(stdout.contains(h), "column {h}: {stdout}");
    }
    let csv = std::fs::read_to_string(d.join("out/filters.csv")).expect("filters.csv");
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 1 + 2 * METHODS.len(), "{csv}");
    let md = std::fs::read_to_string(d.join("out/filters.md")).expect("filters.md");
    assert_eq!(md.lines().count(), 2 + 2 * METHODS.len(), "{md}");
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("out/filters.json")).expect("filters.json"))
            .expect("json");
    let rows = json.as_array().expect("array");
    assert_eq!(rows.len(), 2 * METHODS.len());
    let get = |scene: &str, method: &str| {
        rows.iter()
            .find(|r| r["scene"] == scene && r["method"] == method)
            .unwrap_or_else(|| panic!("no row {scene} {method}"))
    };
    let mut beaten = false;
    for scene in ["lake", "ripple-sphere"] {
        for m in METHODS {
            let r = get(scene, m);
            let model = r["model_mean"].as_f64().expect("model_mean");
            let q = r["quant_mean"].as_f64().expect("quant_mean");
            assert!((0.0..255.0).contains(&model), "{r}");
            assert!((0.0..2.0).contains(&q), "{r}");
            assert!(r["covered_pixels"].as_u64().expect("px") > 0);
            if m == "ndf-exact" {
                assert!(
                    r["issue_cycles_per_pixel"].is_null(),
                    "exact has no cost model"
                );
            } else {
                assert!(r["issue_cycles_per_pixel"].as_f64().expect("cyc") > 0.0);
            }
        }
        let plain = get(scene, "plain");
        let tok = get(scene, "toksvig");
        // One trilinear lookup (8 texels) for the plain bump map, one more for Toksvig.
        assert_eq!(plain["texels_per_pixel"].as_f64(), Some(8.0), "{plain}");
        assert_eq!(tok["texels_per_pixel"].as_f64(), Some(16.0), "{tok}");
        assert!(tok["bytes_per_texel"].as_u64() > plain["bytes_per_texel"].as_u64());
        assert!(tok["issue_cycles_per_pixel"].as_f64() > plain["issue_cycles_per_pixel"].as_f64());
        // Fitted lobes: one single-level lookup (4 texels) per lobe, cost rising with K.
        let lobes: Vec<&serde_json::Value> =
            ["fournier-1", "fournier-2", "fournier-4", "fournier-8"]
                .iter()
                .map(|m| get(scene, m))
                .collect();
        for (r, k) in lobes.iter().zip([1.0, 2.0, 4.0, 8.0]) {
            assert_eq!(r["texels_per_pixel"].as_f64(), Some(4.0 * k), "{r}");
        }
        for w in lobes.windows(2) {
            assert!(
                w[1]["issue_cycles_per_pixel"].as_f64() > w[0]["issue_cycles_per_pixel"].as_f64()
            );
            assert!(w[1]["bytes_per_texel"].as_u64() > w[0]["bytes_per_texel"].as_u64());
        }
        let p = plain["model_mean"].as_f64().unwrap_or(0.0);
        for m in ["toksvig", "lean", "schilling", "ndf-projected"] {
            if get(scene, m)["model_mean"].as_f64().unwrap_or(f64::MAX) < p {
                beaten = true;
            }
        }
    }
    assert!(
        beaten,
        "no filtering method beats the plain bump map: {stdout}"
    );
}

#[test]
fn filters_rejects_unknown_methods_and_scenes_without_bumps() {
    let d = tmp("filters-bad");
    let o = texsim(
        &["filters", "--scene", "lake", "--method", "fournier-9"],
        &d,
    );
    assert!(!o.status.success());
    assert!(
        text(&o).contains("unknown filtering method 'fournier-9'"),
        "{}",
        text(&o)
    );
    assert!(text(&o).contains("toksvig"), "{}", text(&o));
    let o = texsim(
        &[
            "filters", "--scene", "sphere", "--width", "32", "--height", "32",
        ],
        &d,
    );
    assert!(!o.status.success());
    assert!(text(&o).contains("no bump material"), "{}", text(&o));
}
