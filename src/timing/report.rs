//! The timing report as a terminal table (the JSON form is the serde serialization of
//! [`TimingReport`], written as `cycles.json`).

use super::model::TimingReport;
use std::fmt::Write;

/// The report as aligned text.
#[must_use]
pub fn text(r: &TimingReport) -> String {
    let mut o = String::new();
    let _ = writeln!(
        o,
        "timing model: scene '{}' {}x{} on '{}'",
        r.scene, r.width, r.height, r.hw
    );
    let _ = writeln!(
        o,
        "total cycles {} = visibility pass {} + shading pass {}; {} covered pixels, {:.3} cycles/pixel",
        r.total_cycles,
        r.visibility_pass_cycles,
        r.shading_pass_cycles,
        r.covered_pixels,
        r.cycles_per_pixel
    );
    let _ = writeln!(
        o,
        "{:<12} {:>14} {:>12}",
        "unit", "busy cycles", "utilization"
    );
    for u in &r.units {
        let _ = writeln!(
            o,
            "{:<12} {:>14} {:>11.1}%",
            u.unit,
            u.busy_cycles,
            100.0 * u.utilization
        );
    }
    let _ = writeln!(o, "{:<26} {:>14}", "stall cause", "cycles");
    for s in &r.stalls {
        let _ = writeln!(o, "{:<26} {:>14}", s.cause, s.cycles);
    }
    let m = &r.memory;
    let hit = m
        .cache_hit_rate
        .map_or_else(|| "no cache".to_string(), |h| format!("{:.2}%", 100.0 * h));
    let _ = writeln!(
        o,
        "memory: {} footprints, {} texel accesses; cache hit rate {} ({} hits, {} misses); {} bank conflicts in {} footprints; DRAM {} accesses, {} page hits, {} page misses",
        m.footprints,
        m.texel_accesses,
        hit,
        m.cache_hits,
        m.cache_misses,
        m.bank_conflicts,
        m.conflicting_footprints,
        m.dram_accesses,
        m.dram_page_hits,
        m.dram_page_misses
    );
    let _ = writeln!(
        o,
        "texture bytes {} (texel accesses x each map's stored texel size); DRAM bytes {}",
        m.texture_bytes, m.dram_bytes
    );
    let _ = writeln!(
        o,
        "memory cycles from bank conflicts {}, from cache/page misses {}",
        r.bank_conflict_cycles, r.miss_cycles
    );
    let _ = writeln!(
        o,
        "bottleneck: {} ({} cycles); {} events",
        r.bottleneck, r.bottleneck_cycles, r.events
    );
    o
}
