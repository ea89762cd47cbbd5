//! Triangle setup: homogeneous clipping (Sutherland-Hodgman against the near/far planes and a
//! guard band), perspective divide, viewport transform, snapping to the sub-pixel grid,
//! orientation and back-face culling. Conventions are in the parent module header.
//!
//! Setup is the host/geometry side of the machine and runs in f64: the per-vertex `1/w` of
//! the perspective divide is computed here and then quantized into the interpolator's
//! `inv_w_bits` format. The hardware reciprocal unit (`hw_model::reciprocal`) models the
//! per-pixel divide `1 / sum(E_i invw_i)` of perspective-correct interpolation, the one a
//! texture pipeline pays for every fragment.

use crate::fixedpoint::floor_exact;
use hw_model::config::RasterConfig;
use rayon::prelude::*;

/// Largest supported viewport side; larger `width`/`height` are clamped to it.
pub const MAX_VIEWPORT: u32 = 8192;
/// Guard band: clip-space `|x|, |y| <= GUARD_BAND * w` is kept unclipped.
pub const GUARD_BAND: f64 = 4.0;
/// Smallest `w` kept by clipping (the `w > epsilon` plane).
pub const W_EPSILON: f64 = 1e-12;

/// A triangle to draw: indices into the clip-space vertex array.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DrawTri {
    pub v: [u32; 3],
    /// Drop the triangle if it is back-facing (clockwise in NDC).
    pub cull_back: bool,
}

/// A set-up screen-space triangle (post-clip), ready for traversal.
#[derive(Clone, Debug, PartialEq)]
pub struct ScreenTri {
    /// Snapped positions, units of 2^-subpixel_bits pixel, y down.
    pub xy: [[i64; 2]; 3],
    /// Unsnapped screen positions in pixels (for the float twin).
    pub xy_f: [[f64; 2]; 3],
    /// `depth_bits` unorm depth per vertex.
    pub z: [u32; 3],
    /// Depth in [0, 1] per vertex.
    pub z_f: [f64; 3],
    /// 1 / w_clip per (post-clip) vertex.
    pub inv_w: [f64; 3],
    /// Index into `draws` of the source triangle.
    pub src: u32,
    /// Where the vertices come from ([`Setup::src_bary`] gives them as barycentrics of the
    /// source triangle's vertices).
    pub source: VertexSource,
    /// `E0 + E1 + E2` of the snapped triangle, > 0.
    pub area2: i64,
    /// The same from `xy_f`; negative for slivers whose snapping flipped them (float traversal
    /// then negates its edges), zero if the float triangle is degenerate (not drawn in float).
    pub area2_f: f64,
    /// x0, y0, x1, y1 (exclusive) of pixels possibly covered (fixed or float), in the viewport.
    pub bbox: [u32; 4],
}

/// Where a screen triangle's vertices come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VertexSource {
    /// The source triangle's own vertices, in its order or, `swapped`, with vertices 1 and 2
    /// exchanged (setup orients every triangle to `area2 > 0`).
    Unclipped { swapped: bool },
    /// Clipping produced them: their barycentrics are in [`Setup::clipped_bary`].
    Clipped,
}

/// Setup counters. Every input triangle lands in exactly one of `non_finite`, `clipped_away`,
/// `culled`, `degenerate`, or produces at least one output triangle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct SetupStats {
    /// Input triangles (`draws.len()`).
    pub input: u64,
    /// Back-facing with `cull_back` (for clipped triangles: all pieces rejected, one culled).
    pub culled: u64,
    /// Zero snapped area (all pieces).
    pub degenerate: u64,
    /// A NaN/infinite coordinate (input or produced by clipping), or an index out of range.
    pub non_finite: u64,
    /// Entirely outside the view volume (off-screen, behind the camera, beyond far).
    pub clipped_away: u64,
    /// Input triangles that were partly clipped (counted in addition to their outcome).
    pub clipped: u64,
    /// Output triangles (`tris.len()`).
    pub output: u64,
}

/// Result of [`setup`].
#[derive(Clone, Debug)]
pub struct Setup {
    pub tris: Vec<ScreenTri>,
    /// The vertices of every [`VertexSource::Clipped`] triangle as clip-space-linear
    /// barycentrics of its source triangle's vertices, by triangle index (ascending).
    pub clipped_bary: Vec<(u32, [[f64; 3]; 3])>,
    pub width: u32,
    pub height: u32,
    pub subpixel_bits: u32,
    pub depth_bits: u32,
    pub stats: SetupStats,
}

impl Setup {
    /// Each vertex of triangle `i` as clip-space-linear barycentrics of its source triangle's
    /// vertices (unit vectors, in setup's vertex order, for an unclipped triangle).
    #[must_use]
    pub fn src_bary(&self, i: usize) -> [[f64; 3]; 3] {
        const ID: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        match self.tris[i].source {
            VertexSource::Unclipped { swapped: false } => ID,
            VertexSource::Unclipped { swapped: true } => [ID[0], ID[2], ID[1]],
            VertexSource::Clipped => {
                let k = self
                    .clipped_bary
                    .binary_search_by_key(&(i as u32), |e| e.0)
                    .expect("every clipped triangle has its barycentrics");
                self.clipped_bary[k].1
            }
        }
    }
}

impl ScreenTri {
    /// Exact edge values at the centre of pixel (px, py), in units of 2^-2*subpixel_bits
    /// pixel^2 (saturated to `i64` for absurd pixel positions far outside the viewport).
    #[inline]
    #[must_use]
    pub fn edges_fixed(&self, px: i64, py: i64, subpixel_bits: u32) -> [i64; 3] {
        let s = subpixel_bits.clamp(1, 12);
        match small_point(magnitudes(&self.xy), px, py, s) {
            Some((x, y)) => small_edges(&self.xy, x, y),
            None => wide_edges(&self.xy.map(|p| p.map(i128::from)), px, py, s),
        }
    }

    /// [`Self::edges_fixed`] from the float positions `xy_f` snapped (rounded) to `bits`
    /// sub-pixel bits (1..=16) instead of the rasterizer's grid: the attribute setup of a
    /// machine whose planes come from finer positions than its coverage.
    #[must_use]
    pub fn edges_fixed_on_grid(&self, px: i64, py: i64, bits: u32) -> [i64; 3] {
        let s = bits.clamp(1, 16);
        let g = f64::from(1u32 << s);
        let v = self
            .xy_f
            .map(|p| p.map(|c| (c * g).round_ties_even() as i128));
        let small = v
            .iter()
            .flatten()
            .all(|c| c.unsigned_abs() < u128::from(SMALL_EDGES));
        match small.then(|| small_point(0, px, py, s)).flatten() {
            Some((x, y)) => small_edges(&v.map(|p| p.map(|c| c as i64)), x, y),
            None => wide_edges(&v, px, py, s),
        }
    }

    /// The edge values at the centres of pixels (px, py), (px + 1, py) and (px, py + 1), as
    /// `(e, e(px + 1) - e, e(py + 1) - e)`: bit-identical to three calls of
    /// [`Self::edges_fixed`], computed once plus the edges' constant steps
    /// (`-(y_k - y_j) 2^s`, `(x_k - x_j) 2^s`): in plain `i64` under [`SMALL_EDGES`]' bounds,
    /// else with checked `i64` operations, and on any overflow by the exact calls.
    #[inline]
    #[must_use]
    pub fn edges_fixed_with_steps(
        &self,
        px: i64,
        py: i64,
        subpixel_bits: u32,
    ) -> ([i64; 3], [i64; 3], [i64; 3]) {
        let s = subpixel_bits.clamp(1, 12);
        let v = self.xy;
        if let Some((x, y)) = small_point(magnitudes(&v), px, py, s) {
            let (dx, dy) = small_steps(&v, s);
            return (small_edges(&v, x, y), dx, dy);
        }
        self.edges_steps_i64(px, py, subpixel_bits)
            .unwrap_or_else(|| {
                let e = self.edges_fixed(px, py, subpixel_bits);
                let ex = self.edges_fixed(px + 1, py, subpixel_bits);
                let ey = self.edges_fixed(px, py + 1, subpixel_bits);
                let dx = [0, 1, 2].map(|i| ex[i].wrapping_sub(e[i]));
                let dy = [0, 1, 2].map(|i| ey[i].wrapping_sub(e[i]));
                (e, dx, dy)
            })
    }

    /// The edge values at the centre of pixel (px, py) and their constant steps along x and
    /// y, as [`Self::edges_fixed_with_steps`], when the `n` pixels (px + j, py) of a row span
    /// are all within [`SMALL_EDGES`]' bounds: then pixel (px + j, py)'s edges are exactly
    /// `e + j dx` in `i64`, bit-identical to [`Self::edges_fixed`] there. `None` otherwise
    /// (the caller evaluates each pixel).
    #[inline]
    #[must_use]
    pub fn edges_fixed_span(
        &self,
        px: i64,
        py: i64,
        n: usize,
        subpixel_bits: u32,
    ) -> Option<([i64; 3], [i64; 3], [i64; 3])> {
        let s = subpixel_bits.clamp(1, 12);
        let v = self.xy;
        let mags = magnitudes(&v);
        let last = px.checked_add(i64::try_from(n).ok()?.checked_sub(1)?)?;
        small_point(mags, last, py, s)?;
        let (x, y) = small_point(mags, px, py, s)?;
        let (dx, dy) = small_steps(&v, s);
        Some((small_edges(&v, x, y), dx, dy))
    }

    /// [`Self::edges_fixed_with_steps`] in `i64`, `None` when any intermediate (including
    /// the neighbours' edge values) would leave `i64`.
    fn edges_steps_i64(
        &self,
        px: i64,
        py: i64,
        subpixel_bits: u32,
    ) -> Option<([i64; 3], [i64; 3], [i64; 3])> {
        let s = subpixel_bits.clamp(1, 12);
        let h = 1i64 << (s - 1);
        let x = px.checked_mul(1 << s)?.checked_add(h)?;
        let y = py.checked_mul(1 << s)?.checked_add(h)?;
        let (mut e, mut dx, mut dy) = ([0i64; 3], [0i64; 3], [0i64; 3]);
        for i in 0..3 {
            let [xj, yj] = self.xy[(i + 1) % 3];
            let [xk, yk] = self.xy[(i + 2) % 3];
            let ax = xk.checked_sub(xj)?;
            let ay = yk.checked_sub(yj)?;
            let v = ax
                .checked_mul(y.checked_sub(yj)?)?
                .checked_sub(ay.checked_mul(x.checked_sub(xj)?)?)?;
            let sx = ay.checked_mul(1 << s)?.checked_neg()?;
            let sy = ax.checked_mul(1 << s)?;
            v.checked_add(sx)?;
            v.checked_add(sy)?;
            (e[i], dx[i], dy[i]) = (v, sx, sy);
        }
        Some((e, dx, dy))
    }

    /// Float edge values at the point (px + 0.5, py + 0.5) from `xy_f`, evaluated with each
    /// edge's endpoints in canonical order (bit-exact negation across shared edges).
    #[must_use]
    pub fn edges_float(&self, px: f64, py: f64) -> [f64; 3] {
        let x = px + 0.5;
        let y = py + 0.5;
        let mut e = [0.0; 3];
        for (i, out) in e.iter_mut().enumerate() {
            *out = edge_float(self.xy_f[(i + 1) % 3], self.xy_f[(i + 2) % 3], x, y);
        }
        e
    }

    /// [`Self::edges_float`] at `(px, py)`, `(px + 1, py)` and `(px, py + 1)`, bit for bit,
    /// each edge's canonical order found once for the three.
    #[must_use]
    pub fn edges_float_and_steps(&self, px: f64, py: f64) -> [[f64; 3]; 3] {
        let (x, y) = (px + 0.5, py + 0.5);
        let (x1, y1) = ((px + 1.0) + 0.5, (py + 1.0) + 0.5);
        let mut out = [[0.0; 3]; 3];
        // Indexed: the iterator forms measured 1-2% more instructions on W1's float frame.
        #[allow(clippy::needless_range_loop)]
        for i in 0..3 {
            let (a, b) = (self.xy_f[(i + 1) % 3], self.xy_f[(i + 2) % 3]);
            let swap = (b[0], b[1]) < (a[0], a[1]);
            let (p, q) = if swap { (b, a) } else { (a, b) };
            let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
            let sign = |e: f64| if swap { -e } else { e };
            out[0][i] = sign(dx * (y - p[1]) - dy * (x - p[0]));
            out[1][i] = sign(dx * (y - p[1]) - dy * (x1 - p[0]));
            out[2][i] = sign(dx * (y1 - p[1]) - dy * (x - p[0]));
        }
        out
    }
}

/// Vertex coordinates below this bound (in magnitude, on the evaluation grid) and sample
/// positions below 2^28 keep every product and sum of an edge value below 2^61: the edge
/// values are computed in plain `i64`.
const SMALL_EDGES: u64 = 1 << 29;

/// The OR of the vertex coordinates' magnitudes (below [`SMALL_EDGES`] iff each is).
#[inline(always)]
fn magnitudes(v: &[[i64; 2]; 3]) -> u64 {
    v.iter().flatten().fold(0, |m, c| m | c.unsigned_abs())
}

/// The centre of pixel (px, py) on a grid of `s` sub-pixel bits, when the vertices'
/// `magnitudes` and the pixel are within [`SMALL_EDGES`]' bounds.
#[inline(always)]
fn small_point(magnitudes: u64, px: i64, py: i64, s: u32) -> Option<(i64, i64)> {
    let small = magnitudes < SMALL_EDGES && (px.unsigned_abs() | py.unsigned_abs()) < 1 << (28 - s);
    let h = 1i64 << (s - 1);
    small.then(|| ((px << s) + h, (py << s) + h))
}

/// The three edge values at the grid point (x, y) in `i64` (within [`SMALL_EDGES`]' bounds).
#[inline(always)]
fn small_edges(v: &[[i64; 2]; 3], x: i64, y: i64) -> [i64; 3] {
    let edge = |[xj, yj]: [i64; 2], [xk, yk]: [i64; 2]| (xk - xj) * (y - yj) - (yk - yj) * (x - xj);
    [edge(v[1], v[2]), edge(v[2], v[0]), edge(v[0], v[1])]
}

/// The edges' constant steps from one pixel centre to the next along x and along y
/// (`-(y_k - y_j) 2^s`, `(x_k - x_j) 2^s`), within [`SMALL_EDGES`]' bounds.
#[inline(always)]
fn small_steps(v: &[[i64; 2]; 3], s: u32) -> ([i64; 3], [i64; 3]) {
    let [[x0, y0], [x1, y1], [x2, y2]] = *v;
    (
        [-((y2 - y1) << s), -((y0 - y2) << s), -((y1 - y0) << s)],
        [(x2 - x1) << s, (x0 - x2) << s, (x1 - x0) << s],
    )
}

/// Exact edge values of the vertices `v` (on a grid of `s` sub-pixel bits) at the centre of
/// pixel (px, py) in `i128`, saturated to `i64`.
fn wide_edges(v: &[[i128; 2]; 3], px: i64, py: i64, s: u32) -> [i64; 3] {
    let h = 1i128 << (s - 1);
    let x = (i128::from(px) << s) + h;
    let y = (i128::from(py) << s) + h;
    let mut e = [0i64; 3];
    for (i, out) in e.iter_mut().enumerate() {
        let [xj, yj] = v[(i + 1) % 3];
        let [xk, yk] = v[(i + 2) % 3];
        let w = (xk - xj) * (y - yj) - (yk - yj) * (x - xj);
        *out = w.clamp(i128::from(i64::MIN), i128::from(i64::MAX)) as i64;
    }
    e
}

/// `cross(b - a, p - a)` with (a, b) put in lexicographic order first and the sign restored, so
/// that `edge_float(a, b, ..) == -edge_float(b, a, ..)` bit for bit.
#[must_use]
pub(crate) fn edge_float(a: [f64; 2], b: [f64; 2], x: f64, y: f64) -> f64 {
    let swap = (b[0], b[1]) < (a[0], a[1]);
    let (p, q) = if swap { (b, a) } else { (a, b) };
    let e = (q[0] - p[0]) * (y - p[1]) - (q[1] - p[1]) * (x - p[0]);
    if swap {
        -e
    } else {
        e
    }
}

/// A clip-space vertex with its barycentrics in the source triangle.
#[derive(Clone, Copy, Debug, Default)]
struct ClipVert {
    p: [f64; 4],
    b: [f64; 3],
}

/// Number of clip planes (w-epsilon, near, far, +-x guard, +-y guard).
const PLANES: usize = 7;
/// A triangle clipped by 7 planes has at most 3 + 7 vertices.
const MAX_POLY: usize = 3 + PLANES;

/// Signed distance (inside >= 0) of `p` to clip plane `plane`.
fn plane_dist(plane: usize, p: &[f64; 4]) -> f64 {
    let [x, y, z, w] = *p;
    match plane {
        0 => w - W_EPSILON,
        1 => z + w,
        2 => w - z,
        3 => GUARD_BAND * w - x,
        4 => GUARD_BAND * w + x,
        5 => GUARD_BAND * w - y,
        _ => GUARD_BAND * w + y,
    }
}

/// Bit set of the clip planes (bits 0..7) and view-volume sides (bits 7..11: x <= w, x >= -w,
/// y <= w, y >= -w) that `p` is outside of.
fn outcode(p: &[f64; 4]) -> u32 {
    let mut c = 0;
    for plane in 0..PLANES {
        if plane_dist(plane, p) < 0.0 {
            c |= 1 << plane;
        }
    }
    let [x, y, _, w] = *p;
    let sides = [w - x, w + x, w - y, w + y];
    for (i, d) in sides.iter().enumerate() {
        if *d < 0.0 {
            c |= 1 << (PLANES + i);
        }
    }
    c
}

/// A fixed-capacity polygon (no allocation per triangle).
#[derive(Clone, Copy)]
struct Poly {
    v: [ClipVert; MAX_POLY],
    n: usize,
}

impl Poly {
    fn push(&mut self, v: ClipVert) {
        if self.n < MAX_POLY {
            self.v[self.n] = v;
            self.n += 1;
        }
    }
}

/// Point where segment (a -> b) crosses the plane, from the inside endpoint `a` (`da >= 0`)
/// towards the outside one (`db < 0`).
fn intersect(a: &ClipVert, da: f64, b: &ClipVert, db: f64) -> ClipVert {
    let t = da / (da - db);
    let mut r = ClipVert::default();
    for c in 0..4 {
        r.p[c] = a.p[c] + t * (b.p[c] - a.p[c]);
    }
    for c in 0..3 {
        r.b[c] = a.b[c] + t * (b.b[c] - a.b[c]);
    }
    r
}

/// Sutherland-Hodgman against one plane.
fn clip_plane(input: &Poly, plane: usize) -> Poly {
    let mut out = Poly {
        v: [ClipVert::default(); MAX_POLY],
        n: 0,
    };
    for i in 0..input.n {
        let cur = &input.v[i];
        let next = &input.v[(i + 1) % input.n];
        let dc = plane_dist(plane, &cur.p);
        let dn = plane_dist(plane, &next.p);
        let cin = dc >= 0.0;
        let nin = dn >= 0.0;
        if cin {
            out.push(*cur);
        }
        if cin != nin {
            let v = if cin {
                intersect(cur, dc, next, dn)
            } else {
                intersect(next, dn, cur, dc)
            };
            out.push(v);
        }
    }
    out
}

/// A post-divide vertex.
#[derive(Clone, Copy, Debug, Default)]
struct ScreenVert {
    xs: [i64; 2],
    xf: [f64; 2],
    z: u32,
    zf: f64,
    inv_w: f64,
}

/// Parameters of the viewport transform and snapping.
struct Viewport {
    w: f64,
    h: f64,
    scale: f64,
    zmax: f64,
}

impl Viewport {
    /// Divide, viewport-transform and snap; `None` if anything is non-finite.
    fn project(&self, p: &[f64; 4]) -> Option<ScreenVert> {
        let [x, y, z, w] = *p;
        let inv_w = 1.0 / w;
        let xn = x * inv_w;
        let yn = y * inv_w;
        let zn = z * inv_w;
        let px = (xn + 1.0) * 0.5 * self.w;
        let py = (1.0 - yn) * 0.5 * self.h;
        let zf = ((zn + 1.0) * 0.5).clamp(0.0, 1.0);
        let all = [inv_w, px, py, zf];
        if !all.iter().all(|c| c.is_finite()) {
            return None;
        }
        // |px|, |py| <= 2.5 * MAX_VIEWPORT (guard band), so the casts are exact.
        let sx = (px * self.scale).round_ties_even() as i64;
        let sy = (py * self.scale).round_ties_even() as i64;
        let zu = (zf * self.zmax).round_ties_even() as u32;
        Some(ScreenVert {
            xs: [sx, sy],
            xf: [px, py],
            z: zu,
            zf,
            inv_w,
        })
    }

    /// [`Self::project`] of a clipped vertex, `None` also if its barycentrics are not finite.
    fn project_clipped(&self, v: &ClipVert) -> Option<ScreenVert> {
        self.project(&v.p)
            .filter(|_| v.b.iter().all(|c| c.is_finite()))
    }
}

/// What happened to one input triangle.
#[derive(Clone, Copy)]
enum Outcome {
    NonFinite,
    ClippedAway,
    Produced {
        culled: bool,
        degenerate: bool,
        clipped: bool,
        n: u8,
    },
}

/// `cross(b - a, c - a)` on snapped positions.
fn cross_fixed(a: [i64; 2], b: [i64; 2], c: [i64; 2]) -> i64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

fn cross_float(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Pixel range [lo, hi) whose centres may lie in [min, max] (snapped units).
fn pixel_range_fixed(min: i64, max: i64, s: u32, limit: u32) -> (i64, i64) {
    let h = 1i64 << (s - 1);
    // `floor(x / 2^s)` is the arithmetic shift `x >> s` (a division by `1 << s` with `s`
    // known only at run time is a divide instruction).
    let lo = -((h - min) >> s);
    let hi = ((max - h) >> s) + 1;
    (lo.max(0), hi.min(i64::from(limit)))
}

/// Pixel range [lo, hi) whose centres may lie in [min, max] (pixels).
fn pixel_range_float(min: f64, max: f64, limit: u32) -> (i64, i64) {
    // Finite and within the guard band, so the casts are exact (`ceil(x) = -floor(-x)`;
    // `floor_exact` is `floor` without the libm call).
    let lo = -floor_exact(-(min - 0.5)) as i64;
    let hi = floor_exact(max - 0.5) as i64 + 1;
    (lo.max(0), hi.min(i64::from(limit)))
}

/// A fan triangle setup keeps: its vertices oriented to `area2 > 0` (`swapped`: vertices 1 and
/// 2 exchanged), with their barycentrics in the source triangle when it was clipped.
struct Kept {
    vs: [ScreenVert; 3],
    area2: i64,
    swapped: bool,
    bary: Option<[[f64; 3]; 3]>,
}

/// Orients `vs`; `Err(true)` if culled, `Err(false)` if degenerate.
fn orient(vs: [ScreenVert; 3], cull_back: bool) -> Result<([ScreenVert; 3], i64, bool), bool> {
    let mut vs = vs;
    let area2 = cross_fixed(vs[0].xs, vs[1].xs, vs[2].xs);
    if area2 == 0 {
        return Err(false);
    }
    if area2 < 0 {
        // Counter-clockwise in NDC = clockwise in y-down screen space: front-facing.
        vs.swap(1, 2);
        Ok((vs, -area2, true))
    } else if cull_back {
        Err(true)
    } else {
        Ok((vs, area2, false))
    }
}

/// The screen triangle of a kept fan triangle of draw `src`.
fn make_tri(k: &Kept, src: u32, s: u32, width: u32, height: u32) -> ScreenTri {
    let vs = &k.vs;
    let area2_f = cross_float(vs[0].xf, vs[1].xf, vs[2].xf);
    let mut bbox = [0u32; 4];
    for axis in 0..2 {
        let limit = if axis == 0 { width } else { height };
        let mn = vs.iter().map(|v| v.xs[axis]).min().unwrap_or(0);
        let mx = vs.iter().map(|v| v.xs[axis]).max().unwrap_or(0);
        let (lo, hi) = pixel_range_fixed(mn, mx, s, limit);
        let mnf = vs.iter().map(|v| v.xf[axis]).fold(f64::INFINITY, f64::min);
        let mxf = vs
            .iter()
            .map(|v| v.xf[axis])
            .fold(f64::NEG_INFINITY, f64::max);
        let (lof, hif) = pixel_range_float(mnf, mxf, limit);
        let lo = lo.min(lof).min(i64::from(limit));
        let hi = hi.max(hif).max(lo);
        bbox[axis] = lo as u32;
        bbox[axis + 2] = hi as u32;
    }
    ScreenTri {
        xy: vs.map(|v| v.xs),
        xy_f: vs.map(|v| v.xf),
        z: vs.map(|v| v.z),
        z_f: vs.map(|v| v.zf),
        inv_w: vs.map(|v| v.inv_w),
        src,
        source: match k.bary {
            None => VertexSource::Unclipped { swapped: k.swapped },
            Some(_) => VertexSource::Clipped,
        },
        area2: k.area2,
        area2_f,
        bbox,
    }
}

/// A clip-space vertex as every unclipped triangle that uses it sees it: its outcode
/// ([`NON_FINITE`] for a non-finite position) and, inside every clip plane, its projection.
#[derive(Clone, Copy)]
struct VertexProj {
    code: u32,
    screen: Option<ScreenVert>,
}

/// Outcode of a vertex with a non-finite coordinate.
const NON_FINITE: u32 = u32::MAX;
/// Outcode bits of the clip planes.
const CLIP_MASK: u32 = (1 << PLANES) - 1;

/// Everything the per-draw setup reads.
struct Ctx<'a> {
    clip: &'a [[f64; 4]],
    proj: &'a [VertexProj],
    draws: &'a [DrawTri],
    vp: Viewport,
}

/// The widest depth buffer the rasterizer models (`depth_bits` is clamped to 8..=30).
pub const MAX_DEPTH_BITS: u32 = 30;

/// Sets up every triangle of `draws` (see the module header for the conventions).
/// `width`/`height` are clamped to `0..=MAX_VIEWPORT`, the config widths to their valid ranges.
///
/// In parallel and identical for any thread count: every vertex is projected once; a first
/// pass counts each draw's output triangles (and the outcome counters), a second writes each
/// output triangle straight into its slot of the result, in submission order.
#[must_use]
pub fn setup(
    clip: &[[f64; 4]],
    draws: &[DrawTri],
    width: u32,
    height: u32,
    cfg: &RasterConfig,
) -> Setup {
    let width = width.min(MAX_VIEWPORT);
    let height = height.min(MAX_VIEWPORT);
    let s = cfg.subpixel_bits.clamp(1, 12);
    let depth_bits = cfg.depth_bits.clamp(8, MAX_DEPTH_BITS);
    let vp = Viewport {
        w: f64::from(width),
        h: f64::from(height),
        scale: f64::from(1u32 << s),
        zmax: f64::from((1u32 << depth_bits) - 1),
    };
    let proj: Vec<VertexProj> = clip
        .par_iter()
        .map(|p| {
            if !p.iter().all(|c| c.is_finite()) {
                return VertexProj {
                    code: NON_FINITE,
                    screen: None,
                };
            }
            let code = outcode(p);
            VertexProj {
                code,
                screen: if code & CLIP_MASK == 0 {
                    vp.project(p)
                } else {
                    None
                },
            }
        })
        .collect();
    let ctx = Ctx {
        clip,
        proj: &proj,
        draws,
        vp,
    };
    let outcomes: Vec<Outcome> = (0..draws.len() as u32)
        .into_par_iter()
        .map(|src| ctx.for_kept(src, |_| {}))
        .collect();
    let mut stats = outcomes
        .par_iter()
        .fold(SetupStats::default, |mut st, o| {
            st.count(o);
            st
        })
        .reduce(SetupStats::default, |mut a, b| {
            a.add(&b);
            a
        });
    stats.input = draws.len() as u64;
    // (draw, its kept fan triangle) of every output triangle, in submission order.
    let mut out: Vec<(u32, u8)> = Vec::with_capacity(draws.len());
    for (src, o) in outcomes.iter().enumerate() {
        if let Outcome::Produced { n, .. } = *o {
            out.extend((0..n).map(|k| (src as u32, k)));
        }
    }
    let mut tris = vec_populated(out.len());
    out.par_iter()
        .map(|&(src, k)| {
            let t = ctx.nth_kept(src, k);
            make_tri(&t, src, s, width, height)
        })
        .collect_into_vec(&mut tris);
    let clipped_bary = out
        .par_iter()
        .enumerate()
        .filter(|&(_, &(src, _))| {
            matches!(
                outcomes[src as usize],
                Outcome::Produced { clipped: true, .. }
            )
        })
        .map(|(i, &(src, k))| {
            let b = ctx.nth_kept(src, k).bary;
            (i as u32, b.expect("a clipped triangle has barycentrics"))
        })
        .collect();
    stats.output = tris.len() as u64;
    Setup {
        tris,
        clipped_bary,
        width,
        height,
        subpixel_bits: s,
        depth_bits,
        stats,
    }
}

/// An empty vector with room for `n` items, its memory already allocated by the kernel in
/// parallel (Linux `madvise(MADV_POPULATE_WRITE)` on 2 MiB pieces from the worker threads;
/// below 4 MiB, or elsewhere, a plain `Vec::with_capacity`). The per-triangle arrays of a
/// large mesh are written once: touched 4 KiB page by page by the writers, their page faults
/// cost more than computing them and did not scale with threads (1M triangles: about 125,000
/// faults, 2/3 of the setup phase's CPU time). Only pieces with a page not yet resident
/// (`mincore`) are populated: the allocator hands the next frame the memory the last one
/// freed, and walking its resident pages again cost W2 (65,536 triangles, 13 MB of screen
/// triangles) 0.8 ms per frame.
pub(crate) fn vec_populated<T>(n: usize) -> Vec<T> {
    let v: Vec<T> = Vec::with_capacity(n);
    #[cfg(target_os = "linux")]
    {
        const PIECE: usize = 2 << 20;
        let bytes = n.saturating_mul(std::mem::size_of::<T>());
        let start = v.as_ptr() as usize;
        let first = start.next_multiple_of(PAGE);
        let end = (start + bytes) / PAGE * PAGE;
        if bytes >= 4 << 20 && end > first {
            let resident = resident_pages(first, end - first);
            (0..(end - first).div_ceil(PIECE))
                .into_par_iter()
                .filter(|&k| {
                    let pages = k * PIECE / PAGE..((k + 1) * PIECE).min(end - first) / PAGE;
                    resident
                        .as_ref()
                        .and_then(|r| r.get(pages))
                        .is_none_or(|r| r.iter().any(|&b| b & 1 == 0))
                })
                .for_each(|k| {
                    let a = first + k * PIECE;
                    let len = PIECE.min(end - a);
                    // SAFETY: [a, a + len) lies inside the vector's own allocation (rounded
                    // inward to pages); MADV_POPULATE_WRITE only allocates its pages (an
                    // error leaves them to be faulted in on first write) and changes no
                    // content the vector could observe.
                    unsafe {
                        libc::madvise(a as *mut libc::c_void, len, libc::MADV_POPULATE_WRITE);
                    }
                });
        }
    }
    v
}

/// The page size `vec_populated` and `resident_pages` assume (Linux on x86-64). With larger
/// pages `mincore` writes fewer bytes and the population is a less precise hint; no content
/// changes.
#[cfg(target_os = "linux")]
const PAGE: usize = 4096;

/// Whether each page of the `len` bytes from the page-aligned `addr` is resident (bit 0 of its
/// byte, Linux `mincore`); `None` if the call fails (every page then counts as not resident).
#[cfg(target_os = "linux")]
fn resident_pages(addr: usize, len: usize) -> Option<Vec<u8>> {
    let mut pages = vec![0u8; len.div_ceil(PAGE)];
    // SAFETY: [addr, addr + len) is page-aligned and lies inside an allocation of the caller;
    // `pages` has one byte per page of it, which is all `mincore` writes.
    let rc = unsafe { libc::mincore(addr as *mut libc::c_void, len, pages.as_mut_ptr()) };
    (rc == 0).then_some(pages)
}

impl Ctx<'_> {
    /// The `k`-th fan triangle draw `src` keeps (as [`Self::for_kept`] counted it).
    fn nth_kept(&self, src: u32, k: u8) -> Kept {
        let mut i = 0;
        let mut found = None;
        self.for_kept(src, |t| {
            if i == k {
                found = Some(t);
            }
            i += 1;
        });
        found.expect("the draw keeps the triangles its outcome counted")
    }

    /// Runs setup on draw `src` and calls `kept` for each fan triangle it keeps, in order.
    fn for_kept(&self, src: u32, mut kept: impl FnMut(Kept)) -> Outcome {
        let d = &self.draws[src as usize];
        let mut codes = [0u32; 3];
        for (c, &idx) in codes.iter_mut().zip(&d.v) {
            match self.proj.get(idx as usize) {
                Some(v) if v.code != NON_FINITE => *c = v.code,
                _ => return Outcome::NonFinite,
            }
        }
        if codes[0] & codes[1] & codes[2] != 0 {
            return Outcome::ClippedAway;
        }
        if (codes[0] | codes[1] | codes[2]) & CLIP_MASK == 0 {
            let mut vs = [ScreenVert::default(); 3];
            for (out, &idx) in vs.iter_mut().zip(&d.v) {
                match self.proj[idx as usize].screen {
                    Some(v) => *out = v,
                    None => return Outcome::NonFinite,
                }
            }
            let (mut culled, mut degenerate, mut n) = (false, false, 0);
            match orient(vs, d.cull_back) {
                Ok((vs, area2, swapped)) => {
                    kept(Kept {
                        vs,
                        area2,
                        swapped,
                        bary: None,
                    });
                    n = 1;
                }
                Err(true) => culled = true,
                Err(false) => degenerate = true,
            }
            return Outcome::Produced {
                culled,
                degenerate,
                clipped: false,
                n,
            };
        }
        let mut poly = Poly {
            v: [ClipVert::default(); MAX_POLY],
            n: 3,
        };
        for (i, &idx) in d.v.iter().enumerate() {
            let mut b = [0.0; 3];
            b[i] = 1.0;
            poly.v[i] = ClipVert {
                p: self.clip[idx as usize],
                b,
            };
        }
        // Every plane, even those no input vertex is outside of: an edge's cut then depends
        // only on its endpoints, identically in both triangles that share it.
        for plane in 0..PLANES {
            poly = clip_plane(&poly, plane);
            if poly.n < 3 {
                return Outcome::ClippedAway;
            }
        }
        let mut sv = [ScreenVert::default(); MAX_POLY];
        for (out, v) in sv.iter_mut().zip(&poly.v[..poly.n]) {
            match self.vp.project_clipped(v) {
                Some(p) => *out = p,
                None => return Outcome::NonFinite,
            }
        }
        let (mut culled, mut degenerate, mut n) = (false, false, 0);
        for i in 1..poly.n - 1 {
            match orient([sv[0], sv[i], sv[i + 1]], d.cull_back) {
                Ok((vs, area2, swapped)) => {
                    let b = [poly.v[0].b, poly.v[i].b, poly.v[i + 1].b];
                    let b = if swapped { [b[0], b[2], b[1]] } else { b };
                    kept(Kept {
                        vs,
                        area2,
                        swapped,
                        bary: Some(b),
                    });
                    n += 1;
                }
                Err(true) => culled = true,
                Err(false) => degenerate = true,
            }
        }
        Outcome::Produced {
            culled,
            degenerate,
            clipped: true,
            n,
        }
    }
}

impl SetupStats {
    /// Adds another set of counters (all but `input` and `output`).
    fn add(&mut self, o: &SetupStats) {
        self.non_finite += o.non_finite;
        self.clipped_away += o.clipped_away;
        self.culled += o.culled;
        self.degenerate += o.degenerate;
        self.clipped += o.clipped;
    }

    /// Counts one input triangle's outcome.
    fn count(&mut self, outcome: &Outcome) {
        match *outcome {
            Outcome::NonFinite => self.non_finite += 1,
            Outcome::ClippedAway => self.clipped_away += 1,
            Outcome::Produced {
                culled,
                degenerate,
                clipped,
                n,
            } => {
                if clipped {
                    self.clipped += 1;
                }
                if n == 0 {
                    if culled {
                        self.culled += 1;
                    } else if degenerate {
                        self.degenerate += 1;
                    } else {
                        self.clipped_away += 1;
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A populated vector is an empty one with room for its items, whether its memory is new
    /// to the process or resident already (the second call may reuse the first's); `mincore`
    /// finds a written vector's pages resident and a fresh 64 MiB allocation's (mapped on its
    /// own, never touched) not.
    #[test]
    fn populated_vectors_and_resident_pages() {
        for _ in 0..2 {
            let mut v: Vec<u64> = vec_populated(1 << 20);
            assert!(v.is_empty() && v.capacity() >= 1 << 20);
            v.extend(0..1u64 << 20);
            assert_eq!(v[12345], 12345);
        }
        #[cfg(target_os = "linux")]
        {
            let page = |v: &[u8]| (v.as_ptr() as usize).next_multiple_of(PAGE);
            let written = vec![1u8; 1 << 22];
            let r = resident_pages(page(&written), 1 << 21).expect("mincore");
            assert!(r.iter().all(|&b| b & 1 == 1));
            let fresh: Vec<u8> = Vec::with_capacity(1 << 26);
            let r = resident_pages(page(&fresh), 1 << 25).expect("mincore");
            assert!(r.iter().any(|&b| b & 1 == 0));
        }
    }
}
