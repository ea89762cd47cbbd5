//! Footprint assembly (Texram's anisotropic filter): the fixed unit against its f64 twin, the
//! N = 1 identity with plain trilinear, the one-rounding average, and whole-frame behaviour
//! (renders, N x texels, deterministic, less blur than plain trilinear on the receding plane
//! against a supersampled image), and the adaptive probe count (`aniso_adaptive`).

use crate::rng_common::Rng;
use hw_model::config::LodConfig;
use hw_model::fixed::{round_shift_right, SatCounter};
use hw_model::footprint::{footprint, footprint_filter, probe_offset};
use hw_model::lod::{lod, lod_zero};
use hw_model::trilinear::{trilinear, Level};
use hw_model::wrap::WrapMode;
use hw_model::HwConfig;
use texsim::footprint_ref::{footprint_f64, probe_offset_f64};
use texsim::pipeline::{StageImpls, StageKind};
use texsim::render::{render, Maps, RenderOptions};
use texsim::scene;

fn signed(s: &mut Rng, bits: u32) -> i64 {
    let r = s.next();
    let b = (r >> 8) % (bits as u64 + 1);
    let mag = (r >> 16) & ((1u64 << b) - 1);
    if r & 1 == 1 {
        -(mag as i64)
    } else {
        mag as i64
    }
}

const FRAC: u32 = 24;

#[test]
fn lod_and_offsets_match_the_f64_twin() {
    let mut s = Rng(42);
    for f in [4u32, 8, 16] {
        let cfg = LodConfig {
            lod_frac_bits: f,
            lod_cycles: hw_model::datapath::Cycles::Fixed(2),
            lod_cycles_per_bit: hw_model::datapath::Cycles::Fixed(0),
            lod_log2: hw_model::config::LodLog2::Exact,
            lod_per_quad: false,
        };
        for _ in 0..400_000 {
            let base = [signed(&mut s, 26), signed(&mut s, 26)];
            let uv = [
                base,
                [base[0] + signed(&mut s, 22), base[1] + signed(&mut s, 22)],
                [base[0] + signed(&mut s, 22), base[1] + signed(&mut s, 22)],
            ];
            let size = (1u32 << (s.next() % 12), 1u32 << (s.next() % 12));
            let cap = 1u32 << (s.next() % 5);
            let adaptive = s.next() & 1 == 0;
            let mut sat = SatCounter::default();
            let fx = footprint(&uv, size, FRAC, cap, adaptive, &cfg, &mut sat);
            let uvf = uv.map(|p| p.map(|x| x as f64 / f64::from(1u32 << FRAC) / 1.0));
            let ff = footprint_f64(&uvf, size, cap, adaptive);
            let n = fx.probes;
            assert_eq!(n, ff.probes, "same probe count as the twin");
            if adaptive {
                // The anisotropy rounded up to a power of two, capped.
                let (w, h) = (f64::from(size.0), f64::from(size.1));
                let l2 = |p: [f64; 2]| {
                    ((p[0] - uvf[0][0]) * w).powi(2) + ((p[1] - uvf[0][1]) * h).powi(2)
                };
                let (a, b) = (l2(uvf[1]), l2(uvf[2]));
                let (lmaj, lmin) = (a.max(b), a.min(b));
                let nf = f64::from(n);
                assert!(n.is_power_of_two() && n <= cap);
                assert!(n == cap || lmaj <= nf * nf * lmin, "N={n} too small");
                assert!(n == 1 || lmaj > nf * nf / 4.0 * lmin, "N={n} too large");
            } else {
                assert_eq!(n, cap);
            }
            let scale = (1u64 << FRAC) as f64;
            assert_eq!(fx.axis.map(|a| a as f64 / scale), ff.axis);
            let exact = ff.lod * f64::from(1u32 << f);
            let got = fx.lod as f64;
            if got > lod_zero(f) as f64 {
                let d = exact - got;
                assert!(
                    (-1e-6..2.0 + 1e-6).contains(&d),
                    "F={f} N={n} uv={uv:?} size={size:?}: fixed {got} exact {exact}"
                );
            } else {
                assert!(exact < got + 2.0);
            }
            for i in 0..n {
                let o = probe_offset(&fx, i);
                let of = probe_offset_f64(&ff, i);
                for ax in 0..2 {
                    let e = (o[ax] as f64 - of[ax] * scale).abs();
                    assert!(e <= 0.5, "offset error {e} LSB");
                }
            }
        }
    }
}

fn level_data(s: &mut Rng, w: u32, h: u32) -> Vec<[u16; 4]> {
    (0..w * h)
        .map(|_| {
            let r = s.next();
            [
                r as u16,
                (r >> 16) as u16,
                (r >> 32) as u16,
                (r >> 48) as u16,
            ]
        })
        .collect()
}

#[test]
fn one_probe_is_plain_trilinear_and_the_average_rounds_once() {
    let mut s = Rng(9);
    let hw = HwConfig::texram16();
    let data: Vec<Vec<[u16; 4]>> = (0..6)
        .map(|l| level_data(&mut s, 32 >> l, 32 >> l))
        .collect();
    let levels: Vec<Level> = data
        .iter()
        .enumerate()
        .map(|(l, t)| Level {
            width: 32 >> l,
            height: 32 >> l,
            texels: t,
        })
        .collect();
    let wrap = [WrapMode::Repeat, WrapMode::Mirror];
    let lf = hw.lod.lod_frac_bits;
    for _ in 0..1_000_000 {
        let base = [signed(&mut s, 25), signed(&mut s, 25)];
        let uv = [
            base,
            [base[0] + signed(&mut s, 21), base[1] + signed(&mut s, 21)],
            [base[0] + signed(&mut s, 21), base[1] + signed(&mut s, 21)],
        ];
        let mut sat = SatCounter::default();
        // N = 1: the LOD unit's LOD and the trilinear unit's result, bit for bit.
        let f1 = footprint(&uv, (32, 32), FRAC, 1, false, &hw.lod, &mut sat);
        let d = [
            (uv[1][0] - uv[0][0]) * 32,
            (uv[1][1] - uv[0][1]) * 32,
            (uv[2][0] - uv[0][0]) * 32,
            (uv[2][1] - uv[0][1]) * 32,
        ];
        let l = lod(d, FRAC, &hw.lod, &mut sat);
        assert_eq!(f1.lod, l);
        let a = footprint_filter(
            &levels,
            base[0],
            base[1],
            FRAC,
            &f1,
            lf,
            wrap,
            &hw.trilinear,
            None,
        );
        let b = trilinear(
            &levels,
            base[0],
            base[1],
            FRAC,
            l,
            lf,
            wrap,
            &hw.trilinear,
            None,
        );
        assert_eq!(a, b);
        // N = 8: the exact sum of the probes, rounded once.
        let f8 = footprint(&uv, (32, 32), FRAC, 8, false, &hw.lod, &mut sat);
        let got = footprint_filter(
            &levels,
            base[0],
            base[1],
            FRAC,
            &f8,
            lf,
            wrap,
            &hw.trilinear,
            None,
        );
        let mut sum = [0i64; 4];
        for i in 0..8 {
            let o = probe_offset(&f8, i);
            let r = trilinear(
                &levels,
                base[0] + o[0],
                base[1] + o[1],
                FRAC,
                f8.lod,
                lf,
                wrap,
                &hw.trilinear,
                None,
            );
            for c in 0..4 {
                sum[c] += i64::from(r[c]);
            }
        }
        let want = sum.map(|x| round_shift_right(x, 3, hw.trilinear.filter_rounding) as u16);
        assert_eq!(got, want);
    }
}

fn plane(w: u32) -> scene::Scene {
    let mut s = scene::builtin("w1-plane").expect("scene");
    s.width = w;
    s.height = w;
    s
}

fn with_probes(n: u32) -> HwConfig {
    let mut hw = HwConfig::texram16();
    hw.trilinear.aniso_probes = n;
    hw
}

#[test]
fn aniso_renders_costs_n_times_texels_and_is_deterministic() {
    let s = plane(128);
    let base = with_probes(1);
    let maps = Maps::new(&s, base.trilinear.texel_bits);
    let opts = RenderOptions::default();
    let r1 = render(&s, &maps, &base, &opts).expect("render");
    let tex = |r: &texsim::render::Rendered| r.stats.stages[StageKind::Trilinear.index()].texels;
    for n in [2u32, 4, 16] {
        let hw = with_probes(n);
        let a = render(&s, &maps, &hw, &opts).expect("render");
        let b = render(&s, &maps, &hw, &opts).expect("render");
        assert_eq!(a.hw_image, b.hw_image, "deterministic");
        assert_eq!(tex(&a), u64::from(n) * tex(&r1), "N x texels");
        assert_ne!(
            a.hw_image, r1.hw_image,
            "footprint assembly changes the image"
        );
        // The fixed unit tracks its float twin closely.
        let e = a.stats.error_8bit.as_ref().expect("metrics");
        assert!(e.max_abs_lsb <= 2, "N={n}: max error {} LSB", e.max_abs_lsb);
    }
}

/// Mean absolute 8-bit difference between `img` and the 4x4 box-downsampled `ss`, over the
/// covered pixels of `mask`.
fn blur_error(img: &texsim::report::Image, ss: &texsim::report::Image, mask: &[bool]) -> f64 {
    let w = img.width as usize;
    let mut tot = 0.0;
    let mut n = 0.0;
    for y in 0..img.height as usize {
        for x in 0..w {
            if !mask[y * w + x] {
                continue;
            }
            for c in 0..3 {
                let mut acc = 0.0;
                for sy in 0..4 {
                    for sx in 0..4 {
                        let p = ss.px[(4 * y + sy) * 4 * w + 4 * x + sx];
                        acc += f64::from(p[c]);
                    }
                }
                tot += (acc / 16.0 - f64::from(img.px[y * w + x][c])).abs() / 257.0;
                n += 1.0;
            }
        }
    }
    tot / n
}

#[test]
fn aniso_reduces_blur_on_the_receding_plane() {
    let s = plane(96);
    let big = plane(384);
    let hw1 = with_probes(1);
    let maps = Maps::new(&s, hw1.trilinear.texel_bits);
    let float = RenderOptions {
        hw_impls: StageImpls::FLOAT,
        reference: false,
        ..Default::default()
    };
    let ss = render(&big, &maps, &hw1, &float).expect("supersampled");
    let mut errs = Vec::new();
    for n in [1u32, 4, 16] {
        let hw = with_probes(n);
        let r = render(&s, &maps, &hw, &RenderOptions::default()).expect("render");
        errs.push(blur_error(&r.hw_image, &ss.hw_image, &r.mask));
    }
    eprintln!(
        "blur error vs 4x4 supersampled (8-bit LSB, mean): N=1 {:.3}, N=4 {:.3}, N=16 {:.3}",
        errs[0], errs[1], errs[2]
    );
    assert!(
        errs[1] < errs[0],
        "aniso 4 {} vs trilinear {}",
        errs[1],
        errs[0]
    );
    assert!(
        errs[2] < errs[0],
        "aniso 16 {} vs trilinear {}",
        errs[2],
        errs[0]
    );
}

#[test]
fn adaptive_probes_follow_the_anisotropy_and_cost_what_they_take() {
    let s = plane(96);
    let big = plane(384);
    let maps = Maps::new(&s, HwConfig::texram16().trilinear.texel_bits);
    let float = RenderOptions {
        hw_impls: StageImpls::FLOAT,
        reference: false,
        ..Default::default()
    };
    let ss = render(&big, &maps, &with_probes(1), &float).expect("supersampled");
    let timed = RenderOptions {
        timing: true,
        ..Default::default()
    };
    let fixed16 = with_probes(16);
    let adaptive16 = HwConfig {
        trilinear: hw_model::config::TrilinearConfig {
            aniso_adaptive: true,
            ..fixed16.trilinear.clone()
        },
        ..fixed16.clone()
    };
    let run = |hw: &HwConfig| {
        let r = render(&s, &maps, hw, &timed).expect("render");
        let st = &r.stats.stages[StageKind::Trilinear.index()];
        let ev = r.events.as_ref().expect("events");
        let fps = ev.footprints.len() as u64;
        // The stage counts the probes each pixel took: 4 texels per footprint (8 on
        // two levels), as the timing model's event stream has them.
        assert!(
            4 * fps <= st.texels && st.texels <= 8 * fps,
            "{} vs {fps}",
            st.texels
        );
        let cycles = texsim::timing::simulate(ev, hw, "w1-plane").total_cycles;
        (
            blur_error(&r.hw_image, &ss.hw_image, &r.mask),
            st.texels,
            st.issue_cycles,
            cycles,
        )
    };
    let one = run(&with_probes(1));
    let f = run(&fixed16);
    let a = run(&adaptive16);
    eprintln!(
        "w1-plane 96x96 vs 4x4 supersampled, mean 8-bit LSB / trilinear texels / stage cycles / \
         timing cycles: N=1 {one:?}, fixed 16 {f:?}, adaptive <= 16 {a:?}"
    );
    assert!(
        a.1 < f.1 && a.1 > one.1,
        "texels between plain and fixed 16"
    );
    assert!(
        a.2 < f.2 && a.3 < f.3,
        "cheaper than fixed 16 in both cost models"
    );
    assert!(a.0 < one.0, "adaptive {} vs trilinear {}", a.0, one.0);
    assert!(a.0 <= f.0 * 1.1, "adaptive {} vs fixed 16 {}", a.0, f.0);
}
