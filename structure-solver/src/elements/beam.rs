//! 2-node Euler-Bernoulli beam, local and small strain; large rotations come from the
//! corotated frame (`corotation::FrameRule::Beam`, Crisfield 1990 / Battini & Pacoste 2002).
//! Local dofs per node `[u, v, w, θx, θy, θz]`, `x` along the beam.

use nalgebra::DMatrix;

use super::section::BeamSection;

/// Local 12x12 stiffness of a beam of length `l`.
pub fn stiffness(l: f64, s: &BeamSection) -> DMatrix<f64> {
    let mut k = DMatrix::zeros(12, 12);
    let g = s.e / (2.0 * (1.0 + s.nu));
    let mut put = |dofs: [usize; 2], v: f64| {
        k[(dofs[0], dofs[0])] += v;
        k[(dofs[1], dofs[1])] += v;
        k[(dofs[0], dofs[1])] -= v;
        k[(dofs[1], dofs[0])] -= v;
    };
    put([0, 6], s.e * s.area / l);
    put([3, 9], g * s.j / l);
    // bending in x-y (v, θz) and x-z (w, θy; θy = -dw/dx)
    for (v, th, i, sign) in [(1usize, 5usize, s.iz, 1.0), (2, 4, s.iy, -1.0)] {
        let c = s.e * i / l.powi(3);
        let dofs = [v, th, v + 6, th + 6];
        let m = [
            [12.0, 6.0 * l * sign, -12.0, 6.0 * l * sign],
            [6.0 * l * sign, 4.0 * l * l, -6.0 * l * sign, 2.0 * l * l],
            [-12.0, -6.0 * l * sign, 12.0, -6.0 * l * sign],
            [6.0 * l * sign, 2.0 * l * l, -6.0 * l * sign, 4.0 * l * l],
        ];
        for a in 0..4 {
            for b in 0..4 {
                k[(dofs[a], dofs[b])] += c * m[a][b];
            }
        }
    }
    k
}
