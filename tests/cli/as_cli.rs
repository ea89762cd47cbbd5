//! `texsim brdf` through the binary: `spheres` (the paper's sphere grids: images, error, cost),
//! `eval` (values, float and `--fixed`) and `sample` (sampler statistics and chi-square
//! verdicts), and their input errors.

use crate::cli_common::{texsim, text, tmp};

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

/// The last line of a command's standard output, as a number.
fn last_number(o: &std::process::Output) -> f64 {
    String::from_utf8_lossy(&o.stdout)
        .lines()
        .last()
        .and_then(|l| l.trim().parse().ok())
        .unwrap_or(f64::NAN)
}

/// `texsim brdf eval` prints the dot products, exponent and Fresnel, and on its last line the
/// BRDF of the library reference for the same directions (printed to 7 digits); `--fixed` adds
/// the unit's parts and puts its value on the last line (within the unit's 2e-4 relative of the
/// float value here, a smooth case). Bad input is an error naming the field, never a panic.
#[test]
fn eval_prints_the_reference_value_and_the_fixed_units() {
    use texsim::brdf::{dir_from_angles, AshikhminShirley};
    let d = tmp("eval");
    let args = [
        "brdf", "eval", "--nu", "1000", "--nv", "10", "--rs", "0.05", "--rd", "0.5", "--theta1",
        "30", "--phi1", "10", "--theta2", "35", "--phi2", "185",
    ];
    let o = texsim(&args, &d);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    let p = AshikhminShirley::new(1000.0, 10.0, 0.05, 0.5).expect("valid");
    let (k1, k2) = (dir_from_angles(30.0, 10.0), dir_from_angles(35.0, 185.0));
    let expect = p.eval(k1, k2);
    let got = last_number(&o);
    assert!(
        (got - expect).abs() <= 1e-6 * expect,
        "{got} vs {expect}:\n{t}"
    );
    let spec = p.specular(k1, k2);
    assert!(
        expect > 0.1 && spec > 0.01,
        "a case with a visible lobe: {t}"
    );
    for needle in ["h.n=", "exponent ", "fresnel ", "specular ", "pdf(k2|k1) "] {
        assert!(t.contains(needle), "{needle}:\n{t}");
    }
    assert!(!t.contains("fixed unit"), "{t}");
    let mut fixed_args = args.to_vec();
    fixed_args.push("--fixed");
    let o = texsim(&fixed_args, &d);
    let t = text(&o);
    assert!(
        o.status.success() && t.contains("fixed unit: specular"),
        "{t}"
    );
    let fixed = last_number(&o);
    assert!(
        fixed != got && (fixed - expect).abs() <= 2e-4 * expect,
        "{fixed} vs {expect}:\n{t}"
    );
    for (bad, field) in [
        (vec!["--nu=-1"], "nu"),
        (vec!["--rs", "2"], "rs"),
        (vec!["--nu", "10.5", "--fixed"], "nu"),
        (vec!["--fixed", "--hw", "no-such-preset"], "no-such-preset"),
    ] {
        let mut a = vec!["brdf", "eval"];
        a.extend(bad);
        let o = texsim(&a, &d);
        let t = text(&o);
        assert!(!o.status.success(), "{a:?} succeeded:\n{t}");
        assert!(t.contains(field) && !t.contains("panicked"), "{a:?}:\n{t}");
    }
}

/// `texsim brdf sample`: the half-vector chi-square always runs and passes for the right
/// sampler; the reflected-direction one runs within its anisotropy range and is reported as
/// skipped (with the reason) beyond it, as for the README's `--nu 1000 --nv 10`. The last line
/// is the verdict. Bad input is an error naming the field.
#[test]
fn sample_reports_both_tests_within_range_and_skips_beyond() {
    let d = tmp("sample");
    let o = texsim(
        &[
            "brdf",
            "sample",
            "--nu",
            "1000",
            "--nv",
            "10",
            "--samples",
            "50000",
        ],
        &d,
    );
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    let h = t
        .lines()
        .find(|l| l.starts_with("half-vector"))
        .unwrap_or_default();
    assert!(h.ends_with(": pass") && h.contains("0 lost"), "{t}");
    assert!(
        t.contains("reflected-direction chi-square skipped: anisotropy ratio 91.0 > 10"),
        "{t}"
    );
    assert!(
        t.trim_end()
            .ends_with("chi-square (half-vector at the 99.9% level): pass"),
        "{t}"
    );
    let o = texsim(
        &[
            "brdf",
            "sample",
            "--nu",
            "100",
            "--nv",
            "30",
            "--samples",
            "50000",
            "--theta",
            "45",
        ],
        &d,
    );
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    let k2 = t
        .lines()
        .find(|l| l.starts_with("reflected-direction (eq. 19"))
        .unwrap_or_default();
    assert!(k2.ends_with(": pass") && k2.contains("0 lost"), "{t}");
    assert!(
        t.trim_end()
            .ends_with("chi-square (half-vector and reflected-direction at the 99.9% level): pass"),
        "{t}"
    );
    assert!(
        t.contains("valid (above horizon) fraction") && t.contains("mc albedo"),
        "{t}"
    );
    for (bad, field) in [
        (vec!["--samples", "10"], "samples"),
        (vec!["--theta", "120"], "k1"),
        (vec!["--nv", "nan"], "nv"),
    ] {
        let mut a = vec!["brdf", "sample"];
        a.extend(bad);
        let o = texsim(&a, &d);
        let t = text(&o);
        assert!(!o.status.success(), "{a:?} succeeded:\n{t}");
        assert!(t.contains(field) && !t.contains("panicked"), "{a:?}:\n{t}");
    }
}
