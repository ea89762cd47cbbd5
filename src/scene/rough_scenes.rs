//! Built-in scenes for roughness pyramids (issue 4), after the figures of Schilling 1997
//! ("Antialiasing of Bump-Maps"): waves on a lake under a low sun seen from near to far,
//! corrugated sheet iron, brushed metal and small scratches on a glossy surface. Every
//! material is a bump material with `roughness = hw` (so `--vary roughness=...` switches the
//! variant); the height maps are procedural and tileable.

use super::texture::height_image;
use super::{shapes, Camera, Light, Material, RoughChoice, Scene, TextureImage};
use crate::rng::hash_unit;
use glam::DVec3;
use std::f64::consts::TAU;

/// Waves: a sum of sines with integer wave vectors (cycles per tile), so the map tiles.
#[must_use]
pub fn waves_height(size: u32) -> TextureImage {
    const W: [(f64, f64, f64, f64); 6] = [
        (9.0, 2.0, 1.0, 0.3),
        (5.0, -7.0, 0.8, 1.9),
        (13.0, 4.0, 0.55, 4.0),
        (3.0, 11.0, 0.5, 2.6),
        (17.0, -6.0, 0.35, 5.1),
        (22.0, 15.0, 0.25, 0.7),
    ];
    let norm: f64 = W.iter().map(|w| w.2).sum();
    height_image(format!("waves-height-{size}"), size, |s, t| {
        let h: f64 = W
            .iter()
            .map(|&(kx, ky, a, ph)| a * (TAU * (kx * s + ky * t) + ph).sin())
            .sum();
        0.5 + 0.5 * h / norm
    })
}

/// Corrugated sheet: a sine profile along s only (all offsets on a line: K is singular).
#[must_use]
pub fn corrugated_height(size: u32) -> TextureImage {
    height_image(format!("corrugated-height-{size}"), size, |s, _| {
        0.5 + 0.5 * (TAU * 16.0 * s).sin()
    })
}

/// Brushed metal: fine random streaks along s (height varies along t only, plus a weak
/// variation along s): strongly anisotropic roughness.
#[must_use]
pub fn brushed_height(size: u32) -> TextureImage {
    let n = size.max(1);
    height_image(format!("brushed-height-{size}"), size, move |s, t| {
        let row = t * f64::from(n);
        let (r0, fr) = (row.floor(), row - row.floor());
        let at = |r: f64| {
            let r = r.rem_euclid(f64::from(n)) as u64;
            hash_unit(r) * 0.8 + 0.2 * hash_unit(r * 7919 + ((s * 4.0).floor() as u64))
        };
        let w = fr * fr * (3.0 - 2.0 * fr);
        at(r0) * (1.0 - w) + at(r0 + 1.0) * w
    })
}

/// Scratches: 48 thin straight grooves at random angles on a flat glossy surface.
#[must_use]
pub fn scratches_height(size: u32) -> TextureImage {
    let lines: Vec<[f64; 4]> = (0..48u64)
        .map(|i| {
            let (x, y) = (hash_unit(4 * i), hash_unit(4 * i + 1));
            let a = hash_unit(4 * i + 2) * TAU;
            let len = 0.1 + 0.35 * hash_unit(4 * i + 3);
            [x, y, a.cos() * len, a.sin() * len]
        })
        .collect();
    let w = 1.2 / f64::from(size.max(1));
    height_image(format!("scratches-height-{size}"), size, move |s, t| {
        let mut depth = 0.0f64;
        for l in &lines {
            for (ox, oy) in [(0.0, 0.0), (1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)] {
                let (px, py) = (s + ox - l[0], t + oy - l[1]);
                let ll = l[2] * l[2] + l[3] * l[3];
                let u = ((px * l[2] + py * l[3]) / ll).clamp(0.0, 1.0);
                let (dx, dy) = (px - u * l[2], py - u * l[3]);
                let d2 = (dx * dx + dy * dy) / (w * w);
                depth = depth.max((-d2).exp());
            }
        }
        1.0 - depth
    })
}

fn rough_material(name: &str, kd: [f32; 3], ks: f32, shininess: u32, scale: f32) -> Material {
    Material {
        name: name.into(),
        kd,
        bump: Some(0),
        bump_scale: scale,
        ks: [ks; 3],
        shininess,
        roughness: Some(RoughChoice::Hw),
        ..Material::default()
    }
}

pub(super) fn sun(elev_deg: f64, azimuth_deg: f64, color: [f32; 3]) -> Light {
    let (e, a) = (elev_deg.to_radians(), azimuth_deg.to_radians());
    // Direction the light travels: from the sun (elevation e, at azimuth a from -z) down.
    let d = DVec3::new(a.sin() * e.cos(), -e.sin(), a.cos() * e.cos()).normalize();
    Light::Directional {
        direction: [d.x as f32, d.y as f32, d.z as f32],
        color,
    }
}

#[allow(clippy::too_many_arguments)]
pub(super) fn flat_scene(
    name: &str,
    size: (u32, u32),
    plane: (f32, f32),
    camera: Camera,
    light: Light,
    material: Material,
    tex: TextureImage,
    background: [f32; 4],
) -> Scene {
    let mut mesh = shapes::plane(plane.0, plane.1);
    mesh.name = format!("{name}-surface");
    Scene {
        name: name.into(),
        width: size.0,
        height: size.1,
        camera,
        lights: vec![light],
        ambient: [0.06, 0.06, 0.07],
        background,
        meshes: vec![mesh],
        materials: vec![material],
        textures: vec![tex],
        hw: None,
        warnings: Vec::new(),
    }
}

/// `lake`: a 60 x 60 plane of waves (24 tiles across) seen from 1.5 units above the near edge
/// towards the horizon, a low sun (8 degrees) straight ahead: the sun's glitter path runs
/// from the near waves (resolved) to the far ones (many waves per pixel).
#[must_use]
pub fn lake() -> Scene {
    flat_scene(
        "lake",
        (480, 320),
        (60.0, 24.0),
        Camera {
            eye: [0.0, 1.5, 29.0],
            target: [0.0, 0.0, -10.0],
            up: [0.0, 1.0, 0.0],
            fov_y_deg: 40.0,
            near: 0.1,
            far: 200.0,
            view_override: None,
        },
        sun(8.0, 0.0, [1.0, 0.92, 0.8]),
        rough_material("lake-water", [0.04, 0.12, 0.2], 0.9, 128, 1.5),
        waves_height(256),
        [0.55, 0.6, 0.7, 1.0],
    )
}

/// `corrugated`: corrugated sheet iron receding from the viewer (one-dimensional bumps).
#[must_use]
pub fn corrugated() -> Scene {
    flat_scene(
        "corrugated",
        (480, 320),
        (24.0, 8.0),
        Camera {
            eye: [0.0, 2.0, 12.5],
            target: [0.0, 0.0, -4.0],
            up: [0.0, 1.0, 0.0],
            fov_y_deg: 45.0,
            near: 0.1,
            far: 100.0,
            view_override: None,
        },
        sun(25.0, 20.0, [0.95, 0.95, 0.95]),
        rough_material("sheet-iron", [0.35, 0.36, 0.38], 0.7, 48, 2.0),
        corrugated_height(256),
        [0.2, 0.22, 0.25, 1.0],
    )
}

/// `brushed`: a brushed metal plate (streaks along one axis) under a light from the far side.
#[must_use]
pub fn brushed() -> Scene {
    flat_scene(
        "brushed",
        (480, 320),
        (8.0, 2.0),
        Camera {
            eye: [0.0, 2.2, 4.5],
            target: [0.0, 0.0, -1.0],
            up: [0.0, 1.0, 0.0],
            fov_y_deg: 45.0,
            near: 0.1,
            far: 50.0,
            view_override: None,
        },
        sun(30.0, -15.0, [1.0, 1.0, 1.0]),
        rough_material("brushed-metal", [0.25, 0.25, 0.27], 0.8, 96, 0.6),
        brushed_height(256),
        [0.15, 0.15, 0.17, 1.0],
    )
}

/// `scratches`: small scratches on a glossy black surface, highlight seen at a glancing angle.
#[must_use]
pub fn scratches() -> Scene {
    flat_scene(
        "scratches",
        (480, 320),
        (8.0, 2.0),
        Camera {
            eye: [0.0, 1.6, 4.5],
            target: [0.0, 0.0, -1.5],
            up: [0.0, 1.0, 0.0],
            fov_y_deg: 45.0,
            near: 0.1,
            far: 50.0,
            view_override: None,
        },
        sun(20.0, 0.0, [1.0, 1.0, 1.0]),
        rough_material("glossy-scratched", [0.03, 0.03, 0.035], 0.9, 400, 3.0),
        scratches_height(256),
        [0.3, 0.3, 0.32, 1.0],
    )
}
