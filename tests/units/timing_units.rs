//! Unit tests of the timing model's parts: the LRU cache (hand cases), the bank interleave
//! (2x2 footprints conflict-free under the tiled interleave, counted conflicts otherwise) and
//! the DRAM open-page model, on hand-built event streams.

use crate::rng_common::Rng;
use hw_model::timing_config::BankInterleave;
use hw_model::{HwConfig, UnitCost};
use texsim::pipeline::StageKind;
use texsim::timing::events::{FrameEvents, PixelEvent, PlanTiming, TexelFootprint, TextureLayout};
use texsim::timing::model::{bank_of, footprint_conflicts};
use texsim::timing::{simulate, Cache};

#[test]
fn lru_cache_hand_cases() {
    // One set, two ways.
    let mut c = Cache::new(1, 2);
    assert!(!c.access(1));
    assert!(!c.access(2));
    assert!(c.access(1)); // 1 is now most recent, 2 least
    assert!(!c.access(3)); // evicts 2
    assert!(c.access(1));
    assert!(!c.access(2)); // 2 was evicted; evicts 3
    assert!(!c.access(3));
    // Two sets: even keys in set 0, odd keys in set 1; one way each.
    let mut c = Cache::new(2, 1);
    assert!(!c.access(0));
    assert!(!c.access(1));
    assert!(c.access(0));
    assert!(c.access(1));
    assert!(!c.access(2)); // evicts 0 from set 0 only
    assert!(c.access(1));
    assert!(!c.access(0));
}

#[test]
fn lru_cache_matches_a_list_model() {
    let mut seed = Rng(7);
    for ways in [1usize, 2, 4, 8] {
        let sets = 4u64;
        let mut c = Cache::new(sets, ways);
        let mut model: Vec<Vec<u64>> = vec![vec![]; sets as usize];
        for _ in 0..20000 {
            let k = seed.next() % 64;
            let set = &mut model[(k % sets) as usize];
            let hit = if let Some(p) = set.iter().position(|&x| x == k) {
                set.remove(p);
                true
            } else {
                if set.len() == ways {
                    set.pop();
                }
                false
            };
            set.insert(0, k);
            assert_eq!(c.access(k), hit);
        }
    }
}

fn fp(x0: u32, y0: u32, w: u32, h: u32) -> TexelFootprint {
    TexelFootprint {
        stage: StageKind::Trilinear.index() as u8,
        lookup: 0,
        level: 0,
        tex: 0,
        x: [x0, (x0 + 1) % w],
        y: [y0, (y0 + 1) % h],
    }
}

#[test]
fn tiled_interleave_makes_2x2_conflict_free() {
    let mut seed = Rng(1);
    for banks in [4u32, 8, 16, 64] {
        for _ in 0..20000 {
            let w = 1u32 << (1 + seed.next() % 10);
            let h = 1u32 << (1 + seed.next() % 10);
            let x = (seed.next() % u64::from(w)) as u32;
            let y = (seed.next() % u64::from(h)) as u32;
            assert_eq!(
                footprint_conflicts(&fp(x, y, w, h), w, banks, BankInterleave::Tiled),
                0,
                "banks {banks} at ({x},{y}) of {w}x{h}"
            );
        }
    }
}

#[test]
fn conflicts_are_counted_otherwise() {
    // Two tiled banks: bank = x mod 2, so the two texels of each column collide: 2 conflicts.
    assert_eq!(bank_of(3, 5, 16, 2, BankInterleave::Tiled), 1);
    assert_eq!(
        footprint_conflicts(&fp(4, 7, 16, 16), 16, 2, BankInterleave::Tiled),
        2
    );
    // One bank: everything collides (4 texels, 3 conflicts).
    assert_eq!(
        footprint_conflicts(&fp(4, 7, 16, 16), 16, 1, BankInterleave::Tiled),
        3
    );
    // Linear interleave with a width that is a multiple of the bank count: rows alias.
    assert_eq!(
        footprint_conflicts(&fp(4, 7, 16, 16), 16, 4, BankInterleave::Linear),
        2
    );
    // Width = 1 mod 4: the next row's first texel aliases the right neighbour (1 conflict);
    // width = 2 mod 4: the four texels land in four banks.
    assert_eq!(
        footprint_conflicts(&fp(4, 7, 17, 16), 17, 4, BankInterleave::Linear),
        1
    );
    assert_eq!(
        footprint_conflicts(&fp(4, 7, 18, 16), 18, 4, BankInterleave::Linear),
        0
    );
    // Wrapping around an odd-sized level puts columns w - 1 and 0 (both even) side by side:
    // under the tiled interleave both rows conflict.
    assert_eq!(
        footprint_conflicts(&fp(4, 2, 5, 8), 5, 4, BankInterleave::Tiled),
        2
    );
    assert_eq!(
        footprint_conflicts(&fp(3, 2, 5, 8), 5, 4, BankInterleave::Tiled),
        0
    );
    // A 1-texel-wide level reads the same texel twice: not a conflict.
    let thin = TexelFootprint {
        x: [0, 0],
        y: [0, 0],
        ..fp(0, 0, 1, 1)
    };
    assert_eq!(footprint_conflicts(&thin, 1, 1, BankInterleave::Tiled), 0);
}

/// A texture of `levels` whose stored texels take `texel_bytes` bytes.
fn layout(levels: &[(u32, u32)], texel_bytes: u32) -> TextureLayout {
    TextureLayout {
        levels: levels.to_vec(),
        texel_bytes,
    }
}

/// A frame of `fps.len()` pixels, each doing one single-level lookup (one footprint) on a
/// 64x64 texture, with free arithmetic stages.
fn frame(fps: &[TexelFootprint]) -> FrameEvents {
    let pixels = (0..fps.len())
        .map(|i| PixelEvent {
            plan: 0,
            tri: 0,
            fp_end: i as u32 + 1,
        })
        .collect();
    FrameEvents {
        width: 8,
        height: 8,
        triangles: 0,
        spans: 0,
        fragments: 0,
        plans: vec![PlanTiming {
            stages: vec![(StageKind::Trilinear, UnitCost::default())],
        }],
        textures: vec![layout(&[(64, 64)], 8)],
        pixels,
        footprints: fps.to_vec(),
    }
}

#[test]
fn dram_open_pages() {
    let mut hw = HwConfig::texram16();
    hw.timing.dram_page_hit_cycles = 1;
    hw.timing.dram_page_miss_cycles = 6;
    hw.timing.dram_page_bytes = 2048; // 256 texels of 8 bytes: 16x16 tiles
    hw.timing.shade_pixels_in_flight = 1;
    // Same footprint twice: 4 page misses (one per bank), then 4 page hits.
    let r = simulate(&frame(&[fp(2, 2, 64, 64), fp(2, 2, 64, 64)]), &hw, "t");
    let m = &r.memory;
    assert_eq!(
        (m.dram_accesses, m.dram_page_misses, m.dram_page_hits),
        (8, 4, 4)
    );
    // Memory busy: a miss footprint occupies max over banks = 6, a hit one 1.
    let mem = r.units.iter().find(|u| u.unit == "memory").expect("memory");
    assert_eq!(mem.busy_cycles, 7);
    assert_eq!(r.miss_cycles, 5);
    // A footprint in another 16x16 tile opens new pages in every bank again.
    let r = simulate(
        &frame(&[fp(2, 2, 64, 64), fp(20, 2, 64, 64), fp(3, 3, 64, 64)]),
        &hw,
        "t",
    );
    assert_eq!(r.memory.dram_page_misses, 12);
    // One bank: 4 accesses serialize (3 conflicts), 1 miss + 3 hits on the same page.
    hw.timing.banks = 1;
    let r = simulate(&frame(&[fp(2, 2, 64, 64)]), &hw, "t");
    assert_eq!(r.memory.bank_conflicts, 3);
    assert_eq!((r.memory.dram_page_misses, r.memory.dram_page_hits), (1, 3));
    let mem = r.units.iter().find(|u| u.unit == "memory").expect("memory");
    assert_eq!(mem.busy_cycles, 6 + 3);
    assert_eq!(r.bank_conflict_cycles, 3);
}

#[test]
fn stored_texel_size_follows_channels_and_bits() {
    use hw_model::timing_config::stored_texel_bytes;
    // (channels, bits) -> bytes: packed bits rounded up to a power-of-two number of bytes.
    for (c, b, bytes) in [
        (4, 16, 8),
        (4, 8, 4),
        (4, 12, 8),
        (4, 4, 2),
        (2, 16, 4),
        (2, 8, 2),
        (3, 16, 8),
        (3, 8, 4),
        (1, 16, 2),
        (1, 8, 1),
        (1, 4, 1),
        (1, 1, 1),
    ] {
        assert_eq!(stored_texel_bytes(c, b), bytes, "{c} x {b} bits");
    }
}

#[test]
fn narrower_texels_fill_more_of_a_page_and_line() {
    // 2048-byte pages: 8-byte texels tile 16x16, 4-byte ones 32x16. Footprints at x = 2 and
    // x = 20 (same rows) share a page only with the narrower texels.
    let mut hw = HwConfig::texram16();
    hw.timing.dram_page_bytes = 2048;
    hw.timing.shade_pixels_in_flight = 1;
    let fps = [fp(2, 2, 64, 64), fp(20, 2, 64, 64)];
    let run = |bytes: u32, hw: &HwConfig| {
        let mut ev = frame(&fps);
        ev.textures = vec![layout(&[(64, 64)], bytes)];
        simulate(&ev, hw, "t")
    };
    let (wide, narrow) = (run(8, &hw), run(4, &hw));
    assert_eq!(wide.memory.dram_page_misses, 8);
    assert_eq!(narrow.memory.dram_page_misses, 4);
    assert!(narrow.total_cycles < wide.total_cycles);
    // Same accesses, half the bytes (no cache: DRAM bytes are the texels').
    assert_eq!(wide.memory.texel_accesses, narrow.memory.texel_accesses);
    assert_eq!(wide.memory.texture_bytes, 8 * 8);
    assert_eq!(narrow.memory.texture_bytes, 8 * 4);
    assert_eq!(wide.memory.dram_bytes, 8 * 8);
    assert_eq!(narrow.memory.dram_bytes, 8 * 4);
    let tri = |r: &texsim::timing::TimingReport| {
        r.units
            .iter()
            .find(|u| u.unit == "trilinear")
            .expect("trilinear")
            .texture_bytes
    };
    assert_eq!((tri(&wide), tri(&narrow)), (64, 32));
    // A 32-byte line holds 4 texels of 8 bytes (2x2) or 8 of 4 bytes (4x2): the footprint at
    // (1, 1) covers 4 lines of 2x2 but 2 lines of 4x2.
    let mut hw = HwConfig::d3d11();
    hw.timing.cache_bytes = 64 * 4;
    hw.timing.cache_line_bytes = 32;
    hw.timing.cache_ways = 4;
    let run = |bytes: u32| {
        let mut ev = frame(&[fp(1, 1, 64, 64)]);
        ev.textures = vec![layout(&[(64, 64)], bytes)];
        simulate(&ev, &hw, "t")
    };
    let (wide, narrow) = (run(8), run(4));
    assert_eq!(wide.memory.cache_misses, 4);
    assert_eq!(narrow.memory.cache_misses, 2);
    // DRAM bytes with a cache: one line per miss.
    assert_eq!(wide.memory.dram_bytes, 4 * 32);
    assert_eq!(narrow.memory.dram_bytes, 2 * 32);
}

#[test]
fn cache_in_front_of_dram() {
    let mut hw = HwConfig::d3d11();
    hw.timing.cache_bytes = 64 * 4;
    hw.timing.cache_line_bytes = 32; // 4 texels: 2x2 tiles
    hw.timing.cache_ways = 4;
    // An aligned 2x2 footprint is one line: 1 miss then 3 hits; again: 4 hits.
    let r = simulate(&frame(&[fp(2, 2, 64, 64), fp(2, 2, 64, 64)]), &hw, "t");
    assert_eq!((r.memory.cache_hits, r.memory.cache_misses), (7, 1));
    assert_eq!(r.memory.dram_accesses, 1);
    assert_eq!(r.memory.cache_hit_rate, Some(7.0 / 8.0));
    // An unaligned one touches 4 lines.
    let r = simulate(&frame(&[fp(3, 3, 64, 64)]), &hw, "t");
    assert_eq!(r.memory.cache_misses, 4);
}

#[test]
fn filter_throughput_and_units() {
    // 100 pixels, each one footprint that hits the open page: with 1 filter unit at 1
    // bilinear/cycle the filter is busy 100 cycles.
    let mut hw = HwConfig::texram16();
    hw.timing.banks = 4;
    let fps: Vec<_> = (0..100).map(|_| fp(2, 2, 64, 64)).collect();
    let r = simulate(&frame(&fps), &hw, "t");
    let f0 = r
        .units
        .iter()
        .find(|u| u.unit == "filter0")
        .expect("filter");
    assert_eq!(f0.busy_cycles, 100);
    hw.timing.trilinear_units = 2;
    let r = simulate(&frame(&fps), &hw, "t");
    let busy: u64 = r
        .units
        .iter()
        .filter(|u| u.unit.starts_with("filter"))
        .map(|u| u.busy_cycles)
        .sum();
    assert_eq!(busy, 100);
    assert!(r.total_cycles >= 100);
}

/// A frame of `n` pixels whose plan is one arithmetic stage (`Phong`) of `cycles` cycles.
fn alu_frame(n: usize, cycles: u32) -> FrameEvents {
    FrameEvents {
        width: 8,
        height: 8,
        plans: vec![PlanTiming {
            stages: vec![(
                StageKind::Phong,
                UnitCost {
                    ops: 1,
                    cycles,
                    texels: 0,
                },
            )],
        }],
        pixels: (0..n)
            .map(|_| PixelEvent {
                plan: 0,
                tri: 0,
                fp_end: 0,
            })
            .collect(),
        ..FrameEvents::default()
    }
}

fn stall(r: &texsim::timing::TimingReport, cause: &str) -> u64 {
    r.stalls
        .iter()
        .find(|s| s.cause == cause)
        .map_or_else(|| panic!("no stall cause {cause}"), |s| s.cycles)
}

#[test]
fn visibility_pass_is_the_slower_stage_plus_one_item_of_the_other() {
    // 10 triangles x 16 setup cycles = 160; traversal 40 spans x 2 + 400 fragments = 480,
    // 48 per triangle: traversal-bound, 16 + 480 = 496.
    let hw = HwConfig::texram16();
    let ev = FrameEvents {
        triangles: 10,
        spans: 40,
        fragments: 400,
        ..FrameEvents::default()
    };
    let r = simulate(&ev, &hw, "t");
    assert_eq!(r.visibility_pass_cycles, 496);
    assert_eq!(r.total_cycles, 496);
    assert_eq!(stall(&r, "traverse waits for setup"), 496 - 480);
    // Setup-bound: 100 triangles (1600 cycles) with the same traversal: 1600 + 4 = 1604.
    let r = simulate(
        &FrameEvents {
            triangles: 100,
            ..ev
        },
        &hw,
        "t",
    );
    assert_eq!(r.visibility_pass_cycles, 1604);
    assert_eq!(r.bottleneck, "setup");
    assert_eq!(r.bottleneck_cycles, 1600);
}

#[test]
fn in_flight_window_stalls_are_latency_or_the_busy_unit() {
    // Window of 2 pixels, one pixel per cycle, one 10-cycle arithmetic stage.
    let mut hw = HwConfig::texram16();
    hw.timing.shade_pixels_in_flight = 2;
    hw.timing.shade_pixels_per_cycle = 1;
    // Pipelined: p0 0..10, p1 1..11, p2 waits for p0 (8 cycles, latency: p0 never waited)
    // 10..20, p3 issues at 11 (one after p2), no wait: 11..21.
    hw.timing.alu_pipelined = true;
    let r = simulate(&alu_frame(4, 10), &hw, "t");
    assert_eq!(r.shading_pass_cycles, 21);
    assert_eq!(stall(&r, "latency"), 8);
    assert_eq!(stall(&r, "phong busy"), 0);
    assert_eq!(r.bottleneck, texsim::timing::LATENCY_BOTTLENECK);
    // Not pipelined: the unit is busy 10 cycles per pixel. p0 0..10, p1 waits for the unit
    // 10..20, p2 waits 8 for p0 (latency) then the unit: 20..30, p3 waits 9 for p1, which
    // had waited for the unit (phong busy): 30..40.
    hw.timing.alu_pipelined = false;
    let r = simulate(&alu_frame(4, 10), &hw, "t");
    assert_eq!(r.shading_pass_cycles, 40);
    assert_eq!(stall(&r, "latency"), 8);
    assert_eq!(stall(&r, "phong busy"), 9);
    assert_eq!(r.bottleneck, "phong");
    assert_eq!(r.bottleneck_cycles, 40);
    // Two pixels issue per cycle into a wide window, but the pipelined unit accepts one per
    // cycle: pixel i starts at i and finishes at i + 10.
    hw.timing.alu_pipelined = true;
    hw.timing.shade_pixels_per_cycle = 2;
    hw.timing.shade_pixels_in_flight = 64;
    let r = simulate(&alu_frame(8, 10), &hw, "t");
    assert_eq!(r.shading_pass_cycles, 7 + 10);
    assert_eq!(stall(&r, "latency"), 0);
}

#[test]
fn two_bilinears_per_cycle_halve_the_trilinear_filter_time() {
    // 100 pixels, each one trilinear lookup: footprints on levels 0 and 1.
    let mut ev = frame(&[]);
    ev.textures = vec![layout(&[(64, 64), (32, 32)], 8)];
    for i in 0..100u32 {
        ev.footprints.push(fp(2, 2, 64, 64));
        ev.footprints.push(TexelFootprint {
            level: 1,
            ..fp(1, 1, 32, 32)
        });
        ev.pixels.push(PixelEvent {
            plan: 0,
            tri: 0,
            fp_end: 2 * i + 2,
        });
    }
    let busy = |bpc: u32| {
        let mut hw = HwConfig::texram16();
        hw.timing.bilinear_per_cycle = bpc;
        simulate(&ev, &hw, "t")
            .units
            .iter()
            .filter(|u| u.unit.starts_with("filter"))
            .map(|u| u.busy_cycles)
            .sum::<u64>()
    };
    assert_eq!(busy(1), 200);
    assert_eq!(busy(2), 100);
}
