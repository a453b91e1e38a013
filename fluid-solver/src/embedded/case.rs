//! `[fluid.embedded]` to a tracker, with errors naming the field.
//! - Fluid-alone runs ([`prescribed`]): the surface from its file or generator, its prescribed
//!   motion, the tracking algorithm, the loads algorithm and the flood-fill seeds.
//! - Coupled runs ([`from_structure`]): the surface comes from the structure over the protocol;
//!   `tracking`, `loads`, `seeds` and `p_cut` apply, `surface` and `motion` are refused. Without
//!   the section the defaults apply (Alg. 4.2, Alg. 5.3, the default seed).
//!
//! Without seeds the fluid is every node reached from the mesh node nearest to the first probe,
//! or else from the mesh's first node.

use super::generate::{generate, SurfaceMesh};
use super::motion::RigidMotion;
use super::tracker::{Seed, Tracker};
use super::Surface;
use crate::mesh::Mesh;
use interface_protocol::case::{
    Case, EmbeddedSurface, FluidEmbedded, InterfaceTreatment, LoadAlgorithm, Tracking,
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

/// A surface from the structure, tracked as the case says.
#[derive(Debug, Clone)]
pub struct FromStructure {
    pub tracker: Tracker,
    pub loads: LoadAlgorithm,
    /// Cavitation cut-off (`None`: each EOS's default).
    pub p_cut: Option<f64>,
    /// The states of the cut-edge fluxes (Alg. 5.1).
    pub interface: InterfaceTreatment,
}

fn field_error(case: &Case, field: &str, message: impl std::fmt::Display) -> anyhow::Error {
    case.field_error(field, message.to_string()).into()
}

fn section(case: &Case) -> Option<&FluidEmbedded> {
    case.fluid.as_ref().and_then(|f| f.embedded.as_ref())
}

/// The surface mesh of `[fluid.embedded] surface` (required in fluid-alone runs).
pub fn surface_mesh(case: &Case, e: &FluidEmbedded) -> anyhow::Result<SurfaceMesh> {
    match &e.surface {
        None => Err(field_error(
            case,
            "fluid.embedded.surface",
            "a fluid-alone run needs the surface: { file = \"surface.msh\" } or a generator \
             (plate, box, sphere, cylinder)",
        )),
        Some(EmbeddedSurface::Generated { generator }) => Ok(generate(generator)),
        Some(EmbeddedSurface::File { file }) => super::read::read(&case.dir().join(file))
            .map_err(|err| field_error(case, "fluid.embedded.surface.file", err)),
    }
}

/// The flood-fill seeds of the case: `[fluid.embedded] seeds`, or the default.
fn seeds(case: &Case, e: Option<&FluidEmbedded>, mesh: &Mesh) -> Vec<Seed> {
    let mut seeds: Vec<Seed> = e
        .map(|e| e.seeds.iter().map(|s| Seed { point: s.at, fluid: s.active }).collect())
        .unwrap_or_default();
    if seeds.is_empty() {
        let first_probe = case.fluid.as_ref().and_then(|f| f.probes.first());
        seeds.push(Seed { point: first_probe.map_or(mesh.coords[0], |p| p.at), fluid: true });
    }
    seeds
}

/// The tracker of `[fluid.embedded]` on `mesh` at `t0`, or `None` without that section.
pub fn prescribed(case: &Case, mesh: &Mesh, t0: f64) -> anyhow::Result<Option<Prescribed>> {
    let Some(e) = section(case) else {
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
    let tracker = Tracker::new(mesh, surface, e.tracking, &seeds(case, Some(e), mesh))
        .map_err(|err| field_error(case, "fluid.embedded.seeds", err))?;
    Ok(Some(Prescribed { tracker, motion, reference: s.x, loads: e.loads, interface: e.interface }))
}

/// Refuses the keys of `[fluid.embedded]` that only a fluid-alone run reads.
pub fn check_coupled(case: &Case) -> anyhow::Result<()> {
    let Some(e) = section(case) else {
        return Ok(());
    };
    let why = "a coupled run takes the surface and its motion from the structure over the \
               protocol; remove this key (it applies to fluid-alone runs)";
    if e.surface.is_some() {
        return Err(field_error(case, "fluid.embedded.surface", why));
    }
    if e.motion.is_some() {
        return Err(field_error(case, "fluid.embedded.motion", why));
    }
    Ok(())
}

/// The tracker of a surface the structure sent, at rest at `surface.t_b` with the velocities it
/// holds, with the case's tracking, loads, seeds and cut-off.
pub fn from_structure(case: &Case, mesh: &Mesh, surface: Surface) -> anyhow::Result<FromStructure> {
    check_coupled(case)?;
    let e = section(case);
    let tracking = e.map_or(Tracking::default(), |e| e.tracking);
    let tracker = Tracker::new(mesh, surface, tracking, &seeds(case, e, mesh))
        .map_err(|err| field_error(case, "fluid.embedded.seeds", err))?;
    Ok(FromStructure {
        tracker,
        loads: e.map_or(LoadAlgorithm::default(), |e| e.loads),
        p_cut: e.and_then(|e| e.p_cut),
        interface: e.map_or(InterfaceTreatment::default(), |e| e.interface),
    })
}

/// Positions and velocities at `t` of the points whose positions at `t = 0` are `reference`.
pub(crate) fn sample(
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
