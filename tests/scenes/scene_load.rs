//! Scene loading: example TOML, OBJ+MTL, built-in catalogue (Mesa anchor geometry and cameras),
//! texture decoding, normals, camera fit, and large-OBJ load time.

use crate::rng_common::Rng;
use crate::tmp_common::TmpDir;
use glam::{DMat4, DVec3, DVec4};
use std::path::{Path, PathBuf};
use texsim::scene::{
    self, builtin, decode_texture, fit_camera, load, load_obj, smooth_normals, validate, Mesh,
    BUILTIN,
};

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
}

#[test]
fn example_toml_loads_everything() {
    let s = load(&scenes_dir().join("example.toml")).unwrap();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    assert_eq!((s.width, s.height), (800, 600));
    assert_eq!(s.name, "example");
    assert_eq!(s.hw.as_deref(), Some("texram16"));
    assert_eq!(s.lights.len(), 2);
    // 3 TOML textures + the cube's map_Kd.
    assert_eq!(s.textures.len(), 4);
    assert_eq!((s.textures[2].width, s.textures[2].height), (64, 64));
    assert_eq!(s.meshes.len(), 4);
    let cube = &s.meshes[3];
    let m = &s.materials[cube.material];
    assert_eq!(m.name, "checker");
    assert_eq!(m.texture, Some(3));
    assert_eq!(cube.indices.len(), 12);
    // scale 0.7, translate (-0.4, 0.35, 2.2): all corners within 0.35*sqrt(3) of the centre.
    for p in &cube.positions {
        let d = DVec3::from(p.map(f64::from)).distance(DVec3::new(-0.4, 0.35, 2.2));
        assert!((d - 0.35 * 3f64.sqrt()).abs() < 1e-5, "{d}");
    }
    validate(&s).unwrap();
    assert_eq!(
        s.materials
            .iter()
            .find(|m| m.name == "floor")
            .unwrap()
            .wrap_t,
        scene::WrapMode::Mirror
    );
}

/// An unknown TOML field answers with the nearest valid name (not serde's list of every
/// field), with the file and line; a name near nothing keeps the list.
#[test]
fn unknown_scene_field_suggests_the_nearest_name() {
    let d = TmpDir::new("unknown_field");
    let p = d.join("typo.toml");
    std::fs::write(&p, "[output]\nwidht = 64\n").unwrap();
    let e = load(&p).unwrap_err().to_string();
    assert!(e.contains("typo.toml"), "{e}");
    assert!(
        e.contains("unknown field `widht`; did you mean 'width'?"),
        "{e}"
    );
    assert!(!e.contains("expected one of"), "{e}");
    std::fs::write(&p, "[output]\nzzzzzz = 64\n").unwrap();
    let e = load(&p).unwrap_err().to_string();
    assert!(e.contains("expected one of"), "{e}");
}

#[test]
fn cube_obj_texture_and_uv_flip() {
    let s = load_obj(&scenes_dir().join("cube.obj")).unwrap();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    assert_eq!((s.width, s.height), (1024, 768));
    assert_eq!(s.triangle_count(), 12);
    let mesh = &s.meshes[0];
    assert_eq!(mesh.uvs.len(), mesh.positions.len());
    // The +z face's vertex (-0.5,-0.5,0.5) had vt (0,0): bottom-left of the image -> t = 1.
    let i = mesh
        .positions
        .iter()
        .position(|p| {
            *p == [-0.5, -0.5, 0.5]
                && mesh.normals[mesh.positions.iter().position(|q| q == p).unwrap()]
                    == [0.0, 0.0, 1.0]
        })
        .unwrap();
    assert_eq!(mesh.uvs[i], [0.0, 1.0]);
    // Texture: red marker at the top-left, decoded x257.
    let t = &s.textures[0];
    assert_eq!(t.texels[0], [220 * 257, 30 * 257, 30 * 257, 65535]);
    assert_eq!(t.texels[63 * 64 + 63], [65535, 65535, 65535, 65535]);
    // Background opaque dark grey, ambient 0.15, one light.
    assert_eq!(s.background[3], 1.0);
    assert_eq!(s.ambient, [0.15; 3]);
    assert_eq!(s.lights.len(), 1);
}

#[test]
fn builtin_catalogue() {
    assert!(BUILTIN.len() >= 3);
    for (name, desc) in BUILTIN {
        assert!(!desc.is_empty());
        let s = builtin(name).unwrap();
        validate(&s).unwrap();
        assert!(s.triangle_count() > 0);
    }
    let e = builtin("nope").unwrap_err().to_string();
    for (name, _) in BUILTIN {
        assert!(e.contains(name), "{e}");
    }
    let d = builtin("demo").unwrap();
    assert_eq!((d.width, d.height), (1024, 768));
    assert!(d.materials.iter().any(|m| m.lit && m.texture.is_some()));
}

fn project(view: DMat4, proj: DMat4, p: [f32; 3]) -> DVec4 {
    proj * view * DVec4::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]), 1.0)
}

#[test]
fn w1_plane_matches_anchor() {
    let s = builtin("w1-plane").unwrap();
    assert_eq!((s.width, s.height), (1024, 1024));
    assert_eq!(s.background, [0.0; 4]);
    let m = &s.meshes[0];
    assert_eq!(
        m.positions,
        vec![
            [-256.0, 0.0, 1.0],
            [256.0, 0.0, 1.0],
            [256.0, 0.0, -511.0],
            [-256.0, 0.0, -511.0]
        ]
    );
    assert_eq!(
        m.uvs,
        vec![[0.0, 0.0], [16.0, 0.0], [16.0, 16.0], [0.0, 16.0]]
    );
    assert_eq!(m.indices, vec![[0, 1, 2], [0, 2, 3]]);
    let mat = &s.materials[m.material];
    assert!(!mat.lit && !mat.cull_back && mat.kd == [1.0; 3] && mat.texture == Some(0));
    // GL modelview written out by hand: Rx(10) * T(0,-1,0).
    let (c, sn) = (10f64.to_radians().cos(), 10f64.to_radians().sin());
    let gl_view = DMat4::from_cols_array(&[
        1.0, 0.0, 0.0, 0.0, 0.0, c, sn, 0.0, 0.0, -sn, c, 0.0, 0.0, -c, -sn, 1.0,
    ]);
    let v = s.camera.view();
    assert!(v.abs_diff_eq(gl_view, 1e-15), "{v:?}");
    // glFrustum(-t, t, -t, t, n, f) with t = n tan 30.
    let (n, f) = (0.1, 1000.0);
    let t = n * 30f64.to_radians().tan();
    let gl_proj = DMat4::from_cols_array(&[
        n / t,
        0.0,
        0.0,
        0.0,
        0.0,
        n / t,
        0.0,
        0.0,
        0.0,
        0.0,
        -(f + n) / (f - n),
        -1.0,
        0.0,
        0.0,
        -2.0 * f * n / (f - n),
        0.0,
    ]);
    assert!(s.camera.projection(1.0).abs_diff_eq(gl_proj, 1e-9));
    assert!((DVec3::from(s.camera.eye) - DVec3::new(0.0, 1.0, 0.0)).length() < 1e-12);
}

#[test]
fn w2_mesh_matches_anchor() {
    let s = builtin("w2-mesh").unwrap();
    let m = &s.meshes[0];
    assert_eq!(m.positions.len(), 33153);
    assert_eq!(m.indices.len(), 65536);
    // Vertex (i, j) at i*(NV+1)+j, computed as in the C source (double, then float).
    for &(i, j) in &[(0u32, 0u32), (1, 0), (17, 99), (256, 128), (128, 64)] {
        let (u, a) = (
            2.0 * std::f64::consts::PI * f64::from(i) / 256.0,
            2.0 * std::f64::consts::PI * f64::from(j) / 128.0,
        );
        let k = (i * 129 + j) as usize;
        // `const float r = 0.4f` promoted to double, as in C.
        let r = f64::from(0.4f32);
        let want = [
            ((1.0 + r * a.cos()) * u.cos()) as f32,
            ((1.0 + r * a.cos()) * u.sin()) as f32,
            (r * a.sin()) as f32,
        ];
        assert_eq!(m.positions[k], want);
        assert_eq!(
            m.uvs[k],
            [2.0f32 * i as f32 / 256.0, 1.0f32 * j as f32 / 128.0]
        );
    }
    // Index order: quad (i, j) -> (a,b,c), (a,c,d).
    let (i, j) = (3u32, 5u32);
    let q = ((i * 128 + j) * 2) as usize;
    let (a, b, c, d) = (
        i * 129 + j,
        (i + 1) * 129 + j,
        (i + 1) * 129 + j + 1,
        i * 129 + j + 1,
    );
    assert_eq!(m.indices[q], [a, b, c]);
    assert_eq!(m.indices[q + 1], [a, c, d]);
    let mat = &s.materials[0];
    assert!(!mat.cull_back && !mat.lit);
    // Modelview: T(0,0,-3.2) Rx(-50) Rz(20); the torus centre maps to (0,0,-3.2).
    let o = s.camera.view().transform_point3(DVec3::ZERO);
    assert!((o - DVec3::new(0.0, 0.0, -3.2)).length() < 1e-12);
    let x = s.camera.view().transform_vector3(DVec3::X);
    let (c20, s20) = (20f64.to_radians().cos(), 20f64.to_radians().sin());
    let (c50, s50) = (50f64.to_radians().cos(), (-50f64).to_radians().sin());
    // Rx(-50) * (c20, s20, 0) = (c20, s20 c50, s20 sin(-50)).
    assert!((x - DVec3::new(c20, s20 * c50, s20 * s50)).length() < 1e-12);
    assert_eq!(s.camera.fov_y_deg, 45.0);
    assert_eq!((s.camera.near, s.camera.far), (1.0, 10.0));
    // Torus is in front of the camera, inside the far plane.
    for p in m.positions.iter().step_by(97) {
        let c = project(s.camera.view(), s.camera.projection(1.0), *p);
        assert!(c.w > 1.0 && c.w < 10.0);
    }
}

#[test]
fn smooth_normals_area_weighted() {
    // Two triangles sharing vertex 0: one in the XY plane (area 2), one in XZ (area 0.5).
    let pos = [
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [0.0, 2.0, 0.0],
        [0.0, 0.0, -1.0],
        [1.0, 0.0, 0.0],
    ];
    let idx = [[0, 1, 2], [0, 3, 4]];
    let n = smooth_normals(&pos, &idx);
    // Face normals (un-normalized): (0,0,4) and (0,1,0)*... compute: (p3-p0)x(p4-p0) = (0,0,-1)x(1,0,0) = (0,-1,0).
    let want = DVec3::new(0.0, -1.0, 4.0).normalize();
    assert!(
        (DVec3::from(n[0].map(f64::from)) - want).length() < 1e-6,
        "{:?}",
        n[0]
    );
    assert_eq!(n[1], [0.0, 0.0, 1.0]);
    assert_eq!(n[3], [0.0, -1.0, 0.0]);
    // Degenerate and unused vertices get the fallback, never NaN.
    let n = smooth_normals(&[[1.0, 1.0, 1.0]; 3], &[[0, 1, 2], [0, 1, 9]]);
    assert!(n.iter().all(|v| *v == scene::FALLBACK_NORMAL));
    let n = smooth_normals(
        &[[f32::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        &[[0, 1, 2]],
    );
    assert!(n.iter().flatten().all(|c| c.is_finite()));
}

#[test]
fn fit_camera_contains_random_meshes() {
    let mut rng = Rng(11);
    for case in 0..200 {
        let c = DVec3::new(
            rng.unit() * 200.0 - 100.0,
            rng.unit() * 200.0 - 100.0,
            rng.unit() * 200.0 - 100.0,
        );
        let scale = 10f64.powf(rng.unit() * 6.0 - 3.0);
        let pos: Vec<[f32; 3]> = (0..50)
            .map(|_| {
                let p = c + DVec3::new(rng.unit() - 0.5, rng.unit() - 0.5, rng.unit() - 0.5)
                    * scale
                    * 2.0;
                [p.x as f32, p.y as f32, p.z as f32]
            })
            .collect();
        let mesh = Mesh {
            positions: pos.clone(),
            ..Mesh::default()
        };
        let (w, h) = if case % 2 == 0 {
            (1024, 768)
        } else {
            (300, 900)
        };
        let cam = fit_camera(&[mesh], w, h);
        assert!(cam.near > 0.0 && cam.far > cam.near);
        let (view, proj) = (cam.view(), cam.projection(f64::from(w) / f64::from(h)));
        for p in &pos {
            let q = project(view, proj, *p);
            assert!(q.w > 0.0);
            let ndc = q.truncate() / q.w;
            assert!(
                ndc.x.abs() < 0.99 && ndc.y.abs() < 0.99,
                "case {case}: {ndc:?}"
            );
            assert!(ndc.z > -1.0 && ndc.z < 1.0, "case {case}: {ndc:?}");
        }
    }
}

#[test]
fn decode_png_formats() {
    let dir = TmpDir::new("png");
    let p8 = dir.join("rgba8.png");
    image::RgbaImage::from_fn(3, 2, |x, y| {
        image::Rgba([x as u8 * 100, y as u8 * 200, 7, 128])
    })
    .save(&p8)
    .unwrap();
    let t = decode_texture(&p8).unwrap();
    assert_eq!((t.width, t.height), (3, 2));
    assert_eq!(t.texels[5], [200 * 257, 200 * 257, 7 * 257, 128 * 257]);
    let p16 = dir.join("gray16.png");
    image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_fn(2, 2, |x, y| {
        image::Luma([(x * 30000 + y * 1234 + 1) as u16])
    })
    .save(&p16)
    .unwrap();
    let t = decode_texture(&p16).unwrap();
    assert_eq!(t.texels[3], [31235, 31235, 31235, 65535]);
    let pga = dir.join("ga8.png");
    image::ImageBuffer::<image::LumaA<u8>, Vec<u8>>::from_fn(1, 1, |_, _| image::LumaA([9, 10]))
        .save(&pga)
        .unwrap();
    assert_eq!(
        decode_texture(&pga).unwrap().texels[0],
        [9 * 257, 9 * 257, 9 * 257, 10 * 257]
    );
    let prgb16 = dir.join("rgb16.png");
    image::ImageBuffer::<image::Rgb<u16>, Vec<u16>>::from_fn(1, 1, |_, _| {
        image::Rgb([1, 65534, 40000])
    })
    .save(&prgb16)
    .unwrap();
    assert_eq!(
        decode_texture(&prgb16).unwrap().texels[0],
        [1, 65534, 40000, 65535]
    );
    let pj = dir.join("rgb.jpg");
    image::RgbImage::from_fn(16, 8, |_, _| image::Rgb([128, 128, 128]))
        .save(&pj)
        .unwrap();
    let t = decode_texture(&pj).unwrap();
    assert_eq!((t.width, t.height), (16, 8));
    assert!(t
        .texels
        .iter()
        .all(|p| p[3] == 65535 && p[0] % 257 == 0 && (i32::from(p[0] / 257) - 128).abs() <= 2));
}

#[test]
fn large_obj_loads_fast() {
    // 225 x 225 grid = 101,250 triangles, with vt and vn, written as quads.
    let dir = TmpDir::new("big");
    let path = dir.join("big.obj");
    let n = 226usize;
    let mut s = String::with_capacity(n * n * 60);
    for y in 0..n {
        for x in 0..n {
            let h = ((x as f32 * 0.1).sin() * (y as f32 * 0.07).cos()) * 3.0;
            s.push_str(&format!(
                "v {x} {h} {y}\nvt {} {}\n",
                x as f32 / (n - 1) as f32,
                y as f32 / (n - 1) as f32
            ));
        }
    }
    for y in 0..n - 1 {
        for x in 0..n - 1 {
            let a = y * n + x + 1;
            let (b, c, d) = (a + 1, a + n + 1, a + n);
            s.push_str(&format!("f {a}/{a} {b}/{b} {c}/{c} {d}/{d}\n"));
        }
    }
    std::fs::write(&path, s).unwrap();
    let t0 = std::time::Instant::now();
    let scene = load_obj(&path).unwrap();
    let dt = t0.elapsed();
    assert_eq!(scene.triangle_count(), 2 * (n - 1) * (n - 1));
    assert!(scene.meshes[0]
        .normals
        .iter()
        .flatten()
        .all(|c| c.is_finite()));
    eprintln!(
        "loaded {} triangles in {:.1} ms",
        scene.triangle_count(),
        dt.as_secs_f64() * 1e3
    );
    assert!(dt.as_secs_f64() < 2.0, "{dt:?}");
}
