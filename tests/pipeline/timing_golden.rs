//! Golden cycle counts of the timing model: a fixed set of scenes x presets at 256x256.
//!
//! These numbers are the benchmark suite (docs/TIMING.md prints them as a table). The timing
//! model is deterministic integer arithmetic over a bit-exact event stream, so they are exact.
//! Changing any of them must be deliberate: update the constant, the table in docs/TIMING.md,
//! and say in the commit message which model change moved which number and why.

use texsim::render::{render, Maps, RenderOptions};
use texsim::scene::{self, BUILTIN};
use texsim::timing::{cycles, simulate, TimingReport};

/// (scene, preset[+FIELD=VALUE], total cycles, cache hits, bank conflicts, DRAM page misses).
const GOLDEN: &[(&str, &str, u64, u64, u64, u64)] = &[
    ("demo", "texram16", 562627, 0, 0, 278257),
    ("demo", "d3d11", 332441, 298244, 0, 3860),
    ("w1-plane", "texram16", 381277, 0, 0, 173232),
    ("w1-plane", "d3d11", 142703, 252254, 0, 781),
    ("w2-mesh", "texram16", 1481601, 0, 0, 340591),
    ("w2-mesh", "d3d11", 1693936, 315656, 0, 18959),
    ("bumps", "texram16", 717257, 0, 0, 395669),
    ("bumps", "d3d11", 347167, 390589, 0, 3888),
    ("lake", "texram16", 1198593, 0, 0, 513808),
    ("ripple-sphere", "texram16", 483728, 0, 0, 299457),
    (
        "ripple-sphere",
        "texram16+ndf_norm=map",
        633463,
        0,
        0,
        399276,
    ),
    ("as-brushed", "texram16", 467265, 0, 0, 0),
    (
        "w1-plane",
        "texram16+bank_interleave=linear",
        406604,
        0,
        125626,
        60118,
    ),
    ("w1-plane", "texram16+aniso_probes=4", 763477, 0, 0, 362243),
    ("w1-plane", "d3d11+aniso_probes=4", 473576, 841033, 0, 5447),
];

/// Every built-in scene on two presets at 128x128: (scene, preset, total cycles, visibility
/// pass, shading pass, sum of stall cycles, bottleneck, bottleneck cycles, texel accesses, DRAM
/// page misses). Pins the split of the frame, the stall attribution and the bottleneck too.
type Row = (
    &'static str,
    &'static str,
    u64,
    u64,
    u64,
    u64,
    &'static str,
    u64,
    u64,
    u64,
);
const EVERY_SCENE: &[Row] = &[
    (
        "demo", "texram16", 227368, 109331, 118037, 193887, "memory", 114416, 77880, 73816,
    ),
    (
        "demo", "d3d11", 173950, 109331, 64619, 140147, "setup", 109328, 77688, 1206,
    ),
    (
        "w1-plane", "texram16", 114423, 10806, 103617, 92951, "memory", 96450, 72672, 61432,
    ),
    (
        "w1-plane", "d3d11", 47202, 10806, 36396, 25651, "memory", 36342, 72552, 436,
    ),
    (
        "w2-mesh", "texram16", 1097526, 969857, 127669, 1024685, "setup", 969856, 85768, 84847,
    ),
    (
        "w2-mesh", "d3d11", 1102425, 969857, 132568, 1029514, "setup", 969856, 85688, 3092,
    ),
    (
        "sphere", "texram16", 163860, 44455, 119405, 131319, "memory", 118210, 80705, 78228,
    ),
    (
        "sphere", "d3d11", 119449, 44455, 74994, 86924, "memory", 74927, 80265, 1456,
    ),
    (
        "bumps", "texram16", 201660, 41736, 159924, 166701, "memory", 148222, 99425, 98661,
    ),
    (
        "bumps", "d3d11", 102991, 41736, 61255, 67519, "memory", 56927, 99277, 784,
    ),
    (
        "as-metal", "texram16", 534526, 433569, 100957, 492089, "setup", 433568, 0, 0,
    ),
    (
        "as-metal", "d3d11", 458926, 433569, 25357, 416489, "setup", 433568, 0, 0,
    ),
    (
        "as-plastic",
        "texram16",
        534526,
        433569,
        100957,
        492089,
        "setup",
        433568,
        0,
        0,
    ),
    (
        "as-plastic",
        "d3d11",
        458926,
        433569,
        25357,
        416489,
        "setup",
        433568,
        0,
        0,
    ),
    (
        "as-brushed",
        "texram16",
        208382,
        122049,
        86333,
        187636,
        "setup",
        122048,
        0,
        0,
    ),
    (
        "as-brushed",
        "d3d11",
        143726,
        122049,
        21677,
        122980,
        "setup",
        122048,
        0,
        0,
    ),
    (
        "lake", "texram16", 290665, 8614, 282051, 273060, "memory", 193536, 121344, 121344,
    ),
    (
        "lake", "d3d11", 172262, 8614, 163648, 153441, "memory", 49166, 121120, 460,
    ),
    (
        "corrugated",
        "texram16",
        322951,
        9156,
        313795,
        304292,
        "memory",
        215040,
        141824,
        141824,
    ),
    (
        "corrugated",
        "d3d11",
        194819,
        9156,
        185663,
        174969,
        "memory",
        60173,
        141600,
        616,
    ),
    (
        "brushed", "texram16", 387717, 11202, 376515, 365220, "memory", 258048, 172032, 172032,
    ),
    (
        "brushed", "d3d11", 293248, 11202, 282046, 269859, "memory", 131598, 171600, 2307,
    ),
    (
        "scratches",
        "texram16",
        350795,
        10120,
        340675,
        330404,
        "memory",
        233472,
        155648,
        155648,
    ),
    (
        "scratches",
        "d3d11",
        256309,
        10120,
        246189,
        235326,
        "memory",
        109987,
        155360,
        1947,
    ),
    (
        "sky-lake", "texram16", 2423281, 8614, 2414667, 2401628, "memory", 244224, 155136, 152940,
    ),
    (
        "sky-lake", "d3d11", 2359717, 8614, 2351103, 2323419, "memory", 128720, 154912, 2585,
    ),
    (
        "chrome-sphere",
        "texram16",
        3065476,
        44455,
        3021021,
        3028425,
        "memory",
        365778,
        241282,
        241282,
    ),
    (
        "chrome-sphere",
        "d3d11",
        3200428,
        44455,
        3155973,
        3150692,
        "memory",
        439074,
        240250,
        12067,
    ),
    (
        "brushed-sky",
        "texram16",
        3153003,
        11202,
        3141801,
        3126362,
        "memory",
        367704,
        244954,
        244954,
    ),
    (
        "brushed-sky",
        "d3d11",
        3128812,
        11202,
        3117610,
        3086933,
        "memory",
        279546,
        244114,
        6680,
    ),
    (
        "ripple-sphere",
        "texram16",
        177360,
        23095,
        154265,
        160723,
        "memory",
        154008,
        102672,
        102672,
    ),
    (
        "ripple-sphere",
        "d3d11",
        153729,
        23095,
        130634,
        136504,
        "memory",
        130382,
        102432,
        3076,
    ),
    (
        "lod-pair", "texram16", 236012, 44837, 191175, 210887, "memory", 155434, 117288, 100832,
    ),
    (
        "lod-pair", "d3d11", 161092, 44837, 116255, 135691, "memory", 110670, 117212, 2312,
    ),
    (
        "foil", "texram16", 190501, 5492, 185009, 179318, "memory", 184752, 123168, 123168,
    ),
    (
        "foil", "d3d11", 92462, 5492, 86970, 81120, "memory", 86718, 123168, 1530,
    ),
    (
        "fournier-fig2",
        "texram16",
        158077,
        39368,
        118709,
        126788,
        "latency (in-flight window)",
        108376,
        0,
        0,
    ),
    (
        "fournier-fig2",
        "d3d11",
        69476,
        39368,
        30108,
        38187,
        "setup",
        39360,
        0,
        0,
    ),
    (
        "fournier-velvet",
        "texram16",
        249336,
        91219,
        158117,
        221202,
        "latency (in-flight window)",
        150040,
        0,
        0,
    ),
    (
        "fournier-velvet",
        "d3d11",
        130998,
        91219,
        39779,
        102864,
        "setup",
        91216,
        0,
        0,
    ),
    (
        "fournier-silk",
        "texram16",
        204231,
        91219,
        113012,
        176190,
        "latency (in-flight window)",
        105028,
        0,
        0,
    ),
    (
        "fournier-silk",
        "d3d11",
        119652,
        91219,
        28433,
        91611,
        "setup",
        91216,
        0,
        0,
    ),
    (
        "two-slope",
        "texram16",
        111830,
        8752,
        103078,
        94327,
        "memory",
        102912,
        63232,
        63232,
    ),
    (
        "two-slope",
        "d3d11",
        40538,
        8752,
        31786,
        22865,
        "memory",
        27448,
        63232,
        300,
    ),
];

fn config(spec: &str) -> hw_model::HwConfig {
    let (preset, edit) = spec
        .split_once('+')
        .map_or((spec, None), |(p, e)| (p, Some(e)));
    let hw = hw_model::HwConfig::preset(preset).expect("preset");
    match edit.and_then(|e| e.split_once('=')) {
        Some((f, v)) => texsim::hwconfig::set_field(&hw, f, v).expect("field"),
        None => hw,
    }
}

fn small(name: &str) -> scene::Scene {
    let mut s = scene::builtin(name).expect("builtin scene");
    s.width = 256;
    s.height = 256;
    s
}

#[test]
fn golden_cycle_counts() {
    let mut got = Vec::new();
    for &(name, preset, ..) in GOLDEN {
        let s = small(name);
        let hw = config(preset);
        let maps = Maps::new(&s, hw.trilinear.texel_bits);
        let (_, r) = cycles(&s, &maps, &hw).expect("cycles");
        got.push((
            name,
            preset,
            r.total_cycles,
            r.memory.cache_hits,
            r.memory.bank_conflicts,
            r.memory.dram_page_misses,
        ));
    }
    let want: Vec<_> = GOLDEN.to_vec();
    assert_eq!(got, want, "golden cycle counts changed; got {got:?}");
}

#[test]
fn timing_is_deterministic_and_does_not_change_pixels() {
    let s = small("demo");
    let hw = hw_model::HwConfig::d3d11();
    let maps = Maps::new(&s, hw.trilinear.texel_bits);
    let plain = render(
        &s,
        &maps,
        &hw,
        &RenderOptions {
            reference: false,
            ..Default::default()
        },
    )
    .expect("render");
    assert!(plain.events.is_none(), "no events unless asked for");
    let (a, ra) = cycles(&s, &maps, &hw).expect("cycles");
    let (b, rb) = cycles(&s, &maps, &hw).expect("cycles");
    assert_eq!(a.hw_image, plain.hw_image, "timing must not change a pixel");
    assert_eq!(ra, rb);
    assert_eq!(
        a.events.as_ref().map(|e| e.pixels.len()),
        b.events.as_ref().map(|e| e.pixels.len())
    );
    // Every covered pixel is one pixel event; re-simulating gives the same report.
    let ev = a.events.as_ref().expect("events");
    assert_eq!(ev.pixels.len() as u64, a.stats.covered_pixels);
    assert_eq!(simulate(ev, &hw, &s.name), ra);
    // Footprints: one per level used per lookup, so texels = 4 x footprints = stage texels
    // for two-level lookups and at most that otherwise.
    let tex_stage: u64 = a.stats.stages.iter().map(|x| x.texels).sum();
    assert!(4 * ev.footprints.len() as u64 <= tex_stage);
    assert!(8 * ev.footprints.len() as u64 >= tex_stage);
}

#[test]
fn modern_preset_is_faster_and_cached() {
    let s = small("w1-plane");
    let mut out = Vec::new();
    for p in ["texram16", "d3d11"] {
        let hw = hw_model::HwConfig::preset(p).expect("preset");
        let maps = Maps::new(&s, hw.trilinear.texel_bits);
        out.push(cycles(&s, &maps, &hw).expect("cycles").1);
    }
    assert!(out[0].memory.cache_hit_rate.is_none());
    let hr = out[1].memory.cache_hit_rate.expect("cache");
    assert!(hr > 0.5 && hr <= 1.0, "hit rate {hr}");
    assert!(out[1].total_cycles < out[0].total_cycles);
    for r in &out {
        assert!(r.cycles_per_pixel > 0.0);
        let used: u64 = r.stalls.iter().skip(1).map(|s| s.cycles).sum();
        assert!(used <= r.shading_pass_cycles, "stalls bounded by the pass");
        assert!(r.units.iter().all(|u| u.busy_cycles <= r.total_cycles));
    }
}

/// A report's row of [`EVERY_SCENE`] (the bottleneck owned).
fn row(name: &'static str, preset: &'static str, r: &TimingReport) -> OwnedRow {
    (
        name,
        preset,
        r.total_cycles,
        r.visibility_pass_cycles,
        r.shading_pass_cycles,
        r.stalls.iter().map(|s| s.cycles).sum::<u64>(),
        r.bottleneck.clone(),
        r.bottleneck_cycles,
        r.memory.texel_accesses,
        r.memory.dram_page_misses,
    )
}

type OwnedRow = (
    &'static str,
    &'static str,
    u64,
    u64,
    u64,
    u64,
    String,
    u64,
    u64,
    u64,
);

#[test]
fn every_builtin_scene_on_two_presets() {
    let mut got = Vec::new();
    for &(name, _) in BUILTIN {
        for preset in ["texram16", "d3d11"] {
            let mut s = scene::builtin(name).expect("builtin scene");
            s.width = 128;
            s.height = 128;
            let hw = config(preset);
            let maps = Maps::new(&s, hw.trilinear.texel_bits);
            let (_, r) = cycles(&s, &maps, &hw).expect("cycles");
            got.push(row(name, preset, &r));
        }
    }
    let want: Vec<OwnedRow> = EVERY_SCENE
        .iter()
        .map(|&(n, p, t, v, sh, st, b, bc, ta, pm)| (n, p, t, v, sh, st, b.to_string(), bc, ta, pm))
        .collect();
    let listing: Vec<String> = got.iter().map(|r| format!("    {r:?},")).collect();
    assert!(
        got == want,
        "golden cycle counts of the scene suite changed; got:\n{}",
        listing.join("\n")
    );
}

/// The README and docs/TIMING.md print the golden table: every row's numbers are there.
#[test]
fn documented_tables_match_the_golden_counts() {
    let root = env!("CARGO_MANIFEST_DIR");
    for doc in ["README.md", "docs/TIMING.md"] {
        let text = std::fs::read_to_string(format!("{root}/{doc}")).expect("doc");
        for &(name, preset, total, hits, conflicts, misses) in GOLDEN {
            let cells = format!("| {total} | {hits} | {conflicts} | {misses} |");
            assert!(
                text.lines()
                    .any(|l| l.starts_with(&format!("| {name} |")) && l.ends_with(&cells)),
                "{doc}: no table row for {name} on {preset} ending in {cells}"
            );
        }
    }
}

/// Storage is sized by its format: on demo (colour and offset maps, both stored at
/// `texel_bits`) 8-bit texels are exactly half the texture bytes of 16-bit ones, fill twice the
/// texels per DRAM page and cache line, and so cost fewer page misses (texram16), more cache
/// hits (d3d11) and fewer cycles; the texel accesses are the same.
#[test]
fn texel_bits_size_the_memory_traffic() {
    let mut s = scene::builtin("demo").expect("demo");
    s.width = 128;
    s.height = 96;
    for preset in ["texram16", "d3d11"] {
        let run = |bits: &str| {
            let hw = config(&format!("{preset}+texel_bits={bits}"));
            let maps = Maps::new(&s, hw.trilinear.texel_bits);
            cycles(&s, &maps, &hw).expect("cycles").1
        };
        let (wide, narrow) = (run("16"), run("8"));
        let (w, n) = (&wide.memory, &narrow.memory);
        assert_eq!(w.texel_accesses, n.texel_accesses, "{preset}");
        assert_eq!(w.texture_bytes, 2 * n.texture_bytes, "{preset}");
        assert!(narrow.total_cycles < wide.total_cycles, "{preset}");
        if w.cache_hit_rate.is_some() {
            assert!(n.cache_hits > w.cache_hits, "{preset}");
            assert!(n.dram_bytes < w.dram_bytes, "{preset}");
        } else {
            assert!(n.dram_page_misses < w.dram_page_misses, "{preset}");
            assert_eq!(w.dram_bytes, 2 * n.dram_bytes, "{preset}");
        }
        // Per stage: the trilinear and bump-fetch units read their own maps' bytes.
        let bytes = |r: &TimingReport, u: &str| {
            r.units
                .iter()
                .find(|x| x.unit == u)
                .map_or(0, |x| x.texture_bytes)
        };
        for u in ["trilinear", "bump-fetch"] {
            assert!(bytes(&narrow, u) > 0, "{preset} {u}");
            assert_eq!(bytes(&wide, u), 2 * bytes(&narrow, u), "{preset} {u}");
        }
        let per_stage: u64 = wide.units.iter().map(|x| x.texture_bytes).sum();
        assert_eq!(per_stage, w.texture_bytes, "{preset}");
    }
}

/// The timing report of `name` (96x64) rendered on `threads` threads, keeping the event
/// stream or not, and that stream.
fn timed_on(
    threads: usize,
    name: &str,
    hw: &hw_model::HwConfig,
    keep_events: bool,
) -> (TimingReport, Option<texsim::timing::FrameEvents>) {
    timed_at(threads, name, hw, keep_events, (96, 64))
}

/// [`timed_on`] at `width` x `height`.
fn timed_at(
    threads: usize,
    name: &str,
    hw: &hw_model::HwConfig,
    keep_events: bool,
    (width, height): (u32, u32),
) -> (TimingReport, Option<texsim::timing::FrameEvents>) {
    let mut s = scene::builtin(name).expect("builtin scene");
    s.width = width;
    s.height = height;
    let maps = Maps::new(&s, hw.trilinear.texel_bits);
    let opts = RenderOptions {
        reference: false,
        timing: true,
        keep_events,
        ..Default::default()
    };
    let r = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool")
        .install(|| render(&s, &maps, hw, &opts).expect("render"));
    (r.stats.timing.expect("timing report"), r.events)
}

#[test]
fn streamed_model_is_the_same_on_one_thread_and_fed_by_the_workers() {
    // One thread feeds each fragment's trace to the model; on more, the workers take the rows
    // in order and whichever finds the model free feeds it the finished rows.
    // With or without the kept stream, the report is that of `simulate` over the stream.
    let mut aniso = hw_model::HwConfig::d3d11();
    aniso.trilinear.aniso_probes = 4;
    aniso.trilinear.aniso_adaptive = true;
    for hw in [hw_model::HwConfig::texram16(), aniso] {
        for &(name, _) in BUILTIN {
            let (kept, ev) = timed_on(1, name, &hw, true);
            let ev = ev.expect("kept events");
            assert_eq!(simulate(&ev, &hw, name), kept, "{name}: one thread, kept");
            let (fed, ev3) = timed_on(3, name, &hw, true);
            assert_eq!(fed, kept, "{name}: three threads, kept");
            let ev3 = ev3.expect("kept events");
            assert_eq!(ev3.pixels, ev.pixels, "{name}: pixel events");
            assert_eq!(ev3.footprints, ev.footprints, "{name}: footprints");
            for threads in [1, 3] {
                let (r, none) = timed_on(threads, name, &hw, false);
                assert!(none.is_none(), "{name}: no stream unless kept");
                assert_eq!(r, kept, "{name}: {threads} threads, not kept");
            }
        }
    }
}

#[test]
fn rows_reach_the_model_in_order_whichever_worker_feeds_them() {
    // Tall frames of short rows: many rows finish while another worker feeds the model, so
    // rows wait in their slots, are fed by a later worker or after the last row. Every run,
    // on 2 to 4 threads, repeated, gives the one-thread model and stream.
    let hw = hw_model::HwConfig::texram16();
    for (name, size) in [("w1-plane", (24, 600)), ("demo", (40, 360))] {
        let (one, ev) = timed_at(1, name, &hw, true, size);
        let ev = ev.expect("kept events");
        for threads in [2, 3, 4] {
            for _ in 0..3 {
                let (r, ev_n) = timed_at(threads, name, &hw, true, size);
                assert_eq!(r, one, "{name}: {threads} threads");
                let ev_n = ev_n.expect("kept events");
                assert_eq!(
                    ev_n.pixels, ev.pixels,
                    "{name}: {threads} threads, pixel events"
                );
                assert_eq!(ev_n.footprints, ev.footprints, "{name}: {threads} threads");
                assert_eq!(timed_at(threads, name, &hw, false, size).0, one, "{name}");
            }
        }
    }
}
