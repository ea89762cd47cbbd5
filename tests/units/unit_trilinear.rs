//! Filter unit: `lerp` exhaustive at 8 bits (2^24 cases per rounding mode) and random at 16 bits
//! vs exact rationals; bilinear/trilinear vs the f64 twin within the documented LSB bound.

use crate::rng_common::Rng;
use hw_model::config::{HwConfig, TrilinearConfig};
use hw_model::fixed::Rounding;
use hw_model::trilinear::{
    bilinear, lerp, trilinear, trilinear_cost, trilinear_error_bound_q8, Level, TrilinearTrace,
};
use hw_model::wrap::WrapMode;
use texsim::reference::{bilinear_f64, trilinear_f64, LevelF};

const ROUNDINGS: [Rounding; 3] = [Rounding::Truncate, Rounding::HalfUp, Rounding::HalfEven];
const MODES: [WrapMode; 3] = [WrapMode::Repeat, WrapMode::ClampToEdge, WrapMode::Mirror];

/// Exact `(a (2^wb - w) + b w) / 2^wb` rounded by `mode`, via rational comparison.
fn exact_lerp(a: u32, b: u32, w: u32, wb: u32, mode: Rounding) -> u32 {
    let den = 1u64 << wb;
    let num = u64::from(a) * (den - u64::from(w)) + u64::from(b) * u64::from(w);
    let q = num / den;
    let r = num % den;
    (match mode {
        Rounding::Truncate => q,
        Rounding::HalfUp => q + u64::from(2 * r >= den),
        Rounding::HalfEven => q + u64::from(2 * r > den || (2 * r == den && q % 2 == 1)),
    }) as u32
}

#[test]
fn lerp_exhaustive_8_bit() {
    for mode in ROUNDINGS {
        for a in 0u32..256 {
            for b in 0u32..256 {
                for w in 0u32..=256 {
                    let got = lerp(a, b, w, 8, mode);
                    let want = exact_lerp(a, b, w, 8, mode);
                    if got != want {
                        panic!("lerp({a},{b},{w}) {mode:?} = {got}, want {want}");
                    }
                }
            }
        }
    }
}

#[test]
fn lerp_random_16_bit() {
    let mut rng = Rng(0x7e_0001);
    for k in 0..3_000_000u32 {
        let wb = 1 + (k % 16);
        let mode = ROUNDINGS[(k / 16 % 3) as usize];
        let a = rng.below(65536) as u32;
        let b = rng.below(65536) as u32;
        let w = rng.below((1 << wb) + 1) as u32;
        let got = lerp(a, b, w, wb, mode);
        assert_eq!(
            got,
            exact_lerp(a, b, w, wb, mode),
            "lerp({a},{b},{w},{wb}) {mode:?}"
        );
        assert!(got >= a.min(b) && got <= a.max(b));
    }
}

struct Pyramid {
    dims: Vec<(u32, u32)>,
    fixed: Vec<Vec<[u16; 4]>>,
    float: Vec<Vec<[f32; 4]>>,
}

fn pyramid(rng: &mut Rng, texel_bits: u32) -> Pyramid {
    let mut w = 1 + rng.below(40) as u32;
    let mut h = 1 + rng.below(40) as u32;
    let levels = 1 + rng.below(5) as usize;
    let max = (1u64 << texel_bits) - 1;
    let mut p = Pyramid {
        dims: vec![],
        fixed: vec![],
        float: vec![],
    };
    for _ in 0..levels {
        let texels: Vec<[u16; 4]> = (0..w * h)
            .map(|_| [0; 4].map(|_: u16| rng.below(max + 1) as u16))
            .collect();
        let fl = texels
            .iter()
            .map(|t| t.map(|c| (f64::from(c) / max as f64) as f32))
            .collect();
        p.dims.push((w, h));
        p.fixed.push(texels);
        p.float.push(fl);
        w = (w / 2).max(1);
        h = (h / 2).max(1);
    }
    p
}

fn configs() -> Vec<(String, TrilinearConfig)> {
    let mut v: Vec<(String, TrilinearConfig)> = ["texram16", "d3d11", "vulkan-min", "cuda"]
        .iter()
        .filter_map(|n| HwConfig::preset(n).map(|c| (n.to_string(), c.trilinear)))
        .collect();
    let mut c = HwConfig::texram16().trilinear;
    c.texel_bits = 8;
    c.weight_bits = 8;
    c.filter_rounding = Rounding::Truncate;
    c.weight_rounding = Rounding::HalfUp;
    v.push(("t8w8".into(), c));
    v
}

#[test]
fn trilinear_vs_f64_within_bound() {
    let mut rng = Rng(0x7e_0002);
    let frac = 16u32;
    for (name, cfg) in configs() {
        for lfb in [0u32, 4, 8, 16] {
            let bound_bi = trilinear_error_bound_q8(&cfg, frac, false) as f64 / 256.0;
            let bound_tri = trilinear_error_bound_q8(&cfg, frac, true) as f64 / 256.0;
            let max = ((1u64 << cfg.texel_bits) - 1) as f64;
            let mut worst = 0.0f64;
            for _ in 0..40 {
                let p = pyramid(&mut rng, cfg.texel_bits);
                let lv: Vec<Level> = (0..p.dims.len())
                    .map(|i| Level {
                        width: p.dims[i].0,
                        height: p.dims[i].1,
                        texels: &p.fixed[i],
                    })
                    .collect();
                let lf: Vec<LevelF> = (0..p.dims.len())
                    .map(|i| LevelF {
                        width: p.dims[i].0,
                        height: p.dims[i].1,
                        texels: &p.float[i],
                    })
                    .collect();
                for k in 0..2_000u32 {
                    let wrap = [MODES[(k % 3) as usize], MODES[(k / 3 % 3) as usize]];
                    let u = rng.below(6 << frac) as i64 - (3 << frac);
                    let v = rng.below(6 << frac) as i64 - (3 << frac);
                    let lod = rng.below(((lv.len() as u64) + 2) << lfb) as i64 - (1 << lfb);
                    let got = trilinear(&lv, u, v, frac, lod, lfb, wrap, &cfg, None);
                    let s = 2f64.powi(-(frac as i32));
                    let lod_f = lod as f64 * 2f64.powi(-(lfb as i32));
                    let want = trilinear_f64(&lf, u as f64 * s, v as f64 * s, lod_f, wrap);
                    let two = lod > 0
                        && (lod >> lfb) < lv.len() as i64 - 1
                        && lod & ((1 << lfb) - 1) != 0;
                    let bound = if two { bound_tri } else { bound_bi } + 0.01;
                    for c in 0..4 {
                        let e = (f64::from(got[c]) - want[c] * max).abs();
                        assert!(
                            e <= bound,
                            "{name} lfb={lfb}: err {e} > {bound} (u={u} v={v} lod={lod})"
                        );
                        worst = worst.max(e);
                    }
                }
            }
            println!(
                "{name:10} lod_frac_bits={lfb:2}: max |err| {worst:8.3} LSB (bound {bound_tri:.3})"
            );
        }
    }
}

#[test]
fn bilinear_vs_f64_and_trace() {
    let mut rng = Rng(0x7e_0003);
    let cfg = HwConfig::texram16().trilinear;
    let bound = trilinear_error_bound_q8(&cfg, 16, false) as f64 / 256.0 + 0.01;
    for _ in 0..50 {
        let p = pyramid(&mut rng, 16);
        let l = Level {
            width: p.dims[0].0,
            height: p.dims[0].1,
            texels: &p.fixed[0],
        };
        let f = LevelF {
            width: p.dims[0].0,
            height: p.dims[0].1,
            texels: &p.float[0],
        };
        for k in 0..20_000u32 {
            let wrap = [MODES[(k % 3) as usize], MODES[(k / 3 % 3) as usize]];
            let u = rng.below(1 << 18) as i64 - (1 << 17);
            let v = rng.below(1 << 18) as i64 - (1 << 17);
            let got = bilinear(&l, u, v, 16, wrap, &cfg, None);
            let want = bilinear_f64(&f, u as f64 / 65536.0, v as f64 / 65536.0, wrap);
            for c in 0..4 {
                assert!((f64::from(got[c]) - want[c] * 65535.0).abs() <= bound);
            }
            let mut tr = TrilinearTrace::default();
            let a = trilinear(&[l], u, v, 16, 0, 8, wrap, &cfg, Some(&mut tr));
            let b = trilinear(&[l], u, v, 16, 0, 8, wrap, &cfg, None);
            assert_eq!(a, b);
            assert_eq!(tr.levels_used, 1);
            assert_eq!(tr.result, a);
            assert_eq!(tr.level[0].result.map(|x| x as u16), a);
            for (i, &(x, y)) in tr.level[0].coords.iter().enumerate() {
                assert_eq!(
                    tr.level[0].texels[i],
                    p.fixed[0][(y * l.width + x) as usize]
                );
            }
        }
    }
}

#[test]
fn lod_rule_and_trace() {
    let cfg = HwConfig::texram16().trilinear;
    let t0 = vec![[100u16, 200, 300, 400]; 16];
    let t1 = vec![[1000u16, 2000, 3000, 4000]; 4];
    let t2 = vec![[9000u16, 9000, 9000, 9000]; 1];
    let lv = [
        Level {
            width: 4,
            height: 4,
            texels: &t0,
        },
        Level {
            width: 2,
            height: 2,
            texels: &t1,
        },
        Level {
            width: 1,
            height: 1,
            texels: &t2,
        },
    ];
    let w = [WrapMode::Repeat; 2];
    let run = |lod: i64, tr: Option<&mut TrilinearTrace>| {
        trilinear(&lv, 5000, 7000, 16, lod, 8, w, &cfg, tr)
    };
    assert_eq!(run(-1000, None), [100, 200, 300, 400]);
    assert_eq!(run(0, None), [100, 200, 300, 400]);
    assert_eq!(run(256, None), [1000, 2000, 3000, 4000]);
    assert_eq!(run(512, None), [9000; 4]);
    assert_eq!(run(100_000, None), [9000; 4]);
    let mut tr = TrilinearTrace::default();
    // lod = 0.5: halfway between level 0 and 1.
    assert_eq!(run(128, Some(&mut tr)), [550, 1100, 1650, 2200]);
    assert_eq!(
        (
            tr.levels_used,
            tr.level_weight,
            tr.level[0].level,
            tr.level[1].level
        ),
        (2, 128, 0, 1)
    );
    assert_eq!(trilinear(&[], 0, 0, 16, 0, 8, w, &cfg, None), [0; 4]);
    let g = hw_model::timing_config::DEFAULT_GATE_LEVELS_PER_CYCLE;
    assert_eq!(trilinear_cost(&cfg, 2, g).texels, 8);
    assert_eq!(trilinear_cost(&cfg, 1, g).texels, 4);
    // Hand-set cycle fields override the derived latencies.
    let mut set = cfg.clone();
    set.bilinear_cycles = hw_model::datapath::Cycles::Fixed(3);
    set.level_lerp_cycles = hw_model::datapath::Cycles::Fixed(2);
    assert_eq!(trilinear_cost(&set, 2, g).cycles, 2 * 3 + 2);
    assert_eq!(trilinear_cost(&set, 1, g).cycles, 3);
    assert_eq!(
        trilinear_cost(&cfg, 2, g).cycles,
        hw_model::trilinear::datapath(&cfg, 2).latency(g)
    );
}
