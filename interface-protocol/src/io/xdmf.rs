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

use std::fmt::Write as _;
use std::io;
use std::path::{Path, PathBuf};

use super::atomic::write_bytes_atomic;

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
}

/// Writes `<stem>.h5` and `<stem>.xdmf` in a folder; see the module doc for the layout.
pub struct TimeSeriesWriter {
    file: hdf5::File,
    h5_path: PathBuf,
    xdmf_path: PathBuf,
    stem: String,
    /// `<Topology>` and `<Geometry>` elements shared by every step.
    mesh_xml: String,
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
        let mut mesh_xml = topology.xml(&h5_name);
        let _ = write!(
            mesh_xml,
            "        <Geometry GeometryType=\"XYZ\">\n          {}\n        </Geometry>\n",
            data_item(&format!("{} 3", mesh.points.len()), "Float", 8, &h5_name, "/mesh/points")
        );
        Ok(Self {
            file,
            h5_path,
            xdmf_path,
            stem: stem.to_string(),
            mesh_xml,
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
        let mut xml = format!(
            "      <Grid Name=\"{}_{k}\" GridType=\"Uniform\">\n        <Time Value=\"{time:e}\"/>\n{}",
            xml_escape(&self.stem),
            self.mesh_xml
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
                "    <Grid Name=\"{stem}\" GridType=\"Uniform\">\n{}    </Grid>\n",
                self.mesh_xml
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

/// How the topology was stored, for its XDMF element.
struct Topology {
    kind: Option<CellKind>,
    cells: usize,
    dims: String,
    wide: bool,
}

impl Topology {
    fn xml(&self, h5_name: &str) -> String {
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
fn write_topology(g: &hdf5::Group, mesh: &Mesh, cells: usize) -> hdf5::Result<Topology> {
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::process::Command;

    /// Reads an XDMF time series with meshio (and its HDF5 file with h5py) and returns what they
    /// saw as JSON.
    const READER: &str = r#"
import json, sys
import h5py, meshio, numpy as np
xdmf, h5 = sys.argv[1], sys.argv[2]
out = {"steps": []}
with meshio.xdmf.TimeSeriesReader(xdmf) as r:
    points, cells = r.read_points_cells()
    out["points"] = points.tolist()
    out["cells"] = [[c.type, c.data.tolist()] for c in cells]
    for k in range(r.num_steps):
        t, pd, cd = r.read_data(k)
        out["steps"].append({
            "t": t,
            "point_data": {n: v.tolist() for n, v in pd.items()},
            "cell_data": {n: np.concatenate(v).tolist() for n, v in cd.items()},
        })
with h5py.File(h5, "r") as f:
    out["h5_times"] = [float(f["steps"][str(k)].attrs["time"]) for k in range(len(f["steps"]))]
print(json.dumps(out))
"#;

    fn python(script: &str, args: &[&Path]) -> serde_json::Value {
        let probe = Command::new("python3").args(["-c", "import meshio, h5py, numpy"]).output();
        match probe {
            Ok(o) if o.status.success() => {}
            _ => panic!(
                "python3 with meshio, h5py and numpy is needed to check the XDMF output with a real \
                 reader: run scripts/install-deps.sh"
            ),
        }
        let out = Command::new("python3").arg("-c").arg(script).args(args).output().unwrap();
        assert!(out.status.success(), "python failed:\n{}", String::from_utf8_lossy(&out.stderr));
        serde_json::from_slice(&out.stdout).unwrap()
    }

    fn read_back(w: &TimeSeriesWriter) -> serde_json::Value {
        python(READER, &[w.xdmf_path(), w.h5_path()])
    }

    fn f64s(v: &serde_json::Value) -> Vec<f64> {
        let flat = |x: &serde_json::Value| match x.as_array() {
            Some(row) => row.iter().map(|y| y.as_f64().unwrap()).collect(),
            None => vec![x.as_f64().unwrap()],
        };
        v.as_array().unwrap().iter().flat_map(flat).collect()
    }

    /// Twelve points and one or two cells of every kind (values chosen exactly representable).
    struct MixedMesh {
        points: Vec<[f64; 3]>,
        hex: Vec<u32>,
        pyramid: Vec<u32>,
        wedge: Vec<u32>,
        tets: Vec<u64>,
        tri: Vec<u64>,
        quad: Vec<u32>,
        line: Vec<u64>,
    }

    impl MixedMesh {
        fn new() -> Self {
            let points =
                (0..12).map(|i| [(i % 2) as f64, (i / 2 % 2) as f64, i as f64 * 0.25]).collect();
            Self {
                points,
                hex: (0..8).collect(),
                pyramid: vec![4, 5, 7, 6, 8],
                wedge: vec![0, 1, 2, 9, 10, 11],
                tets: vec![8, 9, 10, 11, 0, 2, 4, 8],
                tri: vec![0, 1, 2],
                quad: vec![0, 1, 3, 2],
                line: vec![0, 11],
            }
        }
        fn blocks(&self) -> Vec<CellBlock<'_>> {
            use Connectivity::*;
            vec![
                CellBlock { kind: CellKind::Hex8, connectivity: U32(&self.hex) },
                CellBlock { kind: CellKind::Pyramid5, connectivity: U32(&self.pyramid) },
                CellBlock { kind: CellKind::Wedge6, connectivity: U32(&self.wedge) },
                CellBlock { kind: CellKind::Tet4, connectivity: U64(&self.tets) },
                CellBlock { kind: CellKind::Tri3, connectivity: U64(&self.tri) },
                CellBlock { kind: CellKind::Quad4, connectivity: U32(&self.quad) },
                CellBlock { kind: CellKind::Line2, connectivity: U64(&self.line) },
            ]
        }
    }

    #[test]
    fn mixed_mesh_series_reads_back_in_meshio_and_h5py() {
        let dir = tempfile::tempdir().unwrap();
        let m = MixedMesh::new();
        let blocks = m.blocks();
        let mesh = Mesh { points: &m.points, blocks: &blocks };
        let mut w = TimeSeriesWriter::create(dir.path(), "fluid", &mesh).unwrap();
        let n = m.points.len();
        let ncells = 8;
        let times = [0.0, 0.25, 0.5];
        let rho = |k: usize| (0..n).map(|i| i as f64 + 0.5 * k as f64).collect::<Vec<_>>();
        let vel = |k: usize| {
            (0..n).map(|i| [i as f64, -(k as f64), 0.125 * i as f64]).collect::<Vec<_>>()
        };
        let p = |k: usize| (0..ncells).map(|c| 2.0 * c as f64 + k as f64).collect::<Vec<_>>();
        let write = |w: &mut TimeSeriesWriter, k: usize| {
            let (r, v, p) = (rho(k), vel(k), p(k));
            let fields = [
                Field { name: "rho", location: Location::Node, values: Values::Scalar(&r) },
                Field { name: "velocity", location: Location::Node, values: Values::Vector(&v) },
                Field { name: "p", location: Location::Cell, values: Values::Scalar(&p) },
            ];
            w.write_step(times[k], &fields).unwrap();
        };
        write(&mut w, 0);
        write(&mut w, 1);

        // Mid-run, as after a crash: the files already hold the two steps written.
        let mid = read_back(&w);
        assert_eq!(mid["steps"].as_array().unwrap().len(), 2);
        assert_eq!(f64s(&mid["h5_times"]), vec![0.0, 0.25]);

        write(&mut w, 2);
        let (xdmf, h5) = (w.xdmf_path().to_path_buf(), w.h5_path().to_path_buf());
        w.finish().unwrap();
        let got = python(READER, &[&xdmf, &h5]);

        assert_eq!(f64s(&got["points"]), m.points.as_flattened());
        let cells = got["cells"].as_array().unwrap();
        let kinds: Vec<&str> = cells.iter().map(|c| c[0].as_str().unwrap()).collect();
        assert_eq!(kinds, ["hexahedron", "pyramid", "wedge", "tetra", "triangle", "quad", "line"]);
        let counts: Vec<usize> = cells.iter().map(|c| c[1].as_array().unwrap().len()).collect();
        assert_eq!(counts, [1, 1, 1, 2, 1, 1, 1]);
        let conn: Vec<f64> = cells.iter().flat_map(|c| f64s(&c[1])).collect();
        let mut expect: Vec<f64> = Vec::new();
        for block in &blocks {
            block.connectivity.for_each(|i| expect.push(i as f64));
        }
        assert_eq!(conn, expect);

        let steps = got["steps"].as_array().unwrap();
        assert_eq!(steps.len(), 3);
        assert_eq!(f64s(&got["h5_times"]), times);
        for (k, s) in steps.iter().enumerate() {
            assert_eq!(s["t"].as_f64().unwrap(), times[k]);
            assert_eq!(f64s(&s["point_data"]["rho"]), rho(k));
            assert_eq!(f64s(&s["point_data"]["velocity"]), vel(k).as_flattened());
            assert_eq!(f64s(&s["cell_data"]["p"]), p(k));
        }
    }

    #[test]
    fn single_block_surface_and_mesh_only_file_read_back() {
        let dir = tempfile::tempdir().unwrap();
        let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.5]];
        let tris: [u64; 6] = [0, 1, 2, 1, 3, 2];
        let blocks = [CellBlock { kind: CellKind::Tri3, connectivity: Connectivity::U64(&tris) }];
        let mesh = Mesh { points: &points, blocks: &blocks };
        let mut w = TimeSeriesWriter::create(dir.path(), "structure", &mesh).unwrap();
        let traction = [[1.0, 2.0, 3.0], [-4.0, 5.5, 0.0]];
        let f = [Field {
            name: "traction",
            location: Location::Cell,
            values: Values::Vector(&traction),
        }];
        w.write_step(1e-3, &f).unwrap();
        let got = read_back(&w);
        w.finish().unwrap();
        assert_eq!(got["cells"][0][0], "triangle");
        assert_eq!(f64s(&got["cells"][0][1]), [0.0, 1.0, 2.0, 1.0, 3.0, 2.0]);
        assert_eq!(got["steps"][0]["t"].as_f64().unwrap(), 1e-3);
        assert_eq!(f64s(&got["steps"][0]["cell_data"]["traction"]), traction.as_flattened());

        // No step at all: the XDMF file still opens, holding the mesh.
        let lines = [0u32, 1, 1, 3];
        let blocks = [CellBlock { kind: CellKind::Line2, connectivity: Connectivity::U32(&lines) }];
        let mesh = Mesh { points: &points, blocks: &blocks };
        let w = TimeSeriesWriter::create(dir.path(), "beam", &mesh).unwrap();
        let xdmf = w.xdmf_path().to_path_buf();
        w.finish().unwrap();
        let script = r#"
import sys, json, meshio
m = meshio.read(sys.argv[1])
print(json.dumps([len(m.points), m.cells[0].type, m.cells[0].data.tolist()]))
"#;
        let got = python(script, &[&xdmf]);
        assert_eq!(got, serde_json::json!([4, "line", [[0, 1], [1, 3]]]));
    }

    #[test]
    fn bad_mesh_and_fields_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let points = [[0.0; 3]; 3];
        let bad = [0u32, 1, 3];
        let blocks = [CellBlock { kind: CellKind::Tri3, connectivity: Connectivity::U32(&bad) }];
        let err = TimeSeriesWriter::create(
            dir.path(),
            "fluid",
            &Mesh { points: &points, blocks: &blocks },
        );
        assert!(matches!(err, Err(XdmfError::NodeOutOfRange { index: 3, points: 3, .. })));
        let ragged = [0u32, 1];
        let blocks = [CellBlock { kind: CellKind::Tri3, connectivity: Connectivity::U32(&ragged) }];
        let err = TimeSeriesWriter::create(
            dir.path(),
            "fluid",
            &Mesh { points: &points, blocks: &blocks },
        );
        assert!(matches!(err, Err(XdmfError::Ragged { len: 2, nodes: 3, .. })));
        assert!(matches!(
            TimeSeriesWriter::create(dir.path(), "a:b", &Mesh { points: &points, blocks: &[] }),
            Err(XdmfError::BadStem(_))
        ));

        let tri = [0u32, 1, 2];
        let blocks = [CellBlock { kind: CellKind::Tri3, connectivity: Connectivity::U32(&tri) }];
        let mut w = TimeSeriesWriter::create(
            dir.path(),
            "fluid",
            &Mesh { points: &points, blocks: &blocks },
        )
        .unwrap();
        let two = [1.0, 2.0];
        let err = w.write_step(
            0.0,
            &[Field { name: "rho", location: Location::Node, values: Values::Scalar(&two) }],
        );
        let msg = err.unwrap_err().to_string();
        assert!(
            msg.contains("`rho`") && msg.contains("2 values") && msg.contains("3 Nodes"),
            "{msg}"
        );
        let one = [1.0];
        let ok = [Field { name: "p", location: Location::Cell, values: Values::Scalar(&one) }];
        w.write_step(0.0, &ok).unwrap();
        assert!(matches!(w.write_step(0.0, &ok), Err(XdmfError::TimeOrder { .. })));
        assert!(matches!(w.write_step(f64::NAN, &ok), Err(XdmfError::TimeOrder { .. })));
        let dup = [ok[0], ok[0]];
        assert!(matches!(w.write_step(1.0, &dup), Err(XdmfError::BadFieldName(_))));
        assert_eq!(w.steps(), 1);
        w.finish().unwrap();
    }
}
