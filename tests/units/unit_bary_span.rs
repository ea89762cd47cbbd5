//! The interpolator's span datapaths (`perspective_bary_derivs_span`, `perspective_bary_span`,
//! `interpolate_span`) against one call of the per-sample routine per lane: the same values
//! and the same saturation counts, on seeded spans over random widths and rounding
//! modes, from screen-sized to near-degenerate and huge triangles, tiny and large 1/w, lanes
//! inside and outside the triangle, spans longer than `SPAN_LANES`.

use crate::rng_common::Rng;
use hw_model::config::HwConfig;
use hw_model::fixed::{Format, Overflow, Rounding, SatCounter};
use hw_model::interpolator::{
    interpolate, interpolate_lanes, interpolate_pairs, interpolate_span, perspective_bary,
    perspective_bary_derivs, perspective_bary_derivs_span, perspective_bary_span, EdgeSpan,
    SPAN_LANES,
};
use hw_model::reciprocal::Reciprocal;

const MODES: [Rounding; 3] = [Rounding::Truncate, Rounding::HalfUp, Rounding::HalfEven];

/// A configuration with random interpolator and reciprocal widths and rounding modes.
fn config(rng: &mut Rng) -> HwConfig {
    let mut hw = HwConfig::texram16();
    let i = &mut hw.interp;
    i.bary_bits = rng.int_in(4, 30) as u32;
    i.inv_w_bits = rng.int_in(4, 30) as u32;
    i.interp_rounding = MODES[rng.below(3) as usize];
    let r = &mut hw.reciprocal;
    r.recip_lut_bits = rng.int_in(1, 12) as u32;
    r.recip_iterations = rng.int_in(0, 4) as u32;
    r.recip_mantissa_bits = rng.int_in(8, 30) as u32;
    r.recip_rounding = MODES[rng.below(3) as usize];
    hw
}

/// A value of at most `bits` magnitude bits, either sign.
fn signed(rng: &mut Rng, bits: u32) -> i64 {
    let v = (rng.next() >> (64 - bits.clamp(1, 62))) as i64;
    if rng.next() & 1 == 1 {
        -v
    } else {
        v
    }
}

/// Per-vertex 1/w normalized so that the largest is 2^W: equal, random, or with tiny values
/// (a vertex far behind the others).
fn inv_w(rng: &mut Rng, bits: u32) -> [i64; 3] {
    let one = 1i64 << bits;
    let mut w = [0i64; 3].map(|_| match rng.below(4) {
        0 => one,
        1 => rng.int_in(1, 16),
        _ => rng.int_in(1, one),
    });
    w[rng.below(3) as usize] = one;
    w
}

/// The edges at a span's first pixel and their x and y steps, with `n` lanes: of a triangle
/// on a sub-pixel grid (screen-sized to huge, possibly near-degenerate, the span crossing its
/// edges), or arbitrary values of random magnitudes (deep into the fallback ranges). Every
/// lane's edges fit `i64`.
fn span_edges(rng: &mut Rng, n: usize) -> ([i64; 3], [i64; 3], [i64; 3]) {
    if rng.below(2) == 0 {
        let s = rng.int_in(1, 12) as u32;
        let size = 1i64 << rng.int_in(2, 26);
        let mut v = [[0i64; 2]; 3].map(|_| [0, 1].map(|_| rng.int_in(-size, size)));
        if rng.below(4) == 0 {
            // Near-degenerate: the third vertex close to the line through the first two.
            let t = rng.int_in(-4, 4);
            v[2] = [0, 1].map(|k| v[0][k] + t * (v[1][k] - v[0][k]) + rng.int_in(-1, 1));
        }
        let span = (size >> s).max(4);
        let (px, py) = (rng.int_in(-span, span), rng.int_in(-span, span));
        let edge_at = |px: i64, py: i64| {
            let h = 1i64 << (s - 1);
            let (x, y) = ((px << s) + h, (py << s) + h);
            let e = |[xj, yj]: [i64; 2], [xk, yk]: [i64; 2]| {
                (xk - xj) * (y - yj) - (yk - yj) * (x - xj)
            };
            [e(v[1], v[2]), e(v[2], v[0]), e(v[0], v[1])]
        };
        let e = edge_at(px, py);
        let ex = edge_at(px + 1, py);
        let ey = edge_at(px, py + 1);
        return (
            e,
            [0, 1, 2].map(|i| ex[i] - e[i]),
            [0, 1, 2].map(|i| ey[i] - e[i]),
        );
    }
    let bits = rng.int_in(1, 58) as u32;
    let step_bits = rng.int_in(1, i64::from(58 - (n as u32 + 1).ilog2())) as u32;
    let dy_bits = rng.int_in(1, 58) as u32;
    (
        [0; 3].map(|_| signed(rng, bits)),
        [0; 3].map(|_| signed(rng, step_bits)),
        [0; 3].map(|_| signed(rng, dy_bits)),
    )
}

fn lane(e: [i64; 3], dx: [i64; 3], j: usize) -> [i64; 3] {
    [0, 1, 2].map(|i| e[i] + j as i64 * dx[i])
}

/// 1M spans of 1 to 40 lanes (about 20M lanes): `perspective_bary_derivs_span` equals
/// `perspective_bary_derivs` at every lane, with the same saturation counts; both the fast
/// form (operands below 2^62) and the per-lane fallback are exercised.
#[test]
fn derivs_span_matches_the_per_sample_routine() {
    let mut rng = Rng(0x5a4e_0001);
    let (mut hw, mut recip) = (
        HwConfig::texram16(),
        Reciprocal::new(&HwConfig::texram16().reciprocal),
    );
    let (mut small, mut large) = (0u64, 0u64);
    let mut out = vec![[[0i64; 3]; 3]; 40];
    for case in 0..1_000_000u32 {
        if case % 2000 == 0 {
            hw = config(&mut rng);
            recip = Reciprocal::new(&hw.reciprocal);
        }
        let n = if rng.below(4) == 0 {
            rng.int_in(1, 40) as usize
        } else {
            rng.int_in(1, SPAN_LANES as i64) as usize
        };
        let (e, dx, dy) = span_edges(&mut rng, n);
        let w = inv_w(&mut rng, hw.interp.inv_w_bits);
        let mut sat = SatCounter::default();
        let mut seen = 0u64;
        let put = |j: usize, b| {
            assert!(seen & 1 << j == 0, "case {case}: lane {j} twice");
            seen |= 1 << j;
            out[j] = b;
        };
        let span = EdgeSpan {
            edge: e,
            dx,
            dy,
            lanes: n,
        };
        perspective_bary_derivs_span(&span, w, &hw.interp, &recip, &mut sat, put);
        assert_eq!(seen, (1u64 << n) - 1, "case {case}: every lane once");
        let mut sat_ref = SatCounter::default();
        for (j, got) in out[..n].iter().enumerate() {
            let ej = lane(e, dx, j);
            let want = perspective_bary_derivs(ej, dx, dy, w, &hw.interp, &recip, &mut sat_ref);
            assert_eq!(
                *got, want,
                "case {case} lane {j}: edges {ej:?} {dx:?} {dy:?} w {w:?}"
            );
            let mag = [0, 1, 2]
                .map(|i| [ej[i], dx[i], dy[i]].map(|v| i128::from(v) * i128::from(w[i])))
                .iter()
                .flatten()
                .fold(0u128, |m, v| m | v.unsigned_abs());
            if mag >> 60 == 0 {
                small += 1;
            } else {
                large += 1;
            }
        }
        assert_eq!(sat, sat_ref, "case {case}: saturation counts");
    }
    assert!(small > 5_000_000 && large > 2_000_000, "{small} {large}");
}

/// 300k spans: `perspective_bary_span` equals `perspective_bary` at every lane, with the same
/// saturation counts.
#[test]
fn bary_span_matches_the_per_sample_routine() {
    let mut rng = Rng(0x5a4e_0002);
    let (mut hw, mut recip) = (
        HwConfig::texram16(),
        Reciprocal::new(&HwConfig::texram16().reciprocal),
    );
    let mut out = vec![[0i64; 3]; 40];
    for case in 0..300_000u32 {
        if case % 1000 == 0 {
            hw = config(&mut rng);
            recip = Reciprocal::new(&hw.reciprocal);
        }
        let n = rng.int_in(1, 40) as usize;
        let (e, dx, dy) = span_edges(&mut rng, n);
        let w = inv_w(&mut rng, hw.interp.inv_w_bits);
        let mut sat = SatCounter::default();
        let put = |j: usize, b| out[j] = b;
        let span = EdgeSpan {
            edge: e,
            dx,
            dy,
            lanes: n,
        };
        perspective_bary_span(&span, w, &hw.interp, &recip, &mut sat, put);
        let mut sat_ref = SatCounter::default();
        for (j, got) in out[..n].iter().enumerate() {
            let want = perspective_bary(lane(e, dx, j), w, &hw.interp, &recip, &mut sat_ref);
            assert_eq!(*got, want, "case {case} lane {j}");
        }
        assert_eq!(sat, sat_ref, "case {case}: saturation counts");
    }
}

/// 1M spans of fragments with 1 or 3 samples: `interpolate_span` of pairs equals one
/// `interpolate_pairs` per fragment (values and overflow counts), over formats, rounding
/// and overflow modes, attributes from small to beyond the `i64` accumulator.
#[test]
fn interpolate_span_of_pairs_matches_per_fragment_calls() {
    let mut rng = Rng(0x5a4e_0003);
    for case in 0..1_000_000u32 {
        let bb = rng.int_in(4, 30) as u32;
        let frac = rng.int_in(4, 28) as u32;
        let int = rng.int_in(1, 16) as u32;
        let mut out = Format::signed(int, frac, MODES[rng.below(3) as usize]);
        if rng.below(2) == 0 {
            out = out.with_overflow(Overflow::Wrap);
        }
        let abits = [int + frac + 1, 40, 62][rng.below(3) as usize];
        let attr = [[0i64; 2]; 3].map(|_| [0, 1].map(|_| signed(&mut rng, abits)));
        let samples = [1usize, 3][rng.below(2) as usize];
        let n = rng.int_in(1, 16) as usize;
        let bbits = [bb + 1, bb + 3, 40][rng.below(3) as usize];
        let bary: Vec<[[i64; 3]; 3]> = (0..n)
            .map(|_| [[0i64; 3]; 3].map(|_| [0; 3].map(|_| signed(&mut rng, bbits))))
            .collect();
        let mut got = vec![[[0i64; 2]; 3]; n];
        let mut sat = SatCounter::default();
        let lanes = bary
            .iter()
            .zip(got.iter_mut())
            .map(|(b, r)| (&b[..samples], &mut r[..samples]));
        interpolate_span(lanes, bb, attr, &out, &mut sat);
        let mut sat_ref = SatCounter::default();
        for (b, g) in bary.iter().zip(&got) {
            let mut want = [[0i64; 2]; 3];
            interpolate_pairs(
                &b[..samples],
                bb,
                attr,
                &out,
                &mut sat_ref,
                &mut want[..samples],
            );
            assert_eq!(g, &want, "case {case}");
        }
        assert_eq!(sat, sat_ref, "case {case}: overflow counts");
    }
}

/// 1M runs of lanes (a range of 32 lanes, as the pipeline's runs): `interpolate_lanes` equals
/// one `interpolate_pairs` per lane (values and overflow counts) and leaves the other lanes
/// as they were, over formats, rounding and overflow modes, attributes from small to beyond
/// the `i64` accumulator, barycentrics inside and far outside the triangle.
#[test]
fn interpolate_lanes_matches_interpolate_pairs() {
    const L: usize = 32;
    let mut rng = Rng(0x5a4e_0005);
    let (mut lanes_seen, mut redone) = (0u64, 0u64);
    for case in 0..1_000_000u32 {
        let bb = rng.int_in(4, 30) as u32;
        let frac = rng.int_in(4, 28) as u32;
        let int = rng.int_in(1, 16) as u32;
        let mut out = Format::signed(int, frac, MODES[rng.below(3) as usize]);
        if rng.below(2) == 0 {
            out = out.with_overflow(Overflow::Wrap);
        }
        let abits = [int + frac - 2, int + frac + 1, 40, 62][rng.below(4) as usize];
        let attr = [[0i64; 2]; 3].map(|_| [0, 1].map(|_| signed(&mut rng, abits)));
        let start = rng.int_in(0, L as i64 - 1) as usize;
        let end = rng.int_in(start as i64 + 1, L as i64) as usize;
        let bbits = [bb, bb + 1, bb + 3, 40][rng.below(4) as usize];
        let mut bary = [[[0i64; L]; 3]; 3];
        for lanes in bary.iter_mut().flatten() {
            for b in lanes.iter_mut() {
                *b = signed(&mut rng, bbits);
            }
        }
        let before = [[[0i64; L]; 2]; 3].map(|s| s.map(|a| a.map(|_| rng.next() as i64)));
        let mut got = before;
        let mut sat = SatCounter::default();
        interpolate_lanes(&bary, start..end, bb, attr, &out, &mut sat, &mut got);
        let mut sat_ref = SatCounter::default();
        for j in 0..L {
            for s in 0..3 {
                let want = if (start..end).contains(&j) {
                    let b = [[bary[s][0][j], bary[s][1][j], bary[s][2][j]]];
                    let mut r = [[0i64; 2]];
                    interpolate_pairs(&b, bb, attr, &out, &mut sat_ref, &mut r);
                    r[0]
                } else {
                    [before[s][0][j], before[s][1][j]]
                };
                assert_eq!(
                    [got[s][0][j], got[s][1][j]],
                    want,
                    "case {case} lane {j} sample {s}"
                );
            }
        }
        assert_eq!(sat, sat_ref, "case {case}: overflow counts");
        lanes_seen += (end - start) as u64;
        redone += u64::from(sat.saturated > 0);
    }
    assert!(
        lanes_seen > 8_000_000 && redone > 300_000,
        "{lanes_seen} {redone}"
    );
}

/// 1M spans of 1 to 16 one-sample fragments: `interpolate_span` of three attributes (a
/// colour's channels) equals one `interpolate` per fragment and channel (values and overflow
/// counts), over unsigned and signed formats, rounding and overflow modes, attributes from
/// unorm colours to beyond the `i64` accumulator and barycentrics inside and far outside
/// the triangle.
#[test]
fn interpolate_span_matches_interpolate() {
    let mut rng = Rng(0x5a4e_0004);
    for case in 0..1_000_000u32 {
        let bb = rng.int_in(4, 30) as u32;
        let frac = rng.int_in(1, 24) as u32;
        let mode = MODES[rng.below(3) as usize];
        let mut out = if rng.below(2) == 0 {
            Format::unsigned(0, frac, mode)
        } else {
            Format::signed(rng.int_in(1, 16) as u32, frac, mode)
        };
        if rng.below(4) == 0 {
            out = out.with_overflow(Overflow::Wrap);
        }
        let abits = [frac, frac + 2, 40, 62][rng.below(4) as usize];
        let attr = [[0i64; 3]; 3].map(|_| [0; 3].map(|_| signed(&mut rng, abits)));
        let n = rng.int_in(1, 16) as usize;
        let bbits = [bb, bb + 1, bb + 3, 40][rng.below(4) as usize];
        let bary: Vec<[i64; 3]> = (0..n)
            .map(|_| [0; 3].map(|_| signed(&mut rng, bbits)))
            .collect();
        let mut got = vec![[[0i64; 3]; 1]; n];
        let mut sat = SatCounter::default();
        let lanes = bary
            .iter()
            .zip(got.iter_mut())
            .map(|(b, r)| (std::slice::from_ref(b), &mut r[..]));
        interpolate_span(lanes, bb, attr, &out, &mut sat);
        let mut sat_ref = SatCounter::default();
        for (b, g) in bary.iter().zip(&got) {
            let want = [0, 1, 2].map(|ch| {
                let column = [attr[0][ch], attr[1][ch], attr[2][ch]];
                interpolate(*b, bb, column, &out, &mut sat_ref)
            });
            assert_eq!(g[0], want, "case {case}");
        }
        assert_eq!(sat, sat_ref, "case {case}: overflow counts");
    }
}
