//! `structure-solver check CASE [--set KEY=VALUE]...`: everything a run does before its first
//! step, then a short summary and nothing written. A case with a `[fluid]` section is checked
//! as the coupled participant ([`prepare_coupled`]: the scheme's integrator, the wet surface,
//! the first coupling step against the stable one), any other as a run alone
//! ([`prepare_alone`]: the analysis, its step and step count). Both build the model the run
//! builds, with the same function.

use std::fmt::Write;

use interface_protocol::case::Case;
use interface_protocol::coupling::Staggered;

use crate::build::section;
use crate::couple::{prepare_coupled, unstable_coupling, Coupled};
use crate::mesh::{CellKind, Mesh};
use crate::prepare::{prepare_alone, unstable_note, Alone};

/// `N nodes, M cells (a quadrilaterals, b lines)`.
fn mesh_summary(mesh: &Mesh) -> String {
    let kinds = [
        (CellKind::Line2, "lines"),
        (CellKind::Tri3, "triangles"),
        (CellKind::Quad4, "quadrilaterals"),
        (CellKind::Tet4, "tetrahedra"),
    ];
    let counts: Vec<String> = kinds
        .iter()
        .map(|&(k, name)| (mesh.cells.iter().filter(|c| c.kind == k).count(), name))
        .filter(|&(n, _)| n > 0)
        .map(|(n, name)| format!("{n} {name}"))
        .collect();
    format!("{} nodes, {} cells ({})", mesh.nodes.len(), mesh.cells.len(), counts.join(", "))
}

/// Checks `case` as `run` would start it; the summary, or the first error.
pub fn check(case: &Case) -> anyhow::Result<String> {
    let file = case.source.path.display();
    let s = section(case)?;
    let mut out = String::new();
    let w = &mut out;
    writeln!(w, "{file}: structure ok")?;
    let probe_nodes: Vec<usize>;
    let mesh = if case.fluid.is_some() {
        let Coupled { structure, wet, dt_stable, .. } = prepare_coupled(case)?;
        let scheme = case.coupling.scheme;
        let dt = case.coupling.dt.min(case.coupling.t_end);
        if let Some(message) = unstable_coupling(dt, dt_stable, scheme, s.substeps) {
            return Err(case.field_error("coupling.dt", message).into());
        }
        let mut staggered = Staggered::new(scheme, 0).with_substeps(s.substeps);
        staggered.set_stable_step(dt_stable);
        let m = staggered.substeps(dt);
        writeln!(w, "  mesh       {}", mesh_summary(&structure.mesh))?;
        writeln!(
            w,
            "  coupled    {scheme:?}, wet surface `{}` of {} nodes and {} faces, stable step {:.3e} s",
            s.wet_set.as_deref().unwrap_or_default(),
            wet.nodes.len(),
            wet.elements.len(),
            dt_stable
        )?;
        writeln!(
            w,
            "  substeps   {m} per coupling step of {dt:.3e} s ({})",
            if s.substeps.is_some() { "structure.substeps" } else { "from the stable step" }
        )?;
        probe_nodes = s.probes.iter().map(|p| structure.mesh.nearest_node(p.point)).collect();
        structure.mesh
    } else {
        let alone = prepare_alone(case)?;
        let Alone { integrator, t_end, dt, stable, steps, .. } = alone;
        writeln!(w, "  mesh       {}", mesh_summary(&alone.structure.mesh))?;
        let stable_text = match stable {
            Some(st) => format!(" (stable step {st:.3e} s{})", unstable_note(stable, dt)),
            None => String::new(),
        };
        writeln!(
            w,
            "  run alone  {}, step {dt:.3e}{stable_text}, {steps} steps to {t_end}",
            integrator.name()
        )?;
        probe_nodes = alone.probe_nodes;
        alone.structure.mesh
    };
    for (p, &node) in s.probes.iter().zip(&probe_nodes) {
        let at = mesh.nodes[node];
        writeln!(w, "  probe      {} at node {} {at:?}", p.name, mesh.node_id(node))?;
    }
    Ok(out)
}
