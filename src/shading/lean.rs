//! LEAN mapping (Olano and Baker 2010), host side: the second-moment map of the bump slopes and
//! the float twin of `hw_model::lean`.

use crate::maps::{downsample, quantize_chain, FixedMipChain, MipChain, MipLevel};
use glam::DVec3;

/// The float twin of `hw_model::lean::lean` on decoded moments: `b = (f_u, f_v)` the filtered
/// offsets, `m = (M_uu, M_vv, M_uv)` the filtered second moments, `h` the unit half vector in
/// the frame, `s` the base exponent. `Sigma = M - B B^T + I/s` (a negative diagonal of
/// `M - B B^T` clamped to 0, an off-diagonal that makes `det <= 0` dropped), the slope of `h`
/// clamped to `|h~| <= 256`, the distance below 128; `D = min(1, (1/s) / sqrt(det)) exp(-d/2)`,
/// 0 for `h_n <= 0`.
#[must_use]
pub fn lean_f(b: [f64; 2], m: [f64; 3], h: DVec3, shininess: u32) -> f64 {
    let s = f64::from(shininess.max(1));
    let fin = |x: f64| if x.is_finite() { x } else { 0.0 };
    let (b0, b1) = (fin(b[0]), fin(b[1]));
    let cuu = (fin(m[0]) - b0 * b0).max(0.0) + 1.0 / s;
    let cvv = (fin(m[1]) - b1 * b1).max(0.0) + 1.0 / s;
    let mut cuv = fin(m[2]) - b0 * b1;
    let mut det = cuu * cvv - cuv * cuv;
    if det <= 0.0 {
        cuv = 0.0;
        det = cuu * cvv;
    }
    if h.z.is_nan() || h.z <= 0.0 {
        return 0.0;
    }
    let x0 = (h.x / h.z).clamp(-256.0, 256.0) - b0;
    let x1 = (h.y / h.z).clamp(-256.0, 256.0) - b1;
    let d = ((x0 * x0 * cvv - 2.0 * x0 * x1 * cuv + x1 * x1 * cuu) / det).clamp(0.0, 128.0);
    ((1.0 / s) / det.sqrt()).min(1.0) * (-0.5 * d).exp()
}

/// Decodes filtered moment channels (`[0, 1]`) with range exponent `e`.
#[must_use]
pub fn decode_moments(t: [f64; 3], e: u32) -> [f64; 3] {
    let r = f64::from(e).exp2();
    [t[0] * r, t[1] * r, (2.0 * t[2] - 1.0) * r * 0.5]
}

/// The moment map of level-0 offsets `offs` (`w x h`): per texel `f_u^2 / 2^E`, `f_v^2 / 2^E`,
/// `1/2 + f_u f_v / 2^E` (clamped to [0, 1], each clamp counted), box-filtered MIP levels
/// (linear encoding: a level holds the encoded mean moments). Returns the chain and the clamps.
#[must_use]
pub fn lean_mip_chain(offs: &[[f32; 2]], w: u32, h: u32, e: u32) -> (MipChain, u64) {
    let r = f64::from(e).exp2();
    let mut clamped = 0u64;
    let mut enc = |x: f64| {
        if !(0.0..=1.0).contains(&x) {
            clamped += 1;
        }
        x.clamp(0.0, 1.0) as f32
    };
    let texels = offs
        .iter()
        .map(|o| {
            let (u, v) = (f64::from(o[0]), f64::from(o[1]));
            [enc(u * u / r), enc(v * v / r), enc(0.5 + u * v / r), 1.0]
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
    (MipChain { levels }, clamped)
}

/// The moment chain as texture memory holds it: three channels of `texel_bits`.
#[must_use]
pub fn quantize_lean_chain(chain: &MipChain, texel_bits: u32) -> FixedMipChain {
    let q = quantize_chain(chain, texel_bits);
    let bits = q.format.bits;
    q.stored_as(3, bits)
}
