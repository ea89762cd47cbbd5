//! `perspective_bary_derivs` (analytic derivatives of the perspective-correct barycentrics from
//! one shared reciprocal) against an exact-rational model evaluated in `f64`, on random
//! triangles, samples and 1/w; and the float twin against the same model.

use crate::rng_common::Rng;
use hw_model::config::HwConfig;
use hw_model::fixed::{Rounding, SatCounter};
use hw_model::interpolator::{perspective_bary, perspective_bary_derivs};
use hw_model::reciprocal::{Reciprocal, GUARD_BITS};
use texsim::reference::perspective_bary_derivs_f64;

/// Relative error bound of the reciprocal (as in `hw_model::reciprocal`).
fn recip_rel_bound(hw: &HwConfig) -> f64 {
    let c = &hw.reciprocal;
    let tp = 2f64.powi(-((c.recip_mantissa_bits + GUARD_BITS) as i32));
    let mut e = 2f64.powi(-(c.recip_lut_bits as i32 + 1)) + tp;
    for _ in 0..c.recip_iterations {
        e = e * e + 4.0 * tp;
    }
    e + tp + 2f64.powi(-(c.recip_mantissa_bits as i32)) + 2f64.powi(-61)
}

fn cross(a: [i64; 2], b: [i64; 2], p: [i64; 2]) -> i64 {
    (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
}

/// Exact edge values of a triangle at `p` (positive inside for counter-clockwise in y-down).
fn edges(v: &[[i64; 2]; 3], p: [i64; 2]) -> [i64; 3] {
    [
        cross(v[1], v[2], p),
        cross(v[2], v[0], p),
        cross(v[0], v[1], p),
    ]
}

#[test]
fn derivatives_meet_the_stated_bound() {
    let mut rng = Rng(0xde71_0001);
    let mut configs = vec![HwConfig::texram16()];
    let mut c = HwConfig::texram16();
    c.reciprocal.recip_iterations = 1;
    c.interp.bary_bits = 16;
    c.interp.interp_rounding = Rounding::Truncate;
    configs.push(c);
    for hw in configs {
        let recip = Reciprocal::new(&hw.reciprocal);
        let b = hw.interp.bary_bits;
        let scale = 2f64.powi(b as i32);
        let er = recip_rel_bound(&hw);
        let em = 2f64.powi(-(hw.reciprocal.recip_mantissa_bits as i32 + 1));
        let half = if hw.interp.interp_rounding == Rounding::Truncate {
            1.0
        } else {
            0.5
        };
        let (mut worst, mut n) = (0.0f64, 0u64);
        for _ in 0..400_000 {
            // A triangle of up to 2^(8+s) pixels in 8-bit sub-pixel units, a sample in its
            // bounding box (inside or just outside), 1/w normalized with the largest = 1.0.
            let span = 1i64 << rng.int_in(4, 20);
            let v: [[i64; 2]; 3] =
                std::array::from_fn(|_| [rng.int_in(-span, span), rng.int_in(-span, span)]);
            let mut v = v;
            if cross(v[0], v[1], v[2]) < 0 {
                v.swap(1, 2);
            }
            if cross(v[0], v[1], v[2]) == 0 {
                continue;
            }
            let wts = [0, 1, 2].map(|_| rng.int_in(1, 1 << 16));
            let tot: i64 = wts.iter().sum();
            let p = [0, 1].map(|ax| (0..3).map(|j| wts[j] * v[j][ax]).sum::<i64>() / tot);
            let e = edges(&v, p);
            if e.iter().any(|&x| x < 0) {
                continue;
            }
            let step = 1i64 << hw.raster.subpixel_bits;
            let ex = edges(&v, [p[0] + step, p[1]]);
            let ey = edges(&v, [p[0], p[1] + step]);
            let dx = [0, 1, 2].map(|i| ex[i] - e[i]);
            let dy = [0, 1, 2].map(|i| ey[i] - e[i]);
            let one = 1i64 << hw.interp.inv_w_bits;
            let mut w = [0, 1, 2].map(|_| rng.int_in(1, one));
            w[rng.int_in(0, 2) as usize] = one;
            let mut sat = SatCounter::default();
            let out = perspective_bary_derivs(e, dx, dy, w, &hw.interp, &recip, &mut sat);
            assert_eq!(out[0], perspective_bary(e, w, &hw.interp, &recip, &mut sat));
            let f = |a: [i64; 3]| a.map(|x| x as f64);
            let exact = perspective_bary_derivs_f64(f(e), f(dx), f(dy), f(w));
            for k in 1..3 {
                assert_eq!(
                    out[k].iter().sum::<i64>(),
                    1i64 << b,
                    "triple must sum to 1.0"
                );
                for i in 1..3 {
                    let dp_exact = (exact[k][i] - exact[0][i]) * scale;
                    let dp = (out[k][i] - out[0][i]) as f64;
                    let bound = dp_exact.abs() * (2.0 * er + em + 2f64.powi(-60)) + half + 1e-6;
                    let err = (dp - dp_exact).abs();
                    assert!(
                        err <= bound,
                        "k={k} i={i} dp={dp} exact={dp_exact} err={err} bound={bound}"
                    );
                    worst = worst.max(err / bound);
                    n += 1;
                }
            }
            assert_eq!(sat, SatCounter::default());
        }
        println!(
            "{}: {n} derivative checks, worst error / bound = {worst:.3}",
            hw.name
        );
        assert!(n > 1_000_000, "only {n} checks");
    }
}
