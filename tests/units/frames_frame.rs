//! Frames (natural, unit, main direction) and the perturbed normal: fixed units against their
//! f64 twins, and the hard-case properties (near-parallel m, zero normals, continuity).

use crate::rng_common::Rng;
use glam::DVec3;
use hw_model::blinn_phong::{ShadingConfig, ShadingUnits};
use hw_model::frame::{
    main_direction_frame, main_frame, natural_frame, perturb_normal, unit_frame, Frame, MainRole,
};
use hw_model::vector::Vec3x;
use hw_model::SatCounter;
use texsim::shading::reference as r;

const F: u32 = 14;

fn q(v: DVec3) -> Vec3x {
    r::to_vec3x(v, F)
}

fn d(v: &Vec3x) -> DVec3 {
    r::from_vec3x(v, F)
}

fn ulp() -> f64 {
    (-f64::from(F)).exp2()
}

/// Max deviation from orthonormality of three vectors: | |x|-1 | and |x.y|.
fn ortho_err(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let mut e = 0.0f64;
    for v in [a, b, c] {
        e = e.max((v.length() - 1.0).abs());
    }
    e.max(a.dot(b).abs())
        .max(a.dot(c).abs())
        .max(b.dot(c).abs())
}

fn units() -> ShadingUnits {
    ShadingUnits::new(&ShadingConfig::texram16())
}

/// Orthonormality bound of the fixed main frame (texram16): 3 ulp.
const ORTHO_BOUND_ULP: f64 = 3.0;
/// Component bound of the fixed main frame against its twin on the same quantized inputs,
/// away from the fallback cone: 4 ulp + 2.5 ulp / sin(m, n) (e1 comes from the cross product of
/// the fixed-normalized m and n, each within 0.61 ulp per component, whose direction error
/// grows as 1/sin).
fn main_bound(sin: f64) -> f64 {
    4.0 * ulp() + 2.5 * ulp() / sin
}

#[test]
fn main_frame_random_orthonormal_and_matches_twin() {
    let u = units();
    let t = u.cfg.frame.frame_min_sin_bits;
    let mut s = Rng(11);
    let mut sat = SatCounter::default();
    let (mut worst_o, mut worst_c, mut flag_mismatch) = (0.0f64, 0.0f64, 0u32);
    for i in 0..1_000_000u32 {
        let n_i = s.dir() * (0.05 + s.unit());
        // Every 4th case: m near-parallel to n (angles 2^-20 .. 2^-2 rad).
        let m = if i % 4 == 0 {
            let eps = (-2.0 - 18.0 * s.unit()).exp2();
            let sign = if s.next() & 1 == 0 { 1.0 } else { -1.0 };
            sign * n_i.normalize() + eps * s.dir()
        } else {
            s.dir()
        };
        let (nq, mq) = (q(n_i), q(m));
        let fx = main_direction_frame(&nq, &mq, &u, &mut sat);
        let (n, e1, e2) = (d(&fx.n), d(&fx.e1), d(&fx.e2));
        for v in [n, e1, e2] {
            assert!(v.is_finite());
        }
        let oe = ortho_err(n, e1, e2);
        worst_o = worst_o.max(oe);
        assert!(oe <= ORTHO_BOUND_ULP * ulp(), "case {i}: ortho err {oe}");
        assert!(e1.cross(e2).dot(n) > 0.99, "right-handed");
        let (rn, re1, re2, rfb, _) = r::main_direction_frame(d(&nq), d(&mq), t);
        if rfb != fx.fallback {
            flag_mismatch += 1;
            continue;
        }
        let sin = if rfb {
            0.8
        } else {
            d(&mq).normalize().cross(rn).length()
        };
        let ce = (n - rn)
            .abs()
            .max_element()
            .max((e1 - re1).abs().max_element())
            .max((e2 - re2).abs().max_element());
        worst_c = worst_c.max(ce / main_bound(sin));
        assert!(
            ce <= main_bound(sin),
            "case {i}: component err {ce} sin {sin}"
        );
    }
    println!(
        "main frame: ortho err {:.2} ulp, component err {:.2} of bound, fallback flag mismatches {flag_mismatch}",
        worst_o / ulp(),
        worst_c
    );
    assert!(flag_mismatch < 2000, "only at the cone boundary");
    assert_eq!(sat.saturated, 0);
}

#[test]
fn zero_normal_gives_z_frame() {
    let u = units();
    let mut sat = SatCounter::default();
    // Opposite vertex normals interpolated at the midpoint.
    let a = q(DVec3::new(0.3, -0.5, 0.8).normalize());
    let b = a.map(|x| -x);
    let mid = [0, 1, 2].map(|i| (a[i] + b[i]) / 2);
    for m in [q(DVec3::X), q(DVec3::Z), [0; 3]] {
        let fr = main_direction_frame(&mid, &m, &u, &mut sat);
        assert!(fr.zero_normal);
        assert_eq!(fr.n, [0, 0, 1 << F]);
        assert!(ortho_err(d(&fr.n), d(&fr.e1), d(&fr.e2)) <= ORTHO_BOUND_ULP * ulp());
        let uf = unit_frame(&mid, &[0; 3], &[0; 3], &u, &mut sat);
        assert!(uf.zero_normal && uf.fallback);
        assert!(ortho_err(d(&uf.n), d(&uf.t_u), d(&uf.t_v)) <= ORTHO_BOUND_ULP * ulp());
    }
    assert!(sat.saturated > 0, "zero lengths are counted");
}

/// Continuity away from the jump: along slow paths of n that keep sin(m, n) >= 2 * 2^-t, the
/// fixed frame moves by at most 1.5 step (1 + 1/sin) + 8 ulp / sin per step (e1 turns at rate
/// 1/sin, e2 = n x e1 adds the turn of n); the fallback flag switches only
/// when crossing the cone.
#[test]
fn main_frame_continuity_away_from_cone() {
    let u = units();
    let thr = (-f64::from(u.cfg.frame.frame_min_sin_bits)).exp2();
    let mut s = Rng(23);
    let mut sat = SatCounter::default();
    let step = 1e-3;
    let mut crossings = 0u32;
    for _ in 0..300 {
        let m = s.dir();
        let mut axis = s.dir();
        axis = (axis - m * m.dot(axis)).normalize(); // the plane of n's path contains m
        let start = s.dir();
        let start = (start - axis * axis.dot(start)).normalize();
        let mut prev: Option<(DVec3, DVec3, DVec3, bool, f64)> = None;
        for k in 0..3000 {
            let ang = k as f64 * step;
            let n = (start * ang.cos() + axis.cross(start) * ang.sin()).normalize();
            let fx = main_direction_frame(&q(n), &q(m), &u, &mut sat);
            let cur = (
                d(&fx.n),
                d(&fx.e1),
                d(&fx.e2),
                fx.fallback,
                m.cross(n).length(),
            );
            if let Some(p) = prev {
                let sin = p.4.min(cur.4);
                if p.3 != cur.3 {
                    crossings += 1;
                    assert!(
                        sin < 1.5 * thr,
                        "flag switched away from the cone: sin {sin}"
                    );
                } else if sin >= 2.0 * thr && !cur.3 {
                    let dist = (cur.1 - p.1).length().max((cur.2 - p.2).length());
                    let lim = 1.5 * step * (1.0 + 1.0 / sin) + 8.0 * ulp() / sin;
                    assert!(dist <= lim, "jump {dist} > {lim} at sin {sin}");
                }
            }
            prev = Some(cur);
        }
    }
    println!("continuity: {crossings} cone crossings seen");
}

#[test]
fn unit_and_natural_frames_match_twin() {
    let u = units();
    let lfb = u.cfg.frame.frame_len_frac_bits;
    let mut s = Rng(31);
    let mut sat = SatCounter::default();
    let mut worst = 0.0f64;
    for _ in 0..1_000_000 {
        let n_i = s.dir() * (0.1 + s.unit());
        let du = s.dir() * (0.1 + s.unit());
        let dv = s.dir() * (0.1 + s.unit());
        let (lu, lv) = (4.0 * s.unit(), 4.0 * s.unit());
        let (lur, lvr) = (
            texsim::fixedpoint::to_raw_nearest(lu, lfb),
            texsim::fixedpoint::to_raw_nearest(lv, lfb),
        );
        let fr = natural_frame(&q(n_i), &q(du), &q(dv), lur, lvr, &u, &mut sat);
        let tw = r::natural_frame(d(&q(n_i)), d(&q(du)), d(&q(dv)), lu, lv, 6);
        for (a, b) in [(fr.n, tw.n), (fr.t_u, tw.t_u), (fr.t_v, tw.t_v)] {
            worst = worst.max((d(&a) - b).abs().max_element());
        }
        assert_eq!(fr.len_u, lur);
        let uf = unit_frame(&q(n_i), &q(du), &q(dv), &u, &mut sat);
        assert_eq!((uf.n, uf.t_u, uf.t_v), (fr.n, fr.t_u, fr.t_v));
    }
    println!(
        "unit/natural frame max component err {:.3} ulp",
        worst / ulp()
    );
    assert!(worst <= 0.61 * ulp());
}

/// Perturbed normal against the twin on the same quantized frame and offsets.
#[test]
fn perturbed_normal_matches_twin() {
    let u = units();
    let o = u.cfg.vector.offset_frac_bits;
    let lfb = u.cfg.frame.frame_len_frac_bits;
    let mut s = Rng(41);
    let mut sat = SatCounter::default();
    let (mut worst_u, mut worst_n) = (0.0f64, 0.0f64);
    for i in 0..1_000_000u32 {
        let n_i = s.dir();
        let m = s.dir();
        let natural = i % 2 == 1;
        let role = MainRole {
            m_is_u: i % 4 >= 2,
            mirrored: i % 8 >= 4,
        };
        let mut fr: Frame = main_frame(&q(n_i), &q(m), role, &u, &mut sat);
        if natural {
            fr.len_u = texsim::fixedpoint::to_raw_nearest(0.25 + 2.0 * s.unit(), lfb);
            fr.len_v = texsim::fixedpoint::to_raw_nearest(0.25 + 2.0 * s.unit(), lfb);
        }
        let fu = texsim::fixedpoint::to_raw_nearest(4.0 * s.unit() - 2.0, o);
        let fv = texsim::fixedpoint::to_raw_nearest(4.0 * s.unit() - 2.0, o);
        let p = perturb_normal(&fr, fu, fv, &u, &mut sat);
        let tw = r::FrameF {
            n: d(&fr.n),
            t_u: d(&fr.t_u),
            t_v: d(&fr.t_v),
            len_u: r::from_fixed(fr.len_u, lfb),
            len_v: r::from_fixed(fr.len_v, lfb),
            fallback: fr.fallback,
            zero_normal: fr.zero_normal,
        };
        let want = r::perturb_normal(&tw, r::from_fixed(fu, o), r::from_fixed(fv, o));
        let e = (d(&p.v) - want).abs().max_element();
        assert!(d(&p.v).is_finite());
        if natural {
            worst_n = worst_n.max(e);
        } else {
            worst_u = worst_u.max(e);
        }
    }
    println!(
        "perturbed normal max component err: unit-length frames {:.3} ulp, natural {:.3} ulp",
        worst_u / ulp(),
        worst_n / ulp()
    );
    // Bounds: madd rounding (<= sqrt3/2 ulp in |w| >= ~0.3..1) + normalize (0.61 ulp); the
    // natural frame adds the f*len rounding (1/2 ulp of s3.12 = 2 ulp of s1.14 per offset).
    assert!(worst_u <= 2.5 * ulp(), "unit {worst_u}");
    assert!(worst_n <= 8.0 * ulp(), "natural {worst_n}");
    assert_eq!(sat.saturated, 0);
}

/// One offset map gives the same bumps in every frame: on mutually perpendicular `p_u`, `p_v`,
/// `n` (right-handed and mirrored, lengths in [0.5, 1]), the main frame with `m = p_u`, with
/// `m = p_v` and with a constant `m` along `p_v` equals the unit frame built from the natural
/// directions `n x p_v`, `p_u x n`, and so do the perturbed normals: in fixed point frame
/// components within 6.5 ulp (the main frame's 4 + 2.5 ulp at sin(m, n) = 1) and perturbed
/// normals within 9 ulp (measured 3.0 and 3.0 ulp), in float within 1e-12. With the axes of
/// `m = p_v` applied to `m = p_u` the bumps would turn by 90 degrees.
#[test]
fn main_frame_roles_equal_unit_frame() {
    let u = units();
    let o = u.cfg.vector.offset_frac_bits;
    let t = u.cfg.frame.frame_min_sin_bits;
    let mut s = Rng(53);
    let mut sat = SatCounter::default();
    let (mut worst_t, mut worst_p, mut worst_f) = (0.0f64, 0.0f64, 0.0f64);
    for i in 0..200_000u32 {
        let n = s.dir();
        let a = s.dir();
        let mirrored = i % 2 == 1;
        let pu_dir = (a - n * n.dot(a)).normalize();
        let pv_dir = if mirrored {
            pu_dir.cross(n)
        } else {
            n.cross(pu_dir)
        };
        let pu = pu_dir * (0.5 + 0.5 * s.unit());
        let pv = pv_dir * (0.5 + 0.5 * s.unit());
        assert_eq!(n.dot(pu.cross(pv)) < 0.0, mirrored);
        let (du, dv) = (n.cross(pv).normalize(), pu.cross(n).normalize());
        let n_i = n * (0.3 + s.unit());
        let fu = texsim::fixedpoint::to_raw_nearest(2.0 * s.unit() - 1.0, o);
        let fv = texsim::fixedpoint::to_raw_nearest(2.0 * s.unit() - 1.0, o);
        let uf = unit_frame(&q(n_i), &q(du), &q(dv), &u, &mut sat);
        let want = perturb_normal(&uf, fu, fv, &u, &mut sat);
        let tw_unit = r::unit_frame(n_i, du, dv, t);
        let (fu_f, fv_f) = (r::from_fixed(fu, o), r::from_fixed(fv, o));
        let want_f = r::perturb_normal(&tw_unit, fu_f, fv_f);
        let cases = [
            (pu, true),
            (pv, false),
            (pv_dir * 0.5, false), // a constant m along p_v
        ];
        for (m, m_is_u) in cases {
            let role = MainRole { m_is_u, mirrored };
            let fr = main_frame(&q(n_i), &q(m), role, &u, &mut sat);
            assert!(!fr.fallback);
            let te = (d(&fr.t_u) - d(&uf.t_u))
                .abs()
                .max_element()
                .max((d(&fr.t_v) - d(&uf.t_v)).abs().max_element());
            worst_t = worst_t.max(te);
            assert!(te <= 6.5 * ulp(), "case {i} {role:?}: frame err {te}");
            let p = perturb_normal(&fr, fu, fv, &u, &mut sat);
            let pe = (d(&p.v) - d(&want.v)).abs().max_element();
            worst_p = worst_p.max(pe);
            assert!(pe <= 9.0 * ulp(), "case {i} {role:?}: normal err {pe}");
            let tw = r::main_frame(n_i, m, role, t);
            let fe = (r::perturb_normal(&tw, fu_f, fv_f) - want_f)
                .abs()
                .max_element();
            worst_f = worst_f.max(fe);
            assert!(fe <= 1e-12, "case {i} {role:?}: float twin err {fe}");
        }
    }
    println!(
        "main vs unit frame: frame {:.2} ulp, perturbed normal {:.2} ulp, float twins {:.1e}",
        worst_t / ulp(),
        worst_p / ulp(),
        worst_f
    );
    assert_eq!(sat.saturated, 0);
    // The assignment matters: m = p_u with the axes of m = p_v turns the bumps.
    let (n, pu) = (q(DVec3::Z), q(DVec3::X));
    let swapped = main_frame(&n, &pu, MainRole::default(), &u, &mut sat);
    let right = main_frame(
        &n,
        &pu,
        MainRole {
            m_is_u: true,
            mirrored: false,
        },
        &u,
        &mut sat,
    );
    assert_eq!(right.t_u, q(-DVec3::X));
    assert_eq!(right.t_v, q(-DVec3::Y));
    assert_eq!(swapped.t_u, q(DVec3::Y));
}

/// Earth-like sphere with m = the axis: finite and orthonormal everywhere; the fallback is
/// taken exactly inside the documented cone around the poles; e1 points east elsewhere.
#[test]
fn sphere_poles_with_axis_main_direction() {
    let u = units();
    let thr = (-f64::from(u.cfg.frame.frame_min_sin_bits)).exp2();
    let mut sat = SatCounter::default();
    let m = q(DVec3::Z);
    for j in 0..=400 {
        let th = std::f64::consts::PI * f64::from(j) / 400.0;
        for i in 0..64 {
            let phi = std::f64::consts::TAU * f64::from(i) / 64.0;
            let n = DVec3::new(th.sin() * phi.cos(), th.sin() * phi.sin(), th.cos());
            let fx = main_direction_frame(&q(n), &m, &u, &mut sat);
            let (fn_, e1, e2) = (d(&fx.n), d(&fx.e1), d(&fx.e2));
            assert!(ortho_err(fn_, e1, e2) <= ORTHO_BOUND_ULP * ulp());
            let sin = th.sin();
            if sin < 0.9 * thr {
                assert!(fx.fallback, "inside the cone: th {th}");
            } else if sin > 1.1 * thr {
                assert!(!fx.fallback, "outside the cone: th {th}");
                let east = DVec3::new(-phi.sin(), phi.cos(), 0.0);
                // e1 = m x n / |m x n| is east; error grows as ulp / sin near the cone.
                assert!(
                    (e1 - east).length() <= 4.0 * ulp() + 3.0 * ulp() / sin,
                    "th {th}"
                );
            }
        }
    }
}

/// The paper's remark: interpolating vectors of different lengths directly turns the direction
/// faster near the shorter one; interpolating directions and lengths separately does not.
#[test]
fn separate_length_interpolation() {
    let (a, b) = (DVec3::X, DVec3::Y);
    let (la, lb) = (1.0, 4.0);
    let half = [0.5, 0.5, 0.0];
    let direct = r::interpolate3(half, [a * la, b * lb, DVec3::ZERO]).normalize();
    let dir = r::interpolate3(half, [a, b, DVec3::ZERO]).normalize();
    let len = r::interpolate1(half, [la, lb, 0.0]);
    let bisector = (a + b).normalize();
    assert!((dir - bisector).length() < 1e-12);
    assert!((len - 2.5).abs() < 1e-12);
    assert!(
        direct.angle_between(b) < 0.25,
        "direct interpolation is pulled to the long end"
    );
    let fr = r::natural_frame(DVec3::Z, dir, DVec3::Y, len, 1.0, 6);
    assert!((fr.t_u - bisector).length() < 1e-12 && fr.len_u == 2.5);
}

/// Offsets scaled by large natural lengths saturate the offset format: counted, output finite.
#[test]
fn natural_length_saturation_is_counted() {
    let u = units();
    let lfb = u.cfg.frame.frame_len_frac_bits;
    let o = u.cfg.vector.offset_frac_bits;
    let mut sat = SatCounter::default();
    let fr = natural_frame(
        &q(DVec3::Z),
        &q(-DVec3::X),
        &q(-DVec3::Y),
        texsim::fixedpoint::to_raw_nearest(200.0, lfb),
        texsim::fixedpoint::to_raw_nearest(1000.0, lfb),
        &u,
        &mut sat,
    );
    assert_eq!(sat.saturated, 1, "length 1000 exceeds u8.8");
    let p = perturb_normal(
        &fr,
        texsim::fixedpoint::to_raw_nearest(0.5, o),
        0,
        &u,
        &mut sat,
    );
    assert_eq!(sat.saturated, 2, "0.5 * 200 exceeds the s3.12 offset range");
    // The offset saturates to 8 - 2^-12 and multiplies t_u = -x.
    let want = DVec3::new(-(8.0 - (-12f64).exp2()), 0.0, 1.0).normalize();
    assert!((d(&p.v) - want).length() < 4.0 * ulp());
}

/// The paper's natural-frame identities, checked numerically (the converted text was intact
/// here): `s_u x s_v = p_u x p_v` with `s_u = n^ x p_v`, `s_v = p_u x n^`, and the normal of the
/// displaced surface `p + f n^` is `n + f_u s_u + f_v s_v` to first order (Blinn 1978).
#[test]
fn natural_frame_identities() {
    let mut s = Rng(3);
    for _ in 0..1000 {
        let pu = s.dir() * (0.2 + s.unit());
        let pv = s.dir() * (0.2 + s.unit());
        let n = pu.cross(pv);
        if n.length() < 0.05 {
            continue;
        }
        let nh = n.normalize();
        let (su, sv) = (nh.cross(pv), pu.cross(nh));
        assert!((su.cross(sv) - n).length() < 1e-12);
        // Displaced plane p(u, v) = u pu + v pv + f(u, v) nh with f = a u + b v (small slopes).
        let (a, b) = (0.3 * s.unit() - 0.15, 0.3 * s.unit() - 0.15);
        let exact = (pu + a * nh).cross(pv + b * nh);
        let paper = n + a * su + b * sv;
        // Exact up to the second-order term a b (nh x nh) = 0: identical for a plane.
        assert!((exact - paper).length() < 1e-12);
    }
}
