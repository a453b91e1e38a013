//! The one-point triangle in time (`elements::blt3`): the element's critical-step estimate
//! against its eigenvalues, the discrete period of a cantilever plate in its first mode
//! against `cos ΩΔt = 1 - ω²Δt²/2` of the stiffness eigenvalue (and that eigenvalue against
//! beam theory), and the Sze-Liu-Lo cantilever strip (2004, §3.1) on the 16x1 mesh split into
//! 32 triangles, run explicitly with mass-proportional damping to the static state at every
//! tabulated load level.

use nalgebra::{DMatrix, SymmetricEigen};
use structure_solver::elements::blt3::{Blt3, Blt3Settings};
use structure_solver::elements::RotaryInertia;
use structure_solver::material::{Elastic, J2};
use structure_solver::mesh::generate;

fn elastic(e: f64, nu: f64, rho: f64) -> J2 {
    J2 { elastic: Elastic { e, nu, rho }, sigma_y: f64::INFINITY, h: 0.0 }
}

fn triangles(mesh: &structure_solver::mesh::Mesh) -> Vec<[u32; 3]> {
    mesh.cells.iter().map(|c| [0, 1, 2].map(|k| c.nodes[k] as u32)).collect()
}

/// Linear stiffness at the unstressed configuration `x0` by central differences of the
/// internal force (each column from a fresh copy of the part).
fn stiffness(part: &Blt3, x0: &[[f64; 3]], eps: f64) -> DMatrix<f64> {
    let n = 6 * x0.len();
    let mut k = DMatrix::zeros(n, n);
    for j in 0..n {
        let mut col = vec![0.0; n];
        for sign in [1.0, -1.0] {
            let mut du = vec![0.0; n];
            du[j] = sign * eps;
            let mut x = x0.to_vec();
            if j % 6 < 3 {
                x[j / 6][j % 6] += sign * eps;
            }
            let mut f = vec![0.0; n];
            part.clone().internal_force(&x, &du, &mut f);
            for i in 0..n {
                col[i] += sign * f[i] / (2.0 * eps);
            }
        }
        k.set_column(j, &nalgebra::DVector::from_vec(col));
    }
    k
}

/// Eigenvalues and vectors of `M^-1/2 K M^-1/2` on the dofs `free` (`K` symmetrised).
fn modes(k: &DMatrix<f64>, m: &[f64], free: &[usize]) -> SymmetricEigen<f64, nalgebra::Dyn> {
    let s = DMatrix::from_fn(free.len(), free.len(), |a, b| {
        let (i, j) = (free[a], free[b]);
        0.5 * (k[(i, j)] + k[(j, i)]) / (m[i] * m[j]).sqrt()
    });
    s.symmetric_eigen()
}

#[test]
fn critical_step_estimate_bounds_the_element_eigenvalue() {
    let shapes: [[[f64; 3]; 3]; 3] = [
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 0.866, 0.0]],
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.3, 0.25, 0.0]],
    ];
    let mat = elastic(200e9, 0.3, 7800.0);
    let mut ratios = Vec::new();
    for (s, x0) in shapes.iter().enumerate() {
        for h in [0.01, 0.1] {
            for rotary in [RotaryInertia::Scaled, RotaryInertia::Physical] {
                let set = Blt3Settings { rotary, ..Blt3Settings::default() };
                let part = Blt3::new(vec![[0, 1, 2]], vec![h], mat, set).unwrap();
                let mut m = vec![0.0; 18];
                part.lumped_mass(x0, &mut m);
                let k = stiffness(&part, x0, 1e-7);
                // drilling rotations carry no stiffness: leave them out
                let free: Vec<usize> = (0..18).filter(|i| i % 6 != 5).collect();
                let w_max = modes(&k, &m, &free).eigenvalues.max().sqrt();
                let ratio = part.stable_dt(x0) / (2.0 / w_max);
                println!("shape {s}, h {h}, {rotary:?}: estimate / (2/ω_max) = {ratio:.3}");
                ratios.push(ratio);
            }
        }
    }
    assert!(ratios.iter().all(|&r| r <= 1.0), "estimate above the critical step: {ratios:?}");
    assert!(ratios.iter().all(|&r| r >= 0.7), "estimate needlessly small: {ratios:?}");
}

/// A free-dof explicit central-difference loop over a BLT3 part with isotropic nodal rotary
/// inertia (so `ω̇ = M/I`, no gyroscopic term) and mass-proportional damping `α M`.
struct Explicit {
    x: Vec<[f64; 3]>,
    v: Vec<f64>,
    m: Vec<f64>,
    free: Vec<bool>,
    f: Vec<f64>,
}

impl Explicit {
    /// Starts at `x0` displaced by `u0` (6 per node; rotations as increments), at rest.
    fn new(part: &mut Blt3, x0: &[[f64; 3]], u0: &[f64], free: Vec<bool>) -> Self {
        let n = 6 * x0.len();
        let mut m = vec![0.0; n];
        part.lumped_mass(x0, &mut m);
        let x: Vec<[f64; 3]> = x0
            .iter()
            .enumerate()
            .map(|(i, p)| std::array::from_fn(|a| p[a] + u0[6 * i + a]))
            .collect();
        let mut f = vec![0.0; n];
        part.internal_force(&x, u0, &mut f);
        part.commit();
        Explicit { x, v: vec![0.0; n], m, free, f }
    }

    /// One step of `dt` under `f_ext` with damping `alpha` (the first from rest takes half).
    fn step(&mut self, part: &mut Blt3, dt: f64, f_ext: &[f64], alpha: f64, first: bool) {
        let n = self.v.len();
        let mut du = vec![0.0; n];
        let h = if first { 0.5 * dt } else { dt };
        for i in 0..n {
            if !self.free[i] {
                continue;
            }
            let a = (f_ext[i] - self.f[i]) / self.m[i];
            self.v[i] = ((1.0 - 0.5 * alpha * dt) * self.v[i] + h * a) / (1.0 + 0.5 * alpha * dt);
            du[i] = dt * self.v[i];
        }
        for (p, d) in self.x.iter_mut().zip(du.chunks(6)) {
            for a in 0..3 {
                p[a] += d[a];
            }
        }
        self.f.fill(0.0);
        part.internal_force(&self.x, &du, &mut self.f);
        part.commit();
    }

    /// Largest out-of-balance force on the free dofs.
    fn residual(&self, f_ext: &[f64]) -> f64 {
        (0..self.f.len())
            .filter(|&i| self.free[i])
            .map(|i| (f_ext[i] - self.f[i]).abs())
            .fold(0.0, f64::max)
    }
}

#[test]
fn discrete_period_follows_the_stiffness_eigenvalue_and_beam_theory() {
    // ν = 0 so plate and beam bending stiffness coincide; physical rotary inertia.
    let (l, b, h) = (1.0, 0.1, 0.02);
    let mesh = generate::rectangle(l, b, 24, 2).to_triangles();
    let x0 = mesh.nodes.clone();
    let mat = elastic(200e9, 0.0, 7800.0);
    let set = Blt3Settings { rotary: RotaryInertia::Physical, ..Blt3Settings::default() };
    let mut part = Blt3::new(triangles(&mesh), vec![h; mesh.cells.len()], mat, set).unwrap();
    let n = 6 * x0.len();
    let free: Vec<bool> = (0..n).map(|i| x0[i / 6][0] > 1e-12 && i % 6 != 5).collect();
    let free_dofs: Vec<usize> = (0..n).filter(|&i| free[i]).collect();
    let mut m = vec![0.0; n];
    part.lumped_mass(&x0, &mut m);
    let k = stiffness(&part, &x0, 1e-9);
    let eig = modes(&k, &m, &free_dofs);
    // the first bending mode: the lowest eigenvalue
    let (j, &w2) = eig.eigenvalues.iter().enumerate().min_by(|a, b| a.1.total_cmp(b.1)).unwrap();
    let w = w2.sqrt();
    let inertia = b * h * h * h / 12.0;
    let w_beam = 1.875_104_f64.powi(2)
        * (mat.elastic.e * inertia / (mat.elastic.rho * b * h * l.powi(4))).sqrt();
    // start in that mode (M^-1/2 φ) at a tip deflection of 1e-6 L, at rest
    let tip = x0.iter().position(|p| p[0] == l && p[1] == 0.0).unwrap();
    let mut u0 = vec![0.0; n];
    for (a, &i) in free_dofs.iter().enumerate() {
        u0[i] = eig.eigenvectors[(a, j)] / m[i].sqrt();
    }
    let scale = 1e-6 * l / u0[6 * tip + 2];
    u0.iter_mut().for_each(|u| *u *= scale);
    let dt = 0.9 * part.stable_dt(&x0);
    let mut run = Explicit::new(&mut part, &x0, &u0, free);
    let zero = vec![0.0; n];
    let mut hist = vec![run.x[tip][2]];
    let steps = (2.5 * 2.0 * std::f64::consts::PI / w / dt) as usize;
    for s in 0..steps {
        run.step(&mut part, dt, &zero, 0.0, s == 0);
        hist.push(run.x[tip][2]);
    }
    // cos ΩΔt = (u_{n+1} + u_{n-1}) / (2 u_n), where |u_n| is above half the amplitude
    let (mut worst, mut mean, mut count) = (0.0f64, 0.0, 0);
    let expect = 1.0 - 0.5 * w2 * dt * dt;
    for i in 1..hist.len() - 1 {
        if hist[i].abs() > 0.5e-6 * l {
            let c = (hist[i + 1] + hist[i - 1]) / (2.0 * hist[i]);
            worst = worst.max(((1.0 - c) / (1.0 - expect) - 1.0).abs());
            mean += 1.0 - c;
            count += 1;
        }
    }
    let omega = (1.0 - mean / count as f64).acos() / dt;
    println!("cantilever plate, 96 triangles: ω (eigenvalue) {w:.4} rad/s vs beam theory {w_beam:.4} ({:+.2}%); dt {dt:.3e}, {steps} steps; measured Ω {omega:.4} vs (2/Δt) asin(ωΔt/2) {:.4}; worst relative error of 1 - cos ΩΔt {worst:.2e}", 100.0 * (w / w_beam - 1.0), 2.0 / dt * (w * dt / 2.0).asin());
    assert!(worst < 1e-5);
    assert!((w / w_beam - 1.0).abs() < 0.02);
}

/// Sze, Liu & Lo (2004, Finite Elem. Anal. Des. 40:1551), §3.1, as `tests/sze_cantilever.rs`
/// holds it: P/P_max, -u_tip, w_tip (S4R, 16x1).
const ROWS: &[(f64, [f64; 2])] = &[
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
fn sze_cantilever_on_32_triangles_reaches_the_published_static_states() {
    // L = 10, b = 1, h = 0.1, E = 1.2e6, ν = 0, P_max = 4 at the tip, clamped at x = 0;
    // the paper's 16x1 mesh, each quad split into two triangles; ρ = 1 (quasi-static).
    let mesh = generate::rectangle(10.0, 1.0, 16, 1).to_triangles();
    let x0 = mesh.nodes.clone();
    let mat = elastic(1.2e6, 0.0, 1.0);
    let mut part =
        Blt3::new(triangles(&mesh), vec![0.1; mesh.cells.len()], mat, Blt3Settings::default())
            .unwrap();
    let n = 6 * x0.len();
    let clamped = mesh.node_set("u0").unwrap().to_vec();
    let tip = mesh.node_set("u1").unwrap().to_vec();
    let free: Vec<bool> = (0..n).map(|i| !clamped.contains(&(i / 6))).collect();
    let dt = 0.9 * part.stable_dt(&x0);
    // damping near critical for the first bending mode of the unloaded strip
    let inertia = 1.0 * 0.1f64.powi(3) / 12.0;
    let w1 = 1.875_104_f64.powi(2) * (1.2e6 * inertia / (1.0 * 0.1 * 1e4)).sqrt();
    let alpha = 2.0 * w1;
    let mut run = Explicit::new(&mut part, &x0, &vec![0.0; n], free);
    let mut f_ext = vec![0.0; n];
    let (mut lf, mut first, mut steps) = (0.0, true, 0usize);
    let mut errors = Vec::new();
    println!("Sze cantilever, 32 BLT3 triangles, dt {dt:.3e}, α {alpha:.3}: P/Pmax, -u_tip, w_tip (computed / reference / relative error)");
    for &(target, reference) in ROWS {
        // ramp the load over one first-mode period, then hold until static
        let ramp = (2.0 * std::f64::consts::PI / w1 / dt) as usize;
        let mut k = 0usize;
        loop {
            let p = if k < ramp { lf + (target - lf) * k as f64 / ramp as f64 } else { target };
            for &t in &tip {
                f_ext[6 * t + 2] = 4.0 * p / tip.len() as f64;
            }
            run.step(&mut part, dt, &f_ext, alpha, first);
            first = false;
            k += 1;
            if k > ramp && k.is_multiple_of(200) && run.residual(&f_ext) < 1e-6 * 4.0 {
                break;
            }
            assert!(k < 400_000, "no static state at P/Pmax {target}");
        }
        steps += k;
        lf = target;
        let (mut u, mut w) = (0.0, 0.0);
        for &t in &tip {
            u -= (run.x[t][0] - x0[t][0]) / tip.len() as f64;
            w += (run.x[t][2] - x0[t][2]) / tip.len() as f64;
        }
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
    // the first rows' -u (0.026) has two significant digits: w everywhere, u from row 4
    let worst_w = errors.iter().map(|e| e[1].abs()).fold(0.0, f64::max);
    let worst_u = errors.iter().skip(3).map(|e| e[0].abs()).fold(0.0, f64::max);
    assert!(worst_w < 0.005, "w_tip off by {worst_w}");
    assert!(worst_u < 0.005, "u_tip off by {worst_u}");
}
