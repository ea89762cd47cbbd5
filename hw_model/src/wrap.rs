//! Texel address and wrap unit.

use serde::{Deserialize, Serialize};

/// Texture addressing mode of one axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum WrapMode {
    /// Coordinates repeat with period 1 (GL_REPEAT).
    Repeat,
    /// Texel indices clamp to [0, size-1] (GL_CLAMP_TO_EDGE).
    ClampToEdge,
    /// Coordinates reflect every period (GL_MIRRORED_REPEAT).
    Mirror,
}
