//! Field time series as `<stem>.h5` + `<stem>.xdmf` (XDMF 3), the pair ParaView and meshio open.
//!
//! HDF5 layout: `/mesh/points` (`n x 3` f64), `/mesh/topology` (`cells x nodes` for one cell
//! block; the XDMF `Mixed` list `type, nodes..., type, nodes...` for several, lines as
//! `2, 2, a, b`), then one group per output `/steps/<k>` with attribute `time` and one dataset per
//! field (`n` or `n x 3` f64). The XDMF file is a temporal collection of uniform grids that all
//! reference the one mesh; it is rewritten atomically after every step (after an HDF5 flush), so
//! a run that dies leaves a file that opens with every step written so far.
//!
//! Cell fields follow the cells in block order (block 0's cells, then block 1's, ...). The HDF5
//! file is written without file locking so it can be opened while the run goes on.
//!
//! A moving mesh (a surface carried by the structure) writes its nodal positions with every step
//! ([`TimeSeriesWriter::write_moved_step`]): `/steps/<k>/points` (`n x 3` f64), and that step's
//! grid takes its `<Geometry>` from there while the `<Topology>` stays the one of `/mesh`. This is
//! the form ParaView's XDMF reader gives time-varying geometry (each grid of the temporal
//! collection carries its own geometry); `/mesh/points` then holds the positions at creation.

use std::fmt::Write as _;
use std::io;
use std::path::{Path, PathBuf};

use super::atomic::write_bytes_atomic;

#[cfg(test)]
mod tests;
mod topology;

use topology::write_topology;

/// A linear cell type with VTK/XDMF node ordering.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CellKind {
    Tet4,
    Hex8,
    Wedge6,
    Pyramid5,
    Tri3,
    Quad4,
    Line2,
}

impl CellKind {
    /// Nodes per cell.
    pub fn nodes(self) -> usize {
        match self {
            CellKind::Tet4 => 4,
            CellKind::Hex8 => 8,
            CellKind::Wedge6 => 6,
            CellKind::Pyramid5 => 5,
            CellKind::Tri3 => 3,
            CellKind::Quad4 => 4,
            CellKind::Line2 => 2,
        }
    }
    /// XDMF topology name.
    fn xdmf_name(self) -> &'static str {
        match self {
            CellKind::Tet4 => "Tetrahedron",
            CellKind::Hex8 => "Hexahedron",
            CellKind::Wedge6 => "Wedge",
            CellKind::Pyramid5 => "Pyramid",
            CellKind::Tri3 => "Triangle",
            CellKind::Quad4 => "Quadrilateral",
            CellKind::Line2 => "Polyline",
        }
    }
    /// Type id in a `Mixed` topology (XdmfTopologyType.cpp).
    fn mixed_id(self) -> u64 {
        match self {
            CellKind::Line2 => 2,
            CellKind::Tri3 => 4,
            CellKind::Quad4 => 5,
            CellKind::Tet4 => 6,
            CellKind::Pyramid5 => 7,
            CellKind::Wedge6 => 8,
            CellKind::Hex8 => 9,
        }
    }
}

/// Cell-to-node indices of one block, flat (`cells x nodes`), zero-based.
#[derive(Debug, Clone, Copy)]
pub enum Connectivity<'a> {
    U32(&'a [u32]),
    U64(&'a [u64]),
}

impl Connectivity<'_> {
    fn len(&self) -> usize {
        match self {
            Connectivity::U32(c) => c.len(),
            Connectivity::U64(c) => c.len(),
        }
    }
    fn max(&self) -> Option<u64> {
        match self {
            Connectivity::U32(c) => c.iter().max().map(|&m| m.into()),
            Connectivity::U64(c) => c.iter().max().copied(),
        }
    }
    fn for_each(&self, mut f: impl FnMut(u64)) {
        match self {
            Connectivity::U32(c) => c.iter().for_each(|&i| f(i.into())),
            Connectivity::U64(c) => c.iter().for_each(|&i| f(i)),
        }
    }
}

/// One block of cells of one kind.
#[derive(Debug, Clone, Copy)]
pub struct CellBlock<'a> {
    pub kind: CellKind,
    pub connectivity: Connectivity<'a>,
}

impl CellBlock<'_> {
    /// Number of cells.
    pub fn len(&self) -> usize {
        self.connectivity.len() / self.kind.nodes()
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The mesh written once at the start of a series.
#[derive(Debug, Clone, Copy)]
pub struct Mesh<'a> {
    pub points: &'a [[f64; 3]],
    pub blocks: &'a [CellBlock<'a>],
}

/// Where a field lives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Location {
    Node,
    Cell,
}

/// Field values: one scalar or one 3-vector per node or cell.
#[derive(Debug, Clone, Copy)]
pub enum Values<'a> {
    Scalar(&'a [f64]),
    Vector(&'a [[f64; 3]]),
}

/// A named field at one output time.
#[derive(Debug, Clone, Copy)]
pub struct Field<'a> {
    pub name: &'a str,
    pub location: Location,
    pub values: Values<'a>,
}

/// The time series could not be written.
#[derive(Debug, thiserror::Error)]
pub enum XdmfError {
    #[error("{path}: {source}")]
    Hdf5 { path: PathBuf, source: hdf5::Error },
    #[error(transparent)]
    Io(#[from] io::Error),
    #[error("output stem `{0}` must be non-empty and contain no `/`, `\\` or `:`")]
    BadStem(String),
    #[error(
        "cell block {block} ({kind:?}): connectivity has {len} indices, not a multiple of {nodes}"
    )]
    Ragged { block: usize, kind: CellKind, len: usize, nodes: usize },
    #[error(
        "cell block {block} ({kind:?}): node index {index} out of range (mesh has {points} points)"
    )]
    NodeOutOfRange { block: usize, kind: CellKind, index: u64, points: usize },
    #[error(
        "field name `{0}` must be non-empty, unique in its step and contain no `/`, `:` or `\"`"
    )]
    BadFieldName(String),
    #[error("field `{name}`: {got} values, the mesh has {expected} {location:?}s")]
    FieldLength { name: String, location: Location, expected: usize, got: usize },
    #[error("step time {time} must be finite and greater than the previous step's {previous}")]
    TimeOrder { time: f64, previous: f64 },
    #[error("moved step: {got} nodal positions, the mesh has {expected} points")]
    MovedPoints { expected: usize, got: usize },
}

/// Writes `<stem>.h5` and `<stem>.xdmf` in a folder; see the module doc for the layout.
pub struct TimeSeriesWriter {
    file: hdf5::File,
    h5_path: PathBuf,
    xdmf_path: PathBuf,
    stem: String,
    /// `<Topology>` element shared by every step.
    topology_xml: String,
    /// `<Geometry>` element of `/mesh/points`, for the steps that do not move the mesh.
    geometry_xml: String,
    /// The `<Grid>` element of each step written so far.
    steps_xml: String,
    steps: usize,
    last_time: f64,
    points: usize,
    cells: usize,
}

impl TimeSeriesWriter {
    /// Creates `dir/<stem>.h5` (replacing it) and writes the mesh; `<stem>.xdmf` appears with
    /// the first step (or at [`TimeSeriesWriter::finish`]).
    pub fn create(dir: &Path, stem: &str, mesh: &Mesh) -> Result<Self, XdmfError> {
        if stem.is_empty() || stem.contains(['/', '\\', ':']) {
            return Err(XdmfError::BadStem(stem.to_string()));
        }
        let mut cells = 0;
        for (b, block) in mesh.blocks.iter().enumerate() {
            let (kind, len, nodes) = (block.kind, block.connectivity.len(), block.kind.nodes());
            if len % nodes != 0 {
                return Err(XdmfError::Ragged { block: b, kind, len, nodes });
            }
            if let Some(index) = block.connectivity.max().filter(|&m| m >= mesh.points.len() as u64)
            {
                return Err(XdmfError::NodeOutOfRange {
                    block: b,
                    kind,
                    index,
                    points: mesh.points.len(),
                });
            }
            cells += block.len();
        }
        let h5_path = dir.join(format!("{stem}.h5"));
        let xdmf_path = dir.join(format!("{stem}.xdmf"));
        let h5 = |source| XdmfError::Hdf5 { path: h5_path.clone(), source };
        let file = hdf5::File::with_options()
            .with_fapl(|p| p.file_locking(false))
            .create(&h5_path)
            .map_err(h5)?;
        let g = file.create_group("mesh").map_err(h5)?;
        g.new_dataset::<f64>()
            .shape([mesh.points.len(), 3])
            .create("points")
            .and_then(|d| d.write_raw(mesh.points.as_flattened()))
            .map_err(h5)?;
        let h5_name = format!("{stem}.h5");
        let topology = write_topology(&g, mesh, cells).map_err(h5)?;
        file.create_group("steps").map_err(h5)?;
        file.flush().map_err(h5)?;
        let topology_xml = topology.xml(&h5_name);
        let geometry_xml = geometry_xml(mesh.points.len(), &h5_name, "/mesh/points");
        Ok(Self {
            file,
            h5_path,
            xdmf_path,
            stem: stem.to_string(),
            topology_xml,
            geometry_xml,
            steps_xml: String::new(),
            steps: 0,
            last_time: f64::NEG_INFINITY,
            points: mesh.points.len(),
            cells,
        })
    }

    /// Writes the fields of one output time as HDF5 group `/steps/<k>`, flushes the HDF5 file
    /// and rewrites the XDMF file. Times must increase strictly.
    pub fn write_step(&mut self, time: f64, fields: &[Field]) -> Result<(), XdmfError> {
        self.write_any_step(time, None, fields)
    }

    /// [`TimeSeriesWriter::write_step`] with the mesh's nodal positions at this time, `points`
    /// (one per mesh point, same topology), written as `/steps/<k>/points` and referenced by
    /// this step's `<Geometry>`.
    pub fn write_moved_step(
        &mut self,
        time: f64,
        points: &[[f64; 3]],
        fields: &[Field],
    ) -> Result<(), XdmfError> {
        if points.len() != self.points {
            return Err(XdmfError::MovedPoints { expected: self.points, got: points.len() });
        }
        self.write_any_step(time, Some(points), fields)
    }

    fn write_any_step(
        &mut self,
        time: f64,
        points: Option<&[[f64; 3]]>,
        fields: &[Field],
    ) -> Result<(), XdmfError> {
        if !time.is_finite() || time <= self.last_time {
            return Err(XdmfError::TimeOrder { time, previous: self.last_time });
        }
        for (i, f) in fields.iter().enumerate() {
            let dup = fields[..i].iter().any(|g| g.name == f.name);
            if f.name.is_empty() || f.name.contains(['/', ':', '"']) || f.name == "." || dup {
                return Err(XdmfError::BadFieldName(f.name.to_string()));
            }
            let expected = match f.location {
                Location::Node => self.points,
                Location::Cell => self.cells,
            };
            let got = match f.values {
                Values::Scalar(v) => v.len(),
                Values::Vector(v) => v.len(),
            };
            if got != expected {
                let name = f.name.to_string();
                return Err(XdmfError::FieldLength { name, location: f.location, expected, got });
            }
        }
        let k = self.steps;
        let h5_name = format!("{}.h5", self.stem);
        let h5 = |source| XdmfError::Hdf5 { path: self.h5_path.clone(), source };
        let group = self.file.create_group(&format!("steps/{k}")).map_err(h5)?;
        group.new_attr::<f64>().create("time").and_then(|a| a.write_scalar(&time)).map_err(h5)?;
        let geometry = match points {
            None => self.geometry_xml.clone(),
            Some(x) => {
                group
                    .new_dataset::<f64>()
                    .shape([x.len(), 3])
                    .create("points")
                    .and_then(|d| d.write_raw(x.as_flattened()))
                    .map_err(h5)?;
                geometry_xml(x.len(), &h5_name, &format!("/steps/{k}/points"))
            }
        };
        let mut xml = format!(
            "      <Grid Name=\"{}_{k}\" GridType=\"Uniform\">\n        <Time Value=\"{time:e}\"/>\n{}{geometry}",
            xml_escape(&self.stem),
            self.topology_xml
        );
        for f in fields {
            let (dims, kind) = match f.values {
                Values::Scalar(v) => {
                    group
                        .new_dataset::<f64>()
                        .shape([v.len()])
                        .create(f.name)
                        .and_then(|d| d.write_raw(v))
                        .map_err(h5)?;
                    (v.len().to_string(), "Scalar")
                }
                Values::Vector(v) => {
                    group
                        .new_dataset::<f64>()
                        .shape([v.len(), 3])
                        .create(f.name)
                        .and_then(|d| d.write_raw(v.as_flattened()))
                        .map_err(h5)?;
                    (format!("{} 3", v.len()), "Vector")
                }
            };
            let center = match f.location {
                Location::Node => "Node",
                Location::Cell => "Cell",
            };
            let path = format!("/steps/{k}/{}", f.name);
            let _ = write!(
                xml,
                "        <Attribute Name=\"{}\" AttributeType=\"{kind}\" Center=\"{center}\">\n          {}\n        </Attribute>\n",
                xml_escape(f.name),
                data_item(&dims, "Float", 8, &h5_name, &path)
            );
        }
        xml.push_str("      </Grid>\n");
        self.file.flush().map_err(h5)?;
        self.steps_xml.push_str(&xml);
        self.steps += 1;
        self.last_time = time;
        self.write_xdmf()
    }

    /// Number of steps written.
    pub fn steps(&self) -> usize {
        self.steps
    }

    /// Path of the XDMF file.
    pub fn xdmf_path(&self) -> &Path {
        &self.xdmf_path
    }

    /// Path of the HDF5 file.
    pub fn h5_path(&self) -> &Path {
        &self.h5_path
    }

    /// Flushes and closes both files. With no step written, the XDMF file holds the mesh alone.
    pub fn finish(self) -> Result<(), XdmfError> {
        self.file
            .flush()
            .map_err(|source| XdmfError::Hdf5 { path: self.h5_path.clone(), source })?;
        self.write_xdmf()?;
        self.file.close().map_err(|source| XdmfError::Hdf5 { path: self.h5_path.clone(), source })
    }

    fn write_xdmf(&self) -> Result<(), XdmfError> {
        let stem = xml_escape(&self.stem);
        let body = if self.steps == 0 {
            format!(
                "    <Grid Name=\"{stem}\" GridType=\"Uniform\">\n{}{}    </Grid>\n",
                self.topology_xml, self.geometry_xml
            )
            .replace("\n        ", "\n      ")
        } else {
            format!(
                "    <Grid Name=\"{stem}\" GridType=\"Collection\" CollectionType=\"Temporal\">\n{}    </Grid>\n",
                self.steps_xml
            )
        };
        let text = format!(
            "<?xml version=\"1.0\"?>\n<Xdmf Version=\"3.0\">\n  <Domain>\n{body}  </Domain>\n</Xdmf>\n"
        );
        write_bytes_atomic(&self.xdmf_path, text.as_bytes())?;
        Ok(())
    }
}

/// The `<Geometry>` element of `n` points stored at `path`.
fn geometry_xml(n: usize, h5_name: &str, path: &str) -> String {
    format!(
        "        <Geometry GeometryType=\"XYZ\">\n          {}\n        </Geometry>\n",
        data_item(&format!("{n} 3"), "Float", 8, h5_name, path)
    )
}

fn data_item(dims: &str, number_type: &str, precision: u8, h5_name: &str, path: &str) -> String {
    format!(
        "<DataItem Dimensions=\"{dims}\" DataType=\"{number_type}\" Precision=\"{precision}\" Format=\"HDF\">{}:{}</DataItem>",
        xml_escape(h5_name),
        xml_escape(path)
    )
}

fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}
