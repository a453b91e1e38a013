//! Kinematics of the one-point triangle in its corotated frame: the frame, the constant
//! membrane and curvature rows (linear displacements and rotations, Belytschko, Stolarski &
//! Carpenter 1984) and the assumed transverse shear of MITC3 (Lee & Bathe, Comput. Struct. 82,
//! 2004): covariant shear tied along the three edges, its centroid value and its linear part.
//!
//! Local dofs per node `[u, v, w, θx, θy, θz]`; shear `γ = ∇w + β`, `β = (θy, -θx)`
//! (`γxz = w,x + θy`, `γyz = w,y - θx`), curvature `κ = sym ∇β`, as `bt4` has them.

/// Local dofs of the element.
pub const N_DOF: usize = 18;

/// Rows of a strain over the local dofs.
pub type Row = [f64; N_DOF];

/// The corotated frame of a triangle: `ê3 ∥ x21 × x31`, `ê1` along side 1-2, `ê2 = ê3 × ê1`;
/// local coordinates of the nodes relative to the centroid.
#[derive(Debug, Clone, Copy)]
pub struct Frame {
    pub e: [[f64; 3]; 3],
    pub x: [f64; 3],
    pub y: [f64; 3],
    pub area: f64,
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// `a · b`.
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let inv = 1.0 / dot(a, a).sqrt();
    a.map(|v| v * inv)
}

/// The frame of a triangle at positions `x`.
pub fn frame(x: &[[f64; 3]; 3]) -> Frame {
    let (x21, x31) = (sub(x[1], x[0]), sub(x[2], x[0]));
    let e3 = unit(cross(x21, x31));
    let e1 = unit(x21);
    let e2 = cross(e3, e1);
    let c: [f64; 3] = std::array::from_fn(|k| (x[0][k] + x[1][k] + x[2][k]) / 3.0);
    let lx = x.map(|p| dot(sub(p, c), e1));
    let ly = x.map(|p| dot(sub(p, c), e2));
    let area = 0.5 * ((lx[1] - lx[0]) * (ly[2] - ly[0]) - (lx[2] - lx[0]) * (ly[1] - ly[0]));
    Frame { e: [e1, e2, e3], x: lx, y: ly, area }
}

/// The strain rows of a triangle and the shape factor of its linear shear part.
#[derive(Debug, Clone)]
pub struct Rows {
    /// Membrane `[εx, εy, γxy]`.
    pub membrane: [Row; 3],
    /// Curvature `[κx, κy, κxy]`: `κx = θy,x`, `κy = -θx,y`, `κxy = θy,y - θx,x`.
    pub curvature: [Row; 3],
    /// Assumed shear at the centroid `[γxz, γyz]` and the amplitude `c` of its linear part.
    pub shear: [Row; 3],
    /// `∫ |γ - γ_centroid|² dA = c² A m`, this `m`: the linear part's energy factor.
    pub linear_shear_factor: f64,
}

/// Rows of the triangle with local coordinates `f.x`, `f.y`.
///
/// Shear (MITC3): along edge `i → j`, `D_ij = w_j - w_i + (x_j - x_i) · β̄_ij` (β̄ the mean of
/// the two nodes) is the covariant shear `∫ γ · dx`; with `g_r = x2 - x1`, `g_s = x3 - x1`
/// the assumed field `e_r = D12 + c s`, `e_s = D13 - c r`, `c = D13 - D12 - D23` ties all three
/// edges. At the centroid (`r = s = 1/3`): `e_r = (2 D12 + D13 - D23)/3`,
/// `e_s = (D12 + 2 D13 + D23)/3`, and `γ = J⁻¹ (e_r, e_s)`, `J = [g_r; g_s]`. The linear part
/// `c J⁻¹ (s - 1/3, 1/3 - r)` averages `c² (|j1|² + |j2|² + j1·j2)/18` over the triangle
/// (`j1`, `j2` the columns of `J⁻¹`), so the shear energy is integrated exactly.
pub fn rows(f: &Frame) -> Rows {
    let two_a = 2.0 * f.area;
    let mut membrane = [[0.0; N_DOF]; 3];
    let mut curvature = [[0.0; N_DOF]; 3];
    for i in 0..3 {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        let bx = (f.y[j] - f.y[k]) / two_a;
        let by = (f.x[k] - f.x[j]) / two_a;
        membrane[0][6 * i] = bx;
        membrane[1][6 * i + 1] = by;
        membrane[2][6 * i] = by;
        membrane[2][6 * i + 1] = bx;
        curvature[0][6 * i + 4] = bx;
        curvature[1][6 * i + 3] = -by;
        curvature[2][6 * i + 4] = by;
        curvature[2][6 * i + 3] = -bx;
    }
    let edge = |i: usize, j: usize| {
        let mut d = [0.0; N_DOF];
        let (dx, dy) = (f.x[j] - f.x[i], f.y[j] - f.y[i]);
        d[6 * i + 2] -= 1.0;
        d[6 * j + 2] += 1.0;
        for n in [i, j] {
            d[6 * n + 4] += 0.5 * dx;
            d[6 * n + 3] -= 0.5 * dy;
        }
        d
    };
    let (d12, d13, d23) = (edge(0, 1), edge(0, 2), edge(1, 2));
    let combine = |a: f64, b: f64, c: f64| -> Row {
        std::array::from_fn(|n| a * d12[n] + b * d13[n] + c * d23[n])
    };
    let er = combine(2.0 / 3.0, 1.0 / 3.0, -1.0 / 3.0);
    let es = combine(1.0 / 3.0, 2.0 / 3.0, 1.0 / 3.0);
    let c = combine(-1.0, 1.0, -1.0);
    // J = [[gr.x, gr.y], [gs.x, gs.y]], J⁻¹ = [[gs.y, -gr.y], [-gs.x, gr.x]] / det
    let (grx, gry) = (f.x[1] - f.x[0], f.y[1] - f.y[0]);
    let (gsx, gsy) = (f.x[2] - f.x[0], f.y[2] - f.y[0]);
    let det = grx * gsy - gry * gsx;
    let inv = [[gsy / det, -gry / det], [-gsx / det, grx / det]];
    let gxz = std::array::from_fn(|n| inv[0][0] * er[n] + inv[0][1] * es[n]);
    let gyz = std::array::from_fn(|n| inv[1][0] * er[n] + inv[1][1] * es[n]);
    let (j1, j2) = ([inv[0][0], inv[1][0]], [inv[0][1], inv[1][1]]);
    let m = (j1[0] * j1[0]
        + j1[1] * j1[1]
        + j2[0] * j2[0]
        + j2[1] * j2[1]
        + j1[0] * j2[0]
        + j1[1] * j2[1])
        / 18.0;
    Rows { membrane, curvature, shear: [gxz, gyz, c], linear_shear_factor: m }
}

/// `row · d`.
pub fn apply(row: &Row, d: &[f64; N_DOF]) -> f64 {
    row.iter().zip(d).map(|(a, b)| a * b).sum()
}
