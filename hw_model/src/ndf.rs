//! NDF shading unit: Olano and North 1997, "Normal Distribution Mapping" (UNC TR97-041),
//! sections 5-6. A texel stores the 3D Gaussian of normal directions as nine linearly filterable
//! numbers (mean `mu`, second moments `E[x x^T]`), fetched by three unchanged trilinear lookups
//! (a fourth for the normalization map). Per pixel this unit computes
//! `Sigma = E[x x^T] - mu mu^T` (the paper prints `mu^T mu`; the covariance needs the outer
//! product), the Mahalanobis distance `d = (h - mu)^T Sigma^-1 (h - mu)` of the halfway vector
//! and the elliptically contoured density `g(d)`:
//! - `pearson`: Pearson Type II `g(t) = (1 - t/(2m))^m` for `t < 2m`, else 0. Both copies of
//!   the paper print the denominator as `2^m`; that form is `(1 - t/2^m)^m ~ exp(-t m/2^m)`,
//!   with m = 8 `(1 - t/256)^8 ~ exp(-t/32)`: `d` scaled down 16 times (a variance 16 times too
//!   large, a lobe 4 times too wide in angle), while `(1 - t/(2m))^m -> exp(-t/2)` as m grows
//!   (the Gaussian the paper says it approximates). `tests/units/ndf_unit.rs` checks both limits. m = 8 is three
//!   squarings.
//! - `gauss`: `exp(-t/2) = 2^(-t log2(e)/2)`: integer part by shift, fraction by a `2^f` table
//!   of `2^ndf_exp_lut_bits + 1` entries with linear interpolation.
//!
//! Normalization (`ndf_norm`): `partial` multiplies by `k3 / sqrt|Sigma|` with
//! `k3 = (2 pi)^-3/2` for either density (the paper's images; a 3D density, not a density on the
//! sphere); `map` multiplies by the trilinearly filtered normalization map `1/Z`
//! (`Z = integral of g(d) over the sphere`, pre-integrated per texel on the host), decoded as
//! `q / (2^B - 1) * 2^norm_exp`; `projected` re-approximates with the 2D Gaussian on the plane
//! tangent at `mu/|mu|`: `Sigma_p = P Sigma P + n n^T`, `y = P h`, normalized by
//! `k2 / sqrt|Sigma_p|` with `k2 = 1/(2 pi)` (gauss) or `(m+1)/(2 pi m)` (pearson, exact for the
//! 2D Pearson II). `exact` needs a numerical integral per pixel: float only, rejected by
//! [`NdfUnit::new`] with a `ConfigError` naming `ndf.ndf_norm`.
//!
//! Datapath (W = [`NDF_FRAC`] working fraction bits, F = `ndf_frac_bits`):
//! 1. Decode unorm `q` of `moment_bits` B: `mu = 2q/(2^B-1) - 1`, `E_ii = 2^k q/(2^B-1)`,
//!    `E_ij = 2^k (q/(2^B-1) - 1/2)` (k = `moment_scale_bits`), each by a constant division
//!    (a constant multiplier in hardware) rounded once to W bits.
//! 2. `Sigma` products rounded to W. GRACEFUL DEGRADATION: each diagonal is clamped to at least
//!    the minimum variance `2^-v` ([`NdfConfig::min_variance_bits`]; by default `v = B - 3`,
//!    tied to the moment quantization: a diagonal `E_ii - mu_i^2` computed from stored and
//!    trilinearly filtered channels errs by up to one LSB of `E_ii` (`2^k 2^-B`: half from the
//!    storage rounding, half from the filter's output rounding) plus `2 |mu_i|` times one LSB
//!    of `mu_i` (`2^(1-B)`), at most `(2^k + 4) 2^-B <= 2^(3-B)` for `k <= 2`; the storage half
//!    is checked in `tests/units/ndf_unit.rs`); each clamp is counted
//!    as a saturation. Below that floor the stored variance is quantization noise, so a lobe
//!    sharper than `s = 2^v` degrades to the floor's broader lobe instead of an arbitrarily
//!    sharp one. If a leading minor is then not positive (quantization made the matrix
//!    indefinite: rank-deficient grooves, `mu ~ 0`) the off-diagonals are dropped (a diagonal
//!    matrix with positive entries) and one more saturation is counted.
//! 3. Cofactors and determinant exact (i128). Adjugate block-normalized to `ndf_inverse_bits`
//!    significant bits (one shared exponent), determinant through the reciprocal unit.
//! 4. `d` rounded to F fraction bits, clamped to `[0, 2^DMAX_INT_BITS)` (`g` is 0 there at F <= 28
//!    bits for both densities, so the clamp is not counted).
//! 5. `g` with F fraction bits; normalization; the result `D` with F fraction bits in an `i64`,
//!    saturated (counted) at `2^62`. No NaN or infinity can arise (integers only).
//!
//! `h` with `h_z <= 0` (at or below the horizon of the tangent frame) gives `D = 0`.
//!
//! ERROR BOUND (texram16 widths, against the float twin `texsim::shading::ndf::eval_float` on
//! the same decoded texels, `tests/units/ndf_unit.rs`, 1.02M seeded cases over every option): `d`
//! within 1e-4 relative (measured 4.8e-5) where the float `d` is in (1e-3, 0.99 d_max) (a
//! relative error means little near 0, and `d` saturates at `d_max`; the density and `D`
//! bounds cover those cases); the density unit within 8 LSB of `2^-F` (measured
//! 6.8 Pearson, 1.5 Gauss; exhaustive over 2^23 inputs: 6.79 and 0.50); `D` within 5e-5 of the
//! texel's peak value where `g > 1e-3` (measured 3.1e-5). With narrow widths `d` can err by
//! `cond(Sigma) 2^-W'`; the density and `D` bounds then hold at 8 LSB and 5% of the peak.

use crate::config::{ConfigError, ReciprocalConfig};
use crate::cost::UnitCost;
use crate::datapath::{Component, Cycles, Datapath, Stage};
use crate::fixed::{round_div_i128, round_shift_right_wide, Rounding, SatCounter};
use crate::reciprocal::Reciprocal;
use crate::rsqrt::{isqrt_u128, range, rsqrt_cost, Rsqrt, RsqrtConfig};
use serde::{Deserialize, Serialize};

/// Working fraction bits of the decoded moments, `Sigma`, `h` and `h - mu`.
pub const NDF_FRAC: u32 = 32;
/// Integer bits of the clamped Mahalanobis distance.
pub const DMAX_INT_BITS: u32 = 7;
/// `log2(e) / 2` with 30 fraction bits.
pub const LOG2E_HALF_Q30: i64 = 774_541_002;
/// `(2 pi)^-3/2` with 30 fraction bits (partial normalization constant k3).
pub const K3_Q30: i64 = 68_175_772;
/// `1 / (2 pi)` with 30 fraction bits.
pub const INV_2PI_Q30: i64 = 170_891_319;
/// Saturation limit of the output `D` (raw).
pub const D_MAX_RAW: i64 = 1 << 62;

/// Elliptically contoured density `g`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum NdfDensity {
    /// Pearson Type II, `(1 - t/(2m))^m`.
    Pearson,
    /// `exp(-t/2)`.
    Gauss,
}

/// Normalization option.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum NdfNorm {
    /// `k3 / sqrt|Sigma|` (the paper's images).
    Partial,
    /// The pre-integrated normalization map (fourth lookup).
    Map,
    /// 2D Gaussian on the tangent plane at the mean direction.
    Projected,
    /// Numerical integral per pixel (float reference only).
    Exact,
}

/// NDF unit configuration (field names globally unique).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NdfConfig {
    /// Unorm bits of each of the nine moment channels (and of the normalization map). 4..=16.
    pub moment_bits: u32,
    /// Second moments are stored as `E / 2^k` (diagonal) and `1/2 + E / 2^k` (off-diagonal). 0..=2.
    /// Only this scale is configurable; the biases (`(mu + 1)/2` for the mean, `1/2` for the
    /// off-diagonals) are fixed. `k = 0` clamps `E_ii > 1` (every texel with `n_i^2 + 1/s > 1`,
    /// e.g. `E_zz` of a flat texel; counted by the map builder); `k = 1` covers `s >= 1`.
    pub moment_scale_bits: u32,
    /// Significant bits of the block-normalized adjugate. 4..=30.
    pub ndf_inverse_bits: u32,
    /// Smallest variance on the diagonal of `Sigma` is `2^-bits`. 4..=30, or 0: derived from
    /// the moment quantization, `moment_bits - 3` ([`NdfConfig::min_variance_bits`]).
    pub ndf_min_variance_bits: u32,
    /// Index bits of the `2^f` table of the Gaussian. 2..=12.
    pub ndf_exp_lut_bits: u32,
    /// Fraction bits of `d`, `g` and `D`. 12..=28.
    pub ndf_frac_bits: u32,
    /// Pearson Type II exponent m. 1..=64.
    pub pearson_m: u32,
    /// Density `g`.
    pub ndf_density: NdfDensity,
    /// Normalization option.
    pub ndf_norm: NdfNorm,
    /// Rounding of every reduction in the unit.
    pub ndf_rounding: Rounding,
    /// Cycles per multiply.
    pub ndf_mul_cycles: Cycles,
    /// Cycles per add, compare or shift.
    pub ndf_add_cycles: Cycles,
    /// Cycles per table lookup.
    pub ndf_lut_cycles: Cycles,
}

impl NdfConfig {
    /// Texram-style default: the paper's 16-bit moments, Pearson II with m = 8, partial
    /// normalization.
    #[must_use]
    pub fn texram16() -> Self {
        Self {
            moment_bits: 16,
            moment_scale_bits: 1,
            ndf_inverse_bits: 24,
            ndf_min_variance_bits: 0,
            ndf_exp_lut_bits: 10,
            ndf_frac_bits: 24,
            pearson_m: 8,
            ndf_density: NdfDensity::Pearson,
            ndf_norm: NdfNorm::Partial,
            ndf_rounding: Rounding::HalfEven,
            ndf_mul_cycles: Cycles::Derived,
            ndf_add_cycles: Cycles::Derived,
            ndf_lut_cycles: Cycles::Derived,
        }
    }

    /// Checks the widths; the error names the field. `exact` is allowed here (the float
    /// reference runs it); [`NdfUnit::new`] rejects it.
    pub fn validate(&self) -> Result<(), ConfigError> {
        range("ndf.moment_bits", self.moment_bits, 4, 16)?;
        range("ndf.moment_scale_bits", self.moment_scale_bits, 0, 2)?;
        range("ndf.ndf_inverse_bits", self.ndf_inverse_bits, 4, 30)?;
        if self.ndf_min_variance_bits != 0 {
            range(
                "ndf.ndf_min_variance_bits",
                self.ndf_min_variance_bits,
                4,
                30,
            )?;
        }
        range("ndf.ndf_exp_lut_bits", self.ndf_exp_lut_bits, 2, 12)?;
        range("ndf.ndf_frac_bits", self.ndf_frac_bits, 12, 28)?;
        range("ndf.pearson_m", self.pearson_m, 1, 64)?;
        Ok(())
    }
}

impl NdfConfig {
    /// The minimum variance of `Sigma`'s diagonal is `2^-min_variance_bits()`: the configured
    /// `ndf_min_variance_bits`, or for 0 the quantization floor `moment_bits - 3` (module doc,
    /// step 2), at least 1.
    #[must_use]
    pub fn min_variance_bits(&self) -> u32 {
        if self.ndf_min_variance_bits == 0 {
            self.moment_bits.saturating_sub(3).max(1)
        } else {
            self.ndf_min_variance_bits
        }
    }
}

impl Default for NdfConfig {
    fn default() -> Self {
        Self::texram16()
    }
}

/// Three (or four) filtered texels as the trilinear unit returns them, `moment_bits` unorm.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NdfTexels {
    /// `mu_x, mu_y, mu_z` in channels 0..3.
    pub mean: [u16; 4],
    /// `E_xx, E_yy, E_zz`.
    pub diag: [u16; 4],
    /// `E_xy, E_xz, E_yz`.
    pub off: [u16; 4],
    /// Normalization map `1/Z` in channel 0 (only read by `map`).
    pub norm: [u16; 4],
    /// Power-of-two scale of the normalization map: `1/Z = q/(2^B-1) * 2^norm_exp`. 0..=40.
    pub norm_exp: u32,
}

/// One evaluation's outputs (raw, F = `ndf_frac_bits` fraction bits).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NdfOut {
    /// The shaded NDF value `D`.
    pub d_value: i64,
    /// `g(d)` in `[0, 2^F]`.
    pub g: i64,
    /// The Mahalanobis distance `d` (clamped).
    pub dist: i64,
    /// The regularization dropped the off-diagonals (of `Sigma`, or of `Sigma_p` for
    /// `projected`).
    pub fallback: bool,
}

/// Result of the regularization (step 2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Regularized {
    /// The regularized `Sigma` (W bits, symmetric order).
    pub sigma: [i64; 6],
    /// Diagonal entries raised to the minimum variance (0..=3).
    pub clamped: u32,
    /// The off-diagonals were dropped (a leading minor was not positive).
    pub fallback: bool,
}

/// The unit with its reciprocal, rsqrt and `2^f` tables built.
#[derive(Clone, Debug)]
pub struct NdfUnit {
    cfg: NdfConfig,
    recip: Reciprocal,
    rsqrt: Rsqrt,
    /// `2^(j / 2^L)` with 30 fraction bits, j = 0..=2^L.
    exp_t: Vec<i64>,
}

fn bitlen(x: u128) -> u32 {
    128 - x.leading_zeros()
}

impl NdfUnit {
    /// Builds the unit from its config and the machine's reciprocal and rsqrt units. Rejects
    /// `ndf_norm = exact` (float only) and out-of-range widths.
    pub fn new(
        cfg: &NdfConfig,
        recip: &ReciprocalConfig,
        rsqrt: &RsqrtConfig,
    ) -> Result<Self, ConfigError> {
        cfg.validate()?;
        rsqrt.validate()?;
        if cfg.ndf_norm == NdfNorm::Exact {
            return Err(ConfigError {
                field: "ndf.ndf_norm".into(),
                what: "'exact' is a numerical integral per pixel: float reference only".into(),
            });
        }
        let l = cfg.ndf_exp_lut_bits;
        let one62 = 1u128 << 62;
        let mut roots = vec![0u128; l as usize + 1];
        roots[l as usize] = 2 * one62;
        for b in (0..l as usize).rev() {
            roots[b] = isqrt_u128(roots[b + 1] << 62);
        }
        let exp_t = (0..=(1usize << l))
            .map(|j| {
                let mut acc = one62;
                for (b, r) in roots.iter().enumerate() {
                    if (j >> b) & 1 == 1 {
                        acc = (acc * r) >> 62;
                    }
                }
                round_shift_right_wide(acc as i128, 32, Rounding::HalfEven)
            })
            .collect();
        Ok(Self {
            cfg: cfg.clone(),
            recip: Reciprocal::new(recip),
            rsqrt: Rsqrt::new(rsqrt),
            exp_t,
        })
    }

    /// The configuration in use.
    #[must_use]
    pub fn config(&self) -> &NdfConfig {
        &self.cfg
    }

    /// Decodes the nine moments to W fraction bits: `(mu, [Exx, Eyy, Ezz, Exy, Exz, Eyz])`.
    #[must_use]
    pub fn decode(&self, t: &NdfTexels) -> ([i64; 3], [i64; 6]) {
        let b = self.cfg.moment_bits;
        let k = self.cfg.moment_scale_bits;
        let rnd = self.cfg.ndf_rounding;
        let den = (1i128 << b) - 1;
        let mask = den as u16;
        let unorm = |q: u16, extra: u32| -> i128 { i128::from(q & mask) << (NDF_FRAC + extra) };
        let one = 1i128 << NDF_FRAC;
        let mut mu = [0i64; 3];
        let mut e = [0i64; 6];
        for i in 0..3 {
            mu[i] = (round_div_i128(unorm(t.mean[i], 1), den, rnd) - one) as i64;
            e[i] = round_div_i128(unorm(t.diag[i], k), den, rnd) as i64;
            e[3 + i] = (round_div_i128(unorm(t.off[i], k), den, rnd) - (one << k >> 1)) as i64;
        }
        (mu, e)
    }

    /// `Sigma = E - mu mu^T` (W bits), symmetric order `[xx, yy, zz, xy, xz, yz]`.
    #[must_use]
    pub fn covariance(&self, mu: &[i64; 3], e: &[i64; 6]) -> [i64; 6] {
        let rnd = self.cfg.ndf_rounding;
        let p =
            |a: i64, b: i64| round_shift_right_wide(i128::from(a) * i128::from(b), NDF_FRAC, rnd);
        [
            e[0] - p(mu[0], mu[0]),
            e[1] - p(mu[1], mu[1]),
            e[2] - p(mu[2], mu[2]),
            e[3] - p(mu[0], mu[1]),
            e[4] - p(mu[0], mu[2]),
            e[5] - p(mu[1], mu[2]),
        ]
    }

    /// Step 2 of the module doc: minimum variance and the positive-definite fallback; each
    /// clamped diagonal and the fallback are counted in `sat`.
    #[must_use]
    pub fn regularize(&self, s: &[i64; 6], sat: &mut SatCounter) -> [i64; 6] {
        let r = self.regularize_flags(s);
        sat.saturated += u64::from(r.clamped) + u64::from(r.fallback);
        r.sigma
    }

    /// Step 2 without counting: the regularized matrix, how many diagonals were clamped to the
    /// minimum variance and whether the off-diagonals were dropped.
    #[must_use]
    pub fn regularize_flags(&self, s: &[i64; 6]) -> Regularized {
        let vmin = 1i64 << (NDF_FRAC - self.cfg.min_variance_bits().min(NDF_FRAC));
        let mut r = *s;
        let mut clamped = 0;
        for v in r.iter_mut().take(3) {
            if *v < vmin {
                *v = vmin;
                clamped += 1;
            }
        }
        let (_, det) = cofactors(&r);
        let m2 = i128::from(r[0]) * i128::from(r[1]) - i128::from(r[3]) * i128::from(r[3]);
        let fallback = m2 <= 0 || det <= 0;
        if fallback {
            r[3] = 0;
            r[4] = 0;
            r[5] = 0;
        }
        Regularized {
            sigma: r,
            clamped,
            fallback,
        }
    }

    /// `d = v^T S^-1 v` with F fraction bits (clamped) for a regularized `S` and `v` (W bits),
    /// and `det(S)` exact (3W fraction bits). Input range (what [`NdfUnit::eval`] produces):
    /// `|S_ij| < 2^(W+2)` (moments decoded with `k <= 2`), `|v_i| <= 2^(W+1)`; then the
    /// cofactors stay below `2^(2W+5)`, `det` below `2^(3W+9)` and the quadratic form below
    /// `9 * 2^(I+2W+2)` (`I = ndf_inverse_bits`), all in `i128`; its product with the reciprocal
    /// mantissa is pre-shifted to stay below `2^126` (only at the widest settings, truncating
    /// bits far below the result's).
    #[must_use]
    pub fn mahalanobis(&self, s: &[i64; 6], v: &[i64; 3], sat: &mut SatCounter) -> (i64, i128) {
        let rnd = self.cfg.ndf_rounding;
        let f = self.cfg.ndf_frac_bits;
        let (cof, det) = cofactors(s);
        if det <= 0 {
            sat.saturated += 1;
            return (((1i64 << DMAX_INT_BITS) << f) - 1, 1);
        }
        let big = cof.iter().map(|c| c.unsigned_abs()).max().unwrap_or(0);
        let sh = bitlen(big).saturating_sub(self.cfg.ndf_inverse_bits);
        let a: [i128; 6] = cof.map(|c| i128::from(round_shift_right_wide(c, sh, rnd)));
        let v = v.map(i128::from);
        let q = a[0] * v[0] * v[0]
            + a[1] * v[1] * v[1]
            + a[2] * v[2] * v[2]
            + 2 * (a[3] * v[0] * v[1] + a[4] * v[0] * v[2] + a[5] * v[1] * v[2]);
        // det normalized to at most 62 bits for the reciprocal unit.
        let dsh = bitlen(det as u128).saturating_sub(62);
        let det_n = round_shift_right_wide(det, dsh, rnd).max(1) as u64;
        let r = self.recip.eval(det_n, sat);
        // d 2^F = q 2^sh mant 2^(F - W - dsh - shift).
        let e = sh as i32 + f as i32 - NDF_FRAC as i32 - dsh as i32 - r.shift;
        let q = q.max(0) >> 2;
        let pre = (bitlen(q as u128) + bitlen(u128::from(r.mant))).saturating_sub(126);
        let qm = (q >> pre) * i128::from(r.mant);
        let e = e + 2 + pre as i32;
        let dmax = ((1i64 << DMAX_INT_BITS) << f) - 1;
        let dist = if e >= 0 {
            if bitlen(qm as u128) + e as u32 > 62 {
                dmax
            } else {
                ((qm << e) as i64).min(dmax)
            }
        } else {
            round_shift_right_wide(qm, (-e) as u32, rnd).min(dmax)
        };
        (dist, det)
    }

    /// `g(d)` with F fraction bits for `d` with F fraction bits.
    #[must_use]
    pub fn density(&self, dist: i64) -> i64 {
        let f = self.cfg.ndf_frac_bits;
        let rnd = self.cfg.ndf_rounding;
        let one = 1i64 << f;
        match self.cfg.ndf_density {
            NdfDensity::Pearson => {
                let m = self.cfg.pearson_m;
                let t = one - round_div_i128(i128::from(dist), 2 * i128::from(m), rnd) as i64;
                if t <= 0 {
                    return 0;
                }
                // Square-and-multiply, each product rounded to F bits (m = 8: three squarings).
                let mut base = t;
                let mut acc = one;
                let mut n = m;
                while n > 0 {
                    if n & 1 == 1 {
                        acc = round_shift_right_wide(i128::from(acc) * i128::from(base), f, rnd);
                    }
                    n >>= 1;
                    if n > 0 {
                        base = round_shift_right_wide(i128::from(base) * i128::from(base), f, rnd);
                    }
                }
                acc
            }
            NdfDensity::Gauss => {
                // y = d log2(e)/2 with 30 fraction bits; g = 2^-y = 2^(1 - frac)/2 >> int.
                let y =
                    round_shift_right_wide(i128::from(dist) * i128::from(LOG2E_HALF_Q30), f, rnd);
                let n = y >> 30;
                if n > i64::from(f) + 1 {
                    return 0;
                }
                let fr = y & ((1i64 << 30) - 1);
                // 2^(1 - fr) = exp2 table at (2^30 - fr), in (1, 2].
                let x = (1i64 << 30) - fr;
                let l = self.cfg.ndf_exp_lut_bits;
                let idx = (x >> (30 - l)) as usize;
                let rem = x & ((1i64 << (30 - l)) - 1);
                let t0 = i128::from(self.exp_t[idx]);
                let t1 = i128::from(self.exp_t[(idx + 1).min(self.exp_t.len() - 1)]);
                let lerp = (t0 << (30 - l)) + (t1 - t0) * i128::from(rem);
                // lerp has 30 + (30 - l) fraction bits; halve and shift by n.
                round_shift_right_wide(lerp, 60 - l - f + 1 + n as u32, rnd)
            }
        }
    }

    /// `1/sqrt(det)` for `det` with 3W fraction bits (W even): `(mant, shift)` with
    /// `1/sqrt(det value) ~= mant 2^-shift`.
    fn inv_sqrt_det(&self, det: i128) -> (i64, i32) {
        let mut dsh = bitlen(det as u128).saturating_sub(62);
        dsh += dsh & 1;
        let x = round_shift_right_wide(det, dsh, self.cfg.ndf_rounding).max(1) as u64;
        match self.rsqrt.eval(x) {
            Some(r) => (
                r.mant as i64,
                r.shift + (dsh / 2) as i32 - (3 * NDF_FRAC / 2) as i32,
            ),
            None => (0, 0),
        }
    }

    /// `g * k * 1/sqrt(det)` as `D` with F bits (saturated, counted).
    fn scale_by(&self, g: i64, k_q30: i64, det: i128, sat: &mut SatCounter) -> i64 {
        let (mant, shift) = self.inv_sqrt_det(det);
        let prod = i128::from(g) * i128::from(k_q30) * i128::from(mant);
        let sh = shift + 30;
        let out = if sh >= 0 {
            round_shift_right_wide(prod, sh as u32, self.cfg.ndf_rounding)
        } else if bitlen(prod as u128) + (-sh) as u32 > 62 {
            D_MAX_RAW
        } else {
            (prod << (-sh)) as i64
        };
        if out >= D_MAX_RAW {
            sat.saturated += 1;
            return D_MAX_RAW;
        }
        out
    }

    /// The unit: filtered texels and the unit halfway vector `h` (W fraction bits, tangent
    /// space) to `D`.
    #[must_use]
    pub fn eval(&self, t: &NdfTexels, h: &[i64; 3], sat: &mut SatCounter) -> NdfOut {
        if h[2] <= 0 {
            return NdfOut::default();
        }
        // A unit `h` has components in [-1, 1]; anything outside is clamped (counted), which
        // bounds `h - mu` by 2 for the datapath's widths.
        let one = 1i64 << NDF_FRAC;
        if h.iter().any(|c| c.unsigned_abs() > one.unsigned_abs()) {
            sat.saturated += 1;
        }
        let h = &h.map(|c| c.clamp(-one, one));
        let rnd = self.cfg.ndf_rounding;
        let (mu, e) = self.decode(t);
        let sigma = self.covariance(&mu, &e);
        match self.cfg.ndf_norm {
            NdfNorm::Partial | NdfNorm::Map | NdfNorm::Exact => {
                let reg = self.regularize_flags(&sigma);
                sat.saturated += u64::from(reg.clamped) + u64::from(reg.fallback);
                let s = reg.sigma;
                let v = [h[0] - mu[0], h[1] - mu[1], h[2] - mu[2]];
                let (dist, det) = self.mahalanobis(&s, &v, sat);
                let g = self.density(dist);
                let d_value = if self.cfg.ndf_norm == NdfNorm::Map {
                    let b = self.cfg.moment_bits;
                    let den = (1i128 << b) - 1;
                    let q = i128::from(t.norm[0] & den as u16);
                    let n = round_div_i128((i128::from(g) * q) << t.norm_exp.min(40), den, rnd);
                    if n >= i128::from(D_MAX_RAW) {
                        sat.saturated += 1;
                        D_MAX_RAW
                    } else {
                        n as i64
                    }
                } else {
                    self.scale_by(g, K3_Q30, det, sat)
                };
                NdfOut {
                    d_value,
                    g,
                    dist,
                    fallback: reg.fallback,
                }
            }
            NdfNorm::Projected => {
                let n = self.mean_direction(&mu, sat);
                let p = |a: i64, b: i64| {
                    round_shift_right_wide(i128::from(a) * i128::from(b), NDF_FRAC, rnd)
                };
                let hn = p(h[0], n[0]) + p(h[1], n[1]) + p(h[2], n[2]);
                if hn <= 0 {
                    return NdfOut::default();
                }
                let reg = self.regularize_flags(&sigma);
                let sp = project(&reg.sigma, &n, rnd);
                let reg_p = self.regularize_flags(&sp);
                sat.saturated += u64::from(reg.clamped + reg_p.clamped)
                    + u64::from(reg.fallback)
                    + u64::from(reg_p.fallback);
                let sp = reg_p.sigma;
                let y = [h[0] - p(hn, n[0]), h[1] - p(hn, n[1]), h[2] - p(hn, n[2])];
                let (dist, det) = self.mahalanobis(&sp, &y, sat);
                let g = self.density(dist);
                let k2 = match self.cfg.ndf_density {
                    NdfDensity::Gauss => INV_2PI_Q30,
                    NdfDensity::Pearson => {
                        let m = i64::from(self.cfg.pearson_m);
                        round_div_i128(
                            i128::from(INV_2PI_Q30) * i128::from(m + 1),
                            i128::from(m),
                            rnd,
                        ) as i64
                    }
                };
                // det(Sigma_p) = det2 * 1: the same inverse square root.
                let d_value = self.scale_by(g, k2, det, sat);
                NdfOut {
                    d_value,
                    g,
                    dist,
                    fallback: reg.fallback || reg_p.fallback,
                }
            }
        }
    }

    /// `mu / |mu|` (W bits) through the rsqrt unit; `(0, 0, 1)` (counted) when `mu = 0`.
    #[must_use]
    pub fn mean_direction(&self, mu: &[i64; 3], sat: &mut SatCounter) -> [i64; 3] {
        let n2: i128 = mu.iter().map(|&m| i128::from(m) * i128::from(m)).sum();
        let mut dsh = bitlen(n2 as u128).saturating_sub(62);
        dsh += dsh & 1;
        let x = round_shift_right_wide(n2, dsh, self.cfg.ndf_rounding) as u64;
        match self.rsqrt.eval(x) {
            Some(r) if n2 > 0 => {
                // n raw = mu raw * mant * 2^(W - shift - dsh/2).
                let sh = r.shift + (dsh / 2) as i32 - NDF_FRAC as i32;
                mu.map(|m| {
                    let prod = i128::from(m) * i128::from(r.mant);
                    if sh >= 0 {
                        round_shift_right_wide(prod, sh as u32, self.cfg.ndf_rounding)
                    } else {
                        (prod << (-sh)) as i64
                    }
                })
            }
            _ => {
                sat.saturated += 1;
                [0, 0, 1i64 << NDF_FRAC]
            }
        }
    }
}

/// `P S P + n n^T` with `P = I - n n^T` (W bits), symmetric order.
#[must_use]
fn project(s: &[i64; 6], n: &[i64; 3], rnd: Rounding) -> [i64; 6] {
    let p = |a: i64, b: i64| round_shift_right_wide(i128::from(a) * i128::from(b), NDF_FRAC, rnd);
    let full = |i: usize, j: usize| -> i64 {
        match (i.min(j), i.max(j)) {
            (0, 0) => s[0],
            (1, 1) => s[1],
            (2, 2) => s[2],
            (0, 1) => s[3],
            (0, 2) => s[4],
            _ => s[5],
        }
    };
    let a: [i64; 3] = [0, 1, 2].map(|i| (0..3).map(|j| p(full(i, j), n[j])).sum());
    let c: i64 = (0..3).map(|i| p(n[i], a[i])).sum();
    let c1 = c + (1i64 << NDF_FRAC);
    let entry = |i: usize, j: usize| -> i64 {
        full(i, j) - p(n[i], a[j]) - p(a[i], n[j]) + p(c1, p(n[i], n[j]))
    };
    [
        entry(0, 0),
        entry(1, 1),
        entry(2, 2),
        entry(0, 1),
        entry(0, 2),
        entry(1, 2),
    ]
}

/// Exact cofactors `[c00, c11, c22, c01, c02, c12]` (2W bits) and determinant (3W bits).
#[must_use]
pub fn cofactors(s: &[i64; 6]) -> ([i128; 6], i128) {
    let [a, b, c, d, e, f] = s.map(i128::from);
    // S = [[a d e], [d b f], [e f c]].
    let c00 = b * c - f * f;
    let c11 = a * c - e * e;
    let c22 = a * b - d * d;
    let c01 = e * f - d * c;
    let c02 = d * f - b * e;
    let c12 = d * e - a * f;
    let det = a * c00 + d * c01 + e * c02;
    ([c00, c11, c22, c01, c02, c12], det)
}

/// Texture lookups per pixel: 3 RGB moment maps, plus the normalization map for `map`.
#[must_use]
pub fn ndf_lookups(cfg: &NdfConfig) -> u32 {
    if cfg.ndf_norm == NdfNorm::Map {
        4
    } else {
        3
    }
}

/// Cost of one evaluation, excluding the trilinear lookups themselves; `texels` counts their
/// fetches (8 per trilinear lookup) so the filter cost can be added as
/// `ndf_lookups x trilinear_cost`. Ops: decode 9, Sigma 12, clamp/minors 6, cofactors and
/// determinant 23, adjugate normalization 7, quadratic form 17, reciprocal, scale 2;
/// density: Pearson 2 + 2 log2(m) (m = 8: three squarings), Gauss 7 (table, lerp, shift);
/// partial 3 + rsqrt, map 2, projected 40 + 2 rsqrt. `None` for `exact`: a numerical integral
/// over the sphere per pixel has no datapath here (float only), so it has no cost to report.
#[must_use]
pub fn ndf_cost(
    cfg: &NdfConfig,
    recip: &UnitCost,
    rsqrt: &RsqrtConfig,
    gate_levels_per_cycle: u32,
) -> Option<UnitCost> {
    let (mul, add, lut) = op_counts(cfg)?;
    let core = core_datapath(cfg, rsqrt)?;
    let rs = rsqrt_cost(rsqrt, gate_levels_per_cycle);
    let n_rs = match cfg.ndf_norm {
        NdfNorm::Partial => 1,
        NdfNorm::Projected => 2,
        NdfNorm::Map | NdfNorm::Exact => 0,
    };
    Some(
        UnitCost {
            ops: mul + add + lut + n_rs * rs.ops,
            cycles: core.latency(gate_levels_per_cycle),
            texels: 8 * ndf_lookups(cfg),
        }
        .plus(*recip),
    )
}

/// Multiplies, adds and table lookups of one evaluation (see [`ndf_cost`]); `None` for
/// `exact`.
fn op_counts(cfg: &NdfConfig) -> Option<(u32, u32, u32)> {
    let mut mul = 9 + 6 + 2 + 15 + 3 + 12 + 1;
    let mut add = 6 + 4 + 8 + 7 + 11 + 1;
    let mut lut = 0;
    match cfg.ndf_density {
        NdfDensity::Pearson => {
            let m = cfg.pearson_m.max(1);
            let sq = 31 - m.leading_zeros();
            mul += 1 + sq + m.count_ones() - 1;
            add += 1;
        }
        NdfDensity::Gauss => {
            mul += 2;
            add += 4;
            lut += 1;
        }
    }
    match cfg.ndf_norm {
        NdfNorm::Exact => return None,
        NdfNorm::Partial => {
            mul += 2;
            add += 1;
        }
        NdfNorm::Map => {
            mul += 2;
        }
        NdfNorm::Projected => {
            mul += 3 + 9 + 3 + 6 * 3 + 3;
            add += 2 + 6 + 2 + 18 + 3;
        }
    }
    Some((mul, add, lut))
}

/// The NDF unit without its reciprocal (N = `ndf_frac_bits`): its multiplies in series
/// (`ndf_mul_cycles` each; `N + 2`-bit operands), its adds (`ndf_add_cycles`), the exp table
/// of the Gauss density (`ndf_lut_cycles`) and the rsqrt units of the normalization.
fn core_datapath(cfg: &NdfConfig, rsqrt: &RsqrtConfig) -> Option<Datapath> {
    let (mul, add, lut) = op_counts(cfg)?;
    let w = cfg.ndf_frac_bits + 2;
    let mut d = Datapath::new()
        .stage(
            Stage::new("multiply")
                .then(Component::Multiplier { a: w, b: w })
                .times(mul)
                .cycles(cfg.ndf_mul_cycles),
        )
        .stage(
            Stage::new("add")
                .then(Component::Adder { width: w + 2 })
                .times(add)
                .cycles(cfg.ndf_add_cycles),
        )
        .stage(
            Stage::new("exp table")
                .then(Component::Rom {
                    addr_bits: cfg.ndf_exp_lut_bits,
                    data_bits: w,
                })
                .times(lut)
                .cycles(cfg.ndf_lut_cycles),
        );
    let n_rs = match cfg.ndf_norm {
        NdfNorm::Partial => 1,
        NdfNorm::Projected => 2,
        NdfNorm::Map | NdfNorm::Exact => 0,
    };
    for _ in 0..n_rs {
        d = d.then(crate::rsqrt::datapath(rsqrt));
    }
    Some(d)
}

/// The NDF unit: its multiplies, adds, exp table and rsqrt units, then its reciprocal; `None`
/// for `exact` (float only).
#[must_use]
pub fn datapath(
    cfg: &NdfConfig,
    recip: &ReciprocalConfig,
    rsqrt: &RsqrtConfig,
) -> Option<Datapath> {
    Some(core_datapath(cfg, rsqrt)?.then(crate::reciprocal::datapath(recip)))
}
