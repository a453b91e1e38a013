//! Flat 3-node shell: the discrete Kirchhoff triangle for bending (Batoz, Bathe & Ho 1980,
//! IJNME 15:1771), built from its definition (quadratic normal rotations, Kirchhoff constraints
//! at the corners and along the sides, linear normal rotation along each side), a constant
//! strain membrane and the drilling penalty of `section::DRILL_PENALTY`. Flat membranes of
//! this kind lock in curved shells (the hemisphere benchmark runs on a twice finer mesh).
//!
//! Local dofs per node `[u, v, w, θx, θy, θz]`; normal rotations `βx = θy`, `βy = -θx`.

use nalgebra::{DMatrix, Matrix2, Vector2};

use super::layered::{InPlanePoint, Layers};
use super::section::{add_drilling_penalty, ShellSection};

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

/// The integration points of a flat triangle with in-plane nodal coordinates `xy`: the
/// constant membrane rows and the DKT curvature rows at the three mid-side points (exact for
/// the quadratic elastic integrand, weight `A/3` each); the drilling penalty is the linear part.
pub fn layers(xy: &[[f64; 2]; 3], sec: &ShellSection) -> Layers {
    let j = Matrix2::new(
        xy[1][0] - xy[0][0],
        xy[1][1] - xy[0][1],
        xy[2][0] - xy[0][0],
        xy[2][1] - xy[0][1],
    );
    let area = 0.5 * j.determinant();
    let jinv = j.try_inverse().expect("degenerate triangle");

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

    // DKT bending at the mid-side points
    let t = kirchhoff_map(xy);
    let mut points = Vec::with_capacity(3);
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
        // [w, θx, θy] of each corner to the element's 6 dofs per node
        let mut bb = DMatrix::zeros(3, 18);
        for r in 0..3 {
            for i in 0..3 {
                for a in 0..3 {
                    bb[(r, 6 * i + 2 + a)] = b[(r, 3 * i + a)];
                }
            }
        }
        points.push(InPlanePoint { weight: area / 3.0, bm: bm.clone(), bb });
    }

    let mut k_linear = DMatrix::zeros(18, 18);
    add_drilling_penalty(&mut k_linear, &omega, sec, area);
    Layers { points, k_linear }
}

/// Local 18x18 stiffness of a flat triangle with in-plane nodal coordinates `xy`.
pub fn stiffness(xy: &[[f64; 2]; 3], sec: &ShellSection) -> DMatrix<f64> {
    layers(xy, sec).elastic_stiffness(sec)
}

/// Area of the triangle.
pub fn area(xy: &[[f64; 2]; 3]) -> f64 {
    0.5 * ((xy[1][0] - xy[0][0]) * (xy[2][1] - xy[0][1])
        - (xy[2][0] - xy[0][0]) * (xy[1][1] - xy[0][1]))
}
