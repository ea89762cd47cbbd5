//! Golden cycle counts of the timing model: a fixed set of scenes x presets at 256x256.
//!
//! These numbers are the benchmark suite (docs/TIMING.md prints them as a table). The timing
//! model is deterministic integer arithmetic over a bit-exact event stream, so they are exact.
//! Changing any of them must be deliberate: update the constant, the table in docs/TIMING.md,
//! and say in the commit message which model change moved which number and why.

use texsim::render::{render, Maps, RenderOptions};
use texsim::scene;
use texsim::timing::{cycles, simulate};

/// (scene, preset[+FIELD=VALUE], total cycles, cache hits, bank conflicts, DRAM page misses).
const GOLDEN: &[(&str, &str, u64, u64, u64, u64)] = &[
    ("demo", "texram16", 547268, 0, 0, 278271),
    ("demo", "d3d11", 352827, 297423, 0, 4520),
    ("w1-plane", "texram16", 339825, 0, 0, 173232),
    ("w1-plane", "d3d11", 142679, 252254, 0, 781),
    ("w2-mesh", "texram16", 1481565, 0, 0, 340591),
    ("w2-mesh", "d3d11", 1693909, 315656, 0, 18959),
    ("bumps", "texram16", 672731, 0, 0, 395720),
    ("bumps", "d3d11", 521200, 382201, 0, 9320),
    ("lake", "texram16", 966323, 0, 0, 513808),
    ("ripple-sphere", "texram16", 483653, 0, 0, 299457),
    (
        "ripple-sphere",
        "texram16+ndf_norm=map",
        633390,
        0,
        0,
        399276,
    ),
    ("as-brushed", "texram16", 368300, 0, 0, 0),
    (
        "w1-plane",
        "texram16+bank_interleave=linear",
        377573,
        0,
        125626,
        60118,
    ),
    ("w1-plane", "texram16+aniso_probes=4", 738161, 0, 0, 362243),
    ("w1-plane", "d3d11+aniso_probes=4", 473543, 841033, 0, 5447),
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
