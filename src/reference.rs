//! Float twins of the `hw_model` units: the same algorithm structure in exact-as-possible f64
//! arithmetic (no quantization), used as the reference stages of the pipeline and by the unit
//! tests. Conventions (texel centres, weight of the second operand, LOD clamp) are those of
//! `hw_model::trilinear`; texel values are unorm floats in [0, 1].

use hw_model::wrap::WrapMode;

/// Perspective-correct barycentrics `q_i / sum q`, `q_i = E_i invw_i`, with
/// `p_0 = 1 - p_1 - p_2`; a non-positive denominator gives `[1, 0, 0]` as the fixed unit.
#[inline]
#[must_use]
pub fn perspective_bary_f64(edge: [f64; 3], inv_w: [f64; 3]) -> [f64; 3] {
    let q = [edge[0] * inv_w[0], edge[1] * inv_w[1], edge[2] * inv_w[2]];
    let d = q[0] + q[1] + q[2];
    if d.is_nan() || d <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let r = 1.0 / d;
    let p1 = q[1] * r;
    let p2 = q[2] * r;
    [1.0 - p1 - p2, p1, p2]
}

/// Twin of `hw_model::interpolator::perspective_bary_derivs`: `[p, p + dp/dx, p + dp/dy]`
/// with the analytic derivatives `dp_i/dx = (a_i D - q_i S) / D^2`.
#[inline]
#[must_use]
pub fn perspective_bary_derivs_f64(
    edge: [f64; 3],
    edge_dx: [f64; 3],
    edge_dy: [f64; 3],
    inv_w: [f64; 3],
) -> [[f64; 3]; 3] {
    let p = perspective_bary_f64(edge, inv_w);
    let q = [edge[0] * inv_w[0], edge[1] * inv_w[1], edge[2] * inv_w[2]];
    let d = q[0] + q[1] + q[2];
    if d.is_nan() || d <= 0.0 {
        return [p, p, p];
    }
    let mut out = [p, p, p];
    for (k, de) in [(1usize, edge_dx), (2, edge_dy)] {
        let a = [de[0] * inv_w[0], de[1] * inv_w[1], de[2] * inv_w[2]];
        let sum = a[0] + a[1] + a[2];
        let dp1 = (a[1] * d - q[1] * sum) / (d * d);
        let dp2 = (a[2] * d - q[2] * sum) / (d * d);
        out[k] = [1.0 - (p[1] + dp1) - (p[2] + dp2), p[1] + dp1, p[2] + dp2];
    }
    out
}

/// `a0 + p1 (a1 - a0) + p2 (a2 - a0)`.
#[inline]
#[must_use]
pub fn interpolate_f64(bary: [f64; 3], attr: [f64; 3]) -> f64 {
    attr[0] + bary[1] * (attr[1] - attr[0]) + bary[2] * (attr[2] - attr[0])
}

/// `log2(rho)` of the OpenGL isotropic rule from `(du/dx, dv/dx, du/dy, dv/dy)` in texels;
/// -32 for `rho == 0`, and clamped below at -32 as the fixed unit.
#[inline]
#[must_use]
pub fn lod_f64(d: [f64; 4]) -> f64 {
    let lx = d[0] * d[0] + d[1] * d[1];
    let ly = d[2] * d[2] + d[3] * d[3];
    let l = lx.max(ly);
    if l.is_nan() || l <= 0.0 {
        return -32.0;
    }
    (0.5 * l.log2()).max(-32.0)
}

/// The float twin of the LOD unit with its `lod_log2` mode: [`lod_f64`] for `exact`; for
/// `piecewise-linear` `0.5 (e + L / 2^e - 1)` with `e = floor(log2 L)` (llvmpipe's
/// `lp_build_fast_log2` of the squared length).
#[must_use]
pub fn lod_mode_f64(d: [f64; 4], mode: hw_model::config::LodLog2) -> f64 {
    if mode == hw_model::config::LodLog2::Exact {
        return lod_f64(d);
    }
    let l = (d[0] * d[0] + d[1] * d[1]).max(d[2] * d[2] + d[3] * d[3]);
    if l.is_nan() || l <= 0.0 || !l.is_finite() {
        return -32.0;
    }
    let mut e = crate::fixedpoint::floor_exact(l.log2());
    // log2 may round across a power of two: fix e so that 2^e <= l < 2^(e+1).
    if e.exp2() > l {
        e -= 1.0;
    } else if (e + 1.0).exp2() <= l {
        e += 1.0;
    }
    (0.5 * (e + l / e.exp2() - 1.0)).max(-32.0)
}

/// Wraps a texel index by `mode` into `[0, size-1]`.
///
/// An integral `i` below 2^53 in magnitude (every index [`wrap_f64`] makes for a texture
/// coordinate of that range) wraps in `i64`: the f64 remainder of two integers is exact, so
/// the result is the same, without the software `fmod` that `rem_euclid` calls. Any other
/// `i` (fractions, NaN, infinities, huge values) takes the f64 formula.
#[inline]
#[must_use]
pub fn wrap_index_f64(i: f64, size: u32, mode: WrapMode) -> u32 {
    const TWO_53: f64 = 9_007_199_254_740_992.0;
    if i.abs() < TWO_53 && i as i64 as f64 == i {
        let (k, n) = (i as i64, i64::from(size.max(1)));
        let r = match mode {
            WrapMode::Repeat => k.rem_euclid(n),
            WrapMode::ClampToEdge => k.clamp(0, n - 1),
            WrapMode::Mirror => {
                let m = k.rem_euclid(2 * n);
                if m >= n {
                    2 * n - 1 - m
                } else {
                    m
                }
            }
        };
        return r as u32;
    }
    wrap_index_f64_any(i, size, mode)
}

/// [`wrap_index_f64`] in f64 arithmetic, for any `i`.
#[inline(never)]
fn wrap_index_f64_any(i: f64, size: u32, mode: WrapMode) -> u32 {
    let n = f64::from(size.max(1));
    let r = match mode {
        WrapMode::Repeat => i.rem_euclid(n),
        WrapMode::ClampToEdge => i.clamp(0.0, n - 1.0),
        WrapMode::Mirror => {
            let m = i.rem_euclid(2.0 * n);
            if m >= n {
                2.0 * n - 1.0 - m
            } else {
                m
            }
        }
    };
    if r.is_nan() {
        0
    } else {
        r as u32
    }
}

/// Texel address of one axis: `s = coord * size - 1/2`, `(wrap(floor s), wrap(floor s + 1),
/// s - floor s)` with the continuous weight of the second texel.
#[inline]
#[must_use]
pub fn wrap_f64(coord: f64, size: u32, mode: WrapMode) -> (u32, u32, f64) {
    let s = coord * f64::from(size.max(1)) - 0.5;
    let i0 = crate::fixedpoint::floor_exact(s);
    (
        wrap_index_f64(i0, size, mode),
        wrap_index_f64(i0 + 1.0, size, mode),
        s - i0,
    )
}

/// One MIP level of float texels (row-major, top row first).
#[derive(Clone, Copy, Debug)]
pub struct LevelF<'a> {
    pub width: u32,
    pub height: u32,
    pub texels: &'a [[f32; 4]],
}

#[inline]
fn fetch(level: &LevelF, x: u32, y: u32) -> [f32; 4] {
    let idx = y as usize * level.width as usize + x as usize;
    level.texels.get(idx).copied().unwrap_or([0.0; 4])
}

#[inline]
fn lerp(a: f64, b: f64, w: f64) -> f64 {
    a + (b - a) * w
}

/// Bilinear filter at normalized (u, v): lerp along x on both rows, then along y.
#[inline]
#[must_use]
pub fn bilinear_f64(level: &LevelF, u: f64, v: f64, wrap: [WrapMode; 2]) -> [f64; 4] {
    let (x0, x1, wx) = wrap_f64(u, level.width, wrap[0]);
    let (y0, y1, wy) = wrap_f64(v, level.height, wrap[1]);
    let t00 = fetch(level, x0, y0);
    let t10 = fetch(level, x1, y0);
    let t01 = fetch(level, x0, y1);
    let t11 = fetch(level, x1, y1);
    let mut out = [0.0; 4];
    for c in 0..4 {
        let top = lerp(f64::from(t00[c]), f64::from(t10[c]), wx);
        let bot = lerp(f64::from(t01[c]), f64::from(t11[c]), wx);
        out[c] = lerp(top, bot, wy);
    }
    out
}

/// Trilinear filter with the fixed unit's LOD rule (`lod <= 0`: level 0; `lod >= last`: last
/// level; else levels `floor(lod)` and `floor(lod) + 1` blended by the continuous fraction).
#[inline]
#[must_use]
pub fn trilinear_f64(levels: &[LevelF], u: f64, v: f64, lod: f64, wrap: [WrapMode; 2]) -> [f64; 4] {
    let n = levels.len();
    if n == 0 {
        return [0.0; 4];
    }
    let last = (n - 1) as f64;
    let lod = if lod.is_nan() { 0.0 } else { lod };
    if lod <= 0.0 {
        return bilinear_f64(&levels[0], u, v, wrap);
    }
    if lod >= last {
        return bilinear_f64(&levels[n - 1], u, v, wrap);
    }
    let l0 = crate::fixedpoint::floor_exact(lod);
    let f = lod - l0;
    let l0 = l0 as usize;
    let c0 = bilinear_f64(&levels[l0], u, v, wrap);
    if f == 0.0 {
        return c0;
    }
    let c1 = bilinear_f64(&levels[l0 + 1], u, v, wrap);
    let mut out = [0.0; 4];
    for c in 0..4 {
        out[c] = lerp(c0[c], c1[c], f);
    }
    out
}

/// Unorm modulate: the product of two values in [0, 1].
#[inline]
#[must_use]
pub fn modulate_f64(a: f64, b: f64) -> f64 {
    a * b
}
