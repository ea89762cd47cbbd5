//! Test vectors for RTL (issue 18): for a `hw_model` unit, boundary cases plus seeded random
//! cases, the expected outputs computed by the bit-accurate unit itself, written as `$readmemh`
//! files (one per port) and a JSON manifest of the ports, their formats and rounding.
//!
//! Units are rows of [`UNITS`]: a name, a one-line description and a constructor of its
//! [`UnitAdapter`] (ports, boundary cases, random case generator, evaluator) for a machine.
//! Adding a unit is one adapter and one row.
//!
//! File format: `PORT.hex` holds one value per line, a leading `//` comment line, each value
//! in two's complement masked to the port's `bits` and zero-padded to `ceil(bits / 4)` hex
//! digits. Line `k` of every file is vector `k`: the boundary cases first, then the random ones.

use std::collections::BTreeSet;

use hw_model::fixed::{Rounding, SatCounter};
use hw_model::reciprocal::Reciprocal;
use hw_model::rsqrt::Rsqrt;
use hw_model::wrap::WrapMode;
use hw_model::HwConfig;
use serde::Serialize;
use serde_json::{json, Value};

use crate::provenance::Provenance;
use crate::report::OutputSet;
use crate::rng::SplitMix64;
use crate::{Error, Result};

/// Whether a port is driven by the testbench or checked by it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    Input,
    Output,
}

/// One port of a unit: its width and fixed-point format.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Port {
    pub name: &'static str,
    pub direction: Direction,
    /// Width in bits (sign included).
    pub bits: u32,
    /// Two's complement if true.
    pub signed: bool,
    /// Integer bits, not counting the sign bit.
    pub int_bits: u32,
    /// Fraction bits: the raw value `r` means `r * 2^-frac_bits`.
    pub frac_bits: u32,
    /// Rounding of an output (`None` for inputs and for exact outputs).
    pub rounding: Option<Rounding>,
    pub description: &'static str,
}

impl Port {
    fn input(name: &'static str, signed: bool, int_bits: u32, frac_bits: u32) -> Self {
        Self {
            name,
            direction: Direction::Input,
            bits: int_bits + frac_bits + u32::from(signed),
            signed,
            int_bits,
            frac_bits,
            rounding: None,
            description: "",
        }
    }

    fn output(name: &'static str, signed: bool, int_bits: u32, frac_bits: u32) -> Self {
        Self {
            direction: Direction::Output,
            ..Self::input(name, signed, int_bits, frac_bits)
        }
    }

    fn rounded(self, r: Rounding) -> Self {
        Self {
            rounding: Some(r),
            ..self
        }
    }

    fn doc(self, description: &'static str) -> Self {
        Self {
            description,
            ..self
        }
    }

    /// Smallest and largest raw value of the port.
    #[must_use]
    pub fn range(&self) -> (i64, i64) {
        let mag = self.bits - u32::from(self.signed);
        let hi = ((1u128 << mag) - 1) as i64;
        if self.signed {
            (-hi - 1, hi)
        } else {
            (0, hi)
        }
    }

    /// Hex digits of one value.
    #[must_use]
    pub fn digits(&self) -> usize {
        self.bits.div_ceil(4) as usize
    }

    /// `v` as `$readmemh` text: two's complement masked to `bits`, zero-padded.
    #[must_use]
    pub fn hex(&self, v: i64) -> String {
        let mask = if self.bits >= 64 {
            u64::MAX
        } else {
            (1u64 << self.bits) - 1
        };
        format!("{:0w$x}", (v as u64) & mask, w = self.digits())
    }
}

/// A unit's vector generator for one machine: its ports (inputs first, then outputs), its
/// resolved configuration, its cases and its evaluator (the `hw_model` unit).
pub trait UnitAdapter {
    /// Inputs first, then outputs.
    fn ports(&self) -> Vec<Port>;
    /// The configuration the unit runs with (what the manifest records).
    fn config(&self) -> Value;
    /// Boundary cases: one entry per case, one value per input port.
    fn boundary(&self) -> Vec<Vec<i64>>;
    /// One seeded random case.
    fn random(&self, rng: &mut SplitMix64) -> Vec<i64>;
    /// The unit's outputs for one case, one value per output port.
    fn eval(&self, inputs: &[i64]) -> Vec<i64>;
}

/// One row of the unit table.
pub struct UnitEntry {
    pub name: &'static str,
    pub about: &'static str,
    pub make: fn(&HwConfig) -> Box<dyn UnitAdapter>,
}

/// The units `texsim vectors` knows, in the order `--list` shows them.
pub const UNITS: &[UnitEntry] = &[
    UnitEntry {
        name: "lerp",
        about: "the bilinear/trilinear filter's lerp a + (b - a) w / 2^weight_bits, one rounding (hw_model::trilinear::lerp)",
        make: |hw| Box::new(Lerp::new(hw)),
    },
    UnitEntry {
        name: "bilinear",
        about: "one channel of the bilinear footprint: lerps along x on both rows, then along y (hw_model::trilinear::bilinear)",
        make: |hw| Box::new(Bilinear::new(hw)),
    },
    UnitEntry {
        name: "recip",
        about: "the reciprocal unit 1/x: LUT seed + Newton-Raphson (hw_model::reciprocal)",
        make: |hw| Box::new(Recip::new(hw)),
    },
    UnitEntry {
        name: "rsqrt",
        about: "the reciprocal square root unit 1/sqrt(x): LUT seed + Newton-Raphson (hw_model::rsqrt)",
        make: |hw| Box::new(RsqrtUnit::new(hw)),
    },
    UnitEntry {
        name: "wrap",
        about: "the texel address and wrap unit of one axis: texel pair and weight (hw_model::wrap)",
        make: |hw| Box::new(Wrap::new(hw)),
    },
    UnitEntry {
        name: "lod",
        about: "the LOD unit log2 of the footprint from four derivatives (hw_model::lod)",
        make: |hw| Box::new(Lod::new(hw)),
    },
];

/// The row of unit `name`; an unknown name lists the known ones.
pub fn unit(name: &str) -> Result<&'static UnitEntry> {
    UNITS.iter().find(|u| u.name == name).ok_or_else(|| {
        let names: Vec<&str> = UNITS.iter().map(|u| u.name).collect();
        Error::msg(format!(
            "unknown unit '{name}' for vectors{} (units: {}; `texsim vectors --list`)",
            crate::hwconfig::did_you_mean(name, names.iter().copied()),
            names.join(", ")
        ))
    })
}

/// A generated set of vectors: the unit, its ports and one column of values per port.
#[derive(Clone, Debug)]
pub struct VectorSet {
    pub unit: &'static str,
    pub hw_name: String,
    pub unit_config: Value,
    pub ports: Vec<Port>,
    /// `columns[p][k]`: port `p` of vector `k`.
    pub columns: Vec<Vec<i64>>,
    pub boundary: u64,
    pub random: u64,
    pub seed: u64,
}

impl VectorSet {
    /// Number of vectors.
    #[must_use]
    pub fn len(&self) -> usize {
        self.columns.first().map_or(0, Vec::len)
    }

    /// Whether the set holds no vector.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Bytes of memory one vector needs: each port's value (8 B) and its text (digits + newline).
fn bytes_per_vector(ports: &[Port]) -> u64 {
    ports.iter().map(|p| 9 + p.digits() as u64).sum()
}

/// Boundary cases plus `n` random cases (seed `seed`) of unit `name` on `hw`, evaluated by the
/// unit. The need is checked against the memory budget (field `--n`) before anything is built.
pub fn generate(name: &str, hw: &HwConfig, n: u64, seed: u64) -> Result<VectorSet> {
    let entry = unit(name)?;
    let adapter = (entry.make)(hw);
    let ports = adapter.ports();
    let boundary = adapter.boundary();
    let total = n.saturating_add(boundary.len() as u64);
    crate::budget::check(
        "--n",
        &format!("{total} vectors of unit '{name}'"),
        crate::budget::mul(total, bytes_per_vector(&ports)),
    )?;
    let mut columns: Vec<Vec<i64>> = ports
        .iter()
        .map(|_| Vec::with_capacity(total as usize))
        .collect();
    let n_in = ports
        .iter()
        .filter(|p| p.direction == Direction::Input)
        .count();
    let mut push = |inputs: &[i64]| -> Result<()> {
        let outputs = adapter.eval(inputs);
        if inputs.len() != n_in || inputs.len() + outputs.len() != ports.len() {
            return Err(Error::msg(format!(
                "unit '{name}': a case has {} inputs and {} outputs, its ports say {n_in} and {}",
                inputs.len(),
                outputs.len(),
                ports.len() - n_in
            )));
        }
        for ((col, &v), p) in columns
            .iter_mut()
            .zip(inputs.iter().chain(&outputs))
            .zip(&ports)
        {
            let (lo, hi) = p.range();
            if v < lo || v > hi {
                return Err(Error::msg(format!(
                    "unit '{name}': value {v} of port '{}' is outside its {} bits on '{}'",
                    p.name, p.bits, hw.name
                )));
            }
            col.push(v);
        }
        Ok(())
    };
    for case in &boundary {
        push(case)?;
    }
    let mut rng = SplitMix64::new(seed);
    for _ in 0..n {
        push(&adapter.random(&mut rng))?;
    }
    Ok(VectorSet {
        unit: entry.name,
        hw_name: hw.name.clone(),
        unit_config: adapter.config(),
        ports,
        columns,
        boundary: boundary.len() as u64,
        random: n,
        seed,
    })
}

/// File name of a port's vectors.
#[must_use]
pub fn port_file(p: &Port) -> String {
    format!("{}.hex", p.name)
}

/// One port as the manifest lists it.
#[derive(Serialize)]
struct ManifestPort<'a> {
    #[serde(flatten)]
    port: &'a Port,
    file: String,
}

/// What `manifest.json` holds.
#[derive(Serialize)]
struct Manifest<'a> {
    unit: &'a str,
    description: &'a str,
    hw_config: &'a str,
    unit_config: &'a Value,
    vectors: usize,
    boundary_vectors: u64,
    random_vectors: u64,
    seed: u64,
    texsim_version: &'a str,
    file_format: &'a str,
    ports: Vec<ManifestPort<'a>>,
    provenance: &'a Provenance,
}

/// The `file_format` line of the manifest.
const FILE_FORMAT: &str = "$readmemh: a leading // comment line, then one value per line (line k of every file is vector k, boundary cases first); two's complement masked to the port's bits, zero-padded to ceil(bits/4) hex digits";

/// The manifest (what `manifest.json` holds) as JSON text.
pub fn manifest(set: &VectorSet, provenance: &Provenance) -> Result<String> {
    let m = Manifest {
        unit: set.unit,
        description: unit(set.unit).map_or("", |u| u.about),
        hw_config: &set.hw_name,
        unit_config: &set.unit_config,
        vectors: set.len(),
        boundary_vectors: set.boundary,
        random_vectors: set.random,
        seed: set.seed,
        texsim_version: provenance.texsim_version,
        file_format: FILE_FORMAT,
        ports: set
            .ports
            .iter()
            .map(|p| ManifestPort {
                port: p,
                file: port_file(p),
            })
            .collect(),
        provenance,
    };
    serde_json::to_string_pretty(&m)
        .map(|t| t + "\n")
        .map_err(|e| Error::msg(format!("cannot encode manifest.json: {e}")))
}

/// Every file of the set (one `$readmemh` file per port, `manifest.json`), ready to be written
/// together.
pub fn output_set(set: &VectorSet, provenance: &Provenance) -> Result<OutputSet> {
    let mut out = OutputSet::new();
    for (p, col) in set.ports.iter().zip(&set.columns) {
        let mut text = String::with_capacity(col.len() * (p.digits() + 1) + 128);
        text.push_str(&format!(
            "// texsim vectors {}: port {} ({}, {} bits, {}), {} vectors\n",
            set.unit,
            p.name,
            match p.direction {
                Direction::Input => "input",
                Direction::Output => "output",
            },
            p.bits,
            if p.signed { "signed" } else { "unsigned" },
            col.len()
        ));
        for &v in col {
            text.push_str(&p.hex(v));
            text.push('\n');
        }
        out.add(&port_file(p), text.into_bytes());
    }
    out.add("manifest.json", manifest(set, provenance)?.into_bytes());
    let mut family: Vec<String> = set.ports.iter().map(port_file).collect();
    family.push("manifest.json".into());
    let family: Vec<&str> = family.iter().map(String::as_str).collect();
    out.family(&family);
    Ok(out)
}

/// Sorted distinct values of `v` inside `[lo, hi]`.
fn distinct(v: impl IntoIterator<Item = i64>, lo: i64, hi: i64) -> Vec<i64> {
    v.into_iter()
        .filter(|x| (lo..=hi).contains(x))
        .collect::<BTreeSet<_>>()
        .into_iter()
        .collect()
}

/// The filter lerp `a + (b - a) w / 2^wb` (`hw_model::trilinear::lerp`) at the trilinear
/// unit's widths: `texel_bits` operands, `weight_bits` (at most 16, as the filter uses it)
/// weight fraction bits, `filter_rounding`.
struct Lerp {
    cfg: hw_model::config::TrilinearConfig,
    tb: u32,
    wb: u32,
}

impl Lerp {
    fn new(hw: &HwConfig) -> Self {
        Self {
            cfg: hw.trilinear.clone(),
            tb: hw.trilinear.texel_bits.clamp(1, 16),
            wb: hw.trilinear.weight_bits.min(16),
        }
    }
}

impl UnitAdapter for Lerp {
    fn ports(&self) -> Vec<Port> {
        vec![
            Port::input("a", false, self.tb, 0).doc("first operand (texel channel, unorm code)"),
            Port::input("b", false, self.tb, 0).doc("second operand (texel channel, unorm code)"),
            Port::input("w", false, 1, self.wb)
                .doc("weight of b, in [0, 2^weight_bits] (weight_bits fraction bits)"),
            Port::output("y", false, self.tb, 0)
                .rounded(self.cfg.filter_rounding)
                .doc(
                    "a + (b - a) w / 2^weight_bits, one rounding; between a and b, never saturates",
                ),
        ]
    }

    fn config(&self) -> Value {
        json!({
            "trilinear": self.cfg,
            "operand_bits": self.tb,
            "weight_frac_bits": self.wb,
            "rounding": self.cfg.filter_rounding,
        })
    }

    fn boundary(&self) -> Vec<Vec<i64>> {
        let max = (1i64 << self.tb) - 1;
        let full = 1i64 << self.wb;
        let half = full / 2;
        let codes = distinct([0, 1, 2, max / 2, max / 2 + 1, max - 1, max], 0, max);
        let weights = distinct([0, 1, half - 1, half, half + 1, full - 1, full], 0, full);
        let mut cases = Vec::new();
        for &a in &codes {
            for &b in &codes {
                for &w in &weights {
                    cases.push(vec![a, b, w]);
                }
            }
        }
        // Rounding ties: (b - a) w / 2^wb exactly half-way, below and above even results.
        if self.wb >= 1 {
            for a in distinct([0, 1, 2, 3, 4, 100, max - 4, max - 3], 0, max) {
                for d in [1i64, 3, 5, -1, -3, -5] {
                    let b = a + d;
                    if (0..=max).contains(&b) {
                        cases.push(vec![a, b, half]);
                    }
                }
                if self.wb >= 2 {
                    for d in [2i64, 6, -2, -6] {
                        let b = a + d;
                        if (0..=max).contains(&b) {
                            cases.push(vec![a, b, full / 4]);
                            cases.push(vec![a, b, 3 * full / 4]);
                        }
                    }
                }
            }
        }
        cases
    }

    fn random(&self, rng: &mut SplitMix64) -> Vec<i64> {
        let max = (1i64 << self.tb) - 1;
        vec![
            rng.range(0, max),
            rng.range(0, max),
            rng.range(0, 1i64 << self.wb),
        ]
    }

    fn eval(&self, i: &[i64]) -> Vec<i64> {
        let y = hw_model::trilinear::lerp(
            i[0] as u32,
            i[1] as u32,
            i[2] as u32,
            self.wb,
            self.cfg.filter_rounding,
        );
        vec![i64::from(y)]
    }
}

/// One channel of the bilinear filter (`hw_model::trilinear::bilinear`) from four texels and
/// the two weights: a 2x2 level sampled with clamp-to-edge at `u = (2^wb + 2 wx) 2^-(wb+2)`, the
/// coordinate whose texel-space fraction is exactly `wx / 2^wb` (any weight rounding).
struct Bilinear {
    lerp: Lerp,
}

impl Bilinear {
    fn new(hw: &HwConfig) -> Self {
        Self {
            lerp: Lerp::new(hw),
        }
    }
}

impl UnitAdapter for Bilinear {
    fn ports(&self) -> Vec<Port> {
        let (tb, wb) = (self.lerp.tb, self.lerp.wb);
        let texel = |name, doc| Port::input(name, false, tb, 0).doc(doc);
        let weight = |name, doc| {
            if wb == 0 {
                Port::input(name, false, 1, 0).doc("always 0 (weight_bits = 0)")
            } else {
                Port::input(name, false, 0, wb).doc(doc)
            }
        };
        vec![
            texel("t00", "texel (x0, y0), unorm code"),
            texel("t10", "texel (x1, y0)"),
            texel("t01", "texel (x0, y1)"),
            texel("t11", "texel (x1, y1)"),
            weight("wx", "weight of x1, in [0, 2^weight_bits - 1]"),
            weight("wy", "weight of y1, in [0, 2^weight_bits - 1]"),
            Port::output("y", false, tb, 0)
                .rounded(self.lerp.cfg.filter_rounding)
                .doc("lerp(lerp(t00, t10, wx), lerp(t01, t11, wx), wy), each lerp rounded once"),
        ]
    }

    fn config(&self) -> Value {
        self.lerp.config()
    }

    fn boundary(&self) -> Vec<Vec<i64>> {
        let max = (1i64 << self.lerp.tb) - 1;
        let top = (1i64 << self.lerp.wb) - 1;
        let half = (top + 1) / 2;
        let weights = distinct([0, 1, half, top - 1, top], 0, top);
        let texels = [
            [0, 0, 0, 0],
            [max, max, max, max],
            [0, max, 0, max],
            [0, 0, max, max],
            [max, 0, 0, max],
            [0, 1, 1, 0],
            [0, 1, 2, 3],
            [max - 1, max, max, max - 1],
        ];
        let mut cases = Vec::new();
        for t in texels {
            for &wx in &weights {
                for &wy in &weights {
                    cases.push(vec![t[0], t[1], t[2], t[3], wx, wy]);
                }
            }
        }
        cases
    }

    fn random(&self, rng: &mut SplitMix64) -> Vec<i64> {
        let max = (1i64 << self.lerp.tb) - 1;
        let top = (1i64 << self.lerp.wb) - 1;
        let mut v: Vec<i64> = (0..4).map(|_| rng.range(0, max)).collect();
        v.extend([rng.range(0, top), rng.range(0, top)]);
        v
    }

    fn eval(&self, i: &[i64]) -> Vec<i64> {
        let wb = self.lerp.wb;
        let texels = [i[0], i[1], i[2], i[3]].map(|t| [t as u16, 0, 0, 0]);
        let level = hw_model::trilinear::Level {
            width: 2,
            height: 2,
            texels: &texels,
        };
        let coord = |w: i64| (1i64 << wb) + 2 * w;
        let out = hw_model::trilinear::bilinear(
            &level,
            coord(i[4]),
            coord(i[5]),
            wb + 2,
            [WrapMode::ClampToEdge; 2],
            &self.lerp.cfg,
            None,
        );
        vec![i64::from(out[0])]
    }
}

/// Input width of the reciprocal and rsqrt vectors: the interpolator and the normalizer feed
/// those units values of at most 62 bits.
const WIDE_INPUT_BITS: u32 = 62;

/// The reciprocal unit (`hw_model::reciprocal::Reciprocal::eval`).
struct Recip {
    unit: Reciprocal,
}

impl Recip {
    fn new(hw: &HwConfig) -> Self {
        Self {
            unit: Reciprocal::new(&hw.reciprocal),
        }
    }
}

impl UnitAdapter for Recip {
    fn ports(&self) -> Vec<Port> {
        let m = self.unit.config().recip_mantissa_bits;
        let r = self.unit.config().recip_rounding;
        vec![
            Port::input("x", false, WIDE_INPUT_BITS, 0)
                .doc("integer operand (the caller tracks its binary point)"),
            Port::output("mant", false, 1, m).rounded(r).doc(
                "1/x = mant * 2^-shift, mant in [2^M, 2^(M+1)) (M = recip_mantissa_bits); x = 0: 2^(M+1) - 1",
            ),
            Port::output("shift", true, 7, 0).doc("binary exponent of the result (x = 0: 0)"),
            Port::output("sat", false, 1, 0).doc("1 when x = 0 (saturated result)"),
        ]
    }

    fn config(&self) -> Value {
        json!({
            "reciprocal": self.unit.config(),
            "guard_bits": hw_model::reciprocal::GUARD_BITS,
            "rounding": self.unit.config().recip_rounding,
        })
    }

    fn boundary(&self) -> Vec<Vec<i64>> {
        let c = self.unit.config();
        let p = c.recip_mantissa_bits + hw_model::reciprocal::GUARD_BITS;
        let l = c.recip_lut_bits;
        let top = (1i64 << WIDE_INPUT_BITS) - 1;
        let mut v = vec![0, 1, 2, 3, 5, 7, top, top - 1];
        for k in 1..WIDE_INPUT_BITS {
            let pk = 1i64 << k;
            v.extend([pk, pk - 1, pk + 1]);
        }
        // Input rounding to P fraction bits: ties (P + 2 significant bits ending in 1) and the
        // carry to 2.0.
        for extra in 1..=3u32 {
            let base = 1i64 << (p + extra);
            v.extend([base + (1 << (extra - 1)), base + 3 * (1 << (extra - 1))]);
            v.push((base << 1) - 1);
        }
        // Every seed-LUT interval: its first mantissa and the last of the one before (for LUTs
        // of up to 2^12 entries; the random cases cover larger ones).
        if l <= 12 {
            for i in 0..(1i64 << l) {
                let m = ((1i64 << l) + i) << (p - l.min(p));
                v.extend([m, m - 1]);
            }
        }
        distinct(v, 0, top).into_iter().map(|x| vec![x]).collect()
    }

    fn random(&self, rng: &mut SplitMix64) -> Vec<i64> {
        vec![rng.log_uniform(WIDE_INPUT_BITS) as i64]
    }

    fn eval(&self, i: &[i64]) -> Vec<i64> {
        let mut sat = SatCounter::default();
        let r = self.unit.eval(i[0] as u64, &mut sat);
        vec![
            r.mant as i64,
            i64::from(r.shift),
            (sat.saturated > 0) as i64,
        ]
    }
}

/// The reciprocal square root unit of the shading datapath (`hw_model::rsqrt::Rsqrt::eval`).
struct RsqrtUnit {
    cfg: hw_model::rsqrt::RsqrtConfig,
    unit: Rsqrt,
}

impl RsqrtUnit {
    fn new(hw: &HwConfig) -> Self {
        Self {
            cfg: hw.shading.rsqrt.clone(),
            unit: Rsqrt::new(&hw.shading.rsqrt),
        }
    }
}

impl UnitAdapter for RsqrtUnit {
    fn ports(&self) -> Vec<Port> {
        let b = self.unit.mantissa_bits();
        vec![
            Port::input("x", false, WIDE_INPUT_BITS, 0).doc("integer operand"),
            Port::output("mant", false, 1, b).rounded(self.cfg.rsqrt_rounding).doc(
                "1/sqrt(x) = mant * 2^-shift, mant in [2^(B-1), 2^B] (B = rsqrt_mantissa_bits); 0 when x = 0",
            ),
            Port::output("shift", true, 7, 0).doc("binary exponent of the result (x = 0: 0)"),
            Port::output("valid", false, 1, 0).doc("0 when x = 0 (no result; the caller falls back)"),
        ]
    }

    fn config(&self) -> Value {
        json!({
            "rsqrt": self.cfg,
            "mantissa_bits": self.unit.mantissa_bits(),
            "guard_bits": hw_model::rsqrt::RSQRT_GUARD_BITS,
            "rounding": self.cfg.rsqrt_rounding,
        })
    }

    fn boundary(&self) -> Vec<Vec<i64>> {
        let b = self.unit.mantissa_bits();
        let top = (1i64 << WIDE_INPUT_BITS) - 1;
        let mut v = vec![0, 1, 2, 3, 4, 5, 8, 9, top, top - 1];
        for k in 1..WIDE_INPUT_BITS {
            let pk = 1i64 << k;
            v.extend([pk, pk - 1, pk + 1]);
        }
        // Input rounding to B significant bits: ties and the carry, both exponent parities.
        for extra in 1..=4u32 {
            let base = 1i64 << (b - 1 + extra);
            v.extend([base + (1 << (extra - 1)), base + 3 * (1 << (extra - 1))]);
            v.push((base << 1) - 1);
        }
        // Seed-LUT intervals (exponent parity x top L-1 fraction bits), both parities.
        let l = self.cfg.rsqrt_lut_bits.clamp(1, b);
        if l <= 12 {
            for parity in 0..2i64 {
                for j in 0..(1i64 << (l - 1)) {
                    let m = ((1i64 << (l - 1)) + j) << (b - l);
                    v.extend([m << parity, (m << parity) - 1]);
                }
            }
        }
        distinct(v, 0, top).into_iter().map(|x| vec![x]).collect()
    }

    fn random(&self, rng: &mut SplitMix64) -> Vec<i64> {
        vec![rng.log_uniform(WIDE_INPUT_BITS) as i64]
    }

    fn eval(&self, i: &[i64]) -> Vec<i64> {
        match self.unit.eval(i[0] as u64) {
            Some(r) => vec![r.mant as i64, i64::from(r.shift), 1],
            None => vec![0, 0, 0],
        }
    }
}

/// Largest level side of the wrap vectors (the largest texture side texsim accepts).
const WRAP_MAX_SIZE: i64 = 16384;

/// The texel address and wrap unit of one axis (`hw_model::wrap::wrap`), with the interpolator's
/// texture-coordinate format and the trilinear unit's weight bits and rounding.
struct Wrap {
    cfg: hw_model::config::TrilinearConfig,
    int_bits: u32,
    frac: u32,
    wb: u32,
}

impl Wrap {
    fn new(hw: &HwConfig) -> Self {
        let frac = hw.interp.texcoord_frac_bits.min(60);
        Self {
            cfg: hw.trilinear.clone(),
            int_bits: hw.interp.texcoord_int_bits.min(62 - frac),
            frac,
            wb: hw.trilinear.weight_bits.min(16),
        }
    }

    fn mode(code: i64) -> WrapMode {
        match code {
            0 => WrapMode::Repeat,
            1 => WrapMode::ClampToEdge,
            _ => WrapMode::Mirror,
        }
    }
}

impl UnitAdapter for Wrap {
    fn ports(&self) -> Vec<Port> {
        vec![
            Port::input("coord", true, self.int_bits, self.frac)
                .doc("normalized texture coordinate (1.0 = the level's width)"),
            Port::input("size", false, 15, 0).doc("level size in texels, 1..=16384"),
            Port::input("mode", false, 2, 0).doc("0 repeat, 1 clamp-to-edge, 2 mirror"),
            Port::output("i0", false, 14, 0).doc("first texel index, in [0, size-1]"),
            Port::output("i1", false, 14, 0).doc("second texel index, in [0, size-1]"),
            if self.wb == 0 {
                Port::output("weight", false, 1, 0).doc("weight of i1: always 0 (weight_bits = 0)")
            } else {
                Port::output("weight", false, 0, self.wb)
                    .rounded(self.cfg.weight_rounding)
                    .doc("weight of i1, in [0, 2^weight_bits - 1] (weight_bits fraction bits)")
            },
        ]
    }

    fn config(&self) -> Value {
        json!({
            "trilinear": self.cfg,
            "texcoord_int_bits": self.int_bits,
            "texcoord_frac_bits": self.frac,
            "weight_frac_bits": self.wb,
            "rounding": self.cfg.weight_rounding,
        })
    }

    fn boundary(&self) -> Vec<Vec<i64>> {
        let f = self.frac;
        let one = 1i64 << f;
        let hi = (1i64 << (self.int_bits + f)) - 1;
        let lo = -hi - 1;
        let mut coords = vec![
            0,
            1,
            -1,
            one / 2,
            one,
            -one,
            one - 1,
            one + 1,
            2 * one,
            -2 * one,
            hi,
            lo,
            hi - 1,
            lo + 1,
            hi / 2,
            lo / 2,
        ];
        // The weight carry (fraction of s just below 1), size 1.
        coords.push(3 * (one / 2) - 1);
        coords = distinct(coords, lo, hi);
        let sizes = [1i64, 2, 3, 7, 8, 255, 256, 1000, WRAP_MAX_SIZE];
        let mut cases = Vec::new();
        for &c in &coords {
            for &s in &sizes {
                for m in 0..3 {
                    cases.push(vec![c, s, m]);
                }
            }
        }
        // Weight rounding ties: s = coord * size - 1/2 exactly half a weight LSB above
        // j / 2^wb, for sizes 2^k (needs frac - wb >= k + 1).
        for k in [0u32, 3, 7] {
            if f < self.wb + k + 1 {
                continue;
            }
            for j in [0i64, 1, 2, 3, -1, -2, 5, 6] {
                let num = one + (1i64 << (f - self.wb)) + 2 * j * (1i64 << (f - self.wb));
                let c = num >> (k + 1);
                if (lo..=hi).contains(&c) {
                    for m in 0..3 {
                        cases.push(vec![c, 1i64 << k, m]);
                    }
                }
            }
        }
        cases
    }

    fn random(&self, rng: &mut SplitMix64) -> Vec<i64> {
        let f = self.frac;
        let hi = (1i64 << (self.int_bits + f)) - 1;
        let coord = match rng.range(0, 3) {
            0 => rng.range(-hi - 1, hi),
            1 => rng.range(-(4i64 << f), 4i64 << f),
            _ => rng.range(-(1i64 << f), 1i64 << f),
        };
        let size = if rng.next_u64() & 1 == 0 {
            1i64 << rng.range(0, 14)
        } else {
            rng.range(1, WRAP_MAX_SIZE)
        };
        vec![coord, size, rng.range(0, 2)]
    }

    fn eval(&self, i: &[i64]) -> Vec<i64> {
        let w = hw_model::wrap::wrap(i[0], self.frac, i[1] as u32, Self::mode(i[2]), &self.cfg);
        vec![i64::from(w.i0), i64::from(w.i1), i64::from(w.weight)]
    }
}

/// Integer bits of the LOD vectors' derivatives (level-0 texels per pixel, up to 2^16).
const LOD_DERIV_INT_BITS: u32 = 16;

/// The LOD unit (`hw_model::lod::lod`), derivatives in the interpolator's texture-coordinate
/// fraction bits.
struct Lod {
    cfg: hw_model::config::LodConfig,
    frac: u32,
}

impl Lod {
    fn new(hw: &HwConfig) -> Self {
        Self {
            cfg: hw.lod.clone(),
            frac: hw.interp.texcoord_frac_bits.min(62 - LOD_DERIV_INT_BITS),
        }
    }
}

impl UnitAdapter for Lod {
    fn ports(&self) -> Vec<Port> {
        let d = |name, doc| Port::input(name, true, LOD_DERIV_INT_BITS, self.frac).doc(doc);
        let lf = self.cfg.lod_frac_bits.min(16);
        vec![
            d("dudx", "du/dx in level-0 texels"),
            d("dvdx", "dv/dx in level-0 texels"),
            d("dudy", "du/dy in level-0 texels"),
            d("dvdy", "dv/dy in level-0 texels"),
            Port::output("lod", true, 6, lf).rounded(Rounding::Truncate).doc(
                "floor(log2(rho) 2^lod_frac_bits), rho the longer derivative vector; rho = 0: -(32 << lod_frac_bits)",
            ),
            Port::output("sat", false, 1, 0).doc("1 when 0 < rho < 2^-32 (clamped)"),
        ]
    }

    fn config(&self) -> Value {
        json!({
            "lod": self.cfg,
            "derivative_frac_bits": self.frac,
            "rounding": Rounding::Truncate,
        })
    }

    fn boundary(&self) -> Vec<Vec<i64>> {
        let f = self.frac;
        let top = (1i64 << (LOD_DERIV_INT_BITS + f)) - 1;
        let one = 1i64 << f;
        let mut cases = vec![vec![0, 0, 0, 0]];
        for k in 0..(LOD_DERIV_INT_BITS + f) {
            let v = 1i64 << k;
            cases.push(vec![v, 0, 0, 0]);
            cases.push(vec![0, 0, 0, -v]);
            cases.push(vec![v - 1, v - 1, 0, 0]);
            cases.push(vec![v, v, v, v]);
        }
        for v in [top, -top - 1, top - 1] {
            cases.push(vec![v, v, v, v]);
            cases.push(vec![v, 0, 0, v]);
        }
        // Footprints just above and below one texel, and the larger axis switching.
        for d in [-1i64, 1, 2] {
            cases.push(vec![one + d, 0, 0, one]);
            cases.push(vec![one, 0, 0, one + d]);
            cases.push(vec![one + d, one + d, one, one]);
        }
        // 3-4-5 triangles: exact lengths 5 * 2^k.
        for k in 0..(LOD_DERIV_INT_BITS + f - 3) {
            cases.push(vec![3 << k, 4 << k, 4 << k, -(3 << k)]);
        }
        cases
    }

    fn random(&self, rng: &mut SplitMix64) -> Vec<i64> {
        let mag = LOD_DERIV_INT_BITS + self.frac;
        (0..4).map(|_| rng.signed_log(mag)).collect()
    }

    fn eval(&self, i: &[i64]) -> Vec<i64> {
        let mut sat = SatCounter::default();
        let l = hw_model::lod::lod([i[0], i[1], i[2], i[3]], self.frac, &self.cfg, &mut sat);
        vec![l, (sat.saturated > 0) as i64]
    }
}
