//! Host-side MIP map preparation (Williams 1983, "Pyramidal Parametrics"): a float box-filtered
//! pyramid and its quantization to the hardware's unsigned-normalized texel width.
//!
//! Down-filter convention (also for non-power-of-two sizes): along each axis a level of size
//! `n > 1` is followed by one of size `max(1, floor(n / 2))`. Child texel `i` averages parents
//! `2i` and `2i + 1`; when `n` is odd the last child also takes parent `n - 1`, so it averages
//! three parents. When `n == 1` the axis is copied. Every parent feeds exactly one child with
//! equal weight inside that child (a plain box), so the mean over a level is preserved exactly
//! in exact arithmetic. Levels are computed in f32 from the previous float level.
//!
//! Quantization: `q = round_half_even(x * (2^bits - 1))`, clamped to `[0, 2^bits - 1]`, NaN -> 0.
//! For texels that came from exact 16-bit data (`x = v / 65535`) and `bits == 16` this gives `v`
//! back exactly.

pub mod cube;
mod prepared;
pub use prepared::{bump_sources, ndf_sources, BumpSource, Maps};

/// Stored channels of a bump offset map (`f_u`, `f_v`).
pub const OFFSET_CHANNELS: u32 = 2;

use crate::scene::TextureImage;
use rayon::prelude::*;

/// One float MIP level, RGBA in 0..1, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct MipLevel {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<[f32; 4]>,
}

/// A full float pyramid: level 0 is full resolution, the last level is 1x1.
#[derive(Clone, Debug, PartialEq)]
pub struct MipChain {
    pub levels: Vec<MipLevel>,
}

/// One quantized level: each channel is an unsigned `texel_bits`-bit integer.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FixedLevel {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<[u16; 4]>,
}

/// How a map is stored in texture memory: its channels and bits per channel. The trilinear
/// unit always filters four channels of `texel_bits`; a map stores only the channels it uses
/// (colour RGBA 4, bump offsets 2, roughness D 3 or 1, NDF moments 3, normalization 1), at its
/// own width, so narrower maps move fewer bytes through the cache and DRAM model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct TexelFormat {
    pub channels: u32,
    pub bits: u32,
}

impl TexelFormat {
    /// Bytes one stored texel occupies ([`hw_model::timing_config::stored_texel_bytes`]).
    #[must_use]
    pub fn bytes(self) -> u32 {
        hw_model::timing_config::stored_texel_bytes(self.channels, self.bits)
    }
}

/// A quantized pyramid as the hardware's texture memory holds it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FixedMipChain {
    /// Width of the channels the trilinear unit reads.
    pub texel_bits: u32,
    /// The stored format (channels and their width; RGBA at `texel_bits` unless the map's
    /// builder says otherwise with [`FixedMipChain::stored_as`]).
    pub format: TexelFormat,
    pub levels: Vec<FixedLevel>,
}

impl MipChain {
    /// The levels as the float trilinear twin reads them.
    #[must_use]
    pub fn views(&self) -> Vec<crate::reference::LevelF<'_>> {
        self.levels
            .iter()
            .map(|l| crate::reference::LevelF {
                width: l.width,
                height: l.height,
                texels: &l.texels,
            })
            .collect()
    }
}

impl FixedMipChain {
    /// The same chain stored as `channels` channels of `bits` bits.
    #[must_use]
    pub fn stored_as(mut self, channels: u32, bits: u32) -> Self {
        self.format = TexelFormat { channels, bits };
        self
    }

    /// The levels as the fixed trilinear unit reads them.
    #[must_use]
    pub fn views(&self) -> Vec<hw_model::trilinear::Level<'_>> {
        self.levels
            .iter()
            .map(|l| hw_model::trilinear::Level {
                width: l.width,
                height: l.height,
                texels: &l.texels,
            })
            .collect()
    }
}

/// Size of the level after one of size `n` (see the module doc).
#[must_use]
pub fn next_level_size(n: u32) -> u32 {
    (n / 2).max(1)
}

/// Sizes of every level of a `width` x `height` texture, level 0 first, ending at 1x1.
#[must_use]
pub fn chain_sizes(width: u32, height: u32) -> Vec<(u32, u32)> {
    let (mut w, mut h) = (width.max(1), height.max(1));
    let mut out = vec![(w, h)];
    while w > 1 || h > 1 {
        w = next_level_size(w);
        h = next_level_size(h);
        out.push((w, h));
    }
    out
}

/// Parent range `[start, start + count)` of child `i` along an axis of parent size `n`.
fn parents(i: u32, n: u32, child_n: u32) -> (u32, u32) {
    if n == 1 {
        return (0, 1);
    }
    let start = 2 * i;
    let count = if i + 1 == child_n && n % 2 == 1 { 3 } else { 2 };
    (start, count)
}

/// Box-filters `src` down one level (module doc convention).
#[must_use]
pub fn downsample(src: &MipLevel) -> MipLevel {
    let (w, h) = (src.width, src.height);
    let (nw, nh) = (next_level_size(w), next_level_size(h));
    let mut texels = Vec::with_capacity(nw as usize * nh as usize);
    for y in 0..nh {
        let (y0, cy) = parents(y, h, nh);
        for x in 0..nw {
            let (x0, cx) = parents(x, w, nw);
            let mut acc = [0.0f32; 4];
            for py in y0..y0 + cy {
                let row = py as usize * w as usize;
                for px in x0..x0 + cx {
                    let t = src.texels[row + px as usize];
                    for k in 0..4 {
                        acc[k] += t[k];
                    }
                }
            }
            let inv = 1.0 / (cx * cy) as f32;
            texels.push(acc.map(|a| a * inv));
        }
    }
    MipLevel {
        width: nw,
        height: nh,
        texels,
    }
}

/// A 16-bit unorm channel as a float level holds it: `v / 65535`.
fn unorm16(v: u16) -> f32 {
    f32::from(v) / 65535.0
}

fn level_from_u16(width: u32, height: u32, texels: &[[u16; 4]]) -> MipLevel {
    MipLevel {
        width,
        height,
        texels: texels.iter().map(|t| t.map(unorm16)).collect(),
    }
}

/// Builds the float pyramid of `tex`. Level 0 is `texels / 65535`. Prebuilt levels
/// (`tex.prebuilt_levels`) are used exactly (`/ 65535`) as long as each has the size the
/// convention expects and the right texel count; from the first one that does not (or when
/// they run out) the remaining levels are box-filtered.
#[must_use]
pub fn build_mip_chain(tex: &TextureImage) -> MipChain {
    build_levels(tex).0
}

/// [`build_mip_chain`] and, per level, the 16-bit texels it was made from (`None` for the
/// box-filtered levels).
fn build_levels(tex: &TextureImage) -> (MipChain, Vec<Option<&[[u16; 4]]>>) {
    let sizes = chain_sizes(tex.width, tex.height);
    let mut levels = Vec::with_capacity(sizes.len());
    let mut sources = Vec::with_capacity(sizes.len());
    let expected0 = tex.width as usize * tex.height as usize;
    if tex.width == 0 || tex.height == 0 || tex.texels.len() != expected0 {
        // Not a valid image (`scene::validate` rejects these); give a defined 1x1 black chain.
        levels.push(MipLevel {
            width: 1,
            height: 1,
            texels: vec![[0.0; 4]],
        });
        return (MipChain { levels }, vec![None]);
    }
    levels.push(level_from_u16(tex.width, tex.height, &tex.texels));
    sources.push(Some(&tex.texels[..]));
    let prebuilt = tex.prebuilt_levels.as_deref().unwrap_or(&[]);
    let mut use_prebuilt = true;
    for (li, &(w, h)) in sizes.iter().enumerate().skip(1) {
        let pre = prebuilt
            .get(li - 1)
            .filter(|(pw, ph, t)| *pw == w && *ph == h && t.len() == w as usize * h as usize);
        let (level, source) = match pre {
            Some((pw, ph, t)) if use_prebuilt => (level_from_u16(*pw, *ph, t), Some(&t[..])),
            _ => {
                use_prebuilt = false;
                (downsample(&levels[li - 1]), None)
            }
        };
        levels.push(level);
        sources.push(source);
    }
    (MipChain { levels }, sources)
}

/// `quantize_unorm(unorm16(v), bits)` for every 16-bit `v`, `bits` in 1..=16 (built once):
/// the float path's value for a level made from 16-bit texels, by construction.
fn u16_table(bits: u32) -> &'static [u16; 65536] {
    static TABLES: [std::sync::OnceLock<Box<[u16; 65536]>>; 16] =
        [const { std::sync::OnceLock::new() }; 16];
    TABLES[bits as usize - 1].get_or_init(|| {
        let mut t = Box::new([0u16; 65536]);
        for (v, q) in (0..=u16::MAX).zip(t.iter_mut()) {
            *q = quantize_unorm(unorm16(v), bits);
        }
        t
    })
}

/// Quantizes 16-bit texels `v` as their float level `v / 65535` quantizes to `bits` (1..=16):
/// a copy at 16 bits, else a table of [`quantize_unorm`].
#[must_use]
pub fn quantize_u16_texels(texels: &[[u16; 4]], bits: u32) -> Vec<[u16; 4]> {
    let bits = bits.clamp(1, 16);
    if bits == 16 {
        return texels.to_vec();
    }
    let t = u16_table(bits);
    texels
        .par_iter()
        .map(|p| p.map(|c| t[usize::from(c)]))
        .collect()
}

/// `(build_mip_chain(tex), quantize_chain(&build_mip_chain(tex), texel_bits))` in one pass:
/// the levels made from 16-bit texels quantize from those ([`quantize_u16_texels`]).
#[must_use]
pub fn build_chains(tex: &TextureImage, texel_bits: u32) -> (MipChain, FixedMipChain) {
    let bits = texel_bits.clamp(1, 16);
    let (chain, sources) = build_levels(tex);
    let levels = chain
        .levels
        .iter()
        .zip(&sources)
        .map(|(l, src)| FixedLevel {
            width: l.width,
            height: l.height,
            texels: match src {
                Some(t) => quantize_u16_texels(t, bits),
                None => quantize_texels(&l.texels, bits),
            },
        })
        .collect();
    let fixed = FixedMipChain {
        texel_bits: bits,
        format: TexelFormat { channels: 4, bits },
        levels,
    };
    (chain, fixed)
}

/// Quantizes one value in 0..1 to `bits` bits (module doc rule).
#[inline]
#[must_use]
pub fn quantize_unorm(x: f32, bits: u32) -> u16 {
    let bits = bits.clamp(1, 16);
    let max = f64::from((1u32 << bits) - 1);
    if x.is_nan() {
        return 0;
    }
    // Clamping before rounding is the same as after: both ends are integers.
    crate::fixedpoint::round_ties_even_small((f64::from(x) * max).clamp(0.0, max)) as u16
}

/// Quantizes every level of `chain` to unsigned-normalized `texel_bits` (clamped to 1..=16),
/// stored as RGBA of that width.
#[must_use]
pub fn quantize_chain(chain: &MipChain, texel_bits: u32) -> FixedMipChain {
    let bits = texel_bits.clamp(1, 16);
    FixedMipChain {
        texel_bits: bits,
        format: TexelFormat { channels: 4, bits },
        levels: chain
            .levels
            .iter()
            .map(|l| FixedLevel {
                width: l.width,
                height: l.height,
                texels: quantize_texels(&l.texels, bits),
            })
            .collect(),
    }
}

/// [`quantize_unorm`] on every channel of float texels (`bits` already clamped).
fn quantize_texels(texels: &[[f32; 4]], bits: u32) -> Vec<[u16; 4]> {
    texels
        .par_iter()
        .map(|t| t.map(|c| quantize_unorm(c, bits)))
        .collect()
}
