//! The static cases of the `structure-solver` command line: the cantilever against the elastica
//! (and `P L³/3EI` at a small load, by load steps, displacement control and arc length), a rigid
//! tip, the pressurised sphere octant and cylinder, beams about both axes, gmsh meshes (a strip
//! and a tet column under gravity), a prescribed end rotation and the clamped disc.

mod common;

use common::cli::{cases, fails, last_row, probes, run_in, run_text, table};

/// Tip deflection of a cantilever under a tip load `α = P L²/EI` as fractions of `L`: vertical
/// and horizontal, from the elastica (Mattiasson, IJNME 17, 1981, Table 1).
const ELASTICA: [(f64, f64, f64); 6] = [
    (1.0, 0.30172, 0.05643),
    (2.0, 0.49346, 0.16064),
    (3.0, 0.60325, 0.25442),
    (4.0, 0.66996, 0.32894),
    (5.0, 0.71379, 0.38763),
    (6.0, 0.74457, 0.43459),
];

#[test]
fn static_cantilever_follows_the_elastica_step_by_step() {
    let out = tempfile::tempdir().unwrap();
    let rows = probes("structure-static-cantilever", out.path(), &[]);
    // header row at load factor 0, then one row per load step λ = k/6, α = 6λ
    assert_eq!(rows.len(), 7);
    for (row, (alpha, v, u)) in rows[1..].iter().zip(ELASTICA) {
        let (lambda, ux, uz) = (row[0], row[1], row[3]);
        println!(
            "α = {alpha}: tip w/L {uz:.5} vs {v} ({:+.3}%), u/L {:.5} vs {u} ({:+.3}%)",
            100.0 * (uz / v - 1.0),
            -ux,
            100.0 * (-ux / u - 1.0)
        );
        assert!((lambda - alpha / 6.0).abs() < 1e-12);
        assert!((uz / v - 1.0).abs() < 5e-3);
        assert!((-ux / u - 1.0).abs() < 1e-2);
    }
}

#[test]
fn static_cantilever_at_a_small_load_matches_beam_theory() {
    // λ = 0.01: P = 100 N, δ = P L³/3EI = 0.02 m (EI = E b h³/12 = 1666.7 N m²)
    let delta = 100.0 / (3.0 * 200e9 * 0.1 * 0.01f64.powi(3) / 12.0);
    let out = tempfile::tempdir().unwrap();
    let rows = probes(
        "structure-static-cantilever",
        out.path(),
        &["--set", "structure.t_end=0.01", "--set", "structure.steps=2"],
    );
    let uz = rows.last().unwrap()[3];
    println!(
        "small load: tip {uz:.6e} m vs P L³/3EI = {delta:.6e} m ({:+.3}%)",
        100.0 * (uz / delta - 1.0)
    );
    assert!((uz / delta - 1.0).abs() < 5e-3);
    // half the load, half the deflection
    assert!((rows[1][3] / uz - 0.5).abs() < 1e-3);
    // displacement control: driving the tip to the elastica's w at α = 6 takes the load factor 1
    let out = tempfile::tempdir().unwrap();
    let w = ELASTICA[5].1;
    let control =
        format!("structure.control={{ point = [1.0, 0.05, 0.0], dof = \"uz\", value = {w} }}");
    let rows = probes("structure-static-cantilever", out.path(), &["--set", &control]);
    let last = rows.last().unwrap();
    println!(
        "displacement control: tip w = {:.5} at load factor {:.5} (elastica: 1)",
        last[3], last[0]
    );
    assert!((last[3] - w).abs() < 1e-9);
    assert!((last[0] - 1.0).abs() < 5e-3);
}

#[test]
fn rigid_tip_carrying_the_load_follows_the_elastica() {
    let text = std::fs::read_to_string(cases("structure-static-cantilever").join("case.toml"))
        .unwrap()
        .replace(
            "set = \"tip\"\ndof = \"uz\"\nvalue = 3333.3333333333333",
            "set = \"tip_reference\"\ndof = \"uz\"\nvalue = 10000.0",
        )
        .replace(
            "[[structure.probes]]",
            "[[structure.rigid_bodies]]\nset = \"tip\"\nreference = [1.0, 0.05, 0.0]\n\n\
             [[structure.probes]]",
        );
    assert!(text.contains("tip_reference") && text.contains("rigid_bodies"));
    let row = last_row(&text);
    let (v, u) = (ELASTICA[5].1, ELASTICA[5].2);
    println!("rigid tip, α = 6: w/L {:.5} vs {v}, u/L {:.5} vs {u}", row[3], -row[1]);
    assert!((row[3] / v - 1.0).abs() < 5e-3 && (-row[1] / u - 1.0).abs() < 1e-2);
    // a boundary condition on a node of the body is refused, naming the reference set
    let bad = text.replace("set = \"clamp\"", "set = \"tip\"");
    let (_, o) = run_text(&bad);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        err.contains("structure.bc[0].set")
            && err.contains("moves with structure.rigid_bodies[0]")
            && err.contains("\"tip_reference\""),
        "{err}"
    );
}

/// An octant of a closed sphere (radius 1, 10 mm steel) under uniform pressure, on the three
/// symmetry planes: the pole's collapsed quadrilaterals merge into triangles (`shell`: MITC4
/// and DKT); the membrane solution is `u_r = p R² (1 - ν) / (2 E h)`.
const SPHERE: &str = r#"[structure]
mesh = { generator = "sphere", radius = 1.0, n_theta = 8, n_phi = 8, theta_deg = [0.0, 90.0], phi_deg = [0.0, 90.0] }
material = { e = 200e9, nu = 0.3, rho = 7800.0 }
element = "shell"
thickness = 0.01
integrator = "static"
steps = 1
[[structure.bc]]
set = "u0"
symmetry = "y"
[[structure.bc]]
set = "u1"
symmetry = "x"
[[structure.bc]]
set = "v1"
symmetry = "z"
[[structure.loads]]
pressure = 1e5
[[structure.probes]]
name = "mid"
point = [0.5, 0.5, 0.7071067811865476]
[[structure.probes]]
name = "equator"
point = [0.7071067811865476, 0.7071067811865476, 0.0]
[[structure.probes]]
name = "pole"
point = [0.0, 0.0, 1.0]
"#;

#[test]
fn pressurised_sphere_octant_converges_to_the_membrane_solution() {
    let ur = 1e5 * 0.7 / (2.0 * 200e9 * 0.01);
    // relative errors of u_r at 45° latitude, the equator and the pole for n x n cells
    let errors = |n: usize| {
        let text = SPHERE.replace("n_theta = 8, n_phi = 8", &format!("n_theta = {n}, n_phi = {n}"));
        let row = last_row(&text);
        // the cells' normals (azimuth x polar angle) point inwards: the sphere shrinks
        let radial =
            |p: usize, d: [f64; 3]| -(0..3).map(|k| row[1 + 6 * p + k] * d[k]).sum::<f64>();
        let s = 0.5f64.sqrt();
        [radial(0, [0.5, 0.5, s]), radial(1, [s, s, 0.0]), radial(2, [0.0, 0.0, 1.0])]
            .map(|u| u / ur - 1.0)
    };
    let (e16, e32) = (errors(16), errors(32));
    let order = |i: usize| (e16[i] / e32[i]).abs().log2();
    println!(
        "sphere octant, u_r vs p R²(1-ν)/2Eh: 45° latitude {:+.3}% -> {:+.3}% (order {:.2}), equator {:+.3}% -> {:+.3}% (order {:.2}), pole {:+.1}% -> {:+.1}% (order {:.2})",
        100.0 * e16[0], 100.0 * e32[0], order(0), 100.0 * e16[1], 100.0 * e32[1], order(1),
        100.0 * e16[2], 100.0 * e32[2], order(2)
    );
    assert!(e32[0].abs() < 0.005 && e32[1].abs() < 0.005);
    assert!(order(0) > 1.4 && order(1) > 1.4);
    // the pole, where the collapsed quadrilaterals meet as thin triangles, converges slower
    assert!(order(2) > 0.8);
}

/// A steel cantilever of 2-node beams (10 mm x 20 mm, 1 m) from the `line` generator, under a
/// tip load along the stiff and the weak axis (`up` = local y = global y): `P L³ / 3 E I`.
#[test]
fn beam_cantilever_matches_beam_theory_about_both_axes() {
    let text = r#"[structure]
mesh = { generator = "line", from = [0.0, 0.0, 0.0], to = [1.0, 0.0, 0.0], n = 10 }
integrator = "static"
steps = 1
[structure.materials.steel]
e = 200e9
nu = 0.3
rho = 7800.0
[[structure.parts]]
element = "beam"
section = { rectangle = [0.01, 0.02] }
up = [0.0, 1.0, 0.0]
[[structure.bc]]
set = "start"
fixed = ["ux", "uy", "uz", "rx", "ry", "rz"]
[[structure.loads]]
set = "end"
dof = "uz"
value = 10.0
[[structure.loads]]
set = "end"
dof = "uy"
value = 10.0
[[structure.probes]]
name = "tip"
point = [1.0, 0.0, 0.0]
"#;
    let row = last_row(text);
    // b = 0.01 along y, h = 0.02 along z: I about y (bending in z) = b h³/12
    let (iy, iz) = (0.01 * 0.02f64.powi(3) / 12.0, 0.02 * 0.01f64.powi(3) / 12.0);
    let (wz, wy) = (10.0 / (3.0 * 200e9 * iy), 10.0 / (3.0 * 200e9 * iz));
    println!("beam: tip uz {:.5e} vs {wz:.5e}, uy {:.5e} vs {wy:.5e}", row[3], row[2]);
    assert!((row[3] / wz - 1.0).abs() < 5e-3 && (row[2] / wy - 1.0).abs() < 5e-3);
}

/// A full open cylinder (radius 1, length 1, 10 mm steel) under internal pressure: the
/// generator's seam at θ = 0 = 360° is merged (an open seam would not carry the hoop force);
/// `u_r = p R² / (E h)` with free ends.
#[test]
fn pressurised_cylinder_carries_the_hoop_force_across_its_seam() {
    let text = r#"[structure]
mesh = { generator = "cylinder", radius = 1.0, length = 1.0, n_theta = 32, n_axial = 4 }
material = { e = 200e9, nu = 0.3, rho = 7800.0 }
element = "mitc4"
thickness = 0.01
integrator = "static"
steps = 1
[structure.sets]
x_axis = { min = [0.999, -1e-6, -1.0], max = [1.001, 1e-6, 2.0] }
y_axis = { min = [-1e-6, 0.999, -1.0], max = [1e-6, 1.001, 2.0] }
[[structure.bc]]
set = "v0"
symmetry = "z"
[[structure.bc]]
set = "x_axis"
fixed = ["uy"]
[[structure.bc]]
set = "y_axis"
fixed = ["ux"]
[[structure.loads]]
pressure = 1e5
[[structure.probes]]
name = "seam"
point = [1.0, 0.0, 1.0]
[[structure.probes]]
name = "opposite"
point = [-1.0, 0.0, 0.5]
"#;
    let ur = 1e5 / (200e9 * 0.01);
    let row = last_row(text);
    let (seam, opposite) = (row[1], -row[7]);
    println!(
        "cylinder: u_r at the seam {seam:.5e}, opposite {opposite:.5e} vs p R²/Eh = {ur:.5e} ({:+.2}%, {:+.2}%)",
        100.0 * (seam / ur - 1.0),
        100.0 * (opposite / ur - 1.0)
    );
    assert!((seam / ur - 1.0).abs() < 0.01 && (opposite / ur - 1.0).abs() < 0.01);
}

/// A gmsh 4.1 file of an `nx` x `ny` quad strip `[0, 1] x [0, 0.1]` with physical groups
/// "clamp" (the lines of x = 0), "tip" (the lines of x = 1) and "plate" (the quads).
fn strip_msh(nx: usize, ny: usize) -> String {
    let id = |i: usize, j: usize| j * (nx + 1) + i + 1;
    let mut s = String::from(
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n3\n1 1 \"clamp\"\n1 3 \"tip\"\n\
         2 2 \"plate\"\n$EndPhysicalNames\n$Entities\n0 2 1 0\n1 0 0 0 0 0.1 0 1 1 0\n\
         2 1 0 0 1 0.1 0 1 3 0\n1 0 0 0 1 0.1 0 1 2 0\n$EndEntities\n",
    );
    let n = (nx + 1) * (ny + 1);
    s += &format!("$Nodes\n1 {n} 1 {n}\n2 1 0 {n}\n");
    (1..=n).for_each(|t| s += &format!("{t}\n"));
    for j in 0..=ny {
        for i in 0..=nx {
            s += &format!("{} {} 0\n", i as f64 / nx as f64, 0.1 * j as f64 / ny as f64);
        }
    }
    let total = 2 * ny + nx * ny;
    s += &format!("$EndNodes\n$Elements\n3 {total} 1 {total}\n");
    let mut tag = 0;
    for (curve, i) in [(1, 0), (2, nx)] {
        s += &format!("1 {curve} 1 {ny}\n");
        for j in 0..ny {
            tag += 1;
            s += &format!("{tag} {} {}\n", id(i, j), id(i, j + 1));
        }
    }
    s += &format!("2 1 3 {}\n", nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            tag += 1;
            s += &format!(
                "{tag} {} {} {} {}\n",
                id(i, j),
                id(i + 1, j),
                id(i + 1, j + 1),
                id(i, j + 1)
            );
        }
    }
    s + "$EndElements\n"
}

/// The static cantilever from a gmsh file: physical groups as sets, its boundary lines in no
/// part (sets only); tip deflection `P L³/3EI` at a small load.
#[test]
fn gmsh_cantilever_uses_physical_groups_as_sets() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("strip.msh"), strip_msh(20, 2)).unwrap();
    let text = r#"[structure]
mesh = { generator = "gmsh", file = "strip.msh" }
integrator = "static"
steps = 1
material = { e = 200e9, nu = 0.0, rho = 7800.0 }
[[structure.parts]]
set = "plate"
element = "mitc4"
thickness = 0.01
[[structure.bc]]
set = "clamp"
fixed = ["ux", "uy", "uz", "rx", "ry", "rz"]
[[structure.loads]]
set = "tip"
dof = "uz"
value = 33.333333333333333
[[structure.probes]]
name = "tip"
point = [1.0, 0.05, 0.0]
"#;
    let o = run_in(dir.path(), text);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let uz = table(&dir.path().join("out/structure_probes.csv")).1.pop().unwrap()[3];
    let delta = 100.0 / (3.0 * 200e9 * 0.1 * 0.01f64.powi(3) / 12.0);
    println!(
        "gmsh cantilever: tip {uz:.6e} m vs P L³/3EI = {delta:.6e} m ({:+.3}%)",
        100.0 * (uz / delta - 1.0)
    );
    assert!((uz / delta - 1.0).abs() < 5e-3);
    // the cell table covers every cell of the file, the boundary lines included
    let (_, cells) = table(&dir.path().join("out/structure_cells.csv"));
    assert_eq!(cells.len(), 4 + 40);
}

/// A gmsh 4.1 file of a column `[0, 0.1]² x [0, 1]` of `n` cubes, each split into six tets
/// along its diagonal (positively oriented), with the physical group "base" (the triangles of
/// z = 0) and "column" (the tets).
fn column_msh(n: usize) -> String {
    let id = |i: usize, j: usize, k: usize| 4 * k + 2 * j + i + 1;
    let p = |t: usize| {
        let (i, j, k) = ((t - 1) % 2, (t - 1) / 2 % 2, (t - 1) / 4);
        [0.1 * i as f64, 0.1 * j as f64, k as f64 / n as f64]
    };
    let mut s = String::from(
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n2\n2 1 \"base\"\n3 2 \"column\"\n\
         $EndPhysicalNames\n$Entities\n0 0 1 1\n1 0 0 0 0.1 0.1 0 1 1 0\n\
         1 0 0 0 0.1 0.1 1 1 2 0\n$EndEntities\n",
    );
    let nn = 4 * (n + 1);
    s += &format!("$Nodes\n1 {nn} 1 {nn}\n3 1 0 {nn}\n");
    (1..=nn).for_each(|t| s += &format!("{t}\n"));
    (1..=nn).for_each(|t| s += &format!("{} {} {}\n", p(t)[0], p(t)[1], p(t)[2]));
    let mut tets = Vec::new();
    for k in 0..n {
        let v = |c: [usize; 3]| id(c[0], c[1], k + c[2]);
        for perm in [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]] {
            let mut c = [0; 3];
            let mut t = vec![v(c)];
            for a in perm {
                c[a] = 1;
                t.push(v(c));
            }
            let (a, b, cc, d) = (p(t[0]), p(t[1]), p(t[2]), p(t[3]));
            let e = |x: [f64; 3], y: [f64; 3]| [y[0] - x[0], y[1] - x[1], y[2] - x[2]];
            let (u, w, z) = (e(a, b), e(a, cc), e(a, d));
            let det = u[0] * (w[1] * z[2] - w[2] * z[1]) - u[1] * (w[0] * z[2] - w[2] * z[0])
                + u[2] * (w[0] * z[1] - w[1] * z[0]);
            if det < 0.0 {
                t.swap(2, 3);
            }
            tets.push(t);
        }
    }
    let total = 2 + tets.len();
    s += &format!("$EndNodes\n$Elements\n2 {total} 1 {total}\n2 1 2 2\n");
    s += &format!(
        "1 {} {} {}\n2 {} {} {}\n",
        id(0, 0, 0),
        id(1, 0, 0),
        id(1, 1, 0),
        id(0, 0, 0),
        id(1, 1, 0),
        id(0, 1, 0)
    );
    s += &format!("3 1 4 {}\n", tets.len());
    for (e, t) in tets.iter().enumerate() {
        s += &format!("{} {} {} {} {}\n", e + 3, t[0], t[1], t[2], t[3]);
    }
    s + "$EndElements\n"
}

/// A steel column of tets hanging from its base under gravity (ν = 0): the tip settles by
/// `ρ g L² / 2E`; the base triangles of the file are in no part.
#[test]
fn tet_column_under_gravity_matches_the_closed_form() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("column.msh"), column_msh(10)).unwrap();
    let text = r#"[structure]
mesh = { generator = "gmsh", file = "column.msh" }
integrator = "static"
steps = 1
material = { e = 200e9, nu = 0.0, rho = 7800.0 }
[[structure.parts]]
set = "column"
element = "tet4"
[structure.sets]
x0 = { min = [-1e-9, -1.0, -1e-9], max = [1e-9, 1.0, 1e-9] }
y0 = { min = [-1.0, -1e-9, -1e-9], max = [1.0, 1e-9, 1e-9] }
[[structure.bc]]
set = "base"
symmetry = "z"
[[structure.bc]]
set = "x0"
fixed = ["ux"]
[[structure.bc]]
set = "y0"
fixed = ["uy"]
[[structure.loads]]
gravity = [0.0, 0.0, 9.81]
[[structure.probes]]
name = "a"
point = [0.0, 0.0, 1.0]
[[structure.probes]]
name = "b"
point = [0.1, 0.0, 1.0]
[[structure.probes]]
name = "c"
point = [0.1, 0.1, 1.0]
[[structure.probes]]
name = "d"
point = [0.0, 0.1, 1.0]
"#;
    let o = run_in(dir.path(), text);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let row = table(&dir.path().join("out/structure_probes.csv")).1.pop().unwrap();
    // the mean over the tip's corners (their shares of the lumped weight differ)
    let uz = (0..4).map(|p| row[3 + 6 * p]).sum::<f64>() / 4.0;
    let exact = 7800.0 * 9.81 / (2.0 * 200e9);
    println!(
        "tet column: mean tip {uz:.6e} m vs ρ g L²/2E = {exact:.6e} m ({:+.3}%)",
        100.0 * (uz / exact - 1.0)
    );
    assert!((uz / exact - 1.0).abs() < 1e-3);
}

/// The static cantilever bent by a prescribed end rotation instead of its load (ramped over
/// the load steps): a pure moment, so the strip rolls into a circular arc of angle θ with the
/// tip at `w = L (1 - cos θ)/θ`, `u = -L (1 - sin θ/θ)`.
#[test]
fn prescribed_end_rotation_rolls_the_strip_into_an_arc() {
    let theta = 1.5f64;
    let text = std::fs::read_to_string(cases("structure-static-cantilever").join("case.toml"))
        .unwrap()
        .replace(
            "[[structure.loads]]\nset = \"tip\"\ndof = \"uz\"\nvalue = 3333.3333333333333\n\
             curve = \"linear\"",
            &format!(
                "[[structure.bc]]\nset = \"tip\"\nprescribed = {{ dof = \"ry\", value = {}, \
                 curve = {{ ramp = 1.0 }} }}",
                -theta
            ),
        );
    assert!(text.contains("ramp = 1.0"));
    let row = last_row(&text);
    let (w, u) = ((1.0 - theta.cos()) / theta, -(1.0 - theta.sin() / theta));
    println!(
        "end rotation {theta}: tip (u, w) = ({:.5}, {:.5}) vs arc ({u:.5}, {w:.5})",
        row[1], row[3]
    );
    assert!((row[3] - w).abs() < 2e-3 && (row[1] - u).abs() < 2e-3);
}

/// `w(λ)` at `x` through the three rows of `rows` (`(λ, w)`) nearest to it (quadratic).
fn quadratic_at(rows: &[(f64, f64)], x: f64) -> f64 {
    let i = rows.iter().position(|r| r.0 >= x).unwrap().clamp(1, rows.len() - 2);
    let p = &rows[i - 1..=i + 1];
    (0..3)
        .map(|a| {
            let l: f64 =
                (0..3).filter(|&b| b != a).map(|b| (x - p[b].0) / (p[a].0 - p[b].0)).product();
            l * p[a].1
        })
        .sum()
}

/// The static cantilever by arc-length path following: the path passes the elastica's
/// deflections at α = 3 and α = 6 and stops past the load factor 1.
#[test]
fn arc_length_path_follows_the_elastica() {
    let out = tempfile::tempdir().unwrap();
    let args = ["--set", "structure.arc_length={ initial = 0.2 }", "--set", "structure.steps=100"];
    let rows = probes("structure-static-cantilever", out.path(), &args);
    let path: Vec<(f64, f64)> = rows.iter().map(|r| (r[0], r[3])).collect();
    let last = path.last().unwrap().0;
    let (w3, w6) = (quadratic_at(&path, 0.5), quadratic_at(&path, 1.0));
    println!(
        "arc length: {} steps to λ = {last:.4}; w/L at α = 3 {w3:.5} vs {} ({:+.3}%), α = 6 {w6:.5} vs {} ({:+.3}%)",
        path.len() - 1,
        ELASTICA[2].1,
        100.0 * (w3 / ELASTICA[2].1 - 1.0),
        ELASTICA[5].1,
        100.0 * (w6 / ELASTICA[5].1 - 1.0)
    );
    assert!(last >= 1.0 && path.windows(2).all(|w| w[1].0 > w[0].0));
    assert!((w3 / ELASTICA[2].1 - 1.0).abs() < 5e-3 && (w6 / ELASTICA[5].1 - 1.0).abs() < 5e-3);
    // too few steps to reach the load factor: an error naming `steps`
    let err = fails(
        "structure-static-cantilever",
        "steps = 6",
        "steps = 3\narc_length = { initial = 0.2 }",
    );
    assert!(err.contains("structure.steps") && err.contains("short of"), "{err}");
}

/// A clamped circular plate (radius 1, 10 mm steel) under uniform pressure from the `annulus`
/// generator with `r_inner = 0`: the seam at 360° merges and the centre's collapsed cells
/// become triangles; Kirchhoff's centre deflection is `p a⁴ / 64 D`.
#[test]
fn clamped_disc_under_pressure_matches_kirchhoff() {
    let text = r#"[structure]
mesh = { generator = "annulus", r_inner = 0.0, r_outer = 1.0, n_theta = 32, n_r = 8 }
material = { e = 200e9, nu = 0.3, rho = 7800.0 }
element = "shell"
thickness = 0.01
integrator = "static"
steps = 1
[[structure.bc]]
set = "v1"
fixed = ["ux", "uy", "uz", "rx", "ry", "rz"]
[[structure.loads]]
pressure = 100.0
[[structure.probes]]
name = "centre"
point = [0.0, 0.0, 0.0]
"#;
    let d = 200e9 * 0.01f64.powi(3) / (12.0 * (1.0 - 0.09));
    let w = 100.0 / (64.0 * d);
    // the cells' normals (azimuth x radius) point to -z
    let centre = -last_row(text)[3];
    println!(
        "clamped disc: centre {centre:.5e} m vs p a⁴/64D = {w:.5e} m ({:+.2}%)",
        100.0 * (centre / w - 1.0)
    );
    assert!((centre / w - 1.0).abs() < 0.02);
}
