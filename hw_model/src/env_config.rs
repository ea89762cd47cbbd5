//! Configuration of the environment-map units ([`crate::reflect`], [`crate::cube_face`],
//! [`crate::env_lod`]): the reflection-vector and face-coordinate widths, their rounding, the
//! roughness-driven filter and the hand-set cycle overrides (Schilling 1997, the "balanced
//! system"; `docs/ENVMAP.md`).

use crate::config::ConfigError;
use crate::datapath::Cycles;
use crate::rsqrt::range;
use serde::{Deserialize, Serialize};

/// How the environment lookup's footprint is chosen (Schilling 1997, "balanced system").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum EnvFilter {
    /// The LOD from the reflection vector's screen derivatives only.
    #[default]
    None,
    /// `lambda_1` (the largest standard deviation of the roughness) widens the footprint
    /// isotropically: `LOD = max(LOD_derivs, log2(width of lambda_1 on the face))`.
    Lambda1,
    /// The roughness ellipse `D`, carried to the face, joins the derivative footprint and
    /// drives footprint assembly along its major axis.
    Ellipse,
}

impl EnvFilter {
    /// The name used in files and on the command line.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            EnvFilter::None => "none",
            EnvFilter::Lambda1 => "lambda1",
            EnvFilter::Ellipse => "ellipse",
        }
    }
}

/// The environment-map units' widths and costs (`[env]` in a hw file; absent: texram16).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvConfig {
    /// Fraction bits of the reflection vector's components (signed 1.R, saturating). 4..=20.
    pub reflect_bits: u32,
    /// Fraction bits of the face coordinates `s, t` in `[0, 1]` (unsigned 0.C, the texture
    /// coordinates the trilinear unit reads on the face). 4..=24.
    pub face_coord_bits: u32,
    /// Rounding of the reflection vector and of the face coordinates.
    pub env_rounding: crate::fixed::Rounding,
    /// The machine's environment filter (a material's `env_filter` may override it).
    pub env_filter: EnvFilter,
    /// Cycles of the reflection unit (dot, scale, subtract).
    pub reflect_cycles: Cycles,
    /// Cycles of the face unit's select-and-scale stage (excluding the reciprocal).
    pub face_cycles: Cycles,
}

impl EnvConfig {
    /// Texram-style default: s1.15 reflection vector, 16-bit face coordinates, half-even.
    #[must_use]
    pub fn texram16() -> Self {
        Self {
            reflect_bits: 15,
            face_coord_bits: 16,
            env_rounding: crate::fixed::Rounding::HalfEven,
            env_filter: EnvFilter::None,
            reflect_cycles: Cycles::Derived,
            face_cycles: Cycles::Derived,
        }
    }

    /// Checks the widths; the error names the field.
    pub fn validate(&self) -> Result<(), ConfigError> {
        range("env.reflect_bits", self.reflect_bits, 4, 20)?;
        range("env.face_coord_bits", self.face_coord_bits, 4, 24)?;
        Ok(())
    }
}

impl Default for EnvConfig {
    fn default() -> Self {
        Self::texram16()
    }
}
