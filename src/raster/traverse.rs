//! Scanline traversal (Pineda edge functions, solved per row for the exact span) into a
//! visibility buffer, with the top-left fill rule and a strictly-less depth test; parallel over
//! horizontal bands. Conventions are in the parent module header.

use super::setup::{ScreenTri, Setup};
use crate::prefetch::prefetch;
use rayon::prelude::*;

/// No triangle covers this pixel.
pub const NO_TRI: u32 = u32::MAX;
/// Fewest and most rows per parallel band ([`band_rows`]).
pub const BAND_ROWS: (u32, u32) = (16, 64);

/// Rows per parallel band of an image `height` rows high on `threads` threads: about eight
/// bands per thread, within [`BAND_ROWS`]. A triangle is set up again in each band it
/// reaches, so fewer bands cost less where the threads do not need them: W2 (65,536
/// triangles, 1024 rows) rasterized in 11.5-12.5 ms with 64 rows against 12.5-13.3 ms with
/// 16 on one thread, and 5.7-6.4 against 6.3-7.2 ms on two. The output does not depend on
/// the band size: each pixel is in one band, which walks its triangles in submission order.
#[must_use]
pub fn band_rows(height: u32, threads: usize) -> u32 {
    let bands = u32::try_from(8 * threads.max(1)).unwrap_or(u32::MAX);
    (height / bands).clamp(BAND_ROWS.0, BAND_ROWS.1)
}

/// Which coverage and depth model traversal uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coverage {
    /// Snapped positions, exact integer edges and depth.
    Fixed,
    /// Unsnapped `xy_f`, f64 edges and depth (the float twin).
    Float,
}

/// Per-pixel index of the visible triangle.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct VisBuffer {
    pub width: u32,
    pub height: u32,
    /// Row-major, top row first: index into `setup.tris`, or [`NO_TRI`].
    pub tri: Vec<u32>,
}

/// Traversal counters.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct RasterStats {
    /// Non-empty spans (one row of one triangle).
    pub spans: u64,
    /// Covered samples before the depth test.
    pub fragments: u64,
    /// Fragments rejected by the depth test.
    pub depth_fails: u64,
    /// Pixels with a triangle at the end.
    pub visible: u64,
}

impl RasterStats {
    fn add(mut self, o: RasterStats) -> RasterStats {
        self.spans += o.spans;
        self.fragments += o.fragments;
        self.depth_fails += o.depth_fails;
        self.visible += o.visible;
        self
    }
}

/// `floor(a / b)` for `b > 0`.
#[cfg(test)]
fn floor_div(a: i64, b: i64) -> i64 {
    a.div_euclid(b)
}

/// `ceil(a / b)` for `b > 0`.
#[cfg(test)]
fn ceil_div(a: i64, b: i64) -> i64 {
    -((-a).div_euclid(b))
}

/// One fixed edge `E(px) = c(py) + step * px` with `c(py) = a * (Y - yj) - b * (h - xj)`.
#[derive(Clone, Copy)]
struct FixedEdge {
    a: i64,
    b: i64,
    xj: i64,
    yj: i64,
    /// Smallest passing value: 0 on top-left edges, 1 otherwise.
    t: i64,
    step: i64,
}

/// A triangle prepared for fixed traversal.
struct FixedTri {
    e: [FixedEdge; 3],
    s: u32,
    h: i64,
    x0: i64,
    x1: i64,
    /// The vertices' depths (below 2^30).
    z: [i64; 3],
    /// Denominator of the rounded depth `(2N + area2) / (2 area2)`.
    den: i64,
    /// Per-pixel quotient/remainder step of the depth numerator (the quotient is only used,
    /// as `i64`, between two covered pixels, where it is bounded).
    dq: i128,
    dr: i64,
}

impl FixedTri {
    #[inline]
    fn new(t: &ScreenTri, s: u32, width: u32) -> Self {
        let h = 1i64 << (s - 1);
        let e = [0usize, 1, 2].map(|i| {
            let [xj, yj] = t.xy[(i + 1) % 3];
            let [xk, yk] = t.xy[(i + 2) % 3];
            let a = xk - xj;
            let b = yk - yj;
            let top_left = b < 0 || (b == 0 && a > 0);
            FixedEdge {
                a,
                b,
                xj,
                yj,
                t: i64::from(!top_left),
                step: -(b << s),
            }
        });
        let z = t.z.map(i64::from);
        let den = 2 * t.area2;
        let (dq, dr) = match depth_numerator([e[0].step, e[1].step, e[2].step], z)
            .and_then(|n| n.checked_mul(2))
        {
            Some(dm) => (i128::from(dm.div_euclid(den)), dm.rem_euclid(den)),
            None => {
                let dm = 2
                    * (0..3)
                        .map(|i| i128::from(e[i].step) * i128::from(z[i]))
                        .sum::<i128>();
                let den128 = i128::from(den);
                (dm.div_euclid(den128), dm.rem_euclid(den128) as i64)
            }
        };
        Self {
            e,
            s,
            h,
            x0: i64::from(t.bbox[0]),
            x1: i64::from(t.bbox[2].min(width)),
            z,
            den,
            dq,
            dr,
        }
    }

    /// The walk of rows `py0..py1` (`py0 < py1`) starting at `py0`: each edge's value at the
    /// centre of pixel 0 and the floor of `(value - t) / |step|` as quotient and remainder
    /// (the edge's span bound), with their per-row increments when there is a second row.
    #[inline]
    fn walk(&self, py0: i64, py1: i64) -> RowWalk {
        let y = (py0 << self.s) + self.h;
        let mut w = RowWalk {
            c: [0; 3],
            q: [0; 3],
            r: [0; 3],
            dc: [0; 3],
            dq: [0; 3],
            dr: [0; 3],
        };
        for (i, e) in self.e.iter().enumerate() {
            let c = e.a * (y - e.yj) - e.b * (self.h - e.xj);
            let d = e.step.abs().max(1);
            w.c[i] = c;
            (w.q[i], w.r[i]) = floor_qr(c - e.t, d);
            if py1 - py0 >= 2 {
                w.dc[i] = e.a << self.s;
                (w.dq[i], w.dr[i]) = floor_qr(w.dc[i], d);
            }
        }
        w
    }

    /// Exact span [xl, xr) of the walk's current row and the edge values at `xl`: equal to
    /// [`Self::span`] of that row.
    #[inline(always)]
    fn walk_span(&self, w: &RowWalk) -> (i64, i64, [i64; 3]) {
        let mut xl = self.x0;
        let mut xr = self.x1;
        for (e, &q) in self.e.iter().zip(&w.q) {
            if e.step == 0 {
                if q < 0 {
                    return (xl, xl, w.c);
                }
            } else if e.step > 0 {
                xl = xl.max(-q);
            } else {
                xr = xr.min(q + 1);
            }
        }
        let ev = [0, 1, 2].map(|i| w.c[i] + self.e[i].step * xl);
        (xl, xr, ev)
    }

    /// Advances the walk one row down (only within the rows [`Self::walk`] was given).
    #[inline(always)]
    fn walk_next(&self, w: &mut RowWalk) {
        for (i, e) in self.e.iter().enumerate() {
            let d = e.step.abs().max(1);
            w.c[i] += w.dc[i];
            w.q[i] += w.dq[i];
            w.r[i] += w.dr[i];
            let carry = w.r[i] >= d;
            w.r[i] -= if carry { d } else { 0 };
            w.q[i] += i64::from(carry);
        }
    }

    /// Exact span [xl, xr) of row `py` and the edge values at `xl`.
    #[cfg(test)]
    fn span(&self, py: i64) -> (i64, i64, [i64; 3]) {
        let y = (py << self.s) + self.h;
        let mut xl = self.x0;
        let mut xr = self.x1;
        let mut c = [0i64; 3];
        for (e, ci) in self.e.iter().zip(c.iter_mut()) {
            *ci = e.a * (y - e.yj) - e.b * (self.h - e.xj);
            if e.step == 0 {
                if *ci < e.t {
                    return (xl, xl, c);
                }
            } else if e.step > 0 {
                xl = xl.max(ceil_div(e.t - *ci, e.step));
            } else {
                xr = xr.min(floor_div(*ci - e.t, -e.step) + 1);
            }
        }
        let ev = [0, 1, 2].map(|i| c[i] + self.e[i].step * xl);
        (xl, xr, ev)
    }

    /// Depth walker at the span start: (quotient, remainder, dq, dr) with `dq`, `dr` zero for
    /// one-pixel spans (the step is only bounded between two covered pixels).
    #[inline]
    fn depth_start(&self, ev: &[i64; 3], len: i64) -> (i64, i64, i64, i64) {
        let (q, r) = match depth_numerator(*ev, self.z)
            .and_then(|n| n.checked_mul(2)?.checked_add(self.den / 2))
        {
            Some(m) => (m.div_euclid(self.den), m.rem_euclid(self.den)),
            None => {
                let n: i128 = (0..3)
                    .map(|i| i128::from(ev[i]) * i128::from(self.z[i]))
                    .sum();
                let den = i128::from(self.den);
                let m = 2 * n + den / 2;
                (m.div_euclid(den) as i64, m.rem_euclid(den) as i64)
            }
        };
        if len >= 2 {
            (q, r, self.dq as i64, self.dr)
        } else {
            (q, r, 0, 0)
        }
    }
}

/// The state of [`FixedTri::walk`]: per edge the value at the centre of pixel 0 of the
/// current row `c`, `floor((c - t) / d)` (`d = |step|`, 1 for a horizontal edge) as `q` and
/// `r`, and their per-row steps (`c` grows by `a 2^s` per row).
struct RowWalk {
    c: [i64; 3],
    q: [i64; 3],
    r: [i64; 3],
    dc: [i64; 3],
    dq: [i64; 3],
    dr: [i64; 3],
}

/// `(floor(m / d), m mod d)` for `d > 0` (no division for `d == 1`).
#[inline(always)]
fn floor_qr(m: i64, d: i64) -> (i64, i64) {
    if d == 1 {
        (m, 0)
    } else {
        (m.div_euclid(d), m.rem_euclid(d))
    }
}

/// `sum(e_i z_i)` in `i64`, `None` if a product or sum would overflow (the caller then
/// takes the exact `i128` sum).
#[inline(always)]
fn depth_numerator(e: [i64; 3], z: [i64; 3]) -> Option<i64> {
    e[0].checked_mul(z[0])?
        .checked_add(e[1].checked_mul(z[1])?)?
        .checked_add(e[2].checked_mul(z[2])?)
}

/// One float edge in canonical order: `E = sign * (dx * (y - p1) - dy * (x - p0))`.
#[derive(Clone, Copy)]
struct FloatEdge {
    p: [f64; 2],
    dx: f64,
    dy: f64,
    neg: bool,
    top_left: bool,
    /// -1: E decreases with x, 0: horizontal, 1: increases.
    dir: i8,
}

impl FloatEdge {
    #[inline]
    fn eval(&self, x: f64, y: f64) -> f64 {
        let e = self.dx * (y - self.p[1]) - self.dy * (x - self.p[0]);
        if self.neg {
            -e
        } else {
            e
        }
    }

    #[inline]
    fn passes(&self, px: i64, y: f64) -> bool {
        let e = self.eval(px as f64 + 0.5, y);
        e > 0.0 || (e == 0.0 && self.top_left)
    }
}

/// A triangle prepared for float traversal.
struct FloatTri {
    e: [FloatEdge; 3],
    x0: i64,
    x1: i64,
    z: [f64; 3],
    area2: f64,
}

impl FloatTri {
    /// Prepares `t`; if the unsnapped triangle has the opposite orientation to the snapped one
    /// (`area2_f < 0`, slivers only) every edge is negated so that it is positive inside.
    fn new(t: &ScreenTri, width: u32) -> Self {
        let flip = t.area2_f < 0.0;
        let e = [0usize, 1, 2].map(|i| {
            let j = t.xy_f[(i + 1) % 3];
            let k = t.xy_f[(i + 2) % 3];
            let swap = (k[0], k[1]) < (j[0], j[1]);
            let (p, q) = if swap { (k, j) } else { (j, k) };
            let (a, b) = if flip {
                (j[0] - k[0], j[1] - k[1])
            } else {
                (k[0] - j[0], k[1] - j[1])
            };
            FloatEdge {
                p,
                dx: q[0] - p[0],
                dy: q[1] - p[1],
                neg: swap != flip,
                top_left: b < 0.0 || (b == 0.0 && a > 0.0),
                dir: if b < 0.0 {
                    1
                } else if b > 0.0 {
                    -1
                } else {
                    0
                },
            }
        });
        Self {
            e,
            x0: i64::from(t.bbox[0]),
            x1: i64::from(t.bbox[2].min(width)),
            z: t.z_f,
            area2: t.area2_f.abs(),
        }
    }

    /// Span [xl, xr) of row `py`: a division guess per edge, refined by evaluating the edge
    /// (monotone in x under round-to-nearest), so it equals the per-pixel test exactly.
    fn span(&self, py: i64) -> (i64, i64) {
        let y = py as f64 + 0.5;
        let mut xl = self.x0;
        let mut xr = self.x1;
        for e in &self.e {
            if xl >= xr {
                break;
            }
            if e.dir == 0 {
                if !e.passes(xl, y) {
                    return (xl, xl);
                }
                continue;
            }
            let x = e.p[0] + e.dx * (y - e.p[1]) / e.dy - 0.5;
            if e.dir > 0 {
                xl = first_pass(xl, xr, x.ceil() as i64, |px| e.passes(px, y));
            } else {
                xr = last_pass(xl, xr, x.floor() as i64, |px| e.passes(px, y));
            }
        }
        (xl, xr)
    }

    #[inline]
    fn depth(&self, px: i64, y: f64) -> f64 {
        let x = px as f64 + 0.5;
        let n: f64 = (0..3).map(|i| self.e[i].eval(x, y) * self.z[i]).sum();
        n / self.area2
    }
}

/// Smallest px in [lo, hi) with `f(px)` (f monotone false..true), or `hi`; starts at `g`.
fn first_pass(lo: i64, hi: i64, g: i64, f: impl Fn(i64) -> bool) -> i64 {
    if lo >= hi {
        return hi;
    }
    let mut g = g.clamp(lo, hi - 1);
    if f(g) {
        while g > lo && f(g - 1) {
            g -= 1;
        }
        g
    } else {
        loop {
            g += 1;
            if g >= hi || f(g) {
                return g;
            }
        }
    }
}

/// One past the largest px in [lo, hi) with `f(px)` (f monotone true..false), or `lo`.
fn last_pass(lo: i64, hi: i64, g: i64, f: impl Fn(i64) -> bool) -> i64 {
    if lo >= hi {
        return lo;
    }
    let mut g = g.clamp(lo, hi - 1);
    if f(g) {
        while g + 1 < hi && f(g + 1) {
            g += 1;
        }
        g + 1
    } else {
        loop {
            if g <= lo {
                return lo;
            }
            g -= 1;
            if f(g) {
                return g + 1;
            }
        }
    }
}

/// Triangle indices per band, in submission order: binned in parallel by chunks of
/// triangles, each chunk's lists kept apart (`lists[chunk][band]`); a band walks the chunks
/// in order, so no list is concatenated.
struct Bins {
    lists: Vec<Vec<Vec<u32>>>,
}

/// The triangles of one band: `lists[chunk][band]` over the chunks, in submission order.
#[derive(Clone, Copy)]
struct BandIds<'a> {
    bins: &'a Bins,
    band: usize,
}

/// Triangles per parallel binning task.
const BIN_CHUNK: usize = 16384;

/// The triangles of `setup` binned into `bands` bands of `per_band` rows.
fn bin(setup: &Setup, per_band: u32, bands: usize) -> Bins {
    let band_range = |t: &ScreenTri| -> Option<(usize, usize)> {
        let y0 = t.bbox[1];
        let y1 = t.bbox[3].min(setup.height);
        if y0 >= y1 || t.bbox[0] >= t.bbox[2].min(setup.width) {
            return None;
        }
        Some(((y0 / per_band) as usize, ((y1 - 1) / per_band) as usize))
    };
    let lists = setup
        .tris
        .par_chunks(BIN_CHUNK)
        .enumerate()
        .map(|(c, chunk)| {
            let mut lists = vec![Vec::new(); bands];
            for (k, t) in chunk.iter().enumerate() {
                if let Some((b0, b1)) = band_range(t) {
                    let id = (c * BIN_CHUNK + k) as u32;
                    for list in &mut lists[b0..=b1] {
                        list.push(id);
                    }
                }
            }
            lists
        })
        .collect();
    Bins { lists }
}

/// What a band does with its spans.
enum Sink<'a> {
    Vis {
        tri: &'a mut [u32],
        depth_test: bool,
    },
    Count(&'a mut [u32]),
}

/// Traverses the triangles of one band (rows [y0, y1)) into `sink` (rows of this band only).
fn band(
    setup: &Setup,
    ids: BandIds,
    y0: u32,
    y1: u32,
    coverage: Coverage,
    sink: Sink,
) -> RasterStats {
    let w = setup.width as usize;
    let mut st = RasterStats::default();
    let s = setup.subpixel_bits.clamp(1, 12);
    match sink {
        Sink::Count(cnt) => {
            for_spans(setup, ids, y0, y1, coverage, s, |_, py, xl, xr, _| {
                st.spans += 1;
                st.fragments += (xr - xl) as u64;
                let row = (py as usize - y0 as usize) * w;
                for c in &mut cnt[row + xl as usize..row + xr as usize] {
                    *c += 1;
                }
            });
        }
        Sink::Vis { tri, depth_test } => {
            let n = ((y1 - y0) as usize) * w;
            match coverage {
                Coverage::Fixed => {
                    let zmax = (1u32 << setup.depth_bits.clamp(8, super::MAX_DEPTH_BITS)) - 1;
                    let mut depth = vec![zmax; if depth_test { n } else { 0 }];
                    for_spans(setup, ids, y0, y1, coverage, s, |id, py, xl, xr, span| {
                        st.spans += 1;
                        st.fragments += (xr - xl) as u64;
                        let row = (py as usize - y0 as usize) * w;
                        let Prep::Fixed(ft, ev) = span else { return };
                        if !depth_test {
                            tri[row + xl as usize..row + xr as usize].fill(id);
                            return;
                        }
                        let (mut q, mut r, dq, dr) = ft.depth_start(ev, xr - xl);
                        let (d, t) = (
                            &mut depth[row + xl as usize..row + xr as usize],
                            &mut tri[row + xl as usize..row + xr as usize],
                        );
                        if d.len() >= 2 * DEPTH_LANES {
                            let walk = (q, r, dq, dr);
                            if let Some(f) = depth_test_long(walk, ft.den, zmax, id, d, t) {
                                st.depth_fails += f;
                                return;
                            }
                        }
                        let mut fails = 0;
                        for (dz, tz) in d.iter_mut().zip(t.iter_mut()) {
                            let zq = q.clamp(0, i64::from(zmax)) as u32;
                            let pass = zq < *dz;
                            *dz = if pass { zq } else { *dz };
                            *tz = if pass { id } else { *tz };
                            fails += u64::from(!pass);
                            r += dr;
                            let carry = r >= ft.den;
                            r -= if carry { ft.den } else { 0 };
                            q += dq + i64::from(carry);
                        }
                        st.depth_fails += fails;
                    });
                }
                Coverage::Float => {
                    let mut depth = vec![1.0f64; if depth_test { n } else { 0 }];
                    for_spans(setup, ids, y0, y1, coverage, s, |id, py, xl, xr, span| {
                        st.spans += 1;
                        st.fragments += (xr - xl) as u64;
                        let row = (py as usize - y0 as usize) * w;
                        if !depth_test {
                            tri[row + xl as usize..row + xr as usize].fill(id);
                            return;
                        }
                        let Prep::Float(ft) = span else { return };
                        let y = py as f64 + 0.5;
                        for px in xl..xr {
                            let i = row + px as usize;
                            let z = ft.depth(px, y);
                            if z < depth[i] {
                                depth[i] = z;
                                tri[i] = id;
                            } else {
                                st.depth_fails += 1;
                            }
                        }
                    });
                }
            }
            st.visible = tri.iter().filter(|&&t| t != NO_TRI).count() as u64;
        }
    }
    st
}

/// The strictly-less depth test of a span of at least [`DEPTH_LANES`] x 2 pixels (`d` their
/// stored depths, `t` their triangles) from the depth walker `(q, r, dq, dr)` of
/// [`FixedTri::depth_start`] (quotient and remainder over `den`, stepped per pixel), the
/// depths clamped to `0..=zmax`; a passing pixel takes `id`. Returns the pixels that fail, or
/// `None` where [`DepthLanes`] do not serve the span (the band's loop then walks it pixel by
/// pixel). [`DEPTH_LANES`] pixels at once, bit-identical to that walk
/// (`depth_lanes_match_the_pixel_walk`). Out of line, so that the loop of short spans (a
/// mesh's) compiles as before.
#[inline(never)]
fn depth_test_long(
    walk: (i64, i64, i64, i64),
    den: i64,
    zmax: u32,
    id: u32,
    d: &mut [u32],
    t: &mut [u32],
) -> Option<u64> {
    let lanes = DepthLanes::new(walk, den)?;
    #[cfg(target_arch = "x86_64")]
    if hw_model::vector_isa() == hw_model::VectorIsa::Avx512 {
        // SAFETY: the CPU has AVX-512 F, DQ, CD and VL.
        return Some(unsafe { depth_lanes_avx512(lanes, zmax, id, d, t) });
    }
    Some(depth_lanes_vector(lanes, zmax, id, d, t))
}

hw_model::isa_kernel! {
    /// [`depth_lanes`] built for the vector instruction set in force (AVX-512 takes
    /// [`depth_lanes_avx512`] instead).
    fn depth_lanes_vector[](
        w: DepthLanes,
        zmax: u32,
        id: u32,
        d: &mut [u32],
        t: &mut [u32],
    ) -> u64 = depth_lanes::<>;
}

/// One pixel's strictly-less test of the depth quotient `q` clamped to `0..=zmax` against
/// the stored depth `dz`: a passing pixel stores it and takes `id`. Returns whether it passed.
#[inline(always)]
fn depth_pass(q: i64, zmax: u32, id: u32, dz: &mut u32, tz: &mut u32) -> bool {
    let zq = q.clamp(0, i64::from(zmax)) as u32;
    let pass = zq < *dz;
    // The outcomes are not predictable: selects, not branches.
    *dz = std::hint::select_unpredictable(pass, zq, *dz);
    *tz = std::hint::select_unpredictable(pass, id, *tz);
    pass
}

/// The depth walker's quotient and remainder over `den` advanced by `(dq, dr)` (`dr < den`).
#[inline(always)]
fn depth_step((q, r): (i64, i64), (dq, dr): (i64, i64), den: i64) -> (i64, i64) {
    let r = r + dr;
    let carry = r >= den;
    (q + dq + i64::from(carry), r - if carry { den } else { 0 })
}

/// Lanes of [`depth_lanes`]: pixels walked at once.
const DEPTH_LANES: usize = 8;

/// The depth walker of a span as [`DEPTH_LANES`] lanes: lane `l` at pixel `l` (its quotient
/// `q` and remainder `r` over `den`), and the step of `DEPTH_LANES` pixels, `DEPTH_LANES`
/// times the per-pixel step `(dq, dr)` as a quotient and a remainder below `den`.
#[derive(Clone, Copy)]
struct DepthLanes {
    q: [i64; DEPTH_LANES],
    r: [i64; DEPTH_LANES],
    step: (i64, i64),
    den: i64,
}

impl DepthLanes {
    /// `None` when the lanes' step would leave `i64` (then the span is walked pixel by
    /// pixel). The quotients are only bounded between a span's covered pixels, so the lanes
    /// serve a span of at least `DEPTH_LANES` + 1 pixels (its pixel `DEPTH_LANES` is covered).
    #[inline(always)]
    fn new((q, r, dq, dr): (i64, i64, i64, i64), den: i64) -> Option<Self> {
        let lanes = DEPTH_LANES as i64;
        let carries = (dr.checked_mul(lanes)?).div_euclid(den);
        let step = (
            dq.checked_mul(lanes)?.checked_add(carries)?,
            dr * lanes - carries * den,
        );
        let mut walker = Self {
            q: [q; DEPTH_LANES],
            r: [r; DEPTH_LANES],
            step,
            den,
        };
        for l in 1..DEPTH_LANES {
            (walker.q[l], walker.r[l]) =
                depth_step((walker.q[l - 1], walker.r[l - 1]), (dq, dr), den);
        }
        Some(walker)
    }
}

/// [`depth_test_long`] on [`DepthLanes`]: each chunk of [`DEPTH_LANES`] pixels tested and the
/// lanes stepped at once, the last pixels by the lanes where they stand.
#[inline(always)]
fn depth_lanes(mut w: DepthLanes, zmax: u32, id: u32, d: &mut [u32], t: &mut [u32]) -> u64 {
    let mut fails = 0;
    let (mut dc, mut tc) = (
        d.chunks_exact_mut(DEPTH_LANES),
        t.chunks_exact_mut(DEPTH_LANES),
    );
    for (d, t) in (&mut dc).zip(&mut tc) {
        for l in 0..DEPTH_LANES {
            fails += u64::from(!depth_pass(w.q[l], zmax, id, &mut d[l], &mut t[l]));
            (w.q[l], w.r[l]) = depth_step((w.q[l], w.r[l]), w.step, w.den);
        }
    }
    let (d, t) = (dc.into_remainder(), tc.into_remainder());
    for ((dz, tz), &q) in d.iter_mut().zip(t.iter_mut()).zip(&w.q) {
        fails += u64::from(!depth_pass(q, zmax, id, dz, tz));
    }
    fails
}

/// [`depth_lanes`] in AVX-512 registers: the lanes' quotients and remainders in two vectors
/// of eight `i64`, the test a compare mask that the stores of the depths and triangles take
/// (the compiler's own vectors of [`depth_lanes`] moved that mask through general registers,
/// W1: 3.2% of the frame's samples).
///
/// # Safety
/// The CPU must have AVX-512 F, DQ, CD and VL ([`hw_model::VectorIsa::Avx512`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512dq,avx512cd,avx512vl")]
unsafe fn depth_lanes_avx512(
    w: DepthLanes,
    zmax: u32,
    id: u32,
    d: &mut [u32],
    t: &mut [u32],
) -> u64 {
    use std::arch::x86_64::{
        _mm256_cmplt_epu32_mask, _mm256_loadu_si256, _mm256_mask_storeu_epi32, _mm256_set1_epi32,
        _mm512_add_epi64, _mm512_cmpge_epi64_mask, _mm512_cvtepi64_epi32, _mm512_loadu_si512,
        _mm512_mask_sub_epi64, _mm512_max_epi64, _mm512_min_epi64, _mm512_set1_epi64,
        _mm512_setzero_si512, _mm512_storeu_si512,
    };
    const _: () = assert!(DEPTH_LANES == 8);
    let n = d.len().min(t.len());
    let whole = n - n % DEPTH_LANES;
    let mut q = _mm512_loadu_si512(w.q.as_ptr().cast());
    let mut r = _mm512_loadu_si512(w.r.as_ptr().cast());
    let (step_q, step_r) = (_mm512_set1_epi64(w.step.0), _mm512_set1_epi64(w.step.1));
    let den = _mm512_set1_epi64(w.den);
    let (zero, top) = (_mm512_setzero_si512(), _mm512_set1_epi64(i64::from(zmax)));
    // A carry adds 1 to a quotient: subtracting the mask's -1.
    let minus_one = _mm512_set1_epi64(-1);
    let ids = _mm256_set1_epi32(id as i32);
    let mut passed = 0u64;
    for k in (0..whole).step_by(DEPTH_LANES) {
        // SAFETY: `k + DEPTH_LANES <= n`, within both slices.
        let (dp, tp) = (d.as_mut_ptr().add(k), t.as_mut_ptr().add(k));
        let zq = _mm512_cvtepi64_epi32(_mm512_min_epi64(_mm512_max_epi64(q, zero), top));
        let pass = _mm256_cmplt_epu32_mask(zq, _mm256_loadu_si256(dp.cast()));
        _mm256_mask_storeu_epi32(dp.cast(), pass, zq);
        _mm256_mask_storeu_epi32(tp.cast(), pass, ids);
        passed += u64::from(pass.count_ones());
        r = _mm512_add_epi64(r, step_r);
        let carry = _mm512_cmpge_epi64_mask(r, den);
        r = _mm512_mask_sub_epi64(r, carry, r, den);
        let stepped = _mm512_add_epi64(q, step_q);
        q = _mm512_mask_sub_epi64(stepped, carry, stepped, minus_one);
    }
    // The last pixels take the lanes' quotients where they stand.
    let mut last = [0i64; DEPTH_LANES];
    _mm512_storeu_si512(last.as_mut_ptr().cast(), q);
    let mut fails = whole as u64 - passed;
    for ((dz, tz), &q) in d[whole..n].iter_mut().zip(&mut t[whole..n]).zip(&last) {
        fails += u64::from(!depth_pass(q, zmax, id, dz, tz));
    }
    fails
}

/// A prepared triangle handed to a span callback (fixed: with the edge values at `xl`).
enum Prep<'a> {
    Fixed(&'a FixedTri, &'a [i64; 3]),
    Float(&'a FloatTri),
}

/// Calls `f(id, py, xl, xr, prep)` for every non-empty span of the band's triangles, in
/// submission order.
fn for_spans(
    setup: &Setup,
    ids: BandIds,
    y0: u32,
    y1: u32,
    coverage: Coverage,
    s: u32,
    mut f: impl FnMut(u32, i64, i64, i64, Prep<'_>),
) {
    let mut ids = ids.bins.lists.iter().flat_map(|c| &c[ids.band]).peekable();
    while let Some(&id) = ids.next() {
        // The next triangle's data is read while this one is walked.
        if let Some(&&next) = ids.peek() {
            prefetch(&setup.tris, next as usize);
        }
        let t = &setup.tris[id as usize];
        let ya = t.bbox[1].max(y0);
        let yb = t.bbox[3].min(y1);
        match coverage {
            Coverage::Fixed => {
                if ya >= yb {
                    continue;
                }
                let ft = FixedTri::new(t, s, setup.width);
                let (ya, yb) = (i64::from(ya), i64::from(yb));
                let mut walk = ft.walk(ya, yb);
                for py in ya..yb {
                    if py > ya {
                        ft.walk_next(&mut walk);
                    }
                    let (xl, xr, ev) = ft.walk_span(&walk);
                    if xl < xr {
                        f(id, py, xl, xr, Prep::Fixed(&ft, &ev));
                    }
                }
            }
            Coverage::Float => {
                // Zero or NaN: nothing to draw in float.
                if t.area2_f == 0.0 || t.area2_f.is_nan() {
                    continue;
                }
                let ft = FloatTri::new(t, setup.width);
                for py in ya..yb {
                    let py = i64::from(py);
                    let (xl, xr) = ft.span(py);
                    if xl < xr {
                        f(id, py, xl, xr, Prep::Float(&ft));
                    }
                }
            }
        }
    }
}

/// Runs `band` over all bands in parallel; `out` has one entry per pixel.
fn run(setup: &Setup, coverage: Coverage, out: &mut [u32], vis: Option<bool>) -> RasterStats {
    let w = setup.width as usize;
    let h = setup.height;
    if w == 0 || h == 0 {
        return RasterStats::default();
    }
    let per_band = band_rows(h, rayon::current_num_threads());
    let bands = h.div_ceil(per_band) as usize;
    let bins = bin(setup, per_band, bands);
    out.par_chunks_mut(per_band as usize * w)
        .enumerate()
        .map(|(b, rows)| {
            let y0 = b as u32 * per_band;
            let y1 = (y0 + per_band).min(h);
            let ids = BandIds {
                bins: &bins,
                band: b,
            };
            let sink = match vis {
                Some(depth_test) => Sink::Vis {
                    tri: rows,
                    depth_test,
                },
                None => Sink::Count(rows),
            };
            band(setup, ids, y0, y1, coverage, sink)
        })
        .reduce(RasterStats::default, RasterStats::add)
}

/// Rasterizes `setup.tris` in submission order into a visibility buffer. With `depth_test`,
/// a fragment is kept if its depth is strictly less than the stored one (cleared to the far
/// value); without, later triangles overwrite earlier ones.
#[must_use]
pub fn rasterize(setup: &Setup, coverage: Coverage, depth_test: bool) -> (VisBuffer, RasterStats) {
    let n = setup.width as usize * setup.height as usize;
    let mut tri = vec![NO_TRI; n];
    let stats = run(setup, coverage, &mut tri, Some(depth_test));
    (
        VisBuffer {
            width: setup.width,
            height: setup.height,
            tri,
        },
        stats,
    )
}

/// How many triangles cover each pixel (no depth test), row-major.
#[must_use]
pub fn coverage_count(setup: &Setup, coverage: Coverage) -> Vec<u32> {
    let n = setup.width as usize * setup.height as usize;
    let mut cnt = vec![0u32; n];
    let _ = run(setup, coverage, &mut cnt, None);
    cnt
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::VertexSource;
    use crate::rng_common::Rng;

    /// A test triangle prepared for fixed traversal ([`prepared`]).
    struct Prepared {
        ft: FixedTri,
        /// Its vertices oriented as setup orients them (`area2 > 0`).
        xy: [[i64; 2]; 3],
        /// The first and last pixel rows its positions reach.
        rows: (i64, i64),
    }

    /// The triangle of sub-pixel positions `xy` (either winding) and depths `z` prepared for
    /// fixed traversal with `s` sub-pixel bits on an image `width` pixels wide; `None` for a
    /// degenerate one.
    fn prepared(mut xy: [[i64; 2]; 3], z: [u32; 3], s: u32, width: u32) -> Option<Prepared> {
        let cross = (xy[1][0] - xy[0][0]) * (xy[2][1] - xy[0][1])
            - (xy[1][1] - xy[0][1]) * (xy[2][0] - xy[0][0]);
        if cross == 0 {
            return None;
        }
        if cross < 0 {
            xy.swap(1, 2);
        }
        let lo = |c: usize| xy.iter().map(|p| p[c]).min().unwrap_or(0) >> s;
        let hi = |c: usize| xy.iter().map(|p| p[c]).max().unwrap_or(0) >> s;
        let clampw = |v: i64| v.clamp(0, i64::from(width)) as u32;
        let t = ScreenTri {
            xy,
            xy_f: [[0.0; 2]; 3],
            z,
            z_f: [0.0; 3],
            inv_w: [1.0; 3],
            src: 0,
            source: VertexSource::Unclipped { swapped: false },
            area2: cross.abs(),
            area2_f: 1.0,
            bbox: [clampw(lo(0) - 1), 0, clampw(hi(0) + 2), 0],
        };
        Some(Prepared {
            ft: FixedTri::new(&t, s, width),
            xy,
            rows: (lo(1), hi(1)),
        })
    }

    /// The depth test of spans of at least 16 pixels through [`depth_test_long`] (and its
    /// lanes built without AVX-512), and of shorter ones through the walk's steps
    /// ([`depth_pass`], [`depth_step`]), against each pixel's exact rounded depth
    /// `floor((2 sum(e_i z_i) + den / 2) / den)` in `i128`, on 20k seeded triangles (depths
    /// below 2^30, every depth width, sub-pixel widths 1 to 12): the same stored depths,
    /// triangles and failures over random stored depths. (The band's own loop of short spans
    /// is checked against a brute-force model in `tests/pipeline/raster_rules.rs`.)
    #[test]
    fn depth_lanes_match_the_pixel_walk() {
        let mut rng = Rng(0xdef7_1a2e);
        let (mut lane_spans, mut pixels) = (0u64, 0u64);
        for i in 0..20_000u32 {
            let s = 1 + i % 12;
            let scale = 1i64 << s;
            let reach = [8i64, 64, 400][(i % 3) as usize] * scale;
            let c = [rng.int_in(0, 600) * scale, rng.int_in(0, 600) * scale];
            let mut xy = [[0i64; 2]; 3];
            for p in &mut xy {
                *p = [
                    c[0] + rng.int_in(-reach, reach),
                    c[1] + rng.int_in(-reach, reach),
                ];
            }
            let db = 8 + i % 23;
            let zmax = (1u32 << db) - 1;
            let z = [0; 3].map(|_: u32| rng.int_in(0, i64::from(zmax)) as u32);
            let Some(Prepared {
                ft,
                xy,
                rows: (lo, hi),
            }) = prepared(xy, z, s, 1024)
            else {
                continue;
            };
            let (py0, py1) = (lo, hi + 1);
            let mut walk = ft.walk(py0, py1);
            for py in py0..py1 {
                if py > py0 {
                    ft.walk_next(&mut walk);
                }
                let (xl, xr, ev) = ft.walk_span(&walk);
                if xl >= xr {
                    continue;
                }
                let n = (xr - xl) as usize;
                lane_spans += u64::from(n >= 2 * DEPTH_LANES);
                pixels += n as u64;
                let stored: Vec<u32> = (0..n)
                    .map(|_| rng.int_in(0, i64::from(zmax)) as u32)
                    .collect();
                let (mut d, mut tris) = (stored.clone(), vec![7u32; n]);
                let walk = ft.depth_start(&ev, xr - xl);
                let fails = if n >= 2 * DEPTH_LANES {
                    let f = depth_test_long(walk, ft.den, zmax, 3, &mut d, &mut tris);
                    f.expect("lanes for a span's step")
                } else {
                    let (mut q, mut r) = (walk.0, walk.1);
                    let mut fails = 0;
                    for (dz, tz) in d.iter_mut().zip(tris.iter_mut()) {
                        fails += u64::from(!depth_pass(q, zmax, 3, dz, tz));
                        (q, r) = depth_step((q, r), (walk.2, walk.3), ft.den);
                    }
                    fails
                };
                let mut want_fails = 0;
                for j in 0..n {
                    let e = [0, 1, 2].map(|k| i128::from(ev[k] + ft.e[k].step * j as i64));
                    let num: i128 = (0..3).map(|k| e[k] * i128::from(z[k])).sum();
                    let den = i128::from(ft.den);
                    let zq = (2 * num + den / 2)
                        .div_euclid(den)
                        .clamp(0, i128::from(zmax)) as u32;
                    let pass = zq < stored[j];
                    want_fails += u64::from(!pass);
                    let want = if pass { (zq, 3) } else { (stored[j], 7) };
                    assert_eq!(
                        (d[j], tris[j]),
                        want,
                        "{xy:?} s {s} row {py} pixel {j} of {n}"
                    );
                }
                assert_eq!(fails, want_fails, "{xy:?} s {s} row {py}");
                // The lanes built without AVX-512 too (`depth_lanes`).
                if let (Some(walk), true) = (DepthLanes::new(walk, ft.den), n >= 2 * DEPTH_LANES) {
                    let (mut d2, mut t2) = (stored.clone(), vec![7u32; n]);
                    let f2 = depth_lanes(walk, zmax, 3, &mut d2, &mut t2);
                    assert_eq!((f2, d2, t2), (fails, d, tris), "{xy:?} s {s} row {py}");
                }
            }
        }
        assert!(
            lane_spans > 150_000 && pixels > 10_000_000,
            "{lane_spans} {pixels}"
        );
    }

    /// The row walk gives the per-row span and edge values of [`FixedTri::span`] (the exact
    /// per-row division) on 250k seeded triangles, small to guard-band sized, every sub-pixel
    /// width, horizontal and vertical edges included, over each triangle's rows and beyond.
    #[test]
    fn row_walk_matches_the_per_row_spans() {
        let mut rng = Rng(0x5eed_3a1c);
        let (mut rows, mut covered, mut horizontal) = (0u64, 0u64, 0u64);
        for i in 0..250_000u32 {
            let s = 1 + i % 12;
            let scale = 1i64 << s;
            let reach = [4i64, 64, 1024, 20_000][(i / 12 % 4) as usize] * scale;
            let cx = rng.int_in(-reach, reach) + 512 * scale;
            let cy = rng.int_in(-reach, reach) + 512 * scale;
            let mut xy = [[0i64; 2]; 3];
            for p in &mut xy {
                *p = [
                    cx + rng.int_in(-reach, reach),
                    cy + rng.int_in(-reach, reach),
                ];
            }
            if i % 7 == 0 {
                xy[2][1] = xy[1][1];
            }
            if i % 11 == 0 {
                xy[0][0] = xy[2][0];
            }
            let width = 1024 + (i % 3) * 500;
            let Some(Prepared {
                ft,
                xy,
                rows: (lo, hi),
            }) = prepared(xy, [0; 3], s, width)
            else {
                continue;
            };
            horizontal += u64::from(
                xy.iter()
                    .enumerate()
                    .any(|(k, p)| p[1] == xy[(k + 1) % 3][1]),
            );
            let py0 = lo - 2 + rng.int_in(0, 3);
            let py1 = (hi + 2).min(py0 + 40).max(py0 + 1);
            let mut walk = ft.walk(py0, py1);
            for py in py0..py1 {
                if py > py0 {
                    ft.walk_next(&mut walk);
                }
                let (xl, xr, ev) = ft.walk_span(&walk);
                let (xl0, xr0, ev0) = ft.span(py);
                assert_eq!(xl < xr, xl0 < xr0, "{xy:?} {s} {py}");
                if xl < xr {
                    assert_eq!((xl, xr, ev), (xl0, xr0, ev0), "{xy:?} {s} {py}");
                    covered += 1;
                }
                rows += 1;
            }
        }
        assert!(rows > 2_000_000 && covered > 500_000, "{rows} {covered}");
        assert!(horizontal > 30_000, "{horizontal}");
    }
}
