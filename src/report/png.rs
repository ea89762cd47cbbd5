//! PNG encoding: the [`Image`] itself as straight-alpha RGBA8 (via [`Image::to_rgba8`]) or RGBA16
//! (exact) with the `image` crate, and tiny-skia pixmaps (demultiplied by tiny-skia).

use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder};
use tiny_skia::Pixmap;

use super::{draw, quantize, Image};
use crate::{Error, Result};

fn check(img: &Image) -> Result<()> {
    if img.width == 0 || img.height == 0 {
        return Err(Error::msg(format!(
            "cannot encode an empty {}x{} image as PNG",
            img.width, img.height
        )));
    }
    if !img.is_consistent() {
        return Err(Error::msg(format!(
            "image {}x{} holds {} pixels, expected {}",
            img.width,
            img.height,
            img.px.len(),
            u64::from(img.width) * u64::from(img.height)
        )));
    }
    Ok(())
}

fn encode(bytes: &[u8], w: u32, h: u32, ty: ExtendedColorType) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    PngEncoder::new(&mut out)
        .write_image(bytes, w, h, ty)
        .map_err(|e| Error::msg(format!("PNG encoding of a {w}x{h} image failed: {e}")))?;
    Ok(out)
}

/// PNG, RGBA 8 bits per channel, straight alpha, channels rounded as [`Image::to_rgba8`].
pub fn encode_png8(img: &Image) -> Result<Vec<u8>> {
    check(img)?;
    encode(
        &img.to_rgba8(),
        img.width,
        img.height,
        ExtendedColorType::Rgba8,
    )
}

/// PNG, RGBA 16 bits per channel, exactly the image's values.
pub fn encode_png16(img: &Image) -> Result<Vec<u8>> {
    check(img)?;
    let bytes: Vec<u8> = img
        .px
        .iter()
        .flat_map(|p| p.iter().flat_map(|c| c.to_ne_bytes()))
        .collect();
    encode(&bytes, img.width, img.height, ExtendedColorType::Rgba16)
}

/// PNG of a pixmap (tiny-skia demultiplies it to straight alpha).
pub fn encode_pixmap(p: &Pixmap) -> Result<Vec<u8>> {
    p.encode_png().map_err(|e| {
        Error::msg(format!(
            "PNG encoding of a {}x{} pixmap failed: {e}",
            p.width(),
            p.height()
        ))
    })
}

/// The image as a premultiplied RGBA8 pixmap (channels rounded as [`Image::to_rgba8`], then
/// premultiplied). A zero-sized image gives a transparent 1x1 pixmap; missing pixels are
/// transparent.
#[must_use]
pub fn image_to_pixmap(img: &Image) -> Pixmap {
    let mut p = draw::new_pixmap(img.width, img.height);
    if p.width() != img.width || p.height() != img.height {
        return p;
    }
    let w = img.width as usize;
    for (i, dst) in p.pixels_mut().iter_mut().enumerate() {
        let (x, y) = ((i % w) as u32, (i / w) as u32);
        if let Some(c) = img.get(x, y) {
            let q = c.map(|v| quantize(v, 8) as u8);
            *dst = tiny_skia::ColorU8::from_rgba(q[0], q[1], q[2], q[3]).premultiply();
        }
    }
    p
}
