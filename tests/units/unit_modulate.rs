//! Modulate and unorm conversion vs exact rationals: exhaustive at 8 bits (all a, b, every
//! output width and rounding), random at 16 bits and mixed widths, and vs the f64 twin.

use crate::rng_common::Rng;
use hw_model::fixed::Rounding;
use hw_model::modulate::{modulate, modulate_cost, modulate_span, unorm_convert};
use texsim::fixedpoint::{from_unorm, to_unorm};
use texsim::reference::modulate_f64;

const ROUNDINGS: [Rounding; 3] = [Rounding::Truncate, Rounding::HalfUp, Rounding::HalfEven];

/// Asserts that `q` is `num/den` correctly rounded by `mode` (checked by cross-multiplying).
fn assert_rounded(q: u32, num: u128, den: u128, mode: Rounding, ctx: &dyn Fn() -> String) {
    let q = u128::from(q);
    let ok = match mode {
        Rounding::Truncate => q * den <= num && num < (q + 1) * den,
        Rounding::HalfUp => {
            (2 * q).saturating_sub(1) * den <= 2 * num
                && 2 * num < (2 * q + 1) * den
                && (q > 0 || 2 * num < den)
        }
        Rounding::HalfEven => {
            let lo = 2 * q * den; // 2 num compared to (2q +- 1) den
            let d2 = 2 * num;
            let below = d2 + den; // d2 >= lo - den  <=> below >= lo
            let tie_lo = below == lo;
            let tie_hi = d2 == lo + den;
            below >= lo && d2 <= lo + den && (!tie_lo || q % 2 == 0) && (!tie_hi || q % 2 == 0)
        }
    };
    assert!(ok, "{}: got {q}", ctx());
}

#[test]
fn modulate_exhaustive_8_bit() {
    for mode in ROUNDINGS {
        for ob in 1u32..=16 {
            let mo = (1u128 << ob) - 1;
            for a in 0u32..256 {
                for b in 0u32..256 {
                    let q = modulate(a, 8, b, 8, ob, mode);
                    assert_rounded(q, u128::from(a * b) * mo, 255 * 255, mode, &|| {
                        format!("modulate({a},{b}) -> {ob} bits {mode:?}")
                    });
                }
            }
        }
    }
    // Endpoints are exact: 1 x 1 = 1, x * 1 = x.
    for a in 0..256 {
        assert_eq!(modulate(a, 8, 255, 8, 8, Rounding::Truncate), a);
    }
}

#[test]
fn modulate_random_mixed_widths() {
    let mut rng = Rng(0x30d_0001);
    for k in 0..1_500_000u32 {
        let (ab, bb, ob) = (
            1 + (k % 16),
            1 + (k / 16 % 16),
            1 + (rng.next() % 16) as u32,
        );
        let mode = ROUNDINGS[(k / 256 % 3) as usize];
        let a = (rng.next() % (1 << ab)) as u32;
        let b = (rng.next() % (1 << bb)) as u32;
        let q = modulate(a, ab, b, bb, ob, mode);
        let (ma, mb, mo) = ((1u128 << ab) - 1, (1u128 << bb) - 1, (1u128 << ob) - 1);
        assert_rounded(
            q,
            u128::from(a) * u128::from(b) * mo,
            ma * mb,
            mode,
            &|| format!("modulate({a}/{ab},{b}/{bb}) -> {ob} {mode:?}"),
        );
        if mode != Rounding::Truncate {
            let f = modulate_f64(from_unorm(a, ab), from_unorm(b, bb)) * mo as f64;
            assert!((f64::from(q) - f).abs() <= 0.5 + 1e-9);
        }
    }
    // Inputs above their range clamp; zero widths give 0.
    assert_eq!(modulate(1000, 8, 255, 8, 8, Rounding::HalfEven), 255);
    assert_eq!(modulate(5, 0, 5, 8, 8, Rounding::HalfEven), 0);
    assert!(
        modulate_cost(
            &hw_model::HwConfig::texram16().color,
            hw_model::timing_config::DEFAULT_GATE_LEVELS_PER_CYCLE
        )
        .ops > 0
    );
}

/// `modulate_span` equals `modulate` per channel: every input pair at every width pair up to
/// 6 bits (the output width and mode cycling), then 4M seeded lanes in spans of 1 to 16 with
/// widths 0 to 20 (beyond 16 clamps), inputs up to 2^20 (above their maximum clamps) and a
/// fifth of them at the maxima.
#[test]
fn modulate_span_matches_modulate() {
    fn check(lanes: &[([u32; 4], [u32; 4])], (ab, bb, ob): (u32, u32, u32), mode: Rounding) {
        let mut got = vec![[u32::MAX; 4]; lanes.len()];
        let it = lanes
            .iter()
            .zip(got.iter_mut())
            .map(|(&(a, b), o)| (a, b, o));
        modulate_span(it, ab, bb, ob, mode);
        for (&(a, b), g) in lanes.iter().zip(&got) {
            let want = [0, 1, 2, 3].map(|ch| modulate(a[ch], ab, b[ch], bb, ob, mode));
            assert_eq!(*g, want, "{a:?}/{ab} x {b:?}/{bb} -> {ob} {mode:?}");
        }
    }
    for ab in 1u32..=6 {
        for bb in 1u32..=6 {
            let ob = (ab + bb) % 16 + 1;
            let mode = ROUNDINGS[((ab + bb) % 3) as usize];
            let lanes: Vec<_> = (0..1u32 << ab)
                .flat_map(|a| (0..1u32 << bb).map(move |b| ([a; 4], [b, b, b, 0])))
                .collect();
            check(&lanes, (ab, bb, ob), mode);
        }
    }
    let mut rng = Rng(0x30d_0002);
    let mut lanes = Vec::with_capacity(16);
    let mut done = 0u32;
    while done < 4_000_000 {
        let w = [0u32; 3].map(|_| rng.below(21) as u32);
        let mode = ROUNDINGS[rng.below(3) as usize];
        let n = rng.int_in(1, 16) as usize;
        let value = |bits: u32, rng: &mut Rng| {
            if rng.below(5) == 0 {
                ((1u64 << bits.min(16)) - 1) as u32
            } else {
                (rng.next() % (1u64 << (bits + 1).min(20))) as u32
            }
        };
        lanes.clear();
        for _ in 0..n {
            let a = [0; 4].map(|_| value(w[0], &mut rng));
            let b = [0; 4].map(|_| value(w[1], &mut rng));
            lanes.push((a, b));
        }
        check(&lanes, (w[0], w[1], w[2]), mode);
        done += n as u32;
    }
}

#[test]
fn unorm_convert_exhaustive_and_random() {
    for mode in ROUNDINGS {
        for from in 1u32..=16 {
            for to in 1u32..=16 {
                let n = 1u32 << from;
                let step = (n / 4096).max(1);
                let mut x = 0;
                while x < n {
                    let q = unorm_convert(x, from, to, mode);
                    let (mf, mt) = ((1u128 << from) - 1, (1u128 << to) - 1);
                    assert_rounded(q, u128::from(x) * mt, mf, mode, &|| {
                        format!("{x}: {from}->{to}")
                    });
                    x += step;
                }
            }
        }
    }
    // 8 -> 16 is the exact x * 257 expansion; 16 -> 8 round trip is the identity.
    for x in 0u32..256 {
        assert_eq!(unorm_convert(x, 8, 16, Rounding::Truncate), x * 257);
        assert_eq!(unorm_convert(x * 257, 16, 8, Rounding::HalfEven), x);
        assert_eq!(to_unorm(from_unorm(x, 8), 8), x);
    }
    let mut rng = Rng(0x30d_0002);
    for _ in 0..500_000 {
        let x = rng.next() as u32;
        let q = unorm_convert(x, 32, 16, Rounding::HalfEven);
        assert_rounded(
            q,
            u128::from(x) * 65535,
            (1u128 << 32) - 1,
            Rounding::HalfEven,
            &|| format!("{x}"),
        );
    }
}
