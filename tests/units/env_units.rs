//! The environment-map units (`hw_model::{reflect, cube_face, env_lod}`) against their float
//! twins (`texsim::shading::env`): the bounds of their doc comments over seeded random inputs
//! (10^7 reflections, 4 M directions), exhaustively over every direction of 1.6 components,
//! and the hard cases (edges, corners, axes, the zero vector, normal parallel to the view,
//! grazing reflections, zero roughness, 1x1 faces).

use crate::rng_common::Rng;
use glam::DVec3;
use hw_model::config::HwConfig;
use hw_model::cube_face::{cube_face, project, select_face};
use hw_model::env_config::{EnvConfig, EnvFilter};
use hw_model::env_lod::{env_lod, FaceRoughness};
use hw_model::fixed::SatCounter;
use hw_model::reciprocal::Reciprocal;
use hw_model::reflect::reflect;
use hw_model::vector::VectorConfig;
use texsim::shading::env::{
    cube_face_f, env_lod_f, face_axes_f, project_f, reflect_f, select_face_f, FaceRoughnessF,
};

fn unit_raw(rng: &mut Rng, f: u32) -> [i64; 3] {
    let d = DVec3::new(rng.normal(), rng.normal(), rng.normal()).normalize_or(DVec3::Z);
    let s = f64::from(1u32 << f);
    [d.x, d.y, d.z].map(|c| (c * s).round() as i64)
}

fn deq(r: &[i64; 3], f: u32) -> DVec3 {
    let s = f64::from(1u32 << f);
    DVec3::new(r[0] as f64 / s, r[1] as f64 / s, r[2] as f64 / s)
}

/// 10^7 random unit-vector pairs: each component within 1/2 ulp of 1.R of the exact
/// `2 (n . v) n - v` of the quantized inputs (exact in f64: every term has <= 48 bits).
#[test]
fn reflect_within_half_ulp_of_exact() {
    let vc = VectorConfig::texram16();
    let f = vc.vector_frac_bits;
    for r_bits in [8u32, 15, 20] {
        let cfg = EnvConfig {
            reflect_bits: r_bits,
            ..EnvConfig::texram16()
        };
        let mut rng = Rng(0xe17 + u64::from(r_bits));
        let ulp = f64::from(1u32 << r_bits);
        let mut worst = 0.0f64;
        let cases = if r_bits == 15 { 10_000_000 } else { 1_000_000 };
        let mut sat = SatCounter::default();
        for _ in 0..cases {
            let n = unit_raw(&mut rng, f);
            let v = unit_raw(&mut rng, f);
            let r = reflect(&n, &v, &vc, &cfg, &mut sat);
            let e = reflect_f(deq(&n, f), deq(&v, f));
            for i in 0..3 {
                worst = worst.max((r[i] as f64 - e[i] * ulp).abs());
            }
        }
        assert_eq!(sat.saturated, 0, "R={r_bits}");
        assert!(worst <= 0.5, "R={r_bits}: {worst} ulp");
        println!("reflect R={r_bits}: max error {worst:.3} ulp over {cases} pairs");
    }
}

/// Normal parallel to the view reflects the view; a grazing view (n . v = 0) gives `-v`.
#[test]
fn reflect_hard_cases() {
    let vc = VectorConfig::texram16();
    let cfg = EnvConfig::texram16();
    let one = 1i64 << vc.vector_frac_bits;
    let rs = cfg.reflect_bits - vc.vector_frac_bits;
    let mut sat = SatCounter::default();
    let n = [0, 0, one];
    assert_eq!(reflect(&n, &n, &vc, &cfg, &mut sat), [0, 0, one << rs]);
    let v = [one, 0, 0];
    assert_eq!(reflect(&n, &v, &vc, &cfg, &mut sat), [-one << rs, 0, 0]);
    let mut rng = Rng(77);
    for _ in 0..100_000 {
        let n = unit_raw(&mut rng, vc.vector_frac_bits);
        let r = reflect(&n, &n, &vc, &cfg, &mut sat);
        let e = reflect_f(deq(&n, 14), deq(&n, 14));
        for i in 0..3 {
            assert!((r[i] as f64 / f64::from(1u32 << 15) - e[i]).abs() <= 2f64.powi(-16));
        }
    }
    assert_eq!(sat.saturated, 0);
}

fn check_face(r: &[i64; 3], recip: &Reciprocal, cfg: &EnvConfig, worst: &mut f64) {
    let mut sat = SatCounter::default();
    let c = cube_face(r, recip, cfg, &mut sat);
    let rf = DVec3::new(r[0] as f64, r[1] as f64, r[2] as f64);
    assert_eq!(c.face, select_face_f(rf), "{r:?}");
    let (sc, tc, ma) = face_axes_f(rf, c.face);
    let one = f64::from(1u32 << cfg.face_coord_bits);
    for (got, num) in [(c.s, sc), (c.t, tc)] {
        let exact = (num / ma.abs() + 1.0) * 0.5 * one;
        *worst = worst.max((got as f64 - exact).abs());
    }
}

/// 4 M random directions at three widths: face as the float twin, `s, t` within
/// `1/2 ulp + e_recip / 2` of the exact `(sc / |ma| + 1) / 2`.
#[test]
fn cube_face_within_bound() {
    let hw = HwConfig::texram16();
    let recip = Reciprocal::new(&hw.reciprocal);
    let m = hw.reciprocal.recip_mantissa_bits;
    for (r_bits, c_bits) in [(15u32, 16u32), (10, 8), (20, 24)] {
        let cfg = EnvConfig {
            reflect_bits: r_bits,
            face_coord_bits: c_bits,
            ..EnvConfig::texram16()
        };
        let bound = 0.5 + 2f64.powi(c_bits as i32 - m as i32 - 1) + 1e-9;
        let mut rng = Rng(0xc0be + u64::from(c_bits));
        let mut worst = 0.0;
        for _ in 0..4_000_000 / 3 {
            let r = unit_raw(&mut rng, r_bits);
            check_face(&r, &recip, &cfg, &mut worst);
        }
        assert!(worst <= bound, "R={r_bits} C={c_bits}: {worst} > {bound}");
        println!("cube_face R={r_bits} C={c_bits}: max error {worst:.4} ulp (bound {bound:.4})");
    }
}

/// Every direction with components in 1.6 (129^3 = 2.1 M, under 2^24), except zero.
#[test]
fn cube_face_exhaustive_small() {
    let hw = HwConfig::texram16();
    let recip = Reciprocal::new(&hw.reciprocal);
    let cfg = EnvConfig {
        reflect_bits: 6,
        face_coord_bits: 10,
        ..EnvConfig::texram16()
    };
    let mut worst = 0.0;
    for x in -64i64..=64 {
        for y in -64i64..=64 {
            for z in -64i64..=64 {
                if (x, y, z) != (0, 0, 0) {
                    check_face(&[x, y, z], &recip, &cfg, &mut worst);
                }
            }
        }
    }
    assert!(worst <= 0.5 + 2f64.powi(10 - 25) + 1e-9, "{worst}");
}

/// Edges and corners have exactly one face (ties to the lower axis) and land on its border;
/// axes land on the face centre; the zero vector takes +Z's centre and is counted.
#[test]
fn cube_edges_corners_and_zero() {
    let hw = HwConfig::texram16();
    let recip = Reciprocal::new(&hw.reciprocal);
    let cfg = EnvConfig::texram16();
    let one = 1i64 << cfg.face_coord_bits;
    let a = 1i64 << 14;
    let mut sat = SatCounter::default();
    // +X/+Y edge: +X, s centre (z = 0), t = 0 (-y / x = -1).
    let c = cube_face(&[a, a, 0], &recip, &cfg, &mut sat);
    assert_eq!((c.face, c.s, c.t), (0, one / 2, 0));
    // -Y/-Z edge: -Y wins the tie over -Z; tc = -rz = a, |ma| = a: t = 1.
    let c = cube_face(&[0, -a, -a], &recip, &cfg, &mut sat);
    assert_eq!((c.face, c.s, c.t), (3, one / 2, one));
    // Corners: every corner takes an X face, at a face corner.
    for sx in [-1, 1] {
        for sy in [-1, 1] {
            for sz in [-1, 1] {
                let c = cube_face(&[sx * a, sy * a, sz * a], &recip, &cfg, &mut sat);
                assert_eq!(c.face, u8::from(sx < 0));
                assert!(c.s == 0 || c.s == one, "{c:?}");
                assert!(c.t == 0 || c.t == one, "{c:?}");
            }
        }
    }
    assert_eq!(sat.saturated, 0);
    for (i, face) in [(0usize, 0u8), (1, 2), (2, 4)] {
        for sign in [1i64, -1] {
            let mut r = [0; 3];
            r[i] = sign * a;
            let c = cube_face(&r, &recip, &cfg, &mut sat);
            assert_eq!(c.face, face + u8::from(sign < 0));
            assert_eq!((c.s, c.t), (one / 2, one / 2));
        }
    }
    let c = cube_face(&[0, 0, 0], &recip, &cfg, &mut sat);
    assert_eq!((c.face, c.s, c.t), (4, one / 2, one / 2));
    assert_eq!(sat.saturated, 1);
    let (f, st) = cube_face_f(DVec3::ZERO);
    assert_eq!((f, st), (4, [0.5, 0.5]));
    assert_eq!(select_face(&[5, -5, 5]), 0);
    // A direction just past an edge, projected on the neighbouring face: outside [0, 1],
    // finite, and as the float twin.
    let r = [a, a + 64, 0];
    let p = project(&r, 0, &recip, &cfg, &mut sat);
    let pf = project_f(DVec3::new(a as f64, (a + 64) as f64, 0.0), 0);
    assert!(p[1] < 0);
    assert!((p[1] as f64 / one as f64 - pf[1]).abs() < 2.0 / one as f64);
    // The far side of a face: the limit, counted.
    let before = sat.saturated;
    let p = project(&[-a, 0, 0], 0, &recip, &cfg, &mut sat);
    assert_eq!(p[0].abs(), one << 8);
    assert_eq!(sat.saturated, before + 1);
}

fn st_raw(st: &[[f64; 2]; 3], c: u32) -> [[i64; 2]; 3] {
    st.map(|p| p.map(|x| (x * f64::from(1u32 << c)).round() as i64))
}

/// The ellipse's minor length in float: the longest of the three candidates besides the major.
fn minor_len(st: &[[f64; 2]; 3], r: &FaceRoughnessF) -> f64 {
    let dx = [st[1][0] - st[0][0], st[1][1] - st[0][1]];
    let dy = [st[2][0] - st[0][0], st[2][1] - st[0][1]];
    let mut l: Vec<f64> = [dx, dy, r.axes[0], r.axes[1]]
        .iter()
        .map(|d| d[0].hypot(d[1]))
        .collect();
    l.sort_by(f64::total_cmp);
    l[2]
}

/// The environment LOD against its float twin on the same quantized inputs, every filter:
/// LOD at most 3 LSB below the float one and never more than 1 above, plus for the
/// ellipse the effect of its minor's one rounding (`-2^F log2(1 - 2^-(C+1/2) / |minor|)`); lambda1 and ellipse never go below none.
#[test]
fn env_lod_matches_float_twin() {
    let hw = HwConfig::texram16();
    let cfg = EnvConfig::texram16();
    let c = cfg.face_coord_bits;
    let one = f64::from(1u32 << c);
    let lf = f64::from(1u32 << hw.lod.lod_frac_bits);
    let mut rng = Rng(0x10d);
    let mut worst = (0.0f64, 0.0f64);
    for i in 0..1_000_000u32 {
        let size = 1u32 << rng.below(11);
        let s0 = [rng.range(0.0, 1.0), rng.range(0.0, 1.0)];
        let scale = 2f64.powf(rng.range(-14.0, -1.0));
        let mut st = [s0; 3];
        for p in st.iter_mut().skip(1) {
            *p = [
                s0[0] + rng.range(-1.0, 1.0) * scale,
                s0[1] + rng.range(-1.0, 1.0) * scale,
            ];
        }
        let raw = st_raw(&st, c);
        let stq = raw.map(|p| p.map(|x| x as f64 / one));
        let rs = 2f64.powf(rng.range(-14.0, -1.0));
        let axes_f = [
            [rng.range(-1.0, 1.0) * rs, rng.range(-1.0, 1.0) * rs],
            [rng.range(-1.0, 1.0) * rs, rng.range(-1.0, 1.0) * rs],
        ];
        let fr = FaceRoughness {
            axes: axes_f.map(|a| a.map(|x| (x * one).round() as i64)),
        };
        let frf = FaceRoughnessF {
            axes: fr.axes.map(|a| a.map(|x| x as f64 / one)),
        };
        let probes = 1u32 << (i % 4);
        let mut lods = Vec::new();
        let mut ellipse_slack = 0.0;
        for filter in [EnvFilter::None, EnvFilter::Lambda1, EnvFilter::Ellipse] {
            let mut sat = SatCounter::default();
            let fp = env_lod(
                &raw, size, &fr, filter, probes, true, &cfg, &hw.lod, &mut sat,
            );
            let ff = env_lod_f(&stq, size, &frf, filter, probes, true);
            assert!(fp.lod.abs() < 64 << 16);
            if ff.lod > -31.0 {
                let d = fp.lod as f64 - ff.lod * lf;
                // The ellipse's minor is rounded once per component (1/2 ulp of 0.C each).
                let slack = if filter == EnvFilter::Ellipse {
                    {
                        let m = minor_len(&stq, &frf) * one;
                        if m > 0.75 {
                            -lf * (1.0 - 0.71 / m).log2()
                        } else {
                            f64::INFINITY
                        }
                    }
                } else {
                    0.0
                };
                ellipse_slack = slack;
                assert!(
                    (-3.0 - slack..=1.0 + slack).contains(&d),
                    "{filter:?} {d} {fp:?} {ff:?}"
                );
                worst = (worst.0.min(d), worst.1.max(d));
            }
            lods.push(fp.lod);
        }
        assert!(lods[1] >= lods[0], "{lods:?}");
        assert!(
            lods[2] as f64 >= lods[0] as f64 - 3.0 - ellipse_slack,
            "{lods:?}"
        );
    }
    println!(
        "env_lod vs float: LOD error in [{:.3}, {:.3}] LSB",
        worst.0, worst.1
    );
}

/// A zero-roughness texel gives every filter the derivative-only footprint; a 1x1 face gives
/// finite LODs; a rough texel with tiny derivatives raises the LOD (lambda1) and steers the
/// probes along the ellipse (ellipse).
#[test]
fn env_lod_hard_cases() {
    let hw = HwConfig::texram16();
    let cfg = EnvConfig::texram16();
    let c = cfg.face_coord_bits;
    let st = [
        [1 << 15, 1 << 15],
        [(1 << 15) + 4, 1 << 15],
        [1 << 15, (1 << 15) + 4],
    ];
    let zero = FaceRoughness::default();
    let mut sat = SatCounter::default();
    for size in [1u32, 64, 1024] {
        let base = env_lod(
            &st,
            size,
            &zero,
            EnvFilter::None,
            4,
            true,
            &cfg,
            &hw.lod,
            &mut sat,
        );
        for filter in [EnvFilter::Lambda1, EnvFilter::Ellipse] {
            let fp = env_lod(&st, size, &zero, filter, 4, true, &cfg, &hw.lod, &mut sat);
            assert_eq!(fp.lod, base.lod, "{filter:?} {size}");
        }
    }
    let rough = FaceRoughness {
        axes: [[1 << (c - 5), 0], [0, 1 << (c - 9)]],
    };
    let none = env_lod(
        &st,
        256,
        &rough,
        EnvFilter::None,
        8,
        true,
        &cfg,
        &hw.lod,
        &mut sat,
    );
    let l1 = env_lod(
        &st,
        256,
        &rough,
        EnvFilter::Lambda1,
        8,
        true,
        &cfg,
        &hw.lod,
        &mut sat,
    );
    let el = env_lod(
        &st,
        256,
        &rough,
        EnvFilter::Ellipse,
        8,
        true,
        &cfg,
        &hw.lod,
        &mut sat,
    );
    // The longer axis: 256 / 32 = 8 texels: lambda1 LOD = 3.
    assert_eq!(l1.lod, 3 << 16);
    assert!(none.lod < 0);
    // The ellipse: 8 texels along s, 0.5 across -> 8 probes along s, LOD log2(max(1, 0.5)) = 0.
    assert_eq!(el.probes, 8);
    assert_eq!(el.axis, [1 << (c - 5), 0]);
    assert_eq!(el.lod, 0);
}

/// The widths are validated (naming the field) and sweepable by their leaf names.
#[test]
fn env_widths_validated_and_sweepable() {
    let hw = HwConfig::texram16();
    let mut bad = hw.clone();
    bad.env.reflect_bits = 3;
    let e = bad.validate().unwrap_err();
    assert_eq!(e.field, "env.reflect_bits");
    bad.env.reflect_bits = 15;
    bad.env.face_coord_bits = 30;
    assert_eq!(bad.validate().unwrap_err().field, "env.face_coord_bits");
    let c = texsim::hwconfig::set_field(&hw, "reflect_bits", "10").expect("reflect_bits");
    assert_eq!(c.env.reflect_bits, 10);
    let c = texsim::hwconfig::set_field(&hw, "env_filter", "ellipse").expect("env_filter");
    assert_eq!(c.env.env_filter, EnvFilter::Ellipse);
    assert!(texsim::hwconfig::set_field(&hw, "face_coord_bits", "2").is_err());
    // Wider reflection and face words cost delay and area.
    let area = |h: &HwConfig, name: &str| {
        hw_model::datapath::units(h)
            .into_iter()
            .find(|r| r.name == name)
            .map(|r| (r.delay, r.area))
            .expect("unit")
    };
    let mut last = (0, 0);
    for b in [6u32, 10, 15, 20] {
        let h = texsim::hwconfig::set_field(&hw, "reflect_bits", &b.to_string()).expect("set");
        let now = area(&h, "cube_face");
        assert!(now.1 > last.1 && now.0 >= last.0, "{b}: {now:?}");
        last = now;
    }
}
