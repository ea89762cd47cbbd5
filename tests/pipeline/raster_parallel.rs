//! Determinism across thread counts, and the throughput figure on a 100k-triangle mesh.

use crate::raster_common::*;
use glam::{DMat4, DVec3};
use std::time::Instant;
use texsim::raster::{
    band_rows, coverage_count, rasterize, setup, Coverage, DrawTri, Setup, NO_TRI,
};

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
        .install(f)
}

/// Random overlapping triangles with quantized depths (many equal-depth ties) plus big ones.
fn random_scene(seed: u64, n: usize, w: u32, h: u32) -> Setup {
    let mut rng = Rng(seed);
    let mut v = Vec::new();
    let mut d = Vec::new();
    for i in 0..n {
        let (cx, cy) = (
            rng.range(-20.0, f64::from(w) + 20.0),
            rng.range(-20.0, f64::from(h) + 20.0),
        );
        let size = if i % 50 == 0 {
            300.0
        } else {
            rng.range(1.0, 40.0)
        };
        let z = (rng.range(-1.0, 1.0) * 8.0).round() / 8.0;
        let base = v.len() as u32;
        for _ in 0..3 {
            let mut c = px_to_clip(
                cx + rng.range(-size, size),
                cy + rng.range(-size, size),
                z,
                w,
                h,
            );
            let s = rng.range(0.5, 2.0);
            c = c.map(|q| q * s);
            v.push(c);
        }
        d.push(DrawTri {
            v: [base, base + 1, base + 2],
            cull_back: i % 3 == 0,
        });
    }
    setup(&v, &d, w, h, &cfg(8, 24))
}

/// The bands' height follows the thread count (`band_rows`): 64, 37 and 18 rows for the
/// 600-row image on 1, 2 and 4 threads, 31, 16 and 16 for the 250-row one.
#[test]
fn identical_for_any_thread_count() {
    for (seed, w, h) in [
        (1u64, 333u32, 250u32),
        (2, 128, 17),
        (3, 64, 300),
        (5, 96, 600),
    ] {
        let s = random_scene(seed, 4000, w, h);
        for cov in [Coverage::Fixed, Coverage::Float] {
            for depth in [true, false] {
                let r1 = in_pool(1, || rasterize(&s, cov, depth));
                for threads in [2, 4] {
                    assert!(h < 32 || band_rows(h, threads) < band_rows(h, 1));
                    let r = in_pool(threads, || rasterize(&s, cov, depth));
                    assert_eq!(r.0, r1.0, "{cov:?} depth={depth} threads={threads}");
                    assert_eq!(r.1, r1.1);
                }
            }
            let c1 = in_pool(1, || coverage_count(&s, cov));
            for threads in [2, 4] {
                assert_eq!(in_pool(threads, || coverage_count(&s, cov)), c1);
            }
            if w * h < 5000 {
                assert_eq!(
                    c1,
                    brute_count(&s, cov == Coverage::Float),
                    "brute-force model"
                );
            }
        }
    }
}

/// More triangles than one binning task takes (the bins are built by chunks of triangles in
/// parallel and walked chunk by chunk): the same buffers and counters for any thread count.
#[test]
fn binned_by_chunks_identical_for_any_thread_count() {
    let s = random_scene(4, 40_000, 257, 190);
    for cov in [Coverage::Fixed, Coverage::Float] {
        let r1 = in_pool(1, || rasterize(&s, cov, true));
        for threads in [2, 3] {
            let r = in_pool(threads, || rasterize(&s, cov, true));
            assert_eq!(r.0, r1.0, "{cov:?} threads={threads}");
            assert_eq!(r.1, r1.1);
        }
        let c1 = in_pool(1, || coverage_count(&s, cov));
        assert_eq!(in_pool(2, || coverage_count(&s, cov)), c1);
        // Every fragment of the counts is a fragment of the traversal.
        assert_eq!(
            c1.iter().map(|&c| u64::from(c)).sum::<u64>(),
            r1.1.fragments
        );
    }
    // Without the depth test the last covering triangle in submission order wins: the bins
    // keep that order across their chunks.
    let (vis, _) = in_pool(2, || rasterize(&s, Coverage::Fixed, false));
    let mut last = vec![NO_TRI; vis.tri.len()];
    for (id, t) in s.tris.iter().enumerate() {
        for py in t.bbox[1]..t.bbox[3] {
            for px in t.bbox[0]..t.bbox[2] {
                if covers_fixed(t, i64::from(px), i64::from(py), s.subpixel_bits) {
                    last[(py * s.width + px) as usize] = id as u32;
                }
            }
        }
    }
    assert_eq!(vis.tri, last);
}

/// A ~100k-triangle sphere at 1024x1024; prints the timings (run with --nocapture; use
/// `--release` for the figure in the report). The bound is loose (shared CI machines).
#[test]
fn throughput_100k_triangles_1024() {
    let (p, t) = uv_sphere(320, 160);
    assert!(t.len() >= 100_000, "{}", t.len());
    let view = DMat4::look_at_rh(DVec3::new(0.0, 0.0, 2.2), DVec3::ZERO, DVec3::Y);
    let proj = DMat4::perspective_rh_gl(60f64.to_radians(), 1.0, 0.1, 10.0);
    let clip = transform(&(proj * view * DMat4::from_rotation_x(0.5)), &p);
    for cull in [true, false] {
        let d = draws(&t, cull);
        let t0 = Instant::now();
        let s = setup(&clip, &d, 1024, 1024, &cfg(8, 24));
        let t1 = Instant::now();
        let (vis_fixed, st) = rasterize(&s, Coverage::Fixed, true);
        let t2 = Instant::now();
        let (vis_float, _) = rasterize(&s, Coverage::Float, true);
        let t3 = Instant::now();
        eprintln!(
            "{} tris, cull={cull}, {} threads: setup {:.1} ms, fixed {:.1} ms, float {:.1} ms; {st:?}",
            t.len(),
            rayon::current_num_threads(),
            (t1 - t0).as_secs_f64() * 1e3,
            (t2 - t1).as_secs_f64() * 1e3,
            (t3 - t2).as_secs_f64() * 1e3,
        );
        assert!(st.visible > 600_000, "{st:?}");
        let differ = vis_fixed
            .tri
            .iter()
            .zip(&vis_float.tri)
            .filter(|(a, b)| a != b)
            .count();
        assert!(
            differ * 100 < vis_fixed.tri.len(),
            "fixed vs float differ on {differ} pixels"
        );
        assert!((t3 - t0).as_secs_f64() < 20.0);
        let (t4, (vis1, _)) = in_pool(1, || {
            let t = Instant::now();
            let s1 = setup(&clip, &d, 1024, 1024, &cfg(8, 24));
            let r = rasterize(&s1, Coverage::Fixed, true);
            (t.elapsed(), r)
        });
        eprintln!(
            "  1 thread: setup + fixed raster {:.1} ms",
            t4.as_secs_f64() * 1e3
        );
        assert_eq!(vis1, vis_fixed);
    }
}

#[test]
fn setup_identical_for_any_thread_count() {
    let mut rng = Rng(5);
    let (w, h) = (300u32, 200u32);
    let mut v = Vec::new();
    for _ in 0..30_000 {
        // Many cross the near plane or the guard band, some are behind the camera.
        v.push([
            rng.range(-6.0, 6.0),
            rng.range(-6.0, 6.0),
            rng.range(-2.0, 2.0),
            rng.range(-0.5, 2.0),
        ]);
    }
    let d: Vec<DrawTri> = (0..10_000u32)
        .map(|i| DrawTri {
            v: [3 * i, 3 * i + 1, 3 * i + 2],
            cull_back: i % 2 == 0,
        })
        .collect();
    let s1 = in_pool(1, || setup(&v, &d, w, h, &cfg(8, 24)));
    assert!(
        s1.stats.clipped > 1000 && s1.stats.output > 1000,
        "{:?}",
        s1.stats
    );
    // Submission order is kept.
    assert!(s1.tris.windows(2).all(|p| p[0].src <= p[1].src));
    for threads in [2, 4] {
        let s = in_pool(threads, || setup(&v, &d, w, h, &cfg(8, 24)));
        assert_eq!(s.stats, s1.stats);
        assert_eq!(s.tris, s1.tris, "threads={threads}");
    }
}
