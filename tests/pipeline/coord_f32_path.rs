//! The `float32` coordinate path (`interp.coord_arith`, the `llvmpipe` preset) against a
//! reimplementation of llvmpipe's setup, plane evaluation and LOD in the host's `f32`
//! (`mul_add` for the fused multiply-adds): bit for bit on random triangles and pixels.

use crate::rng_common::Rng;
use texsim::pipeline::clip_f32::{clip_triangle, ShadedVertex};
use texsim::pipeline::coord_f32::{
    coords_at, fast_log2, quad_lod, setup, vertex_transform, Plane, Planes, Vertex,
};

/// Host `f32` twin of `coord_f32::setup` (`lp_state_setup.c`).
fn setup_host(v: [[f32; 5]; 3]) -> [[f32; 3]; 3] {
    let dx01 = v[0][0] - v[1][0];
    let dy01 = v[0][1] - v[1][1];
    let dx20 = v[2][0] - v[0][0];
    let dy20 = v[2][1] - v[0][1];
    let ooa = 1.0 / (dx01 * dy20 - dy01 * dx20);
    let (dx01o, dy01o, dx20o, dy20o) = (dx01 * ooa, dy01 * ooa, dx20 * ooa, dy20 * ooa);
    let (x0c, y0c) = (v[0][0] - 0.5, v[0][1] - 0.5);
    let coef = |a: [f32; 3]| {
        let da01 = a[0] - a[1];
        let da20 = a[2] - a[0];
        let dadx = da01 * dy20o - da20 * dy01o;
        let dady = da20 * dx01o - da01 * dx20o;
        [a[0] - (dadx * x0c + dady * y0c), dadx, dady]
    };
    let w = v.map(|p| p[2]);
    [
        coef(w),
        coef(v.map(|p| p[3] * p[2])),
        coef(v.map(|p| p[4] * p[2])),
    ]
}

fn at_host(p: &[[f32; 3]; 3], x: i64, y: i64) -> [f32; 2] {
    let (xf, yf) = (x as f32, y as f32);
    let ev = |c: [f32; 3]| c[2].mul_add(yf, c[1].mul_add(xf, c[0]));
    let oow = 1.0 / ev(p[0]);
    [ev(p[1]) * oow, ev(p[2]) * oow]
}

fn fast_log2_host(x: f32) -> f32 {
    let b = x.to_bits();
    let e = ((b >> 23) & 0xFF) as i32 - 128;
    e as f32 + f32::from_bits((b & 0x7F_FFFF) | 0x3F80_0000)
}

fn lod_host(p: &[[f32; 3]; 3], qx: i64, qy: i64, w: u32, h: u32, frac: u32) -> i64 {
    let (q0, q1, q2) = (
        at_host(p, qx, qy),
        at_host(p, qx + 1, qy),
        at_host(p, qx, qy + 1),
    );
    let size = [w as f32, h as f32];
    let sq = |d: f32, ax: usize| (d * size[ax]) * (d * size[ax]);
    let rx = sq(q1[0] - q0[0], 0) + sq(q1[1] - q0[1], 1);
    let ry = sq(q2[0] - q0[0], 0) + sq(q2[1] - q0[1], 1);
    let lod = fast_log2_host(rx.max(ry)) * 0.5;
    (lod * (1u32 << frac) as f32).floor() as i64
}

fn bits(p: &Plane) -> [u32; 3] {
    [p.a0, p.dadx, p.dady]
}

#[test]
fn float32_path_matches_host_f32() {
    let mut r = Rng(0xC00F);
    let mut checked = 0u64;
    for _ in 0..20_000 {
        // Window positions across a 1024 viewport, 1/w from near to far, coordinates 0..16.
        let v: [[f32; 5]; 3] = std::array::from_fn(|_| {
            [
                r.range(-64.0, 1088.0) as f32,
                r.range(-64.0, 1088.0) as f32,
                r.range(0.001, 10.0) as f32,
                r.range(-2.0, 18.0) as f32,
                r.range(-2.0, 18.0) as f32,
            ]
        });
        let host = setup_host(v);
        let vb: [Vertex; 3] = v.map(|p| p.map(f32::to_bits));
        let planes: Planes = setup(vb);
        let got = [planes.inv_w, planes.s, planes.t].map(|p| bits(&p));
        let want = host.map(|c| c.map(f32::to_bits));
        if want
            .iter()
            .flatten()
            .any(|&b| !f32::from_bits(b).is_finite())
        {
            continue;
        }
        assert_eq!(got, want, "setup of {v:?}");
        for _ in 0..16 {
            let (x, y) = (r.int_in(0, 1023), r.int_in(0, 1023));
            let h = at_host(&host, x, y);
            if !(h[0].is_finite() && h[1].is_finite()) {
                continue;
            }
            assert_eq!(
                coords_at(&planes, x, y),
                h.map(f32::to_bits),
                "({x}, {y}) of {v:?}"
            );
            let (qx, qy) = (x & !1, y & !1);
            let want = lod_host(&host, qx, qy, 1024, 512, 8);
            if (-(1 << 20)..(1 << 20)).contains(&want) {
                assert_eq!(
                    quad_lod(&planes, qx, qy, 1024, 512, 8),
                    want,
                    "lod at ({x}, {y})"
                );
            }
            checked += 1;
        }
    }
    assert!(checked > 200_000, "{checked}");
}

/// `lp_build_fast_log2` exhaustively over the positive normal encodings' exponents and a
/// 2^16 stride of fractions.
#[test]
fn fast_log2_matches_host() {
    for e in 1u32..255 {
        for f in (0..(1u32 << 23)).step_by(1 << 7) {
            let x = e << 23 | f;
            assert_eq!(
                fast_log2(x),
                fast_log2_host(f32::from_bits(x)).to_bits(),
                "{x:#x}"
            );
        }
    }
}

/// Host `f32` twin of `coord_f32::vertex_transform`: `MVP p` as a product and three
/// product-plus-sum steps, `1/w`, `x (1/w) scale + translate` fused.
fn vertex_host(m: &[[f32; 4]; 4], p: [f32; 3], w: u32, h: u32) -> [f32; 3] {
    let pos = [p[0], p[1], p[2], 1.0];
    let clip: [f32; 4] = std::array::from_fn(|r| {
        let t = pos[0] * m[r][0];
        let t = pos[1] * m[r][1] + t;
        let t = pos[2] * m[r][2] + t;
        pos[3] * m[r][3] + t
    });
    let oow = 1.0 / clip[3];
    let (hw, hh) = ((w / 2) as f32, (h / 2) as f32);
    [
        (clip[0] * oow).mul_add(hw, hw),
        (clip[1] * oow).mul_add(-hh, hh),
        oow,
    ]
}

#[test]
fn vertex_transform_matches_host_f32() {
    let mut r = Rng(0x7E57);
    for _ in 0..200_000 {
        let m: [[f32; 4]; 4] =
            std::array::from_fn(|_| std::array::from_fn(|_| r.range(-3.0, 3.0) as f32));
        let p: [f32; 3] = std::array::from_fn(|_| r.range(-300.0, 300.0) as f32);
        let want = vertex_host(&m, p, 1024, 768);
        if want.iter().any(|x| !x.is_finite()) {
            continue;
        }
        let got = vertex_transform(&m.map(|row| row.map(f32::to_bits)), p, 1024, 768);
        assert_eq!(got, want.map(f32::to_bits), "{m:?} {p:?}");
    }
}

/// Host `f32` twin of `clip_f32::clip_triangle` (`draw_pipe_clip.c`): outcodes, each plane in
/// turn, the symmetric choice of `t`, `out + t (in - out)`, the C viewport transform, the fan.
fn clip_host(v: [ShadedVertex; 3], half: [f32; 2]) -> Vec<[Vertex; 3]> {
    #[derive(Clone, Copy)]
    struct V {
        clip: [f32; 4],
        win: [f32; 3],
        st: [f32; 2],
    }
    let f = |x: u32| f32::from_bits(x);
    let planes: [[f32; 4]; 6] = [
        [-1.0, 0.0, 0.0, 1.0],
        [1.0, 0.0, 0.0, 1.0],
        [0.0, -1.0, 0.0, 1.0],
        [0.0, 1.0, 0.0, 1.0],
        [0.0, 0.0, 1.0, 1.0],
        [0.0, 0.0, -1.0, 1.0],
    ];
    let dot = |a: &[f32; 4], b: &[f32; 4]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
    let interp = |t: f32, out: &V, inn: &V| {
        let clip: [f32; 4] = std::array::from_fn(|i| out.clip[i] + t * (inn.clip[i] - out.clip[i]));
        let oow = 1.0 / clip[3];
        V {
            clip,
            win: [
                clip[0] * oow * half[0] + half[0],
                clip[1] * oow * -half[1] + half[1],
                oow,
            ],
            st: std::array::from_fn(|i| out.st[i] + t * (inn.st[i] - out.st[i])),
        }
    };
    let mut poly: Vec<V> = v
        .iter()
        .map(|s| V {
            clip: s.clip.map(f),
            win: s.window.map(f),
            st: s.st.map(f),
        })
        .collect();
    let mut mask = 0u32;
    for q in &poly {
        for (p, pl) in planes.iter().enumerate() {
            if dot(&q.clip, pl) < 0.0 {
                mask |= 1 << p;
            }
        }
    }
    let sv = |q: &V| [q.win[0], q.win[1], q.win[2], q.st[0], q.st[1]].map(f32::to_bits);
    if mask == 0 {
        // A triangle inside every plane bypasses the clipper.
        return vec![[sv(&poly[0]), sv(&poly[1]), sv(&poly[2])]];
    }
    while mask != 0 && poly.len() >= 3 {
        let p = mask.trailing_zeros() as usize;
        mask &= !(1 << p);
        let n = poly.len();
        let mut out = Vec::new();
        let mut prev = poly[0];
        let mut dp_prev = dot(&prev.clip, &planes[p]);
        for i in 1..=n {
            let vert = poly[i % n];
            let dp = dot(&vert.clip, &planes[p]);
            let different = if dp_prev >= 0.0 {
                out.push(prev);
                dp < 0.0
            } else {
                dp >= 0.0
            };
            if different {
                let denom = dp - dp_prev;
                out.push(if dp < 0.0 {
                    if -dp < dp_prev {
                        interp(dp / denom, &vert, &prev)
                    } else {
                        interp(-dp_prev / denom, &prev, &vert)
                    }
                } else if -dp_prev < dp {
                    interp(-dp_prev / denom, &prev, &vert)
                } else {
                    interp(dp / denom, &vert, &prev)
                });
            }
            prev = vert;
            dp_prev = dp;
        }
        poly = out;
    }
    (2..poly.len())
        .map(|i| [sv(&poly[i - 1]), sv(&poly[i]), sv(&poly[0])])
        .collect()
}

#[test]
fn clipper_matches_host_f32() {
    let mut r = Rng(0xC11F);
    let mut clipped = 0;
    for _ in 0..50_000 {
        let v: [ShadedVertex; 3] = std::array::from_fn(|_| {
            let w = r.range(-2.0, 6.0) as f32;
            let clip = [
                r.range(-8.0, 8.0) as f32,
                r.range(-8.0, 8.0) as f32,
                r.range(-8.0, 8.0) as f32,
                w,
            ];
            ShadedVertex {
                clip: clip.map(f32::to_bits),
                window: [
                    r.range(0.0, 1024.0) as f32,
                    r.range(0.0, 1024.0) as f32,
                    1.0 / w,
                ]
                .map(f32::to_bits),
                st: [r.range(0.0, 16.0) as f32, r.range(0.0, 16.0) as f32].map(f32::to_bits),
            }
        });
        let want = clip_host(v, [512.0, 384.0]);
        let got = clip_triangle(v, [512.0f32.to_bits(), 384.0f32.to_bits()]);
        if want.len() != 1 || got.len() != 1 {
            clipped += 1;
        }
        assert_eq!(got, want, "{v:?}");
    }
    assert!(clipped > 10_000, "{clipped}");
}
