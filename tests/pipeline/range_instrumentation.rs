//! `render --ranges` (`texsim::render::ranges`): per stage and signal the range of the float
//! reference, the values outside the declared format and the integer bits needed.

use texsim::render::ranges::{int_bits_for, SignalRange};
use texsim::render::{render, Maps, RenderOptions};

fn ranges_of(scene: &str, hw: &hw_model::HwConfig) -> Vec<SignalRange> {
    let mut sc = texsim::scene::builtin(scene).expect("scene");
    sc.width = 96;
    sc.height = 72;
    texsim::scene::validate(&sc).expect("valid");
    let maps = Maps::new(&sc, hw.trilinear.texel_bits);
    let opts = RenderOptions {
        ranges: true,
        ..RenderOptions::default()
    };
    let r = render(&sc, &maps, hw, &opts).expect("render");
    r.stats.ranges.expect("ranges asked for")
}

fn row<'a>(rows: &'a [SignalRange], signal: &str) -> &'a SignalRange {
    rows.iter()
        .find(|r| r.signal == signal)
        .unwrap_or_else(|| panic!("no signal {signal}"))
}

#[test]
fn integer_bits_hold_the_range() {
    assert_eq!(int_bits_for(0.0, 1.0), 0, "unorm: 1.0 is the all-ones code");
    assert_eq!(int_bits_for(-0.5, 0.99), 0);
    assert_eq!(int_bits_for(-1.0, 0.5), 0);
    assert_eq!(int_bits_for(-1.0, 1.0), 1);
    assert_eq!(int_bits_for(0.0, 173.8), 8);
    assert_eq!(int_bits_for(0.0, 256.0), 9);
    assert_eq!(int_bits_for(-3.0, 2.0), 2);
    assert_eq!(int_bits_for(-4.5, 2.0), 3);
}

#[test]
fn demo_and_bumps_report_the_bits_each_signal_needs() {
    let hw = hw_model::HwConfig::texram16();
    let demo = ranges_of("demo", &hw);
    for s in ["bary", "color", "uv", "lod", "texel", "out"] {
        let r = row(&demo, s);
        assert!(r.samples > 0 && r.min <= r.max, "{r:?}");
        assert!(r.min.is_finite() && r.max.is_finite());
        assert_eq!(r.int_bits_needed, int_bits_for(r.min, r.max));
        assert_eq!(r.outside, 0, "texram16 holds demo's {s}");
    }
    // Unorm signals stay in [0, 1] and need no integer bit.
    assert_eq!(row(&demo, "texel").int_bits_needed, 0);
    let bumps = ranges_of("bumps", &hw);
    for s in ["n_i", "fr_n", "normal"] {
        let r = row(&bumps, s);
        assert!(r.min >= -1.0 - 1e-9 && r.max <= 1.0 + 1e-9, "{r:?}");
        assert!(r.int_bits_needed <= 1);
    }
    // A render without the flag carries no ranges.
    let mut sc = texsim::scene::builtin("demo").expect("scene");
    sc.width = 32;
    sc.height = 24;
    let maps = Maps::new(&sc, hw.trilinear.texel_bits);
    let r = render(&sc, &maps, &hw, &RenderOptions::default()).expect("render");
    assert!(r.stats.ranges.is_none());
}

/// Texture coordinates declared with fewer integer bits than the scene's values need: the
/// values outside the format are counted and the needed bits exceed the declared ones.
#[test]
fn a_narrow_format_shows_values_outside_it() {
    let hw = hw_model::HwConfig::texram16();
    let wide = ranges_of("demo", &hw);
    let need = row(&wide, "uv").int_bits_needed;
    assert!(need >= 2, "demo's texture coordinates repeat: {need}");
    let narrow = texsim::hwconfig::set_field(&hw, "texcoord_int_bits", &(need - 1).to_string())
        .expect("field");
    let rows = ranges_of("demo", &narrow);
    let uv = row(&rows, "uv");
    assert!(uv.outside > 0, "{uv:?}");
    assert!(uv.int_bits_needed > uv.int_bits_declared);
    assert_eq!(
        uv.int_bits_needed, need,
        "the float reference's range does not depend on the format"
    );
}
