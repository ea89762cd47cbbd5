//! Parameters of the timing model (when things happen, not what each bit is). The functional
//! units never read these; only `texsim`'s timing model (`texsim::timing`) does.
//!
//! Sources: the structure (embedded DRAM in banks interleaved so that a 2x2 bilinear
//! footprint is read in one access, open pages, footprint assembly) follows Schilling, Knittel
//! and Strasser, "Texram: a smart memory for texturing", IEEE CG&A 16(3), 1996. Every number in
//! the presets is an assumption of this simulator (documented in docs/TIMING.md), not a figure
//! quoted from the paper; change them in a hw TOML file (`[timing]` section) or by `--vary`.

use crate::config::ConfigError;
use serde::{Deserialize, Serialize};

/// How texel (x, y) of a level maps to a memory bank.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BankInterleave {
    /// 2D interleave: `bank = (x mod bx) + bx (y mod by)` with `bx * by = banks`, `bx >= by`
    /// (powers of two). With 4 or more banks any 2x2 footprint is conflict-free on levels whose
    /// sides are multiples of `bx` and `by`; a footprint that wraps around an odd-sized level
    /// (texel `w - 1` next to texel 0) can conflict, and is counted.
    Tiled,
    /// Linear interleave of the row-major texel index: `bank = (y * width + x) mod banks`.
    /// Vertical neighbours collide whenever `width` is a multiple of `banks`.
    Linear,
}

/// Bytes of the widest stored texel (4 channels of 16 bits): cache lines and DRAM pages hold
/// at least one.
pub const MAX_TEXEL_BYTES: u32 = 8;

/// Bytes one stored texel of `channels` channels of `bits` bits occupies in texture memory:
/// the packed bits rounded up to a whole power-of-two number of bytes (texels are addressed by
/// shifts, so a 48-bit texel takes 8 bytes and a 4-bit one 1 byte). Channels and bits are
/// clamped to 1..=4 and 1..=16, so the result is 1, 2, 4 or 8 ([`MAX_TEXEL_BYTES`]).
#[must_use]
pub fn stored_texel_bytes(channels: u32, bits: u32) -> u32 {
    (channels.clamp(1, 4) * bits.clamp(1, 16))
        .div_ceil(8)
        .next_power_of_two()
}

/// Throughput, latency, memory and cache parameters of the texture pipeline. Bytes per texel
/// are not a field: they follow each map's format ([`stored_texel_bytes`]).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimingConfig {
    /// Number of trilinear filter units working in parallel.
    pub trilinear_units: u32,
    /// Bilinear footprints one trilinear unit completes per cycle.
    pub bilinear_per_cycle: u32,
    /// Texture memory banks (a power of two).
    pub banks: u32,
    /// Mapping of texels to banks.
    pub bank_interleave: BankInterleave,
    /// Texel cache size in bytes (0 = no cache: every texel is a DRAM access).
    pub cache_bytes: u32,
    /// Cache line size in bytes; a line holds a square-ish 2D tile of texels.
    pub cache_line_bytes: u32,
    /// Cache associativity (LRU replacement).
    pub cache_ways: u32,
    /// Latency of a cache hit in cycles (pipelined: a bank accepts one hit per cycle).
    pub cache_hit_cycles: u32,
    /// DRAM page size in bytes; a page holds a square-ish 2D tile of texels.
    pub dram_page_bytes: u32,
    /// Cycles a bank is busy for an access that hits its open page.
    pub dram_page_hit_cycles: u32,
    /// Cycles a bank is busy for an access that opens a new page (precharge + activate + read).
    pub dram_page_miss_cycles: u32,
    /// Fragments the visibility pass traverses per cycle (after the span start cost).
    pub raster_fragments_per_cycle: u32,
    /// Pixels the shading pass issues per cycle.
    pub shade_pixels_per_cycle: u32,
    /// Pixels in flight in the shading pass: pixel `i` issues only when pixel `i - n` is done
    /// (the capacity of the pipeline registers and queues between the units).
    pub shade_pixels_in_flight: u32,
    /// Arithmetic units are pipelined: one operation issues per cycle and its cycles from the
    /// unit configs are latency. When false, a unit is busy for all of its cycles (iterative).
    pub alu_pipelined: bool,
    /// The clock target: gate levels that fit in one cycle. Every unit's latency is derived
    /// from its datapath's critical path as `ceil(delay / gate_levels_per_cycle)` per stage
    /// (`hw_model::datapath`), unless a hand-set `*_cycles` field overrides it. Absent in older
    /// files: 32 (an assumption, like the other timing parameters).
    #[serde(default = "default_gate_levels_per_cycle")]
    pub gate_levels_per_cycle: u32,
}

/// The presets' clock target (an assumption: about 32 gate levels per cycle).
pub const DEFAULT_GATE_LEVELS_PER_CYCLE: u32 = 32;

const fn default_gate_levels_per_cycle() -> u32 {
    DEFAULT_GATE_LEVELS_PER_CYCLE
}

impl TimingConfig {
    /// Texram-style: one trilinear unit, texels in embedded DRAM behind 4 banks (2D
    /// interleave), no cache, cheap open-page hits, pipelined arithmetic units.
    #[must_use]
    pub fn texram16() -> Self {
        Self {
            trilinear_units: 1,
            bilinear_per_cycle: 1,
            banks: 4,
            bank_interleave: BankInterleave::Tiled,
            cache_bytes: 0,
            cache_line_bytes: 32,
            cache_ways: 2,
            cache_hit_cycles: 1,
            dram_page_bytes: 2048,
            dram_page_hit_cycles: 1,
            dram_page_miss_cycles: 6,
            raster_fragments_per_cycle: 1,
            shade_pixels_per_cycle: 1,
            shade_pixels_in_flight: 16,
            alu_pipelined: true,
            gate_levels_per_cycle: DEFAULT_GATE_LEVELS_PER_CYCLE,
        }
    }

    /// A later texture unit: pipelined arithmetic, a 16 KiB 4-way texel cache with 64-byte
    /// lines in 4 banks, external DRAM with expensive page misses, two bilinear per cycle.
    #[must_use]
    pub fn modern() -> Self {
        Self {
            trilinear_units: 1,
            bilinear_per_cycle: 2,
            banks: 4,
            bank_interleave: BankInterleave::Tiled,
            cache_bytes: 16384,
            cache_line_bytes: 64,
            cache_ways: 4,
            cache_hit_cycles: 4,
            dram_page_bytes: 2048,
            dram_page_hit_cycles: 8,
            dram_page_miss_cycles: 40,
            raster_fragments_per_cycle: 1,
            shade_pixels_per_cycle: 1,
            shade_pixels_in_flight: 64,
            alu_pipelined: true,
            gate_levels_per_cycle: DEFAULT_GATE_LEVELS_PER_CYCLE,
        }
    }

    /// Checks the ranges; the error names the field.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let err = |f: &str, what: String| ConfigError {
            field: format!("timing.{f}"),
            what,
        };
        for (f, v, lo, hi) in [
            ("trilinear_units", self.trilinear_units, 1, 64),
            ("bilinear_per_cycle", self.bilinear_per_cycle, 1, 8),
            ("banks", self.banks, 1, 64),
            ("cache_ways", self.cache_ways, 1, 64),
            (
                "cache_line_bytes",
                self.cache_line_bytes,
                MAX_TEXEL_BYTES,
                4096,
            ),
            (
                "dram_page_bytes",
                self.dram_page_bytes,
                MAX_TEXEL_BYTES,
                1 << 20,
            ),
            ("cache_bytes", self.cache_bytes, 0, 1 << 26),
            ("cache_hit_cycles", self.cache_hit_cycles, 0, 1000),
            ("dram_page_hit_cycles", self.dram_page_hit_cycles, 1, 1000),
            ("dram_page_miss_cycles", self.dram_page_miss_cycles, 1, 1000),
            (
                "raster_fragments_per_cycle",
                self.raster_fragments_per_cycle,
                1,
                64,
            ),
            ("shade_pixels_per_cycle", self.shade_pixels_per_cycle, 1, 64),
            (
                "gate_levels_per_cycle",
                self.gate_levels_per_cycle,
                1,
                10_000,
            ),
            (
                "shade_pixels_in_flight",
                self.shade_pixels_in_flight,
                1,
                4096,
            ),
        ] {
            if v < lo || v > hi {
                return Err(err(f, format!("{v} is out of range {lo}..={hi}")));
            }
        }
        for (f, v) in [
            ("banks", self.banks),
            ("cache_line_bytes", self.cache_line_bytes),
            ("dram_page_bytes", self.dram_page_bytes),
        ] {
            if !v.is_power_of_two() {
                return Err(err(f, format!("{v} is not a power of two")));
            }
        }
        if self.cache_bytes != 0 {
            let set = self.cache_line_bytes * self.cache_ways;
            if self.cache_bytes < set || (self.cache_bytes / set) * set != self.cache_bytes {
                return Err(err(
                    "cache_bytes",
                    format!(
                        "{} is not a whole number of sets of {} ways x {} bytes",
                        self.cache_bytes, self.cache_ways, self.cache_line_bytes
                    ),
                ));
            }
        }
        Ok(())
    }
}
