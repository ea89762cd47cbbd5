//! Shading unit configs: defaults valid, TOML round trip with the kebab-case enums, validation
//! names the field, costs follow the config.

use hw_model::blinn_phong::{blinn_phong_cost, ShadingConfig, ShadingUnits};
use hw_model::frame::{frame_cost, perturb_cost, FrameKind};
use hw_model::pow::{pow_cost, PowMethod};
use hw_model::rsqrt::rsqrt_cost;

#[test]
fn texram16_valid_and_toml_roundtrip() {
    let c = ShadingConfig::texram16();
    assert!(c.validate().is_ok());
    let text = toml::to_string(&c).expect("serialize");
    assert!(text.contains("frame_kind = \"main\""));
    assert!(text.contains("pow_method = \"log-exp\""));
    let back: ShadingConfig = toml::from_str(&text).expect("parse");
    assert_eq!(back, c);
    let edited = text
        .replace("\"main\"", "\"natural\"")
        .replace("\"log-exp\"", "\"squaring\"");
    let e: ShadingConfig = toml::from_str(&edited).expect("parse");
    assert_eq!(e.frame.frame_kind, FrameKind::Natural);
    assert_eq!(e.pow.pow_method, PowMethod::Squaring);
    assert!(toml::from_str::<ShadingConfig>(&text.replace("\"main\"", "\"polar\"")).is_err());
}

#[test]
fn validation_names_the_field() {
    type Edit = Box<dyn Fn(&mut ShadingConfig)>;
    let cases: Vec<(Edit, &str)> = vec![
        (
            Box::new(|c| c.vector.vector_frac_bits = 20),
            "vector_frac_bits",
        ),
        (
            Box::new(|c| c.vector.offset_int_bits = 9),
            "offset_int_bits",
        ),
        (
            Box::new(|c| c.rsqrt.rsqrt_iterations = 5),
            "rsqrt_iterations",
        ),
        (
            Box::new(|c| c.rsqrt.rsqrt_mantissa_bits = 12),
            "rsqrt_mantissa_bits",
        ),
        (
            Box::new(|c| c.frame.frame_min_sin_bits = 0),
            "frame_min_sin_bits",
        ),
        (Box::new(|c| c.pow.pow_lut_bits = 15), "pow_lut_bits"),
        (
            Box::new(|c| c.shade.shade_color_bits = 17),
            "shade_color_bits",
        ),
    ];
    for (edit, field) in cases {
        let mut c = ShadingConfig::texram16();
        edit(&mut c);
        let e = c.validate().expect_err(field);
        assert!(e.to_string().contains(field), "{e}");
    }
}

#[test]
fn costs_follow_config() {
    let mut c = ShadingConfig::texram16();
    let g = hw_model::timing_config::DEFAULT_GATE_LEVELS_PER_CYCLE;
    let base = rsqrt_cost(&c.rsqrt, g);
    // One more Newton-Raphson step adds its stage's derived latency; a hand-set value wins.
    let step = hw_model::rsqrt::datapath(&c.rsqrt)
        .stages
        .iter()
        .find(|s| s.name == "Newton-Raphson step")
        .expect("NR stage")
        .latency_once(g);
    c.rsqrt.rsqrt_iterations = 2;
    assert_eq!(rsqrt_cost(&c.rsqrt, g).cycles, base.cycles + step);
    c.rsqrt.rsqrt_cycles_per_iteration = hw_model::datapath::Cycles::Fixed(7);
    assert_eq!(rsqrt_cost(&c.rsqrt, g).cycles, base.cycles - step + 2 * 7);
    c.pow.pow_method = PowMethod::Squaring;
    assert_eq!(pow_cost(&c.pow, g).ops, 2 * c.pow.pow_exponent_bits - 1);
    let u = ShadingUnits::new(&c);
    assert!(frame_cost(FrameKind::Main, &u, g).ops > frame_cost(FrameKind::Unit, &u, g).ops);
    assert!(perturb_cost(&u, g).cycles > 0 && blinn_phong_cost(&u, g).ops > 0);
}
