//! Fill rule on hand-built cases, spans against a brute-force model, edge functions, and depth.

use crate::raster_common::*;
use texsim::raster::{
    coverage_count, rasterize, setup, Coverage, DrawTri, ScreenTri, Setup, VertexSource, NO_TRI,
};

const BOTH: [Coverage; 2] = [Coverage::Fixed, Coverage::Float];

/// Set of covered pixels of a single-triangle setup (w x h = 16 x 16, vertices in pixels).
fn covered(pts: [[f64; 2]; 3], sp: u32, cov: Coverage) -> Vec<(u32, u32)> {
    let (w, h) = (16u32, 16u32);
    let clip: Vec<[f64; 4]> = pts
        .iter()
        .map(|p| px_to_clip(p[0], p[1], 0.0, w, h))
        .collect();
    let s = setup(
        &clip,
        &[DrawTri {
            v: [0, 1, 2],
            cull_back: false,
        }],
        w,
        h,
        &cfg(sp, 16),
    );
    let c = coverage_count(&s, cov);
    let mut out = Vec::new();
    for py in 0..h {
        for px in 0..w {
            match c[(py * w + px) as usize] {
                0 => {}
                1 => out.push((px, py)),
                k => panic!("one triangle covered ({px},{py}) {k} times"),
            }
        }
    }
    out
}

fn all_orders(p: [[f64; 2]; 3]) -> Vec<[[f64; 2]; 3]> {
    let [a, b, c] = p;
    vec![
        [a, b, c],
        [b, c, a],
        [c, a, b],
        [a, c, b],
        [c, b, a],
        [b, a, c],
    ]
}

fn check_hand_case(pts: [[f64; 2]; 3], expect: &[(u32, u32)]) {
    let mut expect = expect.to_vec();
    expect.sort_by_key(|&(x, y)| (y, x));
    for order in all_orders(pts) {
        for sp in [1u32, 4, 8, 12] {
            for cov in BOTH {
                assert_eq!(covered(order, sp, cov), expect, "{order:?} sp={sp} {cov:?}");
            }
        }
    }
}

#[test]
fn top_left_square_diagonal_through_centres() {
    // Square (2.5,2.5)-(6.5,6.5): every side and the diagonal run through pixel centres.
    let a = [[2.5, 2.5], [6.5, 2.5], [6.5, 6.5]];
    let b = [[2.5, 2.5], [6.5, 6.5], [2.5, 6.5]];
    // Upper-right half: top edge in, right edge out, diagonal is its left edge: in.
    let mut ea = Vec::new();
    let mut eb = Vec::new();
    for py in 2..6u32 {
        for px in 2..6u32 {
            if px >= py {
                ea.push((px, py));
            } else {
                eb.push((px, py));
            }
        }
    }
    check_hand_case(a, &ea);
    // Lower-left half: left edge in, bottom edge out, diagonal is its right edge: out.
    check_hand_case(b, &eb);
}

#[test]
fn top_left_apex_up_and_flat_top() {
    // Apex on a pixel centre at the top: the apex sample is on a left and a right edge: out.
    check_hand_case(
        [[4.5, 2.5], [2.5, 6.5], [6.5, 6.5]],
        &[(4, 3), (3, 4), (4, 4), (3, 5), (4, 5), (5, 5)],
    );
    // Flat top on pixel centres: top edge in (left corner in, right corner out), bottom apex out.
    check_hand_case(
        [[2.5, 2.5], [6.5, 2.5], [4.5, 6.5]],
        &[
            (2, 2),
            (3, 2),
            (4, 2),
            (5, 2),
            (3, 3),
            (4, 3),
            (5, 3),
            (3, 4),
            (4, 4),
            (4, 5),
        ],
    );
    // Flat bottom through centres is excluded; vertical left edge through centres is included,
    // the hypotenuse (a right edge) is not, nor the apex on both.
    check_hand_case(
        [[3.5, 1.5], [3.5, 4.5], [6.5, 4.5]],
        &[(3, 2), (3, 3), (4, 3)],
    );
    // Vertical right edge through centres is excluded; the hypotenuse is a left edge.
    check_hand_case(
        [[6.5, 1.5], [3.5, 4.5], [6.5, 4.5]],
        &[(5, 2), (4, 3), (5, 3)],
    );
}

#[test]
fn top_left_four_triangles_around_a_centre_vertex() {
    // Four triangles sharing the vertex (5.5, 5.5) = centre of pixel (5,5): exactly one owns it.
    let c = [5.5, 5.5];
    let corners = [[1.5, 1.5], [9.5, 1.5], [9.5, 9.5], [1.5, 9.5]];
    let (w, h) = (16u32, 16u32);
    let mut clip: Vec<[f64; 4]> = corners
        .iter()
        .map(|p| px_to_clip(p[0], p[1], 0.0, w, h))
        .collect();
    clip.push(px_to_clip(c[0], c[1], 0.0, w, h));
    let tris: Vec<[u32; 3]> = (0..4).map(|i| [4, i, (i + 1) % 4]).collect();
    for sp in [1u32, 8] {
        let s = setup(&clip, &draws(&tris, false), w, h, &cfg(sp, 16));
        for cov in BOTH {
            let cnt = coverage_count(&s, cov);
            for py in 0..h {
                for px in 0..w {
                    let inside = (1..9).contains(&px) && (1..9).contains(&py);
                    assert_eq!(
                        cnt[(py * w + px) as usize],
                        u32::from(inside),
                        "({px},{py})"
                    );
                }
            }
            // The owner of the shared vertex: the triangle for which both edges through it are
            // top or left, i.e. the one to the lower right of (+eps, +eps^2): the right one.
            let owner: Vec<usize> = (0..4)
                .filter(|&i| covers_fixed(&s.tris[i], 5, 5, sp))
                .collect();
            assert_eq!(owner.len(), 1);
            assert_eq!(
                s.tris[owner[0]].src, 1,
                "the right-hand triangle owns the vertex"
            );
        }
    }
}

/// Random triangles on coarse grids (many samples exactly on edges and vertices), one at a
/// time, against the brute-force model; also the edge-function contract.
#[test]
fn spans_match_brute_force_and_edges() {
    let mut rng = Rng(42);
    let (w, h) = (48u32, 40u32);
    let mut tested = 0;
    for case in 0..3000 {
        let sp = [1u32, 2, 3, 8, 12][case % 5];
        let grid = [1.0, 0.5, 0.25, 1.0 / 16.0, 1.0 / 4096.0][case % 5];
        let mut v = Vec::new();
        for _ in 0..3 {
            let x = (rng.range(-10.0, 58.0) / grid).round() * grid;
            let y = (rng.range(-10.0, 50.0) / grid).round() * grid;
            v.push(px_to_clip(x, y, rng.range(-1.0, 1.0), w, h));
        }
        if case % 7 == 0 {
            // Random w: the same screen triangle through a different divide.
            for c in &mut v {
                let s = rng.range(0.1, 10.0);
                *c = c.map(|q| q * s);
            }
        }
        let s = setup(
            &v,
            &[DrawTri {
                v: [0, 1, 2],
                cull_back: false,
            }],
            w,
            h,
            &cfg(sp, 16),
        );
        if s.tris.is_empty() {
            continue;
        }
        tested += 1;
        for (cov, float) in [(Coverage::Fixed, false), (Coverage::Float, true)] {
            assert_eq!(
                coverage_count(&s, cov),
                brute_count(&s, float),
                "case {case} {cov:?}"
            );
        }
        check_edges(&s, &s.tris[0]);
    }
    assert!(tested > 2000, "{tested}");
}

fn check_edges(s: &Setup, t: &ScreenTri) {
    let sp = s.subpixel_bits;
    let cross = (t.xy[1][0] - t.xy[0][0]) * (t.xy[2][1] - t.xy[0][1])
        - (t.xy[1][1] - t.xy[0][1]) * (t.xy[2][0] - t.xy[0][0]);
    assert_eq!(cross, t.area2);
    assert!(t.area2 > 0);
    let cnt = coverage_count(s, Coverage::Fixed);
    // Includes helper samples outside the bbox and the viewport.
    for py in -2..i64::from(s.height) + 2 {
        for px in -2..i64::from(s.width) + 2 {
            let e = t.edges_fixed(px, py, sp);
            assert_eq!(e[0] + e[1] + e[2], t.area2, "edges sum at ({px},{py})");
            let inside_view =
                px >= 0 && py >= 0 && px < i64::from(s.width) && py < i64::from(s.height);
            if !inside_view {
                continue;
            }
            let c = cnt[(py * i64::from(s.width) + px) as usize] == 1;
            if c {
                assert!(
                    e.iter().all(|&v| v >= 0),
                    "covered with a negative edge at ({px},{py})"
                );
                let [x0, y0, x1, y1] = t.bbox.map(i64::from);
                assert!(
                    px >= x0 && px < x1 && py >= y0 && py < y1,
                    "covered outside bbox"
                );
            }
            if e.iter().all(|&v| v > 0) {
                assert!(c, "strictly inside but not covered at ({px},{py})");
            }
            if e.iter().any(|&v| v < 0) {
                assert!(!c);
            }
        }
    }
}

/// Exact model of the fixed depth: round-half-up of sum(E_i z_i) / area2.
fn depth_fixed(t: &ScreenTri, px: i64, py: i64, sp: u32) -> i128 {
    let e = t.edges_fixed(px, py, sp);
    let n: i128 = (0..3).map(|i| i128::from(e[i]) * i128::from(t.z[i])).sum();
    let a = i128::from(t.area2);
    (2 * n + a).div_euclid(2 * a)
}

fn depth_float(t: &ScreenTri, px: i64, py: i64) -> f64 {
    let e = t.edges_float(px as f64, py as f64);
    (0..3).map(|i| e[i] * t.z_f[i]).sum::<f64>() / t.area2_f
}

/// Brute-force visibility (strictly-less, earlier wins ties) against `rasterize`.
#[test]
fn depth_matches_brute_force_model() {
    let mut rng = Rng(1234);
    let (w, h) = (70u32, 45u32);
    for case in 0..60 {
        let n = 2 + rng.below(30) as usize;
        let mut v = Vec::new();
        for _ in 0..3 * n {
            let x = rng.range(-20.0, 90.0);
            let y = rng.range(-20.0, 65.0);
            // Quantized depths make equal-depth ties common.
            let z = if case % 2 == 0 {
                (rng.range(-1.0, 1.0) * 4.0).round() / 4.0
            } else {
                rng.range(-1.0, 1.0)
            };
            v.push(px_to_clip(x, y, z, w, h));
        }
        let tris: Vec<[u32; 3]> = (0..n as u32)
            .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
            .collect();
        let sp = [4u32, 8, 12][case % 3];
        let db = [8u32, 16, 24, 30][case % 4];
        let s = setup(&v, &draws(&tris, false), w, h, &cfg(sp, db));
        let zmax = (1i128 << db) - 1;
        for depth_test in [true, false] {
            for (cov, float) in [(Coverage::Fixed, false), (Coverage::Float, true)] {
                let (vis, stats) = rasterize(&s, cov, depth_test);
                let mut exp = vec![NO_TRI; (w * h) as usize];
                let mut zi = vec![zmax; (w * h) as usize];
                let mut zf = vec![1.0f64; (w * h) as usize];
                let mut frags = 0;
                let mut fails = 0;
                for (ti, t) in s.tris.iter().enumerate() {
                    for py in 0..i64::from(h) {
                        for px in 0..i64::from(w) {
                            let i = (py * i64::from(w) + px) as usize;
                            let hit = if float {
                                covers_float(t, px, py)
                            } else {
                                covers_fixed(t, px, py, sp)
                            };
                            if !hit {
                                continue;
                            }
                            frags += 1;
                            let pass = if !depth_test {
                                true
                            } else if float {
                                let z = depth_float(t, px, py);
                                let p = z < zf[i];
                                if p {
                                    zf[i] = z;
                                }
                                p
                            } else {
                                let z = depth_fixed(t, px, py, sp);
                                assert!(z >= 0 && z <= zmax);
                                let lo = i128::from(*t.z.iter().min().unwrap());
                                let hi = i128::from(*t.z.iter().max().unwrap());
                                assert!(z >= lo && z <= hi, "depth outside the vertex range");
                                let p = z < zi[i];
                                if p {
                                    zi[i] = z;
                                }
                                p
                            };
                            if pass {
                                exp[i] = ti as u32;
                            } else {
                                fails += 1;
                            }
                        }
                    }
                }
                assert_eq!(vis.tri, exp, "case {case} {cov:?} depth_test={depth_test}");
                assert_eq!(stats.fragments, frags);
                assert_eq!(stats.depth_fails, fails);
                assert_eq!(
                    stats.visible,
                    exp.iter().filter(|&&t| t != NO_TRI).count() as u64
                );
            }
        }
    }
}

/// A near quad hides a far one whatever the submission order; equal depth: the first wins.
#[test]
fn depth_ordering_near_hides_far() {
    let (w, h) = (64u32, 48u32);
    let quad = |x0: f64, y0: f64, x1: f64, y1: f64, z: f64| {
        [[x0, y0], [x1, y0], [x1, y1], [x0, y1]].map(|p| px_to_clip(p[0], p[1], z, w, h))
    };
    let near = quad(5.0, 5.0, 40.0, 30.0, -0.2);
    let far = quad(20.0, 10.0, 60.0, 45.0, 0.3);
    for (first, second, near_first) in [(near, far, true), (far, near, false)] {
        let mut v = first.to_vec();
        v.extend_from_slice(&second);
        let tris = [[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]];
        let s = setup(&v, &draws(&tris, false), w, h, &cfg(8, 24));
        for cov in BOTH {
            let (vis, _) = rasterize(&s, cov, true);
            let (paint, _) = rasterize(&s, cov, false);
            for py in 0..h {
                for px in 0..w {
                    let (x, y) = (f64::from(px) + 0.5, f64::from(py) + 0.5);
                    let in_near = (5.0..40.0).contains(&x) && (5.0..30.0).contains(&y);
                    let in_far = (20.0..60.0).contains(&x) && (10.0..45.0).contains(&y);
                    let t = vis.tri[(py * w + px) as usize];
                    let src = (t != NO_TRI).then(|| s.tris[t as usize].src / 2);
                    let (near_src, far_src) = if near_first { (0, 1) } else { (1, 0) };
                    let expect = if in_near {
                        Some(near_src)
                    } else if in_far {
                        Some(far_src)
                    } else {
                        None
                    };
                    assert_eq!(src, expect, "{cov:?} ({px},{py})");
                    // Painter's order: the second quad wins wherever it covers.
                    let t = paint.tri[(py * w + px) as usize];
                    let src = (t != NO_TRI).then(|| s.tris[t as usize].src / 2);
                    let second_in = if near_first { in_far } else { in_near };
                    let first_in = if near_first { in_near } else { in_far };
                    let expect = if second_in {
                        Some(1)
                    } else if first_in {
                        Some(0)
                    } else {
                        None
                    };
                    assert_eq!(src, expect, "painter {cov:?} ({px},{py})");
                }
            }
        }
    }
    // Coplanar duplicate: the earlier triangle keeps every pixel.
    let q = quad(3.0, 3.0, 50.0, 40.0, 0.1);
    let v = q.to_vec();
    let tris = [[0, 1, 2], [0, 2, 3], [0, 1, 2], [0, 2, 3]];
    let s = setup(&v, &draws(&tris, false), w, h, &cfg(8, 24));
    for cov in BOTH {
        let (vis, st) = rasterize(&s, cov, true);
        assert!(vis
            .tri
            .iter()
            .all(|&t| t == NO_TRI || s.tris[t as usize].src < 2));
        assert_eq!(st.depth_fails * 2, st.fragments);
    }
}

/// `edges_fixed_with_steps` (one i64 evaluation plus constant steps) is bit-identical to three
/// `edges_fixed` calls, for ordinary coordinates and for ones far beyond any guard band whose
/// products leave `i64` (where it must fall back to the `i128` evaluation).
#[test]
fn edge_steps_match_three_evaluations() {
    let mut rng = Rng(77);
    let mut t = ScreenTri {
        xy: [[0; 2]; 3],
        xy_f: [[0.0; 2]; 3],
        z: [0; 3],
        z_f: [0.0; 3],
        inv_w: [1.0; 3],
        src: 0,
        source: VertexSource::Unclipped { swapped: false },
        area2: 1,
        area2_f: 1.0,
        bbox: [0; 4],
    };
    for case in 0..1_000_000u32 {
        let (span, pspan) = match case % 4 {
            0 => (1i64 << 20, 4096i64),
            1 => (1 << 31, 1 << 20),
            2 => (1 << 40, 1 << 40),
            _ => (1 << 44, 1 << 30),
        };
        for v in &mut t.xy {
            *v = [0, 1].map(|_| rng.below(2 * span as u64) as i64 - span);
        }
        let px = rng.below(2 * pspan as u64) as i64 - pspan;
        let py = rng.below(2 * pspan as u64) as i64 - pspan;
        let sub = 1 + (rng.below(12) as u32);
        let e = t.edges_fixed(px, py, sub);
        let ex = t.edges_fixed(px + 1, py, sub);
        let ey = t.edges_fixed(px, py + 1, sub);
        let dx = [0, 1, 2].map(|i| ex[i].wrapping_sub(e[i]));
        let dy = [0, 1, 2].map(|i| ey[i].wrapping_sub(e[i]));
        assert_eq!(
            t.edges_fixed_with_steps(px, py, sub),
            (e, dx, dy),
            "case {case}: {:?} at ({px}, {py}) sub {sub}",
            t.xy
        );
    }
}

/// `edges_fixed_on_grid` (the attribute setup from the float positions on a finer grid,
/// `interp.attr_subpixel_bits`): on the rasterizer's own grid it equals `edges_fixed` of the
/// snapped positions, and on a grid `k` bits finer it is `edges_fixed` scaled by `4^k` when
/// the float positions lie on the coarser grid.
#[test]
fn edges_on_a_finer_grid_match_the_snapped_edges() {
    let mut rng = Rng(78);
    let mut t = ScreenTri {
        xy: [[0; 2]; 3],
        xy_f: [[0.0; 2]; 3],
        z: [0; 3],
        z_f: [0.0; 3],
        inv_w: [1.0; 3],
        src: 0,
        source: VertexSource::Unclipped { swapped: false },
        area2: 1,
        area2_f: 1.0,
        bbox: [0; 4],
    };
    for case in 0..200_000u32 {
        let sub = 1 + (rng.below(12) as u32);
        let g = f64::from(1u32 << sub);
        for (v, f) in t.xy.iter_mut().zip(t.xy_f.iter_mut()) {
            *f = [0, 1].map(|_| (rng.below(1 << 30) as f64 / 65536.0) - 8192.0);
            *v = f.map(|c| (c * g).round_ties_even() as i64);
        }
        let px = rng.below(16384) as i64 - 8192;
        let py = rng.below(16384) as i64 - 8192;
        let e = t.edges_fixed(px, py, sub);
        assert_eq!(t.edges_fixed_on_grid(px, py, sub), e, "case {case}");
        // Positions on the coarse grid: the finer grid only scales the edges.
        let k = rng.below(16 - u64::from(sub) + 1) as u32;
        t.xy_f = t.xy.map(|v| v.map(|c| c as f64 / g));
        let fine = t.edges_fixed_on_grid(px, py, sub + k);
        let scale = 1i64 << (2 * k);
        assert_eq!(fine, e.map(|x| x * scale), "case {case}: sub {sub} + {k}");
    }
}
