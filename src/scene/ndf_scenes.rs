//! Built-in scenes of NDF mapping (Olano and North 1997), shaded by `ndf-fetch`/`ndf-shade`
//! (see `crate::pipeline::ndf`): `ripple-sphere` (their Figure 1: one rippled sphere at
//! three distances, the highlight blurs and stretches along the ripples as the MIP level
//! coarsens), `lod-pair` (their Figure 2: one wavy object at two polygon counts, per-vertex
//! normals against the NDF map), `foil` (crumpled foil: many small facets whose coarse
//! levels become a broad, anisotropic lobe).

use super::{shapes, Camera, Light, Material, Mesh, Scene, TextureImage};
use crate::shading::ndf::{procedural_normals, wave_slope};
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

/// Sphere tessellations of `lod-pair`: coarse 12x6 and fine 64x32 quads.
pub const LOD_PAIR_TESSELLATIONS: [(u32, u32); 2] = [(12, 6), (64, 32)];
/// Largest slope of the `waves` normal map of `lod-pair`.
pub const LOD_PAIR_AMPLITUDE: f64 = 0.3;

/// A sphere whose vertex normals sample the wavy surface of `lod-pair`: the `waves` normal map
/// applied at each vertex as the bump and NDF paths apply it per pixel (offset
/// `f_u = -n_x/n_z = slope` along `t_u` of the default main frame, `t_u = -normalize(p_v x n)`):
/// what per-vertex normals of that smooth object are.
fn wavy_vertex_normals(mut m: Mesh) -> Mesh {
    for (n, uv) in m.normals.iter_mut().zip(&m.uvs) {
        let nn = DVec3::from(n.map(f64::from));
        let (phi, th) = (
            2.0 * std::f64::consts::PI * f64::from(uv[0]),
            std::f64::consts::PI * f64::from(uv[1]),
        );
        let pv = DVec3::new(th.cos() * phi.sin(), -th.sin(), th.cos() * phi.cos());
        let tu = -pv.cross(nn).normalize_or_zero();
        let w = (nn + tu * wave_slope(f64::from(uv[0]), LOD_PAIR_AMPLITUDE)).normalize();
        *n = [w.x as f32, w.y as f32, w.z as f32];
    }
    m
}

/// `lod-pair` (Olano and North, Figure 2): one wavy object (a sphere with 8 sine waves across u,
/// slope up to 0.3) at two polygon counts, 12x6 (left) and 64x32 (right), shininess 128.
/// Top row, the paper's a) and b): per-vertex normals of the wavy surface, Phong-interpolated
/// and shaded per pixel with Blinn-Phong (a bump material on a flat normal map): the fine mesh
/// resolves the waves (8 vertices per wave), the coarse one aliases them (1.5 per wave), so the
/// highlight changes with the polygon count. Bottom row, c) and d): the smooth sphere's normals
/// with the waves in an NDF map (texture 0): the per-pixel NDF in the interpolated frame keeps
/// the highlights alike on both meshes, and its coarse MIP levels carry the waves' spread.
pub fn lod_pair() -> Scene {
    let [(cs, cr), (fs, fr)] = LOD_PAIR_TESSELLATIONS;
    let r = 0.62;
    let (x, y) = (1.05, 0.72);
    let mut phong = ndf_material("phong", [0.6, 0.3, 0.25], 128);
    phong.ndf = false;
    phong.bump = Some(1);
    let mut sc = scene(
        "lod-pair",
        vec![
            placed(
                shapes::sphere(1.0, cs, cr),
                "ndf-coarse",
                DVec3::new(-x, -y, 0.0),
                r,
            ),
            placed(
                shapes::sphere(1.0, fs, fr),
                "ndf-fine",
                DVec3::new(x, -y, 0.0),
                r,
            ),
            placed(
                wavy_vertex_normals(shapes::sphere(1.0, cs, cr)),
                "phong-coarse",
                DVec3::new(-x, y, 0.0),
                r,
            ),
            placed(
                wavy_vertex_normals(shapes::sphere(1.0, fs, fr)),
                "phong-fine",
                DVec3::new(x, y, 0.0),
                r,
            ),
        ],
        vec![ndf_material("ndf", [0.6, 0.3, 0.25], 128), phong],
        normal_texture("waves", 128, LOD_PAIR_AMPLITUDE),
    );
    for m in &mut sc.meshes[2..] {
        m.material = 1;
    }
    let mut flat = normal_texture("waves", 16, 0.0);
    flat.name = "flat normals".into();
    sc.textures.push(flat);
    sc
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
