//! The bubble's volume from its level set, two ways:
//!
//! - [`piecewise_linear`]: the volume where the piecewise-linear interpolant of `φ` is positive,
//!   each hex split into six tets about its diagonal `0-6`, each pyramid into two about its
//!   base's diagonal `0-2`, and each tet's share exact for a
//!   linear `φ` ([`positive_fraction`]). The interpolant is within `O(h²)` of the signed distance
//!   where that is smooth (at a sphere of radius `R >> h`), so the volume is too.
//! - [`smoothed_heaviside`]: `Σ |C_i| H(φ_i/h_i)` over the nodes' dual cells with the linear ramp
//!   `H(s) = clamp(1/2 + s, 0, 1)`: a point rule whose point (the node) is not the centroid of its
//!   dual cell on a graded mesh, nor inside a symmetric cell at a symmetry plane, which leaves an
//!   `O(h)` bias at a curved interface. Kept to show that bias against the first.

use fluid_solver::mesh::{CellKind, Mesh};

/// The six tets of a hex (gmsh order: `0 1 2 3` one face, `4 5 6 7` the opposite one, `4` over
/// `0`) about its diagonal `0-6`: each holds the diagonal and one edge of the loop `1 2 3 7 4 5`
/// of the other vertices.
const HEX_TETS: [[usize; 4]; 6] =
    [[0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6], [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6]];

/// The fraction of a tet where a linear function with vertex values `v` is positive.
///
/// With `k` positive values the region is a corner tet (`k = 1`: `a³ / Π (a - v_j)`), its
/// complement (`k = 3`), or a wedge (`k = 2`, positives `a, b`, the others `c, d <= 0`):
/// `(a²b² - ab(a + b)(c + d) + (a² + ab + b²) cd) / ((a - c)(a - d)(b - c)(b - d))`, every term
/// of which is non-negative, so no formula cancels and none divides by less than a positive value.
pub fn positive_fraction(v: [f64; 4]) -> f64 {
    let (pos, neg): (Vec<f64>, Vec<f64>) = v.iter().partition(|&&x| x > 0.0);
    match (pos.as_slice(), neg.as_slice()) {
        ([], _) => 0.0,
        (_, []) => 1.0,
        (&[a], n) => a.powi(3) / n.iter().map(|&x| a - x).product::<f64>(),
        (p, &[e]) => 1.0 - (-e).powi(3) / p.iter().map(|&x| x - e).product::<f64>(),
        (&[a, b], &[c, d]) => {
            let num = a * a * b * b - a * b * (a + b) * (c + d) + (a * a + a * b + b * b) * c * d;
            num / ((a - c) * (a - d) * (b - c) * (b - d))
        }
        _ => unreachable!("four values split in two"),
    }
}

/// The volume of a tet with vertices `x`.
fn tet_volume(x: [[f64; 3]; 4]) -> f64 {
    let d = |k: usize| [x[k][0] - x[0][0], x[k][1] - x[0][1], x[k][2] - x[0][2]];
    let (a, b, c) = (d(1), d(2), d(3));
    let det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
        + a[2] * (b[0] * c[1] - b[1] * c[0]);
    det.abs() / 6.0
}

/// The volume where the piecewise-linear interpolant of the nodal `phi` is positive, over the
/// mesh's tets, hexes (each as [`HEX_TETS`]) and pyramids.
pub fn piecewise_linear(mesh: &Mesh, phi: &[f64]) -> anyhow::Result<f64> {
    positive_integral(mesh, phi, None)
}

/// The integral of the nodal `f` over the same volume, `f` taken in each tet as the mean of its
/// vertices where `φ > 0` (the gas mass from the gas density: free of the jumps of a sum over
/// the gas nodes' dual cells as nodes change fluid).
pub fn piecewise_linear_integral(mesh: &Mesh, phi: &[f64], f: &[f64]) -> anyhow::Result<f64> {
    positive_integral(mesh, phi, Some(f))
}

fn positive_integral(mesh: &Mesh, phi: &[f64], f: Option<&[f64]>) -> anyhow::Result<f64> {
    let mut v = 0.0;
    for (n, cell) in mesh.cells.iter().enumerate() {
        let tets: &[[usize; 4]] = match cell.kind {
            CellKind::Tet => &[[0, 1, 2, 3]],
            CellKind::Hex => &HEX_TETS,
            CellKind::Pyramid => &[[0, 1, 2, 4], [0, 2, 3, 4]],
            other => anyhow::bail!("cell {n}: a {} has no tet split here", other.name()),
        };
        let nodes = cell.nodes();
        for t in tets {
            let at = t.map(|k| nodes[k] as usize);
            let values = at.map(|i| phi[i]);
            if values.iter().all(|&p| p <= 0.0) {
                continue;
            }
            let weight = f.map_or(1.0, |f| {
                let gas: Vec<f64> = at.iter().filter(|&&i| phi[i] > 0.0).map(|&i| f[i]).collect();
                gas.iter().sum::<f64>() / gas.len() as f64
            });
            v += tet_volume(at.map(|i| mesh.coords[i])) * positive_fraction(values) * weight;
        }
    }
    Ok(v)
}

/// `Σ |C_i| H(φ_i/h_i)` with the linear ramp `H(s) = clamp(1/2 + s, 0, 1)` across each node's
/// dual cell, whose size `h_i` is the cube root of its volume mirrored through the symmetry
/// planes `x_k = 0` it lies on.
pub fn smoothed_heaviside(mesh: &Mesh, phi: &[f64]) -> f64 {
    let mut v = 0.0;
    for (i, x) in mesh.coords.iter().enumerate() {
        let mirrored = x.iter().filter(|&&x| x.abs() < 1e-12).count();
        let h = (mesh.volumes[i] * f64::from(1u32 << mirrored)).cbrt();
        v += mesh.volumes[i] * (0.5 + phi[i] / h).clamp(0.0, 1.0);
    }
    v
}

/// The fraction against planes through the unit corner tet `(0, e_x, e_y, e_z)` (vertex values
/// in that order): `φ = x - s` is positive in a corner tet of fraction `(1 - s)³`, `φ = s - x` in
/// its complement, and `φ = x + y - s` (two positive vertices) outside the wedge `x + y < s`,
/// whose volume `∫∫_{x+y<s} (1 - x - y) = s²/2 - s³/3` is the fraction `3s² - 2s³`.
#[test]
fn tet_fractions_of_planes() {
    for s in [0.1, 0.37, 0.8] {
        let corner = (1.0f64 - s).powi(3);
        assert!((positive_fraction([-s, 1.0 - s, -s, -s]) - corner).abs() < 1e-14);
        assert!((positive_fraction([s, s - 1.0, s, s]) - (1.0 - corner)).abs() < 1e-14);
        let wedge = 3.0 * s * s - 2.0 * s.powi(3);
        let f = positive_fraction([-s, 1.0 - s, 1.0 - s, -s]);
        assert!((f - (1.0 - wedge)).abs() < 1e-14, "s = {s}: {f} against {}", 1.0 - wedge);
    }
    assert_eq!(positive_fraction([-1.0, -2.0, 0.0, -3.0]), 0.0);
    assert_eq!(positive_fraction([1.0, 2.0, 3.0, 4.0]), 1.0);
}
