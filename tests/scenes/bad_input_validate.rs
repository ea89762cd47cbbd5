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

/// The up-front budget of a whole run: framebuffer and timing events from the image size,
/// texels from the textures; the error names the largest part, the need and the limit.
#[test]
fn run_budget_names_the_largest_part() {
    use texsim::budget::{check_run, RunNeed, DEFAULT_MAX_MEMORY};
    let hw = hw_model::HwConfig::preset("texram16").unwrap();
    let s = base();
    check_run(&s, &hw, false, true).expect("the sphere fits");
    let mut s = base();
    s.width = 8192;
    s.height = 8192;
    let need = RunNeed::of(&s, &hw, false, true);
    assert!(need.total() > DEFAULT_MAX_MEMORY, "{need:?}");
    let e = check_run(&s, &hw, false, true)
        .expect_err("8192x8192 with timing")
        .to_string();
    for m in [
        "width x height",
        "8192x8192",
        "needs about",
        "limit",
        "--max-memory",
    ] {
        assert!(e.contains(m), "'{e}' should mention '{m}'");
    }
    let mut s = base();
    s.textures.push(TextureImage {
        name: "huge".into(),
        width: 16384,
        height: 16384,
        texels: vec![],
        prebuilt_levels: None,
    });
    let e = check_run(&s, &hw, true, false)
        .expect_err("huge texture")
        .to_string();
    assert!(e.contains("field 'textures'"), "{e}");
}

/// The float reference's exact depth test sets the scene up and rasterizes it again when the
/// depth buffer is narrower than 30 bits: the estimate counts its triangles, vertices and
/// pixels then, and only then.
#[test]
fn run_budget_counts_the_exact_depth_test() {
    use texsim::budget::{
        RunNeed, BYTES_PER_EXACT_DEPTH_PIXEL, BYTES_PER_EXACT_DEPTH_TRIANGLE,
        BYTES_PER_EXACT_DEPTH_VERTEX,
    };
    let narrow = hw_model::HwConfig::preset("texram16").unwrap();
    assert!(narrow.raster.depth_bits < 30);
    let mut wide = narrow.clone();
    wide.raster.depth_bits = 30;
    let s = base();
    let (tris, verts) = s.meshes.iter().fold((0, 0), |(t, v), m| {
        (t + m.indices.len() as u64, v + m.positions.len() as u64)
    });
    let pixels = u64::from(s.width) * u64::from(s.height);
    let (n, w) = (
        RunNeed::of(&s, &narrow, true, false),
        RunNeed::of(&s, &wide, true, false),
    );
    assert_eq!(
        n.triangles - w.triangles,
        tris * BYTES_PER_EXACT_DEPTH_TRIANGLE + verts * BYTES_PER_EXACT_DEPTH_VERTEX
    );
    assert_eq!(
        n.framebuffer - w.framebuffer,
        pixels * BYTES_PER_EXACT_DEPTH_PIXEL
    );
    assert_eq!(
        RunNeed::of(&s, &narrow, false, false),
        RunNeed::of(&s, &wide, false, false),
        "no reference, no second pass"
    );
}

/// A number or a list where a hw file wants a name (a rounding mode) gets the names it takes,
/// which serde's own message leaves out.
#[test]
fn hw_enum_field_of_the_wrong_type_lists_its_names() {
    for value in ["1", "[1]", "true"] {
        let e = texsim::hwconfig::parse(&format!("[trilinear]\nweight_rounding = {value}\n"))
            .expect_err(value)
            .to_string();
        assert!(
            e.contains("field 'trilinear.weight_rounding'")
                && e.contains("is not a name: expected one of `truncate`, `half-up`, `half-even`"),
            "{e}"
        );
    }
}
