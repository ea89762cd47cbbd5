//! Bump-map preparation: central differences with wrap, encoding, decode by the fixed unit,
//! normal-map conversion, errors.

use glam::DVec3;
use hw_model::vector::{offset_from_texel, VectorConfig};
use hw_model::SatCounter;
use texsim::scene::TextureImage;
use texsim::shading::bump::{
    bump_image_from_height, height_to_offsets, heights_from_texture, normal_map_to_offsets,
    offsets_to_image, BumpParams, OffsetEncoding,
};
use texsim::shading::reference as r;

fn img(w: u32, h: u32, f: impl Fn(u32, u32) -> [u16; 4]) -> TextureImage {
    let mut texels = Vec::new();
    for y in 0..h {
        for x in 0..w {
            texels.push(f(x, y));
        }
    }
    TextureImage {
        name: "test.png".into(),
        width: w,
        height: h,
        texels,
        prebuilt_levels: None,
    }
}

#[test]
fn central_differences_with_wrap() {
    let (w, h) = (8u32, 4u32);
    // h = x / 8 ramp: interior f_u = scale / 8, wrap edges see the jump.
    let heights: Vec<f32> = (0..h)
        .flat_map(|_| (0..w).map(|x| x as f32 / 8.0))
        .collect();
    let p = BumpParams {
        scale: 2.0,
        v_up: false,
    };
    let o = height_to_offsets(&heights, w, h, &p).expect("ok");
    for y in 0..h as usize {
        for x in 1..7usize {
            assert!((o[y * 8 + x][0] - 0.25).abs() < 1e-6);
            assert_eq!(o[y * 8 + x][1], 0.0);
        }
        // x = 0: (h[1] - h[7]) / 2 * 2 = (1/8 - 7/8)
        assert!((o[y * 8][0] - (0.125 - 0.875)).abs() < 1e-6);
    }
    // Sine along rows: second-order accurate against the analytic derivative.
    let n = 64u32;
    let hs: Vec<f32> = (0..n)
        .flat_map(|y| {
            (0..n).map(move |_| 0.5 + 0.5 * (y as f32 * std::f32::consts::TAU / 64.0).sin())
        })
        .collect();
    for v_up in [false, true] {
        let o = height_to_offsets(&hs, n, n, &BumpParams { scale: 1.0, v_up }).expect("ok");
        for y in 0..n {
            let exact = 0.5
                * (std::f64::consts::TAU / 64.0)
                * (f64::from(y) * std::f64::consts::TAU / 64.0).cos();
            let got = f64::from(o[(y * n + 5) as usize][1]) * if v_up { -1.0 } else { 1.0 };
            assert!(
                (got - exact).abs() < 2e-3 * exact.abs().max(0.01) + 1e-5,
                "y {y}: {got} vs {exact}"
            );
        }
    }
}

#[test]
fn encoding_roundtrip_fixed_decode_and_linearity() {
    let vc = VectorConfig::texram16();
    let enc = OffsetEncoding::for_offset_int_bits(vc.offset_int_bits);
    assert_eq!(enc.range, 8.0);
    let offs: Vec<[f32; 2]> = (0..2000)
        .map(|i| [(i as f32 - 1000.0) / 120.0, -(i as f32) / 300.0])
        .collect();
    let im = offsets_to_image(&offs, 2000, 1, &enc);
    let expect_clamped = offs.iter().flatten().filter(|f| f.abs() > 8.0).count() as u64;
    assert_eq!(im.clamped, expect_clamped);
    let mut sat = SatCounter::default();
    for (o, t) in offs.iter().zip(&im.texels) {
        assert_eq!((t[2], t[3]), (0.0, 1.0));
        for k in 0..2 {
            let dec = enc.decode(t[k]);
            if o[k].abs() < 7.99 {
                assert!((dec - o[k]).abs() < 1e-5);
                // As a 16-bit texel, decoded by the fixed unit: within 1 ulp of s3.12 plus the
                // 1/65535 vs 1/65536 scale difference (<= 2R / 65536).
                let raw = (f64::from(t[k]) * 65535.0).round() as u64;
                let fx = offset_from_texel(raw, 16, &vc, &mut sat) as f64 / 4096.0;
                assert!(
                    (fx - f64::from(o[k])).abs() <= 1.0 / 4096.0 + 16.0 / 65536.0,
                    "{fx} vs {}",
                    o[k]
                );
            }
        }
    }
    // The bilinear average of encoded values decodes to the average offset.
    let (a, b) = (enc.encode(1.5).0, enc.encode(-0.25).0);
    assert!((enc.decode(0.25 * a + 0.75 * b) - (0.25 * 1.5 - 0.75 * 0.25)).abs() < 1e-6);
}

#[test]
fn texture_sources_and_errors() {
    // 8-bit source expanded by 257: heights exact multiples of 1/255.
    let t = img(4, 4, |x, _| [(x * 60 * 257) as u16, 0, 0, 65535]);
    let hs = heights_from_texture(&t, 0).expect("ok");
    assert!((hs[1] - 60.0 / 255.0).abs() < 1e-6);
    let bi = bump_image_from_height(
        &t,
        &BumpParams {
            scale: 1.0,
            v_up: false,
        },
        &OffsetEncoding { range: 8.0 },
    )
    .expect("ok");
    assert_eq!((bi.width, bi.height, bi.texels.len()), (4, 4, 16));
    assert!(heights_from_texture(&t, 4).is_err());
    let bad = height_to_offsets(
        &[0.0; 5],
        2,
        2,
        &BumpParams {
            scale: 1.0,
            v_up: false,
        },
    );
    assert!(bad.expect_err("size").message().contains("bump height map"));
    let nan = height_to_offsets(
        &[0.0; 4],
        2,
        2,
        &BumpParams {
            scale: f32::NAN,
            v_up: false,
        },
    );
    assert!(nan.expect_err("scale").message().contains("bump_scale"));
    assert!(height_to_offsets(
        &[],
        0,
        0,
        &BumpParams {
            scale: 1.0,
            v_up: false
        }
    )
    .is_err());
    let mut broken = t.clone();
    broken.texels.pop();
    assert!(normal_map_to_offsets(&broken, false)
        .expect_err("size")
        .message()
        .contains("test.png"));
}

/// Offsets from a normal map, applied in the unit frame of an orthonormal (T, B, N), give back
/// the map's normal.
#[test]
fn normal_map_roundtrip_through_the_frame() {
    let enc = |c: f64| ((c * 0.5 + 0.5) * 65535.0).round() as u16;
    let normals = [
        DVec3::new(0.3, -0.2, 0.9).normalize(),
        DVec3::new(-0.6, 0.1, 0.5).normalize(),
        DVec3::new(0.0, 0.0, 1.0),
        DVec3::new(0.9, 0.0, 0.01).normalize(),
    ];
    let t = img(4, 1, |x, _| {
        let n = normals[x as usize];
        [enc(n.x), enc(n.y), enc(n.z), 65535]
    });
    let (offs, clamped) = normal_map_to_offsets(&t, false).expect("ok");
    assert_eq!(clamped, 1, "the grazing normal is clamped");
    // A tilted surface frame: T, B, N orthonormal.
    let nn = DVec3::new(0.2, 0.3, 0.9).normalize();
    let tt = (DVec3::X - nn * nn.x).normalize();
    let bb = nn.cross(tt);
    let fr = r::unit_frame(nn, nn.cross(bb), tt.cross(nn), 6);
    for (i, n) in normals.iter().enumerate().take(3) {
        let p = r::perturb_normal(&fr, f64::from(offs[i][0]), f64::from(offs[i][1]));
        let want = (tt * n.x + bb * n.y + nn * n.z).normalize();
        assert!((p - want).length() < 1e-4, "texel {i}: {p} vs {want}");
    }
    let (flipped, _) = normal_map_to_offsets(&t, true).expect("ok");
    assert!((flipped[0][1] + offs[0][1]).abs() < 1e-6);
}
