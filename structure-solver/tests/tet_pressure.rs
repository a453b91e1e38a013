//! Pressure on the boundary faces of tets (`FeModel::face_pressure`, faces from
//! `wet::tet_boundary`): a uniform pressure on a closed body of tets has zero resultant and
//! zero moment to round-off, and a pressure on one face of a block gives `p A` into the
//! block, through the same reduction as every load.

use nalgebra::Vector3;
use structure_solver::assembly::{Curve, FeModel, Part};
use structure_solver::material::{Elastic, Material};
use structure_solver::mesh::generate;
use structure_solver::model::Model;
use structure_solver::wet::tet_boundary;

const STEEL: Material = Material::Elastic(Elastic { e: 2e11, nu: 0.3, rho: 7800.0 });

/// Resultant force and moment about the origin of a nodal force vector.
fn resultant(m: &FeModel, f: &[f64]) -> (Vector3<f64>, Vector3<f64>) {
    let (mut r, mut q) = (Vector3::zeros(), Vector3::zeros());
    for (n, x) in m.positions().iter().enumerate() {
        let fn_ = Vector3::new(f[6 * n], f[6 * n + 1], f[6 * n + 2]);
        r += fn_;
        q += x.cross(&fn_);
    }
    (r, q)
}

#[test]
fn uniform_pressure_on_a_closed_tet_body_has_no_resultant_or_moment() {
    let mut mesh = generate::block([1.0, 2.0, 0.5], [3, 4, 2]);
    // a skewed, off-origin body so that no symmetry hides an error
    for p in &mut mesh.nodes {
        *p = [p[0] + 0.3 * p[1] + 1.0, p[1] - 0.2 * p[2] + 2.0, p[2] + 0.1 * p[0] * p[1] - 3.0];
    }
    let all = mesh.cell_set("all").unwrap().to_vec();
    let faces = tet_boundary(&mesh, &all);
    assert_eq!(faces.len(), 2 * 2 * (3 * 4 + 4 * 2 + 3 * 2), "boundary triangles");
    let mut m = FeModel::new(&mesh, |_| Part::Solid(STEEL)).unwrap();
    let p = 1e5;
    m.face_pressure(&faces, p, Curve::Constant).unwrap();
    let mut f = vec![0.0; m.n_dof()];
    m.external_force(0.0, &mut f);
    let (r, q) = resultant(&m, &f);
    let scale = p * faces.len() as f64;
    println!(
        "closed tet body: |F| {:.2e}, |M| {:.2e} (scale p·faces {scale:.1e})",
        r.norm(),
        q.norm()
    );
    assert!(r.norm() < 1e-12 * scale, "resultant {r:?}");
    assert!(q.norm() < 1e-11 * scale, "moment {q:?}");
    // pressure pushes inwards: the nodes of the top face are pushed down
    let top = mesh.node_set("z1").unwrap();
    let fz: f64 = top.iter().map(|&n| f[6 * n + 2]).sum();
    assert!(fz < 0.0, "top face pushed into the body: {fz}");
}

#[test]
fn pressure_on_one_face_of_a_block_gives_p_times_area() {
    let (lx, ly, lz) = (1.5, 0.8, 0.4);
    let mesh = generate::block([lx, ly, lz], [3, 2, 2]);
    let all = mesh.cell_set("all").unwrap().to_vec();
    let mut top = vec![false; mesh.nodes.len()];
    mesh.node_set("z1").unwrap().iter().for_each(|&n| top[n] = true);
    let faces: Vec<[usize; 3]> =
        tet_boundary(&mesh, &all).into_iter().filter(|f| f.iter().all(|&n| top[n])).collect();
    assert_eq!(faces.len(), 2 * 3 * 2);
    let mut m = FeModel::new(&mesh, |_| Part::Solid(STEEL)).unwrap();
    let p = 2.5e4;
    m.face_pressure(&faces, p, Curve::Linear).unwrap();
    let mut f = vec![0.0; m.n_dof()];
    m.external_force(0.5, &mut f);
    let (r, _) = resultant(&m, &f);
    let expected = Vector3::new(0.0, 0.0, -0.5 * p * lx * ly);
    let err = (r - expected).norm() / expected.norm();
    println!("block top face: F {r:?}, p·A {expected:?}, rel. error {err:.2e}");
    assert!(err < 1e-14, "resultant {r:?} vs {expected:?}");
    assert!(m.face_pressure(&[[0, 1, 10_000]], p, Curve::Constant).is_err());
}
