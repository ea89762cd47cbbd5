//! The stage table: one row per stage kind, from which the kind, its name, the count and the
//! dispatch are generated (as tiny-skia's `Stage` list and its function tables), and the
//! [`Program`] a material's plan is compiled into once per render: its stages' twins and
//! costs resolved, so the pixel loop only calls what is in the program.
//!
//! A row names the stage's fixed twin, its float twin, its cost per invocation and its texture
//! lookups per invocation (what the timing model budgets events for), and optionally a fixed
//! twin over a span of fragments (`fixed_span`, see [`SpanFn`]; without one, a span runs the
//! fixed twin on each fragment) and when that span twin may take the fragments of several
//! triangles at once (`across`, see [`AcrossFn`]) and when it may run with the chain's
//! signals in lanes (`lanes`, see [`LanesFn`]). Adding a stage is a file with those four
//! functions and a row here (see `docs/ARCHITECTURE.md`).

use super::lanes::{keeps_lanes, LaneCell};
use super::stages::{Counters, Machine, TriAttrs, TriFloat};
use super::{
    as_shade, bary, bump_fetch, color, env_fetch, frame, lean_fetch, lean_shade, lobe_fetch,
    lobe_shade, lod, modulate, ndf_fetch, ndf_shade, normal, perturb, phong, rough_fetch,
    rough_shade, texcoord, toksvig_fetch, toksvig_shade, trilinear,
};
use super::{Frag, Impl, Plan, StageImpls};
use crate::raster::ScreenTri;
use hw_model::{HwConfig, UnitCost};
use serde::Serialize;
use std::fmt;

/// What a stage twin sees of the pixel it shades (of the first fragment of a span; of a run's
/// first span for a stage that runs across triangles, [`AcrossFn`]).
#[derive(Clone, Copy)]
pub struct Px<'a> {
    /// The material's plan (maps, frame, lights and options of its stages).
    pub plan: &'a Plan,
    /// The twin of every stage kind in this run (a Fixed stage reads a Fixed producer's raw
    /// value and rounds a Float producer's carrier into its input format).
    pub impls: &'a StageImpls,
    pub m: &'a Machine<'a>,
    pub tri: &'a ScreenTri,
    pub a: &'a TriAttrs,
    /// The triangle's vertex data in float ([`TriFloat::NONE`] when no stage of the render's
    /// passes reads it).
    pub af: &'a TriFloat,
    /// The pixel (for a span: its first fragment's; fragment `j` is at (`x + j`, `y`)).
    pub x: i64,
    pub y: i64,
    /// The plan's colour comes from a Fixed `color` stage (its raw value is in `Frag::color_x`).
    pub color_raw: bool,
    /// A stage of this run may read the float carriers of a Fixed producer (see
    /// [`Program::carriers`]); when false, the Fixed twins write their raw values only.
    pub carriers: bool,
    /// The span's barycentrics when its row computed them in one pass
    /// ([`super::bary::Row`], [`Program::row_bary`]).
    pub row_bary: Option<&'a [[[i64; 3]; 3]]>,
    /// The run's lanes when the program keeps the chain's signals there ([`Program::lanes`]).
    pub lanes: Option<&'a LaneCell>,
    /// The lane of the span's first fragment (0 for a stage that runs across triangles).
    pub base: usize,
}

impl Px<'_> {
    /// True when stage `kind` runs its fixed twin in this run.
    #[inline]
    #[must_use]
    pub fn fixed(&self, kind: StageKind) -> bool {
        self.impls.of(kind) == Impl::Fixed
    }

    /// Samples per pixel: the pixel and, when the plan needs derivatives, its two helpers.
    #[inline]
    #[must_use]
    pub fn samples(&self) -> usize {
        if self.plan.derivatives {
            3
        } else {
            1
        }
    }
}

/// A stage twin: shades one fragment, counting into the run's counters.
pub type RunFn = fn(&Px, &mut Frag, &mut Counters);
/// A stage twin over a span: the fragments of consecutive pixels (`px.x + j`, `px.y`) of one
/// triangle, `j` = index in the slice (or, for a stage that runs across triangles, see
/// [`AcrossFn`], the fragments of a run of such spans); the same results and counts as the
/// [`RunFn`] twin on each fragment in turn.
pub type SpanFn = fn(&Px, &mut [Frag], &mut Counters);
/// Whether a stage's fixed twins (per fragment and over a span) read nothing of the pixel
/// they shade beyond its fragment, the plan, the machine and the run's options (not
/// `Px::tri`, `a`, `af`, `x`, `y` nor `row_bary`) in a plan on a machine: its span twin may
/// then take the fragments of consecutive spans of one program, of several triangles, at
/// once ([`super::stages::run_spans`]), so that short spans (a mesh's) fill its batches.
pub type AcrossFn = fn(&Machine, &Plan) -> bool;
/// Whether a stage's fixed twins may run in a program that keeps the chain's signals in the
/// run's lanes ([`super::lanes`]) in a plan on a machine: given [`Px::lanes`], its span twin
/// reads and writes the barycentrics and texture coordinates there, and neither twin reads
/// those fields of a fragment otherwise (the per-fragment twin never sees lanes).
pub type LanesFn = fn(&Machine, &Plan) -> bool;
/// A stage's cost per invocation in a plan on a machine (fixed units' ops, cycles, texels).
pub type CostFn = fn(&Machine, &Plan) -> UnitCost;
/// Texture lookups per invocation on a hardware configuration.
pub type LookupsFn = fn(&HwConfig) -> u32;

/// One row of the stage table.
#[derive(Clone, Copy)]
pub struct StageRow {
    pub kind: StageKind,
    pub name: &'static str,
    pub fixed: RunFn,
    /// The fixed twin over a span, when the stage has one.
    pub fixed_span: Option<SpanFn>,
    /// When `fixed_span` may take several triangles' spans at once.
    pub across: AcrossFn,
    /// When the stage may run in a program that keeps the chain's signals in lanes.
    pub lanes: LanesFn,
    pub float: RunFn,
    /// The float twin reads the triangle's float vertex data (`Px::af`, a
    /// [`super::stages::TriFloat`]): a render builds it when such a twin runs
    /// ([`super::stages::reads_tri_floats`]).
    pub float_reads_vertices: bool,
    pub cost: CostFn,
    pub lookups: LookupsFn,
}

/// A stage whose span twin takes one triangle's span at a time.
fn never(_: &Machine, _: &Plan) -> bool {
    false
}

/// A stage whose fixed twins read only the fragment, the plan, the machine and the options.
fn always(_: &Machine, _: &Plan) -> bool {
    true
}

/// A stage that reads no texture.
fn no_lookups(_: &HwConfig) -> u32 {
    0
}

/// A stage that makes one trilinear lookup.
fn one_lookup(_: &HwConfig) -> u32 {
    1
}

/// `Some(span)` for a row's `fixed_span`, `None` without one.
macro_rules! optional_span {
    () => {
        None
    };
    ($span:expr) => {
        Some($span)
    };
}

/// A row's `across` or `lanes`: [`never`] unless given.
macro_rules! or_never {
    () => {
        never
    };
    ($f:expr) => {
        $f
    };
}

/// A row's `float_reads_vertices`: `false` unless given.
macro_rules! optional_flag {
    () => {
        false
    };
    ($flag:expr) => {
        $flag
    };
}

macro_rules! stage_table {
    ($( $(#[doc = $doc:literal])* $kind:ident $name:literal {
        fixed: $fixed:expr, $(fixed_span: $span:expr,)? $(across: $across:expr,)?
        $(lanes: $lanes:expr,)? float: $float:expr,
        $(float_reads_vertices: $reads:expr,)? cost: $cost:expr, lookups: $lookups:expr $(,)?
    } )*) => {
        /// The kinds of stage, in pipeline order (generated from the stage table).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
        #[serde(rename_all = "kebab-case")]
        pub enum StageKind {
            $( $(#[doc = $doc])* $kind, )*
        }

        impl StageKind {
            /// Number of stage kinds.
            pub const COUNT: usize = [$($name),*].len();

            /// Every stage kind, in pipeline order.
            pub const ALL: [StageKind; StageKind::COUNT] = [$(StageKind::$kind,)*];
        }

        /// The stage table, indexed by [`StageKind::index`].
        pub const STAGES: [StageRow; StageKind::COUNT] = [$(
            StageRow {
                kind: StageKind::$kind,
                name: $name,
                fixed: $fixed,
                fixed_span: optional_span!($($span)?),
                across: or_never!($($across)?),
                lanes: or_never!($($lanes)?),
                float: $float,
                float_reads_vertices: optional_flag!($($reads)?),
                cost: $cost,
                lookups: $lookups,
            },
        )*];
    };
}

stage_table! {
    /// Perspective-correct barycentrics (reciprocal unit + interpolator setup).
    Bary "bary" {
        fixed: bary::fixed, fixed_span: bary::fixed_span, lanes: always, float: bary::float,
        float_reads_vertices: true, cost: bary::cost, lookups: no_lookups,
    }
    /// Vertex colour interpolation (Gouraud lighting result).
    Color "color" {
        fixed: color::fixed, fixed_span: color::fixed_span, float: color::float,
        float_reads_vertices: true, cost: color::cost, lookups: no_lookups,
    }
    /// Texture-coordinate interpolation, with the helper samples for derivatives.
    Texcoord "texcoord" {
        fixed: texcoord::fixed, fixed_span: texcoord::fixed_span, lanes: texcoord::lanes,
        float: texcoord::float, float_reads_vertices: true, cost: texcoord::cost,
        lookups: no_lookups,
    }
    /// LOD from the texture-coordinate derivatives.
    Lod "lod" {
        fixed: lod::fixed, fixed_span: lod::fixed_span, across: lod::across, lanes: lod::lanes,
        float: lod::float, cost: lod::cost, lookups: no_lookups,
    }
    /// Wrap + trilinear MIP filtering (footprint assembly with `aniso_probes` > 1).
    Trilinear "trilinear" {
        fixed: trilinear::fixed, fixed_span: trilinear::fixed_span, across: always,
        lanes: trilinear::lanes, float: trilinear::float, cost: trilinear::cost,
        lookups: trilinear::lookups,
    }
    /// Colour x texel.
    Modulate "modulate" {
        fixed: modulate::fixed, fixed_span: modulate::fixed_span, across: always, lanes: always,
        float: modulate::float, cost: modulate::cost, lookups: no_lookups,
    }
    /// Bump materials: interpolation of the normal, frame vectors/lengths and light vectors.
    Normal "normal" {
        fixed: normal::fixed, fixed_span: normal::fixed_span, float: normal::float,
        cost: normal::cost,
        lookups: no_lookups,
    }
    /// Bump materials: LOD + trilinear fetch of the offset map `(f_u, f_v)`.
    BumpFetch "bump-fetch" {
        fixed: bump_fetch::fixed, float: bump_fetch::float, cost: bump_fetch::cost,
        lookups: one_lookup,
    }
    /// Bump materials: the local frame (natural, unit or main direction).
    Frame "frame" {
        fixed: frame::fixed, float: frame::float, cost: frame::cost,
        lookups: no_lookups,
    }
    /// Bump materials: `n' = normalize(n + f_u s_u + f_v s_v)`.
    Perturb "perturb" {
        fixed: perturb::fixed, float: perturb::float, cost: perturb::cost,
        lookups: no_lookups,
    }
    /// Bump materials: per-pixel Blinn-Phong over every scene light (+ ambient).
    Phong "phong" {
        fixed: phong::fixed, float: phong::float, cost: phong::cost,
        lookups: no_lookups,
    }
    /// Ashikhmin-Shirley materials: the anisotropic Phong BRDF per pixel over every light.
    AsShade "as-shade" {
        fixed: as_shade::fixed, float: as_shade::float, cost: as_shade::cost,
        lookups: no_lookups,
    }
    /// Roughness materials: trilinear fetch of the D map at the bump fetch's LOD.
    RoughFetch "rough-fetch" {
        fixed: rough_fetch::fixed, float: rough_fetch::float, cost: rough_fetch::cost,
        lookups: one_lookup,
    }
    /// Roughness materials: Blinn-Phong with the modified specular term (replaces `phong`).
    RoughShade "rough-shade" {
        fixed: rough_shade::fixed, float: rough_shade::float, cost: rough_shade::cost,
        lookups: no_lookups,
    }
    /// Toksvig materials: trilinear fetch of the Toksvig map at the bump fetch's LOD.
    ToksvigFetch "toksvig-fetch" {
        fixed: toksvig_fetch::fixed, float: toksvig_fetch::float, cost: toksvig_fetch::cost,
        lookups: one_lookup,
    }
    /// Toksvig materials: adjusted exponent and scale, Blinn-Phong (replaces `phong`).
    ToksvigShade "toksvig-shade" {
        fixed: toksvig_shade::fixed, float: toksvig_shade::float, cost: toksvig_shade::cost,
        lookups: no_lookups,
    }
    /// LEAN materials: trilinear fetch of the second-moment map at the bump fetch's LOD.
    LeanFetch "lean-fetch" {
        fixed: lean_fetch::fixed, float: lean_fetch::float, cost: lean_fetch::cost,
        lookups: one_lookup,
    }
    /// LEAN materials: the slope Gaussian at the half vector per light (replaces `phong`).
    LeanShade "lean-shade" {
        fixed: lean_shade::fixed, float: lean_shade::float, cost: lean_shade::cost,
        lookups: no_lookups,
    }
    /// NDF materials: LOD + three trilinear lookups of the moment maps (+1 normalization map).
    NdfFetch "ndf-fetch" {
        fixed: ndf_fetch::fixed, float: ndf_fetch::float, cost: ndf_fetch::cost,
        lookups: ndf_fetch::lookups,
    }
    /// NDF materials: Sigma, its inverse, Mahalanobis distance, density, normalization, lights.
    NdfShade "ndf-shade" {
        fixed: ndf_shade::fixed, float: ndf_shade::float, cost: ndf_shade::cost,
        lookups: no_lookups,
    }
    /// Environment-map materials: reflection, cube face, roughness-filtered footprint on
    /// the face, `shade + ks * env`.
    EnvFetch "env-fetch" {
        fixed: env_fetch::fixed, float: env_fetch::float, cost: env_fetch::cost,
        lookups: env_fetch::lookups,
    }
    /// Fitted Fournier lobes: the nearest level's texel of the K lobe maps (K lookups).
    LobeFetch "lobe-fetch" {
        fixed: lobe_fetch::fixed, float: lobe_fetch::float, cost: lobe_fetch::cost,
        lookups: lobe_fetch::lookups,
    }
    /// Fournier multiple surfaces: the sum of the lobes' Phong shadings over every light.
    LobeShade "lobe-shade" {
        fixed: lobe_shade::fixed, float: lobe_shade::float, cost: lobe_shade::cost,
        lookups: no_lookups,
    }
}

impl StageKind {
    /// The name used on the command line and in reports.
    #[must_use]
    pub const fn name(self) -> &'static str {
        STAGES[self as usize].name
    }

    /// The table row of this kind.
    #[must_use]
    pub const fn row(self) -> &'static StageRow {
        &STAGES[self as usize]
    }

    /// Parses a stage name.
    pub fn parse(s: &str) -> crate::Result<StageKind> {
        Self::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = Self::ALL.iter().map(|k| k.name()).collect();
                crate::Error::msg(format!(
                    "unknown stage '{s}' (stages: {})",
                    names.join(", ")
                ))
            })
    }

    /// Position in [`StageKind::ALL`].
    #[must_use]
    pub const fn index(self) -> usize {
        self as usize
    }
}

impl fmt::Display for StageKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// One compiled stage: its kind, the twin that runs (per fragment and, when it has one, over
/// a span, and whether over several triangles' spans at once) and its cost per invocation.
#[derive(Clone, Copy)]
pub struct Op {
    pub kind: StageKind,
    pub run: RunFn,
    /// The twin over a span (`None`: `run` on each fragment of the span).
    pub span: Option<SpanFn>,
    /// `span` takes the fragments of several triangles' spans at once ([`AcrossFn`]).
    pub across: bool,
    pub cost: UnitCost,
}

/// A plan compiled for one run: the stages in order with their twins and costs resolved.
pub struct Program {
    pub ops: Vec<Op>,
    pub impls: StageImpls,
    /// The plan's colour comes from a Fixed `color` stage.
    pub color_raw: bool,
    /// Whether the Fixed twins must also write the float carriers of their results: false
    /// only when every stage of the plan runs Fixed and is one of `bary`, `color`,
    /// `texcoord`, `lod`, `trilinear`, `modulate`, whose Fixed twins read their producers'
    /// raw values only (and the fragment's output is then the last stage's raw value).
    pub carriers: bool,
    /// The plan's barycentrics run Fixed as one pass over each row's spans
    /// ([`super::bary::Row`]) before the row is shaded.
    pub row_bary: bool,
    /// Some stage of the program runs across triangles ([`Op::across`]): the pixel loop
    /// gathers consecutive spans of this program into one run ([`super::stages::run_spans`]).
    pub gathers: bool,
    /// The span twins of `bary`, `texcoord`, `lod` and `trilinear` pass the barycentrics and
    /// texture coordinates in the run's lanes, not in the fragments ([`super::lanes`]).
    pub lanes: bool,
}

impl Program {
    /// Counts `fragments` runs of this program into `c`: each stage's invocations and its
    /// planned cost per invocation (the per-fragment [`super::stages::run`] counts neither).
    /// Costs add modulo 2^64, because a stage that charged a fragment less than planned
    /// (`trilinear`'s adaptive probes) may have taken the difference from `c` before the
    /// charge; the charged totals are the true, non-negative sums.
    pub fn charge(&self, fragments: u64, c: &mut Counters) {
        for op in &self.ops {
            let k = op.kind.index();
            c.invocations[k] += fragments;
            let cost = [op.cost.ops, op.cost.cycles, op.cost.texels];
            for (acc, per) in c.cost[k].iter_mut().zip(cost) {
                *acc = acc.wrapping_add(fragments.wrapping_mul(u64::from(per)));
            }
        }
    }

    /// What the stages of this program see at pixel (`x`, `y`) of `tri` (for a span, its first
    /// fragment's pixel), with the run's lanes (given only to a program that keeps them,
    /// [`Program::lanes`]) and the span's first lane.
    #[must_use]
    #[allow(clippy::too_many_arguments)]
    pub fn px<'a>(
        &'a self,
        plan: &'a Plan,
        m: &'a Machine<'a>,
        tri: &'a ScreenTri,
        (a, af): (&'a TriAttrs, &'a TriFloat),
        (x, y): (i64, i64),
        row_bary: Option<&'a [[[i64; 3]; 3]]>,
        (lanes, base): (Option<&'a LaneCell>, usize),
    ) -> Px<'a> {
        Px {
            plan,
            impls: &self.impls,
            m,
            tri,
            a,
            af,
            x,
            y,
            color_raw: self.color_raw,
            carriers: self.carriers,
            row_bary,
            lanes,
            base,
        }
    }

    /// Compiles `plan` with the twins `impls` on the machine `m`.
    #[must_use]
    pub fn new(plan: &Plan, impls: &StageImpls, m: &Machine) -> Self {
        let ops: Vec<Op> = plan
            .stages
            .iter()
            .map(|&kind| {
                let row = kind.row();
                let (run, span) = match impls.of(kind) {
                    Impl::Fixed => (row.fixed, row.fixed_span),
                    Impl::Float => (row.float, None),
                };
                Op {
                    kind,
                    run,
                    span,
                    across: span.is_some() && (row.across)(m, plan),
                    cost: (row.cost)(m, plan),
                }
            })
            .collect();
        const RAW_ONLY: [StageKind; 6] = [
            StageKind::Bary,
            StageKind::Color,
            StageKind::Texcoord,
            StageKind::Lod,
            StageKind::Trilinear,
            StageKind::Modulate,
        ];
        let raw_only = plan
            .stages
            .iter()
            .all(|&k| impls.of(k) == Impl::Fixed && RAW_ONLY.contains(&k));
        Self {
            impls: *impls,
            color_raw: plan.has(StageKind::Color) && impls.of(StageKind::Color) == Impl::Fixed,
            carriers: !raw_only,
            row_bary: plan.has(StageKind::Bary)
                && impls.of(StageKind::Bary) == Impl::Fixed
                && super::bary::row_pass(m, plan),
            gathers: ops.iter().any(|op| op.across),
            lanes: keeps_lanes(plan, impls, m),
            ops,
        }
    }
}
