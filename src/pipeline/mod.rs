//! The per-fragment pipeline: a material's stages, each run Fixed (hw_model) or Float (reference).
//!
//! The planner ([`plan`]) pushes only the stages a material needs, as a fixed-function state
//! vector would enable them: an untextured unlit material has no stage at all, a texture adds
//! texture-coordinate, LOD and trilinear stages, lighting adds the colour interpolator. An absent
//! effect is a stage that was never pushed, so it costs neither simulation time nor cycles.
//!
//! Stages communicate through a [`Frag`] whose signals are `f64` carriers. A Fixed stage converts
//! its inputs to its declared input formats, computes in integers, and writes back the exact
//! value of its fixed result; since every fixed value is exactly representable in `f64`, a chain
//! of Fixed stages is bit-accurate, and a Fixed stage after a Float one sees the float value
//! rounded into its input format (how a mixed run isolates one stage's error). In a program of
//! Fixed stages of the common texturing chain, the span twins pass the barycentrics and texture
//! coordinates in lanes of the run instead of the fragments ([`lanes`]).

pub mod as_shade;
pub mod bary;
pub mod bump;
pub mod bump_fetch;
pub mod clip_f32;
pub mod color;
pub mod coord_f32;
pub mod env;
pub mod env_fetch;
pub mod frame;
pub mod lanes;
pub mod lean;
pub mod lean_fetch;
pub mod lean_shade;
pub mod lobe_fetch;
pub mod lobe_fit;
pub mod lobe_shade;
pub mod lod;
pub mod modulate;
pub mod ndf;
pub mod ndf_fetch;
pub mod ndf_shade;
pub mod normal;
pub mod perturb;
pub mod phong;
pub mod rough;
pub mod rough_fetch;
pub mod rough_shade;
pub mod stages;
pub mod table;
pub mod texcoord;
pub mod toksvig;
pub mod toksvig_fetch;
pub mod toksvig_shade;
pub mod trace;
pub mod trilinear;

pub use table::{Program, Px, StageKind, StageRow, STAGES};

use crate::scene::{FrameKind, MainDirection, Material, WrapMode};
use serde::Serialize;

/// Which twin of a stage runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Impl {
    /// The bit-accurate hw_model unit.
    Fixed,
    /// The exact-math reference.
    Float,
}

/// Which twin each stage kind uses in one run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StageImpls(pub [Impl; StageKind::COUNT]);

impl StageImpls {
    /// Every stage fixed: the hardware.
    pub const FIXED: StageImpls = StageImpls([Impl::Fixed; StageKind::COUNT]);
    /// Every stage float: the reference.
    pub const FLOAT: StageImpls = StageImpls([Impl::Float; StageKind::COUNT]);

    /// The twin used for `kind`.
    #[must_use]
    pub const fn of(&self, kind: StageKind) -> Impl {
        self.0[kind.index()]
    }

    /// Returns a copy with `kind` set to `imp`.
    #[must_use]
    pub fn with(mut self, kind: StageKind, imp: Impl) -> Self {
        self.0[kind.index()] = imp;
        self
    }

    /// True when every stage is of one twin.
    #[must_use]
    pub fn is_all(&self, imp: Impl) -> bool {
        self.0.iter().all(|&i| i == imp)
    }
}

/// The stages one material needs, with what they need to know.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// Stage kinds in execution order.
    pub stages: Vec<StageKind>,
    /// Index of the texture (into the prepared maps), when textured.
    pub texture: Option<usize>,
    /// Colour used when no colour interpolation stage runs (unlit: kd; alpha 1).
    pub const_color: [f64; 4],
    /// Whether the texture-coordinate stage must also produce derivatives (for LOD).
    pub derivatives: bool,
    /// Texture addressing of s and t.
    pub wrap: [WrapMode; 2],
    /// Bump mapping and per-pixel shading, for bump-mapped materials.
    pub bump: Option<BumpPlan>,
    /// Ashikhmin-Shirley shading (with `bump` holding its normal/frame inputs).
    pub aniso: Option<as_shade::AsPlan>,
    /// Roughness map and modified Blinn-Phong (`rough`), for roughness materials.
    pub rough: Option<rough::RoughPlan>,
    /// NDF mapping (with `bump` for the frame), for NDF materials.
    pub ndf: Option<ndf::NdfPlan>,
    /// Environment map (with `bump` for the normal), for materials with `env`.
    pub env: Option<env::EnvPlan>,
    /// Multiple-surface lobes (with `bump` for the frame), for Fournier materials.
    pub lobes: Option<lobe_shade::LobePlan>,
    /// Toksvig's exponent (with `bump`), for `bump_filter = "toksvig"` materials.
    pub toksvig: Option<toksvig::ToksvigPlan>,
    /// LEAN mapping (with `bump`), for `bump_filter = "lean"` materials.
    pub lean: Option<lean::LeanPlan>,
}

/// What the bump stages of one material need.
#[derive(Clone, Debug, PartialEq)]
pub struct BumpPlan {
    /// Index of the offset map in the prepared maps (after the scene's textures).
    pub map: usize,
    /// The material's frame; `None` uses the hardware's `frame_kind`.
    pub frame: Option<FrameKind>,
    /// Main direction of the main frame.
    pub main: MainDirection,
    /// Diffuse and specular colours (0..1) and the specular exponent.
    pub kd: [f64; 3],
    pub ks: [f64; 3],
    pub shininess: u32,
}

impl Plan {
    /// True when the plan contains `kind`.
    #[must_use]
    pub fn has(&self, kind: StageKind) -> bool {
        self.stages.contains(&kind)
    }
}

/// Builds the plan of one material. `has_uvs`: the mesh supplies texture coordinates.
/// (Bump maps need the offset-map index: see [`plan_with_bump`]; here they are ignored.)
#[must_use]
pub fn plan(material: &Material, has_uvs: bool) -> Plan {
    plan_with_bump(material, has_uvs, None)
}

/// Builds the plan of one material whose bump height map (if any) was prepared as offset map
/// `bump_map`. A bump material with texture coordinates runs `bary`, `texcoord` (with
/// derivatives), the diffuse texture's `lod` and `trilinear` when textured, then `normal`,
/// `bump-fetch`, `frame`, `perturb`, `phong`; it is lit per pixel whatever `lit` says.
/// Without UVs or without `bump_map` the material is planned as if it had no bump map.
#[must_use]
pub fn plan_with_bump(material: &Material, has_uvs: bool, bump_map: Option<usize>) -> Plan {
    let textured = material.texture.is_some() && has_uvs;
    if let Some(p) = as_shade::plan_as(material, has_uvs) {
        return p;
    }
    if let Some(p) = lobe_shade::plan_lobes(material, has_uvs) {
        return p;
    }
    if let (Some(map), true, Some(_)) = (bump_map, has_uvs, material.bump) {
        let mut stages = vec![StageKind::Bary, StageKind::Texcoord];
        if textured {
            stages.extend([StageKind::Lod, StageKind::Trilinear]);
        }
        stages.extend([
            StageKind::Normal,
            StageKind::BumpFetch,
            StageKind::Frame,
            StageKind::Perturb,
            StageKind::Phong,
        ]);
        let kd = material.kd.map(f64::from);
        return Plan {
            stages,
            texture: if textured { material.texture } else { None },
            const_color: [kd[0], kd[1], kd[2], 1.0],
            derivatives: true,
            wrap: [material.wrap_s, material.wrap_t],
            bump: Some(BumpPlan {
                map,
                frame: material.frame,
                main: material.main_direction,
                kd,
                ks: material.ks.map(f64::from),
                shininess: material.shininess,
            }),
            aniso: None,
            rough: None,
            ndf: None,
            env: None,
            lobes: None,
            toksvig: None,
            lean: None,
        };
    }
    let mut stages = Vec::with_capacity(6);
    let kd = material.kd.map(f64::from);
    let white = kd.iter().all(|&c| c == 1.0);
    if material.lit || textured {
        stages.push(StageKind::Bary);
    }
    if material.lit {
        stages.push(StageKind::Color);
    }
    if textured {
        stages.extend([StageKind::Texcoord, StageKind::Lod, StageKind::Trilinear]);
        if material.lit || !white {
            stages.push(StageKind::Modulate);
        }
    }
    Plan {
        stages,
        texture: if textured { material.texture } else { None },
        const_color: [kd[0], kd[1], kd[2], 1.0],
        derivatives: textured,
        wrap: [material.wrap_s, material.wrap_t],
        bump: None,
        aniso: None,
        rough: None,
        ndf: None,
        env: None,
        lobes: None,
        toksvig: None,
        lean: None,
    }
}

/// Per-fragment signals passed between stages. Each signal has an `f64` carrier (always
/// written) and, when a Fixed stage produced it, its raw fixed value (`*_x`), which a Fixed
/// consumer reads directly; a Fixed consumer of a Float producer quantizes the carrier.
///
/// Laid out in this order (`repr(C)`): the raw signals of the common stages first, then the
/// colour and output carriers that every run sets and the trace (its count ahead of its
/// footprints), so that a span of those stages touches the first few cache lines of each
/// fragment (W1's fastest frame 2% to 4% shorter than with the compiler's order, stop 58 in
/// `docs/PERFORMANCE_LOG.md`). In a program that keeps the common chain's signals in lanes
/// ([`lanes`]), its span twins pass the barycentrics and texture coordinates there and leave
/// `bary_x` and `uv_x` unwritten.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C)]
pub struct Frag {
    /// Raw barycentrics (`bary_bits` fraction bits).
    pub bary_x: [[i64; 3]; 3],
    /// Raw texture coordinates (`texcoord_frac_bits`).
    pub uv_x: [[i64; 2]; 3],
    /// Raw LOD (`lod_frac_bits`).
    pub lod_x: i64,
    /// Raw texel (`texel_bits` unorm).
    pub texel_x: [u32; 4],
    /// Raw output and its unorm width; `out_bits == 0` means the output is the float carrier.
    pub out_x: [u32; 4],
    pub out_bits: u32,
    /// Raw colour (`color_bits` unorm).
    pub color_x: [u32; 4],
    /// Interpolated colour (unorm, 0..1).
    pub color: [f64; 4],
    /// The fragment's output colour (unorm).
    pub out: [f64; 4],
    /// The texel footprints the stages fetched (recorded only when `trace.on`).
    pub trace: trace::Trace,
    /// Perspective-correct barycentrics at the sample, and at the helper samples (x+1, y) and
    /// (x, y+1) when derivatives are needed.
    pub bary: [[f64; 3]; 3],
    /// Texture coordinates at the sample and the two helper samples (normalized).
    pub uv: [[f64; 2]; 3],
    /// Level of detail (log2 texels per pixel).
    pub lod: f64,
    /// Filtered texel (unorm).
    pub texel: [f64; 4],
    /// Bump stages (vectors in vector format `s1.F` when raw, lengths in len format).
    pub bump: BumpFrag,
    /// Roughness fetch: filtered D channels (unorm) and their raw texels.
    pub rough: [f64; 3],
    pub rough_x: [u32; 3],
    /// NDF stages.
    pub ndf: ndf::NdfFrag,
    /// Toksvig fetch: the filtered Toksvig texel.
    pub toksvig: toksvig::ToksvigFrag,
    /// LEAN fetch: the filtered second-moment texel.
    pub lean: lean::LeanFrag,
    /// Lobe fetch: the fetched lobe texels of a fitted-lobe material.
    pub lobe: lobe_fit::LobeFrag,
}

/// Most point lights shaded per pixel by a bump material (their vectors are interpolated).
pub const MAX_POINT_LIGHTS: usize = 4;

/// Per-fragment signals of the bump stages: carriers and raw values (`*_x`).
#[derive(Clone, Copy, Debug, Default)]
pub struct BumpFrag {
    /// Interpolated normal, directions of `s_u`, `s_v`, main direction.
    pub n_i: [f64; 3],
    pub n_i_x: [i64; 3],
    pub d_u: [f64; 3],
    pub d_u_x: [i64; 3],
    pub d_v: [f64; 3],
    pub d_v_x: [i64; 3],
    pub m: [f64; 3],
    pub m_x: [i64; 3],
    /// Interpolated lengths of `s_u`, `s_v` (natural frame).
    pub len: [f64; 2],
    pub len_x: [i64; 2],
    /// Interpolated (per-triangle scaled) vectors towards the eye and each point light.
    pub to_eye: [f64; 3],
    pub to_eye_x: [i64; 3],
    pub to_light: [[f64; 3]; MAX_POINT_LIGHTS],
    pub to_light_x: [[i64; 3]; MAX_POINT_LIGHTS],
    /// Filtered offset-map channels (unorm) and their raw texels.
    pub texel: [f64; 2],
    pub texel_x: [u32; 2],
    /// The frame: normal, the two tangents, the two lengths.
    pub fr_n: [f64; 3],
    pub fr_n_x: [i64; 3],
    pub fr_t_u: [f64; 3],
    pub fr_t_u_x: [i64; 3],
    pub fr_t_v: [f64; 3],
    pub fr_t_v_x: [i64; 3],
    pub fr_len: [f64; 2],
    pub fr_len_x: [i64; 2],
    /// The perturbed unit normal.
    pub normal: [f64; 3],
    pub normal_x: [i64; 3],
}
