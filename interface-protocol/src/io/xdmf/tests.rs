//! Read-back tests of the XDMF series through meshio and h5py.

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
    let vel =
        |k: usize| (0..n).map(|i| [i as f64, -(k as f64), 0.125 * i as f64]).collect::<Vec<_>>();
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
    let f =
        [Field { name: "traction", location: Location::Cell, values: Values::Vector(&traction) }];
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
    let err =
        TimeSeriesWriter::create(dir.path(), "fluid", &Mesh { points: &points, blocks: &blocks });
    assert!(matches!(err, Err(XdmfError::NodeOutOfRange { index: 3, points: 3, .. })));
    let ragged = [0u32, 1];
    let blocks = [CellBlock { kind: CellKind::Tri3, connectivity: Connectivity::U32(&ragged) }];
    let err =
        TimeSeriesWriter::create(dir.path(), "fluid", &Mesh { points: &points, blocks: &blocks });
    assert!(matches!(err, Err(XdmfError::Ragged { len: 2, nodes: 3, .. })));
    assert!(matches!(
        TimeSeriesWriter::create(dir.path(), "a:b", &Mesh { points: &points, blocks: &[] }),
        Err(XdmfError::BadStem(_))
    ));

    let tri = [0u32, 1, 2];
    let blocks = [CellBlock { kind: CellKind::Tri3, connectivity: Connectivity::U32(&tri) }];
    let mut w =
        TimeSeriesWriter::create(dir.path(), "fluid", &Mesh { points: &points, blocks: &blocks })
            .unwrap();
    let two = [1.0, 2.0];
    let err = w.write_step(
        0.0,
        &[Field { name: "rho", location: Location::Node, values: Values::Scalar(&two) }],
    );
    let msg = err.unwrap_err().to_string();
    assert!(msg.contains("`rho`") && msg.contains("2 values") && msg.contains("3 Nodes"), "{msg}");
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

/// Reads every grid's own geometry of an XDMF time series with meshio (its reader pointed at
/// each grid of the temporal collection in turn), as JSON `[[t, points], ...]`.
const MOVED_READER: &str = r#"
import json, sys
import meshio
out = []
with meshio.xdmf.TimeSeriesReader(sys.argv[1]) as r:
    grids = list(r.collection)
    for k in range(r.num_steps):
        r.mesh_grid = grids[k]
        points, cells = r.read_points_cells()
        t, _, _ = r.read_data(k)
        out.append([t, points.tolist(), [c.type for c in cells]])
print(json.dumps(out))
"#;

#[test]
fn moved_steps_carry_their_own_geometry() {
    let dir = tempfile::tempdir().unwrap();
    let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
    let quad = [0u32, 1, 3, 2];
    let blocks = [CellBlock { kind: CellKind::Quad4, connectivity: Connectivity::U32(&quad) }];
    let mesh = Mesh { points: &points, blocks: &blocks };
    let mut w = TimeSeriesWriter::create(dir.path(), "surface", &mesh).unwrap();
    let moved = |t: f64| points.map(|p| [p[0] + 2.0 * t, p[1], p[2] - t]);
    for t in [0.0, 0.5, 1.5] {
        let speed = [2.0; 4];
        let f = [Field { name: "speed", location: Location::Node, values: Values::Scalar(&speed) }];
        w.write_moved_step(t, &moved(t), &f).unwrap();
    }
    let wrong = [[0.0; 3]; 3];
    assert!(matches!(
        w.write_moved_step(2.0, &wrong, &[]),
        Err(XdmfError::MovedPoints { expected: 4, got: 3 })
    ));
    let xdmf = w.xdmf_path().to_path_buf();
    w.finish().unwrap();
    let got = python(MOVED_READER, &[&xdmf]);
    let steps = got.as_array().unwrap();
    assert_eq!(steps.len(), 3);
    for (s, t) in steps.iter().zip([0.0, 0.5, 1.5]) {
        assert_eq!(s[0].as_f64().unwrap(), t);
        assert_eq!(f64s(&s[1]), moved(t).as_flattened());
        assert_eq!(s[2], serde_json::json!(["quad"]));
    }
}
