//! `texsim vectors` (RTL test vectors, and the SystemVerilog lerp checked against them under
//! Icarus Verilog) and `texsim compare` (image against image), as users run them.

use crate::cli_common::{texsim, text, tmp};
use hw_model::fixed::SatCounter;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

const UNITS: [&str; 6] = ["lerp", "bilinear", "recip", "rsqrt", "wrap", "lod"];

fn run_ok(args: &[&str], cwd: &Path) -> String {
    let o = texsim(args, cwd);
    assert!(o.status.success(), "texsim {args:?} failed: {}", text(&o));
    text(&o)
}

fn manifest(dir: &Path) -> Value {
    let s = std::fs::read_to_string(dir.join("manifest.json")).expect("manifest.json");
    serde_json::from_str(&s).expect("manifest is JSON")
}

/// The values of one port file, checking its comment line, digit count and width.
fn read_port(dir: &Path, port: &Value) -> Vec<i64> {
    let bits = port["bits"].as_u64().unwrap() as u32;
    let signed = port["signed"].as_bool().unwrap();
    let file = port["file"].as_str().unwrap();
    let text = std::fs::read_to_string(dir.join(file)).expect(file);
    let mut lines = text.lines();
    assert!(
        lines.next().unwrap().starts_with("// texsim vectors"),
        "{file}"
    );
    lines
        .map(|l| {
            assert_eq!(l.len(), bits.div_ceil(4) as usize, "{file}: '{l}'");
            let raw = u64::from_str_radix(l, 16).expect("hex");
            assert!(
                bits >= 64 || raw >> bits == 0,
                "{file}: {l} wider than {bits} bits"
            );
            if signed && raw >> (bits - 1) & 1 == 1 {
                (raw as i64) - (1i64 << bits)
            } else {
                raw as i64
            }
        })
        .collect()
}

/// Every port's values by name.
fn columns(dir: &Path) -> Vec<(String, Vec<i64>)> {
    let m = manifest(dir);
    m["ports"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| (p["name"].as_str().unwrap().to_string(), read_port(dir, p)))
        .collect()
}

fn col<'a>(cols: &'a [(String, Vec<i64>)], name: &str) -> &'a [i64] {
    &cols.iter().find(|(n, _)| n == name).expect(name).1
}

#[test]
fn vectors_list_names_every_unit() {
    let d = tmp("list");
    let out = run_ok(&["vectors", "--list"], &d);
    for u in UNITS {
        assert!(
            out.lines().any(|l| l.starts_with(u)),
            "{u} missing from:\n{out}"
        );
    }
}

#[test]
fn vectors_files_match_the_manifest_and_are_seeded() {
    let d = tmp("files");
    for unit in UNITS {
        let (a, b, c) = (
            d.join(unit),
            d.join(format!("{unit}-again")),
            d.join(format!("{unit}-s8")),
        );
        for (dir, seed) in [(&a, "7"), (&b, "7"), (&c, "8")] {
            let dir = dir.to_str().unwrap();
            run_ok(
                &["vectors", unit, "--n", "300", "--seed", seed, "--out", dir],
                &d,
            );
        }
        let m = manifest(&a);
        assert_eq!(m["unit"], unit);
        assert_eq!(m["hw_config"], "texram16");
        assert_eq!(m["seed"], 7);
        assert_eq!(m["random_vectors"], 300);
        assert!(m["texsim_version"].is_string() && m["unit_config"].is_object());
        let n = m["vectors"].as_u64().unwrap() as usize;
        let nb = m["boundary_vectors"].as_u64().unwrap() as usize;
        assert_eq!(n, nb + 300);
        assert!(nb >= 10, "{unit}: only {nb} boundary cases");
        let ports = m["ports"].as_array().unwrap();
        assert!(ports.iter().any(|p| p["direction"] == "input"));
        assert!(ports.iter().any(|p| p["direction"] == "output"));
        for p in ports {
            let file = p["file"].as_str().unwrap();
            let v = read_port(&a, p);
            assert_eq!(v.len(), n, "{unit} {file}");
            let same = std::fs::read(a.join(file)).unwrap();
            assert_eq!(
                same,
                std::fs::read(b.join(file)).unwrap(),
                "{unit} {file}: seed 7 twice"
            );
            let other = read_port(&c, p);
            assert_eq!(
                v[..nb],
                other[..nb],
                "{unit} {file}: boundary cases do not depend on the seed"
            );
        }
        let input = ports.iter().find(|p| p["direction"] == "input").unwrap();
        assert_ne!(
            read_port(&a, input)[nb..],
            read_port(&c, input)[nb..],
            "{unit}: seeds 7 and 8"
        );
    }
}

/// The exact lerp `a + (b - a) w / 2^wb` rounded by `r`, in i128 (independent of hw_model).
fn exact_lerp(a: i64, b: i64, w: i64, wb: u32, r: &str) -> i64 {
    let num = (i128::from(a) << wb) + i128::from(b - a) * i128::from(w);
    if wb == 0 {
        return num as i64;
    }
    let fl = num >> wb;
    let rem = num - (fl << wb);
    let half = 1i128 << (wb - 1);
    let up = match r {
        "truncate" => false,
        "half-up" => rem >= half,
        "half-even" => rem > half || (rem == half && fl & 1 == 1),
        _ => panic!("rounding {r}"),
    };
    (fl + i128::from(up)) as i64
}

#[test]
fn lerp_vectors_cover_the_boundaries_and_equal_the_exact_lerp() {
    let d = tmp("lerp");
    for hw in ["texram16", "d3d11", "vulkan-min"] {
        let dir = d.join(hw);
        run_ok(
            &[
                "vectors",
                "lerp",
                "--hw",
                hw,
                "--n",
                "5000",
                "--out",
                dir.to_str().unwrap(),
            ],
            &d,
        );
        let m = manifest(&dir);
        let ports = m["ports"].as_array().unwrap();
        let wb = ports[2]["frac_bits"].as_u64().unwrap() as u32;
        let tb = ports[0]["bits"].as_u64().unwrap() as u32;
        let rounding = ports[3]["rounding"].as_str().unwrap().to_string();
        let cols = columns(&dir);
        let (a, b, w, y) = (
            col(&cols, "a"),
            col(&cols, "b"),
            col(&cols, "w"),
            col(&cols, "y"),
        );
        let max = (1i64 << tb) - 1;
        let mut ties = 0;
        for k in 0..a.len() {
            assert_eq!(
                y[k],
                exact_lerp(a[k], b[k], w[k], wb, &rounding),
                "{hw} vector {k}"
            );
            let frac = (i128::from(b[k] - a[k]) * i128::from(w[k])).rem_euclid(1i128 << wb);
            ties += usize::from(wb > 0 && frac == 1i128 << (wb - 1));
        }
        for need in [0, 1 << wb, (1 << wb) - 1] {
            assert!(w.contains(&need), "{hw}: weight {need} missing");
        }
        assert!(
            a.contains(&max) && b.contains(&0) && a.contains(&0),
            "{hw}: extreme codes"
        );
        assert!(ties >= 20, "{hw}: only {ties} rounding ties");
    }
}

#[test]
fn other_units_vectors_are_the_units_outputs() {
    let d = tmp("units");
    let hw = texsim::hwconfig::resolve("texram16").unwrap();
    for unit in ["bilinear", "recip", "rsqrt", "wrap", "lod"] {
        let dir = d.join(unit);
        run_ok(
            &[
                "vectors",
                unit,
                "--n",
                "3000",
                "--out",
                dir.to_str().unwrap(),
            ],
            &d,
        );
        let cols = columns(&dir);
        let n = cols[0].1.len();
        match unit {
            "bilinear" => {
                // Three exact lerps in the bilinear order (rows along x, then along y).
                let m = manifest(&dir);
                let wb = m["ports"][4]["frac_bits"].as_u64().unwrap() as u32;
                let r = m["ports"][6]["rounding"].as_str().unwrap().to_string();
                let t = ["t00", "t10", "t01", "t11"].map(|p| col(&cols, p));
                let (wx, wy, y) = (col(&cols, "wx"), col(&cols, "wy"), col(&cols, "y"));
                for k in 0..n {
                    let top = exact_lerp(t[0][k], t[1][k], wx[k], wb, &r);
                    let bot = exact_lerp(t[2][k], t[3][k], wx[k], wb, &r);
                    assert_eq!(y[k], exact_lerp(top, bot, wy[k], wb, &r), "vector {k}");
                }
                assert!(wx.contains(&0) && wx.contains(&((1 << wb) - 1)));
            }
            "recip" => {
                let u = hw_model::reciprocal::Reciprocal::new(&hw.reciprocal);
                let (x, mant, shift, sat) = (
                    col(&cols, "x"),
                    col(&cols, "mant"),
                    col(&cols, "shift"),
                    col(&cols, "sat"),
                );
                assert!(x.contains(&0) && x.contains(&((1i64 << 62) - 1)));
                for k in 0..n {
                    let mut s = SatCounter::default();
                    let r = u.eval(x[k] as u64, &mut s);
                    assert_eq!(
                        (mant[k], shift[k], sat[k]),
                        (
                            r.mant as i64,
                            i64::from(r.shift),
                            i64::from(s.saturated > 0)
                        ),
                        "x {}",
                        x[k]
                    );
                }
                assert_eq!(sat.iter().filter(|&&s| s == 1).count(), 1, "x = 0 once");
            }
            "rsqrt" => {
                let u = hw_model::rsqrt::Rsqrt::new(&hw.shading.rsqrt);
                let (x, mant, shift, valid) = (
                    col(&cols, "x"),
                    col(&cols, "mant"),
                    col(&cols, "shift"),
                    col(&cols, "valid"),
                );
                for k in 0..n {
                    let want = u
                        .eval(x[k] as u64)
                        .map_or((0, 0, 0), |r| (r.mant as i64, i64::from(r.shift), 1));
                    assert_eq!((mant[k], shift[k], valid[k]), want, "x {}", x[k]);
                }
            }
            "wrap" => {
                let (c, size, mode) = (col(&cols, "coord"), col(&cols, "size"), col(&cols, "mode"));
                let (i0, i1, w) = (col(&cols, "i0"), col(&cols, "i1"), col(&cols, "weight"));
                for k in 0..n {
                    let m = [
                        hw_model::wrap::WrapMode::Repeat,
                        hw_model::wrap::WrapMode::ClampToEdge,
                        hw_model::wrap::WrapMode::Mirror,
                    ][mode[k] as usize];
                    let o = hw_model::wrap::wrap(
                        c[k],
                        hw.interp.texcoord_frac_bits,
                        size[k] as u32,
                        m,
                        &hw.trilinear,
                    );
                    assert_eq!(
                        (i0[k], i1[k], w[k]),
                        (i64::from(o.i0), i64::from(o.i1), i64::from(o.weight)),
                        "vector {k}"
                    );
                    assert!(i0[k] < size[k] && i1[k] < size[k]);
                }
                assert!(mode.contains(&0) && mode.contains(&1) && mode.contains(&2));
            }
            _ => {
                let d4 = ["dudx", "dvdx", "dudy", "dvdy"].map(|p| col(&cols, p));
                let (lod, sat) = (col(&cols, "lod"), col(&cols, "sat"));
                let f = hw.interp.texcoord_frac_bits;
                for k in 0..n {
                    let mut s = SatCounter::default();
                    let l = hw_model::lod::lod(
                        [d4[0][k], d4[1][k], d4[2][k], d4[3][k]],
                        f,
                        &hw.lod,
                        &mut s,
                    );
                    assert_eq!(
                        (lod[k], sat[k]),
                        (l, i64::from(s.saturated > 0)),
                        "vector {k}"
                    );
                }
                assert!(
                    lod.contains(&hw_model::lod::lod_zero(hw.lod.lod_frac_bits)),
                    "rho = 0 case"
                );
                assert!(lod.contains(&0), "one texel per pixel");
            }
        }
    }
}

#[test]
fn vectors_bad_input_fails_cleanly_and_writes_nothing() {
    let d = tmp("bad");
    let out = d.join("v");
    let o = texsim(&["vectors", "lerpp", "--out", out.to_str().unwrap()], &d);
    assert_eq!(o.status.code(), Some(1));
    let t = text(&o);
    assert!(
        t.contains("unknown unit 'lerpp'") && t.contains("did you mean 'lerp'"),
        "{t}"
    );
    assert!(!out.exists());
    let o = texsim(
        &[
            "--max-memory",
            "1M",
            "vectors",
            "lerp",
            "--n",
            "100000000",
            "--out",
            out.to_str().unwrap(),
        ],
        &d,
    );
    assert_eq!(o.status.code(), Some(1));
    let t = text(&o);
    assert!(
        t.contains("field '--n'") && t.contains("limit of 1.00 MiB"),
        "{t}"
    );
    assert!(!out.exists());
    let o = texsim(
        &[
            "vectors",
            "lerp",
            "--hw",
            "no-such-hw",
            "--out",
            out.to_str().unwrap(),
        ],
        &d,
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(text(&o).contains("no-such-hw"));
    let file = d.join("a-file");
    std::fs::write(&file, b"x").unwrap();
    let under = file.join("sub");
    let o = texsim(&["vectors", "lerp", "--out", under.to_str().unwrap()], &d);
    assert_eq!(o.status.code(), Some(1));
    assert!(text(&o).contains("a-file"), "{}", text(&o));
    let o = texsim(&["vectors", "lerp", "--n", "-3"], &d);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(!d.join("out").exists());
    assert_eq!(
        std::fs::read_dir(&d).unwrap().count(),
        1,
        "only a-file is left"
    );
}

/// Whether Icarus Verilog is installed. Where it is missing, the test fails with how to install
/// it when `CI` or `TEXSIM_REQUIRE_RTL_SIM` is set (`.ci/run` installs it, so CI always runs the
/// RTL), and is skipped with that note otherwise, so that `cargo test --workspace` passes on a
/// fresh machine without a Debian package.
fn iverilog_installed() -> bool {
    let found = Command::new("iverilog")
        .arg("-V")
        .output()
        .is_ok_and(|o| o.status.success() || !o.stdout.is_empty());
    if found {
        return true;
    }
    let note = "Icarus Verilog is not installed: the SystemVerilog lerp test needs it. Install it \
                with `apt-get update && apt-get install -y iverilog` (Debian package iverilog); \
                .ci/run does";
    let required = ["CI", "TEXSIM_REQUIRE_RTL_SIM"]
        .iter()
        .any(|v| std::env::var_os(v).is_some_and(|x| !x.is_empty() && x != "0" && x != "false"));
    assert!(!required, "{note}");
    eprintln!("skipped: {note}");
    false
}

/// Compiles the SystemVerilog `unit` (lerp or bilinear) and its testbench with the manifest's
/// widths and runs the vectors in `dir`; returns (success, output).
fn simulate(dir: &Path, unit: &str) -> (bool, String) {
    let m = manifest(dir);
    let ports = m["ports"].as_array().unwrap();
    let port = |name: &str| ports.iter().find(|p| p["name"] == name).expect(name);
    let (first, weight) = if unit == "lerp" {
        ("a", "w")
    } else {
        ("t00", "wx")
    };
    let tb = port(first)["bits"].as_u64().unwrap();
    let wb = port(weight)["frac_bits"].as_u64().unwrap();
    let round = match port("y")["rounding"].as_str().unwrap() {
        "truncate" => 0,
        "half-up" => 1,
        _ => 2,
    };
    let n = m["vectors"].as_u64().unwrap();
    let rtl = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("hw_model/rtl");
    let mut sources = vec![rtl.join("lerp.sv")];
    if unit == "bilinear" {
        sources.push(rtl.join("bilinear.sv"));
    }
    sources.push(rtl.join(format!("{unit}_tb.sv")));
    let top = format!("{unit}_tb");
    let c = Command::new("iverilog")
        .args(["-g2012", "-o", "sim"])
        .arg(format!("-P{top}.TB={tb}"))
        .arg(format!("-P{top}.WB={wb}"))
        .arg(format!("-P{top}.ROUND={round}"))
        .arg(format!("-P{top}.N={n}"))
        .args(&sources)
        .current_dir(dir)
        .output()
        .expect("run iverilog");
    assert!(c.status.success(), "iverilog: {}", text(&c));
    let r = Command::new("vvp")
        .args(["-n", "sim"])
        .current_dir(dir)
        .output()
        .expect("run vvp");
    (r.status.success(), text(&r))
}

#[test]
fn systemverilog_lerp_and_bilinear_pass_every_vector_and_catch_a_wrong_one() {
    if !iverilog_installed() {
        return;
    }
    let d = tmp("rtl");
    let custom = |name: &str, body: &str| {
        let p = d.join(format!("{name}.toml"));
        std::fs::write(&p, format!("base = \"texram16\"\n[trilinear]\n{body}\n")).unwrap();
        p.to_str().unwrap().to_string()
    };
    let configs = [
        ("texram16".to_string(), "half-even"),
        ("d3d11".to_string(), "half-even"),
        (
            custom(
                "trunc10",
                "texel_bits = 10\nweight_bits = 5\nfilter_rounding = \"truncate\"",
            ),
            "truncate",
        ),
        (
            custom(
                "halfup8",
                "texel_bits = 8\nweight_bits = 3\nfilter_rounding = \"half-up\"",
            ),
            "half-up",
        ),
        (
            custom("w0", "texel_bits = 12\nweight_bits = 0"),
            "half-even",
        ),
    ];
    for unit in ["lerp", "bilinear"] {
        for (i, (hw, rounding)) in configs.iter().enumerate() {
            let dir = d.join(format!("{unit}{i}"));
            let dir_s = dir.to_str().unwrap();
            run_ok(
                &[
                    "vectors", unit, "--hw", hw, "--n", "10000", "--seed", "3", "--out", dir_s,
                ],
                &d,
            );
            let m = manifest(&dir);
            let y = m["ports"]
                .as_array()
                .unwrap()
                .iter()
                .find(|p| p["name"] == "y")
                .unwrap();
            assert_eq!(y["rounding"], *rounding, "{hw}");
            let n = m["vectors"].as_u64().unwrap();
            let (ok, out) = simulate(&dir, unit);
            assert!(ok, "{unit} {hw}: {out}");
            let line = format!("{unit}_tb: {n} vectors, {n} passed, 0 failed");
            assert!(out.contains(&line), "{unit} {hw}: {out}");
            // Negative control: one wrong expected value is caught.
            let y = dir.join("y.hex");
            let text_y = std::fs::read_to_string(&y).unwrap();
            let mut lines: Vec<String> = text_y.lines().map(str::to_string).collect();
            let k = lines.len() / 2;
            let v = u64::from_str_radix(&lines[k], 16).unwrap();
            let width = lines[k].len();
            lines[k] = format!("{:0width$x}", v ^ 1);
            std::fs::write(&y, lines.join("\n") + "\n").unwrap();
            let (ok, out) = simulate(&dir, unit);
            assert!(!ok, "{unit} {hw}: a wrong expected value passed: {out}");
            let line = format!("{unit}_tb: {n} vectors, {} passed, 1 failed", n - 1);
            assert!(out.contains(&line), "{unit} {hw}: {out}");
            assert!(
                out.contains(&format!("vector {}:", k - 1)),
                "{unit} {hw}: {out}"
            );
            // A truncated file is not a pass either.
            let short = text_y.lines().take(10).collect::<Vec<_>>().join("\n") + "\n";
            std::fs::write(&y, short).unwrap();
            let (ok, out) = simulate(&dir, unit);
            assert!(
                !ok && out.contains(&format!("{} failed", n - 9)),
                "{unit} {hw}: {out}"
            );
        }
    }
}

fn write_png(path: &Path, w: u32, h: u32, px: &[[u8; 4]]) {
    let raw: Vec<u8> = px.iter().flatten().copied().collect();
    image::RgbaImage::from_raw(w, h, raw)
        .unwrap()
        .save(path)
        .unwrap();
}

fn compare_json(dir: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("compare.json")).unwrap()).unwrap()
}

#[test]
fn compare_reports_a_single_bad_pixel() {
    let d = tmp("cmp1");
    let (w, h) = (16u32, 12u32);
    let a: Vec<[u8; 4]> = (0..w * h)
        .map(|i| [(i % 251) as u8, 40, 200, 255])
        .collect();
    let mut b = a.clone();
    b[(5 * w + 9) as usize][1] = 41; // (9, 5): G differs by 1
    b[(2 * w + 3) as usize][3] = 0; // (3, 2): alpha only
    write_png(&d.join("a.png"), w, h, &a);
    write_png(&d.join("b.png"), w, h, &b);
    let out = run_ok(&["compare", "a.png", "b.png", "--out", "cmp"], &d);
    assert!(out.contains("match: 99.479% exact"), "{out}");
    let j = compare_json(&d.join("cmp"));
    assert_eq!(j["metrics"]["pixels"], 192);
    assert_eq!(j["metrics"]["max_abs_lsb"], 1);
    assert_eq!(j["metrics"]["histogram"][1], serde_json::json!(["1", 1]));
    let ch = j["channels"].as_array().unwrap();
    assert_eq!(
        (
            ch[0]["max_abs_lsb"].as_u64(),
            ch[1]["max_abs_lsb"].as_u64(),
            ch[3]["max_abs_lsb"].as_u64()
        ),
        (Some(0), Some(1), Some(255))
    );
    assert_eq!(j["worst"].as_array().unwrap().len(), 1);
    assert_eq!(j["worst"][0]["x"], 9);
    assert_eq!(j["worst"][0]["y"], 5);
    assert_eq!(j["worst"][0]["a"][1], 40);
    assert_eq!(j["worst"][0]["b"][1], 41);
    assert!(j["provenance"]["texsim_version"].is_string());
    // The bad pixel stands out on the error map; every other image pixel is black.
    let map = image::open(d.join("cmp/compare_error.png"))
        .unwrap()
        .to_rgb8();
    for y in 0..h {
        for x in 0..w {
            let p = map.get_pixel(x, y).0;
            if (x, y) == (9, 5) {
                assert!(p.iter().map(|&c| u32::from(c)).sum::<u32>() > 200, "{p:?}");
            } else {
                assert_eq!(p, [0, 0, 0], "({x}, {y})");
            }
        }
    }
    // Identical images: 100%.
    let out = run_ok(&["compare", "a.png", "a.png", "--out", "same"], &d);
    assert!(out.contains("match: 100.000% exact"), "{out}");
    assert_eq!(
        compare_json(&d.join("same"))["worst"],
        serde_json::json!([])
    );
}

#[test]
fn compare_masks_and_coverage_select_pixels() {
    let d = tmp("cmp2");
    let (w, h) = (8u32, 8u32);
    // A covers the left half (clear 0,0,0,0 elsewhere); B covers the top half on a grey clear.
    let a: Vec<[u8; 4]> = (0..w * h)
        .map(|i| {
            if i % w < 4 {
                [100, 100, 100, 255]
            } else {
                [0; 4]
            }
        })
        .collect();
    let b: Vec<[u8; 4]> = (0..w * h)
        .map(|i| {
            if i / w < 4 {
                [103, 100, 100, 255]
            } else {
                [0, 0, 0, 0]
            }
        })
        .collect();
    write_png(&d.join("a.png"), w, h, &a);
    write_png(&d.join("b.png"), w, h, &b);
    run_ok(
        &[
            "compare",
            "a.png",
            "b.png",
            "--coverage-from",
            "a",
            "--out",
            "ca",
        ],
        &d,
    );
    let j = compare_json(&d.join("ca"));
    assert_eq!(j["metrics"]["pixels"], 32);
    assert_eq!(
        (
            j["covered_a"].as_u64(),
            j["covered_b"].as_u64(),
            j["covered_only_one"].as_u64()
        ),
        (Some(32), Some(32), Some(32))
    );
    assert_eq!(j["metrics"]["max_abs_lsb"], 100);
    run_ok(
        &[
            "compare",
            "a.png",
            "b.png",
            "--coverage-from",
            "both",
            "--out",
            "cb",
        ],
        &d,
    );
    let j = compare_json(&d.join("cb"));
    assert_eq!(j["metrics"]["pixels"], 16);
    assert_eq!(j["metrics"]["max_abs_lsb"], 3);
    assert_eq!(j["channels"][0]["mean_abs_lsb"], 3.0);
    assert_eq!(j["worst"][0]["x"], 0);
    assert_eq!(j["worst"][0]["y"], 0);
    // With another clear colour everything in A is covered.
    run_ok(
        &[
            "compare",
            "a.png",
            "b.png",
            "--coverage-from",
            "a",
            "--clear",
            "1,2,3,4",
            "--out",
            "cc",
        ],
        &d,
    );
    assert_eq!(compare_json(&d.join("cc"))["metrics"]["pixels"], 64);
    // A mask: only the bottom-left quarter (where B is clear and A covered).
    let m: Vec<[u8; 4]> = (0..w * h)
        .map(|i| {
            if i % w < 4 && i / w >= 4 {
                [255, 255, 255, 255]
            } else {
                [0, 0, 0, 255]
            }
        })
        .collect();
    write_png(&d.join("m.png"), w, h, &m);
    run_ok(
        &[
            "compare", "a.png", "b.png", "--mask", "m.png", "--top", "3", "--out", "cm",
        ],
        &d,
    );
    let j = compare_json(&d.join("cm"));
    assert_eq!(j["metrics"]["pixels"], 16);
    assert_eq!(j["metrics"]["pct_exact"], 0.0);
    assert_eq!(j["worst"].as_array().unwrap().len(), 3);
}

#[test]
fn compare_bad_input_fails_cleanly() {
    let d = tmp("cmp3");
    write_png(&d.join("a.png"), 4, 4, &[[1, 2, 3, 255]; 16]);
    write_png(&d.join("b.png"), 5, 4, &[[1, 2, 3, 255]; 20]);
    std::fs::write(d.join("text.png"), b"not an image").unwrap();
    let cases: [(&[&str], &str); 7] = [
        (&["compare", "a.png", "b.png"], "a.png is 4x4, b.png is 5x4"),
        (&["compare", "a.png", "missing.png"], "missing.png"),
        (
            &["compare", "a.png", "text.png"],
            "text.png: not a PNG or JPEG image",
        ),
        (
            &["compare", "a.png", "a.png", "--mask", "b.png"],
            "the mask is 5x4, the images are 4x4",
        ),
        (
            &[
                "compare",
                "a.png",
                "a.png",
                "--coverage-from",
                "a",
                "--clear",
                "1,2,3",
            ],
            "field '--clear'",
        ),
        (
            &["compare", "a.png", "a.png", "--bits", "17"],
            "field '--bits'",
        ),
        (
            &["compare", "a.png", "a.png", "--top", "100001"],
            "field '--top'",
        ),
    ];
    for (args, msg) in cases {
        let o = texsim(args, &d);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {}", text(&o));
        assert!(text(&o).contains(msg), "{args:?}: {}", text(&o));
    }
    assert!(!d.join("out").exists());
    let o = texsim(
        &[
            "compare",
            "a.png",
            "a.png",
            "--mask",
            "a.png",
            "--coverage-from",
            "a",
        ],
        &d,
    );
    assert_eq!(o.status.code(), Some(2));
}
