//! Built-in scenes of NDF mapping (Olano and North 1997), shaded by `ndf-fetch`/`ndf-shade`
//! (see `crate::pipeline::ndf_stages`): `ripple-sphere` (their Figure 1: one rippled sphere at
//! three distances, the highlight blurs and stretches along the ripples as the MIP level
//! coarsens), `lod-pair` (their Figure 2: one smooth object at two polygon counts; the per-pixel
//! NDF keeps the highlights alike), `foil` (crumpled foil: many small facets whose coarse
//! levels become a broad, anisotropic lobe).

use super::{shapes, Camera, Light, Material, Mesh, Scene, TextureImage};
use crate::shading::ndf::procedural_normals;
use glam::{DMat4, DVec3};

/// A tangent-space normal map texture (`rgb = n/2 + 1/2`, 16-bit) of a procedural kind.
fn normal_texture(kind: &str, size: u32, amplitude: f64) -> TextureImage {
    let normals = procedural_normals(kind, size, size, amplitude)
        .unwrap_or_else(|_| vec![DVec3::Z; (size * size) as usize]);
    let q = |c: f64| ((c * 0.5 + 0.5).clamp(0.0, 1.0) * 65535.0).round() as u16;
    TextureImage {
        name: format!("{kind} normals"),
        width: size,
        height: size,
        texels: normals
            .iter()
            .map(|n| [q(n.x), q(n.y), q(n.z), 65535])
            .collect(),
        prebuilt_levels: None,
    }
}

fn ndf_material(name: &str, kd: [f32; 3], shininess: u32) -> Material {
    Material {
        name: name.into(),
        kd,
        bump: Some(0),
        bump_scale: 1.0,
        bump_normal_map: true,
        ks: [0.6; 3],
        shininess,
        cull_back: true,
        ndf: true,
        ..Material::default()
    }
}

fn placed(mut m: Mesh, name: &str, at: DVec3, scale: f64) -> Mesh {
    m.name = name.into();
    super::geometry::transform_mesh(
        &mut m,
        &(DMat4::from_translation(at) * DMat4::from_scale(DVec3::splat(scale))),
    );
    m
}

fn scene(name: &str, meshes: Vec<Mesh>, materials: Vec<Material>, tex: TextureImage) -> Scene {
    let l = DVec3::new(-0.5, -0.6, -1.0).normalize();
    Scene {
        name: name.into(),
        width: 480,
        height: 320,
        camera: Camera {
            eye: [0.0, 0.0, 4.0],
            target: [0.0, 0.0, 0.0],
            up: [0.0, 1.0, 0.0],
            fov_y_deg: 40.0,
            near: 0.1,
            far: 100.0,
            view_override: None,
        },
        lights: vec![Light::Directional {
            direction: [l.x as f32, l.y as f32, l.z as f32],
            color: [1.0, 0.95, 0.9],
        }],
        ambient: [0.05, 0.05, 0.06],
        background: [0.08, 0.08, 0.1, 1.0],
        meshes,
        materials,
        textures: vec![tex],
        hw: None,
        warnings: Vec::new(),
    }
}

/// `ripple-sphere`: the rippled sphere near, mid and far (three MIP scales), shininess 64.
pub fn ripple_sphere() -> Scene {
    let s = shapes::sphere(1.0, 48, 24);
    scene(
        "ripple-sphere",
        vec![
            placed(s.clone(), "near", DVec3::new(-1.45, 0.0, 0.0), 1.0),
            placed(s.clone(), "mid", DVec3::new(1.0, -0.2, -3.0), 1.0),
            placed(s, "far", DVec3::new(5.0, 1.0, -8.0), 1.0),
        ],
        vec![ndf_material("ripple", [0.25, 0.35, 0.6], 64)],
        normal_texture("ripple", 128, 0.5),
    )
}

/// `lod-pair`: one smooth sphere at 12x6 and at 64x32 quads, shininess 128, flat normals: the
/// per-pixel NDF of the interpolated frame gives the same highlight on both.
pub fn lod_pair() -> Scene {
    scene(
        "lod-pair",
        vec![
            placed(
                shapes::sphere(1.0, 12, 6),
                "coarse",
                DVec3::new(-1.1, 0.0, 0.0),
                1.0,
            ),
            placed(
                shapes::sphere(1.0, 64, 32),
                "fine",
                DVec3::new(1.1, 0.0, 0.0),
                1.0,
            ),
        ],
        vec![ndf_material("smooth", [0.6, 0.3, 0.25], 128)],
        normal_texture("ripple", 16, 0.0),
    )
}

/// `foil`: crumpled foil (random facets, 2x2 texels each), shininess 256, as a near tile (the
/// facets sparkle) and a far one (coarse levels: one broad, duller highlight), both facing the
/// halfway vector of the light and the eye.
pub fn foil() -> Scene {
    let tile = |name: &str, at: DVec3, scale: f64| {
        let mut t = shapes::plane(3.0, 3.0);
        t.name = name.into();
        super::geometry::transform_mesh(
            &mut t,
            &(DMat4::from_translation(at)
                * DMat4::from_scale(DVec3::splat(scale))
                * DMat4::from_rotation_y((-12f64).to_radians())
                * DMat4::from_rotation_x(70f64.to_radians())),
        );
        t
    };
    let mut m = ndf_material("foil", [0.5, 0.5, 0.52], 256);
    m.cull_back = false;
    scene(
        "foil",
        vec![
            tile("near", DVec3::new(-0.9, 0.0, 0.0), 0.6),
            tile("far", DVec3::new(4.0, 0.8, -12.0), 0.6),
        ],
        vec![m],
        normal_texture("foil", 128, 0.45),
    )
}
