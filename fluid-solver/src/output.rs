//! Field output of the fluid: the mesh and nodal ρ, velocity, p, Mach and material id as an
//! XDMF/HDF5 time series (`fluid.h5` + `fluid.xdmf`) through `interface_protocol::io::xdmf`;
//! with an embedded surface also each node's `status` and the cut-edge pressure `p_wall`
//! ([`crate::embedded::output`], which also writes the surface's own series).

use crate::embedded::output::mesh_fields;
use crate::embedded::tracker::Tracker;
use crate::mesh::{CellKind, Mesh};
use crate::semidiscretization::Semidiscretization;
use interface_protocol::io::xdmf::{
    self, CellBlock, Connectivity, Field, Location, TimeSeriesWriter, Values,
};
use std::path::Path;

/// Opens `fluid.h5`/`fluid.xdmf` in `dir` and writes the mesh (cells grouped by kind).
pub fn create_writer(dir: &Path, mesh: &Mesh) -> Result<TimeSeriesWriter, xdmf::XdmfError> {
    let kinds = [
        (CellKind::Tet, xdmf::CellKind::Tet4),
        (CellKind::Hex, xdmf::CellKind::Hex8),
        (CellKind::Prism, xdmf::CellKind::Wedge6),
        (CellKind::Pyramid, xdmf::CellKind::Pyramid5),
    ];
    // gmsh and VTK/XDMF share the node order of these linear cells.
    let connectivity: Vec<(xdmf::CellKind, Vec<u32>)> = kinds
        .iter()
        .map(|&(ours, theirs)| {
            let c: Vec<u32> = mesh
                .cells
                .iter()
                .filter(|c| c.kind == ours)
                .flat_map(|c| c.nodes().to_vec())
                .collect();
            (theirs, c)
        })
        .filter(|(_, c)| !c.is_empty())
        .collect();
    let blocks: Vec<CellBlock> = connectivity
        .iter()
        .map(|(kind, c)| CellBlock { kind: *kind, connectivity: Connectivity::U32(c) })
        .collect();
    TimeSeriesWriter::create(dir, "fluid", &xdmf::Mesh { points: &mesh.coords, blocks: &blocks })
}

/// Writes one time step of the primitive fields, the Mach number (each node's own sound speed),
/// the material id of each node (`material`, as a scalar) and, when the run has one, the level
/// set `phi` (empty: none), and with an embedded surface (`embedded`) the node `status` and
/// `p_wall` of [`crate::embedded::output`].
pub fn write_fields(
    writer: &mut TimeSeriesWriter,
    semi: &Semidiscretization,
    time: f64,
    prim: &[[f64; 5]],
    phi: &[f64],
    embedded: Option<&Tracker>,
) -> Result<(), xdmf::XdmfError> {
    let rho: Vec<f64> = prim.iter().map(|w| w[0]).collect();
    let p: Vec<f64> = prim.iter().map(|w| w[4]).collect();
    let v: Vec<[f64; 3]> = prim.iter().map(|w| [w[1], w[2], w[3]]).collect();
    let mach: Vec<f64> = prim
        .iter()
        .enumerate()
        .map(|(i, w)| {
            let c = semi.eos_at(i).sound_speed(w[0], w[4]);
            (w[1] * w[1] + w[2] * w[2] + w[3] * w[3]).sqrt() / c
        })
        .collect();
    let material: Vec<f64> = semi.material().iter().map(|&m| f64::from(m)).collect();
    let mut fields = vec![
        Field { name: "rho", location: Location::Node, values: Values::Scalar(&rho) },
        Field { name: "velocity", location: Location::Node, values: Values::Vector(&v) },
        Field { name: "p", location: Location::Node, values: Values::Scalar(&p) },
        Field { name: "mach", location: Location::Node, values: Values::Scalar(&mach) },
        Field { name: "material", location: Location::Node, values: Values::Scalar(&material) },
    ];
    if !phi.is_empty() {
        fields.push(Field { name: "phi", location: Location::Node, values: Values::Scalar(phi) });
    }
    let (status, p_wall) = embedded.map(|t| mesh_fields(&semi.mesh, t)).unwrap_or_default();
    if embedded.is_some() {
        fields.push(Field {
            name: "status",
            location: Location::Node,
            values: Values::Scalar(&status),
        });
        fields.push(Field {
            name: "p_wall",
            location: Location::Node,
            values: Values::Scalar(&p_wall),
        });
    }
    writer.write_step(time, &fields)
}
