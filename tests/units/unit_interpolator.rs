//! Perspective-correct barycentrics vs exact rationals (i128), interpolation vs exact integer
//! rounding, and both vs the f64 twins.

use crate::rng_common::Rng;
use hw_model::config::{HwConfig, InterpConfig};
use hw_model::fixed::{Format, Overflow, Rounding, SatCounter};
use hw_model::interpolator::{interpolate, perspective_bary, BARY_LIMIT};
use hw_model::reciprocal::{Reciprocal, GUARD_BITS};
use texsim::reference::{interpolate_f64, perspective_bary_f64};

/// Relative error bound of the reciprocal (see `hw_model::reciprocal`), plus D truncation.
fn recip_rel_bound(hw: &HwConfig) -> f64 {
    let c = &hw.reciprocal;
    let tp = 2f64.powi(-((c.recip_mantissa_bits + GUARD_BITS) as i32));
    let mut e = 2f64.powi(-(c.recip_lut_bits as i32 + 1)) + tp;
    for _ in 0..c.recip_iterations {
        e = e * e + 4.0 * tp;
    }
    e + tp + 2f64.powi(-(c.recip_mantissa_bits as i32)) + 2f64.powi(-61)
}

fn configs() -> Vec<HwConfig> {
    let mut v = vec![HwConfig::texram16()];
    let mut c = HwConfig::texram16();
    c.reciprocal.recip_iterations = 2;
    c.interp.bary_bits = 24;
    c.interp.interp_rounding = Rounding::Truncate;
    v.push(c);
    let mut c = HwConfig::texram16();
    c.reciprocal.recip_lut_bits = 6;
    c.reciprocal.recip_mantissa_bits = 16;
    c.interp.bary_bits = 12;
    c.interp.inv_w_bits = 12;
    c.interp.interp_rounding = Rounding::HalfUp;
    v.push(c);
    v
}

fn rand_edge(rng: &mut Rng, inside: bool) -> [i64; 3] {
    let bits = 1 + rng.below(54) as u32;
    let mut e = [0i64; 3];
    for x in &mut e {
        *x = (rng.next() >> (64 - bits)) as i64;
    }
    if !inside {
        let k = rng.below(3) as usize;
        e[k] = -e[k] / (1 + rng.below(4) as i64);
    }
    e
}

fn rand_invw(rng: &mut Rng, ib: u32) -> [i64; 3] {
    let one = 1i64 << ib;
    let mut w = [0i64; 3];
    for x in &mut w {
        *x = 1 + rng.below(one as u64) as i64;
    }
    w[rng.below(3) as usize] = one;
    w
}

#[test]
fn bary_vs_exact_rational() {
    let mut rng = Rng(0xba_0001);
    for hw in configs() {
        let cfg: InterpConfig = hw.interp.clone();
        let recip = Reciprocal::new(&hw.reciprocal);
        let b = cfg.bary_bits;
        let er = recip_rel_bound(&hw);
        let h = if cfg.interp_rounding == Rounding::Truncate {
            1.0
        } else {
            0.5
        };
        let mut max_in = 0.0f64;
        let mut degenerate = 0;
        for k in 0..400_000 {
            let inside = k % 4 != 0;
            let e = rand_edge(&mut rng, inside);
            let w = rand_invw(&mut rng, cfg.inv_w_bits);
            let mut sat = SatCounter::default();
            let p = perspective_bary(e, w, &cfg, &recip, &mut sat);
            assert_eq!(p[0] + p[1] + p[2], 1i64 << b, "sum != 1");
            let q: Vec<i128> = (0..3)
                .map(|i| i128::from(e[i]) * i128::from(w[i]))
                .collect();
            let d: i128 = q.iter().sum();
            if d <= 0 {
                degenerate += 1;
                assert_eq!(p, [1i64 << b, 0, 0]);
                assert_eq!(sat.saturated, 1);
                continue;
            }
            let mut bounds = [0.0; 3];
            for i in 1..3 {
                let exact = q[i] as f64 / d as f64; // P_i
                if exact.abs() * 2f64.powi(b as i32) > BARY_LIMIT as f64 / 2.0 {
                    continue;
                }
                let Some(pd) = i128::from(p[i]).checked_mul(d) else {
                    continue;
                };
                let err = (pd - (q[i] << b)) as f64 / d as f64;
                let bound = exact.abs() * 2f64.powi(b as i32) * er + h + 1e-6;
                assert!(
                    err.abs() <= bound,
                    "p{i} err {err} > {bound}: e={e:?} w={w:?} {p:?}"
                );
                bounds[i] = bound;
                if inside {
                    max_in = max_in.max(err.abs());
                }
            }
            // p0 against its exact value.
            let q0 = q[0] << b;
            if let Some(pd) = i128::from(p[0]).checked_mul(d) {
                if bounds[1] > 0.0 && bounds[2] > 0.0 {
                    let err = (pd - q0) as f64 / d as f64;
                    assert!(err.abs() <= bounds[1] + bounds[2], "p0 err {err}");
                }
            }
            // The f64 twin agrees within the same bound (+ float rounding).
            if inside {
                let f = perspective_bary_f64(
                    [e[0] as f64, e[1] as f64, e[2] as f64],
                    [w[0] as f64, w[1] as f64, w[2] as f64],
                );
                for i in 1..3 {
                    let diff = (p[i] as f64 - f[i] * 2f64.powi(b as i32)).abs();
                    assert!(diff <= bounds[i] + 1e-6, "twin diff {diff}");
                }
            }
        }
        println!(
            "{}: bary_bits={b} max |err| inside = {max_in:.4} LSB (recip rel bound {er:.3e}), {degenerate} D<=0",
            hw.name
        );
    }
}

#[test]
fn bary_degenerate_and_vertices() {
    let hw = HwConfig::texram16();
    let recip = Reciprocal::new(&hw.reciprocal);
    let one = 1i64 << hw.interp.bary_bits;
    let mut sat = SatCounter::default();
    assert_eq!(
        perspective_bary([0, 0, 0], [1, 1, 1 << 24], &hw.interp, &recip, &mut sat),
        [one, 0, 0]
    );
    assert_eq!(sat.saturated, 1);
    assert_eq!(
        perspective_bary([-5, 1, 1], [1 << 24; 3], &hw.interp, &recip, &mut sat),
        [one, 0, 0]
    );
    assert_eq!(sat.saturated, 2);
    // At a vertex the barycentrics are exact.
    let w = [1 << 24, 3 << 20, 5 << 18];
    assert_eq!(
        perspective_bary([0, 1 << 40, 0], w, &hw.interp, &recip, &mut sat),
        [0, one, 0]
    );
    assert_eq!(
        perspective_bary([0, 0, 12345], w, &hw.interp, &recip, &mut sat),
        [0, 0, one]
    );
    assert_eq!(sat.saturated, 2);
}

fn exact_round(acc: i128, shift: u32, mode: Rounding) -> i128 {
    let den = 1i128 << shift;
    let q = acc.div_euclid(den);
    let r = acc.rem_euclid(den);
    match mode {
        Rounding::Truncate => q,
        Rounding::HalfUp => q + i128::from(2 * r >= den),
        Rounding::HalfEven => q + i128::from(2 * r > den || (2 * r == den && q.rem_euclid(2) == 1)),
    }
}

#[test]
fn interpolate_exact_rounding() {
    let mut rng = Rng(0xba_0002);
    let modes = [Rounding::Truncate, Rounding::HalfUp, Rounding::HalfEven];
    for k in 0..1_200_000u32 {
        let bb = 4 + rng.below(27) as u32;
        let mut out = Format::signed(
            8 + rng.below(8) as u32,
            4 + rng.below(20) as u32,
            modes[(k % 3) as usize],
        );
        if k % 7 == 0 {
            out.overflow = Overflow::Wrap;
        }
        let lim = (out.max_raw() as u64) * 2;
        let attr = [0; 3].map(|_: i64| rng.below(lim) as i64 - out.max_raw());
        let one = 1i64 << bb;
        let spread = if k % 5 == 0 {
            4 * one as u64
        } else {
            one as u64
        };
        let p1 = rng.below(spread) as i64 - if k % 5 == 0 { one } else { 0 };
        let p2 = rng.below(spread) as i64 - if k % 5 == 0 { one } else { 0 };
        let bary = [one - p1 - p2, p1, p2];
        let mut sat = SatCounter::default();
        let got = interpolate(bary, bb, attr, &out, &mut sat);
        let exact = i128::from(bary[0]) * i128::from(attr[0])
            + i128::from(bary[1]) * i128::from(attr[1])
            + i128::from(bary[2]) * i128::from(attr[2]);
        let r = exact_round(exact, bb, out.rounding);
        let (lo, hi) = (i128::from(out.min_raw()), i128::from(out.max_raw()));
        if r < lo || r > hi {
            match out.overflow {
                Overflow::Saturate => {
                    assert_eq!(i128::from(got), r.clamp(lo, hi));
                    assert_eq!(sat.saturated, 1);
                }
                Overflow::Wrap => {
                    assert_eq!(
                        i128::from(got).rem_euclid(hi - lo + 1),
                        r.rem_euclid(hi - lo + 1)
                    );
                    assert_eq!(sat.wrapped, 1);
                }
            }
        } else {
            assert_eq!(
                i128::from(got),
                r,
                "bary={bary:?} attr={attr:?} bb={bb} {out:?}"
            );
            assert_eq!(sat, SatCounter::default());
            if k % 8 == 0 {
                let s = 2f64.powi(-(bb as i32));
                let f = interpolate_f64(
                    [bary[0] as f64 * s, bary[1] as f64 * s, bary[2] as f64 * s],
                    [attr[0] as f64, attr[1] as f64, attr[2] as f64],
                );
                let tol = 1.0 + f.abs() * 1e-12;
                assert!((got as f64 - f).abs() <= tol, "twin {got} vs {f}");
            }
        }
    }
}

/// `interp.texcoord_reduce`: the offset is the floor of the middle of the range for repeat, an
/// even integer for mirror (a mirror period is two repeats), nothing for clamp-to-edge.
#[test]
fn texcoord_offset_is_an_integer_period() {
    use texsim::pipeline::stages::texcoord_offset;
    use texsim::scene::WrapMode;
    assert_eq!(
        texcoord_offset([1e6, 1e6 + 3.0, 1e6 + 1.5], WrapMode::Repeat),
        1e6 + 1.0
    );
    assert_eq!(texcoord_offset([-7.25, -6.0, -6.5], WrapMode::Repeat), -7.0);
    assert_eq!(texcoord_offset([257.3; 3], WrapMode::Mirror), 256.0);
    assert_eq!(texcoord_offset([258.3; 3], WrapMode::Mirror), 258.0);
    assert_eq!(texcoord_offset([-3.5; 3], WrapMode::Mirror), -4.0);
    assert_eq!(texcoord_offset([1e6; 3], WrapMode::ClampToEdge), 0.0);
    assert_eq!(texcoord_offset([f64::NAN, 0.0, 1.0], WrapMode::Repeat), 0.0);
}

/// A textured plane whose coordinates sit 2^20 repeats away renders the same hardware image as
/// the plane near 0 (repeat and mirror), with no saturation; without the reduction the far
/// coordinates saturate the 8 integer bits, and the saturations are counted.
#[test]
fn far_texture_coordinates_reduce_exactly() {
    use texsim::render::{render, Maps, RenderOptions};
    let dir = crate::tmp_common::TmpDir::new("reduce");
    for wrap in ["repeat", "mirror"] {
        let p = dir.join(format!("plane_{wrap}.toml"));
        std::fs::write(
            &p,
            format!(
                "[output]\nwidth = 96\nheight = 72\n[camera]\neye = [0.0, 1.0, 2.5]\ntarget = [0.0, 0.0, 0.0]\n\
                 [[textures]]\nname = \"c\"\nprocedural = \"noise-checker\"\nsize = 64\n\
                 [[materials]]\nname = \"m\"\ntexture = \"c\"\nwrap_s = \"{wrap}\"\nwrap_t = \"{wrap}\"\nlit = false\n\
                 [[meshes]]\nshape = \"plane\"\nsize = 4.0\nuv_scale = 6.0\nmaterial = \"m\"\n"
            ),
        )
        .unwrap();
        let near = texsim::scene::load(&p).unwrap();
        let mut far = near.clone();
        for uv in &mut far.meshes[0].uvs {
            // 2^20 + k with k a multiple of 1/8 stays exact in f32.
            assert_eq!(uv[0] * 8.0, (uv[0] * 8.0).round(), "{uv:?}");
            uv[0] += 1_048_576.0;
            uv[1] -= 1_048_576.0;
        }
        let hw = HwConfig::preset("texram16").unwrap();
        let opts = RenderOptions {
            reference: false,
            ..RenderOptions::default()
        };
        let maps = Maps::new(&near, hw.trilinear.texel_bits);
        let a = render(&near, &maps, &hw, &opts).unwrap();
        let b = render(&far, &maps, &hw, &opts).unwrap();
        let sat = |r: &texsim::render::Rendered| {
            r.stats.input_saturated
                + r.stats.input_wrapped
                + r.stats
                    .stages
                    .iter()
                    .map(|s| s.saturated + s.wrapped)
                    .sum::<u64>()
        };
        assert!(
            a.stats.covered_pixels > 3000,
            "{wrap}: {}",
            a.stats.covered_pixels
        );
        assert_eq!(sat(&a), 0, "{wrap}");
        assert_eq!(sat(&b), 0, "{wrap}: far coordinates saturate");
        assert!(
            a.hw_image.px == b.hw_image.px,
            "{wrap}: the far plane renders differently"
        );
        let mut off = hw.clone();
        off.interp.texcoord_reduce = false;
        let c = render(&far, &maps, &off, &opts).unwrap();
        assert!(
            c.stats.input_saturated > 0,
            "{wrap}: saturations not counted"
        );
        assert!(a.hw_image.px != c.hw_image.px, "{wrap}");
    }
}
