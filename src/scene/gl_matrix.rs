//! Mesa 22.3's float32 matrix stack (`src/mesa/math/m_matrix.c`) for the built-in Mesa anchor
//! scenes: `glFrustum`, `glRotated`, `glTranslated` and the model-view-projection product in
//! binary32 as Mesa's C code computes them (each product and sum rounded in turn, no
//! contraction), so llvmpipe's float32 vertex transform (`interp.coord_arith = "float32"`)
//! starts from the matrix llvmpipe used. Matrices are row-major `m[row][col]`.

/// A 4x4 binary32 matrix, row-major.
pub type Mat4f = [[f32; 4]; 4];

const IDENTITY: Mat4f = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

/// `matmul4`: `a b`, each entry `a_i0 b_0j + a_i1 b_1j + a_i2 b_2j + a_i3 b_3j` left to right.
#[must_use]
pub fn mul(a: &Mat4f, b: &Mat4f) -> Mat4f {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j] + a[i][3] * b[3][j]
        })
    })
}

/// `_math_matrix_frustum` of `glFrustum(l, r, b, t, n, f)` (its double arguments rounded to
/// float).
#[must_use]
pub fn frustum(l: f64, r: f64, b: f64, t: f64, n: f64, f: f64) -> Mat4f {
    let (l, r, b, t, n, f) = (l as f32, r as f32, b as f32, t as f32, n as f32, f as f32);
    let x = (2.0 * n) / (r - l);
    let y = (2.0 * n) / (t - b);
    let a = (r + l) / (r - l);
    let bb = (t + b) / (t - b);
    let c = -(f + n) / (f - n);
    let d = -(2.0 * f * n) / (f - n);
    [
        [x, 0.0, a, 0.0],
        [0.0, y, bb, 0.0],
        [0.0, 0.0, c, d],
        [0.0, 0.0, -1.0, 0.0],
    ]
}

/// `_math_matrix_rotate` about a coordinate axis (0 = x, 2 = z) by `deg` degrees (the
/// optimized single-axis paths), times the current matrix `m`: `m R`.
#[must_use]
pub fn rotate_axis(m: &Mat4f, deg: f64, axis: usize) -> Mat4f {
    let arg = (f64::from(deg as f32) * std::f64::consts::PI / 180.0) as f32;
    let (s, c) = (f64::from(arg).sin() as f32, f64::from(arg).cos() as f32);
    let mut r = IDENTITY;
    let (i, j) = if axis == 0 { (1, 2) } else { (0, 1) };
    r[i][i] = c;
    r[j][j] = c;
    r[i][j] = -s;
    r[j][i] = s;
    mul(m, &r)
}

/// `_math_matrix_translate`: the last column `m0 x + m1 y + m2 z + m3`, row by row.
#[must_use]
pub fn translate(m: &Mat4f, x: f64, y: f64, z: f64) -> Mat4f {
    let (x, y, z) = (x as f32, y as f32, z as f32);
    let mut out = *m;
    for row in out.iter_mut() {
        // `((m0 x + m1 y) + m2 z) + m3`: the last addition commutes exactly.
        row[3] += row[0] * x + row[1] * y + row[2] * z;
    }
    out
}

/// The model-view-projection matrix Mesa computes for the W1 anchor (the GL calls of
/// `shared/anchors/mesa/mesa_anchor.c`): `glFrustum(-top, top, -top, top, 0.1, 1000)` with
/// `top = 0.1 tan 30 deg`, `glRotated(10, 1,0,0)`, `glTranslated(0,-1,0)`.
#[must_use]
pub fn w1_plane_mvp() -> Mat4f {
    let top = 0.1 * (30.0 * std::f64::consts::PI / 180.0).tan();
    let p = frustum(-top, top, -top, top, 0.1, 1000.0);
    let mv = translate(&rotate_axis(&IDENTITY, 10.0, 0), 0.0, -1.0, 0.0);
    mul(&p, &mv)
}

/// The model-view-projection matrix Mesa computes for the W2 anchor: `glFrustum` with
/// `top = tan 22.5 deg`, near 1, far 10, `glTranslated(0,0,-3.2)`, `glRotated(-50, 1,0,0)`,
/// `glRotated(20, 0,0,1)`.
#[must_use]
pub fn w2_mesh_mvp() -> Mat4f {
    let top = (22.5 * std::f64::consts::PI / 180.0).tan();
    let p = frustum(-top, top, -top, top, 1.0, 10.0);
    let mv = translate(&IDENTITY, 0.0, 0.0, -3.2);
    let mv = rotate_axis(&rotate_axis(&mv, -50.0, 0), 20.0, 2);
    mul(&p, &mv)
}
