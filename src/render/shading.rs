//! The shading phase: per-triangle attributes in the units' formats, then every covered pixel
//! through its plan's compiled program (in parallel by rows, bit-identical for any thread
//! count), with the stages' traces collected into timing events when asked.

use super::Geometry;
use crate::pipeline::bump::{BumpAttrs, BumpVertex};
use crate::pipeline::clip_f32::ShadedVertex;
use crate::pipeline::coord_f32::{self, F32Tri};
use crate::pipeline::stages::{output16, run, run_span, Counters, Machine, TriAttrs, SPAN_MAX};
use crate::pipeline::{Frag, Program, StageImpls};
use crate::raster::{ScreenTri, VertexSource};
use crate::raster::{Setup, VisBuffer, NO_TRI};
use crate::report::Image;
use crate::timing::events::{record_pixel, FrameEvents, RowEvents};
use crate::timing::Simulator;
use glam::DMat4;
use hw_model::config::CoordArith;
use hw_model::f32_convert::from_i32;
use hw_model::fixed::SatCounter;
use rayon::prelude::*;

/// Bump data of every screen triangle of a bump plan (clipped vertices blended from their
/// source vertices); sets `TriAttrs::bump`.
pub(super) fn bump_attrs(
    setup: &Setup,
    geo: &Geometry,
    m: &Machine,
    attrs: &mut [TriAttrs],
) -> (Vec<BumpAttrs>, SatCounter) {
    let mut out = Vec::new();
    let mut sat = SatCounter::default();
    if geo.bump.is_empty() {
        return (out, sat);
    }
    for (i, (t, a)) in setup.tris.iter().zip(attrs.iter_mut()).enumerate() {
        let plan = &geo.plans[a.plan as usize];
        if plan.bump.is_none() {
            continue;
        }
        let d = &geo.draws[t.src as usize];
        let src_bary = setup.src_bary(i);
        let blend = |k: usize| -> BumpVertex {
            let w = src_bary[k];
            let mut r = BumpVertex::default();
            for (&wj, &vi) in w.iter().zip(&d.v) {
                let Some(b) = geo.bump.get(vi as usize) else {
                    continue;
                };
                for c in 0..3 {
                    r.n[c] += wj * b.n[c];
                    r.du[c] += wj * b.du[c];
                    r.dv[c] += wj * b.dv[c];
                    r.m[c] += wj * b.m[c];
                    r.p[c] += wj * b.p[c];
                }
                for c in 0..2 {
                    r.len[c] += wj * b.len[c];
                }
            }
            r
        };
        let verts = [blend(0), blend(1), blend(2)];
        a.bump = out.len() as u32;
        out.push(BumpAttrs::new(
            m,
            &verts,
            geo.eye,
            &geo.point_lights,
            &mut sat,
        ));
    }
    (out, sat)
}

/// Per-triangle attributes of every screen triangle, in the machine's formats.
pub(super) fn tri_attrs(setup: &Setup, geo: &Geometry, m: &Machine) -> (Vec<TriAttrs>, SatCounter) {
    // Written in parallel straight into their vector; the overflow counts sum in any order.
    let mut out = (
        crate::raster::vec_populated(setup.tris.len()),
        SatSum::default(),
    );
    out.par_extend(setup.tris.par_iter().enumerate().map(|(i, t)| {
        let d = &geo.draws[t.src as usize];
        let blend = |k: usize| -> ([f64; 3], [f64; 2]) {
            let w = setup.src_bary(i)[k];
            let mut c = [0.0; 3];
            let mut uv = [0.0; 2];
            for (&wj, &vi) in w.iter().zip(&d.v) {
                let vi = vi as usize;
                for (acc, &x) in c.iter_mut().zip(&geo.color[vi]) {
                    *acc += wj * x;
                }
                for (acc, &x) in uv.iter_mut().zip(&geo.uv[vi]) {
                    *acc += wj * x;
                }
            }
            (c, uv)
        };
        // An unclipped triangle's vertices are its source's: the blend with unit weights is
        // `x + 0.0` (a zero's sign dropped) when every blended value is finite.
        let direct = match t.source {
            VertexSource::Unclipped { swapped } => {
                let vs = if swapped {
                    [d.v[0], d.v[2], d.v[1]]
                } else {
                    d.v
                };
                let finite = vs.iter().all(|&vi| {
                    let vi = vi as usize;
                    geo.color[vi]
                        .iter()
                        .chain(&geo.uv[vi])
                        .all(|x| x.is_finite())
                });
                finite.then(|| {
                    vs.map(|vi| {
                        let vi = vi as usize;
                        (geo.color[vi].map(|x| x + 0.0), geo.uv[vi].map(|x| x + 0.0))
                    })
                })
            }
            VertexSource::Clipped => None,
        };
        let [(c0, t0), (c1, t1), (c2, t2)] = direct.unwrap_or_else(|| [0, 1, 2].map(blend));
        let mut sat = SatCounter::default();
        let plan = geo.draw_plan[t.src as usize];
        let wrap = geo.plans[plan as usize].wrap;
        let a = TriAttrs::new(m, plan, t.inv_w, [c0, c1, c2], [t0, t1, t2], wrap, &mut sat);
        (a, sat)
    }));
    (out.0, out.1 .0)
}

/// The sum of overflow counters collected from a parallel iterator (nothing stored per item).
#[derive(Default)]
struct SatSum(SatCounter);

impl ParallelExtend<SatCounter> for SatSum {
    fn par_extend<I: IntoParallelIterator<Item = SatCounter>>(&mut self, items: I) {
        let s = items
            .into_par_iter()
            .reduce(SatCounter::default, |mut a, b| {
                a.add(&b);
                a
            });
        self.0.add(&s);
    }
}

/// llvmpipe's setup of every screen triangle for the float32 coordinate path
/// (`interp.coord_arith = "float32"`; empty otherwise), once per triangle; sets
/// `TriAttrs::f32_tri`.
pub(super) fn f32_tris(
    setup: &Setup,
    geo: &Geometry,
    m: &Machine,
    attrs: &mut [TriAttrs],
) -> Vec<F32Tri> {
    if m.hw.interp.coord_arith != CoordArith::Float32 {
        return Vec::new();
    }
    for (i, a) in attrs.iter_mut().enumerate() {
        a.f32_tri = i as u32;
    }
    setup
        .tris
        .par_iter()
        .map(|t| {
            let (src, half) = llvmpipe_source(t, geo, setup.width, setup.height);
            F32Tri::new(src, half)
        })
        .collect()
}

/// The view-projection matrix as binary32 (row-major `m[row][col]`).
fn matrix_f32(vp: &DMat4) -> [[u32; 4]; 4] {
    let c = vp.to_cols_array_2d();
    std::array::from_fn(|r| std::array::from_fn(|k| (c[k][r] as f32).to_bits()))
}

/// The source triangle of screen triangle `tri` as llvmpipe's vertex shader leaves it (each
/// vertex through [`shade_vertex`] with its texture coordinates, in draw order) and the
/// viewport's half sizes: what [`F32Tri::new`] clips and sets up.
fn llvmpipe_source(
    tri: &ScreenTri,
    geo: &Geometry,
    width: u32,
    height: u32,
) -> ([ShadedVertex; 3], [u32; 2]) {
    let f = |x: f64| (x as f32).to_bits();
    let d = &geo.draws[tri.src as usize];
    let mvp = geo.mesa_mvp.map_or_else(
        || matrix_f32(&geo.view_projection),
        |m| m.map(|row| row.map(f32::to_bits)),
    );
    let src = d.v.map(|vi| {
        let vi = vi as usize;
        let st = [f(geo.uv[vi][0]), f(geo.uv[vi][1])];
        coord_f32::shade_vertex(&mvp, geo.object[vi], st, width, height)
    });
    let half = [width / 2, height / 2].map(|h| from_i32(h as i32));
    (src, half)
}

/// What the shading pass reads: the visible triangles and everything prepared for them.
pub(super) struct ShadeInput<'a> {
    pub(super) vis: &'a VisBuffer,
    pub(super) setup: &'a Setup,
    pub(super) attrs: &'a [TriAttrs],
    pub(super) geo: &'a Geometry,
    pub(super) m: &'a Machine<'a>,
    /// Shade one fragment at a time through [`run`] (the reference of the span path).
    pub(super) per_fragment: bool,
}

/// Shades row `y` into `row` with the plans compiled as `progs`, adding to `c`; `on_pixel(plan
/// index, triangle, frag)` sees every shaded fragment in raster order (a no-op closure
/// compiles to the plain loop; the timing model records its events through it, from the
/// footprints the stages traced when `trace`). The covered pixels run in spans of up to
/// [`SPAN_MAX`] consecutive pixels of one triangle ([`run_span`]), or one at a time
/// ([`run`]) with `inp.per_fragment`: the same image, counters and fragments.
/// `frags` is the caller's scratch ([`frag_scratch`], one per worker: a fragment is ~3 KB, so
/// a span's worth is not built per row).
#[allow(clippy::too_many_arguments)]
pub(super) fn shade_row(
    inp: &ShadeInput,
    progs: &[Program],
    y: usize,
    row: &mut [[u16; 4]],
    frags: &mut [Frag],
    c: &mut Counters,
    trace: bool,
    mut on_pixel: impl FnMut(u32, u32, &Frag),
) {
    shade_row_spans(inp, progs, y, row, frags, c, trace, |pi, t, span| {
        for frag in span {
            on_pixel(pi, t, frag);
        }
    });
}

/// [`shade_row`] with `on_span(plan index, triangle, fragments)` seeing the shaded fragments a
/// span at a time (consecutive pixels of one triangle, in raster order).
#[allow(clippy::too_many_arguments)]
fn shade_row_spans(
    inp: &ShadeInput,
    progs: &[Program],
    y: usize,
    row: &mut [[u16; 4]],
    frags: &mut [Frag],
    c: &mut Counters,
    trace: bool,
    mut on_span: impl FnMut(u32, u32, &[Frag]),
) {
    let w = inp.vis.width as usize;
    let cap = if inp.per_fragment { 1 } else { SPAN_MAX };
    let frags = &mut frags[..cap];
    for frag in frags.iter_mut() {
        frag.trace.on = trace;
    }
    let tris = &inp.vis.tri[y * w..(y + 1) * w];
    // The fragments of each run of one program, charged when the run ends.
    let mut run_of: Option<(usize, u64)> = None;
    let mut x = 0;
    while x < w {
        let t = tris[x];
        if t == NO_TRI {
            x += 1;
            continue;
        }
        let n = tris[x..(x + cap).min(w)]
            .iter()
            .take_while(|&&u| u == t)
            .count();
        let a = &inp.attrs[t as usize];
        let pi = a.plan as usize;
        match &mut run_of {
            Some((p, k)) if *p == pi => *k += n as u64,
            _ => {
                if let Some((p, k)) = run_of.replace((pi, n as u64)) {
                    progs[p].charge(k, c);
                }
            }
        }
        let tri = &inp.setup.tris[t as usize];
        let plan = &inp.geo.plans[pi];
        let (px, py) = (x as i64, y as i64);
        let span = &mut frags[..n];
        if inp.per_fragment {
            run(&progs[pi], plan, inp.m, tri, a, px, py, &mut span[0], c);
        } else {
            run_span(&progs[pi], plan, inp.m, tri, a, px, py, span, c);
        }
        for (frag, out) in span.iter().zip(&mut row[x..x + n]) {
            *out = output16(frag);
        }
        on_span(a.plan, t, span);
        x += n;
    }
    if let Some((p, k)) = run_of {
        progs[p].charge(k, c);
    }
}

/// The fragments [`shade_row`] works in: one span's worth.
pub(super) fn frag_scratch() -> Vec<Frag> {
    vec![Frag::default(); SPAN_MAX]
}

/// Rows shaded per band when the timing model runs beside the shading (see [`shade`]).
const BAND_ROWS: usize = 16;

/// Shades every covered pixel with `impls`; returns the image, the counters and, when `timing`
/// holds the frame's timing model, the event stream (rows concatenated in row order) and the
/// model fed with every pixel (the stream's pixel and footprint lists stay empty unless
/// `keep_events`). The model and the stream see the pixels in raster order, identical for
/// any thread count:
/// - on one thread the rows are shaded in order and each fragment's trace goes straight to
///   the model (and, with `keep_events`, to the stream): no row's events are stored;
/// - on more, the frame is shaded in bands of [`BAND_ROWS`] rows: while a band is shaded (in
///   parallel by rows, each row recording its events) the previous band's events are fed to
///   the model and appended to the stream, so the sequential model overlaps the shading; the
///   two sets of row buffers alternate between the bands.
pub(super) fn shade<'h>(
    inp: &ShadeInput,
    impls: &StageImpls,
    background: [u16; 4],
    timing: Option<Simulator<'h>>,
    keep_events: bool,
) -> (Image, Counters, Option<(FrameEvents, Simulator<'h>)>) {
    let vis = inp.vis;
    let w = vis.width as usize;
    let mut img = Image::new(vis.width, vis.height, background);
    let progs: Vec<Program> = inp
        .geo
        .plans
        .iter()
        .map(|p| Program::new(p, impls, inp.m))
        .collect();
    let progs = &progs[..];
    let Some(mut sim) = timing else {
        let counters = img
            .px
            .par_chunks_mut(w.max(1))
            .enumerate()
            .map_init(frag_scratch, |frags, (y, row)| {
                let mut c = Counters::default();
                shade_row(inp, progs, y, row, frags, &mut c, false, |_, _, _| {});
                c
            })
            .reduce(Counters::default, |mut a, b| {
                a.add(&b);
                a
            });
        return (img, counters, None);
    };
    let mut counters = Counters::default();
    let mut fe = FrameEvents {
        width: vis.width,
        height: vis.height,
        ..FrameEvents::default()
    };
    if rayon::current_num_threads() == 1 {
        let mut ev = RowEvents::default();
        let mut frags = frag_scratch();
        for (y, row) in img.px.chunks_mut(w.max(1)).enumerate() {
            let c = &mut counters;
            shade_row_spans(inp, progs, y, row, &mut frags, c, true, |pi, t, span| {
                sim.span(pi, span.iter().map(|frag| frag.trace.footprints()));
                if keep_events {
                    for frag in span {
                        record_pixel(pi, t, frag, &mut ev);
                    }
                }
            });
            if keep_events {
                fe.append_row(&ev);
                ev.clear();
            }
        }
        return (img, counters, Some((fe, sim)));
    }
    // A row's events: at most the most lookups of a plan, of two levels each, per pixel.
    let lookups = inp
        .geo
        .plans
        .iter()
        .map(|p| {
            p.stages
                .iter()
                .map(|&k| crate::timing::events::lookups(k, inp.m.hw) as usize)
                .sum::<usize>()
        })
        .max()
        .unwrap_or(0);
    let new_row = || RowEvents {
        pixels: Vec::with_capacity(w),
        footprints: Vec::with_capacity(w * 2 * lookups),
    };
    let mut consume = |rows: Vec<(Counters, RowEvents)>| {
        rows.into_iter()
            .map(|(c, mut ev)| {
                counters.add(&c);
                sim.row(&ev);
                if keep_events {
                    fe.append_row(&ev);
                }
                ev.clear();
                ev
            })
            .collect::<Vec<_>>()
    };
    let mut pending = Vec::new();
    let mut spare: Vec<RowEvents> = Vec::new();
    for (band, px) in img.px.chunks_mut((w * BAND_ROWS).max(1)).enumerate() {
        let previous = std::mem::take(&mut pending);
        let rows = px.len().div_ceil(w.max(1));
        spare.resize_with(rows, new_row);
        let buffers = std::mem::take(&mut spare);
        let (shaded, returned) = rayon::join(
            || {
                px.par_chunks_mut(w.max(1))
                    .zip(buffers)
                    .enumerate()
                    .map_init(frag_scratch, |frags, (r, (row, mut ev))| {
                        let mut c = Counters::default();
                        let y = band * BAND_ROWS + r;
                        shade_row(inp, progs, y, row, frags, &mut c, true, |pi, t, frag| {
                            record_pixel(pi, t, frag, &mut ev);
                        });
                        (c, ev)
                    })
                    .collect::<Vec<_>>()
            },
            || consume(previous),
        );
        pending = shaded;
        spare = returned;
    }
    consume(pending);
    (img, counters, Some((fe, sim)))
}
