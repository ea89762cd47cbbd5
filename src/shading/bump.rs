//! Bump maps as precomputed offset vectors `(f_u, f_v)` (Schilling 1997, "Bump mapping with
//! Precalculated Derivatives"): from a height map by central differences with wrap, or from a
//! tangent-space normal map, stored as a two-channel unorm level-0 image that the ordinary
//! trilinear unit filters unchanged (filtering is linear, so it commutes with the affine
//! decode below).
//!
//! Offsets: `f_u = scale * (h[x+1, y] - h[x-1, y]) / 2`, `f_v = scale * (h[x, y+1] -
//! h[x, y-1]) / 2` (indices wrap), `h` in `[0, 1]`, derivative per level-0 texel. `f_v` follows
//! the row index (top row first) unless `v_up` is set, in which case it is negated (v grows
//! upwards, OpenGL convention). In the unit and main frames an offset of 1 tilts the normal by
//! 45 degrees; in the natural frame it is multiplied by the frame lengths.
//!
//! Encoding (scale/bias): channel `c = 1/2 + f / (2 R)`, clamped to `[0, 1]` (clamps are
//! counted), decode `f = (c - 1/2) * 2 R`, with `R = 2^offset_int_bits` to match the fixed
//! offset format (`hw_model::vector::offset_from_texel`; for texram16 R = 8 and the 16-bit
//! texel minus 2^15 is the s3.12 offset). Image channels: `(c_u, c_v, 0, 1)`.

use crate::error::{Error, Result};
use crate::scene::TextureImage;

/// Bump-map preparation parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BumpParams {
    /// Bump height scale: multiplies the height differences.
    pub scale: f32,
    /// Negate `f_v` (v grows upwards while rows go down).
    pub v_up: bool,
}

/// The offset encoding range `R` (offsets in `[-R, R)`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OffsetEncoding {
    pub range: f32,
}

impl OffsetEncoding {
    /// `R = 2^offset_int_bits`, matching `hw_model::vector::offset_format`.
    #[must_use]
    pub fn for_offset_int_bits(bits: u32) -> Self {
        Self {
            range: (bits.min(30) as f32).exp2(),
        }
    }

    /// Encodes one offset into a unorm channel; `true` if it was clamped.
    #[must_use]
    pub fn encode(&self, f: f32) -> (f32, bool) {
        let c = 0.5 + f / (2.0 * self.range);
        if c.is_nan() {
            return (0.5, true);
        }
        let cl = c.clamp(0.0, 1.0);
        (cl, cl != c)
    }

    /// Decodes a (filtered) unorm channel.
    #[must_use]
    pub fn decode(&self, c: f32) -> f32 {
        (c - 0.5) * 2.0 * self.range
    }
}

/// An encoded bump map, level 0.
#[derive(Clone, Debug, PartialEq)]
pub struct BumpImage {
    pub width: u32,
    pub height: u32,
    /// `(c_u, c_v, 0, 1)` per texel, top row first.
    pub texels: Vec<[f32; 4]>,
    /// Offsets clamped by the encoding.
    pub clamped: u64,
}

fn check_size(name: &str, w: u32, h: u32, len: usize) -> Result<()> {
    if w == 0 || h == 0 {
        return Err(Error::field(name, format!("empty image {w}x{h}")));
    }
    if (w as usize).checked_mul(h as usize) != Some(len) {
        return Err(Error::field(
            name,
            format!("{len} values for a {w}x{h} image"),
        ));
    }
    Ok(())
}

/// Per-texel offsets `(f_u, f_v)` of a height map (`w * h` values, top row first).
pub fn height_to_offsets(heights: &[f32], w: u32, h: u32, p: &BumpParams) -> Result<Vec<[f32; 2]>> {
    check_size("bump height map", w, h, heights.len())?;
    if !p.scale.is_finite() {
        return Err(Error::field(
            "bump_scale",
            format!("{} is not finite", p.scale),
        ));
    }
    if let Some(i) = heights.iter().position(|x| !x.is_finite()) {
        return Err(Error::field(
            "bump height map",
            format!("texel {i} is not finite"),
        ));
    }
    let (wu, hu) = (w as usize, h as usize);
    let at = |x: usize, y: usize| heights[y * wu + x];
    let sv = if p.v_up { -0.5 } else { 0.5 } * p.scale;
    let mut out = Vec::with_capacity(heights.len());
    for y in 0..hu {
        let (ym, yp) = ((y + hu - 1) % hu, (y + 1) % hu);
        for x in 0..wu {
            let (xm, xp) = ((x + wu - 1) % wu, (x + 1) % wu);
            let fu = 0.5 * p.scale * (at(xp, y) - at(xm, y));
            let fv = sv * (at(x, yp) - at(x, ym));
            out.push([fu, fv]);
        }
    }
    Ok(out)
}

/// Heights in `[0, 1]` from one channel (0..=3) of a texture image.
pub fn heights_from_texture(img: &TextureImage, channel: usize) -> Result<Vec<f32>> {
    if channel > 3 {
        return Err(Error::field(
            "bump channel",
            format!("{channel} is not in 0..=3"),
        ));
    }
    check_size(&img.name, img.width, img.height, img.texels.len())?;
    Ok(img
        .texels
        .iter()
        .map(|t| f32::from(t[channel]) / 65535.0)
        .collect())
}

/// Encodes offsets into the level-0 image `(c_u, c_v, 0, 1)`.
#[must_use]
pub fn offsets_to_image(offsets: &[[f32; 2]], w: u32, h: u32, enc: &OffsetEncoding) -> BumpImage {
    let mut clamped = 0u64;
    let texels = offsets
        .iter()
        .map(|o| {
            let (cu, a) = enc.encode(o[0]);
            let (cv, b) = enc.encode(o[1]);
            clamped += u64::from(a) + u64::from(b);
            [cu, cv, 0.0, 1.0]
        })
        .collect();
    BumpImage {
        width: w,
        height: h,
        texels,
        clamped,
    }
}

/// Height-map texture (channel 0) -> encoded bump image.
pub fn bump_image_from_height(
    img: &TextureImage,
    p: &BumpParams,
    enc: &OffsetEncoding,
) -> Result<BumpImage> {
    let hts = heights_from_texture(img, 0)?;
    let offs =
        height_to_offsets(&hts, img.width, img.height, p).map_err(|e| e.context(&img.name))?;
    Ok(offsets_to_image(&offs, img.width, img.height, enc))
}

/// Smallest tangent-space `n_z` accepted from a normal map; flatter normals are clamped to it
/// (|offset| <= 1/0.05 = 20 before the encoding clamp) and counted.
pub const NORMAL_MAP_MIN_Z: f32 = 0.05;

/// Tangent-space normal map (`rgb = n * 0.5 + 0.5`, x along `T = dP/du`, y along `B = dP/dv`
/// with `v` = the texture's `t`, which grows down the image) -> offsets. `flip_green`: the
/// map's green channel points along `-B`, i.e. towards the image's top row; that is the
/// OpenGL convention (green up), which the pipeline assumes for `bump_normal_map` (it passes
/// `true`); maps authored green-down (DirectX convention) have y along `B` and need `false`.
/// The offsets `f_u = -n_x / n_z`, `f_v = -n_y / n_z` (`n_y` after the flip) reproduce the
/// normal's direction in the unit and main frames (`t_u = -T`, `t_v = -B`). Returns the
/// offsets and the number of texels whose `n_z` was clamped.
pub fn normal_map_to_offsets(img: &TextureImage, flip_green: bool) -> Result<(Vec<[f32; 2]>, u64)> {
    check_size(&img.name, img.width, img.height, img.texels.len())?;
    let mut clamped = 0u64;
    let offs = img
        .texels
        .iter()
        .map(|t| {
            let c = |i: usize| f32::from(t[i]) / 65535.0 * 2.0 - 1.0;
            let (x, mut y, mut z) = (c(0), c(1), c(2));
            if flip_green {
                y = -y;
            }
            if z < NORMAL_MAP_MIN_Z {
                z = NORMAL_MAP_MIN_Z;
                clamped += 1;
            }
            [-x / z, -y / z]
        })
        .collect();
    Ok((offs, clamped))
}
