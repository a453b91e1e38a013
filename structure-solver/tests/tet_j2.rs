//! J2 tets: a block of tets stretched uniaxially (lateral faces free) past yield, unloaded and
//! yielded in reverse. The deformation is homogeneous, so the second Piola-Kirchhoff stress
//! follows the 1D law in the Green strain exactly: `S = σy + E H/(E+H) (E11 - σy/E)` on
//! loading (`H` the plastic modulus of `material::j2`), slope `E` on unloading, reverse yield at
//! `-(σy + H εp)` (isotropic hardening); lateral strain `-ν E11ᵉ - ½ E11ᵖ`.

use structure_solver::assembly::{Curve, FeModel, Part};
use structure_solver::material::{Elastic, Material, J2};
use structure_solver::mesh::{Cell, CellKind, Mesh};
use structure_solver::statics::{load_steps, NewtonSettings};

/// Unit cube cut into 6 tets around its 0-6 diagonal.
fn cube() -> Mesh {
    let mut m = Mesh::default();
    for k in 0..2 {
        for j in 0..2 {
            for i in 0..2 {
                m.nodes.push([i as f64, j as f64, k as f64]);
            }
        }
    }
    let c = [0, 1, 3, 2, 4, 5, 7, 6]; // hexahedron corner order
    for t in [[0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6], [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6]] {
        m.cells.push(Cell { kind: CellKind::Tet4, nodes: t.iter().map(|&a| c[a]).collect() });
    }
    m
}

#[test]
fn uniaxial_stretch_hardens_unloads_and_yields_in_reverse() {
    let mesh = cube();
    let (e, nu, sy, h) = (200e3, 0.3, 250.0, 2000.0);
    let j2 = J2 { elastic: Elastic { e, nu, rho: 1.0 }, sigma_y: sy, h };
    let mut m = FeModel::new(&mesh, |_| Part::Solid(Material::J2(j2))).unwrap();
    let x1 = mesh.nodes_where(|p| p[0] == 1.0);
    m.fix(&mesh.nodes_where(|p| p[0] == 0.0), [true, false, false, false, false, false]);
    m.fix(&mesh.nodes_where(|p| p[1] == 0.0), [false, true, false, false, false, false]);
    m.fix(&mesh.nodes_where(|p| p[2] == 0.0), [false, false, true, false, false, false]);
    let corner = mesh.nearest_node([1.0, 1.0, 1.0]);
    // end displacement: 1% at t = 1, back to 0.5% at t = 2
    let curve = Curve::Table(vec![(0.0, 0.0), (1.0, 0.01), (2.0, 0.005)]);
    m.prescribe(&x1, 0, 1.0, curve.clone());
    let s = NewtonSettings { tol: 1e-10, max_iter: 20, max_cuts: 4 };
    let targets: Vec<f64> = (1..=20).map(|i| i as f64 / 10.0).collect();
    let (mut s_peak, mut e_peak, mut ep_peak) = (0.0, 0.0, 0.0);
    let (mut worst_s, mut worst_lat) = (0.0f64, 0.0f64);
    load_steps(&mut m, &targets, &s, |m, c| {
        let mut f = vec![0.0; m.n_dof()];
        m.internal_force(&mut f);
        let stretch = 1.0 + curve.at(c.t);
        let e11 = 0.5 * (stretch * stretch - 1.0);
        // P11 = F11 S11 on the unit reference face
        let s11 = x1.iter().map(|&n| f[6 * n]).sum::<f64>() / stretch;
        let (want, e11p) = if c.t <= 1.0 + 1e-12 {
            if e11 <= sy / e {
                (e * e11, 0.0)
            } else {
                let sv = sy + e * h / (e + h) * (e11 - sy / e);
                (s_peak, e_peak, ep_peak) = (sv, e11, e11 - sv / e);
                (sv, ep_peak)
            }
        } else {
            // elastic unloading, then reverse yield at -κ(α_peak) = -(σy + H εp_peak)
            let kappa = sy + h * ep_peak;
            let elastic = s_peak - e * (e_peak - e11);
            if elastic >= -kappa {
                (elastic, ep_peak)
            } else {
                let e_rev = e_peak - (s_peak + kappa) / e;
                let sv = -kappa - e * h / (e + h) * (e_rev - e11);
                (sv, e11 - sv / e)
            }
        };
        let mut u = vec![[0.0; 3]; m.n_nodes()];
        m.displacement(&mut u);
        let lat = 0.5 * ((1.0 + u[corner][1]).powi(2) - 1.0);
        let lat_want = -nu * (e11 - e11p) - 0.5 * e11p;
        worst_s = worst_s.max((s11 - want).abs() / sy);
        worst_lat = worst_lat.max((lat - lat_want).abs() / e11.abs());
        println!(
            "t {:.1}: E11 {e11:.5}, S11 {s11:.3} vs {want:.3}, E22 {lat:.6} vs {lat_want:.6}",
            c.t
        );
    })
    .unwrap();
    println!("worst stress error / σy {worst_s:.1e}, lateral strain error / E11 {worst_lat:.1e}");
    assert!(worst_s < 1e-6, "uniaxial stress error {worst_s:e}");
    assert!(worst_lat < 1e-6, "lateral strain error {worst_lat:e}");
}
