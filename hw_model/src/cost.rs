//! Cost of one unit invocation: operations and cycles, from the unit's config.

use serde::Serialize;

/// What one invocation of a unit costs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct UnitCost {
    /// Arithmetic operations (adds, multiplies, table lookups, shifts that need an adder).
    pub ops: u32,
    /// Cycles, from the unit's per-op cycle counts in `HwConfig`.
    pub cycles: u32,
    /// Texel fetches from texture memory.
    pub texels: u32,
}

impl UnitCost {
    /// Component-wise sum.
    #[must_use]
    pub const fn plus(self, o: UnitCost) -> UnitCost {
        UnitCost {
            ops: self.ops + o.ops,
            cycles: self.cycles + o.cycles,
            texels: self.texels + o.texels,
        }
    }
    /// `n` invocations.
    #[must_use]
    pub const fn times(self, n: u32) -> UnitCost {
        UnitCost {
            ops: self.ops * n,
            cycles: self.cycles * n,
            texels: self.texels * n,
        }
    }
}
