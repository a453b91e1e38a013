//! A one-dimensional line of node-centred finite volumes for tests: the edge loop of the solver
//! (MUSCL with nodal central-difference gradients, a numerical flux per edge, gather to the two
//! nodes, two-stage TVD Runge-Kutta) on `[0, 1]`, periodic or with transmissive ends.

use super::{numerical_flux, physical_flux, FluxScheme};
use crate::eos::Eos;
use crate::reconstruct::limiter::Limiter;
use crate::reconstruct::muscl::reconstruct;

#[derive(Clone, Copy, PartialEq)]
pub(crate) enum Ends {
    Periodic,
    Transmissive,
}

/// Advances the primitive states `w` (node `i` at `x = (i + ½)/n`) to time `t` with CFL `cfl`.
pub(crate) fn run(
    eos: &Eos,
    scheme: FluxScheme,
    limiter: Limiter,
    ends: Ends,
    w: &[[f64; 5]],
    t: f64,
    cfl: f64,
) -> Vec<[f64; 5]> {
    let n = w.len();
    let h = 1.0 / n as f64;
    let mut q: Vec<[f64; 5]> = w.iter().map(|x| eos.prim_to_cons(x)).collect();
    let neighbour = |i: usize, di: isize| match ends {
        Ends::Periodic => (i as isize + di).rem_euclid(n as isize) as usize,
        Ends::Transmissive => (i as isize + di).clamp(0, n as isize - 1) as usize,
    };
    let residual = |q: &[[f64; 5]]| {
        let w: Vec<[f64; 5]> = q.iter().map(|x| eos.cons_to_prim(x)).collect();
        let grad: Vec<[[f64; 3]; 5]> = (0..n)
            .map(|i| {
                let (a, b) = (&w[neighbour(i, -1)], &w[neighbour(i, 1)]);
                let span =
                    (neighbour(i, 1) as f64 - neighbour(i, -1) as f64).rem_euclid(n as f64) * h;
                std::array::from_fn(|k| [(b[k] - a[k]) / span, 0.0, 0.0])
            })
            .collect();
        let mut r = vec![[0.0; 5]; n];
        let edges = if ends == Ends::Periodic { n } else { n - 1 };
        for i in 0..edges {
            let j = (i + 1) % n;
            let (wij, wji) =
                reconstruct(limiter, eos, &w[i], &grad[i], eos, &w[j], &grad[j], &[h, 0.0, 0.0]);
            let f = numerical_flux(scheme, eos, &wij, &wji, &[1.0, 0.0, 0.0]);
            for k in 0..5 {
                r[i][k] -= f[k] / h;
                r[j][k] += f[k] / h;
            }
        }
        if ends == Ends::Transmissive {
            let (fl, fr) = (
                physical_flux(eos, &w[0], &[1.0, 0.0, 0.0]),
                physical_flux(eos, &w[n - 1], &[1.0, 0.0, 0.0]),
            );
            for k in 0..5 {
                r[0][k] += fl[k] / h;
                r[n - 1][k] -= fr[k] / h;
            }
        }
        r
    };
    let mut time = 0.0;
    while time < t {
        let smax = q
            .iter()
            .map(|x| {
                let w = eos.cons_to_prim(x);
                w[1].abs() + eos.sound_speed(w[0], w[4])
            })
            .fold(0.0, f64::max);
        let dt = (cfl * h / smax).min(t - time);
        let r1 = residual(&q);
        let q1: Vec<[f64; 5]> =
            (0..n).map(|i| std::array::from_fn(|k| q[i][k] + dt * r1[i][k])).collect();
        let r2 = residual(&q1);
        for i in 0..n {
            for k in 0..5 {
                q[i][k] = 0.5 * (q[i][k] + q1[i][k] + dt * r2[i][k]);
            }
        }
        time += dt;
    }
    q.iter().map(|x| eos.cons_to_prim(x)).collect()
}
