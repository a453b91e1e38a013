//! Patch tests: on distorted patches, prescribing a linear field on the boundary must
//! reproduce it exactly inside. Shells: constant membrane strain and constant curvature (4-node
//! MITC4 and 3-node DKT); tets: constant strain. Amplitudes are small (strain ~1e-6) so the
//! corotational kinematics is linear to ~1e-12.

use structure_solver::assembly::{Curve, FeModel, Part};
use structure_solver::elements::ShellSection;
use structure_solver::material::{Elastic, Material};
use structure_solver::mesh::{generate, Cell, CellKind, Mesh};
use structure_solver::model::Model;
use structure_solver::statics::{load_steps, NewtonSettings};

/// A 3x3 patch of the unit square, interior nodes moved off the grid.
fn distorted_patch(triangles: bool) -> Mesh {
    let mut m = generate::rectangle(1.0, 1.0, 3, 3);
    let moves = [(5, [0.08, -0.05]), (6, [-0.06, 0.07]), (9, [0.05, 0.06]), (10, [-0.07, -0.04])];
    for (n, d) in moves {
        m.nodes[n][0] += d[0];
        m.nodes[n][1] += d[1];
    }
    if triangles {
        m.to_triangles()
    } else {
        m
    }
}

fn boundary(m: &Mesh) -> Vec<usize> {
    m.nodes_where(|p| {
        p[0].abs() < 1e-12
            || p[1].abs() < 1e-12
            || (p[0] - 1.0).abs() < 1e-12
            || (p[1] - 1.0).abs() < 1e-12
    })
}

fn solve(model: &mut FeModel) {
    let s = NewtonSettings { tol: 1e-9, max_iter: 10, max_cuts: 0 };
    load_steps(model, &[1.0], &s, |_, _| {}).unwrap();
}

/// Prescribes `field(x, y)` (6 dof values) on `nodes` for the dofs in `mask`.
fn prescribe(
    model: &mut FeModel,
    mesh: &Mesh,
    nodes: &[usize],
    mask: [bool; 6],
    field: &dyn Fn(f64, f64) -> [f64; 6],
) {
    for &n in nodes {
        let p = mesh.nodes[n];
        let v = field(p[0], p[1]);
        for c in 0..6 {
            if mask[c] {
                model.prescribe(&[n], c, v[c], Curve::Linear);
            }
        }
    }
}

fn shell_patch(triangles: bool, bending: bool) {
    let mesh = distorted_patch(triangles);
    let sec = ShellSection { e: 1e6, nu: 0.3, rho: 1.0, h: 0.05 };
    let mut model = FeModel::new(&mesh, |_| Part::Shell(sec)).unwrap();
    let s = 1e-6;
    // membrane: u = a x + b y, v = c x + d y; bending: w = ½(kx x² + ky y² + kxy x y),
    // θx = ∂w/∂y, θy = -∂w/∂x
    let field = move |x: f64, y: f64| -> [f64; 6] {
        if bending {
            let (kx, ky, kxy) = (2.0 * s, -s, 1.5 * s);
            let w = 0.5 * (kx * x * x + ky * y * y + kxy * x * y);
            [0.0, 0.0, w, ky * y + 0.5 * kxy * x, -(kx * x + 0.5 * kxy * y), 0.0]
        } else {
            let (u, v) = (s * (1.0 * x + 0.4 * y), s * (-0.3 * x + 2.0 * y));
            [u, v, 0.0, 0.0, 0.0, 0.5 * s * (-0.3 - 0.4)]
        }
    };
    let b = boundary(&mesh);
    let all: Vec<usize> = (0..mesh.nodes.len()).collect();
    if bending {
        prescribe(&mut model, &mesh, &b, [false, false, true, true, true, false], &field);
        model.fix(&all, [true, true, false, false, false, true]);
    } else {
        prescribe(&mut model, &mesh, &b, [true, true, false, false, false, false], &field);
        model.fix(&all, [false, false, true, true, true, false]);
    }
    solve(&mut model);
    let x = model.positions().to_vec();
    let r = model.rotations().to_vec();
    let mut worst = 0.0f64;
    for n in 0..mesh.nodes.len() {
        let p = mesh.nodes[n];
        let want = field(p[0], p[1]);
        let got = [x[n].x - p[0], x[n].y - p[1], x[n].z - p[2]];
        for c in 0..3 {
            worst = worst.max((got[c] - want[c]).abs() / s);
        }
        if bending {
            // small rotations: θ ≈ axial(R - Rᵀ)/2
            let th = [0.5 * (r[n][(2, 1)] - r[n][(1, 2)]), 0.5 * (r[n][(0, 2)] - r[n][(2, 0)])];
            worst = worst.max((th[0] - want[3]).abs() / s).max((th[1] - want[4]).abs() / s);
        }
    }
    let name = format!(
        "{} {}",
        if triangles { "triangles" } else { "quads" },
        if bending { "bending" } else { "membrane" }
    );
    println!("{name}: max interior error / field scale = {worst:.2e}");
    assert!(worst < 1e-6, "{name}: patch error {worst:e}");
}

#[test]
fn quad_membrane_patch() {
    shell_patch(false, false);
}

#[test]
fn quad_bending_patch() {
    shell_patch(false, true);
}

#[test]
fn triangle_membrane_patch() {
    shell_patch(true, false);
}

#[test]
fn triangle_bending_patch() {
    shell_patch(true, true);
}

/// A 2x2x2 block of cubes, each cut into 6 tets, the centre node moved off the grid.
fn tet_patch() -> Mesh {
    let n = 2;
    let id = |i: usize, j: usize, k: usize| (k * (n + 1) + j) * (n + 1) + i;
    let mut m = Mesh::default();
    for k in 0..=n {
        for j in 0..=n {
            for i in 0..=n {
                m.nodes.push([i as f64 * 0.5, j as f64 * 0.5, k as f64 * 0.5]);
            }
        }
    }
    m.nodes[id(1, 1, 1)] = [0.56, 0.45, 0.53];
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let c = [
                    id(i, j, k),
                    id(i + 1, j, k),
                    id(i + 1, j + 1, k),
                    id(i, j + 1, k),
                    id(i, j, k + 1),
                    id(i + 1, j, k + 1),
                    id(i + 1, j + 1, k + 1),
                    id(i, j + 1, k + 1),
                ];
                // 6 tets around the 0-6 diagonal
                for t in [
                    [0, 1, 2, 6],
                    [0, 2, 3, 6],
                    [0, 3, 7, 6],
                    [0, 7, 4, 6],
                    [0, 4, 5, 6],
                    [0, 5, 1, 6],
                ] {
                    let mut nodes = t.map(|a| c[a]).to_vec();
                    // positive volume
                    let p = |a: usize| m.nodes[nodes[a]];
                    let v = |a: usize, b: usize| [0, 1, 2].map(|q| p(a)[q] - p(b)[q]);
                    let (a, b, cc) = (v(1, 0), v(2, 0), v(3, 0));
                    let det = a[0] * (b[1] * cc[2] - b[2] * cc[1])
                        - a[1] * (b[0] * cc[2] - b[2] * cc[0])
                        + a[2] * (b[0] * cc[1] - b[1] * cc[0]);
                    if det < 0.0 {
                        nodes.swap(1, 2);
                    }
                    m.cells.push(Cell { kind: CellKind::Tet4, nodes });
                }
            }
        }
    }
    m
}

#[test]
fn tet_constant_strain_patch() {
    let mesh = tet_patch();
    let mut model = FeModel::new(&mesh, |_| {
        Part::Solid(Material::Elastic(Elastic { e: 1e6, nu: 0.3, rho: 1.0 }))
    })
    .unwrap();
    let s = 1e-6;
    let grad = [[1.0, 0.3, -0.2], [0.1, -0.5, 0.4], [0.2, 0.6, 0.8]];
    let field = |p: [f64; 3]| [0, 1, 2].map(|i| s * (0..3).map(|j| grad[i][j] * p[j]).sum::<f64>());
    let interior = mesh.nearest_node([0.56, 0.45, 0.53]);
    for n in 0..mesh.nodes.len() {
        if n != interior {
            let v = field(mesh.nodes[n]);
            for c in 0..3 {
                model.prescribe(&[n], c, v[c], Curve::Linear);
            }
        }
    }
    solve(&mut model);
    let mut u = vec![[0.0; 3]; model.n_nodes()];
    model.displacement(&mut u);
    let want = field(mesh.nodes[interior]);
    let err = (0..3).map(|c| (u[interior][c] - want[c]).abs() / s).fold(0.0, f64::max);
    println!("tet patch: interior error / field scale = {err:.2e}");
    assert!(err < 1e-6, "tet patch error {err:e}");
}
