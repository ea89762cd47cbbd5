//! `scene::validate` on scenes built in code: every broken invariant is an Error naming the
//! field, and the built-in scenes pass.

use texsim::scene::{builtin, validate, Scene, TextureImage};

fn base() -> Scene {
    builtin("sphere").unwrap()
}

fn expect(s: &Scene, needle: &str) {
    let r = std::panic::catch_unwind(|| validate(s)).expect("validate panicked");
    let e = r.expect_err("expected a validation error").to_string();
    assert!(e.contains(needle), "'{e}' should mention '{needle}'");
}

#[test]
fn validate_rejects_each_broken_invariant() {
    validate(&base()).unwrap();
    let mut s = base();
    s.width = 0;
    expect(&s, "width");
    let mut s = base();
    s.height = 8193;
    expect(&s, "height");
    let mut s = base();
    s.meshes[0].positions[5][1] = f32::NAN;
    expect(&s, "positions");
    let mut s = base();
    s.meshes[0].normals[3][0] = f32::INFINITY;
    expect(&s, "normals");
    let mut s = base();
    s.meshes[0].normals.pop();
    expect(&s, "normals");
    let mut s = base();
    s.meshes[0].uvs[0][1] = f32::NAN;
    expect(&s, "uvs");
    let mut s = base();
    s.meshes[0].uvs.truncate(3);
    expect(&s, "uvs");
    let mut s = base();
    let n = s.meshes[0].positions.len() as u32;
    s.meshes[0].indices[7] = [0, 1, n];
    expect(&s, "indices");
    let mut s = base();
    s.meshes[0].material = 9;
    expect(&s, "material");
    let mut s = base();
    s.materials[0].texture = Some(4);
    expect(&s, "texture");
    let mut s = base();
    s.meshes[0].indices.clear();
    expect(&s, "no triangles");
    let mut s = base();
    s.camera.near = 0.0;
    expect(&s, "near");
    let mut s = base();
    s.camera.fov_y_deg = 180.0;
    expect(&s, "fov_y_deg");
    let mut s = base();
    s.camera.target = s.camera.eye;
    expect(&s, "target");
    let mut s = base();
    s.camera.up = [0.0; 3];
    expect(&s, "up");
    let mut s = base();
    s.background[0] = f32::NAN;
    expect(&s, "background");
    let mut s = base();
    s.textures[0].texels.pop();
    expect(&s, "textures[0]");
    let mut s = base();
    s.textures.push(TextureImage {
        name: "bad-chain".into(),
        width: 4,
        height: 4,
        texels: vec![[0; 4]; 16],
        prebuilt_levels: Some(vec![(2, 2, vec![[0; 4]; 4])]),
    });
    expect(&s, "bad-chain");
}
