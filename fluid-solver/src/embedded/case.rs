//! `[fluid.embedded]` to a tracker (fluid-alone runs): the surface from its file or generator,
//! its prescribed motion, the tracking algorithm and the flood-fill seeds, with errors naming the
//! field. Without seeds the fluid is every node reached from the mesh node nearest to the first
//! probe, or else from the mesh's first node.

use super::generate::{generate, SurfaceMesh};
use super::motion::RigidMotion;
use super::tracker::{Seed, Tracker};
use super::Surface;
use crate::mesh::Mesh;
use interface_protocol::case::{
    Case, EmbeddedSurface, FluidEmbedded, InterfaceTreatment, LoadAlgorithm,
};

/// An embedded surface with its prescribed motion, ready to step.
#[derive(Debug, Clone)]
pub struct Prescribed {
    pub tracker: Tracker,
    /// `x(t) = motion(reference, t)`; no motion keeps the surface at rest.
    pub motion: Option<RigidMotion>,
    /// Surface node positions at `t = 0`.
    pub reference: Vec<[f64; 3]>,
    pub loads: LoadAlgorithm,
    /// The states of the cut-edge fluxes (Alg. 5.1, [`super::riemann_fs::interface`]).
    pub interface: InterfaceTreatment,
}

impl Prescribed {
    /// Positions and velocities of the surface nodes at `t`.
    pub fn sample(&self, t: f64) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
        sample(self.motion.as_ref(), &self.reference, t)
    }
}

fn field_error(case: &Case, field: &str, message: impl std::fmt::Display) -> anyhow::Error {
    case.field_error(field, message.to_string()).into()
}

/// The surface mesh of `[fluid.embedded] surface`.
pub fn surface_mesh(case: &Case, e: &FluidEmbedded) -> anyhow::Result<SurfaceMesh> {
    match &e.surface {
        EmbeddedSurface::Generated { generator } => Ok(generate(generator)),
        EmbeddedSurface::File { file } => super::read::read(&case.dir().join(file))
            .map_err(|err| field_error(case, "fluid.embedded.surface.file", err)),
    }
}

/// The tracker of `[fluid.embedded]` on `mesh` at `t0`, or `None` without that section.
pub fn prescribed(case: &Case, mesh: &Mesh, t0: f64) -> anyhow::Result<Option<Prescribed>> {
    let Some(e) = case.fluid.as_ref().and_then(|f| f.embedded.as_ref()) else {
        return Ok(None);
    };
    let s = surface_mesh(case, e)?;
    let motion = e.motion.clone().map(RigidMotion::new);
    let (x, v) = sample(motion.as_ref(), &s.x, t0);
    let mut surface = Surface::new(&s.elements, x, 0)
        .map_err(|err| field_error(case, "fluid.embedded.surface", err))?;
    // The motion's velocity at t0: the first step's Hermite path starts from it.
    surface.v_a.clone_from(&v);
    surface.v_b = v;
    surface.t_a = t0;
    surface.t_b = t0;
    let mut seeds: Vec<Seed> =
        e.seeds.iter().map(|s| Seed { point: s.at, fluid: s.active }).collect();
    if seeds.is_empty() {
        let first_probe = case.fluid.as_ref().and_then(|f| f.probes.first());
        seeds.push(Seed { point: first_probe.map_or(mesh.coords[0], |p| p.at), fluid: true });
    }
    let tracker = Tracker::new(mesh, surface, e.tracking, &seeds)
        .map_err(|err| field_error(case, "fluid.embedded.seeds", err))?;
    Ok(Some(Prescribed { tracker, motion, reference: s.x, loads: e.loads, interface: e.interface }))
}

/// Positions and velocities at `t` of the points whose positions at `t = 0` are `reference`.
fn sample(
    motion: Option<&RigidMotion>,
    reference: &[[f64; 3]],
    t: f64,
) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let mut x = reference.to_vec();
    let mut v = vec![[0.0; 3]; x.len()];
    if let Some(m) = motion {
        m.sample(reference, t, &mut x, &mut v);
    }
    (x, v)
}
