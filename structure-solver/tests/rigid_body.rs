//! Rigid bodies and links in `FeModel` (DESIGN §6): a free body tumbling about a non-principal
//! axis under central differences (shape, energy, angular momentum, observed order), a rigid
//! mass on an elastic cantilever (first frequency against the closed form of the discrete
//! system, Newmark and central differences), a rigid end cap carrying an end moment (`M L / EI`
//! and the exact circle at large rotation), and the reduction of loads, velocities and the
//! tangent to the master.

use nalgebra::{Matrix2, Matrix3, Vector3};
use structure_solver::assembly::{Curve, FeModel, Part};
use structure_solver::elements::rotation::{exp, log};
use structure_solver::elements::{BeamSection, ShellSection};
use structure_solver::mesh::{generate, Cell, CellKind, Mesh};
use structure_solver::model::Model;
use structure_solver::rigid::{ExtraMass, RigidError, RigidReference};
use structure_solver::statics::{load_steps, NewtonSettings};
use structure_solver::time::{kinetic_energy, CentralDifference, Implicit, ImplicitScheme};

const PLATE: ShellSection = ShellSection { e: 1e6, nu: 0.3, rho: 1.0, h: 0.05 };

fn v3(v: &[f64], d: usize) -> Vector3<f64> {
    Vector3::new(v[d], v[d + 1], v[d + 2])
}

/// Kinetic energy and angular momentum about the origin summed over the mesh nodes from their
/// own lumped masses (`node_mass`, the model without rigid bodies) and velocities, the nodal
/// rotary inertia turning with the node.
fn node_sums(m: &FeModel, node_mass: &[f64], v: &[f64], nodes: usize) -> (f64, Vector3<f64>) {
    let (x, r) = (m.positions(), m.rotations());
    let (mut e, mut l) = (0.0, Vector3::zeros());
    for n in 0..nodes {
        let (vn, w) = (v3(v, 6 * n), v3(v, 6 * n + 3));
        let j = r[n] * Matrix3::from_diagonal(&v3(node_mass, 6 * n + 3)) * r[n].transpose();
        e += 0.5 * node_mass[6 * n] * vn.norm_squared() + 0.5 * w.dot(&(j * w));
        l += node_mass[6 * n] * x[n].cross(&vn) + j * w;
    }
    (e, l)
}

struct Tumble {
    max_shape: f64,
    max_energy: f64,
    max_momentum: f64,
    max_slave_velocity: f64,
    rotation: Matrix3<f64>,
}

/// A 2 x 1 plate made rigid (master at the mass centre or at a corner node), spinning about
/// an axis near its intermediate principal axis, integrated to `t_end` with steps of `dt`;
/// `pivot`: the corner node at the origin is pinned (the body spins about it).
fn tumble(reference: RigidReference, pivot: bool, dt: f64, t_end: f64) -> Tumble {
    let mesh = generate::rectangle(2.0, 1.0, 4, 2);
    let nn = mesh.nodes.len();
    let mut m = FeModel::new(&mesh, |_| Part::Shell(PLATE)).unwrap();
    let node_mass = m.lumped_mass().to_vec();
    if pivot {
        m.fix(&[0], [true, true, true, false, false, false]);
    }
    let all: Vec<usize> = (0..nn).collect();
    let master = m.rigid_body(&all, reference, ExtraMass::default()).unwrap();
    // velocity of the mass centre and spin, given to the master
    let centre = Vector3::new(1.0, 0.5, 0.0);
    let (vc, w) = (Vector3::new(0.3, -0.2, 0.1), Vector3::new(0.05, 1.0, 0.1));
    let vm = if pivot { Vector3::zeros() } else { vc + w.cross(&(m.positions()[master] - centre)) };
    let mut v0 = vec![0.0; m.n_dof()];
    v0[6 * master..6 * master + 3].copy_from_slice(vm.as_slice());
    v0[6 * master + 3..6 * master + 6].copy_from_slice(w.as_slice());
    let mut cd = CentralDifference::new(&mut m, 0.0, v0, None);
    let x0: Vec<Vector3<f64>> = m.positions()[..nn].to_vec();
    let (e0, l0) = node_sums(&m, &node_mass, &cd.state.v, nn);
    let ke = kinetic_energy(&m, &cd.state.v);
    assert!((ke - e0).abs() < 1e-12 * e0, "master block energy {ke} vs node sum {e0}");
    let mut out = Tumble {
        max_shape: 0.0,
        max_energy: 0.0,
        max_momentum: 0.0,
        max_slave_velocity: 0.0,
        rotation: Matrix3::identity(),
    };
    let steps = (t_end / dt).round() as usize;
    for _ in 0..steps {
        cd.step(&mut m, dt, None);
        let x = m.positions();
        for i in 0..nn {
            for j in i + 1..nn {
                let d = ((x[i] - x[j]).norm() - (x0[i] - x0[j]).norm()).abs();
                out.max_shape = out.max_shape.max(d);
            }
        }
        let (e, l) = node_sums(&m, &node_mass, &cd.state.v, nn);
        out.max_energy = out.max_energy.max((e - e0).abs() / e0);
        out.max_momentum = out.max_momentum.max((l - l0).norm() / l0.norm());
        let ke = kinetic_energy(&m, &cd.state.v);
        out.max_slave_velocity = out.max_slave_velocity.max((ke - e).abs() / e0);
    }
    out.rotation = m.rotations()[master];
    out
}

#[test]
fn free_body_tumbling_keeps_shape_energy_and_momentum() {
    let (dt, t_end) = (0.01, 40.0);
    // energy bounds: the splitting's O((ωΔt)²) error (halving Δt divides it by 3.9-4.0), larger
    // for the pinned body whose inertia about the pivot is more anisotropic
    for (name, reference, pivot, energy_bound) in [
        ("mass centre", RigidReference::MassCentre, false, 1e-7),
        ("corner node", RigidReference::Node(0), false, 1e-7),
        ("pinned corner node", RigidReference::Node(0), true, 1e-4),
    ] {
        let t = tumble(reference, pivot, dt, t_end);
        println!(
            "tumbling plate, master at the {name}, ω Δt = 0.01, {} steps: max distance change \
             {:.2e}, max |ΔE|/E {:.2e}, max |ΔL|/|L| {:.2e}, |E_nodes - E_master| / E {:.2e}",
            (t_end / dt) as usize,
            t.max_shape,
            t.max_energy,
            t.max_momentum,
            t.max_slave_velocity
        );
        assert!(t.max_shape < 1e-12, "{name}: slave distances changed by {:e}", t.max_shape);
        assert!(t.max_energy < energy_bound, "{name}: energy error {:e}", t.max_energy);
        assert!(t.max_momentum < 1e-9, "{name}: angular momentum error {:e}", t.max_momentum);
        assert!(
            t.max_slave_velocity < 1e-11,
            "{name}: slave velocities {:e}",
            t.max_slave_velocity
        );
    }
    // observed order of the orientation at t = 4 (Richardson: differences of dt, dt/2, dt/4)
    let r: Vec<Matrix3<f64>> = [0.02, 0.01, 0.005]
        .iter()
        .map(|&dt| tumble(RigidReference::MassCentre, false, dt, 4.0).rotation)
        .collect();
    let e1 = log(&(r[0] * r[1].transpose())).norm();
    let e2 = log(&(r[1] * r[2].transpose())).norm();
    let order = (e1 / e2).log2();
    println!("orientation at t = 4: differences {e1:.3e}, {e2:.3e}, observed order {order:.3}");
    assert!((order - 2.0).abs() < 0.15, "observed order {order}");
}

/// A cantilever of one elastic beam element (length `L`) ending in a rigid arm (a second
/// beam element, rigid) with an extra mass `M_e` (inertia `J_e`) at offset `e` beyond the
/// elastic tip: the master is the tip node. In `(w, ψ = dw/dx)` of the tip the stiffness is
/// `EI/L³ [[12, -6L], [-6L, 4L²]]` (exact for the cubic element) and the mass
/// `[[Σm, Σm x], [Σm x, Σ(m x² + I_y)]]` over the body's point masses at offsets `x`.
struct TipMass {
    model: FeModel,
    tip: usize,
    omega: f64,
    mode: [f64; 2],
}

/// `planar`: the tip held in the x-z plane (else free in 3D: the motion stays planar by
/// symmetry, and central differences take the free rigid-body drift of the master).
fn tip_mass(planar: bool) -> TipMass {
    let (l, arm, e_off) = (1.0, 0.1, 0.2);
    let sec = BeamSection::rectangle(2e11, 0.3, 7850.0, 0.05, 0.05);
    let (me, je) = (20.0, 0.4);
    let mesh = Mesh {
        nodes: vec![[0.0, 0.0, 0.0], [l, 0.0, 0.0], [l + arm, 0.0, 0.0]],
        cells: vec![
            Cell { kind: CellKind::Line2, nodes: vec![0, 1] },
            Cell { kind: CellKind::Line2, nodes: vec![1, 2] },
        ],
        ..Mesh::default()
    };
    let mut m = FeModel::new(&mesh, |_| Part::Beam(sec, [0.0, 1.0, 0.0])).unwrap();
    m.fix(&[0], [true; 6]);
    if planar {
        m.fix(&[1], [false, true, false, true, false, true]); // the x-z plane
    }
    let mut inertia = [[0.0; 3]; 3];
    for (k, row) in inertia.iter_mut().enumerate() {
        row[k] = je;
    }
    let extra = ExtraMass { mass: me, centre: Some([l + e_off, 0.0, 0.0]), inertia };
    let tip = m.rigid_body(&[1, 2], RigidReference::Node(1), extra).unwrap();
    // closed form
    let ei = sec.e * sec.iy;
    let k = Matrix2::new(12.0, -6.0 * l, -6.0 * l, 4.0 * l * l) * (ei / l.powi(3));
    let rho_a = sec.rho * sec.area;
    let iy_node = |len: f64| sec.rho * sec.iy * len / 2.0;
    // (mass, offset from the tip, rotary inertia about y)
    let parts = [
        (rho_a * (l + arm) / 2.0, 0.0, iy_node(l) + iy_node(arm)),
        (rho_a * arm / 2.0, arm, iy_node(arm)),
        (me, e_off, je),
    ];
    let mut mm = Matrix2::zeros();
    for (mass, x, iy) in parts {
        mm += Matrix2::new(mass, mass * x, mass * x, mass * x * x + iy);
    }
    let a = mm.try_inverse().unwrap() * k;
    let (tr, det) = (a.trace(), a.determinant());
    let w2 = 0.5 * (tr - (tr * tr - 4.0 * det).sqrt());
    let phi = Matrix2::new(a[(0, 0)] - w2, a[(0, 1)], a[(1, 0)], a[(1, 1)] - w2);
    // null vector of phi: (-phi01, phi00)
    let mode = [-phi[(0, 1)], phi[(0, 0)]];
    TipMass { model: m, tip, omega: w2.sqrt(), mode }
}

/// Period of `w(t)` from its first and last upward zero crossings.
fn period(ts: &[f64], ws: &[f64]) -> f64 {
    let mut ups = Vec::new();
    for i in 1..ws.len() {
        if ws[i - 1] < 0.0 && ws[i] >= 0.0 {
            ups.push(ts[i - 1] + (ts[i] - ts[i - 1]) * ws[i - 1] / (ws[i - 1] - ws[i]));
        }
    }
    assert!(ups.len() >= 2, "fewer than two periods");
    (ups[ups.len() - 1] - ups[0]) / (ups.len() - 1) as f64
}

#[test]
fn rigid_tip_mass_first_frequency() {
    let TipMass { omega, mode, tip, .. } = tip_mass(true);
    let t1 = 2.0 * std::f64::consts::PI / omega;
    // initial velocity in the first mode, small amplitude (θy = -dw/dx)
    let scale = 1e-3 * omega / mode[0].abs().max(mode[1].abs());
    let mut v0 = vec![0.0; 6 * 3];
    v0[6 * tip + 2] = scale * mode[0];
    v0[6 * tip + 4] = -scale * mode[1];
    for (name, steps_per_period, planar) in [
        ("Newmark", 64.0, true),
        ("midpoint", 64.0, true),
        ("central differences", 400.0, true),
        ("central differences, tip free in 3D", 400.0, false),
    ] {
        let mut m = tip_mass(planar).model;
        let dt = t1 / steps_per_period;
        let (mut ts, mut ws) = (vec![0.0], vec![0.0]);
        let n = (3.2 * steps_per_period) as usize;
        let implicit = name == "Newmark" || name == "midpoint";
        if implicit {
            let scheme =
                if name == "Newmark" { ImplicitScheme::Newmark } else { ImplicitScheme::Midpoint };
            let mut im = Implicit::new(&mut m, scheme, 0.0, v0.clone(), None);
            im.params.tol = 1e-8;
            for _ in 0..n {
                im.step(&mut m, dt, None).unwrap();
                ts.push(im.state.t);
                ws.push(-(m.positions()[tip].z));
            }
        } else {
            let mut cd = CentralDifference::new(&mut m, 0.0, v0.clone(), None);
            for _ in 0..n {
                cd.step(&mut m, dt, None);
                ts.push(cd.state.t);
                ws.push(-(m.positions()[tip].z));
            }
        }
        // the scheme's discrete frequency back to the continuous one
        let big = 2.0 * std::f64::consts::PI / period(&ts, &ws);
        let got = if implicit {
            2.0 / dt * (0.5 * big * dt).tan()
        } else {
            2.0 / dt * (0.5 * big * dt).sin()
        };
        let e = (got - omega) / omega;
        println!(
            "rigid tip mass, {name}, {steps_per_period} steps per period: ω = {got:.6} vs \
             closed form {omega:.6} ({:+.2e})",
            e
        );
        assert!(e.abs() < 1e-5, "{name}: frequency error {e:e}");
    }
}

/// The Sze strip (L = 10, b = 1, h = 0.1, E = 1.2e6, ν = 0: EI = 100) with its end nodes a
/// rigid cap whose master (a node at the mass centre of the cap) carries an end moment.
fn capped_strip() -> (FeModel, usize, Mesh) {
    let mesh = generate::rectangle(10.0, 1.0, 16, 1);
    let sec = ShellSection { e: 1.2e6, nu: 0.0, rho: 1.0, h: 0.1 };
    let mut m = FeModel::new(&mesh, |_| Part::Shell(sec)).unwrap();
    m.fix(mesh.node_set("u0").unwrap(), [true; 6]);
    let cap = mesh.node_set("u1").unwrap().to_vec();
    let master = m.rigid_body(&cap, RigidReference::MassCentre, ExtraMass::default()).unwrap();
    (m, master, mesh)
}

#[test]
fn rigid_cap_end_moment_rolls_the_strip_into_a_circle() {
    use std::f64::consts::PI;
    let (l, ei) = (10.0, 100.0);
    let s = NewtonSettings { tol: 1e-7, max_iter: 30, max_cuts: 6 };
    // linear: θ = M L / EI
    let (mut m, master, _) = capped_strip();
    let moment = 1e-3 * ei / l;
    m.point_load(master, 4, moment, Curve::Linear);
    load_steps(&mut m, &[1.0], &s, |_, _| {}).unwrap();
    let theta = log(&m.rotations()[master]).y;
    let e_lin = (theta - 1e-3) / 1e-3;
    println!("end moment, linear: θ = {theta:.6e} vs M L / EI = 1e-3 ({e_lin:+.2e})");
    assert!(e_lin.abs() < 1e-4);
    // large: M = 2π EI / L closes the circle; check at quarter turns
    let (mut m, master, _) = capped_strip();
    m.point_load(master, 4, 2.0 * PI * ei / l, Curve::Linear);
    let mut rows = Vec::new();
    let d = m.n_nodes() - 1;
    for quarter in 1..=4 {
        // each call starts from the converged state of the last
        let targets: Vec<f64> =
            (10 * quarter - 9..=10 * quarter).map(|k| k as f64 / 40.0).collect();
        load_steps(&mut m, &targets, &s, |_, _| {}).unwrap();
        let mut u = vec![[0.0; 3]; m.n_nodes()];
        m.displacement(&mut u);
        rows.push((quarter as f64 / 4.0, u[d], m.rotations()[d]));
    }
    for (t, u, r) in rows {
        let phi = 2.0 * PI * t;
        // the continuum circle of radius L / φ and the end rotation φ about y
        let rho = l / phi;
        let exact = [rho * phi.sin() - l, 0.0, -rho * (1.0 - phi.cos())];
        let err = ((u[0] - exact[0]).powi(2) + (u[2] - exact[2]).powi(2)).sqrt() / l;
        let rot = (r - exp(&Vector3::new(0.0, phi, 0.0))).norm();
        println!(
            "end moment, φ = {:.2}π: tip (u, w) = ({:.5}, {:.5}) vs circle ({:.5}, {:.5}), error / L \
             {err:.2e}; |R_end - R_y(φ)| = {rot:.2e}",
            phi / PI,
            u[0],
            u[2],
            exact[0],
            exact[2],
        );
        // nodes on 16 chords of the circle would be 1.1e-3 L off it at most (φ = 3π/2); the
        // corotated shells put the tip on the circle itself to about 1e-6 L
        assert!(err < 2e-3, "tip off the circle at φ = {phi}");
        assert!(rot < 1e-6, "end rotation off M L / EI at φ = {phi}");
        assert!(u[1].abs() < 1e-9);
    }
}

#[test]
fn loads_on_slaves_reduce_to_force_and_moment() {
    let mesh = generate::rectangle(2.0, 1.0, 2, 1);
    let mut m = FeModel::new(&mesh, |_| Part::Shell(PLATE)).unwrap();
    let p = [0.5, 0.25, 0.3];
    let master =
        m.rigid_body(&[1, 2, 4, 5], RigidReference::Point(p), ExtraMass::default()).unwrap();
    assert_eq!(master, mesh.nodes.len());
    let loads = [
        (1, [1.0, 2.0, 0.0, 0.0, 0.0, 0.5]),
        (4, [0.0, -3.0, 4.0, 1.0, 0.0, 0.0]),
        (5, [2.0, 0.0, -1.0, 0.0, 0.0, 0.0]),
    ];
    for (n, f) in loads {
        for (c, v) in f.iter().enumerate() {
            m.point_load(n, c, *v, Curve::Constant);
        }
    }
    // turn the body by a finite rotation: the arms turn with it
    let turn = Vector3::new(0.3, -0.2, 0.5);
    let mut du = vec![0.0; m.n_dof()];
    du[6 * master..6 * master + 3].copy_from_slice(&[0.1, 0.2, -0.1]);
    du[6 * master + 3..6 * master + 6].copy_from_slice(turn.as_slice());
    m.apply_increment(&du);
    let x = m.positions().to_vec();
    let (mut f_sum, mut m_sum) = (Vector3::zeros(), Vector3::zeros());
    for (n, f) in loads {
        let force = Vector3::new(f[0], f[1], f[2]);
        f_sum += force;
        m_sum += Vector3::new(f[3], f[4], f[5]) + (x[n] - x[master]).cross(&force);
    }
    let mut f = vec![0.0; m.n_dof()];
    m.external_force(0.0, &mut f);
    let (gf, gm) = (v3(&f, 6 * master), v3(&f, 6 * master + 3));
    println!("reduced load: F = {gf:?} (sum {f_sum:?}), M = {gm:?} (Σ M + r × F = {m_sum:?})");
    assert!((gf - f_sum).norm() < 1e-14 && (gm - m_sum).norm() < 1e-13);
    for n in [1, 2, 4, 5] {
        assert!(f[6 * n..6 * n + 6].iter().all(|&v| v == 0.0), "slave {n} keeps a load");
        assert!(m.constrained()[6 * n..6 * n + 6].iter().all(|&c| c));
    }
    // slaves moved rigidly with the master, and velocities follow v_m + ω × r
    let x0 = m.initial_positions();
    let rm = m.rotations()[master];
    for n in [1, 2, 4, 5] {
        let want = x[master] + rm * (x0[n] - Vector3::from(p));
        assert!((x[n] - want).norm() < 1e-14);
        assert!((m.rotations()[n] - rm).norm() < 1e-14);
    }
    let mut v = vec![0.0; m.n_dof()];
    let mut a = vec![0.0; m.n_dof()];
    v[6 * master..6 * master + 6].copy_from_slice(&[1.0, 0.0, -1.0, 0.2, 0.4, -0.3]);
    a[6 * master..6 * master + 6].copy_from_slice(&[0.0, 1.0, 0.0, -0.1, 0.0, 0.2]);
    m.dependent_motion(&mut v, &mut a);
    let (w, al) = (Vector3::new(0.2, 0.4, -0.3), Vector3::new(-0.1, 0.0, 0.2));
    let r = x[4] - x[master];
    let vs = Vector3::new(1.0, 0.0, -1.0) + w.cross(&r);
    let acc = Vector3::new(0.0, 1.0, 0.0) + al.cross(&r) + w.cross(&w.cross(&r));
    assert!((v3(&v, 24) - vs).norm() < 1e-14 && (v3(&a, 24) - acc).norm() < 1e-14);
    // gravity on the slaves and on an extra mass off the master
    let mut m = FeModel::new(&mesh, |_| Part::Shell(PLATE)).unwrap();
    let node_mass = m.lumped_mass().to_vec();
    let g = Vector3::new(0.0, -3.0, -9.81);
    m.gravity([g.x, g.y, g.z], Curve::Constant);
    let extra = ExtraMass { mass: 2.0, centre: Some([1.0, 1.5, -0.5]), ..ExtraMass::default() };
    let master = m.rigid_body(&[1, 2, 4, 5], RigidReference::Node(4), extra).unwrap();
    let x = m.positions().to_vec();
    let (mut f_sum, mut m_sum) = (Vector3::zeros(), Vector3::zeros());
    for n in [1, 2, 4, 5] {
        f_sum += node_mass[6 * n] * g;
        m_sum += (x[n] - x[master]).cross(&(node_mass[6 * n] * g));
    }
    f_sum += 2.0 * g;
    m_sum += (Vector3::new(1.0, 1.5, -0.5) - x[master]).cross(&(2.0 * g));
    let mut f = vec![0.0; m.n_dof()];
    m.external_force(0.0, &mut f);
    let (gf, gm) = (v3(&f, 6 * master), v3(&f, 6 * master + 3));
    println!("reduced weight: F = {gf:?} (want {f_sum:?}), M = {gm:?} (want {m_sum:?})");
    assert!((gf - f_sum).norm() < 1e-13 && (gm - m_sum).norm() < 1e-13);
    let body = &m.rigid_bodies()[0];
    let total: f64 = [1, 2, 4, 5].iter().map(|&n| node_mass[6 * n]).sum::<f64>() + 2.0;
    assert!((body.mass() - total).abs() < 1e-14);
    // errors
    let mut m = FeModel::new(&mesh, |_| Part::Shell(PLATE)).unwrap();
    m.fix(&[0], [true; 6]);
    let none = ExtraMass::default();
    assert_eq!(m.rigid_body(&[], RigidReference::MassCentre, none), Err(RigidError::Empty));
    assert_eq!(
        m.rigid_body(&[0, 1], RigidReference::Node(1), none),
        Err(RigidError::ConstrainedSlave { node: 0, dof: 0 })
    );
    assert_eq!(
        m.rigid_body(&[1, 99], RigidReference::Node(1), none),
        Err(RigidError::NodeRange { node: 99, n: 6 })
    );
    let bad = ExtraMass { mass: -1.0, ..none };
    assert_eq!(m.rigid_body(&[1, 2], RigidReference::Node(1), bad), Err(RigidError::BadExtra));
    m.rigid_body(&[1, 2], RigidReference::Node(1), none).unwrap();
    assert_eq!(
        m.rigid_body(&[3, 2], RigidReference::Node(3), none),
        Err(RigidError::TwoBodies { node: 2, body: 0 })
    );
    // a rigid link of two nodes without rotary inertia has none about its axis
    let tets = Mesh {
        nodes: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        cells: vec![Cell { kind: CellKind::Tet4, nodes: vec![0, 1, 2, 3] }],
        ..Mesh::default()
    };
    let steel =
        structure_solver::material::Material::Elastic(structure_solver::material::Elastic {
            e: 2e11,
            nu: 0.3,
            rho: 7850.0,
        });
    let mut t = FeModel::new(&tets, |_| Part::Solid(steel)).unwrap();
    let err = t.rigid_body(&[0, 1], RigidReference::MassCentre, none).unwrap_err();
    println!("rigid link of two tet nodes: {err}");
    assert!(matches!(err, RigidError::SingularInertia { .. }));
}

/// The reduced tangent `Tᵀ K T` plus the geometric term of the rotating arms against central
/// differences of the reduced residual, in a bent state with the end moment on.
#[test]
fn reduced_tangent_matches_finite_differences() {
    let (mut m, master, _) = capped_strip();
    m.point_load(master, 4, 30.0, Curve::Linear);
    m.point_load(master, 2, 2.0, Curve::Linear);
    let s = NewtonSettings { tol: 1e-9, max_iter: 30, max_cuts: 6 };
    load_steps(&mut m, &[0.5, 1.0], &s, |_, _| {}).unwrap();
    // move off equilibrium so that the slaves carry net forces
    let n = m.n_dof();
    let mut du = vec![0.0; n];
    du[6 * master + 2] = 0.05;
    du[6 * master + 4] = 0.03;
    m.apply_increment(&du);
    let mut trip = structure_solver::model::Tangent::default();
    m.tangent(1.0, &mut trip);
    let mut k = vec![0.0; n * n];
    for e in trip.triplets() {
        k[e.row * n + e.col] += e.val;
    }
    let g = |m: &mut FeModel| {
        let (mut fi, mut fe) = (vec![0.0; n], vec![0.0; n]);
        m.internal_force(&mut fi);
        m.external_force(1.0, &mut fe);
        fi.iter().zip(&fe).map(|(a, b)| a - b).collect::<Vec<f64>>()
    };
    m.commit();
    let free: Vec<usize> = (0..n).filter(|&d| !m.constrained()[d]).collect();
    let (h, mut worst, mut scale) = (1e-6, 0.0f64, 0.0f64);
    for &j in &free {
        let mut du = vec![0.0; n];
        du[j] = h;
        m.apply_increment(&du);
        let gp = g(&mut m);
        m.revert();
        du[j] = -h;
        m.apply_increment(&du);
        let gm = g(&mut m);
        m.revert();
        for &i in &free {
            let fd = (gp[i] - gm[i]) / (2.0 * h);
            worst = worst.max((fd - k[i * n + j]).abs());
            scale = scale.max(k[i * n + j].abs());
        }
    }
    println!(
        "reduced tangent vs finite differences: max error / max entry = {:.2e}",
        worst / scale
    );
    assert!(worst / scale < 1e-6);
}
