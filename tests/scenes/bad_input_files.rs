//! Bad user input: every case returns an Error naming the file or field, never panics; soft
//! problems (missing MTL, missing/undecodable map_Kd, no UVs) become warnings.

use std::path::{Path, PathBuf};

use crate::tmp_common::TmpDir;
use texsim::scene::{load, load_obj, load_toml, Scene};
use texsim::Result;

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
    let dir = TmpDir::new("missing");
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
    let dir = TmpDir::new("obj");
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
    let dir = TmpDir::new("nan");
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
    let dir = TmpDir::new("mtl");
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
    let dir = TmpDir::new("tex");
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
    let dir = TmpDir::new("mapkd");
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
    let dir = TmpDir::new("nouv");
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
    let dir = TmpDir::new("plain");
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
    let dir = TmpDir::new("toml");
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
    // An untagged key (a number or a list) says what it takes, not its Rust type.
    let p = write(
        &dir,
        "scale.toml",
        b"[[meshes]]\nshape = \"cube\"\nscale = [1.0, 2.0]\n",
    );
    let e = expect_err(
        move || load_toml(&p),
        &["scale.toml", "expected a number or [x, y, z]"],
    );
    assert!(!e.contains("ScaleCfg"), "{e}");
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
    let dir = TmpDir::new("ttex");
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
    let dir = TmpDir::new("min");
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
    let dir = TmpDir::new("fuzz");
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
}

/// Runs `f` on another thread and waits at most 10 s: a loader that hangs (a FIFO) or reads
/// without bound (/dev/zero) fails the test instead of stopping the suite.
fn within_10s<T: Send + 'static>(what: &str, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    rx.recv_timeout(std::time::Duration::from_secs(10))
        .unwrap_or_else(|_| panic!("{what}: no answer within 10 s"))
}

fn err_text<T>(r: Result<T>) -> String {
    match r {
        Ok(_) => panic!("expected an error"),
        Err(e) => e.to_string(),
    }
}

/// A scene, material, hardware or texture file that is a FIFO or a device is refused by name
/// before it is opened (a FIFO never blocks, /dev/zero is not read without bound).
#[test]
fn special_files_are_refused() {
    let dir = TmpDir::new("special");
    let fifo = |name: &str| {
        let p = dir.join(name);
        let st = std::process::Command::new("mkfifo")
            .arg(&p)
            .status()
            .expect("mkfifo");
        assert!(st.success());
        p
    };
    let cases: Vec<(String, Box<dyn FnOnce() -> String + Send>)> = vec![
        {
            let p = fifo("pipe.obj");
            ("fifo obj".into(), Box::new(move || err_text(load(&p))))
        },
        {
            let p = fifo("pipe.toml");
            ("fifo toml".into(), Box::new(move || err_text(load(&p))))
        },
        {
            let p = fifo("pipe_hw.toml");
            let s = p.display().to_string();
            (
                "fifo hw".into(),
                Box::new(move || err_text(texsim::hwconfig::resolve(&s))),
            )
        },
        {
            let p = fifo("pipe.png");
            (
                "fifo png".into(),
                Box::new(move || err_text(texsim::scene::decode_texture(&p))),
            )
        },
        {
            fifo("lib.mtl");
            let p = write(
                &dir,
                "with_mtl.obj",
                format!("mtllib lib.mtl\n{TRI}f 1 2 3\n").as_bytes(),
            );
            ("fifo mtl".into(), Box::new(move || err_text(load(&p))))
        },
        (
            "/dev/zero hw".into(),
            Box::new(|| err_text(texsim::hwconfig::resolve("/dev/zero"))),
        ),
        (
            "/dev/zero png".into(),
            Box::new(|| err_text(texsim::scene::decode_texture(Path::new("/dev/zero")))),
        ),
    ];
    for (what, f) in cases {
        let e = within_10s(&what, f);
        assert!(e.contains("not a regular file"), "{what}: {e}");
    }
    // A symbolic link to a regular file is fine.
    let real = write(&dir, "real.toml", GOOD_MESH.as_bytes());
    let link = dir.join("link.toml");
    std::os::unix::fs::symlink(&real, &link).unwrap();
    load(&link).expect("a link to a regular file loads");
}

/// A text file over the cap is refused by its size, before it is read (a sparse file: no
/// disk and no memory used).
#[test]
fn oversized_text_files_are_refused() {
    let dir = TmpDir::new("huge");
    let p = dir.join("huge.toml");
    let f = std::fs::File::create(&p).unwrap();
    f.set_len(texsim::budget::MAX_TEXT_FILE_BYTES + 1).unwrap();
    let t = std::time::Instant::now();
    let e = expect_err(move || load(&p), &["huge.toml", "over the limit"]);
    assert!(t.elapsed().as_secs() < 2, "{e}");
    let p = dir.join("huge_hw.toml");
    std::fs::File::create(&p)
        .unwrap()
        .set_len(texsim::budget::MAX_TEXT_FILE_BYTES + 1)
        .unwrap();
    let e = err_text(texsim::hwconfig::resolve(&p.display().to_string()));
    assert!(
        e.contains("huge_hw.toml") && e.contains("over the limit"),
        "{e}"
    );
}

/// Budgets checked while loading, before the allocation: a procedural texture of 16384 (4 GiB
/// of texels and more in maps) or 8193, and shapes whose triangles exceed the budget (one
/// sphere at the per-mesh maximum, or several that are fine alone).
#[test]
fn loader_budgets_fail_fast_with_the_field() {
    let dir = TmpDir::new("budget");
    for size in [16384, 8193] {
        let p = write(
            &dir,
            &format!("tex{size}.toml"),
            format!(
                "[output]\nwidth = 64\nheight = 48\n[[textures]]\nname = \"t\"\nprocedural = \"checker\"\nsize = {size}\n{GOOD_MESH}"
            )
            .as_bytes(),
        );
        let t = std::time::Instant::now();
        let e = expect_err(
            move || load(&p),
            &["textures[0].size", "needs about", "limit", "--max-memory"],
        );
        assert!(t.elapsed().as_secs() < 2, "{size}: {e}");
    }
    let p = write(
        &dir,
        "big_sphere.toml",
        b"[[meshes]]\nshape = \"sphere\"\nsegments = 4096\nrings = 4096\n",
    );
    let t = std::time::Instant::now();
    expect_err(
        move || load(&p),
        &["meshes[0].segments", "33554432 triangles", "limit"],
    );
    assert!(t.elapsed().as_secs() < 2);
    // Three of these fit the default limit at 736 B per shape triangle, four do not.
    let four = "[[meshes]]\nshape = \"sphere\"\nsegments = 1024\nrings = 400\n".repeat(4);
    let p = write(&dir, "four.toml", four.as_bytes());
    let t = std::time::Instant::now();
    expect_err(
        move || load(&p),
        &["meshes[3].segments", "3276800 triangles", "limit"],
    );
    assert!(t.elapsed().as_secs() < 10);
}

/// A seeded mutation fuzzer over valid OBJ, MTL, TOML scene, hardware TOML and PNG files
/// (byte flips, deletions, duplications, truncations and inserted hostile tokens): 4,000
/// cases, no panic, every error names its file (or, for hardware text, says something).
#[test]
fn seeded_mutations_of_valid_files_never_panic() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let read = |n: &str| std::fs::read(root.join(n)).unwrap();
    let seeds: [(&str, Vec<u8>); 5] = [
        ("obj", read("cube.obj")),
        ("mtl", read("cube.mtl")),
        ("toml", read("example.toml")),
        (
            "hw",
            b"base = \"d3d11\"\nname = \"mine\"\n[interp]\nbary_bits = 20\ntexcoord_overflow = \"wrap\"\n[trilinear]\nweight_bits = 6\n[lod]\nlod_frac_bits = 4\n".to_vec(),
        ),
        ("png", read("checker64.png")),
    ];
    let tokens: [&[u8]; 18] = [
        b"-1",
        b"0",
        b"1e309",
        b"nan",
        b"inf",
        b"9999999999",
        b"-2147483649",
        b"\"",
        b"=",
        b"[",
        b"]",
        b"[[",
        b"\n",
        b"/",
        b" ",
        b"#",
        b"\xff\xfe",
        b"0.5",
    ];
    let mut state = 0x5eed_0017_u64;
    let mut next = move || {
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    };
    let dir = TmpDir::new("mutate");
    std::fs::copy(root.join("checker64.png"), dir.join("checker64.png")).unwrap();
    std::fs::copy(root.join("cube.mtl"), dir.join("cube.mtl")).unwrap();
    std::fs::copy(root.join("cube.obj"), dir.join("cube.obj")).unwrap();
    let start = std::time::Instant::now();
    let cases = 4000;
    for i in 0..cases {
        let (kind, seed) = &seeds[i % seeds.len()];
        let mut b = seed.clone();
        for _ in 0..1 + next() % 4 {
            let len = b.len().max(1) as u64;
            let at = (next() % len) as usize;
            match next() % 6 {
                0 if !b.is_empty() => {
                    let i = at.min(b.len() - 1);
                    b[i] = next() as u8;
                }
                1 => {
                    let end = (at + 1 + (next() % 16) as usize).min(b.len());
                    b.drain(at.min(end)..end);
                }
                2 => {
                    let end = (at + 1 + (next() % 32) as usize).min(b.len());
                    let piece = b[at.min(end)..end].to_vec();
                    b.splice(at..at, piece);
                }
                3 => b.truncate(at),
                _ => {
                    let t = tokens[(next() % tokens.len() as u64) as usize];
                    let at = at.min(b.len());
                    b.splice(at..at, t.iter().copied());
                }
            }
        }
        let name = format!("m{i}");
        let (path, r): (
            PathBuf,
            std::thread::Result<std::result::Result<(), String>>,
        ) = match *kind {
            "obj" => {
                let p = write(&dir, &format!("{name}.obj"), &b);
                let q = p.clone();
                (
                    p,
                    std::panic::catch_unwind(move || {
                        load(&q).map(|_| ()).map_err(|e| e.to_string())
                    }),
                )
            }
            "mtl" => {
                write(&dir, &format!("{name}.mtl"), &b);
                let p = write(
                    &dir,
                    &format!("{name}_uses_mtl.obj"),
                    format!("mtllib {name}.mtl\nusemtl Material\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n").as_bytes(),
                );
                let q = p.clone();
                (
                    p,
                    std::panic::catch_unwind(move || {
                        load(&q).map(|_| ()).map_err(|e| e.to_string())
                    }),
                )
            }
            "toml" => {
                let p = write(&dir, &format!("{name}.toml"), &b);
                let q = p.clone();
                (
                    p,
                    std::panic::catch_unwind(move || {
                        load(&q).map(|_| ()).map_err(|e| e.to_string())
                    }),
                )
            }
            "hw" => {
                let p = write(&dir, &format!("{name}_hw.toml"), &b);
                let q = p.display().to_string();
                (
                    p,
                    std::panic::catch_unwind(move || {
                        texsim::hwconfig::resolve(&q)
                            .map(|_| ())
                            .map_err(|e| e.to_string())
                    }),
                )
            }
            _ => {
                let p = write(&dir, &format!("{name}.png"), &b);
                let q = p.clone();
                (
                    p,
                    std::panic::catch_unwind(move || {
                        texsim::scene::decode_texture(&q)
                            .map(|_| ())
                            .map_err(|e| e.to_string())
                    }),
                )
            }
        };
        let shown = String::from_utf8_lossy(&b)
            .chars()
            .take(400)
            .collect::<String>();
        match r {
            Err(_) => panic!("case {i} ({kind}) panicked on {shown:?}"),
            Ok(Err(e)) => {
                let file = path.file_name().unwrap().to_string_lossy().into_owned();
                assert!(
                    e.contains(&file),
                    "case {i} ({kind}): error '{e}' does not name {file}"
                );
            }
            Ok(Ok(())) => {}
        }
        std::fs::remove_file(&path).ok();
    }
    eprintln!(
        "{cases} mutated files in {:.2} s",
        start.elapsed().as_secs_f64()
    );
}
