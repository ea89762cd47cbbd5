//! End to end per pixel: offsets texels -> frame -> perturbed normal -> Blinn-Phong, fixed
//! against the f64 twin for all three frame kinds.
#![allow(clippy::needless_range_loop)]

use glam::DVec3;
use hw_model::blinn_phong::{bump_shade, BlinnPhongInput, BumpPixel, ShadingConfig, ShadingUnits};
use hw_model::frame::{FrameKind, MainRole};
use hw_model::SatCounter;
use texsim::shading::bump::OffsetEncoding;
use texsim::shading::reference as r;

fn splitmix(s: &mut u64) -> u64 {
    *s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *s;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

fn unif(s: &mut u64) -> f64 {
    (splitmix(s) >> 11) as f64 / (1u64 << 53) as f64
}

fn rand_dir(s: &mut u64) -> DVec3 {
    loop {
        let v = DVec3::new(
            2.0 * unif(s) - 1.0,
            2.0 * unif(s) - 1.0,
            2.0 * unif(s) - 1.0,
        );
        let l = v.length();
        if l > 0.1 && l <= 1.0 {
            return v / l;
        }
    }
}

#[test]
fn bump_shade_matches_twin_all_frames() {
    const F: u32 = 14;
    let ulp = (-f64::from(F)).exp2();
    for kind in [FrameKind::Natural, FrameKind::Unit, FrameKind::Main] {
        let mut cfg = ShadingConfig::texram16();
        cfg.frame.frame_kind = kind;
        let u = ShadingUnits::new(&cfg);
        let lfb = cfg.frame.frame_len_frac_bits;
        let enc = OffsetEncoding::for_offset_int_bits(cfg.vector.offset_int_bits);
        let mut s = 1234u64;
        let mut sat = SatCounter::default();
        let (mut worst_n, mut worst_c) = (0.0f64, 0.0f64);
        for _ in 0..200_000 {
            let n_i = rand_dir(&mut s);
            let m = rand_dir(&mut s);
            if m.cross(n_i).length() < 0.1 {
                continue;
            }
            // Tangent directions roughly in the tangent plane, as interpolation gives them.
            let du = (m.cross(n_i) + 0.1 * rand_dir(&mut s)).normalize();
            let dv = (n_i.cross(du) + 0.1 * rand_dir(&mut s)).normalize();
            let lens = [0.5 + unif(&mut s), 0.5 + unif(&mut s)];
            let texels = [0; 2].map(|_: u64| 32768 - 8192 + splitmix(&mut s) % 16384);
            let q = |v: DVec3| r::to_vec3x(v, F);
            let bits = splitmix(&mut s);
            let main_role = MainRole {
                m_is_u: bits & 1 == 1,
                mirrored: bits & 2 == 2,
            };
            let px = BumpPixel {
                n_i: q(n_i),
                d_u: q(du),
                d_v: q(dv),
                len_u: r::to_fixed(lens[0], lfb),
                len_v: r::to_fixed(lens[1], lfb),
                m: q(m),
                main_role,
                offset_texels: texels,
                texel_bits: 16,
            };
            let l = rand_dir(&mut s);
            let v = rand_dir(&mut s);
            let shininess = 1 + (splitmix(&mut s) % 64) as u32;
            let col = |s: &mut u64| [0; 3].map(|_: u64| splitmix(s) % 65536);
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
            let sf = f64::from(shininess);
            for k in 0..3 {
                let b = fc(light)[k]
                    * (fc(kd)[k] * 40.0 * ulp + fc(ks)[k] * (sf * 40.0 * ulp + 4e-4))
                    + 2.0 / 65535.0;
                let e = (out.color[k] as f64 / 65535.0 - want[k]).abs();
                worst_c = worst_c.max(e);
                assert!(e <= b, "{kind:?} ch {k}: err {e} > {b}");
            }
        }
        println!(
            "{kind:?}: perturbed normal max err {:.2} ulp, colour max err {:.2e}",
            worst_n / ulp,
            worst_c
        );
    }
}
