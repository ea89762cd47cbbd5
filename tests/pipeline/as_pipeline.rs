//! Ashikhmin-Shirley materials through the pipeline: the built-in scenes `as-metal`,
//! `as-plastic` and `as-brushed` render fixed and float within measured error bounds, without
//! NaN, deterministically for any thread count; the `as-shade` cost is the unit costs; the
//! TOML material fields and their errors; the sweep knobs of the unit; brushed highlights turn
//! with the main direction.

use hw_model::HwConfig;
use texsim::pipeline::{Impl, StageImpls, StageKind};
use texsim::render::{render, Maps, RenderOptions, Rendered};
use texsim::scene::{self, Scene};

fn small(name: &str, w: u32, h: u32) -> Scene {
    let mut s = scene::builtin(name).expect("builtin scene");
    s.width = w;
    s.height = h;
    s
}

fn go(s: &Scene, hw: &HwConfig, impls: StageImpls) -> Rendered {
    let maps = Maps::new(s, hw.trilinear.texel_bits);
    let opts = RenderOptions {
        hw_impls: impls,
        ..RenderOptions::default()
    };
    render(s, &maps, hw, &opts).expect("render")
}

fn stage(r: &Rendered, k: StageKind) -> &texsim::render::StageStats {
    r.stats.stages.iter().find(|s| s.stage == k).expect("stage")
}

/// (scene, width, height, max 8-bit LSB all fixed, max 8-bit LSB with only `as-shade` fixed).
/// Measured at these sizes: as-metal 38 / 3, as-plastic 6 / 3, as-brushed 4 / 2. The all-fixed
/// maximum of as-metal is one pixel on the highlight of an `n = 10^4` sphere, a pixel-sized
/// spike where the 2^-14 quantization of the interpolated normal (upstream of `as-shade`)
/// moves the lobe `(h.n)^E` by a large fraction of its height; `as-shade` alone stays within 3.
const SCENES: [(&str, u32, u32, u32, u32); 3] = [
    ("as-metal", 200, 200, 64, 4),
    ("as-plastic", 200, 200, 10, 4),
    ("as-brushed", 240, 180, 6, 4),
];

#[test]
fn scenes_render_within_bounds_without_nan() {
    let hw = HwConfig::texram16();
    for (name, w, h, max_all, max_iso) in SCENES {
        let s = small(name, w, h);
        let r = go(&s, &hw, StageImpls::FIXED);
        let st = &r.stats;
        let e8 = st.error_8bit.as_ref().expect("reference");
        eprintln!(
            "{name} {w}x{h}: max {} mean {:.4} LSB8, {:.2} cycles/px",
            e8.max_abs_lsb, e8.mean_abs_lsb, st.issue_cycles.per_covered_pixel
        );
        assert!(st.covered_pixels > 1000, "{name}");
        assert!(e8.max_abs_lsb <= max_all, "{name}: {}", e8.max_abs_lsb);
        assert!(e8.pct_within_1lsb >= 99.8, "{name}: {}", e8.pct_within_1lsb);
        assert_eq!(st.bump.nonfinite + st.bump.ref_nonfinite, 0, "{name}");
        let a = stage(&r, StageKind::AsShade);
        assert_eq!(a.invocations, st.covered_pixels, "{name}");
        assert_eq!(a.imp, Impl::Fixed);
        // Only the stages an AS material needs ran.
        for k in [StageKind::Phong, StageKind::Perturb, StageKind::BumpFetch] {
            assert_eq!(stage(&r, k).invocations, 0, "{name} {k}");
        }
        // The AS stage alone (everything else float).
        let iso = go(
            &s,
            &hw,
            StageImpls::FLOAT.with(StageKind::AsShade, Impl::Fixed),
        );
        let e = iso.stats.error_8bit.as_ref().expect("reference");
        eprintln!("{name} as-shade isolated: max {} LSB8", e.max_abs_lsb);
        assert!(e.max_abs_lsb <= max_iso, "{name}: {}", e.max_abs_lsb);
        // All float: the hardware image is the reference.
        let fl = go(&s, &hw, StageImpls::FLOAT);
        assert_eq!(fl.stats.error_16bit.as_ref().expect("ref").max_abs_lsb, 0);
    }
}

#[test]
fn as_shade_cost_is_the_unit_costs() {
    use hw_model::aniso_phong::aniso_phong_cost;
    use hw_model::rsqrt::rsqrt_cost;
    use hw_model::vector::{dot_cost, normalize_cost};
    let hw = HwConfig::texram16();
    let s = small("as-brushed", 160, 120);
    let r = go(&s, &hw, StageImpls::FIXED);
    let sh = &hw.shading;
    let g = hw.timing.gate_levels_per_cycle;
    let nz = normalize_cost(&sh.vector, rsqrt_cost(&sh.rsqrt, g), g);
    let mac = hw_model::blinn_phong::mac_datapath(sh).latency(g);
    let half = hw_model::blinn_phong::half_vector_datapath(sh).latency(g);
    // One directional and one point light: eye + point normalizations, then per light the
    // half vector (add + normalize), six dots, the unit and two colour multiply-adds; ambient.
    let per_light = half
        + nz.cycles
        + 6 * dot_cost(&sh.vector, g).cycles
        + aniso_phong_cost(&hw.aniso_phong, g).cycles
        + 2 * mac;
    let per_px = 2 * nz.cycles + 2 * per_light + mac;
    let a = stage(&r, StageKind::AsShade);
    assert_eq!(a.issue_cycles, a.invocations * u64::from(per_px));
    // A costlier unit shows up in the stage's cycles and the summary's issue cycles/px.
    let mut slow = hw.clone();
    slow.aniso_phong.aniso_mul_cycles = hw_model::datapath::Cycles::Fixed(3);
    let r2 = go(&s, &slow, StageImpls::FIXED);
    assert!(stage(&r2, StageKind::AsShade).issue_cycles > a.issue_cycles);
    assert!(r2.stats.issue_cycles.per_covered_pixel > r.stats.issue_cycles.per_covered_pixel);
}

#[test]
fn deterministic_for_any_thread_count() {
    let hw = HwConfig::texram16();
    let s = small("as-brushed", 160, 120);
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool")
        .install(|| go(&s, &hw, StageImpls::FIXED));
    let many = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .expect("pool")
        .install(|| go(&s, &hw, StageImpls::FIXED));
    assert_eq!(one.hw_image.px, many.hw_image.px);
    assert_eq!(
        one.ref_image.as_ref().map(|i| &i.px),
        many.ref_image.as_ref().map(|i| &i.px)
    );
    let (a, b) = (
        stage(&one, StageKind::AsShade),
        stage(&many, StageKind::AsShade),
    );
    assert_eq!((a.saturated, a.issue_cycles), (b.saturated, b.issue_cycles));
}

/// Mean 16-bit LSB error with only `as-shade` fixed (everything upstream float), on `hw`.
fn isolated_error(s: &Scene, hw: &HwConfig) -> (f64, u32, u64) {
    let r = go(
        s,
        hw,
        StageImpls::FLOAT.with(StageKind::AsShade, Impl::Fixed),
    );
    let e = r.stats.error_16bit.as_ref().expect("ref");
    (
        e.mean_abs_lsb,
        e.max_abs_lsb,
        stage(&r, StageKind::AsShade).saturated,
    )
}

/// Each sweep knob of the unit on its own, set through `set_field` (the path of `texsim
/// sweep`), on a scene where it matters, with only `as-shade` fixed: the coarse setting gives a
/// larger mean error than texram16 (by the factor in the table, about half the measured ratio).
/// Fresnel is checked on as-plastic and as-brushed (`R_s < 1`): on as-metal `R_s = 1` makes
/// `F = 1` whatever the width. `exponent_max_bits = 10` cannot hold the `n = 10^4` spheres
/// (or `n_v = 2000`): their exponents are clamped, and counted as saturations.
#[test]
fn each_unit_knob_changes_the_error() {
    let hw = HwConfig::texram16();
    // (scene, field, coarse value, minimum ratio coarse / texram16 of the mean 16-bit error).
    let cases: [(&str, &str, &str, f64); 7] = [
        ("as-metal", "aniso_pow_lut_bits", "2", RATIO_LUT),
        ("as-metal", "aniso_pow_frac_bits", "8", RATIO_FRAC),
        ("as-metal", "aniso_ratio_bits", "4", RATIO_RATIO),
        ("as-metal", "exponent_max_bits", "10", RATIO_EMAX),
        ("as-brushed", "exponent_max_bits", "10", RATIO_EMAX),
        ("as-plastic", "fresnel_bits", "6", RATIO_FRESNEL),
        ("as-brushed", "fresnel_bits", "6", RATIO_FRESNEL),
    ];
    let mut base = std::collections::HashMap::new();
    for (name, field, value, min_ratio) in cases {
        let s = if name == "as-brushed" {
            small(name, 160, 120)
        } else {
            small(name, 120, 120)
        };
        let (e0, _, sat0) = *base.entry(name).or_insert_with(|| isolated_error(&s, &hw));
        let c = texsim::hwconfig::set_field(&hw, field, value).expect(field);
        let (e, max, sat) = isolated_error(&s, &c);
        eprintln!(
            "{name} {field}={value}: mean16 {e:.3} (texram16 {e0:.3}, ratio {:.2}), max16 {max}, saturated {sat} ({sat0})",
            e / e0
        );
        assert!(e.is_finite() && e0 > 0.0, "{name} {field}");
        assert!(
            e > min_ratio * e0,
            "{name} {field}={value}: {e} vs texram16 {e0}"
        );
        if field == "exponent_max_bits" {
            assert!(sat > sat0 + 1000, "{name}: clamped exponents are counted");
        }
    }
}

// Measured ratios of the mean 16-bit error, coarse / texram16 (as-metal and as-plastic at
// 120x120, as-brushed at 160x120): aniso_pow_lut_bits=2 4.22, aniso_pow_frac_bits=8 5.55,
// aniso_ratio_bits=4 4.77, exponent_max_bits=10 314 (as-metal) and 326 (as-brushed),
// fresnel_bits=6 158 (as-plastic) and 24.7 (as-brushed). Asserted at about half.
const RATIO_LUT: f64 = 2.0;
const RATIO_FRAC: f64 = 2.5;
const RATIO_RATIO: f64 = 2.0;
const RATIO_EMAX: f64 = 100.0;
const RATIO_FRESNEL: f64 = 10.0;

#[track_caller]
fn write_toml(name: &str, body: &str) -> crate::tmp_common::TmpFile {
    crate::tmp_common::TmpFile::new(name, "s.toml", body)
}

fn with_material(fields: &str) -> String {
    format!(
        "[output]\nwidth = 64\nheight = 48\n\n[[materials]]\nname = \"m\"\n{fields}\n\n[[meshes]]\nshape = \"sphere\"\nmaterial = \"m\"\n"
    )
}

#[test]
fn toml_material_fields_and_errors() {
    let p = write_toml(
        "ok",
        &with_material(
            "brdf = \"ashikhmin-shirley\"\nnu = 10\nnv = 1000.0\nrs = 0.9\nrd = 0.1\nmain_direction = [0.0, 1.0, 0.0]",
        ),
    );
    let s = scene::load(&p).expect("load");
    let b = s.materials[0].brdf.expect("AS material");
    assert_eq!((b.nu, b.nv, b.rs, b.rd), (10.0, 1000.0, 0.9, 0.1));
    let r = go(&s, &HwConfig::texram16(), StageImpls::FIXED);
    assert!(stage(&r, StageKind::AsShade).invocations > 0);
    for (fields, needle) in [
        ("nu = 10", "materials[0].nu"),
        ("brdf = \"cook-torrance\"", "materials[0].brdf"),
        ("brdf = \"ashikhmin-shirley\"\nnu = 1.5", "materials[0].nu"),
        ("brdf = \"ashikhmin-shirley\"\nnv = -1", "materials[0].nv"),
        ("brdf = \"ashikhmin-shirley\"\nnv = 1e7", "materials[0].nv"),
        ("brdf = \"ashikhmin-shirley\"\nrs = 2", "materials[0].rs"),
        ("brdf = \"ashikhmin-shirley\"\nrd = nan", "materials[0].rd"),
        (
            "brdf = \"ashikhmin-shirley\"\nexponent_map = \"nope\"",
            "materials[0].exponent_map",
        ),
        ("exponent_map = \"nope\"", "materials[0].exponent_map"),
    ] {
        let p = write_toml("bad", &with_material(fields));
        let e = scene::load(&p).expect_err(fields).to_string();
        assert!(e.contains(needle), "{fields}: {e}");
    }
}

#[test]
fn exponent_map_scene_fetches_per_pixel_exponents() {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/as_brushed.toml");
    let mut s = scene::load(&p).expect("load");
    s.width = 240;
    s.height = 180;
    let m = &s.materials[1];
    assert_eq!(m.brdf.and_then(|b| b.exponent_map), Some(0));
    let hw = HwConfig::texram16();
    let r = go(&s, &hw, StageImpls::FIXED);
    let fetch = stage(&r, StageKind::BumpFetch);
    assert!(fetch.invocations > 0 && fetch.texels > 0);
    assert_eq!(
        fetch.invocations,
        stage(&r, StageKind::Texcoord).invocations
    );
    assert!(
        fetch.invocations < r.stats.covered_pixels,
        "only the mapped sphere"
    );
    let e8 = r.stats.error_8bit.as_ref().expect("reference");
    eprintln!("as_brushed.toml 240x180: max {} LSB8", e8.max_abs_lsb);
    assert!(e8.max_abs_lsb <= 8, "{}", e8.max_abs_lsb);
    assert_eq!(r.stats.bump.nonfinite + r.stats.bump.ref_nonfinite, 0);
    // A constant exponent map of 1 (white) gives the material's own exponents.
    let mut flat = s.clone();
    flat.textures[0]
        .texels
        .iter_mut()
        .for_each(|t| *t = [u16::MAX; 4]);
    let mut plain = flat.clone();
    if let Some(b) = plain.materials[1].brdf.as_mut() {
        b.exponent_map = None;
    }
    let a = go(&flat, &hw, StageImpls::FIXED);
    let b = go(&plain, &hw, StageImpls::FIXED);
    assert_eq!(a.hw_image.px, b.hw_image.px);
}

/// Intensity-weighted orientation (degrees in `(-90, 90]`, from +x toward +y up the screen) and
/// elongation (ratio of the principal variances) of an image's red channel.
fn highlight_axis(img: &texsim::report::Image) -> (f64, f64) {
    let (mut s, mut sx, mut sy) = (0.0, 0.0, 0.0);
    for y in 0..img.height {
        for x in 0..img.width {
            let w = f64::from(img.px[(y * img.width + x) as usize][0]);
            s += w;
            sx += w * f64::from(x);
            sy -= w * f64::from(y);
        }
    }
    let (mx, my) = (sx / s, sy / s);
    let (mut cxx, mut cyy, mut cxy) = (0.0, 0.0, 0.0);
    for y in 0..img.height {
        for x in 0..img.width {
            let w = f64::from(img.px[(y * img.width + x) as usize][0]);
            let (dx, dy) = (f64::from(x) - mx, -f64::from(y) - my);
            cxx += w * dx * dx;
            cyy += w * dy * dy;
            cxy += w * dx * dy;
        }
    }
    let angle = 0.5 * (2.0 * cxy).atan2(cxx - cyy);
    let tr = 0.5 * (cxx + cyy);
    let d = (0.25 * (cxx - cyy).powi(2) + cxy * cxy).sqrt();
    (angle.to_degrees(), (tr + d) / (tr - d))
}

/// Brushed metal follows its main direction: a sphere seen along -z, lit from the viewer, with
/// `n_u = 20`, `n_v = 800` and a constant main direction `m` in the screen plane. At the centre
/// the frame is `u = m x n`, so the lobe is narrow along `v` (parallel to `m`) and the highlight
/// is stretched across `m` (principal variance ratio about `(n_v + 1)/(n_u + 1) = 38` for an
/// unclipped Gaussian lobe). Rotating `m` by 0, 30, 45, 90 and 135 degrees rotates the
/// highlight's principal axis by the same angle in the fixed image and in the float reference
/// (measured within 0.01 degrees; asserted within 1) and the highlight stays elongated
/// (measured variance ratio 31.7-32.0; asserted > 10).
#[test]
fn brushed_highlight_follows_the_main_direction() {
    let hw = HwConfig::texram16();
    let mut axes = Vec::new();
    for deg in [0.0f64, 30.0, 45.0, 90.0, 135.0] {
        let (sa, ca) = deg.to_radians().sin_cos();
        // m at `deg` from screen up (+y), turning toward -x.
        let body = format!(
            "[output]\nwidth = 96\nheight = 96\nbackground = [0.0, 0.0, 0.0, 1.0]\n\n[camera]\neye = [0.0, 0.0, 3.0]\ntarget = [0.0, 0.0, 0.0]\nfov_y_deg = 40.0\n\n[[lights]]\nkind = \"directional\"\ndirection = [0.0, 0.0, -1.0]\ncolor = [1.0, 1.0, 1.0]\n\n[[materials]]\nname = \"m\"\nbrdf = \"ashikhmin-shirley\"\nnu = 20\nnv = 800\nrs = 0.9\nrd = 0.0\nmain_direction = [{}, {}, 0.0]\n\n[[meshes]]\nshape = \"sphere\"\nmaterial = \"m\"\n",
            -sa, ca
        );
        let p = write_toml(&format!("axis{deg}"), &body);
        let s = scene::load(&p).expect("load");
        let r = go(&s, &hw, StageImpls::FIXED);
        let fixed = highlight_axis(&r.hw_image);
        let float = highlight_axis(r.ref_image.as_ref().expect("reference"));
        eprintln!("m at {deg} deg: fixed axis {fixed:?}, float axis {float:?}");
        axes.push((deg, fixed, float));
    }
    let (_, f0, r0) = axes[0];
    for &(deg, f, r) in &axes {
        for (what, a, a0) in [("fixed", f, f0), ("float", r, r0)] {
            assert!(a.1 > 10.0, "{what} at {deg}: not elongated {a:?}");
            // Rotation of the axis, modulo 180 degrees, against the rotation of m.
            let turn = (a.0 - a0.0 - deg).rem_euclid(180.0);
            let off = turn.min(180.0 - turn);
            assert!(
                off < 1.0,
                "{what}: m turned {deg}, axis turned {}",
                a.0 - a0.0
            );
        }
    }
    // At 0 degrees (m = screen up) the highlight is stretched across m: along x.
    assert!(f0.0.abs() < 1.0 && r0.0.abs() < 1.0, "{f0:?} {r0:?}");
}
