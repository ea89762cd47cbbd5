//! The signals of the common texturing chain held as lanes of a run (structure of arrays):
//! `bary` -> `texcoord` -> `lod`, `trilinear`. In a program that keeps them
//! ([`Program::lanes`](super::table::Program::lanes)), `bary`'s span twin writes each
//! fragment's raw barycentrics into [`Lanes::bary`] instead of [`Frag::bary_x`], `texcoord`
//! interpolates all of a span's texture coordinates at once from there into [`Lanes::uv`]
//! (`hw_model::interpolator::interpolate_lanes`, vector lanes where the CPU has them), and
//! `lod` and the trilinear batch read them there: no stage copies them out of or into the
//! fragments, whose layout (one fragment after another) made each of them a scattered
//! store or load (PERFORMANCE_LOG, stops 55, 58 and 59). Lane `j` of a run is its fragment
//! `j` ([`super::stages::run_spans`]); a span's first fragment is lane [`Px::base`].

use super::stages::{Machine, SPAN_MAX};
use super::table::Px;
use super::{Frag, Impl, Plan, StageImpls, StageKind};
use std::cell::RefCell;

/// Lanes of a run: one per fragment of [`super::stages::run_spans`].
pub const LANES: usize = SPAN_MAX;
const _: () = assert!(LANES.is_power_of_two());

/// Fewest fragments of each span of a run that takes the lanes
/// ([`super::stages::run_spans`]); runs of shorter spans keep the signals in the fragments.
pub const LANES_SPAN_MIN: usize = 8;

/// The chain's raw signals of a run's fragments, by lane.
#[derive(Clone, Debug)]
pub struct Lanes {
    /// `bary[sample][component][lane]`: the barycentrics `bary` writes and `texcoord` reads.
    pub bary: [[[i64; LANES]; 3]; 3],
    /// `uv[sample][axis][lane]`: the texture coordinates `texcoord` writes and `lod` and
    /// `trilinear` read.
    pub uv: [[[i64; LANES]; 2]; 3],
}

impl Default for Lanes {
    fn default() -> Self {
        Self {
            bary: [[[0; LANES]; 3]; 3],
            uv: [[[0; LANES]; 2]; 3],
        }
    }
}

impl Lanes {
    /// Lane `j`'s texture coordinates of sample 0 (the pixel's own), as `Frag::uv_x[0]`.
    #[inline(always)]
    #[must_use]
    pub fn uv0(&self, j: usize) -> [i64; 2] {
        [self.uv[0][0][j], self.uv[0][1][j]]
    }

    /// Lane `j`'s texture coordinates, as [`Frag::uv_x`] holds them.
    #[inline(always)]
    #[must_use]
    pub fn uv_of(&self, j: usize) -> [[i64; 2]; 3] {
        let [s0, s1, s2] = &self.uv;
        [
            [s0[0][j], s0[1][j]],
            [s1[0][j], s1[1][j]],
            [s2[0][j], s2[1][j]],
        ]
    }
}

/// A run's lanes as its stages share them through [`Px::lanes`] (one per worker).
pub type LaneCell = RefCell<Lanes>;

/// Whether a program compiled from `plan` with `impls` on `m` keeps the chain's signals in
/// lanes: every stage runs Fixed and its row says it may ([`super::table::LanesFn`]: `bary`,
/// `modulate`; `texcoord` and `lod` off the float32 coordinate path; `trilinear` with one
/// probe, as footprint assembly reads the fragment's three samples), the plan has `bary`,
/// `texcoord` and derivatives, and the CPU has vector lanes ([`vector_lanes`]): without them
/// `interpolate_lanes` runs its lanes one by one, which took more instructions than the
/// fragments' path (callgrind, W1, `texcoord` 126.3M against 91.8M).
#[must_use]
pub fn keeps_lanes(plan: &Plan, impls: &StageImpls, m: &Machine) -> bool {
    plan.stages
        .iter()
        .all(|&k| impls.of(k) == Impl::Fixed && (k.row().lanes)(m, plan))
        && plan.has(StageKind::Bary)
        && plan.has(StageKind::Texcoord)
        && plan.derivatives
        && vector_lanes()
}

/// Whether this CPU runs `interpolate_lanes` as vector lanes ([`hw_model::vector_batches`]:
/// AVX2 or AVX-512).
#[must_use]
pub fn vector_lanes() -> bool {
    hw_model::vector_batches()
}

/// Sample 0 of the lanes' texture coordinates into the fragments of the span at `px` (a
/// trilinear path that reads the fragments).
pub fn uv0_into(px: &Px, frags: &mut [Frag]) {
    if let Some(cell) = px.lanes {
        let lanes = cell.borrow();
        for (j, frag) in frags.iter_mut().enumerate() {
            frag.uv_x[0] = lanes.uv0(px.base + j);
        }
    }
}
