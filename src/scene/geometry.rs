//! Scene geometry helpers: area-weighted vertex normals (sum of un-normalized face cross
//! products, Max 1999 "Weights for computing vertex normals" baseline), bounding-sphere camera
//! fit, a fitted key light, affine mesh transforms and whole-scene validation.

use glam::{DMat3, DMat4, DVec3};

use super::{Camera, Light, Mesh, Scene};
use crate::{Error, Result};

/// Normal given to a vertex whose accumulated normal has zero (or non-finite) length.
pub const FALLBACK_NORMAL: [f32; 3] = [0.0, 0.0, 1.0];

/// Vertical field of view used by [`fit_camera`], degrees.
pub const FIT_FOV_Y_DEG: f64 = 45.0;

/// Per-vertex normals: the normalized sum of the (area-weighted) face normals `(b-a) x (c-a)`
/// of the triangles using the vertex. Triangles with an out-of-range index or a non-finite
/// cross product are skipped; a vertex with a zero-length sum gets [`FALLBACK_NORMAL`].
#[must_use]
pub fn smooth_normals(positions: &[[f32; 3]], indices: &[[u32; 3]]) -> Vec<[f32; 3]> {
    let n = positions.len();
    let mut acc = vec![DVec3::ZERO; n];
    for tri in indices {
        let [a, b, c] = tri.map(|i| i as usize);
        if a >= n || b >= n || c >= n {
            continue;
        }
        let pa = DVec3::from(positions[a].map(f64::from));
        let pb = DVec3::from(positions[b].map(f64::from));
        let pc = DVec3::from(positions[c].map(f64::from));
        let cr = (pb - pa).cross(pc - pa);
        if !cr.is_finite() {
            continue;
        }
        acc[a] += cr;
        acc[b] += cr;
        acc[c] += cr;
    }
    acc.into_iter()
        .map(|v| {
            let len = v.length();
            if len > 0.0 && len.is_finite() {
                let u = v / len;
                [u.x as f32, u.y as f32, u.z as f32]
            } else {
                FALLBACK_NORMAL
            }
        })
        .collect()
}

/// Bounding sphere (centre of the axis-aligned box, radius to the farthest finite vertex).
/// No finite vertex: centre 0, radius 1. A zero radius becomes 1.
#[must_use]
pub fn bounding_sphere(meshes: &[Mesh]) -> (DVec3, f64) {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    let finite = meshes
        .iter()
        .flat_map(|m| m.positions.iter())
        .map(|p| DVec3::from(p.map(f64::from)))
        .filter(|p| p.is_finite());
    for p in finite.clone() {
        lo = lo.min(p);
        hi = hi.max(p);
    }
    if !lo.is_finite() || !hi.is_finite() {
        return (DVec3::ZERO, 1.0);
    }
    let c = (lo + hi) * 0.5;
    let r = finite.map(|p| p.distance(c)).fold(0.0, f64::max);
    (c, if r > 0.0 { r } else { 1.0 })
}

/// A camera that frames all meshes: looks at the bounding-sphere centre from the
/// front-upper-right diagonal (+x, +y, +z), vertical FOV 45 deg, distance such that the sphere
/// fits the narrower of the two FOVs with a 10 % margin; near/far bracket the sphere.
#[must_use]
pub fn fit_camera(meshes: &[Mesh], width: u32, height: u32) -> Camera {
    let (c, r) = bounding_sphere(meshes);
    let aspect = f64::from(width.max(1)) / f64::from(height.max(1));
    let half_v = (FIT_FOV_Y_DEG * 0.5).to_radians();
    let half_h = (half_v.tan() * aspect).atan();
    let half = half_v.min(half_h);
    let dist = r / half.sin() * 1.1;
    let dir = DVec3::new(1.0, 0.75, 1.6).normalize();
    let eye = c + dir * dist;
    let near = (dist - 1.2 * r).max(0.01 * r);
    let far = dist + 1.2 * r;
    Camera {
        eye: eye.to_array(),
        target: c.to_array(),
        up: [0.0, 1.0, 0.0],
        fov_y_deg: FIT_FOV_Y_DEG,
        near,
        far,
        view_override: None,
    }
}

/// A white-ish (0.85) directional key light coming from the upper left of `camera`, slightly
/// from behind it (pairs with an ambient of 0.15 so lit colours stay within 0..1).
#[must_use]
pub fn fit_light(camera: &Camera) -> Light {
    let view = camera.view();
    // Camera axes in world space: rows of the view rotation.
    let inv = view.inverse();
    let right = inv.transform_vector3(DVec3::X);
    let up = inv.transform_vector3(DVec3::Y);
    let back = inv.transform_vector3(DVec3::Z);
    let to_light = (-right + 1.2 * up + 0.8 * back).normalize_or_zero();
    let d = if to_light.is_finite() && to_light != DVec3::ZERO {
        -to_light
    } else {
        DVec3::new(0.5, -1.0, -0.5).normalize()
    };
    Light::Directional {
        direction: [d.x as f32, d.y as f32, d.z as f32],
        color: [0.85; 3],
    }
}

/// Applies an affine transform to a mesh in place (normals by the inverse transpose,
/// re-normalized; a degenerate result becomes [`FALLBACK_NORMAL`]).
pub fn transform_mesh(mesh: &mut Mesh, m: &DMat4) {
    for p in &mut mesh.positions {
        let q = m.transform_point3(DVec3::from(p.map(f64::from)));
        *p = [q.x as f32, q.y as f32, q.z as f32];
    }
    let lin = DMat3::from_mat4(*m);
    let nm = if lin.determinant().abs() > 0.0 {
        lin.inverse().transpose()
    } else {
        lin
    };
    for n in &mut mesh.normals {
        let q = (nm * DVec3::from(n.map(f64::from))).normalize_or_zero();
        *n = if q != DVec3::ZERO && q.is_finite() {
            [q.x as f32, q.y as f32, q.z as f32]
        } else {
            FALLBACK_NORMAL
        };
    }
    if lin.determinant() < 0.0 {
        // A mirroring transform flips the winding; restore counter-clockwise fronts.
        for t in &mut mesh.indices {
            t.swap(1, 2);
        }
    }
}

fn finite3(v: &[f32; 3]) -> bool {
    v.iter().all(|c| c.is_finite())
}

fn check_finite(name: &str, v: &[f32]) -> Result<()> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(())
    } else {
        Err(Error::field(name, format!("{v:?} must be finite")))
    }
}

/// Checks a scene: output size in 1..=8192, finite camera with `0 < near < far` and a
/// non-degenerate view, finite lights/ambient/background, per mesh finite positions, one finite
/// normal per position, UVs empty or one finite pair per position, indices in range, a valid
/// material index; at least one triangle overall; material texture indices in range; texture
/// sizes matching their texel counts (prebuilt levels following the MIP size rule).
pub fn validate(scene: &Scene) -> Result<()> {
    for (name, v) in [("width", scene.width), ("height", scene.height)] {
        if !(1..=8192).contains(&v) {
            return Err(Error::field(name, format!("{v} is outside 1..=8192")));
        }
    }
    let cam = &scene.camera;
    let cam_ok = cam
        .eye
        .iter()
        .chain(&cam.target)
        .chain(&cam.up)
        .all(|c| c.is_finite());
    if !cam_ok {
        return Err(Error::field("camera", "eye/target/up must be finite"));
    }
    if !(cam.fov_y_deg > 0.0 && cam.fov_y_deg < 180.0) {
        return Err(Error::field(
            "camera.fov_y_deg",
            format!("{} is outside (0, 180)", cam.fov_y_deg),
        ));
    }
    if !(cam.near > 0.0 && cam.far > cam.near && cam.far.is_finite()) {
        return Err(Error::field(
            "camera.near",
            format!("need 0 < near < far (near {}, far {})", cam.near, cam.far),
        ));
    }
    match cam.view_override {
        Some(v)
            if !v.view.is_finite()
                || v.mvp_f32
                    .is_some_and(|m| !m.iter().flatten().all(|x| x.is_finite())) =>
        {
            return Err(Error::field("camera.view_override", "must be finite"));
        }
        Some(_) => {}
        None => {
            let f = DVec3::from(cam.target) - DVec3::from(cam.eye);
            if f.length() == 0.0 {
                return Err(Error::field("camera.target", "equals camera.eye"));
            }
            if f.cross(DVec3::from(cam.up)).length() <= 1e-12 * f.length() {
                return Err(Error::field(
                    "camera.up",
                    "is zero or parallel to the view direction",
                ));
            }
        }
    }
    for (i, l) in scene.lights.iter().enumerate() {
        let (v, c) = match l {
            Light::Directional { direction, color } => (direction, color),
            Light::Point { position, color } => (position, color),
        };
        if !finite3(v) || !finite3(c) {
            return Err(Error::field(&format!("lights[{i}]"), "must be finite"));
        }
    }
    check_finite("ambient", &scene.ambient)?;
    check_finite("background", &scene.background)?;
    for (mi, m) in scene.materials.iter().enumerate() {
        let effects = [
            ("brdf", m.brdf.is_some()),
            ("roughness", m.roughness.is_some()),
            ("ndf", m.ndf),
        ];
        let on: Vec<&str> = effects.iter().filter(|e| e.1).map(|e| e.0).collect();
        if on.len() > 1 {
            return Err(Error::field(
                &format!("materials[{mi}]"),
                format!(
                    "{} are alternative shading models; choose one",
                    on.join(" and ")
                ),
            ));
        }
        if let Some(b) = &m.brdf {
            b.validate(&format!("materials[{mi}]"))?;
            if let Some(t) = b.exponent_map.filter(|&t| t >= scene.textures.len()) {
                return Err(Error::field(
                    &format!("materials[{mi}].exponent_map"),
                    format!("index {t} out of range ({} textures)", scene.textures.len()),
                ));
            }
        }
    }
    for (ti, t) in scene.textures.iter().enumerate() {
        let what = format!("textures[{ti}] '{}'", t.name);
        if t.width == 0 || t.height == 0 || t.width > 65536 || t.height > 65536 {
            return Err(Error::field(
                &what,
                format!("bad size {}x{}", t.width, t.height),
            ));
        }
        if t.texels.len() != t.width as usize * t.height as usize {
            return Err(Error::field(&what, "texel count does not match its size"));
        }
        if let Some(levels) = &t.prebuilt_levels {
            let sizes = crate::maps::chain_sizes(t.width, t.height);
            if levels.len() + 1 != sizes.len() {
                return Err(Error::field(
                    &what,
                    "prebuilt MIP level count does not reach 1x1",
                ));
            }
            for (li, ((w, h, tx), &(ew, eh))) in levels.iter().zip(&sizes[1..]).enumerate() {
                if (*w, *h) != (ew, eh) || tx.len() != ew as usize * eh as usize {
                    return Err(Error::field(
                        &what,
                        format!("prebuilt level {} should be {ew}x{eh}", li + 1),
                    ));
                }
            }
        }
    }
    for (mi, m) in scene.materials.iter().enumerate() {
        if let Some(t) = m.texture {
            if t >= scene.textures.len() {
                return Err(Error::field(
                    &format!("materials[{mi}] '{}'.texture", m.name),
                    format!("index {t} out of range ({} textures)", scene.textures.len()),
                ));
            }
        }
        if !finite3(&m.kd) {
            return Err(Error::field(
                &format!("materials[{mi}] '{}'.kd", m.name),
                "must be finite",
            ));
        }
        let field = |f: &str| format!("materials[{mi}] '{}'.{f}", m.name);
        if let Some(t) = m.bump {
            if t >= scene.textures.len() {
                return Err(Error::field(
                    &field("bump"),
                    format!("index {t} out of range ({} textures)", scene.textures.len()),
                ));
            }
        }
        if !m.bump_scale.is_finite() {
            return Err(Error::field(&field("bump_scale"), "must be finite"));
        }
        if !finite3(&m.ks) || m.ks.iter().any(|&c| c < 0.0) {
            return Err(Error::field(&field("ks"), "must be finite and >= 0"));
        }
        if let super::MainDirection::Constant(d) = m.main_direction {
            if !finite3(&d) {
                return Err(Error::field(&field("main_direction"), "must be finite"));
            }
        }
    }
    for (mi, mesh) in scene.meshes.iter().enumerate() {
        let what = |f: &str| format!("meshes[{mi}] '{}'.{f}", mesh.name);
        let n = mesh.positions.len();
        if let Some(i) = mesh.positions.iter().position(|p| !finite3(p)) {
            return Err(Error::field(
                &what("positions"),
                format!("vertex {i} is not finite"),
            ));
        }
        if mesh.normals.len() != n {
            return Err(Error::field(
                &what("normals"),
                "need one normal per position",
            ));
        }
        if let Some(i) = mesh.normals.iter().position(|p| !finite3(p)) {
            return Err(Error::field(
                &what("normals"),
                format!("normal {i} is not finite"),
            ));
        }
        if !mesh.uvs.is_empty() && mesh.uvs.len() != n {
            return Err(Error::field(
                &what("uvs"),
                "need none or one uv per position",
            ));
        }
        if let Some(i) = mesh
            .uvs
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(Error::field(&what("uvs"), format!("uv {i} is not finite")));
        }
        if let Some(t) = mesh
            .indices
            .iter()
            .position(|t| t.iter().any(|&i| i as usize >= n))
        {
            return Err(Error::field(
                &what("indices"),
                format!("triangle {t} uses a vertex index >= {n}"),
            ));
        }
        if mesh.material >= scene.materials.len() {
            return Err(Error::field(
                &what("material"),
                format!(
                    "index {} out of range ({} materials)",
                    mesh.material,
                    scene.materials.len()
                ),
            ));
        }
    }
    if scene.triangle_count() == 0 {
        return Err(Error::msg(format!("scene '{}': no triangles", scene.name)));
    }
    Ok(())
}
