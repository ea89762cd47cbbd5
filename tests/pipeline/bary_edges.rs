//! The `bary` stage's edge evaluation (`pipeline::bary::edges_with_steps`, `edges_at`: `i64`
//! without overflow checks under their bounds) gives the `ScreenTri` routines' values, inside
//! the bounds and beyond them (where it falls back to those routines).

use crate::rng_common::Rng;
use texsim::pipeline::bary::{edges_at, edges_with_steps};
use texsim::raster::ScreenTri;

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
fn bary_edges_match_the_screen_tri_routines() {
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
        assert_eq!(
            edges_with_steps(&t, px, py, sub),
            t.edges_fixed_with_steps(px, py, sub),
            "case {case}: {:?} at ({px}, {py}) sub {sub}",
            t.xy
        );
        assert_eq!(edges_at(&t, px, py, sub, None), t.edges_fixed(px, py, sub));
        assert_eq!(
            edges_at(&t, px, py, sub, Some(grid)),
            t.edges_fixed_on_grid(px, py, grid),
            "case {case}: {:?} at ({px}, {py}) grid {grid}",
            t.xy_f
        );
    }
    assert!(small > 500_000 && large > 500_000, "{small} {large}");
}
