//! `trilinear`: wrap + trilinear MIP filtering of the material texture (Williams 1983;
//! `hw_model::trilinear`), or footprint assembly over `aniso_probes` probes along the major
//! axis (`hw_model::footprint`) when the plan has derivatives.

use super::lanes::{uv0_into, Lanes};
use super::stages::{each_fragment, unorm, Counters, Machine};
use super::texcoord::quantize_uv;
use super::trace::{hardware_uv, trilinear_traced, unit_traced, Lookup, Trace};
use super::{Frag, Plan, Px, StageKind};
use crate::fixedpoint::to_raw;
use crate::footprint_ref::{footprint_f64, footprint_filter_f64};
use crate::reference::trilinear_f64;
use hw_model::fixed::{ConstRounding, SatCounter};
use hw_model::footprint::{footprint, footprint_cost, footprint_filter, MAX_PROBES};
use hw_model::trilinear::{
    trilinear_cost, BatchFootprints, BatchLevels, Level, SampleBatch, TrilinearTrace,
    TrilinearUnit, BATCH_LANES,
};
use hw_model::{HwConfig, UnitCost};

const KIND: StageKind = StageKind::Trilinear;

/// The stage's (first) lookup, of texture `t`.
#[inline(always)]
fn first_lookup(t: usize) -> Lookup {
    Lookup {
        stage: KIND,
        lookup: 0,
        tex: t,
    }
}

/// Footprint assembly runs: more than one probe and the derivatives it needs.
#[inline]
fn aniso(px: &Px) -> bool {
    px.m.hw.trilinear.aniso_probes > 1 && px.plan.derivatives
}

/// Whether the fixed twins may run with the chain's signals in lanes
/// ([`super::table::LanesFn`]): with one probe (footprint assembly reads the fragment's three
/// samples' coordinates).
#[must_use]
pub fn lanes(m: &Machine, _: &Plan) -> bool {
    m.hw.trilinear.aniso_probes <= 1
}

/// Fixed twin.
pub fn fixed(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let Some(t) = px.plan.texture else { return };
    let m = px.m;
    let k = KIND.index();
    let sat = &mut c.sat[k];
    let aniso = aniso(px);
    if !px.fixed(StageKind::Texcoord) && !px.fixed(StageKind::Lod) {
        quantize_uv(frag, m, if aniso { px.samples() } else { 1 }, sat);
    }
    let l = if px.fixed(StageKind::Lod) {
        frag.lod_x
    } else {
        to_raw(frag.lod, &m.lod_fmt, sat)
    };
    let (r, took) = lookup(m, px.plan, t, &frag.uv_x, l, aniso, &mut frag.trace, sat);
    if took != m.hw.trilinear.aniso_probes {
        c.cost[k] = per_pixel_probes(c.cost[k], m, took);
    }
    store_texel(
        frag,
        r.map(u32::from),
        m.hw.trilinear.texel_bits,
        px.carriers,
    );
}

/// A sample's channels (`tb` bits) as the fragment's texel and output, and as their float
/// carriers when the plan keeps them.
#[inline(always)]
fn store_texel(frag: &mut Frag, texel: [u32; 4], tb: u32, carriers: bool) {
    frag.texel_x = texel;
    frag.out_x = texel;
    frag.out_bits = tb;
    if carriers {
        frag.texel = texel.map(|x| unorm(x, tb));
        frag.out = frag.texel;
    }
}

/// Fixed twin over a span, or over a run of a program's spans (it runs across triangles, see
/// `table::AcrossFn`): the unit set up once (rounding modes, wrap mode, texture levels;
/// the lerp constants and the coordinate and LOD formats of `Machine::trilinear_setup`), then
/// one sample per fragment; a span of at least [`BATCH_MIN`] fragments on a
/// texture the unit's batch form takes (`Machine::tex_batch`) samples [`BATCH_LANES`] at a time
/// ([`batches`]). Footprint assembly and a Float `lod` producer take [`fixed`] on each fragment.
pub fn fixed_span(px: &Px, frags: &mut [Frag], c: &mut Counters) {
    let Some(t) = px.plan.texture else { return };
    if aniso(px) || !px.fixed(StageKind::Lod) {
        return each_fragment(fixed, px, frags, c);
    }
    let m = px.m;
    let hw = m.hw;
    let cfg = &hw.trilinear;
    let (setup, wrap) = (&m.trilinear_setup, px.plan.wrap);
    hw_model::with_rounding!(cfg.filter_rounding, F => {
        hw_model::with_rounding!(cfg.weight_rounding, W => {
            let unit = TrilinearUnit::<F, W>::new(cfg, setup, wrap);
            let levels = &m.tex_fixed[t];
            let tb = cfg.texel_bits;
            if unit.repeats() && m.tex_pow2[t] {
                match m.tex_batch[t].as_ref() {
                    Some(shape) if frags.len() >= BATCH_MIN && unit.batch_form() => {
                        let k = (&unit, &levels[..], shape, (t, tb), px.carriers);
                        match px.lanes {
                            Some(cell) => {
                                let lanes = &cell.borrow();
                                batches(k, &InLanes { lanes, base: px.base }, frags);
                            }
                            None => batches(k, &InFrags, frags),
                        }
                    }
                    _ => {
                        uv0_into(px, frags);
                        span_lanes::<F, W, true>(&unit, levels, t, tb, px.carriers, frags);
                    }
                }
            } else {
                uv0_into(px, frags);
                span_lanes::<F, W, false>(&unit, levels, t, tb, px.carriers, frags);
            }
        })
    });
}

/// The samples of [`fixed_span`]'s fast path: each fragment's lookup at its raw coordinates
/// and raw LOD, its texel and output as [`fixed`] writes them. `POW2_REPEAT`: the unit's
/// wrap is Repeat and the texture's levels have power-of-two sides (`Machine::tex_pow2`), so
/// [`TrilinearUnit::sample_pow2_repeat`] samples them.
#[inline(always)]
fn span_lanes<F: ConstRounding, W: ConstRounding, const POW2_REPEAT: bool>(
    unit: &TrilinearUnit<F, W>,
    levels: &[Level],
    t: usize,
    tb: u32,
    carriers: bool,
    frags: &mut [Frag],
) {
    let at = first_lookup(t);
    for frag in frags.iter_mut() {
        let [u, v] = frag.uv_x[0];
        let texel =
            unit_traced::<F, W, POW2_REPEAT>(unit, levels, u, v, frag.lod_x, &mut frag.trace, at);
        store_texel(frag, texel, tb, carriers);
    }
}

/// Fragments a span (or run of spans) needs for [`batches`]: shorter ones took longer in
/// batches than sample by sample.
const BATCH_MIN: usize = 8;

/// [`span_lanes`] of a span of Repeat on power-of-two `levels` of the shape `shape`,
/// [`BATCH_LANES`] fragments at a time through [`TrilinearUnit::sample_batch_pow2_repeat`]
/// (whose [`TrilinearUnit::batch_form`] the caller has checked), which also gives the
/// footprints of a batch with a traced fragment ([`Trace::record_lane`]).
#[inline(always)]
fn batches<F: ConstRounding, W: ConstRounding, U: Uv0>(
    (unit, levels, shape, (t, tb), carriers): Batches<'_, F, W>,
    uv: &U,
    frags: &mut [Frag],
) {
    let at = first_lookup(t);
    let mut batch = SampleBatch::default();
    let mut out = [[0; 4]; BATCH_LANES];
    // The footprints' arrays, only when a fragment is traced.
    let mut fps = frags
        .iter()
        .any(|f| f.trace.on)
        .then(BatchFootprints::default);
    for (k, chunk) in frags.chunks_mut(BATCH_LANES).enumerate() {
        let first = k * BATCH_LANES;
        uv.fill(first, chunk, &mut batch);
        let traced = fps.as_mut();
        if !unit.sample_batch_pow2_repeat(levels, shape, &batch, chunk.len(), &mut out, traced) {
            // Levels of another shape than the machine's (not reached): sample by sample.
            for (j, frag) in chunk.iter_mut().enumerate() {
                frag.uv_x[0] = uv.uv0(first + j, frag);
            }
            span_lanes::<F, W, true>(unit, levels, t, tb, carriers, chunk);
            continue;
        }
        for (j, (frag, &texel)) in chunk.iter_mut().zip(&out).enumerate() {
            store_texel(frag, texel, tb, carriers);
            if let (Some(fps), true) = (&fps, frag.trace.on) {
                frag.trace.record_lane(at, fps, j);
            }
        }
    }
}

/// What [`batches`] samples with: the unit, the texture's levels and their batch shape, the
/// texture and its texel bits, and whether the plan keeps carriers.
type Batches<'a, F, W> = (
    &'a TrilinearUnit<'a, F, W>,
    &'a [Level<'a>],
    &'a BatchLevels,
    (usize, u32),
    bool,
);

/// Where [`batches`] reads a fragment's texture coordinates (sample 0): fragment `j` of the
/// run, `frag`.
trait Uv0 {
    fn uv0(&self, j: usize, frag: &Frag) -> [i64; 2];

    /// The batch's coordinates and raw LODs from `chunk`, fragments `first..` of the run.
    #[inline(always)]
    fn fill(&self, first: usize, chunk: &[Frag], batch: &mut SampleBatch) {
        for (j, frag) in chunk.iter().enumerate() {
            [batch.u[j], batch.v[j]] = self.uv0(first + j, frag);
            batch.lod[j] = frag.lod_x;
        }
    }
}

/// In the fragments ([`Frag::uv_x`]).
struct InFrags;

impl Uv0 for InFrags {
    #[inline(always)]
    fn uv0(&self, _: usize, frag: &Frag) -> [i64; 2] {
        frag.uv_x[0]
    }
}

/// In the run's lanes ([`super::lanes`]), the span's first fragment at lane `base`.
struct InLanes<'a> {
    lanes: &'a Lanes,
    base: usize,
}

impl Uv0 for InLanes<'_> {
    #[inline(always)]
    fn uv0(&self, j: usize, _: &Frag) -> [i64; 2] {
        self.lanes.uv0(self.base + j)
    }

    /// The coordinates copied from the lanes as slices (W1's fastest frame -4% against lane
    /// by lane, and -2% against copying whole batches of lanes, stop 61).
    #[inline(always)]
    fn fill(&self, first: usize, chunk: &[Frag], batch: &mut SampleBatch) {
        let (at, n) = (self.base + first, chunk.len());
        let [u, v] = &self.lanes.uv[0];
        batch.u[..n].copy_from_slice(&u[at..at + n]);
        batch.v[..n].copy_from_slice(&v[at..at + n]);
        for (lod, frag) in batch.lod.iter_mut().zip(chunk) {
            *lod = frag.lod_x;
        }
    }
}

/// Float twin. Under timing it records the footprints the hardware unit fetches for its
/// inputs rounded into the machine's formats.
pub fn float(px: &Px, frag: &mut Frag, c: &mut Counters) {
    let Some(t) = px.plan.texture else { return };
    let m = px.m;
    let (probes, adaptive) = (m.hw.trilinear.aniso_probes, m.hw.trilinear.aniso_adaptive);
    let [u, v] = frag.uv[0];
    let aniso = aniso(px);
    frag.texel = if aniso {
        let levels = &m.tex_float[t];
        let size = levels.first().map_or((1, 1), |l0| (l0.width, l0.height));
        let fp = footprint_f64(&frag.uv, size, probes, adaptive);
        if fp.probes != probes {
            let k = KIND.index();
            c.cost[k] = per_pixel_probes(c.cost[k], m, fp.probes);
        }
        footprint_filter_f64(levels, u, v, &fp, px.plan.wrap)
    } else {
        trilinear_f64(&m.tex_float[t], u, v, frag.lod, px.plan.wrap)
    };
    frag.out_bits = 0;
    frag.out = frag.texel;
    if frag.trace.on {
        let mut scratch = SatCounter::default();
        let uv = hardware_uv(m, frag, px.fixed(StageKind::Texcoord), &mut scratch);
        let l = if px.fixed(StageKind::Lod) {
            frag.lod_x
        } else {
            to_raw(frag.lod, &m.lod_fmt, &mut scratch)
        };
        let _ = lookup(m, px.plan, t, &uv, l, aniso, &mut frag.trace, &mut scratch);
    }
}

/// One invocation: footprint assembly over `aniso_probes` probes when the plan has
/// derivatives, else one trilinear lookup (two levels).
#[must_use]
pub fn cost(m: &Machine, plan: &Plan) -> UnitCost {
    if plan.derivatives {
        footprint_cost(
            &m.hw.trilinear,
            &m.hw.lod,
            m.hw.trilinear.aniso_probes,
            m.hw.timing.gate_levels_per_cycle,
        )
    } else {
        trilinear_cost(&m.hw.trilinear, 2, m.hw.timing.gate_levels_per_cycle)
    }
}

/// Lookups per invocation: one per probe.
#[must_use]
pub fn lookups(hw: &HwConfig) -> u32 {
    hw.trilinear.aniso_probes.max(1)
}

/// A stage's accumulated `[ops, cycles, texels]` with this pixel's planned footprint-assembly
/// cost (`aniso_probes` probes) replaced by that of the `probes` it took (`aniso_adaptive`).
fn per_pixel_probes(acc: [u64; 3], m: &Machine, probes: u32) -> [u64; 3] {
    let cost = |n: u32| m.footprint_costs[(n.clamp(1, 16).ilog2()) as usize];
    let planned = cost(m.hw.trilinear.aniso_probes);
    let took = cost(probes);
    // Modulo 2^64: the planned cost is charged per program after the fragments ran
    // (`Program::charge`), so the running sum may dip below it meanwhile.
    [
        acc[0]
            .wrapping_sub(u64::from(planned.ops))
            .wrapping_add(u64::from(took.ops)),
        acc[1]
            .wrapping_sub(u64::from(planned.cycles))
            .wrapping_add(u64::from(took.cycles)),
        acc[2]
            .wrapping_sub(u64::from(planned.texels))
            .wrapping_add(u64::from(took.texels)),
    ]
}

/// The fixed lookup of texture `t` at raw coordinates `uv` (sample and helper samples) and raw
/// LOD `l`: footprint assembly when `aniso`, else one trilinear lookup; its footprints go into
/// `trace`. Returns the filtered texel and the probes it took.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn lookup(
    m: &Machine,
    plan: &Plan,
    t: usize,
    uv: &[[i64; 2]; 3],
    l: i64,
    aniso: bool,
    trace: &mut Trace,
    sat: &mut SatCounter,
) -> ([u16; 4], u32) {
    if aniso {
        return footprint_lookup(m, plan, t, uv, trace, sat);
    }
    let hw = m.hw;
    let at = first_lookup(t);
    let [u, v] = uv[0];
    let r = trilinear_traced(
        &m.tex_fixed[t],
        u,
        v,
        m.uv_fmt.frac_bits,
        l,
        hw.lod.lod_frac_bits,
        plan.wrap,
        &hw.trilinear,
        trace,
        at,
    );
    (r, hw.trilinear.aniso_probes)
}

/// [`lookup`] by footprint assembly.
#[inline(never)]
fn footprint_lookup(
    m: &Machine,
    plan: &Plan,
    t: usize,
    uv: &[[i64; 2]; 3],
    trace: &mut Trace,
    sat: &mut SatCounter,
) -> ([u16; 4], u32) {
    let hw = m.hw;
    let fb = m.uv_fmt.frac_bits;
    let lfb = hw.lod.lod_frac_bits;
    let levels = &m.tex_fixed[t];
    let [u, v] = uv[0];
    let size = levels.first().map_or((1, 1), |l0| (l0.width, l0.height));
    let (probes, adaptive) = (hw.trilinear.aniso_probes, hw.trilinear.aniso_adaptive);
    let fp = footprint(uv, size, fb, probes, adaptive, &hw.lod, sat);
    if !trace.on {
        let r = footprint_filter(levels, u, v, fb, &fp, lfb, plan.wrap, &hw.trilinear, None);
        return (r, fp.probes);
    }
    let mut traces = [TrilinearTrace::default(); MAX_PROBES];
    let r = footprint_filter(
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
        trace.record(KIND, i as u32, t, tr);
    }
    (r, fp.probes)
}
