//! BT4 shells as an explicit-only part of `FeModel`: a cantilever plate with a J2 material and
//! a rotation-driven tip follows exactly the trajectory of the same BT4 shells in the
//! stand-alone `ShellModel` (forces, mass, critical step and plastic state), and static and
//! implicit solves refuse the model with a clear error.

use structure_solver::assembly::{Curve, FeModel, Part};
use structure_solver::elements::bt4::{Bt4, Bt4Settings};
use structure_solver::elements::{RotaryInertia, ShellSection, ShellYield};
use structure_solver::explicit_shell::ShellModel;
use structure_solver::material::{Elastic, ThicknessRule, J2};
use structure_solver::mesh::generate;
use structure_solver::model::Model;
use structure_solver::statics::{load_steps, NewtonSettings, StaticsError};
use structure_solver::time::{CentralDifference, Implicit, ImplicitError, ImplicitScheme};

const SEC: ShellSection = ShellSection { e: 200e9, nu: 0.3, rho: 7800.0, h: 0.002 };
const YIELD: ShellYield = ShellYield { sigma_y: 100e6, hardening: 1e9, points: 5 };

#[test]
fn bt4_part_follows_the_stand_alone_bt4_model() {
    let mesh = generate::rectangle(0.2, 0.05, 8, 2);
    let mut fe = FeModel::new(&mesh, |_| Part::Bt4(SEC, Some(YIELD))).unwrap();
    fe.set_rotary_inertia(RotaryInertia::Scaled);
    let conn: Vec<[u32; 4]> =
        mesh.cells.iter().map(|c| [0, 1, 2, 3].map(|i| c.nodes[i] as u32)).collect();
    let j2 = J2 {
        elastic: Elastic { e: SEC.e, nu: SEC.nu, rho: SEC.rho },
        sigma_y: YIELD.sigma_y,
        h: YIELD.hardening,
    };
    let settings = Bt4Settings {
        rule: ThicknessRule::gauss(5),
        rotary: RotaryInertia::Scaled,
        ..Bt4Settings::default()
    };
    let ne = conn.len();
    let mut sm = ShellModel::new(mesh.nodes.clone(), Bt4::new(conn, vec![SEC.h; ne], j2, settings));
    // clamped at x = 0; the tip is pushed up at 20 m/s (enough to yield)
    let root = mesh.node_set("u0").unwrap();
    let tip = mesh.node_set("u1").unwrap();
    fe.fix(root, [true; 6]);
    fe.prescribe(tip, 2, 20.0, Curve::Linear);
    for &n in root {
        for c in 0..6 {
            sm.constrain(6 * n + c);
        }
    }
    for &n in tip {
        sm.constrain(6 * n + 2);
        sm.prescribed_velocity[6 * n + 2] = 20.0;
    }
    assert_eq!(fe.lumped_mass(), sm.lumped_mass(), "lumped mass");
    assert_eq!(fe.stable_dt(), sm.stable_dt(), "element critical step");
    let dt = 0.5 * fe.stable_dt();
    let n = fe.n_dof();
    let mut a = CentralDifference::new(&mut fe, 0.0, vec![0.0; n], None);
    let mut b = CentralDifference::new(&mut sm, 0.0, vec![0.0; n], None);
    for _ in 0..400 {
        a.step(&mut fe, dt, None);
        b.step(&mut sm, dt, None);
    }
    let (mut ua, mut ub) = (vec![[0.0; 3]; mesh.nodes.len()], vec![[0.0; 3]; mesh.nodes.len()]);
    fe.displacement(&mut ua);
    sm.displacement(&mut ub);
    let scale = ub.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    let diff =
        ua.iter().flatten().zip(ub.iter().flatten()).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    let alpha = (0..ne)
        .flat_map(|e| (0..5).map(move |p| (e, p)))
        .map(|(e, p)| sm.bt4.plastic_strain(e, p))
        .fold(0.0f64, f64::max);
    println!("max displacement {scale:.4e}, FeModel - ShellModel {diff:.3e}, max plastic strain {alpha:.3e}");
    assert!(scale > 1e-3, "the tip must move: {scale}");
    assert!(alpha > 0.0, "the plate must yield");
    assert!(diff <= 1e-9 * scale, "FeModel with BT4 departs from ShellModel by {diff:e}");
}

#[test]
fn static_and_implicit_solves_refuse_bt4() {
    let mesh = generate::rectangle(0.2, 0.05, 2, 1);
    let mut fe = FeModel::new(&mesh, |_| Part::Bt4(SEC, None)).unwrap();
    fe.fix(mesh.node_set("u0").unwrap(), [true; 6]);
    assert!(!fe.has_tangent());
    let err = load_steps(&mut fe, &[1.0], &NewtonSettings::default(), |_, _| {}).unwrap_err();
    assert!(matches!(err, StaticsError::NoTangent), "{err}");
    assert!(err.to_string().contains("BT4"), "{err}");
    let n = fe.n_dof();
    let mut im = Implicit::new(&mut fe, ImplicitScheme::Midpoint, 0.0, vec![0.0; n], None);
    let err = im.step(&mut fe, 1e-6, None).unwrap_err();
    assert!(matches!(err, ImplicitError::NoTangent), "{err}");
    // triangles cannot be BT4
    let err = FeModel::new(&mesh.to_triangles(), |_| Part::Bt4(SEC, None)).unwrap_err();
    assert!(err.to_string().contains("BT4"), "{err}");
}
