//! Mesa's draw-module clipper (`draw_pipe_clip.c`, `do_clip_tri`) in binary32 on the
//! `hw_model::f32_*` units, for the float32 coordinate path: the planes a vertex is outside
//! of, each clipped in turn (Sutherland-Hodgman, the plane distance `dot4(clip, plane)`
//! evaluated left to right, `t` from the vertex inside, `out + t (in - out)` for the clip
//! position and the texture coordinates), the new vertices' `1/w` and window position
//! (`x (1/w) scale + translate`, unfused C), and the polygon emitted as the fan
//! `(v[i-1], v[i], v[0])` of the last-vertex provoking convention.

use super::coord_f32::Vertex;
use hw_model::f32_add::{add, sub};
use hw_model::f32_div::div;
use hw_model::f32_mul::mul;

const ONE: u32 = 0x3F80_0000;
const NEG_ONE: u32 = 0xBF80_0000;
const SIGN: u32 = 0x8000_0000;

/// A vertex leaving the vertex shader: clip position, window x, y and `1/w`, s, t.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ShadedVertex {
    pub clip: [u32; 4],
    pub window: [u32; 3],
    pub st: [u32; 2],
}

/// The six view-volume planes in the draw module's order (`draw_context.c`): right, left,
/// top, bottom, near (`z + w`, OpenGL depth), far.
const PLANES: [[u32; 4]; 6] = [
    [NEG_ONE, 0, 0, ONE],
    [ONE, 0, 0, ONE],
    [0, NEG_ONE, 0, ONE],
    [0, ONE, 0, ONE],
    [0, 0, ONE, ONE],
    [0, 0, NEG_ONE, ONE],
];

fn dot4(a: &[u32; 4], b: &[u32; 4]) -> u32 {
    let s = add(mul(a[0], b[0]), mul(a[1], b[1]));
    let s = add(s, mul(a[2], b[2]));
    add(s, mul(a[3], b[3]))
}

fn negative(x: u32) -> bool {
    x & SIGN != 0 && x & !SIGN != 0
}

/// `LINTERP(t, out, in)`.
fn lerp(t: u32, out: u32, inn: u32) -> u32 {
    add(out, mul(t, sub(inn, out)))
}

/// `interp()`: the vertex at `t` from `out` towards `inn`, its window position by the C
/// viewport transform (`half` the viewport's half width and height, y down).
fn interp(t: u32, out: &ShadedVertex, inn: &ShadedVertex, half: [u32; 2]) -> ShadedVertex {
    let clip: [u32; 4] = std::array::from_fn(|i| lerp(t, out.clip[i], inn.clip[i]));
    let oow = div(ONE, clip[3]);
    let win = |v: u32, scale: u32, trans: u32| add(mul(mul(v, oow), scale), trans);
    ShadedVertex {
        clip,
        window: [
            win(clip[0], half[0], half[0]),
            win(clip[1], half[1] ^ SIGN, half[1]),
            oow,
        ],
        st: std::array::from_fn(|i| lerp(t, out.st[i], inn.st[i])),
    }
}

/// The planes vertex `v` is outside of (bit i for plane i).
#[must_use]
pub fn outcode(v: &ShadedVertex) -> u32 {
    (0..6).fold(0, |m, p| {
        if negative(dot4(&v.clip, &PLANES[p])) {
            m | 1 << p
        } else {
            m
        }
    })
}

/// Clips triangle `v` (the draw order) for a viewport of `half` half-sizes (binary32) and
/// returns the triangles the setup receives, each as its vertices (window x, y, `1/w`, s, t);
/// the triangle itself when no vertex is outside.
#[must_use]
pub fn clip_triangle(v: [ShadedVertex; 3], half: [u32; 2]) -> Vec<[Vertex; 3]> {
    let mask = v.iter().fold(0, |m, x| m | outcode(x));
    if mask == 0 {
        return vec![v.map(|s| setup_vertex(&s))];
    }
    clip_outside(v, mask, half)
}

/// A vertex as the setup reads it: window x, y, `1/w`, s, t.
#[must_use]
pub fn setup_vertex(s: &ShadedVertex) -> Vertex {
    [s.window[0], s.window[1], s.window[2], s.st[0], s.st[1]]
}

/// [`clip_triangle`] of a triangle whose vertices' outcodes OR to `mask` (not 0).
#[must_use]
pub fn clip_outside(v: [ShadedVertex; 3], mut mask: u32, half: [u32; 2]) -> Vec<[Vertex; 3]> {
    let mut poly: Vec<ShadedVertex> = v.to_vec();
    while mask != 0 && poly.len() >= 3 {
        let p = mask.trailing_zeros() as usize;
        mask &= !(1 << p);
        let plane = &PLANES[p];
        let n = poly.len();
        let mut out = Vec::with_capacity(n + 1);
        let mut prev = poly[0];
        let mut dp_prev = dot4(&prev.clip, plane);
        for i in 1..=n {
            let vert = poly[i % n];
            let dp = dot4(&vert.clip, plane);
            let different_sign = if !negative(dp_prev) {
                out.push(prev);
                negative(dp)
            } else {
                !negative(dp)
            };
            if different_sign {
                let denom = sub(dp, dp_prev);
                let neg = |x: u32| x ^ SIGN;
                let lt = |a: u32, b: u32| negative(sub(a, b));
                let new = if negative(dp) {
                    if lt(neg(dp), dp_prev) {
                        interp(div(dp, denom), &vert, &prev, half)
                    } else {
                        interp(div(neg(dp_prev), denom), &prev, &vert, half)
                    }
                } else if lt(neg(dp_prev), dp) {
                    interp(div(neg(dp_prev), denom), &prev, &vert, half)
                } else {
                    interp(div(dp, denom), &vert, &prev, half)
                };
                out.push(new);
            }
            prev = vert;
            dp_prev = dp;
        }
        poly = out;
    }
    (2..poly.len())
        .map(|i| [poly[i - 1], poly[i], poly[0]].map(|s| setup_vertex(&s)))
        .collect()
}
