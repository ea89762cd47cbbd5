//! `bary`: perspective-correct barycentrics at the pixel and, when the plan needs derivatives,
//! at its two first-order neighbours (Heckbert & Moreton 1991; `hw_model::interpolator`);
//! with `lod_per_quad` the neighbours carry the finite differences of the pixel's 2x2 quad;
//! with `attr_subpixel_bits` the edges come from the float positions on that finer grid.

use super::lanes::Lanes;
use super::stages::TriAttrs;
use super::stages::{each_fragment, Counters, Machine};
use super::{Frag, Plan, Px, StageKind};
use crate::fixedpoint::from_raw;
use crate::raster::ScreenTri;
use crate::reference::{perspective_bary_derivs_f64, perspective_bary_f64};
use hw_model::interpolator::{
    perspective_bary, perspective_bary_cost, perspective_bary_derivs, perspective_bary_derivs_cost,
    perspective_bary_derivs_span, perspective_bary_derivs_spans, perspective_bary_span, DerivLanes,
    DerivSpan, DerivsOut, EdgeSpan, GATHER_MAX_LANES,
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
    let edges = |x: i64, y: i64| {
        if regrid {
            tri.edges_fixed_on_grid(x, y, grid)
        } else {
            tri.edges_fixed(x, y, sub)
        }
    };
    if px.plan.derivatives && hw.lod.lod_per_quad {
        // The pixel, then its helpers carry the quad's finite differences.
        let mut b =
            |x: i64, y: i64| perspective_bary(edges(x, y), a.inv_w_x, &hw.interp, &m.recip, sat);
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
        let (e, dx, dy) = if regrid {
            // The attribute grid: the steps are differences of edge values.
            let e = edges(px.x, px.y);
            let (ex, ey) = (edges(px.x + 1, px.y), edges(px.x, px.y + 1));
            (
                e,
                [0, 1, 2].map(|i| ex[i].wrapping_sub(e[i])),
                [0, 1, 2].map(|i| ey[i].wrapping_sub(e[i])),
            )
        } else {
            tri.edges_fixed_with_steps(px.x, px.y, sub)
        };
        frag.bary_x = perspective_bary_derivs(e, dx, dy, a.inv_w_x, &hw.interp, &m.recip, sat);
    } else {
        frag.bary_x[0] = perspective_bary(edges(px.x, px.y), a.inv_w_x, &hw.interp, &m.recip, sat);
    }
    if px.carriers {
        for s in 0..px.samples() {
            frag.bary[s] = frag.bary_x[s].map(|r| from_raw(r, bb));
        }
    }
}

/// Fixed twin over a span: the edges at the span's first pixel and their constant steps
/// (`ScreenTri::edges_fixed_span`), then the interpolator's span datapath
/// (`perspective_bary_derivs_span`, `perspective_bary_span`), bit-identical to [`fixed`] on
/// each fragment; a lone fragment is a one-lane span when the plan needs derivatives. A lone
/// fragment without them (the span's setup costs more than it saves), `lod_per_quad`,
/// `attr_subpixel_bits` and spans beyond the edges' `i64` bounds run [`fixed`] per fragment.
pub fn fixed_span(px: &Px, frags: &mut [Frag], c: &mut Counters) {
    if let Some(lanes) = px.lanes {
        return into_lanes(px, frags, &mut lanes.borrow_mut(), c);
    }
    if let Some(row) = px.row_bary {
        // Computed with the row's other spans ([`Row`]).
        for (frag, b) in frags.iter_mut().zip(row) {
            frag.bary_x = *b;
        }
        return carriers(px, frags);
    }
    let Some(span) = edge_span(px, frags.len()) else {
        return each_fragment(fixed, px, frags, c);
    };
    let sat = &mut c.sat[StageKind::Bary.index()];
    let (inv_w, cfg, recip) = (px.a.inv_w_x, &px.m.hw.interp, &px.m.recip);
    if px.plan.derivatives {
        let out = |j: usize, b| frags[j].bary_x = b;
        perspective_bary_derivs_span(&span, inv_w, cfg, recip, sat, out);
    } else {
        let out = |j: usize, b| frags[j].bary_x[0] = b;
        perspective_bary_span(&span, inv_w, cfg, recip, sat, out);
    }
    carriers(px, frags);
}

/// [`fixed_span`] in a program that keeps the chain's signals in lanes
/// ([`super::lanes`]): the same barycentrics, written to the span's lanes (from
/// `px.base`) rather than to the fragments. (Such a program has derivatives and writes no
/// carriers.)
fn into_lanes(px: &Px, frags: &mut [Frag], lanes: &mut Lanes, c: &mut Counters) {
    // The datapath's vector batches store their lanes whole.
    let mut out = DerivLanes {
        bary: &mut lanes.bary,
        base: px.base,
    };
    if let Some(row) = px.row_bary {
        for (j, b) in row.iter().enumerate() {
            out.lane(j, *b);
        }
        return;
    }
    let Some(span) = edge_span(px, frags.len()) else {
        each_fragment(fixed, px, frags, c);
        for (j, frag) in frags.iter().enumerate() {
            out.lane(j, frag.bary_x);
        }
        return;
    };
    let sat = &mut c.sat[StageKind::Bary.index()];
    perspective_bary_derivs_span(&span, px.a.inv_w_x, &px.m.hw.interp, &px.m.recip, sat, out);
}

/// The `n` pixels of the span at `px` as the span datapath takes them: their edges and
/// steps on the raster's grid, when the plan takes the span datapath ([`span_edges`]), the
/// span is worth it (more than one pixel, or derivatives) and the steps fit `i64`.
fn edge_span(px: &Px, n: usize) -> Option<EdgeSpan> {
    if !(span_edges(px.m, px.plan) && (n > 1 || px.plan.derivatives)) {
        return None;
    }
    let sub = px.m.hw.raster.subpixel_bits;
    let (edge, dx, dy) = px.tri.edges_fixed_span(px.x, px.y, n, sub)?;
    Some(EdgeSpan {
        edge,
        dx,
        dy,
        lanes: n,
    })
}

/// The float carriers of the span's raw barycentrics, when the run reads them.
#[inline]
fn carriers(px: &Px, frags: &mut [Frag]) {
    if px.carriers {
        let bb = px.m.hw.interp.bary_bits;
        for frag in frags.iter_mut() {
            for s in 0..px.samples() {
                frag.bary[s] = frag.bary_x[s].map(|r| from_raw(r, bb));
            }
        }
    }
}

/// Whether a span of `plan` takes its edges and their steps on the raster's grid (the span
/// datapath): neither `lod_per_quad` with derivatives nor an `attr_subpixel_bits` grid.
fn span_edges(m: &Machine, plan: &Plan) -> bool {
    let hw = m.hw;
    let grid = hw.interp.attr_subpixel_bits;
    let regrid = grid != 0 && grid != hw.raster.subpixel_bits;
    let quad = plan.derivatives && hw.lod.lod_per_quad;
    !(regrid || quad)
}

/// Whether the Fixed barycentrics of `plan` run as one pass over each row's spans ([`Row`]):
/// with derivatives, on the span datapath ([`span_edges`]).
#[must_use]
pub fn row_pass(m: &Machine, plan: &Plan) -> bool {
    plan.derivatives && span_edges(m, plan)
}

/// The barycentrics and derivatives of one row's spans, computed before the row is shaded by
/// one call of the interpolator's multi-span datapath
/// ([`perspective_bary_derivs_spans`]), so that the lanes of short spans (a mesh's) fill the
/// vector batches across the spans as a long span's do; [`fixed_span`] then takes each
/// span's from here (`Px::row_bary`, `SpanAt::row_bary`). Bit-identical to [`fixed_span`]
/// span by span, with the same saturation counts (`frames_in_spans_equal_frames_per_fragment`
/// in the pipeline tests; the datapath's own test is `gathered_spans_match_per_lane_calls`). A
/// worker keeps one and reuses its buffers row after row.
#[derive(Default)]
pub struct Row {
    spans: Vec<DerivSpan>,
    /// The first pixel of each of `spans`.
    starts: Vec<usize>,
    /// Per pixel of the row: its barycentrics when its span is in `spans`.
    bary: Vec<[[i64; 3]; 3]>,
    /// The next of `starts` [`Row::take`] looks for (the row is shaded in the order its spans
    /// were added).
    next: usize,
}

impl Row {
    /// Empties the row for one of `width` pixels.
    pub fn start(&mut self, width: usize) {
        self.spans.clear();
        self.starts.clear();
        self.next = 0;
        self.bary.resize(width, [[0; 3]; 3]);
    }

    /// Adds the span of `n` pixels from (`x`, `y`) of `tri` (attributes `a`), a span of a
    /// plan with [`row_pass`]. A span of more than `GATHER_MAX_LANES` (which fills its own
    /// vector batches) or beyond the `i64` bounds of its edges' steps is left to
    /// [`fixed_span`].
    pub fn push(
        &mut self,
        m: &Machine,
        tri: &ScreenTri,
        a: &TriAttrs,
        (x, y): (usize, i64),
        n: usize,
    ) {
        if n > GATHER_MAX_LANES {
            return;
        }
        let sub = m.hw.raster.subpixel_bits;
        if let Some((edge, dx, dy)) = tri.edges_fixed_span(x as i64, y, n, sub) {
            let span = EdgeSpan {
                edge,
                dx,
                dy,
                lanes: n,
            };
            self.spans.push(DerivSpan {
                span,
                inv_w: a.inv_w_x,
            });
            self.starts.push(x);
        }
    }

    /// Computes every span added since [`Row::start`], its saturations counted in `c`.
    pub fn run(&mut self, m: &Machine, c: &mut Counters) {
        if self.spans.is_empty() {
            return;
        }
        let (cfg, recip) = (&m.hw.interp, &m.recip);
        let sat = &mut c.sat[StageKind::Bary.index()];
        let (starts, bary) = (&self.starts, &mut self.bary);
        perspective_bary_derivs_spans(&self.spans, cfg, recip, sat, |i, j, b| {
            bary[starts[i] + j] = b;
        });
    }

    /// Whether [`Row::run`] computed the barycentrics of the span from pixel `x` (then in
    /// [`Row::bary`]); the row's spans are asked for in order.
    pub fn take(&mut self, x: usize) -> bool {
        if self.starts.get(self.next) != Some(&x) {
            return false;
        }
        self.next += 1;
        true
    }

    /// The row's barycentrics by pixel: those of the spans [`Row::take`] found.
    #[must_use]
    pub fn bary(&self) -> &[[[i64; 3]; 3]] {
        &self.bary
    }
}

/// Float twin: the same algorithm on float edge functions.
pub fn float(px: &Px, frag: &mut Frag, _: &mut Counters) {
    let (x, y) = (px.x as f64, px.y as f64);
    let (tri, af) = (px.tri, px.af);
    if px.plan.derivatives && px.m.hw.lod.lod_per_quad {
        let p = perspective_bary_f64(tri.edges_float(x, y), af.inv_w);
        let (qx, qy) = ((px.x & !1) as f64, (px.y & !1) as f64);
        let b = |x: f64, y: f64| perspective_bary_f64(tri.edges_float(x, y), af.inv_w);
        let (q0, q1, q2) = (b(qx, qy), b(qx + 1.0, qy), b(qx, qy + 1.0));
        frag.bary = [
            p,
            [0, 1, 2].map(|i| p[i] + q1[i] - q0[i]),
            [0, 1, 2].map(|i| p[i] + q2[i] - q0[i]),
        ];
    } else if px.plan.derivatives {
        let [e, ex, ey] = tri.edges_float_and_steps(x, y);
        let dx = [0, 1, 2].map(|i| ex[i] - e[i]);
        let dy = [0, 1, 2].map(|i| ey[i] - e[i]);
        frag.bary = perspective_bary_derivs_f64(e, dx, dy, af.inv_w);
    } else {
        frag.bary[0] = perspective_bary_f64(tri.edges_float(x, y), af.inv_w);
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
