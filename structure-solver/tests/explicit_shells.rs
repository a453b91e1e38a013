//! Explicit one-point shells through `FeModel` (`Part::Bt4`: BT4 on quadrilaterals, BLT3 on
//! triangles, several materials): a strip of two materials in series (two BT4 materials, and
//! BT4 beside BLT3) against the closed-form end displacement and stress; a membrane patch test
//! on a distorted mixed quadrilateral/triangle mesh; the Sze-Liu-Lo cantilever on 32
//! triangles at every tabulated load level; forces, state and motion of a yielding mixed mesh
//! bitwise the same on 1 and 2 threads.

use structure_solver::assembly::{Curve, FeModel, Part};
use structure_solver::elements::bt4::LANES;
use structure_solver::elements::incidence::chunk_bounds;
use structure_solver::elements::{RotaryInertia, ShellSection, ShellYield};
use structure_solver::mesh::{generate, Cell, CellKind, Mesh};
use structure_solver::model::Model;
use structure_solver::time::CentralDifference;

/// An `nx` x `ny` grid on `[0, lx] x [0, ly]` whose cell `(i, j)` is split into two triangles
/// where `split(i, j)`; interior nodes moved by up to `jitter` of a cell. Node sets of the
/// generator (`u0`, `u1`, ...); cells in grid order, a split cell's two triangles in its place.
fn mixed(
    (lx, ly): (f64, f64),
    (nx, ny): (usize, usize),
    split: impl Fn(usize, usize) -> bool,
    jitter: f64,
) -> Mesh {
    let mut mesh = generate::rectangle(lx, ly, nx, ny);
    let (dx, dy) = (lx / nx as f64, ly / ny as f64);
    let mut cells = Vec::new();
    for c in &mesh.cells {
        let cx = c.nodes.iter().map(|&n| mesh.nodes[n][0]).sum::<f64>() / 4.0;
        let cy = c.nodes.iter().map(|&n| mesh.nodes[n][1]).sum::<f64>() / 4.0;
        let (i, j) = ((cx / dx) as usize, (cy / dy) as usize);
        let n = &c.nodes;
        if split(i, j) {
            cells.push(Cell { kind: CellKind::Tri3, nodes: vec![n[0], n[1], n[2]] });
            cells.push(Cell { kind: CellKind::Tri3, nodes: vec![n[0], n[2], n[3]] });
        } else {
            cells.push(c.clone());
        }
    }
    mesh.cells = cells;
    mesh.cell_sets.clear();
    for (k, p) in mesh.nodes.iter_mut().enumerate() {
        let inside = p[0] > 1e-9 && p[0] < lx - 1e-9 && p[1] > 1e-9 && p[1] < ly - 1e-9;
        if inside {
            let s = ((k * 7) % 5) as f64 / 4.0 - 0.5;
            let t = ((k * 3) % 7) as f64 / 6.0 - 0.5;
            p[0] += jitter * dx * s;
            p[1] += jitter * dy * t;
        }
    }
    mesh
}

fn centroid_x(mesh: &Mesh, c: usize) -> f64 {
    let n = &mesh.cells[c].nodes;
    n.iter().map(|&i| mesh.nodes[i][0]).sum::<f64>() / n.len() as f64
}

/// Dynamic relaxation through the model: central differences with mass-proportional damping
/// `α M` under the fixed nodal load `f_ext`, from rest, until the out-of-balance force on the
/// free dofs stays below `tol` (checked every 200 steps); returns the steps taken.
fn relax(model: &mut FeModel, f_ext: &[f64], alpha: f64, dt: f64, tol: f64, max: usize) -> usize {
    let n = model.n_dof();
    let (mut v, mut a, mut r, mut fi, mut du) =
        (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    model.internal_force(&mut fi);
    for step in 0..max {
        for i in 0..n {
            r[i] = f_ext[i] - fi[i];
        }
        model.apply_inverse_mass(&r, &mut a);
        let c = model.constrained();
        let kick = if step == 0 { 0.5 * dt } else { dt };
        for i in 0..n {
            v[i] = if c[i] {
                0.0
            } else {
                ((1.0 - 0.5 * alpha * dt) * v[i] + kick * a[i]) / (1.0 + 0.5 * alpha * dt)
            };
            du[i] = dt * v[i];
        }
        model.apply_increment(&du);
        model.internal_force(&mut fi);
        model.commit();
        if step % 200 == 199 {
            let c = model.constrained();
            let res =
                (0..n).filter(|&i| !c[i]).map(|i| (f_ext[i] - fi[i]).abs()).fold(0.0, f64::max);
            if res < tol {
                return step + 1;
            }
        }
    }
    panic!("no static state in {max} steps");
}

/// `x` component of the displacement of node `n`.
fn ux(model: &FeModel, n: usize) -> f64 {
    model.positions()[n].x - model.initial_positions()[n].x
}

#[test]
fn two_materials_in_series_give_the_closed_form_end_displacement() {
    // A strip L x b x h, clamped at x = 0, pulled at x = L by σ b h; steel for x < L/2,
    // aluminium beyond; ν = 0, so the stress is σ everywhere and u(L) = σ (L/2)(1/E1 + 1/E2).
    // 20 x 2 cells of quadrilaterals, or with every other column of the aluminium half split
    // into triangles (BT4 of both materials beside BLT3 of aluminium).
    let (l, b, h, sigma) = (1.0, 0.1, 0.01, 1e6);
    let steel = ShellSection { e: 200e9, nu: 0.0, rho: 7800.0, h };
    let alu = ShellSection { e: 70e9, nu: 0.0, rho: 2700.0, h };
    let exact = sigma * (0.5 * l) * (1.0 / steel.e + 1.0 / alu.e);
    for (name, right_triangles) in [("BT4 + BT4", false), ("BT4 + BLT3", true)] {
        let mesh = mixed((l, b), (20, 2), |i, _| right_triangles && i >= 10 && (i % 2 == 0), 0.0);
        let right: Vec<bool> =
            (0..mesh.cells.len()).map(|c| centroid_x(&mesh, c) > 0.5 * l).collect();
        let mut model =
            FeModel::new(&mesh, |c| Part::Bt4(if right[c] { alu } else { steel }, None)).unwrap();
        model.set_rotary_inertia(RotaryInertia::Scaled);
        let (quads, tris) = (model.bt4().unwrap(), model.blt3());
        assert_eq!(quads.materials().len(), 2, "{name}: two BT4 materials");
        if right_triangles {
            let t = tris.expect("triangles on the right");
            assert_eq!(t.materials().len(), 2);
            assert!(t.n_elements() == 20 && quads.n_elements() == 30, "{name}");
        } else {
            assert!(tris.is_none());
        }
        model.fix(mesh.node_set("u0").unwrap(), [true; 6]);
        // consistent nodal forces of a uniform traction on the end x = L (3 nodes)
        let tip = mesh.node_set("u1").unwrap().to_vec();
        let mut f_ext = vec![0.0; model.n_dof()];
        for &n in &tip {
            let y = mesh.nodes[n][1];
            let share = if y.abs() < 1e-12 || (y - b).abs() < 1e-12 { 0.25 } else { 0.5 };
            f_ext[6 * n] = share * sigma * b * h;
        }
        // damping near critical for the first axial mode
        let c = (alu.e / alu.rho).sqrt();
        let alpha = 2.0 * std::f64::consts::PI * c / (2.0 * l);
        let dt = 0.9 * model.stable_dt();
        let steps = relax(&mut model, &f_ext, alpha, dt, 1e-9 * sigma * b * h, 200_000);
        let worst_u = tip.iter().map(|&n| (ux(&model, n) / exact - 1.0).abs()).fold(0.0, f64::max);
        // the stress of every element and point, from the two families
        let mut worst_s = 0.0f64;
        let q = model.bt4().unwrap();
        for e in 0..q.n_elements() {
            for p in 0..q.settings.rule.len() {
                worst_s = worst_s.max((q.stress(e, p)[0] / sigma - 1.0).abs());
            }
        }
        if let Some(t) = model.blt3() {
            for e in 0..t.n_elements() {
                for p in 0..t.settings.rule.len() {
                    // the frame's ê1 lies along side 1-2: along x or the diagonal
                    let c = t.conn[e].map(|n| mesh.nodes[n as usize]);
                    let th = (c[1][1] - c[0][1]).atan2(c[1][0] - c[0][0]);
                    let want = sigma * th.cos().powi(2);
                    worst_s = worst_s.max((t.stress(e, p)[0] - want).abs() / sigma);
                }
            }
        }
        println!("{name}: u(L) {:.6e} vs σ L/2 (1/E1 + 1/E2) = {exact:.6e}, worst tip error {worst_u:.2e}, worst stress error {worst_s:.2e} ({steps} steps)", ux(&model, tip[0]));
        assert!(worst_u < 1e-4, "{name}: tip displacement off by {worst_u:e}");
        assert!(worst_s < 1e-4, "{name}: stress off by {worst_s:e}");
    }
}

/// Stress `s` (global `[xx, yy, xy]`) in a frame whose `ê1` makes angle `th` with `x`.
fn rotate_stress(s: [f64; 3], th: f64) -> [f64; 3] {
    let (sn, cs) = th.sin_cos();
    [
        s[0] * cs * cs + s[1] * sn * sn + 2.0 * s[2] * sn * cs,
        s[0] * sn * sn + s[1] * cs * cs - 2.0 * s[2] * sn * cs,
        (s[1] - s[0]) * sn * cs + s[2] * (cs * cs - sn * sn),
    ]
}

/// The membrane patch on a mixed mesh after one increment `Δu = G X` on every node, `G`
/// scaled by `scale`: the largest stress error of any element and point (relative to the
/// exact stress) and the largest interior nodal force relative to the largest force.
fn membrane_patch(scale: f64) -> (f64, f64) {
    // 4 x 4 cells, every other one split into triangles, interior nodes moved off the grid
    let (lx, ly) = (1.0, 0.8);
    let mesh = mixed((lx, ly), (4, 4), |i, j| (i + j) % 2 == 0, 0.3);
    let sec = ShellSection { e: 200e9, nu: 0.3, rho: 7800.0, h: 0.01 };
    let mut model = FeModel::new(&mesh, |_| Part::Bt4(sec, None)).unwrap();
    let (nq, nt) = (model.bt4().unwrap().n_elements(), model.blt3().unwrap().n_elements());
    assert_eq!((nq, nt), (8, 16));
    let g = [[2e-6 * scale, 0.7e-6 * scale], [-0.4e-6 * scale, -1.1e-6 * scale]];
    let x0 = mesh.nodes.clone();
    let mut du = vec![0.0; model.n_dof()];
    let mut xm = x0.clone();
    for (i, p) in x0.iter().enumerate() {
        for a in 0..2 {
            du[6 * i + a] = g[a][0] * p[0] + g[a][1] * p[1];
            xm[i][a] += 0.5 * du[6 * i + a];
        }
    }
    model.apply_increment(&du);
    let mut f = vec![0.0; model.n_dof()];
    model.internal_force(&mut f);
    model.commit();
    // strain in the mid geometry: L = G (I + G/2)⁻¹, Δε = sym(L)
    let m = [[1.0 + g[0][0] / 2.0, g[0][1] / 2.0], [g[1][0] / 2.0, 1.0 + g[1][1] / 2.0]];
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let inv = [[m[1][1] / det, -m[0][1] / det], [-m[1][0] / det, m[0][0] / det]];
    let l = |a: usize, b: usize| g[a][0] * inv[0][b] + g[a][1] * inv[1][b];
    let eps = [l(0, 0), l(1, 1), l(0, 1) + l(1, 0)];
    let d = sec.e / (1.0 - sec.nu * sec.nu);
    let s_global = [
        d * (eps[0] + sec.nu * eps[1]),
        d * (eps[1] + sec.nu * eps[0]),
        d * 0.5 * (1.0 - sec.nu) * eps[2],
    ];
    let side = |a: usize, b: usize| (xm[b][1] - xm[a][1]).atan2(xm[b][0] - xm[a][0]);
    let mut worst = 0.0f64;
    let (q, t) = (model.bt4().unwrap(), model.blt3().unwrap());
    for (e, c) in q.conn.iter().enumerate() {
        let want = rotate_stress(s_global, side(c[0] as usize, c[1] as usize));
        for p in 0..q.settings.rule.len() {
            let s = q.stress(e, p);
            for k in 0..3 {
                worst = worst.max((s[k] - want[k]).abs() / s_global[0].abs());
            }
        }
    }
    for (e, c) in t.conn.iter().enumerate() {
        let want = rotate_stress(s_global, side(c[0] as usize, c[1] as usize));
        for p in 0..t.settings.rule.len() {
            let s = t.stress(e, p);
            for k in 0..3 {
                worst = worst.max((s[k] - want[k]).abs() / s_global[0].abs());
            }
        }
    }
    // interior nodes in equilibrium
    let largest = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let interior =
        |p: &[f64; 3]| p[0] > 1e-9 && p[0] < lx - 1e-9 && p[1] > 1e-9 && p[1] < ly - 1e-9;
    let res = (0..x0.len())
        .filter(|&n| interior(&x0[n]))
        .flat_map(|n| (0..6).map(move |k| 6 * n + k))
        .map(|i| f[i].abs())
        .fold(0.0, f64::max)
        / largest;
    (worst, res)
}

#[test]
fn mixed_mesh_membrane_patch_test_gives_constant_stress_and_no_interior_force() {
    let (worst, res) = membrane_patch(1.0);
    let (worst_small, res_small) = membrane_patch(0.01);
    println!("mixed patch (8 BT4, 16 BLT3): strain increment 2e-6: stress error {worst:.2e}, interior force {res:.2e} of the largest; 2e-8: {worst_small:.2e}, {res_small:.2e}");
    // The model recovers a step's increment from positions, `x^{n+1} - x^n`, to the
    // round-off `ε |x| / |Δu|` of the increment: 1e-10 at 2e-6, 1e-8 at 2e-8.
    assert!(worst < 1e-9, "stress error {worst:e} at a strain increment of 2e-6");
    assert!(worst_small < 1e-7, "stress error {worst_small:e} at a strain increment of 2e-8");
    // Stresses live in each element's frame (ê1 along side 1-2), which turns by O(Δε)
    // between the mid geometry (strain) and the end geometry (forces) differently per
    // element: the interior balance holds to the size of the strain increment and falls
    // with it to that round-off (an assembly error would stay O(1)).
    assert!(res < 2e-6, "interior force {res:e} at a strain increment of 2e-6");
    assert!(res_small < 5e-8, "interior force {res_small:e} at a strain increment of 2e-8");
}

/// Sze, Liu & Lo (2004, Finite Elem. Anal. Des. 40:1551), §3.1, as `tests/sze_cantilever.rs`
/// holds it: P/P_max, -u_tip, w_tip (S4R, 16x1).
const SZE_ROWS: &[(f64, [f64; 2])] = &[
    (0.05, [0.026, 0.663]),
    (0.10, [0.103, 1.309]),
    (0.15, [0.224, 1.922]),
    (0.20, [0.381, 2.493]),
    (0.25, [0.563, 3.015]),
    (0.30, [0.763, 3.488]),
    (0.35, [0.971, 3.912]),
    (0.40, [1.184, 4.292]),
    (0.45, [1.396, 4.631]),
    (0.50, [1.604, 4.933]),
    (0.55, [1.807, 5.202]),
    (0.60, [2.002, 5.444]),
    (0.65, [2.190, 5.660]),
    (0.70, [2.370, 5.855]),
    (0.75, [2.541, 6.031]),
    (0.80, [2.705, 6.190]),
    (0.85, [2.861, 6.335]),
    (0.90, [3.010, 6.467]),
    (0.95, [3.151, 6.588]),
    (1.00, [3.286, 6.698]),
];

#[test]
fn sze_cantilever_on_32_triangles_through_the_model_reaches_the_published_states() {
    // L = 10, b = 1, h = 0.1, E = 1.2e6, ν = 0, P_max = 4 at the tip, clamped at x = 0;
    // the paper's 16x1 mesh, each quad split into two triangles; ρ = 1 (quasi-static)
    let mesh = generate::rectangle(10.0, 1.0, 16, 1).to_triangles();
    let sec = ShellSection { e: 1.2e6, nu: 0.0, rho: 1.0, h: 0.1 };
    let mut model = FeModel::new(&mesh, |_| Part::Bt4(sec, None)).unwrap();
    model.set_rotary_inertia(RotaryInertia::Scaled);
    assert!(model.bt4().is_none() && model.blt3().unwrap().n_elements() == 32);
    model.fix(mesh.node_set("u0").unwrap(), [true; 6]);
    let tip = mesh.node_set("u1").unwrap().to_vec();
    let dt = 0.9 * model.stable_dt();
    let inertia = 0.1f64.powi(3) / 12.0;
    let w1 = 1.875_104_f64.powi(2) * (1.2e6 * inertia / (0.1 * 1e4)).sqrt();
    let alpha = 2.0 * w1;
    let n = model.n_dof();
    let (mut v, mut a, mut r, mut fi, mut du) =
        (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut f_ext = vec![0.0; n];
    model.internal_force(&mut fi);
    let (mut lf, mut first, mut steps) = (0.0, true, 0usize);
    let mut errors = Vec::new();
    println!("Sze cantilever, 32 BLT3 triangles in FeModel, dt {dt:.3e}: P/Pmax, -u_tip, w_tip (computed / reference / relative error)");
    let ramp = (2.0 * std::f64::consts::PI / w1 / dt) as usize;
    for &(target, reference) in SZE_ROWS {
        // ramp the load over one first-mode period, then hold until static
        let mut k = 0usize;
        loop {
            let p = if k < ramp { lf + (target - lf) * k as f64 / ramp as f64 } else { target };
            for &t in &tip {
                f_ext[6 * t + 2] = 4.0 * p / tip.len() as f64;
            }
            for i in 0..n {
                r[i] = f_ext[i] - fi[i];
            }
            model.apply_inverse_mass(&r, &mut a);
            let c = model.constrained();
            let kick = if first { 0.5 * dt } else { dt };
            for i in 0..n {
                v[i] = if c[i] {
                    0.0
                } else {
                    ((1.0 - 0.5 * alpha * dt) * v[i] + kick * a[i]) / (1.0 + 0.5 * alpha * dt)
                };
                du[i] = dt * v[i];
            }
            first = false;
            model.apply_increment(&du);
            model.internal_force(&mut fi);
            model.commit();
            k += 1;
            if k > ramp && k.is_multiple_of(200) {
                let c = model.constrained();
                let res =
                    (0..n).filter(|&i| !c[i]).map(|i| (f_ext[i] - fi[i]).abs()).fold(0.0, f64::max);
                if res < 1e-6 * 4.0 {
                    break;
                }
            }
            assert!(k < 400_000, "no static state at P/Pmax {target}");
        }
        steps += k;
        lf = target;
        let x = model.positions();
        let x0 = model.initial_positions();
        let u = -tip.iter().map(|&t| x[t].x - x0[t].x).sum::<f64>() / tip.len() as f64;
        let w = tip.iter().map(|&t| x[t].z - x0[t].z).sum::<f64>() / tip.len() as f64;
        let e = [(u - reference[0]) / reference[0], (w - reference[1]) / reference[1]];
        println!(
            "  {target:.2}: {u:.4} / {:.3} / {:+.2}%,  {w:.4} / {:.3} / {:+.2}%",
            reference[0],
            100.0 * e[0],
            reference[1],
            100.0 * e[1]
        );
        errors.push(e);
    }
    println!("  {steps} steps");
    // the kernel test's tolerance (`tests/blt3_dynamics.rs`): w everywhere, u from row 4 (the
    // first rows' -u has two significant digits)
    let worst_w = errors.iter().map(|e| e[1].abs()).fold(0.0, f64::max);
    let worst_u = errors.iter().skip(3).map(|e| e[0].abs()).fold(0.0, f64::max);
    assert!(worst_w < 0.005, "w_tip off by {worst_w}");
    assert!(worst_u < 0.005, "u_tip off by {worst_u}");
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap()
}

#[test]
fn yielding_mixed_mesh_is_bitwise_the_same_on_1_and_2_threads() {
    // 36 x 18 cells, a checkerboard of quadrilaterals and split cells: 324 BT4 and 648 BLT3
    // elements (several tasks of both element phases), two J2 materials by position
    let mesh = mixed((0.2, 0.1), (36, 18), |i, j| (i + j) % 2 == 1, 0.2);
    let steel = ShellSection { e: 200e9, nu: 0.3, rho: 7800.0, h: 0.002 };
    let alu = ShellSection { e: 70e9, nu: 0.33, rho: 2700.0, h: 0.003 };
    let y_steel = ShellYield { sigma_y: 250e6, hardening: 1e9, points: 5 };
    let y_alu = ShellYield { sigma_y: 120e6, hardening: 5e8, points: 5 };
    let right: Vec<bool> = (0..mesh.cells.len()).map(|c| centroid_x(&mesh, c) > 0.13).collect();
    let run = |threads: usize| {
        pool(threads).install(|| {
            let mut model = FeModel::new(&mesh, |c| {
                if right[c] {
                    Part::Bt4(alu, Some(y_alu))
                } else {
                    Part::Bt4(steel, Some(y_steel))
                }
            })
            .unwrap();
            model.set_rotary_inertia(RotaryInertia::Scaled);
            model.fix(mesh.node_set("u0").unwrap(), [true; 6]);
            // the tip driven up at 60 m/s: it bends and yields
            model.prescribe(mesh.node_set("u1").unwrap(), 2, 60.0, Curve::Linear);
            let n = model.n_dof();
            let dt = 0.8 * model.stable_dt();
            let mut cd = CentralDifference::new(&mut model, 0.0, vec![0.0; n], None);
            for _ in 0..300 {
                cd.step(&mut model, dt, None);
            }
            (model, cd.state.v)
        })
    };
    let (m1, v1) = run(1);
    let (m2, v2) = run(2);
    let (q, t) = (m1.bt4().unwrap(), m1.blt3().unwrap());
    // several chunks on 2 threads, the last block partial
    assert!(chunk_bounds(q.n_elements(), LANES, 2).len() > 3 && q.n_elements() % LANES != 0);
    assert!(chunk_bounds(t.n_elements(), 1, 2).len() > 3);
    let np = 5;
    let max_alpha = |f: &dyn Fn(usize, usize) -> f64, ne: usize| {
        (0..ne).flat_map(|e| (0..np).map(move |p| (e, p))).map(|(e, p)| f(e, p)).fold(0.0, f64::max)
    };
    let aq = max_alpha(&|e, p| q.plastic_strain(e, p), q.n_elements());
    let at = max_alpha(&|e, p| t.plastic_strain(e, p), t.n_elements());
    println!(
        "{} BT4, {} BLT3: max plastic strain {aq:.3e} (quads), {at:.3e} (triangles)",
        q.n_elements(),
        t.n_elements()
    );
    assert!(aq > 1e-4 && at > 1e-4, "both families must yield: {aq}, {at}");
    let bits = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
    let flat = |m: &FeModel| m.positions().iter().flat_map(|p| [p.x, p.y, p.z]).collect::<Vec<_>>();
    assert!(bits(&flat(&m1), &flat(&m2)), "positions on 1 and 2 threads");
    assert!(bits(&v1, &v2), "velocities on 1 and 2 threads");
    assert_eq!(m1.bt4().unwrap().state(), m2.bt4().unwrap().state(), "BT4 state");
    assert_eq!(m1.blt3().unwrap().state(), m2.blt3().unwrap().state(), "BLT3 state");
    let (mut f1, mut f2) = (vec![0.0; m1.n_dof()], vec![0.0; m2.n_dof()]);
    let (mut m1, mut m2) = (m1, m2);
    pool(1).install(|| m1.internal_force(&mut f1));
    pool(2).install(|| m2.internal_force(&mut f2));
    assert!(bits(&f1, &f2), "internal forces on 1 and 2 threads");
}
