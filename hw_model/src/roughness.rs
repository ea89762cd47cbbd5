//! Modified Blinn-Phong with a roughness map in fixed point (Schilling 1997, "Antialiasing of
//! Bump-Maps", Appendix A): `cos^2 a' = cos^2 a / (|d|^4 / |D d|^2 + cos^2 a)`, where `d` is
//! the projection of `n - h` into the tangent plane (`|d|^2 = 1 - cos^2 a`) and `D` the
//! filtered roughness factor `[[d1, d2], [0, d3]]` with `D D^T = K` (offset covariance).
//!
//! Written as `Q = |d|^2 * N / M`, `cos a' = cos a / sqrt(Q + cos^2 a)` (so
//! `tan a' = tan a / sigma(d)`, sigma the standard deviation of the offsets in direction `d`):
//! - `published`: `N = |d|^2`, `M = |D d|^2` (the paper's formula as printed);
//! - `directional`: `N = |d|^2`, `M = |D^T d|^2 = d^T K d` (the standard deviation of the
//!   offsets along `d`, consistent with `K = D D^T`; `|D d|` is that of `D^T D` instead);
//! - `mahalanobis`: `Q = d^T K^-1 d = N / M` (no `|d|^2` factor: `d^T K^-1 d` already is
//!   `|d|^2 / sigma^2`), `N = (d3 x - d2 y)^2 + (d1 y)^2`, `M = (d1 d3)^2` (the paper's
//!   ellipse `x^T K^-1 x = 1`: the distance to it along `d` is the standard deviation there);
//! - `isotropic`: `N = 1`, `M = lambda1^2` (channel 0 holds lambda1; the paper's simplified
//!   formula `cos^2 a' = l^2 cos^2 a / (1 - cos^2 a + l^2 cos^2 a)`);
//! - `none`: `cos a' = cos a` (the plain filtered bump map, the baseline).
//!
//! Guards, in this order: `cos a = 0` gives 0; `d = 0` (h = n) gives 1 (`Q = 0` by the limit
//! `|d|^4/|Dd|^2 <= |d|^2 / sigma_min^2 -> 0`); `M = 0` (D singular along d, d != 0) gives 0
//! and counts a saturation; `Q >= 2^`[`Q_CAP_BITS`] gives 0 and counts a saturation.
//!
//! Datapath: `d`, `cos a` in vector format (s1.F); the D channels are filtered texels `t`
//! (`texel_bits`) decoded exactly as `d1 = t 2^(e - bits)`, `d2 = (t - 2^(bits-1))
//! 2^(e + 1 - bits)`, `d3` like `d1` (`e = rough_range_exp`, channel range `[0, 2^e)`,
//! `d2` in `[-2^e, 2^e)`); `d1`, `d3` are stored unorm, `d2` offset-binary so that 0 is
//! exact at every stored width ([`widen_d_channel`]). `N` and `M` are exact integers; the divider returns `N / M` with
//! `rough_div_bits` significant bits (round half even, exact remainder); `Q` is formed with
//! `W = 4F + 8` fraction bits; the square root of `Q + cos^2 a` has `rough_sqrt_bits`
//! significant bits (correctly rounded); the divider then forms `cos a / sqrt(...)`, rounded
//! once more to the output's `P` fraction bits.
//!
//! ERROR BOUND (absolute, against the float twin `texsim::shading::roughness::rough_cos_twin`
//! on the same quantized inputs): `1.5 * 2^-div_bits + 2^-sqrt_bits + 2^-(P+1) + 2^-20`
//! (divider `2^-B` relative twice, half of it through the square root; square root `2^-B`;
//! output rounding; the `Q` cap). Measured in `tests/units/roughness_unit.rs` (docs/ROUGHNESS.md).

use crate::blinn_phong::{
    blinn_phong_cost, lit_color, BlinnPhongInput, BlinnPhongOut, ShadingUnits,
};
use crate::config::ConfigError;
use crate::cost::UnitCost;
use crate::datapath::{Component, Cycles, Datapath, Stage};
use crate::fixed::{round_shift_right_sticky, round_shift_right_wide, Rounding, SatCounter};
use crate::pow::{pow_cost, Pow, PowConfig};
use crate::rsqrt::{isqrt_u128, range};
use crate::vector::{dot3, dot_cost, normalize3, Vec3x};
use serde::{Deserialize, Serialize};

/// `Q` (the squared modified tangent) saturates at `2^Q_CAP_BITS`: the result is then below
/// `2^-(Q_CAP_BITS/2)` and is returned as 0.
pub const Q_CAP_BITS: u32 = 40;

/// Which form of the modified Blinn-Phong is evaluated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RoughVariant {
    /// No roughness: plain Blinn-Phong on the filtered bump normal.
    None,
    /// The paper's printed formula, `|D d|`.
    Published,
    /// The directional standard deviation `|D^T d|` (`K = D D^T`).
    Directional,
    /// The exact Mahalanobis form `d^T K^-1 d`.
    Mahalanobis,
    /// The isotropic form with lambda1 (largest standard deviation).
    Isotropic,
}

impl RoughVariant {
    /// All variants, in the order reports list them.
    pub const ALL: [RoughVariant; 5] = [
        RoughVariant::None,
        RoughVariant::Published,
        RoughVariant::Directional,
        RoughVariant::Mahalanobis,
        RoughVariant::Isotropic,
    ];

    /// The configuration name.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            RoughVariant::None => "none",
            RoughVariant::Published => "published",
            RoughVariant::Directional => "directional",
            RoughVariant::Mahalanobis => "mahalanobis",
            RoughVariant::Isotropic => "isotropic",
        }
    }

    /// Parses a configuration name.
    #[must_use]
    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|v| v.name() == s)
    }
}

/// Where the specular exponent comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RoughExponentMode {
    /// `rough_const_exponent` for every material: the highlight size comes from D alone
    /// (the material enters through the base roughness added to K).
    Constant,
    /// The material's own shininess.
    Material,
}

/// Roughness unit configuration.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RoughnessConfig {
    /// Stored bits per D channel (expanded to the texel width by bit replication). 2..=16.
    pub rough_d_bits: u32,
    /// Range exponent `e`: d1, d3 in `[0, 2^e)`, d2 in `[-2^e, 2^e)`. -4..=4.
    pub rough_range_exp: i32,
    /// Significant bits of the divider's quotient. 8..=30.
    pub rough_div_bits: u32,
    /// Significant bits of the square root. 8..=30.
    pub rough_sqrt_bits: u32,
    /// The formula.
    pub rough_variant: RoughVariant,
    /// Constant or material exponent.
    pub rough_exponent_mode: RoughExponentMode,
    /// The exponent in constant mode. 1..=1024.
    pub rough_const_exponent: u32,
    /// Cycles per multiplier stage.
    pub rough_mul_cycles: Cycles,
    /// Quotient bits the divider produces per cycle (SRT radix). 1..=8.
    pub rough_div_bits_per_cycle: u32,
    /// Root bits the square root produces per cycle. 1..=8.
    pub rough_sqrt_bits_per_cycle: u32,
    /// Scale K by 3 when the pyramid is built (offsets uniformly distributed rather than
    /// normal: the ellipse then reaches the edge of the distribution). Host side only.
    #[serde(default)]
    pub rough_uniform: bool,
    /// Scale the specular term by `min(1, (m / s) / (d1 d3))` (`d1 d3 = sqrt(det K')`;
    /// isotropic: `lambda1^2`): the peak of a lobe convolved with Gaussian slopes,
    /// `det(I + s K)^(-1/2)`, so widening conserves energy. Not in the paper (an extension;
    /// off = as published).
    #[serde(default)]
    pub rough_normalize: bool,
}

impl RoughnessConfig {
    /// Texram-style default: 16-bit D channels in `[0, 4)`, 16-bit divide and root,
    /// directional variant, material exponent (constant exponent 1 when switched), radix-4
    /// divider and root, no uniform correction.
    #[must_use]
    pub fn texram16() -> Self {
        Self {
            rough_d_bits: 16,
            rough_range_exp: 2,
            rough_div_bits: 16,
            rough_sqrt_bits: 16,
            rough_variant: RoughVariant::Directional,
            rough_exponent_mode: RoughExponentMode::Material,
            rough_const_exponent: 1,
            rough_mul_cycles: Cycles::Derived,
            rough_div_bits_per_cycle: 2,
            rough_sqrt_bits_per_cycle: 2,
            rough_uniform: false,
            rough_normalize: false,
        }
    }

    /// Checks the widths; the error names the field.
    ///
    /// # Errors
    /// A [`ConfigError`] naming the first out-of-range field.
    pub fn validate(&self) -> Result<(), ConfigError> {
        range("roughness.rough_d_bits", self.rough_d_bits, 2, 16)?;
        if !(-4..=4).contains(&self.rough_range_exp) {
            return Err(ConfigError {
                field: "roughness.rough_range_exp".into(),
                what: format!("{} is out of range -4..=4", self.rough_range_exp),
            });
        }
        range("roughness.rough_div_bits", self.rough_div_bits, 8, 30)?;
        range("roughness.rough_sqrt_bits", self.rough_sqrt_bits, 8, 30)?;
        range(
            "roughness.rough_const_exponent",
            self.rough_const_exponent,
            1,
            1024,
        )?;
        range(
            "roughness.rough_div_bits_per_cycle",
            self.rough_div_bits_per_cycle,
            1,
            8,
        )?;
        range(
            "roughness.rough_sqrt_bits_per_cycle",
            self.rough_sqrt_bits_per_cycle,
            1,
            8,
        )?;
        Ok(())
    }

    /// The specular exponent for a material of shininess `material`.
    #[must_use]
    pub fn exponent(&self, material: u32) -> u32 {
        match self.rough_exponent_mode {
            RoughExponentMode::Constant => self.rough_const_exponent,
            RoughExponentMode::Material => material,
        }
    }
}

impl Default for RoughnessConfig {
    fn default() -> Self {
        Self::texram16()
    }
}

/// Expands a `d_bits`-bit stored channel `q` to `texel_bits` by bit replication (the usual
/// unorm widening, `q (2^T - 1) / (2^d - 1)` within one LSB; exact for `d_bits == texel_bits`).
#[must_use]
pub fn expand_channel(q: u64, d_bits: u32, texel_bits: u32) -> u64 {
    let d = d_bits.clamp(1, 32);
    let t = texel_bits.clamp(1, 32);
    let q = q.min((1u64 << d) - 1);
    if d >= t {
        return q >> (d - t);
    }
    let mut out = 0u64;
    let mut filled = 0u32;
    while filled < t {
        let take = d.min(t - filled);
        out = (out << take) | (q >> (d - take));
        filled += take;
    }
    out
}

/// Index of the signed D channel (`d2`), stored offset-binary ([`widen_d_channel`]).
pub const D2_CHANNEL: usize = 1;

/// Widens stored D channel `channel` (`d_bits` wide) to `texel_bits`, what texture memory
/// holds. `d1`, `d3` (and lambda1) are unorm: bit replication ([`expand_channel`]). `d2` is
/// signed, stored offset-binary, `q = 2^(d-1) + round(d2 2^d / (2R))`, i.e.
/// `d2 = (q - 2^(d-1)) 2R / 2^d`; it is widened by zero padding, `q 2^(T-d)`, which keeps that
/// value exactly (`d2 = (t - 2^(T-1)) 2R / 2^T`, the form [`decode_d`] decodes), so `d2 = 0`
/// (every flat texel) stays exactly 0 at every `d_bits`. Bit replication would move the
/// centre code `2^(d-1)` to `2^(T-1) + 2^(T-1-d) + ...` (8 bits: `0x8080`), a shear of
/// `+2R / (2^d - 1)` on flat texels (+0.016 at 8 bits, +0.27 at 4 bits, `R = 4`).
#[must_use]
pub fn widen_d_channel(q: u64, channel: usize, d_bits: u32, texel_bits: u32) -> u64 {
    if channel != D2_CHANNEL {
        return expand_channel(q, d_bits, texel_bits);
    }
    let d = d_bits.clamp(1, 32);
    let t = texel_bits.clamp(1, 32);
    let q = q.min((1u64 << d) - 1);
    if d >= t {
        q >> (d - t)
    } else {
        q << (t - d)
    }
}

/// Raw D values `[d1, d2, d3]` with `T = texel_bits - rough_range_exp` fraction bits, decoded
/// exactly from filtered texels (module doc). Returns the values and `T`. `d2` is decoded
/// around `2^(texel_bits - 1)`, the widened centre code of [`widen_d_channel`] at every
/// `d_bits`, so a flat texel (`d2 = 0`) decodes to exactly 0.
#[must_use]
pub fn decode_d(t: [u64; 3], texel_bits: u32, cfg: &RoughnessConfig) -> ([i64; 3], u32) {
    let bits = texel_bits.clamp(1, 16);
    let lim = 1u64 << bits;
    let t = t.map(|x| x.min(lim) as i64);
    let frac = (bits as i32 - cfg.rough_range_exp.clamp(-4, 4)) as u32;
    ([t[0], 2 * (t[1] - (1i64 << (bits - 1))), t[2]], frac)
}

/// Inputs of one evaluation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RoughInput {
    /// `cos a = n . h`, vector format (negative values clamp to 0).
    pub cos_a: i64,
    /// `d`, the tangent-plane projection of `n - h` in offset coordinates, vector format.
    pub d: [i64; 2],
    /// Filtered D texels `[d1, d2, d3]` (isotropic: `[lambda1, -, -]`).
    pub dch: [u64; 3],
    /// Bits of those texels.
    pub texel_bits: u32,
}

/// Result of one evaluation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RoughOut {
    /// `cos a'`, unsigned with `P` fraction bits, in `[0, 2^P]`.
    pub cos_mod: u64,
    /// `d` was zero (h = n): `cos a' = 1`.
    pub d_zero: bool,
    /// `M = 0` with `d != 0` (singular D along d) or `Q` saturated: `cos a' = 0`.
    pub degenerate: bool,
}

fn bitlen(x: u128) -> u32 {
    128 - x.leading_zeros()
}

/// The divider: `n / m ~= mant * 2^exp`, `mant` in `[2^(b-1), 2^b)`, correctly rounded (half
/// even) to `b` significant bits. `n, m > 0` and below 2^95; `b` in 2..=30.
#[must_use]
pub fn div_round(n: u128, m: u128, b: u32) -> (u64, i32) {
    let b = b.clamp(2, 30);
    let (ln, lm) = (bitlen(n) as i32, bitlen(m) as i32);
    // n 2^k / m lies in (2^(b+1), 2^(b+3)) for k = b + 2 + lm - ln.
    let k = b as i32 + 2 + lm - ln;
    let (nn, mm) = if k >= 0 {
        (n << k as u32, m)
    } else {
        (n, m << (-k) as u32)
    };
    let q0 = nn / mm;
    let sticky = nn % mm != 0;
    let drop = bitlen(q0) - b;
    let mut mant = round_shift_right_sticky(q0, drop, sticky, Rounding::HalfEven);
    let mut e = drop as i32 - k;
    if mant >> b != 0 {
        mant >>= 1;
        e += 1;
    }
    (mant as u64, e)
}

/// The square root: `sqrt(s) ~= mant * 2^exp`, `mant` in `[2^(b-1), 2^b)`, correctly rounded
/// to `b` significant bits. `s > 0`, below 2^120; `b` in 2..=30.
#[must_use]
pub fn sqrt_round(s: u128, b: u32) -> (u64, i32) {
    let b = b.clamp(2, 30);
    let ls = bitlen(s) as i32;
    // s 4^j has 2b + 1 or 2b + 2 bits, so its root has b + 1 bits.
    let j = (2 * b as i32 + 2 - ls).div_euclid(2);
    let (sp, lost) = if j >= 0 {
        (s << (2 * j) as u32, false)
    } else {
        let sh = (-2 * j) as u32;
        (s >> sh, s & ((1u128 << sh) - 1) != 0)
    };
    let r = isqrt_u128(sp);
    let sticky = lost || r * r != sp;
    let mut mant = round_shift_right_sticky(r, 1, sticky, Rounding::HalfEven);
    let mut e = 1 - j;
    if mant >> b != 0 {
        mant >>= 1;
        e += 1;
    }
    (mant as u64, e)
}

/// `mant * 2^sh` rounded half even to an integer, capped at `cap`.
fn scale_round(mant: u128, sh: i32, cap: u128) -> u128 {
    if sh >= 0 {
        if bitlen(mant) as i32 + sh > bitlen(cap) as i32 {
            return cap;
        }
        (mant << sh as u32).min(cap)
    } else {
        let s = (-sh) as u32;
        if s >= 127 {
            return 0;
        }
        round_shift_right_sticky(mant, s, false, Rounding::HalfEven).min(cap)
    }
}

/// `cos a'` of the configured variant (module doc), `F = vector_frac_bits` of the inputs,
/// `P = out_frac_bits` (2..=30) of the result.
#[must_use]
pub fn rough_cos(
    inp: &RoughInput,
    cfg: &RoughnessConfig,
    vector_frac_bits: u32,
    out_frac_bits: u32,
    sat: &mut SatCounter,
) -> RoughOut {
    let (dv, t) = decode_d(inp.dch, inp.texel_bits, cfg);
    rough_cos_d(
        inp.cos_a,
        inp.d,
        dv,
        t,
        cfg,
        vector_frac_bits,
        out_frac_bits,
        sat,
    )
}

/// Largest magnitude of a raw D value entering [`rough_cos_d`] (larger values saturate,
/// counted): keeps every product of the datapath below 2^100.
pub const D_RAW_LIMIT: i64 = 1 << 20;

/// Scales decoded D (`t` fraction bits) by the frame lengths (`len_frac_bits`): `L D` with
/// `L = diag(len_u, len_v)` is again upper triangular and `(L D)(L D)^T = L K L`, the offset
/// covariance in tangent-plane units (the perturbation is `f_u len_u t_u + f_v len_v t_v`).
/// Rounded half even back to `t` fraction bits; magnitudes above [`D_RAW_LIMIT`] saturate
/// (counted). The isotropic lambda1 (channel 0) is scaled by `max(len_u, len_v)`.
///
/// ERROR BOUND: each entry within 1/2 LSB (`2^-(t+1)`) of the exact product, i.e. of the
/// float twin `texsim::shading::roughness::scale_d_f` on the same decoded D and lengths;
/// a saturated entry is exactly `+-D_RAW_LIMIT` and counts one saturation. Tested in
/// `tests/units/roughness_shade.rs` (2 M random D texels, range exponents, lengths over the whole
/// length format, `len_frac_bits` 4..16).
#[must_use]
pub fn scale_d(
    dv: [i64; 3],
    len: [i64; 2],
    len_frac_bits: u32,
    isotropic: bool,
    sat: &mut SatCounter,
) -> [i64; 3] {
    let lf = len_frac_bits.min(30);
    let (lu, lv) = (len[0].max(0), len[1].max(0));
    let ls = if isotropic {
        [lu.max(lv), lu, lv]
    } else {
        [lu, lu, lv]
    };
    let mut out = [0i64; 3];
    for i in 0..3 {
        let prod = i128::from(dv[i]) * i128::from(ls[i]);
        let r = if lf == 0 {
            prod
        } else {
            i128::from(round_shift_right_wide(prod, lf, Rounding::HalfEven))
        };
        let lim = i128::from(D_RAW_LIMIT);
        out[i] = if r > lim || r < -lim {
            sat.saturated += 1;
            r.clamp(-lim, lim) as i64
        } else {
            r as i64
        };
    }
    out
}

/// [`rough_cos`] on decoded D values `dv = [d1, d2, d3]` with `t` fraction bits (e.g. from
/// [`decode_d`] and [`scale_d`]); `c = cos a` and `d` in vector format (`F` fraction bits).
#[must_use]
#[allow(clippy::too_many_arguments)]
pub fn rough_cos_d(
    cos_a: i64,
    d: [i64; 2],
    dv: [i64; 3],
    t: u32,
    cfg: &RoughnessConfig,
    vector_frac_bits: u32,
    out_frac_bits: u32,
    sat: &mut SatCounter,
) -> RoughOut {
    let f = vector_frac_bits.clamp(1, 15);
    let p = out_frac_bits.clamp(2, 30);
    let one_f = 1i64 << f;
    let c = cos_a.clamp(0, one_f);
    let mut out = RoughOut {
        cos_mod: 0,
        d_zero: false,
        degenerate: false,
    };
    if cfg.rough_variant == RoughVariant::None {
        let shifted = if p >= f {
            c << (p - f)
        } else {
            round_shift_right_wide(i128::from(c), f - p, Rounding::HalfEven)
        };
        out.cos_mod = shifted as u64;
        return out;
    }
    if c == 0 {
        return out;
    }
    let x = d[0].clamp(-one_f, one_f);
    let y = d[1].clamp(-one_f, one_f);
    let dd = (x * x + y * y) as u128;
    if dd == 0 {
        out.d_zero = true;
        out.cos_mod = 1u64 << p;
        return out;
    }
    let lim = D_RAW_LIMIT;
    if dv.iter().any(|v| v.abs() > lim) {
        sat.saturated += 1;
    }
    let [d1, d2, d3] = dv.map(|v| v.clamp(-lim, lim));
    let (x, y, d1, d2, d3) = (
        i128::from(x),
        i128::from(y),
        i128::from(d1),
        i128::from(d2),
        i128::from(d3),
    );
    let sq = |v: i128| (v * v) as u128;
    // N / M has value (N / M) 2^sh.
    let (n, m, sh) = match cfg.rough_variant {
        RoughVariant::Published => (dd, sq(d1 * x + d2 * y) + sq(d3 * y), 2 * t as i32),
        RoughVariant::Directional => (dd, sq(d1 * x) + sq(d2 * x + d3 * y), 2 * t as i32),
        RoughVariant::Mahalanobis => (
            sq(d3 * x - d2 * y) + sq(d1 * y),
            sq(d1 * d3),
            2 * t as i32 - 2 * f as i32,
        ),
        RoughVariant::Isotropic | RoughVariant::None => (1, sq(d1), 2 * t as i32),
    };
    if m == 0 {
        sat.saturated += 1;
        out.degenerate = true;
        return out;
    }
    let (rm, re) = div_round(n, m, cfg.rough_div_bits);
    // Q with W = 4F + 8 fraction bits: lead (2F) * rm * 2^(re + sh) * 2^(2F + 8), `lead` = dd
    // (1.0 for Mahalanobis).
    let w = 4 * f + 8;
    let cap = 1u128 << (w + Q_CAP_BITS);
    let lead = if cfg.rough_variant == RoughVariant::Mahalanobis {
        1u128 << (2 * f)
    } else {
        dd
    };
    let q = scale_round(lead * u128::from(rm), re + sh + 2 * f as i32 + 8, cap);
    if q >= cap {
        sat.saturated += 1;
        out.degenerate = true;
        return out;
    }
    let s = q + ((c * c) as u128) * (1u128 << (2 * f + 8));
    let (sm, se) = sqrt_round(s, cfg.rough_sqrt_bits);
    // cos a' = (c 2^-F) / (sm 2^(se - W/2)).
    let (qm, qe) = div_round(c as u128, u128::from(sm), cfg.rough_div_bits);
    let shift = qe - f as i32 - se + (w / 2) as i32 + p as i32;
    out.cos_mod = scale_round(u128::from(qm), shift, 1u128 << p) as u64;
    out
}

/// `cos a'` raised to the mode's exponent `n` by the power unit (`P = pow_frac_bits`).
///
/// ERROR BOUND (absolute, against the float twin's `cos a'`, `c`, raised to `n` exactly on the
/// same quantized inputs): the power unit's own bound (`hw_model::pow`) at the unit's
/// `cos a'`, `c'`, plus the cosine's bound (module doc, `B`) carried through `x^n`:
/// `n B max(c, c')^(n-1)` (the mean value theorem on [0, 1]). Measured over 1M cases (every
/// variant, both power methods, exponents 1 to 2047) in
/// `tests/units/roughness_unit.rs::specular_meets_the_composed_bound`.
#[must_use]
pub fn rough_specular(
    inp: &RoughInput,
    cfg: &RoughnessConfig,
    vector_frac_bits: u32,
    material_exponent: u32,
    pow: &Pow,
    sat: &mut SatCounter,
) -> (u64, RoughOut) {
    let p = pow.config().pow_frac_bits;
    let o = rough_cos(inp, cfg, vector_frac_bits, p, sat);
    (pow.pow(o.cos_mod, cfg.exponent(material_exponent), sat), o)
}

/// Cycles of one divide or square root of `bits` result bits at `per_cycle` bits per cycle.
/// A digit-recurrence divider or square root of `bits` result bits retiring `per_cycle` bits
/// per step: `ceil(bits / per_cycle)` steps in series, each `per_cycle` subtract-and-select
/// slices of `bits + 2` bits (radix `2^per_cycle`).
fn recurrence(name: &'static str, bits: u32, per_cycle: u32) -> Stage {
    let k = per_cycle.max(1);
    let mut s = Stage::new(name);
    for _ in 0..k {
        s = s
            .then(Component::Adder { width: bits + 2 })
            .then(Component::Mux {
                width: bits + 2,
                inputs: 2,
            });
    }
    s.times(bits.div_ceil(k))
}

/// One multiplier stage of the unit (`rough_mul_cycles`): three `D x D` products side by
/// side and their sum.
fn mul_stage(cfg: &RoughnessConfig, n: u32) -> Stage {
    let d = cfg.rough_d_bits + 2;
    Stage::new("multiply")
        .then_n(3, Component::Multiplier { a: d, b: d })
        .then(Component::Adder { width: 2 * d + 2 })
        .times(n)
        .cycles(cfg.rough_mul_cycles)
}

/// The `cos a'` datapath of [`rough_cost`]: the multiplier stages (three; isotropic two), two
/// dividers of `rough_div_bits` and the square root of `rough_sqrt_bits` at their radix
/// (`rough_div_bits_per_cycle`, `rough_sqrt_bits_per_cycle`); empty for `none`.
#[must_use]
pub fn datapath(cfg: &RoughnessConfig) -> Datapath {
    let mul_stages = match cfg.rough_variant {
        RoughVariant::None => return Datapath::new(),
        RoughVariant::Isotropic => 2,
        RoughVariant::Published | RoughVariant::Directional | RoughVariant::Mahalanobis => 3,
    };
    Datapath::new()
        .stage(mul_stage(cfg, mul_stages))
        .stage(
            recurrence(
                "divide step",
                cfg.rough_div_bits,
                cfg.rough_div_bits_per_cycle,
            )
            .times(
                2 * cfg
                    .rough_div_bits
                    .div_ceil(cfg.rough_div_bits_per_cycle.max(1)),
            ),
        )
        .stage(recurrence(
            "square-root step",
            cfg.rough_sqrt_bits,
            cfg.rough_sqrt_bits_per_cycle,
        ))
}

/// [`rough_blinn_phong`]: Blinn-Phong, four dots, the D scaling (one multiplier stage), the
/// `cos a'` datapath and, with `rough_normalize`, two multiplier stages and one divider.
#[must_use]
pub fn shade_datapath(cfg: &RoughnessConfig, c: &crate::blinn_phong::ShadingConfig) -> Datapath {
    let mut d = crate::blinn_phong::datapath(c)
        .then(crate::vector::dot_datapath(&c.vector).times(4))
        .stage(mul_stage(cfg, 1))
        .then(datapath(cfg));
    if cfg.rough_normalize && cfg.rough_variant != RoughVariant::None {
        d = d.stage(mul_stage(cfg, 2)).stage(recurrence(
            "divide step",
            cfg.rough_div_bits,
            cfg.rough_div_bits_per_cycle,
        ));
    }
    d
}

/// Cost of one `cos a'` for the configured variant (excluding the power unit):
/// `none` is free; the others need `|d|^2` (2 mul, 1 add), `N`/`M` (published, directional,
/// Mahalanobis: 5 mul + 2 add; isotropic: 1 mul), two divides, `dd * N/M` and `cos^2 a`
/// (2 mul, 1 add) and one square root. Cycles: three multiplier stages (isotropic: two), the
/// two divides and the root at their radix.
#[must_use]
pub fn rough_cost(cfg: &RoughnessConfig, gate_levels_per_cycle: u32) -> UnitCost {
    let nm_ops = match cfg.rough_variant {
        RoughVariant::None => return UnitCost::default(),
        RoughVariant::Isotropic => 1,
        RoughVariant::Published | RoughVariant::Directional | RoughVariant::Mahalanobis => 7,
    };
    UnitCost {
        ops: 3 + nm_ops + 3 + 3,
        cycles: datapath(cfg).latency(gate_levels_per_cycle),
        texels: 0,
    }
}

/// Cost of [`rough_specular`]: [`rough_cost`] plus the power unit.
#[must_use]
pub fn rough_specular_cost(
    cfg: &RoughnessConfig,
    pow: &PowConfig,
    gate_levels_per_cycle: u32,
) -> UnitCost {
    rough_cost(cfg, gate_levels_per_cycle).plus(pow_cost(pow, gate_levels_per_cycle))
}

/// Inputs of [`rough_blinn_phong`] beyond the Blinn-Phong ones.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RoughShadeInput {
    /// The frame's unit tangents (vector format).
    pub t_u: Vec3x,
    pub t_v: Vec3x,
    /// D in tangent-plane units ([`scale_d`]), `t` fraction bits.
    pub dv: [i64; 3],
    pub t: u32,
}

/// Blinn-Phong with the modified specular term (Appendix A): as
/// [`crate::blinn_phong::blinn_phong`], with `n.h` replaced by `cos a'` of [`rough_cos_d`]
/// (`d = (h_t . t_u, h_t . t_v)`, `h_t = h - (n.h) n` the tangent-plane projection of `h`)
/// and the exponent of the configured mode (`inp.shininess` is the material's). The colour
/// ending is Blinn-Phong's ([`crate::blinn_phong::lit_color`]: unorm colours, raw `x` means
/// `x / (2^C - 1)`).
///
/// ERROR BOUND (absolute, per colour channel, against the float twin
/// `texsim::shading::roughness::rough_blinn_phong_f` on the same quantized `n`, `l`, `v`,
/// `t_u`, `t_v` and colours, with D the same texels decoded and scaled in float; `F`, `P`,
/// `C` the vector, power and colour fraction bits, `e` the mode's exponent, `x` the twin's
/// `cos a'`): `light (ks S + kd 2^-(F+1)) + 1/(2^C - 1)`, with the specular error
/// `S = E_pow(x_hi) + e x_hi^(e-1) Dx`, `x_hi = min(1, x + Dx)`, `E_pow` the power unit's
/// bound (`crate::pow` module doc) and `Dx = E_cos + E_in`:
/// - `E_cos`: the [`rough_cos`] bound (module doc); `none`: `2^-(P+1)`;
/// - `E_in`: how far the rounding of this unit's own inputs moves the twin's
///   `cos a' = (1 + u^2)^(-1/2)` (monotone in `u = tan a' = W / c`, with `W = |d|^2/|D^T d|`
///   directional, `|d|^2/|D d|` published, `|D^-1 d|` Mahalanobis, `|d|/d1` isotropic):
///   `cos'(u_lo) - cos'(u_hi)` over the range of `u` when `c = n.h` is off by
///   `dc = (sqrt(3) eps_h |n| + 1/2) 2^-F`, each component of `d` by
///   `dd = (sqrt(3) eps_h (|t| + |n| |n.t|) + |n.t|/2 + 3/2) 2^-F + dc 2^-F` and each D entry
///   by `2^-(t+1)` ([`scale_d`]); `eps_h` is [`crate::vector::normalize3`]'s per-component
///   bound in ulp (`rsqrt bound * 2^F + 1/2`, 0.607 at texram16); `none`: `E_in = dc`.
///
/// With `rough_normalize` (ignored for `none`) `S` becomes `f_hi S + x^e (f_hi - f_lo) +
/// 2^-(P+1)`, `[f_lo, f_hi]` the range of `min(1, (e/s) / (d1 d3))` with the divider's
/// `2^-div_bits` and D off by `2^-(t+1)` per entry (`[0, 1]` if `d1` or `d3 <= 2^-(t+1)`).
/// Within 1 ulp of `n.l = 0` the specular term may switch on or off (the whole term is
/// allowed); D saturated by [`scale_d`] (counted) is outside the bound. Measured in
/// `tests/units/roughness_shade.rs`: 1.2 M random cases over variants, normalization, exponent
/// modes, `F` 8..15, `P` 12..24, range exponents -4..4, divider and root widths, orthonormal
/// and sheared frames, lengths 0..16 and D texels; worst error / bound 0.995 (where the bound
/// exceeds 8 LSB; the diffuse `n.l` rounding term is what is tight).
#[must_use]
pub fn rough_blinn_phong(
    inp: &BlinnPhongInput,
    ri: &RoughShadeInput,
    cfg: &RoughnessConfig,
    units: &ShadingUnits,
    sat: &mut SatCounter,
) -> (BlinnPhongOut, RoughOut) {
    let vc = &units.cfg.vector;
    let f = vc.vector_frac_bits;
    let p = units.cfg.pow.pow_frac_bits.clamp(8, 24);
    let one_f = 1i64 << f;
    let ndl = dot3(&inp.n, &inp.l, vc, sat).clamp(0, one_f);
    let sum = [
        inp.l[0] + inp.v[0],
        inp.l[1] + inp.v[1],
        inp.l[2] + inp.v[2],
    ];
    let h_zero = sum == [0; 3];
    let mut ro = RoughOut {
        cos_mod: 0,
        d_zero: false,
        degenerate: false,
    };
    let spec: i64 = if h_zero || ndl == 0 {
        0
    } else {
        let h = normalize3(&sum, [0; 3], &units.rsqrt, vc, sat).v;
        let ndh = dot3(&inp.n, &h, vc, sat);
        let proj = |t: &Vec3x, sat: &mut SatCounter| {
            let ht = dot3(&h, t, vc, sat);
            let nt = dot3(&inp.n, t, vc, sat);
            ht - round_shift_right_wide(i128::from(ndh) * i128::from(nt), f, vc.vector_rounding)
        };
        let d = [proj(&ri.t_u, sat), proj(&ri.t_v, sat)];
        ro = rough_cos_d(ndh, d, ri.dv, ri.t, cfg, f, p, sat);
        let e = cfg.exponent(inp.shininess);
        let sp = units.pow.pow(ro.cos_mod, e, sat);
        if cfg.rough_normalize && cfg.rough_variant != RoughVariant::None {
            normalize_spec(sp, e, inp.shininess, ri, cfg) as i64
        } else {
            sp as i64
        }
    };
    let color = lit_color(inp, ndl, spec, units, sat);
    (BlinnPhongOut { color, h_zero }, ro)
}

/// The energy normalization of [`RoughnessConfig::rough_normalize`]: `spec * min(1, (e / s) /
/// (d1 d3))` with `d1 d3` from the scaled D (`t` fraction bits; isotropic `d1^2`), one divide
/// of `rough_div_bits` and one rounding (half even). `d1 d3 = 0` leaves `spec` unchanged.
///
/// ERROR BOUND (in LSBs of `spec`, against `spec min(1, (e/s)/(d1 d3))` of the same D in
/// float, `texsim::shading::roughness::normalize_factor`): `spec f 2^-div_bits + 1/2`, and
/// never above `spec`. Tested in `tests/units/roughness_unit.rs` (200 000 random cases per
/// variant).
#[must_use]
pub fn normalize_spec(
    spec: u64,
    exponent: u32,
    shininess: u32,
    ri: &RoughShadeInput,
    cfg: &RoughnessConfig,
) -> u64 {
    let lim = D_RAW_LIMIT;
    let d1 = ri.dv[0].clamp(0, lim) as u128;
    let d3 = if cfg.rough_variant == RoughVariant::Isotropic {
        d1
    } else {
        ri.dv[2].clamp(0, lim) as u128
    };
    let det = d1 * d3;
    if det == 0 || spec == 0 {
        return spec;
    }
    // (e / s) / (det 2^-2t) = e 2^2t / (s det).
    let t = ri.t.min(40);
    let (m, ex) = div_round(
        u128::from(exponent.max(1)) << (2 * t),
        u128::from(shininess.max(1)) * det,
        cfg.rough_div_bits,
    );
    scale_round(u128::from(spec) * u128::from(m), ex, u128::from(spec)) as u64
}

/// Cost of [`rough_blinn_phong`]: Blinn-Phong plus four dots and two multiply-subtracts for
/// `d`, the D scaling (3 multiplies) and [`rough_cost`].
#[must_use]
pub fn rough_blinn_phong_cost(
    cfg: &RoughnessConfig,
    units: &ShadingUnits,
    gate_levels_per_cycle: u32,
) -> UnitCost {
    let g = gate_levels_per_cycle;
    let mut c = blinn_phong_cost(units, g)
        .plus(dot_cost(&units.cfg.vector, g).times(4))
        .plus(UnitCost {
            ops: 5,
            cycles: 0,
            texels: 0,
        })
        .plus(rough_cost(cfg, g))
        .plus(
            if cfg.rough_normalize && cfg.rough_variant != RoughVariant::None {
                UnitCost {
                    ops: 3,
                    cycles: 0,
                    texels: 0,
                }
            } else {
                UnitCost::default()
            },
        );
    c.cycles = shade_datapath(cfg, &units.cfg).latency(g);
    c
}
