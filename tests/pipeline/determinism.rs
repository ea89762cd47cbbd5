//! Every built-in scene, with every effect it uses (bumps, roughness, NDF, Ashikhmin-Shirley,
//! adaptive footprint assembly), the ground truth and the timing model, renders bit-identically on 1
//! and on 3 threads, and with the timing model off.

use texsim::render::{render, Maps, RenderOptions, Rendered};
use texsim::scene::{self, BUILTIN};
use texsim::timing::simulate;

fn render_on(threads: usize, s: &scene::Scene, hw: &hw_model::HwConfig, timing: bool) -> Rendered {
    let maps = Maps::new(s, hw.trilinear.texel_bits);
    let opts = RenderOptions {
        timing,
        truth: 4,
        ..RenderOptions::default()
    };
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool")
        .install(|| render(s, &maps, hw, &opts).expect("render"))
}

/// The stats without the wall-clock timings.
fn stats_json(r: &Rendered) -> serde_json::Value {
    let mut v = serde_json::to_value(&r.stats).expect("json");
    v.as_object_mut().expect("object").remove("timings");
    v
}

#[test]
fn every_builtin_scene_is_identical_on_1_and_3_threads() {
    let mut hw = hw_model::HwConfig::texram16();
    hw.trilinear.aniso_probes = 4;
    hw.trilinear.aniso_adaptive = true;
    for &(name, _) in BUILTIN {
        let mut s = scene::builtin(name).expect("builtin");
        s.width = 96;
        s.height = 64;
        let (a, b) = (render_on(1, &s, &hw, true), render_on(3, &s, &hw, true));
        assert!(a.hw_image == b.hw_image, "{name}: hardware image");
        assert!(a.ref_image == b.ref_image, "{name}: reference image");
        assert!(a.truth_image == b.truth_image, "{name}: truth image");
        assert_eq!(stats_json(&a), stats_json(&b), "{name}: stats");
        // The timing model never changes a pixel or a statistic.
        let c = render_on(2, &s, &hw, false);
        assert!(c.events.is_none(), "{name}: no events unless asked for");
        assert!(
            a.hw_image == c.hw_image,
            "{name}: timing changed the hardware image"
        );
        assert!(
            a.ref_image == c.ref_image,
            "{name}: timing changed the reference image"
        );
        // Apart from the timing report itself (absent without timing).
        let untimed = |r: &Rendered| {
            let mut v = stats_json(r);
            let t = v.as_object_mut().expect("object").remove("timing");
            (v, t.is_some_and(|t| !t.is_null()))
        };
        let ((sa, ta), (sc, tc)) = (untimed(&a), untimed(&c));
        assert!(ta && !tc, "{name}: the timing report only with timing");
        assert_eq!(sa, sc, "{name}: timing changed the stats");
        let (ea, eb) = (a.events.expect("events"), b.events.expect("events"));
        assert_eq!(
            serde_json::to_value(simulate(&ea, &hw, name)).expect("json"),
            serde_json::to_value(simulate(&eb, &hw, name)).expect("json"),
            "{name}: timing report"
        );
    }
}
