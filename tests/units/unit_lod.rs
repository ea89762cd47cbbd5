//! LOD unit vs log2 in f64: exhaustive over all (du/dx, dv/dx) in 0..4096^2 (2^24 cases),
//! seeded random otherwise; exact on powers of two and Pythagorean lengths.

use crate::rng_common::Rng;
use hw_model::config::{HwConfig, LodConfig};
use hw_model::fixed::SatCounter;
use hw_model::lod::{lod, lod_zero};
use texsim::reference::lod_f64;

fn cfg(f: u32) -> LodConfig {
    let mut c = HwConfig::texram16().lod;
    c.lod_frac_bits = f;
    c
}

/// The bound of `hw_model::lod`'s doc comment: a result may be 1 LSB below the floor only when
/// `lambda * 2^F` lies less than `F * 2^(F-31)` LSB above an integer (none for F = 0).
fn near(f: u32) -> f64 {
    f64::from(f) * 2f64.powi(f as i32 - 31)
}

/// Error of the f64 reference `x = lambda * 2^F` (|lambda| < 64, log2 of an f64): far below
/// 2^(F-40) LSB; it only decides on which side of an integer `x` falls.
fn slack(f: u32) -> f64 {
    2f64.powi(f as i32 - 40)
}

thread_local! { static MAXD: std::cell::Cell<f64> = const { std::cell::Cell::new(0.0) }; }

/// Checks `got` against `x = lambda * 2^F` (f64): equal to floor(x), or 1 below it only when
/// x is within `near(F)` of an integer from above (or f64 put x just beside an integer).
/// Returns whether it was the 1-below case; records the largest distance as a fraction of
/// `near(F)`.
fn check(got: i64, x: f64, f: u32, ctx: &str) -> bool {
    let fl = x.floor();
    let g = got as f64;
    if g == fl {
        return false;
    }
    if g == fl + 1.0 && fl + 1.0 - x < slack(f) {
        return false;
    }
    let bound = near(f) + slack(f);
    assert!(
        g == fl - 1.0 && x - fl < bound,
        "{ctx}: got {got}, exact {x}, 1-low bound {bound:e} LSB (F = {f})"
    );
    MAXD.with(|m| m.set(m.get().max((x - fl) / bound)));
    true
}

#[test]
fn exhaustive_12_bit_pairs() {
    let c = cfg(16);
    let scale = 65536.0;
    let mut low = 0u32;
    for a in 0i64..4096 {
        for b in 0i64..4096 {
            let mut sat = SatCounter::default();
            let got = lod([a, b, 0, 0], 0, &c, &mut sat);
            if a == 0 && b == 0 {
                assert_eq!(got, lod_zero(16));
                continue;
            }
            let x = lod_f64([a as f64, b as f64, 0.0, 0.0]) * scale;
            if check(got, x, 16, &format!("({a},{b})")) {
                low += 1;
            }
        }
    }
    let d = MAXD.with(|m| m.get()) * (near(16) + slack(16));
    println!("exhaustive 2^24, F=16: {low} results 1 LSB below floor, all within {d:.2e} LSB above an integer (bound {:.2e})", near(16));
    assert!(low < 1000);
}

#[test]
fn random_all_widths() {
    let mut rng = Rng(0x10d_0001);
    let mut low = 0u32;
    for k in 0..1_500_000u32 {
        let f = k % 17;
        let c = cfg(f);
        let frac = [0, 4, 8, 16, 24][(k / 17 % 5) as usize];
        let bits = 1 + (rng.next() % 40) as u32;
        let mut d = [0i64; 4];
        for x in &mut d {
            *x = (rng.next() >> (64 - bits)) as i64 - (1i64 << (bits - 1));
        }
        let mut sat = SatCounter::default();
        let got = lod(d, frac, &c, &mut sat);
        let s = 2f64.powi(-(frac as i32));
        let lam = lod_f64([
            d[0] as f64 * s,
            d[1] as f64 * s,
            d[2] as f64 * s,
            d[3] as f64 * s,
        ]);
        if lam <= -32.0 {
            assert_eq!(got, lod_zero(f));
            continue;
        }
        if check(
            got,
            lam * 2f64.powi(f as i32),
            f,
            &format!("{d:?} frac={frac} F={f}"),
        ) {
            low += 1;
        }
        assert_eq!(sat, SatCounter::default());
    }
    let r = MAXD.with(|m| m.get());
    println!("random 1.5M: {low} results 1 LSB below floor, at most {r:.3} of the bound");
}

#[test]
fn exact_cases() {
    let mut sat = SatCounter::default();
    for f in [0, 4, 8, 16] {
        let c = cfg(f);
        for k in 0..40i64 {
            for frac in [0u32, 8, 16] {
                let v = 1i64 << k;
                let want = (k - i64::from(frac)) << f;
                assert_eq!(lod([v, 0, 0, 0], frac, &c, &mut sat), want.max(lod_zero(f)));
                assert_eq!(
                    lod([0, -v, v / 2, 0], frac, &c, &mut sat),
                    want.max(lod_zero(f))
                );
                assert_eq!(
                    lod([3 * v, 4 * v, 0, 0], frac, &c, &mut sat) >> f,
                    (k - i64::from(frac)) + 2
                );
            }
        }
        assert_eq!(lod([0; 4], 0, &c, &mut sat), -(32 << f));
        // sqrt(2): lambda = 1/2 exactly.
        assert_eq!(lod([1, 1, 0, 0], 0, &c, &mut sat), (1 << f) >> 1);
    }
    // rho = 2^-40: clamped to -32 and counted.
    let c = cfg(8);
    assert_eq!(lod([1, 0, 0, 0], 40, &c, &mut sat), lod_zero(8));
    assert_eq!(sat.saturated, 1);
    // Extreme inputs do not overflow.
    let m = lod([i64::MIN, i64::MIN, i64::MAX, 0], 0, &c, &mut sat);
    assert_eq!(m, (63 << 8) + 128);
}

/// `lod_log2 = piecewise-linear` (llvmpipe's `lp_build_fast_log2`): exhaustive over all
/// (du/dx, dv/dx) in 0..4096^2 at F = 8 and 16, equal to floor of its f64 twin times 2^F (exact
/// in f64: L < 2^25) and within the doc comment's bound of 0.04305 below the exact lambda.
#[test]
fn piecewise_linear_log2_exhaustive_12_bit_pairs() {
    use hw_model::config::LodLog2;
    use texsim::reference::lod_mode_f64;
    for f in [8u32, 16] {
        let mut c = cfg(f);
        c.lod_log2 = LodLog2::PiecewiseLinear;
        let scale = f64::from(1u32 << f);
        let mut worst = 0f64;
        for a in 0i64..4096 {
            for b in 0i64..4096 {
                let mut sat = SatCounter::default();
                let got = lod([a, b, 0, 0], 0, &c, &mut sat);
                if a == 0 && b == 0 {
                    assert_eq!(got, lod_zero(f));
                    continue;
                }
                let d = [a as f64, b as f64, 0.0, 0.0];
                let pwl = lod_mode_f64(d, LodLog2::PiecewiseLinear);
                assert_eq!(got, (pwl * scale).floor() as i64, "({a},{b}) F = {f}");
                let dev = lod_f64(d) - pwl;
                assert!((-1e-12..=0.04305).contains(&dev), "({a},{b}): {dev}");
                worst = worst.max(dev);
            }
        }
        assert!(worst > 0.043, "the bound is reached: {worst}");
    }
}

/// Piecewise-linear mode with fraction bits in the derivatives (`frac` 0..=20) and large
/// lengths: 2M seeded random cases against the f64 twin (exact: the f64 values are exact here).
#[test]
fn piecewise_linear_log2_random_with_fraction_bits() {
    use hw_model::config::LodLog2;
    use texsim::reference::lod_mode_f64;
    let mut rng = Rng(0x11b);
    for i in 0..2_000_000u32 {
        let f = i % 17;
        let frac = (i / 17) % 21;
        let mut c = cfg(f);
        c.lod_log2 = LodLog2::PiecewiseLinear;
        let d: [i64; 4] = std::array::from_fn(|_| {
            let bits = 1 + (rng.next() % 24) as u32;
            (rng.next() % (1u64 << bits)) as i64 - (1i64 << (bits - 1))
        });
        let mut sat = SatCounter::default();
        let got = lod(d, frac, &c, &mut sat);
        let s = f64::from(1u32 << frac);
        let df = d.map(|x| x as f64 / s);
        if d.iter().all(|&x| x == 0) {
            assert_eq!(got, lod_zero(f));
            continue;
        }
        let want = (lod_mode_f64(df, LodLog2::PiecewiseLinear) * f64::from(1u32 << f)).floor();
        assert_eq!(
            got,
            (want as i64).max(lod_zero(f)),
            "{d:?} frac {frac} F {f}"
        );
    }
}

/// 800k runs of lanes (a range of 32 lanes, as the pipeline's runs): `lod_lanes` equals one
/// `lod_with` per lane on the same derivatives (values and saturation counts) and leaves the
/// other lanes as they were, over both log2 modes, every `lod_frac_bits`, coordinate
/// fractions up to 40 bits (from 33 on, small footprints take the clamp), level-0 sizes that
/// are and are not powers of two, and derivatives from zero to beyond `2^31`.
#[test]
fn lod_lanes_matches_lod_with() {
    use hw_model::config::LodLog2;
    use hw_model::lod::{lod_lanes, lod_with, LodSetup};
    const L: usize = 32;
    let mut rng = Rng(0x10d_1a4e);
    let (mut lanes_seen, mut clamped) = (0u64, 0u64);
    for case in 0..800_000u32 {
        let mut c = cfg(rng.int_in(0, 16) as u32);
        if rng.below(4) == 0 {
            c.lod_log2 = LodLog2::PiecewiseLinear;
        }
        let frac = rng.int_in(0, 40) as u32;
        let k = LodSetup::new(frac, &c);
        let sizes = [1, 3, 256, 1000, 1024, 4096];
        let size = [0; 2].map(|_| sizes[rng.below(sizes.len() as u64) as usize]);
        let start = rng.int_in(0, L as i64 - 1) as usize;
        let end = rng.int_in(start as i64 + 1, L as i64) as usize;
        let mut uv = [[[0i64; L]; 2]; 3];
        let step_bits = [0, 1, 4, 12, 20, 28, 34][rng.below(7) as usize];
        let step = |rng: &mut Rng| {
            let bits = if rng.below(8) == 0 {
                rng.below(35) as u32
            } else {
                step_bits
            };
            let m = (1i64 << bits) - 1;
            rng.int_in(-m, m)
        };
        let [s0, s1, s2] = &mut uv;
        for ((a0, a1), a2) in s0.iter_mut().zip(s1.iter_mut()).zip(s2.iter_mut()) {
            for ((u0, u1), u2) in a0.iter_mut().zip(a1.iter_mut()).zip(a2.iter_mut()) {
                *u0 = rng.int_in(-(1 << 30), 1 << 30);
                *u1 = *u0 + step(&mut rng);
                *u2 = *u0 + step(&mut rng);
            }
        }
        let before = [0i64; L].map(|_| rng.next() as i64);
        let mut got = before;
        let mut sat = SatCounter::default();
        lod_lanes(&k, &uv, start..end, (size[0], size[1]), &mut sat, &mut got);
        let mut sat_ref = SatCounter::default();
        for j in 0..L {
            let want = if (start..end).contains(&j) {
                let (w, h) = (i64::from(size[0]), i64::from(size[1]));
                let d = [
                    (uv[1][0][j] - uv[0][0][j]) * w,
                    (uv[1][1][j] - uv[0][1][j]) * h,
                    (uv[2][0][j] - uv[0][0][j]) * w,
                    (uv[2][1][j] - uv[0][1][j]) * h,
                ];
                lod_with(&k, d, &mut sat_ref)
            } else {
                before[j]
            };
            assert_eq!(got[j], want, "case {case} lane {j} ({c:?}, frac {frac})");
        }
        assert_eq!(sat, sat_ref, "case {case}: saturation counts");
        lanes_seen += (end - start) as u64;
        clamped += sat.saturated;
    }
    assert!(
        lanes_seen > 6_000_000 && clamped > 10_000,
        "{lanes_seen} lanes, {clamped} clamped"
    );
}
