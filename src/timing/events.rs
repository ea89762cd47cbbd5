//! The event stream of one render, as the timing model consumes it: per covered pixel (raster
//! order) its plan and triangle, and per texture lookup the texel addresses of each bilinear
//! footprint; per frame the triangle, span and fragment counts of the visibility pass.
//!
//! Events are only built when `RenderOptions::timing` is set; each shading row fills its own
//! [`RowEvents`] and rows are concatenated in row order, so the stream is identical for any
//! thread count. The addresses come from calling the fixed units again with a trace
//! (`hw_model::trilinear::trilinear` / `hw_model::footprint::footprint_filter`) on the
//! fragment's raw texture coordinates; the functional path is untouched.

use crate::fixedpoint::to_raw;
use crate::pipeline::stages::Machine;
use crate::pipeline::{Frag, Impl, Plan, StageImpls, StageKind};
use hw_model::fixed::SatCounter;
use hw_model::footprint::{footprint, footprint_filter, MAX_PROBES};
use hw_model::lod::lod;
use hw_model::trilinear::{trilinear, TrilinearTrace};
use hw_model::{HwConfig, UnitCost};
use serde::Serialize;

/// One bilinear footprint (2x2 texels) read from texture memory.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct TexelFootprint {
    /// Stage kind index (`StageKind::index`) of the lookup.
    pub stage: u8,
    /// Lookup number within the stage (probe of footprint assembly, or the n-th map of a
    /// multi-lookup stage); the footprints of one lookup are consecutive.
    pub lookup: u8,
    /// MIP level.
    pub level: u8,
    /// Texture index (into the prepared maps).
    pub tex: u16,
    /// Texel columns x0, x1 and rows y0, y1 (after wrapping); texels (x0,y0), (x1,y0),
    /// (x0,y1), (x1,y1).
    pub x: [u32; 2],
    pub y: [u32; 2],
}

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
    /// Buffers sized for a row of `width` pixels with up to `lookups` lookups of 2 levels each.
    #[must_use]
    pub fn with_capacity(width: usize, lookups: usize) -> Self {
        Self {
            pixels: Vec::with_capacity(width),
            footprints: Vec::with_capacity(width * 2 * lookups.max(1)),
        }
    }
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
    /// Level sizes (width, height) of each texture, finest first.
    pub textures: Vec<Vec<(u32, u32)>>,
    /// Covered pixels in raster order.
    pub pixels: Vec<PixelEvent>,
    pub footprints: Vec<TexelFootprint>,
}

impl FrameEvents {
    /// Concatenates rows (in row order) into the frame's lists; `fp_end` is rebased.
    pub fn append_row(&mut self, row: RowEvents) {
        let base = self.footprints.len() as u32;
        self.pixels.extend(row.pixels.into_iter().map(|mut p| {
            p.fp_end += base;
            p
        }));
        self.footprints.extend(row.footprints);
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

/// Texture lookups one invocation of `kind` makes. Data-driven so that multi-lookup stages
/// plug in: trilinear makes `aniso_probes` (footprint assembly; 1 = plain trilinear); an NDF
/// stage would make 3 (4 with the normalization map), a roughness stage 2 (bump + roughness).
#[must_use]
pub fn lookups(kind: StageKind, hw: &HwConfig) -> u32 {
    match kind {
        StageKind::Trilinear => hw.trilinear.aniso_probes.max(1),
        StageKind::BumpFetch | StageKind::RoughFetch => 1,
        StageKind::NdfFetch => hw_model::ndf::ndf_lookups(&hw.ndf),
        _ => 0,
    }
}

fn push_trace(
    out: &mut Vec<TexelFootprint>,
    stage: StageKind,
    lookup: u32,
    tex: usize,
    t: &TrilinearTrace,
) {
    for b in t.level.iter().take(t.levels_used as usize) {
        out.push(TexelFootprint {
            stage: stage.index() as u8,
            lookup: lookup as u8,
            level: b.level as u8,
            tex: tex as u16,
            x: [b.coords[0].0, b.coords[1].0],
            y: [b.coords[0].1, b.coords[2].1],
        });
    }
}

/// Records the events of one shaded pixel (after `run` has filled `frag`): its plan and
/// triangle and the footprints of every texture lookup (the material texture and, for bump
/// materials, the offset map), recomputed by the fixed units from the fragment's raw
/// coordinates (float carriers are quantized into the machine's formats).
#[allow(clippy::too_many_arguments)]
pub fn record_pixel(
    plan: &Plan,
    plan_index: u32,
    tri: u32,
    impls: &StageImpls,
    m: &Machine,
    frag: &Frag,
    ev: &mut RowEvents,
) {
    let hw = m.hw;
    let mut sat = SatCounter::default();
    let fb = m.uv_fmt.frac_bits;
    let lfb = hw.lod.lod_frac_bits;
    let uv = if impls.of(StageKind::Texcoord) == Impl::Fixed
        || impls.of(StageKind::Trilinear) == Impl::Fixed
    {
        frag.uv_x
    } else {
        frag.uv.map(|s| s.map(|x| to_raw(x, &m.uv_fmt, &mut sat)))
    };
    let [u, v] = uv[0];
    for &kind in &plan.stages {
        let t = match kind {
            StageKind::Trilinear => plan.texture,
            StageKind::BumpFetch => plan.bump.as_ref().map(|b| b.map),
            StageKind::RoughFetch => plan.rough.as_ref().map(|r| r.map),
            StageKind::NdfFetch => plan.ndf.as_ref().map(|n| n.maps),
            _ => None,
        };
        let Some(t) = t else { continue };
        let Some(levels) = m.tex_fixed.get(t) else {
            continue;
        };
        let size = levels.first().map_or((1, 1), |l| (l.width, l.height));
        let probes = lookups(kind, hw);
        if kind == StageKind::Trilinear && probes > 1 && plan.derivatives {
            let fp = footprint(
                &uv,
                size,
                fb,
                probes,
                hw.trilinear.aniso_adaptive,
                &hw.lod,
                &mut sat,
            );
            let mut traces = [TrilinearTrace::default(); MAX_PROBES];
            let _ = footprint_filter(
                levels,
                u,
                v,
                fb,
                &fp,
                lfb,
                plan.wrap,
                &hw.trilinear,
                Some(&mut traces),
            );
            for (i, tr) in traces.iter().take(fp.probes as usize).enumerate() {
                push_trace(&mut ev.footprints, kind, i as u32, t, tr);
            }
            continue;
        }
        let lod_raw = if kind == StageKind::Trilinear {
            if impls.of(StageKind::Lod) == Impl::Fixed {
                frag.lod_x
            } else {
                to_raw(frag.lod, &m.lod_fmt, &mut sat)
            }
        } else {
            // The bump fetch computes its LOD inline against the offset map's size.
            let d = crate::pipeline::stages::texel_derivs(&uv, size.0, size.1);
            lod(d, fb, &hw.lod, &mut sat)
        };
        // One lookup per map; the NDF fetch reads `probes` maps of one size from `t` on.
        let maps = if kind == StageKind::NdfFetch {
            probes
        } else {
            1
        };
        for i in 0..maps {
            let Some(levels) = m.tex_fixed.get(t + i as usize) else {
                continue;
            };
            let mut tr = TrilinearTrace::default();
            let _ = trilinear(
                levels,
                u,
                v,
                fb,
                lod_raw,
                lfb,
                plan.wrap,
                &hw.trilinear,
                Some(&mut tr),
            );
            push_trace(&mut ev.footprints, kind, i, t + i as usize, &tr);
        }
    }
    ev.pixels.push(PixelEvent {
        plan: plan_index,
        tri,
        fp_end: ev.footprints.len() as u32,
    });
}
