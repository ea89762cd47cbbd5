//! Sphere grids of the Ashikhmin-Shirley paper (Ashikhmin & Shirley 2000, Figs. 2-5): an
//! `N x N` grid of spheres over the exponents (`n_u` per column, `n_v` per row), metallic or
//! plastic, in a furnace (Figs. 2, 4) or under a directional light (Figs. 3, 5), rendered with
//! the float reference and with the fixed-point unit `hw_model::aniso_phong`, plus their
//! difference.
//!
//! Geometry (orthographic, view space: `+x` right, `+y` up, `+z` toward the viewer): sphere
//! `(row, col)` is centred in its `sphere_px x sphere_px` cell with radius
//! `RADIUS_FRAC * sphere_px`; a pixel is sampled at its centre. Inside a disc the normal is the
//! analytic `n = (sx, sy, sqrt(1 - sx^2 - sy^2))`; the view direction is `+z`; outside every
//! disc the pixel is black (opaque). Column `j` has `n_u = exponents[j]` (left to right), row `i`
//! has `n_v = exponents[i]` (top to bottom).
//!
//! Shading frame: Schilling's main-direction frame (as `hw_model::frame`, frame 3):
//! `u = e1 = m x n / |m x n|`, `v = e2 = n x e1`. Where `m` is parallel to `n` (the two poles,
//! `|m^ x n|^2 < 1e-12`) `m` is replaced by the coordinate axis least aligned with `n`
//! (smallest `|n_i|`, lowest index on ties); the frame jumps there, as it must.
//!
//! Radiance:
//! - Light: a directional light of radiance-scaled irradiance `pi` (so a white Lambertian
//!   surface facing it shows 1.0): `L = pi rho(k1 = l, k2 = view) (n.l)`. Float: the reference
//!   [`AshikhminShirley::eval`]. Fixed: the unit's `pi rho` from the quantized dot products
//!   times the quantized `n.l` the unit saw (an exact product).
//! - Furnace: an environment of radiance 1, so by reciprocity `L = R(view)`, the directional
//!   albedo (eq. 6) for the view direction. Float and fixed use the SAME quadrature
//!   ([`AshikhminShirley::albedo_quadrature_with`] at `furnace_res`), so their difference is
//!   arithmetic only; its accuracy against the exact albedo is the quadrature's. At the
//!   default [`FURNACE_RES`] = 3, measured over every pixel of the paper's grids (32 px
//!   spheres, exponents 1..1e4, metal and plastic, view directions up to 88.4 degrees from the
//!   normal at the outermost pixels) against res 32: < 7e-3 (1.8 LSB of 8 bits), worst 6.1e-3
//!   (metal, `n_u = n_v = 1`, 88.4 degrees) and 5.5e-3 (plastic), both on the outermost ring;
//!   below 60 degrees 1.6e-3 (metal) and 1.5e-4 (plastic). `tests/shading/brdf_spheres.rs`
//!   (`furnace_res3_accuracy_including_grazing_pixels`) asserts it on the grazing and diagonal
//!   pixels. Res 6: < 5e-3, worst only within ~1 deg of grazing with exponents <= 1.
//!
//! Tone mapping: clamp to `[0, 1]`, then `round(65535 x)` in every RGB channel (grey).

// `!(x > 0.0)` is used on purpose: it is true for NaN, which must take the guarded path.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::ashikhmin_shirley::{AshikhminShirley, Dots};
use super::fixed_twin::{check_params, pf_to_f64, quantize};
use crate::error::{Error, Result};
use crate::report::{
    compare, encode_pixmap, encode_png8, heatmap, image_to_pixmap, sheet, ErrorMetrics, Image,
    OutputSet,
};
use glam::DVec3;
use hw_model::aniso_phong::{aniso_phong_prepared, AnisoPhongConfig, AnisoPhongRoms};
use hw_model::SatCounter;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::fmt::Write;

/// Sphere radius as a fraction of its cell (a small black gap separates the spheres).
pub const RADIUS_FRAC: f64 = 0.46;
/// Default furnace quadrature resolution (`64 res^2` BRDF evaluations per pixel and image);
/// its error against the exact albedo is < 7e-3 on the paper's grids (module doc).
pub const FURNACE_RES: usize = 3;
/// Largest accepted `sphere_px`.
pub const MAX_SPHERE_PX: u32 = 1024;
/// Largest accepted number of exponents (grid side).
pub const MAX_GRID: usize = 16;
/// Largest accepted image side in pixels.
pub const MAX_IMAGE_PX: u32 = 4096;
/// Largest accepted furnace quadrature resolution.
pub const MAX_FURNACE_RES: usize = 64;
/// Pole threshold of the main-direction frame: `|m^ x n|^2` below this uses the fallback axis.
pub const POLE_EPS: f64 = 1.0e-12;

/// Material of every sphere in a grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// Metal (Figs. 2, 3): `Rs = 1`, `Rd = 0` (specular only, grey).
    Metal,
    /// Plastic (Figs. 4, 5): `Rs = 0.05`, `Rd = 1` (grey instead of the paper's red).
    Plastic,
    /// Any `Rs`, `Rd` in `[0, 1]`.
    Custom {
        /// Specular reflectance at normal incidence.
        rs: f64,
        /// Diffuse albedo.
        rd: f64,
    },
}

impl Material {
    /// `(Rs, Rd)`.
    #[must_use]
    pub fn rs_rd(&self) -> (f64, f64) {
        match *self {
            Material::Metal => (1.0, 0.0),
            Material::Plastic => (0.05, 1.0),
            Material::Custom { rs, rd } => (rs, rd),
        }
    }

    /// Short name: `metal`, `plastic` or `custom`.
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            Material::Metal => "metal",
            Material::Plastic => "plastic",
            Material::Custom { .. } => "custom",
        }
    }
}

/// Illumination of a grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Lighting {
    /// Uniform environment of radiance 1 (the pixel is the directional albedo).
    Furnace,
    /// Directional light; `dir` points toward the light in view space (normalized here).
    Light {
        /// Direction toward the light.
        dir: [f64; 3],
    },
}

/// One sphere grid (see the module docs for geometry, frame and radiance).
#[derive(Clone, Debug, PartialEq)]
pub struct GridSpec {
    /// Exponents of both axes: `n_u` per column, `n_v` per row (integers the unit accepts).
    pub exponents: Vec<f64>,
    /// Cell size of one sphere in pixels.
    pub sphere_px: u32,
    /// Material of every sphere.
    pub material: Material,
    /// Furnace or light.
    pub lighting: Lighting,
    /// Main direction `m` of the anisotropy frame (`u = m x n / |m x n|`), view space.
    pub main_direction: [f64; 3],
    /// Furnace quadrature resolution (`64 res^2` evaluations per pixel); unused under a light.
    pub furnace_res: usize,
}

/// The paper's exponents `1, 10, 100, 1000, 10000`.
pub const PAPER_EXPONENTS: [f64; 5] = [1.0, 10.0, 100.0, 1000.0, 10000.0];
/// Default light direction (toward the light: upper left, in front).
pub const DEFAULT_LIGHT: [f64; 3] = [-0.5, 0.5, 1.0];
/// Default main direction: view-space up, so `u` runs along the latitude circles (horizontal at
/// the sphere centre) and `v` along the meridians.
pub const DEFAULT_MAIN_DIRECTION: [f64; 3] = [0.0, 1.0, 0.0];

impl GridSpec {
    /// The paper's 5 x 5 grid at `sphere_px` pixels per sphere with the default main direction
    /// and furnace resolution.
    #[must_use]
    pub fn paper(material: Material, lighting: Lighting, sphere_px: u32) -> Self {
        Self {
            exponents: PAPER_EXPONENTS.to_vec(),
            sphere_px,
            material,
            lighting,
            main_direction: DEFAULT_MAIN_DIRECTION,
            furnace_res: FURNACE_RES,
        }
    }

    /// `<material>_<furnace|light>`, e.g. `metal_light`.
    #[must_use]
    pub fn name(&self) -> String {
        let l = match self.lighting {
            Lighting::Furnace => "furnace",
            Lighting::Light { .. } => "light",
        };
        format!("{}_{l}", self.material.name())
    }

    /// Image side in pixels.
    #[must_use]
    pub fn image_px(&self) -> u32 {
        (self.exponents.len() as u32).saturating_mul(self.sphere_px)
    }
}

/// Statistics of a rendered grid.
#[derive(Clone, Debug)]
pub struct GridStats {
    /// Saturations counted by the fixed unit over all evaluations.
    pub fixed_saturated: u64,
    /// Pixels whose float radiance exceeded 1 (clipped by the tone map).
    pub float_clipped: u64,
    /// Pixels whose fixed radiance exceeded 1.
    pub fixed_clipped: u64,
    /// Largest `|float - fixed|` after the clamp to `[0, 1]` (linear).
    pub max_abs_linear: f64,
    /// Error metrics float vs fixed in 8-bit LSBs (what the PNGs show).
    pub metrics8: ErrorMetrics,
    /// Largest 8-bit LSB error per sphere, row-major (`row * N + col`).
    pub per_sphere_max_lsb8: Vec<u32>,
    /// Largest `|float - fixed|` per sphere after the clamp (linear), row-major.
    pub per_sphere_max_linear: Vec<f64>,
}

/// The float and fixed renders of a grid with their statistics.
#[derive(Clone, Debug)]
pub struct GridImages {
    /// Float reference, tone-mapped.
    pub float: Image,
    /// Fixed unit, tone-mapped.
    pub fixed: Image,
    /// Float radiance before tone mapping, row-major (0 on the background).
    pub float_linear: Vec<f64>,
    /// Fixed radiance before tone mapping, row-major (0 on the background).
    pub fixed_linear: Vec<f64>,
    /// Comparison figures.
    pub stats: GridStats,
}

/// Where a pixel lands: its sphere `(row, col)` and the analytic unit normal (view space), or
/// `None` on the background. `x`, `y` are pixel indices (top row first).
#[must_use]
pub fn pixel_normal(spec: &GridSpec, x: u32, y: u32) -> Option<(usize, usize, DVec3)> {
    let px = spec.sphere_px;
    if px == 0 {
        return None;
    }
    let n = spec.exponents.len();
    let (col, row) = ((x / px) as usize, (y / px) as usize);
    if col >= n || row >= n {
        return None;
    }
    let c = 0.5 * f64::from(px);
    let r = RADIUS_FRAC * f64::from(px);
    let sx = (f64::from(x % px) + 0.5 - c) / r;
    let sy = -(f64::from(y % px) + 0.5 - c) / r;
    let q = sx * sx + sy * sy;
    if !(q < 1.0) {
        return None;
    }
    Some((row, col, DVec3::new(sx, sy, (1.0 - q).sqrt())))
}

/// The main-direction frame `(u, v)` at unit normal `n` for unit main direction `m` (see the
/// module docs for the pole fallback).
#[must_use]
pub fn main_direction_frame(m: DVec3, n: DVec3) -> (DVec3, DVec3) {
    let mut c = m.cross(n);
    if !(c.length_squared() >= POLE_EPS) {
        let a = n.abs();
        let axis = if a.x <= a.y && a.x <= a.z {
            DVec3::X
        } else if a.y <= a.z {
            DVec3::Y
        } else {
            DVec3::Z
        };
        c = axis.cross(n);
    }
    let u = c.normalize();
    (u, n.cross(u))
}

/// A non-zero finite direction, normalized; the error names `field`.
fn unit(field: &str, v: [f64; 3]) -> Result<DVec3> {
    let d = DVec3::from_array(v);
    let len = d.length();
    if !d.is_finite() || !(len > 1.0e-12) || !len.is_finite() {
        return Err(Error::field(
            field,
            format!("{d} is not a non-zero finite direction"),
        ));
    }
    Ok(d / len)
}

/// Validates a spec and returns its per-sphere materials (row-major), main direction and light.
fn prepare(
    spec: &GridSpec,
    cfg: &AnisoPhongConfig,
) -> Result<(Vec<AshikhminShirley>, DVec3, Option<DVec3>)> {
    let n = spec.exponents.len();
    if n == 0 || n > MAX_GRID {
        return Err(Error::field(
            "exponents",
            format!("{n} exponents; expected 1..={MAX_GRID}"),
        ));
    }
    if !(1..=MAX_SPHERE_PX).contains(&spec.sphere_px) {
        return Err(Error::field(
            "sphere_px",
            format!("{} is not in 1..={MAX_SPHERE_PX}", spec.sphere_px),
        ));
    }
    if u64::from(spec.sphere_px) * n as u64 > u64::from(MAX_IMAGE_PX) {
        return Err(Error::field(
            "sphere_px",
            format!(
                "{} x {n} spheres exceeds the {MAX_IMAGE_PX}-pixel image limit",
                spec.sphere_px
            ),
        ));
    }
    if matches!(spec.lighting, Lighting::Furnace)
        && !(1..=MAX_FURNACE_RES).contains(&spec.furnace_res)
    {
        return Err(Error::field(
            "furnace_res",
            format!("{} is not in 1..={MAX_FURNACE_RES}", spec.furnace_res),
        ));
    }
    let (rs, rd) = spec.material.rs_rd();
    let mut mats = Vec::with_capacity(n * n);
    for &nv in &spec.exponents {
        for &nu in &spec.exponents {
            let p = AshikhminShirley::new(nu, nv, rs, rd)?;
            check_params(&p, cfg).map_err(|e| e.context("exponents"))?;
            mats.push(p);
        }
    }
    let m = unit("main_direction", spec.main_direction)?;
    let light = match spec.lighting {
        Lighting::Furnace => None,
        Lighting::Light { dir } => Some(unit("light dir", dir)?),
    };
    Ok((mats, m, light))
}

/// Per-grid constants of the pixel shader.
struct Shading<'a> {
    m: DVec3,
    light: Option<DVec3>,
    res: usize,
    cfg: &'a AnisoPhongConfig,
    roms: &'a AnisoPhongRoms,
}

/// Float and fixed radiance of one pixel with normal `n` (view space) and saturation count.
fn shade(p: &AshikhminShirley, n: DVec3, sh: &Shading<'_>, sat: &mut SatCounter) -> (f64, f64) {
    let Shading {
        m,
        light,
        res,
        cfg,
        roms,
    } = *sh;
    let (u, v) = main_direction_frame(m, n);
    let local = |w: DVec3| DVec3::new(w.dot(u), w.dot(v), w.dot(n));
    let k_view = local(DVec3::Z);
    let dq = 1.0 / (1u64 << cfg.aniso_dot_frac_bits) as f64;
    match light {
        Some(l) => {
            let k1 = local(l);
            let float = PI * p.eval(k1, k_view) * k1.z.max(0.0);
            let fixed = match Dots::from_dirs(k1, k_view) {
                Some(d) => {
                    let inp = quantize(p, &d, cfg);
                    let out = aniso_phong_prepared(&inp, roms, sat);
                    pf_to_f64(out.total) * (f64::from(inp.nk1) * dq).max(0.0)
                }
                None => 0.0,
            };
            (float, fixed)
        }
        None => {
            let float = p.albedo_quadrature(k_view, res);
            let fixed_unit = |k: DVec3, sat: &mut SatCounter, diffuse: bool| -> f64 {
                // The unit with the view as its k1 (reciprocity), as `fixed_twin::albedo_fixed`.
                match Dots::from_dirs(k_view, k) {
                    Some(d) => {
                        let out = aniso_phong_prepared(&quantize(p, &d, cfg), roms, sat);
                        let part = if diffuse { out.diffuse } else { out.spec };
                        pf_to_f64(part) / PI
                    }
                    None => 0.0,
                }
            };
            let mut sat_d = SatCounter::default();
            let (s, d) = p.albedo_quadrature_with(
                k_view,
                res,
                &mut |k| fixed_unit(k, sat, false),
                &mut |k| fixed_unit(k, &mut sat_d, true),
            );
            sat.add(&sat_d);
            (float, s + d)
        }
    }
}

/// Tone map: clamp to `[0, 1]`, `round(65535 x)`, grey, opaque.
#[must_use]
fn to_px(x: f64) -> [u16; 4] {
    let c = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
    let g = (c * 65535.0).round() as u16;
    [g, g, g, u16::MAX]
}

/// Renders a grid with the float reference and the fixed unit `cfg` (see the module docs).
/// Errors name the bad field (exponents the unit cannot take, zero directions, sizes).
pub fn render_grid(spec: &GridSpec, cfg: &AnisoPhongConfig) -> Result<GridImages> {
    let (mats, m, light) = prepare(spec, cfg)?;
    let roms = AnisoPhongRoms::new(cfg);
    let side = spec.image_px();
    let w = side as usize;
    let n = spec.exponents.len();
    let sh = Shading {
        m,
        light,
        res: spec.furnace_res,
        cfg,
        roms: &roms,
    };
    let mut float_linear = vec![0.0; w * w];
    let mut fixed_linear = vec![0.0; w * w];
    let sats: Vec<SatCounter> = float_linear
        .par_chunks_mut(w)
        .zip(fixed_linear.par_chunks_mut(w))
        .enumerate()
        .map(|(y, (frow, xrow))| {
            let mut sat = SatCounter::default();
            for x in 0..w {
                if let Some((row, col, nrm)) = pixel_normal(spec, x as u32, y as u32) {
                    let p = &mats[row * n + col];
                    let (f, q) = shade(p, nrm, &sh, &mut sat);
                    frow[x] = f;
                    xrow[x] = q;
                }
            }
            sat
        })
        .collect();
    let mut fixed_saturated = 0u64;
    for s in &sats {
        fixed_saturated = fixed_saturated.saturating_add(s.saturated);
    }
    let float = Image {
        width: side,
        height: side,
        px: float_linear.iter().map(|&x| to_px(x)).collect(),
    };
    let fixed = Image {
        width: side,
        height: side,
        px: fixed_linear.iter().map(|&x| to_px(x)).collect(),
    };
    let metrics8 = compare(&float, &fixed, 8, None);
    let mut per_sphere_max_lsb8 = vec![0u32; n * n];
    let mut per_sphere_max_linear = vec![0.0f64; n * n];
    let mut max_abs_linear = 0.0f64;
    let (mut float_clipped, mut fixed_clipped) = (0u64, 0u64);
    for y in 0..side {
        for x in 0..side {
            let i = y as usize * w + x as usize;
            let (a, b) = (float_linear[i], fixed_linear[i]);
            float_clipped += u64::from(a > 1.0);
            fixed_clipped += u64::from(b > 1.0);
            let Some((row, col, _)) = pixel_normal(spec, x, y) else {
                continue;
            };
            let k = row * n + col;
            let d = (a.clamp(0.0, 1.0) - b.clamp(0.0, 1.0)).abs();
            let e = crate::report::quantize(float.px[i][0], 8)
                .abs_diff(crate::report::quantize(fixed.px[i][0], 8));
            per_sphere_max_lsb8[k] = per_sphere_max_lsb8[k].max(e);
            per_sphere_max_linear[k] = per_sphere_max_linear[k].max(d);
            max_abs_linear = max_abs_linear.max(d);
        }
    }
    Ok(GridImages {
        float,
        fixed,
        float_linear,
        fixed_linear,
        stats: GridStats {
            fixed_saturated,
            float_clipped,
            fixed_clipped,
            max_abs_linear,
            metrics8,
            per_sphere_max_lsb8,
            per_sphere_max_linear,
        },
    })
}

/// A text summary of a rendered grid: the spec, the error figures in 8-bit LSBs, clipping and
/// saturation counts, and the per-sphere max error table (rows `n_v`, columns `n_u`).
#[must_use]
pub fn grid_summary(name: &str, spec: &GridSpec, g: &GridImages) -> String {
    let (rs, rd) = spec.material.rs_rd();
    let s = &g.stats;
    let mut t = String::new();
    let light = match spec.lighting {
        Lighting::Furnace => format!("furnace (radiance 1, quadrature res {})", spec.furnace_res),
        Lighting::Light { dir } => format!("light toward {dir:?} (irradiance pi)"),
    };
    let _ = writeln!(
        t,
        "{name}: {n}x{n} spheres at {px} px, Rs={rs} Rd={rd}, {light}, main direction {m:?}",
        n = spec.exponents.len(),
        px = spec.sphere_px,
        m = spec.main_direction
    );
    let _ = writeln!(
        t,
        "float vs fixed (8-bit LSB): max {} mean {:.4} exact {:.2}% within 1 LSB {:.2}%; max |linear| {:.3e}",
        s.metrics8.max_abs_lsb,
        s.metrics8.mean_abs_lsb,
        s.metrics8.pct_exact,
        s.metrics8.pct_within_1lsb,
        s.max_abs_linear
    );
    let _ = writeln!(
        t,
        "clipped to 1: float {} px, fixed {} px; fixed unit saturations {}",
        s.float_clipped, s.fixed_clipped, s.fixed_saturated
    );
    let _ = write!(
        t,
        "max 8-bit LSB error per sphere (rows n_v, columns n_u):\n{:>8}",
        "nv\\nu"
    );
    for e in &spec.exponents {
        let _ = write!(t, " {e:>7}");
    }
    let n = spec.exponents.len();
    for (r, e) in spec.exponents.iter().enumerate() {
        let _ = write!(t, "\n{e:>8}");
        for c in 0..n {
            let _ = write!(t, " {:>7}", s.per_sphere_max_lsb8[r * n + c]);
        }
    }
    t.push('\n');
    t
}

/// Renders a grid and encodes `<name>_float.png`, `<name>_fixed.png`, `<name>_error.png` (8-bit
/// LSB heatmap), `<name>_sheet.png` (float | fixed | error) and `<name>_summary.txt`
/// ([`grid_summary`]). Writes nothing; returns the set and the summary text.
pub fn grid_outputs(
    name: &str,
    spec: &GridSpec,
    cfg: &AnisoPhongConfig,
) -> Result<(OutputSet, String)> {
    let mut out = OutputSet::new();
    let summary = add_grid_outputs(&mut out, name, spec, cfg)?;
    Ok((out, summary))
}

/// [`grid_outputs`] adding into an existing set; returns the summary.
pub fn add_grid_outputs(
    out: &mut OutputSet,
    name: &str,
    spec: &GridSpec,
    cfg: &AnisoPhongConfig,
) -> Result<String> {
    let g = render_grid(spec, cfg)?;
    let heat = heatmap(&g.float, &g.fixed, 8, None);
    let pf = image_to_pixmap(&g.float);
    let px = image_to_pixmap(&g.fixed);
    let sh = sheet(&[("FLOAT", &pf), ("FIXED", &px), ("ERROR (LSB)", &heat)]);
    let summary = grid_summary(name, spec, &g);
    out.add(&format!("{name}_float.png"), encode_png8(&g.float)?);
    out.add(&format!("{name}_fixed.png"), encode_png8(&g.fixed)?);
    out.add(&format!("{name}_error.png"), encode_pixmap(&heat)?);
    out.add(&format!("{name}_sheet.png"), encode_pixmap(&sh)?);
    out.add(&format!("{name}_summary.txt"), summary.clone().into_bytes());
    Ok(summary)
}

/// Default cell size of [`paper_grids`].
pub const PAPER_SPHERE_PX: u32 = 32;

/// The paper's four grids, 5 x 5 over `1..10000` at [`PAPER_SPHERE_PX`]: `metal_furnace`
/// (Fig. 2), `metal_light` (Fig. 3), `plastic_furnace` (Fig. 4), `plastic_light` (Fig. 5).
#[must_use]
pub fn paper_grids() -> Vec<(String, GridSpec)> {
    let light = Lighting::Light { dir: DEFAULT_LIGHT };
    [
        (Material::Metal, Lighting::Furnace),
        (Material::Metal, light),
        (Material::Plastic, Lighting::Furnace),
        (Material::Plastic, light),
    ]
    .into_iter()
    .map(|(m, l)| {
        let s = GridSpec::paper(m, l, PAPER_SPHERE_PX);
        (s.name(), s)
    })
    .collect()
}

/// All of [`paper_grids`] into one set, with the summaries concatenated.
pub fn paper_outputs(cfg: &AnisoPhongConfig) -> Result<(OutputSet, String)> {
    let mut all = OutputSet::new();
    let mut text = String::new();
    for (name, spec) in paper_grids() {
        text.push_str(&add_grid_outputs(&mut all, &name, &spec, cfg)?);
    }
    Ok((all, text))
}

/// Fixed-point cost of a grid: unit evaluations per covered pixel (1 under a light; the
/// furnace quadrature's `64 res^2` specular and `4 res` diffuse evaluations), their ops and
/// cycles from `hw_model::aniso_phong::aniso_phong_cost`, and the per-sphere setup
/// (`aniso_phong_material_cost`, once per sphere).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridCost {
    /// Unit evaluations per covered pixel.
    pub evals_per_px: u64,
    /// Cycles per covered pixel.
    pub cycles_per_px: u64,
    /// Ops per covered pixel.
    pub ops_per_px: u64,
    /// Covered pixels (inside a sphere).
    pub covered_px: u64,
    /// Total cycles: pixels plus the per-sphere setups.
    pub total_cycles: u64,
}

/// The cost of rendering `spec` on the unit `cfg` (see [`GridCost`]).
#[must_use]
pub fn grid_cost(spec: &GridSpec, cfg: &AnisoPhongConfig, gate_levels_per_cycle: u32) -> GridCost {
    let unit = hw_model::aniso_phong::aniso_phong_cost(cfg, gate_levels_per_cycle);
    let setup = hw_model::aniso_phong::aniso_phong_material_cost(cfg, gate_levels_per_cycle);
    let evals = match spec.lighting {
        Lighting::Light { .. } => 1,
        Lighting::Furnace => {
            let r = spec.furnace_res as u64;
            64 * r * r + 4 * r
        }
    };
    let side = spec.image_px();
    let mut covered = 0u64;
    for y in 0..side {
        for x in 0..side {
            covered += u64::from(pixel_normal(spec, x, y).is_some());
        }
    }
    let cycles_per_px = evals * u64::from(unit.cycles);
    let spheres = (spec.exponents.len() * spec.exponents.len()) as u64;
    GridCost {
        evals_per_px: evals,
        cycles_per_px,
        ops_per_px: evals * u64::from(unit.ops),
        covered_px: covered,
        total_cycles: covered * cycles_per_px + spheres * u64::from(setup.cycles),
    }
}

/// One line describing [`grid_cost`].
#[must_use]
pub fn cost_line(name: &str, c: &GridCost) -> String {
    format!(
        "{name} cost: {} unit evaluation(s)/px, {} ops/px, {} cycles/px over {} covered px; {} cycles total (with per-sphere setup)\n",
        c.evals_per_px, c.ops_per_px, c.cycles_per_px, c.covered_px, c.total_cycles
    )
}

/// The four paper grids (metal/plastic x furnace/light) at `sphere_px` per sphere over
/// `exponents`, furnace resolution `furnace_res`: images ([`add_grid_outputs`]) plus a text
/// report with error and cost per grid (`texsim brdf spheres`); cycles at
/// `gate_levels_per_cycle`.
pub fn spheres_report(
    cfg: &AnisoPhongConfig,
    gate_levels_per_cycle: u32,
    exponents: &[f64],
    sphere_px: u32,
    furnace_res: usize,
) -> Result<(OutputSet, String)> {
    let mut all = OutputSet::new();
    let mut text = String::new();
    for (name, mut spec) in paper_grids() {
        spec.exponents = exponents.to_vec();
        spec.sphere_px = sphere_px;
        spec.furnace_res = furnace_res;
        text.push_str(&add_grid_outputs(&mut all, &name, &spec, cfg)?);
        text.push_str(&cost_line(
            &name,
            &grid_cost(&spec, cfg, gate_levels_per_cycle),
        ));
    }
    Ok((all, text))
}
