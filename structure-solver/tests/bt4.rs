//! The Belytschko-Lin-Tsay shell: membrane patch test, rigid rotation of a prestressed element
//! in 1000 explicit steps about a skew axis, the first bending frequency of a cantilever plate
//! in free vibration, and the plastic hinge moment at 5 and 8 thickness points.

use structure_solver::assembly::{FeModel, Part};
use structure_solver::elements::bt4::{Bt4, Bt4Settings};
use structure_solver::elements::{RotaryInertia, ShellSection};
use structure_solver::material::{Elastic, ThicknessRule, J2};
use structure_solver::mesh::{Cell, CellKind, Mesh};
use structure_solver::model::Model;
use structure_solver::time::{critical_dt, CentralDifference};

fn elastic(nu: f64) -> J2 {
    J2 { elastic: Elastic { e: 200e9, nu, rho: 7800.0 }, sigma_y: f64::INFINITY, h: 0.0 }
}

/// `nx` x `ny` quads on `[0, lx] x [0, ly]` in the z = 0 plane, interior nodes moved by
/// `distort` of the spacing.
fn plate(nx: usize, ny: usize, lx: f64, ly: f64, distort: f64) -> (Vec<[f64; 3]>, Vec<[u32; 4]>) {
    let mut x = Vec::new();
    for j in 0..=ny {
        for i in 0..=nx {
            let (mut px, mut py) = (lx * i as f64 / nx as f64, ly * j as f64 / ny as f64);
            if i > 0 && i < nx && j > 0 && j < ny {
                let s = ((i * 7 + j * 13) % 5) as f64 / 4.0 - 0.5;
                px += distort * s * lx / nx as f64;
                py -= distort * s * 0.7 * ly / ny as f64;
            }
            x.push([px, py, 0.0]);
        }
    }
    let id = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let conn = (0..ny)
        .flat_map(|j| {
            (0..nx).map(move |i| [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
        })
        .collect();
    (x, conn)
}

#[test]
fn membrane_patch_test_gives_constant_stress_and_no_interior_force() {
    let (x0, conn) = plate(3, 3, 1.0, 0.8, 0.3);
    let mat = elastic(0.3);
    let n_el = conn.len();
    let mut bt4 = Bt4::new(conn, vec![0.01; n_el], mat, Bt4Settings::default());
    // Linear displacement increment Δu = G X.
    let g = [[2e-6, 0.7e-6], [-0.4e-6, -1.1e-6]];
    let mut du = vec![0.0; 6 * x0.len()];
    let mut x1 = x0.clone();
    for (i, p) in x0.iter().enumerate() {
        for a in 0..2 {
            du[6 * i + a] = g[a][0] * p[0] + g[a][1] * p[1];
            x1[i][a] += du[6 * i + a];
        }
    }
    let mut f = vec![0.0; du.len()];
    bt4.internal_force(&x1, &du, &mut f);
    bt4.commit();
    // Strain in the mid geometry: L = G (I + G/2)^-1, Δε = sym(L).
    let m = [[1.0 + g[0][0] / 2.0, g[0][1] / 2.0], [g[1][0] / 2.0, 1.0 + g[1][1] / 2.0]];
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let inv = [[m[1][1] / det, -m[0][1] / det], [-m[1][0] / det, m[0][0] / det]];
    let l: Vec<Vec<f64>> = (0..2)
        .map(|a| (0..2).map(|b| g[a][0] * inv[0][b] + g[a][1] * inv[1][b]).collect())
        .collect();
    let eps = [l[0][0], l[1][1], l[0][1] + l[1][0]];
    let s_global = mat.elastic.stress_plane_stress(&eps);
    let mut worst: f64 = 0.0;
    for (e, c) in bt4.conn.clone().iter().enumerate() {
        // Stress is stored in the element frame, ê1 along side 1-2 of the mid geometry.
        let mid = |n: u32| {
            let n = n as usize;
            [x0[n][0] + 0.5 * du[6 * n], x0[n][1] + 0.5 * du[6 * n + 1]]
        };
        let (a, b) = (mid(c[0]), mid(c[1]));
        let th = (b[1] - a[1]).atan2(b[0] - a[0]);
        let (sn, cs) = th.sin_cos();
        let s_exact = [
            s_global[0] * cs * cs + s_global[1] * sn * sn + 2.0 * s_global[2] * sn * cs,
            s_global[0] * sn * sn + s_global[1] * cs * cs - 2.0 * s_global[2] * sn * cs,
            (s_global[1] - s_global[0]) * sn * cs + s_global[2] * (cs * cs - sn * sn),
        ];
        for p in 0..5 {
            let s = bt4.stress(e, p);
            for k in 0..3 {
                worst = worst.max((s[k] - s_exact[k]).abs() / s_exact[0].abs());
            }
            assert!(s[3].abs() + s[4].abs() < 1e-9 * s_exact[0].abs());
        }
    }
    let boundary_max = f.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let mut interior_max: f64 = 0.0;
    for j in 1..3 {
        for i in 1..3 {
            let n = j * 4 + i;
            for k in 0..6 {
                interior_max = interior_max.max(f[6 * n + k].abs());
            }
        }
    }
    println!("patch test: max stress error {worst:.2e} (relative), interior force {:.2e} of the largest boundary force", interior_max / boundary_max);
    assert!(worst < 1e-9);
    // Stress lives in each element's frame (ê1 along side 1-2), which turns by O(Δε) between
    // the mid geometry (strain) and the end geometry (forces) differently per element: the
    // interior balance holds to the size of the strain increment (2e-6), not to round-off.
    assert!(interior_max < 0.5e-6 * boundary_max);
}

/// Rotation matrix about unit axis `k` by angle `phi` (Rodrigues).
fn rotation(k: [f64; 3], phi: f64) -> [[f64; 3]; 3] {
    let (s, c) = phi.sin_cos();
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = (1.0 - c) * k[i] * k[j] + if i == j { c } else { 0.0 };
        }
    }
    r[0][1] -= s * k[2];
    r[0][2] += s * k[1];
    r[1][0] += s * k[2];
    r[1][2] -= s * k[0];
    r[2][0] -= s * k[1];
    r[2][1] += s * k[0];
    r
}

fn apply(r: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2])
}

#[test]
fn prestressed_element_rotated_rigidly_in_1000_steps_keeps_its_corotated_stress() {
    // A skew, non-square element in a skew plane.
    let r0 = rotation([0.48, -0.6, 0.64], 0.7);
    let x0: Vec<[f64; 3]> = [[0.0, 0.0, 0.0], [1.1, 0.1, 0.0], [1.0, 0.9, 0.0], [-0.1, 0.8, 0.0]]
        .iter()
        .map(|p| apply(&r0, *p))
        .collect();
    let mut bt4 = Bt4::new(vec![[0, 1, 2, 3]], vec![0.02], elastic(0.3), Bt4Settings::default());
    let prestress = |p: usize| [100e6 + 10e6 * p as f64, -50e6, 30e6 - 5e6 * p as f64, 0.0, 0.0];
    for p in 0..5 {
        bt4.set_stress(0, p, prestress(p));
    }
    let mut f0 = vec![0.0; 24];
    bt4.internal_force(&x0, &[0.0; 24], &mut f0);
    let axis = {
        let a: [f64; 3] = [0.3, 0.5, -0.8];
        let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
        a.map(|v| v / n)
    };
    let (steps, total) = (1000, 1.2);
    let mut x = x0.clone();
    let mut f = vec![0.0; 24];
    for k in 1..=steps {
        let r = rotation(axis, total * k as f64 / steps as f64);
        let mut du = vec![0.0; 24];
        let mut x1 = x.clone();
        for i in 0..4 {
            x1[i] = apply(&r, x0[i]);
            for a in 0..3 {
                du[6 * i + a] = x1[i][a] - x[i][a];
                du[6 * i + 3 + a] = axis[a] * total / steps as f64;
            }
        }
        f.fill(0.0);
        bt4.internal_force(&x1, &du, &mut f);
        bt4.commit();
        x = x1;
    }
    let (mut ds, mut shear): (f64, f64) = (0.0, 0.0);
    for p in 0..5 {
        let s = bt4.stress(0, p);
        for k in 0..3 {
            ds = ds.max((s[k] - prestress(p)[k]).abs() / 100e6);
        }
        shear = shear.max(s[3].abs().max(s[4].abs()) / 100e6);
    }
    // The nodal forces rotate with the element.
    let r = rotation(axis, total);
    let mut df: f64 = 0.0;
    let fmax = f0.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    for i in 0..4 {
        for (off, _) in [(0, "force"), (3, "moment")] {
            let rf = apply(&r, [f0[6 * i + off], f0[6 * i + off + 1], f0[6 * i + off + 2]]);
            for a in 0..3 {
                df = df.max((f[6 * i + off + a] - rf[a]).abs() / fmax);
            }
        }
    }
    println!("rigid rotation 1.2 rad in 1000 steps: in-plane stress change {ds:.2e}, transverse shear {shear:.2e} (of 100 MPa), nodal forces vs rotated {df:.2e}");
    assert!(ds < 1e-9);
    assert!(shear < 1e-6);
    assert!(df < 1e-9);
}

/// Period of the first zero crossings of a sampled signal.
fn period(t: &[f64], u: &[f64]) -> f64 {
    let mut crossings = Vec::new();
    for i in 1..u.len() {
        if u[i - 1] < 0.0 && u[i] >= 0.0 {
            crossings.push(t[i - 1] + (t[i] - t[i - 1]) * (-u[i - 1]) / (u[i] - u[i - 1]));
        }
    }
    assert!(crossings.len() >= 3, "not enough oscillations");
    (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64
}

#[test]
fn cantilever_plate_first_bending_frequency_matches_beam_theory() {
    // ν = 0 so plate and beam bending stiffness coincide; physical rotary inertia.
    let (l, b, h) = (1.0, 0.1, 0.02);
    let (nx, ny) = (24, 2);
    let (x0, conn) = plate(nx, ny, l, b, 0.0);
    let mat = elastic(0.0);
    let cells = conn
        .iter()
        .map(|c| Cell { kind: CellKind::Quad4, nodes: c.iter().map(|&n| n as usize).collect() })
        .collect();
    let mesh = Mesh { nodes: x0.clone(), cells, ..Mesh::default() };
    let e = mat.elastic;
    let section = ShellSection { e: e.e, nu: e.nu, rho: e.rho, h };
    let mut model = FeModel::new(&mesh, |_| Part::Bt4(section, None)).unwrap();
    model.set_rotary_inertia(RotaryInertia::Physical);
    model.fix(&mesh.nodes_where(|p| p[0] == 0.0), [true; 6]);
    let est = critical_dt(&mut model, 0.0, 200, 1e-9);
    let dt = 0.8 * est.element.min(est.power);
    // Initial velocity in the shape of the static tip-load deflection.
    let mut v0 = vec![0.0; 6 * x0.len()];
    for (i, p) in x0.iter().enumerate() {
        let s = p[0] / l;
        v0[6 * i + 2] = 0.01 * s * s * (3.0 - s);
        v0[6 * i + 4] = -0.01 * s * (6.0 - 3.0 * s) / (2.0 * l);
    }
    for (i, c) in model.constrained().to_vec().iter().enumerate() {
        if *c {
            v0[i] = 0.0;
        }
    }
    let mut cd = CentralDifference::new(&mut model, 0.0, v0, None);
    let inertia = b * h * h * h / 12.0;
    let f_theory = 1.875_104_f64.powi(2) / (2.0 * std::f64::consts::PI)
        * (mat.elastic.e * inertia / (mat.elastic.rho * b * h * l.powi(4))).sqrt();
    let t_end = 3.2 / f_theory;
    let tip = x0.iter().position(|p| p[0] == l && p[1] == 0.0).unwrap();
    let (mut ts, mut us) = (Vec::new(), Vec::new());
    let mut disp = vec![[0.0; 3]; x0.len()];
    while cd.state.t < t_end {
        cd.step(&mut model, dt, None);
        model.displacement(&mut disp);
        ts.push(cd.state.t);
        us.push(disp[tip][2]);
    }
    let f = 1.0 / period(&ts, &us);
    println!("cantilever plate: dt {dt:.3e} (element {:.3e}, power {:.3e}), {} steps, f1 {f:.4} Hz vs beam theory {f_theory:.4} Hz ({:+.3}%)", est.element, est.power, ts.len(), 100.0 * (f / f_theory - 1.0));
    assert!((f / f_theory - 1.0).abs() < 0.01);
}

/// Pure bending of one element by nodal rotation increments (`κ_xx` driven, `κ_yy` and
/// `ε_yy` left free through `M_yy = N_yy = 0`): the moment saturates at `Σ w_i |ζ_i| σy b h²/4`.
fn plastic_hinge_moment(rule: ThicknessRule) -> (f64, f64) {
    let mat = J2 { elastic: Elastic { e: 200e9, nu: 0.3, rho: 7800.0 }, sigma_y: 250e6, h: 0.0 };
    let (lx, b, h) = (0.1, 0.05, 0.01);
    let x0 = [[0.0, 0.0, 0.0], [lx, 0.0, 0.0], [lx, b, 0.0], [0.0, b, 0.0]];
    let np = rule.len();
    let rule_w = rule.clone();
    let mut bt4 =
        Bt4::new(vec![[0, 1, 2, 3]], vec![h], mat, Bt4Settings { rule, ..Bt4Settings::default() });
    let kappa_y = 2.0 * mat.sigma_y / (mat.elastic.e * h);
    let steps = 400;
    let dk = 20.0 * kappa_y / steps as f64;
    // Resultants per unit width from the stored stresses (for the free-direction conditions).
    let resultants = |bt4: &Bt4| {
        let (mut n, mut m) = (0.0, 0.0);
        for p in 0..np {
            let s = bt4.stress(0, p)[1];
            n += rule_w.weights[p] * s * h / 2.0;
            m += rule_w.weights[p] * rule_w.points[p] * s * h * h / 4.0;
        }
        (n, m)
    };
    let (mut f, mut moment) = (vec![0.0; 24], 0.0);
    // Increment of the free membrane strain and curvature, from the previous step.
    let (mut eyy, mut kyy) = (0.0, -0.3 * dk);
    for _ in 0..steps {
        // Newton on (N_yy, M_yy) = 0 with the elastic plate compliance as the Jacobian.
        for _ in 0..30 {
            let mut du = vec![0.0; 24];
            for (i, p) in x0.iter().enumerate() {
                du[6 * i + 4] = dk * (p[0] - lx / 2.0); // θ_y: κ_xx = Σ b_x θ_y
                du[6 * i + 3] = -kyy * (p[1] - b / 2.0); // θ_x: κ_yy = -Σ b_y θ_x
                du[6 * i + 1] = eyy * (p[1] - b / 2.0); // u_y: ε_yy
            }
            let x1: Vec<[f64; 3]> =
                x0.iter().enumerate().map(|(i, p)| [p[0], p[1] + du[6 * i + 1], p[2]]).collect();
            f.fill(0.0);
            bt4.internal_force(&x1, &du, &mut f);
            // The trial state is what `commit` would accept; read it by committing a copy.
            let mut probe = bt4.clone();
            probe.commit();
            let (n, m) = resultants(&probe);
            if n.abs() < 1e-6 * mat.sigma_y * h && m.abs() < 1e-6 * mat.sigma_y * h * h {
                bt4 = probe;
                break;
            }
            let d = mat.elastic.e / (1.0 - 0.09);
            eyy -= n / (d * h);
            kyy -= m / (d * h * h * h / 12.0);
        }
        // Moment on the section: sum of m_y at the nodes of the edge x = lx.
        moment = f[6 + 4] + f[12 + 4];
    }
    let factor = rule_w.plastic_moment_factor();
    (moment, factor * mat.sigma_y * b * h * h / 4.0)
}

#[test]
fn plastic_hinge_moment_matches_the_thickness_rule_and_the_fully_plastic_moment() {
    let (m5, ref5) = plastic_hinge_moment(ThicknessRule::gauss(5));
    let (m8, ref8) = plastic_hinge_moment(ThicknessRule::gauss(8));
    let mp = 250e6 * 0.05 * 0.01 * 0.01 / 4.0;
    println!("plastic hinge: 5 points M = {m5:.4} N m vs Σ w|ζ| σy b h²/4 = {ref5:.4} ({:+.3}%), M/M_p = {:.4}", 100.0 * (m5 / ref5 - 1.0), m5 / mp);
    println!(
        "plastic hinge: 8 points M = {m8:.4} N m vs {ref8:.4} ({:+.3}%), M/M_p = {:.4}",
        100.0 * (m8 / ref8 - 1.0),
        m8 / mp
    );
    assert!((m5 / ref5 - 1.0).abs() < 0.01);
    assert!((m8 / ref8 - 1.0).abs() < 0.01);
    assert!((m8 / mp - 1.0).abs() < 0.02);
}
