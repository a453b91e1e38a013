//! The gmsh 4.1 reader on meshes made by gmsh itself (`tests/fixtures/`, written by
//! `tests/fixtures/make_meshes.py` with gmsh 4.15.2): a tet box (ASCII and binary), a transfinite
//! hex box, extruded prisms and a hex/tet box joined by pyramids, each with named physical groups.
//! Each loads; the dual volumes fill the geometric volume; the boundary area vectors close and
//! each named face has its area and outward normal; each named group carries its own boundary
//! condition; a free stream is preserved through RK2 steps; a case runs on one. Also a mesh
//! written here in the 4.1 ASCII format (sparse node tags, mixed blocks) reads back into the same
//! dual mesh, unused sections are skipped, and bad files (truncated, unknown element type, no
//! `$PhysicalNames`, inverted element, unknown node, unterminated section, wrong version) give
//! errors naming the file and line.

mod common;

use common::msh::to_msh;
use fluid_solver::bc::BoundaryCondition;
use fluid_solver::eos::Eos;
use fluid_solver::flux::FluxScheme;
use fluid_solver::initial::InitialCondition;
use fluid_solver::mesh::boxmesh::{BoxCells, BoxSpec};
use fluid_solver::mesh::geometry::norm;
use fluid_solver::mesh::{gmsh, CellKind, Mesh};
use fluid_solver::reconstruct::limiter::Limiter;
use fluid_solver::semidiscretization::{Numerics, Semidiscretization};
use fluid_solver::state::Workspace;
use fluid_solver::time::{rk2_step, TimeStepping};
use std::path::{Path, PathBuf};

const GAS: Eos = Eos::PerfectGas { gamma: 1.4 };

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(name)
}

/// A fixture: its file, the geometric volume, the cell kinds it holds, and per named group the
/// expected sum of the boundary area vectors and of their L1 norms (the faces are axis-aligned,
/// so the latter is the group's area even where two faces of one group meet at an edge).
struct Fixture {
    file: &'static str,
    volume: f64,
    kinds: &'static [CellKind],
    groups: Vec<(&'static str, [f64; 3], f64)>,
}

/// The six faces of the box `[0, a] x [0, b] x [0, c]` named as the box mesher names them.
fn box_groups(a: f64, b: f64, c: f64) -> Vec<(&'static str, [f64; 3], f64)> {
    vec![
        ("xmin", [-b * c, 0.0, 0.0], b * c),
        ("xmax", [b * c, 0.0, 0.0], b * c),
        ("ymin", [0.0, -a * c, 0.0], a * c),
        ("ymax", [0.0, a * c, 0.0], a * c),
        ("zmin", [0.0, 0.0, -a * b], a * b),
        ("zmax", [0.0, 0.0, a * b], a * b),
    ]
}

fn fixtures() -> Vec<Fixture> {
    vec![
        Fixture {
            file: "tet_box.msh",
            volume: 0.48,
            kinds: &[CellKind::Tet],
            groups: box_groups(1.0, 0.8, 0.6),
        },
        Fixture {
            file: "tet_box_binary.msh",
            volume: 0.48,
            kinds: &[CellKind::Tet],
            groups: box_groups(1.0, 0.8, 0.6),
        },
        Fixture {
            file: "hex_box.msh",
            volume: 0.125,
            kinds: &[CellKind::Hex],
            groups: box_groups(1.0, 0.5, 0.25),
        },
        Fixture {
            file: "prism_slab.msh",
            volume: 0.5,
            kinds: &[CellKind::Prism],
            groups: vec![
                ("inlet", [-0.5, 0.0, 0.0], 0.5),
                ("outlet", [0.5, 0.0, 0.0], 0.5),
                ("bottom", [0.0, 0.0, -1.0], 1.0),
                ("top", [0.0, 0.0, 1.0], 1.0),
                ("sides", [0.0; 3], 1.0),
            ],
        },
        Fixture {
            file: "pyramid_box.msh",
            volume: 1.0,
            kinds: &[CellKind::Hex, CellKind::Tet, CellKind::Pyramid],
            groups: vec![
                ("west", [-1.0, 0.0, 0.0], 1.0),
                ("east", [1.0, 0.0, 0.0], 1.0),
                ("walls", [0.0; 3], 4.0),
            ],
        },
    ]
}

fn load(f: &Fixture) -> Mesh {
    let raw = gmsh::read(&fixture(f.file)).unwrap_or_else(|e| panic!("{}: {e}", f.file));
    let mut kinds: Vec<CellKind> = Vec::new();
    for c in &raw.cells {
        if !kinds.contains(&c.kind) {
            kinds.push(c.kind);
        }
    }
    for k in f.kinds {
        assert!(kinds.contains(k), "{}: no {k:?} cells (has {kinds:?})", f.file);
    }
    assert_eq!(kinds.len(), f.kinds.len(), "{}: cell kinds {kinds:?}", f.file);
    let mut names = raw.patch_names.clone();
    names.sort();
    let mut want: Vec<String> = f.groups.iter().map(|g| g.0.to_string()).collect();
    want.sort();
    assert_eq!(names, want, "{}", f.file);
    Mesh::build(raw).unwrap_or_else(|e| panic!("{}: {e}", f.file))
}

#[test]
fn gmsh_fixtures_fill_their_volume_and_name_their_faces() {
    for f in fixtures() {
        let mesh = load(&f);
        let total = mesh.total_volume();
        assert!((total - f.volume).abs() < 1e-13 * f.volume, "{}: {total} vs {}", f.file, f.volume);
        assert!(mesh.volumes.iter().all(|&v| v > 0.0), "{}", f.file);
        let scale = mesh.edge_normals.iter().map(|n| norm(*n)).fold(0.0, f64::max);
        for (i, defect) in mesh.closure_defects().iter().enumerate() {
            let d = norm(*defect);
            assert!(d < 1e-13 * scale, "{}: node {i}: closure defect {d:e}", f.file);
        }
        let mut closed = [0.0; 3];
        for (name, vector, area) in &f.groups {
            let b = mesh.boundary(name).unwrap();
            let mut sum = [0.0; 3];
            let mut l1 = 0.0;
            for n in &b.normals {
                for d in 0..3 {
                    sum[d] += n[d];
                    closed[d] += n[d];
                }
                l1 += n.iter().map(|v| v.abs()).sum::<f64>();
            }
            assert!(
                (0..3).all(|d| (sum[d] - vector[d]).abs() < 1e-13),
                "{} `{name}`: area vector {sum:?}, expected {vector:?}",
                f.file
            );
            assert!((l1 - area).abs() < 1e-13, "{} `{name}`: area {l1}, expected {area}", f.file);
        }
        assert!(closed.iter().all(|v| v.abs() < 1e-13), "{}: boundary sums to {closed:?}", f.file);
        println!(
            "{}: {} nodes, {} edges, {} cells, volume {total:.15}",
            f.file,
            mesh.n_nodes(),
            mesh.n_edges(),
            mesh.cells.len()
        );
    }
}

#[test]
fn binary_and_ascii_fixtures_read_alike() {
    let a = gmsh::read(&fixture("tet_box.msh")).unwrap();
    let b = gmsh::read(&fixture("tet_box_binary.msh")).unwrap();
    assert_eq!(a.coords.len(), b.coords.len());
    // The ASCII file prints 16 significant digits.
    for (p, q) in a.coords.iter().zip(&b.coords) {
        assert!((0..3).all(|d| (p[d] - q[d]).abs() < 1e-15), "{p:?} vs {q:?}");
    }
    assert_eq!(a.cells, b.cells);
    assert_eq!(a.faces, b.faces);
    assert_eq!(a.patch_names, b.patch_names);
}

/// Sections the reader does not use are skipped, whatever they hold.
#[test]
fn unused_sections_are_skipped() {
    let dir = tempfile::tempdir().unwrap();
    let hexes = std::fs::read_to_string(fixture("hex_box.msh")).unwrap();
    let extra = "$EndMeshFormat\n$Comments\nmade by hand: $Nodes 1 2 3\n$EndComments\n";
    let path = dir.path().join("commented.msh");
    std::fs::write(&path, hexes.replacen("$EndMeshFormat\n", extra, 1)).unwrap();
    let a = gmsh::read(&fixture("hex_box.msh")).unwrap();
    let b = gmsh::read(&path).unwrap();
    assert_eq!((a.coords, a.cells, a.faces), (b.coords, b.cells, b.faces));
}

/// With the fluid at rest and slip walls everywhere but on one named group, an outflow at a
/// lower pressure there, the residual is non-zero exactly at the nodes of that group: each name
/// carries its own condition to its own faces.
#[test]
fn each_named_group_carries_its_own_boundary_condition() {
    let rest = [1.0, 0.0, 0.0, 0.0, 1.0];
    for f in fixtures() {
        let mesh = load(&f);
        for (open, _, _) in &f.groups {
            let conditions: Vec<(String, BoundaryCondition)> = f
                .groups
                .iter()
                .map(|(name, _, _)| {
                    let bc = if name == open {
                        BoundaryCondition::Outflow { pressure: 0.5 }
                    } else {
                        BoundaryCondition::SlipWall
                    };
                    (name.to_string(), bc)
                })
                .collect();
            let numerics = Numerics { flux: FluxScheme::Roe, limiter: Limiter::VanAlbada };
            let semi = Semidiscretization::new(mesh.clone(), GAS, numerics, &conditions).unwrap();
            let state = InitialCondition::uniform(rest).state(&semi.mesh, &[GAS]).unwrap();
            let mut ws = Workspace::new(semi.mesh.n_nodes());
            semi.residual(&state.cons, &mut ws).unwrap();
            let moved: Vec<u32> = (0..semi.mesh.n_nodes() as u32)
                .filter(|&i| ws.residual[i as usize].iter().any(|r| r.abs() > 1e-12))
                .collect();
            assert_eq!(moved, semi.mesh.boundary(open).unwrap().nodes, "{} `{open}`", f.file);
        }
    }
}

/// A uniform subsonic stream with far field, inflow and outflow conditions on the named groups
/// stays uniform to round-off through RK2 steps, on every fixture.
#[test]
fn free_stream_is_preserved_on_gmsh_meshes() {
    let w = [1.2, 0.3, -0.2, 0.1, 0.9];
    for f in fixtures() {
        let mesh = load(&f);
        let conditions: Vec<(String, BoundaryCondition)> = f
            .groups
            .iter()
            .enumerate()
            .map(|(k, (name, _, _))| {
                let bc = match k {
                    0 => BoundaryCondition::Inflow { state: w },
                    1 => BoundaryCondition::Outflow { pressure: w[4] },
                    _ => BoundaryCondition::FarField { state: w },
                };
                (name.to_string(), bc)
            })
            .collect();
        for flux in [FluxScheme::Roe, FluxScheme::Hllc] {
            let numerics = Numerics { flux, limiter: Limiter::VanAlbada };
            let semi = Semidiscretization::new(mesh.clone(), GAS, numerics, &conditions).unwrap();
            let mut state = InitialCondition::uniform(w).state(&semi.mesh, &[GAS]).unwrap();
            let initial = state.clone();
            let mut ws = Workspace::new(semi.mesh.n_nodes());
            for _ in 0..5 {
                let dt =
                    rk2_step(&semi, &mut state, &mut ws, TimeStepping::Global { cfl: 0.9 }, 1.0)
                        .unwrap();
                assert!(dt > 0.0);
            }
            let q0 = GAS.prim_to_cons(&w);
            let mut worst: f64 = 0.0;
            for (a, b) in state.cons.iter().zip(&initial.cons) {
                for k in 0..5 {
                    worst = worst.max((a[k] - b[k]).abs() / q0[k].abs().max(1.0));
                }
            }
            assert!(worst < 1e-13, "{} {flux:?}: free stream drifts by {worst:e}", f.file);
        }
    }
}

#[test]
fn gmsh_files_read_back_into_the_same_dual_mesh() {
    let dir = tempfile::tempdir().unwrap();
    for shape in [BoxCells::Tet, BoxCells::Hex] {
        let raw = BoxSpec::uniform([0.0; 3], [1.0, 2.0, 0.5], [3, 4, 2], shape).raw().unwrap();
        let path = dir.path().join("box.msh");
        std::fs::write(&path, to_msh(&raw)).unwrap();
        let read = gmsh::read(&path).unwrap();
        assert_eq!(read.patch_names, raw.patch_names);
        let a = Mesh::build(raw).unwrap();
        let b = Mesh::build(read).unwrap();
        assert_eq!(a.n_edges(), b.n_edges());
        assert!((b.total_volume() - 1.0).abs() < 1e-12);
        for name in a.boundary_names() {
            let (ba, bb) = (a.boundary(&name).unwrap(), b.boundary(&name).unwrap());
            let sum = |bd: &fluid_solver::mesh::Boundary| {
                bd.normals.iter().fold([0.0; 3], |s, n| [s[0] + n[0], s[1] + n[1], s[2] + n[2]])
            };
            let (sa, sb) = (sum(ba), sum(bb));
            assert!((0..3).all(|k| (sa[k] - sb[k]).abs() < 1e-12), "{name}: {sa:?} vs {sb:?}");
        }
    }
}

/// The error of reading `content` written as `dir/name`.
fn read_error(dir: &Path, name: &str, content: &[u8]) -> String {
    let path = dir.join(name);
    std::fs::write(&path, content).unwrap();
    let e = gmsh::read(&path).map(|_| ()).expect_err(name).to_string();
    println!("{e}");
    e
}

/// 1-based number of the first line of `text` satisfying `pred` after line `after`.
fn line_where(text: &str, after: usize, pred: impl Fn(&str) -> bool) -> usize {
    text.lines().enumerate().skip(after).find(|(_, l)| pred(l)).unwrap().0 + 1
}

/// Whether `line` is the header of a block of volume elements of gmsh type `code`.
fn block_of(line: &str, code: &str) -> bool {
    let f: Vec<&str> = line.split(' ').collect();
    f.len() == 4 && f[0] == "3" && f[2] == code
}

/// Replaces line `n` (1-based) of `text`.
fn with_line(text: &str, n: usize, line: &str) -> String {
    let mut lines: Vec<&str> = text.lines().collect();
    lines[n - 1] = line;
    lines.join("\n") + "\n"
}

#[test]
fn bad_gmsh_files_give_errors_naming_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let tets = std::fs::read_to_string(fixture("tet_box.msh")).unwrap();
    let hexes = std::fs::read_to_string(fixture("hex_box.msh")).unwrap();

    // Truncated inside $Elements: the error is at the end of the file.
    let cut = &hexes[..hexes.len() * 3 / 4];
    let e = read_error(dir.path(), "cut.msh", cut.as_bytes());
    let last = 1 + cut.matches('\n').count();
    assert!(e.contains(&format!("cut.msh:{last}:")) && e.contains("truncated"), "{e}");
    // A binary file cut in its node data: the byte offset is named.
    let binary = std::fs::read(fixture("tet_box_binary.msh")).unwrap();
    let e = read_error(dir.path(), "cut_binary.msh", &binary[..binary.len() / 2]);
    assert!(e.contains("cut_binary.msh: byte ") && e.contains("truncated"), "{e}");
    // Big-endian binary data is refused by name (the byte-order integer 1 follows the header).
    let mark = binary.windows(8).position(|w| w == b"4.1 1 8\n").unwrap() + 8;
    let mut swapped = binary.clone();
    swapped[mark..mark + 4].copy_from_slice(&[0, 0, 0, 1]);
    let e = read_error(dir.path(), "big_endian.msh", &swapped);
    assert!(e.contains("big_endian.msh:3:") && e.contains("big-endian"), "{e}");

    // Unknown (second-order) element type in the hex block header.
    let elements = line_where(&hexes, 0, |l| l == "$Elements");
    let header = line_where(&hexes, elements, |l| block_of(l, "5"));
    let fields: Vec<&str> = hexes.lines().nth(header - 1).unwrap().split(' ').collect();
    let bad = format!("{} {} 12 {}", fields[0], fields[1], fields[3]);
    let e = read_error(dir.path(), "order2.msh", with_line(&hexes, header, &bad).as_bytes());
    assert!(
        e.contains(&format!("order2.msh:{header}:"))
            && e.contains("element type 12")
            && e.contains("second-order hexahedron"),
        "{e}"
    );

    // No $PhysicalNames: the error points at a surface entity of a physical group.
    let start = tets.find("$PhysicalNames").unwrap();
    let end = tets.find("$EndPhysicalNames\n").unwrap() + "$EndPhysicalNames\n".len();
    let unnamed = format!("{}{}", &tets[..start], &tets[end..]);
    let e = read_error(dir.path(), "unnamed.msh", unnamed.as_bytes());
    let entities = line_where(&unnamed, 0, |l| l == "$Entities");
    let end_entities = line_where(&unnamed, 0, |l| l == "$EndEntities");
    let line: usize = e
        .strip_prefix(&format!("{}:", dir.path().join("unnamed.msh").display()))
        .and_then(|r| r.split(':').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no line in: {e}"));
    assert!(line > entities && line < end_entities, "{e}");
    assert!(e.contains("no `$PhysicalNames`") && e.contains("physical group"), "{e}");

    // Inverted cells: a tet with two nodes swapped, a mirrored hex.
    let elements = line_where(&tets, 0, |l| l == "$Elements");
    let block = line_where(&tets, elements, |l| block_of(l, "4"));
    let mut t: Vec<&str> = tets.lines().nth(block).unwrap().split(' ').collect();
    t.swap(2, 3);
    let e = read_error(
        dir.path(),
        "inverted_tet.msh",
        with_line(&tets, block + 1, &t.join(" ")).as_bytes(),
    );
    let at = format!("inverted_tet.msh:{}:", block + 1);
    assert!(
        e.contains(&at) && e.contains(&format!("element {} (tetrahedron) is inverted", t[0])),
        "{e}"
    );
    let mut h: Vec<&str> = hexes.lines().nth(header).unwrap().split(' ').collect();
    h.swap(2, 4);
    h.swap(6, 8);
    let e = read_error(
        dir.path(),
        "inverted_hex.msh",
        with_line(&hexes, header + 1, &h.join(" ")).as_bytes(),
    );
    assert!(
        e.contains(&format!("inverted_hex.msh:{}:", header + 1))
            && e.contains("(hexahedron) is inverted"),
        "{e}"
    );

    // A node tag that is not in $Nodes.
    let mut h: Vec<&str> = hexes.lines().nth(header).unwrap().split(' ').collect();
    h[3] = "999999";
    let e = read_error(
        dir.path(),
        "ghost_node.msh",
        with_line(&hexes, header + 1, &h.join(" ")).as_bytes(),
    );
    assert!(
        e.contains(&format!("ghost_node.msh:{}:", header + 1))
            && e.contains("node 999999, which is not in `$Nodes`"),
        "{e}"
    );

    // A section without its end.
    let open = &hexes[..hexes.find("$EndPhysicalNames").unwrap()];
    let e = read_error(dir.path(), "open.msh", open.as_bytes());
    assert!(e.contains("open.msh:") && e.contains("$EndPhysicalNames"), "{e}");
}

#[test]
fn gmsh_errors_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.msh");
    std::fs::write(&path, "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n").unwrap();
    let e = gmsh::read(&path).unwrap_err().to_string();
    assert!(e.contains("bad.msh") && e.contains("4.1"), "{e}");
    // A boundary surface without a physical group leaves dual cells open: named in the error.
    let mut raw = BoxSpec::uniform([0.0; 3], [1.0; 3], [2, 2, 2], BoxCells::Tet).raw().unwrap();
    raw.faces.retain(|f| f.patch != 3);
    raw.patch_names.truncate(6);
    std::fs::write(&path, to_msh(&raw)).unwrap();
    let e = Mesh::build(gmsh::read(&path).unwrap()).unwrap_err().to_string();
    assert!(e.contains("not closed") && e.contains("physical group"), "{e}");
    let e = gmsh::read(&dir.path().join("missing.msh")).unwrap_err().to_string();
    assert!(e.contains("missing.msh") && e.contains("cannot read"), "{e}");
}

/// A case names a gmsh file as its mesh (`fluid.mesh.file`): the sod-tube case on the hex box,
/// whose physical groups carry the box's face names, runs; a bad file stops the case with the
/// field, the file and the line.
#[test]
fn a_case_runs_on_a_gmsh_mesh() {
    use fluid_solver::solver::{self, RunOptions};
    use interface_protocol::case::Case;
    let case_path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../cases/sod-tube/case.toml");
    let text = std::fs::read_to_string(&case_path).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let run = |mesh: &Path, out: &str| {
        let overrides = [
            format!("fluid.mesh={{file=\"{}\"}}", mesh.display()),
            "fluid.time.t_end=0.05".to_string(),
        ];
        let case = Case::load(&case_path, &overrides)?;
        let opts =
            RunOptions { out: dir.path().join(out), quiet: true, restart: None, force: false };
        solver::run(&case, &text, &opts)
    };
    let summary = run(&fixture("hex_box.msh"), "hex").unwrap();
    assert!(summary.steps > 3, "{} steps", summary.steps);
    let hexes = std::fs::read_to_string(fixture("hex_box.msh")).unwrap();
    let bad = dir.path().join("bad.msh");
    std::fs::write(&bad, &hexes[..hexes.len() / 2]).unwrap();
    let e = format!("{:#}", run(&bad, "bad").unwrap_err());
    println!("{e}");
    assert!(
        e.contains("fluid.mesh.file") && e.contains("bad.msh:") && e.contains("truncated"),
        "{e}"
    );
}
