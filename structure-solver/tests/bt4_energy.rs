//! Energy balance of an explicit J2 plate of BT4 shells, free, given an initial velocity
//! (transverse and in-plane): at every step the kinetic energy plus the work of the internal
//! forces equals the initial kinetic energy, and the work of the internal forces is the elastic
//! energy of the stresses plus the plastic work `∫ κ dα` of the points plus the hourglass
//! energy.

use structure_solver::elements::bt4::{Bt4, Bt4Settings};
use structure_solver::elements::RotaryInertia;
use structure_solver::material::{Elastic, J2};
use structure_solver::mesh::generate;

const STEEL: J2 =
    J2 { elastic: Elastic { e: 200e9, nu: 0.3, rho: 7800.0 }, sigma_y: 250e6, h: 1e9 };

/// Elastic energy of the stresses and plastic work `A (h/2) w (σy α + ½ H α²)` of the points.
fn stored_and_dissipated(bt4: &Bt4, area: &[f64]) -> (f64, f64) {
    let el = STEEL.elastic;
    let (e, nu, g) = (el.e, el.nu, el.shear_modulus());
    let gk = 5.0 / 6.0 * g;
    let rule = &bt4.settings.rule;
    let (mut w_el, mut w_p) = (0.0, 0.0);
    for (k, &a) in area.iter().enumerate() {
        let h = bt4.thickness[k];
        for (p, &w) in rule.weights.iter().enumerate() {
            let s = bt4.stress(k, p);
            let (exx, eyy) = ((s[0] - nu * s[1]) / e, (s[1] - nu * s[0]) / e);
            let u = 0.5 * (s[0] * exx + s[1] * eyy + s[2] * s[2] / g)
                + 0.5 * (s[3] * s[3] + s[4] * s[4]) / gk;
            let alpha = bt4.plastic_strain(k, p);
            let vol = a * 0.5 * h * w;
            w_el += vol * u;
            w_p += vol * (STEEL.sigma_y * alpha + 0.5 * STEEL.h * alpha * alpha);
        }
    }
    (w_el, w_p)
}

#[test]
fn explicit_j2_plate_conserves_kinetic_plus_internal_energy() {
    let (l, n, h) = (0.2, 16, 0.002);
    let mesh = generate::rectangle(l, l, n, n);
    let conn: Vec<[u32; 4]> =
        mesh.cells.iter().map(|c| [0, 1, 2, 3].map(|i| c.nodes[i] as u32)).collect();
    let ne = conn.len();
    let settings = Bt4Settings { rotary: RotaryInertia::Physical, ..Bt4Settings::default() };
    let mut bt4 = Bt4::new(conn, vec![h; ne], STEEL, settings);
    let x0 = mesh.nodes.clone();
    let nn = x0.len();
    let mut mass = vec![0.0; 6 * nn];
    bt4.lumped_mass(&x0, &mut mass);
    // v_z = V sin(πx/L) sin(πy/L), and a stretching v_x, v_y.
    let mut v = vec![0.0; 6 * nn];
    for (i, p) in x0.iter().enumerate() {
        let (sx, sy) =
            ((std::f64::consts::PI * p[0] / l).sin(), (std::f64::consts::PI * p[1] / l).sin());
        v[6 * i] = 8.0 * (p[0] / l - 0.5);
        v[6 * i + 1] = -3.0 * (p[1] / l - 0.5);
        v[6 * i + 2] = 40.0 * sx * sy;
    }
    let kinetic = |v: &[f64]| 0.5 * v.iter().zip(&mass).map(|(v, m)| m * v * v).sum::<f64>();
    let ke0 = kinetic(&v);
    let dt = 0.9 * bt4.stable_dt(&x0);
    let area0 = (l / n as f64).powi(2);
    let mut x = x0.clone();
    let (mut f_old, mut f) = (vec![0.0; 6 * nn], vec![0.0; 6 * nn]);
    let mut du = vec![0.0; 6 * nn];
    // a_0 = 0 (no stress): v_{1/2} = v_0.
    let mut work = 0.0;
    let mut worst: f64 = 0.0;
    let steps = 1500;
    for s in 0..steps {
        for i in 0..6 * nn {
            du[i] = dt * v[i];
        }
        for (i, p) in x.iter_mut().enumerate() {
            for k in 0..3 {
                p[k] += du[6 * i + k];
            }
        }
        f.fill(0.0);
        bt4.internal_force(&x, &du, &mut f);
        bt4.commit();
        // Trapezoidal work of the internal forces over the step.
        work +=
            du.iter().zip(f.iter().zip(&f_old)).map(|(d, (a, b))| d * 0.5 * (a + b)).sum::<f64>();
        // v_{n+1} = v_{n+1/2} + dt/2 a_{n+1}, then the next half step.
        let v_full: Vec<f64> = (0..6 * nn).map(|i| v[i] - 0.5 * dt * f[i] / mass[i]).collect();
        for i in 0..6 * nn {
            v[i] -= dt * f[i] / mass[i];
        }
        let balance = (kinetic(&v_full) + work - ke0) / ke0;
        worst = worst.max(balance.abs());
        if s + 1 == steps || s % 300 == 0 {
            let (w_el, w_p) = stored_and_dissipated(&bt4, &vec![area0; ne]);
            println!(
                "step {s}: kinetic {:.4}, internal work {:.4}, elastic {:.4}, plastic {:.4} (of initial kinetic), balance {balance:+.2e}",
                kinetic(&v_full) / ke0, work / ke0, w_el / ke0, w_p / ke0
            );
        }
        std::mem::swap(&mut f, &mut f_old);
    }
    let (w_el, w_p) = stored_and_dissipated(&bt4, &vec![area0; ne]);
    let remainder = (work - w_el - w_p) / ke0;
    println!("internal work - elastic - plastic = {remainder:+.3e} of the initial kinetic energy (hourglass energy and the area change)");
    assert!(w_p > 0.2 * ke0, "the plate must dissipate by yielding: {}", w_p / ke0);
    assert!(worst < 0.01, "kinetic + internal departs from the initial energy by {worst:e}");
    assert!(remainder.abs() < 0.01, "internal work vs elastic + plastic: {remainder:e}");
}
