//! The datapath cost model (`hw_model::datapath`): components and every unit against hand
//! calculations at three widths, monotonicity in each width, latency rounding and overrides,
//! the clock target as a sweepable field, and the table in docs/COST.md.
//!
//! Hand calculations use the module's table: adder `n` = `ceil(log2 n) + 2` levels, `7 n +
//! 3 (n/2) ceil(log2 n)` GE; multiplier `a x b` = `1 + 2 dadda(min) + adder(a + b)` levels,
//! `a b + 7 max(0, a b - 2(a + b) + 3) + 4 (min - 1) + adder_area(a + b)` GE (Dadda heights
//! 2, 3, 4, 6, 9, 13, 19, 28, 42: 17 rows take 6 levels, 9 rows 4, 5 rows 3); comparator
//! `ceil(log2 n) + 1`; mux of k inputs `ceil(log2 k)`; ROM `a + 1` levels, `2^a d / 4` GE.

use hw_model::datapath::{
    ceil_log2, dadda_levels, total_area, units, Component, Cycles, Datapath, Stage, UnitReport,
};
use hw_model::HwConfig;
use texsim::hwconfig::set_field;

fn dp(d: &Datapath) -> (u32, u64) {
    (d.delay(), d.area())
}

fn report(hw: &HwConfig, name: &str) -> UnitReport {
    units(hw)
        .into_iter()
        .find(|r| r.name == name)
        .unwrap_or_else(|| panic!("no unit {name}"))
}

fn with(field: &str, value: u32) -> HwConfig {
    set_field(&HwConfig::texram16(), field, &value.to_string()).expect("valid field")
}

#[test]
fn components_against_hand_calculations() {
    use Component::*;
    assert_eq!(ceil_log2(1), 0);
    assert_eq!(ceil_log2(17), 5);
    assert_eq!(ceil_log2(32), 5);
    assert_eq!(
        (dadda_levels(2), dadda_levels(5), dadda_levels(9)),
        (0, 3, 4)
    );
    assert_eq!(
        (dadda_levels(17), dadda_levels(28), dadda_levels(29)),
        (6, 7, 8)
    );
    // Adder 8: 3 + 2 = 5 levels; 7*8 + 3*4*3 = 56 + 36 = 92 GE.
    assert_eq!(
        (Adder { width: 8 }.delay(), Adder { width: 8 }.area()),
        (5, 92)
    );
    // Adder 17: 5 + 2 = 7; 119 + 3*8*5 = 119 + 120 = 239.
    assert_eq!(
        (Adder { width: 17 }.delay(), Adder { width: 17 }.area()),
        (7, 239)
    );
    // Adder 34: 6 + 2 = 8; 238 + 3*17*6 = 238 + 306 = 544.
    assert_eq!(
        (Adder { width: 34 }.delay(), Adder { width: 34 }.area()),
        (8, 544)
    );
    // Multiplier 17x5: 1 + 2*3 + adder22 (5 + 2) = 14 levels; 85 + 7*(85 - 44 + 3 = 44) + 4*4
    // + adder22 (154 + 3*11*5 = 319) = 85 + 308 + 16 + 319 = 728 GE.
    let m = Multiplier { a: 17, b: 5 };
    assert_eq!((m.delay(), m.area()), (14, 728));
    // Multiplier 17x9: 1 + 2*4 + adder26 (7) = 16; 153 + 7*(153 - 52 + 3 = 104) + 4*8 +
    // adder26 (182 + 3*13*5 = 377) = 153 + 728 + 32 + 377 = 1290.
    let m = Multiplier { a: 17, b: 9 };
    assert_eq!((m.delay(), m.area()), (16, 1290));
    // Multiplier 17x17: 1 + 2*6 + adder34 (8) = 21; 289 + 7*(289 - 68 + 3 = 224) + 4*16 +
    // 544 = 289 + 1568 + 64 + 544 = 2465.
    let m = Multiplier { a: 17, b: 17 };
    assert_eq!((m.delay(), m.area()), (21, 2465));
    // A 1-bit operand is an AND row: 1 level, a*b GE.
    assert_eq!(
        (
            Multiplier { a: 16, b: 1 }.delay(),
            Multiplier { a: 16, b: 1 }.area()
        ),
        (1, 16)
    );
    // ROM 8x28: 8 + 1 = 9 levels; 256*28/4 = 1792 GE. ROM 4x8: 5; 32. ROM 10x24: 11; 6144.
    assert_eq!(
        (
            Rom {
                addr_bits: 8,
                data_bits: 28
            }
            .delay(),
            Rom {
                addr_bits: 8,
                data_bits: 28
            }
            .area()
        ),
        (9, 1792)
    );
    assert_eq!(
        (
            Rom {
                addr_bits: 4,
                data_bits: 8
            }
            .delay(),
            Rom {
                addr_bits: 4,
                data_bits: 8
            }
            .area()
        ),
        (5, 32)
    );
    assert_eq!(
        (
            Rom {
                addr_bits: 10,
                data_bits: 24
            }
            .delay(),
            Rom {
                addr_bits: 10,
                data_bits: 24
            }
            .area()
        ),
        (11, 6144)
    );
    // Comparator 17: 5 + 1 = 6; 4*17 + 3*8*5 = 68 + 120 = 188. 65: 7 + 1 = 8; 260 + 3*32*7 = 932.
    assert_eq!(
        (
            Comparator { width: 17 }.delay(),
            Comparator { width: 17 }.area()
        ),
        (6, 188)
    );
    assert_eq!(
        (
            Comparator { width: 65 }.delay(),
            Comparator { width: 65 }.area()
        ),
        (8, 932)
    );
    // Mux 3x17: 2 levels; 17*2*2 = 68. Mux 2x65: 1; 130.
    assert_eq!(
        (
            Mux {
                width: 17,
                inputs: 3
            }
            .delay(),
            Mux {
                width: 17,
                inputs: 3
            }
            .area()
        ),
        (2, 68)
    );
    assert_eq!(
        (
            Mux {
                width: 65,
                inputs: 2
            }
            .delay(),
            Mux {
                width: 65,
                inputs: 2
            }
            .area()
        ),
        (1, 130)
    );
    // Shifter 29 by 5 bits: 5 levels; 29*5*2 = 290. LZC 64: 6 + 1 = 7; 128. Register 64: 0; 384.
    assert_eq!(
        (
            Shifter {
                width: 29,
                shift_bits: 5
            }
            .delay(),
            Shifter {
                width: 29,
                shift_bits: 5
            }
            .area()
        ),
        (5, 290)
    );
    assert_eq!(
        (
            LeadingZeros { width: 64 }.delay(),
            LeadingZeros { width: 64 }.area()
        ),
        (7, 128)
    );
    assert_eq!(
        (Register { bits: 64 }.delay(), Register { bits: 64 }.area()),
        (0, 384)
    );
}

/// The trilinear unit (T = 16) and its parts at weight_bits 4, 8, 16. Per level the address
/// unit: mul32x17 (1 + 12 + adder49 8 = 21) -> add(17 + W + 1) -> cmp17 (6) beside add17 (7)
/// -> mux3 (2); a lerp: add17 (7) -> mul17x(W+1) -> add(T + W + 2).
#[test]
fn trilinear_at_three_widths() {
    // W = 4: address 21 + 7 + 7 + 2 = 37; lerp 7 + 14 + 7 = 28; bilinear 37 + 2*28 = 93;
    // trilinear 2*93 + 28 = 214.
    // W = 8: address 37; lerp 7 + 16 + 7 = 30; bilinear 97; trilinear 194 + 30 = 224.
    // W = 16: address 21 + 8 + 7 + 2 = 38; lerp 7 + 21 + 8 = 36; bilinear 110; trilinear 256.
    // Areas: address = 2 mul32x17 (4526) + 2 add(18 + W) + 4 (cmp17 188 + add17 239) + 4
    // mux3x17 (68); lerp = add17 (239) + mul17x(W + 1) + add(18 + W); bilinear = address + 12
    // lerps + reg64 (384); blend = 4 lerps + reg64; trilinear = 2 bilinear + blend.
    // W = 4: address 9052 + 2*319 + 1708 + 272 = 11670; lerp 239 + 728 + 319 = 1286;
    //   bilinear 11670 + 15432 + 384 = 27486; blend 5144 + 384 = 5528; trilinear 60500.
    // W = 8: address 9052 + 754 + 1980 = 11786; lerp 239 + 1290 + 377 = 1906; bilinear 11786 +
    //   22872 + 384 = 35042; blend 7624 + 384 = 8008; trilinear 78092.
    // W = 16: address 9052 + 1088 + 1980 = 12120; lerp 239 + 2465 + 544 = 3248; bilinear
    //   12120 + 38976 + 384 = 51480; blend 12992 + 384 = 13376; trilinear 116336.
    let cases = [
        (4, 37, 93, 28, 214, 27486, 5528, 60500),
        (8, 37, 97, 30, 224, 35042, 8008, 78092),
        (16, 38, 110, 36, 256, 51480, 13376, 116336),
    ];
    for (w, addr_d, bil_d, blend_d, tri_d, bil_a, blend_a, tri_a) in cases {
        let hw = with("weight_bits", w);
        let t = &hw.trilinear;
        assert_eq!(hw_model::wrap::datapath(t).delay(), addr_d, "W={w}");
        assert_eq!(
            dp(&hw_model::trilinear::bilinear_datapath(t)),
            (bil_d, bil_a),
            "W={w}"
        );
        let tri = hw_model::trilinear::datapath(t, 2);
        assert_eq!(dp(&tri), (tri_d, tri_a), "W={w}");
        assert_eq!(
            tri.stages.last().map(|s| (s.delay(), s.area())),
            Some((blend_d, blend_a))
        );
        assert_eq!(tri_a, 2 * bil_a + blend_a);
        // At 32 levels per cycle: bilinear ceil(bil / 32), blend ceil(blend / 32).
        let lat = 2 * bil_d.div_ceil(32) + blend_d.div_ceil(32);
        assert_eq!(tri.latency(32), lat, "W={w}");
        assert_eq!(hw_model::trilinear::trilinear_cost(t, 2, 32).cycles, lat);
    }
}

#[test]
fn modulate_at_three_widths() {
    // Four channels side by side: mul C x C -> mul 2C x (C + 1) -> add(C + 1) -> reg 4C.
    // C = 8: mul8x8 (8 rows, 4 levels: 1 + 8 + add16 6 = 15) -> mul16x9 (1 + 8 + add25 7 =
    //   16) -> add9 (6) = 37; area 4 (545 + 1210 + 111) + reg32 192 = 7656.
    // C = 12: mul12x12 (5 levels: 1 + 10 + add24 7 = 18) -> mul24x13 (1 + 10 + add37 8 = 19)
    //   -> add13 (6) = 43; area 4 (1229 + 2630 + 163) + 288 = 16376.
    // C = 16: mul16x16 (1 + 12 + add32 7 = 20) -> mul32x17 (21) -> add17 (7) = 48; area 4
    //   (2145 + 4526 + 239) + 384 = 28024.
    for (c, d, a) in [(8, 37, 7656), (12, 43, 16376), (16, 48, 28024)] {
        let hw = with("color_bits", c);
        assert_eq!(
            dp(&hw_model::modulate::datapath(&hw.color)),
            (d, a),
            "C={c}"
        );
        assert_eq!(report(&hw, "modulate").latency, d.div_ceil(32));
    }
}

#[test]
fn reciprocal_lod_rsqrt_at_three_widths() {
    // Reciprocal (L = 8, 2 iterations, w = M + 4): normalize lzc64 7 + shift 6 + add(w);
    // ROM 9; per step mul(w, w) + add(w + 1) + mul(w, w + 1) + add(w); round lzc + shift +
    // add(M + 1). M = 16 (w = 20: 20 rows -> 7 levels, mul = 1 + 14 + add40 8 = 23), M = 24
    // (w = 28: 28 rows -> 7 levels, mul 23) give the same delay: 7 + 6 + 7 + 9 + 2*(23 + 7 +
    // 23 + 7) + (6 + 5 + 7) = 20 + 9 + 120 + 18 = 167.
    for (m, d, a) in [(16, 167, 17567), (20, 167, 24115), (24, 167, 31687)] {
        let hw = with("recip_mantissa_bits", m);
        assert_eq!(
            dp(&hw_model::reciprocal::datapath(&hw.reciprocal)),
            (d, a),
            "M={m}"
        );
    }
    // LOD: squared lengths 4x mul32x32 (1 + 16 + add64 8 = 25) -> add65 (9) -> cmp65 (8) ->
    // mux (1) -> lzc65 (8) -> shift by 7 (7) = 58; per fraction bit mul32x32 (25) + mux (1) =
    // 26. F = 4: 58 + 4*26 = 162; F = 8: 266; F = 16: 474.
    for (f, d, a) in [(4, 162, 73022), (8, 266, 108290), (16, 474, 178826)] {
        let hw = with("lod_frac_bits", f);
        assert_eq!(dp(&hw_model::lod::datapath(&hw.lod)), (d, a), "F={f}");
        // 32 levels per cycle: 2 + F cycles.
        assert_eq!(report(&hw, "lod").latency, 2 + f);
    }
    // Rsqrt (L = 8, 1 iteration, w = B + 6): normalize 7 + 6 + add(B); ROM 9; step mul(w, w)
    // twice + add(w + 1) + mul(w, w + 1); round add(B + 1). B = 24 (w = 30, 8 levels: mul =
    // 1 + 16 + add60 8 = 25): 20 + 9 + (25 + 25 + 7 + 25) + 7 = 118.
    for (b, d, a) in [(16, 111, 15015), (20, 112, 20277), (24, 118, 26283)] {
        let hw = with("rsqrt_mantissa_bits", b);
        assert_eq!(
            dp(&hw_model::rsqrt::datapath(&hw.shading.rsqrt)),
            (d, a),
            "B={b}"
        );
    }
}

#[test]
fn interpolator_at_three_widths() {
    // Attribute (A = 8 + 24 + 1 = 33, b = B + 2): 2x add34 (8) -> 2x mul34 x b -> add(33 + b
    // + 1) -> add(33 + b + 2) -> reg. B = 24: mul34x26 (26 rows, 7 levels: 1 + 14 + add60 8 =
    // 23) -> add60 (8) -> add61 (8): 8 + 23 + 8 + 8 = 47.
    for (b, d, a) in [(12, 45, 10783), (16, 45, 13135), (24, 47, 17839)] {
        let hw = with("bary_bits", b);
        assert_eq!(
            dp(&hw_model::interpolator::attribute_datapath(&hw.interp)),
            (d, a),
            "B={b}"
        );
    }
    // Barycentrics = the reciprocal (167) + their stage; derivatives = that + a second
    // reciprocal (167) + 2 derivative stages.
    for (b, d, a, dd, da) in [
        (12, 236, 79654, 533, 268445),
        (16, 237, 79884, 536, 269087),
        (24, 237, 80260, 536, 270119),
    ] {
        let hw = with("bary_bits", b);
        let bd = hw_model::interpolator::bary_datapath(&hw.interp, &hw.reciprocal);
        assert_eq!(dp(&bd), (d, a), "B={b}");
        let dv = hw_model::interpolator::bary_derivs_datapath(&hw.interp, &hw.reciprocal);
        assert_eq!(dp(&dv), (dd, da), "B={b}");
        let r = hw_model::reciprocal::datapath(&hw.reciprocal);
        assert!(bd.delay() > r.delay() && dv.delay() > bd.delay() + r.delay());
    }
}

#[test]
fn shading_units_at_three_widths() {
    // Vector components are F + 2 bits. dot: 3x mul v x v -> add(2v + 1) -> add(2v + 2) ->
    // add(v + 2). F = 14 (v = 16): mul16x16 20 + add33 8 + add34 8 + add18 7 = 43; F = 10
    // (v = 12): mul12x12 18 + add25 7 + add26 7 + add14 6 = 38.
    // normalize = dot + rsqrt (118) + scale; frame (main) = 3 normalize + 2 cross + dot;
    // perturb = madd + normalize; Blinn-Phong = 2 dots + half vector + normalize + pow (102)
    // + colour stage (36).
    let cases = [
        (
            10, 38, 4601, 180, 35855, 31, 8928, 38, 12723, 640, 130022, 218, 48578, 400, 72034,
        ),
        (
            12, 40, 6021, 184, 38763, 33, 11736, 40, 14565, 658, 145782, 224, 53328, 408, 77860,
        ),
        (
            14, 43, 7759, 189, 42406, 35, 15144, 43, 16776, 680, 165265, 232, 59182, 420, 85129,
        ),
    ];
    for (f, dot_d, dot_a, nz_d, nz_a, cr_d, cr_a, ma_d, ma_a, fr_d, fr_a, pe_d, pe_a, bp_d, bp_a) in
        cases
    {
        let hw = with("vector_frac_bits", f);
        let sh = &hw.shading;
        assert_eq!(
            dp(&hw_model::vector::dot_datapath(&sh.vector)),
            (dot_d, dot_a),
            "F={f}"
        );
        assert_eq!(
            dp(&hw_model::vector::normalize_datapath(&sh.vector, &sh.rsqrt)),
            (nz_d, nz_a)
        );
        assert_eq!(
            dp(&hw_model::vector::cross_datapath(&sh.vector)),
            (cr_d, cr_a)
        );
        assert_eq!(
            dp(&hw_model::vector::madd_datapath(&sh.vector)),
            (ma_d, ma_a)
        );
        assert_eq!(
            dp(&hw_model::frame::datapath(sh.frame.frame_kind, sh)),
            (fr_d, fr_a)
        );
        assert_eq!(fr_d, 3 * nz_d + 2 * cr_d + dot_d);
        assert_eq!(dp(&hw_model::frame::perturb_datapath(sh)), (pe_d, pe_a));
        assert_eq!(pe_d, ma_d + nz_d);
        assert_eq!(dp(&hw_model::blinn_phong::datapath(sh)), (bp_d, bp_a));
    }
    // Power (log-exp, L = 8, G = 8, E = 11, w = F + 8): log2 table lzc(F + 1) + ROM 9 +
    // mul(w, F - 8) + add(w); times exponent mul(w + 6, 11) + add(w + 6); exp2 table ROM 9 +
    // mul + add + shift 6. F = 16: (6 + 9 + 16 + 7) + (19 + 7) + (9 + 16 + 7 + 6) = 38 + 26
    // + 38 = 102.
    for (f, d, a) in [(8, 69, 4995), (12, 93, 7483), (16, 102, 10417)] {
        let hw = with("pow_frac_bits", f);
        assert_eq!(
            dp(&hw_model::pow::datapath(&hw.shading.pow)),
            (d, a),
            "F={f}"
        );
    }
}

#[test]
fn brdf_roughness_ndf_footprint_at_three_widths() {
    // Ashikhmin-Shirley (d = D + 2): 17x (mul d x d + add(2d + 1)), 13x mul, 4x ROM8x24 (9),
    // dividers of 34 and 22 quotient bits at 4 bits per step (4 x (add + mux)): D = 14:
    // 17*(20 + 8) + 13*20 + 4*9 + 9*4*(8 + 1) + 6*4*(7 + 1) = 476 + 260 + 36 + 324 + 192 = 1288.
    for (d, dl, a) in [(10, 1211, 81881), (12, 1271, 95647), (14, 1288, 112149)] {
        let hw = with("aniso_dot_frac_bits", d);
        assert_eq!(
            dp(&hw_model::aniso_phong::datapath(&hw.aniso_phong)),
            (dl, a),
            "D={d}"
        );
    }
    // Roughness cos a' (d = D + 2): 3x (3x mul d x d + add(2d + 2)), 2 dividers of 16 bits
    // at 2 per step (16 steps of 2 x (add18 7 + mux 1) = 16 levels), the root (8 steps):
    // D = 16: mul18x18 (18 rows, 6 levels: 1 + 12 + add36 8 = 21) + add38 (8) = 29 per stage:
    // 3*29 + 16*16 + 8*16 = 87 + 256 + 128 = 471.
    for (d, dl, a) in [(8, 459, 23016), (12, 465, 30456), (16, 471, 40857)] {
        let hw = with("rough_d_bits", d);
        assert_eq!(
            dp(&hw_model::roughness::datapath(&hw.roughness)),
            (dl, a),
            "D={d}"
        );
    }
    // NDF (w = N + 2; partial normalization, Pearson m = 8): 54 multiplies, 39 adds, one
    // rsqrt (118), the reciprocal (167). N = 24: mul26x26 23, add28 7: 54*23 + 39*7 + 118 +
    // 167 = 1242 + 273 + 285 = 1800; N = 16: mul18x18 21, add20 7: 1134 + 273 + 285 = 1692.
    for (n, dl, a) in [(16, 1692, 217942), (20, 1800, 291052), (24, 1800, 377986)] {
        let hw = with("ndf_frac_bits", n);
        let d = hw_model::ndf::datapath(&hw.ndf, &hw.reciprocal, &hw.shading.rsqrt).expect("ndf");
        assert_eq!(dp(&d), (dl, a), "N={n}");
    }
    // Footprint assembly: 1 probe = the trilinear unit (256); n probes = LOD (474) + the
    // select/offset/average stage + n trilinear samples.
    for (n, dl, a) in [(1, 256, 116336), (2, 1011, 415962), (4, 1532, 655050)] {
        let hw = with("aniso_probes", n);
        let d = hw_model::footprint::datapath(&hw.trilinear, &hw.lod, n);
        assert_eq!(dp(&d), (dl, a), "probes={n}");
        assert_eq!(report(&hw, "footprint").delay, dl);
    }
}

/// Every unit's delay and area never fall when any one width grows, over each field's valid
/// range. `pow_lut_bits` is the exception: a wider table index makes the table larger but the
/// interpolating multiplier (`pow_frac_bits - pow_lut_bits` bits) narrower, so the power unit's
/// area first falls (9865 GE at 2 bits, 9499 at 3) and then grows; for it only growth at the
/// wide end is required.
#[test]
fn monotone_in_every_width() {
    let fields = [
        "weight_bits",
        "texel_bits",
        "color_bits",
        "lod_frac_bits",
        "bary_bits",
        "inv_w_bits",
        "texcoord_frac_bits",
        "texcoord_int_bits",
        "recip_mantissa_bits",
        "recip_lut_bits",
        "recip_iterations",
        "rsqrt_mantissa_bits",
        "rsqrt_lut_bits",
        "rsqrt_iterations",
        "vector_frac_bits",
        "offset_frac_bits",
        "offset_int_bits",
        "pow_frac_bits",
        "pow_guard_bits",
        "pow_exponent_bits",
        "pow_lut_bits",
        "shade_color_bits",
        "rough_d_bits",
        "rough_div_bits",
        "rough_sqrt_bits",
        "aniso_dot_frac_bits",
        "exponent_max_bits",
        "aniso_ratio_bits",
        "aniso_recip_bits",
        "aniso_pow_lut_bits",
        "aniso_pow_frac_bits",
        "ndf_frac_bits",
        "aniso_probes",
    ];
    for f in fields {
        let mut prev: Option<Vec<UnitReport>> = None;
        let mut grew = false;
        for v in 0..=32u32 {
            let Ok(hw) = set_field(&HwConfig::texram16(), f, &v.to_string()) else {
                continue;
            };
            let now = units(&hw);
            if let Some(p) = &prev {
                for (a, b) in p.iter().zip(&now) {
                    if f != "pow_lut_bits" {
                        assert!(
                            b.area >= a.area && b.delay >= a.delay,
                            "{f}={v}: {} delay {} -> {}, area {} -> {}",
                            a.name,
                            a.delay,
                            b.delay,
                            a.area,
                            b.area
                        );
                    }
                    grew |= b.area > a.area;
                }
            }
            prev = Some(now);
        }
        assert!(grew, "{f}: no unit's area grows with it");
    }
}

#[test]
fn latency_rounds_each_stage_up_and_overrides_win() {
    let add = Component::Adder { width: 32 }; // 7 levels
    let s = |n: u32| {
        let mut st = Stage::new("chain");
        for _ in 0..n {
            st = st.then(add);
        }
        st
    };
    // 9 adders = 63 levels: ceil(63 / 32) = 2; 10 = 70: 3; at 1 level per cycle: 70.
    assert_eq!(Datapath::new().stage(s(9)).latency(32), 2);
    assert_eq!(Datapath::new().stage(s(10)).latency(32), 3);
    assert_eq!(Datapath::new().stage(s(10)).latency(1), 70);
    assert_eq!(Datapath::new().stage(s(10)).latency(70), 1);
    // Stages round separately: two stages of 35 levels take 2 + 2 = 4 cycles, where one stage
    // of 70 levels takes ceil(70 / 32) = 3.
    let five = Datapath::new().stage(s(5)).stage(s(5));
    assert_eq!((five.delay(), five.latency(32)), (70, 4));
    // Repeats multiply delay, latency and area; a hand-set value replaces the derived one.
    let r = Datapath::new().stage(s(10).times(3));
    assert_eq!(
        (r.delay(), r.latency(32), r.area()),
        (210, 9, 30 * add.area())
    );
    let fixed = Datapath::new().stage(s(10).times(3).cycles(Cycles::Fixed(1)));
    assert_eq!((fixed.delay(), fixed.latency(32)), (210, 3));
    // A zero-delay stage (registers only) takes no cycle; an empty datapath costs nothing.
    let regs = Datapath::new().stage(Stage::new("reg").then(Component::Register { bits: 8 }));
    assert_eq!((regs.delay(), regs.latency(32), regs.area()), (0, 0, 48));
    assert_eq!(Datapath::new().latency(1), 0);
}

/// The clock target is a hardware field: sweeping it moves latencies; 0 is refused naming it.
#[test]
fn gate_levels_per_cycle_is_a_validated_sweepable_field() {
    let fast = with("gate_levels_per_cycle", 16);
    let slow = with("gate_levels_per_cycle", 64);
    let (f, s) = (report(&fast, "trilinear"), report(&slow, "trilinear"));
    assert_eq!(f.delay, s.delay);
    // Bilinear 110, blend 36: at 16 levels 2*7 + 3 = 17 cycles, at 64 levels 2*2 + 1 = 5.
    assert_eq!((f.latency, s.latency), (17, 5));
    let err = set_field(&HwConfig::texram16(), "gate_levels_per_cycle", "0").expect_err("0");
    assert!(err.to_string().contains("gate_levels_per_cycle"), "{err}");
    // A hand-set field and back to derived through the sweep syntax.
    let set = set_field(&HwConfig::texram16(), "bilinear_cycles", "1").expect("set");
    assert_eq!(set.trilinear.bilinear_cycles, Cycles::Fixed(1));
    assert_eq!(report(&set, "trilinear").latency, 1 + 1 + 2);
    let back = set_field(&set, "bilinear_cycles", "derived").expect("derived");
    assert_eq!(back.trilinear.bilinear_cycles, Cycles::Derived);
    assert!(set_field(&HwConfig::texram16(), "bilinear_cycles", "fast").is_err());
}

/// Wider weights cost delay and area in the trilinear unit and in the machine's total.
#[test]
fn weight_bits_cost_delay_and_area() {
    let mut last = (0, 0, 0);
    for w in [4, 8, 12, 16] {
        let hw = with("weight_bits", w);
        let r = report(&hw, "trilinear");
        let now = (r.delay, r.area, total_area(&units(&hw)));
        assert!(
            now.0 > last.0 && now.1 > last.1 && now.2 > last.2,
            "W={w}: {now:?}"
        );
        last = now;
    }
}

/// docs/COST.md's table (unit | datapath | delay | area | source) is the model at texram16:
/// every unit has a row with its delay and area, and the datapath cell names its stages.
#[test]
fn cost_doc_table_matches_the_model() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/docs/COST.md");
    let text = std::fs::read_to_string(path).expect("docs/COST.md");
    let rows: Vec<Vec<String>> = text
        .lines()
        .filter(|l| l.starts_with("| `"))
        .map(|l| {
            l.trim_matches('|')
                .split('|')
                .map(|c| c.trim().to_string())
                .collect()
        })
        .collect();
    let reports = units(&HwConfig::texram16());
    assert_eq!(rows.len(), reports.len(), "one row per unit");
    for r in &reports {
        let row = rows
            .iter()
            .find(|c| c[0] == format!("`{}`", r.name))
            .unwrap_or_else(|| panic!("docs/COST.md: no row for {}", r.name));
        assert_eq!(
            row.len(),
            5,
            "{}: unit | datapath | delay | area | source",
            r.name
        );
        assert_eq!(row[2], r.delay.to_string(), "{} delay", r.name);
        assert_eq!(row[3], r.area.to_string(), "{} area", r.name);
        for s in &r.datapath.stages {
            assert!(
                row[1].contains(s.name),
                "{}: stage '{}' not in '{}'",
                r.name,
                s.name,
                row[1]
            );
        }
        assert!(!row[4].is_empty(), "{}: no source", r.name);
    }
    let total = format!("{} GE", total_area(&reports));
    assert!(
        text.contains(&total),
        "docs/COST.md does not state the total {total}"
    );
}
