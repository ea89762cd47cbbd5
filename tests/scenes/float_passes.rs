//! The float passes (the reference and the ground truth) do not read the `float_blind` fields
//! of the machine: every built-in scene renders them to the same bits with all those fields
//! changed at once, and a render handed an earlier render's passes (`FloatPasses`) equals one
//! that runs them, images and numbers.

use hw_model::HwConfig;
use std::sync::Arc;
use texsim::hwconfig::{fields, set_field};
use texsim::render::{float_blind, render, FloatPasses, Maps, RenderOptions, Rendered};
use texsim::scene::{builtin, Scene, BUILTIN};

/// A built-in scene at 64x48 (every effect, a small frame).
fn small(name: &str) -> Scene {
    let mut s = builtin(name).unwrap();
    (s.width, s.height) = (64, 48);
    s
}

/// The first value of `candidates` that `c` accepts for `path` and that differs from `now`.
fn other_value(c: &HwConfig, path: &str, now: &str, candidates: &[String]) -> Option<HwConfig> {
    candidates
        .iter()
        .filter(|v| v.as_str() != now)
        .find_map(|v| set_field(c, path, v).ok())
}

/// `base` with every `float_blind` field changed (an integer to its least valid value, else
/// half, double, one more, a small width or 1024; a boolean flipped; a name to another), one after the other.
/// Panics naming a field that no candidate could change.
fn blind_variant(base: &HwConfig) -> HwConfig {
    let mut c = base.clone();
    let mut stuck = Vec::new();
    for (path, now) in fields(base) {
        if !float_blind(&path) {
            continue;
        }
        let candidates: Vec<String> = if let Ok(n) = now.parse::<u32>() {
            let lo = texsim::tune::knob(&c, &path).map_or(n, |k| k.lo);
            [lo, n / 2, n * 2, n + 1, 1, 4, 8, 1024, 0]
                .iter()
                .map(u32::to_string)
                .collect()
        } else {
            ["false", "true", "linear", "tiled"]
                .map(String::from)
                .to_vec()
        };
        match other_value(&c, &path, &now, &candidates) {
            Some(next) => c = next,
            None => stuck.push(path),
        }
    }
    assert!(stuck.is_empty(), "no other valid value for {stuck:?}");
    c
}

fn opts() -> RenderOptions {
    RenderOptions {
        truth: 2,
        ..RenderOptions::default()
    }
}

fn render_on(s: &Scene, base_maps: &Maps, hw: &HwConfig, opts: &RenderOptions) -> Rendered {
    let mut maps = base_maps.clone();
    maps.ensure_texel_bits(hw.trilinear.texel_bits);
    maps.ensure_offset_bits(hw.shading.vector.offset_int_bits);
    render(s, &maps, hw, opts).unwrap_or_else(|e| panic!("{}: {e}", s.name))
}

/// Both renders made the same reference (and count of non-finite float results) and truth.
fn same_float_passes(a: &Rendered, b: &Rendered) -> bool {
    a.ref_image == b.ref_image
        && a.truth_image == b.truth_image
        && a.stats.bump.ref_nonfinite == b.stats.bump.ref_nonfinite
}

/// Everything a render measured, minus its wall times.
fn numbers(r: &Rendered) -> serde_json::Value {
    let mut v = serde_json::to_value(&r.stats).unwrap();
    v.as_object_mut().unwrap().remove("timings");
    v
}

#[test]
fn float_passes_ignore_every_float_blind_field_and_reuse_matches_a_full_render() {
    let base = HwConfig::texram16();
    let variant = blind_variant(&base);
    let blind = fields(&base).iter().filter(|(p, _)| float_blind(p)).count();
    assert!(blind >= 50, "{blind} float-blind fields");
    for (name, _) in BUILTIN {
        let s = small(name);
        let maps = Maps::new(&s, base.trilinear.texel_bits);
        let first = render_on(&s, &maps, &base, &opts());
        let fresh = render_on(&s, &maps, &variant, &opts());
        assert!(first.ref_image.is_some(), "{name}: no reference");
        assert!(
            same_float_passes(&fresh, &first),
            "{name}: float passes differ"
        );
        let kept = FloatPasses::of(&s, &first, &opts()).expect("passes");
        let reused_opts = RenderOptions {
            float_passes: Some(Arc::new(kept)),
            ..opts()
        };
        let reused = render_on(&s, &maps, &variant, &reused_opts);
        assert!(reused.hw_image == fresh.hw_image, "{name}: hardware image");
        assert!(same_float_passes(&reused, &fresh), "{name}: reused passes");
        assert!(reused.mask == fresh.mask, "{name}: mask");
        assert_eq!(numbers(&reused), numbers(&fresh), "{name}");
        assert_eq!(reused.stats.timings.shade_ref_ms, 0.0, "{name}: ran again");
    }
}

/// Each width that is not float-blind changes a float pass of some built-in scene on its
/// own (the list of exceptions is no longer than it must be).
#[test]
fn every_width_left_out_reaches_a_float_pass() {
    let base = HwConfig::texram16();
    // The scenes that show each exception first.
    let order = ["demo", "ripple-sphere", "as-metal"];
    let names = order.iter().copied().chain(
        BUILTIN
            .iter()
            .map(|(n, _)| *n)
            .filter(|n| !order.contains(n)),
    );
    let scenes: Vec<Scene> = names.map(small).collect();
    let mut firsts: Vec<Option<(Maps, Rendered)>> = scenes.iter().map(|_| None).collect();
    for (path, now) in fields(&base) {
        if float_blind(&path) || !texsim::hwconfig::is_width(&path) {
            continue;
        }
        let n: u32 = now.parse().unwrap();
        let candidates: Vec<String> = [1, 4, 8, n / 2, n + 1].iter().map(u32::to_string).collect();
        let c = other_value(&base, &path, &now, &candidates).unwrap();
        let reached = scenes.iter().zip(firsts.iter_mut()).any(|(s, first)| {
            let (maps, r0) = first.get_or_insert_with(|| {
                let maps = Maps::new(s, base.trilinear.texel_bits);
                let r = render_on(s, &maps, &base, &opts());
                (maps, r)
            });
            !same_float_passes(&render_on(s, maps, &c, &opts()), r0)
        });
        assert!(
            reached,
            "{path} does not reach a float pass: make it float-blind"
        );
    }
}

/// Passes kept from another scene, another size, another truth count or without the
/// reference are not used: the render runs its own.
#[test]
fn float_passes_of_another_render_are_not_used() {
    let hw = HwConfig::texram16();
    let demo = small("demo");
    let maps = Maps::new(&demo, hw.trilinear.texel_bits);
    let first = render_on(&demo, &maps, &hw, &opts());
    let kept = Arc::new(FloatPasses::of(&demo, &first, &opts()).unwrap());
    let with = |o: RenderOptions| RenderOptions {
        float_passes: Some(kept.clone()),
        ..o
    };
    let sphere = small("sphere");
    let smaps = Maps::new(&sphere, hw.trilinear.texel_bits);
    let own = render_on(&sphere, &smaps, &hw, &opts());
    assert_eq!(
        render_on(&sphere, &smaps, &hw, &with(opts())).ref_image,
        own.ref_image
    );
    let mut wider = demo.clone();
    wider.width += 1;
    let wmaps = Maps::new(&wider, hw.trilinear.texel_bits);
    let r = render_on(&wider, &wmaps, &hw, &with(opts()));
    assert!(r.stats.timings.shade_ref_ms > 0.0);
    let no_truth = RenderOptions { truth: 0, ..opts() };
    let r = render_on(&demo, &maps, &hw, &with(no_truth));
    assert!(r.stats.timings.shade_ref_ms > 0.0);
}

/// The float passes' depth test is exact: a depth buffer too narrow for the scene shows as
/// error. The demo's ground plane runs to the horizon; at 8 bits its far part rounds to the
/// cleared maximum and fails the depth test, so the hardware shows the background there while
/// the reference shows the plane. Those pixels are compared (and count as large errors), the
/// reference is the one the 24-bit machine gets, and at 24 bits every pixel shows the surface
/// the exact test picks (the error is the shading's alone, as before).
#[test]
fn a_narrow_depth_buffer_shows_as_error_against_the_exact_depth_test() {
    let base = HwConfig::texram16();
    let mut s = builtin("demo").unwrap();
    (s.width, s.height) = (160, 120);
    let maps = Maps::new(&s, base.trilinear.texel_bits);
    let opts = RenderOptions::default();
    let wide = render_on(&s, &maps, &base, &opts);
    let narrow_hw = set_field(&base, "raster.depth_bits", "8").unwrap();
    let narrow = render_on(&s, &maps, &narrow_hw, &opts);
    let covered = |r: &Rendered| r.stats.raster.visible;
    assert!(
        covered(&narrow) < covered(&wide),
        "8-bit depth drops no pixel: {} against {}",
        covered(&narrow),
        covered(&wide)
    );
    assert_eq!(
        narrow.ref_image, wide.ref_image,
        "the reference's depth test"
    );
    assert_eq!(narrow.mask, wide.mask, "the compared pixels");
    let (e_wide, e_narrow) = (
        wide.stats.error_8bit.clone().unwrap(),
        narrow.stats.error_8bit.clone().unwrap(),
    );
    assert_eq!(e_narrow.pixels, e_wide.pixels);
    assert!(e_wide.max_abs_lsb <= 1, "{e_wide:?}");
    assert!(e_narrow.max_abs_lsb >= 32, "{e_narrow:?}");
    let lost = covered(&wide) - covered(&narrow);
    let big = e_narrow
        .histogram
        .iter()
        .find(|(label, _)| label == "32+")
        .map_or(0, |(_, n)| *n);
    assert!(
        big >= lost,
        "{lost} pixels lost, {big} errors of 32 LSB or more"
    );
}
