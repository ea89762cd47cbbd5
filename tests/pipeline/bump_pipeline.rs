//! Bump mapping end to end: the `bumps` scene in each frame, fixed vs float, stage counts and
//! cycles per frame against the unit cost functions, absent bumps cost nothing, determinism,
//! and the real mesh (OBJ + 16-bit height PNG) in TOML and MTL form.

use hw_model::blinn_phong::{blinn_phong_cost, ShadingUnits};
use hw_model::frame::frame_cost;
use hw_model::interpolator::interpolate_cost;
use hw_model::lod::lod_cost;
use hw_model::rsqrt::rsqrt_cost;
use hw_model::trilinear::trilinear_cost;
use hw_model::vector::{madd_cost, normalize_cost};
use hw_model::HwConfig;
use texsim::pipeline::StageKind;
use texsim::render::{render, Maps, RenderOptions, Rendered};
use texsim::report::compare;
use texsim::scene::texture::bricks_height;
use texsim::scene::{self, Camera, FrameKind, Light, MainDirection, Material, Mesh, Scene};

const BUMP_STAGES: [StageKind; 5] = [
    StageKind::Normal,
    StageKind::BumpFetch,
    StageKind::Frame,
    StageKind::Perturb,
    StageKind::Phong,
];

fn small(name: &str, w: u32, h: u32) -> Scene {
    let mut s = scene::builtin(name).expect("builtin scene");
    s.width = w;
    s.height = h;
    s
}

fn hw_with(kind: FrameKind) -> HwConfig {
    let mut hw = HwConfig::texram16();
    hw.shading.frame.frame_kind = kind;
    hw
}

fn go(s: &Scene, hw: &HwConfig) -> Rendered {
    let maps = Maps::new(s, hw.trilinear.texel_bits);
    render(s, &maps, hw, &RenderOptions::default()).expect("render")
}

fn stage(r: &Rendered, k: StageKind) -> &texsim::render::StageStats {
    &r.stats.stages[k.index()]
}

const FRAMES: [FrameKind; 3] = [FrameKind::Natural, FrameKind::Unit, FrameKind::Main];

/// texram16 is 16 bits throughout the shading units: measured on `bumps` at 320x240 the
/// fixed image is within 1 LSB (8-bit) of the float twin on every pixel; max 16-bit error
/// natural 142, unit 96, main 100 LSB, RMSE16 8.9 / 7.3 / 7.3 (specular highlights with
/// shininess 24 amplify the ~1 ulp s1.14 normal error; the natural frame adds the u8.8 length
/// rounding). Asserted with ~2.5x margin for other tessellations of the same error sources:
/// 8-bit max <= 2, >= 99.5% within 1 LSB, 16-bit max <= 400, RMSE16 <= 16, and not identical
/// (the fixed path must really run).
#[test]
fn each_frame_fixed_vs_float_error_is_bounded() {
    let s = small("bumps", 320, 240);
    for kind in FRAMES {
        let r = go(&s, &hw_with(kind));
        let e8 = r.stats.error_8bit.clone().expect("metrics");
        let e16 = r.stats.error_16bit.clone().expect("metrics");
        eprintln!(
            "{kind:?}: max8 {} within1 {:.3}% max16 {} rmse16 {:.3} fallback {} zero {} sat {}",
            e8.max_abs_lsb,
            e8.pct_within_1lsb,
            e16.max_abs_lsb,
            e16.rmse_lsb,
            r.stats.bump.frame_fallback,
            r.stats.bump.zero_normal,
            r.stats.stages.iter().map(|s| s.saturated).sum::<u64>()
        );
        assert!(e8.max_abs_lsb <= 2, "{kind:?} {e8:?}");
        assert!(e8.pct_within_1lsb >= 99.5, "{kind:?} {e8:?}");
        assert!(e16.max_abs_lsb <= 400, "{kind:?} {e16:?}");
        assert!(e16.rmse_lsb <= 16.0, "{kind:?} {e16:?}");
        assert!(
            e16.max_abs_lsb > 0,
            "{kind:?}: fixed path identical to float"
        );
        assert_eq!(r.stats.bump.nonfinite, 0);
        assert_eq!(r.stats.bump.ref_nonfinite, 0);
        // The image is not flat shading: the bumps make neighbouring pixels differ.
        let covered = r.stats.covered_pixels;
        assert!(covered > 20_000, "{covered}");
        for k in BUMP_STAGES {
            assert_eq!(stage(&r, k).invocations, covered, "{k:?}");
        }
        for k in [StageKind::Color, StageKind::Modulate] {
            assert_eq!(stage(&r, k).invocations, 0, "{k:?}");
        }
    }
}

/// Per-frame cycles of the `normal`, `frame` and `perturb` stages equal invocations x the unit
/// costs (an independent sum from the hw_model cost functions), so natural > unit > main in
/// the interpolator and main > natural > unit in the frame unit; the perturbation costs the
/// same in every frame (the natural frame's length multiplies are charged once, in its frame
/// cost). The main frame interpolates `m` (3 scalars) only on the objects with `m = p_u` or
/// `p_v`: their pixel count comes from a second render in which the constant-`m` object has no
/// bump map (same geometry, so the same visibility).
#[test]
fn per_frame_costs_follow_the_units() {
    let s = small("bumps", 160, 120);
    let mut normal = Vec::new();
    let mut frame = Vec::new();
    let mut perturb = Vec::new();
    for kind in FRAMES {
        let hw = hw_with(kind);
        let r = go(&s, &hw);
        let units = ShadingUnits::new(&hw.shading);
        let g = hw.timing.gate_levels_per_cycle;
        let ic = u64::from(interpolate_cost(&hw.interp, g).cycles);
        // Every pixel interpolates n (3), the eye vector (3) and one point light (3).
        let inv = stage(&r, StageKind::Normal).invocations;
        let base = 9 * ic * inv;
        let exp_normal = match kind {
            FrameKind::Natural => base + 8 * ic * inv,
            FrameKind::Unit => base + 6 * ic * inv,
            FrameKind::Main => {
                let mut no_const = s.clone();
                for m in &mut no_const.materials {
                    if matches!(m.main_direction, MainDirection::Constant(_)) {
                        m.bump = None;
                    }
                }
                let r2 = go(&no_const, &hw);
                assert_eq!(r2.stats.covered_pixels, r.stats.covered_pixels);
                let interpolated_m = stage(&r2, StageKind::Normal).invocations;
                assert!(
                    interpolated_m > 0 && interpolated_m < inv,
                    "{interpolated_m}"
                );
                base + 3 * ic * interpolated_m
            }
        };
        let exp_frame = u64::from(frame_cost(kind, &units, g).cycles) * inv;
        assert_eq!(
            stage(&r, StageKind::Normal).issue_cycles,
            exp_normal,
            "{kind:?}"
        );
        assert_eq!(
            stage(&r, StageKind::Frame).issue_cycles,
            exp_frame,
            "{kind:?}"
        );
        let nz = normalize_cost(&hw.shading.vector, rsqrt_cost(&hw.shading.rsqrt, g), g);
        let pert = u64::from(madd_cost(&hw.shading.vector, g).plus(nz).cycles) * inv;
        assert_eq!(stage(&r, StageKind::Perturb).issue_cycles, pert, "{kind:?}");
        let len = u64::from(hw_model::frame::len_datapath(&hw.shading).latency(g));
        let frame_nz = u64::from(nz.times(3).cycles);
        match kind {
            FrameKind::Natural => assert_eq!(exp_frame, (frame_nz + len) * inv),
            FrameKind::Unit => assert_eq!(exp_frame, frame_nz * inv),
            FrameKind::Main => assert!(exp_frame > frame_nz * inv),
        }
        let fetch = u64::from(
            lod_cost(&hw.lod, g)
                .plus(trilinear_cost(&hw.trilinear, 2, g))
                .cycles,
        ) * inv;
        assert_eq!(stage(&r, StageKind::BumpFetch).issue_cycles, fetch);
        assert_eq!(stage(&r, StageKind::BumpFetch).texels, 8 * inv);
        // Two lights (directional + point): two Blinn-Phong, eye + point-light normalize,
        // three colour multiply-adds (ambient + one per light).
        let phong = u64::from(
            blinn_phong_cost(&units, g).times(2).cycles
                + nz.times(2).cycles
                + 3 * hw_model::blinn_phong::mac_datapath(&hw.shading).latency(g),
        ) * inv;
        assert_eq!(stage(&r, StageKind::Phong).issue_cycles, phong);
        normal.push(stage(&r, StageKind::Normal).issue_cycles);
        frame.push(stage(&r, StageKind::Frame).issue_cycles / inv);
        perturb.push(stage(&r, StageKind::Perturb).issue_cycles / inv);
    }
    eprintln!("normal cycles {normal:?} frame cycles/px {frame:?} perturb cycles/px {perturb:?}");
    assert!(normal[0] > normal[1] && normal[1] > normal[2], "{normal:?}");
    assert!(frame[2] > frame[0] && frame[0] > frame[1], "{frame:?}");
    assert!(
        perturb[0] == perturb[1] && perturb[1] == perturb[2],
        "{perturb:?}"
    );
}

#[test]
fn scenes_without_bumps_run_no_bump_stage() {
    for name in ["w1-plane", "sphere"] {
        let s = small(name, 96, 72);
        let r = go(&s, &HwConfig::texram16());
        for k in BUMP_STAGES {
            let st = stage(&r, k);
            assert_eq!(
                (st.invocations, st.issue_cycles, st.ops, st.texels),
                (0, 0, 0, 0),
                "{name} {k:?}"
            );
        }
        assert_eq!(r.stats.bump.frame, "");
        assert_eq!(r.stats.bump.offset_clamped, 0);
    }
}

#[test]
fn bumps_is_deterministic_across_thread_counts() {
    let s = small("bumps", 200, 150);
    let hw = hw_with(FrameKind::Natural);
    let run = |n: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .expect("pool")
            .install(|| go(&s, &hw))
    };
    let (a, b) = (run(1), run(3));
    assert_eq!(a.hw_image, b.hw_image);
    assert_eq!(a.ref_image, b.ref_image);
    for (x, y) in a.stats.stages.iter().zip(&b.stats.stages) {
        assert_eq!(
            (x.invocations, x.saturated, x.issue_cycles),
            (y.invocations, y.saturated, y.issue_cycles)
        );
    }
    assert_eq!(a.stats.bump.frame_fallback, b.stats.bump.frame_fallback);
}

/// The fluted column: OBJ + 16-bit height PNG, as a TOML scene (no `frame` of its own, so the
/// hardware's `frame_kind` selects each frame) and as the bare OBJ whose MTL names the height
/// map (`map_Bump -bm 3`).
#[test]
fn real_mesh_with_height_png_renders_in_every_frame() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/bump_column.toml");
    let mut s = scene::load(&path).expect("toml scene");
    s.width = 160;
    s.height = 192;
    assert_eq!(s.materials[0].frame, None);
    for kind in FRAMES {
        let r = go(&s, &hw_with(kind));
        let e8 = r.stats.error_8bit.clone().expect("metrics");
        assert!(
            e8.max_abs_lsb <= 2 && e8.pct_within_1lsb >= 99.5,
            "{kind:?} {e8:?}"
        );
        assert!(stage(&r, StageKind::Phong).invocations > 5_000);
        assert_eq!(r.stats.bump.ref_nonfinite, 0);
        assert_eq!(
            r.stats.bump.frame,
            match kind {
                FrameKind::Natural => "natural",
                FrameKind::Unit => "unit",
                FrameKind::Main => "main",
            }
        );
    }
    let obj = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/bump_column.obj");
    let mut o = scene::load(&obj).expect("obj scene");
    o.width = 128;
    o.height = 96;
    assert!(o.materials[0].bump.is_some());
    assert_eq!(o.materials[0].bump_scale, 3.0);
    let r = go(&o, &HwConfig::texram16());
    assert!(stage(&r, StageKind::Phong).invocations > 1_000);
    assert_eq!(stage(&r, StageKind::Color).invocations, 0);
}

/// A flat grid in y = 0 over `[-1.5, 1.5]^2`, normals `+y`, `p_u = +x`, `p_v = -z` (UVs 0..2;
/// `(p_u, p_v, n)` right-handed), or with `u` running the other way (mirrored).
fn flat_grid(mirrored: bool) -> Mesh {
    let n = 8u32;
    let mut m = Mesh {
        name: "grid".into(),
        ..Mesh::default()
    };
    for i in 0..=n {
        for j in 0..=n {
            let (a, b) = (j as f32 / n as f32, i as f32 / n as f32);
            m.positions.push([-1.5 + 3.0 * a, 0.0, 1.5 - 3.0 * b]);
            m.normals.push([0.0, 1.0, 0.0]);
            let u = if mirrored { 2.0 * (1.0 - a) } else { 2.0 * a };
            m.uvs.push([u, 2.0 * b]);
        }
    }
    for i in 0..n {
        for j in 0..n {
            let a = i * (n + 1) + j;
            m.indices.push([a, a + 1, a + n + 2]);
            m.indices.push([a, a + n + 2, a + n + 1]);
        }
    }
    m
}

fn grid_scene(mirrored: bool, frame: FrameKind, main: MainDirection, scale: f32) -> Scene {
    Scene {
        name: "grid".into(),
        width: 128,
        height: 96,
        camera: Camera {
            eye: [0.3, 2.6, 1.4],
            target: [0.0, 0.0, 0.0],
            up: [0.0, 1.0, 0.0],
            fov_y_deg: 60.0,
            near: 0.1,
            far: 20.0,
            view_override: None,
        },
        lights: vec![
            Light::Directional {
                direction: [-0.8, -0.45, 0.4],
                color: [0.9; 3],
            },
            Light::Point {
                position: [0.5, 1.0, -0.5],
                color: [0.3; 3],
            },
        ],
        ambient: [0.1; 3],
        background: [0.0, 0.0, 0.0, 1.0],
        meshes: vec![flat_grid(mirrored)],
        materials: vec![Material {
            name: "bump".into(),
            kd: [0.7, 0.6, 0.5],
            bump: Some(0),
            bump_scale: scale,
            frame: Some(frame),
            main_direction: main,
            ks: [0.4; 3],
            shininess: 16,
            ..Material::default()
        }],
        textures: vec![bricks_height(64)],
        hw: None,
        warnings: Vec::new(),
    }
}

/// One offset map gives the same bumps in every frame (Schilling 1997, frame 3 with
/// `m = p_u`, `m = p_v` or a constant `m`, against frame 2): on a flat grid, right-handed and
/// mirrored, the fixed and the float images of the main frame with each main direction are
/// within 1 LSB (8-bit) of the unit frame's, while the bumps themselves change the image by far
/// more (so a frame that turned them would fail).
#[test]
fn main_frame_shades_like_the_unit_frame_for_every_main_direction() {
    let hw = HwConfig::texram16();
    for mirrored in [false, true] {
        let unit = go(
            &grid_scene(mirrored, FrameKind::Unit, MainDirection::Pv, 3.0),
            &hw,
        );
        let flat = go(
            &grid_scene(mirrored, FrameKind::Unit, MainDirection::Pv, 0.0),
            &hw,
        );
        assert!(unit.stats.covered_pixels > 5_000);
        let bumps = compare(&unit.hw_image, &flat.hw_image, 8, None);
        assert!(bumps.max_abs_lsb > 40, "bumps too weak: {bumps:?}");
        let unit_ref = unit.ref_image.as_ref().expect("reference");
        for main in [
            MainDirection::Pu,
            MainDirection::Pv,
            MainDirection::Constant([0.0, 0.0, -1.0]),
        ] {
            let r = go(&grid_scene(mirrored, FrameKind::Main, main, 3.0), &hw);
            assert_eq!(r.stats.bump.frame_fallback, 0);
            let e_hw = compare(&r.hw_image, &unit.hw_image, 8, None);
            let e_ref = compare(r.ref_image.as_ref().expect("reference"), unit_ref, 8, None);
            eprintln!(
                "mirrored {mirrored} {main:?}: hw max8 {} rmse8 {:.4}, ref max8 {} (bumps: max8 {})",
                e_hw.max_abs_lsb, e_hw.rmse_lsb, e_ref.max_abs_lsb, bumps.max_abs_lsb
            );
            assert!(
                e_hw.max_abs_lsb <= 1,
                "mirrored {mirrored} {main:?}: {e_hw:?}"
            );
            assert!(
                e_ref.max_abs_lsb <= 1,
                "mirrored {mirrored} {main:?}: {e_ref:?}"
            );
        }
    }
}

/// 8-bit shading colours (`shade_color_bits = 8`) are unorm end to end: white light straight
/// onto a white diffuse grid is 255 in the fixed image (a `2^C` product scale gives 254), and
/// on `bumps` the fixed image has no systematic bias against the float twin (mean signed
/// error over the covered pixels below 0.1 LSB: measured -0.003; the `2^C` scale gave -0.35).
#[test]
fn eight_bit_shading_is_unbiased() {
    let mut hw = HwConfig::texram16();
    hw.shading.shade.shade_color_bits = 8;
    let mut s = grid_scene(false, FrameKind::Main, MainDirection::Pv, 0.0);
    s.lights = vec![Light::Directional {
        direction: [0.0, -1.0, 0.0],
        color: [1.0; 3],
    }];
    s.ambient = [0.0; 3];
    s.materials[0].kd = [1.0; 3];
    s.materials[0].ks = [0.0; 3];
    let r = go(&s, &hw);
    let white: Vec<u32> = r
        .hw_image
        .px
        .iter()
        .zip(&r.mask)
        .filter(|(_, &m)| m)
        .flat_map(|(p, _)| p[..3].iter().map(|&c| texsim::report::quantize(c, 8)))
        .collect();
    assert!(white.len() > 10_000);
    assert!(white.iter().all(|&c| c == 255), "{:?}", &white[..12]);
    let b = small("bumps", 240, 180);
    let r = go(&b, &hw);
    let refi = r.ref_image.as_ref().expect("reference");
    let (mut sum, mut n) = (0i64, 0i64);
    for ((h, f), &m) in r.hw_image.px.iter().zip(&refi.px).zip(&r.mask) {
        if m {
            for ch in 0..3 {
                let q = |x: u16| i64::from(texsim::report::quantize(x, 8));
                sum += q(h[ch]) - q(f[ch]);
                n += 1;
            }
        }
    }
    let bias = sum as f64 / n as f64;
    eprintln!("bumps at shade_color_bits = 8: mean signed error {bias:.4} LSB over {n} channels");
    assert!(n > 50_000);
    assert!(bias.abs() < 0.1, "mean signed error {bias} LSB");
}
