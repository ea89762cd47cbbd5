//! MIP chain preparation: sizes (POT/NPOT), box-filter values against an independent f64 model,
//! quantization (lossless for exact 16-bit data, round-half-even), and the Mesa W1/W2 texture
//! hashes (FNV-1a-64 of the 8-bit bytes, as `mesa_anchor.c` prints them).

use crate::rng_common::Rng;
use texsim::maps::{
    build_chains, build_mip_chain, chain_sizes, quantize_chain, quantize_u16_texels, quantize_unorm,
};
use texsim::scene::texture::{
    downsample_rgba8, mesa_levels_rgba8, mesa_texture, noise_checker_rgba8, MESA_DARK, MESA_LIGHT,
};
use texsim::scene::{builtin, TextureImage};

fn random_texture(rng: &mut Rng, w: u32, h: u32) -> TextureImage {
    let texels = (0..w * h)
        .map(|_| std::array::from_fn(|_| rng.below(65536) as u16))
        .collect();
    TextureImage {
        name: "rand".into(),
        width: w,
        height: h,
        texels,
        prebuilt_levels: None,
    }
}

#[test]
fn chain_sizes_pot_and_npot() {
    assert_eq!(chain_sizes(8, 2), vec![(8, 2), (4, 1), (2, 1), (1, 1)]);
    assert_eq!(chain_sizes(1024, 1024).len(), 11);
    assert_eq!(chain_sizes(5, 3), vec![(5, 3), (2, 1), (1, 1)]);
    assert_eq!(chain_sizes(7, 1), vec![(7, 1), (3, 1), (1, 1)]);
    assert_eq!(chain_sizes(1, 1), vec![(1, 1)]);
    let mut rng = Rng(7);
    for _ in 0..2000 {
        let (w, h) = (1 + rng.below(5000) as u32, 1 + rng.below(5000) as u32);
        let s = chain_sizes(w, h);
        assert_eq!(s[0], (w, h));
        assert_eq!(*s.last().unwrap(), (1, 1));
        // Length = 1 + floor(log2(max side)).
        assert_eq!(s.len() as u32, 32 - w.max(h).leading_zeros());
        for p in s.windows(2) {
            assert_eq!(p[1].0, (p[0].0 / 2).max(1));
            assert_eq!(p[1].1, (p[0].1 / 2).max(1));
        }
    }
    let tex = random_texture(&mut rng, 13, 6);
    let chain = build_mip_chain(&tex);
    let got: Vec<(u32, u32)> = chain.levels.iter().map(|l| (l.width, l.height)).collect();
    assert_eq!(got, chain_sizes(13, 6));
    for l in &chain.levels {
        assert_eq!(l.texels.len(), (l.width * l.height) as usize);
    }
}

/// Independent model: child texel = mean over its parents, where parents along an axis are
/// {2i, 2i+1} plus 2i+2 for the last child of an odd-sized axis; size-1 axes copy.
fn model_next(src: &[Vec<f64>], w: usize, h: usize, ch: usize) -> (Vec<Vec<f64>>, usize, usize) {
    let nw = (w / 2).max(1);
    let nh = (h / 2).max(1);
    let range = |i: usize, n: usize, cn: usize| -> Vec<usize> {
        if n == 1 {
            vec![0]
        } else if i == cn - 1 && n % 2 == 1 {
            vec![2 * i, 2 * i + 1, 2 * i + 2]
        } else {
            vec![2 * i, 2 * i + 1]
        }
    };
    let mut out = vec![vec![0.0; nw * nh]; ch];
    for c in 0..ch {
        for y in 0..nh {
            for x in 0..nw {
                let (ys, xs) = (range(y, h, nh), range(x, w, nw));
                let mut s = 0.0;
                for &py in &ys {
                    for &px in &xs {
                        s += src[c][py * w + px];
                    }
                }
                out[c][y * nw + x] = s / (ys.len() * xs.len()) as f64;
            }
        }
    }
    (out, nw, nh)
}

#[test]
fn box_filter_matches_independent_model() {
    let mut rng = Rng(42);
    for case in 0..60 {
        let (w, h) = if case < 4 {
            ([1, 2, 3, 4][case], [4, 3, 2, 1][case])
        } else {
            (1 + rng.below(40) as u32, 1 + rng.below(40) as u32)
        };
        let tex = random_texture(&mut rng, w, h);
        let chain = build_mip_chain(&tex);
        let mut cur: Vec<Vec<f64>> = (0..4)
            .map(|c| {
                tex.texels
                    .iter()
                    .map(|t| f64::from(t[c]) / 65535.0)
                    .collect()
            })
            .collect();
        let (mut cw, mut chh) = (w as usize, h as usize);
        for (li, level) in chain.levels.iter().enumerate() {
            if li > 0 {
                let (n, nw, nh) = model_next(&cur, cw, chh, 4);
                cur = n;
                cw = nw;
                chh = nh;
            }
            assert_eq!((level.width as usize, level.height as usize), (cw, chh));
            for (i, t) in level.texels.iter().enumerate() {
                for c in 0..4 {
                    let err = (f64::from(t[c]) - cur[c][i]).abs();
                    // f32 accumulation over <= 11 levels: a few ulps of 1.0 per level.
                    assert!(
                        err < 1e-6,
                        "case {case} level {li} texel {i}: {} vs {}",
                        t[c],
                        cur[c][i]
                    );
                }
            }
        }
    }
}

#[test]
fn box_filter_known_values() {
    // 3x1 row [0, 3, 6]/65535-scaled: NPOT -> one texel = mean of all three.
    let v = |x: u16| [x, x, x, 65535];
    let tex = TextureImage {
        name: "t".into(),
        width: 3,
        height: 1,
        texels: vec![v(0), v(30000), v(60000)],
        prebuilt_levels: None,
    };
    let chain = build_mip_chain(&tex);
    assert_eq!(chain.levels.len(), 2);
    let got = chain.levels[1].texels[0];
    assert!((f64::from(got[0]) - 30000.0 / 65535.0).abs() < 1e-7);
    assert_eq!(got[3], 1.0);
    // 2x2 -> exact mean.
    let tex = TextureImage {
        name: "t".into(),
        width: 2,
        height: 2,
        texels: vec![v(0), v(65535), v(65535), v(65535)],
        prebuilt_levels: None,
    };
    let chain = build_mip_chain(&tex);
    assert!((chain.levels[1].texels[0][0] - 0.75).abs() < 1e-7);
}

#[test]
fn quantize_lossless_for_exact_16_bit_data() {
    let all: Vec<[u16; 4]> = (0..=65535u32)
        .map(|x| [x as u16, (65535 - x) as u16, (x * 7 % 65536) as u16, 65535])
        .collect();
    let tex = TextureImage {
        name: "all".into(),
        width: 256,
        height: 256,
        texels: all.clone(),
        prebuilt_levels: None,
    };
    let q = quantize_chain(&build_mip_chain(&tex), 16);
    assert_eq!(q.texel_bits, 16);
    assert_eq!(q.levels[0].texels, all);
}

#[test]
fn quantize_rounds_half_even_to_n_bits() {
    let mut rng = Rng(99);
    for bits in 1..=16u32 {
        let max = (1u64 << bits) - 1;
        for _ in 0..20000 {
            let x = (rng.next() >> 40) as f32 / (1u64 << 24) as f32 * 1.2 - 0.1;
            let q = u64::from(quantize_unorm(x, bits));
            // Independent: nearest integer to x*max in exact rational terms, ties to even.
            let t = f64::from(x) * max as f64;
            let lo = t.floor();
            let frac = t - lo;
            let round_up = frac > 0.5 || (frac == 0.5 && lo as i64 % 2 == 1);
            let mut r = if round_up { lo + 1.0 } else { lo };
            r = r.clamp(0.0, max as f64);
            assert_eq!(q, r as u64, "x {x} bits {bits}");
        }
        // 0.5 * (2^b - 1) = 2^(b-1) - 0.5 is an exact tie; the even neighbour is 2^(b-1)
        // (0 when b = 1).
        let even = if bits == 1 { 0 } else { 1u64 << (bits - 1) };
        assert_eq!(u64::from(quantize_unorm(0.5, bits)), even);
        assert_eq!(quantize_unorm(f32::NAN, bits), 0);
        assert_eq!(u64::from(quantize_unorm(2.0, bits)), max);
    }
}

fn fnv1a64(mut h: u64, bytes: impl Iterator<Item = u8>) -> u64 {
    for b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x100_0000_01b3);
    }
    h
}
const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

#[test]
fn mesa_texture_hashes_match_the_anchor() {
    let levels = mesa_levels_rgba8(1024);
    assert_eq!(levels.len(), 11);
    let l0 = fnv1a64(FNV_OFFSET, levels[0].2.iter().flatten().copied());
    assert_eq!(format!("{l0:016x}"), "866f6b8675eaa619");
    let all = fnv1a64(
        FNV_OFFSET,
        levels
            .iter()
            .flat_map(|(_, _, t)| t.iter().flatten().copied()),
    );
    assert_eq!(format!("{all:016x}"), "05230205964a4066");

    // The built-in scenes carry exactly these bytes (x257) and the 16-bit chain is lossless.
    for name in ["w1-plane", "w2-mesh"] {
        let s = builtin(name).unwrap();
        let tex = &s.textures[0];
        let q = quantize_chain(&build_mip_chain(tex), 16);
        assert_eq!(q.levels.len(), 11);
        let bytes = |t: &Vec<[u16; 4]>| -> Vec<u8> {
            t.iter()
                .flatten()
                .map(|&c| {
                    assert_eq!(c % 257, 0);
                    (c / 257) as u8
                })
                .collect()
        };
        let h0 = fnv1a64(FNV_OFFSET, bytes(&q.levels[0].texels).into_iter());
        assert_eq!(format!("{h0:016x}"), "866f6b8675eaa619", "{name}");
        let mut h = FNV_OFFSET;
        for l in &q.levels {
            h = fnv1a64(h, bytes(&l.texels).into_iter());
        }
        assert_eq!(format!("{h:016x}"), "05230205964a4066", "{name}");
    }
}

#[test]
fn prebuilt_levels_are_used_only_when_consistent() {
    let mut rng = Rng(5);
    let mut tex = random_texture(&mut rng, 4, 4);
    let l1 = vec![[1000u16, 2000, 3000, 4000]; 4];
    // Level 2 has a wrong size: from there on the chain is box-filtered.
    tex.prebuilt_levels = Some(vec![(2, 2, l1.clone()), (2, 1, vec![[0; 4]; 2])]);
    let q = quantize_chain(&build_mip_chain(&tex), 16);
    assert_eq!(q.levels[1].texels, l1);
    assert_eq!(q.levels[2].texels, vec![[1000, 2000, 3000, 4000]]);
}

#[test]
fn u16_quantization_matches_the_float_path_exhaustively() {
    let all: Vec<[u16; 4]> = (0..=65535u32)
        .map(|v| {
            [
                v as u16,
                (65535 - v) as u16,
                (v * 7 % 65536) as u16,
                v as u16,
            ]
        })
        .collect();
    for bits in 0..=17u32 {
        let q = quantize_u16_texels(&all, bits);
        for (p, t) in all.iter().zip(&q) {
            let f = p.map(|c| quantize_unorm(f32::from(c) / 65535.0, bits));
            assert_eq!(*t, f, "bits {bits} texel {p:?}");
        }
    }
}

fn assert_chains_match(tex: &TextureImage, what: &str) {
    let float = build_mip_chain(tex);
    for bits in 0..=17u32 {
        let (c, q) = build_chains(tex, bits);
        assert_eq!(c, float, "{what}");
        assert_eq!(q, quantize_chain(&float, bits), "{what} bits {bits}");
    }
}

#[test]
fn build_chains_matches_build_then_quantize() {
    let mut rng = Rng(31);
    for &(w, h) in &[
        (1, 1),
        (2, 2),
        (5, 3),
        (7, 1),
        (1, 6),
        (16, 16),
        (33, 17),
        (64, 9),
    ] {
        let tex = random_texture(&mut rng, w, h);
        assert_chains_match(&tex, &format!("random {w}x{h}"));
    }
    // Prebuilt levels: all consistent (Mesa), and a wrong size part way down.
    assert_chains_match(&mesa_texture(64), "mesa-64");
    let mut tex = random_texture(&mut rng, 8, 8);
    tex.prebuilt_levels = Some(vec![
        (4, 4, vec![[1000, 2000, 3000, 4000]; 16]),
        (2, 1, vec![[0; 4]; 2]),
    ]);
    assert_chains_match(&tex, "bad prebuilt");
    // Invalid image: the 1x1 black chain.
    tex.texels.pop();
    assert_chains_match(&tex, "invalid");
    // Random 8-bit data (x 257), the decoder's and generators' usual input, on many sizes.
    for _ in 0..40 {
        let (w, h) = (1 + rng.below(40) as u32, 1 + rng.below(40) as u32);
        let mut tex = random_texture(&mut rng, w, h);
        for p in &mut tex.texels {
            *p = p.map(|c| (c >> 8) * 257);
        }
        assert_chains_match(&tex, &format!("8-bit {w}x{h}"));
    }
}

/// `downsample_rgba8` as the anchor writes it, texel by texel.
fn downsample_model(src: &[[u8; 4]], w: u32, h: u32) -> (u32, u32, Vec<[u8; 4]>) {
    let nw = if w > 1 { w / 2 } else { 1 };
    let nh = if h > 1 { h / 2 } else { 1 };
    let at = |x: u32, y: u32| src[(y * w + x) as usize];
    let mut d = Vec::new();
    for y in 0..nh {
        for x in 0..nw {
            let (x0, x1) = (2 * x, if w > 1 { 2 * x + 1 } else { 2 * x });
            let (y0, y1) = (2 * y, if h > 1 { 2 * y + 1 } else { 2 * y });
            let t = [at(x0, y0), at(x1, y0), at(x0, y1), at(x1, y1)];
            d.push(std::array::from_fn(|k| {
                let s: u32 = t.iter().map(|p| u32::from(p[k])).sum();
                ((s + 2) >> 2) as u8
            }));
        }
    }
    (nw, nh, d)
}

#[test]
fn rgba8_generators_match_texel_models() {
    let mut rng = Rng(77);
    for _ in 0..200 {
        let (w, h) = (1 + rng.below(37) as u32, 1 + rng.below(37) as u32);
        let src: Vec<[u8; 4]> = (0..w * h)
            .map(|_| std::array::from_fn(|_| rng.below(256) as u8))
            .collect();
        assert_eq!(
            downsample_rgba8(&src, w, h),
            downsample_model(&src, w, h),
            "{w}x{h}"
        );
    }
    for size in [0u32, 1, 3, 8, 17, 100] {
        let t = noise_checker_rgba8(size, MESA_LIGHT, MESA_DARK);
        assert_eq!(t.len(), (size * size) as usize);
        for (i, p) in t.iter().enumerate() {
            let (x, y) = (i as u32 % size, i as u32 / size);
            let c = if ((x >> 3) ^ (y >> 3)) & 1 == 1 {
                MESA_LIGHT
            } else {
                MESA_DARK
            };
            let hh = texsim::scene::texture::hash2(x, y);
            let want: [u8; 4] = std::array::from_fn(|k| {
                if k == 3 {
                    255
                } else {
                    (c[k] + ((hh >> (8 * k)) & 63) as i32 - 32).clamp(0, 255) as u8
                }
            });
            assert_eq!(*p, want, "size {size} texel {i}");
        }
    }
}
