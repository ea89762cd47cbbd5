//! Procedural shapes in object space, counter-clockwise front faces seen from outside, analytic
//! unit normals, UVs with `t = 0` on texel row 0 (the top row of the stored image). The torus
//! reproduces the vertex/index order and texcoords of `make_torus` in the Mesa anchor.

use std::f64::consts::PI;

use super::Mesh;

fn f3(x: f64, y: f64, z: f64) -> [f32; 3] {
    [x as f32, y as f32, z as f32]
}

/// A square in the XZ plane (y = 0, normal +y), side `size` centred at the origin, two
/// triangles, UVs 0..`uv_scale` (s along +x, t towards -z).
#[must_use]
pub fn plane(size: f32, uv_scale: f32) -> Mesh {
    let s = size * 0.5;
    Mesh {
        name: "plane".into(),
        positions: vec![[-s, 0.0, s], [s, 0.0, s], [s, 0.0, -s], [-s, 0.0, -s]],
        normals: vec![[0.0, 1.0, 0.0]; 4],
        uvs: vec![
            [0.0, 0.0],
            [uv_scale, 0.0],
            [uv_scale, uv_scale],
            [0.0, uv_scale],
        ],
        indices: vec![[0, 1, 2], [0, 2, 3]],
        material: 0,
    }
}

/// A UV sphere of `radius` with `segments` (longitude, >= 3) x `rings` (latitude, >= 2); the
/// seam and the poles are duplicated; s = j / segments, t = i / rings (t = 0 at the top, +y).
#[must_use]
pub fn sphere(radius: f32, segments: u32, rings: u32) -> Mesh {
    let (segs, rings) = (segments.max(3), rings.max(2));
    let r = f64::from(radius);
    let mut m = Mesh {
        name: "sphere".into(),
        ..Mesh::default()
    };
    for i in 0..=rings {
        let th = PI * f64::from(i) / f64::from(rings);
        for j in 0..=segs {
            let ph = 2.0 * PI * f64::from(j) / f64::from(segs);
            let n = (th.sin() * ph.sin(), th.cos(), th.sin() * ph.cos());
            m.positions.push(f3(r * n.0, r * n.1, r * n.2));
            m.normals.push(f3(n.0, n.1, n.2));
            m.uvs
                .push([j as f32 / segs as f32, i as f32 / rings as f32]);
        }
    }
    let row = segs + 1;
    for i in 0..rings {
        for j in 0..segs {
            let (a, b) = (i * row + j, (i + 1) * row + j);
            let (c, d) = (b + 1, a + 1);
            m.indices.push([a, b, c]);
            m.indices.push([a, c, d]);
        }
    }
    m
}

/// A torus around the z axis (ring in the XY plane), major radius `major`, minor `minor`,
/// `nu` x `nv` segments, (nu+1)(nv+1) vertices with duplicated seams, s = `s_repeat` * i / nu,
/// t = j / nv. With (1.0, 0.4, 256, 128, 2.0) this is the Mesa anchor's W2 torus: positions
/// computed in double and rounded to f32, texcoords computed in f32 as in the C source.
#[must_use]
pub fn torus(major: f32, minor: f32, nu: u32, nv: u32, s_repeat: f32) -> Mesh {
    let (nu, nv) = (nu.max(3), nv.max(3));
    let (rr, r) = (f64::from(major), f64::from(minor));
    let mut m = Mesh {
        name: "torus".into(),
        ..Mesh::default()
    };
    for i in 0..=nu {
        let u = 2.0 * PI * f64::from(i) / f64::from(nu);
        for j in 0..=nv {
            let a = 2.0 * PI * f64::from(j) / f64::from(nv);
            m.positions.push(f3(
                (rr + r * a.cos()) * u.cos(),
                (rr + r * a.cos()) * u.sin(),
                r * a.sin(),
            ));
            m.normals
                .push(f3(a.cos() * u.cos(), a.cos() * u.sin(), a.sin()));
            m.uvs.push([
                s_repeat * i as f32 / nu as f32,
                1.0f32 * j as f32 / nv as f32,
            ]);
        }
    }
    for i in 0..nu {
        for j in 0..nv {
            let a = i * (nv + 1) + j;
            let b = (i + 1) * (nv + 1) + j;
            let c = (i + 1) * (nv + 1) + j + 1;
            let d = i * (nv + 1) + j + 1;
            m.indices.push([a, b, c]);
            m.indices.push([a, c, d]);
        }
    }
    m
}

/// An axis-aligned cube of side `size` centred at the origin: 24 vertices (flat normals), each
/// face UV-mapped 0..1 (t = 0 at the face's top edge).
#[must_use]
pub fn cube(size: f32) -> Mesh {
    let h = size * 0.5;
    // (normal, u axis, v axis) with u x v = normal.
    let faces: [([f32; 3], [f32; 3], [f32; 3]); 6] = [
        ([1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]),
        ([-1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
        ([0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]),
        ([0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ([0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
    ];
    let mut m = Mesh {
        name: "cube".into(),
        ..Mesh::default()
    };
    for (n, u, v) in faces {
        let base = m.positions.len() as u32;
        for (su, sv, uv) in [
            (-1.0, -1.0, [0.0, 1.0]),
            (1.0, -1.0, [1.0, 1.0]),
            (1.0, 1.0, [1.0, 0.0]),
            (-1.0, 1.0, [0.0, 0.0]),
        ] {
            let p: [f32; 3] = std::array::from_fn(|k| h * (n[k] + su * u[k] + sv * v[k]));
            m.positions.push(p);
            m.normals.push(n);
            m.uvs.push(uv);
        }
        m.indices.push([base, base + 1, base + 2]);
        m.indices.push([base, base + 2, base + 3]);
    }
    m
}
