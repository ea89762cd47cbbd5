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
