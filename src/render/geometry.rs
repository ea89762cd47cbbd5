//! The geometry phase: host-side transforms, Gouraud lighting and one plan per mesh (float).

use crate::maps::{bump_sources, ndf_sources, BumpSource};
use crate::pipeline::bump::BumpVertex;
use crate::pipeline::{plan_with_bump, BumpPlan, Plan};
use crate::raster::DrawTri;
use crate::scene::{Light, Scene};
use crate::scene::{MainDirection, Mesh};
use crate::shading::reference as fref;
use crate::shading::tangents::{generate_tangents, generate_uv_derivatives};
use glam::{DMat4, DVec3};
use rayon::prelude::*;

/// Host-side geometry: clip-space vertices, Gouraud vertex colours, texture coordinates, the
/// triangles to draw and the plan of each mesh.
pub struct Geometry {
    pub clip: Vec<[f64; 4]>,
    /// Object-space positions as the scene gives them (float32), for llvmpipe's float32
    /// vertex transform (`interp.coord_arith = "float32"`).
    pub object: Vec<[f32; 3]>,
    /// The view-projection matrix the clip positions come from.
    pub view_projection: DMat4,
    /// The binary32 model-view-projection of the camera's GL program (`GlView::mvp_f32`: the
    /// Mesa anchor scenes); `None` for other cameras.
    pub mesa_mvp: Option<crate::scene::gl_matrix::Mat4f>,
    pub color: Vec<[f64; 3]>,
    pub uv: Vec<[f64; 2]>,
    /// Per-vertex bump data: empty unless some plan is bump mapped (then one per vertex;
    /// default for vertices of other meshes).
    pub bump: Vec<BumpVertex>,
    /// World-space eye position and point-light positions (bump shading).
    pub eye: [f64; 3],
    pub point_lights: Vec<[f64; 3]>,
    pub draws: Vec<DrawTri>,
    /// Plan index of each draw.
    pub draw_plan: Vec<u32>,
    /// One plan per mesh.
    pub plans: Vec<Plan>,
}

impl Geometry {
    /// Transforms, lights (per vertex, float) and plans every mesh of `scene`.
    #[must_use]
    pub fn new(scene: &Scene) -> Self {
        let aspect = f64::from(scene.width) / f64::from(scene.height.max(1));
        let vp = scene.camera.projection(aspect) * scene.camera.view();
        let n: usize = scene.meshes.iter().map(|m| m.positions.len()).sum();
        let mut g = Geometry {
            clip: Vec::with_capacity(n),
            object: Vec::with_capacity(n),
            view_projection: vp,
            mesa_mvp: scene.camera.view_override.and_then(|g| g.mvp_f32),
            color: Vec::with_capacity(n),
            uv: Vec::with_capacity(n),
            draws: Vec::with_capacity(scene.triangle_count()),
            draw_plan: Vec::with_capacity(scene.triangle_count()),
            plans: Vec::with_capacity(scene.meshes.len()),
            bump: Vec::new(),
            eye: scene
                .camera
                .view()
                .inverse()
                .transform_point3(DVec3::ZERO)
                .to_array(),
            point_lights: scene
                .lights
                .iter()
                .filter_map(|l| match l {
                    Light::Point { position, .. } => Some(position.map(f64::from)),
                    Light::Directional { .. } => None,
                })
                .collect(),
        };
        let sources = bump_sources(scene);
        let ndf_srcs = ndf_sources(scene);
        for (mi, mesh) in scene.meshes.iter().enumerate() {
            let mat = &scene.materials[mesh.material];
            let base = g.clip.len() as u32;
            let kd = DVec3::from(mat.kd.map(f64::from));
            g.object.extend_from_slice(&mesh.positions);
            // Per vertex in parallel, written in vertex order: identical for any thread count.
            g.clip.par_extend(
                mesh.positions
                    .par_iter()
                    .map(|p| (vp * DVec3::from(p.map(f64::from)).extend(1.0)).to_array()),
            );
            g.color
                .par_extend(mesh.positions.par_iter().enumerate().map(|(vi, p)| {
                    let c = if mat.lit {
                        let p = DVec3::from(p.map(f64::from));
                        let nrm = mesh
                            .normals
                            .get(vi)
                            .map_or(DVec3::Z, |n| DVec3::from(n.map(f64::from)));
                        kd * lighting(scene, p, nrm.normalize_or_zero())
                    } else {
                        kd
                    };
                    c.clamp(DVec3::ZERO, DVec3::ONE).to_array()
                }));
            g.uv.extend(
                (0..mesh.positions.len())
                    .map(|vi| mesh.uvs.get(vi).map_or([0.0; 2], |t| t.map(f64::from))),
            );
            let bump_map = BumpSource::of(mat).and_then(|b| {
                sources
                    .iter()
                    .position(|o| o.same(&b))
                    .map(|k| scene.textures.len() + k)
            });
            let mut p = plan_with_bump(mat, !mesh.uvs.is_empty(), bump_map);
            crate::pipeline::rough::mark_plan(&mut p, mat);
            if mat.ndf {
                let first = scene.textures.len() + sources.len();
                if let Some(j) = bump_map.and_then(|b| {
                    ndf_srcs
                        .iter()
                        .position(|&s| s == (b - scene.textures.len(), mat.shininess))
                }) {
                    let ne = crate::shading::ndf::norm_exp_for(f64::from(mat.shininess));
                    p = crate::pipeline::ndf::with_ndf(p, first + 4 * j, mat.shininess, ne);
                }
            }
            crate::pipeline::env::mark_plan(&mut p, mat);
            crate::pipeline::toksvig::mark_plan(&mut p, mat);
            crate::pipeline::lean::mark_plan(&mut p, mat);
            crate::pipeline::lobe_fit::mark_plan(&mut p, mat);
            if let Some(bp) = &p.bump {
                g.bump.resize(base as usize, BumpVertex::default());
                g.bump.extend(bump_vertices(mesh, bp));
            }
            g.plans.push(p);
            for t in &mesh.indices {
                g.draws.push(DrawTri {
                    v: t.map(|i| base + i),
                    cull_back: mat.cull_back,
                });
                g.draw_plan.push(mi as u32);
            }
        }
        g
    }
}

/// Per-vertex bump data of `mesh` (Schilling 1997 frame 1 via `reference::natural_vertex`,
/// with per-object reference lengths: the mean `|p_u x p_v| / |p_v|` and `/ |p_u|`). Where the
/// natural frame is undefined (UV-degenerate vertex), the directions come from the fallback
/// tangent of `tangents::generate_tangents` (`d_u = -T`, `d_v = -B`) with length 1.
fn bump_vertices(mesh: &Mesh, bp: &BumpPlan) -> Vec<BumpVertex> {
    let (pos, nor, uvs, idx) = (&mesh.positions, &mesh.normals, &mesh.uvs, &mesh.indices);
    let der = generate_uv_derivatives(pos, nor, uvs, idx);
    let tan = generate_tangents(pos, nor, uvs, idx);
    let v3 = |a: [f32; 3]| DVec3::from(a.map(f64::from));
    let (mut ru, mut rv, mut cnt) = (0.0, 0.0, 0.0);
    for d in &der {
        let (pu, pv) = (v3(d[0]), v3(d[1]));
        let g = pu.cross(pv).length();
        if g > 0.0 && g.is_finite() {
            ru += g / pv.length();
            rv += g / pu.length();
            cnt += 1.0;
        }
    }
    let (ref_u, ref_v) = if cnt > 0.0 {
        (ru / cnt, rv / cnt)
    } else {
        (1.0, 1.0)
    };
    pos.iter()
        .enumerate()
        .map(|(i, p)| {
            let n = nor.get(i).map_or(DVec3::Z, |&n| v3(n));
            let n = fref::normalize_or(n, DVec3::Z).0;
            let t = tan.get(i).copied().unwrap_or([1.0, 0.0, 0.0, 1.0]);
            let tt = DVec3::new(f64::from(t[0]), f64::from(t[1]), f64::from(t[2]));
            let bb = f64::from(t[3]) * n.cross(tt);
            let d = der.get(i).copied().unwrap_or([[0.0; 3]; 2]);
            let (pu, pv) = (v3(d[0]), v3(d[1]));
            let (du, dv, len) = match fref::natural_vertex(n, pu, pv, ref_u, ref_v) {
                Some(nv) => (nv.dir_u, nv.dir_v, [nv.len_u, nv.len_v]),
                None => (-tt, -bb, [1.0, 1.0]),
            };
            let m = match bp.main {
                MainDirection::Pu => fref::normalize_or(pu, tt).0,
                MainDirection::Pv => fref::normalize_or(pv, bb).0,
                MainDirection::Constant(_) => DVec3::ZERO,
            };
            let fin = |v: DVec3| {
                if v.is_finite() {
                    v.to_array()
                } else {
                    [0.0; 3]
                }
            };
            BumpVertex {
                n: fin(n),
                du: fin(du),
                dv: fin(dv),
                len: len.map(|l| if l.is_finite() { l } else { 1.0 }),
                m: fin(m),
                p: p.map(f64::from),
            }
        })
        .collect()
}

/// Lambert irradiance at `p` with unit normal `n` (ambient + each light's n.l).
fn lighting(scene: &Scene, p: DVec3, n: DVec3) -> DVec3 {
    let mut e = DVec3::from(scene.ambient.map(f64::from));
    for l in &scene.lights {
        let (dir, col) = match l {
            Light::Directional { direction, color } => (
                -DVec3::from(direction.map(f64::from)).normalize_or_zero(),
                color,
            ),
            Light::Point { position, color } => (
                (DVec3::from(position.map(f64::from)) - p).normalize_or_zero(),
                color,
            ),
        };
        e += DVec3::from(col.map(f64::from)) * n.dot(dir).max(0.0);
    }
    e
}
