//! Hardware configurations: the presets pinned to the numbers of the APIs they model, full TOML
//! round trips, errors that name the field with its line and column, and the overflow rules.

use hw_model::config::PRESETS;
use hw_model::fixed::{Overflow, Rounding, SatCounter};
use hw_model::wrap::{wrap, WrapMode};
use hw_model::HwConfig;
use texsim::hwconfig::{parse, set_field, to_toml};

fn preset(name: &str) -> HwConfig {
    HwConfig::preset(name).expect("preset")
}

#[test]
fn every_preset_round_trips_through_toml() {
    for &name in PRESETS {
        let p = preset(name);
        p.validate().expect("preset valid");
        let text = to_toml(&p);
        assert_eq!(parse(&text).expect("parse"), p, "{name}:\n{text}");
        // `texsim hw show` output is a complete file: a `base` of another preset changes nothing.
        let rebased = format!("base = \"vulkan-min\"\n{text}");
        assert_eq!(parse(&rebased).expect("parse"), p, "{name} over vulkan-min");
    }
}

#[test]
fn presets_have_the_api_precision_floors() {
    // (name, sub-pixel, sub-texel = weight fraction bits, LOD fraction bits)
    let floors = [
        ("texram16", 8, 16, 16),
        ("d3d11", 8, 8, 8),
        ("vulkan-min", 4, 4, 4),
        ("cuda", 8, 8, 8),
        ("llvmpipe", 8, 8, 8),
    ];
    for (name, sub_px, sub_texel, lod_frac) in floors {
        let p = preset(name);
        assert_eq!(p.name, name);
        assert_eq!(p.raster.subpixel_bits, sub_px, "{name} sub-pixel bits");
        assert_eq!(p.trilinear.weight_bits, sub_texel, "{name} sub-texel bits");
        assert_eq!(p.lod.lod_frac_bits, lod_frac, "{name} LOD fraction bits");
        // Only the floors differ; every datapath format is saturating unless a file says so.
        assert_eq!(p.interp.texcoord_overflow, Overflow::Saturate, "{name}");
        assert_eq!(p.color.color_overflow, Overflow::Saturate, "{name}");
    }
    // texram16: 16 bits throughout the texture datapath.
    let t = preset("texram16");
    assert_eq!(
        [
            t.trilinear.texel_bits,
            t.trilinear.weight_bits,
            t.lod.lod_frac_bits,
            t.color.color_bits
        ],
        [16; 4]
    );
    // The API floors keep texram16's 16-bit texels: only the precision floors differ.
    for name in ["d3d11", "vulkan-min", "cuda"] {
        assert_eq!(preset(name).trilinear.texel_bits, 16, "{name}");
    }
}

/// The llvmpipe preset (Mesa 22.3's 8-bit AoS sampler): every field it changes from texram16.
#[test]
fn llvmpipe_preset_pins_its_texture_path() {
    use hw_model::config::{CoordArith, LodLog2};
    let l = preset("llvmpipe");
    let t = preset("texram16");
    assert_eq!(l.name, "llvmpipe");
    assert_eq!(
        (l.trilinear.texel_bits, l.trilinear.weight_bits),
        (8, 8),
        "8-bit texels and weights"
    );
    assert_eq!(l.trilinear.filter_rounding, Rounding::HalfUp, "pmulhrsw");
    assert_eq!(
        l.trilinear.weight_rounding,
        Rounding::HalfEven,
        "lp_build_iround: round to nearest even"
    );
    assert_eq!(l.lod.lod_frac_bits, 8);
    assert_eq!(l.lod.lod_log2, LodLog2::PiecewiseLinear);
    assert!(l.lod.lod_per_quad);
    assert_eq!(
        l.raster.subpixel_bits, 8,
        "coverage on llvmpipe's 8 sub-pixel bits"
    );
    assert_eq!(
        l.interp.attr_subpixel_bits, 16,
        "attribute planes from finer positions"
    );
    assert_eq!(t.interp.attr_subpixel_bits, 0);
    assert_eq!(
        l.interp.coord_arith,
        CoordArith::Float32,
        "llvmpipe's float32 coordinates"
    );
    assert!(PRESETS
        .iter()
        .all(|&p| p == "llvmpipe" || preset(p).interp.coord_arith == CoordArith::Fixed));
    assert_eq!(
        (l.interp.texcoord_frac_bits, t.interp.texcoord_frac_bits),
        (28, 24),
        "binary32 coordinates below 1/2 keep their low bits"
    );
    let mut bad = l.clone();
    bad.lod.lod_per_quad = false;
    let e = bad.validate().expect_err("float32 needs the quad LOD");
    assert_eq!(e.field, "interp.coord_arith");
    assert_eq!(t.lod.lod_log2, LodLog2::Exact, "other presets unchanged");
    assert!(PRESETS
        .iter()
        .all(|&p| p == "llvmpipe" || !preset(p).lod.lod_per_quad));
    // Everything else is texram16's (timing: the modern memory system of the API presets).
    let mut back = l.clone();
    back.name = t.name.clone();
    back.timing = t.timing.clone();
    back.trilinear = t.trilinear.clone();
    back.lod = t.lod.clone();
    back.interp = t.interp.clone();
    assert_eq!(back, t);
    assert_eq!(l.timing, preset("d3d11").timing);
}

/// CUDA's filter weights are 9-bit fixed point with 8 fraction bits: the unit's weight of the
/// second texel takes every value k/256, k in 0..=255, so the first texel's weight 1 - w takes
/// every k/256 in 1..=256: 256 needs the ninth bit, no finer step is representable.
#[test]
fn cuda_weights_are_9_bit_with_8_fraction_bits() {
    let c = preset("cuda");
    assert_eq!(c.trilinear.weight_rounding, Rounding::HalfEven);
    let one = 1u32 << c.trilinear.weight_bits;
    let mut seen = vec![false; one as usize + 1];
    // Coordinates with 16 fraction bits over 4 texels: every sub-texel position.
    for coord in 0..(1i64 << 16) {
        let o = wrap(coord, 16, 4, WrapMode::Repeat, &c.trilinear);
        seen[o.weight as usize] = true;
        seen[(one - o.weight) as usize] = true;
    }
    assert_eq!(one, 256, "8 fraction bits");
    assert!(seen.iter().all(|&s| s), "every k/256, 0..=256, occurs");
    assert_eq!(32 - (one).leading_zeros(), 9, "1.0 = 256 needs 9 bits");
}

#[test]
fn syntax_errors_give_line_and_column() {
    let e = parse("[interp]\nbary_bits = 20\n[trilinear\nweight_bits = 3\n").expect_err("syntax");
    let m = e.to_string();
    assert!(m.contains("line 3, column"), "{m}");
    assert!(m.contains("[trilinear"), "{m}");
}

#[test]
fn field_errors_name_the_field_with_its_line_and_column() {
    let cases: [(&str, &str, &str); 7] = [
        (
            "base = \"d3d11\"\n[interp]\ntexcoord_overflow = \"clamp\"\n",
            "line 3, column 21",
            "interp.texcoord_overflow",
        ),
        (
            "[trilinear]\n# sub-texel\nweight_bits = 99\n",
            "line 3, column 15",
            "trilinear.weight_bits",
        ),
        (
            "[trilinear]\nweight_bits = \"eight\"\n",
            "line 2, column 15",
            "trilinear.weight_bits",
        ),
        (
            "[color]\ncolor_bits = 8\ncolour_overflow = \"wrap\"\n",
            "line 3, column 19",
            "color.colour_overflow",
        ),
        (
            "shading.rsqrt.rsqrt_mantissa_bits = 99\n",
            "line 1, column 37",
            "rsqrt_mantissa_bits",
        ),
        (
            "color = { color_overflow = \"wrap\", color_bits = 0 }\n",
            "line 1, column 49",
            "color.color_bits",
        ),
        ("\nbase = \"d3d12\"\n", "line 2, column 8", "base"),
    ];
    for (text, at, field) in cases {
        let m = parse(text).expect_err(text).to_string();
        assert!(m.contains(at), "{text:?}: no '{at}' in: {m}");
        assert!(m.contains(field), "{text:?}: no '{field}' in: {m}");
    }
}

#[test]
fn overflow_rules_are_config_fields() {
    let c = parse("[interp]\ntexcoord_overflow = \"wrap\"\n[color]\ncolor_overflow = \"wrap\"\n")
        .expect("parse");
    assert_eq!(c.interp.texcoord_overflow, Overflow::Wrap);
    assert_eq!(c.color.color_overflow, Overflow::Wrap);
    assert!(to_toml(&c).contains("texcoord_overflow = \"wrap\""));
    // Files written before the fields existed still load, saturating.
    let full = to_toml(&HwConfig::texram16());
    let old: String = full
        .lines()
        .filter(|l| !l.contains("_overflow"))
        .map(|l| format!("{l}\n"))
        .collect();
    assert!(!old.contains("overflow"));
    let o: HwConfig = toml::from_str(&old).expect("old file parses");
    assert_eq!(o, HwConfig::texram16());
    // Sweepable by bare name or dotted path; a bad value names the field.
    let base = HwConfig::texram16();
    let s = set_field(&base, "texcoord_overflow", "wrap").expect("bare name");
    assert_eq!(s.interp.texcoord_overflow, Overflow::Wrap);
    let s = set_field(&base, "color.color_overflow", "wrap").expect("dotted path");
    assert_eq!(s.color.color_overflow, Overflow::Wrap);
    let e = set_field(&base, "color_overflow", "clamp").expect_err("bad value");
    assert!(e.to_string().contains("color.color_overflow"), "{e}");
    assert!(e.to_string().contains("saturate"), "{e}");
}

#[test]
fn the_machine_formats_follow_the_overflow_fields() {
    let mut hw = HwConfig::texram16();
    hw.interp.texcoord_int_bits = 2;
    let m = texsim::pipeline::stages::Machine::new(&hw, &[], &[]);
    assert_eq!(m.uv_fmt.overflow, Overflow::Saturate);
    assert_eq!(m.color_fmt.overflow, Overflow::Saturate);
    // Texture coordinates in [-4, 4): u = 5.25 saturates to just below 4, or wraps by the
    // period 8 to -2.75 (the same texel under `repeat`: a whole number of repeats).
    let mut sat = SatCounter::default();
    let raw = texsim::fixedpoint::to_raw(5.25, &m.uv_fmt, &mut sat);
    assert_eq!(
        (raw, sat.saturated, sat.wrapped),
        (m.uv_fmt.max_raw(), 1, 0)
    );
    hw.interp.texcoord_overflow = Overflow::Wrap;
    hw.color.color_overflow = Overflow::Wrap;
    let m = texsim::pipeline::stages::Machine::new(&hw, &[], &[]);
    assert_eq!(m.uv_fmt.overflow, Overflow::Wrap);
    assert_eq!(m.color_fmt.overflow, Overflow::Wrap);
    let mut sat = SatCounter::default();
    let raw = texsim::fixedpoint::to_raw(5.25, &m.uv_fmt, &mut sat);
    let fb = m.uv_fmt.frac_bits;
    assert_eq!((raw, sat.saturated, sat.wrapped), (-11 << (fb - 2), 0, 1));
}

/// A hardware file's `name` is used as given, or rejected: not a string, empty, or a preset's
/// name on a configuration that is not that preset.
#[test]
fn hw_file_name_is_used_or_rejected() {
    let c =
        parse("base = \"d3d11\"\nname = \"mine\"\n[trilinear]\nweight_bits = 6\n").expect("named");
    assert_eq!(c.name, "mine");
    let c = parse("base = \"d3d11\"\n").expect("unnamed");
    assert_eq!(c.name, "d3d11+custom");
    // A complete preset printed by `texsim hw show` keeps its own name.
    assert_eq!(parse(&to_toml(&preset("cuda"))).expect("cuda").name, "cuda");
    for (text, needle) in [
        ("name = 5\n", "expected a string"),
        ("name = \"  \"\n", "is empty"),
        ("name = \"d3d11\"\n", "name of a preset"),
        (
            "base = \"d3d11\"\nname = \"d3d11\"\n[lod]\nlod_frac_bits = 4\n",
            "name of a preset",
        ),
    ] {
        let e = parse(text).expect_err(text).to_string();
        assert!(e.contains("'name'") && e.contains(needle), "{text}: {e}");
    }
}

/// An unknown field answers with the nearest valid name, not the list of every field.
#[test]
fn unknown_fields_suggest_the_nearest_name() {
    let base = preset("texram16");
    let e = set_field(&base, "weight_bit", "4")
        .expect_err("typo")
        .to_string();
    assert!(e.contains("did you mean 'weight_bits'"), "{e}");
    assert!(e.len() < 200, "{e}");
    let e = set_field(&base, "trilinear.wieght_bits", "4")
        .expect_err("typo")
        .to_string();
    assert!(e.contains("did you mean 'trilinear.weight_bits'"), "{e}");
    let e = set_field(&base, "zzz", "4")
        .expect_err("nothing near")
        .to_string();
    assert!(!e.contains("did you mean") && e.len() < 200, "{e}");
    let e = parse("[trilinear]\nweight_bitz = 4\n")
        .expect_err("typo in file")
        .to_string();
    assert!(
        e.contains("did you mean 'weight_bits'") && e.contains("line 2"),
        "{e}"
    );
}

#[test]
fn texel_bytes_was_removed_with_a_message() {
    let base = preset("texram16");
    for name in ["texel_bytes", "timing.texel_bytes"] {
        let e = set_field(&base, name, "4")
            .expect_err("removed")
            .to_string();
        assert!(e.contains("was removed") && e.contains("texel_bits"), "{e}");
    }
    let e = parse("base = \"d3d11\"\n[timing]\ntexel_bytes = 8\n")
        .expect_err("removed field in a file")
        .to_string();
    assert!(
        e.contains("timing.texel_bytes") && e.contains("was removed") && e.contains("line 3"),
        "{e}"
    );
    // A line or page must hold the widest texel (4 x 16 bits).
    let e = parse("[timing]\ncache_line_bytes = 4\n")
        .expect_err("line below a texel")
        .to_string();
    assert!(e.contains("cache_line_bytes") && e.contains("8..="), "{e}");
}

/// `IntFields::set`, which `texsim tune` sets its knobs with, is `set_field` of an integer
/// field: seeded chains of settings of every width field of three presets, values from 0 to 4
/// above the preset's, give the same configuration or both an error, and a refused setting
/// leaves the fields as they were.
#[test]
fn int_fields_set_like_set_field() {
    use crate::rng_common::Rng;
    use texsim::hwconfig::{fields, is_width, IntFields};
    let mut rng = Rng(0x1e7_f1e1d5);
    let (mut same, mut refused) = (0, 0);
    for name in ["texram16", "d3d11", "llvmpipe"] {
        let base = preset(name);
        let widths: Vec<(String, i64)> = fields(&base)
            .into_iter()
            .filter(|(p, _)| is_width(p))
            .filter_map(|(p, v)| Some((p, v.parse().ok()?)))
            .collect();
        assert!(widths.len() > 40, "{name}: {}", widths.len());
        for _ in 0..60 {
            let mut fast = IntFields::of(&base);
            let mut slow = base.clone();
            for _ in 0..6 {
                let (path, v0) = &widths[rng.below(widths.len() as u64) as usize];
                let v = rng.int_in(0, v0 + 4);
                assert_eq!(fast.get(path), Some(slow_get(&slow, path)), "{name} {path}");
                match (fast.set(path, v), set_field(&slow, path, &v.to_string())) {
                    (Ok(a), Ok(b)) => {
                        assert_eq!(a, b, "{name}: {path} = {v}");
                        slow = b;
                        same += 1;
                    }
                    (Err(_), Err(_)) => refused += 1,
                    (a, b) => panic!("{name}: {path} = {v}: {:?} against {:?}", a.err(), b.err()),
                }
            }
        }
    }
    assert!(same > 500 && refused > 50, "{same} set, {refused} refused");
    let mut f = IntFields::of(&preset("texram16"));
    assert!(f.set("trilinear.filter_rounding", 1).is_err());
    assert!(f.set("trilinear.no_such_bits", 1).is_err());
    assert_eq!(f.get("no_such.table"), None);
}

fn slow_get(c: &HwConfig, path: &str) -> i64 {
    texsim::hwconfig::fields(c)
        .into_iter()
        .find(|(p, _)| p == path)
        .and_then(|(_, v)| v.parse().ok())
        .expect("an integer field")
}
