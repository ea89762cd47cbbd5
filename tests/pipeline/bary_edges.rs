//! `ScreenTri`'s edge functions (plain `i64` under their bounds, checked or `i128` beyond them)
//! give the exact `i128` edge values, inside the bounds and beyond them.

use crate::rng_common::Rng;
use texsim::raster::ScreenTri;

/// The exact edge values of vertices `v` (on a grid of `s` bits) at pixel (px, py)'s centre,
/// saturated to `i64`.
fn exact(v: [[i128; 2]; 3], px: i64, py: i64, s: u32) -> [i64; 3] {
    let h = 1i128 << (s - 1);
    let (x, y) = ((i128::from(px) << s) + h, (i128::from(py) << s) + h);
    [0, 1, 2].map(|i| {
        let [xj, yj] = v[(i + 1) % 3];
        let [xk, yk] = v[(i + 2) % 3];
        let w = (xk - xj) * (y - yj) - (yk - yj) * (x - xj);
        w.clamp(i128::from(i64::MIN), i128::from(i64::MAX)) as i64
    })
}

fn tri() -> ScreenTri {
    ScreenTri {
        xy: [[0; 2]; 3],
        xy_f: [[0.0; 2]; 3],
        z: [0; 3],
        z_f: [0.0; 3],
        inv_w: [1.0; 3],
        src: 0,
        source: texsim::raster::VertexSource::Unclipped { swapped: false },
        area2: 1,
        area2_f: 1.0,
        bbox: [0; 4],
    }
}

/// 2M seeded triangles and pixels, coordinates from a screen's to far beyond the 2^29 bound
/// (both sides of it), every sub-pixel grid of the raster (1..=12 bits) and of the attribute
/// setup (1..=16 bits, from the float positions): the same edges and steps, and both the
/// `i64` evaluation and the fallback are exercised.
#[test]
fn screen_tri_edges_match_the_exact_values() {
    let mut rng = Rng(0x5eed_0ba1);
    let mut t = tri();
    let (mut small, mut large) = (0u32, 0u32);
    for case in 0..2_000_000u32 {
        let (span, pspan) = match case % 5 {
            0 => (1i64 << 20, 4096i64),
            1 => ((1 << 29) - 8, 1 << 16),
            2 => (1 << 29, 1 << 17),
            3 => (1 << 31, 1 << 20),
            _ => (1 << 44, 1 << 30),
        };
        for v in &mut t.xy {
            *v = [0, 1].map(|_| rng.below(2 * span as u64) as i64 - span);
        }
        let scale = [1.0, 16.0, 256.0, 65536.0][(case / 5 % 4) as usize];
        for v in &mut t.xy_f {
            *v = [0, 1].map(|_| (rng.below(2 * span as u64) as i64 - span) as f64 / scale);
        }
        let px = rng.below(2 * pspan as u64) as i64 - pspan;
        let py = rng.below(2 * pspan as u64) as i64 - pspan;
        let sub = 1 + (rng.below(12) as u32);
        let grid = 1 + (rng.below(16) as u32);
        let coords = t.xy.iter().flatten().fold(0, |m, c| m | c.unsigned_abs());
        if coords < 1 << 29 && (px.unsigned_abs() | py.unsigned_abs()) < 1 << (28 - sub) {
            small += 1;
        } else {
            large += 1;
        }
        let e = exact(t.xy.map(|p| p.map(i128::from)), px, py, sub);
        assert_eq!(t.edges_fixed(px, py, sub), e, "case {case}");
        let (ws, dx, dy) = t.edges_fixed_with_steps(px, py, sub);
        let ex = exact(t.xy.map(|p| p.map(i128::from)), px + 1, py, sub);
        let ey = exact(t.xy.map(|p| p.map(i128::from)), px, py + 1, sub);
        assert_eq!(ws, e, "case {case}: {:?} at ({px}, {py}) sub {sub}", t.xy);
        assert_eq!(
            dx,
            [0, 1, 2].map(|i| ex[i].wrapping_sub(e[i])),
            "case {case}"
        );
        assert_eq!(
            dy,
            [0, 1, 2].map(|i| ey[i].wrapping_sub(e[i])),
            "case {case}"
        );
        let g = f64::from(1u32 << grid);
        let snapped = t.xy_f.map(|p| p.map(|c| (c * g).round_ties_even() as i128));
        assert_eq!(
            t.edges_fixed_on_grid(px, py, grid),
            exact(snapped, px, py, grid),
            "case {case}: {:?} at ({px}, {py}) grid {grid}",
            t.xy_f
        );
    }
    assert!(small > 500_000 && large > 500_000, "{small} {large}");
}

/// `edges_float_and_steps` is `edges_float` at the pixel and its two neighbours, bit for bit
/// (signed zeros included; a NaN is any NaN, as Rust leaves a NaN result's sign open): 1M
/// seeded triangles, shared and equal vertices, pixels near and far, coordinates of every
/// magnitude and non-finite ones.
#[test]
fn float_edges_and_steps_equal_three_evaluations() {
    let mut rng = Rng(0xED6E_0003);
    let mut t = tri();
    let coord = |rng: &mut Rng| match rng.below(5) {
        0 => rng.below(8) as f64 - 4.0,
        1 => rng.range(-2048.0, 2048.0),
        2 => rng.range(-1.0, 1.0) * 2f64.powi(rng.below(60) as i32),
        3 => [0.0, -0.0, 0.5, f64::NAN, f64::INFINITY][rng.below(5) as usize],
        _ => (rng.below(4096) as f64) / 256.0,
    };
    for k in 0..1_000_000u32 {
        for v in &mut t.xy_f {
            *v = [coord(&mut rng), coord(&mut rng)];
        }
        if k % 7 == 0 {
            t.xy_f[2] = t.xy_f[k as usize % 2];
        }
        let (px, py) = (coord(&mut rng), coord(&mut rng));
        let got = t.edges_float_and_steps(px, py);
        let want = [
            t.edges_float(px, py),
            t.edges_float(px + 1.0, py),
            t.edges_float(px, py + 1.0),
        ];
        let bits = |e: [[f64; 3]; 3]| {
            e.map(|r| {
                r.map(|v| {
                    if v.is_nan() {
                        f64::NAN.to_bits()
                    } else {
                        v.to_bits()
                    }
                })
            })
        };
        assert_eq!(bits(got), bits(want), "{:?} at ({px}, {py})", t.xy_f);
    }
}
