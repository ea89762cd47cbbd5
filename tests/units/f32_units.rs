//! The float32 units (`hw_model::f32_*`) against the host's `f32` (x86 SSE, round to nearest
//! even, no DAZ/FTZ): bit for bit on 10^7 seeded operand sets per operation plus boundary
//! cases, exhaustively over 2^24 slices for the unary ones.

use crate::rng_common::Rng;
use hw_model::{f32_add, f32_convert, f32_div, f32_fma, f32_mul};

/// Boundary encodings: zeros, the smallest and largest subnormals and normals, one, values
/// next to one and two, the largest finite value, infinities and NaNs.
const EDGES: &[u32] = &[
    0x0000_0000,
    0x8000_0000,
    0x0000_0001,
    0x8000_0001,
    0x007F_FFFF,
    0x807F_FFFF,
    0x0080_0000,
    0x8080_0000,
    0x0080_0001,
    0x3F80_0000,
    0xBF80_0000,
    0x3F80_0001,
    0x3F7F_FFFF,
    0x4000_0000,
    0x3FFF_FFFF,
    0x4B80_0000,
    0x4B7F_FFFF,
    0x3400_0000,
    0x3380_0000,
    0x7F7F_FFFF,
    0xFF7F_FFFF,
    0x7F00_0000,
    0x7F80_0000,
    0xFF80_0000,
    0x7FC0_0000,
    0xFFC0_0000,
    0x7F80_0001,
    0x7FA0_0000,
];

/// An operand: a fifth uniformly random bits (NaNs, infinities, subnormals included), a
/// fifth an edge case, the rest with an exponent near `near` (cancellation, ties, carries).
fn operand(r: &mut Rng, near: u32) -> u32 {
    match r.below(5) {
        0 => r.next() as u32,
        1 => EDGES[r.below(EDGES.len() as u64) as usize],
        _ => {
            let e = (near as i64 + r.int_in(-26, 26)).clamp(0, 254) as u32;
            let sign = (r.next() as u32) & 0x8000_0000;
            let frac = match r.below(4) {
                // Few fraction bits set: exact ties and sums.
                0 => (r.next() as u32 & 0x7F_FFFF) & !((1 << r.below(23)) - 1),
                _ => r.next() as u32 & 0x7F_FFFF,
            };
            sign | e << 23 | frac
        }
    }
}

fn random_exp(r: &mut Rng) -> u32 {
    if r.below(8) == 0 {
        r.below(255) as u32
    } else {
        r.int_in(100, 154) as u32
    }
}

/// Equal encodings, or both NaN (the host compiler may commute an operation's operands, so
/// which NaN payload it propagates is not pinned down).
fn same(a: u32, b: u32) -> bool {
    let nan = |x: u32| f32::from_bits(x).is_nan();
    a == b || (nan(a) && nan(b))
}

fn check2(name: &str, unit: fn(u32, u32) -> u32, host: fn(f32, f32) -> f32, seed: u64) {
    let mut r = Rng(seed);
    let mut n = 0u64;
    for &a in EDGES {
        for &b in EDGES {
            let want = host(f32::from_bits(a), f32::from_bits(b)).to_bits();
            assert!(same(unit(a, b), want), "{name}({a:#010x}, {b:#010x})");
            n += 1;
        }
    }
    while n < 10_000_000 {
        let near = random_exp(&mut r);
        let (a, b) = (operand(&mut r, near), operand(&mut r, near));
        let want = host(f32::from_bits(a), f32::from_bits(b)).to_bits();
        let got = unit(a, b);
        assert!(
            same(got, want),
            "{name}({a:#010x}, {b:#010x}) = {got:#010x}, host {want:#010x}"
        );
        n += 1;
    }
}

#[test]
fn add_matches_host() {
    check2("add", f32_add::add, |a, b| a + b, 0xF32A);
}

#[test]
fn sub_matches_host() {
    check2("sub", f32_add::sub, |a, b| a - b, 0xF325);
}

#[test]
fn mul_matches_host() {
    check2("mul", f32_mul::mul, |a, b| a * b, 0xF32B);
}

#[test]
fn div_matches_host() {
    check2("div", f32_div::div, |a, b| a / b, 0xF32D);
}

/// `1 / x` for every `x` of a 2^24 slice: all fractions of the exponents 2^-1 and 2^0 (both
/// signs), and all subnormals' upper fractions: exhaustive over the reciprocal's significand.
#[test]
fn reciprocal_exhaustive_slice() {
    let one = 1f32.to_bits();
    for k in 0..(1u32 << 24) {
        let x = match k >> 22 {
            0 => 0x3F00_0000 | (k & 0x7F_FFFF),
            1 => 0x3F00_0000 | (k & 0x7F_FFFF) | 0x8000_0000,
            2 => 0x3F80_0000 | (k & 0x3F_FFFF) << 1,
            _ => (k & 0x3F_FFFF) << 1 | 1,
        };
        let want = (1.0 / f32::from_bits(x)).to_bits();
        assert_eq!(f32_div::div(one, x), want, "1 / {x:#010x}");
    }
}

#[test]
fn fma_matches_host() {
    let mut r = Rng(0xF32F);
    let mut n = 0u64;
    for &a in EDGES {
        for &b in EDGES {
            for &c in &EDGES[..12] {
                let want = f32::from_bits(a).mul_add(f32::from_bits(b), f32::from_bits(c));
                let got = f32_fma::fma(a, b, c);
                assert!(same(got, want.to_bits()), "fma({a:#x}, {b:#x}, {c:#x})");
                n += 1;
            }
        }
    }
    while n < 10_000_000 {
        // The addend near the product's exponent: cancellation and one rounding.
        let (ea, eb) = (random_exp(&mut r), random_exp(&mut r));
        let a = operand(&mut r, ea);
        let b = operand(&mut r, eb);
        let c = operand(&mut r, (ea + eb).saturating_sub(127).min(254));
        let want = f32::from_bits(a).mul_add(f32::from_bits(b), f32::from_bits(c));
        let got = f32_fma::fma(a, b, c);
        assert!(
            same(got, want.to_bits()),
            "fma({a:#010x}, {b:#010x}, {c:#010x}) = {got:#010x}, host {:#010x}",
            want.to_bits()
        );
        n += 1;
    }
}

/// Every `i32` of magnitude below 2^23 (exact) and a 2^23 slice above 2^24 (rounded, ties
/// included), both signs, plus the extremes.
#[test]
fn from_i32_exhaustive_slice() {
    for k in 0..(1i32 << 23) {
        for x in [k, -k, (1 << 24) + k * 3, i32::MIN + k] {
            assert_eq!(f32_convert::from_i32(x), (x as f32).to_bits(), "{x}");
        }
    }
    for x in [i32::MAX, i32::MIN, 1 << 30, (1 << 24) + 1, (1 << 25) + 2] {
        assert_eq!(f32_convert::from_i32(x), (x as f32).to_bits(), "{x}");
    }
}

/// The host's truncation with `cvttss2si`'s `i32::MIN` outside the range (`as` saturates).
fn trunc_host(f: f32) -> i32 {
    if (-2147483648.0..2147483648.0).contains(&f) {
        f as i32
    } else {
        i32::MIN
    }
}

/// `cvttss2si` over every encoding of a 2^24 slice (exponents 2^-2 to 2^31 with 21 fraction
/// bits, both signs): in-range values truncate as the host's `as i32`, the rest give
/// `i32::MIN`.
#[test]
fn to_i32_trunc_exhaustive_slice() {
    for k in 0..(1u32 << 24) {
        let sign = (k >> 23) << 31;
        let e = 125 + ((k >> 18) & 0x1F) * 33 / 32;
        let x = sign | e << 23 | (k & 0x3_FFFF) << 5 | (k & 0x1F);
        let f = f32::from_bits(x);
        let want = trunc_host(f);
        assert_eq!(f32_convert::to_i32_trunc(x), want, "{x:#010x}");
    }
    for &x in EDGES {
        let f = f32::from_bits(x);
        let want = trunc_host(f);
        assert_eq!(f32_convert::to_i32_trunc(x), want, "{x:#010x}");
    }
}
