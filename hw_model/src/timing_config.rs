//! Parameters of the timing model (when things happen, not what each bit is). The functional
//! units never read these; only `texsim`'s timing model does.

use crate::config::ConfigError;
use serde::{Deserialize, Serialize};

/// Throughput, memory and cache parameters of the texture pipeline.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimingConfig {
    /// Number of trilinear filter units working in parallel.
    pub trilinear_units: u32,
    /// Bilinear footprints one trilinear unit completes per cycle.
    pub bilinear_per_cycle: u32,
    /// Texture memory banks (a 2x2 footprint is conflict-free with 4 banks interleaved by
    /// texel parity in x and y).
    pub banks: u32,
    /// Texel cache size in bytes (0 = no cache).
    pub cache_bytes: u32,
    /// Cache line size in bytes.
    pub cache_line_bytes: u32,
    /// Cache associativity.
    pub cache_ways: u32,
    /// Cycles of a cache hit.
    pub cache_hit_cycles: u32,
    /// DRAM page size in bytes.
    pub dram_page_bytes: u32,
    /// Cycles of a DRAM access that hits the open page.
    pub dram_page_hit_cycles: u32,
    /// Cycles of a DRAM access that opens a new page.
    pub dram_page_miss_cycles: u32,
    /// Bytes per stored texel.
    pub texel_bytes: u32,
}

impl TimingConfig {
    /// Texram-style defaults: one trilinear unit, texels in embedded DRAM behind 4 banks.
    #[must_use]
    pub fn texram16() -> Self {
        Self {
            trilinear_units: 1,
            bilinear_per_cycle: 1,
            banks: 4,
            cache_bytes: 0,
            cache_line_bytes: 32,
            cache_ways: 2,
            cache_hit_cycles: 1,
            dram_page_bytes: 2048,
            dram_page_hit_cycles: 1,
            dram_page_miss_cycles: 6,
            texel_bytes: 8,
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
            ("texel_bytes", self.texel_bytes, 1, 16),
        ] {
            if v < lo || v > hi {
                return Err(err(f, format!("{v} is out of range {lo}..={hi}")));
            }
        }
        for (f, v) in [
            ("cache_line_bytes", self.cache_line_bytes),
            ("dram_page_bytes", self.dram_page_bytes),
        ] {
            if !v.is_power_of_two() {
                return Err(err(f, format!("{v} is not a power of two")));
            }
        }
        if self.cache_bytes != 0 && self.cache_bytes < self.cache_line_bytes * self.cache_ways {
            return Err(err(
                "cache_bytes",
                format!(
                    "{} holds less than one set of {} ways",
                    self.cache_bytes, self.cache_ways
                ),
            ));
        }
        Ok(())
    }
}
