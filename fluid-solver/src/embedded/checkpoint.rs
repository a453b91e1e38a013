//! The embedded boundary's part of a checkpoint (DESIGN §7): `checkpoints/<tag>/embedded.ckpt`,
//! beside the fluid's part and at its step, holds what an embedded run carries from step to step
//! that the case cannot give back: the node status and sides (Alg. 4.2 step 5 redecides only the
//! swept nodes, so the sides are the run's history, not the surface's geometry), the surface's
//! nodal states at both ends of the last step and their times, `p*` at the cut edges and the
//! nodal loads of the last step, the cavitation clips and the interface work counted so far, and
//! a coupled run's own copy of the Hermite path (DESIGN §4).
//!
//! The rest is rebuilt exactly: the hierarchy is built at `t = 0` from the case as the run built
//! it and refitted to the restored states (a refit depends only on them), the cut edges are
//! intersected again, the active nodes follow from the status, and the step view is built anew
//! ([`super::step::EmbeddedStep::update`] is bitwise a fresh build). So a restarted run steps
//! on bit for bit.
//!
//! The same [`Saved`] state, kept in memory before each step, rolls a failed step back, with the
//! [`Undo`] of what the step changed in the fluid state (filled nodes, node materials, the RK2
//! update).

use super::advance::{EmbeddedRun, Kinematics};
use super::case::Prescribed;
use super::intersect::{KeptInside, Near, SurfaceAt};
use super::riemann_fs::WallPressures;
use super::status::{NodeSides, NodeStatus, NO_SIDE};
use super::surface::HermitePath;
use super::tracker::{intersect, Tracker};
use crate::mesh::Mesh;
use crate::semidiscretization::Semidiscretization;
use crate::state::{MaterialId, State, Workspace};
use anyhow::Context;
use interface_protocol::case::Tracking;
use interface_protocol::io::checkpoint::{self, Checkpoint, Found, EXTENSION};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Checkpoint part name of the embedded boundary.
pub const PART: &str = "embedded";

/// What an embedded run carries from one step to the next beyond the case.
#[derive(Debug, Clone, PartialEq)]
pub struct Saved {
    /// The last step `[t_a, t_b]` and the surface's nodal states at its ends.
    pub t_a: f64,
    pub t_b: f64,
    pub x_a: Vec<[f64; 3]>,
    pub v_a: Vec<[f64; 3]>,
    pub x_b: Vec<[f64; 3]>,
    pub v_b: Vec<[f64; 3]>,
    pub sides: NodeSides,
    /// `p*` at the cut edges at `t_b`, in cut order.
    pub p_star: Vec<WallPressures>,
    /// Nodal loads at `t_b`, in surface node order.
    pub loads: Vec<[f64; 3]>,
    pub clips: u64,
    /// [`EmbeddedRun::interface_work`] at `t_b`.
    pub interface_work: f64,
}

/// What a step changed in the fluid state, to undo it when the step fails.
#[derive(Debug, Default)]
pub struct Undo {
    /// The node materials before the step gave changed nodes their new side's fluid.
    pub material: Option<Vec<MaterialId>>,
    /// The conserved states of the filled nodes before the fill, in fill order.
    pub filled: Vec<(usize, [f64; 5])>,
    /// The RK2 stages succeeded: the state they started from is in `ws.stage` (they build the
    /// new state there and swap it in).
    pub stepped: bool,
    /// The level set before the step, when the run has one.
    pub phi: Option<Vec<f64>>,
}

/// The file's scalars.
#[derive(Debug, Serialize, Deserialize)]
struct Meta {
    mesh_nodes: u64,
    surface_nodes: u64,
    topology_version: u64,
    /// 0 Alg. 4.1, 1 Alg. 4.2.
    tracking: u8,
    t_a: f64,
    t_b: f64,
    clips: u64,
    interface_work: f64,
    /// A coupled run's Hermite path `[t_a, t_b]` (its end states are arrays).
    coupled: Option<[f64; 2]>,
}

fn tracking_code(t: Tracking) -> u8 {
    match t {
        Tracking::Projection => 0,
        Tracking::Collision => 1,
    }
}

fn tracking_name(code: u8) -> &'static str {
    match code {
        0 => "projection",
        1 => "collision",
        _ => "unknown",
    }
}

impl EmbeddedRun {
    /// The state a step starts from.
    pub fn save(&self) -> Saved {
        let s = &self.tracker.surface;
        Saved {
            t_a: s.t_a,
            t_b: s.t_b,
            x_a: s.x_a.clone(),
            v_a: s.v_a.clone(),
            x_b: s.x_b.clone(),
            v_b: s.v_b.clone(),
            sides: self.tracker.sides.clone(),
            p_star: self.tracker.p_star.clone(),
            loads: self.loads.clone(),
            clips: self.clips,
            interface_work: self.interface_work,
        }
    }

    /// Puts the run back in the state `saved` on `mesh`: the hierarchy refitted, the cut edges
    /// intersected again, the active nodes from the status, the step view dropped (the next step
    /// builds it anew).
    pub fn restore(&mut self, saved: Saved, mesh: &Mesh) -> anyhow::Result<()> {
        let tracker = &mut self.tracker;
        let s = &mut tracker.surface;
        (s.t_a, s.t_b) = (saved.t_a, saved.t_b);
        (s.x_a, s.v_a, s.x_b, s.v_b) = (saved.x_a, saved.v_a, saved.x_b, saved.v_b);
        tracker.bvh.update(&tracker.surface);
        let near = Near::find(mesh, &tracker.node_boxes, &tracker.bvh);
        let (adjacency, bvh) = (&tracker.adjacency, &tracker.bvh);
        if tracker.tracking == Tracking::Projection {
            // Alg. 4.1 keeps its inside from step to step: rebuilt by the whole-mesh passes.
            let at = SurfaceAt::at_end(&tracker.surface, bvh)?;
            let (kept, cuts) = KeptInside::new(mesh, adjacency, &tracker.node_boxes, at, &near);
            (tracker.cuts, tracker.kept_inside) = (cuts, Some(kept));
        } else {
            tracker.cuts =
                intersect(mesh, adjacency, &tracker.surface, bvh, tracker.tracking, &near)?;
        }
        tracker.active = saved.sides.status.iter().map(|s| *s == NodeStatus::Active).collect();
        tracker.sides = saved.sides;
        tracker.p_star = saved.p_star;
        self.loads = saved.loads;
        self.clips = saved.clips;
        self.interface_work = saved.interface_work;
        self.clear_view();
        Ok(())
    }

    /// Undoes a failed step: the fluid state back to `undo`'s record, the embedded state to
    /// `saved`, the primitives recomputed (bitwise those the step started from).
    pub(super) fn roll_back(
        &mut self,
        saved: Saved,
        undo: Undo,
        semi: &mut Semidiscretization,
        state: &mut State,
        ws: &mut Workspace,
    ) -> anyhow::Result<()> {
        if undo.stepped {
            std::mem::swap(&mut state.cons, &mut ws.stage);
        }
        for (i, q) in undo.filled.into_iter().rev() {
            state.cons[i] = q;
        }
        if let Some(phi) = undo.phi {
            state.phi = phi;
        }
        if let Some(material) = undo.material {
            semi.set_materials(material.clone())?;
            state.material = material;
        }
        self.restore(saved, &semi.mesh)?;
        semi.primitives(&state.cons, ws)?;
        Ok(())
    }
}

/// Path of the part in the tag folder `dir`.
fn part_path(dir: &Path) -> PathBuf {
    dir.join(format!("{PART}.{EXTENSION}"))
}

/// Writes the embedded part of checkpoint `tag` at `(step, time)` under `checkpoints_dir`.
pub fn write(
    run: &EmbeddedRun,
    checkpoints_dir: &Path,
    tag: &str,
    step: u64,
    time: f64,
) -> anyhow::Result<()> {
    let t = &run.tracker;
    let s = &t.surface;
    let mut ck = Checkpoint::new(step, time);
    let coupled = match &run.kinematics {
        Kinematics::Law { .. } => None,
        Kinematics::Coupled { path, x_from, v_from, x_to, v_to } => {
            for (name, v) in
                [("x_from", x_from), ("v_from", v_from), ("x_to", x_to), ("v_to", v_to)]
            {
                ck.put_f64_n(name, v)?;
            }
            Some([path.t_a, path.t_b])
        }
    };
    ck.set_meta(&Meta {
        mesh_nodes: t.sides.status.len() as u64,
        surface_nodes: s.n_nodes() as u64,
        topology_version: s.topology_version,
        tracking: tracking_code(t.tracking),
        t_a: s.t_a,
        t_b: s.t_b,
        clips: run.clips,
        interface_work: run.interface_work,
        coupled,
    })?;
    ck.put("status", t.sides.status.iter().map(|s| *s as u8).collect::<Vec<u8>>())?;
    ck.put("side", t.sides.side.clone())?;
    ck.put("side_fluid", t.sides.side_fluid.iter().map(|f| *f as u8).collect::<Vec<u8>>())?;
    for (name, v) in [("x_a", &s.x_a), ("v_a", &s.v_a), ("x_b", &s.x_b), ("v_b", &s.v_b)] {
        ck.put_f64_n(name, v)?;
    }
    ck.put("triangles", s.triangles.as_flattened().to_vec())?;
    ck.put_f64_n("p_star", &t.p_star)?;
    ck.put_f64_n("loads", &run.loads)?;
    ck.write(checkpoints_dir, tag, PART)?;
    Ok(())
}

/// The embedded part of a checkpoint, read before the run is set up.
#[derive(Debug, Clone)]
pub struct EmbeddedCheckpoint {
    pub found: Found,
    pub path: PathBuf,
    ck: Checkpoint,
}

/// The newest checkpoint under `run_dir/checkpoints` whose fluid part (`fluid_part`) and
/// embedded part are both intact and at one step, with the embedded part read.
pub fn latest(run_dir: &Path, fluid_part: &str) -> anyhow::Result<EmbeddedCheckpoint> {
    let dir = run_dir.join("checkpoints");
    let search = checkpoint::search(&dir, &[fluid_part, PART])?;
    for line in search.notices() {
        eprintln!("warning: {line}");
    }
    let Some(found) = search.found else {
        let fluid_only = checkpoint::search(&dir, &[fluid_part])?.found;
        return Err(match fluid_only {
            Some(f) => anyhow::anyhow!(
                "the case has [fluid.embedded], but no checkpoint in {} holds its state \
                 ({PART}.{EXTENSION}); the newest fluid checkpoint, {}, has none: it was written \
                 by a run without [fluid.embedded]",
                dir.display(),
                f.tag
            ),
            None => anyhow::anyhow!("no complete fluid checkpoint in {}", dir.display()),
        });
    };
    EmbeddedCheckpoint::read(found)
}

impl EmbeddedCheckpoint {
    /// The embedded part of the checkpoint folder `found` (a coupled restart's, named by the
    /// launcher).
    pub fn read(found: Found) -> anyhow::Result<EmbeddedCheckpoint> {
        let path = part_path(&found.dir);
        let ck = Checkpoint::read_file(&path)?;
        Ok(EmbeddedCheckpoint { found, path, ck })
    }
}

/// The embedded part of a checkpoint checked against the case, ready to restore.
#[derive(Debug, Clone)]
pub struct Decoded {
    saved: Saved,
    /// A coupled run's kinematics.
    kinematics: Option<Kinematics>,
    path: PathBuf,
    time: f64,
}

impl EmbeddedCheckpoint {
    /// The checkpoint's state for the surface `[fluid.embedded]` sets up at `t = 0` (`p`, on
    /// `mesh`), checked against it: every mismatch names the file, the field and both values.
    pub fn check(&self, p: &Prescribed, mesh: &Mesh) -> anyhow::Result<Decoded> {
        let law = Kinematics::Law { motion: p.motion.clone(), reference: p.reference.clone() };
        self.decode(&p.tracker, &law, mesh)
    }

    /// The saved state and a coupled run's kinematics, checked against the `tracker` and
    /// `kinematics` of the case (at `t = 0`) and `mesh`.
    pub fn decode(
        &self,
        tracker: &Tracker,
        kinematics: &Kinematics,
        mesh: &Mesh,
    ) -> anyhow::Result<Decoded> {
        let ck = &self.ck;
        let fail = |m: String| anyhow::anyhow!("checkpoint `{}`: {m}", self.path.display());
        let changed = "changed since the checkpoint";
        let meta: Meta = ck.meta()?;
        let (n, surface) = (mesh.n_nodes(), &tracker.surface);
        if meta.mesh_nodes != n as u64 {
            return Err(fail(format!(
                "it holds the status of {} mesh nodes, but the case's mesh has {n}: the mesh {changed}",
                meta.mesh_nodes
            )));
        }
        if meta.surface_nodes != surface.n_nodes() as u64 {
            return Err(fail(format!(
                "it holds {} surface nodes, but the case's [fluid.embedded] surface has {}: the \
                 surface {changed}",
                meta.surface_nodes,
                surface.n_nodes()
            )));
        }
        if meta.tracking != tracking_code(tracker.tracking) {
            return Err(fail(format!(
                "it was tracked by `{}`, but the case's [fluid.embedded] tracking is `{}`",
                tracking_name(meta.tracking),
                tracking_name(tracking_code(tracker.tracking))
            )));
        }
        if meta.topology_version != surface.topology_version
            || ck.u32("triangles")? != surface.triangles.as_flattened()
        {
            return Err(fail(format!(
                "its surface triangles (topology {}) are not those of the case's [fluid.embedded] \
                 surface (topology {}): the surface {changed}",
                meta.topology_version, surface.topology_version
            )));
        }
        if meta.t_b.to_bits() != ck.time.to_bits() {
            return Err(fail(format!(
                "its surface is at t = {:e}, its step at t = {:e}",
                meta.t_b, ck.time
            )));
        }
        let sides = self.sides(n)?;
        let m = surface.n_nodes();
        let nodal = |name: &str, len: usize, what: &str| -> anyhow::Result<Vec<[f64; 3]>> {
            let v = ck.f64_n::<3>(name)?;
            if v.len() != len {
                return Err(fail(format!(
                    "`{name}` holds {} values, not one per {what} ({len})",
                    v.len()
                )));
            }
            Ok(v)
        };
        let [x_a, v_a, x_b, v_b, loads] =
            ["x_a", "v_a", "x_b", "v_b", "loads"].map(|name| nodal(name, m, "surface node"));
        let saved = Saved {
            t_a: meta.t_a,
            t_b: meta.t_b,
            x_a: x_a?,
            v_a: v_a?,
            x_b: x_b?,
            v_b: v_b?,
            sides,
            p_star: ck.f64_n::<2>("p_star")?,
            loads: loads?,
            clips: meta.clips,
            interface_work: meta.interface_work,
        };
        let kinematics = match (kinematics, meta.coupled) {
            (Kinematics::Law { .. }, Some(_)) => {
                return Err(fail(
                    "it was written by a coupled run; a fluid-alone run cannot continue it".into(),
                ))
            }
            (Kinematics::Law { .. }, None) => {
                // The motion law puts the surface exactly where the run left it.
                let (x, v) = kinematics.sample(meta.t_b);
                let off = |a: &[[f64; 3]], b: &[[f64; 3]]| {
                    a.iter().zip(b).position(|(p, q)| p.map(f64::to_bits) != q.map(f64::to_bits))
                };
                if let Some(k) = off(&x, &saved.x_b).or_else(|| off(&v, &saved.v_b)) {
                    return Err(fail(format!(
                        "at t = {:e} the case's [fluid.embedded] motion puts surface node {k} at \
                         {:?} with velocity {:?}, the checkpoint at {:?} with {:?}: the motion or \
                         the surface {changed}",
                        meta.t_b, x[k], v[k], saved.x_b[k], saved.v_b[k]
                    )));
                }
                None
            }
            (Kinematics::Coupled { .. }, None) => {
                return Err(fail("it was written by a fluid-alone run, not a coupled one".into()))
            }
            (Kinematics::Coupled { .. }, Some([t_a, t_b])) => {
                let [x_from, v_from, x_to, v_to] =
                    ["x_from", "v_from", "x_to", "v_to"].map(|name| nodal(name, m, "surface node"));
                Some(Kinematics::Coupled {
                    path: HermitePath { t_a, t_b },
                    x_from: x_from?,
                    v_from: v_from?,
                    x_to: x_to?,
                    v_to: v_to?,
                })
            }
        };
        Ok(Decoded { saved, kinematics, path: self.path.clone(), time: ck.time })
    }

    /// Status and sides of the `n` mesh nodes, each value checked.
    fn sides(&self, n: usize) -> anyhow::Result<NodeSides> {
        let ck = &self.ck;
        let fail = |m: String| anyhow::anyhow!("checkpoint `{}`: {m}", self.path.display());
        let (codes, side) = (ck.u8("status")?, ck.u32("side")?);
        let side_fluid: Vec<bool> = ck.u8("side_fluid")?.iter().map(|f| *f != 0).collect();
        if codes.len() != n || side.len() != n {
            return Err(fail(format!(
                "`status` and `side` hold {} and {} values, not one per mesh node ({n})",
                codes.len(),
                side.len()
            )));
        }
        let mut status = Vec::with_capacity(n);
        for (i, (&c, &s)) in codes.iter().zip(side).enumerate() {
            status.push(match c {
                0 => NodeStatus::Active,
                1 => NodeStatus::Occluded,
                2 => NodeStatus::Inactive,
                _ => return Err(fail(format!("`status` of node {i} is {c}, not 0, 1 or 2"))),
            });
            if s != NO_SIDE && s as usize >= side_fluid.len() {
                return Err(fail(format!(
                    "`side` of node {i} is {s}, but `side_fluid` holds {} sides",
                    side_fluid.len()
                )));
            }
        }
        let unsided = (0..n as u32).filter(|&i| side[i as usize] == NO_SIDE).collect();
        Ok(NodeSides { status, side: side.to_vec(), side_fluid, unsided })
    }
}

impl Decoded {
    /// Puts `run` (set up from the case at `t = 0` on `mesh`) in the checkpoint's state.
    pub fn restore(self, run: &mut EmbeddedRun, mesh: &Mesh) -> anyhow::Result<()> {
        let Decoded { saved, kinematics, path, time } = self;
        let fail = |m: String| anyhow::anyhow!("checkpoint `{}`: {m}", path.display());
        let n_cuts = saved.p_star.len();
        run.restore(saved, mesh).with_context(|| fail("its surface cannot be tracked".into()))?;
        if let Some(k) = kinematics {
            run.kinematics = k;
        }
        let t = &run.tracker;
        if n_cuts != t.cuts.cuts.len() {
            return Err(fail(format!(
                "`p_star` holds {n_cuts} cut edges, but the surface at t = {time:e} cuts {} edges \
                 of the case's mesh: the mesh or the surface changed since the checkpoint",
                t.cuts.cuts.len()
            )));
        }
        let occluded = |s: NodeStatus| s == NodeStatus::Occluded;
        if let Some(i) =
            (0..mesh.n_nodes()).find(|&i| occluded(t.sides.status[i]) != t.cuts.occluded[i])
        {
            return Err(fail(format!(
                "node {i} (x = {:?}) is {:?} in `status`, but the surface at t = {time:e} {} \
                 it: the mesh or the surface changed since the checkpoint",
                mesh.coords[i],
                t.sides.status[i],
                if t.cuts.occluded[i] { "occludes" } else { "does not occlude" }
            )));
        }
        Ok(())
    }
}
