//! Roughness pyramid (Schilling 1997): the recursive covariance rule against the direct
//! covariance of all finest offsets under each texel, the D factorization, lambda1, the
//! encoding and the quantized chain.

#![allow(clippy::needless_range_loop)]

use crate::rng_common::Rng;
use hw_model::roughness::{decode_d, RoughnessConfig, D2_CHANNEL};
use texsim::shading::roughness::{
    build_rough_pyramid, d_factor, d_product, decode_d_texels, lambda1, quantize_d_channel,
    quantize_rough_chain, rough_mip_chain, RoughParams, RoughnessEncoding, UNIFORM_CORRECTION,
};

/// Direct mean and covariance (population, 1/n) of the finest offsets in the block of texel
/// `(x, y)` at level `l` of a power-of-two map.
fn direct(offs: &[[f32; 2]], w: u32, l: u32, x: u32, y: u32) -> ([f64; 2], [f64; 3]) {
    let s = 1u32 << l;
    let n = f64::from(s * s);
    let mut m = [0.0; 2];
    for py in y * s..(y + 1) * s {
        for px in x * s..(x + 1) * s {
            let o = offs[(py * w + px) as usize];
            m[0] += f64::from(o[0]);
            m[1] += f64::from(o[1]);
        }
    }
    let m = m.map(|v| v / n);
    let mut k = [0.0; 3];
    for py in y * s..(y + 1) * s {
        for px in x * s..(x + 1) * s {
            let o = offs[(py * w + px) as usize];
            let (du, dv) = (f64::from(o[0]) - m[0], f64::from(o[1]) - m[1]);
            k[0] += du * du;
            k[1] += du * dv;
            k[2] += dv * dv;
        }
    }
    (m, k.map(|v| v / n))
}

fn check_against_direct(offs: &[[f32; 2]], w: u32, h: u32, tol: f64) -> f64 {
    let pyr = build_rough_pyramid(offs, w, h).expect("valid map");
    let mut worst = 0.0f64;
    for (l, lev) in pyr.levels.iter().enumerate() {
        assert_eq!(lev.width, (w >> l).max(1));
        for y in 0..lev.height {
            for x in 0..lev.width {
                let i = (y * lev.width + x) as usize;
                // Blocks are square only while both sides halve; these maps are square.
                let (m, k) = direct(offs, w, l as u32, x, y);
                for c in 0..2 {
                    let e = (lev.mean[i][c] - m[c]).abs();
                    worst = worst.max(e);
                    assert!(e <= tol, "mean level {l} ({x},{y}) {e}");
                }
                for c in 0..3 {
                    let e = (lev.cov[i][c] - k[c]).abs();
                    worst = worst.max(e);
                    assert!(
                        e <= tol,
                        "cov level {l} ({x},{y}) {} vs {}",
                        lev.cov[i][c],
                        k[c]
                    );
                }
            }
        }
    }
    worst
}

#[test]
fn recursive_rule_is_exact_for_dyadic_offsets() {
    let mut r = Rng(1);
    let (w, h) = (32u32, 32u32);
    let offs: Vec<[f32; 2]> = (0..w * h)
        .map(|_| {
            let a = (r.next() % 512) as f32 / 256.0 - 1.0;
            let b = (r.next() % 512) as f32 / 256.0 - 1.0;
            [a, b]
        })
        .collect();
    let worst = check_against_direct(&offs, w, h, 0.0);
    assert_eq!(worst, 0.0);
}

#[test]
fn recursive_rule_matches_direct_for_random_offsets() {
    let mut r = Rng(2);
    let (w, h) = (64u32, 64u32);
    let offs: Vec<[f32; 2]> = (0..w * h)
        .map(|_| [(r.unit() * 4.0 - 2.0) as f32, (r.unit() * 0.5 - 0.1) as f32])
        .collect();
    let worst = check_against_direct(&offs, w, h, 1e-12);
    println!("random 64x64: worst |recursive - direct| = {worst:e}");
}

#[test]
fn garbled_forms_fail_the_direct_check() {
    // Negative control: dropping either term of the rule breaks the equality the test checks.
    let mut r = Rng(3);
    let offs: Vec<[f32; 2]> = (0..16 * 16)
        .map(|_| [(r.unit() * 2.0 - 1.0) as f32, (r.unit() * 2.0 - 1.0) as f32])
        .collect();
    let pyr = build_rough_pyramid(&offs, 16, 16).expect("valid");
    let top = pyr.levels.last().expect("levels");
    let (_, k) = direct(&offs, 16, 4, 0, 0);
    // Scatter of the level-3 means alone (the second term without the first):
    let l3 = &pyr.levels[3];
    let m = top.mean[0];
    let scatter: f64 = l3.mean.iter().map(|c| (c[0] - m[0]).powi(2)).sum::<f64>() / 4.0;
    let down: f64 = l3.cov.iter().map(|c| c[0]).sum::<f64>() / 4.0;
    assert!((top.cov[0][0] - k[0]).abs() < 1e-12);
    assert!((scatter - k[0]).abs() > 1e-3 && (down - k[0]).abs() > 1e-3);
    assert!((scatter + down - k[0]).abs() < 1e-12);
}

#[test]
fn npot_maps_keep_the_bump_mip_mean_and_a_psd_covariance() {
    let mut r = Rng(4);
    for &(w, h) in &[(5u32, 3u32), (7, 1), (1, 9), (12, 6), (33, 17)] {
        let offs: Vec<[f32; 2]> = (0..w * h)
            .map(|_| [(r.unit() * 2.0 - 1.0) as f32, (r.unit() * 2.0 - 1.0) as f32])
            .collect();
        let pyr = build_rough_pyramid(&offs, w, h).expect("valid");
        let last = pyr.levels.last().expect("levels");
        assert_eq!((last.width, last.height), (1, 1));
        assert_eq!(
            pyr.levels.len(),
            texsim::maps::chain_sizes(w, h).len(),
            "{w}x{h}"
        );
        for lev in &pyr.levels {
            for k in &lev.cov {
                assert!(k[0] >= -1e-15 && k[2] >= -1e-15);
                assert!(k[1] * k[1] <= k[0] * k[2] + 1e-12, "{k:?}");
            }
        }
        // Past the last level: clamped.
        assert_eq!(pyr.level(99), last);
        // The means are the bump MIP: maps::downsample of the offsets, level by level (f32).
        let mut ds = texsim::maps::MipLevel {
            width: w,
            height: h,
            texels: offs.iter().map(|o| [o[0], o[1], 0.0, 0.0]).collect(),
        };
        for lev in &pyr.levels[1..] {
            ds = texsim::maps::downsample(&ds);
            assert_eq!((ds.width, ds.height), (lev.width, lev.height));
            for (m, t) in lev.mean.iter().zip(&ds.texels) {
                for c in 0..2 {
                    let e = (m[c] - f64::from(t[c])).abs();
                    assert!(e <= 1e-6, "{w}x{h} mean {m:?} vs downsample {t:?}");
                }
            }
        }
        // K is the covariance of the finest offsets under the weights that MIP implies (3
        // parents where a size is odd): the weight of each finest texel in each texel, carried
        // down the chain, then the weighted mean and covariance directly.
        let mut weights: Vec<Vec<f64>> = (0..(w * h) as usize)
            .map(|i| {
                let mut v = vec![0.0; (w * h) as usize];
                v[i] = 1.0;
                v
            })
            .collect();
        let (mut pw, mut ph) = (w, h);
        for lev in &pyr.levels[1..] {
            let axis = |i: u32, n: u32, child: u32| {
                if n == 1 {
                    (0, 1)
                } else if i + 1 == child && n % 2 == 1 {
                    (2 * i, 3)
                } else {
                    (2 * i, 2)
                }
            };
            let mut next = Vec::new();
            for y in 0..lev.height {
                let (y0, cy) = axis(y, ph, lev.height);
                for x in 0..lev.width {
                    let (x0, cx) = axis(x, pw, lev.width);
                    let mut acc = vec![0.0; (w * h) as usize];
                    for py in y0..y0 + cy {
                        for px in x0..x0 + cx {
                            for (a, b) in acc.iter_mut().zip(&weights[(py * pw + px) as usize]) {
                                *a += b / f64::from(cx * cy);
                            }
                        }
                    }
                    next.push(acc);
                }
            }
            weights = next;
            (pw, ph) = (lev.width, lev.height);
            for (i, wt) in weights.iter().enumerate() {
                let mut m = [0.0; 2];
                for (o, &k) in offs.iter().zip(wt) {
                    m[0] += k * f64::from(o[0]);
                    m[1] += k * f64::from(o[1]);
                }
                let mut cov = [0.0; 3];
                for (o, &k) in offs.iter().zip(wt) {
                    let (du, dv) = (f64::from(o[0]) - m[0], f64::from(o[1]) - m[1]);
                    cov[0] += k * du * du;
                    cov[1] += k * du * dv;
                    cov[2] += k * dv * dv;
                }
                for c in 0..3 {
                    assert!(
                        (lev.cov[i][c] - cov[c]).abs() <= 1e-12,
                        "{w}x{h} texel {i}: {:?} vs {cov:?}",
                        lev.cov[i]
                    );
                }
                assert!((lev.mean[i][0] - m[0]).abs() <= 1e-12);
            }
        }
    }
}

#[test]
fn bad_inputs_are_errors() {
    assert!(build_rough_pyramid(&[[0.0, 0.0]; 3], 2, 2).is_err());
    assert!(build_rough_pyramid(&[], 0, 0).is_err());
    assert!(build_rough_pyramid(&[[f32::NAN, 0.0]], 1, 1).is_err());
}

fn random_psd(r: &mut Rng) -> [f64; 3] {
    // K = A A^T with random A, some rank-deficient, some with tiny c.
    let s = |r: &mut Rng| (r.unit() * 2.0 - 1.0) * 10f64.powf(r.unit() * 6.0 - 4.0);
    let (p, q, t, u) = (s(r), s(r), s(r), s(r));
    match r.next() % 4 {
        0 => [p * p, p * q, q * q],                        // rank 1
        1 => [p * p + q * q, q * 1e-9 * t, 1e-18 * t * t], // c -> 0
        _ => [p * p + q * q, p * t + q * u, t * t + u * u],
    }
}

#[test]
fn d_factor_reproduces_k_including_singular_and_c_to_zero() {
    let mut r = Rng(5);
    let mut worst = 0.0f64;
    for _ in 0..200_000 {
        let k = random_psd(&mut r);
        let d = d_factor(k);
        assert!(d.iter().all(|v| v.is_finite()));
        assert!(d[0] >= 0.0 && d[2] >= 0.0);
        let kk = d_product(d);
        let scale = k[0].max(k[2]).max(1e-300);
        for i in 0..3 {
            let e = (kk[i] - k[i]).abs() / scale;
            worst = worst.max(e);
        }
    }
    println!("D D^T vs K: worst relative error {worst:e}");
    // Measured 4.3e-16 (a few ulp): the factorization is exact up to rounding.
    assert!(worst < 1e-14, "{worst}");
    // Exact zero c, zero matrix, slightly non-PSD input (rounding): finite, non-negative.
    for k in [
        [1.0, 0.0, 0.0],
        [0.0, 0.0, 0.0],
        [1.0, 1.0 + 1e-12, 1.0],
        [-1e-20, 0.0, 2.0],
    ] {
        let d = d_factor(k);
        assert!(d.iter().all(|v| v.is_finite()), "{k:?}");
        assert!(d[0] >= 0.0 && d[2] >= 0.0);
    }
    assert_eq!(d_factor([4.0, 0.0, 0.0]), [2.0, 0.0, 0.0]);
}

#[test]
fn lambda1_is_the_largest_standard_deviation() {
    let mut r = Rng(6);
    for _ in 0..100_000 {
        let k = random_psd(&mut r);
        let l = lambda1(k);
        // Largest directional variance over a fine angle sweep, from below.
        let mut best = 0.0f64;
        for i in 0..720 {
            let t = f64::from(i) * std::f64::consts::PI / 720.0;
            let (c, s) = (t.cos(), t.sin());
            best = best.max(k[0] * c * c + 2.0 * k[1] * c * s + k[2] * s * s);
        }
        let scale = k[0] + k[2];
        assert!(l * l >= best - 1e-12 * scale, "{k:?}");
        assert!(l * l <= best * (1.0 + 2e-5) + 1e-12 * scale, "{k:?}");
    }
}

#[test]
fn stored_covariance_adds_base_roughness_and_correction() {
    let p = RoughParams {
        base_sigma: 0.25,
        exponent: 2.0,
        correction: UNIFORM_CORRECTION,
    };
    let k = p.stored_cov([0.0, 0.0, 0.0]);
    assert_eq!(k, [0.125, 0.0, 0.125]);
    let k = p.stored_cov([1.0, 0.5, 1.0]);
    assert_eq!(k, [2.0 * (3.0 + 0.0625), 3.0, 2.0 * (3.0 + 0.0625)]);
    // Uniform offsets in [-w, w]: sigma = w / sqrt(3); corrected, the ellipse reaches w.
    let n = 4096;
    let offs: Vec<[f32; 2]> = (0..n)
        .map(|i| {
            [
                ((f64::from(i) + 0.5) / f64::from(n) * 2.0 - 1.0) as f32,
                0.0,
            ]
        })
        .collect();
    let pyr = build_rough_pyramid(&offs, n, 1).expect("valid");
    let a = pyr.levels.last().expect("levels").cov[0][0];
    assert!((a * UNIFORM_CORRECTION - 1.0).abs() < 1e-5, "{a}");
    let fm = RoughParams::for_material(64, 1, false);
    assert!((fm.base_sigma - 0.125).abs() < 1e-15);
}

#[test]
fn encoding_round_trips_through_the_hw_decoder() {
    let cfg = RoughnessConfig {
        rough_range_exp: 1,
        ..RoughnessConfig::texram16()
    };
    let enc = RoughnessEncoding::for_range_exp(cfg.rough_range_exp);
    let mut r = Rng(7);
    for _ in 0..10_000 {
        let d = [r.unit() * 1.9, r.unit() * 3.8 - 1.9, r.unit() * 1.9];
        let (ch, clamped) = enc.encode(d);
        assert_eq!(clamped, 0);
        let back = enc.decode(ch.map(f64::from));
        for i in 0..3 {
            assert!((back[i] - d[i]).abs() < 1e-6);
        }
        // Texels as texture memory holds them, then the hw decoder vs the float decoder.
        let t = ch.map(|c| u64::from(texsim::maps::quantize_unorm(c, 16)));
        let (raw, frac) = decode_d(t, 16, &cfg);
        let f = decode_d_texels(t, 16, cfg.rough_range_exp);
        for i in 0..3 {
            assert_eq!(raw[i] as f64 * (-f64::from(frac)).exp2(), f[i]);
            assert!(
                (f[i] - d[i]).abs() < 4.0 * 2f64.powi(-15),
                "{} {}",
                f[i],
                d[i]
            );
        }
    }
    let (_, clamped) = enc.encode([5.0, -9.0, f64::NAN]);
    assert_eq!(clamped, 3);
}

#[test]
fn quantized_chain_has_d_bits_resolution() {
    let mut r = Rng(8);
    let offs: Vec<[f32; 2]> = (0..16 * 16)
        .map(|_| [(r.unit() * 2.0 - 1.0) as f32, (r.unit() - 0.5) as f32])
        .collect();
    let pyr = build_rough_pyramid(&offs, 16, 16).expect("valid");
    let params = RoughParams::for_material(32, 1, false);
    let enc = RoughnessEncoding::for_range_exp(1);
    for iso in [false, true] {
        let (chain, clamped) = rough_mip_chain(&pyr, &params, &enc, iso);
        assert_eq!(clamped, 0);
        for bits in [4u32, 8, 12, 16] {
            let q = quantize_rough_chain(&chain, bits, 16);
            for (fl, ql) in chain.levels.iter().zip(&q.levels) {
                for (ft, qt) in fl.texels.iter().zip(&ql.texels) {
                    for c in [0, 2] {
                        let v = f64::from(qt[c]) / 65535.0;
                        let e = (v - f64::from(ft[c])).abs();
                        assert!(e <= 0.5 / ((1u32 << bits) - 1) as f64 + 2e-5, "{bits} {e}");
                    }
                    // d2, offset-binary: (t - 2^15) / 2^16 + 1/2, half a step of 2^-bits.
                    let v = (f64::from(qt[1]) - 32768.0) / 65536.0 + 0.5;
                    let e = (v - f64::from(ft[1])).abs();
                    assert!(e <= 0.5 / f64::from(1u32 << bits) + 1e-7, "{bits} d2 {e}");
                }
            }
        }
    }
}

/// The stored-and-widened D texels of one D value at `d_bits`, through the host encoder and
/// quantizer the renderer uses (`RoughnessEncoding::encode` + `quantize_rough_chain`).
fn stored_texels(enc: &RoughnessEncoding, d: [f64; 3], d_bits: u32) -> [u64; 3] {
    let (ch, _) = enc.encode(d);
    let chain = texsim::maps::MipChain {
        levels: vec![texsim::maps::MipLevel {
            width: 1,
            height: 1,
            texels: vec![[ch[0], ch[1], ch[2], 1.0]],
        }],
    };
    let q = quantize_rough_chain(&chain, d_bits, 16);
    let t = q.levels[0].texels[0];
    [0, 1, 2].map(|i| u64::from(t[i]))
}

#[test]
fn flat_texels_decode_to_zero_shear_at_every_d_bits() {
    // A flat region (K = 0) stores K' = m s0^2 I: d2 = 0. Bit-replicating the centre code
    // 2^(d-1) gave 0x8080 at 8 bits, i.e. d2 = +2R/255 (+0.27 at 4 bits): flat texels sheared.
    let offs = vec![[0.25f32, -0.5]; 8 * 8];
    let pyr = build_rough_pyramid(&offs, 8, 8).expect("valid");
    for range_exp in -4..=4 {
        let cfg = RoughnessConfig {
            rough_range_exp: range_exp,
            ..RoughnessConfig::texram16()
        };
        let enc = RoughnessEncoding::for_range_exp(range_exp);
        for shininess in [1u32, 16, 400] {
            let params = RoughParams::for_material(shininess, shininess, false);
            let (chain, _) = rough_mip_chain(&pyr, &params, &enc, false);
            for d_bits in 2..=16 {
                let q = quantize_rough_chain(&chain, d_bits, 16);
                for lev in &q.levels {
                    for t in &lev.texels {
                        let t = [0, 1, 2].map(|i| u64::from(t[i]));
                        let (raw, _) = decode_d(t, 16, &cfg);
                        let f = decode_d_texels(t, 16, range_exp);
                        assert_eq!(raw[1], 0, "e {range_exp} s {shininess} d_bits {d_bits}");
                        assert_eq!(f[1], 0.0, "e {range_exp} s {shininess} d_bits {d_bits}");
                        assert_eq!(raw[0], raw[2], "isotropic K': d1 = d3");
                    }
                }
            }
        }
    }
}

#[test]
fn d2_quantization_is_unbiased_symmetric_and_within_half_a_step() {
    let mut r = Rng(9);
    for range_exp in [-2, 0, 2, 4] {
        let cfg = RoughnessConfig {
            rough_range_exp: range_exp,
            ..RoughnessConfig::texram16()
        };
        let enc = RoughnessEncoding::for_range_exp(range_exp);
        let big_r = enc.range;
        for d_bits in 2..=16u32 {
            let step = 2.0 * big_r / f64::from(1u32 << d_bits);
            let top = big_r - step;
            let (mut sum, n) = (0.0, 20_000);
            for _ in 0..n {
                let x = (r.unit() * 2.0 - 1.0) * top;
                let t = stored_texels(&enc, [0.5 * big_r, x, 0.5 * big_r], d_bits);
                let got = decode_d_texels(t, 16, range_exp)[1];
                let (raw, frac) = decode_d(t, 16, &cfg);
                assert_eq!(raw[1] as f64 * (-f64::from(frac)).exp2(), got);
                let e = got - x;
                // Half a step, plus the f32 rounding of the channel value 1/2 + x / (2R).
                let tol = 0.5 * step + 2.0 * big_r * 2f64.powi(-24);
                assert!(e.abs() <= tol, "{d_bits} {x} {e}");
                sum += e;
            }
            // Symmetric: channel values 1/2 +- j 2^-20 (exact in f32) give mirrored codes.
            let half = 1u64 << (d_bits - 1);
            for j in 0..(1u32 << 19) {
                let y = f64::from(j) * 2f64.powi(-20);
                let (up, down) = (
                    quantize_d_channel((0.5 + y) as f32, D2_CHANNEL, d_bits),
                    quantize_d_channel((0.5 - y) as f32, D2_CHANNEL, d_bits),
                );
                if up < 2 * half - 1 {
                    assert_eq!(up - half, half - down, "{d_bits} {y}");
                }
            }
            let mean = sum / f64::from(n);
            assert!(
                mean.abs() < 0.02 * step,
                "e {range_exp} d_bits {d_bits}: bias {mean}"
            );
            // The ends: -R exactly; +R clamps to the top code R - step.
            let lo = stored_texels(&enc, [0.0, -big_r, 0.0], d_bits);
            let hi = stored_texels(&enc, [0.0, big_r, 0.0], d_bits);
            assert_eq!(decode_d_texels(lo, 16, range_exp)[1], -big_r);
            assert_eq!(decode_d_texels(hi, 16, range_exp)[1], top);
        }
    }
}

#[test]
fn lod_past_the_last_level_reads_the_last_texel_through_the_real_path() {
    // The renderer's path: finest offsets -> covariance pyramid -> D chain -> rough_d_bits
    // quantization -> the trilinear unit (fixed) / trilinear_f64 (float) at an LOD far past
    // the last level -> decode -> the modified Blinn-Phong unit and its twin.
    use hw_model::fixed::SatCounter;
    use hw_model::lod::lod;
    use hw_model::roughness::{rough_cos, RoughInput, RoughVariant};
    use hw_model::trilinear::trilinear;
    use hw_model::wrap::WrapMode;
    use texsim::reference::trilinear_f64;
    use texsim::shading::roughness::rough_cos_twin;
    let mut r = Rng(10);
    let (w, h) = (12u32, 6u32);
    let offs: Vec<[f32; 2]> = (0..w * h)
        .map(|_| [(r.unit() - 0.5) as f32, (r.unit() * 0.6 - 0.3) as f32])
        .collect();
    let pyr = build_rough_pyramid(&offs, w, h).expect("valid");
    let hw = hw_model::HwConfig::texram16();
    let tb = hw.trilinear.texel_bits;
    let lf = hw.lod.lod_frac_bits;
    let frac = 20u32;
    let mut sat = SatCounter::default();
    let wraps = [
        [WrapMode::Repeat, WrapMode::Repeat],
        [WrapMode::ClampToEdge, WrapMode::Mirror],
    ];
    for (variant, iso) in [
        (RoughVariant::Directional, false),
        (RoughVariant::Mahalanobis, false),
        (RoughVariant::Isotropic, true),
    ] {
        for d_bits in [4u32, 8, 16] {
            let cfg = RoughnessConfig {
                rough_variant: variant,
                rough_d_bits: d_bits,
                ..RoughnessConfig::texram16()
            };
            let enc = RoughnessEncoding::for_range_exp(cfg.rough_range_exp);
            let params = RoughParams::for_material(32, 32, false);
            let (chain, clamped) = rough_mip_chain(&pyr, &params, &enc, iso);
            assert_eq!(clamped, 0);
            let q = quantize_rough_chain(&chain, d_bits, tb);
            let fixed = q.views();
            let float = chain.views();
            let last = fixed.len() as i64 - 1;
            let (last_x, last_f) = (
                q.levels[last as usize].texels[0],
                chain.levels[last as usize].texels[0],
            );
            // LODs from the LOD unit with huge derivatives, and raw ones far past the end.
            let huge = lod([1 << 45, 0, 0, 1 << 44], frac, &hw.lod, &mut sat);
            assert!(huge > (last + 20) << lf, "{huge}");
            assert_eq!(sat.saturated, 0, "lod");
            for l in [
                last << lf,
                (last << lf) + 1,
                (last + 1) << lf,
                63 << lf,
                huge,
                i64::MAX,
            ] {
                for _ in 0..200 {
                    let u = (r.next() >> 20) as i64 - (1i64 << 43);
                    let v = (r.next() >> 20) as i64 - (1i64 << 43);
                    for wrap in wraps {
                        let t = trilinear(&fixed, u, v, frac, l, lf, wrap, &hw.trilinear, None);
                        assert_eq!(t, last_x, "lod {l} ({u}, {v})");
                        let (uf, vf) = (
                            u as f64 * (-f64::from(frac)).exp2(),
                            v as f64 * (-f64::from(frac)).exp2(),
                        );
                        for lod_f in [l as f64 * (-f64::from(lf)).exp2(), 1e300, f64::INFINITY] {
                            let tf = trilinear_f64(&float, uf, vf, lod_f, wrap);
                            assert_eq!(tf, last_f.map(f64::from), "lod {lod_f}");
                        }
                    }
                }
            }
            // Decode the last texel both ways, and against the float model's decode of the
            // unquantized chain: finite, within the d_bits quantization step.
            let tex = [0, 1, 2].map(|i| u64::from(last_x[i]));
            let (raw, frac_t) = decode_d(tex, tb, &cfg);
            let dq = decode_d_texels(tex, tb, cfg.rough_range_exp);
            let df = enc.decode([0, 1, 2].map(|i| f64::from(last_f[i])));
            let big_r = enc.range;
            let step = big_r * 2f64.powi(-(d_bits as i32));
            for i in 0..3 {
                assert_eq!(raw[i] as f64 * (-f64::from(frac_t)).exp2(), dq[i]);
                assert!(dq[i].is_finite() && df[i].is_finite());
                let tol = if i == 1 {
                    step
                } else {
                    0.5 * step * 1.07 + big_r * 2f64.powi(-16)
                };
                assert!(
                    (dq[i] - df[i]).abs() <= tol,
                    "{variant:?} {d_bits} ch {i}: {} vs {}",
                    dq[i],
                    df[i]
                );
            }
            // The shading unit on the last texel: finite, in [0, 1], within the unit's bound.
            let f = 14u32;
            let one = f64::from(1u32 << f);
            let b = 1.5 * (-f64::from(cfg.rough_div_bits)).exp2()
                + (-f64::from(cfg.rough_sqrt_bits)).exp2()
                + (-17f64).exp2()
                + (-20f64).exp2();
            for _ in 0..2_000 {
                let a = r.unit() * std::f64::consts::FRAC_PI_2;
                let phi = r.unit() * std::f64::consts::TAU;
                let inp = RoughInput {
                    cos_a: (a.cos() * one).round() as i64,
                    d: [
                        (a.sin() * phi.cos() * one).round() as i64,
                        (a.sin() * phi.sin() * one).round() as i64,
                    ],
                    dch: tex,
                    texel_bits: tb,
                };
                let o = rough_cos(&inp, &cfg, f, 16, &mut sat);
                assert!(o.cos_mod <= 1 << 16);
                assert_eq!(sat.saturated, 0, "{inp:?} {o:?}");
                let twin = rough_cos_twin(
                    variant,
                    inp.cos_a as f64 / one,
                    [inp.d[0] as f64 / one, inp.d[1] as f64 / one],
                    dq,
                );
                assert!(twin.is_finite() && (0.0..=1.0).contains(&twin));
                let e = (o.cos_mod as f64 / 65536.0 - twin).abs();
                assert!(e <= b, "{variant:?} {d_bits}: {inp:?} {e} > {b}");
            }
        }
    }
    assert_eq!(sat.saturated, 0);
}
