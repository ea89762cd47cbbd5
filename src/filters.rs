//! The filtering-method comparison (`texsim filters`): every way texsim has of shading a bump
//! map seen from afar, on the same scenes, against the same supersampled ground truth, with
//! their error and cost side by side.
//!
//! [`METHODS`] is the one list of methods: a row says how a bump material and the hardware
//! are set for the method and how many bytes a texel of its maps occupies. Adding a method
//! is one entry (the Fournier rows `fournier-K` are four).
//!
//! Every scene is rendered once per method with the reference and the ground truth
//! (`RenderOptions::truth`): the plain bump map, Toksvig, LEAN, Schilling's roughness pyramid
//! and the fitted Fournier lobes are measured against the box-filtered mean of plain
//! Blinn-Phong over the finest offsets (`pipeline::rough` truth mode); the Olano-North rows against the mean of the exactly
//! normalized base lobes of the finest normals (`pipeline::ndf::NdfTruth`, the same normals,
//! the von Mises-Fisher lobe `exp(s (n.h - 1))` in place of `(n.h)^s`; the two truths differ by
//! the lobe shape, below 1/s in angle).

use crate::maps::Maps;
use crate::render::{render, RenderOptions};
use crate::scene::{BumpFilter, LobeCount, Material, RoughChoice, Scene};
use crate::summary::SweepRow;
use hw_model::ndf::NdfNorm;
use hw_model::roughness::RoughVariant;
use hw_model::timing_config::stored_texel_bytes;
use hw_model::HwConfig;
use serde::Serialize;

/// One filtering method.
pub struct Method {
    /// The name in the table and on the command line.
    pub name: &'static str,
    /// What the method is (paper).
    pub what: &'static str,
    /// Which ground truth its model error is measured against.
    pub truth: &'static str,
    /// Sets a bump material for the method.
    pub material: fn(&mut Material),
    /// Sets the hardware for the method.
    pub hw: fn(&mut HwConfig),
    /// Bytes per texel position of the maps the method reads (summed over its maps).
    pub bytes_per_texel: fn(&HwConfig) -> u32,
}

const BLINN_TRUTH: &str = "blinn-phong";
const NDF_TRUTH: &str = "ndf-lobes";

fn offset_bytes(hw: &HwConfig) -> u32 {
    stored_texel_bytes(crate::maps::OFFSET_CHANNELS, hw.trilinear.texel_bits)
}

fn ndf_bytes(hw: &HwConfig) -> u32 {
    let b = hw.ndf.moment_bits;
    let n = if hw.ndf.ndf_norm == NdfNorm::Map {
        stored_texel_bytes(1, b)
    } else {
        0
    };
    3 * stored_texel_bytes(3, b) + n
}

fn no_hw(_: &mut HwConfig) {}

fn set_bump(m: &mut Material, rough: Option<RoughChoice>, ndf: bool, f: BumpFilter) {
    m.roughness = rough;
    m.ndf = ndf;
    m.bump_filter = f;
    m.fournier_lobes = None;
}

/// Fournier lobes fitted per texel (`pipeline::lobe_fit`), `k` of them.
fn set_lobes(m: &mut Material, k: u32) {
    set_bump(m, None, false, BumpFilter::Plain);
    m.fournier_lobes = Some(LobeCount::Lobes(k));
}

/// The lobe maps replace the offset map: K maps of four 16-bit channels (`lobe_fit`).
fn lobe_bytes(k: u32) -> u32 {
    k * stored_texel_bytes(4, 16)
}

fn ndf_norm(hw: &mut HwConfig, n: NdfNorm) {
    hw.ndf.ndf_norm = n;
}

/// The methods, in table order.
pub const METHODS: &[Method] = &[
    Method {
        name: "plain",
        what: "filtered bump map, Blinn-Phong (the baseline)",
        truth: BLINN_TRUTH,
        material: |m| {
            set_bump(
                m,
                Some(RoughChoice::Variant(RoughVariant::None)),
                false,
                BumpFilter::Plain,
            );
        },
        hw: no_hw,
        bytes_per_texel: offset_bytes,
    },
    Method {
        name: "toksvig",
        what: "Toksvig 2005: exponent from |Na| of the MIP-mapped normal",
        truth: BLINN_TRUTH,
        material: |m| set_bump(m, None, false, BumpFilter::Toksvig),
        hw: no_hw,
        bytes_per_texel: |hw| offset_bytes(hw) + stored_texel_bytes(3, hw.trilinear.texel_bits),
    },
    Method {
        name: "lean",
        what: "Olano-Baker 2010 LEAN map: slope Gaussian from five moments",
        truth: BLINN_TRUTH,
        material: |m| set_bump(m, None, false, BumpFilter::Lean),
        hw: no_hw,
        bytes_per_texel: |hw| offset_bytes(hw) + stored_texel_bytes(3, hw.trilinear.texel_bits),
    },
    Method {
        name: "schilling",
        what: "Schilling 1997 roughness pyramid (directional variant)",
        truth: BLINN_TRUTH,
        material: |m| {
            set_bump(
                m,
                Some(RoughChoice::Variant(RoughVariant::Directional)),
                false,
                BumpFilter::Plain,
            );
        },
        hw: no_hw,
        bytes_per_texel: |hw| {
            let b = hw.roughness.rough_d_bits.min(hw.trilinear.texel_bits);
            offset_bytes(hw) + stored_texel_bytes(3, b)
        },
    },
    Method {
        name: "ndf-partial",
        what: "Olano-North 1997 NDF map, partial normalization",
        truth: NDF_TRUTH,
        material: |m| set_bump(m, None, true, BumpFilter::Plain),
        hw: |hw| ndf_norm(hw, NdfNorm::Partial),
        bytes_per_texel: ndf_bytes,
    },
    Method {
        name: "ndf-map",
        what: "Olano-North 1997 NDF map, normalization map",
        truth: NDF_TRUTH,
        material: |m| set_bump(m, None, true, BumpFilter::Plain),
        hw: |hw| ndf_norm(hw, NdfNorm::Map),
        bytes_per_texel: ndf_bytes,
    },
    Method {
        name: "ndf-projected",
        what: "Olano-North 1997 NDF map, projected 2D normalization",
        truth: NDF_TRUTH,
        material: |m| set_bump(m, None, true, BumpFilter::Plain),
        hw: |hw| ndf_norm(hw, NdfNorm::Projected),
        bytes_per_texel: ndf_bytes,
    },
    Method {
        name: "ndf-exact",
        what: "Olano-North 1997 NDF map, exact normalization (float only, no cost model)",
        truth: NDF_TRUTH,
        material: |m| set_bump(m, None, true, BumpFilter::Plain),
        hw: |hw| ndf_norm(hw, NdfNorm::Exact),
        bytes_per_texel: ndf_bytes,
    },
    Method {
        name: "fournier-1",
        what: "Fournier 1992 lobes fitted per texel (EM, vMF), K = 1, nearest level",
        truth: BLINN_TRUTH,
        material: |m| set_lobes(m, 1),
        hw: no_hw,
        bytes_per_texel: |_| lobe_bytes(1),
    },
    Method {
        name: "fournier-2",
        what: "Fournier 1992 lobes fitted per texel (EM, vMF), K = 2, nearest level",
        truth: BLINN_TRUTH,
        material: |m| set_lobes(m, 2),
        hw: no_hw,
        bytes_per_texel: |_| lobe_bytes(2),
    },
    Method {
        name: "fournier-4",
        what: "Fournier 1992 lobes fitted per texel (EM, vMF), K = 4, nearest level",
        truth: BLINN_TRUTH,
        material: |m| set_lobes(m, 4),
        hw: no_hw,
        bytes_per_texel: |_| lobe_bytes(4),
    },
    Method {
        name: "fournier-8",
        what: "Fournier 1992 lobes fitted per texel (EM, vMF), K = 8, nearest level",
        truth: BLINN_TRUTH,
        material: |m| set_lobes(m, 8),
        hw: no_hw,
        bytes_per_texel: |_| lobe_bytes(8),
    },
];

/// The method named `name`; the error lists the names.
pub fn method(name: &str) -> crate::Result<&'static Method> {
    METHODS.iter().find(|m| m.name == name).ok_or_else(|| {
        let names: Vec<&str> = METHODS.iter().map(|m| m.name).collect();
        crate::Error::msg(format!(
            "unknown filtering method '{name}' (methods: {})",
            names.join(", ")
        ))
    })
}

/// One row of the comparison.
#[derive(Clone, Debug, Serialize)]
pub struct FilterRow {
    pub scene: String,
    pub method: String,
    pub truth: String,
    /// Float reference vs ground truth, mean and RMS absolute error in 8-bit LSBs.
    pub model_mean: f64,
    pub model_rmse: f64,
    /// Hardware vs float reference (8-bit LSBs): largest and mean error.
    pub quant_max: u32,
    pub quant_mean: f64,
    pub bytes_per_texel: u32,
    /// Texels fetched per covered pixel (all lookups of the pixel, 8 per trilinear lookup).
    pub texels_per_pixel: f64,
    /// Issue cycles per covered pixel (stage cost model; `None` without a cost model).
    pub issue_cycles_per_pixel: Option<f64>,
    /// The timing model's frame cycles per covered pixel (`None` when it did not run).
    pub cycles_per_pixel: Option<f64>,
    pub covered_pixels: u64,
}

/// What to compare.
#[derive(Clone, Debug)]
pub struct FilterOptions {
    /// Ground-truth sub-samples per pixel axis (at least 1).
    pub truth: u32,
    /// Run the timing model per render.
    pub timing: bool,
}

/// `scene` with every bump material set for method `m` (other materials unchanged); `None`
/// when the scene has no bump material.
#[must_use]
pub fn scene_for(scene: &Scene, m: &Method) -> Option<Scene> {
    let mut s = scene.clone();
    let mut any = false;
    for mat in &mut s.materials {
        if mat.bump.is_some() && mat.brdf.is_none() {
            (m.material)(mat);
            any = true;
        }
    }
    any.then_some(s)
}

/// Renders `scene` (named `name`) with every method of `methods` on `hw`, with truth;
/// `progress` is told each method before it runs.
pub fn compare_scene(
    name: &str,
    scene: &Scene,
    hw: &HwConfig,
    methods: &[&Method],
    opts: &FilterOptions,
    progress: &dyn Fn(&str),
) -> crate::Result<Vec<FilterRow>> {
    let mut rows = Vec::with_capacity(methods.len());
    for m in methods {
        let Some(sc) = scene_for(scene, m) else {
            return Err(crate::Error::msg(format!(
                "scene '{name}' has no bump material to filter"
            )));
        };
        progress(m.name);
        let mut cfg = hw.clone();
        (m.hw)(&mut cfg);
        let maps = Maps::with_offset_bits(
            &sc,
            cfg.trilinear.texel_bits,
            cfg.shading.vector.offset_int_bits,
        );
        let ro = RenderOptions {
            timing: opts.timing,
            keep_events: false,
            truth: opts.truth.max(1),
            ..RenderOptions::default()
        };
        let r = render(&sc, &maps, &cfg, &ro)?;
        let row = SweepRow::new(Vec::new(), &r.stats);
        let px = r.stats.covered_pixels.max(1) as f64;
        let (Some(me), Some(q)) = (&row.model_error, &row.error_8bit) else {
            return Err(crate::Error::msg(format!(
                "scene '{name}', method {}: no truth or reference was rendered",
                m.name
            )));
        };
        rows.push(FilterRow {
            scene: name.to_string(),
            method: m.name.to_string(),
            truth: m.truth.to_string(),
            model_mean: me.mean_abs_lsb,
            model_rmse: me.rmse_lsb,
            quant_max: q.max_abs_lsb,
            quant_mean: q.mean_abs_lsb,
            bytes_per_texel: (m.bytes_per_texel)(&cfg),
            texels_per_pixel: row.texels as f64 / px,
            issue_cycles_per_pixel: row.issue_cycles_per_pixel,
            cycles_per_pixel: row.cycles_per_pixel,
            covered_pixels: r.stats.covered_pixels,
        });
    }
    Ok(rows)
}

fn opt(x: Option<f64>) -> String {
    x.map_or_else(|| "-".into(), |v| format!("{v:.2}"))
}

const HEADER: [&str; 10] = [
    "scene",
    "method",
    "truth",
    "model mean",
    "model rmse",
    "quant max / mean",
    "bytes/texel",
    "texels/px",
    "issue cyc/px",
    "cyc/px",
];

fn cells(r: &FilterRow) -> [String; 10] {
    [
        r.scene.clone(),
        r.method.clone(),
        r.truth.clone(),
        format!("{:.3}", r.model_mean),
        format!("{:.3}", r.model_rmse),
        format!("{} / {:.4}", r.quant_max, r.quant_mean),
        r.bytes_per_texel.to_string(),
        format!("{:.2}", r.texels_per_pixel),
        opt(r.issue_cycles_per_pixel),
        opt(r.cycles_per_pixel),
    ]
}

/// The table for a terminal (aligned columns).
#[must_use]
pub fn text_table(rows: &[FilterRow]) -> String {
    let all: Vec<[String; 10]> = rows.iter().map(cells).collect();
    let mut w = HEADER.map(str::len);
    for c in &all {
        for (wi, s) in w.iter_mut().zip(c) {
            *wi = (*wi).max(s.len());
        }
    }
    let line = |c: &[String]| {
        let v: Vec<String> = c
            .iter()
            .zip(&w)
            .map(|(s, &wi)| format!("{s:<wi$}"))
            .collect();
        v.join("  ").trim_end().to_string() + "\n"
    };
    let mut out = line(&HEADER.map(String::from));
    for c in &all {
        out += &line(c);
    }
    out
}

/// The table in Markdown.
#[must_use]
pub fn markdown_table(rows: &[FilterRow]) -> String {
    let mut out = format!("| {} |\n", HEADER.join(" | "));
    out += &format!("|{}\n", "---|".repeat(HEADER.len()));
    for r in rows {
        out += &format!("| {} |\n", cells(r).join(" | "));
    }
    out
}

/// The table as CSV (one header line, plain numbers, empty cells for missing costs).
#[must_use]
pub fn csv_table(rows: &[FilterRow]) -> String {
    let mut out = String::from(
        "scene,method,truth,model_mean,model_rmse,quant_max,quant_mean,bytes_per_texel,texels_per_pixel,issue_cycles_per_pixel,cycles_per_pixel,covered_pixels\n",
    );
    let o = |x: Option<f64>| x.map_or_else(String::new, |v| format!("{v:.4}"));
    for r in rows {
        out += &format!(
            "{},{},{},{:.4},{:.4},{},{:.5},{},{:.4},{},{},{}\n",
            r.scene,
            r.method,
            r.truth,
            r.model_mean,
            r.model_rmse,
            r.quant_max,
            r.quant_mean,
            r.bytes_per_texel,
            r.texels_per_pixel,
            o(r.issue_cycles_per_pixel),
            o(r.cycles_per_pixel),
            r.covered_pixels
        );
    }
    out
}
