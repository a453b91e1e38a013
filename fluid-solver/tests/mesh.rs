//! Mesh invariants: dual volumes fill the domain, every dual cell is closed, least-squares
//! gradients are exact on linear fields, and bad meshes give named errors.

use fluid_solver::mesh::boxmesh::{BoxCells, BoxSpec};
use fluid_solver::mesh::geometry::norm;
use fluid_solver::mesh::{perturb, Cell, CellKind, Mesh, MeshError, RawMesh, TaggedFace};
use fluid_solver::reconstruct::gradient::LsqGradient;

fn graded(shape: BoxCells) -> BoxSpec {
    BoxSpec {
        lo: [-1.0, 0.0, 2.0],
        hi: [1.0, 0.5, 3.0],
        cells: [7, 4, 5],
        grading: [1.2, 0.8, 1.0],
        core: [3, 0, 2],
        shape,
    }
}

/// Asserts the closure and volume invariants; returns the mesh.
fn check_invariants(raw: RawMesh, volume: f64) -> Mesh {
    let mesh = Mesh::build(raw).expect("valid mesh");
    let total = mesh.total_volume();
    assert!((total - volume).abs() < 1e-12 * volume, "dual volumes {total} vs domain {volume}");
    assert!(mesh.volumes.iter().all(|&v| v > 0.0));
    let scale = mesh.edge_normals.iter().map(|n| norm(*n)).fold(0.0, f64::max);
    for (i, defect) in mesh.closure_defects().into_iter().enumerate() {
        let d = norm(defect);
        assert!(d < 1e-13 * scale, "node {i}: closure defect {d:e}");
    }
    // Edges sorted by (i, j) with i < j; the edge blocks cover all edges in order, and each
    // block's edges stay inside its window.
    assert!(mesh.edges.windows(2).all(|w| w[0] < w[1]));
    assert!(mesh.edges.iter().all(|e| e[0] < e[1]));
    let blocks = &mesh.blocks;
    assert_eq!(blocks.edges(0).start, 0);
    assert_eq!(blocks.edges(blocks.len() - 1).end, mesh.n_edges());
    for b in 0..blocks.len() {
        if b > 0 {
            assert_eq!(blocks.edges(b).start, blocks.edges(b - 1).end);
        }
        let (nodes, window) = (blocks.nodes(b), blocks.window(b));
        for &[i, j] in &mesh.edges[blocks.edges(b)] {
            assert!(nodes.contains(&(i as usize)) && window.contains(&(j as usize)), "block {b}");
        }
    }
    mesh
}

#[test]
fn box_meshes_are_closed_and_fill_the_domain() {
    for shape in [BoxCells::Hex, BoxCells::Tet] {
        let mesh = check_invariants(graded(shape).raw().unwrap(), 2.0 * 0.5 * 1.0);
        assert_eq!(mesh.n_nodes(), 8 * 5 * 6);
        assert_eq!(mesh.boundary_names(), ["xmin", "xmax", "ymin", "ymax", "zmin", "zmax"]);
        // The boundary area vectors of a face sum to its area times its outward normal.
        let xmax = mesh.boundary("xmax").unwrap();
        let s: f64 = xmax.normals.iter().map(|n| n[0]).sum();
        assert!((s - 0.5).abs() < 1e-13, "{s}");
    }
}

/// A core of equal cells, then geometric grading: along x of [`graded`], cells 1-3 equal and each
/// after them 1.2 times the previous; along z cells 1-2 equal, then uniform; along y (no core)
/// every cell 0.8 times the previous.
#[test]
fn a_box_core_has_equal_cells_then_grades() {
    let mesh = Mesh::build(graded(BoxCells::Hex).raw().unwrap()).unwrap();
    let axis = |d: usize| {
        let mut x: Vec<f64> = mesh.coords.iter().map(|c| c[d]).collect();
        x.sort_by(f64::total_cmp);
        x.dedup();
        x.windows(2).map(|w| w[1] - w[0]).collect::<Vec<f64>>()
    };
    let (hx, hy, hz) = (axis(0), axis(1), axis(2));
    assert_eq!((hx.len(), hy.len(), hz.len()), (7, 4, 5));
    let close = |a: f64, b: f64| (a - b).abs() < 1e-12 * b.abs();
    assert!(close(hx[1], hx[0]) && close(hx[2], hx[0]), "{hx:?}");
    assert!((3..7).all(|k| close(hx[k], 1.2 * hx[k - 1])), "{hx:?}");
    assert!((1..4).all(|k| close(hy[k], 0.8 * hy[k - 1])), "{hy:?}");
    assert!(hz.iter().all(|&h| close(h, 0.2)), "{hz:?}");
    let too_deep = BoxSpec { core: [8, 0, 0], ..graded(BoxCells::Hex) };
    assert!(matches!(too_deep.raw(), Err(MeshError::Input(_))));
}

#[test]
fn perturbed_meshes_are_closed() {
    for shape in [BoxCells::Hex, BoxCells::Tet] {
        let mut raw = BoxSpec::uniform([0.0; 3], [1.0; 3], [6, 5, 4], shape).raw().unwrap();
        perturb(&mut raw, 0.2, 7);
        check_invariants(raw, 1.0);
    }
}

#[test]
fn tubes_are_one_cell_thick() {
    for shape in [BoxCells::Hex, BoxCells::Tet] {
        let mesh = check_invariants(BoxSpec::tube(0.0, 1.0, 10, 0.1, shape).raw().unwrap(), 0.01);
        assert_eq!(mesh.n_nodes(), 44);
    }
}

/// A unit cube split into two prisms and, around its centre, six pyramids.
#[test]
fn prisms_and_pyramids_are_closed() {
    let cube: Vec<[f64; 3]> = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
        [0.0, 1.0, 1.0],
    ];
    let hex_faces: [[u32; 4]; 6] =
        [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]];
    // Prisms: triangles (0,1,2),(0,2,3) extruded.
    let prisms = RawMesh {
        coords: cube.clone(),
        cells: vec![
            Cell::new(CellKind::Prism, &[0, 1, 2, 4, 5, 6]),
            Cell::new(CellKind::Prism, &[0, 2, 3, 4, 6, 7]),
        ],
        faces: vec![
            TaggedFace { patch: 0, nodes: vec![0, 1, 2] },
            TaggedFace { patch: 0, nodes: vec![0, 2, 3] },
            TaggedFace { patch: 0, nodes: vec![4, 5, 6] },
            TaggedFace { patch: 0, nodes: vec![4, 6, 7] },
            TaggedFace { patch: 1, nodes: vec![0, 1, 5, 4] },
            TaggedFace { patch: 1, nodes: vec![1, 2, 6, 5] },
            TaggedFace { patch: 1, nodes: vec![2, 3, 7, 6] },
            TaggedFace { patch: 1, nodes: vec![3, 0, 4, 7] },
        ],
        patch_names: vec!["caps".into(), "sides".into()],
        origin: "prisms".into(),
    };
    check_invariants(prisms, 1.0);
    let mut coords = cube;
    coords.push([0.5, 0.5, 0.5]);
    let pyramids = RawMesh {
        coords,
        // Each outward face reversed as the base, apex at the centre.
        cells: hex_faces
            .iter()
            .map(|f| Cell::new(CellKind::Pyramid, &[f[0], f[3], f[2], f[1], 8]))
            .collect(),
        faces: hex_faces.iter().map(|f| TaggedFace { patch: 0, nodes: f.to_vec() }).collect(),
        patch_names: vec!["all".into()],
        origin: "pyramids".into(),
    };
    let mesh = check_invariants(pyramids, 1.0);
    assert_eq!(mesh.n_edges(), 12 + 8);
}

#[test]
fn least_squares_gradients_are_exact_on_linear_fields() {
    let g = [
        [1.0, -2.0, 0.5],
        [0.0, 3.0, 1.0],
        [2.0, 0.0, -1.0],
        [-0.5, 0.25, 4.0],
        [10.0, 20.0, 30.0],
    ];
    let c = [1.0, 2.0, -3.0, 0.5, 100.0];
    for shape in [BoxCells::Hex, BoxCells::Tet] {
        let mut raw = graded(shape).raw().unwrap();
        perturb(&mut raw, 0.2, 3);
        let mesh = Mesh::build(raw).unwrap();
        let lsq = LsqGradient::new(&mesh);
        let values: Vec<[f64; 5]> = mesh
            .coords
            .iter()
            .map(|x| {
                std::array::from_fn(|k| c[k] + g[k][0] * x[0] + g[k][1] * x[1] + g[k][2] * x[2])
            })
            .collect();
        let mut grad = vec![[[0.0; 3]; 5]; mesh.n_nodes()];
        lsq.compute(&mesh, &values, &mut grad);
        for gi in &grad {
            for k in 0..5 {
                for d in 0..3 {
                    assert!(
                        (gi[k][d] - g[k][d]).abs() < 1e-10 * 30.0,
                        "{shape:?} {k} {d}: {}",
                        gi[k][d]
                    );
                }
            }
        }
        // Dropping edges keeps linear fields exact where 3D stencils remain.
        let mask: Vec<bool> = (0..mesh.n_edges()).map(|e| e % 5 != 0).collect();
        let masked = LsqGradient::with_mask(&mesh, Some(&mask));
        masked.compute(&mesh, &values, &mut grad);
        let exact = grad.iter().filter(|gi| (gi[4][2] - 30.0).abs() < 1e-8).count();
        let zero = grad.iter().filter(|gi| gi[4] == [0.0; 3]).count();
        assert_eq!(exact + zero, mesh.n_nodes());
        assert!(exact > mesh.n_nodes() / 2);
    }
}

#[test]
fn renumbering_reduces_the_bandwidth() {
    let raw = BoxSpec::uniform([0.0; 3], [1.0; 3], [12, 12, 12], BoxCells::Tet).raw().unwrap();
    let mesh = Mesh::build(raw).unwrap();
    let bandwidth = mesh.edges.iter().map(|e| e[1] - e[0]).max().unwrap();
    // Lexicographic numbering has bandwidth 13 * 13 + 13 + 1 = 183 for this mesh.
    assert!(bandwidth < 183, "bandwidth {bandwidth}");
    // original_ids is a permutation.
    let mut ids = mesh.original_ids.clone();
    ids.sort_unstable();
    assert!(ids.iter().enumerate().all(|(k, &v)| k as u32 == v));
}

#[test]
fn bad_meshes_give_named_errors() {
    let mut raw = BoxSpec::uniform([0.0; 3], [1.0; 3], [2, 2, 2], BoxCells::Tet).raw().unwrap();
    raw.cells[3].nodes.swap(0, 1);
    let e = Mesh::build(raw).unwrap_err();
    assert!(matches!(e, MeshError::BadCell { cell: 3, .. }), "{e}");
    assert!(e.to_string().contains("inverted"), "{e}");

    // A hex that lists a corner twice keeps a positive volume: refused, naming cell and node.
    let mut raw = BoxSpec::uniform([0.0; 3], [1.0; 3], [2, 2, 2], BoxCells::Hex).raw().unwrap();
    raw.cells[5].nodes[3] = raw.cells[5].nodes[2];
    let node = raw.cells[5].nodes[2];
    let e = Mesh::build(raw).unwrap_err();
    assert!(matches!(e, MeshError::RepeatedNode { cell: 5, node: n, .. } if n == node), "{e}");
    assert!(e.to_string().contains(&format!("cell 5 (hexahedron) lists node {node} twice")), "{e}");

    let mut raw = BoxSpec::uniform([0.0; 3], [1.0; 3], [2, 2, 2], BoxCells::Hex).raw().unwrap();
    raw.faces.pop();
    let e = Mesh::build(raw).unwrap_err();
    assert!(matches!(e, MeshError::OpenBoundary { .. }), "{e}");

    let mut raw = BoxSpec::uniform([0.0; 3], [1.0; 3], [2, 2, 2], BoxCells::Hex).raw().unwrap();
    raw.faces[0].nodes = vec![0, 1, 26];
    let e = Mesh::build(raw).unwrap_err();
    assert!(matches!(e, MeshError::OrphanFace { .. }), "{e}");

    let mesh =
        Mesh::build(BoxSpec::uniform([0.0; 3], [1.0; 3], [1, 1, 1], BoxCells::Hex).raw().unwrap())
            .unwrap();
    let e = mesh.boundary("inlet").unwrap_err();
    assert!(
        e.to_string().contains("unknown boundary `inlet`") && e.to_string().contains("xmin"),
        "{e}"
    );
}
