//! Stages over spans of fragments: the span twins of `bary` and `texcoord`, of `lod` and
//! `trilinear`, of `color` and `modulate`, and of `normal`, against their per-fragment twins
//! on seeded spans (values, carriers, traced footprints, saturation counts and costs), and
//! whole frames shaded in spans against the same frames shaded one fragment at a time
//! (images, statistics, counters and cycle counts).

use crate::rng_common::Rng;
use hw_model::config::{CoordArith, HwConfig, LodLog2};
use hw_model::fixed::Rounding;
use hw_model::fixed::SatCounter;
use hw_model::wrap::WrapMode;
use texsim::maps::{build_mip_chain, quantize_chain};
use texsim::pipeline::bump::BumpAttrs;
use texsim::pipeline::lanes::{vector_lanes, LaneCell, LANES};
use texsim::pipeline::stages::{Counters, Machine, TriAttrs, TriFloat};
use texsim::pipeline::table::Program;
use texsim::pipeline::{
    bary, color, lod, modulate, normal, plan, texcoord, trilinear, Frag, Impl, Px, StageImpls,
    StageKind, MAX_POINT_LIGHTS,
};
use texsim::raster::{ScreenTri, VertexSource};
use texsim::render::{render, Maps, RenderOptions, Rendered};
use texsim::scene::{self, FrameKind, MainDirection, Material, TextureImage};
use texsim::timing::simulate;

const MODES: [Rounding; 3] = [Rounding::Truncate, Rounding::HalfUp, Rounding::HalfEven];

/// A fixed-point configuration with random raster, interpolator and reciprocal widths, rounding
/// modes, `lod_per_quad` and attribute grid (off, the raster's, or finer).
fn config(rng: &mut Rng) -> HwConfig {
    let mut hw = HwConfig::texram16();
    hw.raster.subpixel_bits = rng.int_in(1, 12) as u32;
    let i = &mut hw.interp;
    i.bary_bits = rng.int_in(4, 30) as u32;
    i.inv_w_bits = rng.int_in(4, 30) as u32;
    i.interp_rounding = MODES[rng.below(3) as usize];
    i.texcoord_frac_bits = rng.int_in(4, 28) as u32;
    i.texcoord_int_bits = rng.int_in(1, 16) as u32;
    i.coord_arith = CoordArith::Fixed;
    i.attr_subpixel_bits = match rng.below(4) {
        0 => rng.int_in(1, 16) as u32,
        1 => hw.raster.subpixel_bits,
        _ => 0,
    };
    hw.lod.lod_per_quad = rng.below(3) == 0;
    hw.reciprocal.recip_mantissa_bits = rng.int_in(8, 30) as u32;
    hw.reciprocal.recip_iterations = rng.int_in(0, 3) as u32;
    hw.reciprocal.recip_rounding = MODES[rng.below(3) as usize];
    hw
}

/// A triangle on the raster's grid of `sub` bits: screen-sized, huge (beyond the edges' `i64`
/// bounds), or near-degenerate; its float positions a little off the grid.
fn triangle(rng: &mut Rng, sub: u32) -> ScreenTri {
    let size = 1i64 << [rng.int_in(1, 10), rng.int_in(10, 24)][rng.below(2) as usize];
    let mut xy = [[0i64; 2]; 3].map(|_| [0, 1].map(|_| rng.int_in(-size, size) << sub));
    if rng.below(4) == 0 {
        let t = rng.int_in(-3, 3);
        xy[2] = [0, 1].map(|k| xy[0][k] + t * (xy[1][k] - xy[0][k]) + rng.int_in(-2, 2));
    }
    let g = f64::from(1u32 << sub);
    let xy_f = xy.map(|p| p.map(|c| (c as f64 + rng.range(-0.5, 0.5)) / g));
    ScreenTri {
        xy,
        xy_f,
        z: [0; 3],
        z_f: [0.0; 3],
        inv_w: [1.0; 3],
        src: 0,
        source: VertexSource::Unclipped { swapped: false },
        area2: 1,
        area2_f: 1.0,
        bbox: [0; 4],
    }
}

/// Vertex data: 1/w normalized to `2^inv_w_bits` for the largest (some tiny: a vertex far
/// behind), texture coordinates within the format or beyond it.
fn attrs(rng: &mut Rng, hw: &HwConfig) -> (TriAttrs, TriFloat) {
    let bits = hw.interp.inv_w_bits;
    let one = 1i64 << bits;
    let mut inv_w_x = [0i64; 3].map(|_| match rng.below(4) {
        0 => one,
        1 => rng.int_in(1, 8),
        _ => rng.int_in(1, one),
    });
    inv_w_x[rng.below(3) as usize] = one;
    let inv_w_f = inv_w_x.map(|w| w as f64 / one as f64);
    let uv_bits = hw.interp.texcoord_frac_bits + hw.interp.texcoord_int_bits + 2;
    let uv_max = 1i64 << uv_bits.min(60);
    let uv_x = [[0i64; 2]; 3].map(|_| [0, 1].map(|_| rng.int_in(-uv_max, uv_max)));
    let uv_f = uv_x.map(|t| t.map(|v| v as f64 / f64::from(1u32 << hw.interp.texcoord_frac_bits)));
    let a = TriAttrs {
        inv_w_x,
        uv_x,
        ..TriAttrs::default()
    };
    let af = TriFloat {
        inv_w: inv_w_f,
        color: [[0.0; 3]; 3],
        uv: uv_f,
    };
    (a, af)
}

/// The fields `bary` and `texcoord` write, of the first `samples` samples.
fn written(f: &Frag, samples: usize) -> String {
    format!(
        "{:?} {:?} {:?} {:?}",
        &f.bary_x[..samples],
        &f.uv_x[..samples],
        f.bary[..samples]
            .iter()
            .flatten()
            .map(|v| v.to_bits())
            .collect::<Vec<_>>(),
        f.uv[..samples]
            .iter()
            .flatten()
            .map(|v| v.to_bits())
            .collect::<Vec<_>>(),
    )
}

/// A span of 1 to 16 fragments near `tri`'s first vertex (partly outside the triangle, or all
/// outside): its first pixel and length.
fn span_near(rng: &mut Rng, tri: &ScreenTri, sub: u32) -> (i64, i64, usize) {
    let (vx, vy) = (tri.xy[0][0] >> sub, tri.xy[0][1] >> sub);
    let n = rng.int_in(1, 16) as usize;
    let x = vx + rng.int_in(-12, 4);
    let y = vy + rng.int_in(-3, 3);
    (x, y, n)
}

/// The `bary` stage of `impls` over a span: its span twin when fixed, else the float twin on
/// each fragment.
fn bary_span(px: &Px, span: &mut [Frag], c: &mut Counters) {
    if px.impls.of(StageKind::Bary) == Impl::Fixed {
        bary::fixed_span(px, span, c);
    } else {
        texsim::pipeline::stages::each_fragment(bary::float, px, span, c);
    }
}

/// The `bary` stage of `impls` on one fragment.
fn bary_one(px: &Px, f: &mut Frag, c: &mut Counters) {
    if px.impls.of(StageKind::Bary) == Impl::Fixed {
        bary::fixed(px, f, c);
    } else {
        bary::float(px, f, c);
    }
}

/// 300k seeded spans of 1..=16 fragments (pixels in and out of the triangle): `bary` then
/// `texcoord` over the span give, at every fragment, the values and carriers of their
/// per-fragment twins, and the same counters; over raster and interpolator widths, rounding
/// modes, `lod_per_quad`, `attr_subpixel_bits`, derivatives on and off, a Float `bary`
/// before a Fixed `texcoord`, near-degenerate and huge triangles and tiny 1/w.
#[test]
fn span_twins_match_the_per_fragment_twins() {
    let mut rng = Rng(0x5a4e_1001);
    let textured = Material {
        texture: Some(0),
        ..Material::default()
    };
    for group in 0..150u32 {
        let hw = config(&mut rng);
        let m = Machine::new(&hw, &[], &[]);
        let sub = hw.raster.subpixel_bits;
        for case in 0..2000u32 {
            let tri = triangle(&mut rng, sub);
            let (a, af) = attrs(&mut rng, &hw);
            let mut pl = plan(&textured, true);
            pl.derivatives = rng.below(4) != 0;
            let impls = if rng.below(8) == 0 {
                StageImpls::FIXED.with(StageKind::Bary, Impl::Float)
            } else {
                StageImpls::FIXED
            };
            let (x, y, n) = span_near(&mut rng, &tri, sub);
            let px = Px {
                plan: &pl,
                impls: &impls,
                m: &m,
                tri: &tri,
                a: &a,
                af: &af,
                x,
                y,
                color_raw: false,
                carriers: rng.below(2) == 0,
                row_bary: None,
                lanes: None,
                base: 0,
            };
            let mut span = vec![Frag::default(); n];
            let mut c_span = Counters::default();
            bary_span(&px, &mut span, &mut c_span);
            texcoord::fixed_span(&px, &mut span, &mut c_span);
            let mut c_one = Counters::default();
            let samples = px.samples();
            for (j, got) in span.iter().enumerate() {
                let at = Px {
                    x: px.x + j as i64,
                    ..px
                };
                let mut f = Frag::default();
                bary_one(&at, &mut f, &mut c_one);
                texcoord::fixed(&at, &mut f, &mut c_one);
                assert_eq!(
                    written(got, samples),
                    written(&f, samples),
                    "group {group} case {case} fragment {j}"
                );
            }
            for k in [StageKind::Bary, StageKind::Texcoord] {
                assert_eq!(
                    c_span.sat[k.index()],
                    c_one.sat[k.index()],
                    "group {group} case {case}: {k} counts"
                );
            }
        }
    }
}

/// 300k seeded spans of 1..=32 fragments in a program that keeps the chain's signals in
/// lanes (`pipeline::lanes`): `bary` then `texcoord` over the span, from lane `base` of the
/// run, leave in the lanes the barycentrics and texture coordinates their per-fragment twins
/// write to the fragments, with the same counters, and leave the other lanes alone; over the
/// widths and paths of `span_twins_match_the_per_fragment_twins` (`lod_per_quad` and the
/// attribute grid take the per-fragment path, huge triangles the edges' fallback) and
/// barycentrics from the row's pass (`row_bary`). The textured plan with derivatives keeps
/// lanes with vector batches (AVX2 or AVX-512); with a `color` stage, without derivatives or
/// with a Float stage it does not. (The stages here are given the lanes whatever the CPU.)
#[test]
fn span_twins_in_lanes_match_the_per_fragment_twins() {
    let mut rng = Rng(0x5a4e_10a1);
    let textured = Material {
        texture: Some(0),
        lit: false,
        ..Material::default()
    };
    let (mut from_row, mut long) = (0u32, 0u32);
    for group in 0..150u32 {
        let hw = config(&mut rng);
        let m = Machine::new(&hw, &[], &[]);
        let sub = hw.raster.subpixel_bits;
        let mut pl = plan(&textured, true);
        pl.derivatives = true;
        let vector = vector_lanes();
        assert_eq!(
            Program::new(&pl, &StageImpls::FIXED, &m).lanes,
            vector,
            "group {group}"
        );
        let float_lod = StageImpls::FIXED.with(StageKind::Lod, Impl::Float);
        assert!(!Program::new(&pl, &float_lod, &m).lanes);
        let mut flat = plan(&textured, true);
        flat.derivatives = false;
        assert!(!Program::new(&flat, &StageImpls::FIXED, &m).lanes);
        let lit = Material {
            texture: Some(0),
            lit: true,
            ..Material::default()
        };
        let mut lit = plan(&lit, true);
        lit.derivatives = true;
        assert!(lit.has(StageKind::Color));
        assert!(!Program::new(&lit, &StageImpls::FIXED, &m).lanes);
        let cell = LaneCell::default();
        for case in 0..2000u32 {
            let tri = triangle(&mut rng, sub);
            let (a, af) = attrs(&mut rng, &hw);
            let (x, y, _) = span_near(&mut rng, &tri, sub);
            let n = rng.int_in(1, LANES as i64) as usize;
            let base = rng.int_in(0, (LANES - n) as i64) as usize;
            long += u32::from(n >= 8);
            let px = Px {
                plan: &pl,
                impls: &StageImpls::FIXED,
                m: &m,
                tri: &tri,
                a: &a,
                af: &af,
                x,
                y,
                color_raw: false,
                carriers: false,
                row_bary: None,
                lanes: Some(&cell),
                base,
            };
            let mut c_one = Counters::default();
            let want: Vec<Frag> = (0..n)
                .map(|j| {
                    let at = Px {
                        x: px.x + j as i64,
                        lanes: None,
                        ..px
                    };
                    let mut f = Frag::default();
                    bary::fixed(&at, &mut f, &mut c_one);
                    texcoord::fixed(&at, &mut f, &mut c_one);
                    f
                })
                .collect();
            // Sometimes the row's pass computed the barycentrics (counted there).
            let row: Vec<[[i64; 3]; 3]> = want.iter().map(|f| f.bary_x).collect();
            let by_row = rng.below(4) == 0;
            from_row += u32::from(by_row);
            let px = Px {
                row_bary: by_row.then_some(&row[..]),
                ..px
            };
            let before = cell.borrow().clone();
            let mut span = vec![Frag::default(); n];
            let mut c_span = Counters::default();
            bary::fixed_span(&px, &mut span, &mut c_span);
            texcoord::fixed_span(&px, &mut span, &mut c_span);
            let l = cell.borrow();
            for j in 0..LANES {
                let (b, uv) = if (base..base + n).contains(&j) {
                    (want[j - base].bary_x, want[j - base].uv_x)
                } else {
                    (
                        [0, 1, 2].map(|s| [0, 1, 2].map(|c| before.bary[s][c][j])),
                        before.uv_of(j),
                    )
                };
                let got_b = [0, 1, 2].map(|s| [0, 1, 2].map(|c| l.bary[s][c][j]));
                let what = format!("group {group} case {case} lane {j} (base {base}, n {n})");
                assert_eq!(got_b, b, "{what}: barycentrics");
                assert_eq!(l.uv_of(j), uv, "{what}: coordinates");
            }
            let bary_sat = if by_row {
                SatCounter::default()
            } else {
                c_one.sat[StageKind::Bary.index()]
            };
            assert_eq!(c_span.sat[StageKind::Bary.index()], bary_sat, "case {case}");
            let k = StageKind::Texcoord.index();
            assert_eq!(
                c_span.sat[k], c_one.sat[k],
                "group {group} case {case}: counts"
            );
        }
    }
    assert!(from_row > 50_000 && long > 200_000, "{from_row} {long}");
}

/// A texture of random size (powers of two and others, 1 to 80 texels a side) and texels,
/// its MIP chain built by the renderer's rule.
fn texture(rng: &mut Rng) -> TextureImage {
    let side = |rng: &mut Rng| match rng.below(3) {
        0 => 1u32 << rng.below(7),
        _ => rng.int_in(1, 80) as u32,
    };
    let (width, height) = (side(rng), side(rng));
    TextureImage {
        name: "random".into(),
        width,
        height,
        texels: (0..width * height)
            .map(|_| [0; 4].map(|_| rng.next() as u16))
            .collect(),
        prebuilt_levels: None,
    }
}

/// The fields `lod` and `trilinear` write (raw values, carriers' bits, footprints).
fn written_lookup(f: &Frag) -> String {
    format!(
        "{} {:x} {:?} {:?} {} {:?} {:?} {:?}",
        f.lod_x,
        f.lod.to_bits(),
        f.texel_x,
        f.out_x,
        f.out_bits,
        f.texel.map(f64::to_bits),
        f.out.map(f64::to_bits),
        f.trace.footprints(),
    )
}

/// 60k seeded spans of 1..=16 fragments: `lod` then `trilinear` over the span give, at every
/// fragment, the raw values, carriers and traced footprints of their per-fragment twins, and
/// the same saturation counts and costs; over the three rounding modes of the filter and of
/// the weights, weight widths 0 to 16, LOD fraction widths 0 to 16 and both log2 units, texel
/// widths, coordinate formats, every wrap-mode pair, textures of power-of-two and other sizes,
/// coordinates inside, around and far outside the texture (the wide wrap path), tracing on
/// and off, carriers on and off, and the per-fragment fallbacks (footprint assembly, a Float
/// `texcoord` or `lod` producer).
#[test]
fn lookup_span_twins_match_the_per_fragment_twins() {
    let mut rng = Rng(0x5a4e_1002);
    let textured = Material {
        texture: Some(0),
        ..Material::default()
    };
    let modes = [WrapMode::Repeat, WrapMode::ClampToEdge, WrapMode::Mirror];
    let mut fast = 0u32;
    for group in 0..300u32 {
        let mut hw = HwConfig::texram16();
        let t = &mut hw.trilinear;
        t.filter_rounding = MODES[rng.below(3) as usize];
        t.weight_rounding = MODES[rng.below(3) as usize];
        t.weight_bits = rng.int_in(0, 16) as u32;
        t.texel_bits = rng.int_in(1, 16) as u32;
        t.aniso_probes = if rng.below(6) == 0 { 4 } else { 1 };
        t.aniso_adaptive = rng.below(2) == 0;
        hw.lod.lod_frac_bits = rng.int_in(0, 16) as u32;
        hw.lod.lod_log2 = [LodLog2::Exact, LodLog2::PiecewiseLinear][rng.below(2) as usize];
        hw.interp.texcoord_frac_bits = rng.int_in(4, 28) as u32;
        hw.interp.texcoord_int_bits = rng.int_in(1, 16) as u32;
        let chain = build_mip_chain(&texture(&mut rng));
        let fixed_chain = quantize_chain(&chain, hw.trilinear.texel_bits);
        let float_chains = [chain];
        let fixed_chains = [fixed_chain];
        let m = Machine::new(&hw, &float_chains, &fixed_chains);
        let tri = triangle(&mut rng, 4);
        let (a, af) = (TriAttrs::default(), TriFloat::NONE);
        let fb = hw.interp.texcoord_frac_bits;
        let levels = float_chains[0].levels.len() as f64;
        for case in 0..200u32 {
            let mut pl = plan(&textured, true);
            pl.derivatives = rng.below(8) != 0;
            pl.wrap = [0, 1].map(|_| modes[rng.below(3) as usize]);
            let impls = match rng.below(10) {
                0 => StageImpls::FIXED.with(StageKind::Texcoord, Impl::Float),
                1 => StageImpls::FIXED.with(StageKind::Lod, Impl::Float),
                _ => StageImpls::FIXED,
            };
            let aniso = hw.trilinear.aniso_probes > 1 && pl.derivatives;
            let px = Px {
                plan: &pl,
                impls: &impls,
                m: &m,
                tri: &tri,
                a: &a,
                af: &af,
                x: rng.int_in(-50, 50),
                y: rng.int_in(-50, 50),
                color_raw: false,
                carriers: rng.below(2) == 0,
                row_bary: None,
                lanes: None,
                base: 0,
            };
            let n = rng.int_in(1, 16) as usize;
            // Coordinates mostly within a few textures of the origin, some anywhere in the
            // format's range; helper samples a texel-scale step away (LODs below, inside and
            // past the chain).
            let one = 1i64 << fb;
            let lim = 1i64 << (fb + hw.interp.texcoord_int_bits);
            let far = rng.below(8) == 0;
            let trace_on = rng.below(2) == 0;
            let mut span: Vec<Frag> = (0..n)
                .map(|_| {
                    let mut f = Frag::default();
                    let c = |rng: &mut Rng| {
                        if far {
                            rng.int_in(-lim, lim)
                        } else {
                            rng.int_in(-2 * one, 3 * one)
                        }
                    };
                    let uv0 = [c(&mut rng), c(&mut rng)];
                    let step = 1i64 << rng.int_in(0, i64::from(fb));
                    f.uv_x[0] = uv0;
                    for s in 1..3 {
                        f.uv_x[s] = uv0.map(|x| (x + rng.int_in(-step, step)).clamp(-lim, lim));
                    }
                    f.uv = f.uv_x.map(|s| s.map(|x| x as f64 / one as f64));
                    f.lod = rng.range(-2.0, levels + 1.0);
                    f.trace.on = trace_on;
                    f
                })
                .collect();
            let before = span.clone();
            let lod_fixed = impls.of(StageKind::Lod) == Impl::Fixed;
            let mut c_span = Counters::default();
            if lod_fixed {
                lod::fixed_span(&px, &mut span, &mut c_span);
            }
            trilinear::fixed_span(&px, &mut span, &mut c_span);
            let mut c_one = Counters::default();
            for (j, got) in span.iter().enumerate() {
                let at = Px {
                    x: px.x + j as i64,
                    ..px
                };
                let mut f = before[j];
                if lod_fixed {
                    lod::fixed(&at, &mut f, &mut c_one);
                }
                trilinear::fixed(&at, &mut f, &mut c_one);
                assert_eq!(
                    written_lookup(got),
                    written_lookup(&f),
                    "group {group} case {case} fragment {j}"
                );
            }
            for k in [StageKind::Lod, StageKind::Trilinear] {
                assert_eq!(
                    format!("{:?} {:?}", c_span.sat[k.index()], c_span.cost[k.index()]),
                    format!("{:?} {:?}", c_one.sat[k.index()], c_one.cost[k.index()]),
                    "group {group} case {case}: {k} counts"
                );
            }
            if lod_fixed && impls.of(StageKind::Texcoord) == Impl::Fixed && !aniso {
                fast += 1;
            }
        }
    }
    assert!(fast > 30_000, "{fast} spans on the span twins' own paths");
}

/// The fields `color` and `modulate` write (raw values, carriers' bits, output width).
fn written_color(f: &Frag) -> String {
    format!(
        "{:?} {:?} {:?} {:?} {}",
        f.color_x,
        f.color.map(f64::to_bits),
        f.out_x,
        f.out.map(f64::to_bits),
        f.out_bits,
    )
}

/// 120k seeded spans of 1..=16 fragments of a lit, textured plan: `bary`, `color` and
/// `modulate` over the span give, at every fragment, the raw values, carriers and output of
/// their per-fragment twins and the same saturation counts; over colour and texel widths 1
/// to 16, the colour rounding modes, vertex colours at 0, at their maximum and between,
/// raw texels up to beyond their maximum (the unit clamps) and texel carriers unrelated to
/// them, a Float `bary`, `color` or `trilinear` producer (the per-fragment fallback and the
/// carriers' rounding), carriers on and off.
#[test]
fn color_and_modulate_span_twins_match_the_per_fragment_twins() {
    let mut rng = Rng(0x5a4e_1003);
    let lit = Material {
        texture: Some(0),
        lit: true,
        ..Material::default()
    };
    let pl = plan(&lit, true);
    assert!(pl.has(StageKind::Color) && pl.has(StageKind::Modulate));
    let mut fast = 0u32;
    for group in 0..60u32 {
        let mut hw = config(&mut rng);
        let (cb, tb) = (rng.int_in(1, 16) as u32, rng.int_in(1, 16) as u32);
        hw.color.color_bits = cb;
        hw.color.color_rounding = MODES[rng.below(3) as usize];
        hw.trilinear.texel_bits = tb;
        let m = Machine::new(&hw, &[], &[]);
        let sub = hw.raster.subpixel_bits;
        let (cmax, tmax) = ((1i64 << cb) - 1, (1i64 << tb) - 1);
        for case in 0..2000u32 {
            let tri = triangle(&mut rng, sub);
            let (mut a, mut af) = attrs(&mut rng, &hw);
            a.color_x = [[0u16; 3]; 3].map(|_| {
                [0; 3].map(|_| match rng.below(4) {
                    0 => 0,
                    1 => cmax as u16,
                    _ => rng.int_in(0, cmax) as u16,
                })
            });
            af.color = a.color_x.map(|v| v.map(|c| f64::from(c) / cmax as f64));
            let mut impls = StageImpls::FIXED;
            for k in [StageKind::Bary, StageKind::Color, StageKind::Trilinear] {
                if rng.below(8) == 0 {
                    impls = impls.with(k, Impl::Float);
                }
            }
            let (x, y, n) = span_near(&mut rng, &tri, sub);
            let px = Px {
                plan: &pl,
                impls: &impls,
                m: &m,
                tri: &tri,
                a: &a,
                af: &af,
                x,
                y,
                color_raw: impls.of(StageKind::Color) == Impl::Fixed,
                carriers: rng.below(2) == 0,
                row_bary: None,
                lanes: None,
                base: 0,
            };
            let input: Vec<Frag> = (0..n)
                .map(|_| Frag {
                    texel_x: [0; 4].map(|_| rng.int_in(0, tmax + tmax / 2) as u32),
                    // A carrier unrelated to the raw texel: a Float `trilinear` is read from it.
                    texel: [0.0; 4].map(|_| rng.unit()),
                    ..Frag::default()
                })
                .collect();
            let fixed = |k: StageKind| impls.of(k) == Impl::Fixed;
            let color_twin = if fixed(StageKind::Color) {
                color::fixed
            } else {
                color::float
            };
            let mut span = input.clone();
            let mut c_span = Counters::default();
            bary_span(&px, &mut span, &mut c_span);
            if fixed(StageKind::Color) {
                color::fixed_span(&px, &mut span, &mut c_span);
            } else {
                let each = texsim::pipeline::stages::each_fragment;
                each(color::float, &px, &mut span, &mut c_span);
            }
            modulate::fixed_span(&px, &mut span, &mut c_span);
            let mut c_one = Counters::default();
            for (j, (got, f)) in span.iter().zip(input).enumerate() {
                let at = Px {
                    x: px.x + j as i64,
                    ..px
                };
                let mut f = f;
                bary_one(&at, &mut f, &mut c_one);
                color_twin(&at, &mut f, &mut c_one);
                modulate::fixed(&at, &mut f, &mut c_one);
                assert_eq!(
                    written_color(got),
                    written_color(&f),
                    "group {group} case {case} fragment {j}"
                );
            }
            for k in [StageKind::Bary, StageKind::Color, StageKind::Modulate] {
                assert_eq!(
                    c_span.sat[k.index()],
                    c_one.sat[k.index()],
                    "group {group} case {case}: {k} counts"
                );
            }
            fast += u32::from(fixed(StageKind::Bary) && fixed(StageKind::Color));
        }
    }
    assert!(
        fast > 60_000,
        "{fast} spans on the colour span twin's own path"
    );
}

/// 60k seeded spans of 1..=16 fragments of a bump plan: `bary` then `normal` over the span
/// give, at every fragment, the bump signals (raw and carriers) and saturation counts of the
/// per-fragment twins; over the natural, unit and main frames (main directions constant,
/// `p_u` and `p_v`), 0 to 5 point lights (4 are shaded), vector, length and interpolator
/// widths and rounding modes, vertex vectors within their format and beyond it (the
/// interpolator saturates), and a Float `bary` (the per-fragment fallback).
#[test]
fn normal_span_twin_matches_the_per_fragment_twin() {
    let mut rng = Rng(0x5a4e_1004);
    let bumpy = Material {
        texture: Some(0),
        bump: Some(0),
        ..Material::default()
    };
    let (mut fast, mut saturated) = (0u32, 0u64);
    for group in 0..60u32 {
        let mut hw = config(&mut rng);
        let v = &mut hw.shading.vector;
        v.vector_frac_bits = rng.int_in(4, 15) as u32;
        v.vector_rounding = MODES[rng.below(3) as usize];
        hw.shading.frame.frame_len_frac_bits = rng.int_in(2, 12) as u32;
        let f = hw.shading.vector.vector_frac_bits;
        let lights: Vec<scene::Light> = (0..rng.int_in(0, 5))
            .map(|_| scene::Light::Point {
                position: [1.0, 2.0, 3.0],
                color: [1.0; 3],
            })
            .collect();
        let frame = [FrameKind::Natural, FrameKind::Unit, FrameKind::Main][group as usize % 3];
        let main = match rng.below(3) {
            0 => MainDirection::Constant([0.0, 0.0, if group % 2 == 0 { 1.0 } else { -1.0 }]),
            1 => MainDirection::Pu,
            _ => MainDirection::Pv,
        };
        let mut pl = texsim::pipeline::plan_with_bump(&bumpy, true, Some(1));
        let bp = pl.bump.as_mut().expect("bump plan");
        bp.frame = Some(frame);
        bp.main = main;
        assert!(pl.has(StageKind::Normal));
        let big = 1i64 << (f + 2);
        let vec3 = |rng: &mut Rng| [[0i64; 3]; 3].map(|_| [0; 3].map(|_| rng.int_in(-big, big)));
        let battrs: Vec<BumpAttrs> = (0..40)
            .map(|_| BumpAttrs {
                n_x: vec3(&mut rng),
                du_x: vec3(&mut rng),
                dv_x: vec3(&mut rng),
                m_x: vec3(&mut rng),
                eye_x: vec3(&mut rng),
                light_x: [0; MAX_POINT_LIGHTS].map(|_| vec3(&mut rng)),
                len_x: [[0i64; 2]; 3].map(|_| [0; 2].map(|_| rng.int_in(-big, big))),
                ..BumpAttrs::default()
            })
            .collect();
        let m = Machine::new(&hw, &[], &[])
            .with_lights(&lights, [0.1; 3])
            .with_bump_attrs(&battrs);
        let sub = hw.raster.subpixel_bits;
        for case in 0..1000u32 {
            let tri = triangle(&mut rng, sub);
            let (mut a, af) = attrs(&mut rng, &hw);
            a.bump = rng.below(battrs.len() as u64) as u32;
            let impls = if rng.below(8) == 0 {
                StageImpls::FIXED.with(StageKind::Bary, Impl::Float)
            } else {
                StageImpls::FIXED
            };
            let (x, y, n) = span_near(&mut rng, &tri, sub);
            let px = Px {
                plan: &pl,
                impls: &impls,
                m: &m,
                tri: &tri,
                a: &a,
                af: &af,
                x,
                y,
                color_raw: false,
                carriers: rng.below(2) == 0,
                row_bary: None,
                lanes: None,
                base: 0,
            };
            let input = vec![Frag::default(); n];
            let mut span = input.clone();
            let mut c_span = Counters::default();
            bary_span(&px, &mut span, &mut c_span);
            normal::fixed_span(&px, &mut span, &mut c_span);
            let mut c_one = Counters::default();
            for (j, (got, mut f)) in span.iter().zip(input).enumerate() {
                let at = Px {
                    x: px.x + j as i64,
                    ..px
                };
                bary_one(&at, &mut f, &mut c_one);
                normal::fixed(&at, &mut f, &mut c_one);
                assert_eq!(
                    format!("{:?}", got.bump),
                    format!("{:?}", f.bump),
                    "group {group} case {case} fragment {j}"
                );
            }
            let k = StageKind::Normal.index();
            assert_eq!(c_span.sat[k], c_one.sat[k], "group {group} case {case}");
            fast += u32::from(impls.of(StageKind::Bary) == Impl::Fixed);
            saturated += c_span.sat[k].saturated;
        }
    }
    assert!(
        fast > 45_000,
        "{fast} spans on the normal span twin's own path"
    );
    assert!(saturated > 0, "the interpolator's saturation was exercised");
}

fn render_with(s: &scene::Scene, hw: &HwConfig, per_fragment: bool) -> Rendered {
    let maps = Maps::new(s, hw.trilinear.texel_bits);
    let opts = RenderOptions {
        timing: true,
        per_fragment,
        ..RenderOptions::default()
    };
    render(s, &maps, hw, &opts).expect("render")
}

/// The stats without the wall-clock timings.
fn stats_json(r: &Rendered) -> serde_json::Value {
    let mut v = serde_json::to_value(&r.stats).expect("json");
    v.as_object_mut().expect("object").remove("timings");
    v
}

/// Scenes of every kind of plan, on the fixed-point presets, llvmpipe's float32 path, footprint
/// assembly with adaptive probes, `lod_per_quad` and a finer attribute grid: shading in spans
/// (with each row's barycentrics in one pass, `bary::Row`, where the plan has derivatives)
/// gives the per-fragment frame (hardware and reference images, statistics with every stage's
/// counters, and the timing model's cycles).
#[test]
fn frames_in_spans_equal_frames_per_fragment() {
    let mut aniso = HwConfig::texram16();
    aniso.trilinear.aniso_probes = 4;
    aniso.trilinear.aniso_adaptive = true;
    let mut quad = HwConfig::d3d11();
    quad.lod.lod_per_quad = true;
    quad.interp.attr_subpixel_bits = 12;
    quad.interp.interp_rounding = Rounding::Truncate;
    let configs = [
        HwConfig::texram16(),
        HwConfig::vulkan_min(),
        HwConfig::llvmpipe(),
        aniso,
        quad,
    ];
    for hw in &configs {
        for name in [
            "demo", "w1-plane", "w2-mesh", "bumps", "lod-pair", "sky-lake",
        ] {
            let mut s = scene::builtin(name).expect("builtin");
            s.width = 96;
            s.height = 64;
            let (a, b) = (render_with(&s, hw, false), render_with(&s, hw, true));
            let what = format!("{name} on {}", hw.name);
            assert!(a.hw_image == b.hw_image, "{what}: hardware image");
            assert!(a.ref_image == b.ref_image, "{what}: reference image");
            assert_eq!(stats_json(&a), stats_json(&b), "{what}: stats");
            let (ea, eb) = (a.events.expect("events"), b.events.expect("events"));
            assert_eq!(
                serde_json::to_value(simulate(&ea, hw, name)).expect("json"),
                serde_json::to_value(simulate(&eb, hw, name)).expect("json"),
                "{what}: timing report"
            );
        }
    }
}
