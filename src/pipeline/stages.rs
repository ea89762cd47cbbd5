//! What every stage shares: the [`Machine`] (the units and formats of one hardware
//! configuration, built once per render), the per-triangle vertex data ([`TriAttrs`] in the
//! hardware's input formats and, when a stage reads it, [`TriFloat`] in float, so the per-pixel
//! loop allocates nothing), the run's
//! [`Counters`], [`run`], which runs a compiled [`Program`] on one fragment, and
//! [`run_spans`], which runs it on spans of fragments, stage by stage. The stages themselves
//! are one file each, registered in [`super::table`].

use super::bump::BumpAttrs;
use super::lanes::{LaneCell, LANES, LANES_SPAN_MIN};
use super::table::RunFn;
use super::{BumpPlan, Frag, Impl, Plan, Program, Px, StageImpls, StageKind, MAX_POINT_LIGHTS};
use crate::fixedpoint::{floor_exact, to_raw, to_unorm};
use crate::maps::{FixedMipChain, MipChain};
use crate::raster::ScreenTri;
use crate::reference::LevelF;
use crate::scene::{FrameKind, Light, WrapMode};
use crate::shading::reference as fref;
use glam::DVec3;
use hw_model::blinn_phong::ShadingUnits;
use hw_model::config::{CoordArith, HwConfig};
use hw_model::fixed::{Format, Rounding, SatCounter};
use hw_model::frame::len_format;
use hw_model::modulate::unorm_convert;
use hw_model::reciprocal::Reciprocal;
use hw_model::trilinear::{BatchLevels, Level, UnitSetup};
use hw_model::vector::vector_format;
use hw_model::UnitCost;

/// Per-stage counters of one run (summed over fragments; order-independent integer sums).
#[derive(Clone, Copy, Debug, Default)]
pub struct Counters {
    /// Invocations per stage kind (index = `StageKind::index`).
    pub invocations: [u64; StageKind::COUNT],
    /// Overflow events per stage kind.
    pub sat: [SatCounter; StageKind::COUNT],
    /// Cost per stage kind, summed over invocations (ops, cycles, texels).
    pub cost: [[u64; 3]; StageKind::COUNT],
    /// Bump frames built from a fallback (main-direction cone, zero tangent direction).
    pub frame_fallback: u64,
    /// Bump frames whose interpolated normal was zero.
    pub zero_normal: u64,
    /// Blinn-Phong evaluations with `l + v = 0`.
    pub h_zero: u64,
    /// Non-finite float carriers replaced by 0 before conversion (float twins).
    pub nonfinite: u64,
}

impl Counters {
    /// Adds another set of counters.
    pub fn add(&mut self, o: &Counters) {
        self.frame_fallback += o.frame_fallback;
        self.zero_normal += o.zero_normal;
        self.h_zero += o.h_zero;
        self.nonfinite += o.nonfinite;
        for i in 0..StageKind::COUNT {
            self.invocations[i] += o.invocations[i];
            self.sat[i].add(&o.sat[i]);
            for j in 0..3 {
                self.cost[i][j] += o.cost[i][j];
            }
        }
    }
}

/// The fixed units and formats of one hardware configuration, built once per render.
pub struct Machine<'a> {
    pub hw: &'a HwConfig,
    pub recip: Reciprocal,
    /// Cost of one footprint-assembly lookup with 1, 2, 4, 8 and 16 probes (index `log2`),
    /// computed once from the datapaths (`aniso_adaptive` charges each pixel's own probes).
    pub footprint_costs: [UnitCost; 5],
    /// Texture coordinates: signed, texcoord_int_bits.texcoord_frac_bits.
    pub uv_fmt: Format,
    /// Colour channels: unorm color_bits (raw 0..2^bits-1).
    pub color_fmt: Format,
    /// LOD: signed, lod_frac_bits fraction bits.
    pub lod_fmt: Format,
    /// Barycentrics: signed, bary_bits fraction bits.
    pub bary_fmt: Format,
    /// Per texture: fixed levels and float levels.
    pub tex_fixed: Vec<Vec<Level<'a>>>,
    /// Per texture: every fixed level's sides are powers of two (`trilinear::pow2_chain`).
    pub tex_pow2: Vec<bool>,
    /// Per texture: the fixed levels' shape where the trilinear unit's batch form samples them.
    pub tex_batch: Vec<Option<BatchLevels>>,
    /// The constants of the `trilinear` stage's unit (`hw.trilinear`, `uv_fmt`, `hw.lod`).
    pub trilinear_setup: UnitSetup,
    pub tex_float: Vec<Vec<LevelF<'a>>>,
    /// Bump/shading units (rsqrt and pow tables built once).
    pub units: ShadingUnits,
    /// Vector components: signed 1.F (`vector_frac_bits`).
    pub vec_fmt: Format,
    /// Natural-frame lengths: unsigned `frame_len_int_bits.frame_len_frac_bits`.
    pub len_fmt: Format,
    /// The scene lights as the Phong stage sees them ([`Machine::with_lights`]).
    pub lights: Vec<ShadeLight>,
    /// Ambient light (0..1) and as `shade_color_bits` unorm.
    pub ambient: [f64; 3],
    pub ambient_x: [u64; 3],
    /// Per-triangle bump data ([`TriAttrs::bump`] indexes it).
    pub bump_attrs: &'a [BumpAttrs],
    /// Per-triangle llvmpipe setup of the float32 coordinate path ([`TriAttrs::f32_tri`]
    /// indexes it).
    pub f32_tris: &'a [super::coord_f32::F32Tri],
    /// ROMs of the anisotropic Phong unit, built on first use ([`Machine::aniso_roms`]).
    pub aniso_roms: std::sync::OnceLock<hw_model::aniso_phong::AnisoPhongRoms>,
    /// The fixed NDF unit of `hw.ndf` (`None` for the float-only `exact` normalization), built
    /// on first use ([`Machine::ndf`]).
    pub ndf: std::sync::OnceLock<Option<hw_model::ndf::NdfUnit>>,
    /// The density unit of `lean-shade` (the NDF unit with the `gauss` density), built on first
    /// use ([`Machine::lean_density`]).
    pub lean_density: std::sync::OnceLock<Option<hw_model::ndf::NdfUnit>>,
    /// Ground-truth normal maps: when not empty, the float `ndf-shade` supersamples them.
    pub ndf_truth: &'a [super::ndf::NdfTruth],
}

/// One scene light for per-pixel shading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadeLight {
    /// Index of the point light's interpolated vector, `None` for a directional light.
    pub point: Option<usize>,
    /// Unit direction towards a directional light (float and vector format).
    pub l_f: [f64; 3],
    pub l_x: [i64; 3],
    /// Colour (0..1 per channel, clamped) and as `shade_color_bits` unorm.
    pub color_f: [f64; 3],
    pub color_x: [u64; 3],
}

impl<'a> Machine<'a> {
    /// The fixed NDF unit of `hw.ndf` (`None` for the float-only `exact` normalization): its
    /// tables are built by the first `ndf-shade` that needs them, so a frame without an NDF
    /// material does not build them (about 0.09 ms a frame on the AMD guest, stop 62).
    pub fn ndf(&self) -> Option<&hw_model::ndf::NdfUnit> {
        self.ndf
            .get_or_init(|| super::ndf::ndf_unit(self.hw))
            .as_ref()
    }

    /// The density unit of `lean-shade`: `hw.ndf` with the `gauss` density (`None` when its
    /// widths are invalid).
    pub fn lean_density(&self) -> Option<&hw_model::ndf::NdfUnit> {
        self.lean_density
            .get_or_init(|| {
                let cfg = hw_model::ndf::NdfConfig {
                    ndf_density: hw_model::ndf::NdfDensity::Gauss,
                    ndf_norm: hw_model::ndf::NdfNorm::Partial,
                    ..self.hw.ndf.clone()
                };
                hw_model::ndf::NdfUnit::new(&cfg, &self.hw.reciprocal, &self.hw.shading.rsqrt).ok()
            })
            .as_ref()
    }

    /// Builds the units of `hw` over the prepared maps (`fixed[i]` quantizes `float[i]`).
    #[must_use]
    pub fn new(hw: &'a HwConfig, float: &'a [MipChain], fixed: &'a [FixedMipChain]) -> Self {
        let i = &hw.interp;
        let tex_fixed: Vec<Vec<Level<'a>>> = fixed.iter().map(FixedMipChain::views).collect();
        let uv_fmt = Format::signed(i.texcoord_int_bits, i.texcoord_frac_bits, i.interp_rounding)
            .with_overflow(i.texcoord_overflow);
        Self {
            hw,
            recip: Reciprocal::new(&hw.reciprocal),
            footprint_costs: [1, 2, 4, 8, 16].map(|n| {
                hw_model::footprint::footprint_cost(
                    &hw.trilinear,
                    &hw.lod,
                    n,
                    hw.timing.gate_levels_per_cycle,
                )
            }),
            trilinear_setup: UnitSetup::new(&hw.trilinear, uv_fmt.frac_bits, hw.lod.lod_frac_bits),
            uv_fmt,
            color_fmt: Format::unsigned(0, hw.color.color_bits, hw.color.color_rounding)
                .with_overflow(hw.color.color_overflow),
            lod_fmt: Format::signed(8, hw.lod.lod_frac_bits, Rounding::Truncate),
            bary_fmt: Format::signed(16, i.bary_bits, i.interp_rounding),
            tex_pow2: tex_fixed
                .iter()
                .map(|c| hw_model::trilinear::pow2_chain(c))
                .collect(),
            tex_batch: tex_fixed.iter().map(|c| BatchLevels::new(c)).collect(),
            tex_fixed,
            tex_float: float.iter().map(MipChain::views).collect(),
            units: ShadingUnits::new(&hw.shading),
            vec_fmt: vector_format(&hw.shading.vector),
            len_fmt: len_format(&hw.shading.frame, hw.shading.vector.vector_rounding),
            lights: Vec::new(),
            ambient: [0.0; 3],
            ambient_x: [0; 3],
            bump_attrs: &[],
            f32_tris: &[],
            aniso_roms: std::sync::OnceLock::new(),
            ndf: std::sync::OnceLock::new(),
            lean_density: std::sync::OnceLock::new(),
            ndf_truth: &[],
        }
    }

    /// Sets the lights of per-pixel (bump) shading: directional lights as constant unit
    /// directions, the first [`MAX_POINT_LIGHTS`] point lights through interpolated vectors
    /// (further point lights are not shaded per pixel; `render` rejects such scenes).
    #[must_use]
    pub fn with_lights(mut self, lights: &[Light], ambient: [f32; 3]) -> Self {
        let cb = self.hw.shading.shade.shade_color_bits;
        let f = self.hw.shading.vector.vector_frac_bits;
        let mut np = 0;
        self.lights = lights
            .iter()
            .filter_map(|l| {
                let (point, dir, col) = match l {
                    Light::Directional { direction, color } => {
                        let d = -DVec3::from(direction.map(f64::from));
                        (None, fref::normalize_or(d, DVec3::Z).0, color)
                    }
                    Light::Point { color, .. } => {
                        np += 1;
                        if np > MAX_POINT_LIGHTS {
                            return None;
                        }
                        (Some(np - 1), DVec3::Z, color)
                    }
                };
                let color_f = col.map(|c| f64::from(c).clamp(0.0, 1.0));
                Some(ShadeLight {
                    point,
                    l_f: dir.to_array(),
                    l_x: fref::to_vec3x(dir, f),
                    color_f,
                    color_x: color_f.map(|c| u64::from(to_unorm(c, cb))),
                })
            })
            .collect();
        self.ambient = ambient.map(|c| f64::from(c).clamp(0.0, 1.0));
        self.ambient_x = self.ambient.map(|c| u64::from(to_unorm(c, cb)));
        self
    }

    /// Shades NDF materials (float twin) from the supersampled finest normals `truth`.
    #[must_use]
    pub fn with_ndf_truth(mut self, truth: &'a [super::ndf::NdfTruth]) -> Self {
        self.ndf_truth = truth;
        self
    }

    /// Uses `attrs` as the per-triangle bump data.
    #[must_use]
    pub fn with_bump_attrs(mut self, attrs: &'a [BumpAttrs]) -> Self {
        self.bump_attrs = attrs;
        self
    }

    /// The per-triangle float32 setups ([`TriAttrs::f32_tri`] indexes them).
    #[must_use]
    pub fn with_f32_tris(mut self, tris: &'a [super::coord_f32::F32Tri]) -> Self {
        self.f32_tris = tris;
        self
    }

    /// The frame a bump plan uses: its material's, else the hardware's `frame_kind`.
    #[must_use]
    pub fn frame_of(&self, bp: &BumpPlan) -> FrameKind {
        bp.frame.unwrap_or(self.hw.shading.frame.frame_kind)
    }

    /// Cost of one invocation of `kind` in `plan` (fixed units' op and cycle counts).
    #[must_use]
    pub fn stage_cost(&self, kind: StageKind, plan: &Plan) -> UnitCost {
        (kind.row().cost)(self, plan)
    }
}

/// One screen triangle's vertex data in the hardware's input formats (its float form, read
/// only by float twins, is a [`TriFloat`] beside it).
#[derive(Clone, Copy, Debug, Default)]
pub struct TriAttrs {
    /// Plan index (the plan of the mesh the triangle came from).
    pub plan: u32,
    /// 1/w normalized so the largest is exactly 1 << inv_w_bits.
    pub inv_w_x: [i64; 3],
    /// Unorm `color_bits` (at most 16) per vertex and channel; 0 when the plan has no `color`
    /// stage (its only reader).
    pub color_x: [[u16; 3]; 3],
    pub uv_x: [[i64; 2]; 3],
    /// Index into [`Machine::bump_attrs`] (bump materials only; `u32::MAX` otherwise).
    pub bump: u32,
    /// Index into [`Machine::f32_tris`] (`interp.coord_arith = "float32"` only; `u32::MAX`
    /// otherwise).
    pub f32_tri: u32,
}

/// The integer subtracted from one axis of a triangle's texture coordinates `vals` at setup
/// (`interp.texcoord_reduce`): the floor of the middle of their range for `repeat`, the even
/// integer at or below it for `mirror` (a mirror period is two repeats), 0 for
/// `clamp-to-edge` (or non-finite input). Sampling at `x - offset` gives the texel of `x`
/// exactly for the periodic modes.
#[must_use]
pub fn texcoord_offset(vals: [f64; 3], wrap: WrapMode) -> f64 {
    let lo = vals.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = vals.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !(lo.is_finite() && hi.is_finite()) {
        return 0.0;
    }
    let mid = lo * 0.5 + hi * 0.5;
    match wrap {
        WrapMode::Repeat => floor_exact(mid),
        WrapMode::Mirror => 2.0 * floor_exact(mid * 0.5),
        WrapMode::ClampToEdge => 0.0,
    }
}

/// One screen triangle's vertex data in float (post-clip): what the float twins of `bary`,
/// `color` and `texcoord` and the float32 coordinate path read. A render builds them only
/// when a stage of one of its passes reads them; otherwise its stages see [`TriFloat::NONE`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriFloat {
    /// 1 / w_clip per vertex.
    pub inv_w: [f64; 3],
    /// Colour per vertex and channel.
    pub color: [[f64; 3]; 3],
    /// Texture coordinates per vertex.
    pub uv: [[f64; 2]; 3],
}

impl TriFloat {
    /// What a stage sees when the render built no float vertex data: NaN everywhere. Most
    /// readers would turn it into visibly wrong output, but [`texcoord_offset`] takes NaN as
    /// an offset of 0, which only coordinates beyond the format show;
    /// `every_float_reader_gets_the_float_vertex_data` therefore also renders a plane far out.
    pub const NONE: Self = Self {
        inv_w: [f64::NAN; 3],
        color: [[f64::NAN; 3]; 3],
        uv: [[f64::NAN; 2]; 3],
    };
}

/// Whether a stage of a pass with the twins `impls` on `hw` reads [`TriFloat`]: a float twin
/// whose table row says `float_reads_vertices` (`bary`, `color`, `texcoord`), or the float32
/// coordinate path (`interp.coord_arith = "float32"`, whose texture-coordinate reduction starts
/// from the float coordinates). A render builds the float vertex data when this holds or a
/// float pass (the reference, the truth, the signal ranges) runs;
/// `every_float_reader_gets_the_float_vertex_data` checks the rows against every float twin.
#[must_use]
pub fn reads_tri_floats(impls: &StageImpls, hw: &HwConfig) -> bool {
    hw.interp.coord_arith == CoordArith::Float32
        || StageKind::ALL
            .iter()
            .any(|&k| k.row().float_reads_vertices && impls.of(k) == Impl::Float)
}

impl TriAttrs {
    /// Converts float vertex data (post-clip) into the machine's formats. Host-to-hardware
    /// conversions that overflow are counted in `sat`. `color` is `None` when the plan has no
    /// `color` stage: no stage reads the colours then, and they stay 0 (an absent effect costs
    /// no conversion).
    #[must_use]
    pub fn new(
        m: &Machine,
        plan: u32,
        inv_w: [f64; 3],
        color: Option<[[f64; 3]; 3]>,
        uv: [[f64; 2]; 3],
        wrap: [WrapMode; 2],
        sat: &mut SatCounter,
    ) -> Self {
        // `interp.texcoord_reduce`: the fixed coordinates enter the format less one integer per
        // axis (exact: the offset is an integer, the coordinates f64 of f32 data).
        let off: [f64; 2] = if m.hw.interp.texcoord_reduce {
            [0, 1].map(|ax| texcoord_offset([uv[0][ax], uv[1][ax], uv[2][ax]], wrap[ax]))
        } else {
            [0.0; 2]
        };
        let bits = m.hw.interp.inv_w_bits;
        let max = inv_w.iter().copied().fold(f64::MIN_POSITIVE, f64::max);
        let norm = Format::unsigned(1, bits, Rounding::HalfEven);
        let cb = m.hw.color.color_bits;
        // Plain loops: nested array `map`s cost several hundred instructions per triangle.
        let mut inv_w_x = [0i64; 3];
        let mut color_x = [[0u16; 3]; 3];
        let mut uv_x = [[0i64; 2]; 3];
        for v in 0..3 {
            inv_w_x[v] = to_raw(inv_w[v] / max, &norm, sat).max(1);
            for ax in 0..2 {
                uv_x[v][ax] = to_raw(uv[v][ax] - off[ax], &m.uv_fmt, sat);
            }
        }
        if let Some(color) = color {
            for v in 0..3 {
                for ch in 0..3 {
                    // `color.color_bits <= 16` (validated), so the unorm fits.
                    color_x[v][ch] = to_unorm(color[v][ch], cb) as u16;
                }
            }
        }
        Self {
            plan,
            inv_w_x,
            color_x,
            uv_x,
            bump: u32::MAX,
            f32_tri: u32::MAX,
        }
    }

    /// A triangle no stage reads (hidden behind others in the frame's only shading pass): its
    /// plan, nothing converted. The caller keeps the overflow counts exact by taking it only
    /// where [`TriAttrs::new`] would count nothing ([`QuietSetup`]).
    #[must_use]
    pub fn unshaded(plan: u32) -> Self {
        Self {
            plan,
            bump: u32::MAX,
            f32_tri: u32::MAX,
            ..Self::default()
        }
    }
}

/// Bounds on a mesh's texture coordinates within which [`TriAttrs::new`] counts no overflow
/// for a triangle whose 1/w are finite and positive, whatever its wrap modes. The 1/w
/// normalized by the largest are in [0, 1], which the unsigned `1.inv_w_bits` format holds.
/// A coordinate in `[lo, hi]` less its offset (0, or an integer within 2 below the middle of
/// the triangle's own coordinates) is within `b = max(hi - lo + 2, |lo|, |hi|)` of 0; one
/// unit more covers the roundings of the subtraction and of a clipped triangle's blend of its
/// source's coordinates (`b <= 2^40`, so each is far below one unit). When `(b + 1) 2^frac`
/// is at least one LSB inside the coordinate format's range (and below 2^52), every rounded
/// value fits and nothing is counted.
#[derive(Clone, Copy, Debug)]
pub struct QuietSetup {
    quiet: bool,
}

impl QuietSetup {
    /// The bounds `lo`, `hi` (per axis; `None` when a coordinate is not finite) against the
    /// machine's coordinate format.
    #[must_use]
    pub fn new(m: &Machine, bounds: Option<([f64; 2], [f64; 2])>) -> Self {
        let fmt = &m.uv_fmt;
        let scale = crate::fixedpoint::pow2(fmt.frac_bits as i32);
        const LIMIT: i64 = 1 << 52;
        const TWO_40: f64 = (1u64 << 40) as f64;
        let (top, bottom) = (
            (fmt.max_raw().min(LIMIT) - 1) as f64,
            (fmt.min_raw().max(-LIMIT) + 1) as f64,
        );
        let quiet = bounds.is_some_and(|(lo, hi)| {
            (0..2).all(|ax| {
                let (l, h) = (lo[ax], hi[ax]);
                let b = (h - l + 2.0).max(l.abs()).max(h.abs()) + 1.0;
                l <= h && b <= TWO_40 && b * scale <= top && -b * scale >= bottom
            })
        });
        Self { quiet }
    }

    /// Whether the bounds fit the format: without it no triangle skips its conversion.
    #[must_use]
    pub fn is_quiet(&self) -> bool {
        self.quiet
    }

    /// Whether [`TriAttrs::new`] with these 1/w (and coordinates within the bounds) counts
    /// nothing.
    #[inline]
    #[must_use]
    pub fn holds(&self, inv_w: [f64; 3]) -> bool {
        self.quiet && inv_w.iter().all(|&w| w.is_finite() && w > 0.0)
    }
}

/// Component `c` of three vertices' attributes, as the interpolator's `i64` inputs.
#[inline]
pub(crate) fn column<T: Copy + Into<i64>, const N: usize>(v: &[[T; N]; 3], c: usize) -> [i64; 3] {
    [v[0][c].into(), v[1][c].into(), v[2][c].into()]
}

#[inline]
pub(crate) fn column_f<const N: usize>(v: &[[f64; N]; 3], c: usize) -> [f64; 3] {
    [v[0][c], v[1][c], v[2][c]]
}

/// A raw unorm value of `bits` bits as its exact float carrier.
#[inline]
pub(crate) fn unorm(raw: u32, bits: u32) -> f64 {
    f64::from(raw) / f64::from(max_unorm(bits))
}

/// Runs the compiled plan `prog` of `plan` on one fragment at pixel (`x`, `y`) of `tri`; the
/// result is in `frag.out` (and `frag.out_x` when the last stage was Fixed). The stages'
/// invocations and planned costs are not counted here: the caller counts the fragments of
/// each program and charges them once ([`Program::charge`]); a stage whose cost departs from
/// the plan (footprint assembly's adaptive probes) adds the difference to `c` itself.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn run(
    prog: &Program,
    plan: &Plan,
    m: &Machine,
    tri: &ScreenTri,
    (a, af): (&TriAttrs, &TriFloat),
    x: i64,
    y: i64,
    frag: &mut Frag,
    c: &mut Counters,
) {
    start(frag, plan);
    let px = prog.px(plan, m, tri, (a, af), (x, y), None, (None, 0));
    for op in &prog.ops {
        (op.run)(&px, frag, c);
    }
}

/// What every run of a program starts a fragment from: the plan's constant colour as its
/// colour and output, no raw output, no footprints.
#[inline]
fn start(frag: &mut Frag, plan: &Plan) {
    frag.color = plan.const_color;
    frag.out = plan.const_color;
    frag.out_bits = 0;
    frag.trace.clear();
}

/// Most fragments in one span, and in one run of [`run_spans`].
pub const SPAN_MAX: usize = 32;

/// One span of a run of [`run_spans`]: `n` consecutive covered pixels of `tri` from (`x`, `y`)
/// in one row.
#[derive(Clone, Copy)]
pub struct SpanAt<'a> {
    pub tri: &'a ScreenTri,
    /// The triangle's vertex data ([`TriAttrs`], [`TriFloat`]).
    pub attrs: (&'a TriAttrs, &'a TriFloat),
    pub x: i64,
    pub y: i64,
    pub n: usize,
    /// Its row computed its barycentrics ([`super::bary::Row`]; their saturations are
    /// counted there): they are pixels `x..x + n` of the row's.
    pub row_bary: bool,
}

/// [`run`] on consecutive spans of one program (at most [`SPAN_MAX`] fragments in all; the
/// row loop gathers at most 16, `render::shading::GATHER_MAX`):
/// `frags` holds the spans' fragments one span after another, fragment `j` of a span at
/// pixel (`x + j`, `y`) of its triangle. The program runs stage by stage over every span:
/// its span twin ([`super::table::SpanFn`]) on each span, or on all of `frags` at once when
/// the stage runs across triangles ([`super::table::Op::across`]); a stage without a span
/// twin runs its per-fragment twin on each fragment in turn. Every fragment ends as [`run`]
/// leaves it, and the counters get the same sums (`frames_in_spans_equal_frames_per_fragment`
/// in the pipeline tests). `row_bary`: the row's barycentrics, indexed by pixel, read by the
/// spans with [`SpanAt::row_bary`]. `lanes`: the worker's lanes, which a program that keeps
/// the chain's signals there ([`Program::lanes`]) passes its stages, fragment `j` of the run
/// in lane `j`.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn run_spans<'a>(
    prog: &'a Program,
    plan: &'a Plan,
    m: &'a Machine<'a>,
    spans: &[SpanAt<'a>],
    row_bary: &'a [[[i64; 3]; 3]],
    lanes: &'a LaneCell,
    frags: &mut [Frag],
    c: &mut Counters,
) {
    debug_assert!(frags.len() <= LANES);
    for frag in frags.iter_mut() {
        start(frag, plan);
    }
    // Lanes where the spans are long enough for `texcoord`'s vector loop to pay: a run of
    // short spans (a mesh's) costs more in lanes than in the fragments (W2, stop 59).
    let keep = prog.lanes && spans.iter().all(|s| s.n >= LANES_SPAN_MIN);
    let lanes = keep.then_some(lanes);
    let px = |s: &SpanAt<'a>, base: usize| -> Px<'a> {
        let x = s.x as usize;
        let bary = s.row_bary.then(|| &row_bary[x..x + s.n]);
        prog.px(plan, m, s.tri, s.attrs, (s.x, s.y), bary, (lanes, base))
    };
    for op in &prog.ops {
        match op.span {
            Some(span) if op.across => span(&px(&spans[0], 0), frags, c),
            _ => {
                let (mut rest, mut base) = (&mut *frags, 0);
                for s in spans {
                    let (head, tail) = rest.split_at_mut(s.n);
                    match op.span {
                        Some(span) => span(&px(s, base), head, c),
                        None => each_fragment(op.run, &px(s, base), head, c),
                    }
                    (rest, base) = (tail, base + s.n);
                }
            }
        }
    }
}

/// The per-fragment twin `run` on each fragment of the span of `px`, in order.
#[inline]
pub fn each_fragment(run: RunFn, px: &Px, frags: &mut [Frag], c: &mut Counters) {
    for (j, frag) in frags.iter_mut().enumerate() {
        let at = Px {
            x: px.x + j as i64,
            ..*px
        };
        run(&at, frag, c);
    }
}

/// Texel-space derivatives `[du/dx, dv/dx, du/dy, dv/dy]` (raw, texcoord fraction bits) of a
/// `w` x `h` texture from the pixel's texture coordinates and its two helper samples.
#[inline]
#[must_use]
pub fn texel_derivs(uv: &[[i64; 2]; 3], w: u32, h: u32) -> [i64; 4] {
    let (w, h) = (i64::from(w), i64::from(h));
    [
        (uv[1][0] - uv[0][0]) * w,
        (uv[1][1] - uv[0][1]) * h,
        (uv[2][0] - uv[0][0]) * w,
        (uv[2][1] - uv[0][1]) * h,
    ]
}

/// The float twin of [`texel_derivs`].
#[inline]
#[must_use]
pub fn texel_derivs_f64(uv: &[[f64; 2]; 3], w: u32, h: u32) -> [f64; 4] {
    let (w, h) = (f64::from(w), f64::from(h));
    [
        (uv[1][0] - uv[0][0]) * w,
        (uv[1][1] - uv[0][1]) * h,
        (uv[2][0] - uv[0][0]) * w,
        (uv[2][1] - uv[0][1]) * h,
    ]
}

#[inline]
const fn max_unorm(bits: u32) -> u32 {
    ((1u64 << bits) - 1) as u32
}

/// The fragment's output as a 16-bit unorm pixel: exact integer conversion of a Fixed
/// stage's raw output, rounded conversion of a float carrier.
#[inline(always)]
#[must_use]
pub fn output16(frag: &Frag) -> [u16; 4] {
    if frag.out_bits == 0 {
        frag.out.map(|v| to_unorm(v, 16) as u16)
    } else {
        frag.out_x
            .map(|v| unorm_convert(v, frag.out_bits, 16, Rounding::HalfEven) as u16)
    }
}
