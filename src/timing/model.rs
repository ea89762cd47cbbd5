//! The timing model: replays a frame's events through units with throughputs and latencies,
//! a banked texture memory, an optional set-associative LRU texel cache and open-page DRAM.
//! Integer cycles, deterministic (one sequential pass in raster order).
//!
//! Frame = visibility pass + shading pass (the machine resolves visibility first, then shades
//! each covered pixel once; the passes do not overlap):
//! - Visibility pass: a two-stage pipeline, triangle setup (`setup_cycles` per triangle) then
//!   traversal (`span_cycles` per span plus `fragments / raster_fragments_per_cycle`). Only the
//!   totals are known, so its length is `max(setup_busy + traverse_busy / tris, setup_cycles +
//!   traverse_busy)`: the bottleneck stage plus one average item of the other.
//! - Shading pass: pixels issue at `shade_pixels_per_cycle`, in raster order, through their
//!   plan's stages. Each arithmetic stage kind is one unit: with `alu_pipelined` it accepts one
//!   pixel per cycle and its cycles (from the unit configs) are latency; otherwise it is busy
//!   for all of them. A texture stage runs its address/footprint unit (the stage's cycles
//!   beyond its trilinear samples, at least 1), then each lookup: its footprints go through
//!   the memory (in order), then the lookup goes to the earliest free trilinear unit
//!   (`ceil(footprints / bilinear_per_cycle)` busy cycles, latency = the filter's cycles). The
//!   stage completes when its last lookup is filtered. Queues between units are unbounded; a
//!   unit serves pixels in arrival order.
//! - Memory: texel (x, y) of a level is in bank `interleave(x, y)`. Per footprint each distinct
//!   texel is one bank access: a cache hit keeps its bank 1 cycle; a DRAM access (no cache, or
//!   a cache miss filling its line) keeps it `dram_page_hit_cycles` if the bank's open page is
//!   the texel's page, else `dram_page_miss_cycles` (and opens it). Banks work in parallel, so
//!   the footprint occupies the memory `max over banks of the summed busy cycles`; its latency
//!   is that plus `cache_hit_cycles` when there is a cache. Bank conflicts: accesses beyond the
//!   first in a bank within one footprint. Lines and pages are 2D tiles of texels whose count
//!   follows each texture's stored texel size (`TextureLayout::texel_bytes`), so a narrower map
//!   holds more texels per line and page. Texture bytes: each access's texel size; DRAM bytes:
//!   a line per cache miss, else the texel of each DRAM access.
//! - In flight: pixel `i` issues at `max(i / shade_pixels_per_cycle, done(i - n))` with
//!   `n = shade_pixels_in_flight`. Stalls: every cycle by which a pixel's issue is held back
//!   by a full window is attributed to the unit where the pixel it waited for (`i - n`) lost
//!   the most cycles waiting for a busy unit (memory, a filter unit or an arithmetic unit), or
//!   to `latency` if that pixel never waited (the window is too small for the latency). The
//!   stalls therefore sum to at most the shading pass. The memory's own time is split into
//!   bank-conflict cycles (serialization beyond the slowest single access) and miss cycles (a
//!   cache or page miss's cycles beyond a hit's), reported with the memory counters.

use super::events::{
    FrameEvents, PixelEvent, PlanTiming, RowEvents, TexelFootprint, TextureLayout,
};
use crate::pipeline::StageKind;
use hw_model::timing_config::{BankInterleave, TimingConfig};
use hw_model::trilinear::trilinear_cost;
use hw_model::HwConfig;
use serde::Serialize;

/// Busy cycles of one unit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct UnitReport {
    pub unit: String,
    pub busy_cycles: u64,
    /// busy / total cycles.
    pub utilization: f64,
    /// Texel bytes the unit's lookups read from the memory system (texture stages; else 0).
    pub texture_bytes: u64,
}

/// Stall cycles by cause.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StallReport {
    pub cause: String,
    pub cycles: u64,
}

/// Memory-system counters.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct MemoryReport {
    pub footprints: u64,
    /// Distinct texel accesses (a footprint on a 1-texel-wide level reads fewer than 4).
    pub texel_accesses: u64,
    pub cache_hits: u64,
    pub cache_misses: u64,
    /// hits / accesses; `None` without a cache.
    pub cache_hit_rate: Option<f64>,
    pub bank_conflicts: u64,
    /// Footprints with at least one bank conflict.
    pub conflicting_footprints: u64,
    pub dram_accesses: u64,
    pub dram_page_hits: u64,
    pub dram_page_misses: u64,
    /// Bytes of the texel accesses (each texel's stored size: what the filters read).
    pub texture_bytes: u64,
    /// Bytes moved from DRAM: a cache line per miss, or the texel of each access without a
    /// cache.
    pub dram_bytes: u64,
}

/// The timing model's result for one frame.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TimingReport {
    pub scene: String,
    pub hw: String,
    pub width: u32,
    pub height: u32,
    pub total_cycles: u64,
    pub visibility_pass_cycles: u64,
    pub shading_pass_cycles: u64,
    pub covered_pixels: u64,
    pub cycles_per_pixel: f64,
    pub units: Vec<UnitReport>,
    pub stalls: Vec<StallReport>,
    pub memory: MemoryReport,
    /// Memory cycles caused by bank conflicts (serialization within footprints).
    pub bank_conflict_cycles: u64,
    /// Memory cycles caused by cache and page misses (beyond a hit's).
    pub miss_cycles: u64,
    /// The unit with the most busy cycles, or [`LATENCY_BOTTLENECK`] when the shading pass
    /// loses more cycles to latency stalls (a full in-flight window whose oldest pixel never
    /// waited for a busy unit) than the busiest unit is busy.
    pub bottleneck: String,
    /// The bottleneck's busy cycles (or latency stall cycles).
    pub bottleneck_cycles: u64,
    /// Events consumed (pixels + footprints + triangles + spans).
    pub events: u64,
}

/// A set-associative texel cache with LRU replacement (each set ordered most recent first).
#[derive(Clone, Debug)]
pub struct Cache {
    sets: u64,
    ways: usize,
    tags: Vec<u64>,
}

const EMPTY: u64 = u64::MAX;

/// The bottleneck's name when latency, not throughput, limits the shading pass.
pub const LATENCY_BOTTLENECK: &str = "latency (in-flight window)";

impl Cache {
    /// A cache of `sets` x `ways` lines (both at least 1).
    #[must_use]
    pub fn new(sets: u64, ways: usize) -> Self {
        let sets = sets.max(1);
        let ways = ways.max(1);
        Self {
            sets,
            ways,
            tags: vec![EMPTY; sets as usize * ways],
        }
    }

    /// Looks up line `key` (set = key mod sets); on a miss the line is filled, evicting the
    /// least recently used way. Returns true on a hit.
    pub fn access(&mut self, key: u64) -> bool {
        let set_index = if self.sets.is_power_of_two() {
            key & (self.sets - 1)
        } else {
            key % self.sets
        };
        let s = set_index as usize * self.ways;
        let set = &mut self.tags[s..s + self.ways];
        // Move the line to the front: ways are few, so shift them one by one.
        let (last, hit) = match set.iter().position(|&t| t == key) {
            Some(i) => (i, true),
            None => (set.len() - 1, false),
        };
        for j in (1..=last).rev() {
            set[j] = set[j - 1];
        }
        set[0] = key;
        hit
    }
}

/// Square-ish 2D tile of `n` texels (a power of two): width `2^ceil(log2 n / 2)`.
fn tile(n: u32) -> (u32, u32) {
    let n = n.max(1);
    let lw = n.trailing_zeros().div_ceil(2);
    (1 << lw, n >> lw)
}

/// Address of one level: bases and tiles per row of its cache lines and DRAM pages, the log2
/// of the line and page tiles' width and height (from its texture's texel size) and that size.
#[derive(Clone, Copy, Debug)]
struct LevelAddr {
    width: u32,
    line_base: u64,
    line_row: u64,
    page_base: u64,
    page_row: u64,
    line_shift: (u32, u32),
    page_shift: (u32, u32),
    texel_bytes: u32,
}

/// The address record [`AddressMap::level`] answers for a footprint outside the frame's
/// textures: one texel.
const DUMMY_LEVEL: LevelAddr = LevelAddr {
    width: 1,
    line_base: 0,
    line_row: 1,
    page_base: 0,
    page_row: 1,
    line_shift: (0, 0),
    page_shift: (0, 0),
    texel_bytes: 1,
};

/// Address map of the textures: level base indices for cache lines and DRAM pages (tiles are
/// powers of two, so indices are shifts). The levels of every texture are in one list,
/// texture `t`'s from `first[t]` to `first[t + 1]`.
struct AddressMap {
    levels: Vec<LevelAddr>,
    first: Vec<usize>,
}

impl AddressMap {
    fn new(textures: &[TextureLayout], tc: &TimingConfig) -> Self {
        let (mut lb, mut pb) = (0u64, 0u64);
        let mut levels = Vec::new();
        let mut first = vec![0];
        for t in textures {
            let bytes = t.texel_bytes.max(1);
            let lt = tile(tc.cache_line_bytes / bytes);
            let pt = tile(tc.dram_page_bytes / bytes);
            for &(w, h) in &t.levels {
                let line_row = u64::from(w.div_ceil(lt.0));
                let page_row = u64::from(w.div_ceil(pt.0));
                levels.push(LevelAddr {
                    width: w,
                    line_base: lb,
                    line_row,
                    page_base: pb,
                    page_row,
                    line_shift: (lt.0.trailing_zeros(), lt.1.trailing_zeros()),
                    page_shift: (pt.0.trailing_zeros(), pt.1.trailing_zeros()),
                    texel_bytes: bytes,
                });
                lb += line_row * u64::from(h.div_ceil(lt.1));
                pb += page_row * u64::from(h.div_ceil(pt.1));
            }
            first.push(levels.len());
        }
        Self { levels, first }
    }

    /// The address record of a level (a dummy 1-texel level if out of range, which a
    /// render's event stream never produces: checked in debug builds).
    #[inline]
    fn level(&self, tex: u16, level: u8) -> &LevelAddr {
        let t = usize::from(tex);
        let i = self
            .first
            .get(t)
            .map_or(usize::MAX, |&f| f + usize::from(level));
        let end = self.first.get(t + 1).copied().unwrap_or(0);
        debug_assert!(
            i < end,
            "footprint of texture {tex} level {level} outside the frame's textures"
        );
        if i < end {
            &self.levels[i]
        } else {
            &DUMMY_LEVEL
        }
    }
}

/// The bank of texel (x, y) on a level of width `w`.
#[must_use]
pub fn bank_of(x: u32, y: u32, w: u32, banks: u32, mode: BankInterleave) -> usize {
    let b = banks.max(1);
    bank_in_tile(x, y, w, b, tile(b), mode)
}

/// [`bank_of`] with the bank tile of `b` banks (`tile(b)`) resolved.
#[inline]
fn bank_in_tile(x: u32, y: u32, w: u32, b: u32, t: (u32, u32), mode: BankInterleave) -> usize {
    match mode {
        BankInterleave::Tiled => ((x & (t.0 - 1)) + t.0 * (y & (t.1 - 1))) as usize,
        BankInterleave::Linear => {
            ((u64::from(y) * u64::from(w) + u64::from(x)) % u64::from(b)) as usize
        }
    }
}

/// Bank accesses of one footprint under an interleave: the distinct texels and their banks;
/// returns the number of conflicts (accesses beyond the first per bank).
#[must_use]
pub fn footprint_conflicts(fp: &TexelFootprint, w: u32, banks: u32, mode: BankInterleave) -> u32 {
    let mut count = [0u32; 64];
    let mut seen: [(u32, u32); 4] = [(u32::MAX, u32::MAX); 4];
    let mut n = 0;
    for (x, y) in texels(fp) {
        if seen[..n].contains(&(x, y)) {
            continue;
        }
        seen[n] = (x, y);
        n += 1;
        count[bank_of(x, y, w, banks, mode).min(63)] += 1;
    }
    count.iter().map(|&c| c.saturating_sub(1)).sum()
}

#[inline]
fn texels(fp: &TexelFootprint) -> [(u32, u32); 4] {
    [
        (fp.x[0], fp.y[0]),
        (fp.x[1], fp.y[0]),
        (fp.x[0], fp.y[1]),
        (fp.x[1], fp.y[1]),
    ]
}

/// Open-page state of the DRAM banks and the counters of the memory system.
struct Memory<'a> {
    tc: &'a TimingConfig,
    map: AddressMap,
    cache: Option<Cache>,
    open_page: Vec<u64>,
    /// Banks (at least 1) and the last bank's index.
    banks: u32,
    last_bank: usize,
    /// Tiled interleave: the bank tile's column and row masks and the log2 of its width, so
    /// `bank = (x & mask_x) | (y & mask_y) << shift` (the tile's width is a power of two).
    tile_mask: (u32, u32),
    tile_shift: u32,
    /// Linear interleave: `banks - 1` when the bank count is a power of two (`mod` is a
    /// mask), else 0 (the general `mod`).
    linear_mask: u64,
    /// DRAM page hit and miss cycles.
    page_hit: u64,
    page_miss: u64,
    counts: MemoryCounts,
}

/// The memory's running sums; [`MemoryCounts::report`] derives the rest of the report.
#[derive(Clone, Copy, Debug, Default)]
struct MemoryCounts {
    footprints: u64,
    accesses: u64,
    /// Bytes of the texel accesses.
    bytes: u64,
    cache_hits: u64,
    page_hits: u64,
    bank_conflicts: u64,
    conflicting_footprints: u64,
    conflict_cycles: u64,
    miss_cycles: u64,
}

impl MemoryCounts {
    /// The memory report: every access that misses the cache (all of them without one) goes
    /// to DRAM, and a DRAM access that does not hit its bank's open page misses it.
    fn report(&self, tc: &TimingConfig, cached: bool) -> MemoryReport {
        let dram = self.accesses - self.cache_hits;
        MemoryReport {
            footprints: self.footprints,
            texel_accesses: self.accesses,
            cache_hits: if cached { self.cache_hits } else { 0 },
            cache_misses: if cached { dram } else { 0 },
            cache_hit_rate: cached.then(|| self.cache_hits as f64 / self.accesses.max(1) as f64),
            bank_conflicts: self.bank_conflicts,
            conflicting_footprints: self.conflicting_footprints,
            dram_accesses: dram,
            dram_page_hits: self.page_hits,
            dram_page_misses: dram - self.page_hits,
            texture_bytes: self.bytes,
            dram_bytes: if cached {
                dram * u64::from(tc.cache_line_bytes)
            } else {
                self.bytes
            },
        }
    }
}

impl<'a> Memory<'a> {
    fn new(textures: &[TextureLayout], tc: &'a TimingConfig) -> Self {
        let cache = (tc.cache_bytes > 0).then(|| {
            let ways = tc.cache_ways.max(1);
            let sets = tc.cache_bytes / (tc.cache_line_bytes * ways);
            Cache::new(u64::from(sets), ways as usize)
        });
        let banks = tc.banks.max(1);
        let bank_tile = tile(banks);
        Self {
            tc,
            map: AddressMap::new(textures, tc),
            cache,
            open_page: vec![EMPTY; banks as usize],
            banks,
            last_bank: banks as usize - 1,
            tile_mask: (bank_tile.0 - 1, bank_tile.1 - 1),
            tile_shift: bank_tile.0.trailing_zeros(),
            linear_mask: if banks.is_power_of_two() {
                u64::from(banks - 1)
            } else {
                0
            },
            page_hit: u64::from(tc.dram_page_hit_cycles),
            page_miss: u64::from(tc.dram_page_miss_cycles),
            counts: MemoryCounts::default(),
        }
    }

    /// Performs one footprint's accesses; returns (occupancy, latency) in cycles and the texel
    /// bytes read. The distinct texels of the footprint, in the order (x0, y0), (x1, y0),
    /// (x0, y1), (x1, y1), are each one bank access (a footprint on a 1-texel-wide or -high
    /// level collapses its repeated columns or rows). Compiled with (`CACHED`) or without a
    /// texel cache, for the tiled (`TILED`) or linear bank interleave; a row's page (and line)
    /// index is computed once for its columns, and conflicts are counted as the accesses find
    /// their bank already used.
    #[inline(always)]
    fn footprint<const CACHED: bool, const TILED: bool>(
        &mut self,
        fp: &TexelFootprint,
    ) -> (u64, u64, u64) {
        let (page_hit, page_miss) = (self.page_hit, self.page_miss);
        let lv = *self.map.level(fp.tex, fp.level);
        let (tile_mask, tile_shift) = (self.tile_mask, self.tile_shift);
        let (linear_mask, banks, last_bank) = (self.linear_mask, self.banks, self.last_bank);
        // The bank of texel (x, y) ([`bank_of`] with the interleave's masks precomputed).
        let bank_of_texel = |x: u32, y: u32| -> usize {
            let b = if TILED {
                ((x & tile_mask.0) | ((y & tile_mask.1) << tile_shift)) as usize
            } else {
                let i = u64::from(y) * u64::from(lv.width) + u64::from(x);
                (if linear_mask != 0 {
                    i & linear_mask
                } else {
                    i % u64::from(banks)
                }) as usize
            };
            b.min(last_bank)
        };
        let cols = if fp.x[0] == fp.x[1] { 1 } else { 2 };
        let rows = if fp.y[0] == fp.y[1] { 1 } else { 2 };
        let (px, py) = lv.page_shift;
        let (lx, ly) = lv.line_shift;
        let page_col = fp.x.map(|x| u64::from(x >> px));
        let line_col = fp.x.map(|x| u64::from(x >> lx));
        let mut cache = self.cache.as_mut();
        let open_page = &mut self.open_page[..];
        let mut bank = [0usize; 4];
        let mut occs = [0u64; 4];
        let mut n = 0;
        let mut slowest = 0u64;
        let (mut hits, mut page_hits, mut used, mut conflicts) = (0u64, 0u64, 0u64, 0u64);
        for &y in fp.y.iter().take(rows) {
            let page_row = lv.page_base + u64::from(y >> py) * lv.page_row;
            let line_row = lv.line_base + u64::from(y >> ly) * lv.line_row;
            for c in 0..cols {
                let b = bank_of_texel(fp.x[c], y);
                let hit = CACHED
                    && cache
                        .as_mut()
                        .is_some_and(|cache| cache.access(line_row + line_col[c]));
                hits += u64::from(hit);
                let occ = if hit {
                    1
                } else {
                    let page = page_row + page_col[c];
                    let open = &mut open_page[b];
                    if *open == page {
                        page_hits += 1;
                        page_hit
                    } else {
                        *open = page;
                        page_miss
                    }
                };
                // Banks number at most 64 (`TimingConfig::validate`).
                let bit = 1u64 << (b & 63);
                conflicts += u64::from(used & bit != 0);
                used |= bit;
                bank[n & 3] = b;
                occs[n & 3] = occ;
                n += 1;
                slowest = slowest.max(occ);
            }
        }
        // Conflicts: accesses beyond the first in a bank. The footprint occupies the memory for
        // its busiest bank (the summed cycles of the bank's accesses; without a conflict, the
        // slowest access).
        let accesses = n as u64;
        let mut occ = slowest.max(1);
        if conflicts > 0 {
            for i in 0..n {
                let busy: u64 = (i..n)
                    .filter(|&j| bank[j] == bank[i])
                    .map(|j| occs[j])
                    .sum();
                occ = occ.max(busy);
            }
        }
        let bytes = accesses * u64::from(lv.texel_bytes);
        let (fastest, hit_latency) = if CACHED {
            (1, u64::from(self.tc.cache_hit_cycles))
        } else {
            (page_hit, 0)
        };
        let k = &mut self.counts;
        k.footprints += 1;
        k.accesses += accesses;
        k.bytes += bytes;
        k.cache_hits += hits;
        k.page_hits += page_hits;
        k.bank_conflicts += conflicts;
        k.conflicting_footprints += u64::from(conflicts > 0);
        k.conflict_cycles += occ - slowest.max(1);
        k.miss_cycles += slowest.saturating_sub(fastest);
        (occ, occ + hit_latency, bytes)
    }
}

/// A unit that serves requests in arrival order.
#[derive(Clone, Copy, Debug, Default)]
struct Unit {
    free: u64,
    busy: u64,
}

impl Unit {
    /// A request ready at `ready` occupying `occ` cycles: returns its start.
    #[inline]
    fn take(&mut self, ready: u64, occ: u64) -> u64 {
        let start = ready.max(self.free);
        self.free = start + occ;
        self.busy += occ;
        start
    }
}

/// `Simulator::pixel` keeps a pixel's fetching stage kinds in a 64-bit mask.
const _: () = assert!(StageKind::COUNT <= 64);

/// The footprints stage `k` fetched among a pixel's `fps`: the first run of `k`'s footprints.
/// Stages record their footprints in their plan's order, so when the plan's stage kinds are
/// distinct (`in_order`) the run at `cursor` is `k`'s if it is `k`'s at all and everything
/// before the cursor belongs to earlier stages; the cursor then moves past it. Otherwise the
/// footprints are searched.
#[inline]
fn stage_footprints<'f>(
    fps: &'f [TexelFootprint],
    cursor: &mut usize,
    k: usize,
    in_order: bool,
) -> &'f [TexelFootprint] {
    let run_from = |a: usize| {
        let b = fps[a..]
            .iter()
            .position(|f| usize::from(f.stage) != k)
            .map_or(fps.len(), |e| a + e);
        &fps[a..b]
    };
    if in_order && fps.get(*cursor).is_some_and(|f| usize::from(f.stage) == k) {
        let run = run_from(*cursor);
        *cursor += run.len();
        return run;
    }
    fps.iter()
        .position(|f| usize::from(f.stage) == k)
        .map_or(&[], run_from)
}

/// The counts of a frame's visibility pass (what the timing model needs beside its pixels).
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameCounts {
    pub width: u32,
    pub height: u32,
    /// Screen triangles after setup.
    pub triangles: u64,
    /// Non-empty spans of the visibility pass.
    pub spans: u64,
    /// Fragments (covered samples before the depth test) of the visibility pass.
    pub fragments: u64,
}

/// The shading pass of the timing model fed pixel by pixel in raster order ([`Simulator::row`]
/// or [`Simulator::pixel`]), so a render can run it on the rows it has shaded while it shades
/// the next ones; [`Simulator::finish`] adds the visibility pass and reports. Feeding a frame's
/// pixels in order gives exactly [`simulate`] of its events.
pub struct Simulator<'a> {
    hw: &'a HwConfig,
    /// Per plan, its stages as (kind index, cycles, arithmetic-unit occupancy).
    steps: Vec<Vec<(usize, u64, u64)>>,
    alu: Vec<Unit>,
    stage_bytes: Vec<u64>,
    mem_unit: Unit,
    filters: Vec<Unit>,
    mem: Memory<'a>,
    tri_cycles: u64,
    bilinear_lat: u64,
    blend_lat: u64,
    bpc: u64,
    ppc: u64,
    alu_pipelined: bool,
    /// Stall cycles by cause: 0..nk arithmetic units, nk memory, nk + 1 filters, nk + 2
    /// latency.
    stall_by: Vec<u64>,
    /// Completion time and worst cause of the last `shade_pixels_in_flight` pixels.
    ring: Vec<(u64, usize)>,
    last_issue: u64,
    end: u64,
    /// Pixels and footprints fed so far.
    pixels: u64,
    footprints: u64,
    /// The next pixel's issue group (`pixels / shade_pixels_per_cycle`), its place in that
    /// group (`pixels % shade_pixels_per_cycle`) and its ring slot (`pixels % ring.len()`),
    /// kept incrementally so the per-pixel step divides nothing.
    group: u64,
    in_group: u64,
    slot: usize,
    /// Per plan: its stage kinds are distinct, so a pixel's footprints (recorded in the
    /// plan's order) are matched to its stages by one cursor ([`Simulator::pixel`]).
    distinct: Vec<bool>,
}

impl<'a> Simulator<'a> {
    /// The model of machine `hw` for a frame with these plans and textures, before any pixel.
    #[must_use]
    pub fn new(plans: &[PlanTiming], textures: &[TextureLayout], hw: &'a HwConfig) -> Self {
        let tc = &hw.timing;
        let nk = StageKind::ALL.len();
        let glpc = tc.gate_levels_per_cycle;
        let tri_cost = trilinear_cost(&hw.trilinear, 2, glpc);
        let (bilinear_lat, blend_lat) = hw_model::trilinear::filter_latencies(&hw.trilinear, glpc);
        let alu_occ = |cycles: u64| {
            if tc.alu_pipelined {
                cycles.min(1)
            } else {
                cycles
            }
        };
        let steps = plans
            .iter()
            .map(|p| {
                p.stages
                    .iter()
                    .map(|&(kind, cost)| {
                        let c = u64::from(cost.cycles);
                        (kind.index(), c, alu_occ(c))
                    })
                    .collect()
            })
            .collect();
        let distinct = plans
            .iter()
            .map(|p| {
                let kinds = p.stages.iter().fold(0u64, |m, &(k, _)| m | 1 << k.index());
                kinds.count_ones() as usize == p.stages.len()
            })
            .collect();
        let win = tc.shade_pixels_in_flight.max(1) as usize;
        Self {
            hw,
            steps,
            alu: vec![Unit::default(); nk],
            stage_bytes: vec![0; nk],
            mem_unit: Unit::default(),
            filters: vec![Unit::default(); tc.trilinear_units.max(1) as usize],
            mem: Memory::new(textures, tc),
            tri_cycles: u64::from(tri_cost.cycles),
            bilinear_lat: u64::from(bilinear_lat),
            blend_lat: u64::from(blend_lat),
            bpc: u64::from(tc.bilinear_per_cycle.max(1)),
            ppc: u64::from(tc.shade_pixels_per_cycle.max(1)),
            alu_pipelined: tc.alu_pipelined,
            stall_by: vec![0; nk + 3],
            ring: vec![(0, nk + 2); win],
            last_issue: 0,
            end: 0,
            pixels: 0,
            footprints: 0,
            group: 0,
            in_group: 0,
            slot: 0,
            distinct,
        }
    }

    /// Feeds the pixels of one row in order (`fp_end` relative to the row's footprints).
    pub fn row(&mut self, row: &RowEvents) {
        self.pixels_of(&row.pixels, &row.footprints);
    }

    /// Feeds `pixels` in order; their `fp_end` index `footprints`, the previous pixel's end
    /// (0 for the first) being each one's start.
    fn pixels_of(&mut self, pixels: &[PixelEvent], footprints: &[TexelFootprint]) {
        let mut fp_start = 0usize;
        for px in pixels {
            let fp_end = (px.fp_end as usize).min(footprints.len());
            self.issue(px.plan, &footprints[fp_start.min(fp_end)..fp_end]);
            fp_start = fp_end;
        }
        self.footprints += footprints.len() as u64;
    }

    /// Issues the next covered pixel (raster order): plan index `plan`, the footprints its
    /// stages fetched in `fps` (counted as events), e.g. straight from the fragment's trace.
    #[inline]
    pub fn pixel(&mut self, plan: u32, fps: &[TexelFootprint]) {
        self.issue(plan, fps);
        self.footprints += fps.len() as u64;
    }

    /// [`Simulator::pixel`] without counting the footprints (the caller counts its list's).
    #[inline]
    fn issue(&mut self, plan: u32, fps: &[TexelFootprint]) {
        let tiled = self.mem.tc.bank_interleave == BankInterleave::Tiled;
        match (self.mem.cache.is_some(), tiled) {
            (true, true) => self.issue_in::<true, true>(plan, fps),
            (true, false) => self.issue_in::<true, false>(plan, fps),
            (false, true) => self.issue_in::<false, true>(plan, fps),
            (false, false) => self.issue_in::<false, false>(plan, fps),
        }
    }

    /// [`Simulator::issue`] with the memory's [`Memory::footprint`] compiled for the machine.
    #[inline(always)]
    fn issue_in<const CACHED: bool, const TILED: bool>(
        &mut self,
        plan: u32,
        fps: &[TexelFootprint],
    ) {
        let nk = self.alu.len();
        let (c_mem, c_filt, c_lat) = (nk, nk + 1, nk + 2);
        // Pixel i issues in group i / ppc, one cycle after the previous group's last pixel
        // when it opens a group (i % ppc == 0, i > 0), and waits for the pixel `win` places
        // before it (ring slot i % win) to complete.
        let next_slot = u64::from(self.pixels > 0 && self.in_group == 0);
        let ideal = self.group.max(self.last_issue + next_slot);
        let slot = self.slot;
        let mut t = ideal;
        if self.pixels >= self.ring.len() as u64 {
            let (done, cause) = self.ring[slot];
            if done > t {
                self.stall_by[cause] += done - t;
                t = done;
            }
        }
        self.pixels += 1;
        self.in_group += 1;
        if self.in_group == self.ppc {
            self.in_group = 0;
            self.group += 1;
        }
        self.slot = if slot + 1 == self.ring.len() {
            0
        } else {
            slot + 1
        };
        self.last_issue = t;
        let mut worst = (0u64, c_lat);
        let pi = plan as usize;
        let Some(plan) = self.steps.get(pi) else {
            self.ring[slot] = (t, c_lat);
            return;
        };
        // The stage kinds that fetched (stage kinds number fewer than 64).
        let fetched = fps.iter().fold(0u64, |m, f| m | 1u64 << (f.stage & 63));
        let cursor_ok = self.distinct[pi];
        let mut cursor = 0usize;
        for &(k, cycles, occ) in plan {
            let mine = if fetched & (1u64 << k) == 0 {
                &[][..]
            } else {
                stage_footprints(fps, &mut cursor, k, cursor_ok)
            };
            if mine.is_empty() {
                let s = self.alu[k].take(t, occ);
                if s - t > worst.0 {
                    worst = (s - t, k);
                }
                t = s + cycles;
                continue;
            }
            // Texture stage: address/footprint unit, then each lookup through memory + filter.
            let lookups = u64::from(mine[mine.len() - 1].lookup) + 1;
            let setup = cycles.saturating_sub(lookups * self.tri_cycles).max(1);
            let setup_occ = if self.alu_pipelined {
                setup.min(1)
            } else {
                setup
            };
            let s = self.alu[k].take(t, setup_occ);
            if s - t > worst.0 {
                worst = (s - t, k);
            }
            let ready = s + setup;
            let mut done = ready;
            let mut bytes = 0u64;
            // The footprints of one lookup are consecutive: `i` walks them lookup by lookup.
            let mut i = 0;
            while let Some(first) = mine.get(i) {
                let l = first.lookup;
                let mut data = ready;
                let mut nfp = 0u64;
                while let Some(f) = mine.get(i).filter(|f| f.lookup == l) {
                    let (occ, lat, b) = self.mem.footprint::<CACHED, TILED>(f);
                    bytes += b;
                    let ms = self.mem_unit.take(ready, occ);
                    if ms - ready > worst.0 {
                        worst = (ms - ready, c_mem);
                    }
                    data = data.max(ms + lat);
                    nfp += 1;
                    i += 1;
                }
                // `ceil(nfp / bpc)`; a shift when `bpc` is a power of two (no division).
                let occ = if self.bpc.is_power_of_two() {
                    (nfp + self.bpc - 1) >> self.bpc.trailing_zeros()
                } else {
                    nfp.div_ceil(self.bpc)
                };
                let lat = nfp * self.bilinear_lat + if nfp > 1 { self.blend_lat } else { 0 };
                let filters = &mut self.filters;
                let fu = if filters.len() == 1 {
                    0
                } else {
                    (0..filters.len())
                        .min_by_key(|&j| (filters[j].free.max(data), j))
                        .unwrap_or(0)
                };
                let fs = filters[fu].take(data, occ);
                if fs - data > worst.0 {
                    worst = (fs - data, c_filt);
                }
                done = done.max(fs + lat.max(occ));
            }
            self.stage_bytes[k] += bytes;
            t = done;
        }
        self.ring[slot] = (t, worst.1);
        self.end = self.end.max(t);
    }

    /// Adds the visibility pass of the frame (`f`) and reports.
    #[must_use]
    pub fn finish(self, f: &FrameCounts, scene: &str) -> TimingReport {
        let hw = self.hw;
        let tc = &hw.timing;
        let rc = &hw.raster;
        let nk = self.alu.len();
        let c_lat = nk + 2;
        let (c_mem, c_filt) = (nk, nk + 1);
        let (alu, stall_by, mem_unit, filters, stage_bytes) = (
            self.alu,
            self.stall_by,
            self.mem_unit,
            self.filters,
            self.stage_bytes,
        );
        let mem = self.mem;
        // Visibility pass.
        let setup_busy = f.triangles * u64::from(rc.setup_cycles);
        let traverse_busy = f.spans * u64::from(rc.span_cycles)
            + f.fragments
                .div_ceil(u64::from(tc.raster_fragments_per_cycle.max(1)));
        let vis = match traverse_busy.checked_div(f.triangles) {
            None => 0,
            Some(avg) => (setup_busy + avg).max(u64::from(rc.setup_cycles) + traverse_busy),
        };
        let events = self.pixels + self.footprints + f.triangles + f.spans;
        let covered = self.pixels;
        let shade = self.end;
        let total = vis + shade;
        let util = |b: u64| {
            if total == 0 {
                0.0
            } else {
                b as f64 / total as f64
            }
        };
        let mut units = vec![
            UnitReport {
                unit: "setup".into(),
                busy_cycles: setup_busy,
                utilization: util(setup_busy),
                texture_bytes: 0,
            },
            UnitReport {
                unit: "traverse".into(),
                busy_cycles: traverse_busy,
                utilization: util(traverse_busy),
                texture_bytes: 0,
            },
        ];
        for kind in StageKind::ALL {
            let b = alu[kind.index()].busy;
            units.push(UnitReport {
                unit: kind.name().into(),
                busy_cycles: b,
                utilization: util(b),
                texture_bytes: stage_bytes[kind.index()],
            });
        }
        units.push(UnitReport {
            unit: "memory".into(),
            busy_cycles: mem_unit.busy,
            utilization: util(mem_unit.busy),
            texture_bytes: 0,
        });
        for (j, f) in filters.iter().enumerate() {
            units.push(UnitReport {
                unit: format!("filter{j}"),
                busy_cycles: f.busy,
                utilization: util(f.busy),
                texture_bytes: 0,
            });
        }
        let busiest = units
            .iter()
            .fold(None::<&UnitReport>, |best, u| match best {
                Some(b) if b.busy_cycles >= u.busy_cycles => Some(b),
                _ => Some(u),
            })
            .map_or((String::new(), 0), |u| (u.unit.clone(), u.busy_cycles));
        // A frame whose pixels mostly wait for results (the in-flight window is too small for the
        // pipeline's latency) is bound by latency, not by any unit's throughput.
        let (bottleneck, bottleneck_cycles) = if stall_by[c_lat] > busiest.1 {
            (LATENCY_BOTTLENECK.to_string(), stall_by[c_lat])
        } else {
            busiest
        };
        let mut stalls = vec![StallReport {
            cause: "traverse waits for setup".into(),
            cycles: vis.saturating_sub(traverse_busy),
        }];
        for kind in StageKind::ALL {
            stalls.push(StallReport {
                cause: format!("{} busy", kind.name()),
                cycles: stall_by[kind.index()],
            });
        }
        for (cause, i) in [
            ("memory busy", c_mem),
            ("filter busy", c_filt),
            ("latency", c_lat),
        ] {
            stalls.push(StallReport {
                cause: cause.into(),
                cycles: stall_by[i],
            });
        }
        let memory = mem.counts.report(tc, mem.cache.is_some());
        TimingReport {
            scene: scene.to_string(),
            hw: hw.name.clone(),
            width: f.width,
            height: f.height,
            total_cycles: total,
            visibility_pass_cycles: vis,
            shading_pass_cycles: shade,
            covered_pixels: covered,
            cycles_per_pixel: total as f64 / covered.max(1) as f64,
            units,
            stalls,
            memory,
            bank_conflict_cycles: mem.counts.conflict_cycles,
            miss_cycles: mem.counts.miss_cycles,
            bottleneck,
            bottleneck_cycles,
            events,
        }
    }
}

/// Runs the timing model over `ev` on machine `hw`.
#[must_use]
pub fn simulate(ev: &FrameEvents, hw: &HwConfig, scene: &str) -> TimingReport {
    let mut sim = Simulator::new(&ev.plans, &ev.textures, hw);
    sim.pixels_of(&ev.pixels, &ev.footprints);
    sim.finish(&ev.counts(), scene)
}
