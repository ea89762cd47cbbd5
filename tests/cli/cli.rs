//! The command line as users and scripts see it: exit codes, files written, messages.

use crate::cli_common::{texsim, text, tmp};
use std::path::Path;

#[test]
fn render_writes_every_output() {
    let d = tmp("render");
    let o = texsim(
        &[
            "render", "--scene", "demo", "--width", "160", "--height", "120", "--out", "o",
            "--png16",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", text(&o));
    for f in [
        "hw.png",
        "ref.png",
        "error.png",
        "sheet.png",
        "summary.json",
        "hw16.png",
        "ref16.png",
    ] {
        assert!(d.join("o").join(f).is_file(), "missing {f}");
    }
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("o/summary.json")).unwrap()).unwrap();
    assert!(j["stats"]["error_8bit"]["max_abs_lsb"].is_u64());
    assert!(j["stats"]["timing"]["total_cycles"].as_u64().unwrap() > 0);
    assert!(j["stats"]["issue_cycles"]["total"].as_u64().unwrap() > 0);
    assert!(
        text(&o).contains("PSNR") || text(&o).contains("psnr"),
        "{}",
        text(&o)
    );
    // Progress: one line per phase on stderr, in order; stdout stays the summary.
    let err = String::from_utf8_lossy(&o.stderr);
    let mut at = 0;
    for phase in [
        "texture maps",
        "setup",
        "raster",
        "hardware shading",
        "reference",
        "writing outputs",
    ] {
        let line = err[at..]
            .lines()
            .find(|l| l.starts_with("texsim:") && l.contains(phase) && l.ends_with(" ms"))
            .unwrap_or_else(|| panic!("no progress line '{phase}' in order: {err}"));
        at += err[at..].find(line).expect("line") + line.len();
    }
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(!out.lines().any(|l| l.starts_with("texsim:")), "{out}");
}

/// README command 1: `texsim` alone renders the demo into ./out (`cargo run --release`).
#[test]
fn no_arguments_renders_the_demo_into_out() {
    let d = tmp("noargs");
    let t = std::time::Instant::now();
    let o = texsim(&[], &d);
    println!(
        "texsim (demo, 1024x768): {:.2} s",
        t.elapsed().as_secs_f64()
    );
    assert!(o.status.success(), "{}", text(&o));
    for f in [
        "hw.png",
        "ref.png",
        "error.png",
        "sheet.png",
        "summary.json",
    ] {
        let p = d.join("out").join(f);
        assert!(p.is_file(), "missing out/{f}");
        assert!(std::fs::metadata(&p).unwrap().len() > 0, "empty out/{f}");
    }
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("out/summary.json")).unwrap()).unwrap();
    assert_eq!(j["scene"], "demo");
    assert_eq!(j["hw_config"]["name"], "texram16");
    assert_eq!(
        (j["stats"]["width"].as_u64(), j["stats"]["height"].as_u64()),
        (Some(1024), Some(768))
    );
    assert_eq!(j["stats"]["coverage"], "shared");
    assert!(j["stats"]["error_8bit"]["max_abs_lsb"].is_u64());
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("out/summary.json"), "{out}");
}

/// A render removes the outputs an earlier render left that it does not produce itself (and
/// nothing else): a full run writes every name of `RENDER_OUTPUTS`, a reduced one leaves two
/// (and writes its own report.html).
#[test]
fn render_removes_its_own_stale_outputs_only() {
    let d = tmp("stale");
    let small = ["--width", "64", "--height", "48", "--out", "o"];
    let mut full = vec![
        "render",
        "--scene",
        "lake",
        "--truth",
        "--truth-samples",
        "2",
        "--png16",
    ];
    full.extend(small);
    let o = texsim(&full, &d);
    assert!(o.status.success(), "{}", text(&o));
    let list = |dir: &Path| {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    };
    let mut every: Vec<String> = texsim::cli::RENDER_OUTPUTS
        .iter()
        .map(|s| s.to_string())
        .collect();
    every.sort();
    assert_eq!(
        list(&d.join("o")),
        every,
        "a full run writes every render output"
    );
    std::fs::write(d.join("o/notes.txt"), "mine").unwrap();
    std::fs::write(d.join("o/cycles.json"), "{}").unwrap();

    let mut reduced = vec!["render", "--scene", "demo", "--no-reference"];
    reduced.extend(small);
    let o = texsim(&reduced, &d);
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(
        list(&d.join("o")),
        [
            "cycles.json",
            "hw.png",
            "notes.txt",
            "report.html",
            "summary.json",
            "timings.json"
        ]
    );
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("removed") && out.contains("ref.png"), "{out}");
}

#[test]
fn bad_inputs_fail_cleanly_and_write_nothing() {
    let d = tmp("bad");
    std::fs::write(d.join("broken.toml"), "this is = = not toml").unwrap();
    std::fs::write(d.join("hw_bad.toml"), "[trilinear]\nweight_bits = 99\n").unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["render", "missing.obj", "--out", "o"], "missing.obj"),
        (vec!["render", "broken.toml", "--out", "o"], "broken.toml"),
        (vec!["render", "--scene", "nope", "--out", "o"], "nope"),
        (
            vec![
                "render",
                "--scene",
                "demo",
                "--hw",
                "hw_bad.toml",
                "--out",
                "o",
            ],
            "weight_bits",
        ),
        (
            vec![
                "render",
                "--scene",
                "demo",
                "--hw",
                "nosuchpreset",
                "--out",
                "o",
            ],
            "nosuchpreset",
        ),
        (
            vec!["render", "--scene", "demo", "--width", "0", "--out", "o"],
            "width",
        ),
        (
            vec![
                "render",
                "--scene",
                "demo",
                "--isolate",
                "foo",
                "--out",
                "o",
            ],
            "foo",
        ),
        (
            vec![
                "sweep",
                "--scene",
                "demo",
                "--vary",
                "no_such_field=1..2",
                "--out",
                "o",
            ],
            "no_such_field",
        ),
        (
            vec![
                "sweep",
                "--scene",
                "demo",
                "--vary",
                "weight_bits=1..99",
                "--out",
                "o",
            ],
            "weight_bits",
        ),
        (
            vec![
                "probe",
                "--texture",
                "nothere.png",
                "--u",
                "0.5",
                "--v",
                "0.5",
                "--lod",
                "0",
            ],
            "nothere.png",
        ),
    ];
    for (args, needle) in cases {
        let o = texsim(&args, &d);
        assert!(!o.status.success(), "{args:?} succeeded");
        let t = text(&o);
        assert!(
            t.contains(needle),
            "{args:?}: message does not name '{needle}': {t}"
        );
        assert!(!t.contains("panicked"), "{args:?} panicked: {t}");
        assert!(!d.join("o").exists(), "{args:?} wrote output");
    }
}

#[test]
fn hw_show_round_trips_and_sweep_writes_table() {
    let d = tmp("hw");
    let o = texsim(&["hw", "show", "d3d11"], &d);
    assert!(o.status.success());
    std::fs::write(d.join("mine.toml"), &o.stdout).unwrap();
    let o2 = texsim(&["hw", "show", "mine.toml"], &d);
    assert!(o2.status.success(), "{}", text(&o2));
    assert!(String::from_utf8_lossy(&o2.stdout).contains("weight_bits = 8"));

    let o = texsim(
        &[
            "sweep",
            "--scene",
            "demo",
            "--width",
            "96",
            "--height",
            "72",
            "--vary",
            "weight_bits=2..4",
            "--out",
            "s",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", text(&o));
    let csv = std::fs::read_to_string(d.join("s/sweep.csv")).unwrap();
    assert_eq!(csv.lines().count(), 4, "{csv}");
    assert!(d.join("s/sweep.json").is_file());
}

/// The README's probe example runs as printed (from the repository root); `--wrap` lists its
/// values in `--help` and rejects others.
#[test]
fn probe_readme_example_and_wrap_values() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let line = readme
        .lines()
        .find(|l| l.starts_with("texsim probe "))
        .expect("README probe example");
    let cmd = line.split('#').next().unwrap_or(line);
    let args: Vec<&str> = cmd.split_whitespace().skip(1).collect();
    let o = texsim(&args, root);
    assert!(o.status.success(), "{line}: {}", text(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("checker64.png"), "{out}");
    assert!(out.contains("weights"), "{out}");

    let help = text(&texsim(&["probe", "--help"], root));
    for v in ["repeat", "clamp-to-edge", "mirror"] {
        assert!(help.contains(v), "--help does not list '{v}': {help}");
    }
    let tex = root.join("scenes/checker64.png");
    let t = tex.to_str().unwrap();
    let probe = |wrap: &str| {
        texsim(
            &[
                "probe",
                "--texture",
                t,
                "--u",
                "1.3",
                "--v",
                "0.2",
                "--lod",
                "0",
                "--wrap",
                wrap,
            ],
            root,
        )
    };
    let bad = probe("wrapped");
    assert!(!bad.status.success());
    assert!(text(&bad).contains("clamp-to-edge"), "{}", text(&bad));
    let outs: Vec<String> = ["repeat", "clamp-to-edge", "mirror", "clamp"]
        .iter()
        .map(|w| {
            let o = probe(w);
            assert!(o.status.success(), "{w}: {}", text(&o));
            String::from_utf8_lossy(&o.stdout).to_string()
        })
        .collect();
    assert_ne!(outs[0], outs[1], "repeat vs clamp-to-edge at u = 1.3");
    assert_ne!(outs[0], outs[2], "repeat vs mirror at u = 1.3");
    assert_eq!(outs[1], outs[3], "clamp is an alias of clamp-to-edge");
}

#[test]
fn scenes_lists_the_catalogue() {
    let o = texsim(&["scenes"], &std::env::temp_dir());
    let t = text(&o);
    for s in ["demo", "w1-plane", "w2-mesh"] {
        assert!(t.contains(s), "{t}");
    }
}

#[test]
fn brdf_albedo_prints_one_number_last_and_rejects_bad_parameters() {
    let d = std::env::temp_dir();
    let last = |args: &[&str]| -> f64 {
        let o = texsim(args, &d);
        assert!(o.status.success(), "{}", text(&o));
        let out = String::from_utf8_lossy(&o.stdout).to_string();
        out.lines()
            .last()
            .unwrap_or("")
            .trim()
            .parse()
            .expect("last line is a number")
    };
    let args = [
        "brdf", "albedo", "--nu", "100", "--nv", "10", "--rs", "1", "--rd", "0", "--theta", "45",
    ];
    let float = last(&args);
    let mut fixed_args = args.to_vec();
    fixed_args.push("--fixed");
    let fixed = last(&fixed_args);
    // Energy conservation, and the fixed unit within its documented 2e-4 relative bound
    // (plus quadrature noise, identical grids on both sides).
    assert!(float > 0.5 && float <= 1.0, "{float}");
    assert!(
        (fixed - float).abs() <= 1e-3 * float,
        "fixed {fixed} float {float}"
    );
    let o = texsim(&["brdf", "albedo", "--nu=-1"], &d);
    assert!(!o.status.success());
    assert!(text(&o).contains("nu"), "{}", text(&o));
}

#[test]
fn renders_a_real_textured_obj_with_its_mtl() {
    let d = tmp("obj");
    let cube = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cube.obj");
    let o = texsim(
        &[
            "render",
            cube.to_str().unwrap(),
            "--width",
            "200",
            "--height",
            "150",
            "--out",
            "o",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", text(&o));
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("o/summary.json")).unwrap()).unwrap();
    let stages = j["stats"]["stages"].as_array().unwrap();
    let tri = stages.iter().find(|s| s["stage"] == "trilinear").unwrap();
    assert!(
        tri["invocations"].as_u64().unwrap() > 1000,
        "the MTL texture must be sampled: {tri}"
    );
    assert!(j["stats"]["error_8bit"]["max_abs_lsb"].as_u64().unwrap() <= 2);
}

/// Time limit of the 100k-triangle render below (test profile, opt-level 2). Measured on the
/// 2-core machine: see docs/PERFORMANCE_LOG.md, "Large meshes".
const BIG_OBJ_LIMIT_S: f64 = 5.0;

#[test]
fn renders_a_100k_triangle_obj() {
    // A 230 x 230 grid of quads (105,800 triangles) with UVs and no normals, textured through
    // its MTL's map_Kd (a 256x256 PNG written here).
    let d = tmp("big");
    let n = 230usize;
    let mut s = String::with_capacity(8 << 20);
    s.push_str("mtllib big.mtl\nusemtl tiles\n");
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
            let z = 0.1 * (x * 12.0).sin() * (y * 9.0).cos();
            let (u, v) = (4.0 * x, 4.0 * y);
            s.push_str(&format!("v {x} {y} {z}\nvt {u} {v}\n"));
        }
    }
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i + 1;
            let (b, c, e) = (a + 1, a + n + 2, a + n + 1);
            s.push_str(&format!("f {a}/{a} {b}/{b} {c}/{c} {e}/{e}\n"));
        }
    }
    std::fs::write(d.join("big.obj"), s).unwrap();
    std::fs::write(
        d.join("big.mtl"),
        "newmtl tiles\nKd 0.9 0.8 0.7\nmap_Kd tiles.png\n",
    )
    .unwrap();
    let tex = image::RgbImage::from_fn(256, 256, |x, y| {
        let c = if (x / 32 + y / 32) % 2 == 0 { 230 } else { 40 };
        image::Rgb([c, (x & 255) as u8, (y & 255) as u8])
    });
    tex.save(d.join("tiles.png")).unwrap();
    let t = std::time::Instant::now();
    let o = texsim(
        &[
            "render", "big.obj", "--width", "512", "--height", "512", "--out", "o",
        ],
        &d,
    );
    let secs = t.elapsed().as_secs_f64();
    assert!(o.status.success(), "{}", text(&o));
    let t = text(&o);
    assert!(t.contains("105800 triangles"), "{t}");
    assert!(!t.contains("warning"), "{t}");
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("o/summary.json")).unwrap()).unwrap();
    let stages = j["stats"]["stages"].as_array().unwrap();
    let inv = |name: &str| {
        stages.iter().find(|s| s["stage"] == name).unwrap()["invocations"]
            .as_u64()
            .unwrap()
    };
    let covered = j["stats"]["covered_pixels"].as_u64().unwrap();
    assert!(covered > 50_000, "{covered}");
    assert_eq!(
        inv("trilinear"),
        covered,
        "map_Kd is sampled at every pixel"
    );
    assert_eq!(inv("modulate"), covered, "Kd modulates the texture");
    println!("100k-triangle textured OBJ: load + render + reference + outputs in {secs:.2} s");
    assert!(secs < BIG_OBJ_LIMIT_S, "took {secs} s");
}

/// `texsim` with an environment variable set.
fn texsim_env(args: &[&str], cwd: &Path, env: (&str, &str)) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_texsim"))
        .args(args)
        .env(env.0, env.1)
        .current_dir(cwd)
        .output()
        .expect("run texsim")
}

/// Abusive sweeps fail at once with a message naming `--vary`: a range whose length overflows
/// i64 (it panicked), and a 3-axis grid of 4097 values each (materialized before any check).
#[test]
fn sweep_ranges_and_grids_are_budgeted() {
    let d = tmp("sweepbudget");
    let small = [
        "--scene", "sphere", "--width", "32", "--height", "24", "--out", "s",
    ];
    let mut args = vec![
        "sweep",
        "--vary",
        "weight_bits=-9223372036854775808..9223372036854775807",
    ];
    args.extend(small);
    let o = texsim(&args, &d);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(1), "{t}");
    assert!(
        t.contains("--vary") && t.contains("over the limit of 4097"),
        "{t}"
    );
    let mut args = vec!["sweep"];
    for f in ["weight_bits", "texel_bits", "lod_frac_bits"] {
        args.extend(["--vary", Box::leak(format!("{f}=0..4096").into_boxed_str())]);
    }
    args.extend(small);
    let start = std::time::Instant::now();
    let o = texsim(&args, &d);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(1), "{t}");
    assert!(
        t.contains("field '--vary'")
            && t.contains("4097 x 4097 x 4097")
            && t.contains("--max-memory"),
        "{t}"
    );
    assert!(start.elapsed().as_secs() < 10, "{:?}", start.elapsed());
    assert!(!d.join("s").exists());
}

/// A sweep keeps each rendered row's results until it writes them (about 100 KB a row measured
/// at 1x1 pixels): a grid whose settings fit the grid's own budget but whose results do not
/// is refused before the first render, naming `--vary`, and writes nothing. (Such a grid of
/// 4,416 settings at 1x1 once ran to 451 MB under a 64 MiB limit.)
#[test]
fn sweep_results_are_budgeted() {
    let d = tmp("sweepresults");
    let args = "--max-memory 64M sweep --scene demo --vary depth_bits=8..30 --vary \
                subpixel_bits=1..12 --vary color_bits=1..16 --width 1 --height 1 --no-cycles \
                --out s";
    let o = texsim(&args.split_whitespace().collect::<Vec<_>>(), &d);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(1), "{t}");
    assert!(
        t.contains("field '--vary'")
            && t.contains("results of 4416 settings")
            && t.contains("over the limit of 64.00 MiB"),
        "{t}"
    );
    assert!(!d.join("s").exists());
}

/// The framebuffer and timing events of an 8192x8192 `cycles` run are over the default budget:
/// a message naming the size, before anything is allocated.
#[test]
fn cycles_framebuffer_is_budgeted() {
    let d = tmp("cyclesbudget");
    let start = std::time::Instant::now();
    let o = texsim(
        &[
            "cycles", "--scene", "w2-mesh", "--width", "8192", "--height", "8192", "--out", "c",
        ],
        &d,
    );
    let t = text(&o);
    assert_eq!(o.status.code(), Some(1), "{t}");
    assert!(
        t.contains("width x height") && t.contains("8192x8192") && t.contains("TEXSIM_MAX_MEMORY"),
        "{t}"
    );
    assert!(start.elapsed().as_secs() < 10, "{:?}", start.elapsed());
    assert!(!d.join("c").exists());
}

/// The limit comes from `--max-memory`, else `TEXSIM_MAX_MEMORY`; a bad value is an error.
#[test]
fn max_memory_option_and_environment() {
    let d = tmp("maxmem");
    let args = [
        "render", "--scene", "sphere", "--width", "64", "--height", "48", "--out", "o",
    ];
    let o = texsim_env(&args, &d, ("TEXSIM_MAX_MEMORY", "64K"));
    let t = text(&o);
    assert_eq!(o.status.code(), Some(1), "{t}");
    assert!(t.contains("over the limit of 64.00 KiB"), "{t}");
    let mut raised = vec!["--max-memory", "1G"];
    raised.extend(args);
    let o = texsim_env(&raised, &d, ("TEXSIM_MAX_MEMORY", "64K"));
    assert!(o.status.success(), "{}", text(&o));
    let o = texsim(&["--max-memory", "lots", "scenes"], &d);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains("--max-memory"), "{}", text(&o));
    let o = texsim_env(&["scenes"], &d, ("TEXSIM_MAX_MEMORY", "0x"));
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains("TEXSIM_MAX_MEMORY"), "{}", text(&o));
}

/// `--truth-samples` alone is an error, not silently ignored.
#[test]
fn truth_samples_without_truth_is_an_error() {
    let d = tmp("truthsamples");
    let o = texsim(
        &[
            "render",
            "--scene",
            "sphere",
            "--truth-samples",
            "4",
            "--width",
            "32",
            "--height",
            "24",
        ],
        &d,
    );
    let t = text(&o);
    assert_eq!(o.status.code(), Some(1), "{t}");
    assert!(
        t.contains("--truth-samples") && t.contains("--truth"),
        "{t}"
    );
    assert!(!d.join("out").exists());
}

/// `--warmup W --frames N` renders the frame `W + N` times in one process: the outputs are
/// those of one frame (summary.json but its command line, every image byte for byte, with
/// cycles and the reference on), timings.json lists the timed frames and names the median,
/// and a frame count of 0 or above the limit is refused before anything is written.
#[test]
fn repeated_frames_give_one_frames_outputs_and_the_median_timings() {
    let d = tmp("frames");
    let base = [
        "render", "--scene", "demo", "--width", "96", "--height", "72", "--out",
    ];
    let run = |out: &str, extra: &[&str]| {
        let args: Vec<&str> = base
            .iter()
            .copied()
            .chain([out])
            .chain(extra.iter().copied())
            .collect();
        let o = texsim(&args, &d);
        assert!(o.status.success(), "{}", text(&o));
        o
    };
    run("one", &[]);
    let o = run("many", &["--warmup", "1", "--frames", "3"]);
    let t = text(&o);
    assert!(t.contains("frame 4/4 (timed)"), "{t}");
    assert!(
        t.contains("frames: 3 timed after 1 warm-up; hardware path median"),
        "{t}"
    );
    let json = |dir: &str, file: &str| -> serde_json::Value {
        serde_json::from_slice(&std::fs::read(d.join(dir).join(file)).unwrap()).unwrap()
    };
    let mut one = json("one", "summary.json");
    let mut many = json("many", "summary.json");
    for j in [&mut one, &mut many] {
        j.as_object_mut().unwrap().remove("provenance");
    }
    assert!(
        one == many,
        "summary.json differs between one frame and four"
    );
    for f in ["hw.png", "ref.png", "error.png", "flip.png"] {
        let (a, b) = (d.join("one").join(f), d.join("many").join(f));
        assert!(
            std::fs::read(a).unwrap() == std::fs::read(b).unwrap(),
            "{f} differs"
        );
    }
    let times = json("many", "timings.json");
    let timed = times["frames"]["timed"].as_array().unwrap();
    assert_eq!(timed.len(), 3, "{times}");
    assert_eq!(times["frames"]["warmup"], 1, "{times}");
    let median = times["frames"]["median"].as_u64().unwrap() as usize;
    let mut sorted: Vec<f64> = timed.iter().map(|v| v.as_f64().unwrap()).collect();
    sorted.sort_by(f64::total_cmp);
    assert_eq!(timed[median].as_f64(), Some(sorted[1]), "{times}");
    assert_eq!(times["timings"]["hw_total_ms"], timed[median], "{times}");
    for bad in [["--frames", "0"], ["--warmup", "1001"]] {
        let args: Vec<&str> = base.iter().copied().chain(["bad"]).chain(bad).collect();
        let o = texsim(&args, &d);
        let t = text(&o);
        assert_eq!(o.status.code(), Some(2), "{t}");
        assert!(t.contains(bad[0]), "{t}");
        assert!(!d.join("bad").exists());
    }
}

/// Two runs of the same command write byte-identical summary.json files (wall times live in
/// timings.json), and every JSON carries its provenance.
#[test]
fn summary_json_is_byte_identical_between_runs_with_provenance() {
    let d = tmp("identical");
    let args = [
        "render", "--scene", "demo", "--width", "96", "--height", "72", "--out", "o",
    ];
    let o = texsim(&args, &d);
    assert!(o.status.success(), "{}", text(&o));
    let first = std::fs::read(d.join("o/summary.json")).unwrap();
    let o = texsim(&args, &d);
    assert!(o.status.success(), "{}", text(&o));
    let second = std::fs::read(d.join("o/summary.json")).unwrap();
    assert!(first == second, "summary.json differs between two runs");
    let j: serde_json::Value = serde_json::from_slice(&second).unwrap();
    assert_eq!(j["provenance"]["texsim_version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(j["provenance"]["command_line"][1], "render");
    assert!(j["provenance"].get("git_commit").is_some());
    assert_eq!(j["hw_config"]["interp"]["texcoord_reduce"], true);
    let times: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("o/timings.json")).unwrap()).unwrap();
    assert!(
        times["timings"]["hw_total_ms"].as_f64().unwrap() > 0.0,
        "{times}"
    );
    assert!(times["provenance"]["texsim_version"].is_string());
    // cycles.json and every sweep row carry it too.
    let o = texsim(
        &[
            "cycles", "--scene", "sphere", "--width", "48", "--height", "36", "--out", "c",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", text(&o));
    let c: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("c/cycles.json")).unwrap()).unwrap();
    assert_eq!(c["provenance"]["command_line"][1], "cycles");
    let o = texsim(
        &[
            "sweep",
            "--scene",
            "sphere",
            "--width",
            "48",
            "--height",
            "36",
            "--vary",
            "weight_bits=4,8",
            "--out",
            "s",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", text(&o));
    let s: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("s/sweep.json")).unwrap()).unwrap();
    let rows = s.as_array().unwrap();
    assert_eq!(rows[1]["hw_config"]["trilinear"]["weight_bits"], 8);
    assert_eq!(rows[0]["provenance"]["command_line"][1], "sweep");
}

/// A tiny `near` makes every fragment fail the 24-bit depth test: the run says so, naming
/// `camera.near` and a near that works (which then renders pixels).
#[test]
fn tiny_near_warns_with_a_near_that_works() {
    let d = tmp("near");
    let scene = |near: &str| {
        format!(
            "[output]\nwidth = 64\nheight = 48\n[camera]\neye = [0.0, 0.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\nnear = {near}\nfar = 100.0\n[[meshes]]\nshape = \"sphere\"\n"
        )
    };
    std::fs::write(d.join("tiny.toml"), scene("1e-10")).unwrap();
    let o = texsim(&["render", "tiny.toml", "--out", "o"], &d);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    let line = t
        .lines()
        .find(|l| l.starts_with("warning:") && l.contains("camera.near"))
        .unwrap_or_else(|| panic!("no near warning: {t}"));
    assert!(line.contains("failed the 24-bit depth test"), "{line}");
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("o/summary.json")).unwrap()).unwrap();
    assert_eq!(j["stats"]["covered_pixels"], 0);
    assert_eq!(j["stats"]["warnings"].as_array().unwrap().len(), 1);
    let near = line
        .split("near >= ")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .unwrap_or_else(|| panic!("no suggested near: {line}"));
    std::fs::write(d.join("fixed.toml"), scene(near)).unwrap();
    let o = texsim(&["render", "fixed.toml", "--out", "p"], &d);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(!t.contains("camera.near"), "{t}");
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("p/summary.json")).unwrap()).unwrap();
    assert!(j["stats"]["covered_pixels"].as_u64().unwrap() > 300, "{j}");
}

/// `probe --u 256.3 --wrap repeat` samples the texel of u = 0.3 (it saturated the 8 integer
/// bits and returned the edge texel); mirror is periodic over 2.
#[test]
fn probe_far_coordinates_wrap_exactly() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tex = root.join("scenes/checker64.png");
    let tex = tex.to_str().unwrap();
    let fixed_line = |u: &str, wrap: &str| {
        let o = texsim(
            &[
                "probe",
                "--texture",
                tex,
                "--u",
                u,
                "--v",
                "0.7",
                "--lod",
                "0.5",
                "--wrap",
                wrap,
            ],
            root,
        );
        assert!(o.status.success(), "{}", text(&o));
        let out = String::from_utf8_lossy(&o.stdout).into_owned();
        out.lines()
            .filter(|l| !l.starts_with("input:") && !l.contains("float"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    assert_eq!(fixed_line("256.3", "repeat"), fixed_line("0.3", "repeat"));
    assert_eq!(fixed_line("-1023.7", "repeat"), fixed_line("0.3", "repeat"));
    assert_eq!(fixed_line("258.3", "mirror"), fixed_line("0.3", "mirror"));
    assert_eq!(fixed_line("257.3", "mirror"), fixed_line("1.3", "mirror"));
}

/// sweep.csv is RFC 4180 with sweep.json's names: every column after the swept field is a
/// (dotted) field of the JSON row, a null is an empty cell, numbers are the JSON's numbers.
#[test]
fn sweep_csv_uses_the_json_names_and_empty_cells() {
    let d = tmp("sweepcsv");
    let o = texsim(
        &[
            "sweep",
            "--scene",
            "sphere",
            "--width",
            "48",
            "--height",
            "36",
            "--vary",
            "weight_bits=4,8",
            "--out",
            "s",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", text(&o));
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("s/sweep.json")).unwrap()).unwrap();
    let mut rd = csv::Reader::from_path(d.join("s/sweep.csv")).unwrap();
    let head: Vec<String> = rd.headers().unwrap().iter().map(str::to_string).collect();
    assert_eq!(head[0], "weight_bits");
    assert!(head.contains(&"cycles".to_string()), "{head:?}");
    assert!(head.contains(&"texture_bytes".to_string()), "{head:?}");
    assert!(head.contains(&"area_ge".to_string()), "{head:?}");
    // weight_bits changes the filter's datapath: its area columns are there.
    assert!(
        head.contains(&"unit_cost.trilinear.area_ge".to_string()),
        "{head:?}"
    );
    let recs: Vec<csv::StringRecord> = rd.records().map(Result::unwrap).collect();
    assert_eq!(recs.len(), 2);
    for (rec, row) in recs.iter().zip(json.as_array().unwrap()) {
        assert_eq!(&rec[0], row["settings"][0][1].as_str().unwrap());
        for (col, cell) in head.iter().zip(rec.iter()).skip(1) {
            // `unit_cost.NAME.FIELD`: NAME may contain a dot, FIELD does not.
            let v = match col.strip_prefix("unit_cost.") {
                Some(rest) => {
                    let (unit, field) = rest.rsplit_once('.').unwrap();
                    &row["unit_cost"][unit][field]
                }
                None => col.split('.').fold(row, |v, k| &v[k]),
            };
            match v {
                serde_json::Value::Null => assert_eq!(cell, "", "{col}"),
                serde_json::Value::Number(n) => {
                    let x: f64 = cell.parse().unwrap_or_else(|_| panic!("{col}: '{cell}'"));
                    // serde_json's reader may round the last digit differently.
                    let y = n.as_f64().unwrap();
                    assert!((x - y).abs() <= 1e-12 * y.abs(), "{col}: {x} vs {y}");
                }
                serde_json::Value::String(s) => assert_eq!(cell, s, "{col}"),
                serde_json::Value::Bool(b) => assert_eq!(cell, b.to_string(), "{col}"),
                other => panic!("{col}: {other} is not a JSON row field"),
            }
        }
    }
    // Not applicable here: no bump material; the timing model ran (the default).
    let fu = head.iter().position(|h| h == "frame_used").unwrap();
    assert_eq!(&recs[0][fu], "");
    let tc = head.iter().position(|h| h == "cycles").unwrap();
    assert!(recs[0][tc].parse::<u64>().unwrap() > 0);
}

/// Width and height from a PNG's IHDR chunk.
fn png_size(p: &Path) -> (u32, u32) {
    let b = std::fs::read(p).unwrap();
    let be = |i: usize| u32::from_be_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
    (be(16), be(20))
}

/// Renders killed at any moment leave the output directory all old or all new (hw.png and
/// ref.png match summary.json's size), and the next run removes every leftover.
#[test]
fn killed_renders_leave_whole_output_sets() {
    let d = tmp("killed");
    let run = |w: &str, h: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_texsim"))
            .args([
                "render", "--scene", "demo", "--width", w, "--height", h, "--out", "o",
            ])
            .current_dir(&d)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .expect("spawn texsim")
    };
    assert!(run("64", "48").wait().unwrap().success());
    let o = d.join("o");
    let check = |when: &str| {
        if !o.exists() {
            // Killed between the two renames: a complete new directory waits beside it.
            let complete = std::fs::read_dir(&d).unwrap().any(|e| {
                let p = e.unwrap().path();
                p.file_name()
                    .unwrap()
                    .to_string_lossy()
                    .starts_with(".o.texsim-new-")
                    && p.join(".texsim-complete").exists()
            });
            assert!(
                complete,
                "{when}: no output directory and nothing to finish"
            );
            return;
        }
        let j: serde_json::Value =
            serde_json::from_slice(&std::fs::read(o.join("summary.json")).unwrap()).unwrap();
        let size = (
            j["stats"]["width"].as_u64().unwrap() as u32,
            j["stats"]["height"].as_u64().unwrap() as u32,
        );
        for f in ["hw.png", "ref.png"] {
            assert_eq!(png_size(&o.join(f)), size, "{when}: {f} of another run");
        }
    };
    for (i, ms) in [
        0u64, 5, 15, 30, 45, 60, 80, 100, 130, 160, 200, 250, 300, 400,
    ]
    .into_iter()
    .enumerate()
    {
        let (w, h) = if i % 2 == 0 {
            ("200", "150")
        } else {
            ("64", "48")
        };
        let mut c = run(w, h);
        std::thread::sleep(std::time::Duration::from_millis(ms));
        let _ = c.kill();
        let _ = c.wait();
        check(&format!("killed after {ms} ms"));
    }
    assert!(run("64", "48").wait().unwrap().success());
    check("final run");
    let names = |p: &Path| -> Vec<String> {
        std::fs::read_dir(p)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect()
    };
    assert_eq!(names(&d), ["o"], "leftovers beside the output directory");
    let inside = names(&o);
    assert!(
        inside
            .iter()
            .all(|n| !n.contains(".tmp-") && !n.starts_with('.')),
        "{inside:?}"
    );
}

/// `texsim hw show | head -1`: printing into a pipe whose reader has gone ends the process by
/// SIGPIPE, quietly, as Unix tools do (it panicked in `println!` before).
#[cfg(unix)]
#[test]
fn printing_into_a_closed_pipe_ends_quietly() {
    use std::os::fd::FromRawFd;
    use std::os::unix::process::ExitStatusExt;
    let mut fds = [0i32; 2];
    // SAFETY: `fds` holds the two descriptors pipe(2) writes.
    assert_eq!(unsafe { libc::pipe(fds.as_mut_ptr()) }, 0);
    // SAFETY: pipe(2) returned two fresh descriptors that nothing else owns.
    let (reader, writer) = unsafe {
        (
            std::fs::File::from_raw_fd(fds[0]),
            std::fs::File::from_raw_fd(fds[1]),
        )
    };
    drop(reader);
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_texsim"))
        .args(["hw", "show", "texram16"])
        .stdout(std::process::Stdio::from(writer))
        .output()
        .expect("run texsim");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(
        o.status.signal(),
        Some(libc::SIGPIPE),
        "{:?} {err}",
        o.status
    );
}

/// `texsim hw cost` prints every unit with its stages and totals, follows a hw file's widths,
/// clock target and hand-set cycles, and fails clearly on bad input.
#[test]
fn hw_cost_prints_units_and_follows_the_file() {
    let d = tmp("hwcost");
    let o = texsim(&["hw", "cost"], &d);
    assert!(o.status.success(), "{}", text(&o));
    let out = String::from_utf8_lossy(&o.stdout).to_string();
    for unit in hw_model::datapath::units(&hw_model::HwConfig::texram16()) {
        let line = format!("{} ", unit.name);
        assert!(
            out.lines().any(|l| l.starts_with(&line)),
            "no line for {}",
            unit.name
        );
    }
    assert!(
        out.contains("mul17x17") && out.contains("total area"),
        "{out}"
    );
    let unit_line = |out: &str, name: &str| -> Vec<String> {
        out.lines()
            .find(|l| l.starts_with(&format!("{name} ")))
            .map(|l| l.split_whitespace().map(str::to_string).collect())
            .unwrap_or_default()
    };
    // texram16: trilinear 256 levels, 4 + 4 + 2 cycles at 32 levels per cycle.
    assert_eq!(unit_line(&out, "trilinear")[1..3], ["256", "10"]);
    std::fs::write(
        d.join("mine.toml"),
        "base = \"texram16\"\n[trilinear]\nweight_bits = 8\nbilinear_cycles = 1\n\
         [timing]\ngate_levels_per_cycle = 16\n",
    )
    .unwrap();
    let o = texsim(&["hw", "cost", "mine.toml"], &d);
    assert!(o.status.success(), "{}", text(&o));
    let out = String::from_utf8_lossy(&o.stdout).to_string();
    // weight_bits 8: 224 levels; bilinear hand-set to 1 cycle, blend ceil(30 / 16) = 2.
    assert_eq!(unit_line(&out, "trilinear")[1..3], ["224", "4"]);
    assert!(out.contains("cycle(s) set"), "{out}");
    std::fs::write(
        d.join("zero.toml"),
        "base = \"texram16\"\n[timing]\ngate_levels_per_cycle = 0\n",
    )
    .unwrap();
    let o = texsim(&["hw", "cost", "zero.toml"], &d);
    assert!(!o.status.success());
    assert!(text(&o).contains("gate_levels_per_cycle"), "{}", text(&o));
    let o = texsim(&["hw", "cost", "no-such-preset"], &d);
    assert!(!o.status.success());
    assert!(text(&o).contains("no-such-preset"), "{}", text(&o));
}

/// Every built-in benchmark scene (and the demo's many materials) renders the same image,
/// statistics and cycles with the batch kernels built for each instruction set this CPU has
/// (`--vector-isa`): the portable build, AVX2 and AVX-512. `TEXSIM_VECTOR_ISA` chooses where
/// the flag does not; a wider set than the CPU's, or an unknown name, is refused naming the
/// flag or the variable.
#[test]
fn every_vector_isa_renders_the_same() {
    let d = tmp("vector_isa");
    let widest = hw_model::VectorIsa::detected();
    for scene in ["demo", "w1-plane", "w2-mesh"] {
        let mut first: Option<(Vec<u8>, serde_json::Value)> = None;
        for isa in hw_model::VectorIsa::ALL
            .into_iter()
            .filter(|&i| i <= widest)
        {
            let out = format!("{scene}-{}", isa.name());
            let o = texsim(
                &[
                    "--vector-isa",
                    isa.name(),
                    "render",
                    "--scene",
                    scene,
                    "--width",
                    "256",
                    "--height",
                    "192",
                    "--no-reference",
                    "--out",
                    &out,
                ],
                &d,
            );
            assert!(o.status.success(), "{scene} {isa:?}: {}", text(&o));
            let png = std::fs::read(d.join(&out).join("hw.png")).unwrap();
            let mut j: serde_json::Value =
                serde_json::from_slice(&std::fs::read(d.join(&out).join("summary.json")).unwrap())
                    .unwrap();
            assert_eq!(j["provenance"]["vector_isa"], isa.name());
            j.as_object_mut().unwrap().remove("provenance");
            assert!(
                j["stats"]["timing"]["total_cycles"].is_u64(),
                "{scene}: cycles counted"
            );
            match &first {
                None => first = Some((png, j)),
                Some((p, s)) => {
                    assert!(*p == png, "{scene}: {isa:?} image differs from portable");
                    assert_eq!(*s, j, "{scene}: {isa:?} summary differs from portable");
                }
            }
        }
    }
    // The variable when no flag is given (any case), the flag over the variable.
    let small = [
        "render", "--scene", "w1-plane", "--width", "32", "--height", "24",
    ];
    let isa_of = |out: &str| -> serde_json::Value {
        let j: serde_json::Value =
            serde_json::from_slice(&std::fs::read(d.join(out).join("summary.json")).unwrap())
                .unwrap();
        j["provenance"]["vector_isa"].clone()
    };
    let o = texsim_env(
        &[&small[..], &["--out", "env"]].concat(),
        &d,
        ("TEXSIM_VECTOR_ISA", " Portable "),
    );
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(isa_of("env"), "portable");
    let o = texsim_env(
        &[
            &["--vector-isa", widest.name()],
            &small[..],
            &["--out", "flag"],
        ]
        .concat(),
        &d,
        ("TEXSIM_VECTOR_ISA", "portable"),
    );
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(isa_of("flag"), widest.name());
    // Refusals name the flag or the variable and write nothing.
    let refused = |o: std::process::Output, names: &str| {
        assert!(
            !o.status.success() && text(&o).contains(names),
            "{}",
            text(&o)
        );
    };
    refused(
        texsim_env(&["render", "--out", "x"], &d, ("TEXSIM_VECTOR_ISA", "sse9")),
        "environment variable TEXSIM_VECTOR_ISA: unknown instruction set 'sse9'",
    );
    refused(
        texsim_env(
            &["--vector-isa", "portable", "render", "--out", "x"],
            &d,
            ("TEXSIM_VECTOR_ISA", "sse9"),
        ),
        "TEXSIM_VECTOR_ISA",
    );
    refused(
        texsim(&["--vector-isa", "neon", "render", "--out", "x"], &d),
        "--vector-isa: unknown instruction set 'neon'",
    );
    if widest < hw_model::VectorIsa::Avx512 {
        refused(
            texsim(&["--vector-isa", "avx512", "render", "--out", "x"], &d),
            "--vector-isa: this CPU has no avx512",
        );
        refused(
            texsim_env(
                &["render", "--out", "x"],
                &d,
                ("TEXSIM_VECTOR_ISA", "AVX512"),
            ),
            "environment variable TEXSIM_VECTOR_ISA: this CPU has no avx512",
        );
    }
    assert!(!d.join("x").exists(), "nothing written");
}
