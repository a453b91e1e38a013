//! The level set in a velocity field that strains it at the interface, as a growing bubble does.

use super::advect::residual_and_update;
use super::reinit::reinitialise;
use super::LevelSetWorkspace;
use crate::embedded::adjacency::NodeEdges;
use crate::mesh::boxmesh::{BoxCells, BoxSpec};
use crate::mesh::Mesh;
use crate::reconstruct::gradient::LsqGradient;
use crate::reconstruct::limiter::Limiter;

/// The zero of `φ` along the tube's axis nodes (y = z = 0), linearly interpolated.
fn zero_on_axis(mesh: &Mesh, phi: &[f64]) -> f64 {
    let mut axis: Vec<(f64, f64)> = (0..mesh.n_nodes())
        .filter(|&i| mesh.coords[i][1] == 0.0 && mesh.coords[i][2] == 0.0)
        .map(|i| (mesh.coords[i][0], phi[i]))
        .collect();
    axis.sort_by(|a, b| a.0.total_cmp(&b.0));
    let k = axis.windows(2).position(|w| w[0].1 < 0.0 && w[1].1 >= 0.0).unwrap();
    let ((xa, pa), (xb, pb)) = (axis[k], axis[k + 1]);
    xa + (xb - xa) * pa / (pa - pb)
}

/// The zero of `φ = x - x0` carried by `u = 1 - a|x - X(t)|`, `X = x0 + t` (the interface moves at
/// 1, the flow stretches `φ` behind it and compresses it ahead, as the gas and the liquid of a
/// growing bubble do), RK2 at Courant number 0.4 on a tube of `cells` tets, reinitialised every
/// `reinit_every` steps (0: never). Returns the zero's error at `t_end`.
fn zero_error(cells: usize, reinit_every: usize, a: f64, t_end: f64) -> f64 {
    let mesh = Mesh::build(
        BoxSpec::tube(0.0, 1.0, cells, 1.0 / cells as f64, BoxCells::Tet).raw().unwrap(),
    )
    .unwrap();
    let n = mesh.n_nodes();
    let gradient = LsqGradient::new(&mesh);
    let adjacency = NodeEdges::build(&mesh);
    let open: Vec<bool> = mesh.coords.iter().map(|x| x[0] == 0.0 || x[0] == 1.0).collect();
    let x0 = 0.3 + 0.37 / cells as f64;
    let h = 1.0 / cells as f64;
    let steps = (t_end / (0.4 * h / 1.0)).ceil() as usize;
    let dt = t_end / steps as f64;
    let mut phi: Vec<f64> = mesh.coords.iter().map(|x| x[0] - x0).collect();
    let mut lws = LevelSetWorkspace::new(n);
    let prim_at = |t: f64| -> Vec<[f64; 5]> {
        let xi = x0 + t;
        mesh.coords.iter().map(|x| [1.0, 1.0 - a * (x[0] - xi).abs(), 0.0, 0.0, 1.0]).collect()
    };
    for step in 0..steps {
        let t = step as f64 * dt;
        let (p0, p1) = (prim_at(t), prim_at(t + dt));
        for (s, p) in lws.phi.iter_mut().zip(&phi) {
            s[0] = *p;
        }
        let ratio = |i: usize| dt / mesh.volumes[i];
        let old = phi.clone();
        let mut stage = vec![0.0; n];
        residual_and_update(
            &mesh,
            &gradient,
            Limiter::VanAlbada,
            &open,
            None,
            None,
            &p0,
            &mut lws,
            &mut stage,
            |i, r, o| *o = old[i] - ratio(i) * r,
        );
        for (s, p) in lws.phi.iter_mut().zip(&stage) {
            s[0] = *p;
        }
        residual_and_update(
            &mesh,
            &gradient,
            Limiter::VanAlbada,
            &open,
            None,
            None,
            &p1,
            &mut lws,
            &mut phi,
            |i, r, o| *o = 0.5 * old[i] + 0.5 * (stage[i] - ratio(i) * r),
        );
        if reinit_every > 0 && (step + 1) % reinit_every == 0 {
            for (s, p) in lws.phi.iter_mut().zip(&phi) {
                s[0] = *p;
            }
            gradient.compute(&mesh, &lws.phi, &mut lws.grad);
            reinitialise(&mesh, &adjacency, &lws.grad, &mut phi, None);
        }
    }
    zero_on_axis(&mesh, &phi) - (x0 + t_end)
}

/// In the strained flow the zero of `φ` (moved by the mean nodal velocity) lags the interface by
/// a fraction of a cell: first order, within 0.65 h on 25 to 200 cells, the error falling by more
/// than 1.6 per halving of h, with or without reinitialisation (seen: 0.39-0.59 h without, 0.39-0.43
/// h with, ratios 1.71-1.98), so neither the advection nor the frozen nodes of the
/// reinitialisation leave an error that stays as h falls.
#[test]
fn a_strained_interface_lags_by_a_first_order_error() {
    let cells = [25, 50, 100, 200];
    for reinit in [0, 10] {
        let errors: Vec<f64> = cells.iter().map(|&c| zero_error(c, reinit, 2.0, 0.3)).collect();
        let in_cells: Vec<f64> = errors.iter().zip(cells).map(|(e, c)| e * c as f64).collect();
        println!("reinit every {reinit}: zero error {errors:?}, in cells {in_cells:?}");
        for (e, c) in errors.iter().zip(cells) {
            assert!(e.abs() < 0.65 / c as f64, "reinit {reinit}, {c} cells: zero error {e}");
        }
        for w in errors.windows(2) {
            assert!(w[0].abs() > 1.6 * w[1].abs(), "reinit {reinit}: errors {errors:?}");
        }
    }
}
