//! Rasterizer: triangle setup (near-plane and guard-band clipping, snapping to the sub-pixel
//! grid, orientation, culling) and scanline traversal into a visibility buffer.
//!
//! Conventions (written down once):
//! - Screen space: x right, y down, pixel (px, py) covers [px, px+1) x [py, py+1); its sample
//!   is the centre (px + 0.5, py + 0.5). Snapped positions are integers in units of
//!   2^-subpixel_bits pixel.
//! - Edge function `i` is the one opposite vertex `i`: `E_i(p) = cross(v_k - v_j, p - v_j)` with
//!   (i, j, k) cyclic, oriented so that it is positive inside; `E_0 + E_1 + E_2 = area2` exactly
//!   for the fixed (snapped) version, so `E_i / area2` are the screen-space barycentrics.
//! - Fill rule: top-left. A sample exactly on an edge belongs to the triangle if the edge is a
//!   top edge or a left edge. Shared edges are covered exactly once (watertight).
//! - Depth: z_ndc in [-1, 1] maps to an unsigned `depth_bits` integer; interpolated linearly in
//!   screen space with exact integer arithmetic; the test is strictly-less, so of two equal
//!   depths the earlier triangle wins (deterministic for any thread count).
//! - Front faces are counter-clockwise in NDC (OpenGL's default).
//!
//! Details of this implementation:
//! - `cross(a, b) = a.x * b.y - a.y * b.x` in screen coordinates (y down). With
//!   `E_i = A_i * (y - y_j) - B_i * (x - x_j)`, `A_i = x_k - x_j`, `B_i = y_k - y_j`, edge `i` is
//!   a *left* edge when `B_i < 0` (the inside lies towards +x) and a *top* edge when `B_i == 0`
//!   and `A_i > 0` (horizontal, inside lies towards +y, i.e. below it on screen). This equals
//!   sampling at `p + (eps, eps^2)` for an infinitesimal `eps`, so every point of a plane
//!   partition is covered exactly once, including shared vertices.
//! - A triangle that is counter-clockwise in NDC has `cross < 0` in y-down screen space; setup
//!   swaps vertices 1 and 2 of such (front-facing) triangles so that `area2 > 0` always.
//! - Clipping (homogeneous, f64, Sutherland-Hodgman, fan re-triangulation) keeps
//!   `w >= W_EPSILON`, `-w <= z <= w` (near and far planes, as OpenGL) and the guard band
//!   `|x|, |y| <= GUARD_BAND * w`. New vertices are always interpolated from the inside
//!   endpoint towards the outside one, so an edge shared by two triangles is cut at the
//!   bit-identical point in both (watertight after clipping).
//! - Snapping: `round_ties_even(p * 2^subpixel_bits)`; depth:
//!   `round_ties_even(clamp((z_ndc + 1) / 2, 0, 1) * (2^depth_bits - 1))`.
//! - Range: viewports are at most `MAX_VIEWPORT` (8192) square and the guard band is 4, so
//!   snapped coordinates satisfy `|x| <= 2.5 * 8192 * 2^12 < 2^27`; edge values are below 2^57
//!   and fit `i64`; the depth numerator `sum(E_i * z_i)` (< 2^89) uses `i128`.
//! - Depth is interpolated as `round_half_up(sum(E_i * z_i) / area2)` per pixel, exactly, by an
//!   incremental quotient/remainder walk along each span (no per-pixel division; the span's
//!   first numerator in `i64` when it fits, else `i128`).
//! - Spans: a row's span is bounded by each edge's `floor((E(0) - t) / |step|)` (`t` the
//!   fill rule's threshold); these are walked down a triangle's rows by the same exact
//!   quotient/remainder steps, so only its first row in a band divides.
//! - Float coverage evaluates each edge with its endpoints in a canonical (lexicographic) order
//!   and negates, so the two triangles sharing an edge see exactly opposite values; spans are
//!   found by a division guess refined with those evaluations (exact for the float model).
//! - Setup runs in parallel: each vertex is projected once (shared by the unclipped triangles
//!   that use it), a first pass counts each draw's output triangles, a second writes them in
//!   place, in submission order.
//! - Float coverage draws only the triangles fixed setup kept (same list, same culling
//!   decision); a sliver whose snapped orientation is flipped (`area2_f < 0`) is drawn in float
//!   with its own orientation. Float depth is f64, cleared to 1.0, strictly-less as well.
//! - Traversal runs on bands of rows in parallel (16 to 64 rows, [`band_rows`]); triangles
//!   are binned per band in submission order and each band owns its rows, so the output is
//!   bit-identical for any thread count and band size.

mod setup;
mod traverse;

pub(crate) use setup::vec_populated;
pub use setup::{
    setup, DrawTri, ScreenTri, Setup, SetupStats, VertexSource, GUARD_BAND, MAX_DEPTH_BITS,
    MAX_VIEWPORT, W_EPSILON,
};
pub use traverse::{
    band_rows, coverage_count, rasterize, Coverage, RasterStats, VisBuffer, BAND_ROWS, NO_TRI,
};
