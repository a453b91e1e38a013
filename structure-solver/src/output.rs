//! Field output of the structure (DESIGN §7): `structure.h5` + `structure.xdmf`, a time series
//! of nodal displacement and velocity on the mesh (one cell block per cell kind), each step
//! checked for the first non-finite value first (the stop names the field, node and time).
//!
//! Cell fields ([`cell_fields`]): the von Mises stress of every element (`Element::von_mises`:
//! shells the largest through the thickness, beams the largest corner stress, tets from the
//! Cauchy stress; BT4 and BLT3 shells the largest over their thickness points), and the
//! largest equivalent plastic strain through the thickness of J2 shells and explicit shells
//! (tets: at their point) when the model has plastic states. `structure_cells.csv` holds the
//! final cell fields with the cell centroids.
//!
//! Both speak the user's numbering, not the storage order of the renumbered mesh
//! ([`crate::mesh::renumber`]): nodes and cells are written in the user's order (cells grouped
//! by kind, in the user's order within a kind), and the table's `cell` is the user's number.

use std::io::Write;
use std::path::Path;

use interface_protocol::io::finite::{check_finite, Entity, NonFiniteError};
use interface_protocol::io::xdmf::{
    CellBlock, CellKind as XdmfKind, Connectivity, Field, Location, Mesh as XdmfMesh,
    TimeSeriesWriter, Values,
};

use crate::assembly::FeModel;
use crate::elements::layered::shell_von_mises;
use crate::elements::ElementKind;
use crate::mesh::{CellKind, Mesh};
use crate::model::Model;

/// Which mesh cells are the model's elements (`FeModel::elements`, in order), its BT4 shells
/// (`FeModel::bt4`, in order) and its BLT3 shells (`FeModel::blt3`, in order), of `n_cells`
/// (cells of no part carry zeros).
#[derive(Debug, Clone, PartialEq)]
pub struct CellMap {
    pub elements: Vec<usize>,
    pub bt4: Vec<usize>,
    pub blt3: Vec<usize>,
    pub n_cells: usize,
}

/// The committed cell fields of `model`, one value per mesh cell: `von_mises` of every element
/// (`Element::von_mises`; BT4 and BLT3 shells the largest over their thickness points, BLT3
/// with the mean transverse shear stress `Q/h`), and `plastic_strain` when some element has a
/// J2 state or the model has explicit shells.
pub fn cell_fields(model: &FeModel, map: &CellMap) -> Vec<(&'static str, Vec<f64>)> {
    let n = map.n_cells;
    let (bt4, blt3) = (model.bt4(), model.blt3());
    let has_state = (0..model.elements().len()).any(|e| !model.element_state(e).is_empty());
    let mut out = Vec::new();
    if has_state || bt4.is_some() || blt3.is_some() {
        let mut ep = vec![0.0; n];
        for (e, &c) in map.elements.iter().enumerate() {
            let st = model.element_state(e);
            // J2 shells: [εp_xx, εp_yy, γp_xy, α] per point; tets: [εp (6), α].
            let (first, stride) = match model.elements()[e].kind {
                ElementKind::Quad4 | ElementKind::Tri3 => (3, 4),
                ElementKind::Tet4 => (6, 7),
                ElementKind::Beam2 => (0, 1),
            };
            ep[c] = st.iter().skip(first).step_by(stride).fold(0.0, |m: f64, v| m.max(*v));
        }
        if let Some(b) = bt4 {
            let np = b.settings.rule.len();
            for (e, &c) in map.bt4.iter().enumerate() {
                ep[c] = (0..np).map(|p| b.plastic_strain(e, p)).fold(0.0, f64::max);
            }
        }
        if let Some(b) = blt3 {
            let np = b.settings.rule.len();
            for (e, &c) in map.blt3.iter().enumerate() {
                ep[c] = (0..np).map(|p| b.plastic_strain(e, p)).fold(0.0, f64::max);
            }
        }
        out.push(("plastic_strain", ep));
    }
    let mut vm = vec![0.0; n];
    let (x, r) = (model.positions(), model.rotations());
    for (e, (el, &c)) in model.elements().iter().zip(&map.elements).enumerate() {
        let xe: Vec<_> = el.nodes.iter().map(|&i| x[i]).collect();
        let re: Vec<_> = el.nodes.iter().map(|&i| r[i]).collect();
        vm[c] = el.von_mises(&xe, &re, model.element_state(e));
    }
    if let Some(b) = bt4 {
        let np = b.settings.rule.len();
        for (e, &c) in map.bt4.iter().enumerate() {
            vm[c] = (0..np).map(|p| shell_von_mises(&b.stress(e, p))).fold(0.0, f64::max);
        }
    }
    if let Some(b) = blt3 {
        let np = b.settings.rule.len();
        for (e, &c) in map.blt3.iter().enumerate() {
            // [σxx, σyy, σxy, σyz, σzx], the shear resultants [Qxz, Qyz] over h
            let (q, h) = (b.shear(e), b.thickness[e]);
            let point = |p: usize| {
                let s = b.stress(e, p);
                [s[0], s[1], s[2], q[1] / h, q[0] / h]
            };
            vm[c] = (0..np).map(|p| shell_von_mises(&point(p))).fold(0.0, f64::max);
        }
    }
    out.push(("von_mises", vm));
    out
}

/// Writes `cell,x,y,z,<fields>`: the final cell fields at the cell centroids, a row per cell in
/// the user's order, `cell` its user number.
pub fn write_cell_table(
    path: &Path,
    mesh: &Mesh,
    model: &FeModel,
    map: &CellMap,
) -> anyhow::Result<()> {
    let fields = cell_fields(model, map);
    let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
    write!(w, "cell,x,y,z")?;
    for (name, _) in &fields {
        write!(w, ",{name}")?;
    }
    writeln!(w)?;
    for c in mesh.cells_in_user_order() {
        let cell = &mesh.cells[c];
        let k = cell.nodes.len() as f64;
        let x: [f64; 3] =
            std::array::from_fn(|i| cell.nodes.iter().map(|&n| mesh.nodes[n][i]).sum::<f64>() / k);
        write!(w, "{},{:e},{:e},{:e}", mesh.cell_user(c), x[0], x[1], x[2])?;
        for (_, v) in &fields {
            write!(w, ",{:e}", v[c])?;
        }
        writeln!(w)?;
    }
    w.flush()?;
    Ok(())
}

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
    /// Mesh cell of each output cell (cells are written grouped by kind, in the user's order).
    cell_order: Vec<usize>,
    /// Node slot of each output node (the user's order) and the user's number of each slot;
    /// both empty when the user's order is the storage order.
    node_order: Vec<usize>,
    node_user: Vec<usize>,
    /// The user's number of each cell slot, naming a cell in a stop.
    cell_user: Vec<usize>,
    /// Scratch of one nodal field in the user's order.
    reordered: Vec<[f64; 3]>,
    /// The cells of the model's elements, when the series carries cell fields.
    cells: Option<CellMap>,
    cell_fields: Vec<(&'static str, Vec<f64>)>,
    displacement: Vec<[f64; 3]>,
    velocity: Vec<[f64; 3]>,
}

impl FieldOutput {
    /// Starts `structure.h5` + `structure.xdmf` in `dir` with the mesh's nodes and cells in the
    /// user's order; with `cells`, each step also carries the cell fields of the model.
    pub fn create(dir: &Path, mesh: &Mesh, cells: Option<CellMap>) -> anyhow::Result<FieldOutput> {
        let kinds = [CellKind::Line2, CellKind::Tri3, CellKind::Quad4, CellKind::Tet4];
        let user_cells = mesh.cells_in_user_order();
        let node_order = mesh.nodes_in_user_order();
        let identity = node_order.iter().enumerate().all(|(u, &s)| u == s);
        let conn: Vec<(CellKind, Vec<u32>)> = kinds
            .iter()
            .map(|&k| {
                let c = user_cells.iter().map(|&c| &mesh.cells[c]).filter(|c| c.kind == k);
                let user = |n: usize| mesh.node_user(n) as u32;
                (k, c.flat_map(|c| c.nodes.iter().map(|&n| user(n))).collect::<Vec<u32>>())
            })
            .filter(|(_, c)| !c.is_empty())
            .collect();
        let blocks: Vec<CellBlock> = conn
            .iter()
            .map(|(k, c)| CellBlock { kind: xdmf_kind(*k), connectivity: Connectivity::U32(c) })
            .collect();
        let points: Vec<[f64; 3]> = node_order.iter().map(|&s| mesh.nodes[s]).collect();
        let writer = TimeSeriesWriter::create(
            dir,
            "structure",
            &XdmfMesh { points: &points, blocks: &blocks },
        )?;
        let n = mesh.nodes.len();
        let cell_order = kinds
            .iter()
            .flat_map(|&k| user_cells.iter().copied().filter(move |&c| mesh.cells[c].kind == k))
            .collect();
        Ok(FieldOutput {
            writer,
            cell_order,
            node_order: if identity { Vec::new() } else { node_order },
            node_user: if identity {
                Vec::new()
            } else {
                (0..n).map(|s| mesh.node_user(s)).collect()
            },
            cell_user: (0..mesh.cells.len()).map(|c| mesh.cell_user(c)).collect(),
            reordered: Vec::new(),
            cells,
            cell_fields: Vec::new(),
            displacement: vec![[0.0; 3]; n],
            velocity: vec![[0.0; 3]; n],
        })
    }

    /// Loads the model's displacement and the translational velocities `v` (6 per node), and
    /// the cell fields of `fe` when the series carries them; checks all are finite.
    pub fn gather(
        &mut self,
        t: f64,
        model: &dyn Model,
        fe: Option<&FeModel>,
        v: &[f64],
    ) -> anyhow::Result<()> {
        let user = |s: usize| self.node_user.get(s).copied().unwrap_or(s);
        gather_nodal(t, model, v, &mut self.displacement, &mut self.velocity, &user)?;
        if !self.node_order.is_empty() {
            for field in [&mut self.displacement, &mut self.velocity] {
                self.reordered.clear();
                self.reordered.extend(self.node_order.iter().map(|&s| field[s]));
                std::mem::swap(field, &mut self.reordered);
            }
        }
        self.cell_fields = match (&self.cells, fe) {
            (Some(map), Some(fe)) => cell_fields(fe, map),
            _ => Vec::new(),
        };
        for (name, values) in &mut self.cell_fields {
            check_finite(name, Entity::Element, t, &values[..])
                .map_err(|e| NonFiniteError { index: self.cell_user[e.index], ..e })?;
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

    /// The user's number of node slot `s`.
    pub fn node_user(&self, s: usize) -> usize {
        self.node_user.get(s).copied().unwrap_or(s)
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

/// Nodal displacement and translational velocity of the model at `t` (storage order), checked
/// finite: the first non-finite value stops the run naming the field, the node by its user
/// number `user(slot)`, and the time.
pub fn gather_nodal(
    t: f64,
    model: &dyn Model,
    v: &[f64],
    displacement: &mut [[f64; 3]],
    velocity: &mut [[f64; 3]],
    user: &dyn Fn(usize) -> usize,
) -> anyhow::Result<()> {
    model.displacement(displacement);
    for (i, o) in velocity.iter_mut().enumerate() {
        o.copy_from_slice(&v[6 * i..6 * i + 3]);
    }
    let named = |e: NonFiniteError| NonFiniteError { index: user(e.index), ..e };
    check_finite("displacement", Entity::Node, t, displacement).map_err(named)?;
    check_finite("velocity", Entity::Node, t, velocity).map_err(named)?;
    Ok(())
}
