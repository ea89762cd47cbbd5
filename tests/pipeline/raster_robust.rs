//! Degenerate, non-finite, off-screen, behind-the-camera and near-crossing triangles: skipped
//! or clipped, counted, never a panic, never a NaN in a set-up triangle.

use crate::raster_common::*;
use glam::{DMat4, DVec3};
use texsim::raster::{
    coverage_count, rasterize, setup, Coverage, DrawTri, Setup, GUARD_BAND, MAX_VIEWPORT, W_EPSILON,
};

const BOTH: [Coverage; 2] = [Coverage::Fixed, Coverage::Float];

fn one(v: &[[f64; 4]], cull_back: bool, w: u32, h: u32) -> Setup {
    setup(
        v,
        &[DrawTri {
            v: [0, 1, 2],
            cull_back,
        }],
        w,
        h,
        &cfg(8, 24),
    )
}

/// Every invariant a set-up triangle must satisfy, plus the stats identity.
fn check_setup(clip: &[[f64; 4]], d: &[DrawTri], s: &Setup) {
    let st = &s.stats;
    assert_eq!(st.input, d.len() as u64);
    assert_eq!(st.output, s.tris.len() as u64);
    let mut produced = vec![false; d.len()];
    let zmax = (1u64 << s.depth_bits) - 1;
    let bound = (2.5 * f64::from(MAX_VIEWPORT) * 4096.0) as i64;
    for (i, t) in s.tris.iter().enumerate() {
        produced[t.src as usize] = true;
        let src_bary = s.src_bary(i);
        let floats = t
            .xy_f
            .iter()
            .flatten()
            .chain(&t.z_f)
            .chain(&t.inv_w)
            .chain(src_bary.iter().flatten())
            .chain(std::iter::once(&t.area2_f));
        assert!(
            floats.into_iter().all(|v| v.is_finite()),
            "non-finite field in {t:?}"
        );
        assert!(t.area2 > 0);
        assert!(t.xy.iter().flatten().all(|c| c.abs() < bound));
        assert!(t.z.iter().all(|&z| u64::from(z) <= zmax));
        assert!(t.z_f.iter().all(|z| (0.0..=1.0).contains(z)));
        assert!(t
            .inv_w
            .iter()
            .all(|&iw| iw > 0.0 && iw <= 1.0 / W_EPSILON * 1.000001));
        assert!(t.bbox[0] <= t.bbox[2] && t.bbox[2] <= s.width);
        assert!(t.bbox[1] <= t.bbox[3] && t.bbox[3] <= s.height);
        // src_bary reconstructs the clip-space vertex (linear in clip space), when the source
        // is well conditioned (magnitudes within 1e6 of each other).
        let src = d[t.src as usize].v.map(|i| clip[i as usize]);
        let big = src.iter().flatten().fold(0.0f64, |m, c| m.max(c.abs()));
        let w_min = src.iter().map(|c| c[3].abs()).fold(f64::MAX, f64::min);
        let conditioned = big < 1e6 && w_min > 1e-3;
        for (k, b) in src_bary.iter().enumerate() {
            assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-9, "bary {b:?}");
            assert!(b.iter().all(|&c| (-1e-9..=1.0 + 1e-9).contains(&c)));
            if !conditioned {
                continue;
            }
            let p: [f64; 4] = std::array::from_fn(|c| (0..3).map(|i| b[i] * src[i][c]).sum());
            let px = (p[0] / p[3] + 1.0) * 0.5 * f64::from(s.width);
            let py = (1.0 - p[1] / p[3]) * 0.5 * f64::from(s.height);
            let tol = 1e-6 * (1.0 + px.abs() + py.abs());
            assert!(
                (px - t.xy_f[k][0]).abs() < tol && (py - t.xy_f[k][1]).abs() < tol,
                "{px} {py} vs {:?}, p {p:?}, src {src:?}, b {b:?}",
                t.xy_f[k]
            );
            assert!((1.0 / p[3] - t.inv_w[k]).abs() <= 1e-6 * t.inv_w[k]);
        }
    }
    let n_produced = produced.iter().filter(|&&p| p).count() as u64;
    assert_eq!(
        st.input,
        st.non_finite + st.clipped_away + st.culled + st.degenerate + n_produced,
        "{st:?}"
    );
    for cov in BOTH {
        let (vis, rs) = rasterize(s, cov, true);
        assert!(vis
            .tri
            .iter()
            .all(|&t| t == texsim::raster::NO_TRI || (t as usize) < s.tris.len()));
        assert!(rs.visible <= rs.fragments);
        let _ = coverage_count(s, cov);
    }
}

#[test]
fn degenerate_triangles_are_skipped() {
    let (w, h) = (32u32, 32u32);
    let cases = [
        // Collinear.
        [[1.0, 1.0], [5.0, 5.0], [9.0, 9.0]],
        // Repeated vertex.
        [[3.0, 4.0], [3.0, 4.0], [20.0, 7.0]],
        // All the same point.
        [[7.3, 7.3], [7.3, 7.3], [7.3, 7.3]],
        // Non-zero float area but zero after snapping (1/1024 px apart at 8 bits).
        [[10.0, 10.0], [20.0, 10.0], [15.0, 10.0 + 1.0 / 1024.0]],
    ];
    for c in cases {
        let v: Vec<[f64; 4]> = c
            .iter()
            .map(|p| px_to_clip(p[0], p[1], 0.0, w, h))
            .collect();
        let s = one(&v, false, w, h);
        assert_eq!(s.stats.degenerate, 1, "{c:?}: {:?}", s.stats);
        assert!(s.tris.is_empty());
        check_setup(
            &v,
            &[DrawTri {
                v: [0, 1, 2],
                cull_back: false,
            }],
            &s,
        );
    }
}

#[test]
fn non_finite_and_bad_indices_are_skipped() {
    let good = [
        [-0.5, -0.5, 0.0, 1.0],
        [0.5, -0.5, 0.0, 1.0],
        [0.0, 0.5, 0.0, 1.0],
    ];
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        for vert in 0..3 {
            for comp in 0..4 {
                let mut v = good.to_vec();
                v[vert][comp] = bad;
                let d = [DrawTri {
                    v: [0, 1, 2],
                    cull_back: false,
                }];
                let s = setup(&v, &d, 32, 32, &cfg(8, 24));
                assert_eq!(s.stats.non_finite, 1, "{bad} at {vert}.{comp}");
                check_setup(&v, &d, &s);
            }
        }
    }
    let d = [
        DrawTri {
            v: [0, 1, 3],
            cull_back: false,
        },
        DrawTri {
            v: [u32::MAX, 1, 2],
            cull_back: true,
        },
        DrawTri {
            v: [0, 1, 2],
            cull_back: false,
        },
    ];
    let s = setup(&good, &d, 32, 32, &cfg(8, 24));
    assert_eq!(s.stats.non_finite, 2);
    assert_eq!(s.stats.output, 1);
    check_setup(&good, &d, &s);
}

#[test]
fn off_screen_and_behind_camera_are_clipped_away() {
    let cases: [[[f64; 4]; 3]; 6] = [
        // Right of the screen (x > w for all).
        [
            [1.5, 0.0, 0.0, 1.0],
            [3.0, 0.5, 0.0, 1.0],
            [2.0, -0.5, 0.0, 1.0],
        ],
        // Above.
        [
            [0.0, 1.5, 0.0, 1.0],
            [0.5, 3.0, 0.0, 1.0],
            [-0.5, 2.0, 0.0, 1.0],
        ],
        // Behind the camera (w < 0).
        [
            [0.0, 0.0, 0.5, -1.0],
            [0.5, 0.0, 0.5, -1.0],
            [0.0, 0.5, 0.5, -2.0],
        ],
        // In front of the near plane (z < -w).
        [
            [0.0, 0.0, -1.5, 1.0],
            [0.5, 0.0, -2.0, 1.0],
            [0.0, 0.5, -3.0, 1.0],
        ],
        // Beyond the far plane.
        [
            [0.0, 0.0, 1.5, 1.0],
            [0.5, 0.0, 2.0, 1.0],
            [0.0, 0.5, 3.0, 1.0],
        ],
        // w = 0 everywhere.
        [
            [0.0, 0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
        ],
    ];
    for c in cases {
        let d = [DrawTri {
            v: [0, 1, 2],
            cull_back: false,
        }];
        let s = setup(&c, &d, 40, 30, &cfg(8, 24));
        assert_eq!(s.stats.clipped_away, 1, "{c:?}: {:?}", s.stats);
        check_setup(&c, &d, &s);
    }
}

#[test]
fn near_plane_and_guard_band_crossings_are_clipped() {
    let (w, h) = (64u32, 64u32);
    let cases: [[[f64; 4]; 3]; 4] = [
        // One vertex behind the camera: a quad remains (two triangles).
        [
            [-0.5, -0.5, 0.5, 1.0],
            [0.5, -0.5, 0.5, 1.0],
            [0.0, 0.8, 2.0, -1.0],
        ],
        // Two vertices behind the near plane: one triangle remains.
        [
            [-0.5, -0.5, 0.5, 1.0],
            [0.5, -0.5, -3.0, 1.0],
            [0.0, 0.5, -3.0, 1.0],
        ],
        // Far outside the guard band on both sides.
        [
            [-1e6, -0.5, 0.0, 1.0],
            [1e6, -0.5, 0.0, 1.0],
            [0.0, 1e6, 0.0, 1.0],
        ],
        // Crossing w = 0 far off to the side.
        [
            [-100.0, 0.0, 0.0, -0.5],
            [0.5, 0.1, 0.0, 1.0],
            [0.0, 0.5, 0.0, 1.0],
        ],
    ];
    for c in cases {
        for cull in [false, true] {
            let d = [DrawTri {
                v: [0, 1, 2],
                cull_back: cull,
            }];
            let s = setup(&c, &d, w, h, &cfg(12, 30));
            assert_eq!(s.stats.clipped, 1, "{c:?}: {:?}", s.stats);
            check_setup(&c, &d, &s);
            if !cull {
                assert!(!s.tris.is_empty(), "{c:?}: {:?}", s.stats);
            }
            for t in &s.tris {
                for p in &t.xy_f {
                    let lim = (GUARD_BAND + 1.0) / 2.0 * 64.0 + 1e-6;
                    assert!(p[0].abs() <= lim && p[1].abs() <= lim, "{p:?}");
                }
            }
        }
        // With culling, exactly one orientation survives.
        let rev = [c[0], c[2], c[1]];
        let d = [DrawTri {
            v: [0, 1, 2],
            cull_back: true,
        }];
        let a = setup(&c, &d, w, h, &cfg(12, 30));
        let b = setup(&rev, &d, w, h, &cfg(12, 30));
        assert_eq!(
            a.tris.is_empty() as u32 + b.tris.is_empty() as u32,
            1,
            "{c:?}"
        );
    }
}

#[test]
fn back_face_culling_counts() {
    let (w, h) = (32u32, 32u32);
    // Counter-clockwise in NDC: front.
    let ccw = [
        [-0.5, -0.5, 0.0, 1.0],
        [0.5, -0.5, 0.0, 1.0],
        [0.0, 0.5, 0.0, 1.0],
    ];
    let cw = [ccw[0], ccw[2], ccw[1]];
    assert_eq!(one(&ccw, true, w, h).stats.output, 1);
    let s = one(&cw, true, w, h);
    assert_eq!((s.stats.culled, s.stats.output), (1, 0));
    assert_eq!(one(&cw, false, w, h).stats.output, 1);
    // Same pixels either way round.
    for cov in BOTH {
        assert_eq!(
            coverage_count(&one(&ccw, false, w, h), cov),
            coverage_count(&one(&cw, false, w, h), cov)
        );
    }
}

#[test]
fn odd_viewports_never_panic() {
    let v = [
        [-0.9, -0.9, 0.0, 1.0],
        [0.9, -0.8, 0.0, 1.0],
        [0.0, 0.95, 0.0, 1.0],
    ];
    let d = [DrawTri {
        v: [0, 1, 2],
        cull_back: false,
    }];
    for (w, h) in [(0u32, 0u32), (0, 10), (10, 0), (1, 1), (37, 23), (3, 200)] {
        let s = setup(&v, &d, w, h, &cfg(8, 24));
        check_setup(&v, &d, &s);
        let (vis, _) = rasterize(&s, Coverage::Fixed, true);
        assert_eq!(vis.tri.len(), (w * h) as usize);
    }
    let s = setup(&v, &d, 100_000, 20, &cfg(8, 24));
    assert_eq!(s.width, MAX_VIEWPORT);
    // Config widths outside the range are clamped, not a panic.
    let s = setup(&v, &d, 16, 16, &cfg(0, 99));
    assert_eq!((s.subpixel_bits, s.depth_bits), (1, 30));
    check_setup(&v, &d, &s);
}

/// Random garbage: huge, tiny, zero, negative w, NaN, infinities, bad indices.
#[test]
fn fuzz_setup_and_rasterize() {
    let mut rng = Rng(77);
    let specials = [
        0.0,
        -0.0,
        1e300,
        -1e300,
        1e-300,
        1e-12,
        f64::NAN,
        f64::INFINITY,
        1.0,
        -1.0,
        4.0,
        1e20,
    ];
    for round in 0..400 {
        let nv = 3 + rng.below(30) as usize;
        let v: Vec<[f64; 4]> = (0..nv)
            .map(|_| {
                std::array::from_fn(|c| match rng.below(10) {
                    0 => specials[rng.below(specials.len() as u64) as usize],
                    1 => rng.range(-1e6, 1e6),
                    _ if c == 3 => rng.range(-0.5, 3.0),
                    _ => rng.range(-3.0, 3.0),
                })
            })
            .collect();
        let nt = 1 + rng.below(40) as usize;
        let d: Vec<DrawTri> = (0..nt)
            .map(|_| DrawTri {
                v: std::array::from_fn(|_| rng.below(nv as u64 + 1) as u32),
                cull_back: rng.below(2) == 0,
            })
            .collect();
        let (w, h) = (1 + rng.below(70) as u32, 1 + rng.below(50) as u32);
        let sp = 1 + (round % 12) as u32;
        let s = setup(&v, &d, w, h, &cfg(sp, 8 + (round % 23) as u32));
        check_setup(&v, &d, &s);
    }
}

/// Two triangles sharing an edge that crosses the near plane, w = 0 or the guard band: every
/// clip vertex on the shared edge is bit-identical in both (watertight after clipping).
#[test]
fn shared_clipped_edges_are_cut_identically() {
    let mut rng = Rng(31337);
    let mut checked = 0;
    for _ in 0..3000 {
        let mut p = || {
            [
                rng.range(-30.0, 30.0),
                rng.range(-30.0, 30.0),
                rng.range(-3.0, 3.0),
                rng.range(-1.0, 3.0),
            ]
        };
        let v = vec![p(), p(), p(), p()];
        // Edge (0, 1) shared, traversed in opposite directions.
        let d = [
            DrawTri {
                v: [0, 1, 2],
                cull_back: false,
            },
            DrawTri {
                v: [1, 0, 3],
                cull_back: false,
            },
        ];
        let s = setup(&v, &d, 97, 61, &cfg(8, 24));
        check_setup(&v, &d, &s);
        let on_edge = |src: u32, third: usize| -> Vec<[u64; 2]> {
            s.tris
                .iter()
                .enumerate()
                .filter(|(_, t)| t.src == src)
                .flat_map(|(i, t)| {
                    let b = s.src_bary(i);
                    (0..3)
                        .filter(move |&k| b[k][third] == 0.0)
                        .map(move |k| t.xy_f[k].map(f64::to_bits))
                })
                .collect()
        };
        let a = on_edge(0, 2);
        let b = on_edge(1, 2);
        for p in &a {
            checked += 1;
            assert!(
                b.contains(p) || b.is_empty(),
                "shared-edge vertex {p:?} not in {b:?}"
            );
        }
    }
    assert!(checked > 1000, "{checked}");
}

/// Setup projects each vertex once for the unclipped triangles that share it: a mesh with
/// shared vertices sets up exactly as the same triangles with a copy of every vertex each,
/// clipped ones (near plane, guard band) and culled ones included.
#[test]
fn shared_vertices_set_up_as_copies() {
    let (p, t) = uv_sphere(200, 100);
    let view = DMat4::look_at_rh(
        DVec3::new(0.3, 0.2, 0.6),
        DVec3::new(1.0, 0.0, -0.5),
        DVec3::Y,
    );
    let proj = DMat4::perspective_rh_gl(100f64.to_radians(), 1.3, 0.35, 10.0);
    let clip = transform(&(proj * view), &p);
    let copies: Vec<[f64; 4]> = t.iter().flatten().map(|&i| clip[i as usize]).collect();
    for cull in [false, true] {
        let shared = setup(&clip, &draws(&t, cull), 200, 150, &cfg(8, 24));
        let unrolled: Vec<[u32; 3]> = (0..t.len() as u32)
            .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
            .collect();
        let copied = setup(&copies, &draws(&unrolled, cull), 200, 150, &cfg(8, 24));
        assert!(shared.stats.clipped > 50, "{:?}", shared.stats);
        assert_eq!(shared.stats, copied.stats);
        assert_eq!(shared.tris, copied.tris);
        assert_eq!(shared.clipped_bary, copied.clipped_bary);
        check_setup(&clip, &draws(&t, cull), &shared);
    }
}
