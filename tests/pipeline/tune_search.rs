//! `texsim::tune`: the width search finds a machine that meets the budget on every scene,
//! cheaper than texram16, with far fewer renders than the grid, deterministically.

use texsim::tune::{tune, Budget, Metric, Trial, TuneSpec};

fn small(name: &str, w: u32, h: u32) -> texsim::scene::Scene {
    let mut sc = texsim::scene::builtin(name).expect("built-in scene");
    sc.width = w;
    sc.height = h;
    texsim::scene::validate(&sc).expect("valid");
    sc
}

fn spec(scenes: Vec<texsim::scene::Scene>, budget: &str, knobs: &[&str]) -> TuneSpec {
    TuneSpec {
        scenes,
        base: hw_model::HwConfig::texram16(),
        budgets: vec![Budget::parse(budget).expect("budget")],
        knobs: knobs.iter().map(|k| (*k).to_string()).collect(),
        truth: 0,
    }
}

fn area(c: &hw_model::HwConfig) -> u64 {
    hw_model::datapath::total_area(&hw_model::datapath::units(c))
}

/// The done-when on small scenes: demo and bumps, max8 <= 1, every width.
#[test]
fn demo_and_bumps_max8_1_is_met_cheaper_than_texram16_with_few_renders() {
    let sp = spec(
        vec![small("demo", 96, 72), small("bumps", 96, 72)],
        "max8=1",
        &[],
    );
    let mut seen = 0usize;
    let r = tune(&sp, &mut |_t: &Trial| seen += 1).expect("tune");
    assert_eq!(seen, r.trials.len());
    let best = r.best_trial();
    assert_eq!(best.phase, "verify");
    assert_eq!(r.best, r.trials.len() - 1);
    assert!(best.meets && best.complete);
    for e in &best.scenes {
        assert!(e.max8 <= 1, "{}: max8 {}", e.scene, e.max8);
    }
    assert_eq!(best.scenes.len(), 2);
    // The found machine is the verified row's, and it is cheaper than texram16.
    assert_eq!(area(&r.machine), best.area_ge);
    assert!(best.area_ge < area(&hw_model::HwConfig::texram16()));
    assert!(r.knobs.len() > 20, "every width: {} knobs", r.knobs.len());
    for (k, v) in r.knobs.iter().zip(&best.values) {
        assert!((k.lo..=k.hi).contains(v), "{} = {v}", k.field);
    }
    // Renders: one per scene per distinct point at most, far fewer than the grid.
    let distinct: std::collections::HashSet<&Vec<u32>> =
        r.trials.iter().map(|t| &t.values).collect();
    assert!(r.renders <= 2 * distinct.len() as u64 + 2);
    assert!((r.renders as f64) < r.grid_renders / 1e6);
    assert!(r.renders < 1000, "{} renders", r.renders);
    // The found machine round-trips through a hw TOML file.
    let back = texsim::hwconfig::parse(&texsim::hwconfig::to_toml(&r.machine)).expect("toml");
    assert_eq!(back, r.machine);
}

/// Two runs give the same trials; each knob's bisection finds a value that meets the budget
/// alone, and one bit less (when not the least) misses it.
#[test]
fn search_is_deterministic_and_bisection_is_tight() {
    let sp = spec(
        vec![small("demo", 64, 48)],
        "mean8=0.05",
        &["weight_bits", "texel_bits", "lod_frac_bits"],
    );
    let a = tune(&sp, &mut |_t: &Trial| {}).expect("tune");
    let b = tune(&sp, &mut |_t: &Trial| {}).expect("tune");
    let key = |r: &texsim::tune::TuneResult| {
        r.trials
            .iter()
            .map(|t| (t.phase, t.values.clone(), t.meets, t.area_ge))
            .collect::<Vec<_>>()
    };
    assert_eq!(key(&a), key(&b));
    let best = a.best_trial();
    assert!(best.scenes[0].mean8 <= 0.05);
    // Local minimality of the verified point: every knob one lower misses the budget or
    // does not save area (the descent tried them all).
    for i in 0..a.knobs.len() {
        if best.values[i] == a.knobs[i].lo {
            continue;
        }
        let mut p = best.values.clone();
        p[i] -= 1;
        let t = a.trials.iter().find(|t| t.values == p);
        let t = t.expect("the descent tried one bit less of every knob");
        assert!(!t.meets || (t.area_ge, t.total_bits) >= (best.area_ge, best.total_bits));
    }
}

#[test]
fn budgets_parse_and_bad_ones_name_the_flag() {
    let b = Budget::parse("within1=99.5").expect("parse");
    assert_eq!(b.metric, Metric::Within1);
    assert!(b.load(99.75) <= 1.0 && b.load(99.0) > 1.0);
    let p = Budget::parse("psnr=40").expect("alias");
    assert_eq!(p.metric, Metric::Psnr8);
    assert!(p.load(f64::INFINITY) == 0.0 && p.load(39.0) > 1.0 && p.load(41.0) <= 1.0);
    let m = Budget::parse("max8=0").expect("zero");
    assert!(m.load(0.0) <= 1.0 && m.load(1.0) > 1.0);
    let f = Budget::parse("flip_mean=0.01").expect("flip");
    assert_eq!(f.metric, Metric::FlipMean);
    assert!(f.load(0.005) <= 1.0 && f.load(0.02) > 1.0 && f.load(f64::NAN).is_infinite());
    for bad in [
        "max8",
        "max9=1",
        "max8=x",
        "within1=101",
        "mean8=-1",
        "flip_p99=1.5",
        "psnr8=1e308",
    ] {
        let e = Budget::parse(bad).unwrap_err().to_string();
        assert!(e.contains("--budget"), "{bad}: {e}");
    }
    let hw = hw_model::HwConfig::texram16();
    let e = texsim::tune::knob(&hw, "weight_bit")
        .unwrap_err()
        .to_string();
    assert!(e.contains("weight_bits"), "{e}");
    let k = texsim::tune::knob(&hw, "weight_bits").expect("knob");
    assert_eq!(
        (k.field.as_str(), k.lo, k.hi),
        ("trilinear.weight_bits", 0, 16)
    );
}

/// A FLIP budget: the search computes FLIP per scene and the verified machine meets it,
/// cheaper than texram16.
#[test]
fn a_flip_budget_is_met_by_the_verified_machine() {
    let sp = spec(
        vec![small("demo", 80, 60)],
        "flip_mean=0.01",
        &["weight_bits", "texel_bits", "color_bits"],
    );
    let r = tune(&sp, &mut |_t: &Trial| {}).expect("tune");
    let best = r.best_trial();
    assert!(best.meets);
    let f = best.scenes[0].flip_mean.expect("FLIP computed");
    assert!(f <= 0.01, "{f}");
    assert!(best.area_ge < area(&hw_model::HwConfig::texram16()));
    assert!(r.trials.iter().any(|t| !t.meets), "the budget binds");
}
