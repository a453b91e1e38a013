//! The initial level set (thesis §3.3.2: `φ` is initialised by the signed distance to the initial
//! interface), from the case's regions.
//!
//! One region against the background, a half space or a sphere: its exact signed distance
//! (positive inside, zero on the surface, which counts as inside). Otherwise (boxes, cylinders,
//! several regions in order): the interface points are found on every edge whose ends hold
//! different fluids, by bisecting the fluid of the initial condition along the edge to round-off,
//! and each node takes its distance to them by the closest-point transform of [`super::reinit`],
//! signed by its fluid. Either way the sign of `φ` gives exactly the initial materials.

use super::reinit::{distance_to_interface, Seed};
use super::LevelSet;
use crate::initial::InitialCondition;
use crate::mesh::geometry::{add, dot, norm, scale, sub};
use crate::mesh::Mesh;
use crate::state::MaterialId;
use interface_protocol::case::Region;

/// Bisections of an edge for its interface point (to round-off of the edge length).
const BISECTIONS: usize = 60;

/// The signed distance `φ` of every node to the interface of `ic` between `materials[0]`
/// (`φ < 0`) and `materials[1]` (`φ >= 0`), with `material` the nodes' initial materials.
pub fn signed_distance(
    mesh: &Mesh,
    ls: &LevelSet,
    ic: &InitialCondition,
    material: &[MaterialId],
) -> Vec<f64> {
    let positive = ls.materials[1];
    if let [(region, fill)] = ic.regions[..] {
        if ic.background.material != fill.material {
            let sign = if fill.material == positive { 1.0 } else { -1.0 };
            let exact = match region {
                Region::HalfSpace { point, normal } => {
                    let n = scale(normal, 1.0 / norm(normal));
                    Some(Box::new(move |x: [f64; 3]| dot(sub(x, point), n))
                        as Box<dyn Fn([f64; 3]) -> f64>)
                }
                Region::Sphere { center, radius } => {
                    Some(Box::new(move |x: [f64; 3]| radius - norm(sub(x, center)))
                        as Box<dyn Fn([f64; 3]) -> f64>)
                }
                _ => None,
            };
            if let Some(d) = exact {
                return mesh
                    .coords
                    .iter()
                    .zip(material)
                    .map(|(&x, &m)| signed(sign * d(x), m == positive))
                    .collect();
            }
        }
    }
    let seeds: Vec<Seed> = mesh
        .edges
        .iter()
        .filter(|&&[i, j]| material[i as usize] != material[j as usize])
        .map(|&[i, j]| {
            let (i, j) = (i as usize, j as usize);
            let point = interface_point(ic, mesh.coords[i], mesh.coords[j]);
            Seed { ends: [i, j], point, normal: None }
        })
        .collect();
    let d = distance_to_interface(mesh, &ls.adjacency, &seeds, None);
    d.iter()
        .zip(material)
        .map(|(&d, &m)| {
            // No interface anywhere: one fluid, a unit distance of its sign.
            let d = if d.is_finite() { d } else { 1.0 };
            signed(if m == positive { d } else { -d }, m == positive)
        })
        .collect()
}

/// `v` on the side `positive` (`φ >= 0`) or not, whatever round-off did to its sign (a node on
/// the surface of a region is inside it: `+0`; a node outside at zero distance gets the
/// smallest negative number).
fn signed(v: f64, positive: bool) -> f64 {
    match (positive, v >= 0.0) {
        (true, true) | (false, false) => v,
        (true, false) => 0.0,
        (false, true) => -f64::MIN_POSITIVE,
    }
}

/// The point where the fluid of `ic` changes between `a` and `b` (whose fluids differ).
fn interface_point(ic: &InitialCondition, a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    let at = |t: f64| add(a, scale(sub(b, a), t));
    let ma = ic.at(a).material;
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..BISECTIONS {
        let mid = 0.5 * (lo + hi);
        if ic.at(at(mid)).material == ma {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    at(0.5 * (lo + hi))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bc::BoundaryCondition;
    use crate::eos::Eos;
    use crate::initial::Fill;
    use crate::mesh::boxmesh::{BoxCells, BoxSpec, FACE_NAMES};
    use crate::semidiscretization::{Numerics, Semidiscretization};

    fn setup(ic: &InitialCondition) -> (Semidiscretization, LevelSet, Vec<MaterialId>) {
        let spec = BoxSpec::uniform([0.0; 3], [1.0; 3], [12, 12, 12], BoxCells::Tet);
        let mesh = Mesh::build(spec.raw().unwrap()).unwrap();
        let eos = [Eos::PerfectGas { gamma: 1.4 }, Eos::StiffenedGas { gamma: 4.4, p_c: 6e8 }];
        let state = ic.state(&mesh, &eos).unwrap();
        let walls: Vec<(String, BoundaryCondition)> =
            FACE_NAMES.iter().map(|n| (n.to_string(), BoundaryCondition::SlipWall)).collect();
        let semi = Semidiscretization::with_materials(
            mesh,
            eos.to_vec(),
            state.material.clone(),
            Numerics::default(),
            &walls,
        )
        .unwrap();
        let ls = LevelSet::new(&semi, [0, 1], 10);
        (semi, ls, state.material)
    }

    fn ic(regions: Vec<Region>) -> InitialCondition {
        let fill = |material| Fill { state: [1.0, 0.0, 0.0, 0.0, 1e5], material };
        InitialCondition {
            background: fill(0),
            regions: regions.into_iter().map(|r| (r, fill(1))).collect(),
        }
    }

    /// A sphere: the exact signed distance, its sign the materials.
    #[test]
    fn a_sphere_gets_its_exact_signed_distance() {
        let (c, radius) = ([0.5, 0.45, 0.5], 0.3);
        let ic = ic(vec![Region::Sphere { center: c, radius }]);
        let (semi, ls, material) = setup(&ic);
        let phi = signed_distance(&semi.mesh, &ls, &ic, &material);
        for (i, &x) in semi.mesh.coords.iter().enumerate() {
            assert_eq!(ls.material_of(phi[i]), material[i], "node {i}");
            assert!((phi[i] - (radius - norm(sub(x, c)))).abs() < 1e-15);
        }
    }

    /// A box: the closest-point distance from the bisected interface points, the right signs
    /// everywhere, and near the exact distance to the box faces (nodes off its edges and corners).
    #[test]
    fn a_box_gets_a_signed_distance_from_its_interface_points() {
        let (lo, hi) = ([0.21, 0.3, 0.27], [0.74, 0.69, 0.8]);
        let ic = ic(vec![Region::Box { lo, hi }]);
        let (semi, ls, material) = setup(&ic);
        let phi = signed_distance(&semi.mesh, &ls, &ic, &material);
        let h = 1.0 / 12.0;
        let mut checked = 0;
        for (i, &x) in semi.mesh.coords.iter().enumerate() {
            assert_eq!(ls.material_of(phi[i]), material[i], "node {i}");
            // Inside, away from the box's edges: the distance to the nearest face.
            let d: Vec<f64> = (0..3).flat_map(|k| [x[k] - lo[k], hi[k] - x[k]]).collect();
            let inside = d.iter().all(|&v| v > 0.0);
            let mut sorted = d.clone();
            sorted.sort_by(f64::total_cmp);
            if inside && sorted[1] - sorted[0] > 1.5 * h {
                assert!(
                    (phi[i] - sorted[0]).abs() < 0.1 * h,
                    "node {i}: {} vs {}",
                    phi[i],
                    sorted[0]
                );
                checked += 1;
            }
        }
        assert!(checked > 10, "{checked}");
    }
}
