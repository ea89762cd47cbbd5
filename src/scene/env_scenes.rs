//! Built-in scenes for environment maps filtered by the roughness pyramid (issue 16; Schilling
//! 1997, "balanced system"): a wavy lake reflecting the procedural sky from near to far, a
//! bumpy chrome sphere and a brushed metal plate under the sky. Every material is a bump
//! material with `roughness = hw` and `env_filter = hw`, so `--vary env_filter=...` and
//! `--vary roughness=...` switch them.

use super::geometry::{fit_camera, fit_light};
use super::texture::ripples_height;
use super::{shapes, EnvMaterial, EnvSource, Material, RoughChoice, Scene};

/// The sky cube of the built-in scenes: 256 texels per face, the hardware's filter.
const SKY: EnvMaterial = EnvMaterial {
    filter: None,
    size: 256,
    source: EnvSource::Sky,
};

/// Shininess of the mirrors: a base roughness `1/sqrt(1024)` (1/32 slope) in the D map.
const MIRROR_SHININESS: u32 = 1024;

/// `sky-lake`: the `lake` waves (near to far) reflecting the sky, `ks` 0.8.
#[must_use]
pub fn sky_lake() -> Scene {
    let mut s = super::rough_scenes::lake();
    s.name = "sky-lake".into();
    let m = &mut s.materials[0];
    m.name = "lake-mirror".into();
    m.kd = [0.02, 0.05, 0.08];
    m.ks = [0.8; 3];
    m.shininess = MIRROR_SHININESS;
    m.env = Some(SKY);
    s
}

/// `brushed-sky`: the `brushed` metal plate reflecting the sky.
#[must_use]
pub fn brushed_sky() -> Scene {
    let mut s = super::rough_scenes::brushed();
    s.name = "brushed-sky".into();
    let m = &mut s.materials[0];
    m.ks = [0.85; 3];
    m.shininess = MIRROR_SHININESS;
    m.env = Some(SKY);
    s
}

/// `chrome-sphere`: a rippled chrome sphere reflecting the sky, 480x360.
#[must_use]
pub fn chrome_sphere() -> Scene {
    let mut ball = shapes::sphere(1.0, 96, 48);
    ball.material = 0;
    let meshes = vec![ball];
    let camera = fit_camera(&meshes, 480, 360);
    let light = fit_light(&camera);
    Scene {
        name: "chrome-sphere".into(),
        width: 480,
        height: 360,
        camera,
        lights: vec![light],
        ambient: [0.02; 3],
        background: [0.3, 0.32, 0.36, 1.0],
        meshes,
        materials: vec![Material {
            name: "chrome".into(),
            kd: [0.02; 3],
            ks: [0.9; 3],
            shininess: MIRROR_SHININESS,
            bump: Some(0),
            bump_scale: 1.0,
            cull_back: true,
            roughness: Some(RoughChoice::Hw),
            env: Some(SKY),
            ..Material::default()
        }],
        textures: vec![ripples_height(256)],
        hw: None,
        warnings: Vec::new(),
    }
}
