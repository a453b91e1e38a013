//! The von Mises stress of every element (`Element::von_mises`, written by `output`): membrane
//! patches of MITC4 and DKT in uniaxial tension, a tet in uniaxial tension (exact, Saint
//! Venant-Kirchhoff), a MITC4 strip under an end moment at the outer fibre (elastic: the
//! surfaces; J2: the outermost Gauss point), a beam's corner stress under tension and end
//! couples, and the cell field of `structure.xdmf` read back
//! with h5py; and the wet surface of a tet cube (`couple::wet_surface`): its boundary
//! triangles, area and outward normals.

mod common;

use std::process::Command;

use nalgebra::{Matrix3, Rotation3, Vector3};
use structure_solver::assembly::{Curve, FeModel, Part};
use structure_solver::couple::wet_surface;
use structure_solver::elements::{BeamSection, Element, ShellSection, ShellYield};
use structure_solver::material::{Elastic, Material};
use structure_solver::mesh::{generate, Cell, CellKind, Mesh};
use structure_solver::output::{cell_fields, CellMap};
use structure_solver::statics::{load_steps, NewtonSettings};

const E: f64 = 2.0e11;
const NU: f64 = 0.3;

/// A rigid rotation of space about `axis` (its angle the length).
fn rotation(axis: [f64; 3]) -> Matrix3<f64> {
    *Rotation3::from_scaled_axis(Vector3::from(axis)).matrix()
}

/// Uniaxial strain of the membrane patches.
const EPS: f64 = 1e-6;

/// In-plane uniaxial stress `σ = E ε` along x on a shell of in-plane nodes `xy` placed in a
/// skew plane (`q0`): the nodes moved by `u = ε x`, `v = -ν ε y`, then the whole turned by a
/// large rigid rotation `q` (the nodal rotations too).
fn membrane_von_mises(xy: &[[f64; 2]], make: impl Fn(&[Vector3<f64>]) -> Element) -> f64 {
    let (q0, q) = (rotation([0.4, -0.7, 1.1]), rotation([-0.9, 0.2, 0.5]));
    let x0: Vec<Vector3<f64>> = xy.iter().map(|p| q0 * Vector3::new(p[0], p[1], 0.0)).collect();
    let x: Vec<Vector3<f64>> = xy
        .iter()
        .map(|p| q * q0 * Vector3::new(p[0] * (1.0 + EPS), p[1] * (1.0 - NU * EPS), 0.0))
        .collect();
    let el = make(&x0);
    let r = vec![q; xy.len()];
    el.von_mises(&x, &r, &vec![0.0; el.n_state()]) / (E * EPS)
}

#[test]
fn membrane_patches_in_uniaxial_tension_give_sigma() {
    let sec = ShellSection { e: E, nu: NU, rho: 7800.0, h: 0.01 };
    let quad = [[0.0, 0.0], [1.1, 0.1], [1.2, 0.9], [-0.1, 1.0]];
    let tri = [[0.0, 0.0], [1.0, 0.2], [0.3, 0.8]];
    let yield_ = ShellYield { sigma_y: 1e30, hardening: 0.0, points: 5 };
    for (name, ratio) in [
        (
            "MITC4",
            membrane_von_mises(&quad, |x| {
                Element::quad4([0, 1, 2, 3], &[x[0], x[1], x[2], x[3]], &sec, None)
            }),
        ),
        (
            "DKT",
            membrane_von_mises(&tri, |x| Element::tri3([0, 1, 2], &[x[0], x[1], x[2]], &sec, None)),
        ),
        (
            "MITC4 J2",
            membrane_von_mises(&quad, |x| {
                Element::quad4([0, 1, 2, 3], &[x[0], x[1], x[2], x[3]], &sec, Some(yield_))
            }),
        ),
        (
            "DKT J2",
            membrane_von_mises(&tri, |x| {
                Element::tri3([0, 1, 2], &[x[0], x[1], x[2]], &sec, Some(yield_))
            }),
        ),
    ] {
        println!("{name} membrane patch: von Mises / σ = {ratio:.12}");
        // exact up to the O(ε²) of the corotated small-strain measure (DKT: 0.02 ε relative)
        assert!((ratio - 1.0).abs() < 0.1 * EPS, "{name}: {ratio}");
    }
}

/// Saint Venant-Kirchhoff in uniaxial stress: stretches `λ` along x and `μ` across with
/// `μ² - 1 = -ν (λ² - 1)` make `S = E E_xx` the only stress, so `σ_xx = λ S / μ²` exactly.
#[test]
fn tet_in_uniaxial_tension_gives_sigma() {
    let (lambda, q) = (1.001_f64, rotation([0.4, -0.7, 1.1]));
    let e_xx = 0.5 * (lambda * lambda - 1.0);
    let mu = (1.0 - NU * (lambda * lambda - 1.0)).sqrt();
    let sigma = lambda * E * e_xx / (mu * mu);
    let x0 = [Vector3::zeros(), Vector3::x(), Vector3::y(), Vector3::z()].map(|p| p * 0.1);
    let x = x0.map(|p| q * Vector3::new(lambda * p.x, mu * p.y, mu * p.z));
    let el =
        Element::tet4([0, 1, 2, 3], &x0, Material::Elastic(Elastic { e: E, nu: NU, rho: 1.0 }));
    let ratio = el.von_mises(&x, &[Matrix3::identity(); 4], &vec![0.0; el.n_state()]) / sigma;
    println!("tet in tension: σ = {sigma:.6e}, von Mises / σ = {ratio:.12}");
    assert!((ratio - 1.0).abs() < 1e-9, "{ratio}");
}

/// The largest cell von Mises stress next to the clamp of a strip `L x b x h` (8 x 1 MITC4)
/// under an end moment `M` about y, over `6M / (b h²)`.
fn strip_under_end_moment(part: Part) -> f64 {
    let (l, b, h, m) = (1.0, 0.1, 0.01, 1e-3);
    let mesh = generate::rectangle(l, b, 8, 1);
    let mut fe = FeModel::new(&mesh, |_| part).unwrap();
    fe.fix(mesh.node_set("u0").unwrap(), [true; 6]);
    for &n in mesh.node_set("u1").unwrap() {
        fe.point_load(n, 4, m / 2.0, Curve::Linear);
    }
    let s = NewtonSettings::default();
    load_steps(&mut fe, &[1.0], &s, |_, _| {}).unwrap();
    let map = CellMap { elements: (0..8).collect(), bt4: vec![], blt3: vec![], n_cells: 8 };
    let fields = cell_fields(&fe, &map);
    let vm = &fields.iter().find(|(n, _)| *n == "von_mises").unwrap().1;
    vm[0] / (6.0 * m / (b * h * h))
}

#[test]
fn strip_under_an_end_moment_gives_the_outer_fibre_stress_at_the_clamp() {
    let sec = ShellSection { e: 2.0e9, nu: 0.0, rho: 1.0, h: 0.01 };
    let elastic = strip_under_end_moment(Part::Shell(sec));
    println!("MITC4 strip, end moment: clamp cell von Mises / (6M/bh²) = {elastic:.9} (surfaces)");
    assert!((elastic - 1.0).abs() < 1e-6, "{elastic}");
    // J2 far below yield at 5 Gauss points through the thickness: the outermost at ζ = 0.90618
    let yield_ = ShellYield { sigma_y: 1e30, hardening: 0.0, points: 5 };
    let j2 = strip_under_end_moment(Part::ShellJ2(sec, yield_));
    let zeta = (5.0 + 2.0 * (10.0_f64 / 7.0).sqrt()).sqrt() / 3.0;
    println!("MITC4 J2 strip: clamp cell von Mises / (6M/bh²) = {j2:.9} (outer Gauss point ζ = {zeta:.9})");
    assert!((j2 / zeta - 1.0).abs() < 1e-6, "{j2} vs {zeta}");
}

/// A rectangular beam `b x h` along x under an end force `P` along it and end couples `M_y`,
/// `M_z`: the largest corner stress `P/(bh) + 6 M_y/(b h²) + 6 M_z/(h b²)` in every cell (the
/// loads small enough that `P` times the deflection is below 1e-4 of the moments).
#[test]
fn beam_under_tension_and_end_couples_gives_the_corner_stress() {
    let (b, h) = (0.02, 0.04);
    let (p, my, mz) = (0.8, 5.0e-3, 3.0e-3);
    let mesh = generate::line([0.0; 3], [1.0, 0.0, 0.0], 4);
    let sec = BeamSection::rectangle(E, NU, 7800.0, b, h);
    let mut fe = FeModel::new(&mesh, |_| Part::Beam(sec, [0.0, 1.0, 0.0])).unwrap();
    fe.fix(mesh.node_set("start").unwrap(), [true; 6]);
    let end = mesh.node_set("end").unwrap()[0];
    for (c, v) in [(0, p), (4, my), (5, mz)] {
        fe.point_load(end, c, v, Curve::Linear);
    }
    load_steps(&mut fe, &[1.0], &NewtonSettings::default(), |_, _| {}).unwrap();
    let map = CellMap { elements: (0..4).collect(), bt4: vec![], blt3: vec![], n_cells: 4 };
    let fields = cell_fields(&fe, &map);
    let vm = &fields.iter().find(|(n, _)| *n == "von_mises").unwrap().1;
    let exact = p / (b * h) + 6.0 * my / (b * h * h) + 6.0 * mz / (h * b * b);
    for (c, v) in vm.iter().enumerate() {
        println!("beam cell {c}: corner stress / exact = {:.9}", v / exact);
        assert!((v / exact - 1.0).abs() < 1e-4, "cell {c}: {v} vs {exact}");
    }
}

/// The cell values of `von_mises` in the last step of `structure.h5`, read by h5py.
const LAST_VON_MISES: &str = r#"
import json, sys, h5py
with h5py.File(sys.argv[1], "r") as f:
    last = max(f["steps"].keys(), key=int)
    print(json.dumps([float(v) for v in f["steps"][last]["von_mises"][()]]))
"#;

#[test]
fn xdmf_carries_the_von_mises_stress_of_mitc4_cells() {
    let probe = Command::new("python3").args(["-c", "import h5py"]).output();
    assert!(
        probe.is_ok_and(|o| o.status.success()),
        "python3 with h5py is needed to read structure.h5: run scripts/install-deps.sh"
    );
    let dir = tempfile::tempdir().unwrap();
    let case = r#"[case]
name = "mitc4-stress"
[structure]
mesh = { generator = "rectangle", lx = 1.0, ly = 0.1, nx = 8, ny = 2 }
material = { e = 200e9, nu = 0.3, rho = 7800.0 }
thickness = 0.02
element = "mitc4"
integrator = "midpoint"
dt = 2e-5
t_end = 2e-3
[structure.sets]
clamp = { min = [-1e-9, -1.0, -1.0], max = [1e-9, 1.0, 1.0] }
tip = { min = [0.999999, -1.0, -1.0], max = [1.000001, 1.0, 1.0] }
[[structure.bc]]
set = "clamp"
fixed = ["ux", "uy", "uz", "rx", "ry", "rz"]
[[structure.loads]]
set = "tip"
dof = "uz"
value = 2000.0
[[structure.probes]]
name = "tip"
point = [1.0, 0.0, 0.0]
[output]
fields_every = 100
"#;
    let out = dir.path().join("out");
    let o = common::cli::run_in(dir.path(), case);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let xdmf = std::fs::read_to_string(out.join("structure.xdmf")).unwrap();
    assert!(xdmf.contains("von_mises"), "structure.xdmf has no von_mises field");
    let o = Command::new("python3")
        .args(["-c", LAST_VON_MISES, out.join("structure.h5").to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "h5py failed:\n{}", String::from_utf8_lossy(&o.stderr));
    let vm: Vec<f64> = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(vm.len(), 16);
    // the cell table holds the same final values (all cells are quads: same order)
    let csv = std::fs::read_to_string(out.join("structure_cells.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header, ["cell", "x", "y", "z", "von_mises"]);
    let table: Vec<Vec<f64>> =
        lines.map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
    let min = vm.iter().cloned().fold(f64::INFINITY, f64::min);
    let max = vm.iter().cloned().fold(0.0, f64::max);
    let clamp = table.iter().filter(|c| c[1] < 0.125).map(|c| c[4]).fold(0.0, f64::max);
    println!("structure.h5 von_mises at t = 2 ms: min {min:.4e}, max {max:.4e}, clamp cells {clamp:.4e} Pa");
    assert!(min > 0.0, "a MITC4 cell has zero von Mises stress: {vm:?}");
    for (a, row) in vm.iter().zip(&table) {
        assert!(
            (a - row[4]).abs() <= 1e-12 * a.abs(),
            "structure.h5 {a} vs structure_cells.csv {}",
            row[4]
        );
    }
}

/// A cube `[0, L]³` of `k³` sub-cubes each split into six tets (of both orientations), with
/// the cell set "solid".
fn tet_cube(l: f64, k: usize) -> Mesh {
    let id = |i: usize, j: usize, m: usize| (m * (k + 1) + j) * (k + 1) + i;
    let mut mesh = Mesh::default();
    for m in 0..=k {
        for j in 0..=k {
            for i in 0..=k {
                mesh.nodes.push([i, j, m].map(|v| l * v as f64 / k as f64));
            }
        }
    }
    // the six tets 0 → a → a|b → 7 around the diagonal of a cube with corners c(0..8) (bit 1:
    // x, 2: y, 4: z; Kuhn's conforming split)
    let paths = [[1, 2], [2, 1], [2, 4], [4, 2], [4, 1], [1, 4]];
    for m in 0..k {
        for j in 0..k {
            for i in 0..k {
                let c = |b: usize| id(i + (b & 1), j + (b >> 1 & 1), m + (b >> 2 & 1));
                for [a, b] in paths {
                    let nodes = vec![c(0), c(a), c(a | b), c(7)];
                    mesh.cells.push(Cell { kind: CellKind::Tet4, nodes });
                }
            }
        }
    }
    mesh.cell_sets.insert("solid".into(), (0..mesh.cells.len()).collect());
    mesh
}

#[test]
fn wet_surface_of_a_tet_cube_is_its_outward_boundary() {
    let (l, k) = (2.0, 3);
    let mesh = tet_cube(l, k);
    let wet = wet_surface(&mesh, "solid").unwrap();
    let p = |e: &interface_protocol::messages::SurfaceElement, a: usize| {
        Vector3::from(mesh.nodes[wet.nodes[e.nodes[a] as usize]])
    };
    let centre = Vector3::repeat(0.5 * l);
    let (mut area, mut sum) = (0.0, Vector3::zeros());
    let mut per_face = [0usize; 6];
    for e in &wet.elements {
        assert_eq!(e.n_nodes, 3);
        let (a, b, c) = (p(e, 0), p(e, 1), p(e, 2));
        let n = 0.5 * (b - a).cross(&(c - a));
        let g = (a + b + c) / 3.0;
        assert!(n.dot(&(g - centre)) > 0.0, "inward triangle at {g:?}");
        // the cube face it lies on: the axis of its normal
        let axis = n.iamax();
        assert!((n.norm() - n[axis].abs()).abs() < 1e-12 * n.norm(), "normal {n:?} off axis");
        per_face[2 * axis + usize::from(n[axis] > 0.0)] += 1;
        area += n.norm();
        sum += n;
    }
    println!(
        "tet cube {k}³: {} boundary triangles, per face {per_face:?}, area {area} (6 L² = {}), |Σ n dA| = {:.1e}",
        wet.elements.len(),
        6.0 * l * l,
        sum.norm()
    );
    assert_eq!(wet.elements.len(), 12 * k * k);
    assert!(per_face.iter().all(|&f| f == 2 * k * k), "{per_face:?}");
    assert!((area - 6.0 * l * l).abs() < 1e-12 * area);
    assert!(sum.norm() < 1e-12 * area);
    // every surface node is on the cube's boundary
    let on_boundary = |x: &[f64; 3]| x.iter().any(|&v| v.abs() < 1e-12 || (v - l).abs() < 1e-12);
    assert!(wet.nodes.iter().all(|&n| on_boundary(&mesh.nodes[n])));
    assert_eq!(wet.nodes.len(), 6 * k * k + 2);
}

#[test]
fn wet_set_of_mixed_cells_is_refused_naming_the_set() {
    let mut mesh = tet_cube(1.0, 1);
    mesh.cells.push(Cell { kind: CellKind::Tri3, nodes: vec![0, 1, 2] });
    mesh.cell_sets.insert("mixed".into(), (0..mesh.cells.len()).collect());
    let err = wet_surface(&mesh, "mixed").unwrap_err();
    println!("{err}");
    assert!(
        err.contains("\"mixed\"") && err.contains("Tri3") && err.contains("tetrahedra"),
        "{err}"
    );
}
