//! Built-in Ashikhmin-Shirley scenes: the paper's sphere grids (Ashikhmin & Shirley 2000,
//! Figs. 3 and 5: `n_u` per column, `n_v` per row over `1, 10, 100, 1000, 10000`, under a
//! light) rendered through the pipeline's `as-shade` stage, and brushed metal on meshes from
//! one main direction.

use super::{shapes, AsBrdf, Camera, Light, MainDirection, Material, Mesh, Scene};
use glam::{DMat4, DVec3};

/// The exponents of the grids (columns `n_u`, rows `n_v`).
pub const GRID_EXPONENTS: [f64; 5] = [1.0, 10.0, 100.0, 1000.0, 10000.0];

/// A `5 x 5` grid of spheres, one material per sphere (`brdf(nu, nv)`), seen head-on from
/// far away (narrow field of view: nearly the orthographic view of `brdf::spheres`), lit by
/// one directional light from the upper left front (the direction of `brdf::spheres`).
fn grid(name: &str, kd: [f32; 3], rs: f64, rd: f64) -> Scene {
    let n = GRID_EXPONENTS.len();
    let mut meshes = Vec::with_capacity(n * n);
    let mut materials = Vec::with_capacity(n * n);
    for (row, &nv) in GRID_EXPONENTS.iter().enumerate() {
        for (col, &nu) in GRID_EXPONENTS.iter().enumerate() {
            let mut s: Mesh = shapes::sphere(0.46, 48, 24);
            s.name = format!("sphere nu={nu} nv={nv}");
            s.material = materials.len();
            let x = col as f64 - 0.5 * (n as f64 - 1.0);
            let y = 0.5 * (n as f64 - 1.0) - row as f64;
            super::geometry::transform_mesh(
                &mut s,
                &DMat4::from_translation(DVec3::new(x, y, 0.0)),
            );
            meshes.push(s);
            materials.push(Material {
                name: format!("as nu={nu} nv={nv}"),
                kd,
                cull_back: true,
                main_direction: MainDirection::Constant([0.0, 1.0, 0.0]),
                brdf: Some(AsBrdf {
                    nu,
                    nv,
                    rs,
                    rd,
                    exponent_map: None,
                }),
                ..Material::default()
            });
        }
    }
    let l = DVec3::new(-0.5, 0.5, 1.0).normalize();
    Scene {
        name: name.into(),
        width: 400,
        height: 400,
        camera: Camera {
            eye: [0.0, 0.0, 40.0],
            target: [0.0, 0.0, 0.0],
            up: [0.0, 1.0, 0.0],
            fov_y_deg: 7.2,
            near: 30.0,
            far: 50.0,
            view_override: None,
        },
        lights: vec![Light::Directional {
            direction: [-l.x as f32, -l.y as f32, -l.z as f32],
            color: [1.0; 3],
        }],
        ambient: [0.0; 3],
        background: [0.0, 0.0, 0.0, 1.0],
        meshes,
        materials,
        textures: Vec::new(),
        hw: None,
        warnings: Vec::new(),
    }
}

/// `as-metal`: the metal grid (Fig. 3): `R_s = 1`, `R_d = 0`.
#[must_use]
pub fn as_metal() -> Scene {
    grid("as-metal", [1.0; 3], 1.0, 0.0)
}

/// `as-plastic`: the plastic grid (Fig. 5): `R_s = 0.05`, `R_d = 1`, red diffuse.
#[must_use]
pub fn as_plastic() -> Scene {
    grid("as-plastic", [0.9, 0.12, 0.08], 0.05, 1.0)
}

/// `as-brushed`: a torus of brushed metal whose brushing follows one constant main direction
/// (world up: `u = m x n` runs around the vertical, so the grooves are horizontal on any
/// mesh), and a sphere brushed along its parallels (`m = p_u`), under a directional and a
/// point light.
#[must_use]
pub fn as_brushed() -> Scene {
    let mut torus = shapes::torus(0.75, 0.3, 96, 48, 1.0);
    torus.name = "brushed-torus".into();
    torus.material = 0;
    super::geometry::transform_mesh(
        &mut torus,
        &(DMat4::from_translation(DVec3::new(-0.55, 0.0, 0.0))
            * DMat4::from_rotation_x((-65f64).to_radians())),
    );
    let mut ball = shapes::sphere(0.6, 96, 48);
    ball.name = "brushed-sphere".into();
    ball.material = 1;
    super::geometry::transform_mesh(
        &mut ball,
        &DMat4::from_translation(DVec3::new(1.15, 0.1, -0.3)),
    );
    let materials = vec![
        Material {
            name: "brushed-steel".into(),
            kd: [1.0; 3],
            cull_back: true,
            main_direction: MainDirection::Constant([0.0, 1.0, 0.0]),
            brdf: Some(AsBrdf {
                nu: 20.0,
                nv: 2000.0,
                rs: 0.9,
                rd: 0.05,
                exponent_map: None,
            }),
            ..Material::default()
        },
        Material {
            name: "brushed-sphere".into(),
            kd: [0.9, 0.7, 0.4],
            cull_back: true,
            main_direction: MainDirection::Pu,
            brdf: Some(AsBrdf {
                nu: 1000.0,
                nv: 10.0,
                rs: 0.7,
                rd: 0.2,
                exponent_map: None,
            }),
            ..Material::default()
        },
    ];
    let d = DVec3::new(-0.4, -0.6, -0.7).normalize();
    Scene {
        name: "as-brushed".into(),
        width: 640,
        height: 480,
        camera: Camera {
            eye: [0.0, 1.2, 3.6],
            target: [0.25, 0.0, 0.0],
            up: [0.0, 1.0, 0.0],
            fov_y_deg: 45.0,
            near: 0.1,
            far: 50.0,
            view_override: None,
        },
        lights: vec![
            Light::Directional {
                direction: [d.x as f32, d.y as f32, d.z as f32],
                color: [0.8, 0.8, 0.75],
            },
            Light::Point {
                position: [1.5, 2.0, 2.0],
                color: [0.5, 0.55, 0.6],
            },
        ],
        ambient: [0.1, 0.1, 0.12],
        background: [0.12, 0.12, 0.14, 1.0],
        meshes: vec![torus, ball],
        materials,
        textures: Vec::new(),
        hw: None,
        warnings: Vec::new(),
    }
}
