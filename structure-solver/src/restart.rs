//! Checkpoints of the structure (DESIGN §6, §7): the model's committed state and the
//! integrator's velocities and accelerations, as named arrays of an
//! `interface_protocol::io::checkpoint` file (`checkpoints/<tag>/structure.ckpt`).
//!
//! The state of an `FeModel`: positions `x`, nodal rotation matrices `rotations`, accumulated
//! spins `spins` (BT4 shells read their increments from them), the J2 state of every element
//! `material`, for BT4 shells per point the stresses, equivalent plastic strain and
//! hourglass stresses (`bt4.*`), for BLT3 shells per point the stresses and equivalent
//! plastic strain and per element the shear resultants (`blt3.*`), and the topology
//! (`topology.*`: version, node and element ids, reference positions, the user's fixed dofs,
//! and the element list with the element each was copied from), so that a restart after a
//! change at run time first rebuilds the changed model from the one its case builds. A
//! restart restores all of it, so it reproduces the run bitwise. Arrays are in the model's
//! storage order (the slots of the renumbered mesh, [`crate::mesh::renumber`]), which the
//! same case always rebuilds: a checkpoint is a restart state, not an output in the user's
//! numbering.

use interface_protocol::io::checkpoint::Checkpoint;
use nalgebra::{Matrix3, Vector3};

use crate::assembly::{FeModel, TopologyRecord};
use crate::elements::blt3::Blt3State;
use crate::elements::bt4::Bt4State;
use crate::model::Model;
use crate::time::Dynamics;

/// The part name of the structure's checkpoint files.
pub const PART: &str = "structure";

/// `ck`'s array `name` with exactly `n` values, or an error naming it.
fn sized<'a>(ck: &'a Checkpoint, name: &str, n: usize) -> anyhow::Result<&'a [f64]> {
    let a = ck.f64(name)?;
    if a.len() != n {
        anyhow::bail!(
            "checkpoint at step {}: array `{name}` holds {} values, the model needs {n} (another mesh?)",
            ck.step,
            a.len()
        );
    }
    Ok(a)
}

fn flat(v: &[Vector3<f64>]) -> Vec<f64> {
    v.iter().flat_map(|p| [p.x, p.y, p.z]).collect()
}

fn vectors(a: &[f64]) -> Vec<Vector3<f64>> {
    a.chunks_exact(3).map(Vector3::from_column_slice).collect()
}

/// The arrays of a [`TopologyRecord`].
const TOPOLOGY: &str = "topology.node_ids";

fn save_topology(model: &FeModel, ck: &mut Checkpoint) -> anyhow::Result<()> {
    let t = model.topology_record();
    ck.put("topology.version", vec![t.version])?;
    ck.put(TOPOLOGY, t.node_ids)?;
    ck.put("topology.x0", t.x0)?;
    ck.put("topology.fixed", t.fixed.iter().map(|&f| f as u8).collect::<Vec<u8>>())?;
    ck.put("topology.element_ids", t.element_ids)?;
    ck.put("topology.element_source", t.element_source)?;
    ck.put("topology.element_offsets", t.element_offsets)?;
    ck.put("topology.element_nodes", t.element_nodes)?;
    Ok(())
}

/// The topology record of `ck`, if it holds one (checkpoints written before topology
/// changes existed hold none: the model as built).
fn load_topology(ck: &Checkpoint) -> anyhow::Result<Option<TopologyRecord>> {
    if !ck.names().any(|n| n == TOPOLOGY) {
        return Ok(None);
    }
    let version = match ck.u64("topology.version")? {
        [v] => *v,
        v => anyhow::bail!(
            "checkpoint at step {}: array `topology.version` holds {} values, expected 1",
            ck.step,
            v.len()
        ),
    };
    Ok(Some(TopologyRecord {
        version,
        node_ids: ck.u64(TOPOLOGY)?.to_vec(),
        x0: ck.f64("topology.x0")?.to_vec(),
        fixed: ck.u8("topology.fixed")?.iter().map(|&f| f != 0).collect(),
        element_ids: ck.u64("topology.element_ids")?.to_vec(),
        element_source: ck.u64("topology.element_source")?.to_vec(),
        element_offsets: ck.u64("topology.element_offsets")?.to_vec(),
        element_nodes: ck.u64("topology.element_nodes")?.to_vec(),
    }))
}

/// Puts the topology, committed configuration and element state of `model` into `ck`.
pub fn save_state(model: &FeModel, ck: &mut Checkpoint) -> anyhow::Result<()> {
    save_topology(model, ck)?;
    ck.put("x", flat(model.positions()))?;
    let r: Vec<f64> = model.rotations().iter().flat_map(|m| m.as_slice().to_vec()).collect();
    ck.put("rotations", r)?;
    ck.put("spins", flat(model.committed_spins()))?;
    let material: Vec<f64> =
        (0..model.elements().len()).flat_map(|e| model.element_state(e).to_vec()).collect();
    ck.put("material", material)?;
    if let Some(b) = model.bt4() {
        let s = b.state();
        ck.put("bt4.stress", s.stress.clone())?;
        ck.put("bt4.plastic_strain", s.alpha.clone())?;
        ck.put("bt4.hourglass", s.hourglass.clone())?;
    }
    if let Some(b) = model.blt3() {
        let s = b.state();
        ck.put("blt3.stress", s.stress.clone())?;
        ck.put("blt3.plastic_strain", s.alpha.clone())?;
        ck.put("blt3.shear", s.shear.clone())?;
    }
    Ok(())
}

/// Restores what [`save_state`] wrote into `model` (the model its case builds) and commits
/// it: the topology first, then the state of the changed model.
pub fn restore_state(model: &mut FeModel, ck: &Checkpoint) -> anyhow::Result<()> {
    if let Some(t) = load_topology(ck)? {
        model
            .rebuild_topology(&t)
            .map_err(|e| anyhow::anyhow!("checkpoint at step {}: {e}", ck.step))?;
    }
    let n = model.n_nodes();
    let x = vectors(sized(ck, "x", 3 * n)?);
    let r: Vec<Matrix3<f64>> =
        sized(ck, "rotations", 9 * n)?.chunks_exact(9).map(Matrix3::from_column_slice).collect();
    let spins = vectors(sized(ck, "spins", 3 * n)?);
    let n_state: usize = (0..model.elements().len()).map(|e| model.element_state(e).len()).sum();
    let material = sized(ck, "material", n_state)?;
    let bt4 = match model.bt4() {
        Some(b) => {
            let s = b.state();
            Some(Bt4State {
                stress: sized(ck, "bt4.stress", s.stress.len())?.to_vec(),
                alpha: sized(ck, "bt4.plastic_strain", s.alpha.len())?.to_vec(),
                hourglass: sized(ck, "bt4.hourglass", s.hourglass.len())?.to_vec(),
            })
        }
        None => None,
    };
    let blt3 = match model.blt3() {
        Some(b) => {
            let s = b.state();
            Some(Blt3State {
                stress: sized(ck, "blt3.stress", s.stress.len())?.to_vec(),
                alpha: sized(ck, "blt3.plastic_strain", s.alpha.len())?.to_vec(),
                shear: sized(ck, "blt3.shear", s.shear.len())?.to_vec(),
            })
        }
        None => None,
    };
    model
        .restore_committed(&x, &r, &spins, material, bt4, blt3)
        .map_err(|e| anyhow::anyhow!("checkpoint at step {}: {e}", ck.step))
}

/// Puts the integrator state (`t` is the checkpoint's time).
pub fn save_dynamics(ck: &mut Checkpoint, d: &Dynamics) -> anyhow::Result<()> {
    ck.put("v", d.v.clone())?;
    ck.put("a", d.a.clone())?;
    Ok(())
}

/// The integrator state of a checkpoint for a model of `n_dof` dofs.
pub fn load_dynamics(ck: &Checkpoint, n_dof: usize) -> anyhow::Result<Dynamics> {
    Ok(Dynamics {
        t: ck.time,
        v: sized(ck, "v", n_dof)?.to_vec(),
        a: sized(ck, "a", n_dof)?.to_vec(),
    })
}
