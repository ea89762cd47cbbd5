//! The `texsim` command line. `texsim` alone is `texsim render --scene demo --out ./out`.

use crate::hwconfig;
use crate::pipeline::{Impl, StageImpls, StageKind};
use crate::render::{render, CoverageMode, Maps, RenderOptions, Rendered};
use crate::report::{self, OutputSet};
use crate::scene::{self, Scene};
use crate::{Error, Result};
use clap::{Args, Parser, Subcommand, ValueEnum};
use hw_model::HwConfig;
use std::path::PathBuf;

/// Bit-accurate simulator of fixed-function texture hardware (Texram-style).
#[derive(Parser, Debug)]
#[command(name = "texsim", version, about, long_about = None)]
pub struct Cli {
    /// Worker threads (default: all cores). Output is bit-identical for any count.
    #[arg(long, global = true)]
    pub threads: Option<usize>,
    /// Memory limit of the run (bytes, or with K, M, G, T: 4G). Every input is budgeted
    /// against it before anything large is allocated. Default: TEXSIM_MAX_MEMORY, else 2G.
    #[arg(long, global = true, value_name = "SIZE")]
    pub max_memory: Option<String>,
    /// Vector instruction set of the batch kernels: portable, avx2 or avx512 (at most what
    /// this CPU has). Output is bit-identical for any; only the time differs. Default:
    /// TEXSIM_VECTOR_ISA, else the widest this CPU has.
    #[arg(long, global = true, value_name = "ISA")]
    pub vector_isa: Option<String>,
    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render a scene on the simulated hardware and the float reference; write PNGs and summary.json.
    Render(RenderArgs),
    /// List the built-in scenes.
    Scenes,
    /// Render once per setting of one or more HwConfig fields; print and write the table.
    ///
    /// Columns: quant_* compare the hardware with the float reference (the quantization
    /// error; error_8bit.* and error_16bit.* in sweep.csv and sweep.json), model_* the float
    /// reference with the ground truth (--truth; model_error.*); sat: saturations and wraps;
    /// cycles, cyc/px, tex_bytes, dram_bytes: the timing model; area_ge, max_lat and
    /// area:UNIT, delay:UNIT, lat:UNIT: the datapath cost model. sweep.json also holds each
    /// row's worst pixel (location, hardware and reference values).
    Sweep(SweepArgs),
    /// Find the narrowest machine (least area) that keeps every --scene within every
    /// --budget: per-knob bisection, a greedy descent trading bits, a verified final run;
    /// writes tune.json, tune.csv and tuned.toml (a hw file for --hw) into --out.
    Tune(TuneArgs),
    /// Join the shards of a sweep (`sweep --shard K/N`) into one sweep.json, sweep.csv and
    /// table, in grid order; every shard and every grid row must be present once.
    Merge(MergeArgs),
    /// Hardware configurations.
    Hw {
        #[command(subcommand)]
        cmd: HwCmd,
    },
    /// Sample one texture through the trilinear unit (fixed and float), showing texels and weights.
    Probe(ProbeArgs),
    /// The Ashikhmin-Shirley anisotropic Phong BRDF: values, directional albedo, sampler statistics.
    Brdf {
        #[command(subcommand)]
        cmd: BrdfCmd,
    },
    /// Run the timing model on a scene: cycles, unit utilization, stalls, cache and banks;
    /// prints the report and writes cycles.json.
    Cycles(CyclesArgs),
    /// Test vectors for RTL: boundary and seeded random cases of a hw_model unit with the
    /// unit's outputs, as $readmemh files (one per port) and manifest.json.
    Vectors(VectorsArgs),
    /// Compare two images (a render against Mesa, a GPU capture, another simulator): match %,
    /// per-channel differences, histogram, error map, the pixels that differ most.
    Compare(CompareArgs),
    /// Fit Fournier multiple-surface lobes (K vMF lobes per texel, EM) to a procedural normal
    /// map at every MIP level: lobes, iterations, fallbacks, residual and time per level.
    Fit(crate::fit_cmd::FitArgs),
    /// Compare the bump-map filtering methods (plain bump map, Toksvig, LEAN, Schilling's
    /// roughness pyramid, Olano-North NDF with each normalization) on the same scenes and ground truth:
    /// model error, quantization error, bytes per texel, texels, issue and timing cycles per
    /// pixel; prints the table and writes filters.csv, filters.json and filters.md.
    Filters(FiltersArgs),
}

/// Arguments of `texsim filters`.
#[derive(Args, Debug, Clone)]
pub struct FiltersArgs {
    /// Built-in scenes with bump materials (repeat the flag, or a comma list), e.g.
    /// `--scene ripple-sphere --scene lake`.
    #[arg(long, value_delimiter = ',', required = true)]
    pub scene: Vec<String>,
    /// Methods to compare (comma list; default: all of `texsim::filters::METHODS`: plain,
    /// toksvig, lean, schilling, ndf-partial, ndf-map, ndf-projected, ndf-exact).
    #[arg(long, value_delimiter = ',')]
    pub method: Vec<String>,
    /// Override the image width and height of every scene.
    #[arg(long)]
    pub width: Option<u32>,
    #[arg(long)]
    pub height: Option<u32>,
    /// Hardware preset or hw TOML file (default: each scene's, else texram16).
    #[arg(long)]
    pub hw: Option<String>,
    /// Output directory.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Ground-truth sub-samples per pixel axis.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub truth: u32,
    /// Skip the timing model (no cyc/px column; faster).
    #[arg(long)]
    pub no_cycles: bool,
}

/// Arguments of `texsim vectors`.
#[derive(Args, Debug, Clone)]
pub struct VectorsArgs {
    /// The unit (`--list` shows them).
    #[arg(required_unless_present = "list")]
    pub unit: Option<String>,
    /// List the units and exit.
    #[arg(long)]
    pub list: bool,
    /// Hardware preset or hw TOML file: the unit's widths and rounding.
    #[arg(long, default_value = "texram16")]
    pub hw: String,
    /// Random cases (after the boundary cases).
    #[arg(long, default_value_t = 1000)]
    pub n: u64,
    /// Seed of the random cases.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output directory [default: out/vectors/UNIT].
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Which image's coverage selects the compared pixels (`texsim compare --coverage-from`).
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum CoverageFromArg {
    /// Pixels of A that differ from the clear colour.
    A,
    /// Pixels of B that differ from the clear colour.
    B,
    /// Pixels covered in A or in B.
    Either,
    /// Pixels covered in both.
    Both,
}

/// Arguments of `texsim compare`.
#[derive(Args, Debug, Clone)]
pub struct CompareArgs {
    /// First image (PNG or JPEG), e.g. a texsim hw.png.
    pub a: PathBuf,
    /// Second image, same size.
    pub b: PathBuf,
    /// Compare only where this image (same size) is not black in RGB.
    #[arg(long, conflicts_with = "coverage_from")]
    pub mask: Option<PathBuf>,
    /// Compare only covered pixels: those whose 8-bit RGBA differs from --clear, in A, B,
    /// either or both (the Mesa anchor counts coverage so, with clear 0,0,0,0).
    #[arg(long, value_enum)]
    pub coverage_from: Option<CoverageFromArg>,
    /// Clear colour of --coverage-from, 8-bit R,G,B,A.
    #[arg(long, default_value = "0,0,0,0", requires = "coverage_from")]
    pub clear: String,
    /// Bits of the difference unit (8 = what PNG8 holds).
    #[arg(long, default_value_t = 8)]
    pub bits: u32,
    /// How many of the most different pixels to list.
    #[arg(long, default_value_t = 10)]
    pub top: usize,
    /// Output directory (compare.json, compare_error.png).
    #[arg(long, default_value = "out/compare")]
    pub out: PathBuf,
}

/// Parameters of the Ashikhmin-Shirley BRDF.
#[derive(Args, Debug, Clone)]
pub struct BrdfParams {
    /// Phong exponent along the tangent u.
    #[arg(long, default_value_t = 10.0)]
    pub nu: f64,
    /// Phong exponent along the bitangent v.
    #[arg(long, default_value_t = 10.0)]
    pub nv: f64,
    /// Specular reflectance at normal incidence (Schlick's R_s).
    #[arg(long, default_value_t = 0.05)]
    pub rs: f64,
    /// Diffuse reflectance R_d.
    #[arg(long, default_value_t = 0.5)]
    pub rd: f64,
}

#[derive(Subcommand, Debug)]
pub enum BrdfCmd {
    /// Directional albedo at polar angle --theta (quadrature; Monte Carlo check). The last line
    /// is the albedo alone; --fixed gives the fixed-point unit's.
    Albedo {
        #[command(flatten)]
        p: BrdfParams,
        /// Polar angle of the incident direction in degrees, [0, 90).
        #[arg(long, default_value_t = 0.0)]
        theta: f64,
        /// Evaluate with the fixed-point unit of --hw.
        #[arg(long)]
        fixed: bool,
        /// Hardware preset or file (for --fixed).
        #[arg(long, default_value = "texram16")]
        hw: String,
    },
    /// BRDF value for the directions (theta1, phi1) and (theta2, phi2), in degrees. The last
    /// line is rho(k1, k2); --fixed gives the fixed-point unit's.
    Eval {
        #[command(flatten)]
        p: BrdfParams,
        /// Polar angle of k1 (toward the light) from the normal, in degrees.
        #[arg(long, default_value_t = 30.0)]
        theta1: f64,
        /// Azimuth of k1 from the tangent u (the n_u axis), in degrees.
        #[arg(long, default_value_t = 0.0)]
        phi1: f64,
        /// Polar angle of k2 (toward the viewer) from the normal, in degrees.
        #[arg(long, default_value_t = 30.0)]
        theta2: f64,
        /// Azimuth of k2 from the tangent u, in degrees.
        #[arg(long, default_value_t = 180.0)]
        phi2: f64,
        /// Also evaluate the fixed-point unit of --hw (integer exponents required).
        #[arg(long)]
        fixed: bool,
        /// Hardware preset or file (for --fixed).
        #[arg(long, default_value = "texram16")]
        hw: String,
    },
    /// Sampler statistics and chi-square goodness-of-fit tests against the pdf: of the half
    /// vectors (any anisotropy) and, for anisotropy ratios up to 10, of the reflected directions.
    Sample {
        #[command(flatten)]
        p: BrdfParams,
        /// Polar angle of the incident direction in degrees.
        #[arg(long, default_value_t = 30.0)]
        theta: f64,
        /// Azimuth of the incident direction in degrees.
        #[arg(long, default_value_t = 0.0)]
        phi: f64,
        /// Number of samples.
        #[arg(long, default_value_t = 200_000)]
        samples: usize,
        /// PRNG seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Render the paper's sphere grids (metal and plastic, furnace and light; Figs. 2-5) with
    /// the fixed unit and the float reference; writes the images and their difference, prints
    /// error and cost per grid.
    Spheres(SpheresArgs),
}

/// Arguments of `texsim brdf spheres`.
#[derive(Args, Debug, Clone)]
pub struct SpheresArgs {
    /// Output directory.
    #[arg(long, default_value = "out/spheres")]
    pub out: PathBuf,
    /// Hardware preset or hw TOML file (its `aniso_phong` unit).
    #[arg(long, default_value = "texram16")]
    pub hw: String,
    /// Pixels per sphere.
    #[arg(long, default_value_t = crate::brdf::spheres::PAPER_SPHERE_PX)]
    pub size: u32,
    /// Exponents of both axes (comma list; n_u per column, n_v per row).
    #[arg(long, value_delimiter = ',', default_values_t = crate::brdf::spheres::PAPER_EXPONENTS)]
    pub exponents: Vec<f64>,
    /// Furnace quadrature resolution (64 res^2 evaluations per pixel).
    #[arg(long, default_value_t = crate::brdf::spheres::FURNACE_RES)]
    pub furnace_res: usize,
}

#[derive(Subcommand, Debug)]
pub enum HwCmd {
    /// Print a preset (or a hw TOML file, resolved) as TOML.
    Show {
        /// Preset name (texram16, d3d11, vulkan-min, cuda, llvmpipe) or path to a hw TOML file.
        preset: String,
    },
    /// List the presets.
    List,
    /// Each unit's datapath (components with their widths), critical path in gate levels,
    /// pipeline latency at the clock target and area in gate equivalents (a proxy), with totals.
    Cost {
        /// Preset name (texram16, d3d11, vulkan-min, cuda) or path to a hw TOML file.
        #[arg(default_value = "texram16")]
        preset: String,
    },
}

/// Which scene to use: a file or a built-in.
#[derive(Args, Debug, Clone, Default)]
pub struct SceneArgs {
    /// Scene file: an OBJ (with its MTL) or a TOML scene.
    pub input: Option<PathBuf>,
    /// Built-in scene (see `texsim scenes`); used when no INPUT is given (default: demo).
    #[arg(long)]
    pub scene: Option<String>,
    /// Hardware: a preset (texram16, d3d11, vulkan-min, cuda, llvmpipe) or a hw TOML file.
    /// Default: the scene's `hw`, else texram16.
    #[arg(long)]
    pub hw: Option<String>,
    /// Output directory.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Override the image width.
    #[arg(long)]
    pub width: Option<u32>,
    /// Override the image height.
    #[arg(long)]
    pub height: Option<u32>,
}

#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum CoverageArg {
    /// The reference shades the hardware's fragments (isolates the shading error).
    Shared,
    /// The reference rasterizes on its own in float (adds the coverage error).
    Independent,
}

#[derive(Args, Debug, Clone)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Also write 16-bit PNGs (hw16.png, ref16.png).
    #[arg(long)]
    pub png16: bool,
    /// How the reference chooses fragments.
    #[arg(long, value_enum, default_value = "shared")]
    pub coverage: CoverageArg,
    /// Stages the "hardware" image runs in float (comma list of stage names as the stage table
    /// prints them, e.g. bary,lod,trilinear,frame,phong; an unknown name lists them all).
    #[arg(long, value_delimiter = ',')]
    pub float: Vec<String>,
    /// Run only this stage in fixed point (all others float): the error of one stage in isolation.
    #[arg(long, conflicts_with = "float")]
    pub isolate: Option<String>,
    /// Skip the float reference (no error metrics).
    #[arg(long)]
    pub no_reference: bool,
    /// Skip the timing model (no cycle count; the hardware path runs without collecting its
    /// timing events: a tenth to a fifth less wall time on the built-in scenes).
    #[arg(long)]
    pub no_cycles: bool,
    /// Also render the supersampled ground truth (roughness materials: the full-resolution
    /// bump map; NDF materials: the finest normal map; others: their float reference) into
    /// truth.png and add model_error (float vs truth) and quantization_error (hardware vs
    /// float) to summary.json; roughness scenes also get baseline.png and baseline_error.
    #[arg(long)]
    pub truth: bool,
    /// Ground-truth sub-samples per pixel axis (N x N per pixel; default 16); only with
    /// --truth.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub truth_samples: Option<u32>,
    /// Range instrumentation: per stage and signal the least and largest value the float
    /// reference computes, the values outside the declared format, and the integer bits each
    /// signal needs; printed and written to summary.json (`stats.ranges`). An extra float
    /// pass: without the flag nothing is counted.
    #[arg(long)]
    pub ranges: bool,
    /// Skip the LDR-FLIP comparison (hardware vs reference: `flip` in summary.json, flip.png),
    /// which costs about as much as the reference pass.
    #[arg(long)]
    pub no_flip: bool,
    /// Render the frame this many times in one process after the warm-up frames and report
    /// the median frame's wall times (every frame's output is the same); with --warmup, the
    /// method of the Mesa anchor's `--frames N --warmup W`: warm frames reuse the memory of
    /// earlier ones instead of faulting in fresh pages.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=MAX_FRAMES))]
    pub frames: u32,
    /// Frames rendered and not timed before the --frames timed ones.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=MAX_FRAMES))]
    pub warmup: u32,
}

/// Most frames `texsim render --frames` or `--warmup` takes.
pub const MAX_FRAMES: i64 = 1000;

#[derive(Args, Debug, Clone)]
pub struct SweepArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// FIELD=A..B (inclusive integer range) or FIELD=v1,v2,... ; FIELD is any HwConfig field
    /// name (`texsim hw show texram16`), or `hw` to switch the whole machine (presets or files;
    /// give it first, later axes edit it). Several --vary make a grid. Or give a sweep plan
    /// (a TOML file with `vary = [...]`) as INPUT: `texsim sweep plan.toml`.
    #[arg(long)]
    pub vary: Vec<String>,
    /// Run the timing model per setting: each row's cycles, texture and DRAM bytes. This is
    /// the default; the flag is kept so that older command lines work.
    #[arg(long, conflicts_with = "no_cycles")]
    pub cycles: bool,
    /// Skip the timing model (rows without cycles and bytes; faster).
    #[arg(long)]
    pub no_cycles: bool,
    /// Also render the ground truth per setting, with N x N sub-samples per pixel (`--truth`
    /// alone: 16), and add each row's model error (float vs truth); 0 = off.
    #[arg(long, default_value_t = 0, num_args = 0..=1, default_missing_value = "16",
          value_parser = clap::value_parser!(u32).range(0..=64))]
    pub truth: u32,
    /// Ground-truth sub-samples per pixel axis, as on `render` (`--truth --truth-samples 4`
    /// is `--truth 4`); only with --truth.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub truth_samples: Option<u32>,
    /// Stages every row runs in float (as on `render`).
    #[arg(long, value_delimiter = ',')]
    pub float: Vec<String>,
    /// Run only this stage in fixed point in every row (all others float): how the swept
    /// field changes the error of that stage alone (as on `render`).
    #[arg(long, conflicts_with = "float")]
    pub isolate: Option<String>,
    /// Render only shard K of N (K in 1..=N): grid rows K-1, K-1+N, ...; writes
    /// sweep-shard-K-of-N.json and .csv into --out for `texsim merge`. `--shard N` takes K
    /// from a Slurm array: SLURM_ARRAY_TASK_ID - SLURM_ARRAY_TASK_MIN (default 0) + 1.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<String>,
    /// Also compute LDR-FLIP (hardware vs reference) per setting: the flip_mean and flip_p99
    /// columns (about as costly as the reference pass of each row).
    #[arg(long)]
    pub flip: bool,
}

/// Arguments of `texsim merge`.
#[derive(Args, Debug, Clone)]
pub struct MergeArgs {
    /// Shard files (sweep-shard-K-of-N.json) or directories holding them.
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Output directory of sweep.json and sweep.csv [default: the first shard's directory].
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Arguments of `texsim tune`.
#[derive(Args, Debug, Clone)]
pub struct TuneArgs {
    /// Built-in scene or scene file (TOML, OBJ); repeat for several: the budget must hold on
    /// every one.
    #[arg(long, required = true)]
    pub scene: Vec<String>,
    /// METRIC=LIMIT, repeatable, all must hold: max8=N (largest 8-bit channel error),
    /// within1=P (percent of pixels within 1 LSB, at least), mean8=X (mean absolute error),
    /// psnr8=DB (at least), flip_mean=F, flip_p99=F (LDR-FLIP, 0..1); against the float
    /// reference, or the truth with --truth.
    #[arg(long, required = true)]
    pub budget: Vec<String>,
    /// Fields to search (leaf names or dotted paths, comma list or repeated); default: every
    /// width and iteration count of the machine.
    #[arg(long, value_delimiter = ',')]
    pub knob: Vec<String>,
    /// The widest machine (the knobs' upper bounds): a preset or a hw TOML file.
    #[arg(long, default_value = "texram16")]
    pub hw: String,
    /// Render every scene at WxH (e.g. 320x240) instead of its own size.
    #[arg(long)]
    pub size: Option<String>,
    /// Compare the hardware against the ground truth (N x N sub-samples per pixel; --truth
    /// alone: 16) instead of the float reference.
    #[arg(long, default_value_t = 0, num_args = 0..=1, default_missing_value = "16",
          value_parser = clap::value_parser!(u32).range(0..=64))]
    pub truth: u32,
    /// Output directory.
    #[arg(long, default_value = "out/tune")]
    pub out: PathBuf,
}

#[derive(Args, Debug, Clone)]
pub struct CyclesArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
}

#[derive(Args, Debug, Clone)]
pub struct ProbeArgs {
    /// Texture image (PNG or JPEG).
    #[arg(long)]
    pub texture: PathBuf,
    /// Normalized texture coordinate u (1.0 = texture width).
    #[arg(long, allow_hyphen_values = true)]
    pub u: f64,
    /// Normalized texture coordinate v.
    #[arg(long, allow_hyphen_values = true)]
    pub v: f64,
    /// Level of detail (log2 texels per pixel; <= 0 magnifies).
    #[arg(long, allow_hyphen_values = true)]
    pub lod: f64,
    /// Hardware preset or hw TOML file.
    #[arg(long, default_value = "texram16")]
    pub hw: String,
    /// Wrap mode of both axes.
    #[arg(long, value_enum, default_value = "repeat")]
    pub wrap: WrapArg,
}

/// Texture addressing mode of `texsim probe --wrap`.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum WrapArg {
    /// Coordinates repeat with period 1 (GL_REPEAT).
    Repeat,
    /// Texel indices clamp to the edge (GL_CLAMP_TO_EDGE).
    #[value(alias = "clamp")]
    ClampToEdge,
    /// Coordinates reflect every period (GL_MIRRORED_REPEAT).
    Mirror,
}

impl From<WrapArg> for crate::scene::WrapMode {
    fn from(w: WrapArg) -> Self {
        match w {
            WrapArg::Repeat => Self::Repeat,
            WrapArg::ClampToEdge => Self::ClampToEdge,
            WrapArg::Mirror => Self::Mirror,
        }
    }
}

/// Runs the parsed command line.
pub fn run(cli: Cli) -> Result<()> {
    if cli.threads == Some(0) {
        return Err(Error::field("--threads", "must be at least 1"));
    }
    // A second initialization (tests calling run twice) keeps the first pool: harmless.
    let _ = rayon::ThreadPoolBuilder::new()
        .num_threads(cli.threads.unwrap_or(0))
        .stack_size(WORKER_STACK)
        .build_global();
    rayon::scope(|_| dispatch(cli))
}

/// The environment variable that names the batch kernels' instruction set when
/// `--vector-isa` does not.
pub const ENV_VECTOR_ISA: &str = "TEXSIM_VECTOR_ISA";

/// Runs the batch kernels with the instruction set `flag` (`--vector-isa`), else
/// `TEXSIM_VECTOR_ISA`, names (an empty variable is unset); with the widest this CPU has where
/// neither is set. The variable is checked even where the flag overrides it, as
/// `TEXSIM_MAX_MEMORY` is.
fn choose_vector_isa(flag: Option<&str>) -> Result<()> {
    let env_ctx = format!("environment variable {ENV_VECTOR_ISA}");
    let env = std::env::var(ENV_VECTOR_ISA).unwrap_or_default();
    let from_env = match env.trim() {
        "" => None,
        name => Some(parse_vector_isa(name).map_err(|e| e.context(&env_ctx))?),
    };
    let chosen = match flag {
        Some(name) => Some((
            parse_vector_isa(name).map_err(|e| e.context("--vector-isa"))?,
            "--vector-isa".to_string(),
        )),
        None => from_env.map(|isa| (isa, env_ctx)),
    };
    let Some((isa, ctx)) = chosen else {
        return Ok(());
    };
    hw_model::isa::limit_vector_isa(isa).map_err(|widest| {
        Error::msg(format!(
            "this CPU has no {}: its widest is {}",
            isa.name(),
            widest.name()
        ))
        .context(ctx)
    })
}

/// The instruction set `name` names (`portable`, `avx2` or `avx512`, in any case).
fn parse_vector_isa(name: &str) -> Result<hw_model::VectorIsa> {
    hw_model::VectorIsa::from_name(&name.trim().to_ascii_lowercase()).ok_or_else(|| {
        Error::msg(format!(
            "unknown instruction set '{name}' (portable, avx2 or avx512)"
        ))
    })
}

/// The stack of the worker threads, on one of which [`run`] runs the command: as large as a
/// main thread's usual 8 MiB.
const WORKER_STACK: usize = 8 << 20;

/// [`run`] on a worker thread of the global pool: the command's parallel loops start there,
/// not by waking a worker from the main thread and waiting for it (which cost each of a
/// frame's parallel phases a thread switch).
fn dispatch(cli: Cli) -> Result<()> {
    crate::budget::check_env()?;
    if let Some(m) = &cli.max_memory {
        let bytes = crate::budget::parse_size(m).map_err(|e| e.context("--max-memory"))?;
        crate::budget::set_max_memory(bytes);
    }
    choose_vector_isa(cli.vector_isa.as_deref())?;
    match cli.command {
        None => render_cmd(&RenderArgs {
            scene: SceneArgs {
                scene: Some("demo".into()),
                ..SceneArgs::default_out()
            },
            png16: false,
            coverage: CoverageArg::Shared,
            float: vec![],
            isolate: None,
            no_reference: false,
            no_cycles: false,
            truth: false,
            truth_samples: None,
            ranges: false,
            no_flip: false,
            frames: 1,
            warmup: 0,
        }),
        Some(Command::Render(a)) => render_cmd(&a),
        Some(Command::Scenes) => {
            println!("built-in scenes (texsim render --scene NAME):");
            for (name, desc) in scene::BUILTIN {
                println!("  {name:<14} {desc}");
            }
            Ok(())
        }
        Some(Command::Sweep(a)) => sweep_cmd(&a),
        Some(Command::Tune(a)) => tune_cmd(&a),
        Some(Command::Merge(a)) => merge_cmd(&a),
        Some(Command::Hw {
            cmd: HwCmd::Show { preset },
        }) => {
            print!("{}", hwconfig::to_toml(&hwconfig::resolve(&preset)?));
            Ok(())
        }
        Some(Command::Hw {
            cmd: HwCmd::Cost { preset },
        }) => {
            print!("{}", hwconfig::cost_text(&hwconfig::resolve(&preset)?));
            Ok(())
        }
        Some(Command::Hw { cmd: HwCmd::List }) => {
            for p in hw_model::config::PRESETS {
                println!("{p}");
            }
            Ok(())
        }
        Some(Command::Probe(a)) => {
            print!("{}", crate::probe::probe_cmd(&a)?);
            Ok(())
        }
        Some(Command::Brdf { cmd }) => brdf_cmd(&cmd),
        Some(Command::Cycles(a)) => cycles_cmd(&a),
        Some(Command::Vectors(a)) => vectors_cmd(&a),
        Some(Command::Compare(a)) => compare_cmd(&a),
        Some(Command::Fit(a)) => {
            print!("{}", crate::fit_cmd::fit_cmd(&a)?);
            Ok(())
        }
        Some(Command::Filters(a)) => filters_cmd(&a),
    }
}

impl SceneArgs {
    fn default_out() -> Self {
        Self {
            out: PathBuf::from("out"),
            ..Default::default()
        }
    }

    /// Loads the scene and resolves the hardware config.
    pub fn load(&self) -> Result<(Scene, HwConfig)> {
        let mut sc = match (&self.input, &self.scene) {
            (Some(_), Some(_)) => {
                return Err(Error::msg("give either a scene file or --scene, not both"))
            }
            (Some(p), None) => scene::load(p)?,
            (None, name) => scene::builtin(name.as_deref().unwrap_or("demo"))?,
        };
        if let Some(w) = self.width {
            sc.width = w;
        }
        if let Some(h) = self.height {
            sc.height = h;
        }
        scene::validate(&sc)?;
        let spec = self
            .hw
            .clone()
            .or_else(|| sc.hw.clone())
            .unwrap_or_else(|| "texram16".into());
        let hw = hwconfig::resolve(&spec)?;
        Ok((sc, hw))
    }
}

fn impls_from(a: &RenderArgs) -> Result<StageImpls> {
    stage_impls(a.isolate.as_deref(), &a.float)
}

/// The twins of `--isolate STAGE` or `--float A,B` (render and sweep).
fn stage_impls(isolate: Option<&str>, float: &[String]) -> Result<StageImpls> {
    if let Some(s) = isolate {
        let k = StageKind::parse(s).map_err(|e| e.context("--isolate"))?;
        return Ok(StageImpls::FLOAT.with(k, Impl::Fixed));
    }
    let mut im = StageImpls::FIXED;
    for s in float {
        let k = StageKind::parse(s).map_err(|e| e.context("--float"))?;
        im = im.with(k, Impl::Float);
    }
    Ok(im)
}

fn render_cmd(a: &RenderArgs) -> Result<()> {
    if a.truth_samples.is_some() && !a.truth {
        return Err(Error::field(
            "--truth-samples",
            "only means something with --truth (add --truth, or drop --truth-samples)",
        ));
    }
    let (sc, hw) = a.scene.load()?;
    let impls = impls_from(a)?;
    crate::budget::check_run(&sc, &hw, !a.no_reference || a.truth, !a.no_cycles)?;
    for w in &sc.warnings {
        eprintln!("warning: {w}");
    }
    eprintln!(
        "texsim: rendering '{}' ({}x{}, {} triangles) on '{}'...",
        sc.name,
        sc.width,
        sc.height,
        sc.triangle_count(),
        hw.name
    );
    let elapsed_ms = |t: std::time::Instant| t.elapsed().as_secs_f64() * 1e3;
    let t = std::time::Instant::now();
    let maps = Maps::with_offset_bits(
        &sc,
        hw.trilinear.texel_bits,
        hw.shading.vector.offset_int_bits,
    );
    progress_line("texture maps", elapsed_ms(t));
    let opts = RenderOptions {
        hw_impls: impls,
        reference: !a.no_reference || a.truth,
        timing: !a.no_cycles,
        keep_events: false,
        coverage: match a.coverage {
            CoverageArg::Shared => CoverageMode::Shared,
            CoverageArg::Independent => CoverageMode::Independent,
        },
        truth: if a.truth {
            a.truth_samples.unwrap_or(DEFAULT_TRUTH_SAMPLES)
        } else {
            0
        },
        progress: Some(progress_line),
        ranges: a.ranges,
        ..RenderOptions::default()
    };
    let (mut r, frames) = render_frames(&sc, &maps, &hw, &opts, a.warmup, a.frames)?;
    let t = std::time::Instant::now();
    let mut out = OutputSet::new();
    // FLIP beside the images' encoding (the truth outputs change neither image nor mask).
    let (error_map, (flip, flip_ms)) = rayon::join(
        || stage_images(&r, a.png16, &mut out),
        || {
            let t_flip = std::time::Instant::now();
            let flip = r
                .ref_image
                .as_ref()
                .filter(|_| !a.no_flip)
                .and_then(|rf| crate::flip::flip(&r.hw_image, rf, Some(&r.mask)));
            (flip, elapsed_ms(t_flip))
        },
    );
    let error_map = error_map?;
    if a.truth {
        truth_outputs(&sc, &maps, &hw, &mut r, &mut out)?;
    }
    if let Some(f) = &flip {
        out.add("flip.png", crate::flip::error_map_png(f, Some(&r.mask))?);
        progress_line("FLIP", flip_ms);
    }
    let flip_stats = flip.as_ref().map(|f| &f.stats);
    let mut rep_row = crate::summary::SweepRow::new(Vec::new(), &r.stats);
    rep_row.flip = flip_stats.cloned();
    crate::pareto::mark_sweep(std::slice::from_mut(&mut rep_row));
    let mut row = report::html::sweep_report_row(&rep_row);
    row.strip = report::html::render_strip(
        &r.hw_image,
        r.ref_image.as_ref(),
        r.truth_image.as_ref(),
        &r.mask,
        error_map.as_ref(),
        flip.as_ref(),
    )?;
    let page = report::html::HtmlReport {
        title: format!("texsim render: {} on {}", sc.name, hw.name),
        subtitle: format!(
            "{}x{}, {} triangles, {} covered pixels",
            sc.width,
            sc.height,
            sc.triangle_count(),
            r.stats.covered_pixels
        ),
        rows: vec![row],
        tables: vec![("Summary".into(), crate::summary::text(&r.stats))],
        ranges: None,
        hw_config: hwconfig::to_toml(&hw),
    };
    out.add("report.html", report::html::html(&page)?.into_bytes());
    let prov = crate::provenance::Provenance::of_process();
    let json = serde_json::json!({
        "provenance": &prov,
        "scene": &r.stats.scene,
        "hw_config": &hw,
        "stats": &r.stats,
        "flip": flip_stats,
        "warnings": &sc.warnings,
    });
    out.add(
        "summary.json",
        serde_json::to_vec_pretty(&json).map_err(|e| Error::msg(e.to_string()))?,
    );
    // Wall times differ between two runs: their own file, so summary.json compares with cmp.
    let times = serde_json::json!({
        "provenance": &prov,
        "scene": &r.stats.scene,
        "timings": &r.stats.timings,
        "frames": &frames,
    });
    out.add(
        "timings.json",
        serde_json::to_vec_pretty(&times).map_err(|e| Error::msg(e.to_string()))?,
    );
    out.family(RENDER_OUTPUTS);
    let stale = out.stale_in(&a.scene.out);
    let written = out.write_to(&a.scene.out)?;
    progress_line("writing outputs", elapsed_ms(t));
    print!("{}", crate::summary::text(&r.stats));
    if frames.timed.len() > 1 || frames.warmup > 0 {
        println!("{}", frames.line());
    }
    if let Some(rg) = &r.stats.ranges {
        print!("{}", crate::render::ranges::table(rg, &r.stats.stages));
    }
    if let Some(f) = flip_stats {
        println!("{}", crate::summary::flip_line(f));
    }
    for w in &r.stats.warnings {
        eprintln!("warning: {w}");
    }
    println!("wrote:");
    for p in written {
        println!("  {}", p.display());
    }
    if !stale.is_empty() {
        println!("removed (outputs of an earlier run that this run did not produce):");
        for p in stale {
            println!("  {}", p.display());
        }
    }
    Ok(())
}

/// The frames of one `texsim render`: how many warm-up frames ran untimed and the hardware
/// path's wall time of each timed one (`timings.json`'s `frames`).
#[derive(Debug, serde::Serialize)]
struct Frames {
    warmup: u32,
    /// `hw_total_ms` of each timed frame, in the order they ran.
    timed: Vec<f64>,
    /// The index in `timed` of the median frame, whose timings the render reports (the lower
    /// of the two middle ones for an even count).
    median: usize,
}

impl Frames {
    fn line(&self) -> String {
        let lo = self.timed.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = self.timed.iter().copied().fold(0.0, f64::max);
        format!(
            "frames: {} timed after {} warm-up; hardware path median {:.1} ms (min {lo:.1}, max {hi:.1}); the wall times above are the median frame's",
            self.timed.len(),
            self.warmup,
            self.timed[self.median],
        )
    }
}

/// Renders `warmup + frames` frames one after the other (each dropped before the next starts,
/// so the memory budget holds) and returns the last with the timings of the median timed
/// frame. The progress lines are the last frame's.
fn render_frames(
    sc: &Scene,
    maps: &Maps,
    hw: &HwConfig,
    opts: &RenderOptions,
    warmup: u32,
    frames: u32,
) -> Result<(Rendered, Frames)> {
    let total = warmup + frames.max(1);
    let quiet = RenderOptions {
        progress: None,
        ..opts.clone()
    };
    let mut timings = Vec::with_capacity(frames as usize);
    let mut last = None;
    for i in 0..total {
        drop(last.take());
        let r = render(sc, maps, hw, if i + 1 == total { opts } else { &quiet })?;
        if i >= warmup {
            timings.push(r.stats.timings.clone());
        }
        if total > 1 {
            let what = if i < warmup { "warm-up" } else { "timed" };
            progress_line(
                &format!("frame {}/{total} ({what})", i + 1),
                r.stats.timings.hw_total_ms,
            );
        }
        last = Some(r);
    }
    let mut order: Vec<usize> = (0..timings.len()).collect();
    order.sort_by(|&a, &b| timings[a].hw_total_ms.total_cmp(&timings[b].hw_total_ms));
    let median = order[(order.len() - 1) / 2];
    let mut r = last.expect("at least one frame");
    r.stats.timings = timings[median].clone();
    let frames = Frames {
        warmup,
        timed: timings.iter().map(|t| t.hw_total_ms).collect(),
        median,
    };
    Ok((r, frames))
}

/// Ground-truth sub-samples per pixel axis of `texsim render --truth` without `--truth-samples`.
pub const DEFAULT_TRUTH_SAMPLES: u32 = 16;

/// Every file `texsim render` may write; those a run does not produce are removed from its
/// output directory, so no earlier run's image stays beside a new `summary.json`.
pub const RENDER_OUTPUTS: &[&str] = &[
    "hw.png",
    "hw16.png",
    "ref.png",
    "ref16.png",
    "error.png",
    "flip.png",
    "sheet.png",
    "truth.png",
    "baseline.png",
    "summary.json",
    "timings.json",
    "report.html",
];

/// Writes truth.png and fills the baseline error: the same scene with every roughness material
/// switched to `none` (plain filtered bump map), all stages float, against the truth.
fn truth_outputs(
    sc: &Scene,
    maps: &Maps,
    hw: &HwConfig,
    r: &mut Rendered,
    out: &mut OutputSet,
) -> Result<()> {
    let Some(truth) = &r.truth_image else {
        eprintln!(
            "warning: --truth: the scene has no roughness or NDF material, no truth rendered"
        );
        return Ok(());
    };
    out.add("truth.png", report::encode_png8(truth)?);
    if r.stats.roughness.is_none() {
        if let (Some(m), Some(q)) = (&r.stats.model_error, &r.stats.quantization_error) {
            eprintln!(
                "vs ground truth: model_error mean {:.3} rmse {:.3}; quantization_error mean {:.4} rmse {:.4} (8-bit LSB)",
                m.mean_abs_lsb, m.rmse_lsb, q.mean_abs_lsb, q.rmse_lsb
            );
        }
        return Ok(());
    }
    let mut base = sc.clone();
    for m in &mut base.materials {
        if m.roughness.is_some() {
            m.roughness = Some(scene::RoughChoice::Variant(
                hw_model::roughness::RoughVariant::None,
            ));
        }
    }
    let b = render(
        &base,
        maps,
        hw,
        &RenderOptions {
            hw_impls: StageImpls::FLOAT,
            reference: false,
            ..RenderOptions::default()
        },
    )?;
    out.add("baseline.png", report::encode_png8(&b.hw_image)?);
    if let Some(rs) = r.stats.roughness.as_mut() {
        rs.baseline_error = Some(report::compare(&b.hw_image, truth, 8, Some(&r.mask)));
        let show = |n: &str, e: &Option<report::ErrorMetrics>| {
            if let Some(e) = e {
                eprintln!(
                    "  {n:<20} mean {:.3} rmse {:.3} max {} (8-bit LSB)",
                    e.mean_abs_lsb, e.rmse_lsb, e.max_abs_lsb
                );
            }
        };
        eprintln!(
            "roughness vs ground truth ({0}x{0} samples/pixel):",
            rs.truth_samples
        );
        show("model_error", &rs.model_error);
        show("quantization_error", &rs.quantization_error);
        show("baseline_error", &rs.baseline_error);
    }
    Ok(())
}

/// Adds the images of a render; returns the error map (for report.html), when there is a
/// reference.
fn stage_images(
    r: &Rendered,
    png16: bool,
    out: &mut OutputSet,
) -> Result<Option<tiny_skia::Pixmap>> {
    out.add("hw.png", report::encode_png8(&r.hw_image)?);
    if png16 {
        out.add("hw16.png", report::encode_png16(&r.hw_image)?);
    }
    if let Some(rf) = &r.ref_image {
        out.add("ref.png", report::encode_png8(rf)?);
        if png16 {
            out.add("ref16.png", report::encode_png16(rf)?);
        }
        let heat = report::heatmap(&r.hw_image, rf, 8, Some(&r.mask));
        let hwp = report::image_to_pixmap(&r.hw_image);
        let rfp = report::image_to_pixmap(rf);
        let sheet = report::sheet(&[
            ("hardware", &hwp),
            ("reference", &rfp),
            ("error (8-bit LSB)", &heat),
        ]);
        out.add("error.png", report::encode_pixmap(&heat)?);
        out.add("sheet.png", report::encode_pixmap(&sheet)?);
        return Ok(Some(heat));
    }
    Ok(None)
}

/// One `--vary` axis: a field and its values.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Axis {
    pub field: String,
    pub values: Vec<String>,
}

/// Parses `FIELD=A..B` or `FIELD=v1,v2,...`.
pub fn parse_axis(s: &str) -> Result<Axis> {
    let (field, vals) = s
        .split_once('=')
        .ok_or_else(|| Error::field("--vary", format!("'{s}' is not FIELD=A..B or FIELD=v1,v2")))?;
    let field = field.trim().to_string();
    if field.is_empty() {
        return Err(Error::field("--vary", format!("'{s}' has no field name")));
    }
    let values: Vec<String> = if let Some((a, b)) = vals.split_once("..") {
        let parse = |x: &str| {
            x.trim()
                .parse::<i64>()
                .map_err(|_| Error::field("--vary", format!("'{x}' in '{s}' is not an integer")))
        };
        let (a, b) = (parse(a)?, parse(b)?);
        // i128: the length of any i64 range fits.
        let len = i128::from(b) - i128::from(a) + 1;
        if len < 1 {
            return Err(Error::field(
                "--vary",
                format!("range {a}..{b} in '{s}' is empty"),
            ));
        }
        if len > MAX_AXIS_VALUES as i128 {
            return Err(Error::field(
                "--vary",
                format!(
                    "range {a}..{b} in '{s}' has {len} values, over the limit of {MAX_AXIS_VALUES} per axis"
                ),
            ));
        }
        (a..=b).map(|v| v.to_string()).collect()
    } else {
        vals.split(',')
            .map(|v| v.trim().to_string())
            .filter(|v| !v.is_empty())
            .collect()
    };
    if values.is_empty() {
        return Err(Error::field("--vary", format!("'{s}' has no values")));
    }
    Ok(Axis { field, values })
}

/// Refuses axes that would overwrite each other: a `hw` axis after another axis (it
/// replaces the whole machine, so the earlier axis's values would be lost and its rows
/// identical), a second `hw` axis, or two axes on the same field.
pub fn check_axes(base: &HwConfig, axes: &[Axis]) -> Result<()> {
    let fields = hwconfig::fields(base);
    let path = |name: &str| hwconfig::dotted_path(&fields, name);
    for (i, ax) in axes.iter().enumerate() {
        if ax.field == "hw" && i > 0 {
            return Err(Error::field(
                "--vary",
                format!(
                    "'hw' comes after --vary {}: it replaces the whole machine and would overwrite that axis (its rows would be identical); give --vary hw=... first",
                    axes[i - 1].field
                ),
            ));
        }
        for prev in &axes[..i] {
            if ax.field != "hw" && path(&prev.field) == path(&ax.field) {
                return Err(Error::field(
                    "--vary",
                    format!(
                        "'{}' and '{}' both set {}: the later axis would overwrite the earlier one",
                        prev.field,
                        ax.field,
                        path(&ax.field)
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Most values of one `--vary` range.
pub const MAX_AXIS_VALUES: u64 = 4097;

/// The number of rows of the grid of `axes` (saturating).
#[must_use]
pub fn grid_rows(axes: &[Axis]) -> u64 {
    axes.iter()
        .fold(1u64, |n, a| n.saturating_mul(a.values.len() as u64))
}

/// The cartesian product of the axes, first axis slowest. The grid's size is checked against
/// the memory budget ([`crate::budget`]) before any row is built.
pub fn grid(axes: &[Axis]) -> Result<Vec<Vec<(String, String)>>> {
    let n = grid_rows(axes);
    let shape: Vec<String> = axes.iter().map(|a| a.values.len().to_string()).collect();
    crate::budget::check(
        "--vary",
        &format!("a grid of {} = {n} settings", shape.join(" x ")),
        crate::budget::mul(n, crate::budget::BYTES_PER_SWEEP_ROW),
    )?;
    let mut rows: Vec<Vec<(String, String)>> = vec![vec![]];
    for ax in axes {
        let mut next = Vec::with_capacity(rows.len() * ax.values.len());
        for r in &rows {
            for v in &ax.values {
                let mut n = r.clone();
                n.push((ax.field.clone(), v.clone()));
                next.push(n);
            }
        }
        rows = next;
    }
    Ok(rows)
}

fn sweep_cmd(a: &SweepArgs) -> Result<()> {
    let a = &crate::sweep_plan::apply(a)?;
    if a.vary.is_empty() {
        return Err(Error::field(
            "--vary",
            "give at least one --vary FIELD=A..B, or a sweep plan file (texsim sweep plan.toml)",
        ));
    }
    if a.truth_samples.is_some() && a.truth == 0 {
        return Err(Error::field(
            "--truth-samples",
            "only means something with --truth (add --truth, or drop --truth-samples)",
        ));
    }
    let truth = a.truth_samples.unwrap_or(a.truth);
    let impls = stage_impls(a.isolate.as_deref(), &a.float)?;
    let (sc, base) = a.scene.load()?;
    let axes: Vec<Axis> = a
        .vary
        .iter()
        .map(|s| parse_axis(s))
        .collect::<Result<_>>()?;
    check_axes(&base, &axes)?;
    let shard = a
        .shard
        .as_deref()
        .map(|s| {
            crate::sweep_shard::Shard::parse(
                s,
                std::env::var("SLURM_ARRAY_TASK_ID").ok().as_deref(),
                std::env::var("SLURM_ARRAY_TASK_MIN").ok().as_deref(),
            )
        })
        .transpose()?;
    let grid_total = grid_rows(&axes);
    let (grid_index, settings): (Vec<u64>, Vec<_>) = grid(&axes)?
        .into_iter()
        .enumerate()
        .map(|(i, r)| (i as u64, r))
        .filter(|(i, _)| shard.is_none_or(|s| s.owns(*i)))
        .unzip();
    // Validate every setting before rendering anything.
    let configs: Vec<HwConfig> = settings
        .iter()
        .map(|row| {
            row.iter().try_fold(base.clone(), |c, (f, v)| {
                if f == "hw" {
                    hwconfig::resolve(v)
                } else {
                    hwconfig::set_field(&c, f, v)
                }
            })
        })
        .collect::<Result<_>>()?;
    let timing = !a.no_cycles;
    let render_need = crate::budget::RunNeed::of(&sc, &base, true, timing);
    render_need.check(&sc)?;
    for w in &sc.warnings {
        eprintln!("warning: {w}");
    }
    let mut maps = Maps::new(&sc, base.trilinear.texel_bits);
    // Rows that agree on every axis reaching the float passes share them: their key is the
    // values of those axes (a `hw` axis among them).
    let base_fields = hwconfig::fields(&base);
    let reaches: Vec<bool> = axes
        .iter()
        .map(|ax| {
            ax.field == "hw"
                || !crate::render::float_blind(&hwconfig::dotted_path(&base_fields, &ax.field))
        })
        .collect();
    // Keys are worth keeping only when some axis does not reach the passes (else every row
    // has its own key).
    let kept_passes = if reaches.contains(&false) {
        crate::render::float_pass_budget()
    } else {
        0
    };
    // The rows this run renders are kept until the outputs are written, beside one render and
    // the float passes kept for the next rows.
    crate::budget::check(
        "--vary",
        &format!(
            "keeping the results of {} settings beside a render of '{}'",
            settings.len(),
            sc.name
        ),
        crate::budget::mul(settings.len() as u64, crate::budget::BYTES_PER_SWEEP_RESULT)
            .saturating_add(render_need.total())
            .saturating_add(kept_passes),
    )?;
    let mut float_passes = crate::render::FloatPassCache::new(kept_passes);
    let mut rows = Vec::with_capacity(configs.len());
    let mut worst_pixels = Vec::with_capacity(configs.len());
    let mut strips: Vec<Vec<(String, Vec<u8>)>> = Vec::with_capacity(configs.len());
    let sweep_start = std::time::Instant::now();
    for (i, (cfg, set)) in configs.iter().zip(&settings).enumerate() {
        let label: Vec<String> = set.iter().map(|(f, v)| format!("{f}={v}")).collect();
        let elapsed = sweep_start.elapsed().as_secs_f64();
        let eta = if i == 0 {
            String::new()
        } else {
            format!(
                " (elapsed {elapsed:.1} s, ETA {:.1} s)",
                elapsed / i as f64 * (configs.len() - i) as f64
            )
        };
        eprintln!("[{}/{}] {}{eta}", i + 1, configs.len(), label.join(" "));
        maps.ensure_texel_bits(cfg.trilinear.texel_bits);
        maps.ensure_offset_bits(cfg.shading.vector.offset_int_bits);
        let key: Vec<&String> = set
            .iter()
            .zip(&reaches)
            .filter(|(_, &r)| r)
            .map(|((_, v), _)| v)
            .collect();
        let opts = RenderOptions {
            timing,
            truth,
            hw_impls: impls,
            float_passes: float_passes.get(&key),
            ..RenderOptions::default()
        };
        let r = render(&sc, &maps, cfg, &opts)?;
        float_passes.keep(key, &sc, &r, &opts);
        for w in &r.stats.warnings {
            eprintln!("  warning: {w}");
        }
        let mut row = crate::summary::SweepRow::new(set.clone(), &r.stats);
        let worst = r
            .ref_image
            .as_ref()
            .and_then(|re| crate::sweep_shard::worst_pixel(&r.hw_image, re, &r.mask));
        if let Some(w) = &worst {
            if w.error_lsb > 0 {
                eprintln!(
                    "  worst pixel ({}, {}): {} LSB, hw {:?} vs reference {:?}",
                    w.x, w.y, w.error_lsb, w.hw, w.reference
                );
            }
        }
        worst_pixels.push(worst);
        let flip = r
            .ref_image
            .as_ref()
            .filter(|_| a.flip)
            .and_then(|rf| crate::flip::flip(&r.hw_image, rf, Some(&r.mask)));
        row.flip = flip.as_ref().map(|f| f.stats.clone());
        strips.push(report::html::render_strip(
            &r.hw_image,
            r.ref_image.as_ref(),
            r.truth_image.as_ref(),
            &r.mask,
            None,
            flip.as_ref(),
        )?);
        let varies_frame = set
            .iter()
            .any(|(f, _)| f == "frame" || f == "frame_kind" || f.ends_with(".frame_kind"));
        let kind = cfg.shading.frame.frame_kind.name();
        let used = &row.frame_used;
        if varies_frame && !used.is_empty() && !used.split('+').any(|u| u == kind) {
            eprintln!(
                "warning: frame_kind={kind} has no effect: every bump material sets its own `frame` (used: {used})"
            );
        }
        let cpp = row
            .cycles_per_pixel
            .map_or_else(|| "-".into(), |c| format!("{c:.2}"));
        if let (Some(m), Some(q)) = (&row.model_error, &row.error_8bit) {
            eprintln!(
                "  model_error (vs truth) mean {:.3} rmse {:.3}; quantization_error mean {:.4} rmse {:.4}; {cpp} cycles/px",
                m.mean_abs_lsb, m.rmse_lsb, q.mean_abs_lsb, q.rmse_lsb
            );
        }
        if let Some(why) = r.stats.issue_cycles.not_modelled {
            eprintln!("  no cycles: {why}");
        }
        rows.push(row);
        keep_report_strips(&mut rows, &mut strips);
    }
    crate::pareto::mark_sweep(&mut rows);
    let table = crate::summary::sweep_table(&rows);
    print!("{table}");
    let mut out = OutputSet::new();
    let csv_name = shard.map_or_else(|| "sweep.csv".to_string(), |s| s.file("csv"));
    out.add(&csv_name, crate::summary::sweep_csv(&rows)?.into_bytes());
    // Each row carries its provenance and the full configuration it ran on.
    let prov = crate::provenance::Provenance::of_process();
    let json_rows = rows
        .iter()
        .zip(&configs)
        .zip(worst_pixels.iter().zip(&grid_index))
        .map(|((row, cfg), (worst, gi))| {
            let mut v = serde_json::to_value(row).map_err(|e| Error::msg(e.to_string()))?;
            if let Some(o) = v.as_object_mut() {
                o.insert("hw_config".into(), serde_json::json!(cfg));
                o.insert("provenance".into(), serde_json::json!(&prov));
                o.insert("worst_pixel".into(), serde_json::json!(worst));
                if shard.is_some() {
                    o.insert("grid_index".into(), serde_json::json!(gi));
                }
            }
            Ok(v)
        })
        .collect::<Result<Vec<_>>>()?;
    let json = match shard {
        None => serde_json::to_vec_pretty(&json_rows),
        Some(s) => serde_json::to_vec_pretty(&serde_json::json!({
            "shard": s.index,
            "shards": s.count,
            "grid_rows": grid_total,
            "rows": json_rows,
        })),
    }
    .map_err(|e| Error::msg(e.to_string()))?;
    out.add(
        &shard.map_or_else(|| "sweep.json".to_string(), |s| s.file("json")),
        json,
    );
    let page = report::html::HtmlReport {
        title: format!("texsim sweep: {} on {}", sc.name, base.name),
        subtitle: format!(
            "{}x{}; {} settings: {}",
            sc.width,
            sc.height,
            rows.len(),
            a.vary.join(" ")
        ),
        rows: rows
            .iter()
            .zip(strips)
            .map(|(r, strip)| report::html::ReportRow {
                strip,
                ..report::html::sweep_report_row(r)
            })
            .collect(),
        tables: vec![("Sweep table".into(), table)],
        ranges: None,
        hw_config: hwconfig::to_toml(&base),
    };
    out.add("report.html", report::html::html(&page)?.into_bytes());
    for p in out.write_to(&a.scene.out)? {
        println!("wrote {}", p.display());
    }
    Ok(())
}

fn merge_cmd(a: &MergeArgs) -> Result<()> {
    let files = crate::sweep_shard::shard_files(&a.inputs)?;
    let m = crate::sweep_shard::merge(&files)?;
    print!("{}", crate::summary::sweep_table(&m.rows));
    let mut out = OutputSet::new();
    out.add(
        "sweep.csv",
        crate::summary::sweep_csv(&m.rows)?.into_bytes(),
    );
    out.add(
        "sweep.json",
        serde_json::to_vec_pretty(&m.json_rows).map_err(|e| Error::msg(e.to_string()))?,
    );
    let dir = a
        .out
        .clone()
        .unwrap_or_else(|| crate::sweep_shard::default_out(&files));
    println!("merged {} shard files, {} rows", files.len(), m.rows.len());
    for p in out.write_to(&dir)? {
        println!("wrote {}", p.display());
    }
    Ok(())
}

/// Bounds the image strips a sweep keeps for report.html: once more than twice
/// `MAX_STRIPS` rows hold one, the rows past the first `MAX_STRIPS` that are off the Pareto
/// fronts so far drop theirs (a dominated row stays dominated as rows are added).
fn keep_report_strips(
    rows: &mut [crate::summary::SweepRow],
    strips: &mut [Vec<(String, Vec<u8>)>],
) {
    let max = report::html::MAX_STRIPS;
    if strips.iter().filter(|s| !s.is_empty()).count() <= 2 * max {
        return;
    }
    crate::pareto::mark_sweep(rows);
    for (i, (r, s)) in rows.iter().zip(strips.iter_mut()).enumerate() {
        if i >= max && !r.pareto_area && r.pareto_cycles != Some(true) {
            s.clear();
        }
    }
}

fn brdf_model(p: &BrdfParams) -> Result<crate::brdf::ashikhmin_shirley::AshikhminShirley> {
    crate::brdf::ashikhmin_shirley::AshikhminShirley::new(p.nu, p.nv, p.rs, p.rd)
}

/// The Ashikhmin-Shirley unit config of `hw` when `--fixed` is given.
fn fixed_unit(fixed: bool, hw: &str) -> Result<Option<hw_model::aniso_phong::AnisoPhongConfig>> {
    Ok(if fixed {
        Some(hwconfig::resolve(hw)?.aniso_phong)
    } else {
        None
    })
}

fn brdf_cmd(cmd: &BrdfCmd) -> Result<()> {
    use crate::brdf::ashikhmin_shirley::dir_from_angles;
    use crate::brdf::report::{albedo_report, eval_report, sample_report};
    let text = match cmd {
        BrdfCmd::Albedo {
            p,
            theta,
            fixed,
            hw,
        } => {
            let cfg = fixed_unit(*fixed, hw)?;
            albedo_report(&brdf_model(p)?, *theta, cfg.as_ref())?
        }
        BrdfCmd::Eval {
            p,
            theta1,
            phi1,
            theta2,
            phi2,
            fixed,
            hw,
        } => {
            let cfg = fixed_unit(*fixed, hw)?;
            eval_report(
                &brdf_model(p)?,
                dir_from_angles(*theta1, *phi1),
                dir_from_angles(*theta2, *phi2),
                cfg.as_ref(),
            )?
        }
        BrdfCmd::Sample {
            p,
            theta,
            phi,
            samples,
            seed,
        } => sample_report(
            &brdf_model(p)?,
            dir_from_angles(*theta, *phi),
            *samples,
            *seed,
        )?,
        BrdfCmd::Spheres(a) => {
            let hw = hwconfig::resolve(&a.hw)?;
            let (out, text) = crate::brdf::spheres::spheres_report(
                &hw.aniso_phong,
                hw.timing.gate_levels_per_cycle,
                &a.exponents,
                a.size,
                a.furnace_res,
            )?;
            let mut text = text;
            for p in out.write_to(&a.out)? {
                text.push_str(&format!("wrote {}\n", p.display()));
            }
            text
        }
    };
    print!("{text}");
    if !text.ends_with('\n') {
        println!();
    }
    Ok(())
}

fn cycles_cmd(a: &CyclesArgs) -> Result<()> {
    let (sc, hw) = a.scene.load()?;
    crate::budget::check_run(&sc, &hw, false, true)?;
    for w in &sc.warnings {
        eprintln!("warning: {w}");
    }
    eprintln!(
        "texsim: timing '{}' ({}x{}, {} triangles) on '{}'...",
        sc.name,
        sc.width,
        sc.height,
        sc.triangle_count(),
        hw.name
    );
    let maps = Maps::with_offset_bits(
        &sc,
        hw.trilinear.texel_bits,
        hw.shading.vector.offset_int_bits,
    );
    let (r, rep) = crate::timing::cycles(&sc, &maps, &hw)?;
    for w in &r.stats.warnings {
        eprintln!("warning: {w}");
    }
    let mut out = OutputSet::new();
    let json = serde_json::json!({
        "provenance": crate::provenance::Provenance::of_process(),
        "scene": &sc.name,
        "hw_config": &hw,
        "timing": &rep,
    });
    out.add(
        "cycles.json",
        serde_json::to_vec_pretty(&json).map_err(|e| Error::msg(e.to_string()))?,
    );
    let written = out.write_to(&a.scene.out)?;
    print!("{}", crate::timing::report::text(&rep));
    for p in written {
        println!("wrote {}", p.display());
    }
    Ok(())
}

fn vectors_cmd(a: &VectorsArgs) -> Result<()> {
    if a.list {
        for u in crate::vectors::UNITS {
            println!("{:<8} {}", u.name, u.about);
        }
        return Ok(());
    }
    let name = a.unit.as_deref().unwrap_or_default();
    let hw = hwconfig::resolve(&a.hw)?;
    let set = crate::vectors::generate(name, &hw, a.n, a.seed)?;
    let out = crate::vectors::output_set(&set, &crate::provenance::Provenance::of_process())?;
    let dir = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out/vectors").join(set.unit));
    let written = out.write_to(&dir)?;
    println!(
        "vectors '{}' on '{}': {} vectors ({} boundary, {} random, seed {})",
        set.unit,
        set.hw_name,
        set.len(),
        set.boundary,
        set.random,
        set.seed
    );
    for p in written {
        println!("wrote {}", p.display());
    }
    Ok(())
}

fn compare_cmd(a: &CompareArgs) -> Result<()> {
    use crate::compare::{CoverageFrom, Selection};
    let ia = crate::compare::load_image(&a.a)?;
    let ib = crate::compare::load_image(&a.b)?;
    let sel = match (&a.mask, a.coverage_from) {
        (Some(m), _) => Selection::Mask(crate::compare::load_image(m)?),
        (None, Some(f)) => Selection::Coverage {
            from: match f {
                CoverageFromArg::A => CoverageFrom::A,
                CoverageFromArg::B => CoverageFrom::B,
                CoverageFromArg::Either => CoverageFrom::Either,
                CoverageFromArg::Both => CoverageFrom::Both,
            },
            clear: crate::compare::parse_clear(&a.clear)?,
        },
        (None, None) => Selection::All,
    };
    let (an, bn) = (a.a.display().to_string(), a.b.display().to_string());
    let (c, mask) = crate::compare::compare(&ia, &an, &ib, &bn, &sel, a.bits, a.top)?;
    let prov = crate::provenance::Provenance::of_process();
    let out = crate::compare::output_set(&c, &ia, &ib, &mask, &prov)?;
    let written = out.write_to(&a.out)?;
    print!("{}", crate::compare::format_report(&c));
    for p in written {
        println!("wrote {}", p.display());
    }
    Ok(())
}

/// One progress line on stderr: a finished phase and its wall time.
fn filters_cmd(a: &FiltersArgs) -> Result<()> {
    let methods: Vec<&crate::filters::Method> = if a.method.is_empty() {
        crate::filters::METHODS.iter().collect()
    } else {
        a.method
            .iter()
            .map(|m| crate::filters::method(m).map_err(|e| e.context("--method")))
            .collect::<Result<_>>()?
    };
    let opts = crate::filters::FilterOptions {
        truth: a.truth,
        timing: !a.no_cycles,
    };
    let mut rows = Vec::new();
    for name in &a.scene {
        let sa = SceneArgs {
            scene: Some(name.clone()),
            width: a.width,
            height: a.height,
            hw: a.hw.clone(),
            ..SceneArgs::default_out()
        };
        let (sc, hw) = sa.load()?;
        crate::budget::check_run(&sc, &hw, true, opts.timing)?;
        let progress = |m: &str| eprintln!("[{name}] {m}");
        rows.extend(crate::filters::compare_scene(
            name, &sc, &hw, &methods, &opts, &progress,
        )?);
    }
    print!("{}", crate::filters::text_table(&rows));
    let mut out = OutputSet::new();
    out.add("filters.csv", crate::filters::csv_table(&rows).into_bytes());
    out.add(
        "filters.json",
        serde_json::to_vec_pretty(&rows).map_err(|e| Error::msg(e.to_string()))?,
    );
    out.add(
        "filters.md",
        crate::filters::markdown_table(&rows).into_bytes(),
    );
    for p in out.write_to(&a.out)? {
        println!("wrote {}", p.display());
    }
    Ok(())
}

fn progress_line(phase: &str, ms: f64) {
    eprintln!("texsim:   {phase:<18} {ms:>9.1} ms");
}

/// Runs `texsim tune`.
fn tune_cmd(a: &TuneArgs) -> Result<()> {
    let size = a
        .size
        .as_deref()
        .map(crate::tune_cli::parse_size)
        .transpose()?;
    let budgets = a
        .budget
        .iter()
        .map(|b| crate::tune::Budget::parse(b))
        .collect::<Result<Vec<_>>>()?;
    let base = hwconfig::resolve(&a.hw).map_err(|e| e.context("--hw"))?;
    let scenes = a
        .scene
        .iter()
        .map(|s| crate::tune_cli::load_scene(s, size))
        .collect::<Result<Vec<_>>>()?;
    for sc in &scenes {
        crate::budget::check_run(sc, &base, true, true)?;
        for w in &sc.warnings {
            eprintln!("warning: scene '{}': {w}", sc.name);
        }
    }
    let spec = crate::tune::TuneSpec {
        scenes,
        base,
        budgets,
        knobs: a.knob.clone(),
        truth: a.truth,
    };
    let knobs = if spec.knobs.is_empty() {
        crate::tune::default_knobs(&spec.base)?
    } else {
        spec.knobs
            .iter()
            .map(|n| crate::tune::knob(&spec.base, n))
            .collect::<Result<Vec<_>>>()?
    };
    eprintln!(
        "texsim: tuning {} knobs on {} scene(s) from '{}'",
        knobs.len(),
        spec.scenes.len(),
        spec.base.name
    );
    let start = std::time::Instant::now();
    let mut prev: Vec<u32> = knobs.iter().map(|k| k.hi).collect();
    println!("trials (knobs that differ from the previous trial):");
    let mut print = |t: &crate::tune::Trial| {
        println!("{}", crate::tune_cli::trial_line(&knobs, t, &prev));
        prev.clone_from(&t.values);
    };
    let r = crate::tune::tune(&spec, &mut print)?;
    let texram16_area =
        hw_model::datapath::total_area(&hw_model::datapath::units(&hw_model::HwConfig::texram16()));
    let summary = crate::tune_cli::summary_text(&r, texram16_area);
    print!("{summary}");
    eprintln!("texsim: tune took {:.1} s", start.elapsed().as_secs_f64());
    let mut out = OutputSet::new();
    let mut json = serde_json::to_value(&r).map_err(|e| Error::msg(e.to_string()))?;
    if let Some(o) = json.as_object_mut() {
        o.insert("texram16_area_ge".into(), serde_json::json!(texram16_area));
        o.insert("hw_config".into(), serde_json::json!(&r.machine));
        o.insert(
            "provenance".into(),
            serde_json::json!(crate::provenance::Provenance::of_process()),
        );
    }
    out.add(
        "tune.json",
        serde_json::to_vec_pretty(&json).map_err(|e| Error::msg(e.to_string()))?,
    );
    out.add("tune.csv", crate::tune_cli::tune_csv(&r)?.into_bytes());
    let budgets: Vec<String> = r.budgets.iter().map(crate::tune::Budget::label).collect();
    let toml = format!(
        "# texsim tune: least area meeting {} on {} (vs {}); use with --hw tuned.toml\n{}",
        budgets.join(", "),
        r.scenes.join(", "),
        r.against,
        hwconfig::to_toml(&r.machine)
    );
    out.add("tuned.toml", toml.into_bytes());
    out.add(
        "report.html",
        crate::tune_cli::tune_report(&r, &summary)?.into_bytes(),
    );
    for p in out.write_to(&a.out)? {
        println!("wrote {}", p.display());
    }
    Ok(())
}
