//! texsim float <-> fixed conversion: rounding modes, ties, saturation and NaN, round trips.

use crate::rng_common::Rng;
use hw_model::fixed::{Format, Overflow, Rounding, SatCounter};
use texsim::fixedpoint::{from_raw, from_unorm, to_raw, to_unorm};

#[test]
fn to_raw_rounding_and_ties() {
    let s = |r| Format::signed(10, 4, r);
    let mut sat = SatCounter::default();
    // 2.53125 = 40.5/16.
    assert_eq!(to_raw(2.53125, &s(Rounding::Truncate), &mut sat), 40);
    assert_eq!(to_raw(2.53125, &s(Rounding::HalfUp), &mut sat), 41);
    assert_eq!(to_raw(2.53125, &s(Rounding::HalfEven), &mut sat), 40);
    assert_eq!(to_raw(-2.53125, &s(Rounding::Truncate), &mut sat), -41);
    assert_eq!(to_raw(-2.53125, &s(Rounding::HalfUp), &mut sat), -40);
    assert_eq!(to_raw(-2.53125, &s(Rounding::HalfEven), &mut sat), -40);
    assert_eq!(to_raw(-2.59375, &s(Rounding::HalfEven), &mut sat), -42); // -41.5 -> -42
    assert_eq!(sat, SatCounter::default());
    assert_eq!(to_raw(f64::NAN, &s(Rounding::HalfEven), &mut sat), 0);
    assert_eq!(
        to_raw(f64::INFINITY, &s(Rounding::HalfEven), &mut sat),
        (1 << 14) - 1
    );
    assert_eq!(
        to_raw(f64::NEG_INFINITY, &s(Rounding::HalfEven), &mut sat),
        -(1 << 14)
    );
    assert_eq!(
        to_raw(1e300, &s(Rounding::HalfEven), &mut sat),
        (1 << 14) - 1
    );
    assert_eq!(
        to_raw(5000.0, &s(Rounding::HalfEven), &mut sat),
        (1 << 14) - 1
    );
    assert_eq!(sat.saturated, 5);
    let mut w = s(Rounding::Truncate);
    w.overflow = Overflow::Wrap;
    assert_eq!(to_raw(1024.0, &w, &mut sat), -(1 << 14));
    assert_eq!(sat.wrapped, 1);
}

#[test]
fn to_raw_random_vs_integer_model() {
    let mut rng = Rng(0xf9_0001);
    let f = Format::signed(30, 16, Rounding::HalfEven);
    for k in 0..1_000_000u32 {
        // x = n / 2^20 exactly: the model rounds n >> 4 by each mode.
        let n = (rng.next() as i64) >> 18;
        let x = n as f64 / 1048576.0;
        for mode in [Rounding::Truncate, Rounding::HalfUp, Rounding::HalfEven] {
            let fm = Format {
                rounding: mode,
                ..f
            };
            let mut sat = SatCounter::default();
            let got = to_raw(x, &fm, &mut sat);
            let want = hw_model::fixed::round_shift_right(n, 4, mode);
            assert_eq!(got, want, "k={k} n={n} {mode:?}");
            assert_eq!(from_raw(got, 16), got as f64 / 65536.0);
        }
    }
}

#[test]
fn unorm_round_trip() {
    for bits in 1..=16u32 {
        let max = (1u32 << bits) - 1;
        for x in 0..=max.min(70_000) {
            assert_eq!(to_unorm(from_unorm(x, bits), bits), x);
        }
        assert_eq!(to_unorm(-1.0, bits), 0);
        assert_eq!(to_unorm(2.0, bits), max);
        assert_eq!(to_unorm(f64::NAN, bits), 0);
    }
    // Half-even: 0.5 * 255 = 127.5 -> 128, 1.5/255 -> 2, 2.5/255 -> 2.
    assert_eq!(to_unorm(0.5, 8), 128);
    assert_eq!(to_unorm(2.5 / 255.0, 8), 2);
}

/// `round_ties_even_small` is `round_ties_even` on [0, 2^52): every quarter in [0, 2^22) (the
/// unorm conversions' range and its ties), exhaustively, and 4M seeded doubles up to 2^52.
#[test]
fn round_ties_even_small_is_round_ties_even() {
    use texsim::fixedpoint::round_ties_even_small;
    for k in 0..(1u64 << 24) {
        let y = k as f64 * 0.25;
        assert_eq!(round_ties_even_small(y), y.round_ties_even(), "{y}");
    }
    let mut rng = Rng(0x5eed_0052);
    for _ in 0..4_000_000 {
        let y = (rng.next() >> 12) as f64 * rng.unit();
        assert_eq!(round_ties_even_small(y), y.round_ties_even(), "{y}");
    }
}
