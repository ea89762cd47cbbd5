//! What a unit's width costs: its datapath (the adders, multipliers, shifters, comparators,
//! ROMs, muxes and registers it instantiates, with their widths), the critical path in gate
//! levels, the pipeline latency at a clock target, and an area in gate equivalents.
//!
//! **The area is a proxy** (gate equivalents from textbook cell counts, no wiring, no
//! placement, no library); the delay counts gate levels of textbook structures, not a timing
//! analysis. Both are meant to compare widths and units against each other and against a
//! designer's own estimate (`texsim hw cost` prints every component), not to size a chip.
//!
//! A unit's [`Datapath`] is a serial list of [`Stage`]s, one per operation of the unit (the
//! granularity of the hand-set per-op cycle fields of `HwConfig`). A stage is a serial list of
//! steps; a step is a set of components working side by side (its delay is the slowest of
//! them). Each stage registers its result: its latency is `ceil(delay / gate_levels_per_cycle)`
//! cycles, or the hand-set cycle field that overrides it ([`Cycles::Fixed`]); a unit's
//! latency is the sum over its stages. A stage repeated `n` times (Newton-Raphson iterations,
//! the bilinear footprint of each level, multiplies of a long chain) is unrolled: `n` times
//! its delay, latency and area (the units are pipelined, one pixel per cycle).
//!
//! # The constant table (gate levels, gate equivalents = NAND2 areas)
//!
//! | block | delay (gate levels) | area (GE) | source |
//! |---|---|---|---|
//! | full adder (3:2 compressor) | [`FA_LEVELS`] = 2 (two XOR levels) | [`FA_GE`] = 7 | Weste & Harris, *CMOS VLSI Design* 4th ed., sec. 11.2.1 (28-transistor mirror adder = 7 NAND2) |
//! | half adder | - | [`HA_GE`] = 4 | XOR2 (about 2.3 GE) + AND2 (about 1.3 GE) |
//! | prefix adder, `n` bits | `ceil(log2 n)` + [`ADDER_PG_LEVELS`] = 2 (p/g and sum XOR) | `n` full adders + `(n/2) ceil(log2 n)` prefix cells of [`PREFIX_CELL_GE`] = 3 | Sklansky / Kogge-Stone, Weste & Harris sec. 11.2.2.8 |
//! | multiplier `a x b` | [`PP_LEVELS`] = 1 (AND) + [`FA_LEVELS`] x Dadda levels for `min(a, b)` rows (about `log_{3/2}`; heights 2, 3, 4, 6, 9, 13, 19, 28, 42, 63) + prefix adder of `a + b` bits | `a b` AND gates of [`PP_GE`] = 1, `max(0, a b - 2(a + b) + 3)` full adders, `min(a, b) - 1` half adders, the final adder | Dadda, "Some schemes for parallel multipliers", Alta Frequenza 34, 1965; Wallace, IEEE TEC 13(1), 1964 |
//! | barrel shifter, `w` bits by up to `2^s - 1` | `s` mux levels ([`MUX2_LEVELS`] = 1 each) | `w s` 2:1 muxes of [`MUX2_GE`] = 2 | Weste & Harris sec. 11.8 |
//! | comparator, `n` bits | `ceil(log2 n)` + 1 (carry of a subtract) | `n` half adders + the prefix cells | as the adder, without the sum |
//! | leading-zero counter, `n` bits | `ceil(log2 n)` + 1 | `2 n` | Oklobdzija, IEEE TVLSI 2(1), 1994 (tree LZC) |
//! | mux, `k` inputs of `w` bits | `ceil(log2 k)` | `w (k - 1)` 2:1 muxes | - |
//! | ROM, `2^a` words of `d` bits | `a` + 1 (decoder tree, bit line) | `ceil(2^a d / ` [`ROM_BITS_PER_GE`] `)`, 4 bits per GE | mask ROM about 0.25 GE per bit (proxy) |
//! | register, `b` bits | 0 (setup folded into the stage) | `b` x [`FF_GE`] = 6 | D flip-flop 4.5 to 6.5 GE in standard-cell libraries |
//!
//! `gate_levels_per_cycle` (the clock target, `[timing]` of a hw config; 32 in every preset, an
//! assumption) turns delays into cycles. docs/COST.md prints every unit at texram16.

use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::fmt;

/// Gate levels of one full-adder (3:2 compressor) level in a multiplier tree.
pub const FA_LEVELS: u32 = 2;
/// Gate levels of a prefix adder beyond its `ceil(log2 n)` prefix levels (p/g, sum XOR).
pub const ADDER_PG_LEVELS: u32 = 2;
/// Gate levels of the partial-product AND of a multiplier.
pub const PP_LEVELS: u32 = 1;
/// Gate levels of one 2:1 mux.
pub const MUX2_LEVELS: u32 = 1;
/// Gate equivalents of a full adder.
pub const FA_GE: u64 = 7;
/// Gate equivalents of a half adder.
pub const HA_GE: u64 = 4;
/// Gate equivalents of one (g, p) prefix cell.
pub const PREFIX_CELL_GE: u64 = 3;
/// Gate equivalents of one partial-product AND.
pub const PP_GE: u64 = 1;
/// Gate equivalents of a 2:1 mux.
pub const MUX2_GE: u64 = 2;
/// Gate equivalents of a D flip-flop.
pub const FF_GE: u64 = 6;
/// ROM bits per gate equivalent.
pub const ROM_BITS_PER_GE: u64 = 4;
/// Dadda's maximum heights: a tree of `j` full-adder levels reduces `DADDA[j]` rows to two.
pub const DADDA: [u32; 12] = [2, 3, 4, 6, 9, 13, 19, 28, 42, 63, 94, 141];

/// `ceil(log2 n)` (0 for n <= 1).
#[must_use]
pub const fn ceil_log2(n: u32) -> u32 {
    if n <= 1 {
        0
    } else {
        32 - (n - 1).leading_zeros()
    }
}

/// Full-adder levels of a Dadda tree reducing `rows` partial products to two.
#[must_use]
pub fn dadda_levels(rows: u32) -> u32 {
    DADDA.iter().position(|&h| h >= rows).map_or_else(
        // Beyond the table (never at the widths the units support): one more level per 3/2.
        || DADDA.len() as u32 + ceil_log2(rows / DADDA[DADDA.len() - 1] + 1) * 2,
        |j| j as u32,
    )
}

/// One hardware building block with its widths.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Component {
    /// Prefix (carry-lookahead) adder/subtractor of `width` bits.
    Adder { width: u32 },
    /// Array multiplier `a x b` bits: partial products, Dadda tree, final prefix adder.
    Multiplier { a: u32, b: u32 },
    /// Barrel shifter of `width` bits by a `shift_bits`-bit amount.
    Shifter { width: u32, shift_bits: u32 },
    /// Magnitude comparator of `width` bits.
    Comparator { width: u32 },
    /// Leading-zero counter of `width` bits (normalization).
    LeadingZeros { width: u32 },
    /// Multiplexer selecting one of `inputs` words of `width` bits.
    Mux { width: u32, inputs: u32 },
    /// ROM (lookup table) of `2^addr_bits` words of `data_bits` bits.
    Rom { addr_bits: u32, data_bits: u32 },
    /// Pipeline register of `bits` flip-flops.
    Register { bits: u32 },
}

fn adder_area(n: u32) -> u64 {
    u64::from(n) * FA_GE + u64::from(n / 2) * u64::from(ceil_log2(n)) * PREFIX_CELL_GE
}

impl Component {
    /// Critical path in gate levels (see the module's table).
    #[must_use]
    pub fn delay(&self) -> u32 {
        match *self {
            Component::Adder { width } => {
                if width == 0 {
                    0
                } else {
                    ceil_log2(width) + ADDER_PG_LEVELS
                }
            }
            Component::Multiplier { a, b } => {
                if a == 0 || b == 0 {
                    return 0;
                }
                let rows = a.min(b);
                let tree = if rows <= 1 {
                    0
                } else {
                    FA_LEVELS * dadda_levels(rows)
                };
                let fin = if rows <= 1 {
                    0
                } else {
                    Component::Adder { width: a + b }.delay()
                };
                PP_LEVELS + tree + fin
            }
            Component::Shifter { shift_bits, .. } => shift_bits * MUX2_LEVELS,
            Component::Comparator { width } | Component::LeadingZeros { width } => {
                if width == 0 {
                    0
                } else {
                    ceil_log2(width) + 1
                }
            }
            Component::Mux { inputs, .. } => ceil_log2(inputs) * MUX2_LEVELS,
            Component::Rom { addr_bits, .. } => addr_bits + 1,
            Component::Register { .. } => 0,
        }
    }

    /// Area in gate equivalents (a proxy; see the module's table).
    #[must_use]
    pub fn area(&self) -> u64 {
        match *self {
            Component::Adder { width } => adder_area(width),
            Component::Multiplier { a, b } => {
                if a == 0 || b == 0 {
                    return 0;
                }
                let (a, b) = (u64::from(a), u64::from(b));
                let pp = a * b * PP_GE;
                if a.min(b) <= 1 {
                    return pp;
                }
                let fa = (a * b + 3).saturating_sub(2 * (a + b));
                let ha = a.min(b) - 1;
                pp + fa * FA_GE + ha * HA_GE + adder_area((a + b) as u32)
            }
            Component::Shifter { width, shift_bits } => {
                u64::from(width) * u64::from(shift_bits) * MUX2_GE
            }
            Component::Comparator { width } => {
                u64::from(width) * HA_GE
                    + u64::from(width / 2) * u64::from(ceil_log2(width)) * PREFIX_CELL_GE
            }
            Component::LeadingZeros { width } => 2 * u64::from(width),
            Component::Mux { width, inputs } => {
                u64::from(width) * u64::from(inputs.saturating_sub(1)) * MUX2_GE
            }
            Component::Rom {
                addr_bits,
                data_bits,
            } => ((1u64 << addr_bits.min(40)) * u64::from(data_bits)).div_ceil(ROM_BITS_PER_GE),
            Component::Register { bits } => u64::from(bits) * FF_GE,
        }
    }
}

impl fmt::Display for Component {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Component::Adder { width } => write!(f, "add{width}"),
            Component::Multiplier { a, b } => write!(f, "mul{a}x{b}"),
            Component::Shifter { width, shift_bits } => write!(f, "shift{width}/{shift_bits}"),
            Component::Comparator { width } => write!(f, "cmp{width}"),
            Component::LeadingZeros { width } => write!(f, "lzc{width}"),
            Component::Mux { width, inputs } => write!(f, "mux{inputs}x{width}"),
            Component::Rom {
                addr_bits,
                data_bits,
            } => write!(f, "rom{addr_bits}x{data_bits}"),
            Component::Register { bits } => write!(f, "reg{bits}"),
        }
    }
}

/// A hand-set cycle count or the one derived from the datapath.
///
/// In a hw TOML file: `bilinear_cycles = 3` (an explicit override) or `bilinear_cycles =
/// "derived"` (`ceil(delay / gate_levels_per_cycle)` of the op's stage; the presets' value).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Cycles {
    /// From the stage's delay and the clock target.
    #[default]
    Derived,
    /// Hand-set: this many cycles, whatever the widths.
    Fixed(u32),
}

impl Cycles {
    /// The hand-set value, or `derived()`.
    #[inline]
    #[must_use]
    pub fn or_else(self, derived: impl FnOnce() -> u32) -> u32 {
        match self {
            Cycles::Derived => derived(),
            Cycles::Fixed(c) => c,
        }
    }
}

impl Serialize for Cycles {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Cycles::Derived => s.serialize_str("derived"),
            Cycles::Fixed(c) => s.serialize_u32(*c),
        }
    }
}

impl<'de> Deserialize<'de> for Cycles {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl serde::de::Visitor<'_> for V {
            type Value = Cycles;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a cycle count (0..=1000) or \"derived\"")
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Cycles, E> {
                if v > 1000 {
                    return Err(E::custom(format!("{v} cycles is out of range 0..=1000")));
                }
                Ok(Cycles::Fixed(v as u32))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Cycles, E> {
                if v < 0 {
                    return Err(E::custom(format!("{v} cycles is negative")));
                }
                self.visit_u64(v as u64)
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Cycles, E> {
                match v {
                    "derived" => Ok(Cycles::Derived),
                    other => other.parse::<u64>().map_or_else(
                        |_| {
                            Err(E::custom(format!(
                                "'{other}' is neither a cycle count nor \"derived\""
                            )))
                        },
                        |n| self.visit_u64(n),
                    ),
                }
            }
        }
        d.deserialize_any(V)
    }
}

/// Components side by side (one step of a stage): `count` copies of `component`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Part {
    /// Copies working in parallel.
    pub count: u32,
    /// The component.
    pub component: Component,
}

/// One operation of a unit: a serial list of steps, each a set of parallel parts, registered
/// at its output.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Stage {
    /// What the stage computes.
    pub name: &'static str,
    /// Serial steps; the parts of one step work side by side.
    pub steps: Vec<Vec<Part>>,
    /// Unrolled copies of the stage in series (iterations, levels, chained ops).
    pub repeat: u32,
    /// The hand-set cycles of one copy ([`Cycles::Fixed`]), or derived from its delay.
    #[serde(serialize_with = "ser_cycles")]
    pub cycles: Cycles,
}

fn ser_cycles<S: Serializer>(c: &Cycles, s: S) -> Result<S::Ok, S::Error> {
    c.serialize(s)
}

impl Stage {
    /// An empty stage, repeated once, its cycles derived.
    #[must_use]
    pub fn new(name: &'static str) -> Self {
        Self {
            name,
            steps: Vec::new(),
            repeat: 1,
            cycles: Cycles::Derived,
        }
    }
    /// Appends a step of one component.
    #[must_use]
    pub fn then(self, c: Component) -> Self {
        self.then_n(1, c)
    }
    /// Appends a step of `n` copies of `c` side by side.
    #[must_use]
    pub fn then_n(mut self, n: u32, c: Component) -> Self {
        self.steps.push(vec![Part {
            count: n,
            component: c,
        }]);
        self
    }
    /// Adds `n` copies of `c` beside the last step (a new step if there is none).
    #[must_use]
    pub fn beside(mut self, n: u32, c: Component) -> Self {
        let p = Part {
            count: n,
            component: c,
        };
        match self.steps.last_mut() {
            Some(s) => s.push(p),
            None => self.steps.push(vec![p]),
        }
        self
    }
    /// The stage unrolled `n` times in series.
    #[must_use]
    pub fn times(mut self, n: u32) -> Self {
        self.repeat = n;
        self
    }
    /// The hand-set cycles of one copy, if `c` is [`Cycles::Fixed`].
    #[must_use]
    pub fn cycles(mut self, c: Cycles) -> Self {
        self.cycles = c;
        self
    }
    /// Gate levels through one copy: the sum over its steps of each step's slowest part.
    #[must_use]
    pub fn delay_once(&self) -> u32 {
        self.steps
            .iter()
            .map(|s| s.iter().map(|p| p.component.delay()).max().unwrap_or(0))
            .sum()
    }
    /// Gate levels through all copies.
    #[must_use]
    pub fn delay(&self) -> u32 {
        self.repeat * self.delay_once()
    }
    /// Cycles of one copy at `gate_levels_per_cycle`: the override, else
    /// `ceil(delay_once / gate_levels_per_cycle)`.
    #[must_use]
    pub fn latency_once(&self, gate_levels_per_cycle: u32) -> u32 {
        self.cycles
            .or_else(|| self.delay_once().div_ceil(gate_levels_per_cycle.max(1)))
    }
    /// Cycles of all copies.
    #[must_use]
    pub fn latency(&self, gate_levels_per_cycle: u32) -> u32 {
        self.repeat * self.latency_once(gate_levels_per_cycle)
    }
    /// Gate equivalents of all copies.
    #[must_use]
    pub fn area(&self) -> u64 {
        u64::from(self.repeat)
            * self
                .steps
                .iter()
                .flatten()
                .map(|p| u64::from(p.count) * p.component.area())
                .sum::<u64>()
    }
}

/// A unit's datapath: its stages in series.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Datapath {
    /// The stages in the order the data passes them.
    pub stages: Vec<Stage>,
}

impl Datapath {
    /// No stages: zero delay, latency and area.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }
    /// Appends a stage (serial composition).
    #[must_use]
    pub fn stage(mut self, s: Stage) -> Self {
        if s.repeat > 0 && !s.steps.is_empty() {
            self.stages.push(s);
        }
        self
    }
    /// Appends all stages of `other` (serial composition of two units).
    #[must_use]
    pub fn then(mut self, other: Datapath) -> Self {
        self.stages.extend(other.stages);
        self
    }
    /// `n` copies of this datapath in series.
    #[must_use]
    pub fn times(self, n: u32) -> Self {
        let mut out = Datapath::new();
        for _ in 0..n {
            out = out.then(self.clone());
        }
        out
    }
    /// Critical path in gate levels: the sum of the stages' delays.
    #[must_use]
    pub fn delay(&self) -> u32 {
        self.stages.iter().map(Stage::delay).sum()
    }
    /// Pipeline latency in cycles at `gate_levels_per_cycle`: the sum of the stages' latencies
    /// (each `ceil(delay / gate_levels_per_cycle)` unless hand-set).
    #[must_use]
    pub fn latency(&self, gate_levels_per_cycle: u32) -> u32 {
        self.stages
            .iter()
            .map(|s| s.latency(gate_levels_per_cycle))
            .sum()
    }
    /// Area in gate equivalents (a proxy): the sum over all components.
    #[must_use]
    pub fn area(&self) -> u64 {
        self.stages.iter().map(Stage::area).sum()
    }
}

/// One unit of a machine as `texsim hw cost` reports it.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct UnitReport {
    /// The unit (the `hw_model` module, with the variant where a module has several).
    pub name: &'static str,
    /// Its datapath at this machine's widths.
    pub datapath: Datapath,
    /// Critical path in gate levels.
    pub delay: u32,
    /// Pipeline latency in cycles at the machine's `gate_levels_per_cycle`.
    pub latency: u32,
    /// Area in gate equivalents (a proxy).
    pub area: u64,
}

impl UnitReport {
    /// The report of `datapath` at `gate_levels_per_cycle`.
    #[must_use]
    pub fn new(name: &'static str, datapath: Datapath, gate_levels_per_cycle: u32) -> Self {
        Self {
            name,
            delay: datapath.delay(),
            latency: datapath.latency(gate_levels_per_cycle),
            area: datapath.area(),
            datapath,
        }
    }
}

/// Every unit of machine `hw` with its datapath at `hw`'s widths, delay, latency at
/// `hw.timing.gate_levels_per_cycle`, and area; the order is the pipeline's. Sub-units appear
/// on their own and inside the units that instantiate them (`reciprocal` inside the
/// barycentrics, `rsqrt` inside `vector.normalize`, ...); [`TOP_LEVEL`] names the units
/// whose areas sum to the machine's ([`total_area`]).
#[must_use]
pub fn units(hw: &crate::HwConfig) -> Vec<UnitReport> {
    let g = hw.timing.gate_levels_per_cycle;
    let sh = &hw.shading;
    let mut v = vec![
        UnitReport::new("reciprocal", crate::reciprocal::datapath(&hw.reciprocal), g),
        UnitReport::new(
            "interpolator.bary",
            crate::interpolator::bary_datapath(&hw.interp, &hw.reciprocal),
            g,
        ),
        UnitReport::new(
            "interpolator.bary-derivs",
            crate::interpolator::bary_derivs_datapath(&hw.interp, &hw.reciprocal),
            g,
        ),
        UnitReport::new(
            "interpolator.attribute",
            crate::interpolator::attribute_datapath(&hw.interp),
            g,
        ),
        UnitReport::new("lod", crate::lod::datapath(&hw.lod), g),
        UnitReport::new("wrap", crate::wrap::datapath(&hw.trilinear), g),
        UnitReport::new(
            "bilinear",
            crate::trilinear::bilinear_datapath(&hw.trilinear),
            g,
        ),
        UnitReport::new("trilinear", crate::trilinear::datapath(&hw.trilinear, 2), g),
        UnitReport::new(
            "footprint",
            crate::footprint::datapath(&hw.trilinear, &hw.lod, hw.trilinear.aniso_probes),
            g,
        ),
        UnitReport::new("modulate", crate::modulate::datapath(&hw.color), g),
        UnitReport::new("rsqrt", crate::rsqrt::datapath(&sh.rsqrt), g),
        UnitReport::new("vector.dot", crate::vector::dot_datapath(&sh.vector), g),
        UnitReport::new("vector.cross", crate::vector::cross_datapath(&sh.vector), g),
        UnitReport::new(
            "vector.normalize",
            crate::vector::normalize_datapath(&sh.vector, &sh.rsqrt),
            g,
        ),
        UnitReport::new("vector.madd", crate::vector::madd_datapath(&sh.vector), g),
        UnitReport::new("pow", crate::pow::datapath(&sh.pow), g),
        UnitReport::new("frame", crate::frame::datapath(sh.frame.frame_kind, sh), g),
        UnitReport::new("perturb", crate::frame::perturb_datapath(sh), g),
        UnitReport::new("blinn_phong", crate::blinn_phong::datapath(sh), g),
        UnitReport::new("roughness", crate::roughness::datapath(&hw.roughness), g),
        UnitReport::new(
            "roughness.shade",
            crate::roughness::shade_datapath(&hw.roughness, sh),
            g,
        ),
    ];
    if let Some(d) = crate::ndf::datapath(&hw.ndf, &hw.reciprocal, &sh.rsqrt) {
        v.push(UnitReport::new("ndf", d, g));
    }
    v.push(UnitReport::new(
        "toksvig",
        crate::toksvig::datapath(&hw.toksvig, hw.trilinear.texel_bits),
        g,
    ));
    v.push(UnitReport::new("lean", crate::lean::datapath(&hw.lean), g));
    v.push(UnitReport::new(
        "aniso_phong",
        crate::aniso_phong::datapath(&hw.aniso_phong),
        g,
    ));
    v.push(UnitReport::new(
        "reflect",
        crate::reflect::datapath(&sh.vector, &hw.env),
        g,
    ));
    v.push(UnitReport::new(
        "cube_face",
        crate::cube_face::datapath(&hw.env, &hw.reciprocal),
        g,
    ));
    v.push(UnitReport::new(
        "env_lod.lambda1",
        crate::env_lod::lambda1_datapath(&hw.lod),
        g,
    ));
    v.push(UnitReport::new(
        "env_lod.ellipse",
        crate::env_lod::datapath(&hw.env),
        g,
    ));
    v.push(UnitReport::new(
        "multi_lobe",
        crate::multi_lobe::datapath(&hw.multi_lobe, sh),
        g,
    ));
    // The IEEE binary32 units of the float32 coordinate path (`interp.coord_arith`).
    v.push(UnitReport::new("f32_add", crate::f32_add::datapath(), g));
    v.push(UnitReport::new("f32_mul", crate::f32_mul::datapath(), g));
    v.push(UnitReport::new("f32_div", crate::f32_div::datapath(), g));
    v.push(UnitReport::new("f32_fma", crate::f32_fma::datapath(), g));
    v.push(UnitReport::new(
        "f32_convert",
        crate::f32_convert::datapath(),
        g,
    ));
    v
}

/// The units whose areas make up the machine (one per stage kind of the pipeline that has
/// arithmetic: the barycentrics with their derivatives, the attribute interpolator, the LOD
/// unit, footprint assembly (the trilinear unit when `aniso_probes = 1`), modulate, frame,
/// perturb, Blinn-Phong, the roughness shader, the NDF unit and the Ashikhmin-Shirley unit).
pub const TOP_LEVEL: &[&str] = &[
    "interpolator.bary-derivs",
    "interpolator.attribute",
    "lod",
    "footprint",
    "modulate",
    "frame",
    "perturb",
    "blinn_phong",
    "roughness.shade",
    "ndf",
    "aniso_phong",
];

/// The machine's area proxy: the sum of the [`TOP_LEVEL`] units' areas.
#[must_use]
pub fn total_area(reports: &[UnitReport]) -> u64 {
    reports
        .iter()
        .filter(|r| TOP_LEVEL.contains(&r.name))
        .map(|r| r.area)
        .sum()
}

/// The longest latency of any unit, in cycles.
#[must_use]
pub fn max_latency(reports: &[UnitReport]) -> u32 {
    reports.iter().map(|r| r.latency).max().unwrap_or(0)
}
