//! Energy balance of an explicit J2 plate of BT4 and BLT3 shells in one `FeModel` (a
//! checkerboard of quadrilaterals and split cells), free, given an initial velocity
//! (transverse and in-plane): at every step the kinetic energy plus the work of the internal
//! forces equals the initial kinetic energy, and the work of the internal forces is the
//! elastic energy of the stresses (and BLT3's shear resultants) plus the plastic work
//! `∫ κ dα` of the points, to the hourglass energy of the quadrilaterals.

use structure_solver::assembly::{FeModel, Part};
use structure_solver::elements::blt3::{frame, rows};
use structure_solver::elements::{RotaryInertia, ShellSection, ShellYield};
use structure_solver::mesh::{generate, Cell, CellKind, Mesh};
use structure_solver::model::Model;
use structure_solver::time::{kinetic_energy, CentralDifference};

const SEC: ShellSection = ShellSection { e: 200e9, nu: 0.3, rho: 7800.0, h: 0.002 };
const YIELD: ShellYield = ShellYield { sigma_y: 250e6, hardening: 1e9, points: 5 };

/// `n` x `n` cells on `[0, l]²`, cell `(i, j)` split into two triangles where `i + j` is odd.
fn checkerboard(l: f64, n: usize) -> Mesh {
    let mut mesh = generate::rectangle(l, l, n, n);
    let d = l / n as f64;
    let mut cells = Vec::new();
    for c in &mesh.cells {
        let cx = c.nodes.iter().map(|&k| mesh.nodes[k][0]).sum::<f64>() / 4.0;
        let cy = c.nodes.iter().map(|&k| mesh.nodes[k][1]).sum::<f64>() / 4.0;
        let (i, j) = ((cx / d) as usize, (cy / d) as usize);
        let m = &c.nodes;
        if (i + j) % 2 == 1 {
            cells.push(Cell { kind: CellKind::Tri3, nodes: vec![m[0], m[1], m[2]] });
            cells.push(Cell { kind: CellKind::Tri3, nodes: vec![m[0], m[2], m[3]] });
        } else {
            cells.push(c.clone());
        }
    }
    mesh.cells = cells;
    mesh.cell_sets.clear();
    mesh
}

/// Elastic energy per unit volume of a shell point `[σxx, σyy, σxy]` (plane stress) plus
/// `½ (σyz² + σzx²) / κG` of the given transverse shear stresses.
fn density(s: &[f64], shear: [f64; 2]) -> f64 {
    let (e, nu) = (SEC.e, SEC.nu);
    let g = e / (2.0 * (1.0 + nu));
    let (exx, eyy) = ((s[0] - nu * s[1]) / e, (s[1] - nu * s[0]) / e);
    0.5 * (s[0] * exx + s[1] * eyy + s[2] * s[2] / g)
        + 0.5 * (shear[0] * shear[0] + shear[1] * shear[1]) / (5.0 / 6.0 * g)
}

/// Elastic energy and plastic work `(h/2) w A (σy α + ½ H α²)` of both families, with the
/// reference areas.
fn stored_and_dissipated(model: &FeModel, x0: &[[f64; 3]]) -> (f64, f64) {
    let (q, t) = (model.bt4().unwrap(), model.blt3().unwrap());
    let rule = &q.settings.rule;
    let h = SEC.h;
    let plastic = |a: f64| YIELD.sigma_y * a + 0.5 * YIELD.hardening * a * a;
    let (mut w_el, mut w_p) = (0.0, 0.0);
    for (e, c) in q.conn.iter().enumerate() {
        let p = c.map(|n| x0[n as usize]);
        let (d1, d2) = ([0, 1, 2].map(|k| p[2][k] - p[0][k]), [0, 1, 2].map(|k| p[3][k] - p[1][k]));
        let area = 0.5 * (d1[0] * d2[1] - d1[1] * d2[0]).abs();
        for (k, &w) in rule.weights.iter().enumerate() {
            let s = q.stress(e, k);
            let vol = area * 0.5 * h * w;
            w_el += vol * density(&s[..3], [s[3], s[4]]);
            w_p += vol * plastic(q.plastic_strain(e, k));
        }
    }
    let kgh = 5.0 / 6.0 * SEC.e / (2.0 * (1.0 + SEC.nu)) * h;
    for (e, c) in t.conn.iter().enumerate() {
        let f = frame(&c.map(|n| x0[n as usize]));
        for (k, &w) in rule.weights.iter().enumerate() {
            let vol = f.area * 0.5 * h * w;
            w_el += vol * density(&t.stress(e, k), [0.0, 0.0]);
            w_p += vol * plastic(t.plastic_strain(e, k));
        }
        // shear resultants: Q = κGh γ at the centroid, κGh m c for the linear part
        let qs = t.shear(e);
        let m = rows(&f).linear_shear_factor;
        w_el += f.area * 0.5 * ((qs[0] * qs[0] + qs[1] * qs[1]) / kgh + qs[2] * qs[2] / (kgh * m));
    }
    (w_el, w_p)
}

#[test]
fn explicit_j2_mixed_plate_conserves_kinetic_plus_internal_energy() {
    let (l, n) = (0.2, 16);
    let mesh = checkerboard(l, n);
    let mut model = FeModel::new(&mesh, |_| Part::Bt4(SEC, Some(YIELD))).unwrap();
    model.set_rotary_inertia(RotaryInertia::Physical);
    let (nq, nt) = (model.bt4().unwrap().n_elements(), model.blt3().unwrap().n_elements());
    assert_eq!((nq, nt), (128, 256));
    let x0 = mesh.nodes.clone();
    // v_z = V sin(πx/L) sin(πy/L), and a stretching v_x, v_y
    let nd = model.n_dof();
    let mut v0 = vec![0.0; nd];
    for (i, p) in x0.iter().enumerate() {
        let (sx, sy) =
            ((std::f64::consts::PI * p[0] / l).sin(), (std::f64::consts::PI * p[1] / l).sin());
        v0[6 * i] = 8.0 * (p[0] / l - 0.5);
        v0[6 * i + 1] = -3.0 * (p[1] / l - 0.5);
        v0[6 * i + 2] = 40.0 * sx * sy;
    }
    let ke0 = kinetic_energy(&model, &v0);
    let dt = 0.9 * model.stable_dt();
    let mut cd = CentralDifference::new(&mut model, 0.0, v0, None);
    let mut f_old = cd.internal_force().to_vec();
    let (mut work, mut worst) = (0.0, 0.0f64);
    let steps = 1500;
    for s in 0..steps {
        cd.step(&mut model, dt, None);
        // trapezoidal work of the internal forces over the step's increment Δt v^{n+1/2}
        let f = cd.internal_force();
        work += cd
            .v_half
            .iter()
            .zip(f.iter().zip(&f_old))
            .map(|(v, (a, b))| dt * v * 0.5 * (a + b))
            .sum::<f64>();
        f_old.copy_from_slice(f);
        let balance = (kinetic_energy(&model, &cd.state.v) + work - ke0) / ke0;
        worst = worst.max(balance.abs());
        if s + 1 == steps || s % 300 == 0 {
            let (w_el, w_p) = stored_and_dissipated(&model, &x0);
            println!(
                "step {s}: kinetic {:.4}, internal work {:.4}, elastic {:.4}, plastic {:.4} (of initial kinetic), balance {balance:+.2e}",
                kinetic_energy(&model, &cd.state.v) / ke0, work / ke0, w_el / ke0, w_p / ke0
            );
        }
    }
    let (w_el, w_p) = stored_and_dissipated(&model, &x0);
    let remainder = (work - w_el - w_p) / ke0;
    println!("{nq} BT4 + {nt} BLT3: internal work - elastic - plastic = {remainder:+.3e} of the initial kinetic energy (hourglass energy and the area change)");
    assert!(w_p > 0.2 * ke0, "the plate must dissipate by yielding: {}", w_p / ke0);
    assert!(worst < 0.01, "kinetic + internal departs from the initial energy by {worst:e}");
    assert!(remainder.abs() < 0.01, "internal work vs elastic + plastic: {remainder:e}");
}
