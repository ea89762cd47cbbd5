//! Built-in procedural scenes. `w1-plane` and `w2-mesh` reproduce the Mesa anchor workloads of
//! `/work/shared/anchors/mesa/mesa_anchor.c` exactly: texture generator, integer MIP chain,
//! geometry order, GL modelview (as `Camera::view_override`) and `glFrustum` projection.

use glam::{DMat4, DVec3};

use super::geometry::{fit_camera, fit_light};
use super::gl_matrix::{self, Mat4f};
use super::texture::{
    bricks_height, checker, mesa_texture, procedural, ripples_height, MESA_TEX_SIZE,
};
use super::{shapes, Camera, GlView, Light, MainDirection, Material, Mesh, Scene, WrapMode};
use crate::{Error, Result};

/// Built-in scene names with a one-line description (for `texsim scenes`).
pub const BUILTIN: &[(&str, &str)] = &[
    ("demo", "textured ground plane to the horizon (minification), lit textured torus and sphere, bump-mapped brick sphere"),
    ("w1-plane", "Mesa anchor W1: 1024x1024, one textured quad receding to the horizon, unlit (GL_REPLACE)"),
    ("w2-mesh", "Mesa anchor W2: 1024x1024, 256x128 textured torus (65536 triangles), unlit, culling off"),
    ("sphere", "a lit, checker-textured UV sphere, fitted camera, 1024x768"),
    ("bumps", "bump-mapped brick sphere, rippled torus and brick tile under a grazing directional light and a point light, 640x480"),
    ("as-metal", "Ashikhmin-Shirley metal spheres over n_u x n_v = 1..10000 under a light (paper Fig. 3), 400x400"),
    ("as-plastic", "Ashikhmin-Shirley red plastic spheres over n_u x n_v = 1..10000 under a light (paper Fig. 5), 400x400"),
    ("as-brushed", "brushed-metal torus (one main direction) and sphere (m = p_u), Ashikhmin-Shirley, 640x480"),
    ("lake", "roughness: waves on a lake under a low sun, near to far (highlight widens with distance), 480x320"),
    ("corrugated", "roughness: corrugated sheet iron receding (one-dimensional bumps, singular K), 480x320"),
    ("brushed", "roughness: brushed metal plate (anisotropic streaks), 480x320"),
    ("scratches", "roughness: small scratches on a glossy surface, 480x320"),
    ("sky-lake", "environment map: the lake's waves reflecting the procedural sky, near to far, filtered by env_filter, 480x320"),
    ("chrome-sphere", "environment map: a rippled chrome sphere reflecting the sky, 480x360"),
    ("brushed-sky", "environment map: the brushed metal plate reflecting the sky (anisotropic roughness), 480x320"),
    ("ripple-sphere", "NDF mapping (Olano-North Fig. 1): a rippled sphere at three distances, highlight blurs and stretches with the MIP level, 480x320"),
    ("lod-pair", "NDF mapping (Olano-North Fig. 2): a wavy sphere at two polygon counts, per-vertex normals vs NDF map, 480x320"),
    ("foil", "NDF mapping: crumpled foil tile, shininess 256, 480x320"),
    ("fournier-fig2", "Fournier multiple surfaces (Fig. 2): spheres with an anisotropic lobe pair and 2, 3 and 7 normals, 480x128"),
    ("fournier-velvet", "Fournier multiple surfaces (Fig. 3): velvet lobes on a torus and a sphere, 320x240"),
    ("fournier-silk", "Fournier multiple surfaces (Fig. 4): silk lobes on the same geometry, 320x240"),
    ("two-slope", "Fournier lobes fitted to a bump map: fine V-grooves (two slopes per far texel) receding, fournier_lobes = hw, 320x200"),
];

/// A built-in scene by name; an unknown name is an error listing the known ones.
pub fn builtin(name: &str) -> Result<Scene> {
    let scene = match name {
        "demo" => demo()?,
        "w1-plane" => w1_plane(),
        "w2-mesh" => w2_mesh(),
        "sphere" => sphere()?,
        "bumps" => bumps(),
        "as-metal" => super::as_scenes::as_metal(),
        "as-plastic" => super::as_scenes::as_plastic(),
        "as-brushed" => super::as_scenes::as_brushed(),
        "lake" => super::rough_scenes::lake(),
        "corrugated" => super::rough_scenes::corrugated(),
        "brushed" => super::rough_scenes::brushed(),
        "scratches" => super::rough_scenes::scratches(),
        "sky-lake" => super::env_scenes::sky_lake(),
        "chrome-sphere" => super::env_scenes::chrome_sphere(),
        "brushed-sky" => super::env_scenes::brushed_sky(),
        "ripple-sphere" => super::ndf_scenes::ripple_sphere(),
        "lod-pair" => super::ndf_scenes::lod_pair(),
        "foil" => super::ndf_scenes::foil(),
        "fournier-fig2" => super::lobe_scenes::fig2(),
        "fournier-velvet" => super::lobe_scenes::velvet(),
        "fournier-silk" => super::lobe_scenes::silk(),
        "two-slope" => super::fit_scenes::two_slope(),
        other => {
            let known: Vec<&str> = BUILTIN.iter().map(|(n, _)| *n).collect();
            return Err(Error::msg(format!(
                "unknown built-in scene '{other}' (known: {})",
                known.join(", ")
            )));
        }
    };
    super::validate(&scene).map_err(|e| e.context(format!("built-in scene '{name}'")))?;
    Ok(scene)
}

/// A camera with an exact view matrix and the binary32 model-view-projection Mesa builds for
/// it; eye/target/up are derived from the view for display only.
fn camera_from_view(view: DMat4, mvp_f32: Mat4f, fov_y_deg: f64, near: f64, far: f64) -> Camera {
    let inv = view.inverse();
    let eye = inv.transform_point3(DVec3::ZERO);
    let target = eye + inv.transform_vector3(DVec3::NEG_Z);
    let up = inv.transform_vector3(DVec3::Y);
    Camera {
        eye: eye.to_array(),
        target: target.to_array(),
        up: up.to_array(),
        fov_y_deg,
        near,
        far,
        view_override: Some(GlView {
            view,
            mvp_f32: Some(mvp_f32),
        }),
    }
}

fn mesa_material() -> Material {
    Material {
        name: "mesa-replace".into(),
        kd: [1.0; 3],
        texture: Some(0),
        wrap_s: WrapMode::Repeat,
        wrap_t: WrapMode::Repeat,
        lit: false,
        cull_back: false,
        ..Material::default()
    }
}

fn mesa_scene(name: &str, mesh: Mesh, camera: Camera) -> Scene {
    Scene {
        name: name.into(),
        width: 1024,
        height: 1024,
        camera,
        lights: Vec::new(),
        ambient: [0.0; 3],
        background: [0.0; 4],
        meshes: vec![mesh],
        materials: vec![mesa_material()],
        textures: vec![mesa_texture(MESA_TEX_SIZE)],
        hw: None,
        warnings: Vec::new(),
    }
}

/// The W1 modelview: `glRotated(10, 1,0,0); glTranslated(0,-1,0)`.
#[must_use]
pub fn w1_view() -> DMat4 {
    DMat4::from_rotation_x(10f64.to_radians()) * DMat4::from_translation(DVec3::new(0.0, -1.0, 0.0))
}

/// The W2 modelview: `glTranslated(0,0,-3.2); glRotated(-50, 1,0,0); glRotated(20, 0,0,1)`.
#[must_use]
pub fn w2_view() -> DMat4 {
    DMat4::from_translation(DVec3::new(0.0, 0.0, -3.2))
        * DMat4::from_rotation_x((-50f64).to_radians())
        * DMat4::from_rotation_z(20f64.to_radians())
}

fn w1_plane() -> Scene {
    const S: f32 = 256.0;
    let mesh = Mesh {
        name: "w1-plane".into(),
        positions: vec![
            [-S, 0.0, 1.0],
            [S, 0.0, 1.0],
            [S, 0.0, 1.0 - 2.0 * S],
            [-S, 0.0, 1.0 - 2.0 * S],
        ],
        normals: vec![[0.0, 1.0, 0.0]; 4],
        uvs: vec![[0.0, 0.0], [16.0, 0.0], [16.0, 16.0], [0.0, 16.0]],
        indices: vec![[0, 1, 2], [0, 2, 3]],
        material: 0,
    };
    // glFrustum(-top, top, -top, top, 0.1, 1000) with top = n tan 30 deg: 60 deg, aspect 1.
    mesa_scene(
        "w1-plane",
        mesh,
        camera_from_view(w1_view(), gl_matrix::w1_plane_mvp(), 60.0, 0.1, 1000.0),
    )
}

fn w2_mesh() -> Scene {
    let mut mesh = shapes::torus(1.0, 0.4, 256, 128, 2.0);
    mesh.name = "w2-mesh".into();
    // glFrustum with top = 1 * tan 22.5 deg: 45 deg, aspect 1, near 1, far 10.
    mesa_scene(
        "w2-mesh",
        mesh,
        camera_from_view(w2_view(), gl_matrix::w2_mesh_mvp(), 45.0, 1.0, 10.0),
    )
}

fn demo() -> Result<Scene> {
    let mut ground = shapes::plane(1600.0, 200.0);
    ground.name = "ground".into();
    ground.material = 0;
    let mut torus = shapes::torus(0.55, 0.22, 96, 48, 3.0);
    torus.name = "torus".into();
    torus.material = 1;
    super::geometry::transform_mesh(
        &mut torus,
        &(DMat4::from_translation(DVec3::new(0.75, 0.95, -1.9))
            * DMat4::from_rotation_y(35f64.to_radians())
            * DMat4::from_rotation_x(-65f64.to_radians())),
    );
    let mut ball = shapes::sphere(0.7, 64, 32);
    ball.name = "sphere".into();
    ball.material = 2;
    super::geometry::transform_mesh(
        &mut ball,
        &DMat4::from_translation(DVec3::new(-1.6, 0.7, -4.5)),
    );
    let mut bumped = shapes::sphere(0.45, 48, 24);
    bumped.name = "brick-sphere".into();
    bumped.material = 3;
    super::geometry::transform_mesh(
        &mut bumped,
        &(DMat4::from_translation(DVec3::new(-0.55, 0.5, -2.1))
            * DMat4::from_rotation_y(-30f64.to_radians())),
    );
    let materials = vec![
        Material {
            name: "ground".into(),
            kd: [1.0; 3],
            texture: Some(0),
            ..Material::default()
        },
        Material {
            name: "torus".into(),
            kd: [1.0; 3],
            texture: Some(1),
            cull_back: true,
            ..Material::default()
        },
        Material {
            name: "sphere".into(),
            kd: [1.0; 3],
            texture: Some(2),
            cull_back: true,
            ..Material::default()
        },
        Material {
            name: "brick-sphere".into(),
            kd: [0.75, 0.38, 0.28],
            bump: Some(3),
            bump_scale: 2.0,
            ks: [0.35; 3],
            shininess: 24,
            cull_back: true,
            ..Material::default()
        },
    ];
    let mut ground_tex = procedural("tiles", 512)?;
    ground_tex.name = "demo-ground".into();
    let torus_tex = checker(64, 8, [250, 200, 60], [150, 30, 40]);
    let sphere_tex = mesa_texture(256);
    let dir = DVec3::new(0.55, -0.75, -0.4).normalize();
    Ok(Scene {
        name: "demo".into(),
        width: 1024,
        height: 768,
        camera: Camera {
            eye: [0.0, 1.6, 1.2],
            target: [0.0, 0.85, -4.0],
            up: [0.0, 1.0, 0.0],
            fov_y_deg: 50.0,
            near: 0.1,
            far: 2000.0,
            view_override: None,
        },
        lights: vec![Light::Directional {
            direction: [dir.x as f32, dir.y as f32, dir.z as f32],
            color: [0.85, 0.82, 0.75],
        }],
        ambient: [0.15, 0.16, 0.2],
        background: [0.55, 0.68, 0.86, 1.0],
        meshes: vec![ground, torus, ball, bumped],
        materials,
        textures: vec![ground_tex, torus_tex, sphere_tex, bricks_height(256)],
        hw: None,
        warnings: Vec::new(),
    })
}

fn sphere() -> Result<Scene> {
    let mut ball = shapes::sphere(1.0, 96, 48);
    ball.material = 0;
    let mut tex = procedural("checker", 256)?;
    tex.name = "sphere-checker".into();
    let meshes = vec![ball];
    let camera = fit_camera(&meshes, 1024, 768);
    let light = fit_light(&camera);
    Ok(Scene {
        name: "sphere".into(),
        width: 1024,
        height: 768,
        camera,
        lights: vec![light],
        ambient: [0.15; 3],
        background: super::obj::OBJ_BACKGROUND,
        meshes,
        materials: vec![Material {
            name: "sphere".into(),
            kd: [1.0; 3],
            texture: Some(0),
            cull_back: true,
            ..Material::default()
        }],
        textures: vec![tex],
        hw: None,
        warnings: Vec::new(),
    })
}

/// `bumps`: three bump-mapped objects (frame from the hardware's `frame_kind`, so
/// `--vary frame=...` switches all of them): a UV sphere with bricks (poles, seam), a torus
/// with ripples and a brick tile lying flat, lit by a directional light 8 degrees above the
/// tile (grazing) and a point light.
fn bumps() -> Scene {
    let mut ball = shapes::sphere(0.8, 48, 24);
    ball.name = "brick-sphere".into();
    ball.material = 0;
    super::geometry::transform_mesh(
        &mut ball,
        &(DMat4::from_translation(DVec3::new(-0.95, 0.85, 0.0))
            * DMat4::from_rotation_y(20f64.to_radians())),
    );
    let mut torus = shapes::torus(0.55, 0.22, 64, 32, 2.0);
    torus.name = "ripple-torus".into();
    torus.material = 1;
    super::geometry::transform_mesh(
        &mut torus,
        &(DMat4::from_translation(DVec3::new(1.0, 0.75, 0.1))
            * DMat4::from_rotation_y((-30f64).to_radians())
            * DMat4::from_rotation_x((-60f64).to_radians())),
    );
    let mut tile = shapes::plane(4.4, 2.0);
    tile.name = "brick-tile".into();
    tile.material = 2;
    let bump = |name: &str, kd: [f32; 3], tex: usize, scale: f32| Material {
        name: name.into(),
        kd,
        bump: Some(tex),
        bump_scale: scale,
        ks: [0.35; 3],
        shininess: 24,
        cull_back: true,
        ..Material::default()
    };
    let materials = vec![
        bump("brick-sphere", [0.75, 0.38, 0.28], 0, 2.0),
        Material {
            main_direction: MainDirection::Pu,
            ..bump("ripple-torus", [0.35, 0.55, 0.8], 1, 3.0)
        },
        Material {
            main_direction: MainDirection::Constant([0.0, 0.0, -1.0]),
            cull_back: false,
            ..bump("brick-tile", [0.7, 0.66, 0.6], 0, 2.0)
        },
    ];
    let graze = DVec3::new(-1.0, -(8f64.to_radians().tan()), -0.35).normalize();
    Scene {
        name: "bumps".into(),
        width: 640,
        height: 480,
        camera: Camera {
            eye: [0.0, 2.4, 3.6],
            target: [0.0, 0.45, 0.0],
            up: [0.0, 1.0, 0.0],
            fov_y_deg: 45.0,
            near: 0.1,
            far: 50.0,
            view_override: None,
        },
        lights: vec![
            Light::Directional {
                direction: [graze.x as f32, graze.y as f32, graze.z as f32],
                color: [0.8, 0.75, 0.65],
            },
            Light::Point {
                position: [0.3, 2.2, 1.6],
                color: [0.45, 0.5, 0.6],
            },
        ],
        ambient: [0.08, 0.08, 0.1],
        background: [0.1, 0.11, 0.14, 1.0],
        meshes: vec![ball, torus, tile],
        materials,
        textures: vec![bricks_height(256), ripples_height(256)],
        hw: None,
        warnings: Vec::new(),
    }
}
