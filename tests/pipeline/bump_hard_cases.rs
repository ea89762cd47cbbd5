//! Bump-mapping hard cases at pipeline level, each in all three frames, fixed and float:
//! w close to the near plane, long thin triangles, opposite vertex normals (zero-length
//! interpolated normal), main direction parallel to the normal (fallback), grazing light,
//! UV-degenerate and mirrored UVs, and saturation of the offset format (counted, reported).
//! Every case: no non-finite float carrier, and the fixed image stays close to the float one
//! except where a fallback decision may differ between the twins.

use hw_model::HwConfig;
use texsim::pipeline::StageKind;
use texsim::render::{render, Maps, RenderOptions, Rendered};
use texsim::scene::texture::bricks_height;
use texsim::scene::{Camera, FrameKind, Light, MainDirection, Material, Mesh, Scene};

const FRAMES: [FrameKind; 3] = [FrameKind::Natural, FrameKind::Unit, FrameKind::Main];

fn scene(meshes: Vec<Mesh>, mat: Material, camera: Camera, lights: Vec<Light>) -> Scene {
    Scene {
        name: "hard".into(),
        width: 96,
        height: 72,
        camera,
        lights,
        ambient: [0.1; 3],
        background: [0.0, 0.0, 0.0, 1.0],
        meshes,
        materials: vec![mat],
        textures: vec![bricks_height(64)],
        hw: None,
        warnings: Vec::new(),
    }
}

fn bump_mat() -> Material {
    Material {
        name: "bump".into(),
        kd: [0.7, 0.6, 0.5],
        bump: Some(0),
        bump_scale: 2.0,
        ks: [0.4; 3],
        shininess: 16,
        ..Material::default()
    }
}

fn cam(eye: [f64; 3], target: [f64; 3], near: f64) -> Camera {
    Camera {
        eye,
        target,
        up: [0.0, 1.0, 0.0],
        fov_y_deg: 60.0,
        near,
        far: 100.0,
        view_override: None,
    }
}

fn sun(dir: [f32; 3]) -> Light {
    Light::Directional {
        direction: dir,
        color: [0.9; 3],
    }
}

/// A flat grid in y = 0 of `n x n` quads over `[-s, s]^2`, UVs `0..uv`, normals `+y`.
fn grid(n: u32, s: f32, uv: f32) -> Mesh {
    let mut m = Mesh {
        name: "grid".into(),
        ..Mesh::default()
    };
    for i in 0..=n {
        for j in 0..=n {
            let (a, b) = (j as f32 / n as f32, i as f32 / n as f32);
            m.positions.push([-s + 2.0 * s * a, 0.0, s - 2.0 * s * b]);
            m.normals.push([0.0, 1.0, 0.0]);
            m.uvs.push([uv * a, uv * b]);
        }
    }
    for i in 0..n {
        for j in 0..n {
            let a = i * (n + 1) + j;
            let (b, c, d) = (a + 1, a + n + 2, a + n + 1);
            m.indices.push([a, b, c]);
            m.indices.push([a, c, d]);
        }
    }
    m
}

fn go(s: &Scene, kind: FrameKind) -> Rendered {
    let mut hw = HwConfig::texram16();
    hw.shading.frame.frame_kind = kind;
    let maps = Maps::new(s, hw.trilinear.texel_bits);
    render(s, &maps, &hw, &RenderOptions::default()).expect("render")
}

/// Common checks; returns the 8-bit error metrics. `min_within1` is the share of pixels the
/// fixed image must have within 1 LSB (8-bit) of the float one.
fn check(name: &str, s: &Scene, min_within1: f64) -> Vec<Rendered> {
    FRAMES
        .iter()
        .map(|&kind| {
            let r = go(s, kind);
            let e8 = r.stats.error_8bit.clone().expect("metrics");
            eprintln!(
                "{name} {kind:?}: px {} max8 {} within1 {:.3}% fallback {} zero {} nonfinite {}/{}",
                r.stats.covered_pixels,
                e8.max_abs_lsb,
                e8.pct_within_1lsb,
                r.stats.bump.frame_fallback,
                r.stats.bump.zero_normal,
                r.stats.bump.nonfinite,
                r.stats.bump.ref_nonfinite
            );
            assert!(
                r.stats.covered_pixels > 200,
                "{name} {kind:?}: nothing drawn"
            );
            assert_eq!(r.stats.bump.nonfinite, 0, "{name} {kind:?}");
            assert_eq!(r.stats.bump.ref_nonfinite, 0, "{name} {kind:?}");
            assert_eq!(
                r.stats.stages[StageKind::Phong.index()].invocations,
                r.stats.covered_pixels
            );
            assert!(e8.pct_within_1lsb >= min_within1, "{name} {kind:?}: {e8:?}");
            r
        })
        .collect()
}

#[test]
fn w_close_to_the_near_plane() {
    // A large floor passing just under the eye: triangles are clipped at the near plane and
    // the bottom rows sample w within a few near-distances.
    let s = scene(
        vec![grid(8, 20.0, 40.0)],
        bump_mat(),
        cam([0.0, 0.02, 0.0], [0.0, -0.3, -5.0], 0.01),
        vec![sun([-0.3, -0.8, -0.5])],
    );
    for r in check("near-plane", &s, 99.0) {
        assert!(r.stats.setup.clipped > 0, "no clipping exercised");
    }
}

#[test]
fn long_thin_triangles() {
    // 1 x 0.004 slivers (aspect 250:1) across the view.
    let mut m = Mesh {
        name: "slivers".into(),
        ..Mesh::default()
    };
    let rows = 300u32;
    for i in 0..=rows {
        let z = -(i as f32) * 0.004;
        for x in [-1.0f32, 1.0] {
            m.positions.push([x, 0.0, z]);
            m.normals.push([0.0, 1.0, 0.0]);
            m.uvs.push([(x + 1.0) * 2.0, i as f32 * 0.008]);
        }
    }
    for i in 0..rows {
        let a = 2 * i;
        m.indices.push([a, a + 1, a + 3]);
        m.indices.push([a, a + 3, a + 2]);
    }
    let s = scene(
        vec![m],
        bump_mat(),
        cam([0.0, 1.2, 0.8], [0.0, 0.0, -0.6], 0.05),
        vec![sun([-0.4, -0.7, -0.3])],
    );
    check("slivers", &s, 99.0);
}

#[test]
fn opposite_vertex_normals_give_a_zero_interpolated_normal() {
    // Left column +y, right column -y: n_I passes through zero on the middle line; the frame
    // falls back to +z there (counted), nothing becomes NaN.
    // Looking straight down with an odd width: the middle pixel column samples x = 0, where
    // the interpolated n_y = 1 - 2 a is below one ulp of s1.14 and rounds to zero.
    let mut m = grid(1, 1.0, 2.0);
    m.normals = vec![
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
    ];
    let mut down = cam([0.0, 2.0, 0.0], [0.0, 0.0, 0.0], 0.1);
    down.up = [0.0, 0.0, -1.0];
    let mut s = scene(
        vec![m],
        bump_mat(),
        down,
        vec![
            sun([0.2, -1.0, 0.1]),
            Light::Point {
                position: [0.0, 0.5, 0.0],
                color: [0.5; 3],
            },
        ],
    );
    s.width = 97;
    s.height = 73;
    // Pixels next to the zero line flip between +-n_I under rounding: allow 3% there.
    let rs = check("opposite-normals", &s, 97.0);
    // Where |n_I| < 1 ulp the fixed interpolator returns exactly zero: the middle column.
    assert!(
        rs.iter().any(|r| r.stats.bump.zero_normal > 0),
        "no zero normal was met"
    );
}

#[test]
fn main_direction_parallel_to_the_normal_falls_back_everywhere() {
    for (what, m) in [
        ("parallel", [0.0f32, 1.0, 0.0]),
        ("anti-parallel", [0.0, -1.0, 0.0]),
        // 0.5 degrees off: inside the 2^-6 (0.9 degree) cone.
        ("0.5 deg", [0.0, 1.0, 0.5f32.to_radians().tan()]),
    ] {
        let mat = Material {
            main_direction: MainDirection::Constant(m),
            frame: Some(FrameKind::Main),
            ..bump_mat()
        };
        let s = scene(
            vec![grid(2, 1.0, 2.0)],
            mat,
            cam([0.0, 1.5, 1.2], [0.0, 0.0, 0.0], 0.1),
            vec![sun([-0.5, -0.6, -0.3])],
        );
        let r = go(&s, FrameKind::Unit);
        assert_eq!(r.stats.bump.frame, "main");
        assert_eq!(
            r.stats.bump.frame_fallback, r.stats.covered_pixels,
            "{what}: every pixel must use the fallback axis"
        );
        let e8 = r.stats.error_8bit.clone().expect("metrics");
        // Both twins fall back to the same axis (x): the images agree as in the normal case.
        assert!(
            e8.max_abs_lsb <= 2 && e8.pct_within_1lsb >= 99.5,
            "{what} {e8:?}"
        );
    }
}

#[test]
fn grazing_light_and_view() {
    // The light lies exactly in the tile's plane and the eye 2 degrees above it.
    let s = scene(
        vec![grid(4, 3.0, 6.0)],
        bump_mat(),
        cam(
            [0.0, 0.1, 3.2],
            [0.0, 0.1 - 3.2 * 2f64.to_radians().tan(), 0.0],
            0.05,
        ),
        vec![
            sun([-1.0, 0.0, 0.0]),
            Light::Point {
                position: [2.0, 0.0, 0.0],
                color: [0.6; 3],
            },
        ],
    );
    check("grazing", &s, 99.0);
}

#[test]
fn uv_degenerate_and_mirrored_uvs() {
    // Left half: mirrored u (det < 0); a strip of triangles with all-equal UVs on the right.
    let mut m = grid(4, 1.0, 2.0);
    for (p, t) in m.positions.iter().zip(m.uvs.iter_mut()) {
        if p[0] < 0.0 {
            t[0] = -t[0];
        }
        if p[0] > 0.9 {
            *t = [0.5, 0.5];
        }
    }
    let s = scene(
        vec![m],
        bump_mat(),
        cam([0.0, 1.6, 1.0], [0.0, 0.0, 0.0], 0.1),
        vec![sun([-0.3, -0.8, -0.4])],
    );
    check("uv-degenerate-mirrored", &s, 99.0);
}

#[test]
fn offset_saturation_is_counted_and_reported() {
    let mut mat = bump_mat();
    mat.bump_scale = 4.0;
    let s = scene(
        vec![grid(2, 1.0, 2.0)],
        mat,
        cam([0.0, 1.5, 1.2], [0.0, 0.0, 0.0], 0.1),
        vec![sun([-0.5, -0.6, -0.3])],
    );
    let mut hw = HwConfig::texram16();
    hw.shading.vector.offset_int_bits = 0;
    // Maps prepared for the default range: render re-encodes for offset_int_bits = 0.
    let maps = Maps::new(&s, 16);
    let r = render(&s, &maps, &hw, &RenderOptions::default()).expect("render");
    let direct = Maps::with_offset_bits(&s, 16, 0);
    let r2 = render(&s, &direct, &hw, &RenderOptions::default()).expect("render");
    assert_eq!(r.hw_image, r2.hw_image);
    assert!(r.stats.bump.offset_clamped > 0);
    assert_eq!(r.stats.bump.offset_clamped, r2.stats.bump.offset_clamped);
    // Range 1 clamps the same offsets in both twins, so the images still agree closely.
    let e8 = r.stats.error_8bit.clone().expect("metrics");
    assert!(e8.pct_within_1lsb >= 99.0, "{e8:?}");
    // With the default range (8) nothing clamps (|f| <= 4 * 0.5 * max |dh| < 8).
    let r3 = render(&s, &maps, &HwConfig::texram16(), &RenderOptions::default()).expect("r");
    assert_eq!(r3.stats.bump.offset_clamped, 0);
}

#[test]
fn poles_of_a_sphere_with_spherical_uvs() {
    // Looking straight down at the north pole: every pole triangle is a UV sliver with
    // |p_u| -> 0, the natural lengths grow as 1/sin(theta) (any u8.8 saturation is counted).
    let mut down = cam([0.0, 2.6, 0.0], [0.0, 0.0, 0.0], 0.1);
    down.up = [0.0, 0.0, -1.0];
    let s = scene(
        vec![texsim::scene::shapes::sphere(1.0, 32, 16)],
        Material {
            main_direction: MainDirection::Pu,
            ..bump_mat()
        },
        down,
        vec![
            sun([-0.6, -0.5, -0.2]),
            Light::Point {
                position: [0.5, 2.0, 0.5],
                color: [0.5; 3],
            },
        ],
    );
    check("pole", &s, 98.0);
}

#[test]
fn normal_map_matches_the_height_map_it_was_made_from() {
    use texsim::shading::bump::{height_to_offsets, heights_from_texture, BumpParams};
    let h = bricks_height(64);
    let p = BumpParams {
        scale: 2.0,
        v_up: false,
    };
    let offs = height_to_offsets(&heights_from_texture(&h, 0).expect("heights"), 64, 64, &p)
        .expect("offsets");
    // OpenGL-style normal map: n = (-f_u, +f_v, 1) / |.| (green towards the top row = -t).
    let texels = offs
        .iter()
        .map(|f| {
            let (x, y, z) = (-f64::from(f[0]), f64::from(f[1]), 1.0f64);
            let l = (x * x + y * y + z * z).sqrt();
            let c = |v: f64| ((v / l * 0.5 + 0.5) * 65535.0).round() as u16;
            [c(x), c(y), c(z), 65535]
        })
        .collect();
    let nmap = texsim::scene::TextureImage {
        name: "nmap".into(),
        width: 64,
        height: 64,
        texels,
        prebuilt_levels: None,
    };
    let base = scene(
        vec![grid(2, 1.0, 2.0)],
        bump_mat(),
        cam([0.0, 1.5, 1.2], [0.0, 0.0, 0.0], 0.1),
        vec![sun([-0.5, -0.6, -0.3])],
    );
    let mut nm = base.clone();
    nm.textures.push(nmap);
    nm.materials[0].bump = Some(1);
    nm.materials[0].bump_scale = 1.0;
    nm.materials[0].bump_normal_map = true;
    for kind in [FrameKind::Unit, FrameKind::Main] {
        let a = go(&base, kind);
        let b = go(&nm, kind);
        let e = texsim::report::compare(&a.hw_image, &b.hw_image, 8, Some(&a.mask));
        eprintln!("normal map vs height map {kind:?}: {e:?}");
        assert!(
            e.max_abs_lsb <= 2 && e.pct_within_1lsb >= 99.0,
            "{kind:?} {e:?}"
        );
        // A flipped green channel would tilt v the wrong way: clearly different.
        let mut flipped = nm.clone();
        for t in &mut flipped.textures[1].texels {
            t[1] = 65535 - t[1];
        }
        let c = go(&flipped, kind);
        let e2 = texsim::report::compare(&a.hw_image, &c.hw_image, 8, Some(&a.mask));
        assert!(e2.max_abs_lsb > 10, "{kind:?} flipped {e2:?}");
    }
}

/// Saturation inside the pipeline is counted per stage, never silent: one mesh of two grids
/// whose texture densities differ 40:1, natural frame. The relative lengths (per-mesh
/// reference = the mean `|p_u| sin`) are ~20 on the densely textured half, so `f_u len_u`
/// leaves the s3.12 offset format there and the `perturb` stage counts it; the stage totals
/// reach the sweep row.
#[test]
fn offset_format_saturation_in_the_pipeline_is_counted_per_stage() {
    let mut m = grid(2, 1.0, 0.05);
    for p in &mut m.positions {
        p[0] -= 1.1;
    }
    let fine = grid(2, 1.0, 2.0);
    let base = m.positions.len() as u32;
    m.positions
        .extend(fine.positions.iter().map(|p| [p[0] + 1.1, p[1], p[2]]));
    m.normals.extend(fine.normals);
    m.uvs.extend(fine.uvs);
    m.indices
        .extend(fine.indices.iter().map(|t| t.map(|i| i + base)));
    let mut mat = bump_mat();
    mat.frame = Some(FrameKind::Natural);
    mat.bump_scale = 4.0;
    let mut s = scene(
        vec![m],
        mat,
        cam([0.0, 2.6, 1.6], [0.0, 0.0, 0.0], 0.1),
        vec![sun([-0.5, -0.6, -0.3])],
    );
    (s.width, s.height) = (320, 240);
    let r = go(&s, FrameKind::Natural);
    let pert = &r.stats.stages[StageKind::Perturb.index()];
    eprintln!(
        "perturb: {} invocations, {} saturated; offsets clamped {}",
        pert.invocations, pert.saturated, r.stats.bump.offset_clamped
    );
    assert!(pert.invocations > 1000);
    assert!(pert.saturated > 0, "f len beyond s3.12 must be counted");
    assert_eq!(r.stats.bump.nonfinite, 0);
    assert_eq!(r.stats.bump.ref_nonfinite, 0);
    let row = texsim::summary::SweepRow::new(Vec::new(), &r.stats);
    assert!(row.saturated >= pert.saturated);
    // The same scene in the unit frame (lengths 1) saturates nothing there.
    let mut s_unit = s.clone();
    s_unit.materials[0].frame = Some(FrameKind::Unit);
    let u = go(&s_unit, FrameKind::Unit);
    assert_eq!(u.stats.stages[StageKind::Perturb.index()].saturated, 0);
}

/// A normal map with normals flatter than `NORMAL_MAP_MIN_Z` (here: every 4th texel lies in
/// the tangent plane) has those `n_z` clamped; the count reaches `Maps` and the render's
/// `offsets clamped`, also after re-encoding for another offset range.
#[test]
fn normal_map_nz_clamps_are_reported() {
    let texels: Vec<[u16; 4]> = (0..64 * 64)
        .map(|i| {
            if i % 4 == 0 {
                [65535, 32768, 32768, 65535]
            } else {
                [32768, 32768, 65535, 65535]
            }
        })
        .collect();
    let mut s = scene(
        vec![grid(2, 1.0, 2.0)],
        bump_mat(),
        cam([0.0, 1.5, 1.2], [0.0, 0.0, 0.0], 0.1),
        vec![sun([-0.5, -0.6, -0.3])],
    );
    s.textures.push(texsim::scene::TextureImage {
        name: "flat-normals".into(),
        width: 64,
        height: 64,
        texels,
        prebuilt_levels: None,
    });
    s.materials[0].bump = Some(1);
    s.materials[0].bump_scale = 0.1;
    s.materials[0].bump_normal_map = true;
    let mut maps = Maps::new(&s, 16);
    assert_eq!(maps.normal_nz_clamped, 64 * 64 / 4);
    assert!(maps.bump_clamped >= maps.normal_nz_clamped);
    let r = render(&s, &maps, &HwConfig::texram16(), &RenderOptions::default()).expect("r");
    assert_eq!(r.stats.bump.offset_clamped, maps.bump_clamped);
    maps.ensure_offset_bits(2);
    assert!(maps.bump_clamped >= 64 * 64 / 4);
}
