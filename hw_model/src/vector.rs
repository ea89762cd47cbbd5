//! Fixed-point 3-vector unit: dot, cross, normalize and the bump multiply-add
//! `n' = n + g_u t_u + g_v t_v` (Schilling 1997, eq. `n' = n + f_u s_u + f_v s_v`).
//!
//! Formats (all saturating, every clamp counted in the [`SatCounter`]):
//! - vector: signed, 1 integer bit, `F = vector_frac_bits` fraction bits (unit vectors and
//!   their components lie in `[-1, 1]`; +1.0 is representable);
//! - offset: signed, `offset_int_bits` integer bits, `offset_frac_bits` fraction bits (the
//!   bump offsets `f_u, f_v` and the natural frame's scaled offsets);
//! - wide: signed, `offset_int_bits + 2` integer bits, `F` fraction bits (the unnormalized
//!   perturbed normal).
//!
//! Products are exact (`i64`/`i128`); each output is rounded once by `vector_rounding`.

use crate::config::ConfigError;
use crate::cost::UnitCost;
use crate::datapath::{Component, Cycles, Datapath, Stage};
use crate::fixed::{
    round_shift_right, round_shift_right_wide, ConstRounding, Format, Rounding, SatCounter,
    ShiftRound,
};
use crate::rsqrt::{range, Rsqrt};
use serde::{Deserialize, Serialize};

/// A 3-vector of raw fixed-point components (format given by context, usually vector format).
pub type Vec3x = [i64; 3];

/// Vector unit configuration.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VectorConfig {
    /// Fraction bits of vector components (signed 1.F). 4..=15.
    pub vector_frac_bits: u32,
    /// Fraction bits of bump offsets `f_u, f_v`. 4..=16.
    pub offset_frac_bits: u32,
    /// Integer bits (plus sign) of bump offsets. 0..=8.
    pub offset_int_bits: u32,
    /// Rounding of every vector-unit output.
    pub vector_rounding: Rounding,
    /// Cycles of one dot product (3 multiplies, 2 adds).
    pub dot_cycles: Cycles,
    /// Cycles of one cross product (6 multiplies, 3 subtracts).
    pub cross_cycles: Cycles,
    /// Cycles of the final scale in a normalize (3 multiplies), excluding dot and rsqrt.
    pub normalize_scale_cycles: Cycles,
    /// Cycles of the bump multiply-add (6 multiplies, 6 adds).
    pub madd_cycles: Cycles,
}

impl VectorConfig {
    /// Texram-style default: 16-bit components (s1.14), offsets s3.12.
    #[must_use]
    pub fn texram16() -> Self {
        Self {
            vector_frac_bits: 14,
            offset_frac_bits: 12,
            offset_int_bits: 3,
            vector_rounding: Rounding::HalfEven,
            dot_cycles: Cycles::Derived,
            cross_cycles: Cycles::Derived,
            normalize_scale_cycles: Cycles::Derived,
            madd_cycles: Cycles::Derived,
        }
    }

    /// Checks the widths; the error names the field.
    pub fn validate(&self) -> Result<(), ConfigError> {
        range("vector.vector_frac_bits", self.vector_frac_bits, 4, 15)?;
        range("vector.offset_frac_bits", self.offset_frac_bits, 4, 16)?;
        range("vector.offset_int_bits", self.offset_int_bits, 0, 8)?;
        Ok(())
    }
}

/// The vector component format: signed 1.F, saturating.
#[must_use]
pub fn vector_format(cfg: &VectorConfig) -> Format {
    Format::signed(1, cfg.vector_frac_bits, cfg.vector_rounding)
}

/// The bump offset format: signed `offset_int_bits`.`offset_frac_bits`, saturating.
#[must_use]
pub fn offset_format(cfg: &VectorConfig) -> Format {
    Format::signed(
        cfg.offset_int_bits,
        cfg.offset_frac_bits,
        cfg.vector_rounding,
    )
}

/// The unnormalized perturbed-normal format: signed (offset_int_bits+2).F, saturating.
#[must_use]
pub fn wide_format(cfg: &VectorConfig) -> Format {
    Format::signed(
        cfg.offset_int_bits + 2,
        cfg.vector_frac_bits,
        cfg.vector_rounding,
    )
}

/// Exact dot product of raw vectors (fraction bits add).
#[must_use]
pub fn dot3_exact(a: &Vec3x, b: &Vec3x) -> i128 {
    (0..3).map(|i| i128::from(a[i]) * i128::from(b[i])).sum()
}

/// Dot product of two vector-format vectors, rounded once to vector format.
/// ERROR: at most 1/2 ulp (2^-(F+1)) from the exact dot of the inputs, unless saturated.
#[must_use]
pub fn dot3(a: &Vec3x, b: &Vec3x, cfg: &VectorConfig, sat: &mut SatCounter) -> i64 {
    let f = cfg.vector_frac_bits;
    let r = match dot3_narrow(a, b) {
        Some(d) => round_shift_right(d, f, cfg.vector_rounding),
        None => round_shift_right_wide(dot3_exact(a, b), f, cfg.vector_rounding),
    };
    vector_format(cfg).fit(r, sat)
}

/// [`dot3_exact`] when its products and sums fit `i64` (always for vector- and wide-format
/// inputs, below 2^26), else `None`. `round_shift_right` of an `i64` is
/// `round_shift_right_wide` of the same value, so the units reduce it in 64 bits with the
/// same result (checked against the 128-bit forms by
/// `narrow_dot_cross_madd_match_the_wide_forms`).
#[inline(always)]
fn dot3_narrow(a: &Vec3x, b: &Vec3x) -> Option<i64> {
    a[0].checked_mul(b[0])?
        .checked_add(a[1].checked_mul(b[1])?)?
        .checked_add(a[2].checked_mul(b[2])?)
}

/// `x y - z w` when it fits `i64` with its products, else `None`.
#[inline(always)]
fn cross_term(x: i64, y: i64, z: i64, w: i64) -> Option<i64> {
    x.checked_mul(y)?.checked_sub(z.checked_mul(w)?)
}

/// Exact cross product of raw vectors (fraction bits add); inputs must be below 2^31 in
/// magnitude (vector and wide formats are).
#[must_use]
pub fn cross3_exact(a: &Vec3x, b: &Vec3x) -> [i128; 3] {
    let m = |x: i64, y: i64| i128::from(x) * i128::from(y);
    [
        m(a[1], b[2]) - m(a[2], b[1]),
        m(a[2], b[0]) - m(a[0], b[2]),
        m(a[0], b[1]) - m(a[1], b[0]),
    ]
}

/// Cross product of two vector-format vectors, each component rounded once to vector format.
/// ERROR: at most 1/2 ulp per component from the exact cross product, unless saturated.
#[must_use]
pub fn cross3(a: &Vec3x, b: &Vec3x, cfg: &VectorConfig, sat: &mut SatCounter) -> Vec3x {
    let (f, mode) = (cfg.vector_frac_bits, cfg.vector_rounding);
    let fmt = vector_format(cfg);
    let narrow = (|| {
        Some([
            cross_term(a[1], b[2], a[2], b[1])?,
            cross_term(a[2], b[0], a[0], b[2])?,
            cross_term(a[0], b[1], a[1], b[0])?,
        ])
    })();
    let r = match narrow {
        Some(c) => c.map(|c| round_shift_right(c, f, mode)),
        None => cross3_exact(a, b).map(|c| round_shift_right_wide(c, f, mode)),
    };
    r.map(|r| fmt.fit(r, sat))
}

/// Result of a normalization.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Normalized {
    /// The unit vector in vector format (or the fallback).
    pub v: Vec3x,
    /// True if the input had zero length and `v` is the caller's fallback.
    pub zero: bool,
}

/// `v / |v|` for raw components of any binary scale (the result does not depend on it) and
/// magnitude below 2^62,
/// result in vector format: `|v|^2` exact (u128), reduced by an even shift (truncating) to at
/// most 62 bits, `1/sqrt` by the [`Rsqrt`] unit, one rounding per output component.
///
/// Zero length: returns `fallback` with `zero = true` and counts one saturation event.
///
/// ERROR BOUND per component, against the exact `v/|v|` of the given raw input:
/// `rsqrt relative error + 2^-(F+1)` (texram16: 0.607 ulp of s1.14; measured 0.577 ulp over
/// 1M random inputs of 1..40-bit components in `tests/units/frames_vector.rs`).
#[must_use]
pub fn normalize3(
    v: &[i64; 3],
    fallback: Vec3x,
    rsqrt: &Rsqrt,
    cfg: &VectorConfig,
    sat: &mut SatCounter,
) -> Normalized {
    crate::with_rounding!(cfg.vector_rounding, M => {
        normalize3_in::<M>(v, fallback, rsqrt, cfg, sat)
    })
}

/// [`normalize3`] compiled for the rounding mode `M` (`vector_rounding`). Components below
/// 2^31 (vector and wide formats always) take 64-bit arithmetic: their squares' sum fits
/// `u64` (3 * 2^62 < 2^64) and their products with the rsqrt mantissa (at most 2^30) stay
/// below 2^62, reduced by one [`ShiftRound`] resolved per call; larger ones the 128-bit forms.
/// The same bits either way (`narrow_normalize_matches_the_wide_form`).
#[inline(always)]
fn normalize3_in<M: ConstRounding>(
    v: &[i64; 3],
    fallback: Vec3x,
    rsqrt: &Rsqrt,
    cfg: &VectorConfig,
    sat: &mut SatCounter,
) -> Normalized {
    let small = (v[0].unsigned_abs() | v[1].unsigned_abs() | v[2].unsigned_abs()) >> 31 == 0;
    let s: u128 = if small {
        let sq = |c: i64| c.unsigned_abs() * c.unsigned_abs();
        u128::from(sq(v[0]) + sq(v[1]) + sq(v[2]))
    } else {
        v.iter()
            .map(|&c| (i128::from(c) * i128::from(c)) as u128)
            .sum()
    };
    if s == 0 {
        sat.saturated += 1;
        return Normalized {
            v: fallback,
            zero: true,
        };
    }
    let bits = 128 - s.leading_zeros();
    let j = if bits > 62 {
        (bits - 62).div_ceil(2)
    } else {
        0
    };
    let s_red = (s >> (2 * j)) as u64;
    let Some(r) = rsqrt.eval(s_red) else {
        sat.saturated += 1;
        return Normalized {
            v: fallback,
            zero: true,
        };
    };
    // 1/sqrt(s) = mant * 2^-(shift + j), so out_raw = v_raw * mant * 2^(F - j - shift).
    let f = cfg.vector_frac_bits as i32;
    let rshift = j as i32 + r.shift - f;
    let fmt = vector_format(cfg);
    let scale = u32::try_from(rshift)
        .ok()
        .and_then(ShiftRound::<M>::new)
        .filter(|_| small && r.mant >> 31 == 0);
    let out = match scale {
        Some(round) => v.map(|c| fmt.fit(round.apply(c * r.mant as i64), sat)),
        None => v.map(|c| {
            let p = i128::from(c) * i128::from(r.mant);
            let q = if rshift >= 0 {
                round_shift_right_wide(p, rshift as u32, M::MODE)
            } else {
                i64::try_from(p << (-rshift).min(64) as u32).unwrap_or(i64::MAX)
            };
            fmt.fit(q, sat)
        }),
    };
    Normalized {
        v: out,
        zero: false,
    }
}

/// Bump multiply-add `n + g_u t_u + g_v t_v`: `n`, `t_u`, `t_v` in vector format, `g_u`, `g_v`
/// in offset format; exact sum, one rounding to wide format (saturating, counted).
/// ERROR: at most 1/2 ulp per component, unless saturated.
#[must_use]
pub fn madd(
    n: &Vec3x,
    t_u: &Vec3x,
    t_v: &Vec3x,
    g_u: i64,
    g_v: i64,
    cfg: &VectorConfig,
    sat: &mut SatCounter,
) -> [i64; 3] {
    let o = cfg.offset_frac_bits;
    let fmt = wide_format(cfg);
    let mut out = [0i64; 3];
    for i in 0..3 {
        let narrow = (|| {
            let n = n[i].checked_mul((o < 62).then(|| 1i64 << o)?)?;
            n.checked_add(g_u.checked_mul(t_u[i])?)?
                .checked_add(g_v.checked_mul(t_v[i])?)
        })();
        let r = match narrow {
            Some(acc) => round_shift_right(acc, o, cfg.vector_rounding),
            None => {
                let acc = (i128::from(n[i]) << o)
                    + i128::from(g_u) * i128::from(t_u[i])
                    + i128::from(g_v) * i128::from(t_v[i]);
                round_shift_right_wide(acc, o, cfg.vector_rounding)
            }
        };
        out[i] = fmt.fit(r, sat);
    }
    out
}

/// Cost of one dot product; cycles from [`dot_datapath`].
#[must_use]
pub fn dot_cost(cfg: &VectorConfig, gate_levels_per_cycle: u32) -> UnitCost {
    UnitCost {
        ops: 5,
        cycles: dot_datapath(cfg).latency(gate_levels_per_cycle),
        texels: 0,
    }
}

/// Cost of one cross product; cycles from [`cross_datapath`].
#[must_use]
pub fn cross_cost(cfg: &VectorConfig, gate_levels_per_cycle: u32) -> UnitCost {
    UnitCost {
        ops: 9,
        cycles: cross_datapath(cfg).latency(gate_levels_per_cycle),
        texels: 0,
    }
}

/// Cost of one normalize: dot (|v|^2), rsqrt, three scaling multiplies (the stages of
/// [`normalize_datapath`]).
#[must_use]
pub fn normalize_cost(
    cfg: &VectorConfig,
    rsqrt_cost: UnitCost,
    gate_levels_per_cycle: u32,
) -> UnitCost {
    dot_cost(cfg, gate_levels_per_cycle)
        .plus(rsqrt_cost)
        .plus(UnitCost {
            ops: 3,
            cycles: scale_datapath(cfg).latency(gate_levels_per_cycle),
            texels: 0,
        })
}

/// Cost of one bump multiply-add; cycles from [`madd_datapath`].
#[must_use]
pub fn madd_cost(cfg: &VectorConfig, gate_levels_per_cycle: u32) -> UnitCost {
    UnitCost {
        ops: 12,
        cycles: madd_datapath(cfg).latency(gate_levels_per_cycle),
        texels: 0,
    }
}

/// Width of a vector component: sign, one integer bit, `vector_frac_bits`.
fn vw(cfg: &VectorConfig) -> u32 {
    cfg.vector_frac_bits + 2
}

/// A dot product (`dot_cycles`): three products side by side, two adds, the rounding.
#[must_use]
pub fn dot_datapath(cfg: &VectorConfig) -> Datapath {
    let v = vw(cfg);
    Datapath::new().stage(
        Stage::new("dot")
            .then_n(3, Component::Multiplier { a: v, b: v })
            .then(Component::Adder { width: 2 * v + 1 })
            .then(Component::Adder { width: 2 * v + 2 })
            .then(Component::Adder { width: v + 2 })
            .cycles(cfg.dot_cycles),
    )
}

/// A cross product (`cross_cycles`): six products side by side, three subtracts, the rounding.
#[must_use]
pub fn cross_datapath(cfg: &VectorConfig) -> Datapath {
    let v = vw(cfg);
    Datapath::new().stage(
        Stage::new("cross")
            .then_n(6, Component::Multiplier { a: v, b: v })
            .then_n(3, Component::Adder { width: 2 * v + 1 })
            .then_n(3, Component::Adder { width: v + 1 })
            .cycles(cfg.cross_cycles),
    )
}

/// The normalizer's scaling (`normalize_scale_cycles`): three products by `1/|v|`, rounding.
#[must_use]
pub fn scale_datapath(cfg: &VectorConfig) -> Datapath {
    let v = vw(cfg);
    Datapath::new().stage(
        Stage::new("scale by rsqrt")
            .then_n(3, Component::Multiplier { a: v, b: v + 2 })
            .then_n(3, Component::Adder { width: v + 1 })
            .then(Component::Register { bits: 3 * v })
            .cycles(cfg.normalize_scale_cycles),
    )
}

/// A normalize: [`dot_datapath`] (`|v|^2`), the rsqrt unit, [`scale_datapath`].
#[must_use]
pub fn normalize_datapath(cfg: &VectorConfig, rsqrt: &crate::rsqrt::RsqrtConfig) -> Datapath {
    dot_datapath(cfg)
        .then(crate::rsqrt::datapath(rsqrt))
        .then(scale_datapath(cfg))
}

/// The bump multiply-add `n + f_u t_u + f_v t_v` (`madd_cycles`; O = offset width): six
/// products side by side, two adds per component, the rounding.
#[must_use]
pub fn madd_datapath(cfg: &VectorConfig) -> Datapath {
    let v = vw(cfg);
    let o = cfg.offset_frac_bits + cfg.offset_int_bits + 1;
    Datapath::new().stage(
        Stage::new("multiply-add")
            .then_n(6, Component::Multiplier { a: v, b: o })
            .then_n(3, Component::Adder { width: v + o + 1 })
            .then_n(3, Component::Adder { width: v + o + 2 })
            .then_n(3, Component::Adder { width: v + 1 })
            .cycles(cfg.madd_cycles),
    )
}

/// Decodes a filtered offset texel (unsigned, `texel_bits` bits, value `t / 2^texel_bits`)
/// stored with bias 1/2 and range `R = 2^offset_int_bits` (`f = (t/2^bits - 1/2) * 2R`, the
/// encoding of `texsim::shading::bump`) into offset format, rounded once, saturating.
/// For texram16 (16-bit texels, s3.12 offsets) this is exactly `t - 2^15`.
#[must_use]
pub fn offset_from_texel(t: u64, texel_bits: u32, cfg: &VectorConfig, sat: &mut SatCounter) -> i64 {
    let bits = texel_bits.clamp(1, 32);
    let centered = i64::try_from(t.min(u64::from(u32::MAX))).unwrap_or(0) - (1i64 << (bits - 1));
    // f_raw = centered * 2^(I + 1 + O - bits)
    let sh = cfg.offset_int_bits as i32 + 1 + cfg.offset_frac_bits as i32 - bits as i32;
    let raw = if sh >= 0 {
        centered << sh
    } else {
        round_shift_right_wide(i128::from(centered), (-sh) as u32, cfg.vector_rounding)
    };
    offset_format(cfg).fit(raw, sat)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rsqrt::RsqrtConfig;
    use crate::test_rng::splitmix64 as next;

    const MODES: [Rounding; 3] = [Rounding::Truncate, Rounding::HalfUp, Rounding::HalfEven];

    /// [`dot3`] as first written (the exact dot in `i128`): the oracle.
    fn dot3_before(a: &Vec3x, b: &Vec3x, cfg: &VectorConfig, sat: &mut SatCounter) -> i64 {
        let r = round_shift_right_wide(dot3_exact(a, b), cfg.vector_frac_bits, cfg.vector_rounding);
        vector_format(cfg).fit(r, sat)
    }

    /// [`cross3`] as first written.
    fn cross3_before(a: &Vec3x, b: &Vec3x, cfg: &VectorConfig, sat: &mut SatCounter) -> Vec3x {
        let fmt = vector_format(cfg);
        cross3_exact(a, b).map(|c| {
            fmt.fit(
                round_shift_right_wide(c, cfg.vector_frac_bits, cfg.vector_rounding),
                sat,
            )
        })
    }

    /// [`madd`] as first written.
    fn madd_before(
        n: &Vec3x,
        t_u: &Vec3x,
        t_v: &Vec3x,
        (g_u, g_v): (i64, i64),
        cfg: &VectorConfig,
        sat: &mut SatCounter,
    ) -> [i64; 3] {
        let o = cfg.offset_frac_bits;
        let fmt = wide_format(cfg);
        [0, 1, 2].map(|i| {
            let acc = (i128::from(n[i]) << o)
                + i128::from(g_u) * i128::from(t_u[i])
                + i128::from(g_v) * i128::from(t_v[i]);
            fmt.fit(round_shift_right_wide(acc, o, cfg.vector_rounding), sat)
        })
    }

    /// [`normalize3`] as first written (`|v|^2` and the scaling products in `i128`).
    fn normalize3_before(
        v: &[i64; 3],
        fallback: Vec3x,
        rsqrt: &Rsqrt,
        cfg: &VectorConfig,
        sat: &mut SatCounter,
    ) -> Normalized {
        let s: u128 = v
            .iter()
            .map(|&c| (i128::from(c) * i128::from(c)) as u128)
            .sum();
        let zero = Normalized {
            v: fallback,
            zero: true,
        };
        if s == 0 {
            sat.saturated += 1;
            return zero;
        }
        let bits = 128 - s.leading_zeros();
        let j = if bits > 62 {
            (bits - 62).div_ceil(2)
        } else {
            0
        };
        let Some(r) = rsqrt.eval((s >> (2 * j)) as u64) else {
            sat.saturated += 1;
            return zero;
        };
        let rshift = j as i32 + r.shift - cfg.vector_frac_bits as i32;
        let fmt = vector_format(cfg);
        let out = v.map(|c| {
            let p = i128::from(c) * i128::from(r.mant);
            let q = if rshift >= 0 {
                round_shift_right_wide(p, rshift as u32, cfg.vector_rounding)
            } else {
                i64::try_from(p << (-rshift).min(64) as u32).unwrap_or(i64::MAX)
            };
            fmt.fit(q, sat)
        });
        Normalized {
            v: out,
            zero: false,
        }
    }

    /// A seeded component of a random bit length 0 to 62 and sign (the ends of that range,
    /// 2^31 and its neighbours among them), so the inputs cross the units' 64-bit bounds
    /// (the units take components below 2^62, where their 128-bit sums cannot overflow).
    fn component(s: &mut u64) -> i64 {
        const ENDS: [i64; 8] = [
            (1 << 62) - 1,
            1 - (1 << 62),
            1 << 31,
            (1 << 31) - 1,
            -(1 << 31),
            -(1 << 31) - 1,
            0,
            -1,
        ];
        let r = next(s);
        if r & 15 == 0 {
            return ENDS[(r >> 4) as usize % ENDS.len()];
        }
        let len = (r >> 8) % 63;
        let mag = if len == 0 { 0 } else { next(s) >> (64 - len) };
        let v = mag as i64;
        if r & 32 == 0 {
            v.wrapping_neg()
        } else {
            v
        }
    }

    /// A vector of components of one random bit length, up to `max_bits` (so normalize sees
    /// vectors near its bounds, not only one huge component).
    fn vector(s: &mut u64, max_bits: u64) -> Vec3x {
        let len = next(s) % (max_bits + 1);
        [0; 3].map(|_: i64| {
            if next(s) & 7 == 0 {
                component(s)
            } else if len == 0 {
                0
            } else {
                let m = (next(s) >> (64 - len)) as i64;
                if next(s) & 1 == 0 {
                    -m
                } else {
                    m
                }
            }
        })
    }

    /// A configuration of random widths and rounding (within `VectorConfig::validate`).
    fn config(s: &mut u64) -> VectorConfig {
        VectorConfig {
            vector_frac_bits: 4 + (next(s) % 12) as u32,
            offset_frac_bits: 4 + (next(s) % 13) as u32,
            offset_int_bits: (next(s) % 9) as u32,
            vector_rounding: MODES[(next(s) % 3) as usize],
            ..VectorConfig::texram16()
        }
    }

    /// dot, cross and the bump multiply-add (their sums in `i64` where they fit) against the
    /// units as first written, in `i128`: 3M seeded cases over random widths and modes with
    /// components of every bit length and the ends of `i64`; the same outputs and counts.
    #[test]
    fn narrow_dot_cross_madd_match_the_wide_forms() {
        let mut s = 0x0dd_c0de;
        let (mut sat, mut sat_before) = (SatCounter::default(), SatCounter::default());
        for i in 0..1_000_000u32 {
            let cfg = config(&mut s);
            let max_bits = if i % 2 == 0 { 62 } else { 34 };
            let (a, b) = (vector(&mut s, max_bits), vector(&mut s, max_bits));
            let c = vector(&mut s, max_bits);
            let g = (component(&mut s), component(&mut s));
            assert_eq!(
                dot3(&a, &b, &cfg, &mut sat),
                dot3_before(&a, &b, &cfg, &mut sat_before),
                "dot {a:?} {b:?} {cfg:?}"
            );
            assert_eq!(
                cross3(&a, &b, &cfg, &mut sat),
                cross3_before(&a, &b, &cfg, &mut sat_before),
                "cross {a:?} {b:?} {cfg:?}"
            );
            assert_eq!(
                madd(&a, &b, &c, g.0, g.1, &cfg, &mut sat),
                madd_before(&a, &b, &c, g, &cfg, &mut sat_before),
                "madd {a:?} {b:?} {c:?} {g:?} {cfg:?}"
            );
        }
        assert_eq!(sat, sat_before);
        assert!(sat.saturated > 0, "the saturation path was exercised");
    }

    /// [`normalize3`] (`|v|^2` in `u64` and the scaling in `i64` where they fit) against the
    /// unit as first written: 2M seeded vectors over random vector widths, rsqrt widths and
    /// modes, components of every bit length to 62, zero vectors among them.
    #[test]
    fn narrow_normalize_matches_the_wide_form() {
        let mut s = 0x0a11_5ca1;
        let (mut sat, mut sat_before) = (SatCounter::default(), SatCounter::default());
        let units: Vec<Rsqrt> = (0..24u32)
            .map(|i| {
                Rsqrt::new(&RsqrtConfig {
                    rsqrt_mantissa_bits: 8 + (next(&mut s) % 23) as u32,
                    rsqrt_lut_bits: 1 + (next(&mut s) % 8) as u32,
                    rsqrt_iterations: i % 5,
                    rsqrt_rounding: MODES[(i / 5 % 3) as usize],
                    ..RsqrtConfig::texram16()
                })
            })
            .collect();
        for i in 0..2_000_000u32 {
            let cfg = config(&mut s);
            let u = &units[(next(&mut s) % 24) as usize];
            let v = vector(&mut s, if i % 2 == 0 { 62 } else { 33 });
            let fallback = [1, 2, 3];
            assert_eq!(
                normalize3(&v, fallback, u, &cfg, &mut sat),
                normalize3_before(&v, fallback, u, &cfg, &mut sat_before),
                "{v:?} {cfg:?}"
            );
        }
        assert_eq!(sat, sat_before);
    }
}
