//! Locality renumbering (`mesh::renumber`): a permutation of nodes and cells that keeps every
//! cell, set and user id; it brings the profile of a randomly numbered plate back to within a
//! small factor of the row-by-row one; and a randomly numbered input runs the same as the
//! natural one per user id: bitwise once renumbered (the storage order depends on the
//! geometry only), to round-off against the model built in the natural order as given.

use std::path::Path;
use std::process::Command;

use structure_solver::assembly::{FeModel, Part};
use structure_solver::elements::{ShellSection, ShellYield};
use structure_solver::mesh::generate::{block, cylinder, line, rectangle};
use structure_solver::mesh::merge::merge_coincident;
use structure_solver::mesh::renumber::{
    bandwidth_profile, mean_cell_spread, renumber, shuffle_numbering,
};
use structure_solver::mesh::{Cell, CellKind, Mesh};
use structure_solver::model::Model;
use structure_solver::time::CentralDifference;

/// Checks that `r` is `m` renumbered: both numberings are permutations and inverse pairs,
/// every slot holds its user's node (position, id) and cell (kind, nodes in their order), and
/// every set holds the same user numbers.
fn assert_renumbering_of(m: &Mesh, r: &Mesh) {
    let (nn, nc) = (m.nodes.len(), m.cells.len());
    for (what, numbering, n) in [("node", &r.node_numbering, nn), ("cell", &r.cell_numbering, nc)] {
        let mut seen = vec![false; n];
        assert_eq!(numbering.user.len(), n, "{what} numbering covers every slot");
        for (s, &u) in numbering.user.iter().enumerate() {
            assert!(!seen[u], "{what} user number {u} twice");
            seen[u] = true;
            assert_eq!(numbering.slot[u], s, "{what} slot of user {u}");
        }
    }
    for s in 0..nn {
        let u = r.node_user(s);
        assert_eq!(r.nodes[s], m.nodes[u], "node slot {s}");
        assert_eq!(r.node_id(s), m.node_id(u), "node id of slot {s}");
    }
    for c in 0..nc {
        let u = r.cell_user(c);
        assert_eq!(r.cells[c].kind, m.cells[u].kind);
        let nodes: Vec<usize> = r.cells[c].nodes.iter().map(|&n| r.node_user(n)).collect();
        assert_eq!(nodes, m.cells[u].nodes, "cell slot {c} (user {u})");
    }
    let users = |v: &[usize], f: &dyn Fn(usize) -> usize| {
        let mut u: Vec<usize> = v.iter().map(|&i| f(i)).collect();
        u.sort_unstable();
        u
    };
    let id = |i: usize| i;
    for (name, v) in &m.node_sets {
        let got = users(r.node_set(name).unwrap(), &|s| r.node_user(s));
        assert_eq!(got, users(v, &id), "node set {name}");
    }
    for (name, v) in &m.cell_sets {
        let got = users(r.cell_set(name).unwrap(), &|c| r.cell_user(c));
        assert_eq!(got, users(v, &id), "cell set {name}");
    }
}

#[test]
fn renumbering_is_a_permutation_keeping_cells_sets_and_ids() {
    let mut mixed = rectangle(2.0, 1.0, 6, 3);
    let beam = line([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], 4);
    let base = mixed.nodes.len();
    mixed.nodes.extend(beam.nodes.iter().skip(1));
    mixed.cells.extend(beam.cells.iter().map(|c| Cell {
        kind: c.kind,
        nodes: c.nodes.iter().map(|&n| if n == 0 { 0 } else { base + n - 1 }).collect(),
    }));
    let meshes = [
        ("rectangle", rectangle(1.0, 0.5, 7, 5)),
        ("shuffled rectangle", shuffle_numbering(&rectangle(1.0, 0.5, 7, 5), 7)),
        (
            "closed cylinder",
            merge_coincident(cylinder(1.0, 2.0, [0.0, std::f64::consts::TAU], 12, 4)).unwrap(),
        ),
        ("tet block", block([1.0, 2.0, 0.5], [3, 4, 2])),
        ("shells and a beam", mixed),
    ];
    for (name, m) in meshes {
        let r = renumber(m.clone());
        println!("{name}: {} nodes, {} cells", r.nodes.len(), r.cells.len());
        assert_renumbering_of(&m, &r);
        // renumbering again changes nothing and composes the user's numbers
        let again = renumber(r.clone());
        assert_eq!(again.nodes, r.nodes, "{name}");
        assert_eq!(again.cells, r.cells, "{name}");
        assert_renumbering_of(&m, &again);
        // a node added after renumbering takes the next user number
        let mut grown = r.clone();
        let s = grown.push_node([9.0, 9.0, 9.0]);
        assert_eq!((grown.node_user(s), grown.node_numbering.slot_of(s)), (s, s));
    }
}

#[test]
fn renumbering_brings_a_shuffled_plate_back_near_the_natural_profile() {
    let n = 100;
    let natural = rectangle(1.0, 1.0, n, n);
    let shuffled = shuffle_numbering(&natural, 0x5eed);
    let (renumbered, renumbered_shuffled) = (renumber(natural.clone()), renumber(shuffled.clone()));
    // the storage order is the geometry's, whatever the input numbering
    assert_eq!(renumbered.nodes, renumbered_shuffled.nodes);
    assert_eq!(renumbered.cells, renumbered_shuffled.cells);
    let row = |what: &str, m: &Mesh| {
        let (b, p) = bandwidth_profile(m);
        let spread = mean_cell_spread(m);
        println!(
            "{n} x {n} plate, {what}: bandwidth {b}, profile {p}, mean element spread {spread:.1}"
        );
        (b, p, spread)
    };
    let (b_nat, p_nat, s_nat) = row("natural (row by row)", &natural);
    let (b_sh, p_sh, s_sh) = row("shuffled", &shuffled);
    let (b_re, p_re, s_re) = row("shuffled, renumbered", &renumbered_shuffled);
    println!(
        "profile / natural: shuffled {:.1}, renumbered {:.2}; bandwidth / natural: shuffled {:.1}, renumbered {:.1}",
        p_sh as f64 / p_nat as f64,
        p_re as f64 / p_nat as f64,
        b_sh as f64 / b_nat as f64,
        b_re as f64 / b_nat as f64
    );
    assert!(p_sh > 30 * p_nat, "a random numbering has a profile of order n^2");
    assert!(p_re < 3 * p_nat, "renumbered profile {p_re} vs natural {p_nat}");
    assert!(s_re < 2.0 * s_nat && s_sh > 30.0 * s_nat);
}

/// A plate of BT4 (`bt4`) or MITC4 J2 shells clamped along `x = 0`, given an initial
/// velocity, after `steps` central-difference steps: the displacement of each node slot.
fn run_plate(mesh: &Mesh, bt4: bool, steps: usize) -> Vec<[f64; 3]> {
    let section = ShellSection { e: 200e9, nu: 0.3, rho: 7800.0, h: 0.01 };
    let y = ShellYield { sigma_y: 250e6, hardening: 1e9, points: 5 };
    let part = if bt4 { Part::Bt4(section, Some(y)) } else { Part::ShellJ2(section, y) };
    let mut model = FeModel::new(mesh, |_| part).unwrap();
    model.fix(&mesh.nodes_where(|p| p[0] == 0.0), [true; 6]);
    let mut v = vec![0.0; 6 * mesh.nodes.len()];
    for (i, p) in mesh.nodes.iter().enumerate() {
        v[6 * i] = 60.0 * p[0];
        v[6 * i + 2] = 20.0 * (3.0 * p[0]).sin() * (1.0 + p[1]);
    }
    let dt = 0.8 * model.stable_dt();
    let mut cd = CentralDifference::new(&mut model, 0.0, v, None);
    for _ in 0..steps {
        cd.step(&mut model, dt, None);
    }
    let mut u = vec![[0.0; 3]; mesh.nodes.len()];
    model.displacement(&mut u);
    u
}

#[test]
fn a_shuffled_plate_runs_as_the_natural_one_per_user_id() {
    let natural = rectangle(1.0, 0.6, 20, 12);
    let shuffled = renumber(shuffle_numbering(&natural, 0xabc));
    let renumbered = renumber(natural.clone());
    for bt4 in [true, false] {
        let kind = if bt4 { "BT4" } else { "MITC4" };
        let u_nat = run_plate(&natural, bt4, 60);
        let u_sh = run_plate(&shuffled, bt4, 60);
        let u_re = run_plate(&renumbered, bt4, 60);
        // the shuffled mesh's node ids are the natural numbers
        let scale = u_nat.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        let mut diff = 0.0f64;
        for (s, u) in u_sh.iter().enumerate() {
            let k = shuffled.node_id(s) as usize;
            assert_eq!(u, &u_re[s], "{kind}: node {k} differs bitwise from the natural input");
            diff = (0..3).fold(diff, |d, c| d.max((u[c] - u_nat[k][c]).abs()));
        }
        println!("{kind}: largest displacement {scale:.3e} m, shuffled and renumbered vs natural as given: {:.2e} relative", diff / scale);
        assert!(scale > 1e-3, "{kind}: the plate moves");
        assert!(diff <= 1e-12 * scale, "{kind}: {diff:e} vs {scale:e}");
    }
}

/// `mesh` (quadrilaterals only) as a gmsh 4.1 file: one surface, physical group "plate",
/// nodes and elements in the mesh's order, tags from 1.
fn write_msh(mesh: &Mesh, path: &Path) {
    use std::fmt::Write;
    let (nn, nc) = (mesh.nodes.len(), mesh.cells.len());
    let mut s = String::from("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n");
    s += "$PhysicalNames\n1\n2 1 \"plate\"\n$EndPhysicalNames\n";
    s += "$Entities\n0 0 1 0\n1 0 0 0 1 1 0 1 1 0\n$EndEntities\n";
    writeln!(s, "$Nodes\n1 {nn} 1 {nn}\n2 1 0 {nn}").unwrap();
    (1..=nn).for_each(|t| writeln!(s, "{t}").unwrap());
    mesh.nodes.iter().for_each(|p| writeln!(s, "{:e} {:e} {:e}", p[0], p[1], p[2]).unwrap());
    writeln!(s, "$EndNodes\n$Elements\n1 {nc} 1 {nc}\n2 1 3 {nc}").unwrap();
    for (k, c) in mesh.cells.iter().enumerate() {
        assert_eq!(c.kind, CellKind::Quad4);
        let n: Vec<String> = c.nodes.iter().map(|n| (n + 1).to_string()).collect();
        writeln!(s, "{} {}", k + 1, n.join(" ")).unwrap();
    }
    s += "$EndElements\n";
    std::fs::write(path, s).unwrap();
}

/// The case of `cases/structure-plastic-plate` on the gmsh file `mesh.msh`, shortened.
fn plate_case(dir: &Path) -> std::path::PathBuf {
    let case = Path::new(env!("CARGO_MANIFEST_DIR")).join("../cases/structure-plastic-plate");
    let text = std::fs::read_to_string(case.join("case.toml")).unwrap();
    let from = "mesh = { generator = \"rectangle\", lx = 0.1, ly = 0.1, nx = 10, ny = 10 }";
    assert!(text.contains(from));
    let text = text
        .replace(from, "mesh = { generator = \"gmsh\", file = \"mesh.msh\" }")
        .replace("t_end = 2e-2", "t_end = 1e-3")
        .replace("fields_every = 1000", "fields_every = 50");
    let path = dir.join("case.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// Node positions and the last step's displacement of `structure.h5`, by h5py.
const LAST_STEP: &str = r#"
import json, sys, h5py
with h5py.File(sys.argv[1], "r") as f:
    last = max(f["steps"].keys(), key=int)
    print(json.dumps({"points": f["mesh"]["points"][()].tolist(),
                      "u": f["steps"][last]["displacement"][()].tolist()}))
"#;

#[test]
fn a_shuffled_gmsh_file_gives_the_outputs_of_the_natural_one_per_user_id() {
    let probe = Command::new("python3").args(["-c", "import h5py"]).output();
    assert!(
        probe.is_ok_and(|o| o.status.success()),
        "python3 with h5py is needed to read structure.h5: run scripts/install-deps.sh"
    );
    let natural = rectangle(0.1, 0.1, 10, 10);
    let shuffled = shuffle_numbering(&natural, 0xfeed);
    let mut outputs = Vec::new();
    for (name, mesh) in [("natural", &natural), ("shuffled", &shuffled)] {
        let dir = tempfile::tempdir().unwrap();
        write_msh(mesh, &dir.path().join("mesh.msh"));
        let case = plate_case(dir.path());
        let out = dir.path().join("out");
        let o = Command::new(env!("CARGO_BIN_EXE_structure-solver"))
            .args(["run", case.to_str().unwrap(), "--quiet", "--out", out.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(o.status.success(), "{name}: {}", String::from_utf8_lossy(&o.stderr));
        let read = |f: &str| std::fs::read_to_string(out.join(f)).unwrap();
        let h5 = Command::new("python3")
            .args(["-c", LAST_STEP, out.join("structure.h5").to_str().unwrap()])
            .output()
            .unwrap();
        assert!(h5.status.success(), "h5py: {}", String::from_utf8_lossy(&h5.stderr));
        let h5: serde_json::Value = serde_json::from_slice(&h5.stdout).unwrap();
        outputs.push((read("structure_probes.csv"), read("structure_cells.csv"), h5, dir));
    }
    let ((probes_n, cells_n, h5_n, _), (probes_s, cells_s, h5_s, _)) = (&outputs[0], &outputs[1]);
    // the probe is the same node, its history bitwise the same
    assert!(probes_n.lines().count() > 10);
    assert_eq!(probes_n, probes_s, "structure_probes.csv");
    // the cell table: one row per user cell in the user's order; the same cell (its centroid)
    // carries bitwise the same values
    let rows = |t: &str| -> Vec<(String, String)> {
        t.lines()
            .skip(1)
            .map(|l| l.split_once(',').map(|(c, rest)| (c.to_string(), rest.to_string())).unwrap())
            .collect()
    };
    let (rows_n, rows_s) = (rows(cells_n), rows(cells_s));
    assert_eq!(rows_n.len(), 100);
    for (k, (c, _)) in rows_s.iter().enumerate() {
        assert_eq!(c, &k.to_string(), "the table's cells are the user's, in order");
    }
    let mut sorted_n: Vec<&String> = rows_n.iter().map(|r| &r.1).collect();
    let mut sorted_s: Vec<&String> = rows_s.iter().map(|r| &r.1).collect();
    sorted_n.sort();
    sorted_s.sort();
    assert_eq!(sorted_n, sorted_s, "cell rows by centroid");
    let plastic = rows_n.iter().filter(|r| r.1.split(',').nth(3) != Some("0e0")).count();
    println!("{plastic} of 100 cells yielded");
    assert!(plastic > 0);
    // structure.h5: node k of the shuffled file is node `node_id(k)` of the natural one
    let f = |v: &serde_json::Value| -> Vec<Vec<f64>> { serde_json::from_value(v.clone()).unwrap() };
    let (x_n, u_n, x_s, u_s) =
        (f(&h5_n["points"]), f(&h5_n["u"]), f(&h5_s["points"]), f(&h5_s["u"]));
    assert_eq!(x_n.len(), 121);
    let scale = u_n.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(scale > 1e-5, "the plate deflects: {scale:e}");
    for k in 0..x_s.len() {
        let n = shuffled.node_id(k) as usize;
        assert_eq!(x_s[k], x_n[n], "points of user node {k}");
        assert_eq!(u_s[k], u_n[n], "displacement of user node {k}");
        assert_eq!(x_n[n], natural.nodes[n].to_vec(), "natural points in the user's order");
    }
}

#[test]
fn the_wet_surface_keeps_the_users_order_when_renumbered() {
    use structure_solver::couple::wet_surface;
    let mut plate = rectangle(1.0, 0.5, 6, 4);
    let strip = plate.nodes_where(|p| p[0] < 0.4);
    plate.node_sets.insert("strip".into(), strip);
    let tets = block([1.0, 1.0, 1.0], [2, 2, 2]);
    for (mesh, set) in [(&plate, "all"), (&plate, "strip"), (&tets, "all")] {
        let m = shuffle_numbering(mesh, 11);
        let r = renumber(m.clone());
        let (given, renumbered) = (wet_surface(&m, set).unwrap(), wet_surface(&r, set).unwrap());
        // the same wet nodes (by user number) in the same order, the same faces
        let users: Vec<usize> = renumbered.nodes.iter().map(|&s| r.node_user(s)).collect();
        assert_eq!(users, given.nodes, "wet set {set}");
        assert_eq!(renumbered.elements, given.elements, "wet set {set}");
        assert!(!given.elements.is_empty());
    }
}

/// A model built from a case is stored in the renumbered order but keeps the user's ids in
/// its topology layer: node id `j (nx + 1) + i` of the rectangle generator names the node at
/// `(i / nx, j / ny)` and element id `j nx + i` the cell with those corner nodes, whatever slot
/// the renumbering gave them.
#[test]
fn a_model_built_from_a_case_names_nodes_and_elements_by_user_id() {
    use interface_protocol::case::Case;
    use structure_solver::assembly::{RotaryInertia, Store};
    let text = r#"[structure]
mesh = { generator = "rectangle", lx = 1.0, ly = 1.0, nx = 6, ny = 4 }
material = { e = 1e6, nu = 0.3, rho = 1.0 }
element = "shell"
thickness = 0.1
integrator = "newmark"
dt = 1e-3
t_end = 1e-2
"#;
    let case = Case::parse(text, Path::new("case.toml"), &[]).unwrap();
    let s = structure_solver::build::build(&case, RotaryInertia::Physical).unwrap();
    let (t, x0) = (s.model.topology(), s.model.initial_positions());
    let (nx, ny) = (6, 4);
    assert_eq!(t.nodes().len(), (nx + 1) * (ny + 1));
    let mut moved = 0;
    for j in 0..=ny {
        for i in 0..=nx {
            let id = (j * (nx + 1) + i) as u64;
            let slot = t.nodes().slot(id).expect("every user id has a slot");
            moved += usize::from(slot as u64 != id);
            assert_eq!(t.nodes().id(slot), Some(id));
            assert_eq!(s.mesh.node_id(slot), id, "the mesh and the model agree");
            let p = x0[slot];
            assert!((p.x - i as f64 / nx as f64).abs() < 1e-15, "node {id} at {p:?}");
            assert!((p.y - j as f64 / ny as f64).abs() < 1e-15, "node {id} at {p:?}");
        }
    }
    assert!(moved > 0, "the renumbering moved nodes");
    let mut moved = 0;
    for j in 0..ny {
        for i in 0..nx {
            let id = (j * nx + i) as u64;
            let c = t.elements().slot(id).expect("every element id has a slot");
            moved += usize::from(c as u64 != id);
            let corner = |i: usize, j: usize| (j * (nx + 1) + i) as u64;
            let want = [corner(i, j), corner(i + 1, j), corner(i + 1, j + 1), corner(i, j + 1)];
            let nodes: Vec<u64> = match t.store(c) {
                Some(Store::Element(e)) => s.model.elements()[e].nodes.clone(),
                other => panic!("element {id}: stored as {other:?}"),
            }
            .iter()
            .map(|&n| t.nodes().id(n).unwrap())
            .collect();
            assert_eq!(nodes, want, "element {id} (slot {c})");
        }
    }
    assert!(moved > 0, "the renumbering moved cells");
}
