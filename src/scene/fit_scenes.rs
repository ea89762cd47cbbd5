//! Built-in scenes for Fournier lobes fitted to a bump map (issue 15): `two-slope`, a plane of
//! fine V-grooves receding from the viewer, where the texels of the far MIP levels hold two
//! distinct slopes (one Gaussian lobe must fail, two lobes hold them). Its material has
//! `fournier_lobes = hw`, so `--vary fournier_lobes=1,2,4,8` switches K.

use super::rough_scenes::{flat_scene, sun};
use super::texture::height_image;
use super::{Camera, LobeCount, Material, Scene, TextureImage};

/// V-grooves across `s` (ridges along `t`), `period` texels wide: heights rise and fall linearly, so the offsets
/// take two slopes of opposite sign (and, at the ridges and valleys, the central difference
/// between them).
#[must_use]
pub fn vgroove_height(size: u32, period: u32) -> TextureImage {
    let cycles = f64::from(size) / f64::from(period.max(1));
    height_image(
        format!("vgroove-height-{size}-{period}"),
        size,
        move |s, _| {
            let x = (s * cycles).fract();
            1.0 - (2.0 * x - 1.0).abs()
        },
    )
}

/// `two-slope`: a 40 x 40 plane of V-grooves (20 tiles of 16 grooves, 8 texels each), seen
/// from 1.5 units above it towards the horizon, lit by a low sun straight ahead: near the
/// viewer the grooves are resolved, far away every pixel covers many of them, and the two
/// slopes reflect the sun in two glitter paths left and right of the centre.
#[must_use]
pub fn two_slope() -> Scene {
    let material = Material {
        name: "vgrooves".into(),
        kd: [0.25, 0.25, 0.28],
        bump: Some(0),
        bump_scale: 2.0,
        ks: [0.8; 3],
        shininess: 64,
        fournier_lobes: Some(LobeCount::Hw),
        ..Material::default()
    };
    flat_scene(
        "two-slope",
        (320, 200),
        (40.0, 20.0),
        Camera {
            eye: [0.0, 1.5, 19.0],
            target: [0.0, 0.0, -6.0],
            up: [0.0, 1.0, 0.0],
            fov_y_deg: 45.0,
            near: 0.1,
            far: 100.0,
            view_override: None,
        },
        sun(20.0, 0.0, [1.0, 0.95, 0.9]),
        material,
        vgroove_height(128, 8),
        [0.2, 0.22, 0.25, 1.0],
    )
}
