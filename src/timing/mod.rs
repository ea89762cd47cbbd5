//! Timing model (GitHub issue 7): cycle counts of a frame on a Texram-style machine, separate
//! from the functional model. It consumes the event stream of a render ([`events`]) and never
//! changes a pixel; events are only built when `RenderOptions::timing` is set, so a render
//! without it pays nothing. Parameters: `HwConfig::timing` (`hw_model::timing_config`) and the
//! per-op cycle fields of the unit configs. The model is described in [`model`] and
//! docs/TIMING.md.

pub mod events;
pub mod model;
pub mod report;

#[cfg(test)]
mod equivalence;
#[cfg(test)]
mod previous;

pub use events::{FrameEvents, PixelEvent, RowEvents, TexelFootprint, TextureLayout};
pub use model::{simulate, Cache, FrameCounts, Simulator, TimingReport, LATENCY_BOTTLENECK};

use crate::render::{render, Maps, RenderOptions, Rendered};
use crate::scene::Scene;
use hw_model::HwConfig;

/// Renders `scene` on `hw` with event collection (no float reference); the render runs the
/// timing model over its events (`RenderStats::timing`), which is returned beside it.
pub fn cycles(
    scene: &Scene,
    maps: &Maps,
    hw: &HwConfig,
) -> crate::Result<(Rendered, TimingReport)> {
    let opts = RenderOptions {
        reference: false,
        timing: true,
        ..RenderOptions::default()
    };
    let r = render(scene, maps, hw, &opts)?;
    let rep = match (&r.stats.timing, r.stats.issue_cycles.not_modelled) {
        (Some(t), _) => t.clone(),
        (None, Some(why)) => return Err(crate::Error::msg(format!("no cycle count: {why}"))),
        (None, None) => return Err(crate::Error::msg("render produced no timing events")),
    };
    Ok((r, rep))
}
