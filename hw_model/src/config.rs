//! `HwConfig`: every width and per-op cost of the simulated machine, and its presets.
//!
//! Machine variants are data: a preset is a value of this type, a TOML file deserializes into
//! it, and a sweep edits one field at a time. Every leaf field has a globally unique name
//! (`weight_bits`, `recip_iterations`, ...) so that `texsim sweep --vary NAME=...` can address it
//! without a path. Widths are validated by [`HwConfig::validate`], which names the field at fault.

use crate::aniso_phong::AnisoPhongConfig;
use crate::blinn_phong::ShadingConfig;
use crate::datapath::Cycles;
use crate::fixed::{Overflow, Rounding};
use crate::roughness::RoughnessConfig;
use crate::timing_config::TimingConfig;
use serde::{Deserialize, Serialize};
use std::fmt;

/// A configuration value out of its supported range; names the field.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ConfigError {
    /// Dotted path of the field, e.g. `trilinear.weight_bits`.
    pub field: String,
    /// What is wrong with it.
    pub what: String,
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "hw config field '{}': {}", self.field, self.what)
    }
}

impl std::error::Error for ConfigError {}

fn check(field: &str, value: u32, lo: u32, hi: u32) -> Result<(), ConfigError> {
    if value < lo || value > hi {
        return Err(ConfigError {
            field: field.to_string(),
            what: format!("{value} is out of range {lo}..={hi}"),
        });
    }
    Ok(())
}

/// The default overflow rule of the datapath formats (fields absent in older files).
const fn saturate() -> Overflow {
    Overflow::Saturate
}

/// The default of boolean knobs that are on unless a file says otherwise.
const fn yes() -> bool {
    true
}

/// Rasterizer: vertex snapping, depth, and its timing costs.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RasterConfig {
    /// Sub-pixel bits of snapped vertex positions (D3D11 requires 8; Vulkan's minimum is 4).
    pub subpixel_bits: u32,
    /// Depth buffer bits (unsigned normalized).
    pub depth_bits: u32,
    /// Cycles to set up one triangle (edge and plane equations).
    pub setup_cycles: u32,
    /// Cycles to start one span (one scanline of one triangle).
    pub span_cycles: u32,
}

/// Reciprocal unit (1/w and 1/area): LUT seed plus Newton-Raphson refinement.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReciprocalConfig {
    /// Index bits of the seed LUT (the LUT has 2^bits entries).
    pub recip_lut_bits: u32,
    /// Newton-Raphson iterations after the LUT.
    pub recip_iterations: u32,
    /// Fraction bits of the mantissa the unit computes and returns.
    pub recip_mantissa_bits: u32,
    /// Rounding of each multiply inside the unit and of its result.
    pub recip_rounding: Rounding,
    /// Cycles of the LUT lookup.
    pub recip_lut_cycles: Cycles,
    /// Cycles per Newton-Raphson iteration (two multiplies and a subtract).
    pub recip_iteration_cycles: Cycles,
}

/// Attribute interpolator: perspective-correct barycentrics and per-attribute interpolation.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InterpConfig {
    /// Fraction bits of per-vertex 1/w after per-triangle normalization (largest = 1.0).
    pub inv_w_bits: u32,
    /// Fraction bits of the perspective-correct barycentrics (they sum to exactly 1.0).
    pub bary_bits: u32,
    /// Fraction bits of interpolated texture coordinates (normalized: 1.0 = one texture width).
    pub texcoord_frac_bits: u32,
    /// Integer bits (plus sign) of texture coordinates: the repeat range is +-2^int_bits.
    pub texcoord_int_bits: u32,
    /// Rounding of interpolation results.
    pub interp_rounding: Rounding,
    /// What a texture coordinate outside +-2^texcoord_int_bits does (vertex input and
    /// interpolated result): `saturate` (clamp, counted) or `wrap` (keep the low bits, counted;
    /// with `repeat` addressing a wrap by a whole number of repeats changes no texel).
    /// Absent in older files: `saturate`.
    #[serde(default = "saturate")]
    pub texcoord_overflow: Overflow,
    /// Per-triangle texture-coordinate offset reduction at setup (the usual hardware trick for
    /// tiled terrain and atlases): each triangle's s and t are reduced by one integer each
    /// (the nearest integer below the middle of the triangle's range; an even one for
    /// `mirror`; none for `clamp-to-edge`), which changes no texel for `repeat` and `mirror`.
    /// Only a triangle whose own range of coordinates exceeds +-2^texcoord_int_bits still
    /// saturates (or wraps) and is counted. `false`: coordinates enter the format as given.
    /// Absent in older files: `true`.
    #[serde(default = "yes")]
    pub texcoord_reduce: bool,
    /// Sub-pixel bits of the vertex positions the barycentrics (the attribute setup) use:
    /// 0 = the rasterizer's `subpixel_bits`; more models a setup from finer positions than
    /// coverage (llvmpipe: coverage on 8 bits, attribute planes from the float positions).
    /// Absent in older files: 0.
    #[serde(default)]
    pub attr_subpixel_bits: u32,
    /// Arithmetic of the texture coordinates and their LOD: `fixed` (the barycentric
    /// interpolator and LOD unit above) or `float32` (Mesa llvmpipe's IEEE binary32 path,
    /// bit for bit: plane equations from its triangle setup, `a0 + dadx x + dady y` by fused
    /// multiply-adds, `s/w` times `1 / (1/w)`, the LOD from the 2x2 quad's float32
    /// differences and `lp_build_fast_log2`; the `hw_model::f32_*` units). `float32` needs
    /// `lod.lod_per_quad = true` and `lod.lod_log2 = "piecewise-linear"`. Absent in older
    /// files: `fixed`.
    #[serde(default)]
    pub coord_arith: CoordArith,
    /// Cycles to form the perspective-correct barycentrics of one fragment (excl. reciprocal).
    pub bary_cycles: Cycles,
    /// Cycles per interpolated scalar attribute.
    pub attr_cycles: Cycles,
}

/// LOD unit: log2 of the texel footprint from the texture-coordinate derivatives.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LodConfig {
    /// Fraction bits of the LOD (D3D11 requires 8; Vulkan's minimum `mipmapPrecisionBits` is 4).
    pub lod_frac_bits: u32,
    /// Fixed cycles of the unit (squares, compare, normalize).
    pub lod_cycles: Cycles,
    /// Extra cycles per LOD fraction bit (the log2 produces one bit per squaring step).
    pub lod_cycles_per_bit: Cycles,
    /// The log2: `exact` (bit-serial squaring) or `piecewise-linear` (exponent plus mantissa
    /// fraction, llvmpipe's `lp_build_fast_log2`). Absent in older files: `exact`.
    #[serde(default)]
    pub lod_log2: LodLog2,
    /// Derivatives per 2x2 quad (llvmpipe's default): the finite differences between the
    /// quad's first pixel (even x, even y) and its right and lower neighbours, shared by the
    /// four pixels; `false`: the analytic derivatives at each pixel. Absent in older files:
    /// `false`.
    #[serde(default)]
    pub lod_per_quad: bool,
}

/// The arithmetic of the texture-coordinate path (`interp.coord_arith`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CoordArith {
    /// Fixed point: exact-edge barycentrics, the interpolator and the LOD unit.
    #[default]
    Fixed,
    /// IEEE binary32 as Mesa 22.3 llvmpipe computes it (`src/pipeline/coord_f32.rs`).
    Float32,
}

/// How the LOD unit forms `log2` of the squared footprint length.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LodLog2 {
    /// Bit-serial repeated squaring: `floor(log2(L) 2^(F-1))` (see `hw_model::lod`).
    #[default]
    Exact,
    /// `log2(L) ~= e + (L / 2^e - 1)`, `e = floor(log2 L)`: exact at powers of two, at most
    /// 0.0861 low in between (Mesa llvmpipe's `lp_build_fast_log2`).
    PiecewiseLinear,
}

/// Texel address/wrap and the trilinear filter unit.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrilinearConfig {
    /// Sub-texel bits: fraction bits of the bilinear weights (D3D11: 8; Vulkan minimum: 4).
    /// A weight is in [0, 2^weight_bits] inclusive, i.e. weight_bits + 1 bits.
    pub weight_bits: u32,
    /// Bits per texel channel as stored in texture memory (unsigned normalized).
    pub texel_bits: u32,
    /// Rounding of the bilinear lerps and of the level blend.
    pub filter_rounding: Rounding,
    /// Rounding when the texel-space coordinate is reduced to weight_bits.
    pub weight_rounding: Rounding,
    /// Cycles of one bilinear footprint (4 texels, 3 lerps per channel).
    pub bilinear_cycles: Cycles,
    /// Cycles of the blend between the two levels.
    pub level_lerp_cycles: Cycles,
    /// Anisotropic footprint assembly (Texram): trilinear probes along the footprint's major
    /// axis, averaged; 1 = plain trilinear. A power of two, at most 16.
    pub aniso_probes: u32,
    /// Footprint assembly picks the probe count per pixel: the anisotropy of the footprint
    /// rounded up to a power of two, at most `aniso_probes` (false: always `aniso_probes`).
    #[serde(default)]
    pub aniso_adaptive: bool,
}

/// Colour datapath: vertex colour and the modulate (colour x texel) unit.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColorConfig {
    /// Bits per colour channel (unsigned normalized).
    pub color_bits: u32,
    /// Rounding of the modulate multiply.
    pub color_rounding: Rounding,
    /// What an interpolated colour channel outside the unorm range does: `saturate` or
    /// `wrap` (both counted in the `color` stage). Absent in older files: `saturate`.
    #[serde(default = "saturate")]
    pub color_overflow: Overflow,
    /// Cycles of one modulate (4 channels in parallel).
    pub modulate_cycles: Cycles,
}

/// The whole simulated machine.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HwConfig {
    /// Preset or user name of this configuration.
    pub name: String,
    pub raster: RasterConfig,
    pub reciprocal: ReciprocalConfig,
    pub interp: InterpConfig,
    pub lod: LodConfig,
    pub trilinear: TrilinearConfig,
    pub color: ColorConfig,
    /// Per-pixel shading units: rsqrt, vector ops, frames, pow, Blinn-Phong.
    pub shading: ShadingConfig,
    /// The Ashikhmin-Shirley anisotropic Phong unit.
    pub aniso_phong: AnisoPhongConfig,
    /// The roughness-map unit (modified Blinn-Phong, Schilling 1997); absent in old files.
    #[serde(default)]
    pub roughness: RoughnessConfig,
    /// Timing-model parameters (never read by the functional units).
    pub timing: TimingConfig,
    /// The NDF mapping unit (absent in older files: the Texram-style default).
    #[serde(default)]
    pub ndf: crate::ndf::NdfConfig,
    /// The environment-map units (absent in older files: the Texram-style default).
    #[serde(default)]
    pub env: crate::env_config::EnvConfig,
    /// The multi-lobe (Fournier multiple-surface) unit (absent in older files: the default).
    #[serde(default)]
    pub multi_lobe: crate::multi_lobe::MultiLobeConfig,
    /// The Toksvig exponent unit (absent in older files: the Texram-style default).
    #[serde(default)]
    pub toksvig: crate::toksvig::ToksvigConfig,
    /// The LEAN mapping unit (absent in older files: the Texram-style default).
    #[serde(default)]
    pub lean: crate::lean::LeanConfig,
}

/// Names of the built-in presets, in the order `texsim hw list` shows them.
pub const PRESETS: &[&str] = &["texram16", "d3d11", "vulkan-min", "cuda", "llvmpipe"];

impl HwConfig {
    /// Texram-style machine: 16-bit datapath throughout (texels, weights, LOD fraction, colour).
    #[must_use]
    pub fn texram16() -> Self {
        Self {
            name: "texram16".into(),
            raster: RasterConfig {
                subpixel_bits: 8,
                depth_bits: 24,
                setup_cycles: 16,
                span_cycles: 2,
            },
            reciprocal: ReciprocalConfig {
                recip_lut_bits: 8,
                recip_iterations: 2,
                recip_mantissa_bits: 24,
                recip_rounding: Rounding::HalfEven,
                recip_lut_cycles: Cycles::Derived,
                recip_iteration_cycles: Cycles::Derived,
            },
            interp: InterpConfig {
                inv_w_bits: 24,
                bary_bits: 24,
                texcoord_frac_bits: 24,
                texcoord_int_bits: 8,
                interp_rounding: Rounding::HalfEven,
                texcoord_overflow: Overflow::Saturate,
                texcoord_reduce: true,
                attr_subpixel_bits: 0,
                coord_arith: CoordArith::Fixed,
                bary_cycles: Cycles::Derived,
                attr_cycles: Cycles::Derived,
            },
            lod: LodConfig {
                lod_frac_bits: 16,
                lod_cycles: Cycles::Derived,
                lod_cycles_per_bit: Cycles::Derived,
                lod_log2: LodLog2::Exact,
                lod_per_quad: false,
            },
            trilinear: TrilinearConfig {
                weight_bits: 16,
                texel_bits: 16,
                filter_rounding: Rounding::HalfEven,
                weight_rounding: Rounding::Truncate,
                bilinear_cycles: Cycles::Derived,
                level_lerp_cycles: Cycles::Derived,
                aniso_probes: 1,
                aniso_adaptive: false,
            },
            color: ColorConfig {
                color_bits: 16,
                color_rounding: Rounding::HalfEven,
                color_overflow: Overflow::Saturate,
                modulate_cycles: Cycles::Derived,
            },
            shading: ShadingConfig::texram16(),
            aniso_phong: AnisoPhongConfig::texram16(),
            roughness: RoughnessConfig::texram16(),
            timing: TimingConfig::texram16(),
            ndf: crate::ndf::NdfConfig::texram16(),
            env: crate::env_config::EnvConfig::texram16(),
            multi_lobe: crate::multi_lobe::MultiLobeConfig::texram16(),
            toksvig: crate::toksvig::ToksvigConfig::texram16(),
            lean: crate::lean::LeanConfig::texram16(),
        }
    }

    /// The D3D11 precision floor: 8 sub-pixel, 8 sub-texel and 8 LOD-fraction bits.
    #[must_use]
    pub fn d3d11() -> Self {
        let mut c = Self::texram16();
        c.name = "d3d11".into();
        c.timing = TimingConfig::modern();
        c.raster.subpixel_bits = 8;
        c.trilinear.weight_bits = 8;
        c.lod.lod_frac_bits = 8;
        c
    }

    /// Vulkan's required minimums: 4 sub-pixel, 4 sub-texel and 4 mipmap-precision bits
    /// (the Vulkan 1.4 roadmap profile raises sub-texel to 8 and mipmap precision to 6).
    #[must_use]
    pub fn vulkan_min() -> Self {
        let mut c = Self::texram16();
        c.name = "vulkan-min".into();
        c.timing = TimingConfig::modern();
        c.raster.subpixel_bits = 4;
        c.trilinear.weight_bits = 4;
        c.lod.lod_frac_bits = 4;
        c
    }

    /// A CUDA-like texture unit: filter weights in 9-bit fixed point with 8 fraction bits.
    #[must_use]
    pub fn cuda() -> Self {
        let mut c = Self::texram16();
        c.name = "cuda".into();
        c.timing = TimingConfig::modern();
        c.trilinear.weight_bits = 8;
        c.trilinear.weight_rounding = Rounding::HalfEven;
        c.lod.lod_frac_bits = 8;
        c
    }

    /// Mesa llvmpipe's 8-bit AoS texture path (Mesa 22.3, `lp_bld_sample_aos.c`,
    /// `lp_bld_sample.c`): 8-bit texels, coordinates rounded to 8 sub-texel bits to nearest
    /// even (`lp_build_iround`), lerps `a + ((b - a) w + 128) >> 8` (pmulhrsw), LOD per 2x2
    /// quad from finite differences with the piecewise-linear `lp_build_fast_log2`, level
    /// fraction truncated to 8 bits; coverage on 8 sub-pixel bits; the texture coordinates
    /// and LOD in llvmpipe's float32 arithmetic (`interp.coord_arith = "float32"`), handed to
    /// the sampler on 28 fraction bits (`texcoord_frac_bits`, the widest: a binary32
    /// coordinate below 1/2 has bits under 2^-24 that decide its rounded weight).
    #[must_use]
    pub fn llvmpipe() -> Self {
        let mut c = Self::texram16();
        c.name = "llvmpipe".into();
        c.timing = TimingConfig::modern();
        c.trilinear.texel_bits = 8;
        c.trilinear.weight_bits = 8;
        c.trilinear.filter_rounding = Rounding::HalfUp;
        c.trilinear.weight_rounding = Rounding::HalfEven;
        c.lod.lod_frac_bits = 8;
        c.lod.lod_log2 = LodLog2::PiecewiseLinear;
        c.lod.lod_per_quad = true;
        c.interp.attr_subpixel_bits = 16;
        c.interp.coord_arith = CoordArith::Float32;
        c.interp.texcoord_frac_bits = 28;
        c
    }

    /// A preset by name (`texram16`, `d3d11`, `vulkan-min`, `cuda`, `llvmpipe`).
    pub fn preset(name: &str) -> Option<Self> {
        match name {
            "texram16" => Some(Self::texram16()),
            "d3d11" => Some(Self::d3d11()),
            "vulkan-min" => Some(Self::vulkan_min()),
            "cuda" => Some(Self::cuda()),
            "llvmpipe" => Some(Self::llvmpipe()),
            _ => None,
        }
    }

    /// Checks every width against the range the units support; the error names the field.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let r = &self.raster;
        check("raster.subpixel_bits", r.subpixel_bits, 1, 12)?;
        check("raster.depth_bits", r.depth_bits, 8, 30)?;
        let q = &self.reciprocal;
        check("reciprocal.recip_lut_bits", q.recip_lut_bits, 1, 16)?;
        check("reciprocal.recip_iterations", q.recip_iterations, 0, 4)?;
        check(
            "reciprocal.recip_mantissa_bits",
            q.recip_mantissa_bits,
            8,
            30,
        )?;
        let i = &self.interp;
        check("interp.inv_w_bits", i.inv_w_bits, 4, 30)?;
        check("interp.bary_bits", i.bary_bits, 4, 30)?;
        check("interp.texcoord_frac_bits", i.texcoord_frac_bits, 4, 28)?;
        check("interp.texcoord_int_bits", i.texcoord_int_bits, 1, 16)?;
        check("interp.attr_subpixel_bits", i.attr_subpixel_bits, 0, 16)?;
        check("lod.lod_frac_bits", self.lod.lod_frac_bits, 0, 16)?;
        if i.coord_arith == CoordArith::Float32
            && !(self.lod.lod_per_quad && self.lod.lod_log2 == LodLog2::PiecewiseLinear)
        {
            return Err(ConfigError {
                field: "interp.coord_arith".into(),
                what: "float32 (llvmpipe's path) needs lod.lod_per_quad = true and \
                       lod.lod_log2 = \"piecewise-linear\""
                    .into(),
            });
        }
        let t = &self.trilinear;
        check("trilinear.weight_bits", t.weight_bits, 0, 16)?;
        check("trilinear.texel_bits", t.texel_bits, 1, 16)?;
        check("trilinear.aniso_probes", t.aniso_probes, 1, 16)?;
        if !t.aniso_probes.is_power_of_two() {
            return Err(ConfigError {
                field: "trilinear.aniso_probes".into(),
                what: format!("{} is not a power of two", t.aniso_probes),
            });
        }
        check("color.color_bits", self.color.color_bits, 1, 16)?;
        self.shading.validate()?;
        self.aniso_phong.validate()?;
        self.roughness.validate()?;
        self.timing.validate()?;
        self.ndf.validate()?;
        self.env.validate()?;
        self.multi_lobe.validate()?;
        self.toksvig.validate()?;
        self.lean.validate()?;
        Ok(())
    }
}

impl Default for HwConfig {
    fn default() -> Self {
        Self::texram16()
    }
}
