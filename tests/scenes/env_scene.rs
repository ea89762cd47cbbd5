//! Environment-map keys of TOML scenes (`env_map`, `env_filter`, `env_size`) and their errors
//! (the field named, never a panic); a TOML scene with an environment map renders with
//! `env-fetch`.

use hw_model::env_config::EnvFilter;
use std::path::PathBuf;
use texsim::pipeline::StageKind;
use texsim::render::{render, Maps, RenderOptions};
use texsim::scene;

fn write(name: &str, body: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("texsim-envscene-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("tmp");
    let p = d.join("s.toml");
    std::fs::write(&p, body).expect("write");
    p
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
