//! The one-point triangle (`elements::blt3`): membrane and bending patch tests on a distorted
//! mesh (constant strain and constant curvature reproduced exactly, interior nodes in
//! equilibrium), rigid motions (translation; a 1.2 rad rotation about a skew axis in one
//! increment and in 1000) of a prestressed element leave its corotated stress unchanged and
//! rotate its forces, and the plastic hinge moment at 5 and 8 thickness points.

use structure_solver::elements::blt3::{frame, Blt3, Blt3Error, Blt3Settings};
use structure_solver::material::{Elastic, ThicknessRule, J2};
use structure_solver::mesh::generate;

fn elastic(nu: f64) -> J2 {
    J2 { elastic: Elastic { e: 200e9, nu, rho: 7800.0 }, sigma_y: f64::INFINITY, h: 0.0 }
}

/// A 3x3 rectangle split into 18 triangles, interior nodes moved off the grid.
fn patch() -> (Vec<[f64; 3]>, Vec<[u32; 3]>, Vec<bool>) {
    let mesh = generate::rectangle(1.0, 0.8, 3, 3).to_triangles();
    let mut x = mesh.nodes.clone();
    let boundary: Vec<bool> = x
        .iter()
        .map(|p| {
            p[0].abs() < 1e-12
                || (p[0] - 1.0).abs() < 1e-12
                || p[1].abs() < 1e-12
                || (p[1] - 0.8).abs() < 1e-12
        })
        .collect();
    for (i, p) in x.iter_mut().enumerate() {
        if !boundary[i] {
            let s = ((i * 7) % 5) as f64 / 4.0 - 0.5;
            p[0] += 0.3 * s / 3.0;
            p[1] -= 0.2 * s / 3.0;
        }
    }
    let conn = mesh.cells.iter().map(|c| [0, 1, 2].map(|k| c.nodes[k] as u32)).collect();
    (x, conn, boundary)
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

/// Angle of side 1-2 of element `c` at positions `x`.
fn side_angle(x: &[[f64; 3]], c: &[u32; 3]) -> f64 {
    let (a, b) = (x[c[0] as usize], x[c[1] as usize]);
    (b[1] - a[1]).atan2(b[0] - a[0])
}

/// Largest interior nodal force relative to the largest force.
fn interior_residual(f: &[f64], boundary: &[bool], dofs: &[usize]) -> f64 {
    let scale = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut worst = 0.0f64;
    for (n, b) in boundary.iter().enumerate() {
        if !b {
            for &k in dofs {
                worst = worst.max(f[6 * n + k].abs());
            }
        }
    }
    worst / scale
}

#[test]
fn membrane_patch_test_gives_constant_stress_and_no_interior_force() {
    let (x0, conn, boundary) = patch();
    let mat = elastic(0.3);
    let ne = conn.len();
    let mut part = Blt3::new(conn.clone(), vec![0.01; ne], mat, Blt3Settings::default()).unwrap();
    // Linear displacement increment Δu = G X.
    let g = [[2e-6, 0.7e-6], [-0.4e-6, -1.1e-6]];
    let mut du = vec![0.0; 6 * x0.len()];
    let mut x1 = x0.clone();
    let mut xm = x0.clone();
    for (i, p) in x0.iter().enumerate() {
        for a in 0..2 {
            du[6 * i + a] = g[a][0] * p[0] + g[a][1] * p[1];
            x1[i][a] += du[6 * i + a];
            xm[i][a] += 0.5 * du[6 * i + a];
        }
    }
    let mut f = vec![0.0; du.len()];
    part.internal_force(&x1, &du, &mut f);
    part.commit();
    // Strain in the mid geometry: L = G (I + G/2)⁻¹, Δε = sym(L).
    let m = [[1.0 + g[0][0] / 2.0, g[0][1] / 2.0], [g[1][0] / 2.0, 1.0 + g[1][1] / 2.0]];
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let inv = [[m[1][1] / det, -m[0][1] / det], [-m[1][0] / det, m[0][0] / det]];
    let l = |a: usize, b: usize| g[a][0] * inv[0][b] + g[a][1] * inv[1][b];
    let eps = [l(0, 0), l(1, 1), l(0, 1) + l(1, 0)];
    let s_global = mat.elastic.stress_plane_stress(&eps);
    let mut worst = 0.0f64;
    for (e, c) in conn.iter().enumerate() {
        let s_exact = rotate_stress(s_global, side_angle(&xm, c));
        for p in 0..part.settings.rule.len() {
            let s = part.stress(e, p);
            for k in 0..3 {
                worst = worst.max((s[k] - s_exact[k]).abs() / s_global[0].abs());
            }
        }
    }
    let res = interior_residual(&f, &boundary, &[0, 1, 2, 3, 4, 5]);
    println!("membrane patch: stress error {worst:.2e}, interior force {res:.2e} of the largest");
    assert!(worst < 1e-9);
    // Stress lives in each element's frame (ê1 along side 1-2), which turns by O(Δε) between
    // the mid geometry (strain) and the end geometry (forces) differently per element (as in
    // `bt4`): the interior balance holds to the size of the strain increment (2e-6).
    assert!(res < 0.5e-6);
}

#[test]
fn bending_patch_test_gives_constant_curvature_and_no_interior_force() {
    let (x0, conn, boundary) = patch();
    let mat = elastic(0.3);
    let (ne, h) = (conn.len(), 0.01);
    let mut part = Blt3::new(conn.clone(), vec![h; ne], mat, Blt3Settings::default()).unwrap();
    // Kirchhoff field w = s (a x² + b y² + c x y)/2, θy = -w,x, θx = w,y: κ = -s (a, b, c);
    // small, since the field's own membrane strain w,x²/2 ~ s² stands against s h/2
    let (a, b, c, s) = (1.0, -0.6, 0.8, 1e-10);
    let mut du = vec![0.0; 6 * x0.len()];
    let mut x1 = x0.clone();
    for (i, p) in x0.iter().enumerate() {
        let (x, y) = (p[0], p[1]);
        du[6 * i + 2] = s * (a * x * x + b * y * y + c * x * y) / 2.0;
        du[6 * i + 4] = -s * (a * x + c * y / 2.0);
        du[6 * i + 3] = s * (b * y + c * x / 2.0);
        x1[i][2] += du[6 * i + 2];
    }
    let mut f = vec![0.0; du.len()];
    part.internal_force(&x1, &du, &mut f);
    part.commit();
    let kappa = [-s * a, -s * b, -s * c];
    let rule = part.settings.rule.clone();
    let (mut worst, mut shear) = (0.0f64, 0.0f64);
    let scale = mat.elastic.stress_plane_stress(&kappa)[0].abs() * h / 2.0;
    for (e, cn) in conn.iter().enumerate() {
        let k_local = rotate_stress([kappa[0], kappa[1], kappa[2] / 2.0], side_angle(&x0, cn));
        let k_local = [k_local[0], k_local[1], 2.0 * k_local[2]];
        let s_unit = mat.elastic.stress_plane_stress(&k_local);
        for (p, &zeta) in rule.points.iter().enumerate() {
            let z = zeta * h / 2.0;
            let st = part.stress(e, p);
            for k in 0..3 {
                worst = worst.max((st[k] - z * s_unit[k]).abs() / scale);
            }
        }
        // shear resultants against the bending moment's scale M / L (L = 1)
        let q = part.shear(e);
        shear = shear.max(q.iter().fold(0.0f64, |m, v| m.max(v.abs())) / (scale * h * h / 6.0));
    }
    let res = interior_residual(&f, &boundary, &[2, 3, 4]);
    println!("bending patch: curvature stress error {worst:.2e}, shear {shear:.2e}, interior force {res:.2e} of the largest");
    assert!(worst < 1e-6);
    assert!(shear < 1e-6);
    assert!(res < 1e-6);
}

/// Rotation matrix of angle `phi` about unit axis `k` (Rodrigues).
fn rotation(k: [f64; 3], phi: f64) -> [[f64; 3]; 3] {
    let (s, c) = phi.sin_cos();
    let kx = [[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]];
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let kk: f64 = (0..3).map(|m| kx[i][m] * kx[m][j]).sum();
            r[i][j] = f64::from(u8::from(i == j)) + s * kx[i][j] + (1.0 - c) * kk;
        }
    }
    r
}

fn apply(r: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| (0..3).map(|j| r[i][j] * v[j]).sum())
}

/// A skew triangle prestressed at every thickness point, its forces at rest.
fn prestressed() -> (Blt3, Vec<[f64; 3]>, Vec<f64>) {
    let x0 = vec![[0.1, 0.0, 0.05], [1.2, 0.3, -0.1], [0.4, 0.9, 0.2]];
    let mut part =
        Blt3::new(vec![[0, 1, 2]], vec![0.02], elastic(0.3), Blt3Settings::default()).unwrap();
    for p in 0..part.settings.rule.len() {
        let z = part.settings.rule.points[p];
        part.set_stress(0, p, [100e6 + 30e6 * z, -40e6, 25e6 - 10e6 * z]);
    }
    let mut f0 = vec![0.0; 18];
    part.clone().internal_force(&x0, &[0.0; 18], &mut f0);
    (part, x0, f0)
}

/// Rotates `part` rigidly about the centroid by `phi` about `k` in `steps` increments; returns
/// the largest stress change (relative to 100 MPa) and force error (relative to `|f0|`).
fn rigid_rotation(steps: usize, k: [f64; 3], phi: f64) -> (f64, f64) {
    let (mut part, x0, f0) = prestressed();
    let s0: Vec<[f64; 3]> = (0..part.settings.rule.len()).map(|p| part.stress(0, p)).collect();
    let c: [f64; 3] = std::array::from_fn(|a| (x0[0][a] + x0[1][a] + x0[2][a]) / 3.0);
    let mut x = x0.clone();
    let mut f = vec![0.0; 18];
    for n in 1..=steps {
        let r = rotation(k, phi * n as f64 / steps as f64);
        let mut du = [0.0; 18];
        let mut xn = x.clone();
        for i in 0..3 {
            let rel: [f64; 3] = std::array::from_fn(|a| x0[i][a] - c[a]);
            let p = apply(&r, rel);
            for a in 0..3 {
                xn[i][a] = c[a] + p[a];
                du[6 * i + a] = xn[i][a] - x[i][a];
                du[6 * i + 3 + a] = k[a] * phi / steps as f64;
            }
        }
        f.fill(0.0);
        part.internal_force(&xn, &du, &mut f);
        part.commit();
        x = xn;
    }
    let ds = (0..s0.len())
        .flat_map(|p| (0..3).map(move |k| (p, k)))
        .map(|(p, kk)| (part.stress(0, p)[kk] - s0[p][kk]).abs() / 100e6)
        .fold(0.0f64, f64::max);
    let r = rotation(k, phi);
    let scale = f0.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut df = 0.0f64;
    for i in 0..3 {
        for o in [0, 3] {
            let want = apply(&r, [f0[6 * i + o], f0[6 * i + o + 1], f0[6 * i + o + 2]]);
            for a in 0..3 {
                df = df.max((f[6 * i + o + a] - want[a]).abs() / scale);
            }
        }
    }
    (ds, df)
}

#[test]
fn rigid_motions_leave_the_corotated_stress_unchanged_and_rotate_the_forces() {
    // translation
    let (mut part, x0, f0) = prestressed();
    let t = [0.3, -1.1, 0.7];
    let x1: Vec<[f64; 3]> = x0.iter().map(|p| std::array::from_fn(|a| p[a] + t[a])).collect();
    let mut du = [0.0; 18];
    for i in 0..3 {
        du[6 * i..6 * i + 3].copy_from_slice(&t);
    }
    let mut f = vec![0.0; 18];
    part.internal_force(&x1, &du, &mut f);
    let scale = f0.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let dt = f.iter().zip(&f0).fold(0.0f64, |m, (a, b)| m.max((a - b).abs())) / scale;
    // rotations about a skew axis
    let n = (1.0f64 + 4.0 + 9.0).sqrt();
    let k = [1.0 / n, -2.0 / n, 3.0 / n];
    let (ds1, df1) = rigid_rotation(1, k, 1.2);
    let (ds2, df2) = rigid_rotation(1000, k, 1.2);
    println!("rigid translation: force change {dt:.2e}; rotation 1.2 rad in 1 step: stress change {ds1:.2e}, force vs rotated {df1:.2e}; in 1000 steps: {ds2:.2e}, {df2:.2e}");
    assert!(dt < 1e-12);
    assert!(ds1 < 1e-12 && df1 < 1e-12);
    assert!(ds2 < 1e-9 && df2 < 1e-9);
}

/// Pure bending of one triangle by Kirchhoff increments (`κ_xx` driven, `κ_yy` and
/// `ε_yy` left free through `M_yy = N_yy = 0`); the moment per unit width is read from the
/// nodal moments by virtual work, `m = Σ_i m_yi (x_i - x_c) / A`, and saturates at
/// `Σ wᵢ|ζᵢ| σy h²/4`.
fn plastic_hinge_moment(rule: ThicknessRule) -> (f64, f64) {
    let mat = J2 { elastic: Elastic { e: 200e9, nu: 0.3, rho: 7800.0 }, sigma_y: 250e6, h: 0.0 };
    let h = 0.01;
    // side 1-2 along x: the element frame is the global one; small, so the Kirchhoff
    // increment's own membrane strain (w,x²/2 of one step) stays below 1e-3 of the yield strain
    let x0 = [[0.0, 0.0, 0.0], [0.01, 0.0, 0.0], [0.003, 0.006, 0.0]];
    let (np, rule_w) = (rule.len(), rule.clone());
    let mut part =
        Blt3::new(vec![[0, 1, 2]], vec![h], mat, Blt3Settings { rule, ..Blt3Settings::default() })
            .unwrap();
    let area = frame(&x0).area;
    let xc: [f64; 3] = std::array::from_fn(|a| (x0[0][a] + x0[1][a] + x0[2][a]) / 3.0);
    let kappa_y = 2.0 * mat.sigma_y / (mat.elastic.e * h);
    let steps = 400;
    let dk = 20.0 * kappa_y / steps as f64;
    let resultants = |p: &Blt3| {
        let (mut n, mut m) = (0.0, 0.0);
        for k in 0..np {
            let s = p.stress(0, k)[1];
            n += rule_w.weights[k] * s * h / 2.0;
            m += rule_w.weights[k] * rule_w.points[k] * s * h * h / 4.0;
        }
        (n, m)
    };
    let (mut f, mut moment) = (vec![0.0; 18], 0.0);
    let (mut eyy, mut kyy) = (0.0, -0.3 * dk);
    for _ in 0..steps {
        for _ in 0..30 {
            let mut du = vec![0.0; 18];
            // Kirchhoff increment (θy = -w,x, θx = w,y): no transverse shear
            for (i, p) in x0.iter().enumerate() {
                let (x, y) = (p[0] - xc[0], p[1] - xc[1]);
                du[6 * i + 4] = dk * x;
                du[6 * i + 3] = -kyy * y;
                du[6 * i + 2] = -(dk * x * x + kyy * y * y) / 2.0;
                du[6 * i + 1] = eyy * y;
            }
            // each step starts from the flat triangle (the hinge is geometrically linear)
            let x1: Vec<[f64; 3]> = x0
                .iter()
                .enumerate()
                .map(|(i, p)| std::array::from_fn(|a| p[a] + du[6 * i + a]))
                .collect();
            f.fill(0.0);
            let mut probe = part.clone();
            probe.internal_force(&x1, &du, &mut f);
            probe.commit();
            let (n, m) = resultants(&probe);
            if n.abs() < 1e-6 * mat.sigma_y * h && m.abs() < 1e-6 * mat.sigma_y * h * h {
                part = probe;
                break;
            }
            let d = mat.elastic.e / (1.0 - 0.09);
            eyy -= n / (d * h);
            kyy -= m / (d * h * h * h / 12.0);
        }
        moment = (0..3).map(|i| f[6 * i + 4] * (x0[i][0] - xc[0])).sum::<f64>() / area;
    }
    (moment, rule_w.plastic_moment_factor() * mat.sigma_y * h * h / 4.0)
}

#[test]
fn plastic_hinge_moment_matches_the_thickness_rule_and_the_fully_plastic_moment() {
    let (m5, ref5) = plastic_hinge_moment(ThicknessRule::gauss(5));
    let (m8, ref8) = plastic_hinge_moment(ThicknessRule::gauss(8));
    let mp = 250e6 * 0.01 * 0.01 / 4.0;
    println!("triangle hinge: 5 points m = {m5:.4} N vs Σ w|ζ| σy h²/4 = {ref5:.4} ({:+.3}%), m/m_p = {:.4}; 8 points m = {m8:.4} vs {ref8:.4} ({:+.3}%), m/m_p = {:.4}", 100.0 * (m5 / ref5 - 1.0), m5 / mp, 100.0 * (m8 / ref8 - 1.0), m8 / mp);
    assert!((m5 / ref5 - 1.0).abs() < 0.01);
    assert!((m8 / ref8 - 1.0).abs() < 0.01);
    assert!((m8 / mp - 1.0).abs() < 0.02);
    assert!(m5 / mp < 0.96, "5 points stay below the fully plastic moment");
}

#[test]
fn bad_thickness_is_an_error_naming_the_element() {
    let e = Blt3::new(vec![[0, 1, 2]; 2], vec![0.01, -1.0], elastic(0.3), Blt3Settings::default())
        .unwrap_err();
    assert_eq!(e, Blt3Error::BadThickness { element: 1, h: -1.0 });
    assert!(e.to_string().contains("element 1"));
    let e = Blt3::new(vec![[0, 1, 2]], vec![], elastic(0.3), Blt3Settings::default()).unwrap_err();
    assert!(matches!(e, Blt3Error::Thickness { conn: 1, thickness: 0 }));
}
