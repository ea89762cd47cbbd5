//! Toksvig 2005 ("Mipmapping Normal Maps"), host side: the Toksvig map (the MIP-mapped, not
//! renormalized, average unit normal of a bump map) and the float twin of
//! `hw_model::toksvig`.

use crate::maps::{downsample, quantize_chain, FixedMipChain, MipChain, MipLevel};
use glam::DVec3;

/// The float twin of `hw_model::toksvig::toksvig`: `len = |Na|` (clamped to [0, 1]) and the
/// base exponent `s` give the real exponent `s' = L s / (L + s (1 - L))` (Toksvig eq. 6) and
/// the specular scale `(1 + s') / (1 + s)`. `s = 0` gives `(0, 1)`.
#[must_use]
pub fn toksvig_f(len: f64, shininess: u32) -> (f64, f64) {
    let s = f64::from(shininess);
    if shininess == 0 {
        return (0.0, 1.0);
    }
    let l = if len.is_finite() {
        len.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let den = l + s * (1.0 - l);
    let sp = if den > 0.0 { l * s / den } else { s };
    (sp, (1.0 + sp) / (1.0 + s))
}

/// `|Na|` of a filtered Toksvig texel (channels `(n + 1) / 2` in [0, 1]).
#[must_use]
pub fn mean_length(t: [f64; 3]) -> f64 {
    DVec3::new(2.0 * t[0] - 1.0, 2.0 * t[1] - 1.0, 2.0 * t[2] - 1.0).length()
}

/// Blinn-Phong with a real exponent (the float path of `toksvig-shade`): `light (kd max(0,
/// n.l) + ks max(0, n.h)^s)`, no specular term where `n.l <= 0` or `l = -v` (reported).
#[must_use]
pub fn blinn_phong_real(
    n: DVec3,
    l: DVec3,
    v: DVec3,
    exponent: f64,
    kd: [f64; 3],
    ks: [f64; 3],
    light: [f64; 3],
) -> ([f64; 3], bool) {
    let ndl = n.dot(l).clamp(0.0, 1.0);
    let sum = l + v;
    let h_zero = sum == DVec3::ZERO;
    let spec = if h_zero || ndl == 0.0 {
        0.0
    } else {
        let x = n.dot(sum.normalize()).clamp(0.0, 1.0);
        if exponent <= 0.0 {
            1.0
        } else {
            x.powf(exponent)
        }
    };
    let mut c = [0.0; 3];
    for i in 0..3 {
        c[i] = (light[i] * (kd[i] * ndl + ks[i] * spec)).clamp(0.0, 1.0);
    }
    (c, h_zero)
}

/// The Toksvig map of level-0 offsets `offs` (`w x h`, decoded `(f_u, f_v)`): per texel the
/// unit normal `normalize(f_u, f_v, 1)` in the frame basis (as the NDF maps' texel normal)
/// encoded `(n + 1) / 2` in RGB, then box-filtered MIP levels (the encoding is linear, so a
/// level holds the encoded average normal, whose length is `|Na|`).
#[must_use]
pub fn toksvig_mip_chain(offs: &[[f32; 2]], w: u32, h: u32) -> MipChain {
    let texels = offs
        .iter()
        .map(|o| {
            let n = DVec3::new(f64::from(o[0]), f64::from(o[1]), 1.0).normalize();
            [
                ((n.x + 1.0) * 0.5) as f32,
                ((n.y + 1.0) * 0.5) as f32,
                ((n.z + 1.0) * 0.5) as f32,
                1.0,
            ]
        })
        .collect();
    let mut levels = vec![MipLevel {
        width: w,
        height: h,
        texels,
    }];
    while let Some(last) = levels.last() {
        if last.width <= 1 && last.height <= 1 {
            break;
        }
        let next = downsample(last);
        levels.push(next);
    }
    MipChain { levels }
}

/// The Toksvig chain as texture memory holds it: three channels of `texel_bits`.
#[must_use]
pub fn quantize_toksvig_chain(chain: &MipChain, texel_bits: u32) -> FixedMipChain {
    let q = quantize_chain(chain, texel_bits);
    let bits = q.format.bits;
    q.stored_as(3, bits)
}
