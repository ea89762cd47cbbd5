//! Wrap unit vs an exact integer model (floor division, rational weight rounding, independent
//! wrap formulas): exhaustive at 8 bits (all 2^24 pairs of a 16-bit coordinate with 8 fraction
//! bits and a size 1..=256, every rounding and mode), a coordinate/size/mode/width grid for the
//! other widths, seeded random beyond it, and vs the f64 twin.

use crate::rng_common::Rng;
use hw_model::config::{HwConfig, TrilinearConfig};
use hw_model::fixed::Rounding;
use hw_model::wrap::{wrap, WrapMode, WrapOut};
use texsim::reference::wrap_f64;

const MODES: [WrapMode; 3] = [WrapMode::Repeat, WrapMode::ClampToEdge, WrapMode::Mirror];
const ROUNDINGS: [Rounding; 3] = [Rounding::Truncate, Rounding::HalfUp, Rounding::HalfEven];

fn model_index(i: i128, n: i128, mode: WrapMode) -> u32 {
    (match mode {
        WrapMode::Repeat => ((i % n) + n) % n,
        WrapMode::ClampToEdge => i.max(0).min(n - 1),
        WrapMode::Mirror => {
            let period = i.div_euclid(n);
            let r = i.rem_euclid(n);
            if period % 2 == 0 {
                r
            } else {
                n - 1 - r
            }
        }
    }) as u32
}

/// Exact model: s = (coord * size - 1/2) as a rational with denominator 2^(frac+1).
fn model(coord: i64, frac: u32, size: u32, mode: WrapMode, wb: u32, rnd: Rounding) -> WrapOut {
    let den = 1i128 << (frac + 1);
    let num = i128::from(coord) * i128::from(size) * 2 - (1i128 << frac);
    let mut i0 = num.div_euclid(den);
    let r = num.rem_euclid(den); // fraction = r / den
                                 // weight = round(r * 2^wb / den)
    let wn = r << wb;
    let q = wn / den;
    let rr = wn % den;
    let mut w = match rnd {
        Rounding::Truncate => q,
        Rounding::HalfUp => q + i128::from(2 * rr >= den),
        Rounding::HalfEven => q + i128::from(2 * rr > den || (2 * rr == den && q % 2 == 1)),
    };
    if w == 1i128 << wb {
        i0 += 1;
        w = 0;
    }
    let n = i128::from(size);
    WrapOut {
        i0: model_index(i0, n, mode),
        i1: model_index(i0 + 1, n, mode),
        weight: w as u32,
    }
}

fn tcfg(wb: u32, rnd: Rounding) -> TrilinearConfig {
    let mut c = HwConfig::texram16().trilinear;
    c.weight_bits = wb;
    c.weight_rounding = rnd;
    c
}

#[test]
fn exhaustive_grid() {
    let mut n = 0u64;
    for wb in [0u32, 1, 4, 8, 9, 16] {
        for rnd in ROUNDINGS {
            let c = tcfg(wb, rnd);
            for mode in MODES {
                for size in 1u32..=40 {
                    for coord in -1200i64..1200 {
                        let got = wrap(coord, 8, size, mode, &c);
                        let want = model(coord, 8, size, mode, wb, rnd);
                        assert_eq!(
                            got, want,
                            "coord={coord} size={size} {mode:?} wb={wb} {rnd:?}"
                        );
                        assert!(got.i0 < size && got.i1 < size && got.weight < (1 << wb).max(1));
                        n += 1;
                    }
                }
            }
        }
    }
    assert!(n > 1_000_000);
}

#[test]
fn random_wide() {
    let mut rng = Rng(0x3a_0001);
    for k in 0..1_000_000u32 {
        let wb = (rng.next() % 17) as u32;
        let rnd = ROUNDINGS[(k % 3) as usize];
        let mode = MODES[(k / 3 % 3) as usize];
        let frac = 4 + (rng.next() % 21) as u32;
        let size = 1 + (rng.next() % 70_000) as u32;
        let bits = 1 + (rng.next() % 44) as u32;
        let coord = (rng.next() >> (64 - bits)) as i64 - (1i64 << (bits - 1));
        let c = tcfg(wb, rnd);
        let got = wrap(coord, frac, size, mode, &c);
        assert_eq!(
            got,
            model(coord, frac, size, mode, wb, rnd),
            "coord={coord} frac={frac} size={size}"
        );
    }
    // Extreme coordinates do not overflow and still wrap exactly.
    let c = tcfg(8, Rounding::HalfEven);
    for coord in [i64::MIN, i64::MAX, i64::MIN + 1, i64::MAX - 1] {
        for mode in MODES {
            for size in [1u32, 3, 256, u32::MAX] {
                assert_eq!(
                    wrap(coord, 4, size, mode, &c),
                    model(coord, 4, size, mode, 8, Rounding::HalfEven)
                );
            }
        }
    }
}

/// 1M seeded coordinates within 3 of either end of the 64-bit path (`fits_i64_on`:
/// `|coord| size < 2^61`) on sizes of every bit length up to `u32::MAX`, both sides of each
/// end taken, and at twice the end on the widest sizes of each bit length (where `2 coord
/// size` leaves `i64`), against the exact model.
#[test]
fn ends_of_the_64_bit_path() {
    let mut rng = Rng(0x3a_0002);
    let (mut narrow, mut wide) = (0u32, 0u32);
    for k in 0..1_000_000u32 {
        let wb = (rng.next() % 17) as u32;
        let rnd = ROUNDINGS[(k % 3) as usize];
        let mode = MODES[(k / 3 % 3) as usize];
        let frac = 4 + (rng.next() % 27) as u32;
        let len = 1 + (rng.next() % 32) as u32;
        let top = ((1u64 << len) - 1) as u32;
        let (size, reach) = if k % 4 < 2 {
            (
                ((top >> 1) + 1) | (rng.next() as u32 & (top >> 1)),
                1u64 << 61,
            )
        } else {
            (top - ((rng.next() % 3) as u32).min(top >> 1), 1u64 << 62)
        };
        let end = reach.div_ceil(u64::from(size)) as i64;
        let coord = if k % 2 == 0 { end } else { -end } + (rng.next() % 7) as i64 - 3;
        if hw_model::wrap::fits_i64(coord, frac, size) {
            narrow += 1;
        } else {
            wide += 1;
        }
        assert_eq!(
            wrap(coord, frac, size, mode, &tcfg(wb, rnd)),
            model(coord, frac, size, mode, wb, rnd),
            "coord={coord} frac={frac} size={size} {mode:?} wb={wb} {rnd:?}"
        );
    }
    assert!(narrow > 200_000 && wide > 600_000, "{narrow} {wide}");
}

#[test]
fn nearest_like_with_zero_weight_bits() {
    let c = tcfg(0, Rounding::HalfUp);
    // coord = (i + 0.5)/size +- a bit selects texel i.
    for size in 1u32..20 {
        for i in 0..size {
            for delta in [-100i64, 0, 100] {
                let coord = ((2 * i64::from(i) + 1) << 15) / i64::from(size) + delta;
                let o = wrap(coord, 16, size, WrapMode::ClampToEdge, &c);
                assert_eq!((o.i0, o.weight), (i, 0));
            }
        }
    }
}

#[test]
fn twin_agrees() {
    let mut rng = Rng(0x3a_0002);
    for k in 0..300_000u32 {
        let wb = [4u32, 8, 16][(k % 3) as usize];
        let rnd = ROUNDINGS[(k / 3 % 3) as usize];
        let mode = MODES[(k / 9 % 3) as usize];
        let size = 1 + (rng.next() % 5000) as u32;
        let coord = (rng.next() % (1 << 22)) as i64 - (1 << 21);
        let got = wrap(coord, 16, size, mode, &tcfg(wb, rnd));
        let (a, b, w) = wrap_f64(coord as f64 / 65536.0, size, mode);
        let wq = f64::from(got.weight) / f64::from(1u32 << wb);
        let tol = if rnd == Rounding::Truncate { 1.0 } else { 0.5 } * 2f64.powi(-(wb as i32));
        // Compare the filtered value of a 1-D texture t(i) in [0, 1): |hw - float| <= tol.
        let t = |i: u32| f64::from((i.wrapping_mul(2_654_435_761)) >> 16) / 65536.0;
        let hw = t(got.i0) + (t(got.i1) - t(got.i0)) * wq;
        let fl = t(a) + (t(b) - t(a)) * w;
        assert!(
            (hw - fl).abs() <= tol + 1e-12,
            "coord={coord} size={size} {mode:?}: {hw} vs {fl}"
        );
        if (a, b) == (got.i0, got.i1) && w < 1.0 - tol {
            assert!((wq - w).abs() <= tol + 1e-12, "w {wq} vs {w}");
        }
    }
}

/// Exhaustive at 8 bits: every 16-bit coordinate with 8 fraction bits (-128.0 .. 128.0 in
/// steps of 1/256) on every texture size 1..=256, i.e. all 2^24 (coordinate, size) pairs, each
/// for the three roundings and the three modes at 8 weight bits, against the exact rational.
#[test]
fn exhaustive_8_bit() {
    let cfgs = ROUNDINGS.map(|r| tcfg(8, r));
    let mut n = 0u64;
    for size in 1u32..=256 {
        let sz = i128::from(size);
        for coord in i64::from(i16::MIN)..=i64::from(i16::MAX) {
            // s = coord * size / 256 - 1/2 = num / 512.
            let num = i128::from(coord) * sz * 2 - 256;
            let (q, r) = (num.div_euclid(512), num.rem_euclid(512));
            for (rnd, c) in ROUNDINGS.iter().zip(&cfgs) {
                // weight = r * 2^8 / 512 = r / 2, rounded; a carry to 256 moves to the next texel.
                let (wq, half) = (r / 2, r % 2 == 1);
                let w = match rnd {
                    Rounding::Truncate => wq,
                    Rounding::HalfUp => wq + i128::from(half),
                    Rounding::HalfEven => wq + i128::from(half && wq % 2 == 1),
                };
                let (i0, w) = if w == 256 { (q + 1, 0) } else { (q, w) };
                for mode in MODES {
                    let want = WrapOut {
                        i0: model_index(i0, sz, mode),
                        i1: model_index(i0 + 1, sz, mode),
                        weight: w as u32,
                    };
                    assert_eq!(
                        wrap(coord, 8, size, mode, c),
                        want,
                        "coord={coord} size={size} {mode:?} {rnd:?}"
                    );
                    n += 1;
                }
            }
        }
    }
    assert_eq!(n, 9 << 24);
}

/// The f64 twin's addressing as first written: `floor` and `rem_euclid` in f64 (the
/// independent checker of `wrap_index_f64`'s integer path and `wrap_f64`'s `floor_exact`).
fn wrap_index_f64_formula(i: f64, size: u32, mode: WrapMode) -> u32 {
    let n = f64::from(size.max(1));
    let r = match mode {
        WrapMode::Repeat => i.rem_euclid(n),
        WrapMode::ClampToEdge => i.clamp(0.0, n - 1.0),
        WrapMode::Mirror => {
            let m = i.rem_euclid(2.0 * n);
            if m >= n {
                2.0 * n - 1.0 - m
            } else {
                m
            }
        }
    };
    if r.is_nan() {
        0
    } else {
        r as u32
    }
}

/// A double of every kind the twin meets or could: integers of every bit length, fractions,
/// signed zeros, the ends of the exact `i64` path (2^53 and its neighbours), huge values,
/// infinities and NaN.
fn any_double(rng: &mut Rng) -> f64 {
    let special = [
        0.0,
        -0.0,
        0.5,
        -0.5,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        9_007_199_254_740_992.0,
        -9_007_199_254_740_992.0,
        9_007_199_254_740_991.0,
        -9_007_199_254_740_991.0,
        9_007_199_254_740_994.0,
        9.3e18,
        -9.3e18,
        1e300,
        f64::MIN_POSITIVE,
    ];
    let sign = if rng.next() & 1 == 0 { 1.0 } else { -1.0 };
    match rng.below(4) {
        0 => special[rng.below(special.len() as u64) as usize],
        1 => sign * (rng.next() >> rng.below(64)) as f64,
        2 => sign * (rng.next() >> rng.below(64)) as f64 / f64::from(1u32 << rng.below(31)),
        _ => f64::from_bits(rng.next()),
    }
}

/// `wrap_index_f64` (an `i64` path for integral indices below 2^53) and `wrap_f64`
/// (`floor_exact`) equal the f64 formulas bit for bit: 3M seeded indices and coordinates of
/// every kind, on every mode and sizes from 0 to `u32::MAX`.
#[test]
fn f64_twin_addressing_equals_the_f64_formulas() {
    use texsim::reference::wrap_index_f64;
    let mut rng = Rng(0x3a_0003);
    for k in 0..3_000_000u32 {
        let mode = MODES[(k % 3) as usize];
        let size = match rng.below(4) {
            0 => rng.below(5) as u32,
            1 => u32::MAX - rng.below(3) as u32,
            _ => (rng.next() >> rng.below(64)) as u32,
        };
        let i = if k % 2 == 0 {
            any_double(&mut rng).floor()
        } else {
            any_double(&mut rng)
        };
        assert_eq!(
            wrap_index_f64(i, size, mode),
            wrap_index_f64_formula(i, size, mode),
            "i={i:e} size={size} {mode:?}"
        );
        let coord = any_double(&mut rng);
        let s = coord * f64::from(size.max(1)) - 0.5;
        let i0 = s.floor();
        let want = (
            wrap_index_f64_formula(i0, size, mode),
            wrap_index_f64_formula(i0 + 1.0, size, mode),
            (s - i0).to_bits(),
        );
        let (a, b, w) = wrap_f64(coord, size, mode);
        assert_eq!(
            (a, b, w.to_bits()),
            want,
            "coord={coord:e} size={size} {mode:?}"
        );
    }
}
