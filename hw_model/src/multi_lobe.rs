//! Multiple-surface shading (Fournier 1992, "Normal Distribution Functions and Multiple
//! Surfaces", eqs. 11-12 and sec. 4): a surface point carries K normals `N_i` in its local
//! frame, each with an amplitude `c_i` and a Phong exponent `n_i`, and the shading is the sum
//! of the K traditional Phong shadings ("a sum of Phong peaks"):
//!
//! `colour = sum_lights light * (kd D + ks S)`, `D = sum_i c_i max(0, N_i . l)`,
//! `S = sum_i w_i max(0, N_i . h)^(n_i)` (no specular term of lobe `i` where `N_i . l <= 0`,
//! as in [`crate::blinn_phong`]), `h = (l + v) / |l + v|`. The specular weight `w_i` is `c_i`
//! for made-up lobes; for lobes fitted to a bump map (von Mises-Fisher lobes of weight
//! `alpha_i = c_i` and concentration `kappa_i` seen through the material's `(N . h)^s`,
//! `texsim::shading::fournier_fit`) it is the conversion's peak `alpha_i kappa_i / (kappa_i +
//! s) = c_i n_i / s` (the stored exponent is `n_i = kappa_i s / (kappa_i + s)`): the unit
//! takes the material's reciprocal `2^R / s` ([`shininess_recip`], `R =`
//! [`recip_frac_bits`]) and weights the specular sum by `n_i` exactly, so one stored amplitude
//! gives both the diffuse weight `alpha_i` and the specular one.
//!
//! Storage and decoding: a lobe's direction is two tangent-plane slopes `(p, q)` (signed
//! `lobe_slope_int_bits`.`lobe_slope_frac_bits`), decoded exactly as a bump offset: requantized
//! to the offset format and `N_i = normalize(n + p t_u + q t_v)` by the frame unit's
//! [`crate::frame::perturb_normal`] (so a lobe can never point below the horizon: a lobe at the
//! horizon is the largest slope, saturated and counted). The amplitude is unsigned
//! 1.`lobe_amp_bits` (raw `2^A` = 1.0), the exponent an integer of `lobe_exp_bits` bits (larger
//! ones saturate, counted; the power unit saturates again at `pow_exponent_bits`). At most
//! `lobe_max_lobes` lobes are shaded; extra lobes are dropped and flagged.
//!
//! Rounding: the `K` products `c_i (N_i . l)` and `c_i x_i^(n_i)` (fitted: `c_i n_i x_i^(n_i)`,
//! then times the reciprocal) are summed exactly and each sum leaves through one
//! `round_shift_right` (to `F = vector_frac_bits` and `P = pow_frac_bits`); the colour is [`crate::blinn_phong::lit_color`] (one exact division per
//! channel, saturating at 1.0) and the lights' colours add saturating at 1.0 (counted).
//!
//! ERROR BOUND (absolute, per channel, colours in [0, 1]; against the float twin
//! `texsim::shading::multi_lobe::shade` on the same quantized frame, slopes, amplitudes,
//! exponents, `l`, `v` and colours; asserted in `tests/units/lobe_unit.rs`). With `e_N = 2.5 *
//! 2^-F` the decoded direction's error per component (the frame unit's bound, lengths 1),
//! `d_l = 2^-F + sqrt(3) e_N` the error of `N_i . l` and `d_h = 2.5 * 2^-F + sqrt(3) e_N` that
//! of `N_i . h` (as in `blinn_phong.rs`, plus the direction's error), per light:
//! `light * (kd (sum_i c_i d_l + 2^-(F+1)) + ks (sum_i w_i (E_i + W_i + T_i) + Q + 2^-(P+1))) +
//! 1 / (2^C - 1)`, summed over the lights, where `w_i` is the specular weight (`c_i`, or `c_i
//! n_i / s` for fitted lobes), `Q = 0` for made-up lobes and `Q = sum_i c_i n_i 2^-(R+1)` for
//! fitted ones (the reciprocal's rounding), `x_i = N_i . h` (float), `W_i = min(1, x_i +
//! d_h)^n_i - max(0, x_i - d_h)^n_i` (the power's spread over its input error), `E_i` the power
//! unit's bound (`pow.rs`) at `min(1, x_i + d_h)`, and `T_i = min(1, x_i + d_h)^n_i` where
//! `N_i . l < d_l` (at a lobe's terminator its specular term may switch), else 0. A saturated
//! float sum is compared after clamping to 1.

use crate::blinn_phong::{
    half_vector_datapath, lit_color, mac_datapath, shade_datapath, BlinnPhongInput, ShadingConfig,
    ShadingUnits,
};
use crate::config::ConfigError;
use crate::cost::UnitCost;
use crate::datapath::{Component, Cycles, Datapath, Stage};
use crate::fixed::{round_div_wide, round_shift_right_wide, Format, Rounding, SatCounter};
use crate::frame::{perturb_datapath, perturb_normal, Frame};
use crate::pow::pow_cost;
use crate::rsqrt::{range, rsqrt_cost};
use crate::vector::{
    dot3, dot_cost, dot_datapath, madd_cost, normalize3, normalize_cost, normalize_datapath,
    offset_format, Vec3x,
};
use serde::{Deserialize, Serialize};

/// The largest `lobe_max_lobes` the unit supports.
pub const MAX_LOBES: u32 = 8;

/// Multi-lobe unit configuration (storage formats of a lobe and the K limit).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MultiLobeConfig {
    /// Most lobes shaded per pixel. 1..=8.
    pub lobe_max_lobes: u32,
    /// Integer bits (plus sign) of a stored lobe slope. 0..=8.
    pub lobe_slope_int_bits: u32,
    /// Fraction bits of a stored lobe slope. 2..=16.
    pub lobe_slope_frac_bits: u32,
    /// Fraction bits of a lobe amplitude (unsigned 1.A, raw 2^A = 1.0). 2..=16.
    pub lobe_amp_bits: u32,
    /// Bits of a stored lobe exponent (integer, saturating). 1..=16.
    pub lobe_exp_bits: u32,
    /// Rounding of the lobe sums.
    pub lobe_rounding: Rounding,
    /// Cycles of the amplitude multiply-accumulate of one lobe.
    pub lobe_mac_cycles: Cycles,
    /// Lobes fitted per texel to the bump map of a `fournier_lobes = "hw"` material
    /// (`texsim::pipeline::lobe_fit`). 1..=8.
    #[serde(default = "default_fournier_lobes")]
    pub fournier_lobes: u32,
    /// How fitted lobes combine two MIP levels (`texsim::pipeline::lobe_fetch`): the nearest
    /// level, or both levels shaded and their colours blended by the LOD fraction.
    #[serde(default)]
    pub lobe_level_mix: LevelMix,
}

/// How the fitted lobes of two MIP levels are combined (lobe parameters do not average
/// linearly, so never by filtering the lobes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LevelMix {
    /// The LOD rounded to the nearest level: K lookups, one multi-lobe shading.
    #[default]
    Nearest,
    /// The two levels around the LOD: 2K lookups, two multi-lobe shadings, the colours blended
    /// by the LOD fraction (one lerp per channel).
    Blend,
}

fn default_fournier_lobes() -> u32 {
    2
}

impl MultiLobeConfig {
    /// Texram-style default: 8 lobes, slopes s3.12 (the bump offset format), 16-bit
    /// amplitudes, 11-bit exponents (the power unit's range).
    #[must_use]
    pub fn texram16() -> Self {
        Self {
            lobe_max_lobes: MAX_LOBES,
            lobe_slope_int_bits: 3,
            lobe_slope_frac_bits: 12,
            lobe_amp_bits: 16,
            lobe_exp_bits: 11,
            lobe_rounding: Rounding::HalfEven,
            lobe_mac_cycles: Cycles::Derived,
            fournier_lobes: default_fournier_lobes(),
            lobe_level_mix: LevelMix::Nearest,
        }
    }

    /// Checks the widths; the error names the field.
    pub fn validate(&self) -> Result<(), ConfigError> {
        range(
            "multi_lobe.lobe_max_lobes",
            self.lobe_max_lobes,
            1,
            MAX_LOBES,
        )?;
        range(
            "multi_lobe.lobe_slope_int_bits",
            self.lobe_slope_int_bits,
            0,
            8,
        )?;
        range(
            "multi_lobe.lobe_slope_frac_bits",
            self.lobe_slope_frac_bits,
            2,
            16,
        )?;
        range("multi_lobe.lobe_amp_bits", self.lobe_amp_bits, 2, 16)?;
        range("multi_lobe.lobe_exp_bits", self.lobe_exp_bits, 1, 16)?;
        range(
            "multi_lobe.fournier_lobes",
            self.fournier_lobes,
            1,
            MAX_LOBES,
        )?;
        Ok(())
    }
}

impl Default for MultiLobeConfig {
    fn default() -> Self {
        Self::texram16()
    }
}

/// The stored slope format: signed `lobe_slope_int_bits`.`lobe_slope_frac_bits`, saturating.
#[must_use]
pub fn slope_format(cfg: &MultiLobeConfig) -> Format {
    Format::signed(
        cfg.lobe_slope_int_bits,
        cfg.lobe_slope_frac_bits,
        cfg.lobe_rounding,
    )
}

/// The amplitude format: unsigned 1.`lobe_amp_bits` (raw `2^A` = 1.0), saturating.
#[must_use]
pub fn amp_format(cfg: &MultiLobeConfig) -> Format {
    Format::unsigned(1, cfg.lobe_amp_bits, cfg.lobe_rounding)
}

/// The largest stored exponent, `2^lobe_exp_bits - 1`.
#[must_use]
pub fn max_exponent(cfg: &MultiLobeConfig) -> u32 {
    ((1u64 << cfg.lobe_exp_bits.clamp(1, 16)) - 1) as u32
}

/// One stored lobe (raw values in the formats above).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Lobe {
    /// Slopes `(p, q)` along the frame's `t_u`, `t_v` (slope format).
    pub slope: [i64; 2],
    /// Amplitude `c_i` (amplitude format).
    pub amp: u64,
    /// Phong exponent `n_i`.
    pub exponent: u32,
}

/// One light as the unit sees it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LobeLight {
    /// Unit vector towards the light (vector format).
    pub l: Vec3x,
    /// Light colour (unorm raw, `shade_color_bits`).
    pub color: [u64; 3],
}

/// Inputs of one multi-lobe evaluation.
#[derive(Clone, Copy, Debug)]
pub struct MultiLobeInput<'a> {
    /// The local frame (unit or main frame: lengths 1; the natural frame's lengths scale the
    /// slopes as they scale bump offsets).
    pub frame: &'a Frame,
    pub lobes: &'a [Lobe],
    pub lights: &'a [LobeLight],
    /// Unit vector towards the eye (vector format).
    pub v: Vec3x,
    pub kd: [u64; 3],
    pub ks: [u64; 3],
    /// Fitted lobes: the material's [`shininess_recip`] (each lobe's specular weight is then
    /// `c_i n_i / s`); `None` for made-up lobes (weight `c_i`).
    pub spec_recip: Option<u64>,
}

/// Fraction bits `R = lobe_exp_bits + P + 2` of the reciprocal of a fitted material's Phong
/// exponent (`P = pow_frac_bits`): its rounding adds at most `c_i n_i 2^-(R+1) <= c_i
/// 2^-(P+3)` per lobe.
#[must_use]
pub fn recip_frac_bits(cfg: &MultiLobeConfig, sh: &ShadingConfig) -> u32 {
    cfg.lobe_exp_bits.clamp(1, 16) + sh.pow.pow_frac_bits.clamp(8, 24) + 2
}

/// The reciprocal `round(2^R / s)` of a fitted material's Phong exponent `s` (at least 1), a
/// per-material constant set up with the material (as `kd`, `ks`).
#[must_use]
pub fn shininess_recip(s: u32, cfg: &MultiLobeConfig, sh: &ShadingConfig) -> u64 {
    let r = recip_frac_bits(cfg, sh);
    round_div_wide(1i128 << r, i128::from(s.max(1)), cfg.lobe_rounding) as u64
}

/// Result of one multi-lobe evaluation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MultiLobeOut {
    /// Sum over the lights, saturated at 1.0 (unorm raw, `shade_color_bits`).
    pub color: [u64; 3],
    /// Sum over the lights of each light's (saturated) colour, before the final saturation.
    pub sum: [u64; 3],
    /// Lights with `l + v = 0` (no specular term).
    pub h_zero: u32,
    /// More lobes than `lobe_max_lobes` were given; the extra ones were not shaded.
    pub dropped: bool,
}

/// The decoded unit direction of `lobe` in `frame` (vector format): slopes requantized to the
/// offset format, then the frame unit's perturbation.
#[must_use]
pub fn lobe_direction(
    frame: &Frame,
    lobe: &Lobe,
    cfg: &MultiLobeConfig,
    units: &ShadingUnits,
    sat: &mut SatCounter,
) -> Vec3x {
    let of = offset_format(&units.cfg.vector);
    let sf = cfg.lobe_slope_frac_bits;
    let p = of.requantize(slope_format(cfg).fit(lobe.slope[0], sat), sf, sat);
    let q = of.requantize(slope_format(cfg).fit(lobe.slope[1], sat), sf, sat);
    perturb_normal(frame, p, q, units, sat).v
}

/// `sum_i c_i t_i` with `c_i` in 1.A and `t_i` in `frac` fraction bits, summed exactly and
/// rounded once to `frac` bits. ERROR: at most 1/2 ulp of `frac` bits from the exact sum.
#[must_use]
pub fn lobe_sum(terms: &[(u64, i64)], amp_bits: u32, mode: Rounding) -> i64 {
    let acc: i128 = terms
        .iter()
        .map(|&(c, t)| i128::from(c) * i128::from(t))
        .sum();
    round_shift_right_wide(acc, amp_bits, mode)
}

/// `r sum_i w_i t_i`, summed exactly and rounded once by `shift` bits (the fitted lobes'
/// specular sum: `w_i = c_i n_i`, `r` the reciprocal of the material's exponent). ERROR: at most
/// 1/2 ulp from the exact product.
#[must_use]
pub fn fitted_spec_sum(terms: &[(u64, i64)], r: u64, shift: u32, mode: Rounding) -> i64 {
    let acc: i128 = terms
        .iter()
        .map(|&(w, t)| i128::from(w) * i128::from(t))
        .sum();
    round_shift_right_wide(acc * i128::from(r), shift, mode)
}

/// One multi-lobe evaluation over every light (see the module doc for the formula).
#[must_use]
pub fn multi_lobe_shade(
    inp: &MultiLobeInput,
    cfg: &MultiLobeConfig,
    units: &ShadingUnits,
    sat: &mut SatCounter,
) -> MultiLobeOut {
    let vc = &units.cfg.vector;
    let f = vc.vector_frac_bits;
    let p = units.cfg.pow.pow_frac_bits.clamp(8, 24);
    let one_f = 1i64 << f;
    let a = cfg.lobe_amp_bits;
    let k = (cfg.lobe_max_lobes.clamp(1, MAX_LOBES) as usize).min(inp.lobes.len());
    let dropped = inp.lobes.len() > k;
    let amp_fmt = amp_format(cfg);
    let n_max = max_exponent(cfg);
    let mut dirs = [[0i64; 3]; MAX_LOBES as usize];
    let mut amps = [0u64; MAX_LOBES as usize];
    let mut exps = [0u32; MAX_LOBES as usize];
    for (i, lobe) in inp.lobes[..k].iter().enumerate() {
        dirs[i] = lobe_direction(inp.frame, lobe, cfg, units, sat);
        amps[i] = amp_fmt.fit(lobe.amp.min(i64::MAX as u64) as i64, sat) as u64;
        if lobe.exponent > n_max {
            sat.saturated += 1;
        }
        exps[i] = lobe.exponent.min(n_max);
    }
    let cb = units.cfg.shade.shade_color_bits;
    let out_fmt = Format::unsigned(0, cb, units.cfg.shade.shade_rounding);
    let mut sum = [0u64; 3];
    let mut h_zero = 0u32;
    let x_fmt = Format::unsigned(1, p, vc.vector_rounding);
    // Specular weights: c_i, or c_i n_i (exact) for fitted lobes, scaled by the reciprocal.
    let r_bits = recip_frac_bits(cfg, &units.cfg);
    let mut spec_w = amps;
    if inp.spec_recip.is_some() {
        for i in 0..k {
            spec_w[i] = amps[i] * u64::from(exps[i]);
        }
    }
    for light in inp.lights {
        let hsum = [
            light.l[0] + inp.v[0],
            light.l[1] + inp.v[1],
            light.l[2] + inp.v[2],
        ];
        let hz = hsum == [0; 3];
        h_zero += u32::from(hz);
        let h = if hz {
            [0; 3]
        } else {
            normalize3(&hsum, [0; 3], &units.rsqrt, vc, sat).v
        };
        let mut diffuse = [(0u64, 0i64); MAX_LOBES as usize];
        let mut spec = [(0u64, 0i64); MAX_LOBES as usize];
        for i in 0..k {
            let ndl = dot3(&dirs[i], &light.l, vc, sat).clamp(0, one_f);
            diffuse[i] = (amps[i], ndl);
            let s = if hz || ndl == 0 {
                0
            } else {
                let ndh = dot3(&dirs[i], &h, vc, sat).clamp(0, one_f);
                let x = x_fmt.requantize(ndh, f, sat);
                units.pow.pow(x as u64, exps[i], sat) as i64
            };
            spec[i] = (spec_w[i], s);
        }
        let d = lobe_sum(&diffuse[..k], a, cfg.lobe_rounding);
        let s = match inp.spec_recip {
            None => lobe_sum(&spec[..k], a, cfg.lobe_rounding),
            Some(r) => fitted_spec_sum(&spec[..k], r, a + r_bits, cfg.lobe_rounding),
        };
        let bp = BlinnPhongInput {
            n: [0; 3],
            l: light.l,
            v: inp.v,
            shininess: 0,
            kd: inp.kd,
            ks: inp.ks,
            light: light.color,
        };
        let c = lit_color(&bp, d, s, units, sat);
        for ch in 0..3 {
            sum[ch] += c[ch];
        }
    }
    let color = sum.map(|x| out_fmt.fit(x.min(i64::MAX as u64) as i64, sat) as u64);
    MultiLobeOut {
        color,
        sum,
        h_zero,
        dropped,
    }
}

/// The amplitude multiply-accumulate of one lobe (`lobe_mac_cycles`): `c_i (N_i . l)` and `c_i
/// x_i^(n_i)` side by side, each added to its running sum (`K <= 8`: 3 carry bits).
#[must_use]
pub fn accumulate_datapath(cfg: &MultiLobeConfig, sh: &ShadingConfig) -> Datapath {
    let a = cfg.lobe_amp_bits + 1;
    let f = sh.vector.vector_frac_bits + 1;
    let p = sh.pow.pow_frac_bits + 1;
    Datapath::new().stage(
        Stage::new("lobe accumulate")
            .then(Component::Multiplier { a, b: f.max(p) })
            .beside(1, Component::Multiplier { a, b: f.min(p) })
            .then_n(
                2,
                Component::Adder {
                    width: a + f.max(p) + 3,
                },
            )
            .cycles(cfg.lobe_mac_cycles),
    )
}

/// One lobe and one light through the unit, in order: the lobe's decode (the frame unit's
/// perturbation), the half vector and its normalize, `N_i . l` and `N_i . h`, the power unit,
/// the amplitude accumulate, the colour stage. A K-lobe, L-light pixel iterates it (see
/// [`multi_lobe_cost`]).
#[must_use]
pub fn datapath(cfg: &MultiLobeConfig, sh: &ShadingConfig) -> Datapath {
    perturb_datapath(sh)
        .then(half_vector_datapath(sh))
        .then(normalize_datapath(&sh.vector, &sh.rsqrt))
        .then(dot_datapath(&sh.vector).times(2))
        .then(crate::pow::datapath(&sh.pow))
        .then(accumulate_datapath(cfg, sh))
        .then(shade_datapath(sh))
}

/// The fitted lobes' specular weighting (`spec_recip`): per lobe the exact weight `c_i n_i`
/// (a `(A + 1) x E` multiplier, once per lobe), per light the specular sum times the
/// reciprocal (a `(A + 1 + E + P + 4) x R` multiplier).
#[must_use]
pub fn fitted_weight_datapath(cfg: &MultiLobeConfig, sh: &ShadingConfig) -> [Datapath; 2] {
    let a = cfg.lobe_amp_bits + 1;
    let e = cfg.lobe_exp_bits;
    let p = sh.pow.pow_frac_bits + 1;
    [
        Datapath::new().stage(
            Stage::new("lobe specular weight")
                .then(Component::Multiplier { a, b: e })
                .cycles(cfg.lobe_mac_cycles),
        ),
        Datapath::new().stage(
            Stage::new("lobe specular scale")
                .then(Component::Multiplier {
                    a: a + e + p + 3,
                    b: recip_frac_bits(cfg, sh),
                })
                .cycles(cfg.lobe_mac_cycles),
        ),
    ]
}

/// Extra cost of fitted lobes over [`multi_lobe_cost`] (see [`fitted_weight_datapath`]).
#[must_use]
pub fn fitted_weight_cost(
    cfg: &MultiLobeConfig,
    sh: &ShadingConfig,
    lobes: u32,
    lights: u32,
    gate_levels_per_cycle: u32,
) -> UnitCost {
    let k = lobes.min(cfg.lobe_max_lobes.clamp(1, MAX_LOBES));
    let [weight, scale] = fitted_weight_datapath(cfg, sh);
    let op = |d: Datapath| UnitCost {
        ops: 1,
        cycles: d.latency(gate_levels_per_cycle),
        texels: 0,
    };
    op(weight).times(k).plus(op(scale).times(lights))
}

/// Cost of one pixel with `lobes` lobes and `lights` lights: per lobe its decode (madd +
/// normalize), per light the half vector and its normalize and the colour stage, per lobe and
/// light two dots, the power and the amplitude accumulate, and the final saturating sum over
/// the lights (one colour multiply-add's worth per light).
#[must_use]
pub fn multi_lobe_cost(
    cfg: &MultiLobeConfig,
    units: &ShadingUnits,
    lobes: u32,
    lights: u32,
    gate_levels_per_cycle: u32,
) -> UnitCost {
    let g = gate_levels_per_cycle;
    let c = &units.cfg;
    let k = lobes.min(cfg.lobe_max_lobes.clamp(1, MAX_LOBES));
    let nz = normalize_cost(&c.vector, rsqrt_cost(&c.rsqrt, g), g);
    let decode = madd_cost(&c.vector, g).plus(nz);
    let per_light = UnitCost {
        ops: 3,
        cycles: half_vector_datapath(c).latency(g),
        texels: 0,
    }
    .plus(nz)
    .plus(UnitCost {
        ops: 12,
        cycles: shade_datapath(c).latency(g),
        texels: 0,
    })
    .plus(UnitCost {
        ops: 3,
        cycles: mac_datapath(c).latency(g),
        texels: 0,
    });
    let per_pair = dot_cost(&c.vector, g)
        .times(2)
        .plus(pow_cost(&c.pow, g))
        .plus(UnitCost {
            ops: 4,
            cycles: accumulate_datapath(cfg, c).latency(g),
            texels: 0,
        });
    decode
        .times(k)
        .plus(per_light.times(lights))
        .plus(per_pair.times(k * lights))
}
