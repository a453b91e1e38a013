//! One fluid step with an embedded surface (DESIGN §5.1, "Each step"): the CFL step over the
//! active nodes, limited so that no surface node moves more than one fluid edge (thesis §4.4)
//! -> the surface at `t_b` from its [`Kinematics`] -> tracking -> the nodes that changed side take
//! their new side's fluid ([`super::side_fluid`]) and are filled -> the two RK2 stages with the
//! walls -> `p*` and the nodal loads at `t_b` (Alg. 5.3 or 5.4), whose resultant force and moment
//! go to `surface_forces.csv`. With a level set ([`LevelSetStep`], [`super::level_set`]) the
//! swept nodes also take a `φ` of their new side, `φ` advances with the two stages, and the nodes
//! whose `φ` changed sign then change fluid, as in [`crate::levelset`].
//!
//! The surface moves the same way whoever prescribes it: a fluid-alone run samples its motion
//! law at the end of every step; a coupled run samples the cubic Hermite path (DESIGN §4) between
//! the structure's `(x, v)` at the start of the coupling step (the fluid's own copy) and the
//! published `(x, v)` at its end, so the fluid subcycles inside the coupling step in its own CFL
//! steps and the last one lands on the published state exactly.

use super::case::{sample, Prescribed};
use super::checkpoint::Undo;
use super::fill::fill_changed;
use super::level_set::PhiWall;
use super::loads::{nodal_loads, LoadView};
use super::motion::RigidMotion;
use super::side_fluid::{side_materials, side_phi};
use super::step::{EmbeddedStep, Gradients, Wall};
use super::surface::HermitePath;
use super::swept::Swept;
use super::tracker::Tracker;
use crate::levelset::{LevelSet, LevelSetWorkspace};
use crate::mesh::geometry::{cross, norm};
use crate::semidiscretization::Semidiscretization;
use crate::state::{State, Workspace};
use crate::time::cfl::stable_time_step;
use crate::time::rk2::rk2_step_embedded;
use interface_protocol::case::{InterfaceTreatment, LoadAlgorithm};
use interface_protocol::io::probes::ProbeWriter;
use rayon::prelude::*;
use std::path::Path;

/// Where the surface's nodal states at the end of each fluid step come from.
#[derive(Debug, Clone)]
pub enum Kinematics {
    /// `[fluid.embedded] motion` (fluid-alone runs): `x(t) = motion(reference, t)`, exact at any
    /// time; no motion keeps the surface at rest at `reference`.
    Law { motion: Option<RigidMotion>, reference: Vec<[f64; 3]> },
    /// The structure over the protocol (coupled runs): the Hermite path from `(x_from, v_from)`
    /// at `path.t_a` to `(x_to, v_to)` at `path.t_b`, one coupling step.
    Coupled {
        path: HermitePath,
        x_from: Vec<[f64; 3]>,
        v_from: Vec<[f64; 3]>,
        x_to: Vec<[f64; 3]>,
        v_to: Vec<[f64; 3]>,
    },
}

impl Kinematics {
    /// Nodal positions and velocities at `t`.
    pub fn sample(&self, t: f64) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
        match self {
            Kinematics::Law { motion, reference } => sample(motion.as_ref(), reference, t),
            Kinematics::Coupled { path, x_from, v_from, x_to, v_to } => {
                (0..x_to.len()).map(|n| path.at(t, x_from[n], v_from[n], x_to[n], v_to[n])).unzip()
            }
        }
    }
}

/// The embedded surface of a run and what it reports.
pub struct EmbeddedRun {
    pub tracker: Tracker,
    pub kinematics: Kinematics,
    /// Alg. 5.3 or 5.4.
    pub load_algorithm: LoadAlgorithm,
    /// Cavitation cut-off of the case (`None`: each EOS's default).
    pub p_cut: Option<f64>,
    /// The states of the cut-edge fluxes (Alg. 5.1, [`super::riemann_fs::interface`]).
    pub interface: InterfaceTreatment,
    /// Nodal loads at the end of the last step, in surface node order.
    pub loads: Vec<[f64; 3]>,
    /// Cavitation clips of `p*` counted in the loads passes.
    pub clips: u64,
    /// The work of the nodal loads on the surface since t = 0 along its motion, the fluid's half
    /// of the interface energy balance (PROTOCOL.md §3, `interface_work`): each step from `t_a`
    /// to `t_b` adds `Σ_nodes (f_a + f_b)/2 · (x_b - x_a)`, the trapezoidal rule along the path
    /// the surface took (the Hermite path, coupled).
    pub interface_work: f64,
    /// Seconds spent tracking (refit, intersect, sides, fill) and in the loads.
    pub tracking_s: f64,
    pub loads_s: f64,
    /// Seconds in the special edges' fluxes (cut and frozen; two-material ones with a level set),
    /// summed over threads ([`super::step::FluxClock`]).
    pub wall_flux_s: f64,
    /// The fluid mass over the steps taken ([`MassBalance`]).
    pub mass: MassBalance,
    forces: ProbeWriter,
    /// The last step's view of the boundary, updated from step to step.
    step: Option<EmbeddedStep>,
    /// The edges of the last step's `φ` (with a level set).
    phi_wall: Option<PhiWall>,
}

/// The mass balance of the steps a run took with the surface (`run.json`'s `surface` section):
/// `M = Σ |C_i| ρ_i` over the active nodes before the first step and after the last, the mass
/// that left through the domain's boundary, and the mass the surface created, `Σ_steps (M_after -
/// M_before + outflow)`: the nodes that change status (covered ones leave `M` with their state,
/// uncovered ones join it filled) and what the cut-edge fluxes do not conserve. A restarted run
/// counts from its restart.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct MassBalance {
    pub start: Option<f64>,
    pub end: f64,
    pub outflow: f64,
    pub change: f64,
}

/// `Σ |C_i| ρ_i` over the nodes with `active[i]`, summed by fixed chunks (the same for any
/// number of threads).
pub fn active_mass(semi: &Semidiscretization, cons: &[[f64; 5]], active: &[bool]) -> f64 {
    let volumes = &semi.mesh.volumes;
    let chunk = |c: usize| {
        let range = c * MASS_CHUNK..((c + 1) * MASS_CHUNK).min(cons.len());
        range.filter(|&i| active[i]).map(|i| volumes[i] * cons[i][0]).sum::<f64>()
    };
    let sums: Vec<f64> = (0..cons.len().div_ceil(MASS_CHUNK)).into_par_iter().map(chunk).collect();
    sums.iter().sum()
}

/// Nodes per partial sum of [`active_mass`].
const MASS_CHUNK: usize = 8192;

/// The level set of a step with the surface: its settings and scratch, and the number of this
/// step from 1 (for the reinitialisation).
pub struct LevelSetStep<'a> {
    pub level_set: &'a LevelSet,
    pub lws: &'a mut LevelSetWorkspace,
    pub step_number: u64,
}

impl EmbeddedRun {
    /// The surface of `[fluid.embedded]` with its prescribed motion; opens `surface_forces.csv`
    /// in `dir`.
    pub fn new(prescribed: Prescribed, p_cut: Option<f64>, dir: &Path) -> anyhow::Result<Self> {
        let Prescribed { tracker, motion, reference, loads, interface } = prescribed;
        let kinematics = Kinematics::Law { motion, reference };
        EmbeddedRun::with(tracker, kinematics, loads, interface, p_cut, dir)
    }

    /// A surface moved by `kinematics`, its loads by `load_algorithm`; opens
    /// `surface_forces.csv` in `dir` (`time,surface.fx,...,surface.mz`: the resultant of the
    /// nodal loads on the structure and its moment about the origin).
    pub fn with(
        tracker: Tracker,
        kinematics: Kinematics,
        load_algorithm: LoadAlgorithm,
        interface: InterfaceTreatment,
        p_cut: Option<f64>,
        dir: &Path,
    ) -> anyhow::Result<Self> {
        let forces = ProbeWriter::create(
            &dir.join("surface_forces.csv"),
            &["surface"],
            &["fx", "fy", "fz", "mx", "my", "mz"],
        )?;
        let loads = vec![[0.0; 3]; tracker.surface.n_nodes()];
        Ok(EmbeddedRun {
            tracker,
            kinematics,
            load_algorithm,
            p_cut,
            interface,
            loads,
            clips: 0,
            interface_work: 0.0,
            tracking_s: 0.0,
            loads_s: 0.0,
            wall_flux_s: 0.0,
            mass: MassBalance::default(),
            forces,
            step: None,
            phi_wall: None,
        })
    }

    /// One step from `t` at Courant number `cfl` that does not pass `stop` (a step that reaches
    /// it ends on it exactly), with the level set `level_set` if any; returns the step taken. A
    /// step that fails leaves the run, `state` (level set included) and the node materials as
    /// they were ([`super::checkpoint`]).
    #[allow(clippy::too_many_arguments)]
    pub fn step(
        &mut self,
        semi: &mut Semidiscretization,
        state: &mut State,
        ws: &mut Workspace,
        cfl: f64,
        t: f64,
        stop: f64,
        level_set: Option<LevelSetStep<'_>>,
    ) -> anyhow::Result<f64> {
        let saved = self.save();
        let mut undo = Undo::default();
        if level_set.is_some() {
            // The level set and its materials change all over the step: keep them whole.
            undo.material = Some(state.material.clone());
            undo.phi = Some(state.phi.clone());
        }
        let result = self.try_step(semi, state, ws, cfl, t, stop, level_set, &mut undo);
        if result.is_err() {
            self.phi_wall = None;
            self.roll_back(saved, undo, semi, state, ws)
                .map_err(|e| anyhow::anyhow!("the failed step could not be undone: {e:#}"))?;
        }
        result
    }

    /// [`EmbeddedRun::step`] recording in `undo` what it changes in the fluid state.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn try_step(
        &mut self,
        semi: &mut Semidiscretization,
        state: &mut State,
        ws: &mut Workspace,
        cfl: f64,
        t: f64,
        stop: f64,
        mut level_set: Option<LevelSetStep<'_>>,
        undo: &mut Undo,
    ) -> anyhow::Result<f64> {
        stable_time_step(semi, &state.cons, ws)?;
        let mass_before = active_mass(semi, &state.cons, &self.tracker.active);
        let tracker = &self.tracker;
        let dt_cfl = ws
            .dt_node
            .par_iter()
            .zip(&tracker.active)
            .filter(|(_, a)| **a)
            .map(|(d, _)| *d)
            .reduce(|| f64::INFINITY, f64::min);
        // Thesis §4.4: the surface moves at most half of its nearest edge in a step, from the speed
        // at the start of the step.
        let h = tracker.adjacency.h_min.iter().copied().fold(f64::INFINITY, f64::min);
        let speed = tracker.surface.v_b.iter().map(|v| norm(*v)).fold(0.0, f64::max);
        let dt_surface = if speed > 0.0 { 0.5 * h / speed } else { f64::INFINITY };
        let dt = (cfl * dt_cfl).min(dt_surface).min(stop - t);
        let t_b = if dt >= stop - t { stop } else { t + dt };
        // Tracking: from the surface at t_b to the step's view (the CFL step is the fluid's).
        let start = std::time::Instant::now();
        let (x, v) = self.kinematics.sample(t_b);
        let x_a = tracker.surface.x_b.clone();
        let was_active = tracker.active.clone();
        let tracker = &mut self.tracker;
        let changes = tracker.advance(&semi.mesh, t_b, &x, &v)?;
        let swept = Swept::new(&semi.mesh, tracker, &changes, &was_active);
        let changed_fluid = side_materials(&swept, semi.material());
        // The swept nodes' fluids, level set and states, from their sources before the step.
        let material = changed_fluid.as_deref().unwrap_or(semi.material());
        if let Some(ls) = &level_set {
            for (i, p) in side_phi(&swept, material, &state.phi) {
                state.phi[i] = p;
            }
            debug_assert!(ls
                .level_set
                .check(&State { material: material.to_vec(), ..state.clone() })
                .is_ok());
        }
        let filled = fill_changed(
            &swept,
            &ws.prim,
            |i, j| material[i] == material[j],
            self.interface == InterfaceTreatment::SecondOrder && semi.numerics.second_order(),
        )?;
        if let Some(material) = changed_fluid {
            semi.set_materials(material.clone())?;
            let before = std::mem::replace(&mut state.material, material);
            undo.material.get_or_insert(before);
            // Nodes that changed fluid change the mask of uncut edges too: a new view.
            self.step = None;
        }
        for (i, w) in filled {
            let i = i as usize;
            undo.filled.push((i, state.cons[i]));
            state.cons[i] = semi.eos_at(i).prim_to_cons(&w);
            ws.prim[i] = w;
        }
        // The view is updated in place (bitwise a new one); a failed step leaves none behind.
        let mut step = match self.step.take() {
            Some(mut step) => {
                step.update(semi, tracker);
                step
            }
            None => EmbeddedStep::new(semi, tracker, self.p_cut, self.interface),
        };
        let phi_wall = match (&level_set, self.phi_wall.take()) {
            (None, _) => None,
            (Some(_), Some(mut w)) => {
                w.update(&semi.mesh, tracker);
                Some(w)
            }
            (Some(ls), None) => Some(PhiWall::new(&semi.mesh, ls.level_set, tracker)),
        };
        self.tracking_s += start.elapsed().as_secs_f64();
        let advection = match (&mut level_set, &phi_wall) {
            (Some(ls), Some(w)) => Some((w.advection(ls.level_set), &mut *ls.lws)),
            _ => None,
        };
        let outflow = rk2_step_embedded(semi, state, ws, dt, &step, tracker, advection)?;
        undo.stepped = true;
        if let (Some(ls), Some(w)) = (level_set, &phi_wall) {
            let LevelSetStep { level_set, lws, step_number } = ls;
            let through = Some(&w.through[..]);
            let (changed, _) =
                level_set.after_flow(semi, state, lws, &w.gradient, through, step_number)?;
            if changed > 0 {
                // The special edges and the flow's gradient mask follow the new materials.
                step = EmbeddedStep::new(semi, tracker, self.p_cut, self.interface);
            }
        }
        self.phi_wall = phi_wall;
        let semi = &*semi;
        let start = std::time::Instant::now();
        semi.primitives(&state.cons, ws)?;
        if step.interface == InterfaceTreatment::SecondOrder {
            // `p*` reads the gradients at the active ends of the cut edges only.
            let nodes = self.tracker.cut_edge_ends(&semi.mesh);
            let edges_of = |i| self.tracker.adjacency.edges_of(i);
            step.gradient.compute_at(&semi.mesh, &ws.prim, &nodes, edges_of, &mut ws.grad);
        }
        self.wall_pressures(semi, &step, &ws.prim, &ws.grad)?;
        self.step = Some(step);
        let loads_a = std::mem::take(&mut self.loads);
        let mut loads = loads_a.clone();
        // A new topology may add surface nodes.
        loads.resize(self.tracker.surface.n_nodes(), [0.0; 3]);
        self.write_loads(semi, &mut loads)?;
        // Nodes a new topology added this step start where they were published: no work yet.
        self.interface_work += (0..x_a.len().min(loads_a.len()))
            .map(|n| {
                (0..3)
                    .map(|k| 0.5 * (loads_a[n][k] + loads[n][k]) * (x[n][k] - x_a[n][k]))
                    .sum::<f64>()
            })
            .sum::<f64>();
        self.loads = loads;
        let (mut f, mut m) = ([0.0; 3], [0.0; 3]);
        for (load, x) in self.loads.iter().zip(&x) {
            let r = cross(*x, *load);
            for k in 0..3 {
                f[k] += load[k];
                m[k] += r[k];
            }
        }
        self.forces.write_row(t_b, &[f[0], f[1], f[2], m[0], m[1], m[2]])?;
        self.loads_s += start.elapsed().as_secs_f64();
        if let Some(step) = &self.step {
            self.wall_flux_s += step.wall_flux_clock.take_seconds();
        }
        let mass_after = active_mass(semi, &state.cons, &self.tracker.active);
        let mass = &mut self.mass;
        mass.start.get_or_insert(mass_before);
        mass.end = mass_after;
        mass.outflow += outflow;
        mass.change += mass_after - mass_before + outflow;
        Ok(dt)
    }

    /// `p*` at every cut edge from the primitive states `prim` and their gradients `grad` (read
    /// by the second-order interface only) at the surface's current time (`t_b`), kept in the
    /// tracker for the loads; counts the cavitation clips.
    fn wall_pressures(
        &mut self,
        semi: &Semidiscretization,
        step: &EmbeddedStep,
        prim: &[[f64; 5]],
        grad: &Gradients,
    ) -> anyhow::Result<()> {
        let wall = Wall { step, tracker: &self.tracker, t: self.tracker.surface.t_b };
        let (p_star, clips) = wall.pressures(semi, prim, grad)?;
        self.clips += clips as u64;
        self.tracker.p_star = p_star;
        Ok(())
    }

    /// `p*` and the nodal loads at the current state, before any step (the coupled run's load
    /// at `Init`).
    pub fn start_pressures(
        &mut self,
        semi: &Semidiscretization,
        prim: &[[f64; 5]],
    ) -> anyhow::Result<()> {
        let step = EmbeddedStep::new(semi, &self.tracker, self.p_cut, self.interface);
        let mut grad = vec![[[0.0; 3]; 5]; prim.len()];
        if step.interface == InterfaceTreatment::SecondOrder {
            step.gradient.compute(&semi.mesh, prim, &mut grad);
        }
        self.wall_pressures(semi, &step, prim, &grad)?;
        // The loads at the start, from which the first step's work is counted.
        let mut loads = std::mem::take(&mut self.loads);
        self.write_loads(semi, &mut loads)?;
        self.loads = loads;
        Ok(())
    }

    /// The nodal loads on the structure (Alg. 5.3 or 5.4, both sides of a shell summed) at the
    /// surface's current time from the last `p*`, written into `out` in surface node order (the
    /// protocol's order in a coupled run).
    pub fn write_loads(
        &self,
        semi: &Semidiscretization,
        out: &mut [[f64; 3]],
    ) -> anyhow::Result<()> {
        let tracker = &self.tracker;
        let view = LoadView {
            mesh: &semi.mesh,
            adjacency: &tracker.adjacency,
            surface: &tracker.surface,
            t: tracker.surface.t_b,
            side: &tracker.sides.side,
            cuts: &tracker.cuts.cuts,
            p_star: &tracker.p_star,
        };
        Ok(nodal_loads(self.load_algorithm, &view, out)?)
    }

    /// The step view of the last step (`None` before the first step, after a restore and after a
    /// change of node materials: the next step builds it anew).
    pub fn view(&self) -> Option<&EmbeddedStep> {
        self.step.as_ref()
    }

    pub(super) fn clear_view(&mut self) {
        self.step = None;
    }

    pub fn flush(&mut self) -> anyhow::Result<()> {
        Ok(self.forces.flush()?)
    }
}
