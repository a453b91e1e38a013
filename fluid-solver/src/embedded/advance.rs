//! One fluid step with a prescribed embedded surface (DESIGN §5.1, "Each step"): the CFL step over
//! the active nodes, limited so that no surface node moves more than one fluid edge (thesis §4.4)
//! -> the surface at `t_b` -> tracking -> the uncovered nodes filled -> the two RK2 stages with the
//! walls -> `p*` and the nodal loads at `t_b` (Alg. 5.3 or 5.4), whose resultant force and moment
//! go to `surface_forces.csv`.

use super::case::Prescribed;
use super::fill::fill_changed;
use super::loads::{nodal_loads, LoadView};
use super::step::{EmbeddedStep, Wall};
use crate::mesh::geometry::{cross, norm};
use crate::semidiscretization::Semidiscretization;
use crate::state::{State, Workspace};
use crate::time::cfl::stable_time_step;
use crate::time::rk2::rk2_step_embedded;
use interface_protocol::case::InterfaceTreatment;
use interface_protocol::io::probes::ProbeWriter;
use std::path::Path;

/// The embedded surface of a fluid-alone run and what it reports.
pub struct EmbeddedRun {
    pub prescribed: Prescribed,
    /// Cavitation cut-off of the case (`None`: each EOS's default).
    pub p_cut: Option<f64>,
    /// Nodal loads at the end of the last step, in surface node order.
    pub loads: Vec<[f64; 3]>,
    /// Cavitation clips of `p*` counted in the loads passes.
    pub clips: u64,
    /// Seconds spent tracking (refit, intersect, sides, fill) and in the loads.
    pub tracking_s: f64,
    pub loads_s: f64,
    forces: ProbeWriter,
}

impl EmbeddedRun {
    /// Opens `surface_forces.csv` in `dir` (`time,surface.fx,...,surface.mz`: the resultant of the
    /// nodal loads on the structure and its moment about the origin).
    pub fn new(prescribed: Prescribed, p_cut: Option<f64>, dir: &Path) -> anyhow::Result<Self> {
        let forces = ProbeWriter::create(
            &dir.join("surface_forces.csv"),
            &["surface"],
            &["fx", "fy", "fz", "mx", "my", "mz"],
        )?;
        let loads = vec![[0.0; 3]; prescribed.tracker.surface.n_nodes()];
        Ok(EmbeddedRun {
            prescribed,
            p_cut,
            loads,
            clips: 0,
            tracking_s: 0.0,
            loads_s: 0.0,
            forces,
        })
    }

    /// One step from `t` of at most `dt_max` at Courant number `cfl`; returns the step taken.
    pub fn step(
        &mut self,
        semi: &Semidiscretization,
        state: &mut State,
        ws: &mut Workspace,
        cfl: f64,
        t: f64,
        dt_max: f64,
    ) -> anyhow::Result<f64> {
        let start = std::time::Instant::now();
        let mesh = &semi.mesh;
        stable_time_step(semi, &state.cons, ws)?;
        let tracker = &self.prescribed.tracker;
        let dt_cfl = ws
            .dt_node
            .iter()
            .zip(&tracker.active)
            .filter(|(_, a)| **a)
            .map(|(d, _)| *d)
            .fold(f64::INFINITY, f64::min);
        // Thesis §4.4: the surface moves at most half of its nearest edge in a step, from the speed
        // at the start of the step.
        let h = tracker.adjacency.h_min.iter().copied().fold(f64::INFINITY, f64::min);
        let speed = tracker.surface.v_b.iter().map(|v| norm(*v)).fold(0.0, f64::max);
        let dt_surface = if speed > 0.0 { 0.5 * h / speed } else { f64::INFINITY };
        let dt = (cfl * dt_cfl).min(dt_surface).min(dt_max);
        let (x, v) = self.prescribed.sample(t + dt);
        let was_active = tracker.active.clone();
        let tracker = &mut self.prescribed.tracker;
        let changes = tracker.advance(mesh, t + dt, &x, &v)?;
        let cut = tracker.cuts.cut_mask(mesh.n_edges());
        let material = semi.material();
        let filled = fill_changed(
            mesh,
            &tracker.adjacency,
            &changes,
            &tracker.sides,
            &was_active,
            &cut,
            &ws.prim,
            |i, j| material[i] == material[j],
            self.prescribed.interface == InterfaceTreatment::SecondOrder
                && semi.numerics.second_order(),
        )?;
        for (i, w) in filled {
            let i = i as usize;
            state.cons[i] = semi.eos_at(i).prim_to_cons(&w);
            ws.prim[i] = w;
        }
        let step = EmbeddedStep::new(semi, tracker, self.p_cut, self.prescribed.interface);
        self.tracking_s += start.elapsed().as_secs_f64();
        rk2_step_embedded(semi, state, ws, dt, &step, tracker)?;
        let start = std::time::Instant::now();
        semi.primitives(&state.cons, ws)?;
        if step.interface == InterfaceTreatment::SecondOrder {
            step.gradient.compute(mesh, &ws.prim, &mut ws.grad);
        }
        let wall = Wall { step: &step, tracker, t: t + dt };
        let (p_star, clips) = wall.pressures(semi, &ws.prim, &ws.grad)?;
        self.clips += clips as u64;
        let view = LoadView {
            mesh,
            surface: &tracker.surface,
            t: t + dt,
            side: &tracker.sides.side,
            cuts: &tracker.cuts.cuts,
            p_star: &p_star,
        };
        nodal_loads(self.prescribed.loads, &view, &mut self.loads)?;
        self.prescribed.tracker.p_star = p_star;
        let (mut f, mut m) = ([0.0; 3], [0.0; 3]);
        for (load, x) in self.loads.iter().zip(&x) {
            let r = cross(*x, *load);
            for k in 0..3 {
                f[k] += load[k];
                m[k] += r[k];
            }
        }
        self.forces.write_row(t + dt, &[f[0], f[1], f[2], m[0], m[1], m[2]])?;
        self.loads_s += start.elapsed().as_secs_f64();
        Ok(dt)
    }

    pub fn flush(&mut self) -> anyhow::Result<()> {
        Ok(self.forces.flush()?)
    }
}
