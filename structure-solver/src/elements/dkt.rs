//! Flat 3-node shell: the discrete Kirchhoff triangle for bending (Batoz, Bathe & Ho 1980,
//! IJNME 15:1771), built from its definition (quadratic normal rotations, Kirchhoff constraints
//! at the corners and along the sides, linear normal rotation along each side), a constant
//! strain membrane and the drilling penalty of `section::DRILL_PENALTY`. Flat membranes of
//! this kind lock in curved shells (the hemisphere benchmark runs on a twice finer mesh).
//!
//! Local dofs per node `[u, v, w, θx, θy, θz]`; normal rotations `βx = θy`, `βy = -θx`.

use nalgebra::{DMatrix, Matrix2, Vector2};

use super::section::{add_btdb, ShellSection, DRILL_PENALTY};

/// Quadratic shape functions on the triangle (corners 1-3, mid-sides 4 = 23, 5 = 31, 6 = 12)
/// and their derivatives with respect to `(ξ, η)`.
fn quadratic(xi: f64, eta: f64) -> [[f64; 2]; 6] {
    let l = [1.0 - xi - eta, xi, eta];
    let dl = [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]];
    let mut d = [[0.0; 2]; 6];
    for i in 0..3 {
        for c in 0..2 {
            d[i][c] = (4.0 * l[i] - 1.0) * dl[i][c];
        }
    }
    for (k, (a, b)) in [(1usize, 2usize), (2, 0), (0, 1)].iter().enumerate() {
        for c in 0..2 {
            d[3 + k][c] = 4.0 * (l[*b] * dl[*a][c] + l[*a] * dl[*b][c]);
        }
    }
    d
}

/// `T` (12 x 9): nodal `[w, θx, θy]` of the three corners to `[βx, βy]` at the six nodes of the
/// quadratic rotation field.
fn kirchhoff_map(xy: &[[f64; 2]; 3]) -> DMatrix<f64> {
    let mut t = DMatrix::zeros(12, 9);
    for i in 0..3 {
        t[(2 * i, 3 * i + 2)] = 1.0; // βx = θy
        t[(2 * i + 1, 3 * i + 1)] = -1.0; // βy = -θx
    }
    for (k, (i, j)) in [(1usize, 2usize), (2, 0), (0, 1)].iter().enumerate() {
        let (i, j) = (*i, *j);
        let dx = xy[j][0] - xy[i][0];
        let dy = xy[j][1] - xy[i][1];
        let l = (dx * dx + dy * dy).sqrt();
        let s = Vector2::new(dx / l, dy / l);
        let n = Vector2::new(s.y, -s.x);
        // β_k = 3/(2l)(w_i - w_j) s + (½ n nᵀ - ¼ s sᵀ)(β_i + β_j)
        let m: Matrix2<f64> = 0.5 * n * n.transpose() - 0.25 * s * s.transpose();
        let row = 2 * (3 + k);
        for c in 0..2 {
            t[(row + c, 3 * i)] += 1.5 / l * s[c];
            t[(row + c, 3 * j)] -= 1.5 / l * s[c];
            for node in [i, j] {
                for r in 0..2 {
                    // β_node[r] = Σ t[(2 node + r, col)] U[col]
                    for col in 0..9 {
                        t[(row + c, col)] += m[(c, r)] * t[(2 * node + r, col)];
                    }
                }
            }
        }
    }
    t
}

/// Local 18x18 stiffness of a flat triangle with in-plane nodal coordinates `xy`.
pub fn stiffness(xy: &[[f64; 2]; 3], sec: &ShellSection) -> DMatrix<f64> {
    let to_d = |m: [[f64; 3]; 3]| DMatrix::from_fn(3, 3, |i, j| m[i][j]);
    let (dm, db) = (to_d(sec.membrane()), to_d(sec.bending()));
    let j = Matrix2::new(
        xy[1][0] - xy[0][0],
        xy[1][1] - xy[0][1],
        xy[2][0] - xy[0][0],
        xy[2][1] - xy[0][1],
    );
    let det = j.determinant();
    let area = 0.5 * det;
    let jinv = j.try_inverse().expect("degenerate triangle");
    let mut k = DMatrix::zeros(18, 18);

    // constant strain membrane
    let dl = [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]];
    let mut bm = DMatrix::zeros(3, 18);
    let mut omega = [0.0; 18];
    for i in 0..3 {
        let d = jinv * Vector2::new(dl[i][0], dl[i][1]);
        bm[(0, 6 * i)] = d.x;
        bm[(1, 6 * i + 1)] = d.y;
        bm[(2, 6 * i)] = d.y;
        bm[(2, 6 * i + 1)] = d.x;
        omega[6 * i + 1] += 0.5 * d.x;
        omega[6 * i] -= 0.5 * d.y;
    }
    add_btdb(&mut k, &bm, &dm, area);

    // DKT bending, 3-point mid-side rule (exact for the quadratic integrand)
    let t = kirchhoff_map(xy);
    let mut kb = DMatrix::zeros(9, 9);
    for (xi, eta) in [(0.5, 0.0), (0.5, 0.5), (0.0, 0.5)] {
        let dn = quadratic(xi, eta);
        // curvature rows over the 12 nodal β values
        let mut c = DMatrix::zeros(3, 12);
        for a in 0..6 {
            let d = jinv * Vector2::new(dn[a][0], dn[a][1]);
            c[(0, 2 * a)] = d.x; // βx,x
            c[(1, 2 * a + 1)] = d.y; // βy,y
            c[(2, 2 * a)] = d.y; // βx,y
            c[(2, 2 * a + 1)] = d.x; // βy,x
        }
        let b = c * &t;
        add_btdb(&mut kb, &b, &db, area / 3.0);
    }
    for i in 0..3 {
        for jj in 0..3 {
            for a in 0..3 {
                for b in 0..3 {
                    k[(6 * i + 2 + a, 6 * jj + 2 + b)] += kb[(3 * i + a, 3 * jj + b)];
                }
            }
        }
    }

    // drilling penalty
    let kd = DRILL_PENALTY * sec.shear_modulus() * sec.h * area;
    for i in 0..3 {
        let mut r = omega.map(|v| -v);
        r[6 * i + 5] += 1.0;
        let rv = DMatrix::from_row_slice(1, 18, &r);
        k.gemm_tr(kd, &rv, &rv, 1.0);
    }
    k
}

/// Area of the triangle.
pub fn area(xy: &[[f64; 2]; 3]) -> f64 {
    0.5 * ((xy[1][0] - xy[0][0]) * (xy[2][1] - xy[0][1])
        - (xy[2][0] - xy[0][0]) * (xy[1][1] - xy[0][1]))
}
