//! From a case's `[fluid]` section to a ready problem: mesh, EOS, scheme, boundary conditions,
//! initial state, probes and lines. Errors name the case field (`fluid.<...>`) and what was
//! expected.

use crate::bc::BoundaryCondition;
use crate::eos::Eos;
use crate::flux::FluxScheme;
use crate::initial::InitialCondition;
use crate::mesh::boxmesh::{BoxCells, BoxSpec};
use crate::mesh::{gmsh, Mesh};
use crate::reconstruct::limiter::Limiter;
use crate::semidiscretization::{Numerics, Semidiscretization};
use crate::state::State;
use crate::time::TimeStepping;
use interface_protocol::case::{
    BoxShape, Case, FluidBoundary, FluidLine, FluidProbe, FluidSection,
};

/// Everything a stand-alone run needs.
#[derive(Debug, Clone)]
pub struct Problem {
    pub semi: Semidiscretization,
    pub initial: State,
    pub stepping: TimeStepping,
    pub t_end: f64,
    pub max_steps: Option<u64>,
    pub probes: Vec<FluidProbe>,
    pub lines: Vec<FluidLine>,
}

fn field_error(case: &Case, field: &str, message: impl std::fmt::Display) -> anyhow::Error {
    anyhow::anyhow!("{}: field `{field}`: {message}", case.source.path.display())
}

/// The `[fluid]` section, or an error saying it is needed.
pub fn section(case: &Case) -> anyhow::Result<&FluidSection> {
    case.fluid
        .as_ref()
        .ok_or_else(|| field_error(case, "fluid", "fluid-solver needs a [fluid] section"))
}

/// Builds the mesh of `[fluid.mesh]`.
pub fn mesh(case: &Case) -> anyhow::Result<Mesh> {
    let f = section(case)?;
    let m = f.mesh.as_ref().ok_or_else(|| {
        field_error(case, "fluid.mesh", "missing: give `box = {...}` or `file = \"mesh.msh\"`")
    })?;
    let raw = match (&m.box_mesh, &m.file) {
        (Some(b), _) => BoxSpec {
            lo: b.lo,
            hi: b.hi,
            cells: b.cells,
            grading: b.grading,
            shape: match b.shape {
                BoxShape::Hex => BoxCells::Hex,
                BoxShape::Tet => BoxCells::Tet,
            },
        }
        .raw()
        .map_err(|e| field_error(case, "fluid.mesh.box", e))?,
        (None, Some(file)) => {
            let path = case.dir().join(file);
            gmsh::read(&path).map_err(|e| field_error(case, "fluid.mesh.file", e))?
        }
        (None, None) => {
            return Err(field_error(
                case,
                "fluid.mesh",
                "give `box = {...}` or `file = \"mesh.msh\"`",
            ))
        }
    };
    Mesh::build(raw).map_err(|e| field_error(case, "fluid.mesh", e))
}

/// The EOS of `fluid.eos`.
pub fn eos(case: &Case) -> anyhow::Result<Eos> {
    let f = section(case)?;
    let v = f.eos.clone().ok_or_else(|| {
        field_error(
            case,
            "fluid.eos",
            "missing: e.g. eos = { kind = \"perfect_gas\", gamma = 1.4 }",
        )
    })?;
    v.try_into::<Eos>().map_err(|e| field_error(case, "fluid.eos", e.message().trim()))
}

/// The spatial scheme of `[fluid.numerics]`.
pub fn numerics(case: &Case) -> anyhow::Result<Numerics> {
    let n = &section(case)?.numerics;
    let flux: FluxScheme =
        toml::Value::String(n.flux.clone()).try_into().map_err(|e: toml::de::Error| {
            field_error(case, "fluid.numerics.flux", e.message().trim())
        })?;
    let limiter: Limiter =
        toml::Value::String(n.limiter.clone()).try_into().map_err(|e: toml::de::Error| {
            field_error(case, "fluid.numerics.limiter", e.message().trim())
        })?;
    Ok(Numerics { flux, limiter })
}

/// Builds the whole problem.
pub fn problem(case: &Case) -> anyhow::Result<Problem> {
    let f = section(case)?;
    let mesh = mesh(case)?;
    let eos = eos(case)?;
    let numerics = numerics(case)?;
    let mut conditions = Vec::new();
    for (name, b) in &f.boundary {
        if !mesh.boundaries.iter().any(|m| &m.name == name) {
            return Err(field_error(
                case,
                &format!("fluid.boundary.{name}"),
                format!(
                    "the mesh has no boundary `{name}`; its boundaries are: {}",
                    mesh.boundary_names().join(", ")
                ),
            ));
        }
        let check = |w: &[f64; 5]| {
            eos.check(w).map_err(|e| field_error(case, &format!("fluid.boundary.{name}.state"), e))
        };
        let bc = match *b {
            FluidBoundary::SlipWall => BoundaryCondition::SlipWall,
            FluidBoundary::Symmetry => BoundaryCondition::Symmetry,
            FluidBoundary::FarField { state } => {
                check(&state)?;
                BoundaryCondition::FarField { state }
            }
            FluidBoundary::Inflow { state } => {
                check(&state)?;
                BoundaryCondition::Inflow { state }
            }
            FluidBoundary::Outflow { pressure } => BoundaryCondition::Outflow { pressure },
        };
        conditions.push((name.clone(), bc));
    }
    let init = f.initial.as_ref().ok_or_else(|| {
        field_error(case, "fluid.initial", "missing: give `state = [ρ, u, v, w, p]`")
    })?;
    let ic = InitialCondition {
        background: init.state,
        regions: init.regions.iter().map(|r| (r.region, r.state)).collect(),
    };
    let initial = ic
        .state(&mesh, &eos)
        .map_err(|e| anyhow::anyhow!("{}: {e}", case.source.path.display()))?;
    let semi = Semidiscretization::new(mesh, eos, numerics, &conditions)
        .map_err(|e| field_error(case, "fluid.boundary", e))?;
    let time =
        f.time.as_ref().ok_or_else(|| field_error(case, "fluid.time", "missing: give `t_end`"))?;
    let cfl = f.numerics.cfl;
    let stepping = if f.numerics.local_time_step {
        TimeStepping::Local { cfl }
    } else {
        TimeStepping::Global { cfl }
    };
    Ok(Problem {
        semi,
        initial,
        stepping,
        t_end: time.t_end,
        max_steps: time.max_steps,
        probes: f.probes.clone(),
        lines: f.lines.clone(),
    })
}
