//! Texture-access traces: the texel footprints a fragment's stages fetch, recorded by the
//! functional pass itself (the timing model's events, never a replay).
//!
//! A stage makes every trilinear lookup through [`trilinear_traced`] (or records its
//! footprint-assembly probes with [`Trace::record`]). When the shading pass collects events
//! ([`Trace::on`]), the unit is called with its trace and the footprints it read are appended
//! to the fragment's [`Trace`]; when it does not, the plain unit runs and nothing is paid but
//! one predictable branch per lookup. A float twin under timing records the footprints that
//! the hardware unit fetches for its inputs rounded into the machine's formats (the float
//! arithmetic has no addresses of its own).

use super::StageKind;
use hw_model::config::TrilinearConfig;
use hw_model::fixed::ConstRounding;
use hw_model::trilinear::{
    trilinear_to, BatchFootprints, BilinearTrace, Level, SampleSink, TrilinearTrace, TrilinearUnit,
};
use hw_model::wrap::WrapMode;
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

/// Most footprints one fragment can fetch: footprint assembly's 16 probes of two levels, the
/// offset and roughness maps (two levels each) and four NDF maps (two levels each). An
/// environment material's lookups (`env-fetch`: `aniso_probes` probes of two levels, after
/// its bump and roughness maps) fit too, unless it is also textured with 16 probes (not
/// supported: 4 x 16 + 4 footprints exceed the trace). A fitted-lobe material's texture (16
/// probes of two levels) and its lobe maps blended between two levels (2 x 8 single-level
/// lookups) fit as well.
pub const MAX_FOOTPRINTS: usize =
    2 * hw_model::footprint::MAX_PROBES + 2 * hw_model::multi_lobe::MAX_LOBES as usize;

/// The footprints of one fragment, in the order its stages fetched them (its count ahead of
/// them, so that clearing it touches the fragment's first lines only: [`super::Frag`]).
#[derive(Clone, Copy, Debug)]
#[repr(C)]
pub struct Trace {
    /// Record footprints (set by the shading pass when it collects timing events).
    pub on: bool,
    len: u32,
    fps: [TexelFootprint; MAX_FOOTPRINTS],
}

impl Default for Trace {
    fn default() -> Self {
        Self {
            on: false,
            len: 0,
            fps: [TexelFootprint::default(); MAX_FOOTPRINTS],
        }
    }
}

impl Trace {
    /// Forgets the previous fragment's footprints.
    #[inline]
    pub fn clear(&mut self) {
        self.len = 0;
    }

    /// The footprints recorded since [`Trace::clear`].
    #[must_use]
    pub fn footprints(&self) -> &[TexelFootprint] {
        &self.fps[..self.len as usize]
    }

    /// Appends the footprints of one trilinear lookup (one per level it used).
    pub fn record(&mut self, stage: StageKind, lookup: u32, tex: usize, t: &TrilinearTrace) {
        let at = Lookup { stage, lookup, tex };
        for b in t.level.iter().take(t.levels_used as usize) {
            self.push(at, b);
        }
    }

    /// Appends the footprints of lane `lane` of a batch's lookup (one per level it used).
    #[inline]
    pub fn record_lane(&mut self, at: Lookup, fps: &BatchFootprints, lane: usize) {
        for (level, x, y) in fps.lane(lane) {
            self.push_xy(at, level, x, y);
        }
    }

    /// Appends one bilinear footprint of lookup `at`.
    #[inline]
    fn push(&mut self, at: Lookup, b: &BilinearTrace) {
        let (x, y) = b.columns_rows();
        self.push_xy(at, b.level, x, y);
    }

    /// Appends the footprint of lookup `at` on level `level` with texel columns `x` and rows
    /// `y`.
    #[inline]
    fn push_xy(&mut self, at: Lookup, level: u32, x: [u32; 2], y: [u32; 2]) {
        let Some(slot) = self.fps.get_mut(self.len as usize) else {
            debug_assert!(
                false,
                "more than {MAX_FOOTPRINTS} footprints in one fragment"
            );
            return;
        };
        *slot = TexelFootprint {
            stage: at.stage.index() as u8,
            lookup: at.lookup as u8,
            level: level as u8,
            tex: at.tex as u16,
            x,
            y,
        };
        self.len += 1;
    }
}

/// The sink of a traced lookup: each footprint the filter reads goes straight into the
/// fragment's trace.
struct Recorder<'a> {
    trace: &'a mut Trace,
    at: Lookup,
}

impl SampleSink for Recorder<'_> {
    #[inline(always)]
    fn footprint(&mut self, _: usize, fp: &BilinearTrace) {
        self.trace.push(self.at, fp);
    }
    #[inline(always)]
    fn sample(&mut self, _: u32, _: u32, _: [u16; 4]) {}
}

/// Where a traced lookup comes from: the stage, its lookup number and the map it reads.
#[derive(Clone, Copy, Debug)]
pub struct Lookup {
    pub stage: StageKind,
    pub lookup: u32,
    pub tex: usize,
}

/// [`hw_model::trilinear::trilinear`] of a stage's lookup, its footprints recorded into `trace`
/// when tracing is on.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn trilinear_traced(
    levels: &[Level],
    u: i64,
    v: i64,
    frac: u32,
    lod: i64,
    lod_frac_bits: u32,
    wrap: [WrapMode; 2],
    cfg: &TrilinearConfig,
    trace: &mut Trace,
    at: Lookup,
) -> [u16; 4] {
    if !trace.on {
        return trilinear_to(levels, u, v, frac, lod, lod_frac_bits, wrap, cfg, &mut ());
    }
    let mut sink = Recorder { trace, at };
    trilinear_to(levels, u, v, frac, lod, lod_frac_bits, wrap, cfg, &mut sink)
}

/// [`TrilinearUnit::sample`] of a stage's lookup (a unit set up once for a span), its
/// footprints recorded into `trace` when tracing is on: [`trilinear_traced`] with the unit's
/// configuration. `POW2_REPEAT`: the caller has checked [`TrilinearUnit::pow2_repeat`] of
/// `levels`, and [`TrilinearUnit::sample_pow2_repeat`] samples them.
#[inline(always)]
pub fn unit_traced<F: ConstRounding, W: ConstRounding, const POW2_REPEAT: bool>(
    unit: &TrilinearUnit<F, W>,
    levels: &[Level],
    u: i64,
    v: i64,
    lod: i64,
    trace: &mut Trace,
    at: Lookup,
) -> [u32; 4] {
    if !trace.on {
        return if POW2_REPEAT {
            unit.sample_pow2_repeat(levels, u, v, lod, &mut ())
        } else {
            unit.sample(levels, u, v, lod, &mut ())
        };
    }
    let sink = &mut Recorder { trace, at };
    if POW2_REPEAT {
        unit.sample_pow2_repeat(levels, u, v, lod, sink)
    } else {
        unit.sample(levels, u, v, lod, sink)
    }
}

/// The fragment's texture coordinates as the hardware sees them: the raw values when the
/// `texcoord` stage ran fixed (`raw_uv`), else the float carriers rounded into the machine's
/// format (a float twin's inputs for its trace; overflows go to `sat`).
pub fn hardware_uv(
    m: &super::stages::Machine,
    frag: &super::Frag,
    raw_uv: bool,
    sat: &mut hw_model::fixed::SatCounter,
) -> [[i64; 2]; 3] {
    if raw_uv {
        frag.uv_x
    } else {
        frag.uv
            .map(|s| s.map(|x| crate::fixedpoint::to_raw(x, &m.uv_fmt, sat)))
    }
}

/// For a float twin under timing: records the footprints of the hardware lookups the fixed
/// twin makes, `maps` maps from `at.tex` on (lookups `at.lookup..`), at the fragment's raw
/// coordinates (its float carriers rounded into the machine's format unless `raw_uv`) with the
/// LOD of their derivatives against level 0 of `at.tex`, as the fixed fetch stages compute it.
pub fn trace_float_fetch(
    m: &super::stages::Machine,
    frag: &mut super::Frag,
    raw_uv: bool,
    wrap: [WrapMode; 2],
    at: Lookup,
    maps: u32,
) {
    if !frag.trace.on {
        return;
    }
    let Some(l0) = m.tex_fixed.get(at.tex).and_then(|l| l.first()) else {
        return;
    };
    let mut scratch = hw_model::fixed::SatCounter::default();
    let uv = hardware_uv(m, frag, raw_uv, &mut scratch);
    let fb = m.uv_fmt.frac_bits;
    let d = super::stages::texel_derivs(&uv, l0.width, l0.height);
    let l = hw_model::lod::lod(d, fb, &m.hw.lod, &mut scratch);
    let [u, v] = uv[0];
    for i in 0..maps {
        let Some(levels) = m.tex_fixed.get(at.tex + i as usize) else {
            continue;
        };
        let at = Lookup {
            lookup: at.lookup + i,
            tex: at.tex + i as usize,
            ..at
        };
        let lfb = m.hw.lod.lod_frac_bits;
        let hw = &m.hw.trilinear;
        let _ = trilinear_traced(levels, u, v, fb, l, lfb, wrap, hw, &mut frag.trace, at);
    }
}

/// One lookup of texture `t` for `stage` at the LOD of the pixel's texture-coordinate
/// derivatives on the map's level-0 size: the fixed LOD unit, then the traced trilinear unit.
/// A Float `texcoord` producer's carriers are rounded into the coordinate format. The maps
/// fetched beside the bump map (D, Toksvig, LEAN moments) share it. `None`: no such texture.
pub fn fetch_at_uv_lod(
    px: &super::Px,
    frag: &mut super::Frag,
    c: &mut super::stages::Counters,
    stage: StageKind,
    t: usize,
) -> Option<[u16; 4]> {
    let m = px.m;
    let hw = m.hw;
    let l0 = m.tex_float.get(t).and_then(|l| l.first())?;
    let sat = &mut c.sat[stage.index()];
    let fb = m.uv_fmt.frac_bits;
    let uv = if px.fixed(StageKind::Texcoord) {
        frag.uv_x
    } else {
        frag.uv
            .map(|s| s.map(|x| crate::fixedpoint::to_raw(x, &m.uv_fmt, sat)))
    };
    let d = super::stages::texel_derivs(&uv, l0.width, l0.height);
    let l = hw_model::lod::lod(d, fb, &hw.lod, sat);
    let [u, v] = uv[0];
    let at = Lookup {
        stage,
        lookup: 0,
        tex: t,
    };
    Some(trilinear_traced(
        &m.tex_fixed[t],
        u,
        v,
        fb,
        l,
        hw.lod.lod_frac_bits,
        px.plan.wrap,
        &hw.trilinear,
        &mut frag.trace,
        at,
    ))
}

/// The float twin of [`fetch_at_uv_lod`]: exact LOD and trilinear filter of the float map
/// (under timing, the footprints the hardware fetches for the rounded coordinates).
pub fn fetch_at_uv_lod_f64(
    px: &super::Px,
    frag: &mut super::Frag,
    stage: StageKind,
    t: usize,
) -> Option<[f64; 4]> {
    let m = px.m;
    let l0 = m.tex_float.get(t).and_then(|l| l.first())?;
    let uv = &frag.uv;
    let l = crate::reference::lod_f64(super::stages::texel_derivs_f64(uv, l0.width, l0.height));
    let r = crate::reference::trilinear_f64(&m.tex_float[t], uv[0][0], uv[0][1], l, px.plan.wrap);
    let at = Lookup {
        stage,
        lookup: 0,
        tex: t,
    };
    trace_float_fetch(m, frag, px.fixed(StageKind::Texcoord), px.plan.wrap, at, 1);
    Some(r)
}
