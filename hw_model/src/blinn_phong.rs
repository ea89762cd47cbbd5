//! Blinn-Phong shading in fixed point (Blinn 1977; the model Schilling 1997, Appendix A,
//! builds on): `c = light * (kd * max(0, n.l) + ks * max(0, n.h)^s)`, `h = (l + v)/|l + v|`,
//! the specular term is zero where `n.l <= 0`.
//!
//! Directional and point lights are handled by the caller, which passes the unit vector `l`
//! towards the light (per pixel for a point light) and `v` towards the eye, in vector format.
//! Colours are unsigned normalized with `shade_color_bits` (raw `x` means `x / (2^C - 1)`, as
//! in `modulate` and the pipeline): the products are divided by `2^C - 1` exactly
//! ([`crate::fixed::round_div_wide`]), so white times white is white. The sum saturates at
//! 1.0 (counted).
//! `l = -v` exactly (h undefined) gives no specular term and sets `h_zero`.
//!
//! Also defines the bundle [`ShadingConfig`] of all bump/shading unit configs and
//! [`ShadingUnits`], the units with their tables built once.
//!
//! ERROR BOUND (absolute, per channel, colours in [0, 1], texram16: F = 14, C = 16, power unit
//! L = 8, G = 24, P = 16; against the float twin on the same quantized `n`, `l`, `v`,
//! colours; asserted in `tests/units/frames_shade.rs`, exponents 1..=2047 (all that texram16's
//! 11 bits hold), 1M cases each for log-exp and squaring, grazing light and view and `l = -v`
//! included), with `x = n.h` and `s` the exponent:
//! `light * (ks * (E + s x^(s-1) 2.5 * 2^-F) + kd * 2^-F + T) + 1 / (2^C - 1)`, where
//! `E = x^s (2^(s (0.1803 * 2^-2L + 2^-G)) - 1) + 2 s 2^-G + 2^-(P+1)` is the power unit's
//! error, `2.5 * 2^-F` that of `n.h` (and `2^-F` of `n.l`), and `T = ks x^s` where
//! `n.l < 1.5 * 2^-F` (at the terminator the specular term may switch on or off), else 0.
//! Measured: max error / bound 1.000 (reached where the colour rounding dominates).

use crate::config::ConfigError;
use crate::cost::UnitCost;
use crate::datapath::{Component, Cycles, Datapath, Stage};
use crate::fixed::{round_div_wide, Format, Rounding, SatCounter};
use crate::frame::FrameConfig;
use crate::pow::{pow_cost, Pow, PowConfig};
use crate::rsqrt::{range, rsqrt_cost, Rsqrt, RsqrtConfig};
use crate::vector::{dot3, dot_cost, normalize3, normalize_cost, Vec3x, VectorConfig};
use crate::vector::{dot_datapath, normalize_datapath};
use serde::{Deserialize, Serialize};

/// Shading output configuration.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShadeConfig {
    /// Bits per colour channel of `kd`, `ks`, light and result (unsigned normalized). 4..=16.
    pub shade_color_bits: u32,
    /// Rounding of the final colour.
    pub shade_rounding: Rounding,
    /// Cycles of the colour multiply-adds (3 channels in parallel).
    pub shade_cycles: Cycles,
}

impl ShadeConfig {
    /// Texram-style default: 16-bit colours.
    #[must_use]
    pub fn texram16() -> Self {
        Self {
            shade_color_bits: 16,
            shade_rounding: Rounding::HalfEven,
            shade_cycles: Cycles::Derived,
        }
    }
}

/// All bump-mapping and shading unit configs.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShadingConfig {
    pub rsqrt: RsqrtConfig,
    pub vector: VectorConfig,
    pub frame: FrameConfig,
    pub pow: PowConfig,
    pub shade: ShadeConfig,
}

impl ShadingConfig {
    /// Texram-style defaults of every unit.
    #[must_use]
    pub fn texram16() -> Self {
        Self {
            rsqrt: RsqrtConfig::texram16(),
            vector: VectorConfig::texram16(),
            frame: FrameConfig::texram16(),
            pow: PowConfig::texram16(),
            shade: ShadeConfig::texram16(),
        }
    }

    /// Checks every unit and the cross-unit constraint `rsqrt_mantissa_bits >=
    /// vector_frac_bits + 2` (the normalizer needs two guard bits); the error names the field.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.rsqrt.validate()?;
        self.vector.validate()?;
        self.frame.validate()?;
        self.pow.validate()?;
        range("shade.shade_color_bits", self.shade.shade_color_bits, 4, 16)?;
        if self.rsqrt.rsqrt_mantissa_bits < self.vector.vector_frac_bits + 2 {
            return Err(ConfigError {
                field: "rsqrt.rsqrt_mantissa_bits".into(),
                what: "must be at least vector.vector_frac_bits + 2".into(),
            });
        }
        Ok(())
    }
}

/// The shading units with their tables built once from a [`ShadingConfig`].
#[derive(Clone, Debug)]
pub struct ShadingUnits {
    pub cfg: ShadingConfig,
    pub rsqrt: Rsqrt,
    pub pow: Pow,
}

impl ShadingUnits {
    /// Builds the LUTs (call once per frame, not per pixel).
    #[must_use]
    pub fn new(cfg: &ShadingConfig) -> Self {
        Self {
            cfg: cfg.clone(),
            rsqrt: Rsqrt::new(&cfg.rsqrt),
            pow: Pow::new(&cfg.pow),
        }
    }
}

/// Inputs of one Blinn-Phong evaluation (vectors in vector format, colours unorm raw).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BlinnPhongInput {
    /// Unit (perturbed) normal.
    pub n: Vec3x,
    /// Unit vector towards the light.
    pub l: Vec3x,
    /// Unit vector towards the eye.
    pub v: Vec3x,
    /// Specular exponent.
    pub shininess: u32,
    pub kd: [u64; 3],
    pub ks: [u64; 3],
    /// Light colour.
    pub light: [u64; 3],
}

/// Result of one Blinn-Phong evaluation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BlinnPhongOut {
    /// Colour, unorm raw with `shade_color_bits`.
    pub color: [u64; 3],
    /// `l + v` was zero: no specular term.
    pub h_zero: bool,
}

/// One Blinn-Phong evaluation (see the module doc for the formula and rounding).
#[must_use]
pub fn blinn_phong(
    inp: &BlinnPhongInput,
    units: &ShadingUnits,
    sat: &mut SatCounter,
) -> BlinnPhongOut {
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
    let spec: i64 = if h_zero || ndl == 0 {
        0
    } else {
        let h = normalize3(&sum, [0; 3], &units.rsqrt, vc, sat).v;
        let ndh = dot3(&inp.n, &h, vc, sat).clamp(0, one_f);
        let x = Format::unsigned(1, p, vc.vector_rounding).requantize(ndh, f, sat);
        units.pow.pow(x as u64, inp.shininess, sat) as i64
    };
    let color = lit_color(inp, ndl, spec, units, sat);
    BlinnPhongOut { color, h_zero }
}

/// The colour ending shared by the Blinn-Phong-type units: `light * (kd n.l + ks spec)` with
/// `n.l` in `F = vector_frac_bits` and `spec` in `P` (the power unit's clamped fraction bits)
/// fraction bits. Unorm products: colour raw `x` means `x / (2^C - 1)`, so the result in raw
/// units is `acc light / ((2^C - 1) 2^(F + P))`, one exact rounded division; saturates at 1.0
/// (counted).
#[must_use]
pub fn lit_color(
    inp: &BlinnPhongInput,
    ndl: i64,
    spec: i64,
    units: &ShadingUnits,
    sat: &mut SatCounter,
) -> [u64; 3] {
    let f = units.cfg.vector.vector_frac_bits;
    let p = units.cfg.pow.pow_frac_bits.clamp(8, 24);
    let c = units.cfg.shade.shade_color_bits;
    let out_fmt = Format::unsigned(0, c, units.cfg.shade.shade_rounding);
    let den = ((1i128 << c) - 1) << (f + p);
    [0usize, 1, 2].map(|i| {
        let acc = i128::from(inp.kd[i]) * i128::from(ndl) * (1i128 << p)
            + i128::from(inp.ks[i]) * i128::from(spec) * (1i128 << f);
        let lit = acc * i128::from(inp.light[i]);
        let r = round_div_wide(lit, den, units.cfg.shade.shade_rounding);
        out_fmt.fit(r, sat) as u64
    })
}

/// Cost of one evaluation: two dots, the half-vector add and normalize, the power, and the
/// colour multiply-adds; cycles those of [`datapath`].
#[must_use]
pub fn blinn_phong_cost(units: &ShadingUnits, gate_levels_per_cycle: u32) -> UnitCost {
    let g = gate_levels_per_cycle;
    let c = &units.cfg;
    dot_cost(&c.vector, g)
        .times(2)
        .plus(UnitCost {
            ops: 3,
            cycles: half_vector_datapath(c).latency(g),
            texels: 0,
        })
        .plus(normalize_cost(&c.vector, rsqrt_cost(&c.rsqrt, g), g))
        .plus(pow_cost(&c.pow, g))
        .plus(UnitCost {
            ops: 12,
            cycles: shade_datapath(c).latency(g),
            texels: 0,
        })
}

/// The half vector `l + v` (three adds side by side; no hand-set field).
#[must_use]
pub fn half_vector_datapath(c: &ShadingConfig) -> Datapath {
    let v = c.vector.vector_frac_bits + 2;
    Datapath::new().stage(Stage::new("half vector").then_n(3, Component::Adder { width: v + 1 }))
}

/// The colour stage (`shade_cycles`; S = `shade_color_bits`): per channel the diffuse and
/// specular products side by side, their sum, the clamp (compare, select), rounding.
#[must_use]
pub fn shade_datapath(c: &ShadingConfig) -> Datapath {
    let s = c.shade.shade_color_bits;
    Datapath::new().stage(
        Stage::new("colour")
            .then_n(6, Component::Multiplier { a: s, b: s })
            .then_n(3, Component::Adder { width: 2 * s + 1 })
            .then_n(3, Component::Comparator { width: 2 * s + 1 })
            .then_n(
                3,
                Component::Mux {
                    width: s,
                    inputs: 2,
                },
            )
            .then(Component::Register { bits: 3 * s })
            .cycles(c.shade.shade_cycles),
    )
}

/// One Blinn-Phong evaluation: two dots (`n.l`, then `n.h`), the half vector, its normalize,
/// the power unit, the colour stage.
#[must_use]
pub fn datapath(c: &ShadingConfig) -> Datapath {
    dot_datapath(&c.vector)
        .times(2)
        .then(half_vector_datapath(c))
        .then(normalize_datapath(&c.vector, &c.rsqrt))
        .then(crate::pow::datapath(&c.pow))
        .then(shade_datapath(c))
}

/// Everything one bump-mapped, Blinn-Phong-lit pixel needs (already interpolated).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BumpPixel {
    /// Interpolated normal (vector format or any common scale).
    pub n_i: Vec3x,
    /// Interpolated directions of `s_u`, `s_v` (natural and unit frames).
    pub d_u: Vec3x,
    pub d_v: Vec3x,
    /// Interpolated lengths of `s_u`, `s_v` (natural frame; len format raw).
    pub len_u: i64,
    pub len_v: i64,
    /// Main direction (main frame).
    pub m: Vec3x,
    /// What `m` stands for and whether the texture coordinates are mirrored (main frame).
    pub main_role: crate::frame::MainRole,
    /// The two filtered offset channels as returned by the texture unit.
    pub offset_texels: [u64; 2],
    /// Bits of those texel channels.
    pub texel_bits: u32,
}

/// Result of [`bump_shade`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BumpShadeOut {
    pub color: [u64; 3],
    /// The perturbed unit normal.
    pub normal: Vec3x,
    /// The frame used a fallback (main-direction cone or zero tangent direction).
    pub frame_fallback: bool,
    /// The interpolated normal was zero.
    pub zero_normal: bool,
    /// `l + v` was zero.
    pub h_zero: bool,
}

/// One pixel: decode the offsets, build the frame of `frame_kind`, perturb the normal, shade
/// with one light. `sh.n` is ignored: the perturbed normal replaces it.
///
/// ERROR BOUND (texram16, ulp = 2^-14, against `texsim::shading::reference::bump_shade` on the
/// same quantized inputs and decoded offsets, every frame and [`crate::frame::MainRole`],
/// offsets within +-2, lengths in [0.5, 1.5], exponents 1..=2047; asserted in
/// `tests/units/frames_pixel.rs`, 400k cases per frame, 1.2M in all): perturbed normal
/// <= 16 ulp per component (measured 3.45 / 1.36 / 5.34 ulp natural / unit / main); colour per
/// channel `light * (kd * 40 ulp + ks * (s * 40 ulp * x^(s-1) + P(x, s))) + 2 / (2^C - 1)`
/// with `x = min(1, max(n.h, 0) + 40 ulp)` from the twin's normal and `P` the power unit's
/// bound (`hw_model::pow`): the normal's error reaches `n.l` and `n.h` within 40 ulp, and
/// through `x^s` at most `s` times that times `x^(s-1)` (the mean value theorem on [0, 1]).
/// Measured max 6.84e-2 absolute (large exponents near `n.h = 1`), at most 0.26 of the bound.
/// It holds where the twin's `|n.l|` exceeds 64 ulp. Within that band the normal's error can
/// flip the specular gate (`n.l > 0`), and the colour is then the lit or the unlit value (1,497
/// to 1,609 of the 400k cases per frame).
#[must_use]
pub fn bump_shade(
    px: &BumpPixel,
    sh: &BlinnPhongInput,
    units: &ShadingUnits,
    sat: &mut SatCounter,
) -> BumpShadeOut {
    let vc = &units.cfg.vector;
    let f_u = crate::vector::offset_from_texel(px.offset_texels[0], px.texel_bits, vc, sat);
    let f_v = crate::vector::offset_from_texel(px.offset_texels[1], px.texel_bits, vc, sat);
    let fr = crate::frame::build_frame(
        &px.n_i,
        &px.d_u,
        &px.d_v,
        px.len_u,
        px.len_v,
        &px.m,
        px.main_role,
        units,
        sat,
    );
    let n = crate::frame::perturb_normal(&fr, f_u, f_v, units, sat).v;
    let bp = blinn_phong(&BlinnPhongInput { n, ..*sh }, units, sat);
    BumpShadeOut {
        color: bp.color,
        normal: n,
        frame_fallback: fr.fallback,
        zero_normal: fr.zero_normal,
        h_zero: bp.h_zero,
    }
}

/// One colour multiply-add of the shading stages (`shade_cycles`; S = `shade_color_bits`):
/// three `S x S` products side by side, the add, the rounding.
#[must_use]
pub fn mac_datapath(c: &ShadingConfig) -> Datapath {
    let s = c.shade.shade_color_bits;
    Datapath::new().stage(
        Stage::new("colour multiply-add")
            .then_n(3, Component::Multiplier { a: s, b: s })
            .then_n(3, Component::Adder { width: 2 * s + 1 })
            .then_n(3, Component::Adder { width: s + 1 })
            .cycles(c.shade.shade_cycles),
    )
}

/// Cost of one colour multiply-add ([`mac_datapath`]).
#[must_use]
pub fn mac_cost(c: &ShadingConfig, gate_levels_per_cycle: u32) -> UnitCost {
    UnitCost {
        ops: 3,
        cycles: mac_datapath(c).latency(gate_levels_per_cycle),
        texels: 0,
    }
}
