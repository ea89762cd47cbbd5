//! The stage twins: for each [`StageKind`], a Fixed implementation (hw_model units, declared
//! formats) and a Float implementation (`crate::reference`, exact math), behind one entry point
//! [`run`]. Per-triangle vertex data is prepared once ([`TriAttrs`]), in float and in the
//! hardware's input formats, so the per-pixel loop allocates nothing.

use super::bump_stages::{self, run_bump_stage, BumpAttrs};
use super::{BumpPlan, Frag, Impl, Plan, StageImpls, StageKind, MAX_POINT_LIGHTS};
use crate::fixedpoint::{from_raw, to_raw, to_unorm};
use crate::footprint_ref::{footprint_f64, footprint_filter_f64};
use crate::maps::{FixedMipChain, MipChain};
use crate::raster::ScreenTri;
use crate::reference::{
    interpolate_f64, lod_f64, perspective_bary_derivs_f64, perspective_bary_f64, trilinear_f64,
    LevelF,
};
use crate::scene::{FrameKind, Light, WrapMode};
use crate::shading::reference as fref;
use glam::DVec3;
use hw_model::blinn_phong::{blinn_phong_cost, ShadingUnits};
use hw_model::config::HwConfig;
use hw_model::fixed::{Format, Rounding, SatCounter};
use hw_model::footprint::{footprint, footprint_cost, footprint_filter};
use hw_model::frame::{frame_cost, len_format, perturb_cost};
use hw_model::interpolator::{
    interpolate, interpolate_cost, perspective_bary, perspective_bary_cost,
    perspective_bary_derivs, perspective_bary_derivs_cost,
};
use hw_model::lod::{lod, lod_cost};
use hw_model::modulate::{modulate, modulate_cost, unorm_convert};
use hw_model::reciprocal::Reciprocal;
use hw_model::rsqrt::rsqrt_cost;
use hw_model::trilinear::{trilinear, trilinear_cost, Level};
use hw_model::vector::{normalize_cost, vector_format};
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
    /// ROMs of the anisotropic Phong unit, built on first use ([`Machine::aniso_roms`]).
    pub aniso_roms: std::sync::OnceLock<hw_model::aniso_phong::AnisoPhongRoms>,
    /// The fixed NDF unit of `hw.ndf` (`None` for the float-only `exact` normalization).
    pub ndf: Option<hw_model::ndf::NdfUnit>,
    /// Ground-truth normal maps: when not empty, the float `ndf-shade` supersamples them.
    pub ndf_truth: &'a [super::ndf_stages::NdfTruth],
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
    /// Builds the units of `hw` over the prepared maps (`fixed[i]` quantizes `float[i]`).
    #[must_use]
    pub fn new(hw: &'a HwConfig, float: &'a [MipChain], fixed: &'a [FixedMipChain]) -> Self {
        let i = &hw.interp;
        Self {
            hw,
            recip: Reciprocal::new(&hw.reciprocal),
            uv_fmt: Format::signed(i.texcoord_int_bits, i.texcoord_frac_bits, i.interp_rounding)
                .with_overflow(i.texcoord_overflow),
            color_fmt: Format::unsigned(0, hw.color.color_bits, hw.color.color_rounding)
                .with_overflow(hw.color.color_overflow),
            lod_fmt: Format::signed(8, hw.lod.lod_frac_bits, Rounding::Truncate),
            bary_fmt: Format::signed(16, i.bary_bits, i.interp_rounding),
            tex_fixed: fixed.iter().map(FixedMipChain::views).collect(),
            tex_float: float.iter().map(MipChain::views).collect(),
            units: ShadingUnits::new(&hw.shading),
            vec_fmt: vector_format(&hw.shading.vector),
            len_fmt: len_format(&hw.shading.frame, hw.shading.vector.vector_rounding),
            lights: Vec::new(),
            ambient: [0.0; 3],
            ambient_x: [0; 3],
            bump_attrs: &[],
            aniso_roms: std::sync::OnceLock::new(),
            ndf: super::ndf_stages::ndf_unit(hw),
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
    pub fn with_ndf_truth(mut self, truth: &'a [super::ndf_stages::NdfTruth]) -> Self {
        self.ndf_truth = truth;
        self
    }

    /// Uses `attrs` as the per-triangle bump data.
    #[must_use]
    pub fn with_bump_attrs(mut self, attrs: &'a [BumpAttrs]) -> Self {
        self.bump_attrs = attrs;
        self
    }

    /// The frame a bump plan uses: its material's, else the hardware's `frame_kind`.
    #[must_use]
    pub fn frame_of(&self, bp: &BumpPlan) -> FrameKind {
        bp.frame.unwrap_or(self.hw.shading.frame.frame_kind)
    }

    /// Cost of one invocation of each stage kind of `plan` (zero for absent stages).
    #[must_use]
    pub fn plan_costs(&self, plan: &Plan) -> [UnitCost; StageKind::COUNT] {
        let mut c = [UnitCost::default(); StageKind::COUNT];
        for &k in &plan.stages {
            c[k.index()] = self.stage_cost(k, plan);
        }
        c
    }

    /// Cost of one invocation of `kind` in `plan` (fixed units' op and cycle counts).
    #[must_use]
    pub fn stage_cost(&self, kind: StageKind, plan: &Plan) -> UnitCost {
        let samples = if plan.derivatives { 3 } else { 1 };
        let i = &self.hw.interp;
        match kind {
            StageKind::Bary if plan.derivatives => perspective_bary_derivs_cost(i, &self.recip),
            StageKind::Bary => perspective_bary_cost(i, &self.recip),
            StageKind::Color => interpolate_cost(i).times(3),
            StageKind::Texcoord => interpolate_cost(i).times(2 * samples),
            StageKind::Lod => lod_cost(&self.hw.lod),
            StageKind::Trilinear if plan.derivatives => footprint_cost(
                &self.hw.trilinear,
                &self.hw.lod,
                self.hw.trilinear.aniso_probes,
            ),
            StageKind::Trilinear => trilinear_cost(&self.hw.trilinear, 2),
            StageKind::Modulate => modulate_cost(&self.hw.color),
            StageKind::AsShade => super::as_stages::as_shade_cost(self, plan),
            StageKind::RoughFetch | StageKind::RoughShade => {
                super::rough_stages::rough_stage_cost(self, kind, plan)
            }
            StageKind::NdfFetch | StageKind::NdfShade => {
                super::ndf_stages::ndf_stage_cost(self, kind, plan)
            }
            _ => self.bump_stage_cost(kind, plan),
        }
    }

    /// Cost of one invocation of a bump stage of `plan` (zero without a bump plan).
    fn bump_stage_cost(&self, kind: StageKind, plan: &Plan) -> UnitCost {
        let Some(bp) = &plan.bump else {
            return UnitCost::default();
        };
        let u = &self.units;
        let fk = self.frame_of(bp);
        let np = bump_stages::point_lights(self) as u32;
        let nz = normalize_cost(&u.cfg.vector, rsqrt_cost(&u.cfg.rsqrt));
        let mac = UnitCost {
            ops: 3,
            cycles: u.cfg.shade.shade_cycles,
            texels: 0,
        };
        match kind {
            StageKind::Normal => interpolate_cost(&self.hw.interp)
                .times(bump_stages::normal_attr_count(self, bp, fk)),
            StageKind::BumpFetch => {
                lod_cost(&self.hw.lod).plus(trilinear_cost(&self.hw.trilinear, 2))
            }
            StageKind::Frame => frame_cost(fk, u),
            StageKind::Perturb => perturb_cost(u),
            StageKind::Phong => {
                let lights = self.lights.len() as u32;
                let mut c = blinn_phong_cost(u)
                    .times(lights)
                    .plus(nz.times(1 + np))
                    .plus(mac.times(1 + lights));
                if plan.texture.is_some() {
                    c = c.plus(mac);
                }
                c
            }
            _ => UnitCost::default(),
        }
    }
}

/// One screen triangle's vertex data, in float and in the hardware's input formats.
#[derive(Clone, Copy, Debug, Default)]
pub struct TriAttrs {
    /// Plan index (the plan of the mesh the triangle came from).
    pub plan: u32,
    pub inv_w_f: [f64; 3],
    /// 1/w normalized so the largest is exactly 1 << inv_w_bits.
    pub inv_w_x: [i64; 3],
    pub color_f: [[f64; 3]; 3],
    pub color_x: [[i64; 3]; 3],
    pub uv_f: [[f64; 2]; 3],
    pub uv_x: [[i64; 2]; 3],
    /// Index into [`Machine::bump_attrs`] (bump materials only; `u32::MAX` otherwise).
    pub bump: u32,
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
        WrapMode::Repeat => mid.floor(),
        WrapMode::Mirror => 2.0 * (mid * 0.5).floor(),
        WrapMode::ClampToEdge => 0.0,
    }
}

impl TriAttrs {
    /// Converts float vertex data (post-clip) into the machine's formats. Host-to-hardware
    /// conversions that overflow are counted in `sat`.
    #[must_use]
    pub fn new(
        m: &Machine,
        plan: u32,
        inv_w: [f64; 3],
        color: [[f64; 3]; 3],
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
        let inv_w_x = inv_w.map(|q| to_raw(q / max, &norm, sat).max(1));
        let cb = m.hw.color.color_bits;
        Self {
            plan,
            inv_w_f: inv_w,
            inv_w_x,
            color_f: color,
            color_x: color.map(|c| c.map(|x| i64::from(to_unorm(x, cb)))),
            uv_f: uv,
            uv_x: uv.map(|t| [0, 1].map(|ax| to_raw(t[ax] - off[ax], &m.uv_fmt, sat))),
            bump: u32::MAX,
        }
    }
}

#[inline]
pub(crate) fn column<const N: usize>(v: &[[i64; N]; 3], c: usize) -> [i64; 3] {
    [v[0][c], v[1][c], v[2][c]]
}

#[inline]
pub(crate) fn column_f<const N: usize>(v: &[[f64; N]; 3], c: usize) -> [f64; 3] {
    [v[0][c], v[1][c], v[2][c]]
}

#[inline]
fn unorm(raw: u32, bits: u32) -> f64 {
    f64::from(raw) / f64::from(max_unorm(bits))
}

/// A stage's accumulated `[ops, cycles, texels]` with this pixel's planned footprint-assembly
/// cost (`aniso_probes` probes) replaced by that of the `probes` it took (`aniso_adaptive`).
fn per_pixel_probes(acc: [u64; 3], planned: &UnitCost, m: &Machine, probes: u32) -> [u64; 3] {
    let took = footprint_cost(&m.hw.trilinear, &m.hw.lod, probes);
    [
        acc[0] - u64::from(planned.ops) + u64::from(took.ops),
        acc[1] - u64::from(planned.cycles) + u64::from(took.cycles),
        acc[2] - u64::from(planned.texels) + u64::from(took.texels),
    ]
}

/// Runs `plan` on one fragment at pixel (`px`, `py`) of `tri`, each stage by its twin in
/// `impls`; the result is in `frag.out` (and `frag.out_x` when the last stage was Fixed).
/// A Fixed stage reads the raw value of a Fixed producer and quantizes the carrier of a Float
/// one; `costs` holds the plan's cost per stage kind.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn run(
    plan: &Plan,
    costs: &[UnitCost; StageKind::COUNT],
    impls: &StageImpls,
    m: &Machine,
    tri: &ScreenTri,
    a: &TriAttrs,
    px: i64,
    py: i64,
    frag: &mut Frag,
    c: &mut Counters,
) {
    let samples = if plan.derivatives { 3 } else { 1 };
    let hw = m.hw;
    let cb = hw.color.color_bits;
    let tb = hw.trilinear.texel_bits;
    let bb = hw.interp.bary_bits;
    let fb = m.uv_fmt.frac_bits;
    let lfb = hw.lod.lod_frac_bits;
    let fixed_in = |k: StageKind| impls.of(k) == Impl::Fixed;
    frag.color = plan.const_color;
    frag.out = plan.const_color;
    frag.out_bits = 0;
    let mut color_from_stage = false;
    for &kind in &plan.stages {
        let k = kind.index();
        c.invocations[k] += 1;
        let cost = &costs[k];
        c.cost[k][0] += u64::from(cost.ops);
        c.cost[k][1] += u64::from(cost.cycles);
        c.cost[k][2] += u64::from(cost.texels);
        let fixed = impls.of(kind) == Impl::Fixed;
        let sat = &mut c.sat[k];
        match kind {
            StageKind::Bary => {
                let sub = hw.raster.subpixel_bits;
                if fixed {
                    if plan.derivatives {
                        let (e, dx, dy) = tri.edges_fixed_with_steps(px, py, sub);
                        frag.bary_x = perspective_bary_derivs(
                            e, dx, dy, a.inv_w_x, &hw.interp, &m.recip, sat,
                        );
                    } else {
                        let e = tri.edges_fixed(px, py, sub);
                        frag.bary_x[0] = perspective_bary(e, a.inv_w_x, &hw.interp, &m.recip, sat);
                    }
                    for s in 0..samples {
                        frag.bary[s] = frag.bary_x[s].map(|r| from_raw(r, bb));
                    }
                } else {
                    let (x, y) = (px as f64, py as f64);
                    let e = tri.edges_float(x, y);
                    if plan.derivatives {
                        let ex = tri.edges_float(x + 1.0, y);
                        let ey = tri.edges_float(x, y + 1.0);
                        let dx = [0, 1, 2].map(|i| ex[i] - e[i]);
                        let dy = [0, 1, 2].map(|i| ey[i] - e[i]);
                        frag.bary = perspective_bary_derivs_f64(e, dx, dy, a.inv_w_f);
                    } else {
                        frag.bary[0] = perspective_bary_f64(e, a.inv_w_f);
                    }
                }
            }
            StageKind::Color => {
                color_from_stage = true;
                if fixed {
                    let b = if fixed_in(StageKind::Bary) {
                        frag.bary_x[0]
                    } else {
                        frag.bary[0].map(|x| to_raw(x, &m.bary_fmt, sat))
                    };
                    for ch in 0..3 {
                        let r =
                            interpolate(b, bb, column(&a.color_x, ch), &m.color_fmt, sat) as u32;
                        frag.color_x[ch] = r;
                        frag.color[ch] = unorm(r, cb);
                    }
                    frag.color_x[3] = max_unorm(cb);
                    frag.out_x = frag.color_x;
                    frag.out_bits = cb;
                } else {
                    for ch in 0..3 {
                        frag.color[ch] = interpolate_f64(frag.bary[0], column_f(&a.color_f, ch));
                    }
                    frag.out_bits = 0;
                }
                frag.color[3] = 1.0;
                frag.out = frag.color;
            }
            StageKind::Texcoord => {
                let raw_bary = fixed_in(StageKind::Bary);
                for s in 0..samples {
                    if fixed {
                        let b = if raw_bary {
                            frag.bary_x[s]
                        } else {
                            frag.bary[s].map(|x| to_raw(x, &m.bary_fmt, sat))
                        };
                        for ax in 0..2 {
                            let r = interpolate(b, bb, column(&a.uv_x, ax), &m.uv_fmt, sat);
                            frag.uv_x[s][ax] = r;
                            frag.uv[s][ax] = from_raw(r, fb);
                        }
                    } else {
                        for ax in 0..2 {
                            frag.uv[s][ax] = interpolate_f64(frag.bary[s], column_f(&a.uv_f, ax));
                        }
                    }
                }
            }
            StageKind::Lod => {
                let Some(t) = plan.texture else { continue };
                let Some(l0) = m.tex_float[t].first() else {
                    continue;
                };
                let (w, h) = (l0.width, l0.height);
                if fixed {
                    if !fixed_in(StageKind::Texcoord) {
                        quantize_uv(frag, m, samples, sat);
                    }
                    let d = texel_derivs(&frag.uv_x, w, h);
                    frag.lod_x = lod(d, fb, &hw.lod, sat);
                    frag.lod = from_raw(frag.lod_x, lfb);
                } else {
                    frag.lod = lod_f64(texel_derivs_f64(&frag.uv, w, h));
                }
            }
            StageKind::Trilinear => {
                let Some(t) = plan.texture else { continue };
                let probes = hw.trilinear.aniso_probes;
                let adaptive = hw.trilinear.aniso_adaptive;
                let aniso = probes > 1 && plan.derivatives;
                if fixed {
                    if !fixed_in(StageKind::Texcoord) && !fixed_in(StageKind::Lod) {
                        quantize_uv(frag, m, if aniso { samples } else { 1 }, sat);
                    }
                    let l = if fixed_in(StageKind::Lod) {
                        frag.lod_x
                    } else {
                        to_raw(frag.lod, &m.lod_fmt, sat)
                    };
                    let [u, v] = frag.uv_x[0];
                    let r = if aniso {
                        let levels = &m.tex_fixed[t];
                        let size = levels.first().map_or((1, 1), |l0| (l0.width, l0.height));
                        let fp = footprint(&frag.uv_x, size, fb, probes, adaptive, &hw.lod, sat);
                        if fp.probes != probes {
                            c.cost[k] = per_pixel_probes(c.cost[k], cost, m, fp.probes);
                        }
                        footprint_filter(levels, u, v, fb, &fp, lfb, plan.wrap, &hw.trilinear, None)
                    } else {
                        trilinear(
                            &m.tex_fixed[t],
                            u,
                            v,
                            fb,
                            l,
                            lfb,
                            plan.wrap,
                            &hw.trilinear,
                            None,
                        )
                    };
                    frag.texel_x = r.map(u32::from);
                    frag.texel = frag.texel_x.map(|x| unorm(x, tb));
                    frag.out_x = frag.texel_x;
                    frag.out_bits = tb;
                } else {
                    let [u, v] = frag.uv[0];
                    frag.texel = if aniso {
                        let levels = &m.tex_float[t];
                        let size = levels.first().map_or((1, 1), |l0| (l0.width, l0.height));
                        let fp = footprint_f64(&frag.uv, size, probes, adaptive);
                        if fp.probes != probes {
                            c.cost[k] = per_pixel_probes(c.cost[k], cost, m, fp.probes);
                        }
                        footprint_filter_f64(levels, u, v, &fp, plan.wrap)
                    } else {
                        trilinear_f64(&m.tex_float[t], u, v, frag.lod, plan.wrap)
                    };
                    frag.out_bits = 0;
                }
                frag.out = frag.texel;
            }
            StageKind::Modulate => {
                if fixed {
                    let rnd = hw.color.color_rounding;
                    let col = if color_from_stage && fixed_in(StageKind::Color) {
                        frag.color_x
                    } else {
                        frag.color.map(|x| to_unorm(x, cb))
                    };
                    let tex = if fixed_in(StageKind::Trilinear) {
                        frag.texel_x
                    } else {
                        frag.texel.map(|x| to_unorm(x, tb))
                    };
                    for ch in 0..4 {
                        frag.out_x[ch] = modulate(col[ch], cb, tex[ch], tb, cb, rnd);
                        frag.out[ch] = unorm(frag.out_x[ch], cb);
                    }
                    frag.out_bits = cb;
                } else {
                    for ch in 0..4 {
                        frag.out[ch] = frag.color[ch] * frag.texel[ch];
                    }
                    frag.out_bits = 0;
                }
            }
            StageKind::Normal
            | StageKind::BumpFetch
            | StageKind::Frame
            | StageKind::Perturb
            | StageKind::Phong => run_bump_stage(kind, plan, impls, m, a, frag, c),
            StageKind::AsShade => super::as_stages::run_as_shade(plan, impls, m, frag, c),
            StageKind::RoughFetch | StageKind::RoughShade => {
                super::rough_stages::run_rough_stage(kind, plan, impls, m, frag, c);
            }
            StageKind::NdfFetch | StageKind::NdfShade => {
                super::ndf_stages::run_ndf_stage(kind, plan, impls, m, frag, c);
            }
        }
    }
}

/// Quantizes the float texture coordinates of the first `samples` samples into the machine's
/// format (a Fixed consumer after a Float texcoord stage).
fn quantize_uv(frag: &mut Frag, m: &Machine, samples: usize, sat: &mut SatCounter) {
    for s in 0..samples {
        for ax in 0..2 {
            frag.uv_x[s][ax] = to_raw(frag.uv[s][ax], &m.uv_fmt, sat);
        }
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
#[inline]
#[must_use]
pub fn output16(frag: &Frag) -> [u16; 4] {
    if frag.out_bits == 0 {
        frag.out.map(|v| to_unorm(v, 16) as u16)
    } else {
        frag.out_x
            .map(|v| unorm_convert(v, frag.out_bits, 16, Rounding::HalfEven) as u16)
    }
}
