//! Built-in made-up multiple surfaces (Fournier 1992, sec. 3.4 and 4), shaded by the
//! `lobe-shade` stage: `fournier-fig2`, the paper's Fig. 2 (a sphere with an anisotropic
//! surface, and with multiple surfaces of two, three and seven normals; the seven normals are
//! those of a cylinder's cross-section, as the paper's came "from the filtering of a bump-map
//! extracted from a geometric model describing a cylinder"), and `fournier-velvet` /
//! `fournier-silk`, Figs. 3-4: the same geometry with two multiple surfaces. The paper gives
//! no lobe values (its figures were "shown in presentation"); these are made up to show the
//! effects, as the paper's were (sec. 3.4).

use super::{shapes, Camera, Light, MadeUpLobe, MainDirection, Material, Mesh, Scene};
use glam::{DMat4, DVec3};

/// A lobe tilted `tilt` degrees from the normal towards azimuth `azimuth` degrees (0 = `t_u`,
/// 90 = `t_v`).
fn tilted(tilt: f64, azimuth: f64, amplitude: f32, exponent: u32) -> MadeUpLobe {
    let (t, a) = (tilt.to_radians(), azimuth.to_radians());
    MadeUpLobe {
        direction: [
            (t.sin() * a.cos()) as f32,
            (t.sin() * a.sin()) as f32,
            t.cos() as f32,
        ],
        amplitude,
        exponent,
    }
}

/// Fig. 2's four multiple surfaces, left to right.
#[must_use]
pub fn fig2_surfaces() -> Vec<(&'static str, Vec<MadeUpLobe>)> {
    // Seven normals of a cylinder's cross-section (axis along t_v), each weighted by its
    // projected area (cos of its tilt), amplitudes summing to 1.
    let angles: Vec<f64> = (0..7).map(|j| -67.5 + 22.5 * f64::from(j)).collect();
    let total: f64 = angles.iter().map(|a| a.to_radians().cos()).sum();
    let cylinder = angles
        .iter()
        .map(|&a| {
            tilted(
                a.abs(),
                if a < 0.0 { 180.0 } else { 0.0 },
                (a.to_radians().cos() / total) as f32,
                150,
            )
        })
        .collect();
    vec![
        (
            "anisotropic",
            vec![tilted(7.0, 0.0, 0.5, 60), tilted(7.0, 180.0, 0.5, 60)],
        ),
        (
            "two normals",
            vec![tilted(30.0, 0.0, 0.5, 120), tilted(30.0, 180.0, 0.5, 120)],
        ),
        (
            "three normals",
            vec![
                tilted(28.0, 90.0, 0.34, 120),
                tilted(28.0, 210.0, 0.33, 120),
                tilted(28.0, 330.0, 0.33, 120),
            ],
        ),
        ("seven normals", cylinder),
    ]
}

/// Velvet (Fig. 3): most of the reflection from fibres standing nearly tangent to the
/// surface (six broad lobes 70 degrees off the normal: bright rims at grazing angles), a weak
/// broad lobe along the normal.
#[must_use]
pub fn velvet_lobes() -> Vec<MadeUpLobe> {
    let mut v: Vec<MadeUpLobe> = (0..6)
        .map(|j| tilted(70.0, 60.0 * f64::from(j), 0.15, 6))
        .collect();
    v.push(tilted(0.0, 0.0, 0.1, 4));
    v
}

/// Silk (Fig. 4): threads along `t_u` spread the highlight across them (a wide lobe pair
/// along `t_u`) and a tighter pair along `t_v` from the cross threads.
#[must_use]
pub fn silk_lobes() -> Vec<MadeUpLobe> {
    vec![
        tilted(35.0, 0.0, 0.3, 40),
        tilted(35.0, 180.0, 0.3, 40),
        tilted(12.0, 90.0, 0.2, 200),
        tilted(12.0, 270.0, 0.2, 200),
    ]
}

fn lobe_material(name: &str, kd: [f32; 3], ks: [f32; 3], lobes: Vec<MadeUpLobe>) -> Material {
    Material {
        name: name.into(),
        kd,
        ks,
        cull_back: true,
        main_direction: MainDirection::Constant([0.0, 1.0, 0.0]),
        lobes,
        ..Material::default()
    }
}

fn scene(
    name: &str,
    size: (u32, u32),
    fov_y_deg: f64,
    meshes: Vec<Mesh>,
    materials: Vec<Material>,
) -> Scene {
    let l = DVec3::new(-0.5, 0.6, 1.0).normalize();
    Scene {
        name: name.into(),
        width: size.0,
        height: size.1,
        camera: Camera {
            eye: [0.0, 0.0, 40.0],
            target: [0.0, 0.0, 0.0],
            up: [0.0, 1.0, 0.0],
            fov_y_deg,
            near: 30.0,
            far: 50.0,
            view_override: None,
        },
        lights: vec![
            Light::Directional {
                direction: [-l.x as f32, -l.y as f32, -l.z as f32],
                color: [0.9; 3],
            },
            Light::Point {
                position: [2.0, -1.0, 8.0],
                color: [0.3, 0.3, 0.35],
            },
        ],
        ambient: [0.05; 3],
        background: [0.0, 0.0, 0.0, 1.0],
        meshes,
        materials,
        textures: Vec::new(),
        hw: None,
        warnings: Vec::new(),
    }
}

/// `fournier-fig2`: four spheres in a row, one per multiple surface of [`fig2_surfaces`],
/// lit from the upper left front, 480x128.
#[must_use]
pub fn fig2() -> Scene {
    let surfaces = fig2_surfaces();
    let n = surfaces.len();
    let mut meshes = Vec::with_capacity(n);
    let mut materials = Vec::with_capacity(n);
    for (i, (name, lobes)) in surfaces.into_iter().enumerate() {
        let mut s = shapes::sphere(0.46, 64, 32);
        s.name = format!("sphere {name}");
        s.material = i;
        let x = i as f64 - 0.5 * (n as f64 - 1.0);
        super::geometry::transform_mesh(&mut s, &DMat4::from_translation(DVec3::new(x, 0.0, 0.0)));
        meshes.push(s);
        materials.push(lobe_material(name, [0.15; 3], [0.9; 3], lobes));
    }
    scene("fournier-fig2", (480, 128), 1.6, meshes, materials)
}

/// The geometry of Figs. 3-4: a torus seen obliquely and a sphere (the same for both
/// materials, as in the paper).
fn cloth(name: &str, material: Material) -> Scene {
    let mut torus = shapes::torus(0.55, 0.25, 96, 48, 1.0);
    torus.name = "torus".into();
    super::geometry::transform_mesh(
        &mut torus,
        &(DMat4::from_translation(DVec3::new(-0.45, 0.0, 0.0))
            * DMat4::from_rotation_x((-60f64).to_radians())),
    );
    let mut ball = shapes::sphere(0.42, 64, 32);
    ball.name = "sphere".into();
    super::geometry::transform_mesh(
        &mut ball,
        &DMat4::from_translation(DVec3::new(0.62, 0.0, 0.0)),
    );
    scene(name, (320, 240), 2.6, vec![torus, ball], vec![material])
}

/// `fournier-velvet`: Fig. 3, the cloth geometry in [`velvet_lobes`], dark red, 320x240.
#[must_use]
pub fn velvet() -> Scene {
    cloth(
        "fournier-velvet",
        lobe_material(
            "velvet",
            [0.25, 0.02, 0.05],
            [0.9, 0.35, 0.4],
            velvet_lobes(),
        ),
    )
}

/// `fournier-silk`: Fig. 4, the same geometry in [`silk_lobes`], pale gold, 320x240.
#[must_use]
pub fn silk() -> Scene {
    cloth(
        "fournier-silk",
        lobe_material("silk", [0.35, 0.28, 0.12], [0.9, 0.85, 0.7], silk_lobes()),
    )
}
