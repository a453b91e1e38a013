//! Flat 4-node shell for static and implicit runs: the MITC4 assumed transverse shear of
//! Bathe & Dvorkin (1985, IJNME 21:367) with 2x2 Gauss integration, a membrane with Taylor's
//! incompatible modes (QM6; Taylor, Beresford & Wilson 1976, IJNME 10:1211) against in-plane
//! shear locking, its higher-order part scaled down against the membrane locking of facets
//! (`MEMBRANE_STABILISATION`), and a drilling penalty (`section::DRILL_PENALTY`). Local, small
//! strain: large rotations come from the corotated frame (`corotation`).
//!
//! Local dofs per node `[u, v, w, θx, θy, θz]`; normal rotations `βx = θy`, `βy = -θx`.

use nalgebra::{DMatrix, Matrix2, Vector2};

use super::layered::{InPlanePoint, Layers};
use super::section::{add_btdb, add_drilling_penalty, ShellSection};

/// Share of the higher-order (in-plane bending) membrane energy kept; 1 is the full QM6
/// membrane.
///
/// Flat facets approximating a doubly curved shell cannot bend inextensionally without in-plane
/// bending of the facets, so the full membrane locks coarse curved meshes (Sze hemisphere,
/// 16x16 quads: -1.87% and -3.17% at P_max against S4R; 32x32: -0.13% and -0.75%; halving
/// the membrane modulus moved the 16x16 result by +2.4%). As in the reduced-integration S4R with
/// its hourglass control (Belytschko & Bindeman 1993, assumed-strain stabilisation), the membrane
/// strain is the element's mean strain plus the higher-order part at this share of its energy:
/// exact for constant strain (patch test); the hemisphere on 16x16 at -0.94% and -1.42%
/// (0.1: -0.60%, -0.85%; 0.35: -1.12%, -1.74%). The price is coarse in-plane bending: an
/// in-plane cantilever of length 10 x depth 1 deflects 3.96x, 1.23x, 1.05x the exact value
/// with 1, 2, 4 elements across the depth (full membrane: 0.996, 0.998, 0.9995).
pub const MEMBRANE_STABILISATION: f64 = 0.25;

const XI: [f64; 4] = [-1.0, 1.0, 1.0, -1.0];
const ETA: [f64; 4] = [-1.0, -1.0, 1.0, 1.0];

fn shape(xi: f64, eta: f64) -> ([f64; 4], [f64; 4], [f64; 4]) {
    let mut n = [0.0; 4];
    let mut dxi = [0.0; 4];
    let mut deta = [0.0; 4];
    for i in 0..4 {
        n[i] = 0.25 * (1.0 + XI[i] * xi) * (1.0 + ETA[i] * eta);
        dxi[i] = 0.25 * XI[i] * (1.0 + ETA[i] * eta);
        deta[i] = 0.25 * ETA[i] * (1.0 + XI[i] * xi);
    }
    (n, dxi, deta)
}

fn jacobian(xy: &[[f64; 2]; 4], dxi: &[f64; 4], deta: &[f64; 4]) -> Matrix2<f64> {
    let mut j = Matrix2::zeros();
    for i in 0..4 {
        j[(0, 0)] += dxi[i] * xy[i][0];
        j[(0, 1)] += dxi[i] * xy[i][1];
        j[(1, 0)] += deta[i] * xy[i][0];
        j[(1, 1)] += deta[i] * xy[i][1];
    }
    j
}

/// Covariant transverse shear `γ_ξz` (`dir` 0) or `γ_ηz` (`dir` 1) at `(ξ, η)` as a row over
/// the 24 local dofs.
fn covariant_shear(xy: &[[f64; 2]; 4], xi: f64, eta: f64, dir: usize) -> [f64; 24] {
    let (n, dxi, deta) = shape(xi, eta);
    let j = jacobian(xy, &dxi, &deta);
    let dn = if dir == 0 { dxi } else { deta };
    let (xa, ya) = (j[(dir, 0)], j[(dir, 1)]);
    let mut r = [0.0; 24];
    for i in 0..4 {
        r[6 * i + 2] = dn[i];
        r[6 * i + 4] = n[i] * xa; // βx = θy
        r[6 * i + 3] = -n[i] * ya; // βy = -θx
    }
    r
}

/// The integration points of a flat quad with in-plane nodal coordinates `xy`
/// (counter-clockwise): at each 2x2 Gauss point the membrane rows (with Taylor's incompatible
/// modes condensed with the elastic membrane stiffness, a fixed linear enhancement, so the
/// element stays exact for elastic sections) and the bending rows; the MITC4 transverse shear
/// and the drilling penalty form the linear part.
pub fn layers(xy: &[[f64; 2]; 4], sec: &ShellSection) -> Layers {
    let to_d = |m: [[f64; 3]; 3]| DMatrix::from_fn(3, 3, |i, j| m[i][j]);
    let dm = to_d(sec.membrane());
    let ds = DMatrix::from_diagonal_element(2, 2, sec.shear());
    let g = 1.0 / 3f64.sqrt();
    let gauss = [(-g, -g), (g, -g), (g, g), (-g, g)];
    // MITC4 tying points: γ_ξz at A (0, 1), C (0, -1); γ_ηz at D (1, 0), B (-1, 0).
    let ga = covariant_shear(xy, 0.0, 1.0, 0);
    let gc = covariant_shear(xy, 0.0, -1.0, 0);
    let gd = covariant_shear(xy, 1.0, 0.0, 1);
    let gb = covariant_shear(xy, -1.0, 0.0, 1);
    let (_, dxi0, deta0) = shape(0.0, 0.0);
    let j0 = jacobian(xy, &dxi0, &deta0);
    let (j0inv, det0) = (j0.try_inverse().expect("degenerate quad"), j0.determinant());

    let mut k_linear = DMatrix::zeros(24, 24);
    let mut kaa = DMatrix::<f64>::zeros(4, 4);
    let mut kua = DMatrix::<f64>::zeros(24, 4);
    let mut points = Vec::with_capacity(4);
    let mut incompatible = Vec::with_capacity(4);
    for &(xi, eta) in &gauss {
        let (_, dxi, deta) = shape(xi, eta);
        let j = jacobian(xy, &dxi, &deta);
        let det = j.determinant();
        let jinv = j.try_inverse().expect("degenerate quad");
        let mut bm = DMatrix::zeros(3, 24);
        let mut bb = DMatrix::zeros(3, 24);
        for i in 0..4 {
            let d = jinv * Vector2::new(dxi[i], deta[i]);
            let (nx, ny) = (d.x, d.y);
            bm[(0, 6 * i)] = nx;
            bm[(1, 6 * i + 1)] = ny;
            bm[(2, 6 * i)] = ny;
            bm[(2, 6 * i + 1)] = nx;
            bb[(0, 6 * i + 4)] = nx;
            bb[(1, 6 * i + 3)] = -ny;
            bb[(2, 6 * i + 4)] = ny;
            bb[(2, 6 * i + 3)] = -nx;
        }
        let mut bs = DMatrix::zeros(2, 24);
        for c in 0..24 {
            let gxi = 0.5 * (1.0 + eta) * ga[c] + 0.5 * (1.0 - eta) * gc[c];
            let geta = 0.5 * (1.0 + xi) * gd[c] + 0.5 * (1.0 - xi) * gb[c];
            let cart = jinv * Vector2::new(gxi, geta);
            bs[(0, c)] = cart.x;
            bs[(1, c)] = cart.y;
        }
        add_btdb(&mut k_linear, &bs, &ds, det);
        // incompatible modes P1 = 1 - ξ², P2 = 1 - η² for u and v, derivatives through J0
        // scaled by det J0 / det J so that ∫ G dA = 0 (patch test).
        let p1 = j0inv * Vector2::new(-2.0 * xi, 0.0) * (det0 / det);
        let p2 = j0inv * Vector2::new(0.0, -2.0 * eta) * (det0 / det);
        let mut ginc = DMatrix::zeros(3, 4);
        for (m, p) in [p1, p2].iter().enumerate() {
            ginc[(0, m)] = p.x;
            ginc[(1, 2 + m)] = p.y;
            ginc[(2, m)] = p.y;
            ginc[(2, 2 + m)] = p.x;
        }
        add_btdb(&mut kaa, &ginc, &dm, det);
        kua.gemm_tr(det, &bm, &(&dm * &ginc), 1.0);
        points.push(InPlanePoint { weight: det, bm, bb });
        incompatible.push(ginc);
    }
    // Condensed modes α = -Kαα⁻¹ Kuαᵀ d: membrane rows B_m + G A reproduce
    // K_uu - Kuα Kαα⁻¹ Kuαᵀ exactly.
    let kaa_inv = kaa.try_inverse().expect("incompatible-mode block is positive definite");
    let a = -(kaa_inv * kua.transpose());
    for (p, ginc) in points.iter_mut().zip(&incompatible) {
        p.bm += ginc * &a;
    }
    // membrane: the mean strain plus the higher-order (in-plane bending) part scaled so that
    // it carries `MEMBRANE_STABILISATION` of its energy
    let total: f64 = points.iter().map(|p| p.weight).sum();
    let mean = points.iter().fold(DMatrix::zeros(3, 24), |m, p| m + &p.bm * (p.weight / total));
    let s = MEMBRANE_STABILISATION.sqrt();
    for p in points.iter_mut() {
        p.bm = &mean + (&p.bm - &mean) * s;
    }

    // drilling penalty: θz_i - ω_c, ω_c = ½(v,x - u,y) at the centroid
    let area = 4.0 * det0;
    let mut omega = [0.0; 24];
    for i in 0..4 {
        let d = j0inv * Vector2::new(dxi0[i], deta0[i]);
        omega[6 * i + 1] += 0.5 * d.x;
        omega[6 * i] -= 0.5 * d.y;
    }
    add_drilling_penalty(&mut k_linear, &omega, sec, area);
    Layers { points, k_linear }
}

/// Local 24x24 stiffness of a flat quad with in-plane nodal coordinates `xy` (counter-clockwise).
pub fn stiffness(xy: &[[f64; 2]; 4], sec: &ShellSection) -> DMatrix<f64> {
    layers(xy, sec).elastic_stiffness(sec)
}

/// Area of the flat quad.
pub fn area(xy: &[[f64; 2]; 4]) -> f64 {
    0.5 * ((xy[2][0] - xy[0][0]) * (xy[3][1] - xy[1][1])
        - (xy[3][0] - xy[1][0]) * (xy[2][1] - xy[0][1]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pure in-plane bending of one rectangle (`u = κxy`, `v = -κx²/2`, ν = 0): the full QM6
    /// membrane holds the exact energy `½ E h κ² ∫y² dA`; the element keeps
    /// `MEMBRANE_STABILISATION` of it (the mean strain of the mode is zero).
    #[test]
    fn in_plane_bending_carries_the_stabilised_share_of_the_exact_energy() {
        let (a, b, kappa) = (1.5, 0.5, 1e-3);
        let sec = ShellSection { e: 1e7, nu: 0.0, rho: 1.0, h: 0.1 };
        let xy = [[-a, -b], [a, -b], [a, b], [-a, b]];
        let k = stiffness(&xy, &sec);
        let mut d = nalgebra::DVector::zeros(24);
        for (i, p) in xy.iter().enumerate() {
            d[6 * i] = kappa * p[0] * p[1];
            d[6 * i + 1] = -0.5 * kappa * p[0] * p[0];
        }
        let energy = 0.5 * d.dot(&(&k * &d));
        let exact = 0.5 * sec.e * sec.h * kappa * kappa * (2.0 * a) * (2.0 * b.powi(3) / 3.0);
        let share = energy / exact;
        assert!((share - MEMBRANE_STABILISATION).abs() < 1e-9, "share {share}");
    }
}
