//! End to end per pixel: offsets texels -> frame -> perturbed normal -> Blinn-Phong, fixed
//! against the f64 twin for all three frame kinds.
#![allow(clippy::needless_range_loop)]

use crate::rng_common::Rng;
use glam::DVec3;
use hw_model::blinn_phong::{bump_shade, BlinnPhongInput, BumpPixel, ShadingConfig, ShadingUnits};
use hw_model::frame::{FrameKind, MainRole};
use hw_model::SatCounter;
use texsim::shading::bump::OffsetEncoding;
use texsim::shading::reference as r;

#[test]
fn bump_shade_matches_twin_all_frames() {
    // The band of `n.l` (in ulp) where the specular gate may flip: 3 components of 16 ulp
    // against a unit `l`, and the dot product's rounding.
    const GATE_BAND: f64 = 64.0;
    const F: u32 = 14;
    let ulp = (-f64::from(F)).exp2();
    for kind in [FrameKind::Natural, FrameKind::Unit, FrameKind::Main] {
        let mut cfg = ShadingConfig::texram16();
        cfg.frame.frame_kind = kind;
        let u = ShadingUnits::new(&cfg);
        let lfb = cfg.frame.frame_len_frac_bits;
        let enc = OffsetEncoding::for_offset_int_bits(cfg.vector.offset_int_bits);
        let mut s = Rng(1234);
        let mut sat = SatCounter::default();
        let (mut worst_n, mut worst_c, mut worst_ratio) = (0.0f64, 0.0f64, 0.0f64);
        let mut gate_band = 0u32;
        for _ in 0..400_000 {
            let n_i = s.dir();
            let m = s.dir();
            if m.cross(n_i).length() < 0.1 {
                continue;
            }
            // Tangent directions roughly in the tangent plane, as interpolation gives them.
            let du = (m.cross(n_i) + 0.1 * s.dir()).normalize();
            let dv = (n_i.cross(du) + 0.1 * s.dir()).normalize();
            let lens = [0.5 + s.unit(), 0.5 + s.unit()];
            let texels = [0; 2].map(|_: u64| 32768 - 8192 + s.next() % 16384);
            let q = |v: DVec3| r::to_vec3x(v, F);
            let bits = s.next();
            let main_role = MainRole {
                m_is_u: bits & 1 == 1,
                mirrored: bits & 2 == 2,
            };
            let px = BumpPixel {
                n_i: q(n_i),
                d_u: q(du),
                d_v: q(dv),
                len_u: texsim::fixedpoint::to_raw_nearest(lens[0], lfb),
                len_v: texsim::fixedpoint::to_raw_nearest(lens[1], lfb),
                m: q(m),
                main_role,
                offset_texels: texels,
                texel_bits: 16,
            };
            let l = s.dir();
            let v = s.dir();
            // Every exponent the power unit holds, the small ones weighted.
            let shininess = match s.next() % 4 {
                0 => 1 + (s.next() % 16) as u32,
                1 => 1 + (s.next() % 128) as u32,
                _ => 1 + (s.next() % 2047) as u32,
            };
            let col = |s: &mut Rng| [0; 3].map(|_: u64| s.next() % 65536);
            let (kd, ks, light) = (col(&mut s), col(&mut s), col(&mut s));
            let sh = BlinnPhongInput {
                n: [0; 3],
                l: q(l),
                v: q(v),
                shininess,
                kd,
                ks,
                light,
            };
            let out = bump_shade(&px, &sh, &u, &mut sat);
            let offs = texels.map(|t| f64::from(enc.decode(t as f32 / 65536.0)));
            let fc = |c: [u64; 3]| c.map(|x| x as f64 / 65535.0);
            let dq = |v: &[i64; 3]| r::from_vec3x(v, F);
            let lens_q = [px.len_u, px.len_v].map(|x| r::from_fixed(x, lfb));
            let (want, wn, _, _) = r::bump_shade(
                kind,
                dq(&px.n_i),
                dq(&px.d_u),
                dq(&px.d_v),
                lens_q,
                dq(&px.m),
                main_role,
                offs,
                cfg.frame.frame_min_sin_bits,
                dq(&sh.l),
                dq(&sh.v),
                shininess,
                [fc(kd), fc(ks), fc(light)],
            );
            let ne = (dq(&out.normal) - wn).abs().max_element();
            worst_n = worst_n.max(ne);
            assert!(ne <= 16.0 * ulp, "{kind:?}: normal err {ne}");
            // The specular gate `n.l > 0` flips where the normal's error (16 ulp a component
            // against `l`'s unit length) can change the sign of `n.l`: there the colour is the
            // lit or the unlit value, outside the bound.
            if wn.dot(dq(&sh.l)).abs() <= GATE_BAND * ulp {
                gate_band += 1;
                continue;
            }
            // The specular factor `x^s`: the twin's `x = max(n.h, 0)`, the unit's within 40 ulp
            // of it, so the error carried through `x^s` is at most `s 40 ulp (x + 40 ulp)^(s-1)`
            // (the mean value theorem on [0, 1]), plus the power unit's own bound there.
            let sf = f64::from(shininess);
            let h = (dq(&sh.l) + dq(&sh.v)).normalize_or_zero();
            let x = (wn.dot(h).max(0.0) + 40.0 * ulp).min(1.0);
            let spec = sf * 40.0 * ulp * x.powf(sf - 1.0)
                + crate::frames_pow::bound(&cfg.pow, x, shininess);
            for k in 0..3 {
                let b = fc(light)[k] * (fc(kd)[k] * 40.0 * ulp + fc(ks)[k] * spec) + 2.0 / 65535.0;
                let e = (out.color[k] as f64 / 65535.0 - want[k]).abs();
                worst_c = worst_c.max(e);
                worst_ratio = worst_ratio.max(e / b);
                assert!(e <= b, "{kind:?} ch {k}: err {e} > {b}");
            }
        }
        println!(
            "{kind:?}: perturbed normal max err {:.2} ulp, colour max err {:.2e} (error / bound \
             {worst_ratio:.3}), {gate_band} in the specular gate's band",
            worst_n / ulp,
            worst_c
        );
        assert!(
            gate_band < 4_000,
            "{kind:?}: {gate_band} cases in the gate's band"
        );
    }
}
