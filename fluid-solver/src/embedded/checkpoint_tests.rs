//! The embedded part of a checkpoint and the rollback of a failed step, on a plane moving
//! through a jittered cube of tets: a run restored from its checkpoint is the carried run bit
//! for bit (tracker, step view, and the states of the steps after), and a step that fails, or
//! one undone after it succeeded, leaves the run, the state and the node materials as they were.

use super::advance::{EmbeddedRun, Kinematics};
use super::checkpoint::{self, Undo};
use super::motion::RigidMotion;
use super::step::EmbeddedStep;
use super::tests::{cube_mesh, plane};
use super::tracker::{Seed, Tracker};
use crate::bc::BoundaryCondition;
use crate::eos::Eos;
use crate::mesh::boxmesh::FACE_NAMES;
use crate::semidiscretization::{Numerics, Semidiscretization};
use crate::state::{State, Workspace};
use interface_protocol::case::{InterfaceTreatment, LoadAlgorithm, Motion, Tracking};
use interface_protocol::io::checkpoint::Checkpoint;
use std::path::Path;

const PLANE_Z: f64 = 0.33;

/// A plane at `z = 0.33` through the slip walls of the unit cube moving at `w` in `z`. With
/// `two_fluids`, fluid on both sides (materials 0 below, 1 above, one `eos` each); else the part
/// above is inside the body. The fluid at rest at `(ρ, p)`.
struct Plate {
    semi: Semidiscretization,
    run: EmbeddedRun,
    state: State,
    ws: Workspace,
    t: f64,
}

impl Plate {
    fn new(dir: &Path, eos: Eos, two_fluids: bool, w: f64, rho: f64, p: f64) -> Plate {
        std::fs::create_dir_all(dir).unwrap();
        let mesh = cube_mesh(8, 0.25, 7);
        let walls: Vec<(String, BoundaryCondition)> =
            FACE_NAMES.iter().map(|f| (f.to_string(), BoundaryCondition::SlipWall)).collect();
        let material: Vec<u8> =
            mesh.coords.iter().map(|x| (two_fluids && x[2] > PLANE_Z) as u8).collect();
        let semi = Semidiscretization::with_materials(
            mesh,
            vec![eos; 2],
            material.clone(),
            Numerics::default(),
            &walls,
        )
        .unwrap();
        let mut rest = plane(-0.5, 1.5, -0.5, 1.5, PLANE_Z);
        let velocity = [0.0, 0.0, w];
        rest.v_a = vec![velocity; 4];
        rest.v_b = vec![velocity; 4];
        let mut seeds = vec![Seed { point: [0.5, 0.5, 0.05], fluid: true }];
        seeds.push(Seed { point: [0.5, 0.5, 0.95], fluid: two_fluids });
        let tracker = Tracker::new(&semi.mesh, rest.clone(), Tracking::Collision, &seeds).unwrap();
        let motion = Some(RigidMotion::new(Motion::Translation { velocity }));
        let kinematics = Kinematics::Law { motion, reference: rest.x_b.clone() };
        let loads = LoadAlgorithm::default();
        let interface = InterfaceTreatment::SecondOrder;
        let run = EmbeddedRun::with(tracker, kinematics, loads, interface, None, dir).unwrap();
        let cons = vec![eos.prim_to_cons(&[rho, 0.0, 0.0, 0.0, p]); semi.mesh.n_nodes()];
        let state = State::with_materials(cons, material);
        let mut ws = Workspace::new(semi.mesh.n_nodes());
        semi.primitives(&state.cons, &mut ws).unwrap();
        Plate { semi, run, state, ws, t: 0.0 }
    }

    fn air(dir: &Path, two_fluids: bool) -> Plate {
        Plate::new(dir, Eos::PerfectGas { gamma: 1.4 }, two_fluids, 150.0, 1.2, 1e5)
    }

    fn step(&mut self) -> anyhow::Result<f64> {
        let (semi, state, ws) = (&mut self.semi, &mut self.state, &mut self.ws);
        let dt = self.run.step(semi, state, ws, 0.5, self.t, 1.0, None)?;
        self.t += dt;
        Ok(dt)
    }
}

/// `{:?}` prints every f64 exactly (shortest round trip, the sign of zero, NaN as NaN).
fn bits<T: std::fmt::Debug>(x: &T) -> String {
    format!("{x:?}")
}

/// Writes the embedded part of `run` and an empty fluid part as checkpoint `tag` of `run_dir`.
fn write_checkpoint(run_dir: &Path, run: &EmbeddedRun, step: u64, t: f64) {
    let dir = run_dir.join("checkpoints");
    let tag = format!("step_{step:010}");
    checkpoint::write(run, &dir, &tag, step, t).unwrap();
    Checkpoint::new(step, t).write(&dir, &tag, "fluid").unwrap();
}

/// The run restored from its checkpoint holds the tracker it carried (hierarchy, cut edges,
/// sides, active nodes, `p*`), its loads and clips; a step view built anew from it is bitwise
/// the view the run updated from step to step; and the steps after, across which nodes change
/// side (and, with two fluids, material), give the same states bit for bit.
#[test]
fn a_restored_run_steps_on_bit_for_bit() {
    for two_fluids in [false, true] {
        let dir = tempfile::tempdir().unwrap();
        let mut a = Plate::air(dir.path(), two_fluids);
        for _ in 0..6 {
            a.step().unwrap();
        }
        write_checkpoint(dir.path(), &a.run, 6, a.t);
        let mut b = Plate::air(&dir.path().join("b"), two_fluids);
        let ck = checkpoint::latest(dir.path(), "fluid").unwrap();
        assert_eq!(ck.found.step, 6);
        let (tracker, kinematics) = (&b.run.tracker, &b.run.kinematics);
        let decoded = ck.decode(tracker, kinematics, &b.semi.mesh).unwrap();
        decoded.restore(&mut b.run, &b.semi.mesh).unwrap();
        let (ta, tb) = (&a.run.tracker, &b.run.tracker);
        assert_eq!(ta.surface, tb.surface);
        assert_eq!(ta.bvh, tb.bvh);
        assert_eq!(ta.cuts, tb.cuts);
        assert_eq!((&ta.sides, &ta.active), (&tb.sides, &tb.active));
        assert_eq!(bits(&ta.p_star), bits(&tb.p_star));
        assert_eq!((bits(&a.run.loads), a.run.clips), (bits(&b.run.loads), b.run.clips));
        assert!(!ta.cuts.cuts.is_empty() && ta.p_star.iter().flatten().any(|p| p.is_finite()));
        let fresh = EmbeddedStep::new(&a.semi, tb, None, InterfaceTreatment::SecondOrder);
        let carried = a.run.view().expect("a view after a step");
        assert_eq!(carried, &fresh);
        assert_eq!(bits(&carried.gradient), bits(&fresh.gradient), "gradient bits");
        // The fluid part is the caller's: the state and materials carried over.
        b.state = a.state.clone();
        b.semi.set_materials(a.state.material.clone()).unwrap();
        b.semi.primitives(&b.state.cons, &mut b.ws).unwrap();
        b.t = a.t;
        let sides_at_checkpoint = a.run.tracker.sides.clone();
        for k in 0..10 {
            let (da, db) = (a.step().unwrap(), b.step().unwrap());
            assert_eq!(da.to_bits(), db.to_bits(), "step {k}");
            assert_eq!(bits(&a.state), bits(&b.state), "step {k}");
            assert_eq!(a.run.tracker.sides, b.run.tracker.sides, "step {k}");
            assert_eq!(bits(&a.run.loads), bits(&b.run.loads), "step {k}");
        }
        let now = &a.run.tracker.sides;
        let changed = (0..now.side.len())
            .filter(|&i| {
                now.side[i] != sides_at_checkpoint.side[i]
                    || now.status[i] != sides_at_checkpoint.status[i]
            })
            .count();
        println!("two fluids {two_fluids}: {changed} nodes changed side after the checkpoint");
        assert!(changed >= 8, "{changed} nodes changed side");
    }
}

/// Everything [`EmbeddedRun::save`] holds plus what the restore rebuilds, and the fluid state.
fn snapshot(p: &Plate) -> String {
    let t = &p.run.tracker;
    bits(&(p.run.save(), &t.bvh, &t.cuts, &t.active, &p.state, p.semi.material(), &p.ws.prim))
}

/// A step undone after it succeeded (nodes filled, materials changed, the RK2 update done) leaves
/// the run, state, materials and primitives as they were, and the same step taken again gives
/// what a run that never undid it gives.
#[test]
fn an_undone_step_leaves_everything_as_it_was() {
    let dir = tempfile::tempdir().unwrap();
    let (mut p, mut twin) =
        (Plate::air(dir.path(), true), Plate::air(&dir.path().join("twin"), true));
    let (mut filled, mut material_changes) = (0, 0);
    for k in 0..16 {
        let before = snapshot(&p);
        let mut undo = Undo::default();
        let (semi, state, ws) = (&mut p.semi, &mut p.state, &mut p.ws);
        let saved = p.run.save();
        p.run.try_step(semi, state, ws, 0.5, p.t, 1.0, None, &mut undo).unwrap();
        assert!(undo.stepped);
        filled += undo.filled.len();
        material_changes += undo.material.is_some() as usize;
        p.run.roll_back(saved, undo, semi, state, ws).unwrap();
        assert_eq!(snapshot(&p), before, "step {k}");
        assert!(p.run.view().is_none());
        let dt = p.step().unwrap();
        assert_eq!(dt.to_bits(), twin.step().unwrap().to_bits(), "step {k}");
        assert_eq!(snapshot(&p), snapshot(&twin), "step {k}");
    }
    println!("{filled} nodes filled, {material_changes} steps changed materials");
    assert!(filled >= 8 && material_changes >= 2, "{filled} filled, {material_changes}");
}

/// Water behind a plane pulled away at 400 m/s cavitates in the first step, after the tracking
/// moved the surface: the step fails naming the state and the run is left as it was, bit for bit.
#[test]
fn a_failed_step_is_rolled_back() {
    let dir = tempfile::tempdir().unwrap();
    let (k1, k2) = (2.07e9, 7.15);
    let tait = Eos::Tait { p0: 1e5, rho0: 1000.0, alpha: 1e5 + k1 / k2, beta: k2 };
    let mut p = Plate::new(dir.path(), tait, true, 400.0, 1000.0, 1e5);
    let before = snapshot(&p);
    let e = p.step().unwrap_err().to_string();
    assert!(e.contains("invalid fluid state"), "{e}");
    assert!(p.run.tracking_s > 0.0, "the step failed after the tracking");
    assert_eq!(snapshot(&p), before, "{e}");
    assert_eq!(p.run.tracker.surface.t_b, 0.0);
}
