//! Range instrumentation (`texsim render --ranges`): per stage and signal, the least and
//! largest value the float reference computes over a render, how many values fall outside
//! the signal's declared format (would saturate or wrap), and the integer bits the signal
//! needs (as MATLAB Fixed-Point Designer proposes data types from simulation min/max).
//!
//! Texture coordinates are recorded as the float reference interpolates them, before the
//! per-triangle offset reduction the hardware applies (`texcoord_reduce`), so `uv`'s
//! integer bits are those of a datapath without that reduction.
//!
//! A separate pass over the covered pixels with the all-float twins: the hardware and
//! reference passes carry no counters for it, so a render without `--ranges` costs nothing.

use super::shading::{frag_scratch, shade_row, ShadeInput};
use crate::pipeline::{Frag, Program, StageImpls, StageKind};
use hw_model::fixed::Format;
use rayon::prelude::*;
use serde::Serialize;

/// A per-pixel signal: its stage, name, values in a fragment, declared format.
struct Signal {
    stage: StageKind,
    name: &'static str,
    values: fn(&Frag, &mut dyn FnMut(f64)),
    format: fn(&crate::pipeline::stages::Machine) -> Format,
}

fn each(v: &[f64], f: &mut dyn FnMut(f64)) {
    for &x in v {
        f(x);
    }
}

fn unorm(bits: u32) -> Format {
    Format::unsigned(0, bits, hw_model::fixed::Rounding::HalfEven)
}

/// Every instrumented signal, in pipeline order (each a float carrier of [`Frag`]).
const SIGNALS: &[Signal] = &[
    Signal {
        stage: StageKind::Bary,
        name: "bary",
        values: |f, o| each(&f.bary[0], o),
        format: |m| m.bary_fmt,
    },
    Signal {
        stage: StageKind::Color,
        name: "color",
        values: |f, o| each(&f.color[..3], o),
        format: |m| m.color_fmt,
    },
    Signal {
        stage: StageKind::Texcoord,
        name: "uv",
        values: |f, o| each(&f.uv[0], o),
        format: |m| m.uv_fmt,
    },
    Signal {
        stage: StageKind::Lod,
        name: "lod",
        values: |f, o| o(f.lod),
        format: |m| m.lod_fmt,
    },
    Signal {
        stage: StageKind::Trilinear,
        name: "texel",
        values: |f, o| each(&f.texel, o),
        format: |m| unorm(m.hw.trilinear.texel_bits),
    },
    Signal {
        stage: StageKind::Modulate,
        name: "out",
        values: |f, o| each(&f.out[..3], o),
        format: |m| m.color_fmt,
    },
    Signal {
        stage: StageKind::Normal,
        name: "n_i",
        values: |f, o| each(&f.bump.n_i, o),
        format: |m| m.vec_fmt,
    },
    Signal {
        stage: StageKind::Normal,
        name: "to_eye",
        values: |f, o| each(&f.bump.to_eye, o),
        format: |m| m.vec_fmt,
    },
    Signal {
        stage: StageKind::Normal,
        name: "d_u",
        values: |f, o| each(&f.bump.d_u, o),
        format: |m| m.vec_fmt,
    },
    Signal {
        stage: StageKind::Normal,
        name: "d_v",
        values: |f, o| each(&f.bump.d_v, o),
        format: |m| m.vec_fmt,
    },
    Signal {
        stage: StageKind::Normal,
        name: "len",
        values: |f, o| each(&f.bump.len, o),
        format: |m| m.len_fmt,
    },
    Signal {
        stage: StageKind::BumpFetch,
        name: "offset_texel",
        values: |f, o| each(&f.bump.texel, o),
        format: |m| unorm(m.hw.trilinear.texel_bits),
    },
    Signal {
        stage: StageKind::Frame,
        name: "fr_n",
        values: |f, o| each(&f.bump.fr_n, o),
        format: |m| m.vec_fmt,
    },
    Signal {
        stage: StageKind::Frame,
        name: "fr_t_u",
        values: |f, o| each(&f.bump.fr_t_u, o),
        format: |m| m.vec_fmt,
    },
    Signal {
        stage: StageKind::Frame,
        name: "fr_t_v",
        values: |f, o| each(&f.bump.fr_t_v, o),
        format: |m| m.vec_fmt,
    },
    Signal {
        stage: StageKind::Frame,
        name: "fr_len",
        values: |f, o| each(&f.bump.fr_len, o),
        format: |m| m.len_fmt,
    },
    Signal {
        stage: StageKind::Perturb,
        name: "normal",
        values: |f, o| each(&f.bump.normal, o),
        format: |m| m.vec_fmt,
    },
    Signal {
        stage: StageKind::RoughFetch,
        name: "rough_texel",
        values: |f, o| each(&f.rough, o),
        format: |m| unorm(m.hw.trilinear.texel_bits),
    },
];

/// One signal's range over a render.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SignalRange {
    pub stage: String,
    pub signal: String,
    /// Declared format, `s1.14` (signed, 1 integer bit, 14 fraction bits) or `u0.16`.
    pub format: String,
    /// Values recorded (channels x pixels).
    pub samples: u64,
    pub min: f64,
    pub max: f64,
    /// Values outside the declared format's range (the hardware saturates or wraps them).
    pub outside: u64,
    /// Integer bits (not counting a sign) that hold every value seen: the least `I >= 0`
    /// with `max < 2^I` and `min >= -2^I`.
    pub int_bits_needed: u32,
    /// A sign bit is needed (some value below 0).
    pub signed_needed: bool,
    /// The declared integer bits.
    pub int_bits_declared: u32,
}

/// Integer bits holding `[min, max]` (see [`SignalRange::int_bits_needed`]); a signal in
/// `[0, 1]` needs none (a unorm format's all-ones code is 1.0).
#[must_use]
pub fn int_bits_for(min: f64, max: f64) -> u32 {
    if min >= 0.0 && max <= 1.0 {
        return 0;
    }
    let mut i = 0;
    while i < 64 && (max >= 2f64.powi(i) || min < -(2f64.powi(i))) {
        i += 1;
    }
    i as u32
}

fn format_name(f: &Format) -> String {
    format!(
        "{}{}.{}",
        if f.signed { "s" } else { "u" },
        f.int_bits,
        f.frac_bits
    )
}

/// `[count, outside, min, max]` per signal (min/max as f64 in their own arrays).
#[derive(Clone)]
struct Acc {
    count: Vec<u64>,
    outside: Vec<u64>,
    min: Vec<f64>,
    max: Vec<f64>,
}

impl Acc {
    fn new() -> Self {
        let n = SIGNALS.len();
        Self {
            count: vec![0; n],
            outside: vec![0; n],
            min: vec![f64::INFINITY; n],
            max: vec![f64::NEG_INFINITY; n],
        }
    }

    fn merge(mut self, o: Self) -> Self {
        for i in 0..SIGNALS.len() {
            self.count[i] += o.count[i];
            self.outside[i] += o.outside[i];
            self.min[i] = self.min[i].min(o.min[i]);
            self.max[i] = self.max[i].max(o.max[i]);
        }
        self
    }
}

/// Runs the float twins over the covered pixels of `inp` and returns the range of every
/// signal of a stage the plans use (signals never computed are left out).
pub(super) fn measure(inp: &ShadeInput) -> Vec<SignalRange> {
    let m = inp.m;
    let progs: Vec<Program> = inp
        .geo
        .plans
        .iter()
        .map(|p| Program::new(p, &StageImpls::FLOAT, m))
        .collect();
    let bounds: Vec<(f64, f64)> = SIGNALS
        .iter()
        .map(|s| {
            let f = (s.format)(m);
            let lsb = 2f64.powi(-(f.frac_bits as i32));
            let top = 2f64.powi(f.int_bits as i32);
            // Unorm formats with no integer bits hold 0..=1 (their all-ones code is 1.0).
            let hi = if !f.signed && f.int_bits == 0 {
                1.0
            } else {
                top - lsb
            };
            let lo = if f.signed { -top } else { 0.0 };
            (lo, hi)
        })
        .collect();
    let plans = &inp.geo.plans;
    let w = inp.vis.width as usize;
    let rows = inp.vis.height as usize;
    let acc = (0..rows)
        .into_par_iter()
        .map_init(frag_scratch, |frags, y| {
            let mut acc = Acc::new();
            let mut row = vec![[0u16; 4]; w];
            let mut c = crate::pipeline::stages::Counters::default();
            shade_row(
                inp,
                &progs,
                y,
                &mut row,
                frags,
                &mut c,
                false,
                |pi, _, frag| {
                    let plan = &plans[pi as usize];
                    for (i, s) in SIGNALS.iter().enumerate() {
                        if !plan.stages.contains(&s.stage) {
                            continue;
                        }
                        let (lo, hi) = bounds[i];
                        (s.values)(frag, &mut |x| {
                            if !x.is_finite() {
                                return;
                            }
                            acc.count[i] += 1;
                            acc.outside[i] += u64::from(x < lo || x > hi);
                            acc.min[i] = acc.min[i].min(x);
                            acc.max[i] = acc.max[i].max(x);
                        });
                    }
                },
            );
            acc
        })
        .reduce(Acc::new, Acc::merge);
    SIGNALS
        .iter()
        .enumerate()
        .filter(|(i, _)| acc.count[*i] > 0)
        .map(|(i, s)| {
            let f = (s.format)(m);
            SignalRange {
                stage: s.stage.name().to_string(),
                signal: s.name.to_string(),
                format: format_name(&f),
                samples: acc.count[i],
                min: acc.min[i],
                max: acc.max[i],
                outside: acc.outside[i],
                int_bits_needed: int_bits_for(acc.min[i], acc.max[i]),
                signed_needed: acc.min[i] < 0.0,
                int_bits_declared: f.int_bits,
            }
        })
        .collect()
}

/// The ranges as a terminal table: stage, signal, declared format, min, max, values outside
/// the format, the integer bits needed against those declared (`+N` more needed, `-N` spare),
/// and the stage's saturations and wraps in the hardware pass.
#[must_use]
pub fn table(rows: &[SignalRange], stages: &[super::StageStats]) -> String {
    use std::fmt::Write;
    let mut o = String::new();
    let _ = writeln!(
        o,
        "signal ranges (float reference; integer bits as Fixed-Point Designer would propose):"
    );
    let _ = writeln!(
        o,
        "{:<11} {:<13} {:<8} {:>12} {:>12} {:>10} {:>9} {:>6} {:>9}  hw sat+wrap",
        "stage", "signal", "format", "min", "max", "samples", "outside", "int", "vs decl"
    );
    for r in rows {
        let hw = stages
            .iter()
            .find(|s| s.stage.name() == r.stage)
            .map_or(0, |s| s.saturated + s.wrapped);
        let need = format!(
            "{}{}",
            if r.signed_needed { "s" } else { "u" },
            r.int_bits_needed
        );
        let delta = i64::from(r.int_bits_needed) - i64::from(r.int_bits_declared);
        let _ = writeln!(
            o,
            "{:<11} {:<13} {:<8} {:>12.6} {:>12.6} {:>10} {:>9} {:>6} {:>9}  {hw}",
            r.stage,
            r.signal,
            r.format,
            r.min,
            r.max,
            r.samples,
            r.outside,
            need,
            if delta == 0 {
                "=".to_string()
            } else {
                format!("{delta:+}")
            },
        );
    }
    o
}
