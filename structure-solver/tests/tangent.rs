//! The tangent of the elastic corotated shells (exact material part `Bᵀ K B` plus forward
//! differences of the geometric part) against central differences of the whole force, taken
//! from the same element built as a J2 section that never yields, in a deformed and rotated
//! configuration, with and without a follower pressure.

use nalgebra::{Matrix3, Vector3};
use structure_solver::elements::rotation::exp;
use structure_solver::elements::{Element, ShellSection, ShellYield};

const SEC: ShellSection = ShellSection { e: 1e7, nu: 0.3, rho: 1.0, h: 0.05 };
const NEVER: ShellYield = ShellYield { sigma_y: f64::INFINITY, hardening: 0.0, points: 3 };

fn pressure(p: f64, x: &[Vector3<f64>], out: &mut [f64]) {
    let a = if x.len() == 4 {
        0.5 * (x[2] - x[0]).cross(&(x[3] - x[1]))
    } else {
        0.5 * (x[1] - x[0]).cross(&(x[2] - x[0]))
    };
    out.fill(0.0);
    for i in 0..x.len() {
        for c in 0..3 {
            out[6 * i + c] = a[c] * p / x.len() as f64;
        }
    }
}

#[test]
fn elastic_tangent_matches_central_differences_of_the_force() {
    let x0 = [
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(1.1, 0.0, 0.05),
        Vector3::new(1.0, 0.9, 0.0),
        Vector3::new(-0.1, 1.0, -0.03),
    ];
    let q = |x: &[Vector3<f64>]| -> Vec<Vector3<f64>> {
        x.iter()
            .enumerate()
            .map(|(i, p)| {
                exp(&Vector3::new(0.3, -0.5, 0.8)) * p
                    + Vector3::new(0.05 * i as f64, 0.02, -0.03 * i as f64)
            })
            .collect()
    };
    let rot = |n: usize| -> Vec<Matrix3<f64>> {
        (0..n)
            .map(|i| exp(&Vector3::new(0.3 + 0.05 * i as f64, -0.5, 0.8 - 0.04 * i as f64)))
            .collect()
    };
    let tri = [x0[0], x0[1], x0[2]];
    let cases = [
        (
            "quad",
            Element::quad4([0, 1, 2, 3], &x0, &SEC, None),
            Element::quad4([0, 1, 2, 3], &x0, &SEC, Some(NEVER)),
            q(&x0),
        ),
        (
            "triangle",
            Element::tri3([0, 1, 2], &tri, &SEC, None),
            Element::tri3([0, 1, 2], &tri, &SEC, Some(NEVER)),
            q(&tri),
        ),
    ];
    let load = |xs: &[Vector3<f64>], o: &mut [f64]| pressure(3e3, xs, o);
    for (name, elastic, layered, x) in &cases {
        let r = rot(x.len());
        for with_load in [false, true] {
            let extra: Option<&structure_solver::elements::element::LoadFn> =
                if with_load { Some(&load) } else { None };
            let a = elastic.tangent(x, &r, &[], extra);
            let state = vec![0.0; layered.n_state()];
            let b = layered.tangent(x, &r, &state, extra);
            let scale = b.amax();
            let err = (&a - &b).amax();
            println!(
                "{name}, load {with_load}: |K_analytic - K_central| / |K| = {:.2e}",
                err / scale
            );
            assert!(err < 1e-6 * scale, "{name}: tangent error {:e} of {scale:e}", err);
        }
    }
}
