//! The free-dof solve of Newton iterations (`linsolve::FreeSolver`): the kept factor
//! preconditions the GMRES of later matrices. A linear problem factors once and follows the
//! exact discrete Newmark solution; a mildly nonlinear shell reuses factors across Newton
//! iterations and steps and ends where refactoring every iteration ends; the scatter-map
//! assembly gives the triplet path's matrix bit for bit; one and two threads agree.

use faer::sparse::Triplet;
use faer::Mat;
use nalgebra::{DMatrix, SymmetricEigen};
use structure_solver::assembly::{Curve, FeModel, Part};
use structure_solver::elements::ShellSection;
use structure_solver::linsolve::FreeSolver;
use structure_solver::mesh::generate::rectangle;
use structure_solver::model::{Model, Tangent};
use structure_solver::statics::{load_steps, NewtonSettings};
use structure_solver::time::{Implicit, ImplicitScheme};

/// `n` nodes on a line joined by springs on every dof (stiffness `k (1 + c)` on dof `c`),
/// node 0 fixed, mass `m` per dof, a step load `t_scale(t) · f` on the last node: linear.
struct Springs {
    n: usize,
    k: f64,
    mass: Vec<f64>,
    fixed: Vec<bool>,
    f: [f64; 6],
    /// External force proportional to `t` (statics) instead of constant.
    ramp: bool,
    u: Vec<f64>,
    committed: Vec<f64>,
    epoch: u64,
}

impl Springs {
    fn new(n: usize, ramp: bool) -> Self {
        let mut fixed = vec![false; 6 * n];
        fixed[..6].fill(true);
        Springs {
            n,
            k: 1e4,
            mass: vec![2.0; 6 * n],
            fixed,
            f: [10.0, -20.0, 30.0, 1.0, -2.0, 3.0],
            ramp,
            u: vec![0.0; 6 * n],
            committed: vec![0.0; 6 * n],
            epoch: 0,
        }
    }

    fn stiffness(&self, c: usize) -> f64 {
        self.k * (1.0 + c as f64)
    }
}

impl Model for Springs {
    fn n_nodes(&self) -> usize {
        self.n
    }
    fn lumped_mass(&self) -> &[f64] {
        &self.mass
    }
    fn constrained(&self) -> &[bool] {
        &self.fixed
    }
    fn prescribed(&self, _t: f64, _out: &mut [f64]) {}
    fn apply_increment(&mut self, du: &[f64]) {
        for (u, d) in self.u.iter_mut().zip(du) {
            *u += d;
        }
    }
    fn internal_force(&mut self, f: &mut [f64]) {
        f.fill(0.0);
        for i in 1..self.n {
            for c in 0..6 {
                let (a, b) = (6 * (i - 1) + c, 6 * i + c);
                let s = self.stiffness(c) * (self.u[b] - self.u[a]);
                f[b] += s;
                f[a] -= s;
            }
        }
    }
    fn external_force(&mut self, t: f64, f: &mut [f64]) {
        f.fill(0.0);
        let scale = if self.ramp { t } else { 1.0 };
        for c in 0..6 {
            f[6 * (self.n - 1) + c] = scale * self.f[c];
        }
    }
    fn tangent(&mut self, _t: f64, out: &mut Tangent) {
        out.clear();
        let out = &mut out.entries;
        for i in 1..self.n {
            for c in 0..6 {
                let (a, b, k) = (6 * (i - 1) + c, 6 * i + c, self.stiffness(c));
                out.extend([
                    Triplet::new(a, a, k),
                    Triplet::new(b, b, k),
                    Triplet::new(a, b, -k),
                    Triplet::new(b, a, -k),
                ]);
            }
        }
    }
    fn topology_epoch(&self) -> u64 {
        self.epoch
    }
    fn commit(&mut self) {
        self.committed.clone_from(&self.u);
    }
    fn revert(&mut self) {
        self.u.clone_from(&self.committed);
    }
    fn stable_dt(&self) -> f64 {
        2.0 / (4.0 * self.stiffness(5) / self.mass[0]).sqrt()
    }
    fn displacement(&self, out: &mut [[f64; 3]]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = [self.u[6 * i], self.u[6 * i + 1], self.u[6 * i + 2]];
        }
    }
}

/// The exact Newmark (average acceleration) history of dof `c` of the free nodes of `s`
/// under its step load from rest: per mode of the chain `K φ = ω² m φ`,
/// `q_n = φᵀf / (m ω²) (1 - cos(n Ω Δt))`, `tan(Ω Δt / 2) = ω Δt / 2`.
fn newmark_exact(s: &Springs, c: usize, dt: f64, step: usize) -> Vec<f64> {
    let nf = s.n - 1;
    let (k, m) = (s.stiffness(c), s.mass[0]);
    let kk = DMatrix::from_fn(nf, nf, |i, j| match (i as isize - j as isize).abs() {
        0 if i + 1 == nf => k,
        0 => 2.0 * k,
        1 => -k,
        _ => 0.0,
    });
    let eig = SymmetricEigen::new(kk);
    let mut u = vec![0.0; nf];
    for mode in 0..nf {
        let w2 = eig.eigenvalues[mode] / m;
        let phi = eig.eigenvectors.column(mode);
        let omega_dt = 2.0 * (w2.sqrt() * dt / 2.0).atan(); // Ω Δt
        let q = phi[nf - 1] * s.f[c] / (m * w2) * (1.0 - (step as f64 * omega_dt).cos());
        for i in 0..nf {
            u[i] += q * phi[i];
        }
    }
    u
}

#[test]
fn a_linear_problem_factors_once_and_follows_the_exact_newmark_solution() {
    let dt = 2e-3;
    let mut m = Springs::new(6, false);
    let mut im = Implicit::new(&mut m, ImplicitScheme::Newmark, 0.0, vec![0.0; 36], None);
    im.params.tol = 1e-12;
    let (mut factorisations, mut worst) = (0, 0.0f64);
    for step in 1..=40 {
        let info = im.step(&mut m, dt, None).unwrap();
        assert_eq!(info.iterations, 1, "step {step}: a linear step is one Newton iteration");
        assert_eq!(info.gmres_iterations, 1, "step {step}: the kept factor is exact");
        factorisations += info.factorisations;
        for c in 0..6 {
            let exact = newmark_exact(&m, c, dt, step);
            let scale = exact.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            for (i, e) in exact.iter().enumerate() {
                worst = worst.max((m.u[6 * (i + 1) + c] - e).abs() / scale);
            }
        }
    }
    println!("factorisations {factorisations}, worst relative error {worst:.2e}");
    assert_eq!(factorisations, 1);
    assert_eq!(im.solve_stats().factorisations, 1);
    assert!(worst < 1e-9, "{worst}");
    // refactoring every iteration: one factorisation per step, the same states
    let mut r = Springs::new(6, false);
    let mut ir = Implicit::new(&mut r, ImplicitScheme::Newmark, 0.0, vec![0.0; 36], None);
    ir.params.tol = 1e-12;
    ir.set_factor_reuse(false);
    for _ in 0..40 {
        assert_eq!(ir.step(&mut r, dt, None).unwrap().factorisations, 1);
    }
    let diff = r.u.iter().zip(&m.u).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(diff < 1e-12 * m.u.iter().fold(0.0f64, |a, v| a.max(v.abs())), "{diff}");
}

#[test]
fn linear_load_steps_factor_once() {
    let mut m = Springs::new(5, true);
    let s = NewtonSettings { tol: 1e-12, max_iter: 5, max_cuts: 0 };
    let steps = load_steps(&mut m, &[0.25, 0.5, 1.0], &s, |_, _| {}).unwrap();
    let counts: Vec<usize> = steps.iter().map(|c| c.factorisations).collect();
    assert_eq!(counts, [1, 0, 0], "{steps:?}");
    // u = K⁻¹ f: the spring forces of a chain loaded at its end are all f
    for i in 1..5 {
        for c in 0..6 {
            let exact = i as f64 * m.f[c] / m.stiffness(c);
            assert!((m.u[6 * i + c] - exact).abs() <= 1e-12 * exact.abs(), "node {i} dof {c}");
        }
    }
}

/// A clamped `n x n` MITC4 steel plate, 1 m square, 10 mm thick, under `p`.
fn plate(n: usize, p: f64) -> FeModel {
    let mesh = rectangle(1.0, 1.0, n, n);
    let section = ShellSection { e: 200e9, nu: 0.3, rho: 7800.0, h: 0.01 };
    let mut model = FeModel::new(&mesh, |_| Part::Shell(section)).unwrap();
    let edge = mesh.nodes_where(|q| q[0] == 0.0 || q[0] == 1.0 || q[1] == 0.0 || q[1] == 1.0);
    model.fix(&edge, [true; 6]);
    let cells: Vec<usize> = (0..mesh.cells.len()).collect();
    model.pressure(&cells, p, Curve::Constant);
    model
}

/// `steps` Newmark steps of the plate: per step (Newton iterations, factorisations), and the
/// final displacements.
fn plate_run(reuse: bool, steps: usize) -> (Vec<(usize, usize)>, Vec<[f64; 3]>) {
    let mut m = plate(8, 1e5);
    let n = m.n_dof();
    let mut im = Implicit::new(&mut m, ImplicitScheme::Newmark, 0.0, vec![0.0; n], None);
    im.params.tol = 1e-10;
    im.set_factor_reuse(reuse);
    let mut counts = Vec::new();
    for _ in 0..steps {
        let info = im.step(&mut m, 2e-4, None).unwrap();
        counts.push((info.iterations, info.factorisations));
    }
    let mut u = vec![[0.0; 3]; m.n_nodes()];
    m.displacement(&mut u);
    (counts, u)
}

#[test]
fn a_mildly_nonlinear_shell_reuses_factors_and_ends_where_refactoring_ends() {
    let steps = 12;
    let (reused, u) = plate_run(true, steps);
    let (fresh, u_ref) = plate_run(false, steps);
    println!("reuse (iterations, factorisations) per step: {reused:?}");
    println!("refactor every iteration: {fresh:?}");
    let umax = u.iter().flat_map(|p| p.iter()).fold(0.0f64, |a, v| a.max(v.abs()));
    // deflection near the plate thickness: geometrically nonlinear
    assert!(umax > 0.003, "{umax}");
    let diff = u
        .iter()
        .zip(&u_ref)
        .flat_map(|(a, b)| (0..3).map(move |k| (a[k] - b[k]).abs()))
        .fold(0.0, f64::max);
    println!("largest displacement {umax:.4e} m, difference {diff:.2e} m");
    assert!(diff <= 1e-8 * umax, "{diff}");
    // refactoring: one factorisation per Newton iteration
    assert!(fresh.iter().all(|&(it, f)| f == it), "{fresh:?}");
    assert!(fresh.iter().all(|&(it, _)| it >= 2), "Newton iterates: nonlinear");
    // reuse: whole steps without a factorisation, and steps of several Newton iterations
    // with at most one
    let (its, facts): (usize, usize) =
        reused.iter().fold((0, 0), |(a, b), &(it, f)| (a + it, b + f));
    assert!(reused.iter().filter(|&&(_, f)| f == 0).count() >= steps / 2, "{reused:?}");
    assert!(reused.iter().any(|&(it, f)| it >= 2 && f <= 1), "{reused:?}");
    assert!(3 * facts <= its, "{facts} factorisations for {its} Newton iterations");
}

/// The matrix of the triplet path: each free triplet summed in order into its slot (found by
/// search) of `j`'s pattern, then the mass on the diagonal.
fn triplet_path(
    solver: &FreeSolver,
    k: &[Triplet<usize, usize, f64>],
    ck: f64,
    mass: (f64, &[f64]),
) -> Vec<f64> {
    let j = solver.matrix().unwrap();
    let (ptr, rows) = (j.col_ptr(), j.row_idx());
    let slot = |i: usize, c: usize| ptr[c] + rows[ptr[c]..ptr[c + 1]].binary_search(&i).unwrap();
    let mut a = vec![0.0; rows.len()];
    for e in k {
        if let (Some(i), Some(c)) = (solver.free.index(e.row), solver.free.index(e.col)) {
            a[slot(i, c)] += ck * e.val;
        }
    }
    for (d, &m) in mass.1.iter().enumerate() {
        if let Some(i) = solver.free.index(d) {
            a[slot(i, i)] += mass.0 * m;
        }
    }
    a
}

fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

#[test]
fn the_scatter_map_assembles_the_triplet_paths_matrix_bit_for_bit() {
    let mut m = plate(6, 2e6);
    let mass = m.lumped_mass().to_vec();
    let mut solver = FreeSolver::new(&m);
    let mut trip = Tangent::default();
    let mut check = |m: &mut FeModel, solver: &mut FreeSolver, shuffle: bool| {
        m.tangent(0.0, &mut trip);
        if shuffle {
            // the element blocks as loose entries, last first
            let mut entries: Vec<_> = trip.triplets().collect();
            entries.reverse();
            trip = Tangent::from(entries);
        }
        solver.assemble(&trip, 0.5, Some((3e7, &mass))).unwrap();
        let want = triplet_path(solver, &trip.triplets().collect::<Vec<_>>(), 0.5, (3e7, &mass));
        assert!(same_bits(solver.matrix().unwrap().val(), &want));
    };
    check(&mut m, &mut solver, false); // a new map
                                       // a deformed configuration: new values through the same map
    let mut du = vec![0.0; m.n_dof()];
    for (d, v) in du.iter_mut().enumerate() {
        if !m.constrained()[d] {
            *v = 1e-3 * ((d as f64) * 0.37).sin();
        }
    }
    m.apply_increment(&du);
    check(&mut m, &mut solver, false);
    check(&mut m, &mut solver, true); // the stream reordered: a new map on the same pattern
                                      // two threads or one: the same bits
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let two = solver.matrix().unwrap().val().to_vec();
    pool.install(|| solver.assemble(&trip, 0.5, Some((3e7, &mass)))).unwrap();
    assert!(same_bits(solver.matrix().unwrap().val(), &two));
}

#[test]
fn one_and_two_threads_solve_alike() {
    let mut m = plate(10, 1e5);
    let mass = m.lumped_mass().to_vec();
    let mut trip = Tangent::default();
    m.tangent(0.0, &mut trip);
    let mut f = vec![0.0; m.n_dof()];
    m.external_force(0.0, &mut f);
    let solve = |threads: usize| -> Mat<f64> {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mut solver = FreeSolver::new(&m);
            solver.assemble(&trip, 1.0, Some((1e6, &mass))).unwrap();
            let mut x = solver.free.gather(&f);
            solver.solve_in_place(x.as_mut()).unwrap();
            assert_eq!(solver.stats().factorisations, 1);
            x
        })
    };
    let (one, two) = (solve(1), solve(2));
    let scale = (0..one.nrows()).map(|i| one[(i, 0)].abs()).fold(0.0, f64::max);
    let diff = (0..one.nrows()).map(|i| (one[(i, 0)] - two[(i, 0)]).abs()).fold(0.0, f64::max);
    assert!(scale > 0.0 && diff <= 1e-10 * scale, "{diff} of {scale}");
}

#[test]
fn a_topology_change_renumbers_the_free_dofs() {
    let dt = 2e-3;
    let mut m = Springs::new(6, false);
    let mut im = Implicit::new(&mut m, ImplicitScheme::Newmark, 0.0, vec![0.0; 36], None);
    im.params.tol = 1e-12;
    for _ in 0..5 {
        im.step(&mut m, dt, None).unwrap();
    }
    // node 3 clamped where it is (its motion prescribed to stay), the model says so
    let u3: Vec<f64> = m.u[18..24].to_vec();
    m.fixed[18..24].fill(true);
    m.epoch += 1;
    let mut state = im.state.clone();
    state.v[18..24].fill(0.0);
    state.a[18..24].fill(0.0);
    im.state = state.clone();
    let mut twin = Springs::new(6, false);
    twin.u.clone_from(&m.u);
    twin.commit();
    twin.fixed.clone_from(&m.fixed);
    let mut fresh = Implicit::resume(&twin, ImplicitScheme::Newmark, state);
    fresh.params.tol = 1e-12;
    for _ in 0..5 {
        let info = im.step(&mut m, dt, None).unwrap();
        assert_eq!(info.iterations, 1);
        fresh.step(&mut twin, dt, None).unwrap();
    }
    assert!(m.u[18..24].iter().zip(&u3).all(|(a, b)| a == b), "node 3 stays");
    let diff = m.u.iter().zip(&twin.u).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(diff <= 1e-13, "{diff}");
}
