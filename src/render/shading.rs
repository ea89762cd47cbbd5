//! The shading phase: per-triangle attributes in the units' formats, then every covered pixel
//! through its plan's compiled program (in parallel by rows, bit-identical for any thread
//! count), with the stages' traces collected into timing events when asked.

use super::Geometry;
use crate::pipeline::bump::{BumpAttrs, BumpVertex};
use crate::pipeline::clip_f32::{outcode, ShadedVertex};
use crate::pipeline::coord_f32::{self, F32Tri};
use crate::pipeline::lanes::LaneCell;
use crate::pipeline::stages::{
    output16, run, run_spans, Counters, Machine, QuietSetup, SpanAt, TriAttrs, TriFloat, SPAN_MAX,
};
use crate::pipeline::{bary, Frag, Program, StageImpls, StageKind};
use crate::prefetch::prefetch;
use crate::raster::{ScreenTri, Setup, VertexSource, VisBuffer, NO_TRI};
use crate::report::Image;
use crate::timing::events::{record_pixel, FrameEvents, RowEvents};
use crate::timing::Simulator;
use glam::DMat4;
use hw_model::config::CoordArith;
use hw_model::f32_convert::from_i32;
use hw_model::fixed::SatCounter;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Mutex, MutexGuard, PoisonError};

/// Bump data of every screen triangle of a bump plan (clipped vertices blended from their
/// source vertices), computed in parallel and stored in triangle order; sets
/// `TriAttrs::bump`.
pub(super) fn bump_attrs(
    setup: &Setup,
    geo: &Geometry,
    m: &Machine,
    attrs: &mut [TriAttrs],
) -> (Vec<BumpAttrs>, SatCounter) {
    if geo.bump.is_empty() {
        return (Vec::new(), SatCounter::default());
    }
    // The triangles of a bump plan, in order; their data is written straight into its slots
    // (each is about 1.4 KB: no intermediate copy).
    let bumped: Vec<u32> = (0..attrs.len() as u32)
        .into_par_iter()
        .filter(|&i| geo.plans[attrs[i as usize].plan as usize].bump.is_some())
        .collect();
    let mut out = (
        crate::raster::vec_populated(bumped.len()),
        SatSum::default(),
    );
    out.par_extend(bumped.par_iter().map(|&i| {
        let i = i as usize;
        let d = &geo.draws[setup.tris[i].src as usize];
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
        let mut s = SatCounter::default();
        let b = BumpAttrs::new(m, &verts, geo.eye, &geo.point_lights, &mut s);
        (b, s)
    }));
    for (k, &i) in bumped.iter().enumerate() {
        attrs[i as usize].bump = k as u32;
    }
    let (out, SatSum(sat)) = out;
    (out, sat)
}

/// Which screen triangles cover a pixel of `vis` (`n` triangles): the only ones a shading
/// pass over `vis` reads the attributes of.
fn shaded_triangles(vis: &VisBuffer, n: usize) -> Vec<bool> {
    // One mark more, for the empty pixels ([`NO_TRI`] and any id beyond): every pixel stores
    // without a branch (a branch on the id changing mispredicts at every span's end).
    let marks: Vec<AtomicBool> = (0..=n).map(|_| AtomicBool::new(false)).collect();
    vis.tri.par_chunks(1 << 14).for_each(|ids| {
        for &t in ids {
            marks[(t as usize).min(n)].store(true, Ordering::Relaxed);
        }
    });
    let mut marks: Vec<bool> = marks.into_iter().map(AtomicBool::into_inner).collect();
    marks.truncate(n);
    marks
}

/// The bounds of the texture coordinates of `geo`'s vertices, `None` if one is not finite.
fn uv_bounds(geo: &Geometry) -> Option<([f64; 2], [f64; 2])> {
    let none = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    let (lo, hi) = geo
        .uv
        .par_iter()
        .fold(
            || Some(none),
            |b, uv| {
                let (mut lo, mut hi) = b?;
                for ax in 0..2 {
                    if !uv[ax].is_finite() {
                        return None;
                    }
                    lo[ax] = lo[ax].min(uv[ax]);
                    hi[ax] = hi[ax].max(uv[ax]);
                }
                Some((lo, hi))
            },
        )
        .reduce(
            || Some(none),
            |a, b| {
                let ((la, ha), (lb, hb)) = (a?, b?);
                Some((
                    [0, 1].map(|i| la[i].min(lb[i])),
                    [0, 1].map(|i| ha[i].max(hb[i])),
                ))
            },
        )?;
    Some((lo, hi))
}

/// The most pixels per triangle at which [`tri_attrs`] scans the visibility buffer for the
/// triangles it shades ([`shaded_triangles`]): with fewer triangles, the scan costs more than
/// converting every triangle (W1, two triangles: the scan of its 1M pixels took 0.65 ms of a
/// 25 ms frame). Either way the attributes shaded and the overflow counts are the same.
const SCAN_PIXELS_PER_TRI: usize = 256;

/// Per-triangle attributes of every screen triangle in the machine's formats and, when
/// `floats` (a stage of the render's passes reads them), in float; else the second vector is
/// empty. With `vis`, the visibility buffer of the frame's only shading pass, a triangle
/// that covers none of its pixels ([`shaded_triangles`]) is [`TriAttrs::unshaded`] where that
/// leaves the overflow counts as they were ([`QuietSetup`]): hidden triangles cost no
/// conversion. The pixels are not scanned when the mesh's coordinates could overflow, nor
/// when the triangles are few for the pixels ([`SCAN_PIXELS_PER_TRI`]).
pub(super) fn tri_attrs(
    setup: &Setup,
    geo: &Geometry,
    m: &Machine,
    floats: bool,
    vis: Option<&VisBuffer>,
) -> (Vec<TriAttrs>, Vec<TriFloat>, SatCounter) {
    // Written in parallel straight into their vectors; the overflow counts sum in any order.
    let n = setup.tris.len();
    let reads_color: Vec<bool> = geo.plans.iter().map(|p| p.has(StageKind::Color)).collect();
    let quiet = vis
        .filter(|vis| n * SCAN_PIXELS_PER_TRI >= vis.tri.len())
        .and_then(|vis| {
            let q = QuietSetup::new(m, uv_bounds(geo));
            q.is_quiet().then(|| (shaded_triangles(vis, n), q))
        });
    // One triangle's attributes, float data and overflow counts.
    let convert = |(i, t): (usize, &ScreenTri)| -> (TriAttrs, TriFloat, SatCounter) {
        let plan = geo.draw_plan[t.src as usize];
        if let Some((shaded, q)) = &quiet {
            if !shaded[i] && q.holds(t.inv_w) {
                let a = TriAttrs::unshaded(plan);
                return (a, TriFloat::NONE, SatCounter::default());
            }
        }
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
        let wrap = geo.plans[plan as usize].wrap;
        let (color, uv) = ([c0, c1, c2], [t0, t1, t2]);
        let fixed_color = reads_color[plan as usize].then_some(color);
        let a = TriAttrs::new(m, plan, t.inv_w, fixed_color, uv, wrap, &mut sat);
        let af = TriFloat {
            inv_w: t.inv_w,
            color,
            uv,
        };
        (a, af, sat)
    };
    let tris = setup.tris.par_iter().enumerate();
    if floats {
        let mut out = (
            (
                crate::raster::vec_populated(n),
                crate::raster::vec_populated(n),
            ),
            SatSum::default(),
        );
        out.par_extend(tris.map(|it| {
            let (a, af, sat) = convert(it);
            ((a, af), sat)
        }));
        let ((attrs, af), SatSum(sat)) = out;
        return (attrs, af, sat);
    }
    // Without the float data, which is then not built: each item moved into the vectors is
    // smaller (a move of the attributes with their float data was a `memcpy` call, 0.7% of
    // W2's frame).
    let mut out = (crate::raster::vec_populated(n), SatSum::default());
    out.par_extend(tris.map(|it| {
        let (a, _, sat) = convert(it);
        (a, sat)
    }));
    let (attrs, SatSum(sat)) = out;
    (attrs, Vec::new(), sat)
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
    attrs
        .par_iter_mut()
        .enumerate()
        .for_each(|(i, a)| a.f32_tri = i as u32);
    f32_setups(setup, geo)
}

/// [`F32Tri`] of every screen triangle: its source triangle's vertices as llvmpipe's vertex
/// shader leaves them ([`shade_vertices`], each shared vertex shaded once), clipped and set
/// up (the same as [`F32Tri::new`] of [`llvmpipe_source`]).
fn f32_setups(setup: &Setup, geo: &Geometry) -> Vec<F32Tri> {
    let verts = shade_vertices(setup, geo);
    let half = viewport_half(setup.width, setup.height);
    setup
        .tris
        .par_iter()
        .map(|t| {
            let v = geo.draws[t.src as usize].v.map(|vi| &verts[vi as usize]);
            let mask = v[0].1 | v[1].1 | v[2].1;
            F32Tri::with_mask(v.map(|x| x.0), mask, half)
        })
        .collect()
}

/// Every vertex the screen triangles use through [`coord_f32::shade_vertex`] with its
/// texture coordinates, with its outcode ([`outcode`]); default for unused vertices.
fn shade_vertices(setup: &Setup, geo: &Geometry) -> Vec<(ShadedVertex, u32)> {
    let used: Vec<AtomicBool> = geo.object.iter().map(|_| AtomicBool::new(false)).collect();
    setup.tris.par_iter().for_each(|t| {
        for &vi in &geo.draws[t.src as usize].v {
            used[vi as usize].store(true, Ordering::Relaxed);
        }
    });
    let mvp = llvmpipe_mvp(geo);
    let (width, height) = (setup.width, setup.height);
    geo.object
        .par_iter()
        .zip(&geo.uv)
        .zip(&used)
        .map(|((&p, uv), used)| {
            if !used.load(Ordering::Relaxed) {
                return (ShadedVertex::default(), 0);
            }
            let st = uv.map(|x| (x as f32).to_bits());
            let v = coord_f32::shade_vertex(&mvp, p, st, width, height);
            (v, outcode(&v))
        })
        .collect()
}

/// The view-projection matrix as binary32 (row-major `m[row][col]`).
fn matrix_f32(vp: &DMat4) -> [[u32; 4]; 4] {
    let c = vp.to_cols_array_2d();
    std::array::from_fn(|r| std::array::from_fn(|k| (c[k][r] as f32).to_bits()))
}

/// The model-view-projection llvmpipe's vertex shader applies: the camera's binary32 GL
/// matrix when it has one, else the view-projection rounded to binary32.
fn llvmpipe_mvp(geo: &Geometry) -> [[u32; 4]; 4] {
    geo.mesa_mvp.map_or_else(
        || matrix_f32(&geo.view_projection),
        |m| m.map(|row| row.map(f32::to_bits)),
    )
}

/// The viewport's half sizes in binary32.
fn viewport_half(width: u32, height: u32) -> [u32; 2] {
    [width / 2, height / 2].map(|h| from_i32(h as i32))
}

/// The source triangle of screen triangle `tri` as llvmpipe's vertex shader leaves it (each
/// vertex through [`coord_f32::shade_vertex`] with its texture coordinates, in draw order)
/// and the viewport's half sizes: what [`F32Tri::new`] clips and sets up (the reference of
/// [`f32_setups`]).
#[cfg(test)]
fn llvmpipe_source(
    tri: &ScreenTri,
    geo: &Geometry,
    width: u32,
    height: u32,
) -> ([ShadedVertex; 3], [u32; 2]) {
    let f = |x: f64| (x as f32).to_bits();
    let d = &geo.draws[tri.src as usize];
    let mvp = llvmpipe_mvp(geo);
    let src = d.v.map(|vi| {
        let vi = vi as usize;
        let st = [f(geo.uv[vi][0]), f(geo.uv[vi][1])];
        coord_f32::shade_vertex(&mvp, geo.object[vi], st, width, height)
    });
    (src, viewport_half(width, height))
}

/// What the shading pass reads: the visible triangles and everything prepared for them.
pub(super) struct ShadeInput<'a> {
    pub(super) vis: &'a VisBuffer,
    pub(super) setup: &'a Setup,
    pub(super) attrs: &'a [TriAttrs],
    /// The triangles' float vertex data, in triangle order; empty when no stage reads it.
    pub(super) floats: &'a [TriFloat],
    pub(super) geo: &'a Geometry,
    pub(super) m: &'a Machine<'a>,
    /// Shade one fragment at a time through [`run`] (the reference of the span path).
    pub(super) per_fragment: bool,
}

/// Shades row `y` into `row` with the plans compiled as `progs`, adding to `c`; `on_pixel(plan
/// index, triangle, frag)` sees every shaded fragment in raster order (a no-op closure
/// compiles to the plain loop; the timing model records its events through it, from the
/// footprints the stages traced when `trace`). The covered pixels run in spans of up to
/// [`SPAN_MAX`] consecutive pixels of one triangle, gathered into runs of one program
/// ([`Group`], [`run_spans`]), or one at a time ([`run`]) with `inp.per_fragment`: the same
/// image, counters and fragments.
/// `scratch` is the caller's ([`frag_scratch`], one per worker: a fragment is ~3 KB, so a
/// span's worth is not built per row, nor the row's barycentrics).
#[allow(clippy::too_many_arguments)]
pub(super) fn shade_row(
    inp: &ShadeInput,
    progs: &[Program],
    y: usize,
    row: &mut [[u16; 4]],
    scratch: &mut RowScratch,
    c: &mut Counters,
    trace: bool,
    mut on_pixel: impl FnMut(u32, u32, &Frag),
) {
    shade_row_spans(inp, progs, y, row, scratch, c, trace, |pi, t, span| {
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
    scratch: &mut RowScratch,
    c: &mut Counters,
    trace: bool,
    mut on_span: impl FnMut(u32, u32, &[Frag]),
) {
    let w = inp.vis.width as usize;
    let cap = if inp.per_fragment { 1 } else { SPAN_MAX };
    let RowScratch { frags, bary, lanes } = scratch;
    let frags = &mut frags[..cap];
    for frag in frags.iter_mut() {
        frag.trace.on = trace;
    }
    let tris = &inp.vis.tri[y * w..(y + 1) * w];
    // The barycentrics of the row's spans whose plans take them in one pass.
    let row_bary = !inp.per_fragment && progs.iter().any(|p| p.row_bary);
    if row_bary {
        bary.start(w);
        let mut x = 0;
        while x < w {
            let t = tris[x];
            if t == NO_TRI {
                x += 1;
                continue;
            }
            let n = span_len(tris, x, cap);
            // The next span's triangle is read while this one is added.
            if let Some(&next) = tris.get(x + n) {
                prefetch(inp.attrs, next as usize);
                prefetch(&inp.setup.tris, next as usize);
            }
            let a = &inp.attrs[t as usize];
            if progs[a.plan as usize].row_bary {
                bary.push(inp.m, &inp.setup.tris[t as usize], a, (x, y as i64), n);
            }
            x += n;
        }
        bary.run(inp.m, c);
    }
    // The fragments of each stretch of spans of one program, charged when it ends.
    let mut run_of: Option<(usize, u64)> = None;
    let mut group = Group::new();
    let mut x = 0;
    while x < w {
        let t = tris[x];
        if t == NO_TRI {
            x += 1;
            continue;
        }
        let n = span_len(tris, x, cap);
        // The next span's triangle is read while this one is shaded.
        if let Some(&next) = tris.get(x + n) {
            prefetch(inp.attrs, next as usize);
            prefetch(&inp.setup.tris, next as usize);
        }
        let a = &inp.attrs[t as usize];
        let af = inp.floats.get(t as usize).unwrap_or(&TriFloat::NONE);
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
        let (px, py) = (x as i64, y as i64);
        if inp.per_fragment {
            let (prog, plan) = (&progs[pi], &inp.geo.plans[pi]);
            run(prog, plan, inp.m, tri, (a, af), px, py, &mut frags[0], c);
            row[x] = output16(&frags[0]);
            on_span(a.plan, t, &frags[..1]);
        } else {
            if !group.takes(pi, n) {
                group.shade(inp, progs, (&*bary, &*lanes), frags, row, c, &mut on_span);
            }
            let span = SpanAt {
                tri,
                attrs: (a, af),
                x: px,
                y: py,
                n,
                row_bary: row_bary && bary.take(x),
            };
            group.push(pi, t, span);
            if !progs[pi].gathers {
                group.shade(inp, progs, (&*bary, &*lanes), frags, row, c, &mut on_span);
            }
        }
        x += n;
    }
    group.shade(inp, progs, (&*bary, &*lanes), frags, row, c, &mut on_span);
    if let Some((p, k)) = run_of {
        progs[p].charge(k, c);
    }
}

/// Most fragments in a run of gathered spans ([`Group`]; a longer span is a run of its own):
/// two trilinear batches (`hw_model::trilinear::BATCH_LANES`). On W2 (spans of 4.2 fragments
/// on average) 16 took less time than 8, 24 and 32, whose runs' fragments (about 3 KB each)
/// fall out of the L1 cache between stages (`docs/PERFORMANCE_LOG.md`, stop 54).
const GATHER_MAX: usize = 16;

/// Consecutive spans of a row shaded together ([`run_spans`]): of one program, one span at a
/// time unless the program gathers them ([`Program::gathers`]), then at most [`GATHER_MAX`]
/// fragments.
struct Group<'a> {
    spans: Vec<SpanAt<'a>>,
    /// The triangle of each of `spans`.
    tris: Vec<u32>,
    /// Their program (its index).
    prog: usize,
    /// Their fragments.
    filled: usize,
}

impl<'a> Group<'a> {
    fn new() -> Self {
        Self {
            spans: Vec::with_capacity(GATHER_MAX),
            tris: Vec::with_capacity(GATHER_MAX),
            prog: 0,
            filled: 0,
        }
    }

    /// Whether a span of `n` fragments of program `prog` may join the group.
    fn takes(&self, prog: usize, n: usize) -> bool {
        self.spans.is_empty() || (prog == self.prog && self.filled + n <= GATHER_MAX)
    }

    /// Adds the span `span` of triangle `t` of program `prog` (which [`Group::takes`]).
    fn push(&mut self, prog: usize, t: u32, span: SpanAt<'a>) {
        self.prog = prog;
        self.filled += span.n;
        self.spans.push(span);
        self.tris.push(t);
    }

    /// Shades the group's spans in `frags` ([`run_spans`]), writes their outputs into `row`,
    /// shows each span to `on_span` in order (plan index, triangle, fragments), and empties
    /// the group.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn shade(
        &mut self,
        inp: &ShadeInput,
        progs: &[Program],
        (bary, lanes): (&bary::Row, &LaneCell),
        frags: &mut [Frag],
        row: &mut [[u16; 4]],
        c: &mut Counters,
        on_span: &mut impl FnMut(u32, u32, &[Frag]),
    ) {
        if self.spans.is_empty() {
            return;
        }
        let frags = &mut frags[..self.filled];
        let (prog, plan) = (&progs[self.prog], &inp.geo.plans[self.prog]);
        run_spans(prog, plan, inp.m, &self.spans, bary.bary(), lanes, frags, c);
        let mut rest = &*frags;
        for (s, &t) in self.spans.iter().zip(&self.tris) {
            let (span, tail) = rest.split_at(s.n);
            let x = s.x as usize;
            for (frag, out) in span.iter().zip(&mut row[x..x + s.n]) {
                *out = output16(frag);
            }
            on_span(self.prog as u32, t, span);
            rest = tail;
        }
        self.spans.clear();
        self.tris.clear();
        self.filled = 0;
    }
}

/// The pixels from `x` of a row's `tris` that one span takes: those of the triangle at `x`
/// up to the next pixel of another (or of none), at most `cap`.
#[inline]
fn span_len(tris: &[u32], x: usize, cap: usize) -> usize {
    let t = tris[x];
    tris[x..(x + cap).min(tris.len())]
        .iter()
        .take_while(|&&u| u == t)
        .count()
}

/// What [`shade_row`] works in, one per worker: one span's fragments and the row's
/// barycentrics ([`bary::Row`]).
pub(super) struct RowScratch {
    frags: Vec<Frag>,
    bary: bary::Row,
    lanes: LaneCell,
}

/// A worker's [`RowScratch`].
pub(super) fn frag_scratch() -> RowScratch {
    RowScratch {
        frags: vec![Frag::default(); SPAN_MAX],
        bary: bary::Row::default(),
        lanes: LaneCell::default(),
    }
}

/// Shades every covered pixel with `impls`; returns the image, the counters and, when `timing`
/// holds the frame's timing model, the event stream (rows concatenated in row order) and the
/// model fed with every pixel (the stream's pixel and footprint lists stay empty unless
/// `keep_events`). The model and the stream see the pixels in raster order, identical for
/// any thread count:
/// - on one thread the rows are shaded in order and each fragment's trace goes straight to
///   the model (and, with `keep_events`, to the stream): no row's events are stored;
/// - on more, [`shade_feeding`]: the workers take the rows in order, each recording its row's
///   events, and whichever worker finds the model free feeds it the rows finished so far, in
///   order, so the sequential model overlaps the shading with no barrier between rows.
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
    let mut fe = FrameEvents {
        width: vis.width,
        height: vis.height,
        ..FrameEvents::default()
    };
    if rayon::current_num_threads() == 1 {
        let mut counters = Counters::default();
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
    let fed = Fed {
        next: 0,
        counters: Counters::default(),
        sim,
        fe,
        keep_events,
    };
    let (counters, fe, sim) = shade_feeding(inp, progs, &mut img, fed);
    (img, counters, Some((fe, sim)))
}

/// The timing model's side of [`shade_feeding`]: the next row it takes and what the rows fed
/// so far added up to.
struct Fed<'h> {
    next: usize,
    counters: Counters,
    sim: Simulator<'h>,
    fe: FrameEvents,
    keep_events: bool,
}

/// A mutex's value, also after a worker panicked holding it (the panic is re-raised when the
/// workers are joined).
fn locked<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Most rows a worker of [`shade_feeding`] finishes ahead of the model before it waits for the
/// model's lock to feed it itself: while the model is what lags, the events held at once stay
/// near this many rows (plus one per worker). A row still being shaded holds up the feed, and
/// the rows finished meanwhile wait in their slots; the memory budget counts every pixel's
/// events (`budget::BYTES_PER_EVENT_PIXEL`).
const MAX_ROWS_AHEAD: usize = 32;

/// [`shade`] on several threads with the timing model: every worker of the pool takes the
/// next row (one atomic counter, so the rows finish nearly in order), shades it recording its
/// events into a row buffer and leaves them in the row's slot; then, when no other worker is
/// feeding the model, it feeds it every finished row from the model's next one on, in raster
/// order, and recycles their buffers (a worker [`MAX_ROWS_AHEAD`] rows ahead of the model
/// waits for the model's lock instead). Rows a feeding worker did not see are fed by the next
/// worker to finish a row, and whatever remains after the last row, here. The model, the
/// stream and the counters take the rows in raster order whichever worker shaded or fed them,
/// so the result is that of one thread.
fn shade_feeding<'h>(
    inp: &ShadeInput,
    progs: &[Program],
    img: &mut Image,
    fed: Fed<'h>,
) -> (Counters, FrameEvents, Simulator<'h>) {
    let w = inp.vis.width as usize;
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
    let rows: Vec<Mutex<Option<&mut [[u16; 4]]>>> = img
        .px
        .chunks_mut(w.max(1))
        .map(|row| Mutex::new(Some(row)))
        .collect();
    let slots: Vec<Mutex<Option<(Counters, RowEvents)>>> =
        rows.iter().map(|_| Mutex::new(None)).collect();
    let spare: Mutex<Vec<RowEvents>> = Mutex::new(Vec::new());
    let (next_row, fed_rows) = (AtomicUsize::new(0), AtomicUsize::new(0));
    let model = Mutex::new(fed);
    let feed = |m: &mut Fed| {
        while let Some(slot) = slots.get(m.next) {
            let Some((c, mut ev)) = locked(slot).take() else {
                break;
            };
            m.counters.add(&c);
            m.sim.row(&ev);
            if m.keep_events {
                m.fe.append_row(&ev);
            }
            ev.clear();
            locked(&spare).push(ev);
            m.next += 1;
        }
        fed_rows.store(m.next, Ordering::Release);
    };
    // Every thread of the pool runs this loop (the caller's too when it is one of them), so
    // the frame ends once each has found no row left: a pool thread held up elsewhere delays
    // the end, not the rows.
    rayon::broadcast(|_| {
        let mut frags = frag_scratch();
        loop {
            let y = next_row.fetch_add(1, Ordering::Relaxed);
            let Some(row) = rows.get(y).and_then(|r| locked(r).take()) else {
                break;
            };
            let mut ev = locked(&spare).pop().unwrap_or_else(new_row);
            let mut c = Counters::default();
            shade_row(
                inp,
                progs,
                y,
                row,
                &mut frags,
                &mut c,
                true,
                |pi, t, frag| {
                    record_pixel(pi, t, frag, &mut ev);
                },
            );
            *locked(&slots[y]) = Some((c, ev));
            if y >= fed_rows.load(Ordering::Acquire) + MAX_ROWS_AHEAD {
                feed(&mut locked(&model));
            } else if let Ok(mut m) = model.try_lock() {
                feed(&mut m);
            }
        }
    });
    let mut m = model.into_inner().unwrap_or_else(PoisonError::into_inner);
    feed(&mut m);
    assert_eq!(m.next, slots.len(), "every row fed to the model");
    (m.counters, m.fe, m.sim)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::DrawTri;
    use crate::rng_common::Rng;
    use glam::DVec3;

    /// A seeded mesh of `n` vertices shared by `3 n` triangles, seen by a perspective camera
    /// with some vertices behind it, beside it and beyond its far plane (clipped triangles).
    fn random_geometry(r: &mut Rng, n: usize, mesa: bool) -> Geometry {
        let eye = DVec3::new(r.range(-3.0, 3.0), r.range(-3.0, 3.0), r.range(4.0, 9.0));
        let view = DMat4::look_at_rh(eye, DVec3::ZERO, DVec3::Y);
        let vp = DMat4::perspective_rh_gl(r.range(0.5, 1.5), 4.0 / 3.0, 0.5, 20.0) * view;
        let object: Vec<[f32; 3]> = (0..n)
            .map(|_| {
                [r.range(-6.0, 6.0), r.range(-6.0, 6.0), r.range(-12.0, 8.0)].map(|c| c as f32)
            })
            .collect();
        let clip = object
            .iter()
            .map(|p| (vp * DVec3::from(p.map(f64::from)).extend(1.0)).to_array())
            .collect();
        let draws: Vec<DrawTri> = (0..3 * n)
            .map(|_| DrawTri {
                v: std::array::from_fn(|_| r.below(n as u64) as u32),
                cull_back: r.below(4) == 0,
            })
            .collect();
        Geometry {
            clip,
            mesa_mvp: mesa.then(|| {
                std::array::from_fn(|row| {
                    std::array::from_fn(|col| vp.col(col)[row] as f32 * r.range(0.99, 1.01) as f32)
                })
            }),
            object,
            view_projection: vp,
            color: vec![[0.5; 3]; n],
            uv: (0..n)
                .map(|_| [r.range(-4.0, 4.0), r.range(-4.0, 4.0)])
                .collect(),
            bump: Vec::new(),
            eye: eye.to_array(),
            point_lights: Vec::new(),
            draw_plan: vec![0; draws.len()],
            draws,
            plans: Vec::new(),
        }
    }

    /// The float32 setups from vertices shaded once each ([`f32_setups`]) are those of every
    /// triangle's own vertices ([`llvmpipe_source`], [`F32Tri::new`]), on 200 seeded meshes
    /// (clipped triangles, both matrices, odd and even viewports).
    #[test]
    fn shared_vertex_setups_match_per_triangle_setups() {
        let mut r = Rng(0xF32_5E7);
        let cfg = hw_model::config::RasterConfig {
            subpixel_bits: 8,
            depth_bits: 24,
            setup_cycles: 1,
            span_cycles: 1,
        };
        let (mut tris, mut clipped) = (0, 0);
        for i in 0..200 {
            let geo = random_geometry(&mut r, 30 + i % 50, i % 3 == 0);
            let (w, h) = (64 + r.below(512) as u32, 48 + r.below(512) as u32);
            let setup = crate::raster::setup(&geo.clip, &geo.draws, w, h, &cfg);
            let got = f32_setups(&setup, &geo);
            assert_eq!(got.len(), setup.tris.len());
            for (t, g) in setup.tris.iter().zip(&got) {
                let (src, half) = llvmpipe_source(t, &geo, w, h);
                assert_eq!(g.fan, F32Tri::new(src, half).fan, "mesh {i}");
                clipped += usize::from(g.fan.len() != 1);
            }
            tris += got.len();
        }
        assert!(tris > 10_000 && clipped > 500, "{tris} {clipped}");
    }
}
