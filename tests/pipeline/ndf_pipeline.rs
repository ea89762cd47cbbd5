//! NDF materials in the pipeline: the built-in scenes render in fixed point and float, the
//! fixed image tracks the float one, `ndf-fetch` makes 3 lookups (4 with the normalization
//! map) in the costs and in the timing model's events, and `exact` runs `ndf-shade` in float.

use hw_model::ndf::NdfNorm;
use hw_model::HwConfig;
use texsim::pipeline::{Impl, StageKind};
use texsim::render::{render, Maps, RenderOptions, Rendered};
use texsim::scene::builtin;

fn run(name: &str, hw: &HwConfig, timing: bool) -> Rendered {
    let s = builtin(name).expect("scene");
    let maps = Maps::new(&s, hw.trilinear.texel_bits);
    let opts = RenderOptions {
        timing,
        ..RenderOptions::default()
    };
    render(&s, &maps, hw, &opts).expect("render")
}

fn stage(r: &Rendered, k: StageKind) -> &texsim::render::StageStats {
    r.stats
        .stages
        .iter()
        .find(|s| s.stage == k)
        .expect("stage present")
}

#[test]
fn scenes_render_and_fixed_tracks_float() {
    let hw = HwConfig::texram16();
    // Foil: the sparkles of 2x2-texel facets at shininess 256 have edges one texture-coordinate
    // LSB wide, so the fixed barycentrics alone move a few pixels by up to 3 LSB
    // (`texsim render --scene foil --isolate bary`).
    for (name, bound) in [("ripple-sphere", 2), ("lod-pair", 2), ("foil", 4)] {
        let r = run(name, &hw, false);
        let fetch = stage(&r, StageKind::NdfFetch);
        let shade = stage(&r, StageKind::NdfShade);
        assert!(fetch.invocations > 1000, "{name}");
        assert_eq!(fetch.invocations, shade.invocations);
        assert_eq!(
            fetch.texels,
            8 * 3 * fetch.invocations,
            "{name}: 3 trilinear lookups"
        );
        let e = r.stats.error_8bit.as_ref().expect("reference");
        println!(
            "{name}: max {} mean {:.4} (8-bit LSB)",
            e.max_abs_lsb, e.mean_abs_lsb
        );
        assert!(e.max_abs_lsb <= bound, "{name}: {e:?}");
        // Only lod-pair has non-NDF (Blinn-Phong) meshes: its per-vertex-normal row.
        let phong = stage(&r, StageKind::Phong).invocations;
        assert_eq!(phong > 0, name == "lod-pair", "{name}: phong {phong}");
    }
}

#[test]
fn map_normalization_adds_a_lookup_in_costs_and_timing() {
    let mut hw = HwConfig::texram16();
    hw.ndf.ndf_norm = NdfNorm::Map;
    let r = run("lod-pair", &hw, true);
    let fetch = stage(&r, StageKind::NdfFetch);
    assert_eq!(fetch.texels, 8 * 4 * fetch.invocations);
    let ev = r.events.as_ref().expect("events");
    let k = StageKind::NdfFetch.index() as u8;
    let lookups: std::collections::BTreeSet<u8> = ev
        .footprints
        .iter()
        .filter(|f| f.stage == k)
        .map(|f| f.lookup)
        .collect();
    assert_eq!(lookups.into_iter().collect::<Vec<_>>(), vec![0, 1, 2, 3]);
    let e = r.stats.error_8bit.as_ref().expect("reference");
    assert!(e.max_abs_lsb <= 2, "{e:?}");
    let partial = run("lod-pair", &HwConfig::texram16(), true);
    let t4 = texsim::timing::simulate(ev, &hw, "lod-pair").total_cycles;
    let t3 = texsim::timing::simulate(partial.events.as_ref().expect("events"), &hw, "lod-pair")
        .total_cycles;
    assert!(t4 > t3, "{t4} <= {t3}");
}

#[test]
fn exact_runs_ndf_shade_in_float() {
    let mut hw = HwConfig::texram16();
    hw.ndf.ndf_norm = NdfNorm::Exact;
    let mut s = builtin("lod-pair").expect("scene");
    s.width = 96;
    s.height = 64;
    let maps = Maps::new(&s, 16);
    let r = render(&s, &maps, &hw, &RenderOptions::default()).expect("render");
    assert_eq!(stage(&r, StageKind::NdfShade).imp, Impl::Float);
    assert_eq!(stage(&r, StageKind::NdfFetch).imp, Impl::Fixed);
    // Said in the result (the library prints nothing), naming the field.
    assert!(
        r.stats.warnings.iter().any(|w| w.contains("ndf.ndf_norm")),
        "{:?}",
        r.stats.warnings
    );
}

#[test]
fn moment_bits_sweep_rebuilds_maps() {
    let mut hw = HwConfig::texram16();
    hw.ndf.moment_bits = 8;
    let r8 = run("foil", &hw, false);
    let r16 = run("foil", &HwConfig::texram16(), false);
    let e8 = r8.stats.error_8bit.as_ref().expect("ref").mean_abs_lsb;
    let e16 = r16.stats.error_8bit.as_ref().expect("ref").mean_abs_lsb;
    println!("foil mean error: 8-bit moments {e8:.4}, 16-bit {e16:.4}");
    assert!(e8 > e16);
}

/// `truth` renders the supersampled ground truth and separates the model error (float vs
/// truth) from the quantization error (fixed vs float); the model error dominates.
#[test]
fn truth_separates_model_and_quantization_error() {
    let s = builtin("ripple-sphere").expect("scene");
    let hw = HwConfig::texram16();
    let maps = Maps::new(&s, 16);
    let opts = RenderOptions {
        truth: 16,
        ..RenderOptions::default()
    };
    let r = render(&s, &maps, &hw, &opts).expect("render");
    assert!(r.truth_image.is_some());
    let me = r.stats.model_error.as_ref().expect("model error");
    let qe = r
        .stats
        .quantization_error
        .as_ref()
        .expect("quantization error");
    println!(
        "model {:.4} quantization {:.4}",
        me.mean_abs_lsb, qe.mean_abs_lsb
    );
    assert!(me.mean_abs_lsb > qe.mean_abs_lsb);
    let plain = render(&s, &maps, &hw, &RenderOptions::default()).expect("render");
    assert!(plain.stats.model_error.is_none() && plain.truth_image.is_none());
}

/// `--truth N` sets the truth's sub-samples: N x N per pixel at least (more where the footprint
/// crosses more texels). The truth changes with N and converges: against N = 32, N = 16 is
/// closer than N = 4, which is closer than N = 1.
#[test]
fn truth_samples_matter_and_converge() {
    let mut s = builtin("ripple-sphere").expect("scene");
    s.width = 160;
    s.height = 100;
    let hw = HwConfig::texram16();
    let maps = Maps::new(&s, 16);
    let truth = |n: u32| {
        let opts = RenderOptions {
            truth: n,
            ..RenderOptions::default()
        };
        let r = render(&s, &maps, &hw, &opts).expect("render");
        r.truth_image.expect("truth")
    };
    let t32 = truth(32);
    let diff = |a: &texsim::report::Image| -> f64 {
        let mut d = 0.0;
        for (p, q) in a.px.iter().zip(&t32.px) {
            for ch in 0..3 {
                d += (f64::from(p[ch]) - f64::from(q[ch])).abs();
            }
        }
        d / 257.0 / (3.0 * a.px.len() as f64)
    };
    let e: Vec<f64> = [1, 4, 16].map(|n| diff(&truth(n))).to_vec();
    println!(
        "truth vs N = 32, mean 8-bit LSB: N = 1 {:.4}, 4 {:.4}, 16 {:.4}",
        e[0], e[1], e[2]
    );
    assert!(e[0] > e[1] && e[1] > e[2] && e[2] > 0.0, "{e:?}");
}

/// The truth of a footprint of exactly 4 x 4 texels of a checker of two normals is the mean of
/// the two lobes for any N <= 4 (at least one sample per texel: 4 per axis), and the same lobe
/// for a uniform map at any N; sub-texel footprints are widened to one texel.
#[test]
fn ground_truth_samples_every_texel() {
    use glam::DVec3;
    use texsim::shading::ndf::{base_lobe, ground_truth, truth_samples_per_axis};
    let (n1, n2) = (
        DVec3::new(0.3, 0.0, 1.0).normalize(),
        DVec3::new(-0.2, 0.1, 1.0).normalize(),
    );
    let normals: Vec<DVec3> = (0..64)
        .map(|i| if (i % 8 + i / 8) % 2 == 0 { n1 } else { n2 })
        .collect();
    let h = DVec3::new(0.1, 0.0, 1.0).normalize();
    let s = 64.0;
    let want = 0.5 * (base_lobe(h, n1, s) + base_lobe(h, n2, s));
    for n in [1, 2, 3, 4] {
        assert_eq!(truth_samples_per_axis(4.0, n), 4);
        let got = ground_truth(
            &normals,
            8,
            8,
            s,
            [4.0, 4.0],
            [[4.0, 0.0], [0.0, 4.0]],
            n,
            h,
        );
        assert!(
            (got - want).abs() < 1e-12 * want,
            "N = {n}: {got} vs {want}"
        );
    }
    let uniform = vec![n1; 64];
    for n in [1, 5, 16] {
        let got = ground_truth(
            &uniform,
            8,
            8,
            s,
            [2.3, 5.1],
            [[0.01, 0.0], [0.0, 7.0]],
            n,
            h,
        );
        assert!((got - base_lobe(h, n1, s)).abs() < 1e-12 * got);
    }
    // A sub-texel footprint at a texel edge is widened to one texel: both lobes, half each.
    let edge = ground_truth(
        &normals,
        8,
        8,
        s,
        [4.0, 4.5],
        [[0.1, 0.0], [0.0, 0.1]],
        2,
        h,
    );
    assert!((edge - want).abs() < 1e-12 * want, "{edge} vs {want}");
    // Bad input: a map of the wrong size, non-finite axes.
    assert_eq!(
        ground_truth(&normals, 9, 8, s, [0.0; 2], [[1.0, 0.0], [0.0, 1.0]], 4, h),
        0.0
    );
    let nan = ground_truth(
        &normals,
        8,
        8,
        s,
        [4.0, 4.0],
        [[f64::NAN, 0.0], [0.0, f64::INFINITY]],
        4,
        h,
    );
    assert!(nan.is_finite());
}

/// A TOML material with `ndf = true` on a height map (the bump path's offsets give the
/// normals) renders through the NDF stages; `ndf = "yes"` is an error naming the field.
#[test]
fn toml_ndf_material_from_a_height_map() {
    let d = crate::tmp_common::TmpDir::new("toml");
    let body = |ndf: &str| {
        format!(
            "[output]\nwidth = 96\nheight = 64\n\n[[textures]]\nname = \"bricks\"\nprocedural = \"bricks-height\"\nsize = 64\n\n[[materials]]\nname = \"m\"\nbump = \"bricks\"\nks = [0.5, 0.5, 0.5]\nshininess = 48\nndf = {ndf}\n\n[[meshes]]\nshape = \"sphere\"\nmaterial = \"m\"\n\n[[lights]]\nkind = \"directional\"\ndirection = [-0.3, -0.5, -1.0]\ncolor = [1.0, 1.0, 1.0]\n"
        )
    };
    let p = d.join("ok.toml");
    std::fs::write(&p, body("true")).expect("write");
    let s = texsim::scene::load(&p).expect("load");
    assert!(s.materials[0].ndf);
    let hw = HwConfig::texram16();
    let maps = Maps::new(&s, 16);
    let r = render(&s, &maps, &hw, &RenderOptions::default()).expect("render");
    assert!(stage(&r, StageKind::NdfShade).invocations > 100);
    let e = r.stats.error_8bit.as_ref().expect("reference");
    assert!(e.max_abs_lsb <= 2, "{e:?}");
    let bad = d.join("bad.toml");
    std::fs::write(&bad, body("\"yes\"")).expect("write");
    let err = texsim::scene::load(&bad)
        .expect_err("string for bool")
        .to_string();
    assert!(err.contains("ndf"), "{err}");
}

/// The NDF scenes (hardware, reference and truth) are bit-identical on 1 and 2 threads.
#[test]
fn deterministic_across_thread_counts() {
    let mut s = builtin("ripple-sphere").expect("scene");
    s.width = 160;
    s.height = 100;
    let mut hw = HwConfig::texram16();
    hw.ndf.ndf_norm = NdfNorm::Map;
    let maps = Maps::new(&s, 16);
    let opts = RenderOptions {
        truth: 16,
        ..RenderOptions::default()
    };
    let go = |n: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .expect("pool");
        pool.install(|| render(&s, &maps, &hw, &opts).expect("render"))
    };
    let (a, b) = (go(1), go(2));
    assert_eq!(a.hw_image.px, b.hw_image.px);
    assert_eq!(
        a.ref_image.as_ref().map(|i| &i.px),
        b.ref_image.as_ref().map(|i| &i.px)
    );
    assert_eq!(
        a.truth_image.as_ref().map(|i| &i.px),
        b.truth_image.as_ref().map(|i| &i.px)
    );
}

/// Hardware files without an `[ndf]` section still load (the defaults); bad widths are errors
/// naming the field; the knobs are sweep fields.
#[test]
fn hw_config_ndf_section() {
    let full = texsim::hwconfig::to_toml(&HwConfig::texram16());
    let start = full.find("[ndf]").expect("ndf section");
    let end = full[start + 5..]
        .find("\n[")
        .map_or(full.len(), |i| start + 5 + i);
    let old = format!("{}{}", &full[..start], &full[end..]);
    assert!(!old.contains("moment_bits"));
    let c: HwConfig = toml::from_str(&old).expect("old file parses");
    assert_eq!(c.ndf, hw_model::ndf::NdfConfig::texram16());
    let e = texsim::hwconfig::parse("[ndf]\nmoment_bits = 3\n").expect_err("too narrow");
    assert!(e.to_string().contains("ndf.moment_bits"), "{e}");
    let base = HwConfig::texram16();
    let c = texsim::hwconfig::set_field(&base, "ndf_norm", "projected").expect("knob");
    assert_eq!(c.ndf.ndf_norm, NdfNorm::Projected);
    let c = texsim::hwconfig::set_field(&base, "pearson_m", "16").expect("knob");
    assert_eq!(c.ndf.pearson_m, 16);
    assert!(texsim::hwconfig::set_field(&base, "ndf_density", "cauchy").is_err());
}

/// The specular part of one mesh of `lod-pair` rendered alone, moved to the centre of the view
/// (its bounding box centred at the origin): the hardware image minus the same with `ks = 0`
/// (16-bit, per channel), 0 where uncovered; optionally with the NDF map replaced by the flat
/// one.
fn lod_pair_specular(mesh: usize, flat: bool) -> Vec<[i32; 3]> {
    let mut s = builtin("lod-pair").expect("scene");
    let mut m = s.meshes[mesh].clone();
    let mut c = [0.0f32; 3];
    for (k, ck) in c.iter_mut().enumerate() {
        let lo = m
            .positions
            .iter()
            .map(|p| p[k])
            .fold(f32::INFINITY, f32::min);
        let hi = m
            .positions
            .iter()
            .map(|p| p[k])
            .fold(f32::NEG_INFINITY, f32::max);
        *ck = 0.5 * (lo + hi);
    }
    for p in &mut m.positions {
        for k in 0..3 {
            p[k] -= c[k];
        }
    }
    s.meshes = vec![m];
    if flat {
        s.materials[0].bump = Some(1);
    }
    let hw = HwConfig::texram16();
    let go = |s: &texsim::scene::Scene| {
        let maps = Maps::new(s, 16);
        render(s, &maps, &hw, &RenderOptions::default()).expect("render")
    };
    let full = go(&s);
    for mat in &mut s.materials {
        mat.ks = [0.0; 3];
    }
    let diffuse = go(&s);
    full.hw_image
        .px
        .iter()
        .zip(&diffuse.hw_image.px)
        .zip(&full.mask)
        .map(|((a, b), &covered)| {
            [0, 1, 2].map(|ch| {
                if covered {
                    i32::from(a[ch]) - i32::from(b[ch])
                } else {
                    0
                }
            })
        })
        .collect()
}

/// Relative L1 difference of two specular images: `sum |a - b| / sum (a + b)`, in [0, 1].
fn relative_difference(a: &[[i32; 3]], b: &[[i32; 3]]) -> f64 {
    let (mut d, mut t) = (0i64, 0i64);
    for (pa, pb) in a.iter().zip(b) {
        for ch in 0..3 {
            d += i64::from((pa[ch] - pb[ch]).abs());
            t += i64::from(pa[ch] + pb[ch]);
        }
    }
    d as f64 / t.max(1) as f64
}

/// Figure 2 (Olano and North): one wavy object at two polygon counts (12x6 and 64x32). With
/// per-vertex normals of the wavy surface (Phong-interpolated, Blinn-Phong per pixel) the
/// highlight changes with the polygon count (the coarse mesh aliases the waves); with the waves
/// in the NDF map the two meshes' highlights agree. Each mesh is rendered alone at the same
/// place and the specular images of each pair compared. The NDF map carries the waves: the
/// fine mesh with a flat NDF map differs from the wavy one far more than the two meshes do.
#[test]
fn lod_pair_ndf_highlights_agree_across_tessellations() {
    let s = builtin("lod-pair").expect("scene");
    let names: Vec<&str> = s.meshes.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(
        names,
        ["ndf-coarse", "ndf-fine", "phong-coarse", "phong-fine"]
    );
    assert!(s.materials[0].ndf && !s.materials[1].ndf);
    let sp: Vec<_> = (0..4).map(|i| lod_pair_specular(i, false)).collect();
    let ndf = relative_difference(&sp[0], &sp[1]);
    let phong = relative_difference(&sp[2], &sp[3]);
    let waves = relative_difference(&sp[1], &lod_pair_specular(1, true));
    println!(
        "coarse vs fine specular difference: ndf {ndf:.3}, phong {phong:.3}; ndf fine, waves vs flat map {waves:.3}"
    );
    // Measured (texram16): ndf 0.080, phong 0.334, waves vs flat 0.364.
    assert!(3.0 * ndf < phong, "ndf {ndf} phong {phong}");
    assert!(3.0 * ndf < waves, "ndf {ndf} waves vs flat {waves}");
}
