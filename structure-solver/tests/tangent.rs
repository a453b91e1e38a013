//! The consistent tangent of the corotated elements (`Bᵀ K_l B` plus the closed-form
//! geometric stiffness of `corotation::Reference::tangent`) against central differences of the
//! element force, for the MITC4 and DKT shells (elastic, and J2 through the thickness while
//! yielding) and the beam, at a configuration far from the initial one (rigid rotation of about
//! 60°, nodal rotations differing by up to 10°, strains of a few percent: the skew part of the
//! tangent, a part of the geometric stiffness, is 6e-5 to 5e-2 of it, far above the bound), with
//! and without a follower pressure.

use nalgebra::{DMatrix, Matrix3, Vector3};
use structure_solver::elements::element::LoadFn;
use structure_solver::elements::rotation::exp;
use structure_solver::elements::{BeamSection, Element, ShellSection, ShellYield};

const SEC: ShellSection = ShellSection { e: 1e7, nu: 0.3, rho: 1.0, h: 0.05 };
/// Yields at strains of 1% (the configuration strains the elements by a few percent).
const YIELD: ShellYield = ShellYield { sigma_y: 1e5, hardening: 2e5, points: 5 };

/// Relative bound on `max |K - K_fd| / max |K_fd|`.
const BOUND: f64 = 1e-5;

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

/// Positions: a large rigid rotation of `x0` plus a deformation; rotations: large, differing
/// from node to node.
fn configuration(x0: &[Vector3<f64>]) -> (Vec<Vector3<f64>>, Vec<Matrix3<f64>>) {
    let q = exp(&Vector3::new(0.3, -0.5, 0.8));
    let x = x0
        .iter()
        .enumerate()
        .map(|(i, p)| q * p + Vector3::new(0.05 * i as f64, 0.02, -0.03 * i as f64))
        .collect();
    let r = (0..x0.len())
        .map(|i| exp(&Vector3::new(0.3 + 0.05 * i as f64, -0.5, 0.8 - 0.04 * i as f64)))
        .collect();
    (x, r)
}

fn relative_error(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (a - b).amax() / b.amax()
}

#[test]
fn consistent_tangent_matches_central_differences_of_the_force() {
    let x0 = [
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(1.1, 0.0, 0.05),
        Vector3::new(1.0, 0.9, 0.0),
        Vector3::new(-0.1, 1.0, -0.03),
    ];
    let tri = [x0[0], x0[1], x0[2]];
    let bar = [x0[0], Vector3::new(2.0, 0.3, 0.1)];
    let beam_sec = BeamSection::rectangle(1e7, 0.3, 1.0, 0.1, 0.2);
    let cases: Vec<(&str, Element, &[Vector3<f64>])> = vec![
        ("MITC4 elastic", Element::quad4([0, 1, 2, 3], &x0, &SEC, None), &x0),
        ("MITC4 J2", Element::quad4([0, 1, 2, 3], &x0, &SEC, Some(YIELD)), &x0),
        ("DKT elastic", Element::tri3([0, 1, 2], &tri, &SEC, None), &tri),
        ("DKT J2", Element::tri3([0, 1, 2], &tri, &SEC, Some(YIELD)), &tri),
        ("beam", Element::beam2([0, 1], &bar, Vector3::new(0.0, 0.0, 1.0), &beam_sec), &bar),
    ];
    let load = |xs: &[Vector3<f64>], o: &mut [f64]| pressure(3e3, xs, o);
    for (name, element, x0) in &cases {
        let (x, r) = configuration(x0);
        let state = vec![0.0; element.n_state()];
        if element.n_state() > 0 {
            // the configuration is plastic: the trial state moved
            let mut trial = state.clone();
            let mut f = vec![0.0; 6 * x.len()];
            element.force(&x, &r, &state, &mut trial, &mut f);
            assert!(trial.iter().any(|&v| v != 0.0), "{name}: the sections do not yield");
        }
        for with_load in [false, true] {
            if with_load && x.len() == 2 {
                continue;
            }
            let extra: Option<&LoadFn> = if with_load { Some(&load) } else { None };
            let k = element.tangent(&x, &r, &state, extra);
            let fd = element.tangent_by_differences(&x, &r, &state, extra);
            let err = relative_error(&k, &fd);
            // the geometric part: the asymmetry of the tangent off equilibrium
            let skew = relative_error(&fd, &fd.transpose());
            println!(
                "{name}, pressure {with_load}: |K - K_fd| / |K_fd| = {err:.2e} \
                 (skew part {skew:.2e})"
            );
            assert!(err < BOUND, "{name}: tangent error {err:e}");
            assert!(
                skew > BOUND && skew > 100.0 * err,
                "{name}: the configuration is not stressed enough ({skew:e})"
            );
        }
    }
}
