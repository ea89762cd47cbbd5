//! The timing model against its previous implementation ([`super::previous`], the oracle) on
//! seeded random event streams: random machines (cache or not, tiled or linear interleave, bank
//! counts that are not powers of two, several filter units, pipelined or not), textures of
//! every texel size and plans with repeated stage kinds, pixels with thin, wrapped and
//! out-of-plan footprints; and streams whose footprints come only from the plans' fetching
//! stages in plan order, as a render's do (so plans with one fetching stage take the
//! model's one-stage walk). Every report must be identical, fed as a frame ([`simulate`]),
//! row by row ([`Simulator::row`]), span by span ([`Simulator::span`]: runs of one plan) or
//! pixel by pixel ([`Simulator::pixel`]).

use super::events::{
    lookups, FrameEvents, PixelEvent, PlanTiming, RowEvents, TexelFootprint, TextureLayout,
};
use super::model::{simulate, Simulator};
use super::previous;
use crate::pipeline::StageKind;
use crate::rng_common::Rng;
use hw_model::timing_config::BankInterleave;
use hw_model::{HwConfig, UnitCost};

fn pick<T: Copy>(r: &mut Rng, xs: &[T]) -> T {
    xs[r.below(xs.len() as u64) as usize]
}

/// A footprint of stage `kind`'s lookup on level `level` (of `size`) of texture `tex`: a
/// random texel and, now and then not, its right and lower neighbours (wrapping).
fn random_footprint(
    r: &mut Rng,
    kind: StageKind,
    lookup: u8,
    tex: usize,
    level: usize,
    (w, h): (u32, u32),
) -> TexelFootprint {
    let (x0, y0) = (r.below(u64::from(w)) as u32, r.below(u64::from(h)) as u32);
    let x1 = if r.below(8) == 0 { x0 } else { (x0 + 1) % w };
    let y1 = if r.below(8) == 0 { y0 } else { (y0 + 1) % h };
    TexelFootprint {
        stage: kind.index() as u8,
        lookup,
        level: level as u8,
        tex: tex as u16,
        x: [x0, x1],
        y: [y0, y1],
    }
}

fn machine(r: &mut Rng) -> HwConfig {
    let mut hw = HwConfig::texram16();
    let t = &mut hw.timing;
    t.trilinear_units = pick(r, &[1, 1, 2, 3]);
    t.bilinear_per_cycle = pick(r, &[1, 2, 3]);
    t.banks = pick(r, &[1, 2, 3, 4, 6, 8, 16, 64]);
    t.bank_interleave = pick(r, &[BankInterleave::Tiled, BankInterleave::Linear]);
    t.cache_line_bytes = pick(r, &[8, 16, 32, 64]);
    t.cache_ways = pick(r, &[1, 2, 3, 4]);
    t.cache_bytes = pick(r, &[0, 0, 256, 1024, 16384]);
    t.cache_hit_cycles = pick(r, &[0, 1, 4]);
    t.dram_page_bytes = pick(r, &[64, 512, 2048]);
    t.dram_page_hit_cycles = pick(r, &[1, 2, 8]);
    t.dram_page_miss_cycles = pick(r, &[1, 6, 40]);
    t.shade_pixels_per_cycle = pick(r, &[1, 1, 2, 3]);
    t.shade_pixels_in_flight = pick(r, &[1, 4, 16, 64]);
    t.alu_pipelined = r.below(4) != 0;
    hw
}

/// A random frame of `pixels` pixels. With `fetching` (the machine), a pixel's footprints
/// are those of its plan's stages that make lookups on it, each stage fetching with
/// probability 3/4, in plan order; else of random stages of its plan, now and then of a
/// stage outside it or out of order.
fn frame(r: &mut Rng, pixels: usize, fetching: Option<&HwConfig>) -> FrameEvents {
    let textures: Vec<TextureLayout> = (0..1 + r.below(3))
        .map(|_| {
            let (mut w, mut h) = (1 + r.below(80) as u32, 1 + r.below(80) as u32);
            let mut levels = vec![(w, h)];
            while (w, h) != (1, 1) && levels.len() < 8 {
                (w, h) = ((w / 2).max(1), (h / 2).max(1));
                levels.push((w, h));
            }
            TextureLayout {
                levels,
                texel_bytes: pick(r, &[1, 2, 4, 8]),
            }
        })
        .collect();
    let kinds = StageKind::ALL;
    let plans: Vec<PlanTiming> = (0..1 + r.below(3))
        .map(|_| PlanTiming {
            stages: (0..1 + r.below(6))
                .map(|_| {
                    let cost = UnitCost {
                        cycles: r.below(24) as u32,
                        ..UnitCost::default()
                    };
                    (pick(r, &kinds[..8]), cost)
                })
                .collect(),
        })
        .collect();
    let mut ev = FrameEvents {
        width: 64,
        height: 64,
        triangles: r.below(50),
        spans: r.below(500),
        fragments: r.below(5000),
        plans,
        textures,
        ..FrameEvents::default()
    };
    for _ in 0..pixels {
        // Now and then a plan the frame does not have.
        let extra = u64::from(r.below(50) == 0);
        let plan = r.below(ev.plans.len() as u64 + extra) as u32;
        let stages: Vec<StageKind> = ev
            .plans
            .get(plan as usize)
            .map_or(vec![StageKind::Trilinear], |p| {
                p.stages.iter().map(|s| s.0).collect()
            });
        // Footprints in plan order (now and then a stage outside the plan, or out of order).
        let order: Vec<StageKind> = if let Some(hw) = fetching {
            stages
                .iter()
                .filter(|&&k| lookups(k, hw) > 0 && r.below(4) != 0)
                .copied()
                .collect()
        } else {
            let mut order: Vec<StageKind> =
                stages.iter().filter(|_| r.below(3) == 0).copied().collect();
            if r.below(30) == 0 {
                order.push(pick(r, &kinds));
                order.reverse();
            }
            order
        };
        for kind in order {
            for lookup in 0..1 + r.below(3) as u8 {
                let tex = r.below(ev.textures.len() as u64) as usize;
                let lv = &ev.textures[tex].levels;
                for _ in 0..1 + r.below(2) {
                    let level = r.below(lv.len() as u64) as usize;
                    let fp = random_footprint(r, kind, lookup, tex, level, lv[level]);
                    ev.footprints.push(fp);
                }
            }
        }
        ev.pixels.push(PixelEvent {
            plan,
            tri: 0,
            fp_end: ev.footprints.len() as u32,
        });
    }
    ev
}

#[test]
fn model_matches_previous_on_random_streams() {
    let mut r = Rng(0x7131_2026);
    for case in 0..400 {
        let hw = machine(&mut r);
        let n = 1 + r.below(3000) as usize;
        let ev = frame(&mut r, n, None);
        check(&mut r, case, &hw, &ev);
    }
}

/// As [`model_matches_previous_on_random_streams`], footprints only from fetching stages:
/// plans with one fetching stage (the one-stage walk) and with several, repeated or not.
#[test]
fn model_matches_previous_on_fetching_streams() {
    let mut r = Rng(0x5eed_f7c4);
    let mut mono = 0;
    for case in 0..300 {
        let hw = machine(&mut r);
        let n = 1 + r.below(3000) as usize;
        let ev = frame(&mut r, n, Some(&hw));
        mono += usize::from(ev.plans.iter().any(|p| {
            let fetching = p.stages.iter().filter(|s| lookups(s.0, &hw) > 0);
            fetching.count() == 1
        }));
        check(&mut r, case, &hw, &ev);
    }
    assert!(
        mono > 100,
        "only {mono} frames with a one-fetching-stage plan"
    );
}

/// As [`model_matches_previous_on_fetching_streams`] on frames as a plain textured render
/// makes them: machines issuing mostly one pixel per cycle with pipelined arithmetic, plans
/// of distinct stage kinds with one fetching stage (trilinear) and pixels that mostly make
/// one lookup of one or two footprints, now and then none, several lookups or a footprint
/// of another stage: the one-lookup walk, with and without its steps before the fetching
/// stage skipped (`settle`), cached and uncached, tiled and linear, 1 to 3 filter units.
#[test]
fn model_matches_previous_on_one_lookup_streams() {
    let mut r = Rng(0x1100_4b7e);
    for case in 0..300 {
        let (hw, ev) = one_lookup_frame(&mut r, 0, 40);
        check(&mut r, case, &hw, &ev);
    }
}

/// As [`model_matches_previous_on_one_lookup_streams`] with short runs of one plan (a mesh's
/// spans), often of a plan the frame does not have and with more pixels of the general walk,
/// fed in spans of 1 to 12 pixels: the units skipped for a plan's pixels stay so across its
/// spans and are settled when another plan's pixel, a pixel of the general walk or the report
/// comes.
#[test]
fn model_matches_previous_on_short_mixed_spans() {
    let mut r = Rng(0x5a0e_7d12);
    for case in 0..300 {
        let (hw, ev) = one_lookup_frame(&mut r, 4, 12);
        check(&mut r, case, &hw, &ev);
    }
}

/// As [`model_matches_previous_on_one_lookup_streams`] on the default machine's memory and
/// units (no texel cache, four banks tiled 2x2, one filter unit, one pixel per cycle,
/// pipelined arithmetic: `Simulator::run_in`'s quad lane) with coherent footprints, as a
/// textured surface makes them: each lookup's footprints walk their level a texel or two
/// from the previous ones, now and then jumping, so runs of footprints stay in one DRAM page
/// (all four banks holding it) and cross into the next; now and then a thin footprint (one
/// column or row, so two texels share a bank), none, two lookups or another stage's, and a
/// plan the frame does not have, mid-run.
#[test]
fn quad_lane_matches_previous() {
    let mut r = Rng(0x9aad_1a4e);
    for case in 0..300 {
        let (stay, odd) = pick(&mut r, &[(0, 40), (4, 12), (50, 200)]);
        let (mut hw, mut ev) = one_lookup_frame(&mut r, stay, odd);
        let t = &mut hw.timing;
        t.cache_bytes = 0;
        t.banks = 4;
        t.bank_interleave = BankInterleave::Tiled;
        t.trilinear_units = 1;
        t.shade_pixels_per_cycle = 1;
        t.alu_pipelined = r.below(16) != 0;
        t.dram_page_bytes = pick(&mut r, &[64, 256, 2048]);
        let mut at = [(0u32, 0u32); 16];
        for f in &mut ev.footprints {
            let (w, h) = ev.textures[usize::from(f.tex)].levels[usize::from(f.level)];
            let cursor = &mut at[usize::from(f.level) & 15];
            *cursor = if r.below(64) == 0 {
                (r.below(u64::from(w)) as u32, r.below(u64::from(h)) as u32)
            } else {
                let step = (r.below(3) as u32, u32::from(r.below(16) == 0));
                ((cursor.0 + step.0) % w, (cursor.1 + step.1) % h)
            };
            let (x0, y0) = *cursor;
            let thin = r.below(32) == 0;
            f.x = [x0, if thin { x0 } else { (x0 + 1) % w }];
            f.y = [y0, (y0 + 1) % h];
        }
        check(&mut r, case, &hw, &ev);
    }
}

/// A machine and frame for [`model_matches_previous_on_one_lookup_streams`]: a pixel keeps
/// the previous pixel's plan with probability `stay / (stay + 1)` (a random plan, now and then
/// one the frame does not have, when `stay` > 0; else always a random plan of the frame), and
/// one pixel in `odd` / 4 (about) makes no lookup, two or one of another stage.
fn one_lookup_frame(r: &mut Rng, stay: u64, odd: u64) -> (HwConfig, FrameEvents) {
    let trilinear = StageKind::Trilinear;
    let mut hw = machine(r);
    hw.timing.shade_pixels_per_cycle = pick(r, &[1, 1, 1, 2]);
    hw.timing.alu_pipelined = r.below(8) != 0;
    let mut ev = frame(r, 0, None);
    let plain = [0, 1, 2, 3, 5, 6];
    for p in &mut ev.plans {
        // Distinct kinds in pipeline order around the trilinear stage.
        let mut kinds: Vec<StageKind> = plain
            .iter()
            .filter(|_| r.below(2) == 0)
            .map(|&i| StageKind::ALL[i])
            .collect();
        kinds.push(trilinear);
        kinds.sort_by_key(|k| k.index());
        p.stages = kinds
            .into_iter()
            .map(|k| {
                let cost = UnitCost {
                    cycles: pick(r, &[0, 1, 1, 2, 5, 12]),
                    ..UnitCost::default()
                };
                (k, cost)
            })
            .collect();
    }
    let n = 1 + r.below(3000) as usize;
    let plans = ev.plans.len() as u64;
    let mut plan = 0;
    for i in 0..n {
        if i == 0 || stay == 0 || r.below(stay + 1) == 0 {
            let extra = u64::from(stay > 0 && r.below(8) == 0);
            plan = r.below(plans + extra) as u32;
        }
        let (lookups, stage) = match r.below(odd) {
            0 => (0, trilinear),
            1 => (2, trilinear),
            2 => (1, StageKind::BumpFetch),
            _ => (1, trilinear),
        };
        for lookup in 0..lookups {
            let tex = r.below(ev.textures.len() as u64) as usize;
            let lv = &ev.textures[tex].levels;
            let level = r.below(lv.len() as u64) as usize;
            let levels = 1 + r.below(2) as usize;
            for (l, &size) in lv.iter().enumerate().skip(level).take(levels) {
                let fp = random_footprint(r, stage, lookup, tex, l, size);
                ev.footprints.push(fp);
            }
        }
        ev.pixels.push(PixelEvent {
            plan,
            tri: 0,
            fp_end: ev.footprints.len() as u32,
        });
    }
    (hw, ev)
}

/// The model's reports on `ev` (as a frame, rows, pixels and spans cut at random) against
/// the previous model's.
fn check(r: &mut Rng, case: usize, hw: &HwConfig, ev: &FrameEvents) {
    let want = previous::simulate(ev, hw, "t");
    assert_eq!(simulate(ev, hw, "t"), want, "case {case}: frame");
    // Row by row (rows of 1..40 pixels, `fp_end` rebased) and pixel by pixel.
    let mut rows = Simulator::new(&ev.plans, &ev.textures, hw);
    let mut pixels = Simulator::new(&ev.plans, &ev.textures, hw);
    let mut spans = Simulator::new(&ev.plans, &ev.textures, hw);
    let start = |i: usize| {
        if i == 0 {
            0
        } else {
            ev.pixels[i - 1].fp_end as usize
        }
    };
    let mut p = 0;
    while p < ev.pixels.len() {
        let end = (p + 1 + r.below(40) as usize).min(ev.pixels.len());
        let f = start(p);
        let row = RowEvents {
            pixels: ev.pixels[p..end]
                .iter()
                .map(|&e| PixelEvent {
                    fp_end: e.fp_end - f as u32,
                    ..e
                })
                .collect(),
            footprints: ev.footprints[f..start(end)].to_vec(),
        };
        rows.row(&row);
        for i in p..end {
            let fps = &ev.footprints[start(i)..start(i + 1)];
            pixels.pixel(ev.pixels[i].plan, fps);
        }
        // Spans: runs of up to 1..12 pixels of one plan.
        let mut s = p;
        while s < end {
            let plan = ev.pixels[s].plan;
            let most = (s + 1 + r.below(12) as usize).min(end);
            let e = (s + 1..most)
                .find(|&i| ev.pixels[i].plan != plan)
                .unwrap_or(most);
            spans.span(plan, (s..e).map(|i| &ev.footprints[start(i)..start(i + 1)]));
            s = e;
        }
        p = end;
    }
    assert_eq!(rows.finish(&ev.counts(), "t"), want, "case {case}: rows");
    assert_eq!(
        pixels.finish(&ev.counts(), "t"),
        want,
        "case {case}: pixels"
    );
    assert_eq!(spans.finish(&ev.counts(), "t"), want, "case {case}: spans");
}
