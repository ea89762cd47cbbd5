//! Environment-map keys of TOML scenes (`env_map`, `env_filter`, `env_size`) and their errors
//! (the field named, never a panic); a TOML scene with an environment map renders with
//! `env-fetch`.

use crate::tmp_common::TmpFile;
use hw_model::env_config::EnvFilter;
use texsim::pipeline::StageKind;
use texsim::render::{render, Maps, RenderOptions};
use texsim::scene;

#[track_caller]
fn write(name: &str, body: &str) -> TmpFile {
    TmpFile::new(name, "s.toml", body)
}

fn with_material(fields: &str) -> String {
    format!(
        "[output]\nwidth = 48\nheight = 36\n\n[[textures]]\nname = \"r\"\nprocedural = \"ripples-height\"\nsize = 64\n\n[[materials]]\nname = \"m\"\nbump = \"r\"\nroughness = \"hw\"\n{fields}\n\n[[meshes]]\nshape = \"sphere\"\nmaterial = \"m\"\n"
    )
}

#[test]
fn env_keys_parse_and_render() {
    let p = write(
        "ok",
        &with_material(
            "env_map = \"sky\"\nenv_filter = \"ellipse\"\nenv_size = 16\nks = [0.8, 0.8, 0.8]",
        ),
    );
    let s = scene::load(&p).expect("load");
    let e = s.materials[0].env.expect("env");
    assert_eq!((e.filter, e.size), (Some(EnvFilter::Ellipse), 16));
    let hw = hw_model::HwConfig::texram16();
    let maps = Maps::new(&s, hw.trilinear.texel_bits);
    let r = render(&s, &maps, &hw, &RenderOptions::default()).expect("render");
    let st = r
        .stats
        .stages
        .iter()
        .find(|x| x.stage == StageKind::EnvFetch)
        .expect("env-fetch row");
    assert_eq!(st.invocations, r.stats.covered_pixels);
    assert!(st.invocations > 0);
    // Defaults: the hardware's filter, 256 texels per face.
    let s = scene::load(&write("def", &with_material("env_map = \"sky\""))).expect("load");
    let e = s.materials[0].env.expect("env");
    assert_eq!((e.filter, e.size), (None, 256));
}

#[test]
fn bad_env_keys_are_errors_naming_the_field() {
    for (fields, needle) in [
        ("env_map = \"sunset.hdr\"", "env_map"),
        ("env_map = \"sky\"\nenv_filter = \"gauss\"", "env_filter"),
        ("env_map = \"sky\"\nenv_size = 100", "env_size"),
        ("env_map = \"sky\"\nenv_size = 4096", "env_size"),
        ("env_filter = \"none\"", "env_map"),
    ] {
        let p = write("bad", &with_material(fields));
        let e = scene::load(&p).expect_err(fields).to_string();
        assert!(e.contains(needle), "{fields}: {e}");
    }
}

/// Writes `t` (RGBA16) as a 16-bit PNG.
fn write_png16(path: &std::path::Path, w: u32, h: u32, px: &[[u16; 4]]) {
    let flat: Vec<u16> = px.iter().flatten().copied().collect();
    let img = image::ImageBuffer::<image::Rgba<u16>, _>::from_raw(w, h, flat).expect("buffer");
    img.save(path).expect("png");
}

/// The procedural sky's cube at `n` texels per face, level 0, quantized to 16 bits.
fn sky_faces(n: u32) -> Vec<Vec<[u16; 4]>> {
    texsim::maps::cube::cube_chains(n, &texsim::shading::env::sky_f)
        .iter()
        .map(|c| {
            c.levels[0]
                .texels
                .iter()
                .map(|t| t.map(|v| (f64::from(v) * 65535.0).round() as u16))
                .collect()
        })
        .collect()
}

/// The level-0 faces a loaded scene's environment source builds, back in 16 bits.
fn loaded_faces(s: &scene::Scene, n: u32) -> Vec<Vec<[u16; 4]>> {
    let e = s.materials[0].env.expect("env");
    assert_eq!(e.size, n);
    let f = texsim::maps::cube::env_sampler(e.source, &s.textures);
    texsim::maps::cube::cube_chains(n, &*f)
        .iter()
        .map(|c| {
            c.levels[0]
                .texels
                .iter()
                .map(|t| t.map(|v| (f64::from(v) * 65535.0).round() as u16))
                .collect()
        })
        .collect()
}

/// Six face files and one horizontal-cross file give back the faces they hold, texel for
/// texel; an equirectangular image maps its top row to +Y and its bottom row to -Y, and a
/// scene with it renders `env-fetch`.
#[test]
fn env_images_load_as_cubes() {
    let n = 8u32;
    let faces = sky_faces(n);
    let p = write("faces", "");
    let dir = p.parent().unwrap().to_path_buf();
    let names = ["px", "nx", "py", "ny", "pz", "nz"];
    for (f, name) in faces.iter().zip(names) {
        write_png16(&dir.join(format!("{name}.png")), n, n, f);
    }
    let list: Vec<String> = names.iter().map(|n| format!("\"{n}.png\"")).collect();
    std::fs::write(
        &p,
        with_material(&format!(
            "env_map = [{}]\nks = [0.8, 0.8, 0.8]",
            list.join(", ")
        )),
    )
    .unwrap();
    let s = scene::load(&p).expect("six faces");
    assert!(matches!(
        s.materials[0].env.unwrap().source,
        scene::EnvSource::Faces(_)
    ));
    assert_eq!(loaded_faces(&s, n), faces);

    // The same faces as one horizontal cross (4n x 3n).
    let cell = [(2u32, 1u32), (0, 1), (1, 0), (1, 2), (1, 1), (3, 1)];
    let mut cross = vec![[0u16, 0, 0, 65535]; (4 * n * 3 * n) as usize];
    for (f, &(cx, cy)) in faces.iter().zip(&cell) {
        for y in 0..n {
            for x in 0..n {
                cross[((cy * n + y) * 4 * n + cx * n + x) as usize] = f[(y * n + x) as usize];
            }
        }
    }
    write_png16(&dir.join("cross.png"), 4 * n, 3 * n, &cross);
    std::fs::write(&p, with_material("env_map = \"cross.png\"")).unwrap();
    let s = scene::load(&p).expect("cross");
    assert_eq!(loaded_faces(&s, n), faces);

    // Equirectangular: white sky above the horizon, black below.
    let (w, h) = (32u32, 16u32);
    let eq: Vec<[u16; 4]> = (0..w * h)
        .map(|i| {
            let v = if i / w < h / 2 { 65535 } else { 0 };
            [v, v, v, 65535]
        })
        .collect();
    write_png16(&dir.join("eq.png"), w, h, &eq);
    std::fs::write(
        &p,
        with_material("env_map = \"eq.png\"\nenv_size = 16\nks = [0.8, 0.8, 0.8]"),
    )
    .unwrap();
    let s = scene::load(&p).expect("equirect");
    let e = s.materials[0].env.unwrap();
    assert!(matches!(e.source, scene::EnvSource::Equirect(_)));
    let f = texsim::maps::cube::env_sampler(e.source, &s.textures);
    assert_eq!(f(glam::DVec3::Y), [1.0; 3]);
    assert_eq!(f(-glam::DVec3::Y), [0.0; 3]);
    let hw = hw_model::HwConfig::texram16();
    let maps = Maps::new(&s, hw.trilinear.texel_bits);
    let r = render(&s, &maps, &hw, &RenderOptions::default()).expect("render");
    let st = r
        .stats
        .stages
        .iter()
        .find(|x| x.stage == StageKind::EnvFetch)
        .expect("env-fetch row");
    assert_eq!(st.invocations, r.stats.covered_pixels);
}

/// Bad environment images are errors naming the field and saying what is wrong.
#[test]
fn bad_env_images_name_the_field() {
    let p = write("badimg", "");
    let dir = p.parent().unwrap().to_path_buf();
    let solid = |w: u32, h: u32| vec![[30000u16, 20000, 10000, 65535]; (w * h) as usize];
    write_png16(&dir.join("wide.png"), 6, 2, &solid(6, 2));
    write_png16(&dir.join("f4.png"), 4, 4, &solid(4, 4));
    write_png16(&dir.join("f8.png"), 8, 8, &solid(8, 8));
    write_png16(&dir.join("f3.png"), 3, 3, &solid(3, 3));
    write_png16(&dir.join("rect.png"), 4, 2, &solid(4, 2));
    let six = |files: [&str; 6]| {
        let l: Vec<String> = files.iter().map(|f| format!("\"{f}\"")).collect();
        format!("env_map = [{}]", l.join(", "))
    };
    for (fields, needles) in [
        (
            "env_map = \"wide.png\"".to_string(),
            vec!["env_map", "6x2", "equirectangular"],
        ),
        (
            "env_map = \"missing.png\"".to_string(),
            vec!["env_map", "missing.png"],
        ),
        (
            "env_map = [\"f4.png\", \"f4.png\"]".to_string(),
            vec!["env_map", "six faces"],
        ),
        (
            six(["f4.png", "f4.png", "f8.png", "f4.png", "f4.png", "f4.png"]),
            vec!["env_map", "one size"],
        ),
        (six(["f3.png"; 6]), vec!["env_map", "power of two"]),
        (six(["rect.png"; 6]), vec!["env_map", "square"]),
        (
            format!("{}\nenv_size = 8", six(["f4.png"; 6])),
            vec!["env_size", "4x4"],
        ),
    ] {
        std::fs::write(&p, with_material(&fields)).unwrap();
        let e = scene::load(&p).expect_err(&fields).to_string();
        for n in needles {
            assert!(e.contains(n), "{fields}: {e}");
        }
    }
}
