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
        // The most recent line: nothing moves.
        if set[0] == key {
            return true;
        }
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
/// powers of two, so indices are shifts). The levels of every texture are in one table of
/// `2^shift` entries per texture: texture `t`'s level `l` is entry `t << shift | l`, the
/// entries beyond a texture's levels being the dummy level; `first` (texture `t`'s levels are
/// `first[t]..first[t + 1]` in order) checks a lookup in debug builds. `recent` keeps the
/// last level resolved by [`AddressMap::level_recent`] per level parity (a trilinear lookup's
/// two footprints are on neighbouring levels) with its key `tex << 8 | level` (`u32::MAX`:
/// none).
#[derive(Clone)]
struct AddressMap {
    table: Vec<LevelAddr>,
    shift: u32,
    first: Vec<usize>,
    recent: [(u32, LevelAddr); 2],
}

impl AddressMap {
    fn new(textures: &[TextureLayout], tc: &TimingConfig) -> Self {
        let (mut lb, mut pb) = (0u64, 0u64);
        let most = textures.iter().map(|t| t.levels.len()).max().unwrap_or(0);
        let shift = most.next_power_of_two().trailing_zeros();
        let mut table = vec![DUMMY_LEVEL; textures.len() << shift];
        let mut first = vec![0];
        for (ti, t) in textures.iter().enumerate() {
            let bytes = t.texel_bytes.max(1);
            let lt = tile(tc.cache_line_bytes / bytes);
            let pt = tile(tc.dram_page_bytes / bytes);
            for (li, &(w, h)) in t.levels.iter().enumerate() {
                let line_row = u64::from(w.div_ceil(lt.0));
                let page_row = u64::from(w.div_ceil(pt.0));
                table[ti << shift | li] = LevelAddr {
                    width: w,
                    line_base: lb,
                    line_row,
                    page_base: pb,
                    page_row,
                    line_shift: (lt.0.trailing_zeros(), lt.1.trailing_zeros()),
                    page_shift: (pt.0.trailing_zeros(), pt.1.trailing_zeros()),
                    texel_bytes: bytes,
                };
                lb += line_row * u64::from(h.div_ceil(lt.1));
                pb += page_row * u64::from(h.div_ceil(pt.1));
            }
            first.push(first[ti] + t.levels.len());
        }
        Self {
            table,
            shift,
            first,
            recent: [(u32::MAX, DUMMY_LEVEL); 2],
        }
    }

    /// [`AddressMap::level`] through `recent`: a level resolved by the previous call of its
    /// parity is not looked up again.
    #[inline(always)]
    fn level_recent(&mut self, tex: u16, level: u8) -> &LevelAddr {
        let key = u32::from(tex) << 8 | u32::from(level);
        let i = usize::from(level & 1);
        if self.recent[i].0 != key {
            self.recent[i] = (key, *self.level(tex, level));
        }
        &self.recent[i].1
    }

    /// The address record of a level (a dummy 1-texel level if out of range, which a
    /// render's event stream never produces: checked in debug builds).
    #[inline]
    fn level(&self, tex: u16, level: u8) -> &LevelAddr {
        let (t, l) = (usize::from(tex), usize::from(level));
        debug_assert!(
            self.first
                .get(t + 1)
                .is_some_and(|&end| self.first[t] + l < end),
            "footprint of texture {tex} level {level} outside the frame's textures"
        );
        if l >> self.shift == 0 {
            self.table.get(t << self.shift | l).unwrap_or(&DUMMY_LEVEL)
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
#[derive(Clone)]
struct Memory {
    map: AddressMap,
    cache: Option<Cache>,
    /// Per bank its open DRAM page (banks number at most 64: `TimingConfig::validate`).
    open_page: [u64; 64],
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
    /// Tiled interleave with a power-of-two bank count (at most 64): `tile_mask`, else
    /// (0, 0). A texel's bank is then its tile bits (no clamp), so a footprint whose columns
    /// and rows differ in these bits reads 4 banks (never with (0, 0)).
    quad_mask: (u32, u32),
    /// `quad_mask` is (1, 1) with a bank tile 2 wide: the four banks of a four-bank
    /// footprint are banks 0..4, one per (column, row) parity ([`Memory::quad_dram`]).
    quad4: bool,
    /// Latency a cache adds to a footprint (`cache_hit_cycles`).
    hit_latency: u64,
    /// [`Memory::quad_dram`]'s occupancy by the number of its page hits (0..=4; 8 slots so a
    /// mask indexes it).
    quad_occ: [u64; 8],
    counts: MemoryCounts,
    /// The counts of [`Memory::quad_dram`]'s footprints (added to `counts` by
    /// [`MemoryCounts::total`]).
    quads: QuadCounts,
}

/// The four-bank footprints without a cache ([`Memory::quad_dram`]; 4 DRAM accesses each)
/// by their number of page hits (0..=4; 8 slots so a mask indexes them).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct QuadCounts {
    by_hits: [u64; 8],
}

/// The memory's running sums; [`MemoryCounts::report`] derives the rest of the report.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct MemoryCounts {
    footprints: u64,
    accesses: u64,
    cache_hits: u64,
    page_hits: u64,
    bank_conflicts: u64,
    conflicting_footprints: u64,
    conflict_cycles: u64,
    miss_cycles: u64,
}

impl MemoryCounts {
    /// These counts with the four-bank footprints `q` added (`page_hit`, `page_miss`: the
    /// DRAM's page hit and miss cycles).
    fn total(&self, q: &QuadCounts, page_hit: u64, page_miss: u64) -> MemoryCounts {
        let footprints: u64 = q.by_hits.iter().sum();
        let page_hits: u64 = (0u64..).zip(q.by_hits).map(|(h, n)| h * n).sum();
        // A footprint with a page miss lasts a miss: `page_miss - page_hit` (at least 0)
        // cycles beyond a hit's.
        let missing = footprints - q.by_hits[4];
        MemoryCounts {
            footprints: self.footprints + footprints,
            accesses: self.accesses + 4 * footprints,
            page_hits: self.page_hits + page_hits,
            miss_cycles: self.miss_cycles + missing * page_miss.saturating_sub(page_hit),
            ..*self
        }
    }

    /// The memory report (`bytes`: the texel accesses' bytes): every access that misses the
    /// cache (all of them without one) goes to DRAM, and a DRAM access that does not hit its
    /// bank's open page misses it.
    fn report(&self, tc: &TimingConfig, cached: bool, bytes: u64) -> MemoryReport {
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
            texture_bytes: bytes,
            dram_bytes: if cached {
                dram * u64::from(tc.cache_line_bytes)
            } else {
                bytes
            },
        }
    }
}

impl Memory {
    fn new(textures: &[TextureLayout], tc: &TimingConfig) -> Self {
        let cache = (tc.cache_bytes > 0).then(|| {
            let ways = tc.cache_ways.max(1);
            let sets = tc.cache_bytes / (tc.cache_line_bytes * ways);
            Cache::new(u64::from(sets), ways as usize)
        });
        let banks = tc.banks.max(1);
        let bank_tile = tile(banks);
        // A four-bank footprint is as long as its slowest access, at least 1 cycle.
        let (hit, miss) = (tc.dram_page_hit_cycles, tc.dram_page_miss_cycles);
        let some = u64::from(hit.max(miss).max(1));
        let mut quad_occ = [0; 8];
        quad_occ[..5].copy_from_slice(&[
            u64::from(miss.max(1)),
            some,
            some,
            some,
            u64::from(hit.max(1)),
        ]);
        let quad_mask = if tc.bank_interleave == BankInterleave::Tiled
            && banks.is_power_of_two()
            && banks <= 64
        {
            (bank_tile.0 - 1, bank_tile.1 - 1)
        } else {
            (0, 0)
        };
        Self {
            map: AddressMap::new(textures, tc),
            cache,
            open_page: [EMPTY; 64],
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
            hit_latency: u64::from(tc.cache_hit_cycles),
            quad_occ,
            quad4: quad_mask == (1, 1) && bank_tile.0 == 2,
            quad_mask,
            counts: MemoryCounts::default(),
            quads: QuadCounts::default(),
        }
    }

    /// Performs one footprint's accesses; returns its occupancy in cycles (its latency adds
    /// `hit_latency` with a cache) and the texel bytes read ([`Memory::footprint_any`], with a fast
    /// path for the common footprint: on a tiled interleave with a power-of-two bank count, two
    /// columns and two rows whose bank bits differ put the four texels in four banks, so there is
    /// no conflict and the bank accesses are independent; a texel whose cache line is the previous
    /// texel's hits without a lookup, that line being the most recent of its set). Checked against
    /// the general path by `fast_footprints_match_the_general_path` and against the previous model.
    #[inline(always)]
    fn footprint<const CACHED: bool, const TILED: bool>(
        &mut self,
        fp: &TexelFootprint,
    ) -> (u64, u64) {
        let (m0, m1) = self.quad_mask;
        if !(TILED && (fp.x[0] ^ fp.x[1]) & m0 != 0 && (fp.y[0] ^ fp.y[1]) & m1 != 0) {
            return self.footprint_any::<CACHED, TILED>(fp);
        }
        if !CACHED {
            return self.quad_dram(fp);
        }
        let lv = self.map.level_recent(fp.tex, fp.level);
        let sh = self.tile_shift;
        let bank_col = fp.x.map(|x| (x & m0) as usize);
        let bank_row = fp.y.map(|y| ((y & m1) << sh) as usize);
        let (px, py) = lv.page_shift;
        let (lx, ly) = lv.line_shift;
        let page_col = fp.x.map(|x| u64::from(x >> px));
        let page_row =
            fp.y.map(|y| lv.page_base + u64::from(y >> py) * lv.page_row);
        let line_col = fp.x.map(|x| u64::from(x >> lx));
        let line_row =
            fp.y.map(|y| lv.line_base + u64::from(y >> ly) * lv.line_row);
        let texel_bytes = u64::from(lv.texel_bytes);
        let (page_hit, page_miss) = (self.page_hit, self.page_miss);
        let open_page = &mut self.open_page;
        let mut cache = self.cache.as_mut();
        let mut last_line = None;
        let (mut hits, mut page_hits, mut slowest) = (0u64, 0u64, 0u64);
        for (r, c) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
            let hit = CACHED && {
                let line = line_row[r] + line_col[c];
                let hit = last_line == Some(line)
                    || cache.as_mut().is_some_and(|cache| cache.access(line));
                last_line = Some(line);
                hit
            };
            hits += u64::from(hit);
            let occ = if hit {
                1
            } else {
                let page = page_row[r] + page_col[c];
                let open = &mut open_page[(bank_col[c] | bank_row[r]) & 63];
                if *open == page {
                    page_hits += 1;
                    page_hit
                } else {
                    *open = page;
                    page_miss
                }
            };
            slowest = slowest.max(occ);
        }
        let occ = slowest.max(1);
        let bytes = 4 * texel_bytes;
        let fastest = if CACHED { 1 } else { page_hit };
        let k = &mut self.counts;
        k.footprints += 1;
        k.accesses += 4;
        k.cache_hits += hits;
        k.page_hits += page_hits;
        k.miss_cycles += slowest.saturating_sub(fastest);
        (occ, bytes)
    }

    /// [`Memory::footprint`]'s four-bank footprint without a cache: each texel a DRAM access
    /// to its own bank (hit if the bank's open page is the texel's, which it opens), the
    /// footprint as long as its slowest access; counted in [`Memory::quads`]. With four banks
    /// ([`Memory::quad4`]) the texels' banks are the first texel's with its parity bits flipped.
    #[inline(always)]
    fn quad_dram(&mut self, fp: &TexelFootprint) -> (u64, u64) {
        let lv = self.map.level_recent(fp.tex, fp.level);
        let pages = quad_pages(lv, fp);
        let bytes = 4 * u64::from(lv.texel_bytes);
        let [x0, x1] = fp.x;
        let [y0, y1] = fp.y;
        let hits = match self.open_page.first_chunk_mut::<4>() {
            Some(open) if self.quad4 => quad4_hits(open, quad4_bank(fp), pages),
            _ => {
                let (m0, m1) = self.quad_mask;
                let sh = self.tile_shift;
                let (b0, b1) = ((x0 & m0) as usize, (x1 & m0) as usize);
                let (s0, s1) = (((y0 & m1) << sh) as usize, ((y1 & m1) << sh) as usize);
                let banks = [b0 | s0, b1 | s0, b0 | s1, b1 | s1];
                let mut hits = 0;
                for (bank, page) in banks.into_iter().zip(pages) {
                    let o = &mut self.open_page[bank & 63];
                    hits += usize::from(*o == page);
                    *o = page;
                }
                hits
            }
        };
        let occ = self.quad_occ[hits & 7];
        self.quads.by_hits[hits & 7] += 1;
        (occ, bytes)
    }

    /// Performs one footprint's accesses, any footprint; returns its occupancy in cycles (its
    /// latency adds `hit_latency` with a cache) and the texel bytes read. The distinct texels of
    /// the footprint, in the order (x0, y0), (x1, y0), (x0, y1), (x1, y1), are each one bank access
    /// (a footprint on a 1-texel-wide or -high level collapses its repeated columns or rows).
    /// Compiled with (`CACHED`) or without a texel cache, for the tiled (`TILED`) or linear bank
    /// interleave; a row's page (and line) index is computed once for its columns, and conflicts
    /// are counted as the accesses find their bank already used.
    #[inline(never)]
    fn footprint_any<const CACHED: bool, const TILED: bool>(
        &mut self,
        fp: &TexelFootprint,
    ) -> (u64, u64) {
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
        let two_cols = fp.x[0] != fp.x[1];
        let two_rows = fp.y[0] != fp.y[1];
        let (px, py) = lv.page_shift;
        let (lx, ly) = lv.line_shift;
        let page_col = fp.x.map(|x| u64::from(x >> px));
        let line_col = fp.x.map(|x| u64::from(x >> lx));
        let mut cache = self.cache.as_mut();
        let open_page = &mut self.open_page;
        let mut acc = Accesses::default();
        // One texel access: column `c` of row `y` (whose page and line rows are given).
        let mut access = |c: usize, y: u32, page_row: u64, line_row: u64| {
            let b = bank_of_texel(fp.x[c], y);
            let hit = CACHED
                && cache
                    .as_mut()
                    .is_some_and(|cache| cache.access(line_row + line_col[c]));
            acc.hits += u64::from(hit);
            let occ = if hit {
                1
            } else {
                let page = page_row + page_col[c];
                let open = &mut open_page[b & 63];
                if *open == page {
                    acc.page_hits += 1;
                    page_hit
                } else {
                    *open = page;
                    page_miss
                }
            };
            // Banks number at most 64 (`TimingConfig::validate`).
            let bit = 1u64 << (b & 63);
            acc.conflicts += u64::from(acc.used & bit != 0);
            acc.used |= bit;
            acc.bank[acc.n & 3] = b;
            acc.occ[acc.n & 3] = occ;
            acc.n += 1;
            acc.slowest = acc.slowest.max(occ);
        };
        let rows_of = |y: u32| {
            (
                lv.page_base + u64::from(y >> py) * lv.page_row,
                lv.line_base + u64::from(y >> ly) * lv.line_row,
            )
        };
        let (p0, l0) = rows_of(fp.y[0]);
        access(0, fp.y[0], p0, l0);
        if two_cols {
            access(1, fp.y[0], p0, l0);
        }
        if two_rows {
            let (p1, l1) = rows_of(fp.y[1]);
            access(0, fp.y[1], p1, l1);
            if two_cols {
                access(1, fp.y[1], p1, l1);
            }
        }
        let Accesses {
            bank,
            occ: occs,
            n,
            slowest,
            hits,
            page_hits,
            conflicts,
            ..
        } = acc;
        // Conflicts: accesses beyond the first in a bank. The footprint occupies the memory for
        // its busiest bank (the summed cycles of the bank's accesses; without a conflict, the
        // slowest access).
        let accesses = n as u64;
        let mut occ = slowest.max(1);
        let k = &mut self.counts;
        if conflicts > 0 {
            for i in 0..n {
                let busy: u64 = (i..n)
                    .filter(|&j| bank[j] == bank[i])
                    .map(|j| occs[j])
                    .sum();
                occ = occ.max(busy);
            }
            k.bank_conflicts += conflicts;
            k.conflicting_footprints += 1;
            k.conflict_cycles += occ - slowest.max(1);
        }
        let bytes = accesses * u64::from(lv.texel_bytes);
        let fastest = if CACHED { 1 } else { page_hit };
        k.footprints += 1;
        k.accesses += accesses;
        k.cache_hits += hits;
        k.page_hits += page_hits;
        k.miss_cycles += slowest.saturating_sub(fastest);
        (occ, bytes)
    }
}

/// The DRAM pages of a footprint's texels (x0, y0), (x1, y0), (x0, y1), (x1, y1) on level `lv`.
#[inline(always)]
fn quad_pages(lv: &LevelAddr, fp: &TexelFootprint) -> [u64; 4] {
    let (px, py) = lv.page_shift;
    let (c0, c1) = (u64::from(fp.x[0] >> px), u64::from(fp.x[1] >> px));
    let r0 = lv.page_base + u64::from(fp.y[0] >> py) * lv.page_row;
    let r1 = lv.page_base + u64::from(fp.y[1] >> py) * lv.page_row;
    [r0 + c0, r0 + c1, r1 + c0, r1 + c1]
}

/// With four banks tiled 2x2 (bank `x & 1 | (y & 1) << 1`), the bank of a four-bank
/// footprint's first texel: its columns and rows differ in parity, so its texels' banks are
/// this one with bits flipped ([`quad4_hits`]).
#[inline(always)]
fn quad4_bank(fp: &TexelFootprint) -> usize {
    ((fp.x[0] & 1) | (fp.y[0] & 1) << 1) as usize
}

/// The page hits of a four-bank footprint's texels, pages `pages` ([`quad_pages`]), in banks
/// `b`, `b ^ 1`, `b ^ 2` and `b ^ 3` of `open` (the four banks' open pages): each access hits
/// if its bank's open page is its page, which it opens.
#[inline(always)]
fn quad4_hits(open: &mut [u64; 4], b: usize, pages: [u64; 4]) -> usize {
    let mut hits = 0;
    for (flip, page) in (0..4).zip(pages) {
        let o = &mut open[(b ^ flip) & 3];
        hits += usize::from(*o == page);
        *o = page;
    }
    hits
}

/// The bank accesses of one footprint so far ([`Memory::footprint`]): each one's bank and
/// cycles, their count, the slowest, the cache and page hits, the banks used (a bit each)
/// and the conflicts.
#[derive(Default)]
struct Accesses {
    bank: [usize; 4],
    occ: [u64; 4],
    n: usize,
    slowest: u64,
    hits: u64,
    page_hits: u64,
    used: u64,
    conflicts: u64,
}

/// One lookup's footprints through the memory: their count, summed occupancy, the last one's
/// occupancy and their texel bytes ([`Texturing::lookup_timed`]).
#[derive(Clone, Copy, Debug, Default)]
struct Fetched {
    n: usize,
    occ: u64,
    last: u64,
    bytes: u64,
}

impl Fetched {
    /// When the data of these footprints, reached at `ready`, leaves the memory unit `mem`
    /// (plus a cache's `hit_latency`): they take it as one request of their summed occupancy,
    /// the last one starting latest (the longest wait, charged to `worst`) and ready last.
    #[inline(always)]
    fn through_memory(
        &self,
        mem: &mut Unit,
        ready: u64,
        hit_latency: u64,
        worst: &mut (u64, usize),
    ) -> u64 {
        if self.n == 0 {
            return ready;
        }
        let ms = mem.take(ready, self.occ) + self.occ - self.last;
        if ms - ready > worst.0 {
            *worst = (ms - ready, C_MEM);
        }
        ms + self.last + hit_latency
    }
}

/// A lookup whose data is ready at `data` on the filter unit `unit`, of (occupancy,
/// occupancy-or-latency) `cost` ([`filter_cost`]): returns when its result is ready and
/// updates the pixel's worst wait.
#[inline(always)]
fn filter_on(unit: &mut Unit, data: u64, (occ, lat): (u64, u64), worst: &mut (u64, usize)) -> u64 {
    let fs = unit.take(data, occ);
    if fs - data > worst.0 {
        *worst = (fs - data, C_FILT);
    }
    fs + lat
}

/// A unit that serves requests in arrival order.
#[derive(Clone, Copy, Debug, Default)]
struct Unit {
    free: u64,
    busy: u64,
}

impl Unit {
    /// A request ready at `ready` occupying `occ` cycles: returns its start. (`busy` wraps: an
    /// arithmetic unit's is a sum of signed corrections until [`Simulator::finish`] adds its
    /// plans' steps, exact modulo 2^64 like the true sum.)
    #[inline]
    fn take(&mut self, ready: u64, occ: u64) -> u64 {
        self.busy = self.busy.wrapping_add(occ);
        self.take_free(ready, occ)
    }

    /// [`Unit::take`] without counting the busy cycles (the caller counts them).
    #[inline]
    fn take_free(&mut self, ready: u64, occ: u64) -> u64 {
        let start = ready.max(self.free);
        self.free = start + occ;
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

/// The unit among `units` (not empty) that can start a request ready at `data` first (the
/// lowest index among equals).
#[inline(never)]
fn earliest(units: &[Unit], data: u64) -> usize {
    (0..units.len())
        .min_by_key(|&j| (units[j].free.max(data), j))
        .unwrap_or(0)
}

/// A filter unit's (occupancy, occupancy-or-latency) for a lookup of `nfp` footprints at
/// `bpc` bilinear footprints per cycle: it is busy `ceil(nfp / bpc)` cycles and its result is
/// ready `nfp` bilinear latencies plus the level blend's (two or more footprints) after it
/// starts, or when it frees if later.
fn filter_cost(nfp: u64, bpc: u64, bilinear_lat: u64, blend_lat: u64) -> (u64, u64) {
    let occ = nfp.div_ceil(bpc);
    let lat = nfp * bilinear_lat + if nfp > 1 { blend_lat } else { 0 };
    (occ, lat.max(occ))
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

/// The shading pass of the timing model fed pixel by pixel in raster order ([`Simulator::row`],
/// [`Simulator::span`] or [`Simulator::pixel`]), so a render can run it on the rows it has
/// shaded while it shades the next ones; [`Simulator::finish`] adds the visibility pass and
/// reports. Feeding a frame's pixels in order gives exactly [`simulate`] of its events.
pub struct Simulator<'a> {
    hw: &'a HwConfig,
    /// Every plan's stages, plan after plan ([`PlanSteps`] says where each plan's are).
    steps: Vec<Step>,
    plans: Vec<PlanSteps>,
    /// Per stage kind (index below [`KINDS`]) its arithmetic unit. Its busy cycles are those
    /// of the texture stages that ran on it minus their steps' arithmetic occupancy; every
    /// pixel of a plan is counted in `plan_pixels`, and [`Simulator::finish`] adds each plan's
    /// steps' occupancy that many times.
    alu: [Unit; KINDS],
    plan_pixels: Vec<u64>,
    /// The texture side: memory, filter units and their costs.
    tex: Texturing,
    ppc: u64,
    /// Stall cycles by cause: 0..nk arithmetic units, nk memory, nk + 1 filters, nk + 2
    /// latency (nk = `StageKind::COUNT`; causes below [`CAUSES`]).
    stall_by: [u64; CAUSES],
    /// Completion time and worst cause of the last `shade_pixels_in_flight` pixels.
    ring: Vec<(u64, usize)>,
    /// Where the issue stands (kept in locals while a batch of pixels is fed).
    at: IssueState,
    /// Footprints fed so far.
    footprints: u64,
    /// The pixels that skipped units, not settled yet ([`Lazy`]).
    lazy: Option<Lazy>,
    /// The machine's memory compiled into the walk: a texel cache, a tiled interleave.
    cached: bool,
    tiled: bool,
}

/// The issue's running state: pixels fed, the pixels left in the current issue group (0:
/// the next pixel opens one) and the next pixel's ring slot (`pixels % ring.len()`), kept
/// incrementally so the per-pixel step divides nothing; the last issue and the latest
/// completion.
#[derive(Clone, Copy, Debug, Default)]
struct IssueState {
    pixels: u64,
    left: u64,
    slot: usize,
    last_issue: u64,
    end: u64,
}

impl IssueState {
    /// Issues the next pixel: returns its ring slot and issue cycle (held back by the pixel
    /// `ring.len()` places before it, whose wait is charged to its worst cause in `stall_by`).
    #[inline(always)]
    fn issue(
        &mut self,
        ring: &[(u64, usize)],
        stall_by: &mut [u64; CAUSES],
        ppc: u64,
    ) -> (usize, u64) {
        // Pixel i issues at cycle i / ppc at the earliest, one cycle after the previous
        // group's last pixel when it opens a group (i % ppc == 0, i > 0), and waits for the
        // pixel `win` places before it (ring slot i % win) to complete. Every pixel issues no
        // earlier than its group's cycle, so the previous pixel's issue (plus 1 when this one
        // opens a group) is never earlier than this one's group: it alone bounds the issue.
        // The ring starts with completions at 0, which hold no pixel back.
        let slot = self.slot;
        let opens = self.left == 0;
        if opens {
            self.left = ppc;
        }
        self.left -= 1;
        let mut t = self.last_issue + u64::from(opens);
        let (done, cause) = ring[slot];
        if done > t {
            stall_by[cause & (CAUSES - 1)] += done - t;
            t = done;
        }
        self.pixels += 1;
        self.slot = if slot + 1 == ring.len() { 0 } else { slot + 1 };
        self.last_issue = t;
        (slot, t)
    }
}

/// The texture side of the shading pass: the memory, its unit, the filter units, the texel
/// bytes per stage kind and the costs a texture stage needs.
struct Texturing {
    mem: Memory,
    mem_unit: Unit,
    filters: Vec<Unit>,
    /// Per stage kind (index below [`KINDS`]) the texel bytes its lookups read.
    stage_bytes: [u64; KINDS],
    tri_cycles: u64,
    bilinear_lat: u64,
    blend_lat: u64,
    bpc: u64,
    /// [`filter_cost`] of a lookup of 0, 1, 2 and 3 footprints.
    filter_cost: [(u64, u64); 4],
    alu_pipelined: bool,
}

/// Slots of the per-stage-kind arrays (stage kinds number at most 64), indexed by
/// `kind & (KINDS - 1)`.
const KINDS: usize = 64;
/// Slots of the stall causes (stage kinds, memory, filters, latency), indexed by
/// `cause & (CAUSES - 1)`.
const CAUSES: usize = 128;
const _: () = assert!(StageKind::COUNT + 3 <= CAUSES);

/// One stage of a plan as the model walks it: its kind index, cycles and arithmetic-unit
/// occupancy.
#[derive(Clone, Copy, Debug)]
struct Step {
    k: usize,
    cycles: u64,
    occ: u64,
}

/// Where a plan's stages are in [`Simulator::steps`] (`start..end`), and whether its stage
/// kinds are distinct: then a pixel's footprints (recorded in the plan's order) are matched
/// to its stages by one cursor ([`stage_footprints`]). `mono`: with distinct kinds of which
/// exactly one makes texture lookups on the machine, that stage ([`Mono`]).
#[derive(Clone, Copy, Debug)]
struct PlanSteps {
    start: usize,
    end: usize,
    distinct: bool,
    mono: Option<Mono>,
}

/// A plan's one fetching stage: its place in the plan, its address/footprint unit's (cycles,
/// occupancy) for one lookup ([`Texturing::setup`]), the cycles of the steps before it and
/// whether a pixel may skip those steps and that unit ([`settle`]: one pixel issued per cycle,
/// and those steps and that unit occupying their units at most 1 cycle).
#[derive(Clone, Copy, Debug)]
struct Mono {
    at: usize,
    setup: (u64, u64),
    pre_cycles: u64,
    lazy_ok: bool,
}

impl PlanSteps {
    /// The plan's one fetching stage ([`PlanSteps::mono`]) in `steps` (every plan's), with its
    /// [`Mono`].
    #[inline(always)]
    fn one<'s>(&self, steps: &'s [Step]) -> Option<(OneStage<'s>, Mono)> {
        let m = self.mono?;
        let steps = steps.get(self.start..self.end)?;
        let (pre, rest) = steps.split_at(m.at.min(steps.len()));
        let (&step, post) = rest.split_first()?;
        Some((OneStage { pre, step, post }, m))
    }
}

/// Pixels of plan `plan` that skipped the steps before its fetching stage and its
/// address/footprint unit ([`settle`]): the issue `t` of the last pixel of the run that
/// started waiting for none of them, and the number `n` that skipped them. Kept across
/// [`Simulator::run_in`]'s calls for the plan and settled before anything else reads or uses
/// those units.
#[derive(Clone, Copy, Debug)]
struct Lazy {
    plan: u32,
    t: u64,
    n: u64,
}

impl<'a> Simulator<'a> {
    /// The model of machine `hw` for a frame with these plans and textures, before any pixel.
    #[must_use]
    pub fn new(plans: &[PlanTiming], textures: &[TextureLayout], hw: &'a HwConfig) -> Self {
        let tc = &hw.timing;
        let glpc = tc.gate_levels_per_cycle;
        let tri_cost = trilinear_cost(&hw.trilinear, 2, glpc);
        let (tri_cycles, pipelined) = (u64::from(tri_cost.cycles), tc.alu_pipelined);
        let ppc = u64::from(tc.shade_pixels_per_cycle.max(1));
        let (bilinear_lat, blend_lat) = hw_model::trilinear::filter_latencies(&hw.trilinear, glpc);
        let alu_occ = |cycles: u64| {
            if tc.alu_pipelined {
                cycles.min(1)
            } else {
                cycles
            }
        };
        let mut steps = Vec::new();
        let plans: Vec<PlanSteps> = plans
            .iter()
            .map(|p| {
                let start = steps.len();
                steps.extend(p.stages.iter().map(|&(kind, cost)| {
                    let c = u64::from(cost.cycles);
                    Step {
                        k: kind.index(),
                        cycles: c,
                        occ: alu_occ(c),
                    }
                }));
                let kinds = p.stages.iter().fold(0u64, |m, &(k, _)| m | 1 << k.index());
                let distinct = kinds.count_ones() as usize == p.stages.len();
                let mut fetching = p
                    .stages
                    .iter()
                    .enumerate()
                    .filter(|&(_, &(k, _))| super::events::lookups(k, hw) > 0);
                let mono = match (fetching.next(), fetching.next()) {
                    (Some((at, _)), None) if distinct => {
                        let (pre, step) = (&p.stages[..at], p.stages[at].1);
                        let setup = setup_cost(u64::from(step.cycles), 1, tri_cycles, pipelined);
                        Some(Mono {
                            at,
                            setup,
                            pre_cycles: pre.iter().map(|s| u64::from(s.1.cycles)).sum(),
                            lazy_ok: ppc == 1
                                && setup.1 <= 1
                                && pre.iter().all(|s| alu_occ(u64::from(s.1.cycles)) <= 1),
                        })
                    }
                    _ => None,
                };
                PlanSteps {
                    start,
                    end: steps.len(),
                    distinct,
                    mono,
                }
            })
            .collect();
        let plan_pixels = vec![0; plans.len()];
        let win = tc.shade_pixels_in_flight.max(1) as usize;
        let (bilinear_lat, blend_lat) = (u64::from(bilinear_lat), u64::from(blend_lat));
        let bpc = u64::from(tc.bilinear_per_cycle.max(1));
        Self {
            hw,
            steps,
            plans,
            alu: [Unit::default(); KINDS],
            plan_pixels,
            tex: Texturing {
                mem: Memory::new(textures, tc),
                mem_unit: Unit::default(),
                filters: vec![Unit::default(); tc.trilinear_units.max(1) as usize],
                stage_bytes: [0; KINDS],
                tri_cycles,
                bilinear_lat,
                blend_lat,
                bpc,
                filter_cost: [0, 1, 2, 3].map(|n| filter_cost(n, bpc, bilinear_lat, blend_lat)),
                alu_pipelined: tc.alu_pipelined,
            },
            ppc,
            stall_by: [0; CAUSES],
            ring: vec![(0, StageKind::COUNT + 2); win],
            // The first pixel is in the first group, which it does not open.
            at: IssueState {
                left: u64::from(tc.shade_pixels_per_cycle.max(1)),
                ..IssueState::default()
            },
            footprints: 0,
            lazy: None,
            cached: tc.cache_bytes > 0,
            tiled: tc.bank_interleave == BankInterleave::Tiled,
        }
    }

    /// Feeds the pixels of one row in order (`fp_end` relative to the row's footprints).
    pub fn row(&mut self, row: &RowEvents) {
        self.pixels_of(&row.pixels, &row.footprints);
    }

    /// Feeds `pixels` in order, a run of one plan at a time; their `fp_end` index
    /// `footprints`, the previous pixel's end (0 for the first) being each one's start.
    fn pixels_of(&mut self, pixels: &[PixelEvent], footprints: &[TexelFootprint]) {
        let mut fp_start = 0usize;
        let mut rest = pixels;
        while let Some(first) = rest.first() {
            let n = rest
                .iter()
                .position(|p| p.plan != first.plan)
                .unwrap_or(rest.len());
            let (run, after) = rest.split_at(n);
            self.run(
                first.plan,
                run.iter().map(|px| {
                    let fp_end = (px.fp_end as usize).min(footprints.len());
                    let fps = &footprints[fp_start.min(fp_end)..fp_end];
                    fp_start = fp_end;
                    fps
                }),
            );
            rest = after;
        }
    }

    /// Issues the next covered pixel (raster order): plan index `plan`, the footprints its
    /// stages fetched in `fps`, e.g. straight from the fragment's trace.
    #[inline]
    pub fn pixel(&mut self, plan: u32, fps: &[TexelFootprint]) {
        self.run(plan, std::iter::once(fps));
    }

    /// Issues the next covered pixels (raster order), all of plan `plan`, each with the
    /// footprints its stages fetched: [`Simulator::pixel`] of each in turn, with the plan
    /// resolved and the issue state in locals once for the batch (checked against pixel by
    /// pixel feeding in `timing::equivalence`).
    pub fn span<'f>(&mut self, plan: u32, pixels: impl IntoIterator<Item = &'f [TexelFootprint]>) {
        self.run(plan, pixels.into_iter());
    }

    /// Issues pixels of plan `plan` (each given by its footprints) in raster order, through
    /// the walk compiled for the machine's memory.
    #[inline]
    fn run<'f>(&mut self, plan: u32, pixels: impl Iterator<Item = &'f [TexelFootprint]>) {
        match (self.cached, self.tiled) {
            (true, true) => self.run_in::<true, true>(plan, pixels),
            (true, false) => self.run_in::<true, false>(plan, pixels),
            (false, true) => self.run_in::<false, true>(plan, pixels),
            (false, false) => self.run_in::<false, false>(plan, pixels),
        }
    }

    /// Issues each pixel of plan `plan` (the footprints its stages fetched) in turn, with the
    /// memory's [`Memory::footprint`] compiled with (`CACHED`) or without a texel cache, for
    /// the tiled (`TILED`) or linear interleave. The plan is resolved once; the issue state
    /// lives in locals for the batch. Each pixel is [`pixel_in`] (one lookup of the plan's one
    /// fetching stage walked there, any other pixel [`other_pixel`]), or on the default
    /// machine's memory [`quad_lane`]'s loop. Units skipped for the plan's pixels ([`settle`])
    /// stay so for its next call ([`Lazy`]); another plan's call settles them first.
    #[inline(always)]
    fn run_in<'f, const CACHED: bool, const TILED: bool>(
        &mut self,
        plan: u32,
        pixels: impl Iterator<Item = &'f [TexelFootprint]>,
    ) {
        let Self {
            steps: all_steps,
            plans,
            alu,
            plan_pixels,
            tex,
            ppc,
            stall_by,
            ring,
            at,
            footprints,
            lazy: kept,
            ..
        } = self;
        // Skipped units of another plan are settled before this plan's pixels run.
        let mut lazy = match *kept {
            Some(Lazy { plan: p, t, n }) if p == plan => Some((t, n)),
            Some(_) => {
                settle_plan(alu, all_steps, plans, kept);
                None
            }
            None => None,
        };
        let ppc = *ppc;
        let ring = &mut ring[..];
        let mut st = *at;
        let mut fed = 0u64;
        let first = st.pixels;
        match plans.get(plan as usize) {
            // A plan the frame does not have: the pixel issues and completes at once.
            None => {
                for fps in pixels {
                    fed += fps.len() as u64;
                    let (slot, t) = st.issue(ring, stall_by, ppc);
                    ring[slot] = (t, C_LAT);
                }
            }
            Some(p) => {
                let plan = Walk {
                    one: p.one(all_steps),
                    steps: &all_steps[p.start..p.end],
                    distinct: p.distinct,
                };
                match plan.one {
                    Some((one, m)) if !CACHED && TILED && m.lazy_ok && tex.quad_lane() => {
                        let run = (ring, stall_by, ppc, &mut fed);
                        quad_lane(alu, tex, &plan, (&one, &m), pixels, &mut st, run, &mut lazy);
                    }
                    _ => {
                        for fps in pixels {
                            fed += fps.len() as u64;
                            let (slot, t) = st.issue(ring, stall_by, ppc);
                            let (t, cause) =
                                pixel_in::<CACHED, TILED>(alu, tex, &plan, fps, t, &mut lazy);
                            ring[slot] = (t, cause);
                            st.end = st.end.max(t);
                        }
                    }
                }
            }
        }
        // Skipped units stay so for the plan's next call.
        *kept = lazy.map(|(t, n)| Lazy { plan, t, n });
        if let Some(p) = plan_pixels.get_mut(plan as usize) {
            *p += st.pixels - first;
        }
        *at = st;
        *footprints += fed;
    }

    /// Settles the skipped units, if any ([`Lazy`]): before a report reads them.
    fn settle_all(&mut self) {
        settle_plan(&mut self.alu, &self.steps, &self.plans, &mut self.lazy);
    }
}

/// The stall causes beyond the stage kinds: the memory unit, the filter units and latency (a
/// pixel that never waited for a busy unit).
const C_MEM: usize = StageKind::COUNT;
const C_FILT: usize = StageKind::COUNT + 1;
const C_LAT: usize = StageKind::COUNT + 2;

/// Runs the arithmetic `steps` in order from `t`, each on its kind's unit: returns when the
/// last completes and updates the pixel's worst wait (cycles, cause).
#[inline(always)]
fn arith(alu: &mut [Unit; KINDS], steps: &[Step], mut t: u64, worst: &mut (u64, usize)) -> u64 {
    for &Step { k, cycles, occ } in steps {
        let s = alu[k & (KINDS - 1)].take_free(t, occ);
        if s - t > worst.0 {
            *worst = (s - t, k);
        }
        t = s + cycles;
    }
    t
}

/// One pixel issued at `t` through a plan's `steps` (`distinct`: its stage kinds are),
/// its footprints `fps` matched to its texture stages by [`stage_footprints`]: returns its
/// completion and worst cause.
#[inline(always)]
fn walk<const CACHED: bool, const TILED: bool>(
    alu: &mut [Unit; KINDS],
    tex: &mut Texturing,
    steps: &[Step],
    distinct: bool,
    fps: &[TexelFootprint],
    mut t: u64,
) -> (u64, usize) {
    let mut worst = (0u64, C_LAT);
    // The stage kinds that fetched (stage kinds number fewer than 64).
    let fetched = fps.iter().fold(0u64, |m, f| m | 1u64 << (f.stage & 63));
    let mut cursor = 0usize;
    for step in steps {
        let k = step.k;
        if fetched & (1u64 << (k & 63)) != 0 {
            let mine = stage_footprints(fps, &mut cursor, k, distinct);
            if !mine.is_empty() {
                let unit = &mut alu[k & (KINDS - 1)];
                // The plan's count charges this step's arithmetic occupancy.
                unit.busy = unit.busy.wrapping_sub(step.occ);
                t = tex.stage::<CACHED, TILED>(unit, k, step.cycles, t, mine, &mut worst);
                continue;
            }
        }
        t = arith(alu, std::slice::from_ref(step), t, &mut worst);
    }
    (t, worst.1)
}

/// A pixel of plan `plan` ([`Walk`]) issued at `t` that is not one lookup of its one
/// fetching stage: the skipped units settled ([`settle`]), [`walk_mono`] if its footprints
/// `fps` are all that stage's, else [`walk`]. Out of line, so [`Simulator::run_in`]'s
/// one-lookup loop stays small.
#[inline(never)]
fn other_pixel<const CACHED: bool, const TILED: bool>(
    alu: &mut [Unit; KINDS],
    tex: &mut Texturing,
    plan: &Walk,
    fps: &[TexelFootprint],
    t: u64,
    lazy: &mut Option<(u64, u64)>,
) -> (u64, usize) {
    match &plan.one {
        Some((one, Mono { setup, .. }))
            if fps.iter().all(|f| usize::from(f.stage) == one.step.k) =>
        {
            settle(alu, one, setup.1, lazy);
            walk_mono::<CACHED, TILED>(alu, tex, one, fps, t)
        }
        _ => {
            if let Some((one, Mono { setup, .. })) = &plan.one {
                settle(alu, one, setup.1, lazy);
            }
            walk::<CACHED, TILED>(alu, tex, plan.steps, plan.distinct, fps, t)
        }
    }
}

/// A plan as [`Simulator::run_in`] walks its pixels: its one fetching stage if any (with the
/// steps before and after it), its steps and whether their kinds are distinct.
struct Walk<'s> {
    one: Option<(OneStage<'s>, Mono)>,
    steps: &'s [Step],
    distinct: bool,
}

/// One pixel of plan `plan` issued at `t` with its footprints `fps`: a pixel that is one
/// lookup of the plan's one fetching stage is walked here (the steps before the stage
/// skipped while `lazy`, [`settle`]); any other takes [`other_pixel`] ([`walk_mono`] or the
/// general walk [`walk`]). Returns its completion and worst cause.
#[inline(always)]
fn pixel_in<const CACHED: bool, const TILED: bool>(
    alu: &mut [Unit; KINDS],
    tex: &mut Texturing,
    plan: &Walk,
    fps: &[TexelFootprint],
    t: u64,
    lazy: &mut Option<(u64, u64)>,
) -> (u64, usize) {
    match plan.one {
        Some((ref one, m)) if one_lookup(fps, one.step.k) => {
            let mut worst = (0u64, C_LAT);
            let arrive = t + m.pre_cycles;
            // Only a plan whose pixels may skip (`lazy_ok`) starts skipping, and a skipping
            // pixel reaches the stage at `arrive`: the next one skips.
            let s = match *lazy {
                Some((_, n)) => {
                    debug_assert!(m.lazy_ok);
                    *lazy = Some((t, n + 1));
                    arrive
                }
                None => {
                    let pre_end = arith(alu, one.pre, t, &mut worst);
                    let (k, occ) = (one.step.k, one.step.occ);
                    let unit = &mut alu[k & (KINDS - 1)];
                    // The plan's count charges the step's arithmetic occupancy.
                    unit.busy = unit.busy.wrapping_sub(occ);
                    let s = unit.take(pre_end, m.setup.1);
                    if s - pre_end > worst.0 {
                        worst = (s - pre_end, k);
                    }
                    *lazy = (m.lazy_ok && s == arrive).then_some((t, 0));
                    s
                }
            };
            let done = tex.lookup_from::<CACHED, TILED>(one.step.k, s + m.setup.0, fps, &mut worst);
            (arith(alu, one.post, done, &mut worst), worst.1)
        }
        _ => other_pixel::<CACHED, TILED>(alu, tex, plan, fps, t, lazy),
    }
}

/// [`pixel_in`] out of line: a pixel [`quad_lane`] does not take.
#[inline(never)]
fn general_pixel<const CACHED: bool, const TILED: bool>(
    alu: &mut [Unit; KINDS],
    tex: &mut Texturing,
    plan: &Walk,
    fps: &[TexelFootprint],
    t: u64,
    lazy: &mut Option<(u64, u64)>,
) -> (u64, usize) {
    pixel_in::<CACHED, TILED>(alu, tex, plan, fps, t, lazy)
}

/// [`Simulator::run_in`]'s loop on the common machine and plan ([`Texturing::quad_lane`]: no
/// texel cache, four banks tiled 2x2, one filter unit; a plan whose pixels skip the units
/// before its one fetching stage `one`): a skipping pixel that is one lookup of the stage
/// with one or two footprints whose columns and rows differ in parity (each texel its own
/// bank: [`Memory::quad_dram`]) is walked here as [`pixel_in`] walks it, with the four banks'
/// open pages in locals ([`QuadLocals`]); any other takes [`general_pixel`]. A
/// footprint whose four texels share a page finds that page in all four banks when the
/// previous footprints left it there (`QuadLocals::uniform`): four page hits, nothing to
/// store. Checked against the previous model by `quad_lane_matches_previous`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn quad_lane<'f>(
    alu: &mut [Unit; KINDS],
    tex: &mut Texturing,
    plan: &Walk,
    (one, m): (&OneStage, &Mono),
    pixels: impl Iterator<Item = &'f [TexelFootprint]>,
    st: &mut IssueState,
    (ring, stall_by, ppc, fed): (&mut [(u64, usize)], &mut [u64; CAUSES], u64, &mut u64),
    lazy: &mut Option<(u64, u64)>,
) {
    let k = one.step.k;
    // A footprint of the stage's first lookup reading four banks.
    // (`&` rather than `&&`: one test of the combined condition.)
    let quad = |f: &TexelFootprint| {
        (usize::from(f.stage) == k)
            & (f.lookup == 0)
            & ((f.x[0] ^ f.x[1]) & (f.y[0] ^ f.y[1]) & 1 != 0)
    };
    let ready_after = m.pre_cycles + m.setup.0;
    let quad_occ = tex.mem.quad_occ;
    // The memory's occupancy for four page hits, and the filter's costs of a lookup of one
    // and of two footprints (the only ones taken here).
    let occ_four = quad_occ[4];
    let (cost_one, cost_two) = (tex.filter_cost[1], tex.filter_cost[2]);
    let mut q = QuadLocals::load(tex);
    for fps in pixels {
        *fed += fps.len() as u64;
        let (slot, t) = st.issue(ring, stall_by, ppc);
        let fast = match fps {
            [a] => quad(a),
            [a, b] => quad(a) & quad(b),
            _ => false,
        };
        let n = match *lazy {
            Some((_, n)) if fast => n,
            _ => {
                q.store(tex, k);
                let (done, cause) = general_pixel::<false, true>(alu, tex, plan, fps, t, lazy);
                q = QuadLocals::load(tex);
                ring[slot] = (done, cause);
                st.end = st.end.max(done);
                continue;
            }
        };
        *lazy = Some((t, n + 1));
        let ready = t + ready_after;
        let (mut occ, mut last) = (0u64, 0u64);
        for fp in fps {
            let lv = tex.mem.map.level_recent(fp.tex, fp.level);
            q.bytes += 4 * u64::from(lv.texel_bytes);
            let (px, py) = lv.page_shift;
            // `page_row` >= 1: the four texels share a page when their columns' pages and
            // their rows' pages do.
            let one_page = (fp.x[0] >> px == fp.x[1] >> px) & (fp.y[0] >> py == fp.y[1] >> py);
            let o = if one_page {
                let page = lv.page_base
                    + u64::from(fp.y[0] >> py) * lv.page_row
                    + u64::from(fp.x[0] >> px);
                // So for the four banks: the hits do not depend on which texel is in which
                // bank.
                if page == q.uniform {
                    q.four += 1;
                    occ_four
                } else {
                    // Banks that all hold another page: no hit, nothing to count.
                    let hits = if q.uniform == EMPTY {
                        q.open.iter().filter(|&&o| o == page).count()
                    } else {
                        0
                    };
                    q.open = [page; 4];
                    q.uniform = page;
                    q.by_hits[hits & 7] += 1;
                    quad_occ[hits & 7]
                }
            } else {
                // Two pages or more: the banks no longer hold one page.
                q.uniform = EMPTY;
                let hits = quad4_hits(&mut q.open, quad4_bank(fp), quad_pages(lv, fp));
                q.by_hits[hits & 7] += 1;
                quad_occ[hits & 7]
            };
            occ += o;
            last = o;
        }
        // [`Texturing::lookup_timed`] on the locals: no cache, one filter unit, the bytes
        // counted in `q.bytes`.
        let f = Fetched {
            n: fps.len(),
            occ,
            last,
            bytes: 0,
        };
        let mut worst = (0u64, C_LAT);
        let data = f.through_memory(&mut q.mem_unit, ready, 0, &mut worst);
        let cost = if f.n == 1 { cost_one } else { cost_two };
        let mut done = ready.max(filter_on(&mut q.filter, data, cost, &mut worst));
        if !one.post.is_empty() {
            done = arith(alu, one.post, done, &mut worst);
        }
        ring[slot] = (done, worst.1);
        st.end = st.end.max(done);
    }
    q.store(tex, k);
}

/// What [`quad_lane`] keeps in locals: the four banks' open pages, the page they all hold if
/// one, the four-bank footprints by page hits, the texel bytes read since the last
/// [`QuadLocals::store`], the memory unit and the one filter unit.
struct QuadLocals {
    open: [u64; 4],
    /// The page all four banks hold, if one ([`EMPTY`] otherwise: no page is).
    uniform: u64,
    /// By page hits, the four-bank footprints but those counted in `four`.
    by_hits: [u64; 8],
    /// Footprints that found `uniform` in all four banks since the last store (counted in
    /// `by_hits[4]` on store).
    four: u64,
    bytes: u64,
    mem_unit: Unit,
    filter: Unit,
}

impl QuadLocals {
    #[inline(always)]
    fn load(tex: &Texturing) -> Self {
        let o = &tex.mem.open_page;
        let open = [o[0], o[1], o[2], o[3]];
        Self {
            open,
            uniform: if open.iter().all(|&p| p == open[0]) {
                open[0]
            } else {
                EMPTY
            },
            by_hits: tex.mem.quads.by_hits,
            four: 0,
            bytes: 0,
            mem_unit: tex.mem_unit,
            filter: tex.filters[0],
        }
    }

    /// Writes the locals back, the bytes to stage kind `k`'s.
    #[inline(always)]
    fn store(&mut self, tex: &mut Texturing, k: usize) {
        tex.stage_bytes[k & (KINDS - 1)] += std::mem::take(&mut self.bytes);
        self.by_hits[4] += std::mem::take(&mut self.four);
        tex.mem.open_page[..4].copy_from_slice(&self.open);
        tex.mem.quads.by_hits = self.by_hits;
        tex.mem_unit = self.mem_unit;
        tex.filters[0] = self.filter;
    }
}

/// A plan's one fetching stage as [`walk_mono`] walks it: the steps before it, its step and
/// the steps after it.
#[derive(Clone, Copy)]
struct OneStage<'s> {
    pre: &'s [Step],
    step: Step,
    post: &'s [Step],
}

/// [`walk`] of a pixel of a plan with distinct stage kinds whose footprints `fps` are all of
/// its one fetching stage (`one`): the general walk gives that stage all of them and runs the
/// others as arithmetic, and so does this, inlined.
#[inline(always)]
fn walk_mono<const CACHED: bool, const TILED: bool>(
    alu: &mut [Unit; KINDS],
    tex: &mut Texturing,
    one: &OneStage,
    fps: &[TexelFootprint],
    t: u64,
) -> (u64, usize) {
    let mut worst = (0u64, C_LAT);
    let step = one.step;
    let mut t = arith(alu, one.pre, t, &mut worst);
    if fps.is_empty() {
        t = arith(alu, std::slice::from_ref(&step), t, &mut worst);
    } else {
        let unit = &mut alu[step.k & (KINDS - 1)];
        unit.busy = unit.busy.wrapping_sub(step.occ);
        let w = &mut worst;
        t = tex.stage_in::<CACHED, TILED>(unit, step.k, step.cycles, t, fps, w);
    }
    (arith(alu, one.post, t, &mut worst), worst.1)
}

/// Whether footprints `fps` are one or two of lookup 0 of stage kind `k` (one lookup, as
/// [`Simulator::run_in`] walks it without [`walk_mono`]).
#[inline(always)]
fn one_lookup(fps: &[TexelFootprint], k: usize) -> bool {
    let of = |f: &TexelFootprint| usize::from(f.stage) == k && f.lookup == 0;
    match fps {
        [a] => of(a),
        [a, b] => of(a) && of(b),
        _ => false,
    }
}

/// The arithmetic units of a plan's one fetching stage `one` (distinct kinds) as they stand
/// after a pixel issued at `p` that waited for none of the steps before the stage nor for the
/// stage's address/footprint unit (occupancy `setup_occ`), followed by `n` pixels that skipped
/// them: each of those units freed at its start (issue plus the cycles of the steps before it)
/// plus its occupancy, and the address/footprint unit busy for the `n` pixels. With one pixel
/// issued per cycle and occupancies of at most 1, the next pixel issues later and reaches each
/// of these units when it is free again, so it waits for none of them either:
/// [`Simulator::run_in`] skips them for such pixels (their waits are 0, their units' frees are
/// the last pixel's) and settles the units here before anything else uses them.
#[inline]
fn settle(alu: &mut [Unit; KINDS], one: &OneStage, setup_occ: u64, lazy: &mut Option<(u64, u64)>) {
    if let Some((mut t, n)) = lazy.take() {
        for s in one.pre {
            alu[s.k & (KINDS - 1)].free = t + s.occ;
            t += s.cycles;
        }
        let unit = &mut alu[one.step.k & (KINDS - 1)];
        unit.free = t + setup_occ;
        let owed = n
            .wrapping_mul(setup_occ)
            .wrapping_sub(n.wrapping_mul(one.step.occ));
        unit.busy = unit.busy.wrapping_add(owed);
    }
}

/// [`Texturing::setup`] with trilinear samples of `tri_cycles` and the arithmetic units
/// `pipelined` or not.
#[inline(always)]
fn setup_cost(cycles: u64, lookups: u64, tri_cycles: u64, pipelined: bool) -> (u64, u64) {
    let setup = cycles.saturating_sub(lookups * tri_cycles).max(1);
    let setup_occ = if pipelined { setup.min(1) } else { setup };
    (setup, setup_occ)
}

/// [`settle`] of `lazy`'s plan (of `plans`, whose stages are in `steps`), if any.
#[inline(never)]
fn settle_plan(
    alu: &mut [Unit; KINDS],
    steps: &[Step],
    plans: &[PlanSteps],
    lazy: &mut Option<Lazy>,
) {
    if let Some(Lazy { plan, t, n }) = lazy.take() {
        if let Some((one, m)) = plans.get(plan as usize).and_then(|p| p.one(steps)) {
            settle(alu, &one, m.setup.1, &mut Some((t, n)));
        }
    }
}

impl Texturing {
    /// Whether [`quad_lane`] serves this machine: no texel cache, four banks tiled 2x2
    /// ([`Memory::quad4`]) and one filter unit.
    fn quad_lane(&self) -> bool {
        self.mem.cache.is_none() && self.mem.quad4 && self.filters.len() == 1
    }

    /// [`Texturing::stage_in`], not inlined (the general walk's texture stage).
    #[inline(never)]
    #[allow(clippy::too_many_arguments)]
    fn stage<const CACHED: bool, const TILED: bool>(
        &mut self,
        alu: &mut Unit,
        k: usize,
        cycles: u64,
        t: u64,
        mine: &[TexelFootprint],
        worst: &mut (u64, usize),
    ) -> u64 {
        self.stage_in::<CACHED, TILED>(alu, k, cycles, t, mine, worst)
    }

    /// The address/footprint unit's (cycles, occupancy) in a texture stage of `cycles` per
    /// invocation making `lookups` lookups: the cycles beyond the lookups' trilinear samples,
    /// at least 1.
    #[inline(always)]
    fn setup(&self, cycles: u64, lookups: u64) -> (u64, u64) {
        setup_cost(cycles, lookups, self.tri_cycles, self.alu_pipelined)
    }

    /// A texture stage of kind `k` (`cycles` per invocation, `alu` its address/footprint
    /// unit) reached at `t` with its footprints `mine` (not empty): its address/footprint
    /// unit, then each lookup through the memory and a filter unit; returns its completion
    /// and updates the pixel's worst wait (cycles, cause). One or two footprints of one
    /// lookup (a bilinear or trilinear lookup) skip the search for the lookups' runs; each
    /// run is [`Texturing::lookup_from`].
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn stage_in<const CACHED: bool, const TILED: bool>(
        &mut self,
        alu: &mut Unit,
        k: usize,
        cycles: u64,
        t: u64,
        mine: &[TexelFootprint],
        worst: &mut (u64, usize),
    ) -> u64 {
        let (Some(first), Some(last)) = (mine.first(), mine.last()) else {
            return t;
        };
        let (setup, setup_occ) = self.setup(cycles, u64::from(last.lookup) + 1);
        let s = alu.take(t, setup_occ);
        if s - t > worst.0 {
            *worst = (s - t, k);
        }
        let ready = s + setup;
        if mine.len() <= 2 && first.lookup == last.lookup {
            return self.lookup_from::<CACHED, TILED>(k, ready, mine, worst);
        }
        self.runs_from::<CACHED, TILED>(k, ready, mine, worst)
    }

    /// [`Texturing::lookup_from`] for each lookup of stage kind `k` whose footprints `mine`
    /// (consecutive per lookup) hold several lookups; returns the last completion. Out of
    /// line: the one-lookup path of [`Texturing::stage_in`] stays small.
    #[inline(never)]
    fn runs_from<const CACHED: bool, const TILED: bool>(
        &mut self,
        k: usize,
        ready: u64,
        mine: &[TexelFootprint],
        worst: &mut (u64, usize),
    ) -> u64 {
        mine.chunk_by(|a, b| a.lookup == b.lookup)
            .fold(ready, |done, run| {
                done.max(self.lookup_from::<CACHED, TILED>(k, ready, run, worst))
            })
    }

    /// One lookup of stage kind `k` from `ready` (its address/footprint unit done): its
    /// footprints `mine` through the memory, then its timing ([`Texturing::lookup_timed`]);
    /// returns the lookup's completion (at least `ready`).
    #[inline(always)]
    fn lookup_from<const CACHED: bool, const TILED: bool>(
        &mut self,
        k: usize,
        ready: u64,
        mine: &[TexelFootprint],
        worst: &mut (u64, usize),
    ) -> u64 {
        let mut f = Fetched {
            n: mine.len(),
            ..Fetched::default()
        };
        for fp in mine {
            let (o, b) = self.mem.footprint::<CACHED, TILED>(fp);
            f.occ += o;
            f.bytes += b;
            f.last = o;
        }
        self.lookup_timed::<CACHED>(k, ready, &f, worst)
    }

    /// The timing of one lookup of stage kind `k` from `ready` whose footprints went through
    /// the memory as `f`: the memory unit, then the lookup on a filter unit; returns the
    /// lookup's completion (at least `ready`). The footprints all arrive at `ready`, so the
    /// memory unit serves them back to back from the first one's start: they take it as one
    /// request of their summed occupancy, and the last one starts latest (the longest wait)
    /// and is ready last.
    #[inline(always)]
    fn lookup_timed<const CACHED: bool>(
        &mut self,
        k: usize,
        ready: u64,
        f: &Fetched,
        worst: &mut (u64, usize),
    ) -> u64 {
        let hit_latency = if CACHED { self.mem.hit_latency } else { 0 };
        let data = f.through_memory(&mut self.mem_unit, ready, hit_latency, worst);
        let done = ready.max(self.filter(data, f.n, worst));
        self.stage_bytes[k & (KINDS - 1)] += f.bytes;
        done
    }

    /// A lookup of `n` footprints whose data is ready at `data` on the earliest free filter
    /// unit: returns when its result is ready and updates the pixel's worst wait.
    #[inline(always)]
    fn filter(&mut self, data: u64, n: usize, worst: &mut (u64, usize)) -> u64 {
        // The filter's occupancy and its occupancy-or-latency for `n` footprints.
        let cost = match self.filter_cost.get(n) {
            Some(&c) => c,
            None => filter_cost(n as u64, self.bpc, self.bilinear_lat, self.blend_lat),
        };
        let fu = match &self.filters[..] {
            [_] => 0,
            filters => earliest(filters, data),
        };
        filter_on(&mut self.filters[fu], data, cost, worst)
    }
}

impl Simulator<'_> {
    /// Adds the visibility pass of the frame (`f`) and reports.
    #[must_use]
    pub fn finish(mut self, f: &FrameCounts, scene: &str) -> TimingReport {
        self.settle_all();
        let hw = self.hw;
        let tc = &hw.timing;
        let rc = &hw.raster;
        let nk = StageKind::COUNT;
        let c_lat = nk + 2;
        let (c_mem, c_filt) = (nk, nk + 1);
        let (mut alu, stall_by) = (self.alu, self.stall_by);
        for (p, &n) in self.plans.iter().zip(&self.plan_pixels) {
            for s in &self.steps[p.start..p.end] {
                let u = &mut alu[s.k & (KINDS - 1)];
                u.busy = u.busy.wrapping_add(n.wrapping_mul(s.occ));
            }
        }
        let Texturing {
            mem,
            mem_unit,
            filters,
            stage_bytes,
            ..
        } = self.tex;
        // Visibility pass.
        let setup_busy = f.triangles * u64::from(rc.setup_cycles);
        let traverse_busy = f.spans * u64::from(rc.span_cycles)
            + f.fragments
                .div_ceil(u64::from(tc.raster_fragments_per_cycle.max(1)));
        let vis = match traverse_busy.checked_div(f.triangles) {
            None => 0,
            Some(avg) => (setup_busy + avg).max(u64::from(rc.setup_cycles) + traverse_busy),
        };
        let events = self.at.pixels + self.footprints + f.triangles + f.spans;
        let covered = self.at.pixels;
        let shade = self.at.end;
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
        let counts = mem.counts.total(&mem.quads, mem.page_hit, mem.page_miss);
        // Every texel access is a texture stage's.
        let bytes = stage_bytes.iter().sum();
        let memory = counts.report(tc, mem.cache.is_some(), bytes);
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
            bank_conflict_cycles: counts.conflict_cycles,
            miss_cycles: counts.miss_cycles,
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

#[cfg(test)]
mod tests {
    use super::{Memory, TexelFootprint, TextureLayout};
    use crate::rng_common::Rng;
    use hw_model::timing_config::BankInterleave;
    use hw_model::HwConfig;

    /// [`Memory::quad_dram`]'s four-bank slots ([`Memory::quad4`]) against
    /// [`Memory::footprint_any`] on 1.2M seeded random footprints of four tiled banks without a
    /// cache: neighbouring texels (wrapping around odd and even levels), any two columns and
    /// rows, repeated ones (the fallback), small and large pages; the same cycles and bytes,
    /// counters and open pages after every footprint.
    #[test]
    fn four_bank_slots_match_the_general_path() {
        let mut r = Rng(0x4b_a9c5);
        let pick = |r: &mut Rng, xs: &[u32]| xs[r.below(xs.len() as u64) as usize];
        for case in 0..300 {
            let mut tc = HwConfig::texram16().timing;
            tc.banks = 4;
            tc.bank_interleave = BankInterleave::Tiled;
            tc.cache_bytes = 0;
            tc.dram_page_bytes = pick(&mut r, &[8, 64, 512, 2048]);
            tc.dram_page_hit_cycles = pick(&mut r, &[1, 2, 8]);
            tc.dram_page_miss_cycles = pick(&mut r, &[1, 6, 40]);
            let textures: Vec<TextureLayout> = (0..1 + r.below(3))
                .map(|_| {
                    let (w, h) = (1 + r.below(90) as u32, 1 + r.below(90) as u32);
                    TextureLayout {
                        levels: vec![(w, h), ((w / 2).max(1), (h / 2).max(1))],
                        texel_bytes: pick(&mut r, &[1, 2, 4, 8]),
                    }
                })
                .collect();
            let mut fast = Memory::new(&textures, &tc);
            assert!(fast.quad4);
            let mut general = fast.clone();
            for i in 0..4000 {
                let tex = r.below(textures.len() as u64) as usize;
                let level = r.below(2) as usize;
                let (w, h) = textures[tex].levels[level];
                let near = |r: &mut Rng, n: u32| {
                    let a = r.below(u64::from(n)) as u32;
                    let b = match r.below(8) {
                        0 => a,
                        1 => r.below(u64::from(n)) as u32,
                        _ => (a + 1) % n,
                    };
                    [a, b]
                };
                let fp = TexelFootprint {
                    stage: 0,
                    lookup: 0,
                    level: level as u8,
                    tex: tex as u16,
                    x: near(&mut r, w),
                    y: near(&mut r, h),
                };
                let want = general.footprint_any::<false, true>(&fp);
                let got = fast.footprint::<false, true>(&fp);
                assert_eq!(got, want, "case {case} footprint {i}: {fp:?}");
                let (hit, miss) = (general.page_hit, general.page_miss);
                assert_eq!(
                    fast.counts.total(&fast.quads, hit, miss),
                    general.counts.total(&general.quads, hit, miss),
                    "case {case} footprint {i}"
                );
                assert_eq!(
                    fast.open_page, general.open_page,
                    "case {case} footprint {i}"
                );
            }
        }
    }

    /// [`Memory::footprint`] (with its four-bank fast path) against [`Memory::footprint_any`]
    /// (the general path) on seeded random machines and footprints, most of them 2x2 on
    /// neighbouring texels: the same cycles and bytes, counters, open pages and cache lines
    /// after every footprint.
    #[test]
    fn fast_footprints_match_the_general_path() {
        let mut r = Rng(0x0f00_7b12);
        let pick = |r: &mut Rng, xs: &[u32]| xs[r.below(xs.len() as u64) as usize];
        for case in 0..300 {
            let mut tc = HwConfig::texram16().timing;
            tc.banks = pick(&mut r, &[1, 2, 4, 6, 8, 16, 64]);
            tc.bank_interleave = if r.below(4) == 0 {
                BankInterleave::Linear
            } else {
                BankInterleave::Tiled
            };
            tc.cache_bytes = pick(&mut r, &[0, 256, 4096]);
            tc.cache_line_bytes = pick(&mut r, &[8, 16, 64]);
            tc.cache_ways = pick(&mut r, &[1, 2, 4]);
            tc.cache_hit_cycles = pick(&mut r, &[0, 3]);
            tc.dram_page_bytes = pick(&mut r, &[64, 512, 2048]);
            tc.dram_page_hit_cycles = pick(&mut r, &[1, 2]);
            tc.dram_page_miss_cycles = pick(&mut r, &[1, 9, 40]);
            let textures: Vec<TextureLayout> = (0..1 + r.below(3))
                .map(|_| {
                    let (w, h) = (1 + r.below(70) as u32, 1 + r.below(70) as u32);
                    TextureLayout {
                        levels: vec![(w, h), ((w / 2).max(1), (h / 2).max(1))],
                        texel_bytes: pick(&mut r, &[1, 2, 4, 8]),
                    }
                })
                .collect();
            let mut fast = Memory::new(&textures, &tc);
            let mut general = fast.clone();
            for i in 0..400 {
                let tex = r.below(textures.len() as u64) as usize;
                let level = r.below(2) as usize;
                let (w, h) = textures[tex].levels[level];
                let (x0, y0) = (r.below(u64::from(w)) as u32, r.below(u64::from(h)) as u32);
                let x1 = if r.below(10) == 0 { x0 } else { (x0 + 1) % w };
                let y1 = if r.below(10) == 0 { y0 } else { (y0 + 1) % h };
                let fp = TexelFootprint {
                    stage: 0,
                    lookup: 0,
                    level: level as u8,
                    tex: tex as u16,
                    x: [x0, x1],
                    y: [y0, y1],
                };
                let (want, got) = match (tc.cache_bytes > 0, tc.bank_interleave) {
                    (true, BankInterleave::Tiled) => (
                        general.footprint_any::<true, true>(&fp),
                        fast.footprint::<true, true>(&fp),
                    ),
                    (false, BankInterleave::Tiled) => (
                        general.footprint_any::<false, true>(&fp),
                        fast.footprint::<false, true>(&fp),
                    ),
                    (true, BankInterleave::Linear) => (
                        general.footprint_any::<true, false>(&fp),
                        fast.footprint::<true, false>(&fp),
                    ),
                    (false, BankInterleave::Linear) => (
                        general.footprint_any::<false, false>(&fp),
                        fast.footprint::<false, false>(&fp),
                    ),
                };
                assert_eq!(got, want, "case {case} footprint {i}: {fp:?}");
                let (hit, miss) = (general.page_hit, general.page_miss);
                assert_eq!(
                    fast.counts.total(&fast.quads, hit, miss),
                    general.counts.total(&general.quads, hit, miss),
                    "case {case} footprint {i}"
                );
                assert_eq!(
                    fast.open_page, general.open_page,
                    "case {case} footprint {i}"
                );
                assert_eq!(
                    fast.cache.as_ref().map(|c| &c.tags),
                    general.cache.as_ref().map(|c| &c.tags),
                    "case {case} footprint {i}"
                );
            }
        }
    }
}
