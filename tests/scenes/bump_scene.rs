//! Bump fields of TOML scenes and their errors (named field, never a panic).

use crate::tmp_common::TmpFile;
use std::path::Path;
use texsim::scene::{self, FrameKind, MainDirection};

/// `body` as `s.toml` beside a copy of `scenes/bump_height.png` as `h.png`.
#[track_caller]
fn write(name: &str, body: &str) -> TmpFile {
    let p = TmpFile::new(name, "s.toml", body);
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/bump_height.png");
    std::fs::copy(src, p.dir().join("h.png")).expect("copy");
    p
}

const HEAD: &str = r#"
[[textures]]
name = "bricks"
procedural = "bricks-height"
size = 64
"#;

fn with_material(fields: &str) -> String {
    format!(
        "{HEAD}\n[[materials]]\nname = \"m\"\n{fields}\n\n[[meshes]]\nshape = \"sphere\"\nmaterial = \"m\"\n"
    )
}

#[test]
fn every_bump_field_parses() {
    let p = write(
        "ok",
        &with_material(
            "bump = \"bricks\"\nbump_scale = 2.5\nframe = \"unit\"\nmain_direction = [0.0, 0.0, 1.0]\nks = [0.5, 0.4, 0.3]\nshininess = 7",
        ),
    );
    let s = scene::load(&p).expect("load");
    let m = &s.materials[0];
    assert_eq!(m.bump, Some(0));
    assert_eq!(m.bump_scale, 2.5);
    assert_eq!(m.frame, Some(FrameKind::Unit));
    assert_eq!(m.main_direction, MainDirection::Constant([0.0, 0.0, 1.0]));
    assert_eq!((m.ks, m.shininess), ([0.5, 0.4, 0.3], 7));
    // An image file instead of a texture name, p_u, defaults.
    let p = write(
        "file",
        &with_material("bump = \"h.png\"\nmain_direction = \"p_u\""),
    );
    let s = scene::load(&p).expect("load");
    let m = &s.materials[0];
    assert_eq!(m.bump, Some(1));
    assert_eq!(s.textures[1].width, 128);
    assert_eq!(m.main_direction, MainDirection::Pu);
    assert_eq!((m.frame, m.bump_scale), (None, 1.0));
}

#[test]
fn bad_bump_fields_are_errors_naming_the_field() {
    for (fields, needle) in [
        ("bump = \"missing.png\"", "bump"),
        ("bump = \"bricks\"\nframe = \"diagonal\"", "diagonal"),
        (
            "bump = \"bricks\"\nmain_direction = \"p_w\"",
            "main_direction",
        ),
        (
            "bump = \"bricks\"\nmain_direction = [0.0, 0.0, 0.0]",
            "main_direction",
        ),
        ("bump = \"bricks\"\nbump_scale = nan", "bump_scale"),
        ("bump = \"bricks\"\nks = [-1.0, 0.0, 0.0]", "ks"),
    ] {
        let p = write("bad", &with_material(fields));
        let e = scene::load(&p).expect_err(fields).to_string();
        assert!(e.contains(needle), "{fields}: {e}");
    }
}
