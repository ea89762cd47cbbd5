//! `bary`: perspective-correct barycentrics at the pixel and, when the plan needs derivatives,
//! at its two first-order neighbours (Heckbert & Moreton 1991; `hw_model::interpolator`);
//! with `lod_per_quad` the neighbours carry the finite differences of the pixel's 2x2 quad;
//! with `attr_subpixel_bits` the edges come from the float positions on that finer grid.

use super::stages::{Counters, Machine};
use super::{Frag, Plan, Px, StageKind};
use crate::fixedpoint::from_raw;
use crate::raster::ScreenTri;
use crate::reference::{perspective_bary_derivs_f64, perspective_bary_f64};
use hw_model::interpolator::{
    perspective_bary, perspective_bary_cost, perspective_bary_derivs, perspective_bary_derivs_cost,
};
use hw_model::UnitCost;

/// Fixed twin: exact integer edge functions, one reciprocal, analytic derivatives.
pub fn fixed(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let hw = px.m.hw;
    let sat = &mut c.sat[StageKind::Bary.index()];
    let sub = hw.raster.subpixel_bits;
    let bb = hw.interp.bary_bits;
    let (tri, a, m) = (px.tri, px.a, px.m);
    let grid = hw.interp.attr_subpixel_bits;
    let regrid = grid != 0 && grid != sub;
    if px.plan.derivatives && !hw.lod.lod_per_quad && !regrid {
        let (e, dx, dy) = edges_with_steps(tri, px.x, px.y, sub);
        frag.bary_x = perspective_bary_derivs(e, dx, dy, a.inv_w_x, &hw.interp, &m.recip, sat);
        return carriers(px, frag, bb);
    }
    let plane = EdgePlane::new(tri, sub, regrid.then_some(grid));
    if px.plan.derivatives && hw.lod.lod_per_quad {
        // The pixel, then its helpers carry the quad's finite differences.
        let mut b =
            |x: i64, y: i64| perspective_bary(plane.at(x, y), a.inv_w_x, &hw.interp, &m.recip, sat);
        let p = b(px.x, px.y);
        let (qx, qy) = (px.x & !1, px.y & !1);
        let q0 = b(qx, qy);
        let q1 = b(qx + 1, qy);
        let q2 = b(qx, qy + 1);
        frag.bary_x = [
            p,
            [0, 1, 2].map(|i| p[i] + q1[i] - q0[i]),
            [0, 1, 2].map(|i| p[i] + q2[i] - q0[i]),
        ];
    } else if px.plan.derivatives {
        // The attribute grid (`regrid`): the steps are differences of edge values.
        let e = plane.at(px.x, px.y);
        let (ex, ey) = (plane.at(px.x + 1, px.y), plane.at(px.x, px.y + 1));
        let dx = [0, 1, 2].map(|i| ex[i].wrapping_sub(e[i]));
        let dy = [0, 1, 2].map(|i| ey[i].wrapping_sub(e[i]));
        frag.bary_x = perspective_bary_derivs(e, dx, dy, a.inv_w_x, &hw.interp, &m.recip, sat);
    } else {
        frag.bary_x[0] =
            perspective_bary(plane.at(px.x, px.y), a.inv_w_x, &hw.interp, &m.recip, sat);
    }
    carriers(px, frag, bb);
}

/// The float carriers of the raw barycentrics, when a stage of the run reads them.
#[inline(always)]
fn carriers(px: &Px, frag: &mut Frag, bary_bits: u32) {
    if px.carriers {
        for s in 0..px.samples() {
            frag.bary[s] = frag.bary_x[s].map(|r| from_raw(r, bary_bits));
        }
    }
}

/// The exact edge functions of one triangle on the grid the attributes use:
/// [`ScreenTri::edges_fixed`] (the raster grid) or [`ScreenTri::edges_fixed_on_grid`] (`grid`
/// sub-pixel bits), with the same values. When every vertex coordinate on that grid is below
/// 2^29 in magnitude and the sample below 2^(28 - s) pixels (s sub-pixel bits), every
/// intermediate is below 2^62 and the edges are computed in `i64` from positions snapped once
/// per fragment; otherwise the exact (`i128`, saturating) routines of `ScreenTri` run.
struct EdgePlane<'t> {
    tri: &'t ScreenTri,
    /// The vertex positions on the grid, when they are small.
    small: Option<[[i64; 2]; 3]>,
    /// Sub-pixel bits of the grid (clamped as `ScreenTri` clamps them).
    s: u32,
    /// The attribute grid's bits (`None`: the raster grid).
    grid: Option<u32>,
    sub: u32,
}

/// The edge values at the centre of pixel (`px`, `py`) on the attribute grid (`grid`
/// sub-pixel bits, `None` for the raster grid of `sub` bits), as the stage evaluates them:
/// [`ScreenTri::edges_fixed`] / [`ScreenTri::edges_fixed_on_grid`], the same values.
#[must_use]
pub fn edges_at(tri: &ScreenTri, px: i64, py: i64, sub: u32, grid: Option<u32>) -> [i64; 3] {
    EdgePlane::new(tri, sub, grid).at(px, py)
}

/// Bound on the magnitude of a vertex coordinate and of a sample position (both in units of
/// the grid) for the `i64` edge evaluation of [`EdgePlane`].
const SMALL: u64 = 1 << 29;

impl<'t> EdgePlane<'t> {
    #[inline(always)]
    fn new(tri: &'t ScreenTri, sub: u32, grid: Option<u32>) -> Self {
        let (s, v) = match grid {
            None => (sub.clamp(1, 12), tri.xy.map(|p| p.map(i128::from))),
            Some(bits) => {
                let s = bits.clamp(1, 16);
                let g = f64::from(1u32 << s);
                (
                    s,
                    tri.xy_f
                        .map(|p| p.map(|c| (c * g).round_ties_even() as i128)),
                )
            }
        };
        let fits = v
            .iter()
            .flatten()
            .all(|c| c.unsigned_abs() < u128::from(SMALL));
        Self {
            tri,
            small: fits.then(|| v.map(|p| p.map(|c| c as i64))),
            s,
            grid,
            sub,
        }
    }

    /// The sample position (centre of pixel `p`) on the grid, when it is small.
    #[inline(always)]
    fn sample(&self, p: i64) -> Option<i64> {
        (p.unsigned_abs() < 1 << (28 - self.s)).then(|| (p << self.s) + (1 << (self.s - 1)))
    }

    /// The edge values at the centre of pixel (`px`, `py`).
    #[inline(always)]
    fn at(&self, px: i64, py: i64) -> [i64; 3] {
        match (self.small, self.sample(px), self.sample(py)) {
            (Some(v), Some(x), Some(y)) => small_edges(&v, x, y),
            _ => match self.grid {
                None => self.tri.edges_fixed(px, py, self.sub),
                Some(bits) => self.tri.edges_fixed_on_grid(px, py, bits),
            },
        }
    }
}

/// [`ScreenTri::edges_fixed_with_steps`]: the edges at the centre of pixel (`px`, `py`) on the
/// raster grid and their constant steps to the next pixel in x and in y, in `i64` without
/// overflow checks under [`EdgePlane`]'s bounds (the same values), else the exact routine.
#[inline(always)]
#[must_use]
pub fn edges_with_steps(
    tri: &ScreenTri,
    px: i64,
    py: i64,
    sub: u32,
) -> ([i64; 3], [i64; 3], [i64; 3]) {
    let s = sub.clamp(1, 12);
    let v = tri.xy;
    let [[x0, y0], [x1, y1], [x2, y2]] = v;
    let coords = x0.unsigned_abs()
        | y0.unsigned_abs()
        | x1.unsigned_abs()
        | y1.unsigned_abs()
        | x2.unsigned_abs()
        | y2.unsigned_abs();
    if coords >= SMALL || (px.unsigned_abs() | py.unsigned_abs()) >= 1 << (28 - s) {
        return tri.edges_fixed_with_steps(px, py, sub);
    }
    let h = 1i64 << (s - 1);
    (
        small_edges(&v, (px << s) + h, (py << s) + h),
        [-((y2 - y1) << s), -((y0 - y2) << s), -((y1 - y0) << s)],
        [(x2 - x1) << s, (x0 - x2) << s, (x1 - x0) << s],
    )
}

/// Edge `i` from vertex `i + 1` to `i + 2` at the sample (`x`, `y`), all on one grid,
/// as [`ScreenTri::edges_fixed`] computes it (exact: the operands are below 2^30).
#[inline(always)]
fn small_edges(v: &[[i64; 2]; 3], x: i64, y: i64) -> [i64; 3] {
    let edge = |[xj, yj]: [i64; 2], [xk, yk]: [i64; 2]| (xk - xj) * (y - yj) - (yk - yj) * (x - xj);
    [edge(v[1], v[2]), edge(v[2], v[0]), edge(v[0], v[1])]
}

/// Float twin: the same algorithm on float edge functions.
pub fn float(px: &Px, frag: &mut Frag, _: &mut Counters) {
    let (x, y) = (px.x as f64, px.y as f64);
    let (tri, a) = (px.tri, px.a);
    let e = tri.edges_float(x, y);
    if px.plan.derivatives && px.m.hw.lod.lod_per_quad {
        let p = perspective_bary_f64(e, a.inv_w_f);
        let (qx, qy) = ((px.x & !1) as f64, (px.y & !1) as f64);
        let b = |x: f64, y: f64| perspective_bary_f64(tri.edges_float(x, y), a.inv_w_f);
        let (q0, q1, q2) = (b(qx, qy), b(qx + 1.0, qy), b(qx, qy + 1.0));
        frag.bary = [
            p,
            [0, 1, 2].map(|i| p[i] + q1[i] - q0[i]),
            [0, 1, 2].map(|i| p[i] + q2[i] - q0[i]),
        ];
    } else if px.plan.derivatives {
        let ex = tri.edges_float(x + 1.0, y);
        let ey = tri.edges_float(x, y + 1.0);
        let dx = [0, 1, 2].map(|i| ex[i] - e[i]);
        let dy = [0, 1, 2].map(|i| ey[i] - e[i]);
        frag.bary = perspective_bary_derivs_f64(e, dx, dy, a.inv_w_f);
    } else {
        frag.bary[0] = perspective_bary_f64(e, a.inv_w_f);
    }
}

/// One invocation: the barycentrics, plus their derivatives when the plan needs them.
#[must_use]
pub fn cost(m: &Machine, plan: &Plan) -> UnitCost {
    let glpc = m.hw.timing.gate_levels_per_cycle;
    if plan.derivatives && m.hw.lod.lod_per_quad {
        perspective_bary_cost(&m.hw.interp, &m.recip, glpc).times(4)
    } else if plan.derivatives {
        perspective_bary_derivs_cost(&m.hw.interp, &m.recip, glpc)
    } else {
        perspective_bary_cost(&m.hw.interp, &m.recip, glpc)
    }
}
