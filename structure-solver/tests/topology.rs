//! A model whose topology changes at run time (`assembly::topology*`): elements duplicated
//! with their full state onto copied nodes, as the phantom-node formulation does (thesis §3.5,
//! Fig. 3.2), on a clamped J2 plate of BT4 shells and MITC4 J2 shells side by side, given a
//! transverse velocity that bends it past yield.
//!
//! - Duplicating at t = 0 gives, bitwise, the run of the model built from the start with that
//!   topology (phantom copies sharing real nodes).
//! - Copies onto new nodes only (no interaction) mid-run leave the motion of the original
//!   nodes bitwise identical to the run without them, start with their source's full state
//!   (stress, plastic strain, hourglass stresses), and move as a free body (momentum kept).
//! - A run that duplicates mid-run, checkpoints after the change and is restarted from the
//!   model its mesh builds ends bitwise where the uninterrupted run ends.
//! - Implicit Newmark steps follow a mid-run copy on new nodes (new free-dof numbering); the
//!   plate moves as without it to Newton's tolerance.

use structure_solver::assembly::{FeModel, NewNode, Part, Store, TopologyError};
use structure_solver::elements::{RotaryInertia, ShellSection, ShellYield};
use structure_solver::mesh::{generate, Cell, CellKind, Mesh};
use structure_solver::model::Model;
use structure_solver::restart::{load_dynamics, restore_state, save_dynamics, save_state};
use structure_solver::time::{CentralDifference, Dynamics, ResizeError};

use interface_protocol::io::checkpoint::Checkpoint;
use nalgebra::Matrix3;

const SEC: ShellSection = ShellSection { e: 200e9, nu: 0.3, rho: 7800.0, h: 0.002 };
const YIELD: ShellYield = ShellYield { sigma_y: 100e6, hardening: 1e9, points: 5 };
const LENGTH: f64 = 0.2;

/// Cells of even index are BT4 shells, odd ones MITC4 J2 shells.
fn part(c: usize) -> Part {
    if c.is_multiple_of(2) {
        Part::Bt4(SEC, Some(YIELD))
    } else {
        Part::ShellJ2(SEC, YIELD)
    }
}

fn mesh() -> Mesh {
    generate::rectangle(LENGTH, 0.05, 8, 2)
}

/// The plate of `mesh` clamped at `x = 0`, cells beyond the first 16 of their source's part.
fn plate(mesh: &Mesh, source: &[usize]) -> FeModel {
    let mut m = FeModel::new(mesh, |c| part(if c < 16 { c } else { source[c - 16] })).unwrap();
    m.set_rotary_inertia(RotaryInertia::Scaled);
    m.fix(mesh.node_set("u0").unwrap(), [true; 6]);
    m
}

/// Transverse velocity `80 (x/L)²` m/s at every node, from the reference positions.
fn bending_velocity(m: &FeModel) -> Vec<f64> {
    let mut v = vec![0.0; m.n_dof()];
    for (n, p) in m.initial_positions().iter().enumerate() {
        v[6 * n + 2] = 80.0 * (p.x / LENGTH).powi(2);
    }
    v
}

fn bits(v: impl IntoIterator<Item = f64>) -> Vec<u64> {
    v.into_iter().map(f64::to_bits).collect()
}

/// Positions, rotations, committed spins, element states and BT4 state, bitwise.
fn model_bits(m: &FeModel) -> Vec<u64> {
    let mut all = bits(m.positions().iter().flat_map(|p| [p.x, p.y, p.z]));
    all.extend(bits(m.rotations().iter().flat_map(|r| r.as_slice().to_vec())));
    all.extend(bits(m.committed_spins().iter().flat_map(|p| [p.x, p.y, p.z])));
    all.extend(bits((0..m.elements().len()).flat_map(|e| m.element_state(e).to_vec())));
    let s = m.bt4().unwrap().state();
    all.extend(bits(s.stress.iter().chain(&s.alpha).chain(&s.hourglass).copied()));
    all.extend(bits(m.lumped_mass().iter().copied()));
    all
}

fn dynamics_bits(d: &Dynamics) -> Vec<u64> {
    bits(d.v.iter().chain(&d.a).copied().chain([d.t]))
}

/// The cells copied: an MITC4 shell (element 1) and a BT4 shell (shell 5) near the root.
const COPIED: [usize; 2] = [3, 10];

#[test]
fn duplicating_at_the_start_equals_the_model_built_with_that_topology() {
    let base = mesh();
    // phantom copies: the copy of cell 3 on two new nodes and two of its own, likewise cell 10
    let mut a = plate(&base, &COPIED);
    let new = a.duplicate_nodes(&[(3, 100), (4, 101), (11, 102), (12, 103)]).unwrap();
    assert_eq!(new, 27..31);
    let e3 = a.duplicate_element(3, 500, &[100, 101, 13, 12]).unwrap();
    let e10 = a.duplicate_element(10, 501, &[102, 103, 21, 20]).unwrap();
    assert_eq!((e3, e10), (16, 17));
    assert_eq!(a.topology_version(), 4, "three changes after the built version 1");
    assert_eq!(a.topology().store(16), Some(Store::Element(8)));
    assert_eq!(a.topology().store(17), Some(Store::Bt4(8)));
    assert_eq!(a.topology().nodes().slot(103), Some(30));
    assert_eq!(a.topology().elements().id(17), Some(501));

    let mut union = base.clone();
    for n in [3, 4, 11, 12] {
        union.nodes.push(base.nodes[n]);
    }
    union.cells.push(Cell { kind: CellKind::Quad4, nodes: vec![27, 28, 13, 12] });
    union.cells.push(Cell { kind: CellKind::Quad4, nodes: vec![29, 30, 21, 20] });
    let mut b = plate(&union, &COPIED);
    assert_eq!(a.constrained(), b.constrained(), "free dofs");
    assert_eq!(bits(a.lumped_mass().iter().copied()), bits(b.lumped_mass().iter().copied()));
    assert_eq!(a.stable_dt().to_bits(), b.stable_dt().to_bits(), "element step bound");

    let dt = 0.5 * b.stable_dt();
    let (va, vb) = (bending_velocity(&a), bending_velocity(&b));
    let mut ia = CentralDifference::new(&mut a, 0.0, va, None);
    let mut ib = CentralDifference::new(&mut b, 0.0, vb, None);
    for _ in 0..300 {
        ia.step(&mut a, dt, None);
        ib.step(&mut b, dt, None);
    }
    let shells = a.bt4().unwrap();
    assert!((0..5).any(|p| shells.plastic_strain(0, p) > 0.0), "the BT4 shells yield");
    assert!(a.element_state(0).iter().any(|&s| s != 0.0), "the MITC4 shells yield");
    assert!(shells.stress(8, 0)[0] != 0.0, "the BT4 copy is strained");
    assert!(model_bits(&a) == model_bits(&b), "model state differs from the built union");
    assert!(dynamics_bits(&ia.state) == dynamics_bits(&ib.state), "motion differs");
}

/// Runs the plate `steps` steps at `dt` from rest with the bending velocity.
fn start(steps: usize, dt: f64) -> (FeModel, CentralDifference) {
    let mut m = plate(&mesh(), &[]);
    let v0 = bending_velocity(&m);
    let mut cd = CentralDifference::new(&mut m, 0.0, v0, None);
    for _ in 0..steps {
        cd.step(&mut m, dt, None);
    }
    (m, cd)
}

/// Copies cells 3 and 10 onto copies of their nodes (no node shared with the plate); the
/// new nodes start with their sources' velocity and the acceleration of the changed model.
/// Returns the new node slots' sources.
fn copy_off(m: &mut FeModel, cd: &mut CentralDifference) -> Vec<usize> {
    let sources = vec![3, 4, 13, 12, 11, 21, 20];
    let pairs: Vec<(u64, u64)> = sources.iter().map(|&s| (s as u64, 1000 + s as u64)).collect();
    m.duplicate_nodes(&pairs).unwrap();
    m.duplicate_element(3, 500, &[1003, 1004, 1013, 1012]).unwrap();
    m.duplicate_element(10, 501, &[1012, 1011, 1021, 1020]).unwrap_err();
    // the copy of cell 10 keeps its node order: (11, 12, 21, 20)
    m.duplicate_element(10, 501, &[1011, 1012, 1021, 1020]).unwrap();
    cd.state.copy_nodes(&sources).unwrap();
    cd.follow_topology(m, None).unwrap();
    sources
}

#[test]
fn copies_on_new_nodes_carry_their_state_and_leave_the_plate_unchanged() {
    let dt = 0.5 * plate(&mesh(), &[]).stable_dt();
    let (mut a, mut ia) = start(150, dt);
    let (mut c, mut ic) = start(150, dt);
    let sources = copy_off(&mut c, &mut ic);

    // the full state of the sources
    let b = c.bt4().unwrap();
    let np = 5;
    assert!((0..np).any(|p| b.plastic_strain(5, p) > 0.0), "cell 10 (BT4 shell 5) has yielded");
    for p in 0..np {
        assert_eq!(b.stress(8, p).map(f64::to_bits), b.stress(5, p).map(f64::to_bits));
        assert_eq!(b.plastic_strain(8, p).to_bits(), b.plastic_strain(5, p).to_bits());
    }
    assert_eq!(b.hourglass(8).map(f64::to_bits), b.hourglass(5).map(f64::to_bits));
    assert!(b.hourglass(5).iter().any(|&h| h != 0.0), "hourglass stresses to carry");
    let mitc = c.element_state(1);
    assert!(mitc.iter().any(|&s| s != 0.0), "cell 3 (MITC4 element 1) has yielded");
    assert_eq!(bits(c.element_state(8).iter().copied()), bits(mitc.iter().copied()));
    let (x, r) = (c.positions(), c.rotations());
    for (k, &s) in sources.iter().enumerate() {
        assert_eq!(x[27 + k], x[s]);
        assert_eq!(r[27 + k], r[s]);
    }

    let momentum = |m: &FeModel, v: &[f64]| {
        let mass = m.lumped_mass();
        std::array::from_fn::<f64, 3, _>(|k| (27..34).map(|n| mass[6 * n + k] * v[6 * n + k]).sum())
    };
    let p0 = momentum(&c, &ic.state.v);
    for _ in 0..150 {
        ia.step(&mut a, dt, None);
        ic.step(&mut c, dt, None);
    }
    let n = 27;
    assert!(
        bits(a.positions().iter().flat_map(|p| [p.x, p.y, p.z]))
            == bits(c.positions()[..n].iter().flat_map(|p| [p.x, p.y, p.z])),
        "the plate's positions changed"
    );
    assert!(bits(ia.state.v.iter().copied()) == bits(ic.state.v[..6 * n].iter().copied()));
    // the free pair of copies keeps its momentum; it has moved away from its sources
    let p1 = momentum(&c, &ic.state.v);
    let scale = p0.iter().map(|p| p.abs()).fold(0.0, f64::max);
    for k in 0..3 {
        assert!((p1[k] - p0[k]).abs() <= 1e-12 * scale, "momentum {k}: {} -> {}", p0[k], p1[k]);
    }
    let apart = (c.positions()[27] - c.positions()[3]).norm();
    assert!(apart > 1e-4, "the copy moves on its own ({apart:e} m)");
}

/// Checkpoints `(m, cd)` as step `step`, runs both 100 more steps of `dt`, and restarts `fresh`
/// (the model its mesh builds) from the checkpoint for the same 100 steps: the restarted model,
/// its integrator and the checkpoint read back.
fn through_checkpoint(
    m: &mut FeModel,
    cd: &mut CentralDifference,
    dt: f64,
    step: u64,
    mut fresh: FeModel,
) -> (FeModel, CentralDifference, Checkpoint) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("structure.ckpt");
    let mut ck = Checkpoint::new(step, cd.state.t);
    save_state(m, &mut ck).unwrap();
    save_dynamics(&mut ck, &cd.state).unwrap();
    ck.write_file(&path).unwrap();
    for _ in 0..100 {
        cd.step(m, dt, None);
    }
    let ck = Checkpoint::read_file(&path).unwrap();
    restore_state(&mut fresh, &ck).unwrap();
    let mut cr = CentralDifference::resume(&fresh, load_dynamics(&ck, fresh.n_dof()).unwrap());
    for _ in 0..100 {
        cr.step(&mut fresh, dt, None);
    }
    (fresh, cr, ck)
}

#[test]
fn restart_after_a_change_ends_where_the_uninterrupted_run_ends() {
    let dt = 0.5 * plate(&mesh(), &[]).stable_dt();
    let (mut m, mut cd) = start(100, dt);
    copy_off(&mut m, &mut cd);
    for _ in 0..50 {
        cd.step(&mut m, dt, None);
    }
    let (r, cr, ck) = through_checkpoint(&mut m, &mut cd, dt, 150, plate(&mesh(), &[]));
    assert_eq!(r.topology_version(), m.topology_version());
    assert_eq!(r.topology().elements().ids(), m.topology().elements().ids());
    assert!(model_bits(&r) == model_bits(&m), "restarted model state differs");
    assert!(dynamics_bits(&cr.state) == dynamics_bits(&cd.state), "restarted motion differs");

    // the checkpoint of the changed plate refuses a model of another mesh
    let mut other = FeModel::new(&generate::rectangle(LENGTH, 0.05, 4, 2), part).unwrap();
    let e = restore_state(&mut other, &ck).unwrap_err().to_string();
    assert!(e.contains("a checkpoint of another mesh"), "{e}");
}

#[test]
fn bad_changes_are_refused_with_the_ids_named() {
    let mut m = plate(&mesh(), &[]);
    let e = m.duplicate_nodes(&[(5, 3)]).unwrap_err();
    assert_eq!(e, TopologyError::TakenId { kind: "node", id: 3 });
    let e = m.duplicate_nodes(&[(99, 200)]).unwrap_err();
    assert_eq!(e, TopologyError::UnknownNode { id: 99 });
    let e = m.duplicate_element(77, 500, &[0, 1, 10, 9]).unwrap_err();
    assert_eq!(e, TopologyError::UnknownElement { id: 77 });
    let e = m.duplicate_element(0, 1, &[0, 1, 10, 9]).unwrap_err();
    assert_eq!(e, TopologyError::TakenId { kind: "element", id: 1 });
    let e = m.duplicate_element(0, 500, &[0, 1, 10]).unwrap_err();
    assert_eq!(e, TopologyError::NodeCount { element: 0, got: 3, expected: 4 });
    let e = m.duplicate_element(0, 500, &[1, 0, 10, 9]).unwrap_err().to_string();
    assert!(e.starts_with("element 0: node 1 is at"), "{e}");
    let nan =
        NewNode { id: 300, x0: [0.0, f64::NAN, 0.0], x: [0.0; 3], rotation: Matrix3::identity() };
    let e = m.add_nodes(&[nan]).unwrap_err();
    assert_eq!(e, TopologyError::NotFinite { node: 300, field: "reference position" });
    assert_eq!(m.topology_version(), 1, "refused changes change nothing");
    assert_eq!(m.n_nodes(), 27);

    // ids given by the mesh builder
    let ids: Vec<u64> = (0..27).map(|n| 10 * n + 7).collect();
    let cells: Vec<u64> = (0..16).map(|c| 1000 + c).collect();
    let e = m.set_ids(vec![1; 27], cells.clone()).unwrap_err();
    assert_eq!(e, TopologyError::TakenId { kind: "node", id: 1 });
    m.set_ids(ids, cells).unwrap();
    let node =
        NewNode { id: 9, x0: [1.0, 0.0, 0.0], x: [1.0, 0.0, 0.0], rotation: Matrix3::identity() };
    assert_eq!(m.add_nodes(&[node]).unwrap(), 27..28);
    assert_eq!(m.topology().nodes().slot(57), Some(5));
    let e = m.duplicate_element(1005, 2000, &[57, 67, 157, 147]).unwrap();
    assert_eq!(e, 16);
    assert_eq!(m.lumped_mass()[6 * 27], 0.0, "an added node without element has no mass");
    assert!(m.constrained()[6 * 27..6 * 28].iter().all(|&c| c), "nor free dofs");

    // an integrator that has not been given the new nodes' motion is told so
    let mut d = Dynamics { t: 0.0, v: vec![0.0; 6 * 27], a: vec![0.0; 6 * 27] };
    assert_eq!(d.copy_nodes(&[27]), Err(ResizeError::Source { node: 27, n: 27 }));
    assert!(d.push_nodes(&[0.0; 6], &[0.0; 5]).is_err());
    let mut cd = CentralDifference::resume(&plate(&mesh(), &[]), d);
    let e = cd.follow_topology(&mut m, None).unwrap_err();
    assert_eq!(e, ResizeError::Dofs { model: 6 * 28, state: 6 * 27 });
}

#[test]
fn implicit_steps_follow_a_change_and_leave_the_plate_unchanged() {
    use structure_solver::time::{Implicit, ImplicitScheme};
    let elastic = |m: &Mesh| {
        let mut fe = FeModel::new(m, |_| Part::Shell(SEC)).unwrap();
        fe.fix(m.node_set("u0").unwrap(), [true; 6]);
        fe
    };
    let run = |copy: bool| {
        let mut m = elastic(&mesh());
        let v0 = bending_velocity(&m);
        let mut im = Implicit::new(&mut m, ImplicitScheme::Newmark, 0.0, v0, None);
        // exact solves: the same Newton iterates, so the plate moves only by round-off
        im.params.inexact = false;
        let dt = 2e-5;
        for step in 0..20 {
            if copy && step == 10 {
                let sources = [3, 4, 13, 12];
                let pairs: Vec<(u64, u64)> =
                    sources.iter().map(|&s| (s as u64, 1000 + s as u64)).collect();
                m.duplicate_nodes(&pairs).unwrap();
                m.duplicate_element(3, 500, &[1003, 1004, 1013, 1012]).unwrap();
                im.state.copy_nodes(&sources).unwrap();
                im.follow_topology(&mut m, None).unwrap();
            }
            im.step(&mut m, dt, None).unwrap();
        }
        (m, im)
    };
    let (a, ia) = run(false);
    let (c, ic) = run(true);
    assert_eq!(c.n_nodes(), 31);
    let mut disp = vec![[0.0; 3]; 31];
    c.displacement(&mut disp);
    let tip = (0..3).map(|k| disp[8][k].abs()).fold(0.0, f64::max);
    assert!(tip > 1e-4, "the plate bends ({tip:e} m at the tip)");
    let mut da = vec![[0.0; 3]; 27];
    a.displacement(&mut da);
    let err = (0..27)
        .flat_map(|n| (0..3).map(move |k| (n, k)))
        .map(|(n, k)| (da[n][k] - disp[n][k]).abs())
        .fold(0.0, f64::max);
    assert!(err <= 1e-9 * tip, "the plate's displacement moved by {err:e} m (tip {tip:e} m)");
    let verr = (0..6 * 27).map(|i| (ia.state.v[i] - ic.state.v[i]).abs()).fold(0.0, f64::max);
    let vmax = ia.state.v.iter().map(|v| v.abs()).fold(0.0, f64::max);
    // velocities (rotations included) differ by Newton's tolerance through `2 Δu / Δt`
    assert!(verr <= 1e-5 * vmax, "the plate's velocity moved by {verr:e} m/s (max {vmax:e})");
}

/// The plate's quads split along their diagonal from the first node: BLT3 shells of a `bt4`
/// part, clamped at `x = 0`.
fn triangle_plate(mesh: &Mesh) -> FeModel {
    let mut split = mesh.clone();
    split.cells = mesh
        .cells
        .iter()
        .flat_map(|c| {
            let n = &c.nodes;
            if c.kind != CellKind::Quad4 {
                return vec![c.clone()];
            }
            [[n[0], n[1], n[2]], [n[0], n[2], n[3]]]
                .map(|t| Cell { kind: CellKind::Tri3, nodes: t.to_vec() })
                .to_vec()
        })
        .collect();
    let mut m = FeModel::new(&split, |_| Part::Bt4(SEC, Some(YIELD))).unwrap();
    m.set_rotary_inertia(RotaryInertia::Scaled);
    m.fix(mesh.node_set("u0").unwrap(), [true; 6]);
    m
}

/// Positions, rotations, spins, the BLT3 state and the lumped masses, bitwise.
fn triangle_bits(m: &FeModel) -> Vec<u64> {
    let mut all = bits(m.positions().iter().flat_map(|p| [p.x, p.y, p.z]));
    all.extend(bits(m.rotations().iter().flat_map(|r| r.as_slice().to_vec())));
    all.extend(bits(m.committed_spins().iter().flat_map(|p| [p.x, p.y, p.z])));
    let s = m.blt3().unwrap().state();
    all.extend(bits(s.stress.iter().chain(&s.alpha).chain(&s.shear).copied()));
    all.extend(bits(m.lumped_mass().iter().copied()));
    all
}

/// BLT3 triangles are copied like BT4 quads: a phantom copy of triangle 6 (nodes 3, 4, 13) on
/// two new nodes at t = 0 runs bitwise as the model built with it, past yield; a copy made
/// mid-run onto new nodes survives a checkpoint and restart bitwise.
#[test]
fn triangles_are_copied_with_their_state_and_restart_across_the_change() {
    let base = mesh();
    let mut a = triangle_plate(&base);
    a.duplicate_nodes(&[(3, 100), (4, 101)]).unwrap();
    let copy = a.duplicate_element(6, 500, &[100, 101, 13]).unwrap();
    assert_eq!(a.topology().store(copy), Some(Store::Blt3(32)));
    // the model built with the copy: the split plate and the copy's triangle after it
    let mut union = base.clone();
    union.nodes.extend([base.nodes[3], base.nodes[4]]);
    union.cells.push(Cell { kind: CellKind::Tri3, nodes: vec![27, 28, 13] });
    let mut b = triangle_plate(&union);
    assert_eq!(a.constrained(), b.constrained(), "free dofs");
    assert_eq!(a.stable_dt().to_bits(), b.stable_dt().to_bits(), "element step bound");
    let dt = 0.5 * b.stable_dt();
    let (va, vb) = (bending_velocity(&a), bending_velocity(&b));
    let mut ia = CentralDifference::new(&mut a, 0.0, va, None);
    let mut ib = CentralDifference::new(&mut b, 0.0, vb, None);
    for _ in 0..300 {
        ia.step(&mut a, dt, None);
        ib.step(&mut b, dt, None);
    }
    let shells = a.blt3().unwrap();
    assert!((0..5).any(|p| shells.plastic_strain(6, p) > 0.0), "the triangles yield");
    assert!(shells.stress(32, 0)[0] != 0.0, "the copy is strained");
    assert!(triangle_bits(&a) == triangle_bits(&b), "model state differs from the built union");
    assert!(dynamics_bits(&ia.state) == dynamics_bits(&ib.state), "motion differs");

    // mid-run: a copy of triangle 6 on new nodes, with its source's state, then a restart
    let mut m = triangle_plate(&base);
    let v0 = bending_velocity(&m);
    let mut cd = CentralDifference::new(&mut m, 0.0, v0, None);
    for _ in 0..150 {
        cd.step(&mut m, dt, None);
    }
    let sources = [3, 4, 13];
    let pairs: Vec<(u64, u64)> = sources.iter().map(|&s| (s as u64, 1000 + s as u64)).collect();
    m.duplicate_nodes(&pairs).unwrap();
    let copy = m.duplicate_element(6, 500, &[1003, 1004, 1013]).unwrap();
    let t = m.blt3().unwrap();
    let k = match m.topology().store(copy) {
        Some(Store::Blt3(k)) => k,
        other => panic!("the copy is stored as {other:?}"),
    };
    for p in 0..5 {
        assert_eq!(t.stress(k, p), t.stress(6, p), "stress at point {p}");
        assert_eq!(t.plastic_strain(k, p).to_bits(), t.plastic_strain(6, p).to_bits());
    }
    assert_eq!(t.shear(k), t.shear(6));
    cd.state.copy_nodes(&sources).unwrap();
    cd.follow_topology(&mut m, None).unwrap();
    for _ in 0..50 {
        cd.step(&mut m, dt, None);
    }
    let (r, cr, _) = through_checkpoint(&mut m, &mut cd, dt, 200, triangle_plate(&base));
    assert!(triangle_bits(&r) == triangle_bits(&m), "restarted model state differs");
    assert!(dynamics_bits(&cr.state) == dynamics_bits(&cd.state), "restarted motion differs");
}
