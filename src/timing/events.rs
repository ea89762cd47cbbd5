//! The event stream of one render, as the timing model consumes it: per covered pixel (raster
//! order) its plan and triangle, and per texture lookup the texel addresses of each bilinear
//! footprint; per frame the triangle, span and fragment counts of the visibility pass.
//!
//! Events are only built when `RenderOptions::timing` is set; each shading row fills its own
//! [`RowEvents`] and rows are concatenated in row order, so the stream is identical for any
//! thread count. The addresses are the stages' own traces from the one functional pass
//! ([`crate::pipeline::trace`]): with timing off no event is built.

use crate::pipeline::{Frag, StageKind};
use hw_model::{HwConfig, UnitCost};
use serde::Serialize;

pub use crate::pipeline::trace::TexelFootprint;

/// One covered pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct PixelEvent {
    /// Plan index.
    pub plan: u32,
    /// Screen triangle index.
    pub tri: u32,
    /// End (exclusive) of this pixel's footprints in the frame's footprint list; they start
    /// at the previous pixel's end.
    pub fp_end: u32,
}

/// Events of one row (built in parallel, concatenated in row order).
#[derive(Clone, Debug, Default)]
pub struct RowEvents {
    pub pixels: Vec<PixelEvent>,
    pub footprints: Vec<TexelFootprint>,
}

impl RowEvents {
    /// Empties the lists, keeping their buffers (a fed row's buffers serve later rows).
    pub fn clear(&mut self) {
        self.pixels.clear();
        self.footprints.clear();
    }
}

/// One texture (map) as the memory holds it: its level sizes and the bytes of a stored texel
/// (from its format: `crate::maps::TexelFormat::bytes`).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct TextureLayout {
    /// Level sizes (width, height), finest first.
    pub levels: Vec<(u32, u32)>,
    pub texel_bytes: u32,
}

/// A plan as the timing model sees it: its stages with their per-invocation cost.
#[derive(Clone, Debug, Default, Serialize)]
pub struct PlanTiming {
    pub stages: Vec<(StageKind, UnitCost)>,
}

/// Everything the timing model needs about one frame.
#[derive(Clone, Debug, Default)]
pub struct FrameEvents {
    pub width: u32,
    pub height: u32,
    /// Screen triangles after setup.
    pub triangles: u64,
    /// Non-empty spans of the visibility pass.
    pub spans: u64,
    /// Fragments (covered samples before the depth test) of the visibility pass.
    pub fragments: u64,
    pub plans: Vec<PlanTiming>,
    /// Each texture (map) as the memory holds it.
    pub textures: Vec<TextureLayout>,
    /// Covered pixels in raster order.
    pub pixels: Vec<PixelEvent>,
    pub footprints: Vec<TexelFootprint>,
}

impl FrameEvents {
    /// Concatenates rows (in row order) into the frame's lists; `fp_end` is rebased.
    pub fn append_row(&mut self, row: &RowEvents) {
        let base = self.footprints.len() as u32;
        self.pixels.extend(row.pixels.iter().map(|&p| PixelEvent {
            fp_end: p.fp_end + base,
            ..p
        }));
        self.footprints.extend_from_slice(&row.footprints);
    }

    /// The frame's size and visibility-pass counts.
    #[must_use]
    pub fn counts(&self) -> super::model::FrameCounts {
        super::model::FrameCounts {
            width: self.width,
            height: self.height,
            triangles: self.triangles,
            spans: self.spans,
            fragments: self.fragments,
        }
    }

    /// Number of events (pixels + footprints + triangles + spans).
    #[must_use]
    pub fn len(&self) -> u64 {
        self.pixels.len() as u64 + self.footprints.len() as u64 + self.triangles + self.spans
    }

    /// True when there is no event at all.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Texture lookups one invocation of `kind` makes (the stage table's `lookups` column):
/// trilinear makes `aniso_probes` (footprint assembly; 1 = plain trilinear), the bump and
/// roughness fetches one each, the NDF fetch 3 (4 with the normalization map).
#[must_use]
pub fn lookups(kind: StageKind, hw: &HwConfig) -> u32 {
    (kind.row().lookups)(hw)
}

/// Records the events of one shaded pixel (after `run` has filled `frag` with its trace on):
/// its plan and triangle and the footprints its stages fetched, in the order they fetched them.
pub fn record_pixel(plan_index: u32, tri: u32, frag: &Frag, ev: &mut RowEvents) {
    ev.footprints.extend_from_slice(frag.trace.footprints());
    ev.pixels.push(PixelEvent {
        plan: plan_index,
        tri,
        fp_end: ev.footprints.len() as u32,
    });
}
