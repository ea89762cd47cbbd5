//! Whole-frame tests: stage planning, fixed/float twins, determinism, error bounds.

use texsim::pipeline::{Impl, StageImpls, StageKind};
use texsim::render::{render, CoverageMode, Maps, RenderOptions, Rendered};
use texsim::scene::{self, Scene};

fn small(name: &str, w: u32, h: u32) -> Scene {
    let mut s = scene::builtin(name).expect("builtin scene");
    s.width = w;
    s.height = h;
    s
}

fn go(s: &Scene, opts: &RenderOptions) -> Rendered {
    let hw = hw_model::HwConfig::texram16();
    let maps = Maps::new(s, hw.trilinear.texel_bits);
    render(s, &maps, &hw, opts).expect("render")
}

fn fnv(img: &texsim::report::Image) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for p in &img.px {
        for c in p {
            for b in c.to_le_bytes() {
                h ^= u64::from(b);
                h = h.wrapping_mul(0x0100_0000_01b3);
            }
        }
    }
    h
}

#[test]
fn all_float_hardware_equals_reference_exactly() {
    let s = small("demo", 256, 192);
    let r = go(
        &s,
        &RenderOptions {
            hw_impls: StageImpls::FLOAT,
            ..Default::default()
        },
    );
    assert_eq!(Some(&r.hw_image), r.ref_image.as_ref());
    let e = r.stats.error_16bit.expect("metrics");
    assert_eq!(e.max_abs_lsb, 0);
}

#[test]
fn fixed_path_error_is_small_and_nonzero() {
    let s = small("demo", 320, 240);
    let r = go(&s, &RenderOptions::default());
    let e8 = r.stats.error_8bit.expect("metrics");
    let e16 = r.stats.error_16bit.expect("metrics");
    // texram16 is 16 bits throughout: the hardware image must be visually identical
    // (at most 1 LSB in 8 bits on >= 99.9% of pixels) yet not a copy of the reference.
    assert!(
        e16.max_abs_lsb > 0,
        "fixed path suspiciously identical to float"
    );
    assert!(e8.pct_within_1lsb >= 99.9, "{e8:?}");
    assert!(e8.max_abs_lsb <= 8, "{e8:?}");
}

#[test]
fn coarse_presets_have_larger_error() {
    let s = small("demo", 320, 240);
    let maps = Maps::new(&s, 16);
    let err = |hw: hw_model::HwConfig| {
        let r = render(&s, &maps, &hw, &RenderOptions::default()).expect("render");
        r.stats.error_16bit.expect("metrics").rmse_lsb
    };
    let t16 = err(hw_model::HwConfig::texram16());
    let vk = err(hw_model::HwConfig::vulkan_min());
    assert!(vk > 2.0 * t16, "vulkan-min rmse {vk} vs texram16 {t16}");
}

#[test]
fn isolating_one_stage_attributes_error_to_it() {
    let s = small("demo", 256, 192);
    let hw = hw_model::HwConfig::vulkan_min();
    let maps = Maps::new(&s, 16);
    let rm = |im: StageImpls| {
        let r = render(
            &s,
            &maps,
            &hw,
            &RenderOptions {
                hw_impls: im,
                ..Default::default()
            },
        )
        .expect("render");
        r.stats.error_16bit.expect("metrics").rmse_lsb
    };
    let only_tri = rm(StageImpls::FLOAT.with(StageKind::Trilinear, Impl::Fixed));
    let only_mod = rm(StageImpls::FLOAT.with(StageKind::Modulate, Impl::Fixed));
    // 4 sub-texel bits dominate; a 16-bit modulate is near-exact.
    assert!(
        only_tri > 4.0 * only_mod,
        "trilinear {only_tri} modulate {only_mod}"
    );
}

#[test]
fn absent_stages_are_never_invoked() {
    let mut s = small("demo", 160, 120);
    for m in &mut s.materials {
        m.texture = None;
        m.bump = None;
        m.lit = false;
    }
    let r = go(&s, &RenderOptions::default());
    assert!(r.stats.covered_pixels > 0);
    for st in &r.stats.stages {
        assert_eq!(
            st.invocations, 0,
            "{:?} ran for an unlit untextured scene",
            st.stage
        );
        assert_eq!(st.issue_cycles, 0);
    }
    assert_eq!(r.stats.issue_cycles.stages, 0);

    for m in &mut s.materials {
        m.lit = true;
    }
    let r = go(&s, &RenderOptions::default());
    for st in &r.stats.stages {
        let expect = matches!(st.stage, StageKind::Bary | StageKind::Color);
        assert_eq!(st.invocations > 0, expect, "{:?}", st.stage);
    }
}

#[test]
fn textured_stages_run_once_per_covered_pixel() {
    let s = small("w1-plane", 256, 256);
    let r = go(&s, &RenderOptions::default());
    let inv = |k: StageKind| r.stats.stages[k.index()].invocations;
    assert!(r.stats.covered_pixels > 10_000);
    assert_eq!(inv(StageKind::Trilinear), r.stats.covered_pixels);
    assert_eq!(inv(StageKind::Lod), r.stats.covered_pixels);
    assert_eq!(inv(StageKind::Color), 0, "W1 is unlit (GL_REPLACE)");
    assert_eq!(
        inv(StageKind::Modulate),
        0,
        "white unlit material needs no modulate"
    );
    assert_eq!(
        r.stats.stages[StageKind::Trilinear.index()].texels,
        8 * r.stats.covered_pixels
    );
}

#[test]
fn output_is_identical_for_any_thread_count() {
    let s = small("demo", 256, 192);
    let run_in = |n: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .expect("pool");
        pool.install(|| go(&s, &RenderOptions::default()))
    };
    let a = run_in(1);
    let b = run_in(3);
    assert_eq!(a.hw_image, b.hw_image);
    assert_eq!(a.ref_image, b.ref_image);
    assert_eq!(
        serde_json::to_string(&a.stats.stages).unwrap(),
        serde_json::to_string(&b.stats.stages).unwrap()
    );
}

/// Independent coverage: the reference rasterizes on its own in float, so its fragments differ
/// from the hardware's (snapped vertices: 2 sub-pixel bits make the difference reach the
/// silhouette). Reusing the shared coverage would give the same reference image and mask.
#[test]
fn independent_coverage_rasterizes_the_reference_on_its_own() {
    let s = small("sphere", 200, 150);
    let mut hw = hw_model::HwConfig::texram16();
    hw.raster.subpixel_bits = 2;
    let maps = Maps::new(&s, hw.trilinear.texel_bits);
    let run = |coverage| {
        let opts = RenderOptions {
            coverage,
            ..Default::default()
        };
        render(&s, &maps, &hw, &opts).expect("render")
    };
    let shared = run(CoverageMode::Shared);
    let ind = run(CoverageMode::Independent);
    assert_eq!(
        shared.hw_image, ind.hw_image,
        "the hardware pass is the same"
    );
    let (sr, ir) = (
        shared.ref_image.as_ref().expect("ref"),
        ind.ref_image.as_ref().expect("ref"),
    );
    // Shared coverage: the reference shades exactly the hardware's fragments.
    let bg = shared.hw_image.px[0];
    assert!(!shared.mask[0], "corner is background");
    for (i, &m) in shared.mask.iter().enumerate() {
        if !m {
            assert_eq!(sr.px[i], bg, "shared reference shaded uncovered pixel {i}");
        }
    }
    assert!(shared.mask.iter().zip(&ind.mask).all(|(&a, &b)| !a || b));
    let float_only = (0..ind.mask.len())
        .filter(|&i| ind.mask[i] && !shared.mask[i] && ir.px[i] != bg)
        .count();
    let changed = sr.px.iter().zip(&ir.px).filter(|(a, b)| a != b).count();
    println!("float-only pixels {float_only}, reference pixels changed {changed}");
    assert!(float_only > 0, "no pixel covered by the float raster alone");
    // Inside the silhouette too, interior edges fall elsewhere: other triangles shade.
    assert!(
        changed > float_only,
        "{changed} changed, {float_only} float-only"
    );
    assert_eq!(ind.stats.coverage, CoverageMode::Independent);
}

/// `interp.texcoord_overflow` reaches the texture coordinates: on the demo's floor (texture
/// coordinates spanning dozens of repeats) a 2-bit integer part overflows, and each rule counts
/// its own events, per stage (the interpolator's helper samples) and on vertex input.
#[test]
fn texcoord_overflow_rule_is_counted_per_stage() {
    let s = small("demo", 320, 240);
    let maps = Maps::new(&s, 16);
    let run = |ov: hw_model::fixed::Overflow| {
        let mut hw = hw_model::HwConfig::texram16();
        hw.interp.texcoord_int_bits = 2;
        hw.interp.texcoord_overflow = ov;
        // The coordinates as given (no per-triangle offset reduction): they overflow.
        hw.interp.texcoord_reduce = false;
        render(&s, &maps, &hw, &RenderOptions::default()).expect("render")
    };
    let sat = run(hw_model::fixed::Overflow::Saturate);
    let wrap = run(hw_model::fixed::Overflow::Wrap);
    let tc = |r: &Rendered| {
        let st = &r.stats.stages[StageKind::Texcoord.index()];
        (st.saturated, st.wrapped)
    };
    let (ts, tw) = tc(&sat);
    assert!(
        ts > 0 && tw == 0,
        "saturate: texcoord {ts} saturated, {tw} wrapped"
    );
    let (ws, ww) = tc(&wrap);
    assert!(
        ww > 0 && ws == 0,
        "wrap: texcoord {ws} saturated, {ww} wrapped"
    );
    assert!(sat.stats.input_saturated > 0 && sat.stats.input_wrapped == 0);
    assert!(wrap.stats.input_wrapped > 0 && wrap.stats.input_saturated == 0);
    let json = serde_json::to_value(&wrap.stats).expect("json");
    assert_eq!(json["input_wrapped"], wrap.stats.input_wrapped);
    assert_ne!(sat.hw_image, wrap.hw_image);
}

#[test]
fn golden_fixed_image_of_w1_plane() {
    // The fixed path is bit-exact by design: any change to this hash must be deliberate
    // (update it and say why in the commit). Last change: analytic barycentric derivatives
    // (one reciprocal per pixel) replaced the two helper samples.
    let s = small("w1-plane", 128, 128);
    let r = go(
        &s,
        &RenderOptions {
            reference: false,
            ..Default::default()
        },
    );
    let h = fnv(&r.hw_image);
    assert_eq!(h, GOLDEN_W1_128, "golden hash changed: {h:#018x}");
}

const GOLDEN_W1_128: u64 = 0xc1b4_a43b_8bcf_66b8;

/// Mesa's binary32 matrices come with the anchor scenes' cameras, not with their names: the
/// built-in W1 and W2 carry them, and a scene that is only named `w1-plane` is transformed by
/// its own camera (the float32 vertex transform then starts from its view-projection).
#[test]
fn mesa_matrices_belong_to_the_anchor_cameras_not_to_scene_names() {
    use texsim::scene::gl_matrix;
    for (name, mvp) in [
        ("w1-plane", gl_matrix::w1_plane_mvp()),
        ("w2-mesh", gl_matrix::w2_mesh_mvp()),
    ] {
        let s = scene::builtin(name).expect("scene");
        assert_eq!(s.camera.view_override.and_then(|g| g.mvp_f32), Some(mvp));
    }
    let hw = hw_model::HwConfig::preset("llvmpipe").expect("preset");
    let opts = RenderOptions {
        reference: false,
        ..Default::default()
    };
    let run = |s: &Scene| {
        let maps = Maps::new(s, hw.trilinear.texel_bits);
        render(s, &maps, &hw, &opts).expect("render").hw_image.px
    };
    let mut s = small("w1-plane", 64, 64);
    let anchored = run(&s);
    s.name = "user".into();
    assert_eq!(run(&s), anchored, "the matrices do not follow the name");
    s.camera.view_override = s
        .camera
        .view_override
        .map(|g| scene::GlView { mvp_f32: None, ..g });
    let own = run(&s);
    s.name = "w1-plane".into();
    assert_eq!(
        run(&s),
        own,
        "a user scene named w1-plane keeps its own transform"
    );
    assert_ne!(
        own, anchored,
        "Mesa's float32 product differs from the f64 one here"
    );
}

/// The llvmpipe preset on a small W1: its image lies on the 8-bit grid (8-bit texels,
/// GL_REPLACE), and the LOD per 2x2 quad changes pixels against per-pixel derivatives.
#[test]
fn llvmpipe_preset_samples_8_bit_texels_with_a_lod_per_quad() {
    let s = small("w1-plane", 128, 128);
    let opts = RenderOptions {
        reference: false,
        ..Default::default()
    };
    let run = |hw: &hw_model::HwConfig| {
        let maps = Maps::new(&s, hw.trilinear.texel_bits);
        render(&s, &maps, hw, &opts).expect("render")
    };
    let l = hw_model::HwConfig::preset("llvmpipe").expect("preset");
    let a = run(&l);
    assert!(a.stats.covered_pixels > 4000);
    let mut px = 0;
    for p in &a.hw_image.px {
        if p[3] != 0 {
            px += 1;
            assert!(p.iter().all(|&c| c % 257 == 0), "8-bit value: {p:?}");
        }
    }
    assert!(px > 4000);
    // The per-quad LOD against the per-pixel one, on the fixed coordinate path (the float32
    // path is llvmpipe's and always per quad).
    let mut quad = l.clone();
    quad.interp.coord_arith = hw_model::config::CoordArith::Fixed;
    let q = run(&quad);
    let differ_f32 = a
        .hw_image
        .px
        .iter()
        .zip(&q.hw_image.px)
        .filter(|(x, y)| x != y)
        .count();
    assert!(differ_f32 > 0, "the float32 coordinates change pixels");
    assert!(
        differ_f32 < px / 4,
        "by one rounding here and there: {differ_f32}"
    );
    let mut per_pixel = quad.clone();
    per_pixel.lod.lod_per_quad = false;
    let b = run(&per_pixel);
    let differ = q
        .hw_image
        .px
        .iter()
        .zip(&b.hw_image.px)
        .filter(|(x, y)| x != y)
        .count();
    assert!(differ > 50, "quad LOD changes pixels: {differ}");
    assert!(
        differ < px / 2,
        "but only where the level fraction moves: {differ}"
    );
}

/// A render builds the triangles' float vertex data only when a float pass runs or a stage
/// of its hardware pass reads it (`stages::reads_tri_floats`); a stage that reads it
/// otherwise sees NaN. Every built-in scene, and the W1 plane with its texture coordinates
/// moved 1000 repeats away (the float32 path reduces them by an integer taken from the float
/// coordinates: NaN would leave them beyond the format), with each stage kind's float twin
/// alone and on the float32 coordinate path (`llvmpipe`), gives the same hardware image and
/// stage counts without the reference (the data built only when the stage rows say so) as with
/// it (always).
#[test]
fn every_float_reader_gets_the_float_vertex_data() {
    let texram = hw_model::HwConfig::texram16();
    let llvmpipe = hw_model::HwConfig::llvmpipe();
    let mut far = small("w1-plane", 48, 32);
    for mesh in &mut far.meshes {
        for uv in &mut mesh.uvs {
            *uv = uv.map(|x| x + 1000.0);
        }
    }
    let scenes = scene::BUILTIN
        .iter()
        .map(|&(name, _)| small(name, 48, 32))
        .chain([far]);
    for s in scenes {
        let name = s.name.clone();
        let maps = Maps::new(&s, texram.trilinear.texel_bits);
        let runs = StageKind::ALL
            .iter()
            .map(|&k| {
                (
                    &texram,
                    StageImpls::FIXED.with(k, Impl::Float),
                    k.to_string(),
                )
            })
            .chain([(&llvmpipe, StageImpls::FIXED, "float32 path".to_string())]);
        for (hw, impls, what) in runs {
            let maps = if hw.trilinear.texel_bits == texram.trilinear.texel_bits {
                &maps
            } else {
                &Maps::new(&s, hw.trilinear.texel_bits)
            };
            let with = |reference| {
                let opts = RenderOptions {
                    hw_impls: impls,
                    reference,
                    timing: false,
                    ..Default::default()
                };
                render(&s, maps, hw, &opts).expect("render")
            };
            let (built, own) = (with(true), with(false));
            assert!(
                built.hw_image == own.hw_image,
                "{name}, {what}: hardware image"
            );
            let stages = |r: &Rendered| serde_json::to_value(&r.stats.stages).expect("json");
            assert_eq!(stages(&built), stages(&own), "{name}, {what}: stage counts");
        }
    }
}

/// The hardware pass alone converts the attributes of the triangles it shades only: the
/// image, the stage counters and the setup's overflow counts are those of a render whose
/// reference pass has every triangle converted, on the torus (about half its triangles
/// hidden) and on coordinate formats narrow enough to overflow.
#[test]
fn hidden_triangles_skip_their_conversion_and_keep_every_count() {
    let s = small("w2-mesh", 160, 160);
    let maps = Maps::new(&s, 16);
    for (int_bits, reduce) in [(8, true), (1, true), (1, false)] {
        let mut hw = hw_model::HwConfig::texram16();
        hw.interp.texcoord_int_bits = int_bits;
        hw.interp.texcoord_reduce = reduce;
        let run = |reference| {
            let opts = RenderOptions {
                reference,
                ..Default::default()
            };
            render(&s, &maps, &hw, &opts).expect("render")
        };
        let (alone, with_ref) = (run(false), run(true));
        assert!(alone.stats.covered_pixels > 5000);
        assert_eq!(alone.hw_image, with_ref.hw_image, "{int_bits} {reduce}");
        let counts = |r: &Rendered| {
            let st = &r.stats;
            (
                st.input_saturated,
                st.input_wrapped,
                serde_json::to_string(&st.stages).expect("json"),
            )
        };
        assert_eq!(counts(&alone), counts(&with_ref), "{int_bits} {reduce}");
        // The one-bit format without the offset reduction overflows, at setup and after.
        let overflows = alone.stats.input_saturated > 0;
        assert_eq!(overflows, !reduce, "{int_bits} {reduce}");
    }
}
