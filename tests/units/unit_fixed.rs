//! `hw_model::fixed`: `round_shift_right`(`_wide`) vs exact i128 floor division for every mode,
//! shift and sign; `round_div_wide` vs an independent half-step formula; `Format::fit`/`requantize`
//! saturate and wrap with exact event counts.

use crate::rng_common::Rng;
use hw_model::fixed::{
    round_div_wide, round_shift_right, round_shift_right_wide, Format, Overflow, Rounding,
    SatCounter,
};

const ROUNDINGS: [Rounding; 3] = [Rounding::Truncate, Rounding::HalfUp, Rounding::HalfEven];

/// Exact rounding of x / 2^s for s <= 100 using i128 Euclidean division.
fn exact(x: i128, s: u32, mode: Rounding) -> i128 {
    let den = 1i128 << s;
    let q = x.div_euclid(den);
    let r = x.rem_euclid(den);
    if s == 0 {
        return x;
    }
    let half = den / 2;
    match mode {
        Rounding::Truncate => q,
        Rounding::HalfUp => q + i128::from(r >= half),
        Rounding::HalfEven => q + i128::from(r > half || (r == half && q.rem_euclid(2) == 1)),
    }
}

fn interesting(rng: &mut Rng) -> i64 {
    match rng.next() % 6 {
        0 => (rng.next() % 64) as i64 - 32,
        1 => i64::MIN + (rng.next() % 8) as i64,
        2 => i64::MAX - (rng.next() % 8) as i64,
        3 => {
            // Exact ties: odd multiple of a power of two.
            let k = rng.next() % 62;
            ((rng.next() as i64 >> 40) | 1) << k
        }
        _ => (rng.next() as i64) >> (rng.next() % 64),
    }
}

#[test]
fn round_shift_right_vs_exact() {
    let mut rng = Rng(0xf1_0001);
    for k in 0..1_500_000u32 {
        let x = interesting(&mut rng);
        let s = (rng.next() % 80) as u32;
        let mode = ROUNDINGS[(k % 3) as usize];
        let want = exact(i128::from(x), s, mode);
        assert_eq!(
            i128::from(round_shift_right(x, s, mode)),
            want,
            "x={x} s={s} {mode:?}"
        );
    }
    // Exhaustive small range: all x in -2^11..2^11, s in 0..14.
    for x in -2048i64..2048 {
        for s in 0..14 {
            for mode in ROUNDINGS {
                assert_eq!(
                    i128::from(round_shift_right(x, s, mode)),
                    exact(i128::from(x), s, mode)
                );
            }
        }
    }
}

#[test]
fn round_shift_right_wide_vs_exact() {
    let mut rng = Rng(0xf1_0002);
    for k in 0..1_000_000u32 {
        let hi = interesting(&mut rng);
        let x = (i128::from(hi) << (rng.next() % 60)) + i128::from(rng.next() % 1024);
        let s = (rng.next() % 120) as u32;
        let mode = ROUNDINGS[(k % 3) as usize];
        let want = exact(x, s, mode).clamp(i128::from(i64::MIN), i128::from(i64::MAX));
        assert_eq!(
            i128::from(round_shift_right_wide(x, s, mode)),
            want,
            "x={x} s={s} {mode:?}"
        );
    }
    for mode in ROUNDINGS {
        assert_eq!(
            round_shift_right_wide(i128::MIN, 128, mode),
            if mode == Rounding::Truncate { -1 } else { 0 }
        );
        assert_eq!(round_shift_right_wide(i128::MAX, 200, mode), 0);
        assert_eq!(
            round_shift_right_wide(-1, 127, mode),
            if mode == Rounding::Truncate { -1 } else { 0 }
        );
        assert_eq!(round_shift_right(i64::MIN, 63, mode), -1);
        assert_eq!(
            round_shift_right(i64::MIN, 64, mode),
            if mode == Rounding::Truncate { -1 } else { 0 }
        );
        assert_eq!(
            round_shift_right(-1, 90, mode),
            if mode == Rounding::Truncate { -1 } else { 0 }
        );
    }
}

/// `round_div_wide` against `floor((2x + den) / 2den)` (round half up) with the tie fixed to
/// even, and against the power-of-two divider `round_shift_right_wide`; exact ties, both
/// signs, saturation to i64, and `den <= 0` giving 0.
#[test]
fn round_div_wide_vs_half_step_formula() {
    let mut rng = Rng(0xf1_0003);
    for k in 0..1_000_000u32 {
        let den = match k % 4 {
            0 => (1i128 << (rng.next() % 24)) * ((1i128 << (1 + rng.next() % 16)) - 1),
            1 => 1i128 << (rng.next() % 60),
            _ => 1 + i128::from(rng.next() >> (rng.next() % 63)),
        };
        let x = match k % 5 {
            // Exact ties: an odd multiple of den / 2.
            0 if den % 2 == 0 => (den / 2) * (2 * i128::from(rng.next() as i32) + 1),
            1 => i128::from(interesting(&mut rng)) << (rng.next() % 40),
            _ => i128::from(rng.next() as i64) * i128::from(rng.next() % 4096),
        };
        let mode = ROUNDINGS[(k % 3) as usize];
        let up = (2 * x + den).div_euclid(2 * den);
        let tie = (2 * x + den).rem_euclid(2 * den) == 0;
        let want = match mode {
            Rounding::Truncate => x.div_euclid(den),
            Rounding::HalfUp => up,
            Rounding::HalfEven if tie && up.rem_euclid(2) == 1 => up - 1,
            Rounding::HalfEven => up,
        }
        .clamp(i128::from(i64::MIN), i128::from(i64::MAX));
        assert_eq!(
            i128::from(round_div_wide(x, den, mode)),
            want,
            "x={x} den={den} {mode:?}"
        );
        if den.count_ones() == 1 {
            let s = den.trailing_zeros();
            assert_eq!(
                round_div_wide(x, den, mode),
                round_shift_right_wide(x, s, mode)
            );
        }
    }
    for mode in ROUNDINGS {
        assert_eq!(round_div_wide(255 * 255 * 255, 255 * 255, mode), 255);
        assert_eq!(round_div_wide(i128::MAX, 3, mode), i64::MAX);
        assert_eq!(round_div_wide(i128::MIN, 3, mode), i64::MIN);
        assert_eq!(round_div_wide(7, 0, mode), 0);
        assert_eq!(round_div_wide(7, -2, mode), 0);
    }
    assert_eq!(round_div_wide(-3, 2, Rounding::HalfEven), -2);
    assert_eq!(round_div_wide(-3, 2, Rounding::HalfUp), -1);
    assert_eq!(round_div_wide(-3, 2, Rounding::Truncate), -2);
}

#[test]
fn fit_saturate_and_wrap_counts() {
    let mut rng = Rng(0xf1_0003);
    for k in 0..500_000u32 {
        let signed = k % 2 == 0;
        let int_bits = (rng.next() % 12) as u32;
        let frac_bits = (rng.next() % 12) as u32;
        let mut f = if signed {
            Format::signed(int_bits, frac_bits, Rounding::HalfEven)
        } else {
            Format::unsigned(int_bits, frac_bits, Rounding::HalfEven)
        };
        if k % 4 >= 2 {
            f.overflow = Overflow::Wrap;
        }
        let span = 1i64 << (int_bits + frac_bits + 3);
        let raw = (rng.next() % (2 * span as u64)) as i64 - span;
        let (lo, hi) = if signed {
            (
                -(1i64 << (int_bits + frac_bits)),
                (1i64 << (int_bits + frac_bits)) - 1,
            )
        } else {
            (0, (1i64 << (int_bits + frac_bits)) - 1)
        };
        let mut sat = SatCounter::default();
        let v = f.fit(raw, &mut sat);
        assert!(v >= lo && v <= hi);
        if raw >= lo && raw <= hi {
            assert_eq!((v, sat), (raw, SatCounter::default()));
        } else if f.overflow == Overflow::Saturate {
            assert_eq!((v, sat.saturated, sat.wrapped), (raw.clamp(lo, hi), 1, 0));
        } else {
            let m = hi - lo + 1;
            assert_eq!((v - raw).rem_euclid(m), 0);
            assert_eq!((sat.saturated, sat.wrapped), (0, 1));
        }
    }
    // requantize: one rounding then fit.
    let f = Format::signed(3, 4, Rounding::HalfEven);
    let mut sat = SatCounter::default();
    assert_eq!(f.requantize(0b1_1000, 5, &mut sat), 0b1100); // 0.75 -> 12/16
    assert_eq!(f.requantize(0b1_0100, 5, &mut sat), 0b1010); // 0.625 exact
    assert_eq!(f.requantize(0b1, 5, &mut sat), 0); // 1/32 -> tie to even 0
    assert_eq!(f.requantize(1 << 20, 4, &mut sat), 127);
    assert_eq!(sat.saturated, 1);
}
