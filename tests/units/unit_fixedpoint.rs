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

/// `floor_exact` is `f64::floor` bit for bit: signed zeros, infinities, NaN, the integers and
/// half-integers around 0 and 2^52, and 10M seeded doubles (random bit patterns and values
/// spread over [-2^60, 2^60]).
#[test]
fn floor_exact_is_floor() {
    use texsim::fixedpoint::floor_exact;
    let same = |y: f64| {
        let (a, b) = (floor_exact(y), y.floor());
        assert!(
            a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
            "{y:e}: {a:e} vs {b:e}"
        );
    };
    for y in [
        0.0,
        -0.0,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
        f64::MIN_POSITIVE,
    ] {
        same(y);
        same(-y);
    }
    let two52 = 4_503_599_627_370_496.0f64;
    for k in -4096..=4096 {
        let y = f64::from(k) * 0.25;
        for base in [0.0, two52, -two52, two52 * 2.0, -two52 * 2.0] {
            same(base + y);
            same(base + y * 1e-9);
        }
        for e in [-1074, -60, -1, 0, 1, 51, 52, 53, 62, 63, 64, 1000] {
            same(y * 2f64.powi(e));
        }
    }
    let mut rng = Rng(0x5eed_f100);
    for _ in 0..5_000_000 {
        same(f64::from_bits(rng.next()));
        same((rng.unit() * 2.0 - 1.0) * 2f64.powi((rng.next() % 61) as i32));
    }
}

/// `pow2` is `2f64.powi` for every exponent from below the subnormals to beyond overflow.
#[test]
fn pow2_is_powi() {
    use texsim::fixedpoint::pow2;
    for e in -1200..=1200 {
        assert_eq!(pow2(e).to_bits(), 2f64.powi(e).to_bits(), "2^{e}");
    }
    for e in [i32::MIN, i32::MIN + 1, -100_000, 100_000, i32::MAX] {
        assert_eq!(pow2(e).to_bits(), 2f64.powi(e).to_bits(), "2^{e}");
    }
}

/// `to_raw` before its `i64` fast path (the floor and rounding in `f64` throughout): the oracle.
fn to_raw_before(x: f64, fmt: &Format, sat: &mut SatCounter) -> i64 {
    if x.is_nan() {
        sat.saturated += 1;
        return 0;
    }
    let y = x * texsim::fixedpoint::pow2(fmt.frac_bits as i32);
    let fl = texsim::fixedpoint::floor_exact(y);
    let rem = y - fl;
    let r = match fmt.rounding {
        Rounding::Truncate => fl,
        Rounding::HalfUp => fl + if rem >= 0.5 { 1.0 } else { 0.0 },
        Rounding::HalfEven => {
            let odd = texsim::fixedpoint::floor_exact(fl * 0.5) != fl * 0.5;
            fl + if rem > 0.5 || (rem == 0.5 && odd) {
                1.0
            } else {
                0.0
            }
        }
    };
    const LIM: f64 = 9_223_372_036_854_775_808.0;
    if r >= LIM {
        sat.saturated += 1;
        return fmt.max_raw();
    }
    if r < -LIM {
        sat.saturated += 1;
        return fmt.min_raw();
    }
    fmt.fit(r as i64, sat)
}

/// 4M seeded values (exact ties, integers, values near 2^52 on either side, huge, tiny,
/// infinite and NaN; every rounding, both overflow rules, signed and unsigned formats) give
/// the previous `to_raw`'s raw value and overflow counts.
#[test]
fn to_raw_matches_the_previous_routine() {
    let mut rng = Rng(0x5eed_0ac1);
    let (mut sat, mut sat_before) = (SatCounter::default(), SatCounter::default());
    let (mut fast, mut wide) = (0u32, 0u32);
    for i in 0..4_000_000u32 {
        let rounding = [Rounding::Truncate, Rounding::HalfUp, Rounding::HalfEven][(i % 3) as usize];
        let frac = (rng.next() % 40) as u32;
        let int = (rng.next() % (62 - frac as u64).min(40)) as u32;
        let mut fmt = if i / 3 % 2 == 0 {
            Format::signed(int, frac, rounding)
        } else {
            Format::unsigned(int.max(1), frac, rounding)
        };
        if i / 6 % 4 == 0 {
            fmt.overflow = Overflow::Wrap;
        }
        let scale = texsim::fixedpoint::pow2(-(frac as i32));
        let sign = if rng.next() & 1 == 0 { 1.0 } else { -1.0 };
        let x = match i / 24 % 8 {
            // Exact ties and near-ties on the raw grid.
            0 => sign * ((rng.next() >> 24) as f64 + 0.5) * scale,
            1 => sign * ((rng.next() >> 20) as f64 + [0.5, 0.25, 0.75][(i % 3) as usize]) * scale,
            // Integers and neighbours of 2^52 on the raw grid.
            2 => sign * (rng.next() >> 12) as f64 * scale,
            3 => sign * (4_503_599_627_370_496.0 + (rng.next() % 64) as f64 - 32.0) * scale,
            // Arbitrary doubles, small to huge.
            4 => sign * rng.unit() * texsim::fixedpoint::pow2((rng.next() % 140) as i32 - 70),
            5 => f64::from_bits(rng.next()),
            6 => [
                f64::NAN,
                f64::INFINITY,
                f64::NEG_INFINITY,
                0.0,
                -0.0,
                1e300,
                -1e300,
            ][(i % 7) as usize],
            _ => sign * rng.range(0.0, 4.0),
        };
        let y = x * texsim::fixedpoint::pow2(frac as i32);
        if y.abs() < 4_503_599_627_370_496.0 {
            fast += 1;
        } else {
            wide += 1;
        }
        assert_eq!(
            to_raw(x, &fmt, &mut sat),
            to_raw_before(x, &fmt, &mut sat_before),
            "{x:e} {fmt:?}"
        );
        assert_eq!(sat, sat_before, "{x:e} {fmt:?}");
    }
    assert!(fast > 2_500_000 && wide > 300_000, "{fast} {wide}");
    assert!(sat.saturated > 100_000 && sat.wrapped > 10_000, "{sat:?}");
}

/// `QuietSetup`: for coordinates within its bounds (the bounds themselves and blends of them
/// included) and finite positive 1/w, `TriAttrs::new` counts no overflow, for every wrap mode,
/// rounding and offset reduction, on coordinate formats down to the narrowest the bounds
/// allow; a format too narrow for the bounds, and 1/w that are zero, negative or not finite,
/// are not quiet.
#[test]
fn quiet_setup_keeps_every_attribute_conversion_in_range() {
    use hw_model::HwConfig;
    use texsim::pipeline::stages::{Machine, QuietSetup, TriAttrs};
    use texsim::scene::WrapMode;
    let mut rng = Rng(0x0051_e7a7_7e5e_7001);
    let (mut quiet, mut checked) = (0, 0u64);
    for (int_bits, frac_bits, lo, hi) in [
        (8, 24, 0.0, 1.0),
        (3, 12, -1.0, 2.0),
        (4, 20, 3.0, 9.0),
        (2, 8, 0.0, 0.5),
        (6, 40, -20.0, 20.0),
        (1, 4, 0.0, 1.0),
        (2, 30, 0.0, 8.0),
    ] {
        for rounding in [Rounding::Truncate, Rounding::HalfUp, Rounding::HalfEven] {
            for reduce in [true, false] {
                let mut hw = HwConfig::texram16();
                hw.interp.texcoord_int_bits = int_bits;
                hw.interp.texcoord_frac_bits = frac_bits;
                hw.interp.interp_rounding = rounding;
                hw.interp.texcoord_reduce = reduce;
                let m = Machine::new(&hw, &[], &[]);
                let q = QuietSetup::new(&m, Some(([lo, lo], [hi, hi])));
                assert!(!QuietSetup::new(&m, None).holds([1.0; 3]));
                for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
                    assert!(!q.holds([1.0, bad, 0.5]));
                }
                if !q.holds([1.0; 3]) {
                    continue;
                }
                quiet += 1;
                for _ in 0..20_000 {
                    let mut uv = [[0.0; 2]; 3];
                    for v in &mut uv {
                        for c in v.iter_mut() {
                            *c = match rng.below(8) {
                                0 => lo,
                                1 => hi,
                                // A clipped vertex: a blend of two within the bounds.
                                2 => {
                                    let t = rng.unit();
                                    (1.0 - t) * lo + t * hi
                                }
                                _ => rng.range(lo, hi),
                            };
                        }
                    }
                    let inv_w = [0, 1, 2].map(|_| rng.range(1e-6, 4.0));
                    assert!(q.holds(inv_w));
                    let wrap = [WrapMode::Repeat, WrapMode::Mirror, WrapMode::ClampToEdge];
                    let w = [0, 1].map(|_| wrap[rng.below(3) as usize]);
                    let mut sat = SatCounter::default();
                    let _ = TriAttrs::new(&m, 0, inv_w, None, uv, w, &mut sat);
                    assert_eq!(
                        sat,
                        SatCounter::default(),
                        "{int_bits}.{frac_bits} [{lo}, {hi}] {rounding:?} {w:?} {uv:?} {inv_w:?}"
                    );
                    checked += 1;
                }
            }
        }
    }
    // The bounds fit all but the two narrowest formats (1.4 for [0, 1], 2.30 for [0, 8]).
    assert_eq!(quiet, 5 * 6, "{checked} triangles checked");
}
