//! `texsim brdf spheres`: the paper's sphere grids through the command line (images, error,
//! cost) and its input errors.

mod cli_common;

use cli_common::{texsim, text, tmp};

#[test]
fn spheres_writes_four_grids_with_error_and_cost() {
    let d = tmp("spheres");
    let o = texsim(
        &[
            "brdf",
            "spheres",
            "--out",
            "o",
            "--size",
            "10",
            "--exponents",
            "1,100,10000",
            "--furnace-res",
            "1",
        ],
        &d,
    );
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    for g in [
        "metal_furnace",
        "metal_light",
        "plastic_furnace",
        "plastic_light",
    ] {
        for suffix in [
            "float.png",
            "fixed.png",
            "error.png",
            "sheet.png",
            "summary.txt",
        ] {
            let f = d.join("o").join(format!("{g}_{suffix}"));
            assert!(f.is_file(), "{} missing:\n{t}", f.display());
        }
        assert!(t.contains(&format!("{g}: 3x3 spheres at 10 px")), "{t}");
        assert!(t.contains(&format!("{g} cost: ")), "{t}");
    }
    // Furnace res 1: 64 specular + 4 diffuse evaluations per pixel; light: one.
    assert!(
        t.contains("metal_furnace cost: 68 unit evaluation(s)/px"),
        "{t}"
    );
    assert!(
        t.contains("metal_light cost: 1 unit evaluation(s)/px"),
        "{t}"
    );
    // Every grid within 1 LSB of 8 bits (texram16).
    assert_eq!(t.matches("within 1 LSB 100.00%").count(), 4, "{t}");
}

#[test]
fn spheres_rejects_bad_input_naming_the_field() {
    let d = tmp("bad");
    for (args, field) in [
        (vec!["--size", "0"], "sphere_px"),
        (vec!["--exponents", "1.5"], "nu"),
        (vec!["--furnace-res", "0", "--size", "2"], "furnace_res"),
        (vec!["--hw", "no-such-preset"], "no-such-preset"),
    ] {
        let mut a = vec!["brdf", "spheres", "--out", "o"];
        a.extend(args);
        let o = texsim(&a, &d);
        let t = text(&o);
        assert!(!o.status.success(), "{a:?} succeeded:\n{t}");
        assert!(
            t.contains(field),
            "{a:?}: error does not name {field}:\n{t}"
        );
        assert!(!t.contains("panicked"), "{t}");
    }
}
