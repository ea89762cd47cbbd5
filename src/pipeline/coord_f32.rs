//! The float32 texture-coordinate path of Mesa 22.3 llvmpipe (`interp.coord_arith =
//! "float32"`), bit for bit on the `hw_model::f32_*` units:
//!
//! - triangle setup (`lp_state_setup.c`, `init_args` and `calc_coef4`): the vertices in
//!   llvmpipe's order (the draw order, the first two swapped when its signed area is not
//!   positive, `lp_setup_tri.c` `triangle_both`), `ooa = 1 / (dx01 dy20 - dy01 dx20)`, the
//!   attributes premultiplied by each vertex's `1/w`, `dadx = da01 dy20 ooa - da20 dy01 ooa`,
//!   `dady = da20 dx01 ooa - da01 dx20 ooa`, `a0 = a_0 - (dadx (x_0 - 1/2) + dady (y_0 - 1/2))`,
//!   each product and difference rounded on its own (LLVM does not contract them);
//! - the fragment shader (`lp_bld_interp.c`, `attribs_update_simple`): at the integer pixel
//!   `(X, Y)`, `a = fma(dady, Y, fma(dadx, X, a0))` (`lp_build_fmuladd`, fused on a CPU with
//!   FMA), the same for the interpolated `1/w`, then `a (1 / w)` with a true division
//!   (`lp_build_rcp`);
//! - the LOD (`lp_bld_sample.c`, `lp_build_rho` and `lp_build_lod_selector`): per 2x2 quad, the
//!   differences of the quad's first pixel to its right and lower neighbours, times the
//!   level-0 size, squared and summed per direction, the larger, `lp_build_fast_log2` (the
//!   exponent minus one plus the mantissa in [1, 2)) times 1/2, floored to `lod_frac_bits`.
//!
//! The vertices come from [`vertex_transform`] (the vertex program and viewport transform in
//! binary32) through the draw module's float32 clipper (`super::clip_f32`). The sampler takes
//! the coordinates as fixed point on `texcoord_frac_bits` (28 in the `llvmpipe` preset, exact
//! for every binary32 coordinate of magnitude 1/32 or more).

use super::clip_f32::{clip_outside, clip_triangle, setup_vertex, ShadedVertex};
use super::stages::{texcoord_offset, Counters, Machine};
use super::{Frag, Px, StageKind};
use crate::fixedpoint::{from_raw, to_raw};
use hw_model::f32_add::{add, sub};
use hw_model::f32_convert::{from_i32, to_i32_trunc};
use hw_model::f32_div::div;
use hw_model::f32_fma::fma;
use hw_model::f32_mul::mul;
use hw_model::fixed::SatCounter;

const ONE: u32 = 0x3F80_0000;
const HALF: u32 = 0x3F00_0000;

/// One attribute's plane: the value at pixel (0, 0)'s centre and its steps, binary32.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Plane {
    pub a0: u32,
    pub dadx: u32,
    pub dady: u32,
}

/// A triangle's planes of `1/w`, `s/w` and `t/w`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Planes {
    pub inv_w: Plane,
    pub s: Plane,
    pub t: Plane,
}

/// One vertex as llvmpipe's setup reads it: window x, y, `1/w`, s, t (binary32).
pub type Vertex = [u32; 5];

/// The order in which llvmpipe's setup sees triangle `v` (as the draw module emits it):
/// `triangle_both` swaps the first two vertices when the signed area is not positive.
#[must_use]
pub fn llvmpipe_order(v: [Vertex; 3]) -> [Vertex; 3] {
    let p = v.map(|q| [0, 1].map(|i| f64::from(f32::from_bits(q[i]))));
    let area =
        (p[0][0] - p[1][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[0][1] - p[1][1]);
    if area > 0.0 {
        v
    } else {
        [v[1], v[0], v[2]]
    }
}

/// `calc_coef4` of one attribute (`a` the three vertex values) with the setup's shared terms.
fn coef(a: [u32; 3], s: &SetupTerms) -> Plane {
    let da01 = sub(a[0], a[1]);
    let da20 = sub(a[2], a[0]);
    let dadx = sub(mul(da01, s.dy20_ooa), mul(da20, s.dy01_ooa));
    let dady = sub(mul(da20, s.dx01_ooa), mul(da01, s.dx20_ooa));
    let at_v0 = add(mul(dadx, s.x0_center), mul(dady, s.y0_center));
    Plane {
        a0: sub(a[0], at_v0),
        dadx,
        dady,
    }
}

/// `init_args`' terms shared by every attribute.
struct SetupTerms {
    x0_center: u32,
    y0_center: u32,
    dx01_ooa: u32,
    dy01_ooa: u32,
    dx20_ooa: u32,
    dy20_ooa: u32,
}

/// llvmpipe's setup of the planes from its three vertices in its order.
#[must_use]
pub fn setup(v: [Vertex; 3]) -> Planes {
    let dx01 = sub(v[0][0], v[1][0]);
    let dy01 = sub(v[0][1], v[1][1]);
    let dx20 = sub(v[2][0], v[0][0]);
    let dy20 = sub(v[2][1], v[0][1]);
    let e = mul(dx01, dy20);
    let f = mul(dy01, dx20);
    let ooa = div(ONE, sub(e, f));
    let terms = SetupTerms {
        x0_center: sub(v[0][0], HALF),
        y0_center: sub(v[0][1], HALF),
        dx01_ooa: mul(dx01, ooa),
        dy01_ooa: mul(dy01, ooa),
        dx20_ooa: mul(dx20, ooa),
        dy20_ooa: mul(dy20, ooa),
    };
    let w = v.map(|p| p[2]);
    let persp = |i: usize| v.map(|p| mul(p[i], p[2]));
    Planes {
        inv_w: coef(w, &terms),
        s: coef(persp(3), &terms),
        t: coef(persp(4), &terms),
    }
}

/// `a0 + dadx X + dady Y` as two fused multiply-adds.
fn eval(p: &Plane, x: u32, y: u32) -> u32 {
    fma(p.dady, y, fma(p.dadx, x, p.a0))
}

/// The texture coordinates (s, t) at integer pixel (`x`, `y`), binary32.
#[must_use]
pub fn coords_at(p: &Planes, x: i64, y: i64) -> [u32; 2] {
    let (xf, yf) = (from_i32(x as i32), from_i32(y as i32));
    let oow = div(ONE, eval(&p.inv_w, xf, yf));
    [mul(eval(&p.s, xf, yf), oow), mul(eval(&p.t, xf, yf), oow)]
}

/// `lp_build_fast_log2`: the exponent minus one plus the mantissa in [1, 2), one addition.
#[must_use]
pub fn fast_log2(x: u32) -> u32 {
    let e = ((x >> 23) & 0xFF) as i32 - 128;
    add(from_i32(e), (x & 0x007F_FFFF) | ONE)
}

/// The larger of two non-negative binary32 values (their encodings order as integers).
fn max_nonneg(a: u32, b: u32) -> u32 {
    a.max(b)
}

/// `floor(x)` of a binary32 value as an integer (`i32::MIN` out of range).
fn floor_i32(x: u32) -> i32 {
    let t = to_i32_trunc(x);
    if t != i32::MIN && x >> 31 != 0 && from_i32(t) != x {
        t - 1
    } else {
        t
    }
}

/// The LOD of the 2x2 quad with first pixel (`qx`, `qy`) on a `width` x `height` level 0,
/// scaled by 2^`frac_bits` and floored (`lp_build_rho` + `lp_build_lod_selector`).
#[must_use]
pub fn quad_lod(p: &Planes, qx: i64, qy: i64, width: u32, height: u32, frac_bits: u32) -> i64 {
    let q0 = coords_at(p, qx, qy);
    let q1 = coords_at(p, qx + 1, qy);
    let q2 = coords_at(p, qx, qy + 1);
    let size = [width, height].map(|n| from_i32(n as i32));
    let sq = |d: u32, ax: usize| {
        let v = mul(d, size[ax]);
        mul(v, v)
    };
    let rho_x = add(sq(sub(q1[0], q0[0]), 0), sq(sub(q1[1], q0[1]), 1));
    let rho_y = add(sq(sub(q2[0], q0[0]), 0), sq(sub(q2[1], q0[1]), 1));
    let lod = mul(fast_log2(max_nonneg(rho_x, rho_y)), HALF);
    let scale = from_i32(1 << frac_bits.min(16));
    i64::from(floor_i32(mul(lod, scale)))
}

/// One screen triangle as llvmpipe sets it up, built once per triangle: the source triangle
/// through the draw module's clipper, each emitted triangle (window-space vertices) with its
/// planes (`setup` of the vertices in llvmpipe's order).
#[derive(Clone, Debug, Default)]
pub struct F32Tri {
    pub fan: Vec<([Vertex; 3], Planes)>,
}

impl F32Tri {
    /// Clips `src` (the vertex shader's output, [`shade_vertex`]) with the viewport's half
    /// sizes `half` and sets up every emitted triangle.
    #[must_use]
    pub fn new(src: [ShadedVertex; 3], half: [u32; 2]) -> Self {
        let fan = clip_triangle(src, half)
            .into_iter()
            .map(|t| (t, setup(llvmpipe_order(t))))
            .collect();
        Self { fan }
    }

    /// [`Self::new`] of vertices whose [`outcode`](super::clip_f32::outcode)s OR to `mask`
    /// (computed once per shared vertex by the caller); one allocation when nothing is
    /// clipped.
    #[must_use]
    pub fn with_mask(src: [ShadedVertex; 3], mask: u32, half: [u32; 2]) -> Self {
        if mask == 0 {
            let t = src.map(|s| setup_vertex(&s));
            return Self {
                fan: vec![(t, setup(llvmpipe_order(t)))],
            };
        }
        let fan = clip_outside(src, mask, half)
            .into_iter()
            .map(|t| (t, setup(llvmpipe_order(t))))
            .collect();
        Self { fan }
    }
}

/// The planes llvmpipe shades pixel `px` with: those of the emitted triangle whose
/// window-space interior holds the pixel centre (the first one if none does, on an edge).
fn planes(px: &Px) -> Planes {
    let Some(tri) = px.m.f32_tris.get(px.a.f32_tri as usize) else {
        return setup(llvmpipe_order(Default::default()));
    };
    let (cx, cy) = (px.x as f64 + 0.5, px.y as f64 + 0.5);
    let inside = |t: &[Vertex; 3]| {
        let p = t.map(|q| [0, 1].map(|i| f64::from(f32::from_bits(q[i]))));
        let e =
            |a: [f64; 2], b: [f64; 2]| (b[0] - a[0]) * (cy - a[1]) - (b[1] - a[1]) * (cx - a[0]);
        let (e0, e1, e2) = (e(p[0], p[1]), e(p[1], p[2]), e(p[2], p[0]));
        (e0 >= 0.0 && e1 >= 0.0 && e2 >= 0.0) || (e0 <= 0.0 && e1 <= 0.0 && e2 <= 0.0)
    };
    let hit = tri.fan.iter().find(|(t, _)| inside(t)).or(tri.fan.first());
    hit.map_or_else(|| setup(llvmpipe_order(Default::default())), |(_, p)| *p)
}

/// llvmpipe's vertex transform of object position `p`: the clip position `MVP p` in
/// binary32 (the fixed-function vertex program's `MUL` then three `MAD`s, each a product
/// and a sum rounded on their own: fusing them measured worse), then the draw module's
/// viewport transform: `1/w` by a division, `x (1/w) scale + translate` with a fused
/// multiply-add (for a power-of-two half size the product is exact and fusing changes
/// nothing). `mvp` is texsim's view-projection rounded to binary32, not Mesa's own float32
/// product of the `glFrustum`/`glRotated`/`glTranslated` matrices. Returns window x, y (y
/// down) and `1/w`.
#[must_use]
pub fn vertex_transform(mvp: &[[u32; 4]; 4], p: [f32; 3], width: u32, height: u32) -> [u32; 3] {
    shade_vertex(mvp, p, [0; 2], width, height).window
}

/// [`vertex_transform`] keeping the clip position, with texture coordinates `st`.
#[must_use]
pub fn shade_vertex(
    mvp: &[[u32; 4]; 4],
    p: [f32; 3],
    st: [u32; 2],
    width: u32,
    height: u32,
) -> ShadedVertex {
    let pos = [p[0].to_bits(), p[1].to_bits(), p[2].to_bits(), ONE];
    let clip: [u32; 4] = std::array::from_fn(|r| {
        let m = &mvp[r];
        let t = mul(pos[0], m[0]);
        let t = add(mul(pos[1], m[1]), t);
        let t = add(mul(pos[2], m[2]), t);
        add(mul(pos[3], m[3]), t)
    });
    let oow = div(ONE, clip[3]);
    let half_w = from_i32(width as i32 / 2);
    let half_h = from_i32(height as i32 / 2);
    let vp = |v: u32, scale: u32, trans: u32| fma(mul(v, oow), scale, trans);
    ShadedVertex {
        clip,
        window: [
            vp(clip[0], half_w, half_w),
            vp(clip[1], half_h ^ 0x8000_0000, half_h),
            oow,
        ],
        st,
    }
}

/// The `texcoord` stage on the float32 path: the pixel's coordinates, and for the quad's
/// helpers the pixel plus the quad's differences (as the fixed path's per-quad samples).
pub fn texcoord(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let m = px.m;
    let sat = &mut c.sat[StageKind::Texcoord.index()];
    let planes = planes(px);
    let off = reduction(px, m);
    let fixed = |st: [u32; 2], sat: &mut SatCounter| {
        [0, 1].map(|ax| to_raw(f64::from(f32::from_bits(st[ax])) - off[ax], &m.uv_fmt, sat))
    };
    let p = fixed(coords_at(&planes, px.x, px.y), sat);
    frag.uv_x[0] = p;
    if px.samples() > 1 {
        let (qx, qy) = (px.x & !1, px.y & !1);
        let q0 = fixed(coords_at(&planes, qx, qy), sat);
        let q1 = fixed(coords_at(&planes, qx + 1, qy), sat);
        let q2 = fixed(coords_at(&planes, qx, qy + 1), sat);
        frag.uv_x[1] = [0, 1].map(|ax| p[ax] + q1[ax] - q0[ax]);
        frag.uv_x[2] = [0, 1].map(|ax| p[ax] + q2[ax] - q0[ax]);
    }
    if px.carriers {
        let fb = m.uv_fmt.frac_bits;
        for s in 0..px.samples() {
            frag.uv[s] = frag.uv_x[s].map(|r| from_raw(r, fb));
        }
    }
}

/// The per-triangle integer the fixed coordinates are reduced by (`interp.texcoord_reduce`),
/// as `TriAttrs::new` takes it.
fn reduction(px: &Px, m: &Machine) -> [f64; 2] {
    if !m.hw.interp.texcoord_reduce {
        return [0.0; 2];
    }
    let uv = px.af.uv;
    [0, 1].map(|ax| texcoord_offset([uv[0][ax], uv[1][ax], uv[2][ax]], px.plan.wrap[ax]))
}

/// The `lod` stage on the float32 path.
pub fn lod(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let m = px.m;
    let Some(l0) = px.plan.texture.and_then(|t| m.tex_float[t].first()) else {
        return;
    };
    let sat = &mut c.sat[StageKind::Lod.index()];
    let planes = planes(px);
    let fb = m.hw.lod.lod_frac_bits;
    let raw = quad_lod(&planes, px.x & !1, px.y & !1, l0.width, l0.height, fb);
    frag.lod_x = m.lod_fmt.fit(raw, sat);
    if px.carriers {
        frag.lod = from_raw(frag.lod_x, fb);
    }
}
