//! Moment maps (`texsim::shading::ndf`): MIP averaging of the nine numbers is the mixture's
//! moments, the covariance is `E - mu mu^T` (outer product, not the paper's printed `mu^T mu`),
//! the encoding round-trips, coarse levels of grooves stretch across the grooves, and the
//! exact normalization integrates the base lobe to the von Mises-Fisher constant.

use glam::DVec3;
use hw_model::ndf::{NdfConfig, NdfDensity};
use texsim::shading::ndf::{
    build_ndf_maps, decode_texels, procedural_normals, quantize_texel, sphere_integral, Moments,
};

#[test]
fn mip_level_is_the_mixture_and_covariance_uses_the_outer_product() {
    let (w, h) = (16, 16);
    let normals = procedural_normals("foil", w, h, 0.6).expect("map");
    let s = 32.0;
    let maps = build_ndf_maps(&normals, w, h, s, &NdfConfig::texram16()).expect("maps");
    let (_, _, l1) = &maps.levels[1];
    for y in 0..h / 2 {
        for x in 0..w / 2 {
            let kids: Vec<DVec3> = [(0, 0), (1, 0), (0, 1), (1, 1)]
                .iter()
                .map(|(dx, dy)| normals[((2 * y + dy) * w + 2 * x + dx) as usize].normalize())
                .collect();
            let mean = kids.iter().copied().sum::<DVec3>() / 4.0;
            let t = &l1[(y * (w / 2) + x) as usize];
            assert!((t.mu - mean).length() < 1e-12);
            // Pooled covariance: spread of the four normals plus the base variance 1/s.
            let cov = |i: usize, j: usize| {
                kids.iter()
                    .map(|n| (n[i] - mean[i]) * (n[j] - mean[j]))
                    .sum::<f64>()
                    / 4.0
                    + if i == j { 1.0 / s } else { 0.0 }
            };
            let want = [
                cov(0, 0),
                cov(1, 1),
                cov(2, 2),
                cov(0, 1),
                cov(0, 2),
                cov(1, 2),
            ];
            let got = t.covariance();
            for k in 0..6 {
                assert!((got[k] - want[k]).abs() < 1e-12, "{k}: {got:?} {want:?}");
            }
        }
    }
}

#[test]
fn encoding_round_trips_within_one_step() {
    let cfg = NdfConfig::texram16();
    let step = 2.0 / f64::from((1u32 << cfg.moment_bits) - 1);
    for s in [1.0, 8.0, 100.0, 4000.0] {
        for n in [
            DVec3::Z,
            DVec3::new(0.5, -0.3, 0.8),
            DVec3::new(-0.9, 0.1, 0.3),
        ] {
            let m = Moments::from_normal(n.normalize(), s);
            let d = decode_texels(&quantize_texel(&m, &cfg, 0.0, 0), &cfg);
            assert!((d.mu - m.mu).abs().max_element() <= step / 2.0 + 1e-12);
            for k in 0..6 {
                assert!((d.e[k] - m.e[k]).abs() <= step / 2.0 + 1e-12, "{s} {n} {k}");
            }
        }
    }
}

/// Figure 1's effect: grooves along y (slopes in x) give coarse texels whose spread in x grows
/// level by level while the spread in y stays at the base variance.
#[test]
fn coarse_levels_of_grooves_stretch_across_them() {
    let (w, h) = (64, 64);
    let normals = procedural_normals("grooves", w, h, 0.5).expect("map");
    let s = 64.0;
    let maps = build_ndf_maps(&normals, w, h, s, &NdfConfig::texram16()).expect("maps");
    let mut prev = 0.0;
    for (lvl, (_, _, t)) in maps.levels.iter().enumerate() {
        let c = t[0].covariance();
        println!("level {lvl}: Sigma_xx {:.5} Sigma_yy {:.5}", c[0], c[1]);
        assert!((c[1] - 1.0 / s).abs() < 1e-9);
        assert!(c[0] >= prev - 1e-12);
        prev = c[0];
    }
    assert!(prev > 10.0 / s);
}

/// Exact normalization of a single base lobe: `Z = integral of exp(-s |x - n|^2 / 2)` over the
/// sphere is `2 pi (1 - e^(-2s)) / s` (von Mises-Fisher); the quadrature meets it to 1e-6.
#[test]
fn sphere_integral_of_the_base_lobe_is_the_vmf_constant() {
    let cfg = NdfConfig {
        ndf_density: NdfDensity::Gauss,
        ..NdfConfig::texram16()
    };
    for s in [2.0, 16.0, 256.0, 4096.0] {
        let m = Moments::from_normal(DVec3::new(0.3, 0.2, 0.93).normalize(), s);
        let z = sphere_integral(m.mu, &m.covariance(), &cfg);
        let want = 2.0 * std::f64::consts::PI * (1.0 - (-2.0 * s).exp()) / s;
        println!("s = {s}: Z {z:.9} vMF {want:.9}");
        assert!((z / want - 1.0).abs() < 1e-6, "{s}: {z} {want}");
    }
}

/// The normalization map's scale `2^norm_exp`, `norm_exp = ceil(log2(s/2))` from the base
/// shininess alone (`norm_exp_for`), covers the largest `1/Z` of the chain (no clamp) for both
/// densities and m = 1, 8, 64, from s = 1 up to the variance floor `2^(B-3)`, and wastes at
/// most 3 bits of the channel there (`2^norm_exp <= 8 max 1/Z` from s = 16 on).
#[test]
fn normalization_map_scale_covers_the_largest_inverse_z() {
    use hw_model::ndf::NdfNorm;
    use texsim::shading::ndf::norm_exp_for;
    let flat = vec![DVec3::Z; 4];
    let rip = procedural_normals("ripple", 8, 8, 0.4).expect("map");
    for dens in [NdfDensity::Pearson, NdfDensity::Gauss] {
        for m in [1, 8, 64] {
            let cfg = NdfConfig {
                ndf_norm: NdfNorm::Map,
                ndf_density: dens,
                pearson_m: m,
                ..NdfConfig::texram16()
            };
            for s in [1.0, 2.0, 7.0, 16.0, 64.0, 1000.0, 8192.0] {
                for (n, w) in [(&flat, 2), (&rip, 8)] {
                    let maps = build_ndf_maps(n, w, w, s, &cfg).expect("maps");
                    assert_eq!(maps.norm_exp, norm_exp_for(s));
                    let top = maps.inv_z.iter().flatten().fold(0.0f64, |a, &b| a.max(b));
                    let scale = f64::from(maps.norm_exp).exp2();
                    assert!(
                        top <= scale && maps.clamped == 0,
                        "{dens:?} m={m} s={s}: {top} > {scale}"
                    );
                    if s >= 16.0 && w == 2 {
                        assert!(scale <= 8.0 * top, "{dens:?} m={m} s={s}: {scale} vs {top}");
                    }
                }
            }
        }
    }
}

/// `moment_scale_bits = 0` stores `E_ii` unscaled: `E_zz = n_z^2 + 1/s > 1` of a flat texel is
/// clamped (and counted), at every level; `k = 1` stores it without a clamp.
#[test]
fn scale_zero_clamps_the_diagonal_of_flat_texels() {
    let flat = vec![DVec3::Z; 16];
    for (k, clamps) in [(0u32, true), (1, false), (2, false)] {
        let cfg = NdfConfig {
            moment_scale_bits: k,
            ..NdfConfig::texram16()
        };
        let maps = build_ndf_maps(&flat, 4, 4, 64.0, &cfg).expect("maps");
        // 16 + 4 + 1 texels, one E_zz channel each.
        assert_eq!(maps.clamped, if clamps { 21 } else { 0 }, "k = {k}");
    }
}
