//! Float twin of `hw_model::multi_lobe` (Fournier 1992, eqs. 11-12 and sec. 4: a multiple
//! surface shaded as the sum of its lobes' Phong shadings): the same decode (a lobe's slopes
//! perturb the frame normal), the same per-lobe terminator, the same saturation per light and
//! over the lights, in `f64`.

use super::reference::{normalize_or, perturb_normal, pow, FrameF};
use glam::DVec3;

/// The most lobes shaded (`hw_model::multi_lobe::MAX_LOBES`).
const MAX_LOBES: usize = hw_model::multi_lobe::MAX_LOBES as usize;

/// One lobe in float: slopes along the frame's `t_u`, `t_v`, amplitude, Phong exponent.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LobeF {
    pub slope: [f64; 2],
    pub amp: f64,
    pub exponent: u32,
}

/// The unit direction of `lobe` in the frame `fr` (`normalize(n + p len_u t_u + q len_v t_v)`).
#[must_use]
pub fn lobe_direction(fr: &FrameF, lobe: &LobeF) -> DVec3 {
    perturb_normal(fr, lobe.slope[0], lobe.slope[1])
}

/// Result of [`shade`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MultiLobeF {
    /// Sum over the lights, each light's colour and the sum clamped to [0, 1].
    pub color: [f64; 3],
    /// Sum over the lights of each light's clamped colour, before the final clamp.
    pub sum: [f64; 3],
    /// Lights with `l + v = 0`.
    pub h_zero: u32,
}

/// Twin of `hw_model::multi_lobe::multi_lobe_shade` for the first `max_lobes` lobes: per light
/// `light * (kd sum_i c_i max(0, N_i.l) + ks sum_i c_i max(0, N_i.h)^n_i)`, no specular term of
/// lobe `i` where `N_i.l <= 0` or `l + v = 0`. With `fitted_shininess = Some(s)` (lobes fitted
/// to a bump map) lobe `i`'s specular weight is `c_i n_i / s` instead of `c_i`.
#[must_use]
#[allow(clippy::too_many_arguments)]
pub fn shade(
    fr: &FrameF,
    lobes: &[LobeF],
    max_lobes: usize,
    lights: &[(DVec3, [f64; 3])],
    v: DVec3,
    kd: [f64; 3],
    ks: [f64; 3],
    fitted_shininess: Option<f64>,
) -> MultiLobeF {
    let k = lobes.len().min(max_lobes).min(MAX_LOBES);
    let mut dirs = [DVec3::ZERO; MAX_LOBES];
    for (d, l) in dirs.iter_mut().zip(&lobes[..k]) {
        *d = lobe_direction(fr, l);
    }
    let mut color = [0.0f64; 3];
    let mut h_zero = 0;
    for &(l, light) in lights {
        let sum = l + v;
        let hz = sum == DVec3::ZERO;
        h_zero += u32::from(hz);
        let h = normalize_or(sum, DVec3::ZERO).0;
        let mut d = 0.0;
        let mut s = 0.0;
        for (n, lobe) in dirs[..k].iter().zip(&lobes[..k]) {
            let ndl = n.dot(l).clamp(0.0, 1.0);
            d += lobe.amp * ndl;
            if !hz && ndl > 0.0 {
                let w = fitted_shininess.map_or(lobe.amp, |sh| {
                    lobe.amp * f64::from(lobe.exponent) / sh.max(1.0)
                });
                s += w * pow(n.dot(h).clamp(0.0, 1.0), lobe.exponent);
            }
        }
        for ch in 0..3 {
            color[ch] += (light[ch] * (kd[ch] * d + ks[ch] * s)).clamp(0.0, 1.0);
        }
    }
    MultiLobeF {
        color: color.map(|c| c.clamp(0.0, 1.0)),
        sum: color,
        h_zero,
    }
}
