//! PNG round trips, pixmap conversion, heatmap colours and legend, sheet layout and filtering.

use crate::rng_common::Rng;
use texsim::report::{
    encode_pixmap, encode_png16, encode_png8, heatmap, heatmap_colour, heatmap_layout,
    image_to_pixmap, sheet, sheet_panel_size, Image, MASKED_RGB, SHEET_PAD, SHEET_TITLE_H,
};
use tiny_skia::Pixmap;

fn random_image(rng: &mut Rng, w: u32, h: u32) -> Image {
    Image {
        width: w,
        height: h,
        px: (0..w * h)
            .map(|_| [0u16; 4].map(|_| rng.next() as u16))
            .collect(),
    }
}

fn rgba(p: &Pixmap, x: u32, y: u32) -> [u8; 4] {
    let c = p.pixel(x, y).expect("inside");
    [c.red(), c.green(), c.blue(), c.alpha()]
}

fn opaque(rgb: [u8; 3]) -> [u8; 4] {
    [rgb[0], rgb[1], rgb[2], 255]
}

#[test]
fn png16_round_trip_exact() {
    let mut rng = Rng(11);
    for (w, h) in [(1, 1), (7, 3), (33, 17)] {
        let img = random_image(&mut rng, w, h);
        let png = encode_png16(&img).expect("encode");
        let back = image::load_from_memory(&png).expect("decode");
        assert_eq!(back.color(), image::ColorType::Rgba16);
        let back = back.to_rgba16();
        assert_eq!((back.width(), back.height()), (w, h));
        let got: Vec<[u16; 4]> = back.pixels().map(|p| p.0).collect();
        assert_eq!(got, img.px);
    }
}

#[test]
fn png8_round_trip_equals_to_rgba8() {
    let mut rng = Rng(12);
    for (w, h) in [(1, 1), (5, 9), (40, 3)] {
        let mut img = random_image(&mut rng, w, h);
        img.px[0][3] = 0; // transparent pixel keeps its colour (straight alpha)
        let png = encode_png8(&img).expect("encode");
        let back = image::load_from_memory(&png).expect("decode");
        assert_eq!(back.color(), image::ColorType::Rgba8);
        let back = back.to_rgba8();
        assert_eq!(back.as_raw(), &img.to_rgba8());
        // independent rounding model
        let p = img.px[0];
        let expect = p.map(|c| ((f64::from(c) * 255.0 / 65535.0) + 0.5).floor() as u8);
        assert_eq!(back.get_pixel(0, 0).0, expect);
    }
}

#[test]
fn png_rejects_bad_images() {
    let broken = Image {
        width: 3,
        height: 3,
        px: vec![[0; 4]; 8],
    };
    let e = encode_png8(&broken).expect_err("inconsistent");
    assert!(e.message().contains("3x3"), "{e}");
    assert!(encode_png16(&broken).is_err());
    assert!(encode_png8(&Image::new(0, 4, [0; 4])).is_err());
}

#[test]
fn pixmap_conversion_and_encoding() {
    let mut img = Image::new(4, 2, [65535, 32768, 0, 65535]);
    img.px[1] = [65535, 65535, 65535, 0]; // transparent
    img.px[2] = [65535, 0, 0, 32768]; // half alpha red
    let p = image_to_pixmap(&img);
    assert_eq!((p.width(), p.height()), (4, 2));
    assert_eq!(rgba(&p, 0, 0), [255, 128, 0, 255]);
    assert_eq!(rgba(&p, 1, 0), [0, 0, 0, 0]);
    // premultiplied: alpha 128, red 255 * 128 / 255 = 128
    assert_eq!(rgba(&p, 2, 0), [128, 0, 0, 128]);
    let opaque_img = Image::new(3, 3, [1000, 20000, 65535, 65535]);
    let png = encode_pixmap(&image_to_pixmap(&opaque_img)).expect("encode");
    let back = image::load_from_memory(&png).expect("decode").to_rgba8();
    assert_eq!(back.as_raw(), &opaque_img.to_rgba8());
    // degenerate sizes do not panic
    let z = image_to_pixmap(&Image::new(0, 0, [0; 4]));
    assert_eq!((z.width(), z.height()), (1, 1));
}

/// a: 32x24 gradient; b: equal except a block with growing red error (8-bit LSBs 1..=24).
fn heat_pair() -> (Image, Image) {
    let (w, h) = (32u32, 24u32);
    let mut a = Image::new(w, h, [0; 4]);
    for y in 0..h {
        for x in 0..w {
            a.px[(y * w + x) as usize] = [(x * 257 * 4) as u16, (y * 257 * 8) as u16, 9000, 0];
        }
    }
    let mut b = a.clone();
    for x in 0..24u32 {
        let i = (10 * w + x) as usize;
        b.px[i][0] = (u32::from(a.px[i][0]) + 257 * (x + 1)) as u16;
    }
    (a, b)
}

#[test]
fn heatmap_colours_exact_black_and_legend() {
    let (a, b) = heat_pair();
    let p = heatmap(&a, &b, 8, None);
    let lay = heatmap_layout(a.width, a.height, 8, 24);
    assert_eq!((p.width(), p.height()), (lay.width, lay.height));
    assert!(p.width() > a.width + 20 && p.height() >= a.height);
    for y in 0..a.height {
        for x in 0..a.width {
            let err = if y == 10 && x < 24 { x + 1 } else { 0 };
            let c = rgba(&p, x, y);
            assert_eq!(c, opaque(heatmap_colour(err, 24)), "({x},{y})");
            if err == 0 {
                assert_eq!(c, [0, 0, 0, 255]);
            }
        }
    }
    // the ramp: 1 LSB is dark, the max is bright, and the two differ from black and grey
    let lo = heatmap_colour(1, 24);
    let hi = heatmap_colour(24, 24);
    assert!(lo != [0, 0, 0] && lo != MASKED_RGB);
    let lum = |c: [u8; 3]| u32::from(c[0]) * 3 + u32::from(c[1]) * 6 + u32::from(c[2]);
    assert!(lum(hi) > lum(lo) + 500, "{lo:?} {hi:?}");
    // legend: in the right margin there are label pixels (near white) and ramp pixels
    let mut text = 0;
    let mut top_colour = false;
    for y in 0..p.height() {
        for x in a.width..p.width() {
            let c = rgba(&p, x, y);
            if c[0] > 200 && c[1] > 200 && c[2] > 200 {
                text += 1;
            }
            if c == opaque(hi) {
                top_colour = true;
            }
        }
    }
    assert!(text > 60, "label pixels: {text}");
    assert!(top_colour);
    // bar rows: the top is the max colour, the bottom is the 1 LSB colour, the zero box black
    let bx = lay.bar_x + lay.bar_w / 2;
    assert_eq!(rgba(&p, bx, lay.grad_top), opaque(hi));
    assert_eq!(rgba(&p, bx, lay.grad_bottom - 1), opaque(lo));
    assert_eq!(
        rgba(&p, bx, (lay.zero_top + lay.zero_bottom) / 2),
        [0, 0, 0, 255]
    );
    // a label sits right of the bar at the top (the max, "24")
    let labelled = (lay.grad_top.saturating_sub(4)..lay.grad_top + 4)
        .any(|y| (lay.label_x..p.width()).any(|x| rgba(&p, x, y)[0] > 200));
    assert!(labelled);
}

#[test]
fn heatmap_units_and_mask() {
    let (a, b) = heat_pair();
    // at 16 bits the errors are 257x larger: the max becomes 24 * 257
    let p16 = heatmap(&a, &b, 16, None);
    let m = 24 * 257;
    assert_eq!(rgba(&p16, 0, 10), opaque(heatmap_colour(257, m)));
    assert_eq!(rgba(&p16, 23, 10), opaque(heatmap_colour(m, m)));
    assert_eq!((p16.width(), p16.height()), {
        let l = heatmap_layout(a.width, a.height, 16, m);
        (l.width, l.height)
    });
    // mask out column 23 (the largest error): grey there, and the max drops to 23
    let mask: Vec<bool> = (0..a.width * a.height).map(|i| i % a.width != 23).collect();
    let p = heatmap(&a, &b, 8, Some(&mask));
    assert_eq!(rgba(&p, 23, 10), opaque(MASKED_RGB));
    assert_eq!(rgba(&p, 23, 0), opaque(MASKED_RGB));
    assert_eq!(rgba(&p, 22, 10), opaque(heatmap_colour(23, 23)));
    assert_eq!(rgba(&p, 0, 10), opaque(heatmap_colour(1, 23)));
    // identical images: all black, still a legend; tiny images get a legend-sized canvas
    let q = heatmap(&a, &a, 8, None);
    assert!((0..a.height).all(|y| (0..a.width).all(|x| rgba(&q, x, y) == [0, 0, 0, 255])));
    let tiny = Image::new(2, 1, [0; 4]);
    let t = heatmap(&tiny, &tiny, 8, None);
    assert!(t.height() >= 90 && t.width() > 2);
    assert_eq!(rgba(&t, 1, 0), [0, 0, 0, 255]);
    // b smaller than a: the part of a outside b is shown as masked
    let small = Image::new(1, 1, [0; 4]);
    let s = heatmap(&tiny, &small, 8, None);
    assert_eq!(rgba(&s, 1, 0), opaque(MASKED_RGB));
}

#[test]
fn heatmap_large_scales_legend() {
    let a = Image::new(700, 700, [30000, 30000, 30000, 65535]);
    let mut b = a.clone();
    b.px[0][1] = 65535;
    let p = heatmap(&a, &b, 16, None);
    let lay = heatmap_layout(700, 700, 16, 35535);
    assert_eq!(lay.scale, 2);
    assert_eq!((p.width(), p.height()), (lay.width, 700));
    // "35535" at scale 2 fits: 5 glyphs * 12 px - 2 = 58 px right of label_x
    assert!(lay.width >= lay.label_x + 58);
}

#[test]
fn sheet_sizes_and_filtering() {
    assert_eq!(sheet_panel_size(512, 100), (512, 100));
    assert_eq!(sheet_panel_size(1024, 768), (512, 384));
    assert_eq!(sheet_panel_size(513, 1), (512, 1));
    assert_eq!(sheet_panel_size(1000, 3), (512, 2)); // 1.536 rounds to 2
                                                     // 1024 x 2 opaque columns alternating black / white, and a transparent 300 x 200 panel
    let mut stripes = Image::new(1024, 2, [0, 0, 0, 65535]);
    for (i, p) in stripes.px.iter_mut().enumerate() {
        if i % 2 == 1 {
            *p = [65535; 4];
        }
    }
    let sp = image_to_pixmap(&stripes);
    let clear = image_to_pixmap(&Image::new(300, 200, [0; 4]));
    let big = image_to_pixmap(&Image::new(1024, 768, [0, 65535, 0, 65535]));
    let s = sheet(&[("hardware", &big), ("reference", &sp), ("error", &clear)]);
    let pad = SHEET_PAD;
    let expect_w = pad + (512 + pad) + (512 + pad) + (300 + pad);
    let expect_h = pad + SHEET_TITLE_H + 384 + pad;
    assert_eq!((s.width(), s.height()), (expect_w, expect_h));
    let y0 = pad + SHEET_TITLE_H;
    // big: green survives the filter exactly
    assert_eq!(rgba(&s, pad + 100, y0 + 100), [0, 255, 0, 255]);
    // stripes: each output pixel averages one black and one white column: 127.5 -> 128
    let x1 = pad + 512 + pad;
    assert_eq!(rgba(&s, x1, y0), [128, 128, 128, 255]);
    assert_eq!(rgba(&s, x1 + 511, y0), [128, 128, 128, 255]);
    // transparent panel: opaque dark checker, two different greys
    let x2 = x1 + 512 + pad;
    let c0 = rgba(&s, x2, y0);
    let c1 = rgba(&s, x2 + 8, y0);
    assert!(c0[3] == 255 && c1[3] == 255 && c0 != c1);
    assert!(c0[0] < 100 && c1[0] < 100 && c0[0] == c0[1]);
    // every sheet pixel is opaque
    assert!(s.pixels().iter().all(|c| c.alpha() == 255));
    // title bars carry bright text pixels
    for x_start in [pad, x1, x2] {
        let bright = (pad..pad + SHEET_TITLE_H)
            .flat_map(|y| (x_start..x_start + 120).map(move |x| (x, y)))
            .filter(|&(x, y)| rgba(&s, x, y)[0] > 200)
            .count();
        assert!(bright > 40, "title at {x_start}: {bright}");
    }
    // empty list: just the frame
    let e = sheet(&[]);
    assert_eq!((e.width(), e.height()), (pad, 2 * pad + SHEET_TITLE_H));
}

#[test]
fn font_covers_labels_and_glyphs_are_distinct() {
    use texsim::report::font::{glyph, has_glyph, text_width};
    let needed = "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZ -.:/%+()_=<>#|?,";
    let mut seen: Vec<[u8; 7]> = Vec::new();
    for c in needed.chars() {
        assert!(has_glyph(c), "{c:?}");
        let g = glyph(c);
        assert!(g.iter().all(|r| *r < 32), "{c:?} wider than 5");
        assert!(!seen.contains(&g), "{c:?} duplicates another glyph");
        seen.push(g);
    }
    assert_eq!(glyph('a'), glyph('A'));
    assert_eq!(glyph('\u{e9}'), glyph('?'));
    assert!(!has_glyph('\u{e9}'));
    assert_eq!(text_width("", 2), 0);
    assert_eq!(text_width("8", 1), 5);
    assert_eq!(text_width("16-BIT", 2), (6 * 6 - 1) * 2);
}

/// The heatmap's image area against a per-pixel model (`Image::get`, `metrics::quantize`,
/// `heatmap_colour`): random sizes of both images, every width, random masks (some short),
/// pixel vectors shorter or longer than their size, 300 seeded cases.
#[test]
fn heatmap_random_against_model() {
    use texsim::report::quantize;
    let mut rng = Rng(0x4EA7_0001);
    for case in 0..300 {
        let bits = 1 + rng.below(16) as u32;
        let size = |rng: &mut Rng| (rng.below(20) as u32, rng.below(20) as u32);
        let ((aw, ah), (bw, bh)) = (size(&mut rng), size(&mut rng));
        let mut a = random_image(&mut rng, aw, ah);
        let mut b = random_image(&mut rng, bw, bh);
        // Near pairs too, so small errors and exact pixels occur.
        if rng.below(2) == 0 {
            for (pb, pa) in b.px.iter_mut().zip(&a.px) {
                *pb = pa.map(|c| c.saturating_add(rng.below(600) as u16));
            }
        }
        for img in [&mut a, &mut b] {
            match rng.below(4) {
                0 => img.px.truncate(rng.below(img.px.len() as u64 + 1) as usize),
                1 => img.px.extend((0..rng.below(30)).map(|_| [7u16; 4])),
                _ => {}
            }
        }
        let mask: Option<Vec<bool>> = (rng.below(3) != 0).then(|| {
            (0..rng.below(u64::from(aw * ah) + 10))
                .map(|_| rng.below(3) != 0)
                .collect()
        });
        let err = |x: u32, y: u32| -> Option<u32> {
            let i = (y * aw + x) as usize;
            if let Some(m) = &mask {
                if !m.get(i).copied().unwrap_or(false) {
                    return None;
                }
            }
            let (pa, pb) = (a.get(x, y)?, b.get(x, y)?);
            (0..3)
                .map(|c| quantize(pa[c], bits).abs_diff(quantize(pb[c], bits)))
                .max()
        };
        let max = (0..ah)
            .flat_map(|y| (0..aw).map(move |x| (x, y)))
            .filter_map(|(x, y)| err(x, y))
            .max()
            .unwrap_or(0);
        let p = heatmap(&a, &b, bits, mask.as_deref());
        let lay = heatmap_layout(aw, ah, bits, max);
        assert_eq!(
            (p.width(), p.height()),
            (lay.width, lay.height),
            "case {case}"
        );
        for y in 0..ah {
            for x in 0..aw {
                let want = err(x, y).map_or(MASKED_RGB, |e| heatmap_colour(e, max));
                assert_eq!(rgba(&p, x, y), opaque(want), "case {case} ({x},{y})");
            }
        }
    }
}
