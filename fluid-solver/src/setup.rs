//! From a case's `[fluid]` section to a ready problem: everything a run does before its first
//! step, shared by `run` (alone and coupled) and `check` so that they cannot drift. The mesh
//! (refused before it is built if it cannot fit in memory), the EOS table of the fluids, scheme,
//! boundary conditions (each state admissible for every fluid on its boundary), initial state and
//! node materials (every state admissible for its own fluid's EOS, every region holding a node),
//! probes and lines (inside the mesh; a line time after the end is a warning), and the initial CFL
//! step (a run that would take more than `resources::MAX_STEPS` steps is refused). Errors name the
//! case field (`fluid.<...>`) and what was expected.

use crate::bc::BoundaryCondition;
use crate::eos::Eos;
use crate::flux::FluxScheme;
use crate::initial::{Fill, InitialCondition};
use crate::levelset::{init, LevelSet};
use crate::memory;
use crate::mesh::boxmesh::{BoxCells, BoxSpec};
use crate::mesh::octant::OctantSpec;
use crate::mesh::{gmsh, Mesh};
use crate::probes::{self, Placed};
use crate::reconstruct::limiter::Limiter;
use crate::semidiscretization::{Numerics, Semidiscretization};
use crate::state::{MaterialId, State, Workspace};
use crate::time::cfl::stable_time_step;
use crate::time::{reached, TimeStepping};
use interface_protocol::case::{BoxShape, Case, FluidBoundary, FluidProbe, FluidSection};
use interface_protocol::resources;

/// Whether the fluid runs alone or as a participant of a coupled run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Alone: creates its output folder, draws a progress bar, stops at `fluid.time.t_end` or
    /// `max_steps`, checkpoints every `output.checkpoint_every` steps and writes `run.json`.
    Alone,
    /// Coupled (DESIGN §7): the launcher made the output folder, drives the time with its
    /// `Advance` commands to `coupling.t_end`, asks for checkpoints and writes `run.json` itself;
    /// `[fluid.time]` is not used.
    Coupled,
}

/// Everything a run needs.
#[derive(Debug, Clone)]
pub struct Problem {
    pub semi: Semidiscretization,
    /// The name of each fluid, by material id.
    pub fluid_names: Vec<String>,
    pub initial: State,
    pub stepping: TimeStepping,
    /// The end of the run: `fluid.time.t_end` alone, `coupling.t_end` coupled.
    pub t_end: f64,
    /// `fluid.time.max_steps` (alone only).
    pub max_steps: Option<u64>,
    /// `fluid.time.substeps`: equal steps per coupling interval (coupled only).
    pub substeps: Option<u64>,
    pub probes: Vec<FluidProbe>,
    /// The probes and lines on the mesh.
    pub placed: Placed,
    /// The first step: the CFL step of the initial state.
    pub dt_initial: f64,
    /// What the case asks for that the run will not do (e.g. a line time after the end).
    pub warnings: Vec<String>,
    /// The moving interface of `[fluid.level_set]` (the initial state then holds `φ`).
    pub level_set: Option<LevelSet>,
}

/// An error naming the case file, the line of `field` and the field.
fn field_error(case: &Case, field: &str, message: impl std::fmt::Display) -> anyhow::Error {
    case.field_error(field, message.to_string()).into()
}

/// The `[fluid]` section, or an error saying it is needed.
pub fn section(case: &Case) -> anyhow::Result<&FluidSection> {
    case.fluid
        .as_ref()
        .ok_or_else(|| field_error(case, "fluid", "fluid-solver needs a [fluid] section"))
}

/// Builds the mesh of `[fluid.mesh]`, first refusing one this machine cannot hold.
pub fn mesh(case: &Case) -> anyhow::Result<Mesh> {
    let f = section(case)?;
    let m = f.mesh.as_ref().ok_or_else(|| {
        field_error(
            case,
            "fluid.mesh",
            "missing: give `box = {...}`, `octant = {...}` or `file = \"mesh.msh\"`",
        )
    })?;
    let raw = match (&m.box_mesh, &m.octant, &m.file) {
        (Some(b), _, _) => {
            let key = "fluid.mesh.box.cells";
            let per_hex = match b.shape {
                BoxShape::Hex => 1.0,
                BoxShape::Tet => 6.0,
            };
            let nodes: f64 = b.cells.iter().map(|&c| c as f64 + 1.0).product();
            let cells: f64 = per_hex * b.cells.iter().map(|&c| c as f64).product::<f64>();
            let what = format!("the fluid mesh of `{key} = {:?}`", b.cells);
            memory::ensure_fits(&what, nodes, cells).map_err(|e| field_error(case, key, e))?;
            if nodes > u32::MAX as f64 {
                return Err(field_error(
                    case,
                    key,
                    format!(
                        "{:?} makes {nodes:.3e} nodes, more than the {} a fluid mesh numbers",
                        b.cells,
                        u32::MAX
                    ),
                ));
            }
            BoxSpec {
                lo: b.lo,
                hi: b.hi,
                cells: b.cells,
                grading: b.grading,
                core: b.core,
                shape: match b.shape {
                    BoxShape::Hex => BoxCells::Hex,
                    BoxShape::Tet => BoxCells::Tet,
                },
            }
            .raw()
            .map_err(|e| field_error(case, "fluid.mesh.box", e))?
        }
        (None, Some(o), _) => {
            let spec = OctantSpec::from(o);
            let (nodes, cells) = spec.size();
            let what = format!("the fluid mesh of `fluid.mesh.octant` ({nodes} nodes)");
            memory::ensure_fits(&what, nodes as f64, cells as f64)
                .map_err(|e| field_error(case, "fluid.mesh.octant.cells", e))?;
            spec.raw().map_err(|e| field_error(case, "fluid.mesh.octant", e))?
        }
        (None, None, Some(file)) => {
            let path = case.dir().join(file);
            let raw = gmsh::read(&path).map_err(|e| field_error(case, "fluid.mesh.file", e))?;
            let what = format!("the fluid mesh of `fluid.mesh.file = {file:?}`");
            memory::ensure_fits(&what, raw.coords.len() as f64, raw.cells.len() as f64)
                .map_err(|e| field_error(case, "fluid.mesh.file", e))?;
            raw
        }
        (None, None, None) => {
            return Err(field_error(
                case,
                "fluid.mesh",
                "give `box = {...}`, `octant = {...}` or `file = \"mesh.msh\"`",
            ))
        }
    };
    Mesh::build(raw).map_err(|e| field_error(case, "fluid.mesh", e))
}

/// The fluids of `fluid.eos` or `[fluid.fluids]`: their names and the EOS table, by material id.
pub fn fluids(case: &Case) -> anyhow::Result<(Vec<String>, Vec<Eos>)> {
    let f = section(case)?;
    let materials = f.materials();
    if materials.is_empty() {
        return Err(field_error(
            case,
            "fluid.eos",
            "missing: e.g. eos = { kind = \"perfect_gas\", gamma = 1.4 }, or named fluids \
             [fluid.fluids.<name>] with an eos each",
        ));
    }
    let mut names = Vec::new();
    let mut table = Vec::new();
    for m in materials {
        let eos = m
            .eos
            .clone()
            .try_into::<Eos>()
            .map_err(|e| field_error(case, &m.eos_field, e.message().trim()))?;
        names.push(m.name.to_string());
        table.push(eos);
    }
    Ok((names, table))
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

/// Builds the whole problem for a run in `mode`: everything before the first step.
pub fn problem(case: &Case, mode: Mode) -> anyhow::Result<Problem> {
    let f = section(case)?;
    let mesh = mesh(case)?;
    let (fluid_names, table) = fluids(case)?;
    let numerics = numerics(case)?;
    let init = f.initial.as_ref().ok_or_else(|| {
        field_error(case, "fluid.initial", "missing: give `state = [ρ, u, v, w, p]`")
    })?;
    // Reading the case checked the names (this is its message for a case built otherwise).
    let (background, region_ids) = f.initial_materials().ok_or_else(|| {
        field_error(case, "fluid.initial.fluid", "an unknown or missing fluid name")
    })?;
    let id = |m: usize| m as MaterialId;
    let ic = InitialCondition {
        background: Fill { state: init.state, material: id(background) },
        regions: init
            .regions
            .iter()
            .zip(region_ids)
            .map(|(r, m)| (r.region, Fill { state: r.state, material: id(m) }))
            .collect(),
    };
    let mut initial =
        ic.state(&mesh, &table).map_err(|(field, message)| field_error(case, &field, message))?;
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
        // The fluids initially on this boundary: each must admit its state.
        let index = mesh.boundaries.iter().position(|m| &m.name == name).expect("found above");
        let mut present = vec![false; table.len()];
        for &i in &mesh.boundaries[index].nodes {
            present[initial.material[i as usize] as usize] = true;
        }
        let on_boundary: Vec<(usize, &Eos)> =
            table.iter().enumerate().filter(|(m, _)| present[*m]).collect();
        let whose = |m: usize| match table.len() {
            1 => String::new(),
            _ => format!(" (for fluid `{}` on this boundary)", fluid_names[m]),
        };
        let check = |w: &[f64; 5]| {
            for &(m, eos) in &on_boundary {
                eos.check_input(w).map_err(|e| {
                    field_error(
                        case,
                        &format!("fluid.boundary.{name}.state"),
                        format!("{e}{}", whose(m)),
                    )
                })?;
            }
            Ok::<(), anyhow::Error>(())
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
            FluidBoundary::Outflow { pressure } => {
                for &(m, eos) in &on_boundary {
                    let p_min = eos.min_pressure();
                    let admitted =
                        if eos.is_barotropic() { pressure >= p_min } else { pressure > p_min };
                    if !admitted {
                        return Err(field_error(
                            case,
                            &format!("fluid.boundary.{name}.pressure"),
                            format!(
                                "{pressure} is at or below the lowest pressure {p_min} the EOS \
                                 admits{}",
                                whose(m)
                            ),
                        ));
                    }
                }
                BoundaryCondition::Outflow { pressure }
            }
        };
        conditions.push((name.clone(), bc));
    }
    let placed = probes::place(&mesh, &f.probes, &f.lines)
        .map_err(|(field, message)| field_error(case, &field, message))?;
    let semi = Semidiscretization::with_materials(
        mesh,
        table,
        initial.material.clone(),
        numerics,
        &conditions,
    )
    .map_err(|e| field_error(case, "fluid.boundary", e))?;
    // The level set: the background's fluid where φ < 0, the other where φ >= 0.
    let level_set = match &f.level_set {
        Some(l) => {
            let other = (0..semi.eos.len()).find(|&m| m != background).ok_or_else(|| {
                field_error(case, "fluid.level_set", "a level set needs two fluids")
            })?;
            let ls = LevelSet::new(&semi, [id(background), id(other)], l.reinit_every);
            initial.phi = init::signed_distance(&semi.mesh, &ls, &ic, &initial.material);
            Some(ls)
        }
        None => None,
    };
    let (t_end, end_key, max_steps) = match mode {
        Mode::Alone => {
            let time = f.time.as_ref().ok_or_else(|| {
                field_error(case, "fluid.time", "missing: give `t_end` (a run alone needs it)")
            })?;
            let t_end = time.t_end.ok_or_else(|| {
                field_error(case, "fluid.time.t_end", "missing: a run alone needs its end time")
            })?;
            (t_end, "fluid.time.t_end", time.max_steps)
        }
        Mode::Coupled => (case.coupling.t_end, "coupling.t_end", None),
    };
    let substeps = f.time.as_ref().and_then(|t| t.substeps);
    // A run shortened with `--set` may end before a sample it asks for: said, not refused.
    let mut warnings = Vec::new();
    let substeps = match (mode, substeps) {
        (Mode::Alone, Some(m)) => {
            let message = format!(
                "{m} steps per coupling interval apply to coupled runs; a run alone takes its \
                 CFL steps"
            );
            warnings.push(case.field_error("fluid.time.substeps", message).to_string());
            None
        }
        (_, m) => m,
    };
    for (k, l) in f.lines.iter().enumerate() {
        for (j, &lt) in l.times.iter().enumerate().filter(|(_, &lt)| !reached(t_end, lt)) {
            let message = format!(
                "{lt} is after the end of the run ({end_key} = {t_end}): that sample will not be \
                 written"
            );
            warnings.push(
                case.field_error(&format!("fluid.lines[{k}].times[{j}]"), message).to_string(),
            );
        }
    }
    let cfl = f.numerics.cfl;
    let stepping = if f.numerics.local_time_step {
        TimeStepping::Local { cfl }
    } else {
        TimeStepping::Global { cfl }
    };
    let dt_initial = {
        let mut ws = Workspace::new(semi.mesh.n_nodes());
        cfl * stable_time_step(&semi, &initial.cons, &mut ws)?
    };
    if max_steps.is_none() && resources::step_count(end_key, t_end, dt_initial).is_err() {
        let bound = match mode {
            Mode::Alone => ", or bound the run with fluid.time.max_steps",
            Mode::Coupled => "",
        };
        return Err(field_error(
            case,
            end_key,
            format!(
                "{end_key} = {t_end:e} over the initial CFL step {dt_initial:.3e} is about {:.3e} \
                 steps, more than the {} one run may take; check the end time{bound}",
                t_end / dt_initial,
                resources::MAX_STEPS
            ),
        ));
    }
    Ok(Problem {
        semi,
        fluid_names,
        initial,
        stepping,
        t_end,
        max_steps,
        substeps,
        probes: f.probes.clone(),
        placed,
        dt_initial,
        warnings,
        level_set,
    })
}
