//! `as-shade`: the Ashikhmin-Shirley shading stage (Ashikhmin & Shirley 2000, "An Anisotropic
//! Phong Light Reflection Model": specular eq. 10/18 with Schlick's Fresnel eq. 11, diffuse
//! eq. 16), fixed (`hw_model::aniso_phong`) and float ([`AshikhminShirley::eval_from_dots`]).
//!
//! An AS material runs `bary` (+ `texcoord`, `lod`, `trilinear` when textured), `normal`,
//! (`bump-fetch` of its exponent map, when it has one), `frame` and `as-shade`: the bump
//! stages' interpolation and Schilling's main-direction frame
//! (frame 3: `n`, `e1 = m x n / |m x n|`, `e2 = n x e1`; the axes `u = t_u`, `v = t_v` of
//! `hw_model::frame::main_frame`: `u = -e1`, `v = -e2` for a constant `m` or `m = p_v`,
//! `u = -e2`, `v = e1` for `m = p_u` (the axis along `m` negated on mirrored texture
//! coordinates; only squares of `h.u`, `h.v` enter), so `u` follows the texture's u direction)
//! supply the anisotropy axes, so one main direction gives brushed metal on any mesh. Per light `k1 = l`, with `k2` the
//! direction to the eye:
//!
//! `L = pi (rho_s + kd rho_d) (n.l) E_light` per channel (`E = pi` times the light colour, so a
//! white Lambertian surface facing a unit light shows its colour), plus `ambient kd R_d`.
//! `kd` (times the texture when textured) tints the diffuse term only.
//!
//! Exponent map: `bump-fetch` filters it (LOD + trilinear, like an offset map) and
//! `n_u = t_0 nu`, `n_v = t_1 nv` per pixel; the fixed twin rounds them to integers
//! (`round(t_raw nu / (2^texel_bits - 1))`, the unit takes integer exponents), the float twin
//! keeps them continuous.
//!
//! Fixed twin (integers only): `h = normalize(l + v)` by the vector unit; the six dot products
//! `h.n, h.u, h.v, k.h, n.k1, n.k2` exact from the vector-format operands, rounded once to
//! `aniso_dot_frac_bits`; the unit gives `pi rho_s`, `pi rho_d` as pseudo-floats; each term of
//! `L` is one exact integer product, aligned with [`GUARD`] guard bits, summed over the lights
//! and rounded once to `shade_color_bits` unorm (saturating, counted). `kd`, the light colour
//! and the ambient are `shade_color_bits` unorms whose scale `2^bits - 1` is taken as `2^bits`
//! in the diffuse and ambient products (at most 1 LSB; the Blinn-Phong unit divides by
//! `2^bits - 1` exactly).
//! `l + v = 0` (`k1 = -k2`) gives no contribution and is counted in `h_zero`.

use super::bump::{fixed_eye, fixed_light, float_eye, float_light, float_output};
use super::stages::{Counters, Machine};
use super::{BumpPlan, Frag, Impl, Plan, Px, StageImpls, StageKind};
use crate::brdf::{AshikhminShirley, Dots};
use crate::fixedpoint::{to_raw, to_unorm};
use crate::scene::{FrameKind, Material};
use glam::DVec3;
use hw_model::aniso_phong::{
    aniso_phong_cost, aniso_phong_prepared, AnisoPhongInputs, AnisoPhongRoms, PseudoFloat,
};
use hw_model::fixed::{round_shift_right_wide, Format, SatCounter};
use hw_model::modulate::modulate;
use hw_model::rsqrt::rsqrt_cost;
use hw_model::vector::{dot3_exact, dot_cost, normalize3, normalize_cost, Vec3x};
use hw_model::UnitCost;
use std::f64::consts::PI;

/// Guard fraction bits of the fixed radiance accumulator (below the output LSB).
pub const GUARD: u32 = 24;

/// What the `as-shade` stage of one material needs.
#[derive(Clone, Debug, PartialEq)]
pub struct AsPlan {
    /// The BRDF parameters (float; the fixed twin quantizes them into the unit's formats).
    pub brdf: AshikhminShirley,
    /// Diffuse tint (0..1 per channel).
    pub kd: [f64; 3],
    /// The exponents are scaled per pixel by the exponent map (`BumpPlan::map`, fetched by
    /// `bump-fetch`).
    pub exponent_map: bool,
}

/// The plan of an Ashikhmin-Shirley material (`None` for other materials): `bary`, the
/// texture stages when textured, `normal`, `bump-fetch` of the exponent map, `frame` (always
/// the main-direction frame, with the material's main direction) and `as-shade`. Without
/// texture coordinates (`has_uvs` false) the texture and the exponent map are not used; a bump
/// map of the material is never used.
#[must_use]
pub fn plan_as(material: &Material, has_uvs: bool) -> Option<Plan> {
    let b = material.brdf?;
    let textured = material.texture.is_some() && has_uvs;
    let emap = b.exponent_map.filter(|_| has_uvs);
    let mut stages = vec![StageKind::Bary];
    if textured || emap.is_some() {
        stages.push(StageKind::Texcoord);
    }
    if textured {
        stages.extend([StageKind::Lod, StageKind::Trilinear]);
    }
    stages.push(StageKind::Normal);
    if emap.is_some() {
        stages.push(StageKind::BumpFetch);
    }
    stages.extend([StageKind::Frame, StageKind::AsShade]);
    let kd = material.kd.map(f64::from);
    Some(Plan {
        stages,
        texture: if textured { material.texture } else { None },
        const_color: [kd[0], kd[1], kd[2], 1.0],
        derivatives: textured || emap.is_some(),
        wrap: [material.wrap_s, material.wrap_t],
        bump: Some(BumpPlan {
            map: emap.unwrap_or(usize::MAX),
            frame: Some(FrameKind::Main),
            main: material.main_direction,
            kd,
            ks: [0.0; 3],
            shininess: 0,
        }),
        aniso: Some(AsPlan {
            brdf: AshikhminShirley {
                nu: b.nu,
                nv: b.nv,
                rs: b.rs,
                rd: b.rd,
            },
            kd,
            exponent_map: emap.is_some(),
        }),
        rough: None,
        ndf: None,
        env: None,
        lobes: None,
        toksvig: None,
        lean: None,
    })
}

impl Machine<'_> {
    /// The anisotropic Phong ROMs of this machine's `aniso_phong` config (built once).
    #[must_use]
    pub fn aniso_roms(&self) -> &AnisoPhongRoms {
        self.aniso_roms
            .get_or_init(|| AnisoPhongRoms::new(&self.hw.aniso_phong))
    }
}

/// Cost of one `as-shade` invocation: the eye and point-light normalizations, then per light
/// the half-vector add and normalize, six dot products, one `aniso_phong` evaluation and the
/// colour multiply-adds; the ambient (and texture) multiply-adds. The per-material square root
/// (`aniso_phong_material_cost`) is a constant loaded with the material, not a per-pixel cost.
#[must_use]
pub fn cost(m: &Machine, plan: &Plan) -> UnitCost {
    let u = &m.units;
    let g = m.hw.timing.gate_levels_per_cycle;
    let nz = normalize_cost(&u.cfg.vector, rsqrt_cost(&u.cfg.rsqrt, g), g);
    let np = super::bump::point_lights(m) as u32;
    let lights = m.lights.len() as u32;
    let mac = hw_model::blinn_phong::mac_cost(&u.cfg, g);
    let add = UnitCost {
        ops: 3,
        cycles: hw_model::blinn_phong::half_vector_datapath(&u.cfg).latency(g),
        texels: 0,
    };
    let per_light = add
        .plus(nz)
        .plus(dot_cost(&u.cfg.vector, g).times(6))
        .plus(aniso_phong_cost(&m.hw.aniso_phong, g))
        .plus(mac.times(2));
    let mut c = nz.times(1 + np).plus(per_light.times(lights)).plus(mac);
    if plan.texture.is_some() {
        c = c.plus(mac);
    }
    c
}

/// Exact dot product of two vector-format unit vectors (`2F` fraction bits) rounded once to
/// `fmt` and clamped to `[-1, 1]` (the operands' rounding can exceed 1 by an ulp).
#[inline]
fn dot_to(a: &Vec3x, b: &Vec3x, f: u32, fmt: &Format) -> i32 {
    let e = dot3_exact(a, b);
    let d = fmt.frac_bits;
    let r = if 2 * f >= d {
        round_shift_right_wide(e, 2 * f - d, fmt.rounding)
    } else {
        i64::try_from(e << (d - 2 * f)).unwrap_or(i64::MAX)
    };
    let one = 1i64 << d;
    r.clamp(-one, one) as i32
}

/// `prod * 2^exp` with [`GUARD`] guard fraction bits (rounded by `fmt`'s rule), saturating
/// far above any displayable value.
#[inline]
fn guarded(prod: u128, exp: i32, fmt: &Format) -> i128 {
    const CAP: i128 = 1 << 100;
    let s = exp + GUARD as i32;
    if prod == 0 {
        return 0;
    }
    if s >= 0 {
        let s = s as u32;
        if s >= 100 || prod >= (1u128 << (100 - s)) {
            return CAP;
        }
        (prod << s) as i128
    } else {
        let sh = (-s) as u32;
        let p = i128::try_from(prod).unwrap_or(CAP);
        i128::from(round_shift_right_wide(p, sh.min(127), fmt.rounding))
    }
}

/// Fixed twin (see the module docs); writes `frag.out_x` and its carriers.
pub fn fixed(px: &Px, frag: &mut Frag, c: &mut Counters) {
    shade_fixed(px.plan, px.impls, px.m, frag, c);
}

/// Float twin: [`AshikhminShirley::eval_from_dots`] per light; writes `frag.out`.
pub fn float(px: &Px, frag: &mut Frag, c: &mut Counters) {
    shade_float(px.plan, px.m, frag, c);
}

/// The fixed twin on one fragment of `plan`: its inputs are raw where `impls` ran the
/// producing stage fixed, the quantized carriers otherwise.
#[allow(clippy::needless_range_loop)]
pub fn shade_fixed(
    plan: &Plan,
    impls: &StageImpls,
    m: &Machine,
    frag: &mut Frag,
    c: &mut Counters,
) {
    let Some(ap) = &plan.aniso else { return };
    let fixed_in = |k: StageKind| impls.of(k) == Impl::Fixed;
    let k = StageKind::AsShade.index();
    let mut sat = c.sat[k];
    let units = &m.units;
    let vc = &units.cfg.vector;
    let f = vc.vector_frac_bits;
    let cb = units.cfg.shade.shade_color_bits;
    let max = (1u64 << cb) - 1;
    let bf = &frag.bump;
    let cfg = &m.hw.aniso_phong;
    let rnd = units.cfg.shade.shade_rounding;
    let raw3 = |v: &[f64; 3], sat: &mut SatCounter| v.map(|x| to_raw(x, &m.vec_fmt, sat));
    let (n, tu, tv) = if fixed_in(StageKind::Frame) {
        (bf.fr_n_x, bf.fr_t_u_x, bf.fr_t_v_x)
    } else {
        (
            raw3(&bf.fr_n, &mut sat),
            raw3(&bf.fr_t_u, &mut sat),
            raw3(&bf.fr_t_v, &mut sat),
        )
    };
    let one = 1i64 << f;
    let v = fixed_eye(m, bf, fixed_in(StageKind::Normal), &mut sat);
    let mut kd = ap.kd.map(|x| u64::from(to_unorm(x, cb)));
    if plan.texture.is_some() {
        let tb = m.hw.trilinear.texel_bits;
        let tex = if fixed_in(StageKind::Trilinear) {
            frag.texel_x
        } else {
            frag.texel.map(|x| to_unorm(x, tb))
        };
        for ch in 0..3 {
            kd[ch] = u64::from(modulate(kd[ch] as u32, cb, tex[ch], tb, cb, rnd));
        }
    }
    let dfmt = Format::signed(1, cfg.aniso_dot_frac_bits, cfg.aniso_rounding);
    let ofmt = Format::unsigned(0, cb, rnd);
    let fb = cfg.fresnel_bits;
    let unorm_f = |x: f64| {
        (x * (1u64 << fb) as f64)
            .round()
            .clamp(0.0, (1u64 << fb) as f64)
    };
    let p = &ap.brdf;
    let mut nu = p.nu.clamp(0.0, f64::from(u32::MAX)) as u64;
    let mut nv = p.nv.clamp(0.0, f64::from(u32::MAX)) as u64;
    if ap.exponent_map {
        let tb = m.hw.trilinear.texel_bits;
        let tex = if fixed_in(StageKind::BumpFetch) {
            bf.texel_x
        } else {
            bf.texel.map(|x| to_unorm(x, tb))
        };
        let tmax = (1u64 << tb) - 1;
        let scale = |n: u64, t: u32| (2 * u64::from(t) * n + tmax) / (2 * tmax);
        nu = scale(nu, tex[0]);
        nv = scale(nv, tex[1]);
    }
    let mut inp = AnisoPhongInputs {
        nu: nu.min(u64::from(u32::MAX)) as u32,
        nv: nv.min(u64::from(u32::MAX)) as u32,
        rs: unorm_f(p.rs) as u32,
        rd: unorm_f(p.rd) as u32,
        ..AnisoPhongInputs::default()
    };
    // Ambient: ambient x kd x Rd (fresnel_bits unorm), one product per channel.
    let mut acc = [0i128; 3];
    for ch in 0..3 {
        let prod = u128::from(m.ambient_x[ch]) * u128::from(kd[ch]) * u128::from(inp.rd);
        acc[ch] = guarded(prod, -((cb + fb) as i32), &ofmt);
    }
    let roms = m.aniso_roms();
    for light in &m.lights {
        let l = fixed_light(m, bf, light, fixed_in(StageKind::Normal), &mut sat);
        let sum = [l[0] + v[0], l[1] + v[1], l[2] + v[2]];
        if sum == [0; 3] {
            c.h_zero += 1;
            continue;
        }
        let h = normalize3(&sum, [0, 0, one], &units.rsqrt, vc, &mut sat).v;
        inp.hn = dot_to(&h, &n, f, &dfmt);
        inp.hu = dot_to(&h, &tu, f, &dfmt);
        inp.hv = dot_to(&h, &tv, f, &dfmt);
        inp.kh = dot_to(&l, &h, f, &dfmt);
        inp.nk1 = dot_to(&n, &l, f, &dfmt);
        inp.nk2 = dot_to(&n, &v, f, &dfmt);
        if inp.nk1 <= 0 {
            continue;
        }
        let out = aniso_phong_prepared(&inp, roms, &mut sat);
        let d = cfg.aniso_dot_frac_bits as i32;
        let nk1 = inp.nk1 as u128;
        let term = |x: PseudoFloat, tint: u64, tint_bits: u32, col: u64| {
            let prod = u128::from(x.mant) * nk1 * u128::from(tint) * u128::from(col);
            guarded(prod, x.exp - d - tint_bits as i32, &ofmt)
        };
        for ch in 0..3 {
            let col = light.color_x[ch];
            acc[ch] += term(out.spec, 1, 0, col) + term(out.diffuse, kd[ch], cb, col);
        }
    }
    for ch in 0..3 {
        let r = round_shift_right_wide(acc[ch], GUARD, rnd);
        let r = ofmt.fit(r, &mut sat) as u64;
        frag.out_x[ch] = r as u32;
        frag.out[ch] = r as f64 / max as f64;
    }
    frag.out_x[3] = max as u32;
    frag.out[3] = 1.0;
    frag.out_bits = cb;
    c.sat[k] = sat;
}

/// The float twin on one fragment of `plan`.
#[allow(clippy::needless_range_loop)]
pub fn shade_float(plan: &Plan, m: &Machine, frag: &mut Frag, c: &mut Counters) {
    let Some(ap) = &plan.aniso else { return };
    let bf = &frag.bump;
    let d3 = |v: &[f64; 3]| DVec3::from(*v);
    let (n, u, vv) = (d3(&bf.fr_n), d3(&bf.fr_t_u), d3(&bf.fr_t_v));
    let e = float_eye(bf);
    let mut kd = ap.kd;
    if plan.texture.is_some() {
        for ch in 0..3 {
            kd[ch] *= frag.texel[ch];
        }
    }
    let mut p = ap.brdf;
    if ap.exponent_map {
        p.nu *= bf.texel[0];
        p.nv *= bf.texel[1];
    }
    let mut acc = [0.0f64; 3];
    for ch in 0..3 {
        acc[ch] = m.ambient[ch] * kd[ch] * p.rd;
    }
    for light in &m.lights {
        let l = float_light(bf, light);
        let sum = l + e;
        if sum == DVec3::ZERO {
            c.h_zero += 1;
            continue;
        }
        let h = sum.normalize();
        let dots = Dots {
            hn: h.dot(n),
            hu: h.dot(u),
            hv: h.dot(vv),
            kh: l.dot(h),
            nk1: n.dot(l),
            nk2: n.dot(e),
        };
        let (s, df) = p.eval_from_dots(&dots);
        let nl = dots.nk1.max(0.0);
        for ch in 0..3 {
            acc[ch] += PI * (s + df * kd[ch]) * nl * light.color_f[ch];
        }
    }
    float_output(acc, frag, c);
}
