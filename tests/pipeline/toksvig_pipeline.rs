//! Toksvig materials end to end (issue 15 item 5): only `bump_filter = "toksvig"` materials
//! plan the `toksvig-fetch` and `toksvig-shade` stages, the hardware stays within a few LSBs of
//! its float twin, the model follows the supersampled truth better than the plain filtered
//! bump map on the lake, the frame is bit-identical on 1 and 3 threads, and a bad
//! `bump_filter` in a TOML scene is an error naming the field.

use hw_model::roughness::RoughVariant;
use hw_model::HwConfig;
use texsim::pipeline::StageKind;
use texsim::render::{render, Maps, RenderOptions, Rendered};
use texsim::scene::{builtin, BumpFilter, RoughChoice, Scene};

fn lake(filter: BumpFilter) -> Scene {
    let mut s = builtin("lake").expect("lake");
    s.width = 160;
    s.height = 100;
    for m in &mut s.materials {
        if m.bump.is_some() {
            m.bump_filter = filter;
            m.roughness = match filter {
                BumpFilter::Plain => Some(RoughChoice::Variant(RoughVariant::None)),
                BumpFilter::Toksvig | BumpFilter::Lean => None,
            };
        }
    }
    s
}

fn run(s: &Scene, threads: usize) -> Rendered {
    let hw = HwConfig::texram16();
    let maps = Maps::new(s, hw.trilinear.texel_bits);
    let opts = RenderOptions {
        truth: 8,
        timing: true,
        ..RenderOptions::default()
    };
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool")
        .install(|| render(s, &maps, &hw, &opts).expect("render"))
}

fn invocations(r: &Rendered, k: StageKind) -> u64 {
    r.stats
        .stages
        .iter()
        .find(|s| s.stage == k)
        .map_or(0, |s| s.invocations)
}

#[test]
fn toksvig_stages_only_for_toksvig_materials_and_closer_to_truth() {
    let plain = run(&lake(BumpFilter::Plain), 2);
    let tok = run(&lake(BumpFilter::Toksvig), 2);
    for k in [StageKind::ToksvigFetch, StageKind::ToksvigShade] {
        assert_eq!(invocations(&plain, k), 0, "plain plans no {k}");
        assert!(invocations(&tok, k) > 0, "toksvig plans {k}");
    }
    assert_eq!(
        invocations(&tok, StageKind::Phong),
        0,
        "toksvig-shade replaces phong"
    );
    assert_eq!(
        invocations(&tok, StageKind::ToksvigShade),
        invocations(&plain, StageKind::Phong)
    );
    let q = tok.stats.error_8bit.as_ref().expect("reference");
    assert!(
        q.max_abs_lsb <= 3 && q.mean_abs_lsb < 0.1,
        "quantization {q:?}"
    );
    let (mp, mt) = (
        plain
            .stats
            .model_error
            .as_ref()
            .expect("truth")
            .mean_abs_lsb,
        tok.stats.model_error.as_ref().expect("truth").mean_abs_lsb,
    );
    assert!(mt < 0.9 * mp, "toksvig model error {mt} vs plain {mp}");
    // Toksvig costs one more lookup per pixel and the unit's cycles.
    let texels = |r: &Rendered| r.stats.stages.iter().map(|s| s.texels).sum::<u64>();
    assert_eq!(texels(&tok), 2 * texels(&plain));
    assert!(tok.stats.issue_cycles.total > plain.stats.issue_cycles.total);
}

/// LEAN (the same structure: `lean-fetch` after `bump-fetch`, `lean-shade` for `phong`) is
/// within a few LSBs of its float twin and closer to the truth than the plain bump map.
#[test]
fn lean_stages_only_for_lean_materials_and_closer_to_truth() {
    let plain = run(&lake(BumpFilter::Plain), 2);
    let lean = run(&lake(BumpFilter::Lean), 2);
    for k in [StageKind::LeanFetch, StageKind::LeanShade] {
        assert_eq!(invocations(&plain, k), 0, "plain plans no {k}");
        assert!(invocations(&lean, k) > 0, "lean plans {k}");
    }
    assert_eq!(invocations(&lean, StageKind::Phong), 0);
    let q = lean.stats.error_8bit.as_ref().expect("reference");
    assert!(
        q.max_abs_lsb <= 3 && q.mean_abs_lsb < 0.1,
        "quantization {q:?}"
    );
    let (mp, ml) = (
        plain
            .stats
            .model_error
            .as_ref()
            .expect("truth")
            .mean_abs_lsb,
        lean.stats.model_error.as_ref().expect("truth").mean_abs_lsb,
    );
    assert!(ml < 0.9 * mp, "lean model error {ml} vs plain {mp}");
    let (a, b) = (
        run(&lake(BumpFilter::Lean), 1),
        run(&lake(BumpFilter::Lean), 3),
    );
    assert!(
        a.hw_image == b.hw_image && a.truth_image == b.truth_image,
        "threads"
    );
}

#[test]
fn toksvig_is_identical_on_1_and_3_threads() {
    let s = lake(BumpFilter::Toksvig);
    let (a, b) = (run(&s, 1), run(&s, 3));
    assert!(a.hw_image == b.hw_image, "hardware image");
    assert!(a.ref_image == b.ref_image, "reference image");
    assert!(a.truth_image == b.truth_image, "truth image");
}

#[test]
fn toml_bump_filter_key() {
    let d = crate::tmp_common::TmpDir::new("toml");
    let body = |filter: &str| {
        format!(
            "[output]\nwidth = 96\nheight = 64\n\n[[textures]]\nname = \"bricks\"\nprocedural = \"bricks-height\"\nsize = 64\n\n[[materials]]\nname = \"m\"\nbump = \"bricks\"\nks = [0.5, 0.5, 0.5]\nshininess = 48\nbump_filter = \"{filter}\"\n\n[[meshes]]\nshape = \"sphere\"\nmaterial = \"m\"\n\n[[lights]]\nkind = \"directional\"\ndirection = [-0.3, -0.5, -1.0]\ncolor = [1.0, 1.0, 1.0]\n"
        )
    };
    let p = d.join("ok.toml");
    std::fs::write(&p, body("toksvig")).expect("write");
    let s = texsim::scene::load(&p).expect("load");
    assert_eq!(s.materials[0].bump_filter, BumpFilter::Toksvig);
    let hw = HwConfig::texram16();
    let maps = Maps::new(&s, 16);
    let r = render(&s, &maps, &hw, &RenderOptions::default()).expect("render");
    assert!(invocations(&r, StageKind::ToksvigShade) > 100);
    let e = r.stats.error_8bit.as_ref().expect("reference");
    assert!(e.max_abs_lsb <= 3, "{e:?}");
    let bad = d.join("bad.toml");
    std::fs::write(&bad, body("blurry")).expect("write");
    let err = texsim::scene::load(&bad)
        .expect_err("unknown filter")
        .to_string();
    assert!(
        err.contains("bump_filter") && err.contains("'blurry'"),
        "{err}"
    );
}
