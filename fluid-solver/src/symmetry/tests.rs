//! An octant with three symmetry planes against the whole box it is the eighth of: with the same
//! steps, the octant's nodes hold the whole box's states at the same points.

use super::*;
use crate::bc::BoundaryCondition;
use crate::eos::Eos;
use crate::levelset::{LevelSet, LevelSetWorkspace};
use crate::mesh::boxmesh::{BoxCells, BoxSpec, FACE_NAMES};
use crate::mesh::geometry::dot;
use crate::semidiscretization::{Numerics, Semidiscretization};
use crate::state::{MaterialId, State, Workspace};
use crate::time::{rk2_step, TimeStepping};
use std::collections::HashMap;

const GAS: Eos = Eos::PerfectGas { gamma: 1.4 };
const WATER: Eos = Eos::StiffenedGas { gamma: 4.4, p_c: 6e8 };

/// The octant `[0, a]³` of `n` hexes per axis with symmetry planes at the `min` faces and the
/// whole box `[-a, a]³` of `2n`, each with `outer` at its other faces, for the materials of
/// `material_at` (ids into `eos`); and for every octant node, the whole box's node at the same
/// point.
fn octant_and_whole(
    n: usize,
    a: f64,
    eos: Vec<Eos>,
    outer: BoundaryCondition,
    material_at: impl Fn([f64; 3]) -> MaterialId,
) -> (Semidiscretization, Semidiscretization, Vec<usize>) {
    let build = |lo: f64, cells: usize, min: BoundaryCondition| {
        let mesh = Mesh::build(
            BoxSpec::uniform([lo; 3], [a; 3], [cells; 3], BoxCells::Hex).raw().unwrap(),
        )
        .unwrap();
        let bcs: Vec<(String, BoundaryCondition)> = FACE_NAMES
            .iter()
            .map(|f| (f.to_string(), if f.ends_with("min") { min } else { outer }))
            .collect();
        let material = mesh.coords.iter().map(|&x| material_at(x)).collect();
        Semidiscretization::with_materials(mesh, eos.clone(), material, Numerics::default(), &bcs)
            .unwrap()
    };
    let octant = build(0.0, n, BoundaryCondition::Symmetry);
    let whole = build(-a, 2 * n, outer);
    let key = |x: &[f64; 3]| x.map(|c| (c / a * 1e9).round() as i64);
    let at: HashMap<[i64; 3], usize> =
        whole.mesh.coords.iter().enumerate().map(|(i, x)| (key(x), i)).collect();
    let same = octant.mesh.coords.iter().map(|x| at[&key(x)]).collect();
    (octant, whole, same)
}

/// The largest difference of the primitive states `(ρ, |u|, p)` between the octant's nodes and
/// the whole box's at the same points, relative to `scale`.
fn difference(
    octant: &[[f64; 5]],
    whole: &[[f64; 5]],
    same: &[usize],
    scale: [f64; 3],
) -> [f64; 3] {
    let mut d = [0.0f64; 3];
    for (wo, &j) in octant.iter().zip(same) {
        let ww = &whole[j];
        let du = (1..4).map(|k| (wo[k] - ww[k]).powi(2)).sum::<f64>().sqrt();
        d[0] = d[0].max((wo[0] - ww[0]).abs() / scale[0]);
        d[1] = d[1].max(du / scale[1]);
        d[2] = d[2].max((wo[4] - ww[4]).abs() / scale[2]);
    }
    d
}

/// The velocity components normal to the symmetry planes the node lies on.
fn normal_velocity(mesh: &Mesh, prim: &[[f64; 5]]) -> f64 {
    let mut largest = 0.0f64;
    for (x, w) in mesh.coords.iter().zip(prim) {
        for k in 0..3 {
            if x[k] == 0.0 {
                largest = largest.max(w[1 + k].abs());
            }
        }
    }
    largest
}

/// The octant node counts of a mesh on 0, 1, 2 and 3 symmetry planes.
fn on_planes(mesh: &Mesh) -> [usize; 4] {
    let mut count = [0; 4];
    for x in &mesh.coords {
        count[x.iter().filter(|&&c| c == 0.0).count()] += 1;
    }
    count
}

/// A pressure and density pulse centred at the corner of the octant, even in x, y and z but
/// not spherical, in a gas at rest: 40 steps (the pulse reaches the far faces) of the octant and
/// of the whole box give the same states at every octant node to round-off, and the velocity
/// normal to each plane stays exactly zero on it, at the axes and the corner too. With the weak
/// wall flux alone the normal velocity on the planes reached 4.4% of the largest velocity, and
/// the velocities differed by 5.8% of it, the densities by 0.8% of the pulse.
#[test]
fn an_octant_with_symmetry_planes_steps_as_the_whole_box() {
    let ambient = [1.0, 0.0, 0.0, 0.0, 1.0];
    let outer = BoundaryCondition::FarField { state: ambient };
    let (octant, whole, same) = octant_and_whole(6, 1.0, vec![GAS], outer, |_| 0);
    let counts = on_planes(&octant.mesh);
    assert_eq!(counts, [216, 108, 18, 1]);
    let pulse = |x: &[f64; 3]| {
        let g = (-(x[0] / 0.45).powi(2) - (x[1] / 0.35).powi(2) - (x[2] / 0.3).powi(2)).exp();
        GAS.prim_to_cons(&[1.0 + 0.5 * g, 0.0, 0.0, 0.0, 1.0 + 2.0 * g])
    };
    let state_of = |semi: &Semidiscretization| {
        State::new(semi.mesh.coords.iter().map(pulse).collect::<Vec<_>>())
    };
    let (mut so, mut sw) = (state_of(&octant), state_of(&whole));
    let mut wso = Workspace::new(octant.mesh.n_nodes());
    let mut wsw = Workspace::new(whole.mesh.n_nodes());
    let dt = 0.01;
    let stepping = TimeStepping::Global { cfl: 0.8 };
    for _ in 0..40 {
        assert_eq!(rk2_step(&octant, &mut so, &mut wso, stepping, dt).unwrap(), dt);
        assert_eq!(rk2_step(&whole, &mut sw, &mut wsw, stepping, dt).unwrap(), dt);
    }
    let prim = |s: &State| s.cons.iter().map(|q| GAS.cons_to_prim(q)).collect::<Vec<_>>();
    let (po, pw) = (prim(&so), prim(&sw));
    let u_max = po.iter().map(|w| (w[1] * w[1] + w[2] * w[2] + w[3] * w[3]).sqrt());
    let u_max = u_max.fold(0.0, f64::max);
    let d = difference(&po, &pw, &same, [0.5, u_max, 2.0]);
    let un = normal_velocity(&octant.mesh, &po);
    println!("octant against the whole box: |Δρ|, |Δu|, |Δp| {d:?}; |u·n| {un:e} (|u| {u_max})");
    assert!(u_max > 0.05, "the pulse moved: |u| up to {u_max}");
    assert_eq!(un, 0.0, "velocity across a symmetry plane");
    assert!(d.iter().all(|&e| e < 1e-12), "octant and whole box differ by {d:?}");
}

/// A sphere of gas in water, both at rest, at pressures `[p_gas, p_water]` and `R0/h = r0_h` (the
/// gas 1% of the water's density, the far faces held at `p_water`), with the
/// level set and its ghost states, not reinitialised (the whole box's reinitialisation breaks
/// ties by node number, which the mirror images do not share): 100 steps on the octant and on
/// the whole box. Returns the octant nodes that changed fluid by the number of planes they lie
/// on, the largest differences of `(ρ, |u|, p)` (relative to the gas pressure's scale) and of
/// `φ/h`, and the largest velocity across a plane.
fn bubble_octant_and_whole(p: [f64; 2], r0_h: f64) -> ([usize; 4], [f64; 3], f64, f64) {
    let (r0, h) = (0.01, 0.01 / r0_h);
    let outer = BoundaryCondition::Outflow { pressure: p[1] };
    let inside = |x: [f64; 3]| dot(x, x).sqrt() < r0;
    let (mut octant, mut whole, same) =
        octant_and_whole(10, 10.0 * h, vec![WATER, GAS], outer, |x| u8::from(inside(x)));
    let gas = GAS.prim_to_cons(&[10.0, 0.0, 0.0, 0.0, p[0]]);
    let water = WATER.prim_to_cons(&[1e3, 0.0, 0.0, 0.0, p[1]]);
    let state_of = |semi: &Semidiscretization| State {
        cons: semi.material().iter().map(|&m| if m == 1 { gas } else { water }).collect(),
        material: semi.material().to_vec(),
        phi: semi.mesh.coords.iter().map(|x| r0 - dot(*x, *x).sqrt()).collect(),
    };
    let (mut so, mut sw) = (state_of(&octant), state_of(&whole));
    let (lo, lw) = (LevelSet::new(&octant, [0, 1], 0), LevelSet::new(&whole, [0, 1], 0));
    let (no, nw) = (octant.mesh.n_nodes(), whole.mesh.n_nodes());
    let (mut wso, mut lwso) = (Workspace::new(no), LevelSetWorkspace::new(no));
    let (mut wsw, mut lwsw) = (Workspace::new(nw), LevelSetWorkspace::new(nw));
    let dt = 1e-7;
    let stepping = TimeStepping::Global { cfl: 0.8 };
    let before = so.material.clone();
    for step in 1..=100 {
        let a = lo.step(&mut octant, &mut so, &mut wso, &mut lwso, stepping, dt, step).unwrap();
        let b = lw.step(&mut whole, &mut sw, &mut wsw, &mut lwsw, stepping, dt, step).unwrap();
        assert_eq!((a.dt, b.dt), (dt, dt), "step {step}");
    }
    let mut changed = [0; 4];
    for (i, x) in octant.mesh.coords.iter().enumerate() {
        if so.material[i] != before[i] {
            changed[x.iter().filter(|&&c| c == 0.0).count()] += 1;
        }
    }
    let prim = |s: &State| -> Vec<[f64; 5]> {
        let eos = |m: MaterialId| [WATER, GAS][m as usize];
        s.cons.iter().zip(&s.material).map(|(q, &m)| eos(m).cons_to_prim(q)).collect()
    };
    let (po, pw) = (prim(&so), prim(&sw));
    let d = difference(&po, &pw, &same, [10.0, 10.0, 1e7]);
    let dphi = so.phi.iter().zip(&same).map(|(p, &j)| (p - sw.phi[j]).abs() / h);
    (changed, d, dphi.fold(0.0, f64::max), normal_velocity(&octant.mesh, &po))
}

/// The underwater bubble's start (gas at 10 MPa in water at 1 MPa, `R0/h = 4.97`, so that the
/// first water nodes on the axes and the planes turn to gas within the run) and a collapsing
/// bubble (gas at 0.1 MPa in water at 20 MPa, `R0/h = 5.02`, the outer gas nodes on the axes and
/// the planes turn to water): the octant holds the
/// whole box's `φ` and states at every node to round-off, with nodes on one and on two planes
/// changed fluid. With the weak wall flux alone the velocity across the planes reached 0.95 m/s
/// in the growing bubble; without the mirror images in the ghost states' neighbour mean the
/// collapsing bubble's plane nodes that turned to water took other states.
#[test]
fn an_octant_with_a_level_set_steps_as_the_whole_box() {
    for (p, r0_h) in [([1e7, 1e6], 4.97), ([1e5, 2e7], 5.02)] {
        let (changed, d, dphi, un) = bubble_octant_and_whole(p, r0_h);
        println!(
            "gas at {:e} Pa in water at {:e} Pa, octant against the whole box: changed \
             {changed:?} (off, on 1, 2, 3 planes); |Δρ|, |Δu|, |Δp| {d:?}, |Δφ| {dphi:e} h; \
             |u·n| {un:e}",
            p[0], p[1]
        );
        assert!(changed[1] > 0 && changed[2] > 0, "changed fluid: {changed:?}");
        assert_eq!(un, 0.0, "velocity across a symmetry plane");
        assert!(d.iter().all(|&e| e < 1e-11) && dphi < 1e-11, "{d:?}, |Δφ| {dphi} h");
    }
}
