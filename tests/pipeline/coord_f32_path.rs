//! The `float32` coordinate path (`interp.coord_arith`, the `llvmpipe` preset) against a
//! reimplementation of llvmpipe's setup, plane evaluation and LOD in the host's `f32`
//! (`mul_add` for the fused multiply-adds): bit for bit on random triangles and pixels.

use crate::rng_common::Rng;
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
