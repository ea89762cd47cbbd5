//! Bad user input: every case returns an Error naming the file or field, never panics; soft
//! problems (missing MTL, missing/undecodable map_Kd, no UVs) become warnings.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use texsim::scene::{load, load_obj, load_toml, Scene};
use texsim::Result;

static COUNTER: AtomicUsize = AtomicUsize::new(0);

fn temp_dir(tag: &str) -> PathBuf {
    let n = COUNTER.fetch_add(1, Ordering::SeqCst);
    let d = std::env::temp_dir().join(format!("texsim_bad_input_{}_{tag}_{n}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn write(dir: &Path, name: &str, text: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

const TRI: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

/// Runs `f` under catch_unwind (proving no panic) and returns its error text.
fn expect_err(
    f: impl FnOnce() -> Result<Scene> + std::panic::UnwindSafe,
    must_contain: &[&str],
) -> String {
    let r = std::panic::catch_unwind(f).expect("loader panicked");
    let e = match r {
        Ok(s) => panic!(
            "expected an error, got a scene with {} triangles",
            s.triangle_count()
        ),
        Err(e) => e.to_string(),
    };
    for m in must_contain {
        assert!(e.contains(m), "error '{e}' should mention '{m}'");
    }
    e
}

#[test]
fn missing_file_and_directory() {
    let dir = temp_dir("missing");
    let p = dir.join("nope.obj");
    expect_err(move || load(&p), &["nope.obj"]);
    let p = dir.join("nope.toml");
    expect_err(move || load_toml(&p), &["nope.toml"]);
    let d = dir.join("adir.obj");
    std::fs::create_dir_all(&d).unwrap();
    expect_err(move || load_obj(&d), &["adir.obj", "directory"]);
    let d = dir.join("tdir.toml");
    std::fs::create_dir_all(&d).unwrap();
    expect_err(move || load(&d), &["tdir.toml", "directory"]);
    let p = write(&dir, "scene.dae", b"<xml/>");
    expect_err(move || load(&p), &["scene.dae"]);
}

#[test]
fn malformed_and_empty_obj() {
    let dir = temp_dir("obj");
    let p = write(&dir, "bad.obj", b"v 0 0 zero\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    expect_err(move || load_obj(&p), &["bad.obj", "line 1"]);
    let p = write(&dir, "badface.obj", format!("{TRI}f 1 2 x\n").as_bytes());
    expect_err(move || load_obj(&p), &["badface.obj", "line 4"]);
    let p = write(&dir, "empty.obj", b"");
    expect_err(move || load_obj(&p), &["empty.obj", "no triangles"]);
    let p = write(&dir, "points.obj", format!("{TRI}p 1\nl 1 2\n").as_bytes());
    expect_err(move || load_obj(&p), &["points.obj", "no triangles"]);
    let p = write(&dir, "range.obj", format!("{TRI}f 1 2 7\n").as_bytes());
    expect_err(move || load_obj(&p), &["range.obj", "line 4"]);
    let p = write(&dir, "zero.obj", format!("{TRI}f 0 1 2\n").as_bytes());
    expect_err(move || load_obj(&p), &["zero.obj"]);
    let p = write(&dir, "neg.obj", format!("{TRI}f -1 -2 -9\n").as_bytes());
    expect_err(move || load_obj(&p), &["neg.obj"]);
    let p = write(
        &dir,
        "vtrange.obj",
        format!("{TRI}vt 0 0\nf 1/1 2/5 3/1\n").as_bytes(),
    );
    expect_err(move || load_obj(&p), &["vtrange.obj", "line 5"]);
    let p = write(&dir, "binary.obj", &[0xff, 0xfe, 0x00, 0x80, 0x10, 0x0a]);
    expect_err(move || load_obj(&p), &["binary.obj"]);
}

#[test]
fn non_finite_vertex_names_file_and_index() {
    let dir = temp_dir("nan");
    let p = write(
        &dir,
        "nan.obj",
        b"# comment\nv 0 0 0\nv 1 NaN 0\nv 0 1 0\nf 1 2 3\n",
    );
    expect_err(move || load_obj(&p), &["nan.obj", "vertex 2", "line 3"]);
    let p = write(&dir, "inf.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 inf\nf 1 2 3\n");
    expect_err(move || load_obj(&p), &["inf.obj", "vertex 3"]);
}

#[test]
fn mtl_problems() {
    let dir = temp_dir("mtl");
    // Malformed MTL: error naming the MTL file and line.
    write(&dir, "bad.mtl", b"newmtl a\nKd 1 zero 0\n");
    let p = write(
        &dir,
        "badmtl.obj",
        format!("mtllib bad.mtl\n{TRI}usemtl a\nf 1 2 3\n").as_bytes(),
    );
    expect_err(move || load_obj(&p), &["bad.mtl", "line 2", "Kd"]);
    // A Kd with two values (tobj itself would panic on this).
    write(&dir, "short.mtl", b"newmtl a\nKd 1 0\n");
    let p = write(
        &dir,
        "shortmtl.obj",
        format!("mtllib short.mtl\n{TRI}usemtl a\nf 1 2 3\n").as_bytes(),
    );
    expect_err(move || load_obj(&p), &["short.mtl"]);
    // Missing MTL: a warning and the default material.
    let p = write(
        &dir,
        "nomtl.obj",
        format!("mtllib missing.mtl\n{TRI}usemtl a\nf 1 2 3\n").as_bytes(),
    );
    let s = load_obj(&p).unwrap();
    assert!(
        s.warnings.iter().any(|w| w.contains("missing.mtl")),
        "{:?}",
        s.warnings
    );
    assert_eq!(s.materials[s.meshes[0].material].name, "default");
}

#[test]
fn texture_problems_are_warnings_in_obj() {
    let dir = temp_dir("tex");
    write(&dir, "garbage.png", b"this is not a png at all");
    write(
        &dir,
        "m.mtl",
        b"newmtl gone\nKd 0.5 0.25 1\nmap_Kd -s 2 2 1 missing.png\nnewmtl junk\nKd 0.1 0.2 0.3\nmap_Kd garbage.png\n",
    );
    let body = format!("mtllib m.mtl\n{TRI}vt 0 0\nvt 1 0\nvt 0 1\nusemtl gone\nf 1/1 2/2 3/3\nusemtl junk\nf 1/1 3/3 2/2\n");
    let p = write(&dir, "tex.obj", body.as_bytes());
    let s = std::panic::catch_unwind(|| load_obj(&p)).unwrap().unwrap();
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("missing.png") && w.contains("gone")),
        "{:?}",
        s.warnings
    );
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("garbage.png") && w.contains("junk")),
        "{:?}",
        s.warnings
    );
    assert!(s.textures.is_empty());
    let kds: Vec<[f32; 3]> = s
        .meshes
        .iter()
        .map(|m| s.materials[m.material].kd)
        .collect();
    assert!(kds.contains(&[0.5, 0.25, 1.0]) && kds.contains(&[0.1, 0.2, 0.3]));
    assert!(s.materials.iter().all(|m| m.texture.is_none()));
}

#[test]
fn map_kd_options_spaces_and_backslashes() {
    let dir = temp_dir("mapkd");
    std::fs::create_dir_all(dir.join("sub dir")).unwrap();
    image::RgbaImage::from_pixel(2, 2, image::Rgba([1, 2, 3, 255]))
        .save(dir.join("sub dir").join("my tex.png"))
        .unwrap();
    image::RgbaImage::from_pixel(1, 1, image::Rgba([9, 9, 9, 255]))
        .save(dir.join("sub dir").join("b.png"))
        .unwrap();
    write(
        &dir,
        "m.mtl",
        b"newmtl a\nmap_Kd -clamp on -s 1 1 1 sub dir/my tex.png\nnewmtl b\nmap_Kd sub dir\\b.png\n",
    );
    let body = format!("mtllib m.mtl\n{TRI}vt 0 0\nvt 1 0\nvt 0 1\nusemtl a\nf 1/1 2/2 3/3\nusemtl b\nf 1/1 3/3 2/2\n");
    let p = write(&dir, "o.obj", body.as_bytes());
    let s = load_obj(&p).unwrap();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    assert_eq!(s.textures.len(), 2);
    let a = s.materials.iter().find(|m| m.name == "a").unwrap();
    assert_eq!(a.wrap_s, texsim::scene::WrapMode::ClampToEdge);
    assert_eq!(
        s.textures[a.texture.unwrap()].texels[0],
        [257, 514, 771, 65535]
    );
}

#[test]
fn textured_material_without_uvs_warns() {
    let dir = temp_dir("nouv");
    image::RgbaImage::from_pixel(2, 2, image::Rgba([1, 2, 3, 255]))
        .save(dir.join("t.png"))
        .unwrap();
    write(&dir, "m.mtl", b"newmtl t\nmap_Kd t.png\n");
    let p = write(
        &dir,
        "nouv.obj",
        format!("mtllib m.mtl\n{TRI}usemtl t\nf 1 2 3\n").as_bytes(),
    );
    let s = load_obj(&p).unwrap();
    assert!(
        s.warnings.iter().any(|w| w.contains("texture coordinates")),
        "{:?}",
        s.warnings
    );
    assert_eq!(s.materials[s.meshes[0].material].texture, None);
}

#[test]
fn obj_without_normals_or_uvs_gets_finite_normals() {
    let dir = temp_dir("plain");
    // A tetrahedron plus a degenerate triangle, no vn, no vt.
    let p = write(&dir, "tet.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 5 5 5\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\nf 5 5 5\n");
    let s = load_obj(&p).unwrap();
    let m = &s.meshes[0];
    assert!(m.uvs.is_empty());
    assert_eq!(m.normals.len(), m.positions.len());
    for n in &m.normals {
        assert!(n.iter().all(|c| c.is_finite()));
        let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!((l - 1.0).abs() < 1e-5);
    }
    // Vertex 4 (1,0,0)... the normal at (0,0,0) points away from the solid: (-1,-1,-1)/sqrt3.
    let i0 = m
        .positions
        .iter()
        .position(|p| *p == [0.0, 0.0, 0.0])
        .unwrap();
    for c in m.normals[i0] {
        assert!((c + 1.0 / 3f32.sqrt()).abs() < 1e-5, "{:?}", m.normals[i0]);
    }
}

const GOOD_MESH: &str = "[[meshes]]\nshape = \"cube\"\n";

#[test]
fn toml_errors_name_file_and_field() {
    let dir = temp_dir("toml");
    let p = write(&dir, "syntax.toml", b"[output\nwidth = 3\n");
    expect_err(move || load_toml(&p), &["syntax.toml", "line 1"]);
    let p = write(
        &dir,
        "unknown.toml",
        format!("[output]\nwidht = 640\n{GOOD_MESH}").as_bytes(),
    );
    expect_err(move || load_toml(&p), &["unknown.toml", "widht"]);
    let p = write(
        &dir,
        "type.toml",
        format!("[output]\nwidth = \"wide\"\n{GOOD_MESH}").as_bytes(),
    );
    expect_err(move || load_toml(&p), &["type.toml", "width"]);
    let p = write(
        &dir,
        "w0.toml",
        format!("[output]\nwidth = 0\n{GOOD_MESH}").as_bytes(),
    );
    expect_err(move || load_toml(&p), &["w0.toml", "width"]);
    let p = write(
        &dir,
        "wbig.toml",
        format!("[output]\nheight = 100000\n{GOOD_MESH}").as_bytes(),
    );
    expect_err(move || load_toml(&p), &["wbig.toml", "height"]);
    let p = write(
        &dir,
        "neg.toml",
        format!("[output]\nwidth = -5\n{GOOD_MESH}").as_bytes(),
    );
    expect_err(move || load_toml(&p), &["neg.toml", "width"]);
    let p = write(&dir, "nomesh.toml", b"ambient = [0.1, 0.1, 0.1]\n");
    expect_err(move || load_toml(&p), &["nomesh.toml", "meshes"]);
    let p = write(&dir, "shape.toml", b"[[meshes]]\nshape = \"teapot\"\n");
    expect_err(move || load_toml(&p), &["shape.toml", "shape", "teapot"]);
    let p = write(
        &dir,
        "param.toml",
        b"[[meshes]]\nshape = \"cube\"\nradius = 2.0\n",
    );
    expect_err(move || load_toml(&p), &["param.toml", "radius"]);
    let p = write(
        &dir,
        "mat.toml",
        b"[[meshes]]\nshape = \"cube\"\nmaterial = \"gold\"\n",
    );
    expect_err(move || load_toml(&p), &["mat.toml", "material", "gold"]);
    let p = write(
        &dir,
        "wrap.toml",
        format!("[[materials]]\nname = \"m\"\nwrap_s = \"clamp\"\n{GOOD_MESH}").as_bytes(),
    );
    expect_err(move || load_toml(&p), &["wrap.toml", "clamp"]);
    let p = write(
        &dir,
        "cam.toml",
        format!("[camera]\neye = [0, 0, 5]\n{GOOD_MESH}").as_bytes(),
    );
    expect_err(move || load_toml(&p), &["cam.toml", "camera.target"]);
    let p = write(
        &dir,
        "camfit.toml",
        format!("[camera]\nfit = true\nnear = 0.1\n{GOOD_MESH}").as_bytes(),
    );
    expect_err(move || load_toml(&p), &["camfit.toml", "camera.near"]);
    let p = write(
        &dir,
        "near.toml",
        format!("[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\nnear = 0.0\n{GOOD_MESH}")
            .as_bytes(),
    );
    expect_err(move || load_toml(&p), &["near.toml", "near"]);
    let p = write(
        &dir,
        "light.toml",
        format!("[[lights]]\nkind = \"spot\"\n{GOOD_MESH}").as_bytes(),
    );
    expect_err(move || load_toml(&p), &["light.toml", "spot"]);
    let p = write(
        &dir,
        "ldir.toml",
        format!("[[lights]]\nkind = \"directional\"\n{GOOD_MESH}").as_bytes(),
    );
    expect_err(move || load_toml(&p), &["ldir.toml", "direction"]);
    let p = write(
        &dir,
        "proc.toml",
        format!("[[textures]]\nname = \"t\"\nprocedural = \"marble\"\n{GOOD_MESH}").as_bytes(),
    );
    expect_err(move || load_toml(&p), &["proc.toml", "marble"]);
    let p = write(
        &dir,
        "size.toml",
        format!("[[textures]]\nname = \"t\"\nprocedural = \"checker\"\nsize = 0\n{GOOD_MESH}")
            .as_bytes(),
    );
    expect_err(move || load_toml(&p), &["size.toml", "size"]);
    let p = write(
        &dir,
        "seg.toml",
        b"[[meshes]]\nshape = \"sphere\"\nsegments = 1000000\n",
    );
    expect_err(move || load_toml(&p), &["seg.toml", "segments"]);
    let p = write(
        &dir,
        "scale.toml",
        b"[[meshes]]\nshape = \"cube\"\nscale = 1e308\ntranslate = [1e308, 0, 0]\n",
    );
    expect_err(move || load_toml(&p), &["scale.toml"]);
    let p = write(&dir, "objmiss.toml", b"[[meshes]]\nobj = \"nothere.obj\"\n");
    expect_err(move || load_toml(&p), &["objmiss.toml", "nothere.obj"]);
}

#[test]
fn toml_texture_files_are_strict() {
    let dir = temp_dir("ttex");
    write(&dir, "garbage.png", b"\x89PNG\r\n\x1a\nnot really");
    let p = write(
        &dir,
        "g.toml",
        format!("[[textures]]\nname = \"t\"\nfile = \"garbage.png\"\n{GOOD_MESH}").as_bytes(),
    );
    expect_err(move || load_toml(&p), &["g.toml", "garbage.png"]);
    let p = write(
        &dir,
        "m.toml",
        format!("[[textures]]\nname = \"t\"\nfile = \"missing.png\"\n{GOOD_MESH}").as_bytes(),
    );
    expect_err(move || load_toml(&p), &["m.toml", "missing.png"]);
    let p = write(
        &dir,
        "both.toml",
        format!(
            "[[textures]]\nname = \"t\"\nfile = \"a.png\"\nprocedural = \"checker\"\n{GOOD_MESH}"
        )
        .as_bytes(),
    );
    expect_err(move || load_toml(&p), &["both.toml", "textures[0]"]);
    let p = write(
        &dir,
        "texname.toml",
        format!("[[materials]]\nname = \"m\"\ntexture = \"nope\"\n{GOOD_MESH}").as_bytes(),
    );
    expect_err(move || load_toml(&p), &["texname.toml", "texture", "nope"]);
}

#[test]
fn toml_minimal_and_hw_path() {
    let dir = temp_dir("min");
    let p = write(
        &dir,
        "min.toml",
        format!("hw = \"cfg/my_hw.toml\"\n{GOOD_MESH}").as_bytes(),
    );
    let s = load_toml(&p).unwrap();
    assert_eq!((s.width, s.height), (1024, 768));
    let hw = s.hw.unwrap();
    assert!(
        Path::new(&hw).is_absolute() && hw.ends_with("my_hw.toml"),
        "{hw}"
    );
    assert_eq!(s.lights.len(), 1);
}

#[test]
fn random_garbage_never_panics() {
    // Seeded byte soup built from OBJ/MTL/TOML tokens.
    let mut state = 0x1234_5678_9abc_def0u64;
    let mut next = || {
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    };
    let obj_toks = [
        "v", "vt", "vn", "f", "o", "g", "usemtl", "mtllib", "1", "-1", "0", "2/3", "1//2", "nan",
        "1e40", "\n", " ", "#", "/", "m.mtl", "3", "-7", "0.5",
    ];
    let toml_toks = [
        "[output]",
        "[[meshes]]",
        "shape",
        "=",
        "\"cube\"",
        "\"sphere\"",
        "width",
        "segments",
        "3",
        "0",
        "[",
        "]",
        "\n",
        "radius",
        "-1.0",
        "\"",
        "[[lights]]",
        "kind",
        "\"point\"",
        ",",
        "1e999",
    ];
    let dir = temp_dir("fuzz");
    write(&dir, "m.mtl", b"newmtl a\nKd 1 1 1\nmap_Kd nothing.png\n");
    for i in 0..300 {
        let (toks, ext): (&[&str], &str) = if i % 2 == 0 {
            (&obj_toks, "obj")
        } else {
            (&toml_toks, "toml")
        };
        let mut s = String::new();
        for _ in 0..(next() % 60) {
            s.push_str(toks[(next() % toks.len() as u64) as usize]);
            s.push(' ');
        }
        let p = write(&dir, &format!("f{i}.{ext}"), s.as_bytes());
        let r = std::panic::catch_unwind(|| load(&p));
        assert!(r.is_ok(), "panic on input {i}: {s:?}");
        if let Ok(Err(e)) = r {
            assert!(e.to_string().contains(&format!("f{i}.{ext}")), "{e}");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}
