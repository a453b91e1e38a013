//! Field output of the structure (DESIGN §7): `structure.h5` + `structure.xdmf`, a time series
//! of nodal displacement and velocity on the mesh (one cell block per cell kind), each step
//! checked for the first non-finite value first (the stop names the field, node and time).
//!
//! Cell fields are those the model offers through `Restorable::element_fields` (BT4 shells: the
//! largest von Mises stress and equivalent plastic strain through the thickness; `FeModel`
//! runs, elastic as `structure-solver` builds them, carry nodal fields only).

use std::path::Path;

use interface_protocol::io::finite::{check_finite, Entity};
use interface_protocol::io::xdmf::{
    CellBlock, CellKind as XdmfKind, Connectivity, Field, Location, Mesh as XdmfMesh,
    TimeSeriesWriter, Values,
};

use crate::mesh::{CellKind, Mesh};
use crate::model::Model;
use crate::restart::Restorable;

/// The XDMF cell kind of a mesh cell kind.
fn xdmf_kind(k: CellKind) -> XdmfKind {
    match k {
        CellKind::Line2 => XdmfKind::Line2,
        CellKind::Tri3 => XdmfKind::Tri3,
        CellKind::Quad4 => XdmfKind::Quad4,
        CellKind::Tet4 => XdmfKind::Tet4,
    }
}

/// The `structure.xdmf` series with its per-node work arrays.
pub struct FieldOutput {
    writer: TimeSeriesWriter,
    /// Mesh cell of each output cell (cells are written grouped by kind).
    cell_order: Vec<usize>,
    cell_fields: Vec<(&'static str, Vec<f64>)>,
    displacement: Vec<[f64; 3]>,
    velocity: Vec<[f64; 3]>,
}

impl FieldOutput {
    /// Starts `structure.h5` + `structure.xdmf` in `dir` with the mesh's nodes and cells.
    pub fn create(dir: &Path, mesh: &Mesh) -> anyhow::Result<FieldOutput> {
        let kinds = [CellKind::Line2, CellKind::Tri3, CellKind::Quad4, CellKind::Tet4];
        let conn: Vec<(CellKind, Vec<u32>)> = kinds
            .iter()
            .map(|&k| {
                let c = mesh.cells.iter().filter(|c| c.kind == k);
                (k, c.flat_map(|c| c.nodes.iter().map(|&n| n as u32)).collect::<Vec<u32>>())
            })
            .filter(|(_, c)| !c.is_empty())
            .collect();
        let blocks: Vec<CellBlock> = conn
            .iter()
            .map(|(k, c)| CellBlock { kind: xdmf_kind(*k), connectivity: Connectivity::U32(c) })
            .collect();
        let writer = TimeSeriesWriter::create(
            dir,
            "structure",
            &XdmfMesh { points: &mesh.nodes, blocks: &blocks },
        )?;
        let n = mesh.nodes.len();
        let cell_order = kinds
            .iter()
            .flat_map(|&k| (0..mesh.cells.len()).filter(move |&c| mesh.cells[c].kind == k))
            .collect();
        Ok(FieldOutput {
            writer,
            cell_order,
            cell_fields: Vec::new(),
            displacement: vec![[0.0; 3]; n],
            velocity: vec![[0.0; 3]; n],
        })
    }

    /// Loads the model's displacement and the translational velocities `v` (6 per node) and
    /// checks both are finite.
    pub fn gather(&mut self, t: f64, model: &dyn Restorable, v: &[f64]) -> anyhow::Result<()> {
        gather_nodal(t, model, v, &mut self.displacement, &mut self.velocity)?;
        self.cell_fields = model.element_fields();
        for (name, values) in &mut self.cell_fields {
            check_finite(name, Entity::Element, t, &values[..])?;
            *values = self.cell_order.iter().map(|&c| values[c]).collect();
        }
        Ok(())
    }

    /// Writes the state last gathered (nodal and cell fields) as the step at time `t`.
    pub fn write(&mut self, t: f64) -> anyhow::Result<()> {
        let mut fields = vec![
            Field {
                name: "displacement",
                location: Location::Node,
                values: Values::Vector(&self.displacement),
            },
            Field {
                name: "velocity",
                location: Location::Node,
                values: Values::Vector(&self.velocity),
            },
        ];
        for (name, values) in &self.cell_fields {
            fields.push(Field { name, location: Location::Cell, values: Values::Scalar(values) });
        }
        self.writer.write_step(t, &fields)?;
        Ok(())
    }

    /// Steps written so far.
    pub fn steps(&self) -> usize {
        self.writer.steps()
    }

    /// Closes the series.
    pub fn finish(self) -> anyhow::Result<()> {
        self.writer.finish()?;
        Ok(())
    }
}

/// Nodal displacement and translational velocity of the model at `t`, checked finite: the first
/// non-finite value stops the run naming the field, node and time.
pub fn gather_nodal(
    t: f64,
    model: &dyn Model,
    v: &[f64],
    displacement: &mut [[f64; 3]],
    velocity: &mut [[f64; 3]],
) -> anyhow::Result<()> {
    model.displacement(displacement);
    for (i, o) in velocity.iter_mut().enumerate() {
        o.copy_from_slice(&v[6 * i..6 * i + 3]);
    }
    check_finite("displacement", Entity::Node, t, displacement)?;
    check_finite("velocity", Entity::Node, t, velocity)?;
    Ok(())
}
