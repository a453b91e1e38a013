//! The cell-to-node table of a series: `/mesh/topology` in HDF5 and its XDMF `<Topology>`.

use super::{data_item, CellKind, Connectivity, Mesh};

/// How the topology was stored, for its XDMF element.
pub(super) struct Topology {
    kind: Option<CellKind>,
    cells: usize,
    dims: String,
    wide: bool,
}

impl Topology {
    pub(super) fn xml(&self, h5_name: &str) -> String {
        let (name, extra) = match self.kind {
            Some(CellKind::Line2) => ("Polyline", " NodesPerElement=\"2\""),
            Some(k) => (k.xdmf_name(), ""),
            None => ("Mixed", ""),
        };
        let precision = if self.wide { 8 } else { 4 };
        format!(
            "        <Topology TopologyType=\"{name}\" NumberOfElements=\"{}\"{extra}>\n          {}\n        </Topology>\n",
            self.cells,
            data_item(&self.dims, "UInt", precision, h5_name, "/mesh/topology")
        )
    }
}

/// Writes `/mesh/topology`: the block's own array for one block, the `Mixed` list otherwise
/// (`u32` when every block is `u32`, else `u64`).
pub(super) fn write_topology(g: &hdf5::Group, mesh: &Mesh, cells: usize) -> hdf5::Result<Topology> {
    if let [block] = mesh.blocks {
        let nodes = block.kind.nodes();
        let dims = format!("{} {nodes}", block.len());
        let wide = match block.connectivity {
            Connectivity::U32(c) => {
                g.new_dataset::<u32>()
                    .shape([block.len(), nodes])
                    .create("topology")?
                    .write_raw(c)?;
                false
            }
            Connectivity::U64(c) => {
                g.new_dataset::<u64>()
                    .shape([block.len(), nodes])
                    .create("topology")?
                    .write_raw(c)?;
                true
            }
        };
        return Ok(Topology { kind: Some(block.kind), cells, dims, wide });
    }
    let mut mixed: Vec<u64> = Vec::new();
    for block in mesh.blocks {
        let nodes = block.kind.nodes();
        let mut i = 0;
        block.connectivity.for_each(|node| {
            if i % nodes == 0 {
                mixed.push(block.kind.mixed_id());
                if block.kind == CellKind::Line2 {
                    mixed.push(2);
                }
            }
            mixed.push(node);
            i += 1;
        });
    }
    let wide = mesh.blocks.iter().any(|b| matches!(b.connectivity, Connectivity::U64(_)));
    if wide {
        g.new_dataset::<u64>().shape([mixed.len()]).create("topology")?.write_raw(&mixed)?;
    } else {
        let narrow: Vec<u32> = mixed.iter().map(|&x| x as u32).collect();
        g.new_dataset::<u32>().shape([narrow.len()]).create("topology")?.write_raw(&narrow)?;
    }
    Ok(Topology { kind: None, cells, dims: mixed.len().to_string(), wide })
}
