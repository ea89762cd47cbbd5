//! The statistics phase: what one render measured (serialized into summary.json).

use super::{CoverageMode, Geometry};
use crate::pipeline::{Impl, StageKind};
use crate::raster::{RasterStats, SetupStats};
use crate::report::{ErrorMetrics, Image};
use crate::timing::events::FrameEvents;
use hw_model::HwConfig;
use serde::Serialize;

/// Per-stage statistics of the hardware pass.
#[derive(Clone, Debug, Serialize)]
pub struct StageStats {
    pub stage: StageKind,
    #[serde(rename = "impl")]
    pub imp: Impl,
    pub invocations: u64,
    pub saturated: u64,
    pub wrapped: u64,
    pub ops: u64,
    /// Invocations x the unit's cycles per op ([`IssueCycles`]), not a frame time.
    pub issue_cycles: u64,
    pub texels: u64,
}

/// Bump-mapping events: frames from a fallback, zero interpolated normals, `l + v = 0`,
/// non-finite float carriers (hardware and reference pass), offsets clamped by the map
/// encoding (including normal-map texels whose `n_z` was clamped, [`Maps::bump_clamped`]).
/// Format saturations are in the per-stage `saturated` counts.
#[derive(Clone, Debug, Default, Serialize)]
pub struct BumpStats {
    pub frame_fallback: u64,
    pub zero_normal: u64,
    pub h_zero: u64,
    pub nonfinite: u64,
    pub ref_nonfinite: u64,
    pub offset_clamped: u64,
    /// NDF moment-map channels clamped by their encoding (all moment maps of the scene).
    pub ndf_clamped: u64,
    /// The frames the bump materials used (`natural`, `unit`, `main`), empty without bumps.
    pub frame: String,
}

pub(super) fn bump_frames(geo: &Geometry, hw: &HwConfig) -> String {
    let mut kinds: Vec<&str> = geo
        .plans
        .iter()
        .filter_map(|p| p.bump.as_ref())
        .map(|b| b.frame.unwrap_or(hw.shading.frame.frame_kind).name())
        .collect();
    kinds.sort_unstable();
    kinds.dedup();
    kinds.join("+")
}

/// Wall times in milliseconds.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Timings {
    pub geometry_ms: f64,
    /// Triangle setup (clip, snap) and the per-triangle attributes, which are converted after
    /// the raster (only the visible triangles' when the hardware pass is the only shading
    /// pass).
    pub setup_ms: f64,
    pub raster_ms: f64,
    /// Hardware shading; with cycles on it includes the timing model fed row by row beside
    /// it (the part that did not overlap the shading).
    pub shade_hw_ms: f64,
    /// The reference's raster: with shared coverage the hardware's, plus its exact depth test
    /// on a depth buffer narrower than 30 bits (the scene set up and rasterized again).
    pub raster_ref_ms: f64,
    pub shade_ref_ms: f64,
    /// Setup + raster + hardware shading.
    pub hw_total_ms: f64,
    /// Setup + (shared or float) raster + reference shading.
    pub ref_total_ms: f64,
    /// The timing model's last step after the shading (its visibility pass and report; 0 when
    /// it did not run); not in `hw_total_ms`.
    pub timing_ms: f64,
}

/// Issue cycles: each unit's invocations x its cycles per op from HwConfig, summed with no
/// overlap and no memory: how much arithmetic the frame asks of its units, not how long it
/// takes. The frame's cycles are the timing model's ([`RenderStats::timing`]).
#[derive(Clone, Debug, Default, Serialize)]
pub struct IssueCycles {
    pub setup: u64,
    pub spans: u64,
    pub stages: u64,
    pub total: u64,
    pub per_covered_pixel: f64,
    /// Set when a stage ran without a hardware cost model (`ndf_norm = exact`): the totals
    /// leave its unit out and are no machine's cost; sweeps print `-`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub not_modelled: Option<&'static str>,
}

/// One hardware unit's cost at the machine's widths (`hw_model::datapath::units`): its
/// critical path in gate levels, pipeline latency in cycles and area in gate equivalents.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct UnitCostRow {
    pub unit: String,
    pub delay: u32,
    pub latency: u32,
    pub area_ge: u64,
}

/// What the machine's datapath costs: every unit ([`UnitCostRow`]), the total area of the
/// top-level units (`hw_model::datapath::total_area`, a proxy) and the longest unit latency.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct DatapathCost {
    pub area_ge: u64,
    pub max_latency: u32,
    pub max_latency_unit: String,
    pub units: Vec<UnitCostRow>,
}

impl DatapathCost {
    /// The costs of machine `hw`.
    #[must_use]
    pub fn of(hw: &HwConfig) -> Self {
        use hw_model::datapath::{max_latency, total_area, units};
        let reps = units(hw);
        let max = max_latency(&reps);
        Self {
            area_ge: total_area(&reps),
            max_latency: max,
            max_latency_unit: reps
                .iter()
                .find(|r| r.latency == max)
                .map_or_else(String::new, |r| r.name.to_string()),
            units: reps
                .iter()
                .map(|r| UnitCostRow {
                    unit: r.name.to_string(),
                    delay: r.delay,
                    latency: r.latency,
                    area_ge: r.area,
                })
                .collect(),
        }
    }

    /// The row of unit `name`, if the machine has it.
    #[must_use]
    pub fn unit(&self, name: &str) -> Option<&UnitCostRow> {
        self.units.iter().find(|u| u.unit == name)
    }
}

/// Everything one render produced.
pub struct Rendered {
    pub hw_image: Image,
    pub ref_image: Option<Image>,
    /// The ground truth image (`RenderOptions::truth`).
    pub truth_image: Option<Image>,
    /// Pixels covered by the hardware or the reference pass (the compared set).
    pub mask: Vec<bool>,
    pub stats: RenderStats,
    /// The timing model's events of the hardware pass, when `RenderOptions::timing` was set.
    pub events: Option<FrameEvents>,
}

/// The numbers of one render (serialized into summary.json).
#[derive(Clone, Debug, Serialize)]
pub struct RenderStats {
    pub scene: String,
    pub hw: String,
    pub width: u32,
    pub height: u32,
    pub triangles: u64,
    pub coverage: CoverageMode,
    pub setup: SetupStats,
    pub raster: RasterStats,
    pub covered_pixels: u64,
    /// Host-to-hardware conversions that saturated (vertex attributes out of format range).
    pub input_saturated: u64,
    /// Host-to-hardware conversions that wrapped (formats whose overflow rule is `wrap`).
    pub input_wrapped: u64,
    /// Bump-mapping events of the hardware pass (all zero without bump materials).
    pub bump: BumpStats,
    pub stages: Vec<StageStats>,
    pub issue_cycles: IssueCycles,
    /// The timing model's report of the frame (`RenderOptions::timing`; `None` without it, or
    /// when a stage has no hardware cost model, [`IssueCycles::not_modelled`]).
    pub timing: Option<crate::timing::TimingReport>,
    /// Delay, latency and area of the machine's units (their datapaths at its widths).
    pub datapath: DatapathCost,
    /// Wall times: not part of the results (they differ between two runs), so not serialized
    /// with them; `texsim render` writes them into `timings.json`.
    #[serde(skip)]
    pub timings: Timings,
    /// Error of the hardware image against the reference, in 8-bit and 16-bit LSBs.
    pub error_8bit: Option<ErrorMetrics>,
    pub error_16bit: Option<ErrorMetrics>,
    /// Roughness materials (issue 4): D maps, ground truth and the two errors.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub roughness: Option<RoughStats>,
    /// With `--truth`: the float reference against the ground truth (the model's error) and
    /// the hardware against the float reference (quantization), 8-bit LSBs.
    pub model_error: Option<ErrorMetrics>,
    pub quantization_error: Option<ErrorMetrics>,
    /// `render --ranges`: per stage and signal, the range the float reference computes
    /// (`render::ranges`); absent without it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ranges: Option<Vec<super::ranges::SignalRange>>,
    /// Results that are valid but probably not what was meant (`crate::warnings`).
    pub warnings: Vec<String>,
}

/// Roughness statistics of one render (8-bit LSB metrics over the covered pixels).
#[derive(Clone, Debug, Serialize)]
pub struct RoughStats {
    /// D channel values clamped by the encoding.
    pub d_clamped: u64,
    /// Ground-truth sub-samples per pixel axis (0: no truth rendered).
    pub truth_samples: u32,
    /// Float model vs ground truth.
    pub model_error: Option<ErrorMetrics>,
    /// Fixed vs float of the same model (= `error_8bit`).
    pub quantization_error: Option<ErrorMetrics>,
    /// Plain filtered bump map (variant `none`, float) vs ground truth; filled by the CLI.
    pub baseline_error: Option<ErrorMetrics>,
}
