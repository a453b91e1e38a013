//! Alg. 5.4 (thesis Eq. 5.49-5.52): loads on the surrogate interface of the dual facets of the cut
//! edges. Each cut edge `(i, j)` carries the force `p*_i ν_ij - p*_j ν_ij` on the structure (the
//! fluid of each side pushes towards the other), with the *full* facet area vector: correcting it
//! by `|n·n_E|` would break the zero resultant of a constant pressure on a closed surface (thesis
//! §5.3.3.3). The force acts at the intersection point and goes to the hit triangle's nodes by its
//! barycentric coordinates (`N_i^q(ξ_k)` in Eq. 5.51).

use super::{distribute, or_zero, LoadView};

pub(super) fn loads(view: &LoadView, out: &mut [[f64; 3]]) {
    for (cut, ps) in view.cuts.iter().zip(view.p_star) {
        let nu = view.mesh.edge_normals[cut.edge as usize];
        let dp = or_zero(ps[0]) - or_zero(ps[1]);
        distribute(view.surface, cut.triangle, cut.bary, nu.map(|c| dp * c), out);
    }
}
