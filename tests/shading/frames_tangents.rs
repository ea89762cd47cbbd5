#![allow(clippy::type_complexity)]
//! Tangent generation: planar, mirrored, UV-degenerate, sphere poles, garbage input, random.

use crate::rng_common::Rng;
use glam::DVec3;
use texsim::shading::reference as r;
use texsim::shading::tangents::{generate_tangents, generate_uv_derivatives};

fn v(t: [f32; 4]) -> DVec3 {
    DVec3::new(f64::from(t[0]), f64::from(t[1]), f64::from(t[2]))
}

fn n3(n: [f32; 3]) -> DVec3 {
    DVec3::new(f64::from(n[0]), f64::from(n[1]), f64::from(n[2])).normalize()
}

/// Every tangent finite, unit, perpendicular to the (unit) normal, w = +-1.
fn check_valid(t: &[[f32; 4]], normals: &[[f32; 3]]) {
    for (i, tt) in t.iter().enumerate() {
        assert!(tt.iter().all(|x| x.is_finite()), "vertex {i}: {tt:?}");
        assert!((v(*tt).length() - 1.0).abs() < 1e-5, "vertex {i} not unit");
        assert!(tt[3] == 1.0 || tt[3] == -1.0);
        if let Some(&n) = normals.get(i) {
            let nn = DVec3::new(f64::from(n[0]), f64::from(n[1]), f64::from(n[2]));
            if nn.length() > 0.0 {
                assert!(
                    v(*tt).dot(nn.normalize()).abs() < 1e-5,
                    "vertex {i} not tangent"
                );
            }
        }
    }
}

#[test]
fn planar_quad_and_derivatives() {
    let pos = [
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [2.0, 3.0, 0.0],
        [0.0, 3.0, 0.0],
    ];
    let nor = [[0.0, 0.0, 1.0]; 4];
    let uv = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    let idx = [[0, 1, 2], [0, 2, 3]];
    let t = generate_tangents(&pos, &nor, &uv, &idx);
    for tt in &t {
        assert!((v(*tt) - DVec3::X).length() < 1e-6 && tt[3] == 1.0);
    }
    let d = generate_uv_derivatives(&pos, &nor, &uv, &idx);
    for [pu, pv] in d {
        assert!((n3(pu) - DVec3::X).length() < 1e-6 && (pu[0] - 2.0).abs() < 1e-5);
        assert!((pv[1] - 3.0).abs() < 1e-5 && pv[0].abs() < 1e-6);
    }
    // Natural frame vertex data: s_u = n x p_v = -x * 3, |s_u|/|p_u x p_v| = 1/2.
    let nv = r::natural_vertex(DVec3::Z, DVec3::X * 2.0, DVec3::Y * 3.0, 1.0, 1.0).expect("frame");
    assert!((nv.dir_u + DVec3::X).length() < 1e-12 && (nv.len_u - 0.5).abs() < 1e-12);
    assert!((nv.dir_v + DVec3::Y).length() < 1e-12 && (nv.len_v - 1.0 / 3.0).abs() < 1e-12);
    assert!(r::natural_vertex(DVec3::Z, DVec3::X, DVec3::X, 1.0, 1.0).is_none());
}

#[test]
fn mirrored_uvs_on_a_quad() {
    // Left half u = x, right half u = 2 - x (mirror seam at x = 1, vertices 1 and 4 shared).
    let pos = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [2.0, 1.0, 0.0],
    ];
    let nor = [[0.0, 0.0, 1.0]; 6];
    let uv = [
        [0.0, 0.0],
        [1.0, 0.0],
        [0.0, 0.0],
        [0.0, 1.0],
        [1.0, 1.0],
        [0.0, 1.0],
    ];
    let idx = [[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]];
    let t = generate_tangents(&pos, &nor, &uv, &idx);
    check_valid(&t, &nor);
    for i in [0, 3] {
        assert!(
            (v(t[i]) - DVec3::X).length() < 1e-6 && t[i][3] == 1.0,
            "left {i}"
        );
    }
    for i in [2, 5] {
        assert!(
            (v(t[i]) + DVec3::X).length() < 1e-6 && t[i][3] == -1.0,
            "right {i}"
        );
        // Bitangent w (N x T) is +y on both sides: v grows along +y everywhere.
        let b = f64::from(t[i][3]) * DVec3::Z.cross(v(t[i]));
        assert!((b - DVec3::Y).length() < 1e-6);
    }
    // Seam vertices take one side (not a cancelled sum).
    for i in [1, 4] {
        assert!(v(t[i]).x.abs() > 0.999, "seam {i}: {:?}", t[i]);
    }
}

#[test]
fn uv_degenerate_and_garbage_input() {
    let pos = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [f32::NAN, 0.0, 0.0],
    ];
    let nor = [
        [0.0, 0.0, 1.0],
        [0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [f32::NAN; 3],
    ];
    // All UVs equal; UVs collinear; out-of-range index; NaN position.
    for uv in [
        [[0.5f32, 0.5]; 4],
        [[0.0, 0.0], [0.5, 0.5], [1.0, 1.0], [0.2, 0.2]],
    ] {
        let t = generate_tangents(&pos, &nor, &uv, &[[0, 1, 2], [0, 1, 9], [0, 1, 3]]);
        check_valid(&t, &nor);
        assert_eq!(t.len(), 4);
        // Fallback for n = +z: least aligned axis x.
        assert!((v(t[0]) - DVec3::X).length() < 1e-6);
    }
    let t = generate_tangents(&pos, &nor, &[], &[[0, 1, 2]]);
    check_valid(&t, &nor);
    assert!(generate_tangents(&[], &[], &[], &[[0, 1, 2]]).is_empty());
}

fn uv_sphere(
    segs: u32,
    rings: u32,
    shared_pole: bool,
) -> (Vec<[f32; 3]>, Vec<[f32; 2]>, Vec<[u32; 3]>) {
    let (mut p, mut uv, mut idx) = (Vec::new(), Vec::new(), Vec::new());
    // Grid (segs + 1) x (rings + 1) with u seam duplicated; poles either per segment or shared.
    let id = |i: u32, j: u32| j * (segs + 1) + i;
    for j in 0..=rings {
        for i in 0..=segs {
            let (u, vv) = (i as f32 / segs as f32, j as f32 / rings as f32);
            let (phi, th) = (u * std::f32::consts::TAU, vv * std::f32::consts::PI);
            p.push([th.sin() * phi.cos(), th.sin() * phi.sin(), -th.cos()]);
            uv.push([u, vv]);
        }
    }
    for j in 0..rings {
        for i in 0..segs {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            let (a, b) = if shared_pole && j == 0 {
                (id(0, 0), id(0, 0))
            } else {
                (a, b)
            };
            let (c, d) = if shared_pole && j + 1 == rings {
                (id(0, rings), id(0, rings))
            } else {
                (c, d)
            };
            if a != b {
                idx.push([a, b, c]);
            }
            if c != d {
                idx.push([a, c, d]);
            } else {
                idx.push([a, b, c]);
            }
        }
    }
    (p, uv, idx)
}

#[test]
fn sphere_poles_with_spherical_uvs() {
    for shared in [false, true] {
        let (p, uv, idx) = uv_sphere(24, 12, shared);
        let nor: Vec<[f32; 3]> = p.clone();
        let t = generate_tangents(&p, &nor, &uv, &idx);
        check_valid(&t, &nor);
        // Away from the poles the tangent is the east direction dP/du.
        for (i, pp) in p.iter().enumerate() {
            let q = DVec3::new(f64::from(pp[0]), f64::from(pp[1]), f64::from(pp[2]));
            let east = DVec3::new(-q.y, q.x, 0.0);
            if east.length() > 0.3 {
                assert!(
                    v(t[i]).dot(east.normalize()) > 0.95,
                    "shared={shared} vertex {i}"
                );
            }
        }
    }
}

#[test]
fn random_meshes_never_nan() {
    let mut s = Rng(5);
    for _ in 0..2000 {
        let nv = 3 + (s.next() % 20) as usize;
        let pos: Vec<[f32; 3]> = (0..nv)
            .map(|_| [s.unit_f32(), s.unit_f32(), s.unit_f32()])
            .collect();
        let nor: Vec<[f32; 3]> = (0..nv)
            .map(|i| {
                if i % 7 == 0 {
                    [0.0; 3]
                } else {
                    [s.unit_f32() - 0.5, s.unit_f32() - 0.5, s.unit_f32() - 0.5]
                }
            })
            .collect();
        // Quantized UVs so that many triangles are UV-degenerate.
        let uv: Vec<[f32; 2]> = (0..nv)
            .map(|_| [(s.unit_f32() * 3.0).floor(), (s.unit_f32() * 3.0).floor()])
            .collect();
        let idx: Vec<[u32; 3]> = (0..nv)
            .map(|_| [0; 3].map(|_: u32| (s.next() % nv as u64) as u32))
            .collect();
        let t = generate_tangents(&pos, &nor, &uv, &idx);
        check_valid(&t, &nor);
        let d = generate_uv_derivatives(&pos, &nor, &uv, &idx);
        assert!(d.iter().flatten().flatten().all(|x| x.is_finite()));
    }
}
