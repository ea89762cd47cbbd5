//! Per-vertex tangent frames from UV derivatives (the `p_u`, `p_v` of Schilling 1997 / Blinn
//! 1978), for the natural/unit frames and for tangent-space normal maps.
//!
//! Per triangle: `dP/du = (e1 dv2 - e2 dv1) / det`, `dP/dv = (e2 du1 - e1 du2) / det`,
//! `det = du1 dv2 - du2 dv1`. Contributions are weighted by the triangle's area and kept in two
//! accumulators per vertex by the sign of `det` (mirrored UVs), the heavier one wins (ties:
//! `det > 0`), so a vertex on a mirror seam takes one side's frame instead of a cancelled sum.
//! Gram-Schmidt against the vertex normal, handedness `w = sign((N x T) . B)`.
//!
//! Hard cases: triangles with `|det| <= 1e-7 * max|duv|^2` (UV-degenerate), out-of-range
//! indices or non-finite data contribute nothing; a vertex without a usable tangent (no
//! contribution, `T` parallel to `N`, or sums cancelling as at a sphere pole shared by all
//! segments) gets the fallback `T = normalize(a - N (N . a))` with `a` the coordinate axis least
//! aligned with `N`, `w = +1`; a zero or non-finite normal is replaced by +z. UV seams are
//! split vertices in OBJ meshes, each copy gets its own side's frame. Output is never NaN.

use glam::DVec3;

const DET_EPS: f64 = 1e-7;

#[derive(Clone, Copy, Default)]
struct Acc {
    t: [DVec3; 2],
    b: [DVec3; 2],
    w: [f64; 2],
}

fn v3(p: [f32; 3]) -> DVec3 {
    DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]))
}

fn accumulate(positions: &[[f32; 3]], uvs: &[[f32; 2]], indices: &[[u32; 3]]) -> Vec<Acc> {
    let mut acc = vec![Acc::default(); positions.len()];
    if uvs.len() != positions.len() {
        return acc;
    }
    for tri in indices {
        let [i0, i1, i2] = tri.map(|i| i as usize);
        if i0 >= positions.len() || i1 >= positions.len() || i2 >= positions.len() {
            continue;
        }
        let (p0, p1, p2) = (v3(positions[i0]), v3(positions[i1]), v3(positions[i2]));
        let uv = |i: usize| (f64::from(uvs[i][0]), f64::from(uvs[i][1]));
        let ((u0, w0), (u1, w1), (u2, w2)) = (uv(i0), uv(i1), uv(i2));
        let (e1, e2) = (p1 - p0, p2 - p0);
        let (du1, dv1, du2, dv2) = (u1 - u0, w1 - w0, u2 - u0, w2 - w0);
        let det = du1 * dv2 - du2 * dv1;
        let s = du1.abs().max(dv1.abs()).max(du2.abs()).max(dv2.abs());
        if !det.is_finite() || det.abs() <= DET_EPS * s * s {
            continue;
        }
        let t = (e1 * dv2 - e2 * dv1) / det;
        let b = (e2 * du1 - e1 * du2) / det;
        let area = 0.5 * e1.cross(e2).length();
        if !(t.is_finite() && b.is_finite() && area.is_finite() && area > 0.0) {
            continue;
        }
        let g = usize::from(det < 0.0);
        for i in [i0, i1, i2] {
            acc[i].t[g] += area * t;
            acc[i].b[g] += area * b;
            acc[i].w[g] += area;
        }
    }
    acc
}

fn vertex_normal(normals: &[[f32; 3]], i: usize) -> DVec3 {
    let n = normals.get(i).map_or(DVec3::ZERO, |&n| v3(n));
    let l = n.length();
    if l > 0.0 && l.is_finite() {
        n / l
    } else {
        DVec3::Z
    }
}

fn least_aligned_axis(n: DVec3) -> DVec3 {
    let a = n.abs();
    if a.x <= a.y && a.x <= a.z {
        DVec3::X
    } else if a.y <= a.z {
        DVec3::Y
    } else {
        DVec3::Z
    }
}

fn fallback_tangent(n: DVec3) -> DVec3 {
    let a = least_aligned_axis(n);
    (a - n * n.dot(a)).normalize()
}

/// The winning accumulator group of a vertex, if it has any weight.
fn group(a: &Acc) -> Option<usize> {
    let g = usize::from(a.w[1] > a.w[0]);
    (a.w[g] > 0.0).then_some(g)
}

/// Per-vertex tangent `xyz` (unit, perpendicular to the normal) and handedness `w = +-1`
/// (bitangent = `w * N x T`). One entry per position; never NaN.
#[must_use]
pub fn generate_tangents(
    positions: &[[f32; 3]],
    normals: &[[f32; 3]],
    uvs: &[[f32; 2]],
    indices: &[[u32; 3]],
) -> Vec<[f32; 4]> {
    let acc = accumulate(positions, uvs, indices);
    acc.iter()
        .enumerate()
        .map(|(i, a)| {
            let n = vertex_normal(normals, i);
            let mut out = None;
            if let Some(g) = group(a) {
                let t = a.t[g] - n * n.dot(a.t[g]);
                let tl = t.length();
                if tl > 1e-6 * a.t[g].length() && tl.is_finite() {
                    let t = t / tl;
                    let w = if n.cross(t).dot(a.b[g]) < 0.0 {
                        -1.0
                    } else {
                        1.0
                    };
                    out = Some((t, w));
                }
            }
            let (t, w) = out.unwrap_or_else(|| (fallback_tangent(n), 1.0));
            [t.x as f32, t.y as f32, t.z as f32, w as f32]
        })
        .collect()
}

/// Per-vertex surface derivatives `[p_u, p_v]` (area-weighted mean of the winning handedness
/// group, projected into the tangent plane of the vertex normal) for the natural frame; zero
/// vectors where the vertex has no usable UV triangle.
#[must_use]
pub fn generate_uv_derivatives(
    positions: &[[f32; 3]],
    normals: &[[f32; 3]],
    uvs: &[[f32; 2]],
    indices: &[[u32; 3]],
) -> Vec<[[f32; 3]; 2]> {
    let acc = accumulate(positions, uvs, indices);
    let f = |v: DVec3| [v.x as f32, v.y as f32, v.z as f32];
    acc.iter()
        .enumerate()
        .map(|(i, a)| {
            let n = vertex_normal(normals, i);
            match group(a) {
                Some(g) => {
                    let pu = a.t[g] / a.w[g];
                    let pv = a.b[g] / a.w[g];
                    [f(pu - n * n.dot(pu)), f(pv - n * n.dot(pv))]
                }
                None => [[0.0; 3]; 2],
            }
        })
        .collect()
}
