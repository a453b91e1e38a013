//! BT4 shells as an explicit-only part of `FeModel`: a cantilever plate with a J2 material and
//! a velocity-driven tip follows exactly the trajectory of the same `elements::bt4::Bt4`
//! shells driven directly by a minimal model (forces, mass, critical step and plastic state),
//! and static and implicit solves refuse the model with a clear error.

use structure_solver::assembly::{Curve, FeModel, Part};
use structure_solver::elements::bt4::{Bt4, Bt4Settings};
use structure_solver::elements::{RotaryInertia, ShellSection, ShellYield};
use structure_solver::material::{Elastic, ThicknessRule, J2};
use structure_solver::mesh::generate;
use structure_solver::model::Model;
use structure_solver::model::Tangent;
use structure_solver::statics::{load_steps, NewtonSettings, StaticsError};
use structure_solver::time::{CentralDifference, Implicit, ImplicitError, ImplicitScheme};

const SEC: ShellSection = ShellSection { e: 200e9, nu: 0.3, rho: 7800.0, h: 0.002 };
const YIELD: ShellYield = ShellYield { sigma_y: 100e6, hardening: 1e9, points: 5 };

/// `Bt4` shells alone: fixed dofs and dofs at a prescribed constant velocity, no load; the
/// element reads the end positions and the increment since the last commit.
struct Bt4Only {
    x0: Vec<[f64; 3]>,
    x: Vec<[f64; 3]>,
    x_committed: Vec<[f64; 3]>,
    pending: Vec<f64>,
    bt4: Bt4,
    mass: Vec<f64>,
    constrained: Vec<bool>,
    velocity: Vec<f64>,
}

impl Bt4Only {
    fn new(x0: Vec<[f64; 3]>, bt4: Bt4) -> Self {
        let n = x0.len();
        let mut mass = vec![0.0; 6 * n];
        bt4.lumped_mass(&x0, &mut mass);
        Bt4Only {
            x: x0.clone(),
            x_committed: x0.clone(),
            x0,
            pending: vec![0.0; 6 * n],
            bt4,
            mass,
            constrained: vec![false; 6 * n],
            velocity: vec![0.0; 6 * n],
        }
    }
}

impl Model for Bt4Only {
    fn n_nodes(&self) -> usize {
        self.x0.len()
    }
    fn lumped_mass(&self) -> &[f64] {
        &self.mass
    }
    fn constrained(&self) -> &[bool] {
        &self.constrained
    }
    fn prescribed(&self, t: f64, out: &mut [f64]) {
        for ((o, v), &c) in out.iter_mut().zip(&self.velocity).zip(&self.constrained) {
            if c {
                *o = v * t;
            }
        }
    }
    fn apply_increment(&mut self, du: &[f64]) {
        for (i, x) in self.x.iter_mut().enumerate() {
            for k in 0..3 {
                x[k] += du[6 * i + k];
            }
        }
        self.pending.iter_mut().zip(du).for_each(|(p, d)| *p += d);
    }
    fn internal_force(&mut self, f: &mut [f64]) {
        f.fill(0.0);
        self.bt4.internal_force(&self.x, &self.pending, f);
    }
    fn external_force(&mut self, _t: f64, f: &mut [f64]) {
        f.fill(0.0);
    }
    fn tangent(&mut self, _t: f64, out: &mut Tangent) {
        out.clear();
    }
    fn has_tangent(&self) -> bool {
        false
    }
    fn commit(&mut self) {
        self.bt4.commit();
        self.x_committed.clone_from(&self.x);
        self.pending.fill(0.0);
    }
    fn revert(&mut self) {
        self.x.clone_from(&self.x_committed);
        self.pending.fill(0.0);
    }
    fn stable_dt(&self) -> f64 {
        self.bt4.stable_dt(&self.x)
    }
    fn displacement(&self, out: &mut [[f64; 3]]) {
        for ((o, x), x0) in out.iter_mut().zip(&self.x).zip(&self.x0) {
            *o = [x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]];
        }
    }
}

#[test]
fn bt4_part_follows_the_bt4_shells_driven_directly() {
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
    let mut sm = Bt4Only::new(mesh.nodes.clone(), Bt4::new(conn, vec![SEC.h; ne], j2, settings));
    // clamped at x = 0; the tip is pushed up at 20 m/s (enough to yield)
    let root = mesh.node_set("u0").unwrap();
    let tip = mesh.node_set("u1").unwrap();
    fe.fix(root, [true; 6]);
    fe.prescribe(tip, 2, 20.0, Curve::Linear);
    for &n in root {
        sm.constrained[6 * n..6 * n + 6].fill(true);
    }
    for &n in tip {
        sm.constrained[6 * n + 2] = true;
        sm.velocity[6 * n + 2] = 20.0;
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
    println!("max displacement {scale:.4e}, FeModel - Bt4 alone {diff:.3e}, max plastic strain {alpha:.3e}");
    assert!(scale > 1e-3, "the tip must move: {scale}");
    assert!(alpha > 0.0, "the plate must yield");
    assert!(diff <= 1e-9 * scale, "FeModel with BT4 departs from the BT4 shells alone by {diff:e}");
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
    // lines cannot be explicit shells
    let line = generate::line([0.0; 3], [1.0, 0.0, 0.0], 2);
    let err = FeModel::new(&line, |_| Part::Bt4(SEC, None)).unwrap_err();
    assert!(err.to_string().contains("explicit shell"), "{err}");
}
